"""Every example spec runs on its scene, and the constants are plausible or known exactly."""

import json
import math
from pathlib import Path
from typing import Any, Dict

import numpy as np
import pytest

pytest.importorskip("rhino3dm")

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.mechanisms.multi_block import (
    four_bar_constants,
    four_bar_restitution,
    portal_frame,
)
from cad_maths.mechanisms.two_block import hinge_height
from cad_maths.scenes import read_scene
from shared_schema.spec import parse_spec

G = 9.80665
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SPECS = sorted((EXAMPLES / "specs").glob("*.spec.json"))
POSITIVE_KEYS = ("I0", "K", "Q", "p_eq", "lam", "phi_ov")
#: Scan meshes carry no unit; the examples' (examples/scenes/README.md).
SCAN_UNITS = {"ply": "mm"}


def scene_file(name: str) -> str:
    """Return the scene of spec ``name``: ``<name>.3dm``, or the scan ``<stem>.<fmt>``."""
    stem, _, fmt = name.rpartition("_")
    return f"{stem}.{fmt}" if fmt in SCAN_UNITS else f"{name}.3dm"


def spec_json(name: str) -> Dict[str, Any]:
    return json.loads((EXAMPLES / "specs" / f"{name}.spec.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def results() -> Dict[str, Dict[str, Any]]:
    """Constants of every example spec, by scene name: {"scene": Scene, "mechanisms": ...}."""
    out: Dict[str, Dict[str, Any]] = {}
    for path in SPECS:
        name = path.name[: -len(".spec.json")]
        file = scene_file(name)
        scene = read_scene(EXAMPLES / "scenes" / file, units=SCAN_UNITS.get(file[-3:]))
        spec = parse_spec(path.read_text(encoding="utf-8"), path.name)
        cf = constants_from_spec(spec, scene, scene_name=file, spec_name=path.name)
        mechs = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"]
        out[name] = {"scene": scene, "mechanisms": {m["id"]: m for m in mechs}}
    return out


def the_mechanism(results: Dict[str, Dict[str, Any]], name: str) -> Dict[str, Any]:
    (mech,) = results[name]["mechanisms"].values()
    return mech


def test_every_scene_has_a_spec() -> None:
    scenes = [p.name[: -len(".3dm")] for p in (EXAMPLES / "scenes").glob("*.3dm")]
    scenes += [
        f"{p.stem}_{fmt}" for fmt in SCAN_UNITS for p in (EXAMPLES / "scenes").glob(f"*.{fmt}")
    ]
    assert [p.name[: -len(".spec.json")] for p in SPECS] == sorted(scenes)
    assert len(SPECS) >= 8


@pytest.mark.parametrize("path", SPECS, ids=lambda p: p.name)
def test_constants_are_finite_positive_with_provenance(
    path: Path, results: Dict[str, Dict[str, Any]]
) -> None:
    name = path.name[: -len(".spec.json")]
    scene = results[name]["scene"]
    mechs = results[name]["mechanisms"]
    declared = [m["id"] for m in spec_json(name)["mechanisms"]]
    assert list(mechs) == declared
    scene_ids = {o.id for o in scene.objects}
    for ident, mech in mechs.items():
        for side in ("positive", "negative"):
            if side not in mech:
                assert side == "negative", ident
                continue
            for key in POSITIVE_KEYS:
                value = mech[side][key]
                assert math.isfinite(value) and value > 0.0, (ident, side, key, value)
        if mech["rocking"] == "two_sided":
            assert 0.0 <= mech["eta"] <= 1.0, ident
        ids = mech["provenance"]["object_ids"]
        assert ids and set(ids) <= scene_ids, ident
        assert mech["provenance"]["scene"] == scene_file(name)


def test_portal_frame_is_makris_vassiliou(results: Dict[str, Dict[str, Any]]) -> None:
    p = the_mechanism(results, "portal_frame")
    b, h, span, depth = 0.5, 4.0, 3.0, 0.5
    alpha = math.atan(b / h)
    r = 0.5 * math.hypot(b, h)
    gamma = ((2 * b + span) * depth) / (2 * b * h)  # beam mass over twice a column's (one rho)
    expected_p = math.sqrt(3 * G / (4 * r)) * math.sqrt((1 + 2 * gamma) / (1 + 3 * gamma))
    for side in ("positive", "negative"):
        consts = p.get(side, p["positive"])  # a symmetric frame stores one side
        assert consts["phi_cr"] == pytest.approx(alpha, rel=1e-10), side
        assert consts["p_eq"] == pytest.approx(expected_p, rel=1e-10), side
    eta_mv = (1 - 1.5 * math.sin(alpha) ** 2 + 3 * gamma * math.cos(2 * alpha)) / (1 + 3 * gamma)
    assert p["eta"] == pytest.approx(eta_mv, rel=1e-10)


def test_asym_frame_is_the_portal_frame_function(results: Dict[str, Dict[str, Any]]) -> None:
    p = the_mechanism(results, "asym_frame")
    (density,) = {
        g["density"] for block in spec_json("asym_frame")["mechanisms"][0]["blocks"] for g in block
    }
    blocks, pos, neg = portal_frame(0.5, 4.0, 3.0, 0.5, density, asymmetric=(0.7, 3.6))
    for side, hinges, direction in (("positive", pos, 1), ("negative", neg, -1)):
        ref = four_bar_constants(blocks, *hinges, direction=direction)
        for key in ("I0", "K", "Q", "phi_cr", "M_F", "p_eq", "lam", "phi_ov"):
            assert p[side][key] == pytest.approx(getattr(ref, key), rel=1e-9, abs=1e-12), (
                side,
                key,
            )
    assert p["eta"] == pytest.approx(four_bar_restitution(blocks, pos, neg), rel=1e-9)
    assert p["positive"]["phi_cr"] != pytest.approx(p["negative"]["phi_cr"], rel=1e-3)


def test_two_block_wall_hinge_height(results: Dict[str, Dict[str, Any]]) -> None:
    t = the_mechanism(results, "two_block_wall")
    mech = spec_json("two_block_wall")["mechanisms"][0]
    rho = mech["groups"][0]["density"]
    b, length, h = 0.3, 3.0, 4.0
    n = 0.5 * mech["overburden"]["density"] * 4.0 * 3.0 * 0.2 * G  # half the slab's weight
    h_c = hinge_height(h, rho * b * length * h * G, n, mech["f_mt"], length * b)
    summary = t["geometry"]["two_block"]
    assert summary["overburden_N"] == pytest.approx(n, rel=1e-12)
    assert summary["h_c_m"] == pytest.approx(h_c, rel=1e-12)
    assert 0.5 * h < h_c < h


def test_side_aisle_is_a_true_four_bar(results: Dict[str, Dict[str, Any]]) -> None:
    a = the_mechanism(results, "side_aisle")
    pos, neg = a["positive"], a["negative"]  # unequal wall and pier: two distinct sides
    assert pos["phi_cr"] != pytest.approx(neg["phi_cr"], rel=1e-3)
    summary = a["geometry"]["multi_block"]
    assert summary["positive"]["sense"] == -summary["negative"]["sense"]
    for consts in (pos, neg):
        assert 1.0 < consts["p_eq"] < 10.0 and 0.0 < consts["phi_cr"] < 0.5 * math.pi


def test_scan_wall_ply_is_the_scan_wall_on_a_coarser_mesh(
    results: Dict[str, Dict[str, Any]],
) -> None:
    """The PLY (mm, 8,360 triangles) gives the constants of scan_wall.3dm (201,800 triangles).

    The PLY's vertices are vertices of the .3dm's mesh (one surface sampled 5 times more
    coarsely along y and z), so the two differ only by the linear interpolation of the
    +-15 mm relief over 0.1 m cells instead of 0.02 m ones. The relief itself moves the
    constants from those of the plain 0.6 x 4 x 5 m box by about 1e-3 (checked below); the
    coarser interpolation changes that share by a fraction of order (|k| h)^2 / 8 < 0.5 for its
    waves (|k| <= 19.4 rad/m, h = 0.1 m), mostly far less for the long waves that carry it:
    measured 9e-6, checked at 1e-4.
    """
    ply, ref = the_mechanism(results, "scan_wall_ply"), the_mechanism(results, "scan_wall")
    scan, fine = results["scan_wall_ply"]["scene"], results["scan_wall"]["scene"]
    (coarse_obj,), (fine_obj,) = scan.find("scan_wall"), fine.find("scan_wall")
    um = 1e6  # compare vertex sets on a micrometre grid
    fine_keys = {tuple(k) for k in np.rint(fine.mesh(fine_obj).vertices * um).astype(np.int64)}
    coarse = np.rint(scan.mesh(coarse_obj).vertices * um).astype(np.int64)
    assert coarse.shape[0] == 4182 and all(tuple(k) in fine_keys for k in coarse)
    assert ply["provenance"]["scene_units"] == "millimeters"
    for side in ("positive", "negative"):
        for key in POSITIVE_KEYS:
            assert ply[side][key] == pytest.approx(ref[side][key], rel=1e-4), (side, key)
    assert ply["eta"] == pytest.approx(ref["eta"], rel=1e-4)
    # The undisplaced box in closed form (Housner): half-width b, half-height h, density 2200.
    # The relief (+-15 mm on faces 0.3 m from the mid-plane, smooth and of zero mean over many
    # half-waves) moves mass, lever arms and I0 by ~1e-3; checked at 5e-3 (a wrong unit,
    # axis or side would be off by far more).
    b, h, length, rho = 0.3, 2.5, 4.0, 2200.0
    mass = rho * 2 * b * 2 * h * length
    r = math.hypot(b, h)
    alpha = math.atan(b / h)
    assert ply["geometry"]["mass_kg"] == pytest.approx(mass, rel=5e-3)
    for side in ("positive", "negative"):
        consts = ply[side]
        assert consts["I0"] == pytest.approx(4 / 3 * mass * r**2, rel=5e-3), side
        assert consts["p_eq"] == pytest.approx(math.sqrt(3 * G / (4 * r)), rel=5e-3), side
        assert consts["lam"] == pytest.approx(alpha, rel=5e-3), side
    assert ply["eta"] == pytest.approx(1 - 1.5 * math.sin(alpha) ** 2, rel=5e-3)
