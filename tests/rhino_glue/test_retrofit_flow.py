"""RM_Retrofit: the command's flow on the bundled church, against ``rockmech retrofit``.

The flow is what the Rhino command runs beneath its glue (which only draws the marks as
lines and text dots): it asks for the three files, writes ``<model>.retrofit/retrofit.json``
(the bytes ``rockmech retrofit`` writes), prints the sentences and places each designed
tie's bars. The bars' places are worked here from the constants' geometry: the church's F1
hinge runs from (0, 0, 0) along +y, its centre of mass is at x = 0.297, y = 3.0 m, so the
wall is 6 m long and inward is +x; the spec puts 2 bars 6.2 m long at 8 m (the higher of its
two heights, which needs the less force).
"""

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rhino_plugin.flows.retrofit import RETROFIT_LAYER, retrofit_flow, retrofit_lines
from shared_schema.errors import InputError
from solver_service.cli import app

from .conftest import ScriptedPrompter

ROOT = Path(__file__).resolve().parents[2]
CHURCH = ROOT / "examples" / "constants" / "church_geometry.json"
SITE = ROOT / "examples" / "sites" / "ntc_site.json"
SPEC = ROOT / "examples" / "specs" / "church.retrofit.json"
FILES = [("get_file", str(CHURCH)), ("get_file", str(SITE)), ("get_file", str(SPEC))]


def test_the_flow_writes_rockmech_retrofits_file_and_places_the_bars(tmp_path: Path) -> None:
    ask = ScriptedPrompter(None, FILES)
    # A model in millimetres: 1 model unit = 0.001 m.
    result = retrofit_flow(ask, str(tmp_path), stem="church", unit_scale=0.001)
    assert ask.done()
    out = tmp_path / "church.retrofit" / "retrofit.json"
    assert result.files == [str(out)]
    cli = CliRunner().invoke(
        app,
        ["retrofit", str(CHURCH), "--site", str(SITE), "--spec", str(SPEC), "-o",
         str(tmp_path / "cli")],
    )  # fmt: skip
    assert cli.exit_code == 0, cli.output
    assert out.read_bytes() == (tmp_path / "cli" / "retrofit.json").read_bytes()
    assert ask.messages[0] == f"RM_Retrofit: 4 mechanism(s) via the Python API; wrote {out}"
    assert ask.messages[1:] == retrofit_lines(result.doc) == result.summary
    assert result.summary[0].startswith("2 Ø16 S275 ties at 8 m, 15.1 kN each, make F1 pass")
    f1 = result.doc.find("F1")
    t_bar = f1.options[f1.chosen or 0].T_star_N / 2 / 1e3  # type: ignore[operator]
    f1_marks = [m for m in result.marks if m.label.startswith("F1 ")]
    assert [m.label for m in f1_marks] == [
        f"F1 tie 1/2: Ø16 S275, {t_bar:.3g} kN",
        f"F1 tie 2/2: Ø16 S275, {t_bar:.3g} kN",
    ]
    # In mm: anchorages on the outer face (x = 0) at 8 m, at a quarter and three quarters of
    # the 6 m wall; each bar 6.2 m inward (+x).
    for mark, y in zip(f1_marks, (1500.0, 4500.0)):
        (a, b) = mark.points
        assert a == pytest.approx((0.0, y, 8000.0), abs=1e-6)
        assert b == pytest.approx((6200.0, y, 8000.0), abs=1e-6)
    # F2: one bar at the default height (the top of the moving part), centred on its G.
    (f2,) = [m for m in result.marks if m.label.startswith("F2 ")]
    geo = json.loads(CHURCH.read_text())["mechanisms"][1]["geometry"]
    h2 = result.doc.find("F2").options[0].height_m
    assert f2.points[0] == pytest.approx((0.0, geo["com_m"][1] * 1e3, h2 * 1e3), abs=1e-6)
    assert f2.points[1][0] == pytest.approx(6200.0)
    # A1 and T1 get no tie: nothing drawn for them.
    assert {m.label.split()[0] for m in result.marks} == {"F1", "F2"}
    assert RETROFIT_LAYER == "rockmech retrofit"


def test_the_flow_runs_on_the_service_with_the_same_answer(server: object, tmp_path: Path) -> None:
    local = retrofit_flow(ScriptedPrompter(None, FILES), str(tmp_path / "a"), stem="church")
    ask = ScriptedPrompter(None, FILES)
    remote = retrofit_flow(
        ask,
        str(tmp_path / "b"),
        stem="church",
        service_url=server.url,  # type: ignore[attr-defined]
    )
    assert remote.doc == local.doc and remote.marks == local.marks
    assert "via the service" in ask.messages[0]
    a = (tmp_path / "a" / "church.retrofit" / "retrofit.json").read_bytes()
    assert (tmp_path / "b" / "church.retrofit" / "retrofit.json").read_bytes() == a


def test_a_bad_spec_names_the_field_and_writes_nothing(tmp_path: Path) -> None:
    spec = json.loads(SPEC.read_text())
    spec["steel"]["grade"] = "S460"
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(spec))
    ask = ScriptedPrompter(None, [FILES[0], FILES[1], ("get_file", str(bad))])
    with pytest.raises(InputError) as info:
        retrofit_flow(ask, str(tmp_path), stem="church")
    assert info.value.field == "steel.grade"
    assert not (tmp_path / "church.retrofit").exists()
