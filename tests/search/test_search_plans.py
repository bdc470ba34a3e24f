"""A gallery of plans (issue #37): each wall's outer face from the plan's topology.

Every plan is drawn as rings of outer-face corners (``search_scenes.ring_walls``: material
on the left of each edge) and searched through ``rockmech.search`` as drawn,
turned by odd angles about the vertical, moved to georeferenced coordinates and mirrored.
The references are written here, from the rings the test draws: a wall's outward normal is
the right-hand normal of its edge; a wall at a right turn of its ring (a re-entrant corner)
has the next wall standing on its outer face and cannot move outward; with poor junctions
every other wall overturns alone, λ0 = t / h (its weight's lever t/2 over the load's h/2);
with good ones, the wedge of the return wall is the polygon virtual work written below.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from search_scenes import plan_scene, plan_spec, ring_walls, write_spec

import rockmech

T, H = 0.5, 6.0
PLANS: dict[str, list[list[tuple[float, float]]]] = {
    "L_narrow": [[(0, 0), (10, 0), (10, 4), (4, 4), (4, 10), (0, 10)]],
    "L_wide": [[(0, 0), (10, 0), (10, 7), (7, 7), (7, 10), (0, 10)]],
    "T": [[(0, 0), (12, 0), (12, 4), (8, 4), (8, 10), (4, 10), (4, 4), (0, 4)]],
    "U": [[(0, 0), (12, 0), (12, 10), (8, 10), (8, 4), (4, 4), (4, 10), (0, 10)]],
    "two_buildings": [[(0, 0), (6, 0), (6, 5), (0, 5)], [(8, 0), (14, 0), (14, 5), (8, 5)]],
}
#: (angle [deg], shift [m], mirrored): as drawn, turned by odd angles, far away, mirrored.
PLACES = [
    (0.0, (0.0, 0.0), False),
    (37.0, (4.0e5, 7.0e5), False),
    (-123.4, (-3.5e5, 7.0e5), False),
    (0.0, (0.0, 0.0), True),
]


def _left_turn(p: Any, q: Any, r: Any) -> bool:
    p, q, r = (np.asarray(v, dtype=float) for v in (p, q, r))
    return float((q - p)[0] * (r - q)[1] - (q - p)[1] * (r - q)[0]) > 0.0


def _reference(rings: list[list[tuple[float, float]]]) -> tuple[dict[str, Any], dict[str, str]]:
    """Each wall's outward unit normal in plan, and the held walls with the wall holding them."""
    normals: dict[str, Any] = {}
    held: dict[str, str] = {}
    for k, ring in enumerate(rings):
        n = len(ring)
        for i in range(n):
            a, b = np.asarray(ring[i], dtype=float), np.asarray(ring[(i + 1) % n], dtype=float)
            d = (b - a) / float(np.linalg.norm(b - a))
            normals[f"R{k}W{i}"] = np.array([d[1], -d[0]])
            if not _left_turn(a, b, ring[(i + 2) % n]):
                held[f"R{k}W{i}"] = f"R{k}W{(i + 1) % n}"
    return normals, held


def _place(vec: Any, angle: float, mirror: bool) -> Any:
    v = np.array([-vec[0], vec[1]]) if mirror else np.asarray(vec, dtype=float)
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _walls(rings: list[list[tuple[float, float]]]) -> list[tuple[str, Any, Any, float]]:
    return [w for k, ring in enumerate(rings) for w in ring_walls(ring, T, f"R{k}W")]


def _search(tmp_path: Path, name: str, walls: Any, place: Any, **spec: Any) -> dict[str, Any]:
    angle, shift, mirror = place
    tag = f"{name}_{abs(int(angle))}_{int(mirror)}"
    scene = plan_scene(
        tmp_path, walls, spec.pop("h", H), rotate_deg=angle, shift=shift, mirror=mirror, name=tag
    )
    doc = plan_spec([w[0] for w in walls], **spec)
    return rockmech.search(scene, write_spec(tmp_path / f"{tag}.json", doc)).doc.to_dict()


