"""``rockmech retrofit``: the real command on a free wall and on the bundled church.

The free wall: b = 0.5 m thick (x), L = 4 m long (y), h = 6 m high, 1800 kg/m³, drawn as a
.3dm scene and turned into constants by ``rockmech constants``; it rocks one-sided about its
outer toe (x = 0). Its least tie force for the linear check at h_t = 5 m, worked here from
the clauses (not from the code):

* [C8.7.1.1], at rest, a tie T at h_t opposing the rotation: α0(T) = (W b/2 + T h_t)/(W h/2);
* [C8.7.1.5], one block, the code check's default: e* = 1;
* [C8.7.1.8] a0* = α0 g/(e* FC), and C8.7.1.2.1.7 a_g,SLV = q a_g,SLD: the check passes when
  a0* ≥ a_g S/q (the demand at the ground, NTC 2018 [3.2.2] at T = 0);
* NTC 2018 Tab. 3.2.IV, soil C: S_S = 1.70 − 0.60 F0 a_g/g within [1.00, 1.50]; Tab. 3.2.V,
  T1: S_T = 1;
* so T* = W (α0,req h − b)/(2 h_t) with α0,req = e* FC a_g S/q.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import pytest
from search.search_scenes import BUILD
from typer.testing import CliRunner

import rockmech
from solver_service.cli import app

runner = CliRunner()
REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
CHURCH = EXAMPLES / "constants" / "church_geometry.json"
CHURCH_SITE = EXAMPLES / "sites" / "ntc_site.json"
CHURCH_SPEC = EXAMPLES / "specs" / "church.retrofit.json"

G = 9.80665
B, L, H, RHO, H_T = 0.5, 4.0, 6.0, 1800.0, 5.0
A_G, F0, TC, FC, Q = 0.30, 2.4, 0.3, 1.35, 2.0
SITE = {"hazard": {"code": "NTC2018", "a_g": A_G, "F0": F0, "Tc_star": TC, "soil": "C", "FC": FC}}
SPEC: dict[str, Any] = {
    "steel": {"grade": "S275", "diameters_mm": [10, 12, 16, 20]},
    "anchorage": {"capacity_N": 60000.0, "source": "plate punching, designer's calculation"},
    "mechanisms": {"W": {"heights_m": [H_T], "length_m": 8.0}},
}


def _hand_t_star() -> float:
    w = RHO * G * B * H * L  # weight [N]
    s_s = min(max(1.70 - 0.60 * F0 * A_G, 1.0), 1.5)  # Tab. 3.2.IV, soil C
    alpha_req = 1.0 * FC * A_G * s_s * 1.0 / Q  # e* = 1, S_T = 1
    return w * (alpha_req * H - B) / (2.0 * H_T)


@pytest.fixture(scope="module")
def wall(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The free wall's constants (``rockmech constants``), site and spec files."""
    folder = tmp_path_factory.mktemp("wall")
    bld = BUILD.Builder("wall")
    bld.box("wall", "Walls", (0, 0, 0), (B, L, H), "brick")
    bld.line("axis", "Axes", (0, 0, 0), (0, L, 0))
    scene = Path(bld.write(folder / "wall.3dm"))
    mech = {
        "id": "W",
        "groups": [{"objects": ["wall"], "density": RHO}],
        "axis": {"object": "axis"},
        "rocking": "one_sided",
    }
    (folder / "wall.spec.json").write_text(json.dumps({"mechanisms": [mech]}))
    constants = folder / "c.json"
    res = runner.invoke(
        app, ["constants", str(scene), str(folder / "wall.spec.json"), "-o", str(constants)]
    )
    assert res.exit_code == 0, res.output
    (folder / "site.json").write_text(json.dumps(SITE))
    (folder / "retrofit.spec.json").write_text(json.dumps(SPEC))
    return {
        "constants": constants,
        "site": folder / "site.json",
        "spec": folder / "retrofit.spec.json",
    }


def _args(files: dict[str, Path], *extra: str) -> list[str]:
    return ["retrofit", str(files["constants"]), "--site", str(files["site"]),
            "--spec", str(files["spec"]), *extra]  # fmt: skip


def test_free_wall_t_star_is_the_closed_form(wall: dict[str, Path], tmp_path: Path) -> None:
    out = tmp_path / "out"
    res = runner.invoke(app, _args(wall, "--out", str(out), "--json"))
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    (m,) = doc["mechanisms"]
    opt = m["options"][m["chosen"]]
    assert m["status"] == "designed" and opt["governing"] == "linear SLV"
    assert opt["e_star"] == pytest.approx(1.0, rel=1e-12)
    t_hand = _hand_t_star()
    assert t_hand == pytest.approx(22042.0, rel=1e-3)  # the figure of the hand case above
    assert opt["T_star_N"] == pytest.approx(t_hand, rel=1e-6)
    # NTC 2018 [4.2.6], S275 f_yk = 275 N/mm², γ_M0 = 1.05: Ø10 carries 20.6 kN < T*, Ø12 29.6 kN.
    assert opt["bar"]["diameter_mm"] == 12.0
    assert opt["bar"]["N_pl_Rd_N"] == pytest.approx(math.pi * 36.0 * 275.0 / 1.05, rel=1e-12)
    assert opt["after"]["linear_ratio"] == pytest.approx(1.0, abs=1e-6)
    # The file is the document --json printed, byte for byte.
    assert (out / "retrofit.json").read_text(encoding="utf-8") == res.stdout


