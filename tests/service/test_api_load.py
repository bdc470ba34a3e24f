"""A small run of the load script (``benchmarks/load.py``): no 5xx and no broken connections.

The full run (10,000 requests at concurrency 32, latency and memory figures) is a benchmark,
not a test; this bounded run checks that mixed and malformed traffic never gives a 5xx.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from api_helpers import REPO


@pytest.mark.slow
def test_mixed_and_malformed_traffic_gives_no_5xx(tmp_path: Path) -> None:
    out = tmp_path / "load.json"
    cmd = [sys.executable, str(REPO / "benchmarks" / "load.py")]
    cmd += ["--requests", "400", "--concurrency", "16", "--no-docs", "--json", str(out)]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600, cwd=REPO)
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    report = json.loads(out.read_text())
    statuses = report["summary"]["statuses"]
    assert sum(statuses.values()) == 400
    assert not [k for k in statuses if k.startswith("5") or k == "transport error"], statuses
    kinds = report["summary"]["kinds"]
    for kind, status in (("bad_json", "422"), ("wrong_type", "415"), ("too_large", "413")):
        if kind in kinds:
            assert set(kinds[kind]["statuses"]) == {status}, (kind, kinds[kind])
    assert report["server_alive_after"] is True
    assert report["server_log_tracebacks"] == 0
