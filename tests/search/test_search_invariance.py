"""The whole search output does not depend on where the building is drawn (issue #37).

The example scene (a three-storey façade with six windows, two return walls with good
junctions, a back wall, two floors, a roof and a tie-bar) is read from its ``.3dm`` file and
written again, with rhino3dm, turned about the vertical by odd angles, moved to
georeferenced coordinates (up to 10⁶ m, the largest accepted), mirrored, and drawn in
millimetres. Each copy goes through ``rockmech.search`` with every family, both
directions, the global LP check, the dynamic ranking and a record. The reference is the
search of the scene as drawn, placed by the transformation the test applies:

* the same candidates (family, wall, direction, parameters), with λ0, the constants, the
  overturning accelerations and the record's scale factor the same to 1e-9;
* hinge axes and directions moved and turned as the scene was, to 1e-9 of the building;
* the same static and dynamic rankings, governing mechanisms and critical bands, the same
  built set and the LP's bound to 1e-9 on as many blocks;
* the same notes (a mirrored file's solids are inside out, which the notes say).

Scaling the scene by 2 (its masonry unit with it, the tie's force by 8) keeps λ0 and the
ranking by λ0 and scales p_eq by 2^-1/2.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from search_scenes import EXAMPLE_SCENE, EXAMPLE_SPEC, REPO

import rockmech

RTOL = 1e-9
#: (turn [deg], shift [m], mirrored, scale, file units)
PLACES = {
    "37deg_far": (37.0, (4.0e5, 7.0e5), False, 1.0, "Meters"),
    "-123deg_1e6m": (-123.4, (9.9e5, -9.9e5), False, 1.0, "Meters"),
    "mirrored": (0.0, (0.0, 0.0), True, 1.0, "Meters"),
    "200deg_mirrored_1e6m": (200.0, (-9.9e5, 9.9e5), True, 1.0, "Meters"),
    "millimetres": (0.0, (0.0, 0.0), False, 1000.0, "Millimeters"),
    "61deg_mirrored_mm": (61.0, (300.0, 200.0), True, 1000.0, "Millimeters"),
}
#: What mirroring a file does to its solids, which the notes rightly say.
INSIDE_OUT = "faced inward (inside out)"


def _place(xyz: Any, angle: float, shift: Any, mirror: bool) -> Any:
    """A point of the scene as drawn, where the transformed scene has it [m]."""
    p = np.array(xyz, dtype=float)
    if mirror:
        p[..., 0] = -p[..., 0]
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    x, y = p[..., 0].copy(), p[..., 1].copy()
    p[..., 0], p[..., 1] = c * x - s * y + shift[0], s * x + c * y + shift[1]
    return p


def _write_placed(
    path: Path, angle: float, shift: Any, mirror: bool, scale: float, units: str
) -> Path:
    """The example scene mirrored in x = 0, turned, moved [m] and drawn in ``units``."""
    import rhino3dm as r3

    src = r3.File3dm.Read(str(EXAMPLE_SCENE))
    out = r3.File3dm()
    out.Settings.ModelUnitSystem = getattr(r3.UnitSystem, units)
    steps = []
    if mirror:
        steps.append(r3.Transform.Mirror(r3.Point3d(0, 0, 0), r3.Vector3d(1, 0, 0)))
    steps.append(
        r3.Transform.Rotation(math.radians(angle), r3.Vector3d(0, 0, 1), r3.Point3d(0, 0, 0))
    )
    steps.append(r3.Transform.Translation(r3.Vector3d(shift[0], shift[1], 0.0)))
    steps.append(r3.Transform.Scale(r3.Point3d(0, 0, 0), scale))
    for layer in src.Layers:
        out.Layers.Add(layer)
    for obj in src.Objects:
        geom = obj.Geometry.Duplicate()
        for step in steps:
            geom.Transform(step)
        out.Objects.Add(geom, obj.Attributes)
    assert out.Write(str(path), 7)
    return path


@pytest.fixture(scope="module")
def spec_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    spec = json.loads(EXAMPLE_SPEC.read_text(encoding="utf-8"))
    rk = spec["ranking"]
    rk.pop("site")
    rk["records"] = [str(REPO / "examples" / "records" / "elcentro_NS.dat")]
    rk["n_frequencies"] = 60
    spec["lp"] = True
    path = tmp_path_factory.mktemp("spec") / "search.json"
    path.write_text(json.dumps(spec), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def drawn(spec_path: Path) -> dict[str, Any]:
    return rockmech.search(EXAMPLE_SCENE, spec_path).doc.to_dict()


def _key(c: dict[str, Any]) -> tuple[Any, ...]:
    params = tuple(sorted((k, round(v, 6)) for k, v in c["parameters"].items()))
    return (c["family"], c["facade"], c["direction"], params)


def _numbers(c: dict[str, Any]) -> dict[str, float]:
    out = {"lam0": c["lam0"], "mass_kg": c["mass_kg"], "Z_m": c["Z_m"]}
    out.update({f"p.{k}": v for k, v in c["parameters"].items()})
    for side in ("positive", "negative"):
        consts = (c.get("constants") or {}).get(side)
        for k in ("p_eq", "lam", "phi_ov", "I0", "K", "Q") if consts else ():
            out[f"{side}.{k}"] = consts[k]
    if c.get("overturning"):
        out.update({f"a_p_min[{k}]": v for k, v in enumerate(c["overturning"]["a_p_min_g"])})
    for r in c.get("records", []):
        if r.get("scale") is not None:
            out[f"record.{r['record']}"] = r["scale"]
    return out


def _close(a: float, b: float, scale: float = 1.0) -> bool:
    return abs(a - b) <= RTOL * max(abs(a), scale)


def _rankings(doc: dict[str, Any]) -> dict[str, Any]:
    key = {c["id"]: _key(c) for c in doc["candidates"]}
    rk = doc["rankings"]
    return {
        "static": [key[i] for i in rk["static"]],
        "dynamic": [key[i] for i in rk["dynamic"]],
        "governing": [key[i] for i in rk["governing"]],
        "critical": [key[c["mechanism"]] for c in rk["critical"]],
        "not_built": [key[i] for i in doc["not_built"]],
    }


@pytest.mark.parametrize("name", sorted(PLACES))
def test_the_whole_output_is_the_same_wherever_the_scene_is_drawn(
    tmp_path: Path, spec_path: Path, drawn: dict[str, Any], name: str
) -> None:
    angle, shift, mirror, scale, units = PLACES[name]
    scene = _write_placed(tmp_path / f"{name}.3dm", angle, shift, mirror, scale, units)
    doc = rockmech.search(scene, spec_path).doc.to_dict()
    size = 15.0  # the building's diagonal [m], the scale of its coordinates' tolerance

    ref = {_key(c): c for c in drawn["candidates"]}
    got = {_key(c): c for c in doc["candidates"]}
    assert sorted(got) == sorted(ref) and len(ref) == len(drawn["candidates"]) > 10
    for k, c in ref.items():
        a, b = _numbers(c), _numbers(got[k])
        assert a.keys() == b.keys(), k
        bad = {f: (a[f], b[f]) for f in a if not _close(a[f], b[f], 1e-300)}
        assert not bad, (k, bad)
        # (a mirrored façade runs the other way along its frame: start and end swap)
        assert sorted(got[k]["on_bound"]) == sorted(c["on_bound"]), k
        axis = _place(c["hinge_axis"], angle, shift, mirror)
        assert np.allclose(
            np.asarray(got[k]["hinge_axis"]),
            axis[::-1] if mirror else axis,  # the axis runs along the façade's frame
            rtol=0.0,
            atol=RTOL * size,
        ), k
        assert np.allclose(
            np.asarray(got[k]["direction_vector"]),
            _place(c["direction_vector"], angle, (0.0, 0.0), mirror),
            rtol=0.0,
            atol=RTOL,
        ), k
    assert _rankings(doc) == _rankings(drawn)
    assert len(doc["lp"]) == len(drawn["lp"]) == 3
    for a, b in zip(drawn["lp"], doc["lp"]):
        assert (b["facade"], b["direction"], b["status"]) == (
            a["facade"],
            a["direction"],
            "optimal",
        )
        assert b["n_blocks"] == a["n_blocks"] and _close(b["lam"], a["lam"])
        assert b["missed"] is a["missed"] is False
    notes = [n for n in doc["notes"] if INSIDE_OUT not in n]
    assert notes == drawn["notes"]
    assert any(INSIDE_OUT in n for n in doc["notes"]) is mirror


def test_a_scene_twice_the_size_keeps_lam0_and_scales_p_eq(
    tmp_path: Path, spec_path: Path, drawn: dict[str, Any]
) -> None:
    scene = _write_placed(tmp_path / "twice.3dm", 0.0, (0.0, 0.0), False, 2.0, "Meters")
    spec = json.loads(spec_path.read_text(encoding="utf-8"))
    # the scene's lengths double: the spec's masonry unit with them, the tie's force with the
    # weights (x 8)
    spec["default_junction"]["unit"] = {"length": 0.6, "height": 0.4}
    spec["tie_bars"][0]["force"] *= 8.0
    path = tmp_path / "twice.json"
    path.write_text(json.dumps(spec), encoding="utf-8")
    doc = rockmech.search(scene, path).doc.to_dict()

    def by_key(d: dict[str, Any]) -> dict[tuple[Any, ...], dict[str, Any]]:
        out = {}
        for c in d["candidates"]:
            params = tuple(
                sorted(
                    (k, round(v / 2.0 if k.endswith("_m") and d is doc else v, 6))
                    for k, v in c["parameters"].items()
                )
            )
            out[(c["family"], c["facade"], c["direction"], params)] = c
        return out

    ref, got = by_key(drawn), by_key(doc)
    assert sorted(got) == sorted(ref)
    for k, c in ref.items():
        assert _close(got[k]["lam0"], c["lam0"]), k
        for side in ("positive", "negative"):
            if (c.get("constants") or {}).get(side):
                want = c["constants"][side]["p_eq"] / math.sqrt(2.0)
                assert _close(got[k]["constants"][side]["p_eq"], want), k
    static = [(c["family"], c["facade"], c["direction"]) for c in doc["candidates"]]
    assert static == [(c["family"], c["facade"], c["direction"]) for c in drawn["candidates"]]
