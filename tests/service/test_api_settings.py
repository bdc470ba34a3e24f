"""One settings object, from ROCKMECH_* variables; loopback by default; light app imports."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from shared_schema.errors import InputError
from solver_service.api.server import settings_with
from solver_service.api.settings import Settings


def test_defaults_bind_loopback(monkeypatch: pytest.MonkeyPatch) -> None:
    for key in list(os.environ):
        if key.startswith("ROCKMECH_"):
            monkeypatch.delenv(key)
    cfg = Settings()
    assert cfg.host == "127.0.0.1"
    assert cfg.compute_timeout_s > 0 and cfg.max_body_bytes > 0


def test_environment_and_cli_overrides(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROCKMECH_COMPUTE_TIMEOUT_S", "7.5")
    monkeypatch.setenv("ROCKMECH_MAX_SAMPLES", "1234")
    cfg = settings_with(port=9001, compute_workers=None)
    assert (cfg.compute_timeout_s, cfg.max_samples, cfg.port) == (7.5, 1234, 9001)
    with pytest.raises(InputError, match=r"^port: Input should be less than or equal to 65535"):
        settings_with(port=70000)


def test_the_app_imports_no_plotting_or_compiled_kernels() -> None:
    code = (
        "import sys, json\n"
        "from solver_service.api.app import create_app\n"
        "create_app()\n"
        "print(json.dumps([m for m in ('matplotlib', 'numba', 'scipy', 'rhino3dm') "
        "if m in sys.modules]))\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout.strip().splitlines()[-1]) == []
