"""Schemathesis against the live OpenAPI document of a running server: no failures.

Checks: all of schemathesis' checks on every operation, including ``not_a_server_error``
(no 5xx), status-code, content-type and response-schema conformance,
``negative_data_rejection`` (schema-invalid requests must get 4xx) and
``unsupported_method``; and ``positive_data_acceptance`` ("a request the schema allows must
succeed") on the operations whose schema states the rules the service enforces
(``POSITIVE_DATA_OPERATIONS``): ``/pulse``, whose numbers have plausible ranges that keep
every pulse within the work bound (``shared_schema.rules``: ``P_EQ_RANGE``, ``F_P_RANGE``,
``LAM_RANGE``, ``A_P_G_MAX``), ``/scale-factor`` and the two GET operations.

The schema states the rules across fields it can (``oneOf``: a pulse needs ``eta``, in
[0, 1] two-sided and [-1, 0] one-sided; ``eq28`` takes ``sa_g`` and ``pga_g``, or a record
and ``f_n``; time-domain constants give ``eta`` for every two-sided mechanism;
``dependentRequired``: ``eta_to_negative``, ``eta_to_positive`` and ``eta`` go together), and
the ranges of ``shared_schema.rules``: a record's ``dt`` in ``DT_RANGE_S`` [s], its samples at
most ``ACCEL_MAX_G`` in its own units (``oneOf`` over ``units``), heights at most
``BUILDING_HEIGHT_MAX_M`` [m], ``f_n`` in ``F_N_RANGE`` [Hz]. ``/scale-factor`` keeps three
rules that compare two fields, or a field with a setting of the server, for which JSON Schema
has no keyword: ``z <= H`` (``ec8``), ``h_i <= h_n`` (``nzs``) and the work of the spectrum at
``T_n = 1/f_n`` on a record (samples x ``ceil(20 f_n dt)`` within ``20 x
ROCKMECH_MAX_SAMPLES``). The hooks module ``schemathesis_hooks`` (loaded with
``SCHEMATHESIS_HOOKS``) drops the positive test cases that break one of those three, and
only those; negative cases are left to the service. The module also mends a fault of the
client that stopped some runs on ``/report`` with ``Unsupported type: 'Binary'`` (its
docstring says how). The other operations keep rules of that
kind too, so the positive-data check would find schema-valid requests they rightly refuse:

- constants files (``/envelope``, ``/history``, ``/report``, ``/check``, ``/assess``): rules
  across fields of a mechanism (``eta`` between ``eta_to_negative`` and ``eta_to_positive``;
  ``S² <= mass J`` of ``virtual_work``; physical and short forms agreeing to 1e-9;
  ``K phi_cr`` above ``M_F``, or the static forces alone overturn it; unique ids) and values
  derived from them that must stay finite (``p_eq = sqrt(K/I0)`` of ``K = 5e-324`` makes the
  envelope's ``omega`` infinite; the file format bounds none of ``K``, ``I0``, ``p_eq``, as
  the command line reads the same files);
- envelopes and spectra: ``f_min < f_max``, ``t_min < t_max``;
- records (``/history``, ``/report``, ``/assess``): the work of a time history, samples x
  ``ceil(p_eq dt)`` against the work bound, across the record and the constants;
- uploads (``/constants`` and the multipart forms of ``/history``, ``/spectrum`` and
  ``/report``): the content of the files (a ``.3dm`` must be a Rhino model, a spec must name
  objects of the scene, a record file must be one of the formats).

One schemathesis worker: with two, hypothesis' lambda descriptions call ``ast.parse`` from
two threads at once, and CPython 3.11 (its AST recursion counter is shared between threads)
answers with a spurious ``SystemError: AST constructor recursion depth mismatch`` in the
client (the message of python/cpython#106905); with ``/check`` and ``/assess`` (deep
strategies: constants, site, records) it happened on every run, never in the server.

Schema-valid but absurd requests (a two-sample record 11 hours long, p_eq = 1e300) are
refused up front with 422 by the service's work bound (``20 x ROCKMECH_MAX_SAMPLES``
closed-form steps per run), so no 503 is expected either; the server still gets a 5 s budget
and small size limits, so that nothing can keep it busy. ``ROCKMECH_MAX_SAMPLES`` is 50,000:
the longest pulse the schema allows (1e6 steps) stays within its work bound, as it does at
the default settings. The run is bounded
(``MAX_EXAMPLES`` per operation, fixed seed); the server log must hold no traceback.
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from api_helpers import Server, start_server

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
def fuzz_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    with start_server(
        tmp_path_factory.mktemp("fuzz"),
        compute_timeout_s=COMPUTE_TIMEOUT_S,
        max_samples=MAX_SAMPLES,
    ) as srv:
        yield srv


def test_schemathesis_finds_no_failures(fuzz_server: Server, tmp_path: Path) -> None:
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
    assert "11 passed" in res.stdout, res.stdout[-3000:]
    assert fuzz_server.proc.poll() is None
    log = fuzz_server.log.read_text()
    assert "Traceback" not in log, log[-3000:]