@pytest.mark.parametrize("place", PLACES, ids=["drawn", "37deg_far", "-123deg_far", "mirrored"])
@pytest.mark.parametrize("name", sorted(PLANS))
def test_every_wall_of_a_plan_overturns_away_from_its_building(
    tmp_path: Path, name: str, place: tuple[float, tuple[float, float], bool]
) -> None:
    rings = PLANS[name]
    walls = _walls(rings)
    normals, held = _reference(rings)
    doc = _search(tmp_path, name, walls, place)
    whole = {
        c["facade"]: c
        for c in doc["candidates"]
        if c["family"] == "overturning" and c["parameters"]["hinge_height_m"] == 0.0
    }
    for wid, _, _, _ in walls:
        if wid in held:
            assert wid not in whole and not [c for c in doc["candidates"] if c["facade"] == wid]
            (note,) = [
                n for n in doc["notes"] if n.startswith(f"{wid}: {held[wid]} stands against")
            ]
            assert "cannot move outward" in note
            continue
        c = whole[wid]
        assert c["lam0"] == pytest.approx(T / H, rel=1e-9, abs=0.0)
        assert np.allclose(c["direction_vector"][:2], _place(normals[wid], place[0], place[2]))
        assert abs(c["direction_vector"][2]) < 1e-12
    # no corner of the re-entrant kind, nothing inside out: one candidate per free wall
    assert len(doc["candidates"]) == len(walls) - len(held)
    # the LP check of every façade holds the catalogue's best: its bound, nothing missed
    assert sorted(x["facade"] for x in doc["lp"]) == sorted(whole)
    for x in doc["lp"]:
        assert x["status"] == "optimal" and x["missed"] is False, x["facade"]
        assert x["lam"] == pytest.approx(T / H, rel=1e-9), x["facade"]
    if len(rings) > 1:
        assert any("2 separate buildings" in n for n in doc["notes"])
    else:
        assert not any("separate buildings" in n for n in doc["notes"])


def _wedge_lam0(t: float, length: float, h: float, t_r: float, beta: float) -> float:
    """λ0 of a façade (t × length × h) turning about its outer base edge with the triangular
    wedge of a return wall (thickness t_r along the façade) cut at β from the vertical from
    the junction's foot: virtual work of weights (lever n) against the load (lever z)."""
    m_f = t * length * h
    w = h * math.tan(beta)
    m_w = t_r * h * w / 2.0
    return (m_f * t / 2.0 + m_w * (t + w / 3.0)) / (m_f * h / 2.0 + m_w * 2.0 * h / 3.0)


@pytest.mark.parametrize("place", PLACES[:3], ids=["drawn", "37deg_far", "-123deg_far"])
def test_the_re_entrant_wing_of_an_l_takes_its_one_wedge(
    tmp_path: Path, place: tuple[float, tuple[float, float], bool]
) -> None:
    """Issue #37: the narrow L's re-entrant walls were turned inside out (λ0 21-39 % high).

    R0W3 (outer face x = 4 from y = 4 to 10) stands on R0W2's outer face at the re-entrant
    corner and has a return wall only at its far end (R0W4, 3.5 m into the building): its
    least outward mechanism is the overturning with that one wedge, at the bond angle.
    """
    h = 3.0
    rings = PLANS["L_narrow"]
    walls = _walls(rings)
    doc = _search(tmp_path, "Lgood", walls, place, connection="good", h=h)
    (c,) = [
        c for c in doc["candidates"] if c["facade"] == "R0W3" and c["family"] == "wedge_overturning"
    ]
    beta_bond = math.atan(0.25 / (2 * 0.12))
    beta_hi = math.atan(3.5 / h)
    betas = np.linspace(beta_bond, beta_hi, 20001)
    ref = min(_wedge_lam0(T, 6.0, h, T, b) for b in betas)
    assert c["lam0"] == pytest.approx(ref, rel=1e-7)
    (beta,) = [v for k, v in c["parameters"].items() if k.endswith("_rad")]
    assert beta == pytest.approx(beta_bond, abs=1e-6)  # the least at the bond's bound
    assert not [x for x in doc["candidates"] if x["facade"] == "R0W2"]  # held by R0W3
    assert not [x for x in doc["candidates"] if x["family"] == "corner"]  # not asked


