"""The service's last perimeter gaps (issue #25), each reproduced against the real server.

A request cut by the shutdown, work the estimate let through to the budget, bit-flipped
scenes, echoed megabytes, an oversized one-column record, a 5000-digit number, a loopback
origin under another name, the numerics in the app process, and a slow start of the
compute processes. Each test sends what a user sent and checks the answer and the log.
"""

from __future__ import annotations

import json
import os
import signal
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest
from api_helpers import EXAMPLES, REPO, cli_error, cpu_ticks, peak_rss, wait_busy
from servers import ONE_PROCESS, Server, ServerWith, start_server

CHURCH = json.loads((EXAMPLES / "constants" / "church.json").read_text())
PULSE = {"p_eq": 2.0, "lam": 0.2, "eta": 0.9, "a_p_g": -0.61, "f_p": 1.59}
SPEC = EXAMPLES / "specs" / "facade.spec.json"
#: Exact envelopes of the church at 800 frequencies: seconds of one compute process, within
#: what the estimate lets through at the default 30 s budget.
HEAVY = {"constants": CHURCH, "method": "exact", "n": 800}
#: Modules of the numerics, which only the compute processes may load.
NUMERICS = ("numpy", "scipy", "numba", "llvmlite", "matplotlib", "rhino3dm", "trimesh")


@pytest.fixture(scope="module")
def svc(server_with: ServerWith) -> Server:
    """One compute process, the default limits and budget (30 s)."""
    return server_with(**ONE_PROCESS)


def _worker(server: Server) -> int:
    return server.worker()


def _no_traceback(log: Path) -> None:
    text = log.read_text(errors="replace")
    assert "Traceback" not in text and "CancelledError" not in text, text[-3000:]


# --- a request still running when the shutdown grace ends -----------------------------------


@pytest.mark.slow
def test_a_request_cut_by_the_shutdown_gets_503_json_and_the_log_no_traceback(
    tmp_path: Path,
) -> None:
    with start_server(tmp_path, compute_workers=1, shutdown_timeout_s=1) as srv:
        pid = _worker(srv)
        answers: list[httpx.Response] = []
        thread = threading.Thread(
            target=lambda: answers.append(
                httpx.post(f"{srv.url}/api/v1/envelope", json=HEAVY, timeout=60)
            )
        )
        thread.start()
        wait_busy(pid)
        srv.proc.send_signal(signal.SIGTERM)
        srv.proc.wait(timeout=30)
        thread.join(30)
    (res,) = answers
    assert res.status_code == 503, res.text
    assert res.headers["content-type"] == "application/json"
    doc = res.json()
    assert doc["error"] == "ShuttingDown"
    assert "ROCKMECH_SHUTDOWN_TIMEOUT_S" in doc["detail"] and "after 1 s" in doc["detail"]
    assert int(res.headers["retry-after"]) > 0
    _no_traceback(srv.log)


# --- work estimated against the benchmark's rates -------------------------------------------


def test_exact_envelopes_of_the_church_at_20000_frequencies_are_refused_up_front(
    svc: Server,
) -> None:
    # The estimate counts the cores the service may use; pin it to two, the benchmark's.
    cpus = sorted(os.sched_getaffinity(svc.proc.pid))[:2]
    os.sched_setaffinity(svc.proc.pid, cpus)
    pid = _worker(svc)
    before = cpu_ticks(pid)
    body = {"constants": CHURCH, "method": "exact", "n": 20_000}
    res = httpx.post(f"{svc.url}/api/v1/envelope", json=body, timeout=120)
    assert res.status_code == 422, res.text
    doc = res.json()
    assert doc["field"] == "method"
    detail = doc["detail"]
    # The work, the rates' margin and the limit it cannot meet, named.
    assert "3.75e+08 closed-form steps of exact envelopes" in detail, detail
    assert "2.2e+07 grid points of pulse spectra" in detail, detail
    assert f"on all {len(cpus)} cores" in detail and "2 times the rates measured" in detail
    assert "budget of 30 s" in detail and "ROCKMECH_COMPUTE_TIMEOUT_S" in detail
    assert cpu_ticks(pid) - before < 20  # refused before a compute process worked on it


# --- bit-flipped scenes ---------------------------------------------------------------------


def _chunks(data: bytes, start: int, end: int) -> Iterator[tuple[int, int, int]]:
    """(code, content start, content end) of every long chunk under [start, end) (V5+).

    A chunk's content is walked when it is exactly a sequence of chunks (tables, records,
    class chunks), written here from the openNURBS header independently of the module.
    """
    out, pos = [], start
    while pos < end:
        if end - pos < 12:
            return
        code, length = struct.unpack_from("<IQ", data, pos)
        pos += 12
        if code & 0x80000000:
            continue
        if length > end - pos:
            return
        out.append((code, pos, pos + length))
        pos += length
    for code, lo, hi in out:
        yield code, lo, hi
        yield from _chunks(data, lo, hi - 4 if code & 0x8000 else hi)


