"""Piers, walls out of plumb and solids that are no walls, in the search's wall frame (#37).

A pier's faces do not tell its thickness the way a wall's do (a square's doubled-angle average
vanishes): the search reads it across the shorter side of its footprint, and a square one by
a stated rule. A wall within ``PLUMB_TOL_DEG`` of plumb is idealised as the plumb prism on its
base, with a note; beyond, and for solids that are no slabs (round or polygonal piers, a
sphere, a pyramid), the command refuses with one message naming the wall.

The references are written here: a rigid block of width b (in the direction of motion) and
height h overturning about its base edge has λ0 = b / h (its weight's lever b / 2 over the
load's h / 2); a prism sheared so that its top moves δ along the motion has its centre of mass
δ / 2 further out, λ0 = (b - δ) / h (and (b + δ) / h for a lean against the motion).
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import pytest
from search_scenes import BUILD, cli_refusal, plan_prism, write_spec

import rockmech

H = 4.0
#: (angle [deg], shift [m], mirrored): as drawn, turned by odd angles and moved far (the
#: second 1e6 m from the origin), mirrored.
PLACES = [
    (0.0, (0.0, 0.0), False),
    (37.0, (6.0e5, 8.0e5), False),
    (-123.4, (-3.5e5, 7.0e5), False),
    (0.0, (0.0, 0.0), True),
]
PLACE_IDS = ["drawn", "37deg_1e6m", "-123deg_far", "mirrored"]

Ring = Sequence[tuple[float, float]]


def _prism(outline: Ring, holes: Sequence[Ring], h: float, lean: float = 0.0) -> Any:
    """A closed mesh of a plan polygon (with holes) extruded from z = 0 to h, its section
    moved by ``z * lean`` along x (a prism out of plumb)."""
    return plan_prism(outline, holes, 0.0, h, lean)


def _placement(angle: float, mirror: bool) -> Any:
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return rot @ (np.diag([-1.0, 1.0, 1.0]) if mirror else np.eye(3))


def _scene(out: Path, solids: dict[str, Any], place: Any = PLACES[0], name: str = "piers") -> Path:
    angle, shift, mirror = place
    m = _placement(angle, mirror)
    bld = BUILD.Builder(name)
    for wid, (v, f) in solids.items():
        v = v @ m.T + np.array([shift[0], shift[1], 0.0])
        f = f[:, ::-1] if mirror else f
        bld.mesh(wid, "Walls", np.ascontiguousarray(v), np.ascontiguousarray(f), "brick")
    return bld.write(out / f"{name}.3dm")


def _spec(out: Path, ids: Sequence[str], name: str = "piers") -> Path:
    doc = {
        "walls": [{"id": i, "object": i, "density": 1800.0} for i in ids],
        "families": ["overturning"],
        "directions": ["outward"],
        "ranking": {"n_frequencies": 20, "records": []},
    }
    return write_spec(out / f"{name}.search.json", doc)


def _rect(x0: float, y0: float, bx: float, by: float) -> list[tuple[float, float]]:
    return [(x0, y0), (x0 + bx, y0), (x0 + bx, y0 + by), (x0, y0 + by)]


def _whole(doc: dict[str, Any]) -> dict[str, Any]:
    """Each wall's whole-height overturning candidate."""
    return {
        c["facade"]: c
        for c in doc["candidates"]
        if c["family"] == "overturning" and c["parameters"]["hinge_height_m"] == 0.0
    }


def _refused(tmp_path: Path, solids: dict[str, Any]) -> str:
    """Run the command on a scene it must refuse; return its error line."""
    scene = _scene(tmp_path, solids)
    spec = _spec(tmp_path, list(solids))
    return cli_refusal(scene, spec, tmp_path)


