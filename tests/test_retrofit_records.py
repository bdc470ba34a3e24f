"""The retrofit's records (#39): the least tie force with which every record survives.

The free wall of ``tests/test_cli_retrofit.py`` (b = 0.5 m, L = 4 m, h = 6 m, 1800 kg/m³,
one-sided about its outer toe, a tie at h_t = 5 m on the outer face) on a site of
a_g = 0.45 g, where El Centro 1940 N-S overturns it at its design scale. The hand model
of the tied wall, written here from theory §2.2 (not from the code):

* W = ρ g b h L, R = ½ √(b² + h²), α = atan(b/h), I_O = M (b² + h²)/3, p = √(W R/I_O);
* the tie pulls inward at h_t: M_F = −T h_t cos α (Eq. 15), so Eq. 16 gives
  λ(T) = α + T h_t cos α/(W R) and φ_ov(T) = λ(T) (K = W R = g Q for one block);
* one-sided restitution η = 1 − 2 M R² cos² α/I_O (Eq. 26).

Its least force is checked against a bisection written here with the independent
time-stepping reference (``solver_service.core.reference.simulate_ivp``).
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
from shared_schema.errors import InputError
from solver_service.cli import app
from solver_service.core.model import RockingModel, RockingSide
from solver_service.core.reference import simulate_ivp
from solver_service.workflows.retrofit import with_tie

runner = CliRunner()
REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
ELCENTRO = EXAMPLES / "records" / "elcentro_NS.dat"
CHURCH = EXAMPLES / "constants" / "church_geometry.json"
CHURCH_SITE = EXAMPLES / "sites" / "ntc_site.json"
CHURCH_SPEC = EXAMPLES / "specs" / "church.retrofit.json"

G = 9.80665
B, L, H, RHO, H_T = 0.5, 4.0, 6.0, 1800.0, 5.0
A_G = 0.45
SITE = {
    "hazard": {"code": "NTC2018", "a_g": A_G, "F0": 2.4, "Tc_star": 0.3, "soil": "C", "FC": 1.35}
}
SPEC: dict[str, Any] = {
    "steel": {"grade": "S275", "diameters_mm": [10, 12, 16, 20, 24, 30]},
    "anchorage": {"capacity_N": 60000.0, "source": "plate punching, designer's calculation"},
    "mechanisms": {"W": {"heights_m": [H_T], "length_m": 8.0}},
}
#: The issue's bound on the exact runs of one record's search on the tie force.
RUNS_PER_RECORD = 20


def _scene(folder: Path, walls: list[tuple[str, float, float, float]]) -> Path:
    """Walls (id, x of the outer face, thickness, height) [m], each with its axis."""
    bld = BUILD.Builder("walls")
    for ident, x, b, h in walls:
        bld.box(ident, "Walls", (x, 0, 0), (x + b, L, h), "brick")
        bld.line(f"axis_{ident}", "Axes", (x, 0, 0), (x, L, 0))
    return Path(bld.write(folder / "walls.3dm"))


def _constants(folder: Path, walls: list[tuple[str, float, float, float]]) -> Path:
    """``rockmech constants``: each wall one-sided about its outer toe."""
    scene = _scene(folder, walls)
    mechs = [
        {
            "id": ident,
            "groups": [{"objects": [ident], "density": RHO}],
            "axis": {"object": f"axis_{ident}"},
            "rocking": "one_sided",
        }
        for ident, *_ in walls
    ]
    (folder / "spec.json").write_text(json.dumps({"mechanisms": mechs}))
    out = folder / "c.json"
    res = runner.invoke(app, ["constants", str(scene), str(folder / "spec.json"), "-o", str(out)])
    assert res.exit_code == 0, res.output
    return out


@pytest.fixture(scope="module")
def wall(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("wall")
    constants = _constants(folder, [("W", 0.0, B, H)])
    (folder / "site.json").write_text(json.dumps(SITE))
    (folder / "retrofit.spec.json").write_text(json.dumps(SPEC))
    return {
        "constants": constants,
        "site": folder / "site.json",
        "spec": folder / "retrofit.spec.json",
    }


@pytest.fixture(scope="module")
def wall_doc(wall: dict[str, Path]) -> dict[str, Any]:
    res = runner.invoke(
        app,
        ["retrofit", str(wall["constants"]), "--site", str(wall["site"]), "--spec",
         str(wall["spec"]), "--record", str(ELCENTRO), "--json"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    doc: dict[str, Any] = json.loads(res.stdout)
    return doc


def _hand_model(force: float) -> RockingModel:
    """The tied wall from theory §2.2, one-sided (see the module docstring)."""
    mass = RHO * B * H * L
    w = mass * G
    r = 0.5 * math.hypot(B, H)
    alpha = math.atan2(B, H)
    i_o = mass * (B * B + H * H) / 3.0
    lam = alpha + force * H_T * math.cos(alpha) / (w * r)
    eta = 1.0 - 2.0 * mass * r * r * math.cos(alpha) ** 2 / i_o
    side = RockingSide(math.sqrt(w * r / i_o), lam, lam)
    return RockingModel(positive=side, eta=eta, one_sided=True, name="W")


def test_the_wall_overturns_as_it_stands_and_the_design_scale_is_the_assessments(
    wall: dict[str, Path], wall_doc: dict[str, Any]
) -> None:
    (m,) = wall_doc["mechanisms"]
    (before,) = m["records_before"]
    assert before["survives_design"] is False and before["multiple"] < 1.0
    # The design scale is rockmech assess's, on the same record and site.
    assessed = rockmech.assess(wall["constants"], wall["site"], [ELCENTRO], multiples=[1.0])
    dyn = (assessed.mechanisms[0].dynamics or [])[0]
    assert dyn.scale_factor is not None
    assert before["design_scale"] == pytest.approx(dyn.scale_factor.value, rel=1e-12)
    assert dyn.survives_design is False
    assert wall_doc["records"][0]["name"] == "elcentro_NS"


def test_the_records_tie_force_flips_the_verdict_within_half_a_percent(
    wall_doc: dict[str, Any],
) -> None:
    (m,) = wall_doc["mechanisms"]
    opt = m["options"][m["chosen"]]
    (tie,) = opt["records"]
    t_star = tie["T_star_N"]
    assert t_star > 0.0 and opt["T_records_N"] == t_star
    assert tie["runs"] <= RUNS_PER_RECORD
    low, at, high = tie["flip"]
    assert low["force_N"] == pytest.approx(t_star * (1 - 0.005), rel=1e-12)
    assert high["force_N"] == pytest.approx(t_star * (1 + 0.005), rel=1e-12)
    assert (low["overturned"], at["overturned"], high["overturned"]) == (True, False, False)
    # The code checks need more here: T* is theirs, and the records survive at it too.
    assert opt["T_star_N"] >= t_star
    (after,) = opt["records_after"]
    assert after["survives_design"] is True and after["multiple"] > 1.0


def test_the_records_tie_force_agrees_with_a_bisection_by_the_reference_solver(
    wall_doc: dict[str, Any], elcentro_path: Path
) -> None:
    """A bisection on T with ``simulate_ivp`` and the hand model, to 0.5 %."""
    (m,) = wall_doc["mechanisms"]
    (before,) = m["records_before"]
    scale = before["design_scale"]
    motion = rockmech.read_record(elcentro_path)

    def survives(force: float) -> bool:
        res = simulate_ivp(_hand_model(force), motion.accel, scale=scale)
        return not res.overturned

    # The bracket: λ(T) from λ0 to twice λ0 s_d/s_ov, where the block responds as the
    # untied one to the record scaled by λ0/λ (the least overturning scale halved).
    alpha = math.atan2(B, H)
    w_r = RHO * B * H * L * G * 0.5 * math.hypot(B, H)
    per_lam = w_r / (H_T * math.cos(alpha))  # T per unit of λ [N]
    target = alpha * scale / before["overturning_scale"]
    lo, hi = 0.995 * (target - alpha) * per_lam, 1.005 * (target - alpha) * per_lam
    assert not survives(lo) and survives(hi)
    while hi - lo > 0.005 * hi:
        mid = 0.5 * (lo + hi)
        if survives(mid):
            hi = mid
        else:
            lo = mid
    t_doc = m["options"][m["chosen"]]["records"][0]["T_star_N"]
    assert t_doc == pytest.approx(hi, rel=0.01)
    # The reference's verdicts on the document's flip.
    assert survives(t_doc) and not survives(t_doc * (1 - 0.005))


def test_more_tie_force_never_lowers_the_overturning_scale(wall: dict[str, Path]) -> None:
    from solver_service.workflows.codecheck import check_doc
    from solver_service.workflows.retrofit import with_tie
    from solver_service.workflows.retrofit_records import MechanismRecords

    cf = rockmech.read_constants(wall["constants"])
    site = rockmech.read_site(wall["site"])
    motion = rockmech.read_record(ELCENTRO)
    (mech,) = cf.mechanisms
    recs = MechanismRecords(mech, check_doc(cf, site)["mechanisms"][0], [motion], site)
    forces = [0.0, 1e3, 3e3, 6e3, 1e4, 2e4, 4e4]
    found = [recs.scales(with_tie(mech, t, H_T, listed=False))[0] for t in forces]
    scales = [f.overturning_scale for f in found]
    assert all(s is not None for s in scales)
    assert scales == sorted(scales) and scales[-1] > 3.0 * scales[0]
    # For one block λ and φ_ov grow together: the scale grows as λ(T)/λ0 (to the grid's
    # bisection, 0.1 %), the hand model's λ.
    lam0 = _hand_model(0.0).positive.lam
    for t, s in zip(forces, scales):
        assert s == pytest.approx(scales[0] * _hand_model(t).positive.lam / lam0, rel=2e-3)
    # The margin over the design scale follows.
    assert [f.multiple for f in found] == sorted(f.multiple for f in found)


def test_the_records_come_from_the_spec_relative_to_its_folder(
    wall: dict[str, Path], wall_doc: dict[str, Any], tmp_path: Path
) -> None:
    (tmp_path / "rec").mkdir()
    (tmp_path / "rec" / "elcentro_NS.dat").write_bytes(ELCENTRO.read_bytes())
    spec = {**SPEC, "records": ["rec/elcentro_NS.dat"]}
    path = tmp_path / "r.json"
    path.write_text(json.dumps(spec))
    doc = rockmech.retrofit(wall["constants"], wall["site"], path)
    got = json.loads(doc.model_dump_json())
    assert got["mechanisms"][0]["options"] == wall_doc["mechanisms"][0]["options"]
    # A record the spec names that is not there: one line naming the field.
    path.write_text(json.dumps({**SPEC, "records": ["rec/none.dat"]}))
    res = runner.invoke(
        app, ["retrofit", str(wall["constants"]), "--site", str(wall["site"]), "--spec", str(path)]
    )
    assert res.exit_code == 2 and "Traceback" not in res.output
    (line,) = res.stderr.strip().splitlines()
    assert line.startswith("error: records[0]: file not found: rec/none.dat"), line


def test_records_past_the_budget_are_refused_up_front(wall: dict[str, Path]) -> None:
    from shared_schema.errors import InputError
    from shared_schema.retrofit import read_retrofit_spec
    from solver_service.workflows.limits import (
        RETROFIT_RECORD_RUNS,
        RETROFIT_SCALE_RUNS,
        check_retrofit_work,
        retrofit_record_runs,
    )

    cf = rockmech.read_constants(wall["constants"])
    site = rockmech.read_site(wall["site"])
    spec = read_retrofit_spec(wall["spec"])
    motion = rockmech.read_record(ELCENTRO)
    # One mechanism, one tie height: its scale as it stands, the search and the scale after.
    runs = RETROFIT_SCALE_RUNS + RETROFIT_RECORD_RUNS + RETROFIT_SCALE_RUNS
    assert retrofit_record_runs(cf, spec) == runs
    check_retrofit_work(cf, site, spec, 1.0, "more time", [motion])
    with pytest.raises(InputError) as err:
        check_retrofit_work(cf, site, spec, 1e-5, "more time", [motion])
    assert err.value.field == "spec"
    assert f"{runs} exact runs of each of 1 records" in str(err.value)
    # Without records, the same budget refuses only the code checks.
    with pytest.raises(InputError) as err:
        check_retrofit_work(cf, site, spec, 1e-5, "more time")
    assert "exact runs" not in str(err.value)


def test_the_estimate_counts_the_spectra_of_each_check_with_records(
    wall: dict[str, Path],
) -> None:
    """Each code check with records matches every record and takes its demand (40 + 40)."""
    from shared_schema.retrofit import read_retrofit_spec
    from solver_service.codes.circ2019 import RECORD_POINTS
    from solver_service.workflows.assess import BAND_POINTS
    from solver_service.workflows.limits import (
        RETROFIT_RECORD_PERIODS,
        check_retrofit_work,
        retrofit_checks,
        shortest_time,
    )

    assert RETROFIT_RECORD_PERIODS == BAND_POINTS + RECORD_POINTS
    cf = rockmech.read_constants(wall["constants"])
    site = rockmech.read_site(wall["site"])
    spec = read_retrofit_spec(wall["spec"])
    motion = rockmech.read_record(ELCENTRO)
    n = retrofit_checks(cf, site, spec)
    least = shortest_time(spectrum_steps=n * RETROFIT_RECORD_PERIODS * (motion.accel.n - 1))
    # A budget just under the spectra alone is refused; it names them.
    with pytest.raises(InputError) as err:
        check_retrofit_work(cf, site, spec, 0.99 * least, "more time", [motion])
    assert "sub-steps of response spectra" in str(err.value)


def test_tying_one_wall_moves_the_governing_mechanism_to_the_other(tmp_path: Path) -> None:
    """W (b/h = 1/12) governs; V (b/h = 1/5) cannot take its tie (above its top)."""
    constants = _constants(tmp_path, [("W", 0.0, B, H), ("V", 20.0, 0.8, 4.0)])
    site = tmp_path / "site.json"
    site.write_text(json.dumps({"hazard": {**SITE["hazard"], "a_g": 0.30}}))
    spec = tmp_path / "r.json"
    mechs = {"W": {"heights_m": [H_T]}, "V": {"heights_m": [10.0]}}
    spec.write_text(json.dumps({**SPEC, "mechanisms": mechs}))
    res = runner.invoke(app, ["retrofit", str(constants), "--site", str(site), "--spec", str(spec)])
    assert res.exit_code == 0, res.output
    doc = rockmech.retrofit(constants, site, spec)
    nxt = doc.governs_next
    assert nxt is not None
    assert (nxt.before, nxt.after, nxt.moved) == ("W", "V", True)
    v = doc.find("V")
    assert v.options[0].status == "above_moving_part" and v.chosen is None
    # V's linear ratio by hand: α0 = b/h over α0,req = e* FC a_g S/q (soil C, e* = 1).
    s_s = min(max(1.70 - 0.60 * 2.4 * 0.30, 1.0), 1.5)
    linear = (0.8 / 4.0) / (1.35 * 0.30 * s_s / 2.0)
    assert v.before.linear_ratio == pytest.approx(linear, rel=1e-9)
    assert nxt.after_margin is not None and nxt.after_margin <= linear + 1e-12
    rows = {r.id: r for r in nxt.rows}
    assert (
        rows["W"].tied
        and rows["W"].after_margin is not None
        and rows["W"].after_margin >= 1.0 - 1e-9
    )
    assert rows["V"].after_margin == rows["V"].before_margin == nxt.after_margin
    assert (
        f"with the ties in, of these mechanisms V governs: margin {nxt.after_margin:.3f}"
        in res.stdout
    )
    # The order of the mechanisms changes nothing.
    cf = rockmech.read_constants(constants)
    flipped = cf.model_copy(update={"mechanisms": cf.mechanisms[::-1]})
    again = rockmech.retrofit(flipped, site, spec).governs_next
    assert again is not None
    assert (again.before, again.after, again.after_margin) == ("W", "V", nxt.after_margin)
    assert {r.id: r for r in again.rows} == rows


def test_the_church_on_five_records(shared_records: Path) -> None:
    """The bundled church, El Centro and the four PEER records: every tie survives them."""
    records = [ELCENTRO, *sorted(shared_records.glob("*.AT2"))]
    assert len(records) == 5
    doc = rockmech.retrofit(CHURCH, CHURCH_SITE, CHURCH_SPEC, records=records)
    assert doc.records[0]["name"] == "elcentro_NS"
    for m in doc.mechanisms:
        assert len(m.records_before) == 5
        for o in m.options:
            for tie in o.records:
                assert tie.runs <= RUNS_PER_RECORD
            if o.status == "designed":
                assert all(r.survives_design for r in o.records_after)
                # More force never lowers a record's least overturning scale.
                for b, a in zip(m.records_before, o.records_after):
                    assert b.overturning_scale is not None and a.overturning_scale is not None
                    assert a.overturning_scale >= b.overturning_scale
    nxt = doc.governs_next
    assert nxt is not None and nxt.before == "F1" and nxt.after not in ("F1", "F2")


def test_the_search_goes_on_where_the_verdict_flips_back_just_above(
    wall: dict[str, Path],
) -> None:
    """A verdict that is not monotonic in T: survives in [1000, 1003) N and from 1100 N.

    The least force whose neighbours half a percent below and above read (overturns,
    survives, survives) is the first grid force at or above 1100 N; the search must not stop
    in the narrow window, where T*(1 + 0.005) overturns again.
    """
    from solver_service.workflows.retrofit_records import MechanismRecords, force_grid_ratio

    class Windowed(MechanismRecords):
        def _survives(self, rec: Any, with_tie: Any, force: float) -> bool:
            return 1000.0 <= force < 1003.0 or force >= 1100.0

    cf = rockmech.read_constants(wall["constants"])
    site = rockmech.read_site(wall["site"])
    recs = Windowed(cf.mechanisms[0], {"nonlinear": {"status": "none"}}, [], site)
    # Started at 1001.5 N, inside the window: it survives there and the force below does not.
    found, runs, flip = recs._search(None, None, 1001.5, 1e5, start_overturns=None)
    assert found is not None and 1100.0 <= found < 1100.0 * force_grid_ratio()
    assert [f["overturned"] for f in flip] == [True, False, False]
    assert flip[0]["force_N"] < 1100.0 and runs == recs.runs <= 3 * RUNS_PER_RECORD
    # Nothing up to the largest force: None.
    none, _, _ = recs._search(None, None, 10.0, 500.0, start_overturns=None)
    assert none is None


def test_the_table_gives_the_records_margin_before_and_after(
    wall: dict[str, Path], wall_doc: dict[str, Any]
) -> None:
    res = runner.invoke(
        app,
        ["retrofit", str(wall["constants"]), "--site", str(wall["site"]), "--spec",
         str(wall["spec"]), "--record", str(ELCENTRO)],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    (m,) = wall_doc["mechanisms"]
    before = m["records_before"][0]["multiple"]
    after = m["options"][m["chosen"]]["records_after"][0]["multiple"]
    assert before < 1.0 < after
    line = (
        f"  W: records' least overturning/design scale {before:.3f} (elcentro_NS) -> "
        f"{after:.3f} (elcentro_NS)"
    )
    assert line in res.stdout.splitlines()


def test_with_records_the_nonlinear_check_after_the_tie_is_the_assessments(
    tmp_path: Path,
) -> None:
    """With El Centro, each designed tie's nonlinear ratios are ``rockmech assess``'s.

    The assessment takes the nonlinear demand as the larger of the spectrum's and the
    records' (Circ. 2019 C8.7.1.2.1.8); the retrofit sizes the tie on the same demand, so
    the church's F1 and F2 with their ties at T* pass the assessment with the record.
    """
    doc = rockmech.retrofit(CHURCH, CHURCH_SITE, CHURCH_SPEC, records=[ELCENTRO])
    assert any("C8.7.1.2.1.8" in d for d in doc.decisions)
    cf = rockmech.read_constants(CHURCH)
    before = rockmech.assess(CHURCH, CHURCH_SITE, [ELCENTRO], multiples=[1.0]).to_dict()
    designed = [m for m in doc.mechanisms if m.status == "designed"]
    assert {m.id for m in designed} == {"F1", "F2"}
    for i, m in enumerate(doc.mechanisms):
        # The "before" of every mechanism is the assessment's, records' demand included.
        row = before["mechanisms"][i]
        assert row["id"] == m.id
        if row["nonlinear"].get("status") == "ok":
            assert m.before.SLV_ratio == pytest.approx(row["nonlinear"]["capacity_ratio"], rel=1e-9)
    for m in designed:
        assert m.chosen is not None
        o = m.options[m.chosen]
        assert o.T_star_N is not None and o.after is not None and o.verified
        mechs = [
            with_tie(x, o.T_star_N, o.height_m, listed=False) if x.id == m.id else x
            for x in cf.mechanisms
        ]
        tied = tmp_path / f"tied_{m.id}.json"
        tied.write_text(cf.model_copy(update={"mechanisms": mechs}).model_dump_json())
        after = rockmech.assess(tied, CHURCH_SITE, [ELCENTRO], multiples=[1.0]).to_dict()
        (row,) = [r for r in after["mechanisms"] if r["id"] == m.id]
        non = row["nonlinear"]
        assert o.after.SLV_ratio == pytest.approx(non["capacity_ratio"], rel=1e-9, abs=0)
        assert o.after.SLC_ratio == pytest.approx(non["SLC"]["capacity_ratio"], rel=1e-9)
        assert non["capacity_ratio"] >= 1.0 and non["SLC"]["capacity_ratio"] >= 1.0
        # The records raise the demand: the spectrum alone would give a higher ratio.
        alone = rockmech.retrofit(CHURCH, CHURCH_SITE, CHURCH_SPEC).find(m.id)
        assert alone.before.SLV_ratio is not None and m.before.SLV_ratio is not None
        assert m.before.SLV_ratio <= alone.before.SLV_ratio
