"""A scene or spec that cannot be read as a building gets one clear message (#37).

Walls floating above the ground, a wall drawn on another wall's top, a level touching no
wall, a selector that matches nothing or a curve: one error line that names the object and
what to change, with the amount, and no traceback. Where the reading is legitimate but
surprising (a wall standing on a level, walls that nearly meet, a lifted scene) the search
runs and a note says how it read it.

Each case is also drawn turned by 37° and moved 4e5 m away, so the tolerances are shown to be
relative to the building, not to the coordinates. The references are written here: a bare
rigid wall of thickness t and height h overturning about its base edge has λ0 = t / h (its
weight's lever t / 2 over the load's h / 2).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Optional, Sequence

import pytest
from search_scenes import BUILD, cli_refusal, plan_scene, plan_spec, write_spec

import rockmech

T, H = 0.5, 4.0
#: (angle [deg], shift [m]): as drawn, and turned by an odd angle and moved far away.
PLACES = [(0.0, (0.0, 0.0)), (37.0, (4.0e5, -4.0e5))]
PLACE_IDS = ["drawn", "37deg_4e5m"]
RANKING = {"n_frequencies": 20, "records": []}

Place = tuple[float, tuple[float, float]]


def _l_walls(gap: float = 0.0) -> list[tuple[str, Any, Any, float]]:
    """A (outer face y = 0, x in [0, 5]) and B (outer face x = 0) abutting A's inner face at
    A's start, B's end ``gap`` [m] short of it."""
    return [("A", (0.0, 0.0), (5.0, 0.0), T), ("B", (0.0, 5.0), (0.0, T + gap), T)]


def _scene(
    out: Path,
    walls: Sequence[tuple[str, Any, Any, float]],
    place: Place,
    heights: Optional[dict[str, tuple[float, float]]] = None,
    slabs: Sequence[Any] = (),
) -> Path:
    return plan_scene(
        out,
        walls,
        H,
        rotate_deg=place[0],
        shift=place[1],
        heights=heights,
        slabs=slabs,
        name="bad",
    )


def _spec(out: Path, ids: Sequence[str], levels: Sequence[str] = (), **extra: Any) -> Path:
    doc = plan_spec(ids, levels=levels, families=["overturning"], ranking=RANKING, **extra)
    return write_spec(out / "bad.search.json", doc)


def _refused(out: Path, scene: Path, spec: Path) -> str:
    """Run the command and the Python entry point on input they must refuse; return the
    CLI's one error line (the Python error carries the same message)."""
    line = cli_refusal(scene, spec, out)
    with pytest.raises(rockmech.RockmechError) as err:
        rockmech.search(scene, spec)
    assert line == f"error: {err.value}"
    return line


def _whole(doc: dict[str, Any], wall: str) -> dict[str, Any]:
    """A wall's whole-height overturning candidate (its lowest hinge line)."""
    cands = [c for c in doc["candidates"] if c["facade"] == wall and c["family"] == "overturning"]
    return min(cands, key=lambda c: c["parameters"]["hinge_height_m"])


# --- the ground ------------------------------------------------------------------------------


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
def test_a_wall_floating_above_the_ground_is_refused_with_its_height(
    tmp_path: Path, place: Place
) -> None:
    scene = _scene(tmp_path, _l_walls(), place, heights={"B": (0.5, H)})
    line = _refused(tmp_path, scene, _spec(tmp_path, ["A", "B"]))
    assert line.startswith("error: walls[1] (B): its base at z = 0.500 m is 0.500 m above the ")
    assert "the lowest wall base (z = 0.000 m)" in line
    assert "stands on no level or wall (nothing of the spec is drawn under it)" in line
    assert "draw B down to the ground" in line


def test_a_wall_floating_above_a_slab_names_the_gap(tmp_path: Path) -> None:
    """B stands 0.3 m above a slab that A carries: the gap to the solid under it is given."""
    slab = ("S", [(0.0, T), (5.0, T), (5.0, 5.0), (0.0, 5.0)], [], H, H + 0.2)
    walls = [*_l_walls(), ("C", (5.0, 5.0), (0.0, 5.0), T)]
    scene = _scene(tmp_path, walls, PLACES[1], heights={"C": (H + 0.5, 2 * H)}, slabs=[slab])
    line = _refused(tmp_path, scene, _spec(tmp_path, ["A", "B", "C"], levels=["S"]))
    assert line.startswith("error: walls[2] (C): its base at z = 4.500 m is 4.500 m above ")
    assert "the nearest solid under it, a level, is 0.300 m below its base" in line


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
def test_a_lifted_scene_reads_its_lowest_base_as_the_ground(tmp_path: Path, place: Place) -> None:
    """All walls from z = 100 m: the same λ0 (t / h) as on z = 0, and every Z 0."""
    lifted = {"A": (100.0, 100.0 + H), "B": (100.0, 100.0 + H)}
    scene = _scene(tmp_path, _l_walls(), place, heights=lifted)
    doc = rockmech.search(scene, _spec(tmp_path, ["A", "B"])).doc.to_dict()
    for wall in ("A", "B"):
        c = _whole(doc, wall)
        assert c["lam0"] == pytest.approx(T / H, rel=1e-9), wall
        assert c["parameters"]["hinge_height_m"] == pytest.approx(100.0, abs=1e-9)
    assert all(c["Z_m"] == 0.0 for c in doc["candidates"])
    assert not any("above the ground" in n for n in doc["notes"])


