"""V1 and V2 of issue #31: the search's exact λ0 and refinement against closed forms.

V1 (docs/search.md, Validation): a two-block wall restrained at the top, overburden N
at the top hinge: ``λ0(h1) = (2b/W) [(W + N)/h1 + N/h2]``, minimised at ``h1* = h/(1 + x)``,
``λ* = 2b (N + W)(1 + x)² / (W h)``, ``x = sqrt(N/(N + W))``.

V2 (docs/search.md): a façade with two triangular side-wall wedges cut from the junction's base
corner at β from the vertical, τ = tan β::

    λ0(τ) = [L t²/2 + s H τ t + s H² τ²/3] / [L t H/2 + (2/3) s H² τ]

increasing in τ, so with no crack friction the optimum sits on the bond limit exactly.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from search_scenes import two_block_wall, wedge_facade, wedge_spec

from cad_maths.scenes import read_scene
from cad_maths.search.families import enumerate_candidates, overturning_template, two_block_lam
from cad_maths.search.model import building_from_scene
from cad_maths.search.refine import minimise
from shared_schema.rules import G
from shared_schema.search import SearchSpec

B, H, L, RHO = 0.3, 3.0, 1.0, 1800.0
W = RHO * G * B * H * L


def closed_form_v1(n: float) -> tuple[float, float]:
    x = math.sqrt(n / (n + W))
    return H / (1.0 + x), 2.0 * B * (n + W) * (1.0 + x) ** 2 / (W * H)


@pytest.fixture(scope="module")
def two_block(tmp_path_factory: pytest.TempPathFactory) -> tuple[object, object]:
    path = two_block_wall(tmp_path_factory.mktemp("v1"), B, H, L)
    spec = SearchSpec.model_validate(
        {
            "walls": [{"id": "W", "object": "wall", "density": RHO, "overburden": {"force": W}}],
            "levels": [
                {"id": "S", "kind": "floor", "objects": ["slab"], "density": 2400.0, "tied": True}
            ],
            "families": ["vertical_flexure"],
        }
    )
    return building_from_scene(read_scene(path), spec), spec


@pytest.mark.parametrize("ratio", [0.25, 1.0, 4.0])
def test_v1_two_block_hinge_height_and_multiplier_match_the_closed_form(
    two_block: tuple[object, object], ratio: float
) -> None:
    bld, _ = two_block
    wall = bld.walls["W"]  # type: ignore[attr-defined]
    n = ratio * W
    d = -wall.frame.e_n
    # N at the top hinge H: on the outer face (x = 0 along the collapse direction)
    res = minimise(lambda x: two_block_lam(wall, x[0], d, n, 0.0), [(0.06, 2.94)])
    h1, lam = closed_form_v1(n)
    assert res.x[0] == pytest.approx(h1, rel=1e-9, abs=0.0)
    assert res.value == pytest.approx(lam, rel=1e-9, abs=0.0)


def test_v1_vertical_flexure_candidate_is_the_minimum_with_the_builders_overburden_point(
    two_block: tuple[object, object],
) -> None:
    """The family's candidate puts N where the builder does (the centre line, x = -b/2)."""
    bld, _ = two_block
    cands, _ = enumerate_candidates(bld)  # type: ignore[arg-type]
    (cand,) = [c for c in cands if c.family == "vertical_flexure"]

    # N at (-b/2, h) rises by b (1 + h1/(2 h2)) per unit rotation of block 1 (independent
    # closed form); minimise it on a dense grid and polish with a bracketed search.
    def lam(h1: float) -> float:
        h2 = H - h1
        return (W * B + W * B * (1.0 + h1 / (2.0 * h2))) / (W * h1 / 2.0)

    from scipy.optimize import minimize_scalar

    grid = np.linspace(0.1, 2.9, 2801)
    k = int(np.argmin([lam(x) for x in grid]))
    ref = minimize_scalar(
        lam, bounds=(grid[k - 1], grid[k + 1]), method="bounded", options={"xatol": 1e-13}
    )
    assert cand.lam0 == pytest.approx(ref.fun, rel=1e-12)
    assert cand.params["h1_m"] == pytest.approx(ref.x, rel=1e-7)
    assert cand.typology == "two_block" and cand.rocking == "two_sided"


HW, LW, TW, SW = 9.0, 8.0, 0.5, 0.5


def closed_form_v2(tau: float) -> float:
    num = LW * TW**2 / 2 + SW * HW * tau * TW + SW * HW**2 * tau**2 / 3
    return num / (LW * TW * HW / 2 + 2.0 / 3.0 * SW * HW**2 * tau)


@pytest.fixture(scope="module")
def wedges(tmp_path_factory: pytest.TempPathFactory) -> object:
    path = wedge_facade(tmp_path_factory.mktemp("v2"), HW, LW, TW, SW, reach=12.0)
    spec = SearchSpec.model_validate(wedge_spec("good", (0.25, 0.12)))
    return building_from_scene(read_scene(path), spec)


@pytest.mark.parametrize(("tau", "expected"), [(0.0, 0.05556), (0.5, 0.17460), (1.0, 0.37222)])
def test_v2_wedge_multiplier_matches_the_closed_form(
    wedges: object, tau: float, expected: float
) -> None:
    bld = wedges
    tmpl, why = overturning_template(bld, bld.walls["F"], "outward", 0.0)  # type: ignore[attr-defined]
    assert tmpl is not None, why
    beta = math.atan(tau)
    lam = tmpl.lam([beta, beta])
    assert lam == pytest.approx(closed_form_v2(tau), rel=1e-12)
    assert lam == pytest.approx(expected, abs=5e-6)  # docs/search.md V2, five digits


def test_v2_wedge_multiplier_increases_with_the_angle(wedges: object) -> None:
    bld = wedges
    tmpl, _ = overturning_template(bld, bld.walls["F"], "outward", 0.0)  # type: ignore[attr-defined]
    assert tmpl is not None
    betas = np.linspace(0.0, math.atan(12.0 / HW), 40)
    lams = [tmpl.lam([b, b]) for b in betas]
    assert np.all(np.diff(lams) > 0.0)
    # each side alone too
    assert np.all(np.diff([tmpl.lam([b, betas[0]]) for b in betas]) > 0.0)


def test_v2_optimum_sits_exactly_on_the_bond_limit(wedges: object) -> None:
    bld = wedges
    cands, _ = enumerate_candidates(bld)  # type: ignore[arg-type]
    (full,) = [c for c in cands if c.family == "wedge_overturning" and c.hinge_z == 0.0]
    bond = math.atan(0.25 / (2 * 0.12))
    assert full.params["beta_start_rad"] == bond
    assert full.params["beta_end_rad"] == bond
    assert sorted(full.on_bound) == ["beta_end_rad", "beta_start_rad"]
    assert full.lam0 == pytest.approx(closed_form_v2(math.tan(bond)), rel=1e-12)


def test_v2_poor_connection_gives_plain_overturning(tmp_path: Path) -> None:
    path = wedge_facade(tmp_path, HW, LW, TW, SW)
    spec = SearchSpec.model_validate(wedge_spec("poor", None))
    cands, _ = enumerate_candidates(building_from_scene(read_scene(path), spec))
    (full,) = [c for c in cands if c.hinge_z == 0.0]
    assert full.family == "overturning"
    assert full.lam0 == pytest.approx(TW / HW, rel=1e-12)
