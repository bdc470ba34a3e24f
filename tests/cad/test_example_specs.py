"""Every example spec runs on its scene, and the constants are plausible or known exactly."""

import json
import math
from pathlib import Path
from typing import Any, Dict

import pytest

pytest.importorskip("rhino3dm")

from rhino_plugin.mechanisms.build import constants_from_spec
from rhino_plugin.mechanisms.multi_block import (
    four_bar_constants,
    four_bar_restitution,
    portal_frame,
)
from rhino_plugin.mechanisms.two_block import hinge_height
from rhino_plugin.scene_3dm import Scene
from shared_schema.spec import parse_spec

G = 9.80665
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SPECS = sorted((EXAMPLES / "specs").glob("*.spec.json"))
POSITIVE_KEYS = ("I0", "K", "Q", "p_eq", "lam", "phi_ov")


def spec_json(name: str) -> Dict[str, Any]:
    return json.loads((EXAMPLES / "specs" / f"{name}.spec.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def results() -> Dict[str, Dict[str, Any]]:
    """Constants of every example spec, by scene name: {"scene": Scene, "mechanisms": ...}."""
    out: Dict[str, Dict[str, Any]] = {}
    for path in SPECS:
        name = path.name[: -len(".spec.json")]
        scene = Scene.from_3dm(EXAMPLES / "scenes" / f"{name}.3dm")
        spec = parse_spec(path.read_text(encoding="utf-8"), path.name)
        cf = constants_from_spec(spec, scene, scene_name=f"{name}.3dm", spec_name=path.name)
        mechs = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"]
        out[name] = {"scene": scene, "mechanisms": {m["id"]: m for m in mechs}}
    return out


def the_mechanism(results: Dict[str, Dict[str, Any]], name: str) -> Dict[str, Any]:
    (mech,) = results[name]["mechanisms"].values()
    return mech


def test_every_scene_has_a_spec() -> None:
    scenes = sorted(p.name[: -len(".3dm")] for p in (EXAMPLES / "scenes").glob("*.3dm"))
    assert [p.name[: -len(".spec.json")] for p in SPECS] == scenes
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
        assert mech["provenance"]["scene"] == f"{name}.3dm"


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
