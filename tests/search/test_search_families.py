"""The families and inputs beyond the wedge façade (issue #31).

Gable and parapet (the part above the top level), the corner wedge, a free-standing wall
(two-sided), openings drawn as solids, a scan mesh, a wall that is not a prism, and the
sliding flags.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from search_scenes import BUILD, wedge_facade, wedge_spec

from cad_maths.scenes import read_scene
from cad_maths.search.engine import run_search
from cad_maths.search.specs import build_candidates
from shared_schema.errors import InputError
from shared_schema.search import SearchSpec
from solver_service.workflows.inputs import constants_from_scene_files
from solver_service.workflows.search import search_run, write_search_files

REPO = Path(__file__).resolve().parents[2]


def _built(scene: Any, spec: dict[str, Any], lp: bool = False) -> tuple[Any, Any]:
    res = run_search(scene, SearchSpec.model_validate(spec), lp=lp)
    ids = [f"S{k + 1:02d}" for k in range(len(res.candidates))]
    _cf, failures, agreement, _ = build_candidates(res.building, res.candidates, ids)
    assert not failures, [f.message for f in failures]
    return res, agreement


def _gable_scene(tmp_path: Path, parapet: bool) -> Path:
    """A 0.4 m thick façade (outer face x = 0) 6 m long, eaves at 6 m, and a floor slab
    abutting its inner face just below the eaves; a gable rises to 8 m (or a flat parapet
    to 7 m)."""
    b = BUILD.Builder("gable" if not parapet else "parapet")
    top = [(6.0, 7.0), (0.0, 7.0)] if parapet else [(3.0, 8.0)]
    v, f = BUILD.slab_solid(
        (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0), 0.4,
        [(0.0, 0.0), (6.0, 0.0), (6.0, 6.0), *top, (0.0, 6.0)],
    )  # fmt: skip
    b.mesh("facade", "Walls", v, f, "brick")
    b.box("slab", "Floors", (0.4, 0.0, 5.8), (5.0, 6.0, 6.0), "concrete")
    return b.write(tmp_path / f"{'parapet' if parapet else 'gable'}.3dm")


@pytest.mark.parametrize("parapet", [False, True])
def test_gable_and_parapet_are_the_part_above_the_top_level(tmp_path: Path, parapet: bool) -> None:
    path = _gable_scene(tmp_path, parapet)
    spec = {
        "walls": [{"id": "F", "object": "facade", "density": 1800.0}],
        "levels": [{"id": "L", "kind": "floor", "objects": ["slab"], "density": 2400.0}],
        "directions": ["outward"],
    }
    res, agreement = _built(read_scene(path), spec)
    family = "parapet" if parapet else "gable"
    (top,) = [c for c in res.candidates if c.family == family]
    assert top.hinge_z == pytest.approx(6.0)
    assert not top.contacts  # the slab is below the hinge line
    if parapet:  # a 0.4 x 1 m block above the hinge: λ0 = b/h
        assert top.lam0 == pytest.approx(0.4 / 1.0, rel=1e-12)
    else:  # a triangle of height 2 m: its centre is 2/3 m above the hinge, λ0 = 0.2/(2/3)
        assert top.lam0 == pytest.approx(0.2 / (2.0 / 3.0), rel=1e-12)
    assert all(a["agrees"] for a in agreement.values())
    families = {c.family for c in res.candidates}
    assert "overturning" in families and "partial_overturning" in families


def test_corner_wedge_agrees_with_the_builder(tmp_path: Path) -> None:
    path = wedge_facade(tmp_path)
    res, agreement = _built(read_scene(path), wedge_spec("good", (0.25, 0.12)))
    corners = [c for c in res.candidates if c.family == "corner"]
    assert len(corners) == 2  # one at each end of the façade
    bond = math.atan(0.25 / 0.24)
    for c in corners:
        assert c.params["beta_facade_rad"] == bond and c.params["beta_return_rad"] == bond
        d = c.direction_vector
        assert abs(d[0] + math.sqrt(0.5)) < 1e-12 and abs(abs(d[1]) - math.sqrt(0.5)) < 1e-12
    assert corners[0].lam0 == pytest.approx(corners[1].lam0, rel=1e-12)  # symmetric
    assert all(a["agrees"] for a in agreement.values())


def test_free_standing_wall_rocks_two_sided_with_lambda_b_over_h() -> None:
    scene = read_scene(REPO / "examples" / "scenes" / "rect_wall.3dm")
    spec = {"walls": [{"id": "W", "object": "wall", "density": 1800.0}]}
    res, agreement = _built(scene, spec)
    full = [c for c in res.candidates if c.family == "overturning"]
    assert len(full) == 1 and full[0].rocking == "two_sided"
    assert full[0].lam0 == pytest.approx(0.5 / 3.0, rel=1e-12)
    assert any("rocks two-sided" in n for n in res.notes)
    assert all(a["agrees"] for a in agreement.values())


def test_openings_drawn_as_solids_are_cut_and_the_spec_reopens_only_the_search_scene(
    tmp_path: Path,
) -> None:
    plain = wedge_facade(tmp_path, name="solids")
    import rhino3dm

    b = BUILD.Builder("solids")
    b.model = rhino3dm.File3dm.Read(str(plain))
    b.box("window", "Openings", (-0.1, 1.5, 1.0), (0.6, 2.7, 3.0), "")
    scene_path = b.write(tmp_path / "solids_open.3dm")
    windows = wedge_facade(tmp_path, windows=[(1.5, 2.7, 1.0, 3.0)], name="voids")
    spec = {**wedge_spec("poor", None), "openings": [{"layer": "Openings"}]}
    run = search_run(read_scene(scene_path), SearchSpec.model_validate(spec))
    voids = search_run(read_scene(windows), SearchSpec.model_validate(wedge_spec("poor", None)))
    # the same mechanisms as the wall drawn with the void
    assert [c.lam0 for c in run.result.candidates] == pytest.approx(
        [c.lam0 for c in voids.result.candidates], rel=1e-12
    )
    assert any("(openings cut)" in n for n in run.doc.to_dict()["notes"])
    out = tmp_path / "out"
    out.mkdir()
    write_search_files(run, out, figure=False)
    again = constants_from_scene_files(out / "search.3dm", out / "search.spec.json")
    for m1, m2 in zip(run.constants.mechanisms, again.mechanisms):
        assert m2.positive.p_eq == pytest.approx(m1.positive.p_eq, rel=1e-12)
    with pytest.raises(InputError, match=r"no object with name 'facade \(openings cut\)'"):
        constants_from_scene_files(scene_path, out / "search.spec.json")


def test_scan_mesh_is_idealised_and_the_difference_is_reported() -> None:
    scene = read_scene(REPO / "examples" / "scenes" / "scan_wall.ply", units="mm")
    spec = {"walls": [{"id": "W", "object": "scan_wall", "density": 2000.0}]}
    res, agreement = _built(scene, spec)
    assert any("not a prism of constant thickness" in n for n in res.notes)
    (_full,) = [c for c in res.candidates if c.family == "overturning"]
    a = agreement["S01"]
    assert a["mass_rel"] < 1e-9  # the idealised thickness keeps the mass
    assert 0.0 < a["lam0_rel"] < 0.05 and not a["agrees"]  # the relief moves the centre


def test_a_wall_with_a_pocket_is_idealised_with_a_note() -> None:
    scene = read_scene(REPO / "examples" / "scenes" / "facade.3dm")
    spec = {
        "walls": [
            {"id": "F", "object": "facade", "density": 1800.0},
            {"id": "L", "object": "side_wall_left", "density": 1800.0, "facade": False},
            {"id": "R", "object": "side_wall_right", "density": 1800.0, "facade": False},
        ],
        "default_junction": {"connection": "poor"},
        "directions": ["outward"],
        "families": ["overturning"],
    }
    res = run_search(scene, SearchSpec.model_validate(spec), lp=False)
    assert any(n.startswith("F: not a prism") for n in res.notes)
    assert res.building.walls["F"].exact is False


def test_sliding_is_flagged_where_friction_cannot_hold_the_rocking_multiplier(
    tmp_path: Path,
) -> None:
    b = BUILD.Builder("squat")
    b.box("wall", "Walls", (0.0, 0.0, 0.0), (2.0, 1.0, 1.5), "stone")
    path = b.write(tmp_path / "squat.3dm")
    spec = {"walls": [{"id": "W", "object": "wall", "density": 2600.0}], "friction": 0.6}
    run = search_run(read_scene(path), SearchSpec.model_validate(spec))
    cand = run.doc.to_dict()["candidates"][0]
    # 2 m long and 1 m thick: it rocks across its thickness, λ0 = 1/1.5 > μ
    assert cand["lam0"] == pytest.approx(1.0 / 1.5, rel=1e-12)
    assert cand["sliding"]["required"] == pytest.approx(1.0 / 1.5, rel=1e-12)
    assert any("sliding governs" in n for n in cand["notes"])
    (check,) = run.doc.to_dict()["lp"]
    assert check["sliding_governs"] and check["lam_friction"] < 0.6 * 1.01
    assert "sliding governs this façade" in check["sliding_note"]
    json.dumps(run.doc.to_dict()["lp"])  # JSON-ready