def test_a_courtyard_block_faces_its_courtyard(tmp_path: Path) -> None:
    """The walls round a courtyard face it; a floor over the rooms tells rooms from courtyard.

    The courtyard's ring turns right at each corner (material outside it): each of its walls
    runs on past the corner and the next stands on its courtyard face, which holds it. The
    outer walls overturn outward alone (the floor's small share on their tops).
    """
    outer = [(0.0, 0.0), (14.0, 0.0), (14.0, 12.0), (0.0, 12.0)]
    yard = [(4.0, 4.0), (4.0, 8.0), (10.0, 8.0), (10.0, 4.0)]  # clockwise: material outside
    walls = ring_walls(outer, T, "O") + ring_walls(yard, T, "C")
    slab = ("floor", outer, [yard], H, H + 0.2)
    share = 0.01 * 600.0 * 0.2 * (14.0 * 12.0 - 6.0 * 4.0)  # tributary x the floor's mass [kg]
    for angle, shift, _ in PLACES[:3]:
        tag = f"yard_{abs(int(angle))}"
        scene = plan_scene(
            tmp_path, walls, H, rotate_deg=angle, shift=shift, slabs=[slab], name=tag
        )
        spec = plan_spec([w[0] for w in walls], levels=["floor"])
        spec["levels"][0]["tributary"] = 0.01
        doc = rockmech.search(scene, write_spec(tmp_path / f"{tag}.json", spec)).doc.to_dict()
        notes = doc["notes"]
        by_wall = {c["facade"]: c for c in doc["candidates"]}
        for k, (wid, a, b, _) in enumerate(walls):
            if wid.startswith("C"):
                assert f"{wid}: its outer face is on a courtyard of its building" in notes
                holder = walls[4 + (k - 4 + 1) % 4][0]
                assert any(
                    n.startswith(f"{wid}: {holder} stands against its outer face") for n in notes
                )
                assert wid not in by_wall
                continue
            c = by_wall[wid]
            d = (np.asarray(b) - np.asarray(a)) / float(np.linalg.norm(np.asarray(b) - a))
            assert np.allclose(
                c["direction_vector"][:2], _place(np.array([d[1], -d[0]]), angle, False)
            )
            length = float(np.linalg.norm(np.asarray(b) - a))
            m = 1800.0 * T * length * H
            # the floor bears on the wall's whole top: its share acts at n = t/2, z = H
            ref = (m + share) * (T / 2.0) / (m * H / 2.0 + share * H)
            assert c["lam0"] == pytest.approx(ref, rel=1e-9)
        assert not any("separate buildings" in n for n in notes)


def _wedge_box_scene(tmp_path: Path, gap: float, name: str, middle: bool = False) -> Path:
    """``wedge_facade`` drawn as boxes, its return walls ``gap`` off the façade's inner face
    (negative: running into it); ``middle`` adds a cross wall through the façade's middle."""
    from search_scenes import BUILD

    b = BUILD.Builder(name)
    b.box("facade", "Walls", (0.0, 0.0, 0.0), (0.5, 8.0, 9.0), "brick")
    b.box("left", "Walls", (0.5 + gap, 0.0, 0.0), (12.5 + gap, 0.5, 9.0), "brick")
    b.box("right", "Walls", (0.5 + gap, 7.5, 0.0), (12.5 + gap, 8.0, 9.0), "brick")
    if middle:
        b.box("cross", "Walls", (-1.0, 3.75, 0.0), (12.5, 4.25, 9.0), "brick")
    return b.write(tmp_path / f"{name}.3dm")


def _wedge_doc(tmp_path: Path, scene: Path, **spec: Any) -> dict[str, Any]:
    from search_scenes import wedge_spec

    doc = wedge_spec("good", families=["overturning", "wedge_overturning"], **spec)
    return rockmech.search(scene, write_spec(tmp_path / "s.json", doc)).doc.to_dict()