# --- piers ----------------------------------------------------------------------------------


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
def test_a_square_pier_overturns_about_a_base_edge(
    tmp_path: Path, place: tuple[float, tuple[float, float], bool]
) -> None:
    """1 m x 1 m x 4 m: λ0 = b / h = 0.25 wherever it is drawn, never read at 45 degrees."""
    b = 1.0
    scene = _scene(tmp_path, {"P": _prism(_rect(0.0, 0.0, b, b), [], H)}, place)
    doc = rockmech.search(scene, _spec(tmp_path, ["P"])).doc.to_dict()
    (c,) = doc["candidates"]
    assert c["lam0"] == pytest.approx(b / H, rel=1e-9, abs=0.0)
    # the motion is across one of the pier's sides, as placed
    m = _placement(place[0], place[2])
    sides = [m @ np.array([1.0, 0.0, 0.0]), m @ np.array([0.0, 1.0, 0.0])]
    assert max(abs(float(np.dot(c["direction_vector"], u))) for u in sides) == pytest.approx(1.0)
    assert c["builder"]["lam0"] == pytest.approx(b / H, rel=1e-9, abs=0.0)
    assert c["mass_kg"] == pytest.approx(1800.0 * b * b * H, rel=1e-9)
    (note,) = [n for n in doc["notes"] if n.startswith("P: a square pier")]
    assert "1.000 x 1.000 m in plan" in note and "fixed rule" in note
    assert not any("not a prism" in n for n in doc["notes"])


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
def test_a_near_square_pier_is_read_across_its_shorter_side(
    tmp_path: Path, place: tuple[float, tuple[float, float], bool]
) -> None:
    """0.8 m x 1.0 m (a ratio 1.25, below 1.5): λ0 = 0.8 / h, the motion along the 0.8 m side."""
    bx, by = 1.0, 0.8
    scene = _scene(tmp_path, {"P": _prism(_rect(2.0, -1.0, bx, by), [], H)}, place)
    doc = rockmech.search(scene, _spec(tmp_path, ["P"])).doc.to_dict()
    (c,) = doc["candidates"]
    assert c["lam0"] == pytest.approx(by / H, rel=1e-9, abs=0.0)
    across = _placement(place[0], place[2]) @ np.array([0.0, 1.0, 0.0])
    assert abs(float(np.dot(c["direction_vector"], across))) == pytest.approx(1.0, abs=1e-9)
    (note,) = [n for n in doc["notes"] if n.startswith("P: a pier")]
    assert "1.000 x 0.800 m in plan" in note and "1.25 times as large" in note


@pytest.mark.parametrize("place", PLACES, ids=PLACE_IDS)
def test_a_row_of_piers_each_overturns_across_its_thickness(
    tmp_path: Path, place: tuple[float, tuple[float, float], bool]
) -> None:
    """Three 0.6 m x 1.2 m x 4 m piers 3 m apart, no junctions: each λ0 = 0.6 / 4 = 0.15."""
    b, d, gap = 0.6, 1.2, 3.0
    solids = {f"P{k}": _prism(_rect(k * (b + gap), 0.0, b, d), [], H) for k in range(3)}
    doc = rockmech.search(_scene(tmp_path, solids, place), _spec(tmp_path, solids)).doc.to_dict()
    whole = _whole(doc)
    across = _placement(place[0], place[2]) @ np.array([1.0, 0.0, 0.0])
    for wid in solids:
        c = whole[wid]
        assert c["lam0"] == pytest.approx(b / H, rel=1e-9, abs=0.0)
        assert c["builder"]["lam0"] == pytest.approx(b / H, rel=1e-9, abs=0.0)
        assert abs(float(np.dot(c["direction_vector"], across))) == pytest.approx(1.0, abs=1e-9)
    assert any("3 separate buildings" in n for n in doc["notes"])
    assert not any("pier" in n or "not a prism" in n for n in doc["notes"])


def _polygon(n: int, r: float) -> list[tuple[float, float]]:
    return [
        (r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n)) for k in range(n)
    ]


def _area(ring: Ring) -> float:
    r = np.asarray(ring, dtype=float)
    return 0.5 * abs(
        float(np.dot(r[:, 0], np.roll(r[:, 1], -1)) - np.dot(np.roll(r[:, 0], -1), r[:, 1]))
    )


#: shape -> (outline, holes, height, side of its least rectangle [m]): a regular n-gon of
#: radius r with n a multiple of 4 fits a square of side 2 r cos(pi / n); the L its 4 m box.
NO_SLABS: dict[str, tuple[Ring, list[Ring], float, float]] = {
    "octagon": (_polygon(8, 1.0), [], 5.0, 2.0 * math.cos(math.pi / 8)),
    "round": (_polygon(48, 1.0), [], 5.0, 2.0 * math.cos(math.pi / 48)),
    "hollow_tower": (_polygon(24, 2.6), [_polygon(24, 2.0)], 10.0, 5.2 * math.cos(math.pi / 24)),
    "L_as_one_solid": ([(0, 0), (4, 0), (4, 0.5), (0.5, 0.5), (0.5, 4), (0, 4)], [], 5.0, 4.0),
}


