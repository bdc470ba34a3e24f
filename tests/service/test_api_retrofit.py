"""``POST /api/v1/retrofit`` over HTTP, against ``rockmech retrofit`` on the same files.

The reference is the command line run in-process on the bundled church (constants, site,
retrofit spec): the answer must be the bytes of the ``retrofit.json`` it writes, not close
numbers. The free wall's hand case (``T*`` in closed form from [C8.7.1.1]) is in
tests/test_cli_retrofit.py; here the wall's numbers are checked once more through the
service, and bad input must be a 422 naming the field of the request, never a 5xx.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_helpers import EXAMPLES, runner
from search.search_scenes import BUILD

from shared_schema.constants import parse_constants
from shared_schema.errors import InputError
from shared_schema.retrofit import parse_retrofit_spec
from shared_schema.site import parse_site
from solver_service.api.jobs import run_job
from solver_service.api.jobspec import RetrofitJob, check_job
from solver_service.cli import app

CHURCH = EXAMPLES / "constants" / "church_geometry.json"
SITE = EXAMPLES / "sites" / "ntc_site.json"
SPEC = EXAMPLES / "specs" / "church.retrofit.json"
URL = "/api/v1/retrofit"


def _json(path: Path) -> Any:
    return json.loads(path.read_text(encoding="utf-8"))


def _body(**change: Any) -> dict[str, Any]:
    return {"constants": _json(CHURCH), "site": _json(SITE), "spec": _json(SPEC), **change}


def test_the_answer_is_the_clis_retrofit_json_byte_for_byte(
    client: httpx.Client, tmp_path: Path
) -> None:
    res = client.post(URL, json=_body())
    assert res.status_code == 200, res.text
    assert res.headers["content-type"].startswith("application/json")
    out = tmp_path / "out"
    cli = runner.invoke(
        app,
        ["retrofit", str(CHURCH), "--site", str(SITE), "--spec", str(SPEC), "-o", str(out)],
    )
    assert cli.exit_code == 0, cli.output
    assert res.content == (out / "retrofit.json").read_bytes()
    doc = res.json()
    status = {m["id"]: m["status"] for m in doc["mechanisms"]}
    assert status == {"F1": "designed", "F2": "designed", "A1": "not_applicable",
                      "T1": "not_applicable"}  # fmt: skip
    f1 = next(m for m in doc["mechanisms"] if m["id"] == "F1")
    tie = f1["options"][f1["chosen"]]
    # Two bars share T*; each bar's force is the N_Ed of NTC 2018 [4.2.5] against A f_yk/γ_M0.
    bar = tie["bar"]
    assert tie["bars"] == 2 and bar["force_N"] == pytest.approx(tie["T_star_N"] / 2, rel=1e-12)
    area = math.pi * bar["diameter_mm"] ** 2 / 4.0
    assert bar["N_pl_Rd_N"] == pytest.approx(area * 275.0 / 1.05, rel=1e-12)
    assert tie["after"]["linear_ratio"] >= 1.0 and tie["after"]["SLV_ratio"] >= 1.0


def test_a_free_wall_through_the_service_is_the_hand_case(
    client: httpx.Client, tmp_path: Path
) -> None:
    # One brick block 0.5 x 4 x 6 m, 1800 kg/m³, about its outer toe, its constants made by
    # ``rockmech constants`` from a drawn scene; a tie at h_t = 5 m.
    b, length, h, h_t = 0.5, 4.0, 6.0, 5.0
    bld = BUILD.Builder("wall")
    bld.box("wall", "Walls", (0, 0, 0), (b, length, h), "brick")
    bld.line("axis", "Axes", (0, 0, 0), (0, length, 0))
    scene = Path(bld.write(tmp_path / "wall.3dm"))
    mech = {"id": "W", "groups": [{"objects": ["wall"], "density": 1800.0}],
            "axis": {"object": "axis"}, "rocking": "one_sided"}  # fmt: skip
    (tmp_path / "wall.spec.json").write_text(json.dumps({"mechanisms": [mech]}))
    made = runner.invoke(
        app, ["constants", str(scene), str(tmp_path / "wall.spec.json"), "-o", str(tmp_path / "c")]
    )
    assert made.exit_code == 0, made.output
    site = {"hazard": {"code": "NTC2018", "a_g": 0.3, "F0": 2.4, "Tc_star": 0.3, "soil": "C",
                       "FC": 1.35}}  # fmt: skip
    spec = {
        "steel": {"grade": "S275", "diameters_mm": [10, 12, 16, 20]},
        "anchorage": {"capacity_N": 60000.0, "source": "plate punching, designer's calc."},
        "mechanisms": {"W": {"heights_m": [h_t]}},
    }
    body = {"constants": _json(tmp_path / "c"), "site": site, "spec": spec}
    res = client.post(URL, json=body)
    assert res.status_code == 200, res.text
    (m,) = res.json()["mechanisms"]
    opt = m["options"][m["chosen"]]
    # [C8.7.1.1] α0(T) = (W b/2 + T h_t)/(W h/2); Tab. 3.2.IV soil C: S_S = 1.70 − 0.60·2.4·0.3
    # = 1.268, S_T = 1 (T1); [C8.7.1.5] e* = 1 (one block); the check passes at
    # α0 g/(e* FC) = a_g S/q, so T* = W (α0,req h − b)/(2 h_t), α0,req = e* FC a_g S/q.
    w = 1800.0 * 9.80665 * b * length * h
    alpha_req = 1.0 * 1.35 * 0.3 * 1.268 / 2.0
    t_hand = w * (alpha_req * h - b) / (2.0 * h_t)
    assert t_hand == pytest.approx(22042.0, rel=1e-3)
    assert opt["governing"] == "linear SLV" and opt["e_star"] == pytest.approx(1.0)
    assert opt["T_star_N"] == pytest.approx(t_hand, rel=1e-6)
    assert opt["bar"]["diameter_mm"] == 12.0  # Ø10 carries 20.6 kN < T*, Ø12 29.6 kN


@pytest.mark.parametrize(
    ("change", "field", "words"),
    [
        (lambda b: b["spec"]["steel"].update(grade="S460"), "spec.steel.grade", "S235"),
        (lambda b: b["spec"]["anchorage"].pop("source"), "spec.anchorage.source", "required"),
        (
            lambda b: b["spec"]["anchorage"].update(capacity_N=-5.0),
            "spec.anchorage.capacity_N",
            "greater than 0",
        ),
        (
            lambda b: b["spec"]["mechanisms"].update(F9={}),
            "spec.mechanisms.F9",
            "no mechanism 'F9' in the constants",
        ),
        (
            lambda b: b["spec"]["mechanisms"]["F1"].update(heights_m=[-1.0]),
            "spec.mechanisms.F1.heights_m",
            "outside",
        ),
        (
            lambda b: b["site"].update(local_mechanisms={"method": "circ2009"}),
            "site.local_mechanisms.method",
            "circ2019",
        ),
        (lambda b: b.pop("spec"), "spec", "required"),
    ],
    ids=[
        "grade",
        "no_source",
        "negative_anchorage",
        "unknown_mechanism",
        "negative_height",
        "method",
        "no_spec",
    ],
)
def test_bad_input_is_a_422_naming_the_field(
    client: httpx.Client, change: Any, field: str, words: str
) -> None:
    body = _body()
    change(body)
    res = client.post(URL, json=body)
    assert res.status_code == 422, res.text
    doc = res.json()
    assert doc["field"] == field, doc
    assert words in doc["detail"], doc


def test_a_body_that_is_not_json_or_empty_is_a_422(client: httpx.Client) -> None:
    res = client.post(URL, content=b"", headers={"content-type": "application/json"})
    assert res.status_code == 422 and "constants, site and spec" in res.json()["detail"]
    res = client.post(URL, content=b"{", headers={"content-type": "application/json"})
    assert res.status_code == 422


def _job(**spec_change: Any) -> RetrofitJob:
    spec = {**_json(SPEC), **spec_change}
    return RetrofitJob(
        constants=parse_constants(_json(CHURCH)),
        site=parse_site(SITE.read_bytes()),
        spec=parse_retrofit_spec(spec),
    )


def test_work_past_the_budget_is_refused_up_front() -> None:
    # F1's 2 heights and one default height for F2, A1, T1 = 5 options x (1 check after + 7
    # bisection steps at SLV + 7 at SLC): the site gives the SLC, so 75 checks, 0.125 s at
    # least at twice the measured 1.2e3 checks/s.
    limits = {"budget_s": 0.01, "max_mechanisms": 20}
    with pytest.raises(InputError) as info:
        check_job(_job(), limits)
    assert info.value.field == "spec"
    assert "the retrofit plans 75 code checks" in str(info.value)
    assert "ROCKMECH_COMPUTE_TIMEOUT_S" in str(info.value)
    check_job(_job(), {**limits, "budget_s": 30.0})  # the default budget takes it
    # The compute process answers it as the app would have.
    out = run_job(_job(), [], {**limits, "budget_s": 30.0})
    assert out.status == 200 and json.loads(out.body)["rockmech_version"]