def test_walls_drawn_a_little_apart_or_into_each_other_meet_and_the_notes_say_so(
    tmp_path: Path,
) -> None:
    """Issue #37: return walls 2 mm short, or 10 cm into the façade, lost their junctions."""
    touching = _wedge_doc(tmp_path, _wedge_box_scene(tmp_path, 0.0, "touch"))
    best = touching["candidates"][0]
    assert best["family"] == "wedge_overturning"
    short = _wedge_doc(tmp_path, _wedge_box_scene(tmp_path, 0.002, "short"))
    assert short["candidates"][0]["family"] == "wedge_overturning"
    # the wedge starts 2 mm further in: λ0 within a part in 1e4 of the touching walls'
    assert short["candidates"][0]["lam0"] == pytest.approx(best["lam0"], rel=1e-3)
    for wall in ("L", "R"):
        assert f"{wall} and F are drawn 2 mm apart: read as meeting" in " ".join(short["notes"])
    into = _wedge_doc(tmp_path, _wedge_box_scene(tmp_path, -0.1, "into"))
    assert into["candidates"][0]["lam0"] == pytest.approx(best["lam0"], rel=1e-12)
    for wall in ("L", "R"):
        (note,) = [n for n in into["notes"] if n.startswith(f"{wall} runs 0.100 m into F")]
        assert "(0.45 m³ shared)" in note  # 0.1 x 0.5 x 9 m
    # beyond the joining gap (a tenth of 0.5 m) the walls are apart, and the notes say so
    apart = _wedge_doc(tmp_path, _wedge_box_scene(tmp_path, 0.06, "apart"))
    assert any("3 separate buildings" in n for n in apart["notes"])
    assert apart["candidates"][0]["lam0"] == pytest.approx(0.5 / 9.0, rel=1e-12)


def test_walls_overlapping_in_their_middles_are_refused_with_the_volume(tmp_path: Path) -> None:
    scene = _wedge_box_scene(tmp_path, 0.0, "cross", middle=True)
    spec = {"walls": [{"id": "X", "object": "cross", "density": 1800.0, "facade": False}]}
    with pytest.raises(rockmech.GeometryError) as err:
        _wedge_doc(tmp_path, scene, **{"walls": _wedge_walls() + spec["walls"]})
    assert "the walls F and X overlap by 2.25 m³" in str(err.value)  # 0.5 x 0.5 x 9 m


def _wedge_walls() -> list[dict[str, Any]]:
    from search_scenes import wedge_spec

    return list(wedge_spec()["walls"])


#: A trapezoid plan: outer corners (0, 0) 100°, (10, 0) 90°, (10, Y) 90°, (X3, Y) 80°; the
#: walls W0 (along y = 0), W1 (x = 10), W2 (y = Y) and W3 (the oblique one) of three
#: thicknesses. W1 butts between W0's and W2's inner faces (square corners); W0 and W2 run
#: to W3's outer face, their ends cut along it; W3 butts between their inner faces, its
#: ends cut along them: a parallelogram in plan, an exact prism of thickness t3.
ANGLE = math.radians(100.0)
Y, X3 = 8.0 * math.sin(ANGLE), 8.0 * math.cos(ANGLE)
THICK = {"W0": 0.4, "W1": 0.5, "W2": 0.6, "W3": 0.5}


def _trapezoid() -> dict[str, list[tuple[float, float]]]:
    cot, sin = 1.0 / math.tan(ANGLE), math.sin(ANGLE)
    t0, t1, t2, t3 = (THICK[w] for w in ("W0", "W1", "W2", "W3"))
    y1, y2 = t0, Y - t2
    return {
        "W0": [(0.0, 0.0), (10.0, 0.0), (10.0, t0), (t0 * cot, t0)],
        "W1": [(10.0 - t1, y1), (10.0, y1), (10.0, y2), (10.0 - t1, y2)],
        "W2": [(10.0, y2), (10.0, Y), (X3, Y), (y2 * cot, y2)],
        "W3": [
            (y1 * cot, y1),
            (y1 * cot + t3 / sin, y1),
            (y2 * cot + t3 / sin, y2),
            (y2 * cot, y2),
        ],
    }


def _centroid_depth(ring: list[tuple[float, float]], normal: Any, point: Any) -> float:
    """Depth of a polygon's centroid behind the line through ``point`` with outward
    ``normal`` (shoelace moments) [m]."""
    p = np.asarray(ring, dtype=float)
    x, y = p[:, 0], p[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2.0
    c = np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6.0 * area)
    return float(-(c - np.asarray(point)) @ np.asarray(normal))


