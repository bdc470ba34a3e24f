"""Fixtures of the service tests: one shared server, started once per session."""

from __future__ import annotations

from collections.abc import Iterator

import httpx
import pytest
from api_helpers import TEST_SETTINGS, Server, start_server


@pytest.fixture(scope="session")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    """The shared test server."""
    with start_server(tmp_path_factory.mktemp("service"), **TEST_SETTINGS) as srv:
        yield srv


@pytest.fixture(scope="session")
def client(server: Server) -> Iterator[httpx.Client]:
    """An HTTP client on the shared server, with a generous read timeout."""
    with httpx.Client(base_url=server.url, timeout=httpx.Timeout(180.0)) as c:
        yield c