def test_a_base_a_little_above_the_ground_stands_on_it_with_a_note(tmp_path: Path) -> None:
    """B drawn 20 mm up (within a tenth of its 0.5 m thickness) stands on the ground."""
    scene = _scene(tmp_path, _l_walls(), PLACES[1], heights={"B": (0.02, H)})
    doc = rockmech.search(scene, _spec(tmp_path, ["A", "B"])).doc.to_dict()
    (note,) = [n for n in doc["notes"] if n.startswith("B: its base is")]
    assert "20 mm above the ground" in note and "read as standing on the ground" in note
    assert _whole(doc, "B")["lam0"] == pytest.approx(T / (H - 0.02), rel=1e-9)


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
def test_a_wall_on_a_level_stands_on_it_and_the_level_does_not_load_it(
    tmp_path: Path, place: Place
) -> None:
    """C stands on the slab S on A's top: it rocks about its base on S (λ0 = t / h of its own
    height, S is no load on it), at Z = its base's height, and a note says so."""
    slab = ("S", [(0.0, 0.0), (5.0, 0.0), (5.0, 4.0), (0.0, 4.0)], [], H, H + 0.2)
    walls = [("A", (0.0, 0.0), (5.0, 0.0), T), ("C", (0.0, 0.0), (5.0, 0.0), T)]
    scene = _scene(tmp_path, walls, place, heights={"C": (H + 0.2, 2 * H)}, slabs=[slab])
    run = rockmech.search(scene, _spec(tmp_path, ["A", "C"], levels=["S"]))
    c = _whole(run.doc.to_dict(), "C")
    assert c["lam0"] == pytest.approx(T / (H - 0.2), rel=1e-9)
    assert c["Z_m"] == pytest.approx(H + 0.2, rel=1e-9)
    (note,) = [n for n in run.doc.to_dict()["notes"] if n.startswith("C: stands on")]
    assert note.startswith("C: stands on the level S over 100 % of its footprint; its base at ")
    assert "4.200 m above the ground" in note and "the level is no load on it" in note
    assert "the walls under the level do not carry C's weight" in note


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
def test_a_wall_drawn_on_another_wall_is_refused(tmp_path: Path, place: Place) -> None:
    walls = [("A", (0.0, 0.0), (5.0, 0.0), T), ("C", (0.0, 0.0), (5.0, 0.0), T)]
    scene = _scene(tmp_path, walls, place, heights={"C": (H, 2 * H)})
    line = _refused(tmp_path, scene, _spec(tmp_path, ["A", "C"]))
    assert line.startswith("error: walls[1] (C): stands on A's top (its base at z = 4.000 m")
    assert "join C and A into one solid" in line


def test_a_foundation_under_every_wall_is_not_a_level(tmp_path: Path) -> None:
    slab = ("G", [(-1.0, -1.0), (6.0, -1.0), (6.0, 6.0), (-1.0, 6.0)], [], -0.3, 0.0)
    scene = _scene(tmp_path, _l_walls(), PLACES[1], slabs=[slab])
    line = _refused(tmp_path, scene, _spec(tmp_path, ["A", "B"], levels=["G"]))
    assert line.startswith("error: levels[0] (G): the walls A, B stand on it, and it rests on ")
    assert "remove it from levels" in line


# --- levels ----------------------------------------------------------------------------------


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
@pytest.mark.parametrize(
    ("slab", "said"),
    [
        ((T, 5.0, H + 0.3, H + 0.5), "0.300 m from it (0.300 m above its top)"),
        ((T + 0.3, 5.0, 3.0, 3.2), "0.300 m from it (0.300 m off it in plan)"),
    ],
    ids=["above", "beside"],
)
def test_a_level_touching_no_wall_is_refused_with_the_gap(
    tmp_path: Path, place: Place, slab: tuple[float, float, float, float], said: str
) -> None:
    y0, y1, z0, z1 = slab
    level = ("S", [(0.0, y0), (5.0, y0), (5.0, y1), (0.0, y1)], [], z0, z1)
    scene = _scene(tmp_path, _l_walls()[:1], place, slabs=[level])
    line = _refused(tmp_path, scene, _spec(tmp_path, ["A"], levels=["S"]))
    assert line.startswith("error: levels[0] (S): touches no wall"), line
    assert f"the nearest wall, A, is {said}" in line
    assert "draw it onto the walls that carry it" in line and "remove it from levels" in line


