"""Load test of the REST service: mixed requests, malformed ones included, at fixed concurrency.

What is measured
----------------
A server is started here (``rockmech serve`` in a child process on a free loopback port, two
compute processes, the default budget). After a warm-up of every request kind, ``--requests``
requests (default 10,000) are drawn at random (seeded) from ``MIX`` and sent by
``--concurrency`` (default 32) concurrent clients (httpx, one connection each):

* ``pulse``: one mechanism, one sine pulse (JSON);
* ``history_60s``: one mechanism under a 60 s record at 100 Hz (El Centro 1940 N-S
  resampled and padded to 60 s; 6,001 samples, JSON array with dt);
* ``envelope``: the example church, 100 frequencies, library;
* ``spectrum``: the 60 s record, 50 periods, its largest pulses;
* ``scale_factor``, ``health``;
* malformed: broken JSON, a bool as a number, NaN, a wrong content type, an unknown path,
  a wrong method, too many scale factors (a limit), and a body over the size limit.

Reported: p50 and p99 latency per kind (client side, from sending the request to reading the
whole answer), counts by status, transport errors, the server's resident memory (server and
compute processes) after start-up, after the warm-up and after the run, and the run's wall
time. Targets: no 5xx; memory growth over the run < 10 %; p50 <= 10 ms for ``pulse`` and
<= 30 ms for ``history_60s``.

Under 32 concurrent clients a request's latency is mostly its wait behind the others (Little's
law: latency = concurrency / throughput), so the two latency targets are checked on the
latency of one request at a time: before the load, ``LATENCY_SAMPLES`` requests of each of
the two kinds are sent one after another, and their p50 and p99 are reported too.

Run ``.venv/bin/python benchmarks/load.py``; it rewrites its section of
``docs/benchmarks.md``. ``--requests 400 --no-docs`` is a smoke run (the tests use it).
Every request goes to 127.0.0.1 only, and the run is bounded in count.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import random
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _docs import DOC_MD, load_average, machine_info, md_table, text_table, write_section  # noqa: E402

#: Body limit of the server under test [bytes]; the oversized request sends a bit more.
MAX_BODY = 2 * 1024 * 1024
#: Server settings for the run (ROCKMECH_*).
SETTINGS = {"compute_workers": 2, "max_body_bytes": MAX_BODY, "log_level": "warning"}
#: Requests of each kind sent before measuring (compilation caches, lazy imports).
WARMUP_PER_KIND = 5
#: Targets.
TARGET_P50 = {"pulse": 0.010, "history_60s": 0.030}
TARGET_GROWTH = 0.10
#: Requests of each target kind sent one at a time for the latency targets.
LATENCY_SAMPLES = {"pulse": 300, "history_60s": 100}
#: Seconds a single request may take before the client gives up (counted as an error).
REQUEST_TIMEOUT_S = 120.0


@dataclass
class Request:
    """One HTTP request of the mix."""

    method: str
    path: str
    json: Any = None
    content: Optional[bytes] = None
    headers: dict[str, str] = field(default_factory=dict)


def _record_60s() -> dict[str, Any]:
    """El Centro 1940 N-S at 100 Hz, padded with zeros to 60 s (in g)."""
    data = np.loadtxt(REPO / "examples" / "records" / "elcentro_NS.dat")
    t, a = data[:, 0], data[:, 1]
    dt = 0.01
    grid = np.arange(0.0, 60.0 + dt / 2, dt)
    accel = np.interp(grid, t, a, right=0.0)
    return {"accel": [round(float(v), 6) for v in accel], "dt": dt, "units": "g"}


def build_mix() -> dict[str, tuple[float, Callable[[], Request]]]:
    """Return the request kinds: weight and a factory of the request."""
    church = json.loads((REPO / "examples" / "constants" / "church.json").read_text())
    wall = {"mechanisms": [{"id": "W2", "p_eq": 2.2, "lam": 0.165, "eta": 0.96}]}
    record = _record_60s()
    pulse = {"p_eq": 2.0, "lam": 0.2, "eta": 0.9, "a_p_g": -0.61, "f_p": 1.59}
    history = {"constants": wall, "record": record, "scales": [1.0]}
    bad_json = b'{"p_eq": 2.0, "lam": '
    nan = b'{"p_eq": NaN, "lam": 0.2, "eta": 0.9, "a_p_g": -0.6, "f_p": 1.5}'
    ctype = {"content-type": "application/json"}
    return {
        "pulse": (0.40, lambda: Request("POST", "/api/v1/pulse", json=pulse)),
        "history_60s": (0.20, lambda: Request("POST", "/api/v1/history", json=history)),
        "envelope": (
            0.06,
            lambda: Request("POST", "/api/v1/envelope", json={"constants": church, "n": 100}),
        ),
        "spectrum": (
            0.03,
            lambda: Request("POST", "/api/v1/spectrum", json={"record": record, "n": 50}),
        ),
        "scale_factor": (
            0.04,
            lambda: Request(
                "POST",
                "/api/v1/scale-factor",
                json={"method": "nzs", "h_i": 4.6, "h_n": 12.0},
            ),
        ),
        "health": (0.04, lambda: Request("GET", "/api/v1/health")),
        "bad_json": (
            0.04,
            lambda: Request("POST", "/api/v1/pulse", content=bad_json, headers=ctype),
        ),
        "bool_number": (
            0.04,
            lambda: Request("POST", "/api/v1/pulse", json={**pulse, "p_eq": True}),
        ),
        "nan": (0.03, lambda: Request("POST", "/api/v1/pulse", content=nan, headers=ctype)),
        "wrong_type": (
            0.03,
            lambda: Request(
                "POST",
                "/api/v1/pulse",
                content=json.dumps(pulse).encode(),
                headers={"content-type": "text/plain"},
            ),
        ),
        "not_found": (0.02, lambda: Request("GET", "/api/v1/nothing")),
        "wrong_method": (0.02, lambda: Request("GET", "/api/v1/pulse")),
        "over_limit": (
            0.03,
            lambda: Request("POST", "/api/v1/history", json={**history, "scales": [1.0] * 101}),
        ),
        "too_large": (
            0.02,
            lambda: Request(
                "POST",
                "/api/v1/pulse",
                content=b'{"pad": "' + b"x" * (MAX_BODY + 1024) + b'"}',
                headers=ctype,
            ),
        ),
    }


@dataclass
class Outcome:
    """One answer: request kind, HTTP status (0: transport error) and latency [s]."""

    kind: str
    status: int
    seconds: float


async def _send(client: Any, kind: str, req: Request) -> Outcome:
    import httpx

    start = time.perf_counter()
    try:
        res = await client.request(
            req.method, req.path, json=req.json, content=req.content, headers=req.headers
        )
        await res.aread()
        status = res.status_code
    except httpx.HTTPError:
        status = 0
    return Outcome(kind, status, time.perf_counter() - start)


async def run_load(
    url: str, plan: list[tuple[str, Request]], concurrency: int
) -> tuple[list[Outcome], float]:
    """Send ``plan`` with ``concurrency`` clients; return the outcomes and the wall time [s]."""
    import httpx

    queue: asyncio.Queue[tuple[str, Request]] = asyncio.Queue()
    for item in plan:
        queue.put_nowait(item)
    outcomes: list[Outcome] = []

    async def client_loop() -> None:
        limits = httpx.Limits(max_connections=1, max_keepalive_connections=1)
        async with httpx.AsyncClient(
            base_url=url, timeout=REQUEST_TIMEOUT_S, limits=limits
        ) as client:
            while True:
                try:
                    kind, req = queue.get_nowait()
                except asyncio.QueueEmpty:
                    return
                outcomes.append(await _send(client, kind, req))

    start = time.perf_counter()
    await asyncio.gather(*(client_loop() for _ in range(concurrency)))
    return outcomes, time.perf_counter() - start


def _pct(values: list[float], q: float) -> float:
    if not values:
        return float("nan")
    return float(np.percentile(np.asarray(values), q))


def summarise(outcomes: list[Outcome]) -> dict[str, Any]:
    """Per kind and in total: count, p50, p99 [s] and counts by status."""
    kinds: dict[str, list[Outcome]] = {}
    for o in outcomes:
        kinds.setdefault(o.kind, []).append(o)
    rows = {}
    for kind, items in sorted(kinds.items()):
        times = [o.seconds for o in items]
        statuses: dict[str, int] = {}
        for o in items:
            key = "transport error" if o.status == 0 else str(o.status)
            statuses[key] = statuses.get(key, 0) + 1
        rows[kind] = {
            "count": len(items),
            "p50_s": _pct(times, 50),
            "p99_s": _pct(times, 99),
            "mean_s": statistics.fmean(times),
            "statuses": statuses,
        }
    totals: dict[str, int] = {}
    for o in outcomes:
        key = "transport error" if o.status == 0 else str(o.status)
        totals[key] = totals.get(key, 0) + 1
    all_times = [o.seconds for o in outcomes]
    return {
        "kinds": rows,
        "statuses": dict(sorted(totals.items())),
        "p50_s": _pct(all_times, 50),
        "p99_s": _pct(all_times, 99),
    }


def _ms(seconds: float) -> str:
    return f"{seconds * 1e3:.2f} ms"


def _mib(n: int) -> str:
    return f"{n / 2**20:.1f} MiB"


def markdown(report: dict[str, Any], info: dict[str, str], command: str) -> str:
    """Return the ``service_load`` section of ``docs/benchmarks.md``."""
    s = report["summary"]
    mem = report["memory"]
    growth = mem["after"] / mem["warm"] - 1.0
    rows = [
        [
            kind,
            str(r["count"]),
            _ms(r["p50_s"]),
            _ms(r["p99_s"]),
            ", ".join(f"{k}: {v}" for k, v in sorted(r["statuses"].items())),
        ]
        for kind, r in s["kinds"].items()
    ]
    fivexx = sum(v for k, v in s["statuses"].items() if k.startswith("5"))
    checks = [
        ["no 5xx", f"{fivexx} answers with 5xx", "yes" if fivexx == 0 else "NO"],
        [
            "memory growth < 10 %",
            f"{100 * growth:+.1f} % (after warm-up {_mib(mem['warm'])} -> after run "
            f"{_mib(mem['after'])})",
            "yes" if growth < TARGET_GROWTH else "NO",
        ],
    ]
    single = report["single"]["kinds"]
    for kind, target in TARGET_P50.items():
        p50 = single[kind]["p50_s"]
        checks.append(
            [
                f"p50 {kind} <= {_ms(target)} (one request at a time)",
                f"{_ms(p50)} (p99 {_ms(single[kind]['p99_s'])}; under load: p50 "
                f"{_ms(s['kinds'][kind]['p50_s'])})",
                "yes" if p50 <= target else "NO",
            ]
        )
    lines = [
        "## REST service under load (`benchmarks/load.py`)",
        "",
        f"Command: `{command}`; {report['requests']} requests at concurrency "
        f"{report['concurrency']}, mix seed {report['seed']}; wall time "
        f"{report['wall_s']:.1f} s ({report['requests'] / report['wall_s']:.0f} requests/s).",
        "",
        f"- Date: {info['date']}; rockmech commit: {info['commit']}",
        f"- CPU: {info['cpu']}; nproc = {info['nproc']}; load average at start: "
        f"{report['load_start']}, at the end: {report['load_end']}",
        f"- {info['os']}; Python {info['python']}; "
        + ", ".join(
            f"{k} {info[k]}" for k in ("fastapi", "uvicorn", "numpy", "numba") if k in info
        ),
        "- Server: `rockmech serve` (one uvicorn process, 2 compute processes, default budget), "
        "client: httpx on the same machine, one connection per concurrent client. Latency is "
        "measured by the client, from sending a request to reading the whole answer.",
        "- Figures taken while other work shares the 2 cores are provisional; "
        "re-run on a quiet machine.",
        "",
        md_table(["kind", "requests", "p50", "p99", "statuses"], rows),
        "",
        "One request at a time (before the load; the latency targets): "
        + "; ".join(
            f"{kind} p50 {_ms(r['p50_s'])}, p99 {_ms(r['p99_s'])} ({r['count']} requests)"
            for kind, r in single.items()
        )
        + ". Under the load each request mostly waits behind the other 31 clients' requests "
        "(latency = concurrency / throughput), so its latency measures throughput, not the "
        "cost of one request.",
        "",
        f"All requests: p50 {_ms(s['p50_s'])}, p99 {_ms(s['p99_s'])}; statuses: "
        + ", ".join(f"{k}: {v}" for k, v in s["statuses"].items())
        + ".",
        "",
        f"Server memory (server + compute processes, resident): after start-up "
        f"{_mib(mem['start'])}, after warm-up {_mib(mem['warm'])}, after the run "
        f"{_mib(mem['after'])}.",
        "",
        md_table(["target", "measured", "met"], checks),
    ]
    return "\n".join(lines)


def main(argv: Optional[list[str]] = None) -> int:
    """Run the load test; print the tables; write the docs section unless ``--no-docs``."""
    from solver_service.api.server import background_server, process_rss_bytes

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--requests", type=int, default=10_000, help="requests to send")
    ap.add_argument("--concurrency", type=int, default=32, help="concurrent clients")
    ap.add_argument("--seed", type=int, default=1, help="seed of the request mix")
    ap.add_argument("--no-docs", action="store_true", help="do not rewrite docs/benchmarks.md")
    ap.add_argument("--json", type=Path, default=None, help="also write the results here")
    args = ap.parse_args(argv)
    if not 1 <= args.requests <= 100_000 or not 1 <= args.concurrency <= 256:
        ap.error("--requests must be in [1, 100000] and --concurrency in [1, 256]")
    mix = build_mix()
    rng = random.Random(args.seed)
    names = list(mix)
    weights = [mix[k][0] for k in names]
    plan = [(k, mix[k][1]()) for k in rng.choices(names, weights, k=args.requests)]
    warmup = [(k, mix[k][1]()) for k in names for _ in range(WARMUP_PER_KIND)]
    info = machine_info(("numpy", "numba", "fastapi", "uvicorn", "httpx"))
    load_start = load_average()
    with tempfile.TemporaryDirectory(prefix="rockmech-load-") as tmp:
        log = Path(tmp) / "server.log"
        with background_server(SETTINGS, log) as (url, proc):
            mem_start = process_rss_bytes(proc.pid)
            asyncio.run(run_load(url, warmup, min(args.concurrency, 8)))
            mem_warm = process_rss_bytes(proc.pid)
            serial = [(k, mix[k][1]()) for k, n in LATENCY_SAMPLES.items() for _ in range(n)]
            single, _ = asyncio.run(run_load(url, serial, 1))
            outcomes, wall = asyncio.run(run_load(url, plan, args.concurrency))
            mem_after = process_rss_bytes(proc.pid)
            alive = proc.poll() is None
        server_log = log.read_text()
    summary = summarise(outcomes)
    report = {
        "single": summarise(single),
        "requests": args.requests,
        "concurrency": args.concurrency,
        "seed": args.seed,
        "wall_s": wall,
        "summary": summary,
        "memory": {"start": mem_start, "warm": mem_warm, "after": mem_after},
        "server_alive_after": alive,
        "server_log_tracebacks": server_log.count("Traceback"),
        "load_start": load_start,
        "load_end": load_average(),
    }
    rows = [
        [k, str(r["count"]), _ms(r["p50_s"]), _ms(r["p99_s"]), json.dumps(r["statuses"])]
        for k, r in summary["kinds"].items()
    ]
    print(text_table(["kind", "n", "p50", "p99", "statuses"], rows))
    print(f"all: p50 {_ms(summary['p50_s'])}, p99 {_ms(summary['p99_s'])}; {summary['statuses']}")
    for kind, r in report["single"]["kinds"].items():
        print(
            f"one at a time, {kind}: p50 {_ms(r['p50_s'])}, p99 {_ms(r['p99_s'])}, {r['statuses']}"
        )
    print(
        f"memory: start {_mib(mem_start)}, warm {_mib(mem_warm)}, after {_mib(mem_after)}; "
        f"wall {wall:.1f} s"
    )
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=2) + "\n")
    if not args.no_docs:
        command = "python benchmarks/load.py" + (
            "" if argv is None and len(sys.argv) == 1 else " " + " ".join(sys.argv[1:])
        )
        path = write_section(DOC_MD, "service_load", markdown(report, info, command))
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