def _flips(path: Path) -> list[int]:
    """Offsets inside the largest object data of a scene (a third, half, two thirds in)."""
    data = path.read_bytes()
    _, lo, hi = max(
        (c for c in _chunks(data, 32, len(data)) if c[0] == 0x0002FFFC),
        key=lambda c: c[2] - c[1],
    )
    return [lo + (hi - lo) * k // 6 for k in (2, 3, 4)]


#: The offsets whose flipped bit kept rhino3dm busy for 20-30 s, besides those above.
SLOW_FLIPS = {"asym_frame.3dm": [10533, 19224, 19949], "facade.3dm": [31076]}
SCENES = sorted(p.name for p in (EXAMPLES / "scenes").glob("*.3dm"))


def test_bit_flipped_scenes_are_refused_by_the_archive_check(svc: Server, tmp_path: Path) -> None:
    pid = _worker(svc)
    before = cpu_ticks(pid)
    refused = 0
    for name in SCENES:
        data = (EXAMPLES / "scenes" / name).read_bytes()
        for offset in [*_flips(EXAMPLES / "scenes" / name), *SLOW_FLIPS.get(name, [])]:
            bad = bytearray(data)
            bad[offset] ^= 0x40
            files = {"scene": (name, bytes(bad)), "spec": (SPEC.name, SPEC.read_bytes())}
            res = httpx.post(f"{svc.url}/api/v1/constants", files=files, timeout=60)
            assert res.status_code == 422, (name, offset, res.text)
            detail = res.json()["detail"]
            assert detail.startswith(f"scene: cannot read {name} as a .3dm file"), detail
            assert "fails its CRC check" in detail, (name, offset, detail)
            refused += 1
    assert refused == 3 * len(SCENES) + 4
    # The app refused them all: the compute process (rhino3dm) never saw one.
    assert cpu_ticks(pid) - before < 20
    # The command line says the same, from the same check.
    bad = bytearray((EXAMPLES / "scenes" / "asym_frame.3dm").read_bytes())
    bad[10533] ^= 0x40
    (tmp_path / "asym_frame.3dm").write_bytes(bytes(bad))
    line = cli_error("constants", "asym_frame.3dm", str(SPEC), "-o", "c.json", cwd=tmp_path)
    assert "fails its CRC check" in line
    assert not (tmp_path / "c.json").exists()


# --- echoed input ---------------------------------------------------------------------------


@pytest.mark.parametrize("where", ["mechanism id", "unknown key", "units"])
@pytest.mark.slow
def test_a_422_quotes_at_most_200_characters_of_a_31_mb_value(svc: Server, where: str) -> None:
    big = "W" * 31_000_000
    mech: dict[str, Any] = {"id": "W", "p_eq": 2.0, "lam": 0.2, "eta": 0.9}
    record = {"accel": [0.0, 0.1, 0.0], "dt": 0.01, "units": "g"}
    if where == "mechanism id":
        mech = {**mech, "id": big, "p_eq": -1.0}
    elif where == "unknown key":
        mech = {**mech, big: 1}
    else:
        record = {**record, "units": big}
    body = {"constants": {"mechanisms": [mech]}, "record": record}
    res = httpx.post(f"{svc.url}/api/v1/history", json=body, timeout=120)
    assert res.status_code == 422, res.text[:500]
    assert len(res.content) < 2000, len(res.content)
    detail = res.json()["detail"]
    assert "W" * 200 + "\u2026(31000000 characters)" in detail or (
        "\u2026(31000003 characters)" in detail  # the key with its path
    ), detail


# --- an oversized one-column record ---------------------------------------------------------


def test_an_oversized_one_column_record_is_refused_before_a_compute_process_parses_it(
    svc: Server,
) -> None:
    pid = _worker(svc)
    peak = peak_rss(pid)
    server_peak = peak_rss(svc.proc.pid)
    lines = 7_500_000  # 30 MB, within the 32 MiB body limit; 15 times the sample limit
    record = b"0.1\n" * lines
    files = {"record": ("long.txt", record)}
    form = {"dt": "0.01", "units": "g"}
    res = httpx.post(f"{svc.url}/api/v1/spectrum", files=files, data=form, timeout=120)
    assert res.status_code == 422, res.text
    doc = res.json()
    assert doc["field"] == "record"
    assert f"{lines} lines of numbers" in doc["detail"]
    assert "ROCKMECH_MAX_SAMPLES" in doc["detail"]
    # The compute process never held it; the app held it about twice (body and count).
    assert peak_rss(pid) - peak < 20 * 2**20
    assert peak_rss(svc.proc.pid) - server_peak < 4 * len(record)


# --- numbers no double can hold -------------------------------------------------------------


def test_a_5000_digit_number_gets_a_422_naming_its_field(svc: Server) -> None:
    digits = "1" * 5000
    answers = {}
    body = json.dumps(PULSE).replace('"p_eq": 2.0', f'"p_eq": {digits}')
    answers["p_eq"] = httpx.post(
        f"{svc.url}/api/v1/pulse", content=body, headers={"content-type": "application/json"}
    )
    envelope = '{"constants": {"mechanisms": [{"id": "W", "p_eq": 2, "lam": 0.2}]}, "n": %s}'
    answers["n"] = httpx.post(
        f"{svc.url}/api/v1/envelope",
        content=envelope % digits,
        headers={"content-type": "application/json"},
    )
    mech = '{"id": "W", "p_eq": 2, "lam": ' + digits + ', "eta": 0.9}'
    constants = '{"mechanisms": [' + mech + "]}"
    files = {"constants": ("walls.json", constants), "record": ("r.dat", "0 0.1\n0.01 0.2\n")}
    answers["lam"] = httpx.post(f"{svc.url}/api/v1/history", files=files, timeout=60)
    tree = {"{0}": [{"type": "System.Double", "data": digits}]}
    hops = {"values": [{"ParamName": "p_eq", "InnerTree": tree}]}
    answers["hops p_eq"] = httpx.post(f"{svc.url}/hops/pulse", json=hops)
    for field, res in answers.items():
        assert res.status_code == 422, (field, res.text)
        text = res.text
        assert "4300" not in text and "Exceeds the limit" not in text, text
        assert len(res.content) < 1000, (field, len(res.content))
        message = res.json()["errors"][0] if field.startswith("hops") else res.json()["detail"]
        assert field.split()[-1] in message, (field, message)
    assert "out of the range of double precision" in answers["p_eq"].json()["detail"]
    assert answers["p_eq"].json()["field"] == "p_eq"
    assert answers["n"].json()["field"] == "n"
    assert "lam: Input should be a finite number" in answers["lam"].json()["detail"]


# --- loopback origins -----------------------------------------------------------------------


def test_the_loopback_names_are_one_origin(svc: Server) -> None:
    port = svc.url.rsplit(":", 1)[1]
    for origin in (f"http://localhost:{port}", f"http://[::1]:{port}", svc.url):
        res = httpx.post(f"{svc.url}/api/v1/pulse", json=PULSE, headers={"origin": origin})
        assert res.status_code == 200, (origin, res.text)
    for origin in (f"http://localhost:{int(port) + 1}", f"https://localhost:{port}"):
        res = httpx.post(f"{svc.url}/api/v1/pulse", json=PULSE, headers={"origin": origin})
        assert res.status_code == 403, (origin, res.text)


# --- the app process loads no numerics ------------------------------------------------------


def _mapped(pid: int) -> set[str]:
    """The numerics packages whose files are mapped into process ``pid`` (``/proc/maps``)."""
    text = Path(f"/proc/{pid}/maps").read_text()
    return {name for name in NUMERICS if f"/{name}/" in text or f"/{name}." in text}


def test_the_server_process_maps_no_numerics_and_the_compute_process_does(svc: Server) -> None:
    assert _mapped(svc.proc.pid) == set()
    assert {"numpy", "numba"} <= _mapped(_worker(svc))  # the method sees them where they are
    # Importing the app (and the command's serve path up to uvicorn) loads none either.
    code = (
        "import sys, solver_service.api.app, solver_service.api.server; "
        f"print(sorted(m for m in sys.modules if m.split('.')[0] in {NUMERICS!r}))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=REPO
    ).stdout
    assert out.strip() == "[]", out


# --- a slow start of the compute processes --------------------------------------------------


def test_a_slow_start_is_one_log_line_and_health_says_starting(tmp_path: Path) -> None:
    # No compute process warms up in 0.3 s (its imports alone take longer).
    with start_server(
        tmp_path, ready=False, compute_workers=1, startup_timeout_s=0.3, queue_timeout_s=1
    ) as srv:
        res = httpx.get(f"{srv.url}/api/v1/health")
        assert res.status_code == 503, res.text
        assert res.json()["status"] == "starting"
        res = httpx.post(f"{srv.url}/api/v1/pulse", json=PULSE, timeout=30)
        if res.status_code == 503:  # still starting after the 1 s wait for a process
            assert res.json()["error"] == "PoolBusy"
            assert "still starting" in res.json()["detail"]
        else:  # the restarted process warmed up within the wait
            assert res.status_code == 200, res.text
        deadline = time.monotonic() + 60
        while "did not warm up within 0.3 s" not in srv.log.read_text():
            assert time.monotonic() < deadline, srv.log.read_text()
            time.sleep(0.1)
        assert srv.proc.poll() is None  # the server carries on
    lines = [line for line in srv.log.read_text().splitlines() if "did not warm up" in line]
    assert lines and all("ROCKMECH_STARTUP_TIMEOUT_S" in line for line in lines)
    _no_traceback(srv.log)