# --- walls that do not touch -----------------------------------------------------------------


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
def test_walls_that_nearly_meet_get_a_note_with_the_gap(tmp_path: Path, place: Place) -> None:
    """B stops 80 mm short of A (the joining gap is 50 mm, a tenth of 0.5 m): read apart."""
    scene = _scene(tmp_path, _l_walls(gap=0.08), place)
    doc = rockmech.search(scene, _spec(tmp_path, ["A", "B"])).doc.to_dict()
    (note,) = [n for n in doc["notes"] if "short of" in n]
    assert re.match(
        r"B's end \(s = [0-9.]+ m\) stops 80 mm short of A, beyond the joining gap ", note
    )
    assert "(50 mm, a tenth of the thinnest wall's thickness)" in note
    assert "read as not meeting, B free-standing at that end" in note
    for wall in ("A", "B"):
        assert _whole(doc, wall)["lam0"] == pytest.approx(T / H, rel=1e-9)


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
def test_walls_within_the_joining_gap_meet_and_walls_far_apart_get_no_note(
    tmp_path: Path, place: Place
) -> None:
    near = tmp_path / "near"
    near.mkdir()
    doc = rockmech.search(
        _scene(near, _l_walls(gap=0.03), place), _spec(near, ["A", "B"])
    ).doc.to_dict()
    assert any(n.startswith("B and A are drawn 30 mm apart: read as meeting") for n in doc["notes"])
    assert not any("short of" in n for n in doc["notes"])
    far = tmp_path / "far"
    far.mkdir()
    doc = rockmech.search(
        _scene(far, _l_walls(gap=0.6), place), _spec(far, ["A", "B"])
    ).doc.to_dict()
    assert not any("short of" in n or "apart" in n for n in doc["notes"])


# --- selectors -------------------------------------------------------------------------------


def _selector_scene(out: Path) -> Path:
    bld = BUILD.Builder("sel")
    bld.box("A", "Walls", (0.0, 0.0, 0.0), (5.0, T, H), "brick")
    bld.line("tie", "Ties", (1.0, -1.0, 2.0), (1.0, 3.0, 2.0))
    return bld.write(out / "sel.3dm")


@pytest.mark.parametrize(
    ("doc", "start"),
    [
        (
            {"walls": [{"id": "A", "object": "nope", "density": 1800.0}]},
            "error: walls[0].object: no object with name 'nope' in sel.3dm; available names: "
            "'A', 'tie'",
        ),
        (
            {"walls": [{"id": "A", "object": "tie", "density": 1800.0}]},
            "error: walls[0].object: 'tie' matches tie (Ties, ",
        ),
        (
            {"walls": [{"id": "A", "object": {"layer": "Ties"}, "density": 1800.0}]},
            "error: walls[0].object: {'layer': 'Ties'} matches tie (Ties, ",
        ),
        (
            {"levels": [{"id": "L", "objects": ["nope"], "density": 600.0, "kind": "floor"}]},
            "error: levels[0].objects: no object with name 'nope' in sel.3dm",
        ),
        (
            {"levels": [{"id": "L", "objects": ["tie"], "density": 600.0, "kind": "floor"}]},
            "error: levels[0].objects: 'tie' matches tie (Ties, ",
        ),
        ({"openings": ["tie"]}, "error: openings[0]: 'tie' matches tie (Ties, "),
        (
            {"tie_bars": [{"object": "A", "force": 1000.0}]},
            "error: tie_bars[0].object: 'A' matches A (Walls, ",
        ),
    ],
    ids=["wall_none", "wall_line", "wall_layer_line", "level_none", "level_line", "opening_line",
         "tie_solid"],
)  # fmt: skip
def test_a_selector_that_matches_nothing_or_no_solid_names_the_field(
    tmp_path: Path, doc: dict[str, Any], start: str
) -> None:
    scene = _selector_scene(tmp_path)
    spec = plan_spec(["A"], ranking=RANKING)
    spec.update(doc)
    line = _refused(tmp_path, scene, write_spec(tmp_path / "sel.search.json", spec))
    assert line.startswith(start), line
    if "matches" in start and "tie_bars" not in start:
        assert line.endswith(
            "a line is not a solid; select a closed mesh, polysurface or extrusion"
        )
    if "tie_bars" in start:
        assert line.endswith("is not a line; draw a Line"), line
