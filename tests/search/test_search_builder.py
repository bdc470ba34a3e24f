"""Each candidate is a mechanism spec of an existing typology, through the existing builder.

The search's prism geometry and the constants builder (``cad_maths.mechanisms.build``,
meshes cut by manifold3d) agree to 1e-9 on the exact static multiplier and the mass (issue
#31); the builder's linearised λ sits a few per cent below λ0 on squat blocks.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from search_scenes import EXAMPLE_SCENE, EXAMPLE_SPEC, two_block_wall, wedge_facade, wedge_spec

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.scenes import read_scene
from cad_maths.search.engine import run_search
from cad_maths.search.specs import AGREEMENT_RTOL, build_candidates
from shared_schema.rules import G
from shared_schema.search import SearchSpec, parse_search_spec
from shared_schema.spec import parse_spec


def _built(scene: Path, spec: Any) -> tuple[Any, Any, Any, Any]:
    res = run_search(read_scene(scene), spec, lp=False)
    ids = [f"S{k + 1:02d}" for k in range(len(res.candidates))]
    cf, failures, agreement, _sf = build_candidates(res.building, res.candidates, ids)
    return res, cf, failures, agreement


@pytest.mark.parametrize("connection", ["good", "poor"])
def test_builder_agrees_with_the_search_on_a_wedge_facade(tmp_path: Path, connection: str) -> None:
    path = wedge_facade(
        tmp_path, windows=[(1.5, 2.7, 1.0, 3.0), (5.3, 6.5, 5.0, 7.0)], name=connection
    )
    unit = (0.25, 0.12) if connection == "good" else None
    res, _cf, failures, agreement = _built(
        path, SearchSpec.model_validate(wedge_spec(connection, unit))
    )
    assert not failures
    assert len(agreement) == len(res.candidates) >= 3
    for mid, a in agreement.items():
        assert a["lam0_rel"] <= AGREEMENT_RTOL and a["mass_rel"] <= AGREEMENT_RTOL, mid
        assert a["agrees"]
        # the linearised multiplier of the rocking constants is below the exact one
        assert a["lam"] < a["lam0"]


def test_builder_agrees_on_the_example_with_levels_and_a_tie(tmp_path: Path) -> None:
    spec = parse_search_spec(EXAMPLE_SPEC.read_text())
    _res, cf, failures, agreement = _built(EXAMPLE_SCENE, spec)
    assert not failures
    typologies = {m.typology for m in cf.mechanisms}
    assert "single_block_loaded" in typologies
    for a in agreement.values():
        assert a["lam0_rel"] <= AGREEMENT_RTOL and a["mass_rel"] <= AGREEMENT_RTOL


def test_two_block_candidate_rebuilds_at_its_hinge_height(tmp_path: Path) -> None:
    b, h, rho = 0.3, 3.0, 1800.0
    w = rho * G * b * h * 1.0
    path = two_block_wall(tmp_path, b, h, 1.0)
    spec = SearchSpec.model_validate(
        {
            "walls": [{"id": "W", "object": "wall", "density": rho, "overburden": {"force": w}}],
            "levels": [
                {"id": "S", "kind": "floor", "objects": ["slab"], "density": 2400.0, "tied": True}
            ],
        }
    )
    res, cf, failures, agreement = _built(path, spec)
    assert not failures
    # one mechanism per side, each at its own hinge height
    assert [c.direction for c in res.candidates] == ["outward", "inward"] or [
        c.direction for c in res.candidates
    ] == ["inward", "outward"]
    for mech, cand in zip(cf.mechanisms, res.candidates):
        assert mech.typology == "two_block" and mech.rocking == "two_sided"
        summary = mech.geometry["two_block"]
        assert summary["h_c_source"] == "hinge_height (given)"
        assert summary["h_c_m"] == pytest.approx(cand.params["h1_m"], rel=1e-15)
        a = agreement[mech.id]
        assert a["lam0_rel"] <= AGREEMENT_RTOL and a["mass_rel"] <= AGREEMENT_RTOL
        # the builder's negative side (left out where it equals the positive one) is the
        # search's other side at the same hinge height
        side = mech.negative if mech.negative is not None else mech.positive
        assert side.virtual_work is not None
        neg = side.virtual_work.alpha0
        assert neg == pytest.approx(cand.lam0_negative, rel=1e-9)


def test_search_spec_reopens_with_the_existing_constants_command(tmp_path: Path) -> None:
    """The spec the search writes is a plain mechanism spec: the builder on the input scene
    (not the search's own) gives the same constants."""
    path = wedge_facade(tmp_path)
    spec = SearchSpec.model_validate(wedge_spec("good", (0.25, 0.12)))
    res, cf, _failures, _agreement = _built(path, spec)
    ids = [m.id for m in cf.mechanisms]
    _, _, _, sf = build_candidates(res.building, res.candidates, ids)
    text = sf.model_dump_json(exclude_none=True)
    again = constants_from_spec(
        parse_spec(text), read_scene(path), scene_name=path.name, spec_name="search.spec.json"
    )
    for m1, m2 in zip(cf.mechanisms, again.mechanisms):
        assert m1.positive.p_eq == pytest.approx(m2.positive.p_eq, rel=1e-12)
        assert m1.positive.lam == pytest.approx(m2.positive.lam, rel=1e-12)
    doc = json.loads(text)
    crack = doc["mechanisms"][0]["cracks"][0]
    assert crack["keep"] == "positive" and crack["objects"]


def test_crack_objects_limit_the_cut(tmp_path: Path) -> None:
    """Wedges of different angles on the two sides: each crack cuts only its own wall (a
    plane through one return wall would otherwise cut the other)."""
    path = wedge_facade(tmp_path)
    spec = SearchSpec.model_validate(
        {
            **wedge_spec("good", (0.25, 0.12)),
            "junctions": [
                {
                    "walls": ["F", "L"],
                    "connection": "good",
                    "unit": {"length": 0.25, "height": 0.12},
                },
                {
                    "walls": ["F", "R"],
                    "connection": "good",
                    "unit": {"length": 0.4, "height": 0.12},
                },
            ],
        }
    )
    res, _cf, _failures, agreement = _built(path, spec)
    full = next(c for c in res.candidates if c.family == "wedge_overturning" and c.hinge_z == 0.0)
    assert full.params["beta_start_rad"] != full.params["beta_end_rad"]
    for a in agreement.values():
        assert a["agrees"]
