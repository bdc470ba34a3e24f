"""``solver_service.core`` imports without FastAPI, pydantic or Rhino.

The rule is floor 1's in docs/architecture.md.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

BLOCKED = [
    "fastapi",
    "pydantic",
    "pydantic_core",
    "rhino3dm",
    "Rhino",
    "rhinoscriptsyntax",
    "matplotlib",
    "typer",
]

SCRIPT = f"""
import sys
for name in {BLOCKED!r}:
    sys.modules[name] = None  # any import of it now raises ImportError
import solver_service.core.model, solver_service.core.excitation, solver_service.core.result
import solver_service.core.exact, solver_service.core.records, solver_service.core.freemotion
import solver_service.core.envelope, solver_service.core.amplification
import solver_service.core.reference, solver_service.core.nonlinear
from solver_service.core.exact import simulate
from solver_service.core.model import RockingModel
from solver_service.core.excitation import Pulse
r = simulate(RockingModel.symmetric(2.0, 0.2, 0.9), Pulse(a_p=-5.0, f_p=1.0))
assert r.success
print("ok")
"""


@pytest.mark.slow
def test_core_imports_without_framework_or_rhino() -> None:
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=300, check=False
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "ok"
