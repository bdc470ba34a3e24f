"""The palazzo of the speed benchmark (issue #37) is read as it is drawn.

``examples/scenes/build_scenes.py`` writes the block (``palazzo``) and its spec
(``palazzo_spec``) that ``benchmarks/search_speed.py`` times: an outer ring of 4 walls, a
courtyard ring of 4 and 22 cross walls, 4 storeys, 40 windows, a floor in every room at each
storey and a roof. The references below are the drawing's own facts, written out: which way
each wall's outer face looks, which faces are on the courtyard, which walls hold which.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from search_scenes import BUILD, write_spec

import rockmech

#: The drawing: the outer ring's walls face away from the block, the courtyard's towards it.
OUTWARD = {
    "O0": (0.0, -1.0),  # the south front
    "O1": (1.0, 0.0),
    "O2": (0.0, 1.0),
    "O3": (-1.0, 0.0),
    "CW": (1.0, 0.0),  # the courtyard's west wall, east into the courtyard
    "CE": (-1.0, 0.0),
}
#: Plan centre of the block [m] (32 x 24 m).
CENTRE = (16.0, 12.0)


def _search(tmp_path: Path) -> dict[str, Any]:
    scene = BUILD.palazzo(tmp_path)
    spec = BUILD.palazzo_spec()
    # the reading is the point here: two families, no global check, few mechanisms built
    spec.update(families=["overturning", "wedge_overturning"], lp=False, candidates={"keep": 2})
    spec["ranking"] = {"n_frequencies": 2, "keep": 1}
    return rockmech.search(scene, write_spec(tmp_path / "palazzo.json", spec)).doc.to_dict()


def test_the_palazzo_is_read_as_drawn(tmp_path: Path) -> None:
    doc = _search(tmp_path)
    walls = doc["input"]["walls"]
    assert len(walls) == 30
    assert sum(w["openings"] for w in walls.values()) == 40
    assert {k: walls[k]["openings"] for k in ("O0", "O2", "CW")} == {"O0": 12, "O2": 8, "CW": 2}
    assert all(w["exact_prism"] for w in walls.values())
    assert doc["warnings"] == []
    notes = doc["notes"]
    yard = {
        n.split(":")[0]
        for n in notes
        if n.endswith("its outer face is on a courtyard of its building")
    }
    assert yard == {"CS", "CN", "CW", "CE"}
    # the courtyard's south and north walls run through its corners: its west and east
    # walls stand on their courtyard faces, so they are not moved outward
    for held in ("CS", "CN"):
        for holder in ("CW", "CE"):
            assert any(
                n.startswith(f"{held}: {holder} stands against its outer face") for n in notes
            )
    inner = {n.split(":")[0] for n in notes if "(an inner wall)" in n}
    assert inner == {f"X{k}" for k in range(22)}
    first = {}
    for c in doc["candidates"]:
        first.setdefault(c["facade"], c)
    assert not {"CS", "CN"} & set(first)
    for wid, d in OUTWARD.items():
        assert np.allclose(first[wid]["direction_vector"], [*d, 0.0], atol=1e-12), wid
    # a cross wall (both faces inside) turns its inner side to the block's centre
    plan = {w[0]: w for w in BUILD.palazzo_walls()}
    for k in range(22):
        wid, a, b, t = plan[f"X{k}"]
        a, b = np.asarray(a), np.asarray(b)
        e_s = (b - a) / np.linalg.norm(b - a)
        middle = (a + b) / 2.0 + (t / 2.0) * np.array([-e_s[1], e_s[0]])
        away = middle - np.asarray(CENTRE)
        # the cross walls run along x or y: outward is the axis across them, away from the centre
        axis = np.abs(np.array([e_s[1], e_s[0]]))
        got = np.asarray(first[wid]["direction_vector"][:2])
        if abs(away @ axis) < 1e-9:
            # the middle cross walls of the long wings stand on the centre line: the stated
            # rule names their sides (inner side towards +x, else +y: outward is -x or -y)
            assert wid in ("X10", "X15")
            assert np.allclose(got, -axis, atol=1e-12), wid
            assert any(
                n.startswith(f"{wid}: an inner wall on its building's centre line") for n in notes
            )
            continue
        assert np.allclose(got, np.sign(away @ axis) * axis, atol=1e-12), wid


def test_the_palazzo_has_a_level_per_room_and_storey() -> None:
    rooms = BUILD.palazzo_rooms()
    spec = BUILD.palazzo_spec()
    assert len(rooms) == 22
    assert len(spec["levels"]) == 3 * 22 + 1
    # the rooms and the walls' footprints tile the block less the courtyard (32 x 24 - 18 x 10)
    walls_area = sum(
        float(np.linalg.norm(np.asarray(b) - np.asarray(a))) * t
        for _, a, b, t in BUILD.palazzo_walls()
    )
    rooms_area = sum((x1 - x0) * (y1 - y0) for x0, x1, y0, y1 in rooms)
    assert walls_area + rooms_area == pytest.approx(32.0 * 24.0 - 18.0 * 10.0, rel=1e-12)
