"""A tie-bar only pulls (issue #36, item 4): it acts on the swing that stretches it.

A tie anchored inside the building pulls the façade back while the façade moves away from
the anchorage (the positive, outward swing); on the inward swing the bar goes slack and
carries nothing. Every path that can put a tie on a two-sided mechanism is checked here
against hand-worked references written in the tests (theory §1.8, Eqs. 7-16, [C8.7.1.1]):

* the builder (``rockmech constants`` on a ``.3dm`` scene and a spec): a two-sided wall whose
  only added elements are tie-bars; its negative side is the same wall without them;
* the code check on those constants: the ties' share is taken out of the positive side
  only;
* a constants table: it carries ``M_F`` only, so the negative side of a tied two-sided row
  is the one the table gives (``p_eq_neg``, ``lam_neg``, ``phi_ov_neg``);
* the search's global check (``facade_lp_model`` + ``solve_lp``) on a tied façade loaded
  inward: the bar is slack and the multiplier is the bare wall's.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from cad_scenes import BUILD
from typer.testing import CliRunner

from cad_maths.scenes import read_scene
from cad_maths.search.lp import facade_lp_model, solve_lp
from cad_maths.search.model import building_from_scene
from shared_schema.constants import parse_constants
from shared_schema.errors import GeometryError, InputError
from shared_schema.search import SearchSpec
from shared_schema.site import parse_site
from solver_service.cli import app
from solver_service.workflows.adapter import to_rocking_model
from solver_service.workflows.codecheck import check_doc
from solver_service.workflows.tables import constants_from_table

G = 9.80665
# The wall: x in [0, B] (outer face x = 0), y in [0, L], z in [0, H]; a tie at H_T on the
# outer face, running into the building (+x).
B, L, H, RHO = 0.5, 4.0, 6.0, 1800.0
T, H_T = 20000.0, 5.8
M = RHO * B * L * H
W = M * G
R = 0.5 * math.hypot(B, H)
ALPHA = math.atan2(B, H)
I_O = M * (B * B + H * H) / 3.0  # rectangle about its base edge


def _scene(tmp_path: Path, tie_to: float = 6.0) -> Path:
    b = BUILD.Builder("tied")
    b.box("wall", "Walls", (0, 0, 0), (B, L, H), "brick")
    b.box("slab", "Floors", (0, 0, H), (5, L, H + 0.2), "concrete")  # rests on the wall top
    b.line("tie", "Ties", (0, 2, H_T), (tie_to, 2, H_T))
    b.line("axis", "Axes", (0, 0, 0), (0, L, 0))
    return Path(b.write(tmp_path / "tied.3dm"))


def _wall(ident: str, **extra: Any) -> dict[str, Any]:
    mech = {
        "id": ident,
        "groups": [{"objects": ["wall"], "density": RHO}],
        "axis": {"object": "axis"},
        "rocking": "two_sided",
    }
    mech.update(extra)
    return mech


TIED = _wall("T", typology="single_block_loaded", tie_bars=[{"object": "tie", "force": T}])


def _constants(tmp_path: Path, *mechs: dict[str, Any], tie_to: float = 6.0) -> dict[str, Any]:
    """``rockmech constants scene.3dm spec.json -o out.json``: the file it writes."""
    scene = _scene(tmp_path, tie_to)
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({"mechanisms": list(mechs)}))
    out = tmp_path / "constants.json"
    res = CliRunner().invoke(app, ["constants", str(scene), str(spec), "-o", str(out)])
    assert res.exit_code == 0, res.output
    doc: dict[str, Any] = json.loads(out.read_text())
    return doc


def test_two_sided_tied_wall_pulls_on_the_outward_swing_only(tmp_path: Path) -> None:
    doc = _constants(tmp_path, TIED, _wall("P"))
    tied, plain = (m for m in doc["mechanisms"])
    pos, neg = tied["positive"], tied["negative"]
    # Positive side (outward, the tie stretched): the tie pulls T inward at z = H_T on the
    # outer face through the axis (x = 0), so Eq. 15 gives M_F = -T H_T cos(alpha) and
    # Eq. 16 lam = (K alpha - M_F)/(g Q), phi_ov = alpha - M_F/K, with K = W R, Q = M R.
    m_f = -T * H_T * math.cos(ALPHA)
    assert pos["M_F"] == pytest.approx(m_f, rel=1e-9)
    assert pos["lam"] == pytest.approx((W * R * ALPHA + T * H_T * math.cos(ALPHA)) / (W * R), 1e-9)
    assert pos["phi_ov"] == pytest.approx(ALPHA + T * H_T * math.cos(ALPHA) / (W * R), rel=1e-9)
    assert pos["p_eq"] == pytest.approx(math.sqrt(W * R / I_O), rel=1e-9)
    # [C8.7.1.1] at rest: alpha0 = (W B/2 + T H_T) / (W H/2), S = M H/2, J = M H²/3.
    vw = pos["virtual_work"]
    assert vw["alpha0"] == pytest.approx((W * B / 2 + T * H_T) / (W * H / 2), rel=1e-9)
    assert vw["S"] == pytest.approx(M * H / 2, rel=1e-9)
    assert vw["J"] == pytest.approx(M * H * H / 3, rel=1e-9)
    # Negative side (inward, towards the anchorage): the bar is slack. The wall's own
    # constants: lam = phi_ov = alpha, M_F = 0, alpha0 = B/H (a tie that pushed would give
    # lam = alpha - T H_T cos(alpha)/(W R) = 0.074 - 0.180 < 0 here).
    assert neg["M_F"] == 0.0
    assert neg["lam"] == pytest.approx(ALPHA, rel=1e-9)
    assert neg["phi_ov"] == pytest.approx(ALPHA, rel=1e-9)
    assert neg["virtual_work"]["alpha0"] == pytest.approx(B / H, rel=1e-9)
    # ... identical to the same wall built without the tie (a symmetric single block, whose
    # negative side is its positive side's mirror image and is not written).
    assert "negative" not in plain
    for key in ("I0", "K", "Q", "phi_cr", "p_eq", "lam", "phi_ov", "M_F"):
        assert neg[key] == pytest.approx(plain["positive"][key], rel=1e-12, abs=0.0), key
    for key in ("alpha0", "mass", "S", "J"):
        assert neg["virtual_work"][key] == pytest.approx(
            plain["positive"]["virtual_work"][key], rel=1e-12
        )
    assert tied["eta"] == pytest.approx(plain["eta"], rel=1e-12)
    assert "slack" in tied["geometry"]["loaded"]["negative_side"]
    assert not any("rocking" in w for w in tied["provenance"]["warnings"])  # it was given
    # The solver rocks each side with its own constants.
    model = to_rocking_model(parse_constants(json.dumps(doc)).mechanisms[0])
    assert model.neg.lam == pytest.approx(ALPHA, rel=1e-9)
    assert model.positive.lam == pytest.approx(pos["lam"], rel=1e-15)


def test_a_defaulted_rocking_of_a_tied_wall_is_said(tmp_path: Path) -> None:
    mech = {k: v for k, v in TIED.items() if k != "rocking"}
    tied = _constants(tmp_path, mech)["mechanisms"][0]
    assert tied["rocking"] == "two_sided" and "negative" in tied
    said = [w for w in tied["provenance"]["warnings"] if w.startswith("T.rocking: not given")]
    assert len(said) == 1 and "one_sided" in said[0]


def test_two_sided_loaded_wall_with_one_sided_elements_is_still_refused(tmp_path: Path) -> None:
    mech = {**TIED, "floors": [{"objects": ["slab"], "density": 2400, "tributary": 0.5}]}
    scene = _scene(tmp_path)
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({"mechanisms": [mech]}))
    res = CliRunner().invoke(app, ["constants", str(scene), str(spec), "-o", str(tmp_path / "o")])
    assert res.exit_code != 0
    assert "tie-bars only" in res.output and "floors act on one side" in res.output
    assert "Traceback" not in res.output


def test_a_tie_drawn_outward_from_the_face_is_refused(tmp_path: Path) -> None:
    # A line from the face to x = -3 would pull the wall outward: not a tie anchored inside.
    from cad_maths.mechanisms.build import constants_from_spec
    from cad_maths.scene_3dm import Scene
    from shared_schema.spec import parse_spec

    scene = Scene.from_3dm(_scene(tmp_path, tie_to=-3.0))
    spec = parse_spec(json.dumps({"mechanisms": [TIED]}), "spec.json")
    with pytest.raises(GeometryError, match="runs outward from the façade's outer face"):
        constants_from_spec(spec, scene, scene_name="tied.3dm", spec_name="spec.json")
    # The axis on the inner face (x = B): the positive swing moves the wall towards the
    # anchorage, where the bar is slack, so the spec is refused rather than pulled wrongly.
    inner = BUILD.Builder("inner")
    inner.box("wall", "Walls", (0, 0, 0), (B, L, H), "brick")
    inner.line("tie", "Ties", (0, 2, H_T), (6.0, 2, H_T))
    inner.line("axis", "Axes", (B, 0, 0), (B, L, 0))
    scene = Scene.from_3dm(inner.write(tmp_path / "inner.3dm"))
    with pytest.raises(GeometryError, match="the positive swing would not stretch it"):
        constants_from_spec(spec, scene, scene_name="inner.3dm", spec_name="spec.json")
    with pytest.raises(GeometryError, match="runs outward from W's outer face"):
        building_from_scene(
            read_scene(_scene(tmp_path, tie_to=-3.0)),
            SearchSpec.model_validate(
                {
                    "walls": [{"id": "W", "object": "wall", "density": RHO}],
                    "tie_bars": [{"object": "tie", "force": T}],
                }
            ),
        )


def _site() -> Any:
    return parse_site(
        {
            "hazard": {
                "code": "NTC2018",
                "a_g": 0.20,
                "F0": 2.4,
                "Tc_star": 0.3,
                "soil": "B",
                "FC": 1.35,
            }
        }
    )


def test_code_check_takes_the_ties_out_of_the_positive_side_only(tmp_path: Path) -> None:
    cf = parse_constants(json.dumps(_constants(tmp_path, TIED)))
    row = check_doc(cf, _site())["mechanisms"][0]
    pos, neg = row["sides"]["positive"], row["sides"]["negative"]
    # Positive side: the ties are not verified (the default, C8.7.1.2.1.6), so d0 comes
    # from the wall without them: alpha0 = B/H and phi0 = alpha (no other static force).
    ties = pos["nonlinear"]["ties"]
    assert ties["present"] and ties["treatment"] == "not_verified"
    assert ties["alpha0_with"] == pytest.approx((W * B / 2 + T * H_T) / (W * H / 2), rel=1e-9)
    assert ties["alpha0_without"] == pytest.approx(B / H, rel=1e-9)
    assert ties["phi0_without"] == pytest.approx(ALPHA, rel=1e-9)
    # Negative side: the bar is slack there, nothing to take out; its alpha0 is the wall's.
    assert neg["nonlinear"]["ties"] == {"present": False}
    assert neg["linear"]["status"] == "ok"
    assert neg["linear"]["alpha0"] == pytest.approx(B / H, rel=1e-9)


def test_a_table_carries_the_negative_side_it_is_given(tmp_path: Path) -> None:
    # A table has no tie-bar column: the positive side carries the tie in M_F (physical
    # form), and a two-sided row gives the negative side in the short form, here the bare
    # wall's (lam = phi_ov = alpha). Without it the negative side would be the positive
    # side's mirror image, the tie's restraint included.
    k, q = W * R, M * R
    m_f = -T * H_T * math.cos(ALPHA)
    p_eq = math.sqrt(k / I_O)
    table = tmp_path / "tied.csv"
    table.write_text(
        "id,rocking,I0,K,Q,phi_cr,M_F,p_eq_neg,lam_neg,phi_ov_neg,eta\n"
        f"T,two_sided,{I_O!r},{k!r},{q!r},{ALPHA!r},{m_f!r},{p_eq!r},{ALPHA!r},{ALPHA!r},0.9\n"
    )
    model = to_rocking_model(constants_from_table(table).mechanisms[0])
    assert model.positive.lam == pytest.approx((k * ALPHA - m_f) / (G * q), rel=1e-12)
    assert model.neg.lam == pytest.approx(ALPHA, rel=1e-15)
    assert model.neg.phi_ov == pytest.approx(ALPHA, rel=1e-15)
    with pytest.raises(InputError, match="M_F is only meaningful"):
        bad = tmp_path / "bad.csv"
        bad.write_text("id,p_eq,lam,M_F\nT,2.0,0.2,-1000\n")
        constants_from_table(bad)


def test_search_global_check_leaves_a_slack_tie_out(tmp_path: Path) -> None:
    path = _scene(tmp_path)

    def lam(direction: str, ties: list[dict[str, Any]]) -> float:
        spec = SearchSpec.model_validate(
            {"walls": [{"id": "W", "object": "wall", "density": RHO}], "tie_bars": ties}
        )
        res = solve_lp(facade_lp_model(building_from_scene(read_scene(path), spec), "W", direction))
        assert res.status == "optimal"
        return res.lam

    tie = [{"object": "tie", "force": T}]
    # Outward the tie is stretched: lam0 = (W B/2 + T H_T) / (W H/2).
    assert lam("outward", tie) == pytest.approx((W * B / 2 + T * H_T) / (W * H / 2), rel=1e-9)
    # Inward it is slack: the bare wall's B/H. (A force always against the load, as the
    # check took a tie before, gave the outward value 0.266 here: a bar pushing the wall
    # back on its inward swing.)
    assert lam("inward", tie) == pytest.approx(B / H, rel=1e-9)
    assert lam("inward", []) == pytest.approx(B / H, rel=1e-9)