@pytest.mark.parametrize("place", PLACES, ids=["drawn", "37deg_far", "-123deg_far", "mirrored"])
def test_a_trapezoid_plan_with_a_100_degree_corner_and_three_thicknesses(
    tmp_path: Path, place: tuple[float, tuple[float, float], bool]
) -> None:
    """Each wall overturns away from the plan about its outer base edge; the oblique corners
    are said to be searched without their junction. References: λ0 = 2 d / h with d the
    depth of the footprint's centroid behind the outer face (polygon moments written here):
    t/h for the rectangle W1 and the parallelogram W3, the trapezoids W0 and W2 by their
    moments (the builder, on the real solid); the search idealises them keeping their mass
    and the lesser lever of their weight about the base's edges, λ0 = 2 min(d, t - d) / h:
    exact where the centroid lies nearer the outer face, below the solid's otherwise)."""
    h = 6.0
    quads = _trapezoid()
    outward = {
        "W0": (np.array([0.0, -1.0]), (0.0, 0.0)),
        "W1": (np.array([1.0, 0.0]), (10.0, 0.0)),
        "W2": (np.array([0.0, 1.0]), (10.0, Y)),
        "W3": (np.array([-math.sin(ANGLE), math.cos(ANGLE)]), (0.0, 0.0)),
    }
    angle, shift, mirror = place
    tag = f"trap_{abs(int(angle))}_{int(mirror)}"
    scene = plan_scene(
        tmp_path, [], h, rotate_deg=angle, shift=shift, mirror=mirror, name=tag,
        footprints=sorted(quads.items()),
    )  # fmt: skip
    doc = rockmech.search(
        scene, write_spec(tmp_path / f"{tag}.json", plan_spec(sorted(quads)))
    ).doc.to_dict()
    by_wall = {c["facade"]: c for c in doc["candidates"] if c["family"] == "overturning"}
    assert sorted(by_wall) == sorted(quads)
    for wid, (normal, point) in outward.items():
        c = by_wall[wid]
        depth = _centroid_depth(quads[wid], normal, point)
        ref = 2.0 * depth / h
        assert np.allclose(c["direction_vector"][:2], _place(normal, angle, mirror), atol=1e-9)
        assert c["builder"]["lam0"] == pytest.approx(ref, rel=1e-9, abs=0.0), wid
        if wid in ("W1", "W3"):
            assert ref == pytest.approx(THICK[wid] / h, rel=1e-12)
            assert c["lam0"] == pytest.approx(ref, rel=1e-9, abs=0.0), wid
            assert c["builder"]["agrees"] is True, wid
            assert doc["input"]["walls"][wid]["exact_prism"] is True
        else:  # an oblique end: idealised with the lesser lever of its weight, said so
            lever = min(depth, THICK[wid] - depth)
            assert c["lam0"] == pytest.approx(2.0 * lever / h, rel=1e-9, abs=0.0), wid
            assert c["lam0"] <= ref * (1.0 + 1e-9)  # never above the solid's (to rounding)
            (note,) = [n for n in doc["notes"] if n.startswith(f"{wid}: not a prism")]
            assert "twice the lesser lever of its weight about its base's edges" in note
    for a in ("W0", "W2"):
        (note,) = [n for n in doc["notes"] if n.startswith(f"{a} and W3 meet at")]
        assert note.startswith(f"{a} and W3 meet at 100.0° / 80.0° (not square)")
        assert "each is searched free at that corner" in note
    assert not [n for n in doc["notes"] if "W1 and" in n and "meet at" in n]


def test_a_listed_junction_at_an_oblique_corner_is_refused_with_the_angle(tmp_path: Path) -> None:
    quads = _trapezoid()
    scene = plan_scene(tmp_path, [], 6.0, footprints=sorted(quads.items()), name="trap_listed")
    spec = plan_spec(sorted(quads), connection="good")
    spec["junctions"] = [
        {"walls": ["W3", "W0"], "connection": "good", "unit": {"length": 0.25, "height": 0.12}}
    ]
    with pytest.raises(rockmech.InputError) as err:
        rockmech.search(scene, write_spec(tmp_path / "listed.json", spec))
    assert "the junction ['W0', 'W3'] is listed, but the walls meet at 100.0° / 80.0°" in str(
        err.value
    )
    assert "remove it from junctions" in str(err.value)


