"""The retrofit core (#39): the least tie force that makes a failing mechanism pass.

The free wall of the tests: b = 0.5 m thick (x), L = 4 m long (y), h = 6 m high, 1800 kg/m³,
rocking one-sided about its outer toe (x = 0), a tie at h_t on the outer face. The hand case
is written here from the clauses:

* [C8.7.1.1] at rest: α0(T) = (W b/2 + T h_t)/(W h/2);
* [C8.7.1.5] with one block (the code check's default): e* = 1;
* [C8.7.1.8] a0* = α0 g/(e* FC); C8.7.1.2.1.7: a_g,SLV = q a_g,SLD, so the check passes
  when a0* ≥ a_g S/q (the activation demand of a restrained wall at the ground is the peak
  ground acceleration a_g S, NTC 2018 [3.2.2] at T = 0);
* NTC 2018 Tab. 3.2.IV, soil C: S_S = 1.70 − 0.60 F0 a_g/g in [1.00, 1.50]; S_T = 1 (T1);
* so T* = W (α0,req h − b)/(2 h_t), α0,req = e* FC a_g S/q.

The product's own check (``rockmech.check``) on constants that ``rockmech constants`` builds
with a tie-bar of that force is the independent judge: its verdict flips across T*.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest
from search.search_scenes import BUILD
from typer.testing import CliRunner

import rockmech
from shared_schema.constants import ConstantsFile, parse_constants
from shared_schema.documents.check import Nonlinear2019
from shared_schema.errors import InputError
from shared_schema.retrofit import parse_retrofit_spec
from shared_schema.site import parse_site
from solver_service.cli import app

G = 9.80665
B, L, H, RHO, H_T = 0.5, 4.0, 6.0, 1800.0, 5.8
A_G, F0, TC, FC, Q = 0.25, 2.4, 0.3, 1.35, 2.0
SITE = {"hazard": {"code": "NTC2018", "a_g": A_G, "F0": F0, "Tc_star": TC, "soil": "C", "FC": FC}}
SPEC = {
    "steel": {"grade": "S275", "diameters_mm": [8, 10, 12, 16]},
    "anchorage": {"capacity_N": 60000.0, "source": "plate punching, designer's calculation"},
    "mechanisms": {"W": {"heights_m": [H_T], "length_m": 8.0}},
}


def _hand_t_star() -> float:
    w = RHO * G * B * H * L
    s_s = min(max(1.70 - 0.60 * F0 * A_G, 1.0), 1.5)
    alpha_req = 1.0 * FC * A_G * s_s / Q
    return w * (alpha_req * H - B) / (2.0 * H_T)


def _scene(tmp_path: Path) -> Path:
    b = BUILD.Builder("walls")
    b.box("wall", "Walls", (0, 0, 0), (B, L, H), "brick")
    b.line("axis", "Axes", (0, 0, 0), (0, L, 0))
    b.line("tie", "Ties", (0, 2, H_T), (6, 2, H_T))
    b.box("thin", "Walls", (20, 0, 0), (20.4, L, 5.0), "brick")
    b.line("axis2", "Axes", (20, 0, 0), (20, L, 0))
    return Path(b.write(tmp_path / "walls.3dm"))


def _mech(ident: str, obj: str = "wall", axis: str = "axis", **extra: Any) -> dict[str, Any]:
    m = {
        "id": ident,
        "groups": [{"objects": [obj], "density": RHO}],
        "axis": {"object": axis},
        "rocking": "one_sided",
    }
    m.update(extra)
    return m


def _constants(tmp_path: Path, *mechs: dict[str, Any], name: str = "c") -> ConstantsFile:
    """``rockmech constants walls.3dm spec.json -o c.json``: the file it writes."""
    scene = _scene(tmp_path)
    spec = tmp_path / f"{name}.spec.json"
    spec.write_text(json.dumps({"mechanisms": list(mechs)}))
    out = tmp_path / f"{name}.json"
    res = CliRunner().invoke(app, ["constants", str(scene), str(spec), "-o", str(out)])
    assert res.exit_code == 0, res.output
    return parse_constants(out.read_text())


def _tied(tmp_path: Path, force: float) -> ConstantsFile:
    """The wall with the builder's tie-bar of ``force`` at H_T (not the retrofit's code)."""
    mech = _mech("W", typology="single_block_loaded", tie_bars=[{"object": "tie", "force": force}])
    return _constants(tmp_path, mech, name=f"tied{force:.0f}")


def _site(**mech_options: Any) -> Any:
    data: dict[str, Any] = json.loads(json.dumps(SITE))
    if mech_options:
        data["local_mechanisms"] = {"mechanisms": {"W": mech_options}}
    return parse_site(data)


@pytest.fixture(scope="module")
def wall(tmp_path_factory: pytest.TempPathFactory) -> ConstantsFile:
    return _constants(tmp_path_factory.mktemp("wall"), _mech("W"))


def test_free_wall_linear_t_star_is_the_closed_form_and_flips_the_check(
    wall: ConstantsFile, tmp_path: Path
) -> None:
    t_hand = _hand_t_star()
    assert t_hand == pytest.approx(15645.0, abs=1.0)  # the worked example's figure
    doc = rockmech.retrofit(wall, parse_site(SITE), parse_retrofit_spec(SPEC))
    m = doc.find("W")
    assert m.status == "designed" and m.before.linear_passes is False
    opt = m.options[m.chosen or 0]
    assert opt.e_star == pytest.approx(1.0, rel=1e-12)
    assert opt.T_linear_N == pytest.approx(t_hand, rel=1e-6)
    assert opt.T_star_N == pytest.approx(t_hand, rel=1e-6)
    assert opt.governing == "linear SLV"
    assert opt.T_nonlinear_SLV_N is not None and opt.T_nonlinear_SLV_N < t_hand
    assert opt.after is not None and opt.after.passes
    # The product's check on the builder's tie: fails 0.5 % below T*, passes 0.5 % above.
    below = rockmech.check(_tied(tmp_path, t_hand * 0.995), parse_site(SITE))
    above = rockmech.check(_tied(tmp_path, t_hand * 1.005), parse_site(SITE))
    assert below.mechanisms[0].linear.passes is False
    assert above.mechanisms[0].linear.passes is True


def test_nonlinear_t_is_bracketed_to_half_a_percent(wall: ConstantsFile, tmp_path: Path) -> None:
    doc = rockmech.retrofit(wall, parse_site(SITE), parse_retrofit_spec(SPEC))
    t_nl = doc.find("W").options[0].T_nonlinear_SLV_N
    assert t_nl is not None
    site = _site(ties="verified")  # a designed tie whose bar and anchorage carry it
    lo = rockmech.check(_tied(tmp_path, t_nl * 0.995), site).mechanisms[0].nonlinear
    hi = rockmech.check(_tied(tmp_path, t_nl), site).mechanisms[0].nonlinear
    assert lo.passes is False and hi.passes is True


def test_the_smallest_bar_that_carries_t_star_and_its_steel(wall: ConstantsFile) -> None:
    doc = rockmech.retrofit(wall, parse_site(SITE), parse_retrofit_spec(SPEC))
    opt = doc.find("W").options[0]
    t = _hand_t_star()

    # NTC 2018 [4.2.6] N_pl,Rd = A f_yk/γ_M0, S275 f_yk = 275 N/mm² (Tab. 4.2.I, t ≤ 40 mm),
    # γ_M0 = 1.05 (Tab. 4.2.VII): Ø8 carries 13.17 kN < T*, Ø10 carries 20.57 kN.
    def n_pl(d: float) -> float:
        return math.pi * d * d / 4.0 * 275.0 / 1.05

    assert n_pl(8) < t <= n_pl(10)
    assert opt.bar is not None and opt.bar.diameter_mm == 10.0
    assert opt.bar.N_pl_Rd_N == pytest.approx(n_pl(10), rel=1e-12)
    assert opt.verified and opt.anchorage is not None and opt.anchorage.passes
    # 8 m of Ø10 at 7850 kg/m³.
    assert opt.steel_mass_kg == pytest.approx(math.pi * 0.01**2 / 4 * 8.0 * 7850.0, rel=1e-12)


def test_more_tie_force_never_lowers_the_capacity_ratio(tmp_path: Path) -> None:
    site = _site(ties="verified")
    last = (0.0, 0.0, 0.0)
    for force in (1.0, 4000.0, 8000.0, 16000.0, 32000.0):
        row = rockmech.check(_tied(tmp_path, force), site).mechanisms[0]
        non = row.nonlinear
        assert isinstance(non, Nonlinear2019)  # the 2019 check with its capacity curve
        now = (row.linear_ratio, non.SLV.capacity_ratio, non.SLC.capacity_ratio)
        assert all(n >= p for n, p in zip(now, last)), (force, now, last)
        last = now


def test_a_tie_above_the_moving_part_changes_nothing_and_says_why(wall: ConstantsFile) -> None:
    spec = json.loads(json.dumps(SPEC))
    spec["mechanisms"]["W"]["heights_m"] = [6.5]
    m = rockmech.retrofit(wall, parse_site(SITE), parse_retrofit_spec(spec)).find("W")
    (opt,) = m.options
    assert opt.status == "above_moving_part" and opt.T_star_N is None and opt.after is None
    assert "above the moving part" in opt.decisions[0] and "6 m" in opt.decisions[0]
    assert m.status == "not_achievable"


def test_default_tie_is_at_the_top_of_the_moving_part(wall: ConstantsFile) -> None:
    spec = {k: v for k, v in SPEC.items() if k != "mechanisms"}
    m = rockmech.retrofit(wall, parse_site(SITE), parse_retrofit_spec(spec)).find("W")
    (opt,) = m.options  # no loaded elements: the top only
    assert opt.height_m == pytest.approx(H, rel=1e-9)
    t_top = RHO * G * B * H * L * (1.0 * FC * A_G * 1.34 / Q * H - B) / (2.0 * H)
    assert opt.T_linear_N == pytest.approx(t_top, rel=1e-6)


CHURCH = Path(__file__).resolve().parents[2] / "examples"


def _church_default(order: int = 1) -> Any:
    """The bundled church, its retrofit spec without heights; elements in order or reversed."""
    data = json.loads((CHURCH / "constants" / "church_geometry.json").read_text())
    for m in data["mechanisms"]:
        loaded = m["geometry"].get("loaded")
        if loaded is not None:
            loaded["elements"] = loaded["elements"][::order]
    spec = json.loads((CHURCH / "specs" / "church.retrofit.json").read_text())
    spec["mechanisms"] = {}
    site = CHURCH / "sites" / "ntc_site.json"
    return data, rockmech.retrofit(
        parse_constants(json.dumps(data)), site, parse_retrofit_spec(spec)
    )


def test_default_ties_are_the_top_and_each_level_the_moving_part_crosses() -> None:
    data, doc = _church_default()
    by_id = {m["id"]: m for m in data["mechanisms"]}
    # F1 by hand: the hinge at z = axis_point_m[2] on a horizontal axis; the top the
    # builder's top_m (the wall's highest point, 8 m); each floor's height its load point's z
    # above the hinge; the roof at the top is the top's candidate.
    geo = by_id["F1"]["geometry"]
    z0 = geo["positive"]["axis_point_m"][2]
    top = geo["top_m"]
    levels = {e["element"]: e["at_m"][2] - z0 for e in geo["loaded"]["elements"]}
    assert abs(levels["F1.roof"] - top) < 1e-9
    f1 = doc.find("F1")
    want = [levels["F1.floors[0]"], levels["F1.floors[1]"], top]
    assert [o.height_m for o in f1.options] == pytest.approx(want, abs=1e-12)
    srcs = [o.height_source for o in f1.options]
    assert srcs[0] == "default: floor F1.floors[0] at 3.5 m above the hinge"
    assert srcs[1] == "default: floor F1.floors[1] at 6.6 m above the hinge"
    assert "top of the moving part" in srcs[2] and "roof F1.roof at 8 m" in srcs[2]
    # each tried alone: the top's option is the one a spec listing that height gives
    spec = json.loads((CHURCH / "specs" / "church.retrofit.json").read_text())
    spec["mechanisms"] = {"F1": {"heights_m": [levels["F1.floors[1]"]]}}
    alone = rockmech.retrofit(
        parse_constants(json.dumps(data)),
        CHURCH / "sites" / "ntc_site.json",
        parse_retrofit_spec(spec),
    ).find("F1")
    assert alone.options[0].T_star_N == f1.options[1].T_star_N
    # F2 carries no levels: the top only (its top_m: 8 m, where 2 R cos α would say 6.33 m,
    # its wall not being a homogeneous rectangle)
    (f2,) = doc.find("F2").options
    assert f2.height_m == by_id["F2"]["geometry"]["top_m"] == 8.0


def test_the_work_plan_counts_every_default_candidate() -> None:
    # The plan (--time-limit) counts per candidate 1 check after the tie and 7 bisection steps
    # per limit state; it must count at least the options the retrofit then tries.
    from solver_service.workflows.limits import retrofit_checks

    data, doc = _church_default()
    cf = parse_constants(json.dumps(data))
    site = parse_site((CHURCH / "sites" / "ntc_site.json").read_text())
    states = 1 + int("SLC" in (site.hazard.limit_states or {}))
    spec = json.loads((CHURCH / "specs" / "church.retrofit.json").read_text())
    spec["mechanisms"] = {}
    planned = retrofit_checks(cf, site, parse_retrofit_spec(spec))
    tried = sum(max(len(m.options), 1) for m in doc.mechanisms)
    assert len(doc.find("F1").options) == 3
    assert planned >= tried * (1 + 7 * states)
    assert planned == (4 + 1 + 1 + 1) * (1 + 7 * states)  # F1: top, 2 floors, roof; F2, A1, T1


def test_default_ties_do_not_depend_on_the_order_of_the_elements() -> None:
    _, a = _church_default(1)
    _, b = _church_default(-1)
    assert a.model_dump() == b.model_dump()


def test_a_passing_mechanism_needs_no_tie(wall: ConstantsFile) -> None:
    site = json.loads(json.dumps(SITE))
    site["hazard"]["a_g"] = 0.02
    m = rockmech.retrofit(wall, parse_site(site), parse_retrofit_spec(SPEC)).find("W")
    assert m.status == "passes" and m.options == [] and "needs no tie" in m.decisions[0]


def test_a_weak_anchorage_leaves_the_tie_unverified(wall: ConstantsFile) -> None:
    spec = json.loads(json.dumps(SPEC))
    spec["anchorage"]["capacity_N"] = 5000.0
    m = rockmech.retrofit(wall, parse_site(SITE), parse_retrofit_spec(spec)).find("W")
    opt = m.options[0]
    assert not opt.verified and opt.anchorage is not None and not opt.anchorage.passes
    assert opt.status == "not_carried" and m.status == "not_achievable"
    assert any("not verified" in d for d in opt.decisions)
    # Not verified: the check after leaves it out of d0 (its rule says so).
    assert opt.after is not None and opt.after.ties is not None
    assert "not verified" in opt.after.ties


def test_no_bar_on_offer_is_said(wall: ConstantsFile) -> None:
    spec = json.loads(json.dumps(SPEC))
    spec["steel"]["diameters_mm"] = [6]
    opt = rockmech.retrofit(wall, parse_site(SITE), parse_retrofit_spec(spec)).find("W")
    assert opt.options[0].bar is None
    assert any("no bar on offer" in d for d in opt.options[0].decisions)


def test_invariant_to_the_order_of_mechanisms(tmp_path: Path) -> None:
    a = _constants(tmp_path, _mech("W"), _mech("V", "thin", "axis2"), name="ab")
    b = _constants(tmp_path, _mech("V", "thin", "axis2"), _mech("W"), name="ba")
    spec = {k: v for k, v in SPEC.items() if k != "mechanisms"}
    da = rockmech.retrofit(a, parse_site(SITE), parse_retrofit_spec(spec))
    db = rockmech.retrofit(b, parse_site(SITE), parse_retrofit_spec(spec))
    assert [m.id for m in da.mechanisms] == ["W", "V"]
    for ident in ("W", "V"):
        assert da.find(ident).model_dump() == db.find(ident).model_dump()


def test_paths_work_as_objects(wall: ConstantsFile, tmp_path: Path) -> None:
    (tmp_path / "c.json").write_text(wall.model_dump_json())
    (tmp_path / "site.json").write_text(json.dumps(SITE))
    (tmp_path / "retrofit.json").write_text(json.dumps(SPEC))
    doc = rockmech.retrofit(
        str(tmp_path / "c.json"), tmp_path / "site.json", tmp_path / "retrofit.json"
    )
    assert doc.find("W").options[0].T_star_N == pytest.approx(_hand_t_star(), rel=1e-6)


@pytest.mark.parametrize(
    ("change", "field", "words"),
    [
        (lambda s: s["anchorage"].update(capacity_N=-1.0), "anchorage.capacity_N", "greater"),
        (lambda s: s["anchorage"].update(capacity_N=1e9), "anchorage.capacity_N", "less"),
        (lambda s: s["anchorage"].pop("source"), "anchorage.source", "required"),
        (lambda s: s["anchorage"].update(source="  "), "anchorage.source", "source"),
        (lambda s: s["steel"].update(grade="S460"), "steel.grade", "S355"),
        (lambda s: s["steel"].update(diameters_mm=[120]), "steel.diameters_mm", "80"),
        (lambda s: s["mechanisms"]["W"].update(heights_m=[-2.0]), "mechanisms.W.heights_m", "m"),
    ],
)
def test_bad_spec_names_the_field(change: Any, field: str, words: str) -> None:
    spec = json.loads(json.dumps(SPEC))
    change(spec)
    with pytest.raises(InputError) as err:
        parse_retrofit_spec(json.dumps(spec))
    assert err.value.field is not None and err.value.field.startswith(field), str(err.value)
    assert words in str(err.value)


def test_a_spec_naming_a_missing_mechanism_is_refused(wall: ConstantsFile) -> None:
    spec = json.loads(json.dumps(SPEC))
    spec["mechanisms"]["F9"] = {}
    with pytest.raises(InputError, match="no mechanism 'F9'") as err:
        rockmech.retrofit(wall, parse_site(SITE), parse_retrofit_spec(spec))
    assert err.value.field == "mechanisms.F9"


def test_the_default_top_is_the_moving_parts_highest_point_not_twice_its_centre(
    tmp_path: Path,
) -> None:
    # A stepped wall: the 0.5 m wall (6 m) with a 0.25 m parapet (1 m) on its outer half.
    # Its top is 7 m above the hinge; twice the centre of mass's height is not (by hand).
    b = BUILD.Builder("stepped")
    b.box("wall", "Walls", (0, 0, 0), (B, L, H), "brick")
    b.box("parapet", "Walls", (0, 0, H), (B / 2, L, H + 1.0), "brick")
    b.line("axis", "Axes", (0, 0, 0), (0, L, 0))
    scene = Path(b.write(tmp_path / "stepped.3dm"))
    mech = {"id": "W", "groups": [{"objects": ["wall", "parapet"], "density": RHO}],
            "axis": {"object": "axis"}, "rocking": "one_sided"}  # fmt: skip
    spec = tmp_path / "stepped.spec.json"
    spec.write_text(json.dumps({"mechanisms": [mech]}))
    out = tmp_path / "stepped.json"
    res = CliRunner().invoke(app, ["constants", str(scene), str(spec), "-o", str(out)])
    assert res.exit_code == 0, res.output
    cf = parse_constants(out.read_text())
    geo = cf.mechanisms[0].geometry or {}
    assert geo["top_m"] == pytest.approx(H + 1.0, abs=1e-9)
    v_wall, v_par = B * L * H, B / 2 * L * 1.0
    z_g = (v_wall * H / 2 + v_par * (H + 0.5)) / (v_wall + v_par)
    assert (H + 1.0) - 2 * z_g > 0.4  # the old rule (2 R cos α) put the tie 0.46 m too low
    rspec = parse_retrofit_spec({k: v for k, v in SPEC.items() if k != "mechanisms"})
    m = rockmech.retrofit(cf, parse_site(SITE), rspec).find("W")
    assert [o.height_m for o in m.options] == [pytest.approx(H + 1.0, abs=1e-9)]
    assert "top_m" in m.options[0].height_source
    # Without top_m, a block that is not a rectangle (I_O != 4/3 M R^2) has no default top:
    # refused, naming the heights to give, rather than a tie at 2 R cos α.
    data = json.loads(out.read_text())
    del data["mechanisms"][0]["geometry"]["top_m"]
    with pytest.raises(InputError, match="not a homogeneous rectangle") as err:
        rockmech.retrofit(parse_constants(json.dumps(data)), parse_site(SITE), rspec)
    assert err.value.field == "mechanisms.W.heights_m"
