"""Fixtures of the corpus: one real server for the REST cases, as in ``tests/service``."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

# the service tests' helpers (a real ``rockmech serve`` on a free loopback port)
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "service"))

from api_helpers import TEST_SETTINGS, Server, start_server


@pytest.fixture(scope="session")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    """The corpus's shared test server (the service tests' settings)."""
    with start_server(tmp_path_factory.mktemp("corpus-service"), **TEST_SETTINGS) as srv:
        yield srv


@pytest.fixture(scope="session")
def client(server: Server) -> Iterator[httpx.Client]:
    """An HTTP client on the shared server."""
    with httpx.Client(base_url=server.url, timeout=httpx.Timeout(60.0)) as c:
        yield c