@pytest.mark.parametrize("shape", sorted(NO_SLABS))
def test_a_footprint_without_a_thickness_direction_is_refused(tmp_path: Path, shape: str) -> None:
    """Round, polygonal and hollow footprints, several walls drawn as one: one message."""
    outline, holes, h, side = NO_SLABS[shape]
    line = _refused(tmp_path, {"T": _prism(outline, holes, h)})
    filled = (_area(outline) - sum(_area(r) for r in holes)) / side**2
    assert line.startswith(f"error: T: its footprint at mid-height ({side:.3f} x {side:.3f} m")
    assert f"fills {100 * filled:.0f} % of the least rectangle" in line
    assert "Split it into walls" in line and "mechanism spec" in line


# --- walls out of plumb ---------------------------------------------------------------------

T_W, L_W, H_W = 0.5, 4.0, 6.0


@pytest.mark.parametrize("lean_deg", [3.0, -3.0])
@pytest.mark.parametrize("place", PLACES[:3], ids=PLACE_IDS[:3])
def test_a_wall_out_of_plumb_is_idealised_plumb_with_a_note(
    tmp_path: Path, place: tuple[float, tuple[float, float], bool], lean_deg: float
) -> None:
    """A 0.5 x 4 x 6 m wall sheared 3 degrees across its thickness (its top 0.314 m over).

    The search idealises it as the plumb prism on its base that keeps the lesser lever of
    its weight about the base's edges, λ0 = (t - δ) / h either way (exact when the top
    leans with the motion, on the safe side against it); the builder, on the real solid,
    λ0 = (t -/+ δ) / h for a top leaning with / against the motion.
    """
    tan = math.tan(math.radians(lean_deg))
    delta = H_W * abs(tan)
    solid = _prism(_rect(0.0, 0.0, T_W, L_W), [], H_W, lean=tan)
    scene = _scene(tmp_path, {"W": solid}, place)
    doc = rockmech.search(scene, _spec(tmp_path, ["W"])).doc.to_dict()
    c = _whole(doc)["W"]
    assert c["lam0"] == pytest.approx((T_W - delta) / H_W, rel=1e-8, abs=0.0)
    assert c["mass_kg"] == pytest.approx(1800.0 * T_W * L_W * H_W, rel=1e-9)
    lean_dir = _placement(place[0], place[2]) @ np.array([math.copysign(1.0, tan), 0.0, 0.0])
    with_motion = float(np.dot(c["direction_vector"], lean_dir)) > 0.0
    assert abs(float(np.dot(c["direction_vector"], lean_dir))) == pytest.approx(1.0, abs=1e-9)
    real = (T_W - delta) / H_W if with_motion else (T_W + delta) / H_W
    # the builder's mesh integrals at 1e6 m carry 1e-10 m of rounding on a 0.09 m lever
    assert c["builder"]["lam0"] == pytest.approx(real, rel=1e-8)
    (note,) = [n for n in doc["notes"] if "out of plumb" in n]
    way = "outward" if with_motion else "inward"
    assert note.startswith(f"W: 3.00 degrees out of plumb, its top {delta:.3f} m {way} of its base")
    assert "the builder's constants use the real solid" in note
    assert f"real λ0 is {real / (T_W / H_W):.3g} times a plumb 0.500 m prism's" in note
    assert f"{real / ((T_W - delta) / H_W):.3g} times the idealised one's" in note
    assert f"of the same mass, {T_W - delta:.3f} m thick" in note
    assert not any("not a prism" in n for n in doc["notes"])
    # the global check runs on the idealised prism and holds the catalogue's optimum
    (lp,) = doc["lp"]
    assert lp["status"] == "optimal"
    assert lp["lam"] == pytest.approx((T_W - delta) / H_W, rel=1e-8)


def test_a_wall_leaning_beyond_the_tolerance_is_refused(tmp_path: Path) -> None:
    line = _refused(tmp_path, {"W": _prism(_rect(0.0, 0.0, T_W, L_W), [], H_W, lean=0.105)})
    assert re.match(r"error: W: \d+ % of its side faces lean more than 5 degrees", line), line
    assert f"({math.degrees(math.atan(0.105)):.1f} degrees on average)" in line


# --- solids that are no walls -----------------------------------------------------------------


