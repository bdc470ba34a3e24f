"""Schemathesis against the live OpenAPI document of a running server: no failures.

Checks: all of schemathesis' checks on every operation, including ``not_a_server_error``
(no 5xx), status-code, content-type and response-schema conformance,
``negative_data_rejection`` (schema-invalid requests must get 4xx) and
``unsupported_method``; and ``positive_data_acceptance`` ("a request the schema allows must
succeed") on every operation that takes a JSON body, and the two GETs
(``POSITIVE_DATA_OPERATIONS``): ``/pulse``, ``/scale-factor``, ``/envelope``, ``/check``,
``/assess`` and the JSON forms of ``/history``, ``/spectrum`` and ``/report``. Uploads are
excepted: ``/constants``, ``/search`` and the multipart forms of ``/history``, ``/spectrum`` and
``/report`` (a ``.3dm`` must be a Rhino model, a spec must name objects of the scene, a
record file must be one of the formats); the hooks run the check on JSON bodies only. So is
``/retrofit``, whose spec must name mechanisms of its constants and whose candidate ties must
be for mechanisms in physical form with their geometry (a rule across two documents), and,
for that reason, the positive ``/assess`` cases that carry a ``retrofit`` spec; every other
check, ``not_a_server_error`` among them, still runs on them.

The schema states every rule JSON Schema can state (design 1):

- ranges of ``shared_schema.rules``: a pulse's ``P_EQ_RANGE``, ``F_P_RANGE``, ``LAM_RANGE``,
  ``A_P_G_MAX``; a record's ``dt`` in ``DT_RANGE_S`` and samples at most ``ACCEL_MAX_G`` in
  its own units (``oneOf`` over ``units``); heights at most ``BUILDING_HEIGHT_MAX_M``;
  ``f_n`` in ``F_N_RANGE``; envelope frequencies in ``F_P_RANGE``; the options' own bounds
  (``n >= 2``, ``pulses >= 1``, ``zeta`` in [0, 1), scales and periods > 0, multiples in
  (0, ``MULTIPLE_MAX``]);
- rules across fields (``oneOf``/``anyOf``, written null-aware, since null means "not
  given"): a pulse needs ``eta``, in [0, 1] two-sided and [-1, 0] one-sided; ``eq28`` takes
  ``sa_g`` and ``pga_g``, or a record and ``f_n``; a side gives all four physical constants
  (and then may give ``M_F``) or none and ``p_eq`` and ``lam``; ``eta`` >= 0 two-sided, <= 0
  one-sided; ``eta_to_negative``, ``eta_to_positive`` and ``eta`` together, two-sided
  only; ``eta_source`` with ``eta``; time-domain constants give ``eta`` for every
  two-sided mechanism; a report without a record keeps the time-history options at their
  defaults;
- derived values that must stay finite (design 3): time-domain requests (``/envelope``,
  ``/history``, ``/report``, ``/assess``) bound each side's ``p_eq`` and ``lam`` by the
  ranges of a pulse and the amplification data by those of ``/scale-factor``
  (``shared_schema.api.TIME_DOMAIN_RANGES``, ``AMPLIFICATION_RANGES``), stated in the
  schema for the given values and enforced by the service with a 422 naming the field
  (``constants.mechanisms[i].positive.p_eq``), given or derived. These bounds are
  physical (a block's half-diagonal from 74 km to 7 µm; no structure above 1000 m), so the
  API states them rather than the hooks hiding them; the constants file itself keeps no
  such bound, as the command line reads the same files.

The hooks module ``schemathesis_hooks`` (loaded with ``SCHEMATHESIS_HOOKS``) drops the
positive test cases that break a rule JSON Schema has no keyword for (design 2), each by
calling the service's own rule (its docstrings give the reasons); negative cases are left
to the service, which must still refuse them:

- ``/scale-factor``: ``z <= H`` (``ec8``), ``h_i <= h_n`` (``nzs``), the work of the spectrum
  at ``T_n = 1/f_n`` on a record;
- the constants file (validated as the service validates it): forms agreeing to 1e-9,
  ``S^2 <= mass J`` of ``virtual_work``, ``K phi_cr`` above ``M_F``, derived values that
  overflow or underflow, unique ids, ``eta`` between ``eta_to_negative`` and
  ``eta_to_positive``, and ``p_eq``/``lam`` derived from a physical form in range;
- the options: ``f_min < f_max``, ``t_min < t_max``, a spectrum's ``f_min <= f_max``;
- the server's settings and work bounds (``api.jobspec.check_job``; the compute process's
  steps per sample of a time history and a spectrum's shortest period, an assessment's
  spectra over each mechanism's matching band), a scaled record within the solver's range
  (scale x peak / (g lam) <= ``MAX_AMPLITUDE_RATIO``), a pulse scale factor up the
  structure finite (``h/h_e``) and within the closed form's ``f_p/f_n >= RATIO_MIN``; and
  work that could outlast the 5 s budget on this loaded machine: the service refuses up
  front only what cannot finish at ten times the fastest rate measured and answers the rest
  with 503 at its budget, so positive cases are kept within the budget at half that rate.

The module also mends a fault of the client that stopped some runs on ``/report`` with
``Unsupported type: 'Binary'`` (its docstring says how).

Found by the positive-data check and fixed in the service (regression tests beside them):
a 500 on ``/check`` from virtual work whose ``e* = S^2/(mass J)`` underflowed to 0; a 500
from a derived ``p_eq`` that underflowed to 0; a 500 from exact envelopes of a stiff
structure (the pulse spectrum's ``exp`` overflowed for ``f_p/f_n`` below 4.5e-4); a 500
from ``/assess`` on a record crossing zero once through a zero sample (the pulse search);
integral floats (``100.0``) refused for JSON Schema integers.

One schemathesis worker: with two, hypothesis' lambda descriptions call ``ast.parse`` from
two threads at once, and CPython 3.11 (its AST recursion counter is shared between threads)
answers with a spurious ``SystemError: AST constructor recursion depth mismatch`` in the
client (the message of python/cpython#106905); with ``/check`` and ``/assess`` (deep
strategies: constants, site, records) it happened on every run, never in the server.

Schema-valid but absurd requests (a two-sample record 11 hours long, p_eq = 1e300) are
refused up front with 422 by the service's work bound (``20 x ROCKMECH_MAX_SAMPLES``
closed-form steps per run); the server gets a 5 s budget and small size limits, so that
nothing can keep it busy. ``ROCKMECH_MAX_SAMPLES`` is 50,000: the longest pulse the schema
allows (1e6 steps) stays within its work bound, as it does at the default settings. The run
is bounded (``MAX_EXAMPLES`` per operation, fixed seed); the server log must hold no
traceback.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import httpx
import pytest
from servers import Server, ServerWith

#: Test cases per operation and phase.
MAX_EXAMPLES = 30
#: Operations checked for positive-data acceptance too (the others: module docstring).
POSITIVE_DATA_OPERATIONS = (
    "pulse",
    "scale-factor",
    "envelope",
    "history",
    "spectrum",
    "report",
    "check",
    "assess",
    "health",
    r"schema/kinematic-constants\.json",
)
#: The server's compute budget per request [s] (the hooks read it too: the work estimates).
COMPUTE_TIMEOUT_S = 5
#: The server's ``ROCKMECH_MAX_SAMPLES`` (the hooks read it: a record's work bound).
MAX_SAMPLES = 50_000
#: The hooks module: positive cases that break a rule JSON Schema cannot state are dropped.
HOOKS = "schemathesis_hooks"
SEED = 20261121
#: schemathesis' configuration: every check on every operation, the positive-data check on
#: those operations only (the command line names no checks: its ``--checks`` would override
#: the file's per-operation settings).
CONFIG = f"""
[checks]
enabled = true
positive_data_acceptance.enabled = false

