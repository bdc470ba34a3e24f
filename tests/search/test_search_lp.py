"""The global check (issue #31): an upper-bound LP over every candidate line.

V1 at the LP grid: a two-block wall cut by n bed joints, N at the top hinge (the spec's
``overburden.xi = 0``), gives exactly
``min_k λ0(k h/n)`` of the closed form (docs/search.md, V1: 1.165689 for
n = 300, N = W). V3: on every test scene the LP multiplier is at most the best catalogue
mechanism's, and equal (1e-6) where the catalogue holds the optimum.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from search_scenes import EXAMPLE_SCENE, EXAMPLE_SPEC, two_block_wall, wedge_facade, wedge_spec

from cad_maths.scenes import read_scene
from cad_maths.search.engine import run_search
from cad_maths.search.lp import facade_lp_model, solve_lp
from cad_maths.search.model import building_from_scene
from shared_schema.rules import G
from shared_schema.search import SearchSpec, parse_search_spec

B, H, L, RHO = 0.3, 3.0, 1.0, 1800.0
W = RHO * G * B * H * L


@pytest.fixture(scope="module")
def two_block(tmp_path_factory: pytest.TempPathFactory) -> Any:
    path = two_block_wall(tmp_path_factory.mktemp("lp"), B, H, L)
    spec = SearchSpec.model_validate(
        {
            "walls": [
                {"id": "W", "object": "wall", "density": RHO, "overburden": {"force": W, "xi": 0.0}}
            ],
            "levels": [
                {"id": "S", "kind": "floor", "objects": ["slab"], "density": 2400.0, "tied": True}
            ],
        }
    )
    return building_from_scene(read_scene(path), spec)


@pytest.mark.parametrize("n", [10, 60])
def test_v1_lp_gives_the_closed_form_minimum_at_its_grid(two_block: Any, n: int) -> None:
    heights = [H * k / n for k in range(1, n)]
    model = facade_lp_model(two_block, "W", "outward", heights)
    res = solve_lp(model)

    def lam(h1: float) -> float:
        return (2 * B / W) * ((W + W) / h1 + W / (H - h1))

    assert res.status == "optimal"
    assert res.lam == pytest.approx(min(lam(h) for h in heights), rel=1e-9)
    assert len(res.bodies) == 2  # the two blocks of the strip


@pytest.mark.slow
def test_v1_lp_converges_to_the_closed_form_at_300_joints(two_block: Any) -> None:
    heights = [H * k / 300 for k in range(1, 300)]
    res = solve_lp(facade_lp_model(two_block, "W", "outward", heights))
    assert res.lam == pytest.approx(1.165689, abs=5e-7)  # docs/search.md V1, n = 300


def _scenes(tmp: Path) -> list[tuple[str, Any, Any]]:
    wedge = wedge_facade(tmp, name="plain")
    windows = wedge_facade(
        tmp,
        windows=[
            (1.5, 2.7, 1.0, 3.0),
            (5.3, 6.5, 1.0, 3.0),
            (1.5, 2.7, 5.0, 7.0),
            (5.3, 6.5, 5.0, 7.0),
        ],
        name="windows",
    )
    tb = two_block_wall(tmp, B, H, L)
    tb_spec = {
        "walls": [{"id": "W", "object": "wall", "density": RHO, "overburden": {"force": W}}],
        "levels": [
            {"id": "S", "kind": "floor", "objects": ["slab"], "density": 2400.0, "tied": True}
        ],
    }
    return [
        ("plain good", wedge, wedge_spec("good", (0.25, 0.12))),
        ("plain poor", wedge, wedge_spec("poor", None)),
        ("windows good", windows, wedge_spec("good", (0.25, 0.12))),
        ("windows poor", windows, wedge_spec("poor", None)),
        ("two-block", tb, tb_spec),
        ("example", EXAMPLE_SCENE, json_spec()),
    ]


def json_spec() -> Any:
    return parse_search_spec(EXAMPLE_SPEC.read_text()).model_dump(exclude_unset=True)


def test_v3_lp_never_exceeds_the_catalogue_and_matches_it_where_it_holds_the_optimum(
    tmp_path: Path,
) -> None:
    for label, scene, spec in _scenes(tmp_path):
        res = run_search(read_scene(scene), SearchSpec.model_validate(spec))
        assert res.checks, label
        for check in res.checks:
            assert check.result.status == "optimal", label
            assert check.lam <= check.best * (1.0 + 1e-9), (label, check.facade)
            # every catalogue optimum here is the LP's: equal to 1e-6
            assert check.lam == pytest.approx(check.best, rel=1e-6), (label, check.facade)
            assert not check.missed


def test_lp_says_when_the_catalogue_misses_a_mechanism(tmp_path: Path) -> None:
    """With only partial overturning asked for, the check still cuts the wall at its base:
    it finds the full-height overturning (t/H), lower than every partial one, flags the
    gap and returns that mechanism: the whole façade moving as one body."""
    path = wedge_facade(tmp_path)
    spec = SearchSpec.model_validate(
        wedge_spec("poor", None, families=["partial_overturning"], candidates={"spacing": 1.5})
    )
    res = run_search(read_scene(path), spec)
    (check,) = res.checks
    assert min(c.lam0 for c in res.candidates) > 0.5 / 9.0
    assert check.lam == pytest.approx(0.5 / 9.0, rel=1e-9)
    assert check.missed and check.gap > 0.01
    (body,) = check.result.bodies
    assert {check.model.blocks[b].wall for b in body} == {"F"}
    assert len(body) == len([b for b in check.model.blocks if b.wall == "F"])
