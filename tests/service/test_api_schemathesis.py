"""Schemathesis against the live OpenAPI document of a running server: no failures.

Checks: all of schemathesis' checks on every operation, including ``not_a_server_error``
(no 5xx), status-code, content-type and response-schema conformance,
``negative_data_rejection`` (schema-invalid requests must get 4xx) and
``unsupported_method``; and ``positive_data_acceptance`` ("a request the schema allows must
succeed") on the operations whose schema states every rule the service enforces
(``POSITIVE_DATA_OPERATIONS``): ``/pulse``, whose numbers have plausible ranges that keep
every pulse within the work bound (``shared_schema.rules``: ``P_EQ_RANGE``, ``F_P_RANGE``,
``LAM_RANGE``, ``A_P_G_MAX``), and the two GET operations.

The schema states the rules across fields it can (``oneOf``: a pulse needs ``eta``, in
[0, 1] two-sided and [-1, 0] one-sided; ``eq28`` takes ``sa_g`` and ``pga_g``, or a record
and ``f_n``; time-domain constants give ``eta`` for every two-sided mechanism). The other
operations keep rules JSON Schema cannot state, so the positive-data check would find
schema-valid requests they rightly refuse:

- constants files (``/envelope``, ``/history``, ``/report``, ``/check``, ``/assess``): values
  derived across fields (``p_eq = sqrt(K/I0)`` of ``K = 5e-324`` makes the envelope's
  ``omega`` infinite; ``eta`` must lie between ``eta_to_negative`` and ``eta_to_positive``);
- records (``/history``, ``/spectrum``, ``/report``, ``/scale-factor``): their work depends on
  the samples, time step and mechanisms or period together (a two-sample record 11 hours
  long; ``dt = 1e12`` s against ``T_n = 1/f_n``), checked against the work bound, and a
  sample of ``-1.8e308`` g overflows when converted to m/s² (an Eq. 28 record must also
  have a peak ground acceleration: that rule is stated, with ``contains``);
- uploads (``/constants`` and the multipart forms): the content of the files (a ``.3dm``
  must be a Rhino model, a spec must name objects of the scene).

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

import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from api_helpers import Server, start_server

#: Test cases per operation and phase.
MAX_EXAMPLES = 30
#: Operations checked for positive-data acceptance too (the others: module docstring).
POSITIVE_DATA_OPERATIONS = ("pulse", "health", r"schema/kinematic-constants\.json")
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
        tmp_path_factory.mktemp("fuzz"), compute_timeout_s=5, max_samples=50_000
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
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=900, cwd=tmp_path)
    assert res.returncode == 0, res.stdout[-6000:] + res.stderr[-2000:]
    assert "11 passed" in res.stdout, res.stdout[-3000:]
    assert fuzz_server.proc.poll() is None
    log = fuzz_server.log.read_text()
    assert "Traceback" not in log, log[-3000:]