def test_mitred_corners_are_said_to_form_no_junction(tmp_path: Path) -> None:
    """A box of four walls mitred at its corners (each wall the trapezoid between the outer
    and inner rings): no junction, and the notes say why and what to draw instead."""
    outer = [(0.0, 0.0), (8.0, 0.0), (8.0, 6.0), (0.0, 6.0)]
    t = 0.5
    inner = [(t, t), (8.0 - t, t), (8.0 - t, 6.0 - t), (t, 6.0 - t)]
    quads = {
        f"M{i}": [outer[i], outer[(i + 1) % 4], inner[(i + 1) % 4], inner[i]] for i in range(4)
    }
    scene = plan_scene(tmp_path, [], 6.0, footprints=sorted(quads.items()), name="mitred")
    doc = rockmech.search(
        scene, write_spec(tmp_path / "mitred.json", plan_spec(sorted(quads), connection="good"))
    ).doc.to_dict()
    assert doc["input"]["junctions"] == []
    for i in range(4):
        a, b = sorted([f"M{i}", f"M{(i + 1) % 4}"])
        assert any(
            n.startswith(f"{a} and {b} touch, but neither's end face stands on the other's face")
            for n in doc["notes"]
        )
    assert {c["family"] for c in doc["candidates"]} == {"overturning"}


def test_a_level_drawn_as_several_slabs_loads_each_wall_with_the_slabs_on_it(
    tmp_path: Path,
) -> None:
    """One floor drawn as two slabs (one per room of a box split by a cross wall): each wall
    carries ``tributary`` of the slabs it touches, not of the whole level (before, the west
    wall carried half of both rooms' floor). Reference: the wall and its share at the top's
    centre line, λ0 = (m + share)(t/2) / (m h/2 + share h); the builder agrees."""
    outer = [(0.0, 0.0), (12.0, 0.0), (12.0, 6.0), (0.0, 6.0)]
    walls = ring_walls(outer, T, "R0W")
    cross = ("X", [(5.75, T), (6.25, T), (6.25, 6.0 - T), (5.75, 6.0 - T)])
    slabs = [
        ("slab1", [(0.0, 0.0), (6.0, 0.0), (6.0, 6.0), (0.0, 6.0)], [], H, H + 0.2),
        ("slab2", [(6.0, 0.0), (12.0, 0.0), (12.0, 6.0), (6.0, 6.0)], [], H, H + 0.2),
    ]
    for angle, shift, mirror in PLACES[:2]:
        tag = f"rooms_{abs(int(angle))}"
        scene = plan_scene(
            tmp_path, walls, H, rotate_deg=angle, shift=shift, mirror=mirror, slabs=slabs,
            footprints=[cross], name=tag,
        )  # fmt: skip
        spec = plan_spec([w[0] for w in walls] + ["X"])
        spec["levels"] = [
            {"id": "floor", "kind": "floor", "objects": ["slab1", "slab2"], "density": 600.0,
             "tributary": 0.5}
        ]  # fmt: skip
        doc = rockmech.search(scene, write_spec(tmp_path / f"{tag}.json", spec)).doc.to_dict()
        by_wall = {c["facade"]: c for c in doc["candidates"] if c["family"] == "overturning"}
        share = 0.5 * 600.0 * 0.2 * 6.0 * 6.0  # half of one room's slab [kg]
        for wid in ("R0W1", "R0W3"):  # the east and west walls: one room's slab each
            (w,) = [x for x in walls if x[0] == wid]
            length = float(np.linalg.norm(np.asarray(w[2]) - np.asarray(w[1])))
            m = 1800.0 * T * length * H
            ref = (m + share) * (T / 2.0) / (m * H / 2.0 + share * H)
            c = by_wall[wid]
            assert [lv["mass_kg"] for lv in c["levels"]] == [pytest.approx(share, rel=1e-9)]
            assert c["lam0"] == pytest.approx(ref, rel=1e-9), wid
            assert c["builder"]["agrees"] is True, wid
