"""The command line, the REST service, tables and site files share each range (issue #25).

For every range issue #25 touched, the bound comes from ``shared_schema.rules``: the REST
schema states it, and at the bound itself both front ends accept the value, one step past
it both refuse it with the same words (``rockmech check``/``envelope`` in-process against
``POST /check``/``/envelope`` on the corpus's real server). A range moved in ``rules.py``
moves everywhere, or this test fails.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import httpx
import pytest
from typer.testing import CliRunner

from shared_schema import rules
from solver_service.cli import app

REPO = Path(__file__).resolve().parents[2]
CHURCH_GEOMETRY = REPO / "examples" / "constants" / "church_geometry.json"
SITE = json.loads((REPO / "examples" / "sites" / "ntc_site.json").read_text())
runner = CliRunner()


def _cli(argv: list[str]) -> tuple[int, str]:
    """Exit status and the reason after the field of ``rockmech ARGV``'s error ('' if none)."""
    res = runner.invoke(app, argv)
    assert res.exception is None or isinstance(res.exception, SystemExit), res.output
    assert "Traceback" not in res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("error: ")]
    return res.exit_code, lines[0] if lines else ""


def _rest(client: httpx.Client, endpoint: str, body: dict[str, Any]) -> tuple[int, str]:
    res = client.post(f"/api/v1/{endpoint}", json=body)
    assert res.status_code < 500, res.text
    return res.status_code, "" if res.status_code == 200 else str(res.json()["detail"])


def _reason(message: str) -> str:
    """The words of a range error from "must be" on, the same on both front ends."""
    found = re.search(r"must be .*", message)
    assert found, message
    return found.group(0)


def _around(bounds: tuple[float, float]) -> list[tuple[float, bool]]:
    """Both bounds (accepted) and the next double outside each (refused)."""
    lo, hi = bounds
    return [
        (lo, True),
        (hi, True),
        (math.nextafter(lo, -math.inf), False),
        (math.nextafter(hi, math.inf), False),
    ]


def _schema(client: httpx.Client, model: str) -> dict[str, Any]:
    """The properties of ``model``'s schema in the service's OpenAPI document."""
    schemas = client.get("/api/v1/openapi.json").json()["components"]["schemas"]
    names = [k for k in schemas if k == model or k.startswith(f"{model}-")]
    assert names, sorted(schemas)
    return dict(schemas[names[0]]["properties"])


@pytest.mark.parametrize(
    ("field", "bounds"),
    [("q", rules.BEHAVIOUR_FACTOR_RANGE), ("xi_percent", rules.DAMPING_PERCENT_RANGE)],
)
def test_site_ranges_are_the_rules_on_cli_and_rest(
    field: str, bounds: tuple[float, float], client: httpx.Client, tmp_path: Path
) -> None:
    for model in ("NTCHazard", "EC8Hazard"):
        prop = _schema(client, model)[field]
        assert (prop["minimum"], prop["maximum"]) == bounds
    constants = json.loads(CHURCH_GEOMETRY.read_text())
    for value, accepted in _around(bounds):
        site = json.loads(json.dumps(SITE))
        site["hazard"][field] = value
        path = tmp_path / "site.json"
        path.write_text(json.dumps(site))
        code, cli_error = _cli(["check", str(CHURCH_GEOMETRY), str(path), "--json"])
        status, rest_error = _rest(client, "check", {"constants": constants, "site": site})
        if accepted:
            assert (code, status) == (0, 200), (value, cli_error, rest_error)
            continue
        assert (code, status) == (2, 422), value
        assert f"hazard.NTC2018.{field}: must be in [{bounds[0]:g}, {bounds[1]:g}]" in cli_error
        assert f"hazard.NTC2018.{field}" in rest_error
        assert _reason(cli_error) == _reason(rest_error)


def _envelope_cases(tmp_path: Path, side: dict[str, float]) -> list[list[str]]:
    """``rockmech envelope`` on one short-form mechanism, from a JSON file and from a table."""
    mech = {"id": "W", **side, "eta": 0.9}
    json_path = tmp_path / "c.json"
    json_path.write_text(json.dumps({"mechanisms": [mech]}))
    table = tmp_path / "c.csv"
    table.write_text(",".join(mech) + "\n" + ",".join(str(v) for v in mech.values()) + "\n")
    out = str(tmp_path / "env")
    return [["envelope", str(p), "--out", out, "--n", "5"] for p in (json_path, table)]