[[operations]]
include-path-regex = '^/api/v1/({"|".join(POSITIVE_DATA_OPERATIONS)})$'
checks.positive_data_acceptance.enabled = true
"""


@pytest.fixture(scope="module")
def fuzz_server(server_with: ServerWith) -> Server:
    return server_with(compute_timeout_s=COMPUTE_TIMEOUT_S, max_samples=MAX_SAMPLES)


#: The operations, in groups of about equal work: each group is one test, so that the test
#: workers share them (paths under ``/api/v1/``, as regular expressions).
GROUPS = {
    "pulse-and-small": r"pulse|scale-factor|health|schema/.*|constants|search",
    "envelope-spectrum": r"envelope|spectrum",
    "history": r"history",
    "report": r"report",
    "check-assess": r"check|assess|retrofit",
}


def _operations(url: str, pattern: str) -> int:
    """The number of operations of the live schema whose path matches ``pattern``."""
    doc = httpx.get(f"{url}/api/v1/openapi.json", timeout=30).json()
    regex = re.compile(rf"^/api/v1/({pattern})$")
    return sum(
        1
        for path, item in doc["paths"].items()
        if regex.match(path)
        for method in item
        if method in {"get", "post", "put", "delete", "patch"}
    )


def test_the_groups_cover_every_operation(fuzz_server: Server) -> None:
    total = _operations(fuzz_server.url, ".*")
    assert sum(_operations(fuzz_server.url, p) for p in GROUPS.values()) == total == 13


@pytest.mark.slow
@pytest.mark.parametrize("group", sorted(GROUPS))
def test_schemathesis_finds_no_failures(fuzz_server: Server, tmp_path: Path, group: str) -> None:
    pattern = GROUPS[group]
    exe = Path(sys.executable).with_name("st")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "schemathesis.cli"]
    config = tmp_path / "schemathesis.toml"
    config.write_text(CONFIG)
    cmd += [
        "--config-file",
        str(config),
        "run",
        f"{fuzz_server.url}/api/v1/openapi.json",
        "--max-examples",
        str(MAX_EXAMPLES),
        "--seed",
        str(SEED),
        "--generation-database",
        "none",
        "--workers",
        "1",
        "--request-timeout",
        "60",
        "--no-color",
        "--include-path-regex",
        f"^/api/v1/({pattern})$",
        "--report",
        "junit",
        "--report-dir",
        str(tmp_path),
    ]
    here = Path(__file__).resolve().parent
    env = {
        **os.environ,
        "SCHEMATHESIS_HOOKS": HOOKS,
        "ROCKMECH_MAX_SAMPLES": str(MAX_SAMPLES),
        "ROCKMECH_COMPUTE_TIMEOUT_S": str(COMPUTE_TIMEOUT_S),
        "PYTHONPATH": os.pathsep.join(
            [str(here), str(here.parents[1]), os.environ.get("PYTHONPATH", "")]
        ),
    }
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=900, cwd=tmp_path, env=env)
    assert res.returncode == 0, res.stdout[-6000:] + res.stderr[-2000:]
    expected = _operations(fuzz_server.url, pattern)
    assert f"{expected} passed" in res.stdout, res.stdout[-3000:]
    assert fuzz_server.proc.poll() is None
    log = fuzz_server.log.read_text()
    assert "Traceback" not in log, log[-3000:]