def _uv_sphere(r: float, n_lat: int, n_lon: int) -> Any:
    verts = [(0.0, 0.0, 2 * r)]
    for i in range(1, n_lat):
        phi = math.pi * i / n_lat
        for j in range(n_lon):
            th = 2 * math.pi * j / n_lon
            verts.append((r * math.sin(phi) * math.cos(th), r * math.sin(phi) * math.sin(th),
                          r + r * math.cos(phi)))  # fmt: skip
    verts.append((0.0, 0.0, 0.0))
    faces = []
    ring = lambda i, j: 1 + (i - 1) * n_lon + j % n_lon  # noqa: E731
    for j in range(n_lon):
        faces.append((0, ring(1, j), ring(1, j + 1)))
        faces.append((len(verts) - 1, ring(n_lat - 1, j + 1), ring(n_lat - 1, j)))
        for i in range(1, n_lat - 1):
            a, b, c, d = ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)
            faces += [(a, b, c), (a, c, d)]
    return np.array(verts), np.array(faces, dtype=np.int64)


def test_a_sphere_or_a_pyramid_selected_as_a_wall_is_refused(tmp_path: Path) -> None:
    pyramid = (
        np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0], [1, 1, 3]], dtype=float),
        np.array([[0, 2, 1], [0, 3, 2], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]),
    )
    for name, solid in (("sphere", _uv_sphere(1.0, 8, 12)), ("pyramid", pyramid)):
        (tmp_path / name).mkdir()
        line = _refused(tmp_path / name, {"S": solid})
        assert line.startswith("error: S: ") and "lean more than 5 degrees" in line, line
        assert "a wall is a slab standing within 5 degrees of plumb" in line
        assert "mechanism spec" in line and "as a level" in line


def test_the_doc_json_of_a_pier_is_the_same_when_turned(tmp_path: Path) -> None:
    """The square pier's whole answer (λ0, mass, ranking) does not depend on where it is."""
    docs = []
    for k, place in enumerate(PLACES):
        out = tmp_path / str(k)
        out.mkdir()
        scene = _scene(out, {"P": _prism(_rect(0.0, 0.0, 1.0, 1.0), [], H)}, place)
        docs.append(rockmech.search(scene, _spec(out, ["P"])).doc.to_dict())
    first = docs[0]["candidates"][0]
    for d in docs[1:]:
        (c,) = d["candidates"]
        for key in ("lam0", "mass_kg", "lam_linearised"):
            assert c[key] == pytest.approx(first[key], rel=1e-9), key
        assert json.dumps(c["parameters"]) == json.dumps(first["parameters"])


@pytest.mark.parametrize("place", PLACES[:2], ids=PLACE_IDS[:2])
def test_a_square_pier_carrying_a_level_moves_away_from_it(
    tmp_path: Path, place: tuple[float, tuple[float, float], bool]
) -> None:
    """A slab on the pier reaching 2 m out along +x: the pier's thickness is taken along x
    (the side facing its level), it overturns along -x, and the builder agrees."""
    b = 1.0
    slab = _prism(_rect(0.0, 0.0, 3.0, b), [], 0.2)
    slab = (slab[0] + np.array([0.0, 0.0, H]), slab[1])
    angle, shift, mirror = place
    m = _placement(angle, mirror)
    bld = BUILD.Builder("pier_slab")
    for wid, (v, f), layer in (("P", _prism(_rect(0.0, 0.0, b, b), [], H), "Walls"),
                               ("S", slab, "Floors")):  # fmt: skip
        v = v @ m.T + np.array([shift[0], shift[1], 0.0])
        bld.mesh(wid, layer, np.ascontiguousarray(v), np.ascontiguousarray(f), "brick")
    scene = bld.write(tmp_path / "pier_slab.3dm")
    doc = {
        "walls": [{"id": "P", "object": "P", "density": 1800.0}],
        "levels": [{"id": "S", "kind": "floor", "objects": ["S"], "density": 2400.0}],
        "families": ["overturning"],
        "directions": ["outward"],
        "ranking": {"n_frequencies": 20, "records": []},
    }
    out = rockmech.search(scene, write_spec(tmp_path / "s.json", doc)).doc.to_dict()
    c = _whole(out)["P"]
    assert np.allclose(c["direction_vector"], m @ np.array([-1.0, 0.0, 0.0]), atol=1e-9)
    assert c["builder"]["agrees"], c["builder"]
    (note,) = [n for n in out["notes"] if n.startswith("P: a square pier")]
    assert "the side that faces the levels it carries" in note