def test_the_file_is_the_python_apis_document(wall: dict[str, Path], tmp_path: Path) -> None:
    res = runner.invoke(app, _args(wall, "--out", str(tmp_path)))
    assert res.exit_code == 0, res.output
    api = rockmech.retrofit(wall["constants"], wall["site"], wall["spec"])
    assert (tmp_path / "retrofit.json").read_bytes() == (
        api.model_dump_json(indent=2) + "\n"
    ).encode("utf-8")


def test_the_document_is_stamped_like_every_other(wall: dict[str, Path]) -> None:
    from shared_schema.version import __version__
    from solver_service.workflows.retrofit_files import parse_retrofit_doc
    from solver_service.workflows.units import DOCUMENT_UNITS

    res = runner.invoke(app, _args(wall, "--json"))
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    # The version and the units first, as ``workflows.units.stamp`` puts them.
    assert list(doc)[:2] == ["rockmech_version", "units"]
    assert doc["rockmech_version"] == __version__
    assert doc["units"] == DOCUMENT_UNITS["retrofit"]
    assert doc["units"]["T_star_N"] == "N" and doc["units"]["f_yk"] == "N/mm2"
    # Every number whose name does not end in its unit has one in the block (counts aside).
    unnamed: set[str] = set()

    def walk(value: Any, key: str = "") -> None:
        if isinstance(value, dict):
            for k, v in value.items():
                walk(v, key if k.isdigit() else k)  # f_yk per diameter: {"12": 275.0}
        elif isinstance(value, list):
            for v in value:
                walk(v, key)
        elif isinstance(value, float):
            unnamed.add(key)

    walk({k: v for k, v in doc.items() if k != "units"})
    assert unnamed and unnamed <= set(doc["units"]), unnamed - set(doc["units"])
    # Read back as a retrofit document, the stamp kept.
    back = parse_retrofit_doc(res.stdout)
    assert back.rockmech_version == __version__ and back.units == doc["units"]


def test_the_table_names_the_tie_and_the_ratios(wall: dict[str, Path]) -> None:
    res = runner.invoke(app, _args(wall))
    assert res.exit_code == 0, res.output
    lines = res.stdout.splitlines()
    assert lines[0].split() == ["mechanism", "status", "h_t", "[m]", "T*", "[kN]", "governs",
                                "bars", "least", "a_g", "ratio"]  # fmt: skip
    row = lines[1].split()
    assert row[:3] == ["W", "designed", "5"]
    assert float(row[3]) == pytest.approx(_hand_t_star() / 1e3, rel=1e-3)
    assert row[4:8] == ["linear", "SLV", "1", "Ø12"]
    # The linear check governs T*: its ratio goes from b/h / α0,req (Ø12: to 1).
    alpha_req = FC * A_G * min(max(1.70 - 0.60 * F0 * A_G, 1.0), 1.5) / Q
    before = float(row[-3])
    assert before <= (B / H) / alpha_req + 5e-4 and row[-1] == "1.000"
    assert "1 Ø12 S275 tie at 5 m" in res.stdout and "makes W pass" in res.stdout


