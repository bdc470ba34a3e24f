"""Fault injection against the REST service: kill compute processes, abandon requests.

What is done
------------
A server is started here (``rockmech serve`` in a child process on a free loopback port,
``--workers`` compute processes, a private ``TMPDIR``), then ``--rounds`` rounds of each case
run, in turn:

* ``kill_busy``: a request for exact envelopes (seconds of work) is sent; once a compute
  process uses CPU, it is killed (SIGKILL). Expected: that request gets 503 with
  ``Retry-After``; the next valid request (a pulse) gets 200.
* ``kill_idle``: an idle compute process is killed; at once a pulse is sent. Expected: 200.
* ``disconnect``: the envelope request is sent with a client timeout of ``--abandon-s``
  seconds, so the client gives up and closes its connection. Expected: the busy compute
  process is stopped within a second of the disconnect, and the next pulse gets 200.

Reported per case: rounds, counts by outcome, the next request's status counts, and for
``disconnect`` the time from the client giving up to its worker ending (p50 and max). At the
end: temporary entries left in the server's ``TMPDIR`` besides the live workers' folders
(must be 0), tracebacks in the server log (must be 0), whether the server is still alive.

Run ``.venv/bin/python benchmarks/faults.py --rounds 20``. Bounded: ``--rounds`` per case and
``--max-seconds`` in all; every request goes to 127.0.0.1.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import statistics
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Any

import httpx

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from solver_service.api import scratch  # noqa: E402
from solver_service.api.server import background_server  # noqa: E402

CHURCH = json.loads((REPO / "examples" / "constants" / "church.json").read_text())
HEAVY = {"constants": CHURCH, "method": "exact", "n": 800}
PULSE = {"p_eq": 2.0, "lam": 0.2, "eta": 0.9, "a_p_g": -0.61, "f_p": 1.59}


def _children(pid: int) -> list[int]:
    return [int(p) for p in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]


#: CPU ticks reported for a process that has already ended (it counts as having worked).
GONE_TICKS = 1 << 60


def _ticks(pid: int) -> int:
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:  # ended (and reaped) already
        return GONE_TICKS
    return int(fields[11]) + int(fields[12])


def _gone(pid: int) -> bool:
    try:
        return "zombie" in Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return True


def _ready(url: str, server_pid: int, workers: int, wait_s: float = 60.0) -> list[int]:
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline:
        kids = _children(server_pid)
        alive = httpx.get(f"{url}/api/v1/health").json()["compute_workers"]
        if len(kids) == workers and alive == workers:
            return kids
        time.sleep(0.05)
    raise RuntimeError("compute processes did not come back")


def _busy_worker(pids: list[int], wait_s: float = 10.0) -> int:
    """Return the first of ``pids`` to use 0.2 s of CPU."""
    start = {p: _ticks(p) for p in pids}
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline:
        for p in pids:
            if _ticks(p) - start[p] >= 20:
                return p
        time.sleep(0.02)
    raise RuntimeError("no compute process took the job")


def _pulse(url: str) -> int:
    return httpx.post(f"{url}/api/v1/pulse", json=PULSE, timeout=120).status_code


def kill_busy(url: str, server_pid: int, workers: int) -> dict[str, Any]:
    """Kill the compute process working on a request."""
    pids = _ready(url, server_pid, workers)
    out: list[httpx.Response] = []
    thread = threading.Thread(
        target=lambda: out.append(httpx.post(f"{url}/api/v1/envelope", json=HEAVY, timeout=120))
    )
    thread.start()
    os.kill(_busy_worker(pids), signal.SIGKILL)
    thread.join(120)
    res = out[0]
    outcome = f"{res.status_code} {res.json().get('error', '')}"
    if res.status_code == 503 and "retry-after" not in res.headers:
        outcome += " (no Retry-After)"
    return {"outcome": outcome, "next": _pulse(url)}


def kill_idle(url: str, server_pid: int, workers: int) -> dict[str, Any]:
    """Kill an idle compute process and send a request at once."""
    pids = _ready(url, server_pid, workers)
    os.kill(pids[0], signal.SIGKILL)
    return {"outcome": "killed", "next": _pulse(url)}


def disconnect(url: str, server_pid: int, workers: int, abandon_s: float) -> dict[str, Any]:
    """Give up on a long request; time until its compute process ends."""
    pids = _ready(url, server_pid, workers)
    start = {p: _ticks(p) for p in pids}
    try:
        httpx.post(f"{url}/api/v1/envelope", json=HEAVY, timeout=abandon_s)
        outcome = "answered"
    except httpx.TimeoutException:
        outcome = "abandoned"
    gave_up = time.monotonic()
    busy = [p for p in pids if _ticks(p) - start[p] >= 10]
    if not busy:  # given up while still queued: no compute process to free
        outcome += " in the queue"
    while not all(_gone(p) for p in busy) and time.monotonic() - gave_up < 30:
        time.sleep(0.01)
    freed = time.monotonic() - gave_up
    return {"outcome": outcome, "freed_s": freed, "next": _pulse(url)}


def main(argv: list[str] | None = None) -> int:
    """Run the fault cases; print a table; return 0 if every outcome is the expected one."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=10, help="rounds per case (default 10)")
    ap.add_argument("--workers", type=int, default=2, help="compute processes (default 2)")
    ap.add_argument("--abandon-s", type=float, default=1.0, help="client timeout of disconnect")
    ap.add_argument("--max-seconds", type=float, default=600.0, help="stop after this long")
    ap.add_argument("--json", type=Path, help="also write the results as JSON here")
    args = ap.parse_args(argv)
    results: dict[str, list[dict[str, Any]]] = {"kill_busy": [], "kill_idle": [], "disconnect": []}
    with tempfile.TemporaryDirectory(prefix="rockmech-faults-") as folder:
        tmp = Path(folder) / "tmp"
        tmp.mkdir()
        log = Path(folder) / "server.log"
        settings = {"compute_workers": args.workers, "compute_timeout_s": 60}
        with background_server(settings, log, env={"TMPDIR": str(tmp)}) as (url, proc):
            stop = time.monotonic() + args.max_seconds
            for _ in range(args.rounds):
                if time.monotonic() > stop:
                    break
                results["kill_busy"].append(kill_busy(url, proc.pid, args.workers))
                results["kill_idle"].append(kill_idle(url, proc.pid, args.workers))
                results["disconnect"].append(
                    disconnect(url, proc.pid, args.workers, args.abandon_s)
                )
            pids = _ready(url, proc.pid, args.workers)
            own = set()
            for pid in pids:
                for item in Path(f"/proc/{pid}/environ").read_bytes().split(b"\0"):
                    if item.startswith(b"TMPDIR="):
                        own.add(Path(item[7:].decode()).name)
            # The workers' folders live in the server's one root (solver_service.api.scratch).
            entries = set(tmp.iterdir())
            roots = {p for p in entries if p.name.startswith(scratch.ROOT_PREFIX)}
            inside = {p.name for r in roots for p in r.iterdir()} - {scratch.OWNER_FILE}
            stray = {p.name for p in entries - roots}
            if len(roots) != 1:  # one server, one root
                stray |= {r.name for r in roots}
            leftovers = sorted(stray | (inside - own))
            alive = proc.poll() is None
        tracebacks = log.read_text(errors="replace").count("Traceback")
    ok = True
    print(f"{'case':<11} {'rounds':>6}  outcomes / next request / worker freed after")
    for case, rows in results.items():
        outcomes = Counter(r["outcome"] for r in rows)
        nexts = Counter(str(r["next"]) for r in rows)
        line = f"{case:<11} {len(rows):>6}  {dict(outcomes)} / next {dict(nexts)}"
        if case == "disconnect" and rows:
            freed = [r["freed_s"] for r in rows]
            line += f" / p50 {statistics.median(freed):.2f} s, max {max(freed):.2f} s"
            ok &= max(freed) < 1.0
        expected = {"kill_busy": "503 WorkerLost", "kill_idle": "killed", "disconnect": "abandoned"}
        if case == "disconnect":
            outcomes.pop("abandoned in the queue", None)
        ok &= set(outcomes) <= {expected[case]} and set(nexts) <= {"200"}
        print(line)
    print(
        f"temporary entries left: {len(leftovers)}; server log tracebacks: {tracebacks}; "
        f"server alive: {alive}"
    )
    ok &= not leftovers and tracebacks == 0 and alive
    if args.json:
        doc = {"results": results, "leftovers": leftovers, "tracebacks": tracebacks, "ok": ok}
        args.json.write_text(json.dumps(doc, indent=1))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