@pytest.mark.parametrize(
    ("key", "bounds", "base"),
    [
        ("p_eq", rules.P_EQ_RANGE, {"lam": 0.2}),
        ("lam", rules.LAM_RANGE, {"p_eq": 2.0, "phi_ov": 0.2}),
        ("phi_ov", (0.0, rules.ROTATION_MAX), {"p_eq": 2.0, "lam": 0.2}),
    ],
)
def test_constants_ranges_are_the_rules_on_cli_tables_and_rest(
    key: str,
    bounds: tuple[float, float],
    base: dict[str, float],
    client: httpx.Client,
    tmp_path: Path,
) -> None:
    if key == "phi_ov":
        # stated for the short form, whose phi_ov is given (the physical form derives it)
        schemas = client.get("/api/v1/openapi.json").json()["components"]["schemas"]
        short = schemas[next(k for k in schemas if "SideConstants" in k)]["oneOf"][1]
        stated = [b["properties"]["phi_ov"].get("maximum") for b in short["anyOf"]]
        assert rules.ROTATION_MAX in stated
        cases = [(v, ok) for v, ok in _around(bounds) if v > 0.0]  # (0: "must be > 0")
    else:
        cases = _around(bounds)
        ranges = client.get("/api/v1/openapi.json").json()["components"]["schemas"]
        request = json.dumps(ranges[next(k for k in ranges if k.startswith("EnvelopeRequest"))])
        assert f'"{key}": {{"maximum": {bounds[1]!r}, "minimum": {bounds[0]!r}}}' in request
    for value, accepted in cases:
        side = {**base, key: value}
        body = {"constants": {"mechanisms": [{"id": "W", **side, "eta": 0.9}]}, "n": 5}
        status, rest_error = _rest(client, "envelope", body)
        for argv in _envelope_cases(tmp_path, side):
            code, cli_error = _cli(argv)
            if accepted:
                assert (code, status) == (0, 200), (value, argv[1], cli_error, rest_error)
                continue
            assert (code, status) == (2, 422), (value, argv[1])
            assert key in cli_error and key in rest_error, (cli_error, rest_error)
            assert _reason(cli_error) == _reason(rest_error), (cli_error, rest_error)


PULSE_ARGS = ["pulse", "--p-eq", "2", "--eta", "0.9", "--f-p", "1", "--a-p-g", "1"]


@pytest.mark.parametrize(
    ("given", "field"),
    [({"phi_ov": "value", "lam": 0.2}, "phi_ov"), ({"lam": "value"}, "lam")],
)
def test_a_pulse_rotation_is_the_constants_files_on_cli_and_rest(
    given: dict[str, Any], field: str, client: httpx.Client, tmp_path: Path
) -> None:
    """Issue #36: ``pulse --phi-ov 10`` and ``POST /pulse`` said OVERTURNS; a file refused it.

    phi_ov, given or defaulted to lam, is at most pi/2 on the command line, the REST service
    and in a constants file, refused one step past it with the same words.
    """
    prop = _schema(client, "PulseRequest")["phi_ov"]
    assert prop["maximum"] == rules.ROTATION_MAX
    for value, accepted in _around((0.01, rules.ROTATION_MAX)):
        if not accepted and value < 1.0:
            continue  # below: lam's and phi_ov's own lower bounds, not this rule
        side = {k: value if v == "value" else v for k, v in given.items()}
        argv = [
            *PULSE_ARGS,
            *[a for k, v in side.items() for a in (f"--{k.replace('_', '-')}", repr(v))],
        ]
        code, cli_error = _cli(argv)
        body = {"p_eq": 2.0, "eta": 0.9, "f_p": 1.0, "a_p_g": 1.0, **side}
        status, rest_error = _rest(client, "pulse", body)
        path = tmp_path / "c.json"
        path.write_text(json.dumps({"mechanisms": [{"id": "W", "p_eq": 2.0, "eta": 0.9, **side}]}))
        file_code, file_error = _cli(
            ["envelope", str(path), "--out", str(tmp_path / "e"), "--n", "5"]
        )
        if accepted:
            assert (code, status, file_code) == (0, 200, 0), (value, cli_error, rest_error)
            continue
        assert (code, status, file_code) == (2, 422, 2), value
        assert f"error: {field}: " in cli_error and field in rest_error and field in file_error
        words = rules.rotation_problem(value) if field == "phi_ov" else None
        words = words or rules.default_rotation_problem(value)
        assert words is not None
        for said in (cli_error, rest_error, file_error):
            assert said.endswith(words), (said, words)