def test_the_church_is_retrofitted_from_the_bundled_files(tmp_path: Path) -> None:
    res = runner.invoke(
        app,
        ["retrofit", str(CHURCH), "--site", str(CHURCH_SITE), "--spec", str(CHURCH_SPEC),
         "-o", str(tmp_path), "--json"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    doc = rockmech.retrofit(CHURCH, CHURCH_SITE, CHURCH_SPEC)
    assert res.stdout == doc.model_dump_json(indent=2) + "\n"
    status = {m.id: m.status for m in doc.mechanisms}
    assert status == {"F1": "designed", "F2": "designed", "A1": "not_applicable",
                      "T1": "not_applicable"}  # fmt: skip
    f1 = doc.find("F1")
    tie = f1.options[f1.chosen or 0]
    # Two bars share T* equally; each one's force is checked against the bar and anchorage.
    assert tie.bars == 2 and tie.bar is not None and tie.T_star_N is not None
    assert tie.bar.force_N == pytest.approx(tie.T_star_N / 2, rel=1e-12)
    # 2 bars x 6.2 m of Ø16 at 7850 kg/m³.
    assert tie.steel_mass_kg == pytest.approx(2 * math.pi * 0.016**2 / 4 * 6.2 * 7850, rel=1e-12)


def test_only_retrofit_json_is_replaced_in_the_folder(
    wall: dict[str, Path], tmp_path: Path
) -> None:
    # An earlier run's outputs (rockmech check's document is not a file; use envelope's).
    env = runner.invoke(app, ["envelope", str(CHURCH), "--out", str(tmp_path), "--n", "5"])
    assert env.exit_code == 0, env.output
    (tmp_path / "notes.txt").write_text("mine")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    res = runner.invoke(app, _args(wall, "--out", str(tmp_path)))
    assert res.exit_code == 0, res.output
    after = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    assert set(after) == set(before) | {"retrofit.json"}
    assert all(after[k] == v for k, v in before.items())
    # Run again: its own file is replaced, the others stay.
    assert runner.invoke(app, _args(wall, "--out", str(tmp_path))).exit_code == 0
    assert {p.name for p in tmp_path.iterdir() if p.is_file()} == set(after)


def test_a_users_retrofit_json_is_never_replaced(wall: dict[str, Path], tmp_path: Path) -> None:
    (tmp_path / "retrofit.json").write_text("my notes")
    res = runner.invoke(app, _args(wall, "--out", str(tmp_path)))
    assert res.exit_code == 2
    assert "not written by rockmech" in res.output and "Traceback" not in res.output
    assert (tmp_path / "retrofit.json").read_text() == "my notes"


def _bad(wall: dict[str, Path], tmp_path: Path, change: Any) -> Any:
    spec = json.loads(json.dumps(SPEC))
    change(spec)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(spec))
    return runner.invoke(app, _args({**wall, "spec": path}))


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (lambda s: s["anchorage"].update(capacity_N=-5.0), "anchorage.capacity_N"),
        (lambda s: s["anchorage"].update(capacity_N=1e12), "anchorage.capacity_N"),
        (lambda s: s["anchorage"].pop("source"), "anchorage.source: Field required"),
        (lambda s: s["steel"].update(grade="S460"), "steel.grade"),
        (lambda s: s["mechanisms"].update(F9={}), "mechanisms.F9: no mechanism 'F9'"),
        (lambda s: s["mechanisms"]["W"].update(heights_m=[-1.0]), "mechanisms.W.heights_m"),
        (lambda s: s["mechanisms"]["W"].update(bars=0), "mechanisms.W.bars"),
        (lambda s: s.update(colour="red"), "colour"),
    ],
    ids=[
        "negative_anchorage",
        "absurd_anchorage",
        "no_source",
        "grade",
        "unknown_mechanism",
        "negative_height",
        "no_bars",
        "unknown_field",
    ],
)
def test_bad_spec_is_one_line_naming_the_field(
    wall: dict[str, Path], tmp_path: Path, change: Any, words: str
) -> None:
    res = _bad(wall, tmp_path, change)
    assert res.exit_code == 2, res.output
    assert res.stdout == ""
    (line,) = res.stderr.strip().splitlines()
    assert line.startswith("error: ") and words in line, line


def test_missing_files_and_swapped_arguments(wall: dict[str, Path], tmp_path: Path) -> None:
    res = runner.invoke(app, _args({**wall, "constants": tmp_path / "none.json"}))
    assert res.exit_code == 2 and "error: constants: file not found" in res.stderr
    res = runner.invoke(app, _args({**wall, "site": wall["spec"]}))
    assert res.exit_code == 2 and res.stderr.startswith("error: ") and "Traceback" not in res.output
    res = runner.invoke(app, ["retrofit", str(wall["constants"]), "--site", str(wall["site"])])
    assert res.exit_code == 2 and "--spec: missing option" in res.stderr


def test_work_past_the_time_limit_is_refused_up_front(
    wall: dict[str, Path], tmp_path: Path
) -> None:
    spec = json.loads(json.dumps(SPEC))
    spec["mechanisms"]["W"]["heights_m"] = [1.0 + 0.25 * k for k in range(20)]
    path = tmp_path / "many.json"
    path.write_text(json.dumps(spec))
    # 20 heights x (1 check after + 7 bisection steps at SLV) = 160 checks: at twice the
    # measured 1.4e3 checks/s, 0.057 s at the least.
    res = runner.invoke(app, _args({**wall, "spec": path}, "--time-limit", "0.01"))
    assert res.exit_code == 2
    assert "error: spec: the retrofit plans 160 code checks" in res.stderr
    assert "--no-limits" in res.stderr
    lifted = runner.invoke(app, _args({**wall, "spec": path}, "--no-limits"))
    assert lifted.exit_code == 0, lifted.output


def test_the_planned_bisection_steps_follow_the_retrofits_tolerance() -> None:
    from solver_service.workflows.limits import RETROFIT_BISECTION_STEPS
    from solver_service.workflows.retrofit import T_REL_TOL

    # The bracket halves from half its passing end down to T_REL_TOL of it.
    assert math.ceil(math.log2(0.5 / T_REL_TOL)) == RETROFIT_BISECTION_STEPS


def test_the_rate_of_the_checks_is_the_one_the_benchmark_recorded() -> None:
    from solver_service.workflows.limits import RETROFIT_CHECKS_PER_S

    text = (REPO / "docs" / "benchmarks.md").read_text(encoding="utf-8")
    section = text.split("<!-- BEGIN retrofit -->", 1)[1].split("<!-- END retrofit -->")[0]
    match = re.search(r"([0-9.e+-]+) /s \(`RETROFIT_CHECKS_PER_S`\)", section)
    assert match is not None, section
    assert float(f"{float(match.group(1)):.2g}") == RETROFIT_CHECKS_PER_S
