"""Shared fixtures: paths to bundled and shared data, and the real service (``servers.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
#: The project's shared folder (PEER records), beside the repository; absent on a user's clone.
SHARED_RECORDS = REPO.parent / "shared" / "data" / "records"

#: The real uvicorn server's fixtures (``server``, ``client``, ``server_with``), one home for
#: every test folder (this folder is on ``sys.path``: pytest's rootdir-relative imports).
pytest_plugins = ("servers",)


@pytest.fixture(scope="session")
def elcentro_path() -> Path:
    """The bundled, public-domain El Centro 1940 N-S record (two columns, g)."""
    return EXAMPLES / "records" / "elcentro_NS.dat"


@pytest.fixture(scope="session")
def shared_records() -> Path:
    """The shared PEER records folder; tests using it skip where it is absent."""
    if not SHARED_RECORDS.is_dir():
        pytest.skip(f"shared records folder not found at {SHARED_RECORDS} (not part of a clone)")
    return SHARED_RECORDS


def pytest_configure(config: pytest.Config) -> None:
    """Compile the solver's kernels once, before the test processes start (#28).

    Each path of the solver compiles on its first use and says so on stderr; built here
    first, every test process loads them from numba's cache and no test's output depends on
    which test ran first. Only the controlling process builds (xdist workers have
    ``workerinput``).
    """
    if hasattr(config, "workerinput"):
        return
    from solver_service.core.precompile import build

    build()
