"""A bounded pool of compute processes with a time budget per job.

Why processes. The solver's numba kernels cannot be interrupted from outside, and a
thread cannot be killed, so a computation that overruns its budget in a thread would keep
a core busy (and its memory) until it ended by itself. In a separate process it can be
abandoned safely: the pool ends that process (SIGKILL), answers 503 and starts a fresh
process in its place. The server process itself never computes, so it stays responsive.

Why not ``concurrent.futures.ProcessPoolExecutor``: it pickles its messages and cannot end
one worker without breaking the whole pool. Here each worker speaks framed JSON on its
stdin/stdout (``solver_service.api.worker``), and no pickle is used.

Every process warms its kernels up before it takes work (numba loads them from its cache),
so a replacement does not make the next request pay for compilation. The processes start in
the background: the server answers at once (``/health`` says ``starting`` until every process
has warmed up, and a request waits for a free one as for a busy pool). A process that does
not warm up within ``startup_timeout_s`` (a busy machine, kernels still being compiled) is
ended and started again with twice the time; one that exits while starting is started again
after a pause (``RESTART_PAUSE_S``, doubling up to ``RESTART_PAUSE_MAX_S``). Each of these is
one line in the log, never a traceback, and the server keeps running.

Faults. A worker that dies while idle is noticed (a watcher awaits every process) and
replaced, and a worker is checked to be alive before it is handed out. A job whose worker
died before it received the whole job is retried once on another worker: jobs are pure
computations, so that is safe. A worker that dies while computing is a fault of the
service: ``WorkerLost`` (503 with ``Retry-After``). A job whose caller gives up (its task is
cancelled) ends its worker at once. Every worker gets a private temporary folder
(``TMPDIR``), removed when the worker ends however it ends, so no temporary file outlives
its process; the folders live under one root per server (``solver_service.api.scratch``).

The server killed. A worker whose server is gone (SIGKILL: the server closed nothing) sees
its stdin, a pipe only the server holds, reach its end: it removes its folder and exits at
once, even in the middle of a job (``solver_service.api.worker``). A server starting removes
the roots of servers no longer running.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import os
import shutil
import sys
import tempfile
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

from . import scratch
from .jobspec import Job

__all__ = ["BudgetExceeded", "ComputePool", "PoolBusy", "WorkerLost", "WorkerResult"]

log = logging.getLogger("rockmech.pool")

#: Largest line the pool reads from a worker [bytes] (headers are small; bodies are framed).
STREAM_LIMIT = 1 << 20
#: Seconds a worker is given to exit after its stdin closes, before it is killed.
EXIT_GRACE_S = 2.0
#: Seconds a client is told to wait before retrying after a worker died (``Retry-After``).
RETRY_AFTER_S = 2
#: First pause before a worker that exited while starting is started again [s]; it doubles
#: on each further failure, up to ``RESTART_PAUSE_MAX_S``.
RESTART_PAUSE_S = 1.0
RESTART_PAUSE_MAX_S = 30.0


class BudgetExceeded(Exception):
    """A job ran past the compute time budget; its process was ended."""


class PoolBusy(Exception):
    """No compute process became free in time."""


class WorkerLost(Exception):
    """A compute process ended while it worked on a job (it has been replaced)."""


class _SendFailed(Exception):
    """The worker was gone before it received the whole job (safe to retry)."""


class _StartFailed(Exception):
    """A worker did not warm up in time, or exited while starting (the message says which)."""


@dataclass(frozen=True)
class WorkerResult:
    """A job's answer from a worker."""

    status: int
    media_type: str
    body: bytes


@dataclass(eq=False)
class _Worker:
    proc: asyncio.subprocess.Process
    tmpdir: str
    ready: bool = False
    jobs: int = 0
    watcher: Optional[asyncio.Task[None]] = field(default=None, repr=False)


def _running(proc: asyncio.subprocess.Process) -> bool:
    """Return True if ``proc`` has not exited (an unreaped zombie has exited)."""
    if proc.returncode is not None:
        return False
    try:
        stat = Path(f"/proc/{proc.pid}/stat").read_text()
    except FileNotFoundError:
        return False
    except OSError:  # pragma: no cover - no /proc: trust the return code
        return True
    # Field 3, after the parenthesised command name, is the state; Z and X are dead.
    return stat.rsplit(")", 1)[-1].split()[0] not in ("Z", "X")


class ComputePool:
    """Run jobs in ``size`` worker processes, each job within ``timeout_s`` seconds.

    Parameters
    ----------
    size : int
        Number of worker processes.
    timeout_s : float
        Compute time budget of one job [s].
    queue_timeout_s : float
        Longest wait for a free worker [s].
    startup_timeout_s : float
        Longest start-up of one worker [s].
    limits : dict
        Size limits passed to every job.
    """

    def __init__(
        self,
        size: int,
        timeout_s: float,
        queue_timeout_s: float,
        startup_timeout_s: float,
        limits: dict[str, Any],
    ) -> None:
        self.size = size
        self.timeout_s = timeout_s
        self.queue_timeout_s = queue_timeout_s
        self.startup_timeout_s = startup_timeout_s
        self.limits = dict(limits)
        self._idle: deque[_Worker] = deque()
        self._all: set[_Worker] = set()
        self._tasks: set[asyncio.Task[None]] = set()
        self._cond: Optional[asyncio.Condition] = None
        self._closing = False
        self._started = 0  # workers of the first start that have warmed up
        self._root: Optional[str] = None  # the workers' temporary folders live in it

    @property
    def ready(self) -> bool:
        """True once every worker of the first start has warmed up (``/health``: ``ok``)."""
        return self._started >= self.size

    @property
    def alive(self) -> int:
        """Number of worker processes that have warmed up and are running (ready or busy)."""
        return sum(1 for w in self._all if w.ready and _running(w.proc))

    def pids(self) -> list[int]:
        """Process ids of the running workers (for memory reports and fault tests)."""
        return [w.proc.pid for w in self._all if _running(w.proc)]

    def _condition(self) -> asyncio.Condition:
        if self._cond is None:
            self._cond = asyncio.Condition()
        return self._cond

    async def start(self) -> None:
        """Start every worker in the background (``ready`` says when all have warmed up).

        First removes what servers no longer running left in the temporary folder
        (``scratch.sweep``), then makes this server's root for the workers' folders.
        """
        for root in scratch.sweep():
            log.warning("removed %s, left by a service that is no longer running", root)
        self._root = scratch.make_root()
        for _ in range(self.size):
            self._background(self._start_one(initial=True))

    async def _start_one(self, initial: bool = False) -> None:
        """Start one worker, again and again until one warms up (one log line per failure)."""
        timeout, pause = self.startup_timeout_s, RESTART_PAUSE_S
        while not self._closing:
            try:
                await self._spawn(timeout)
            except (_StartFailed, OSError) as exc:
                if isinstance(exc, _StartFailed) and "did not warm up" in str(exc):
                    log.warning("%s; starting it again with %g s", exc, 2 * timeout)
                    timeout *= 2
                else:
                    log.warning("%s; starting it again in %g s", exc, pause)
                    await asyncio.sleep(pause)
                    pause = min(2 * pause, RESTART_PAUSE_MAX_S)
                continue
            if initial:
                self._started += 1
            return

    async def _spawn(self, timeout_s: float) -> None:
        if self._root is None or not os.path.isdir(self._root):  # removed under us: anew
            self._root = scratch.make_root()
        tmpdir = tempfile.mkdtemp(prefix=scratch.WORKER_PREFIX, dir=self._root)
        proc = await asyncio.create_subprocess_exec(
            sys.executable,
            "-m",
            "solver_service.api.worker",
            stdin=asyncio.subprocess.PIPE,
            stdout=asyncio.subprocess.PIPE,
            limit=STREAM_LIMIT,
            env={**os.environ, "TMPDIR": tmpdir},
        )
        worker = _Worker(proc, tmpdir)
        self._all.add(worker)
        try:
            assert proc.stdout is not None
            try:
                line = await asyncio.wait_for(proc.stdout.readline(), timeout_s)
            except asyncio.TimeoutError:
                raise _StartFailed(
                    f"compute process {proc.pid} did not warm up within {timeout_s:g} s "
                    "(ROCKMECH_STARTUP_TIMEOUT_S; a busy machine, or kernels being compiled)"
                ) from None
            try:
                ready = bool(json.loads(line or b"{}").get("ready"))
            except ValueError:
                ready = False
            if not ready:
                with contextlib.suppress(asyncio.TimeoutError):
                    await asyncio.wait_for(proc.wait(), EXIT_GRACE_S)
                raise _StartFailed(
                    f"compute process {proc.pid} stopped while starting (exit code "
                    f"{proc.returncode}; its messages are above)"
                )
        except BaseException:
            await self._end(worker)
            raise
        if self._closing:
            await self._end(worker)
            return
        worker.ready = True
        worker.watcher = self._background(self._watch(worker))
        await self._release(worker)

    def _background(self, coro: Any) -> asyncio.Task[None]:
        task: asyncio.Task[None] = asyncio.get_running_loop().create_task(coro)
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)
        return task

    async def _watch(self, worker: _Worker) -> None:
        """Replace ``worker`` when it exits on its own (killed while idle, out of memory)."""
        await worker.proc.wait()
        if worker in self._all and not self._closing:
            log.warning("compute process %d exited (%s)", worker.proc.pid, worker.proc.returncode)
            async with self._condition():
                if worker in self._idle:
                    self._idle.remove(worker)
            self._replace(worker)

    async def _release(self, worker: _Worker) -> None:
        async with self._condition():
            self._idle.append(worker)
            self._condition().notify()

    async def _acquire(self) -> _Worker:
        """Hand out an idle worker that is alive; replace any found dead."""
        cond = self._condition()
        deadline = time.monotonic() + self.queue_timeout_s
        async with cond:
            while True:
                while self._idle:
                    worker = self._idle.popleft()
                    if _running(worker.proc):
                        return worker
                    self._replace(worker)
                remaining = deadline - time.monotonic()
                if remaining <= 0 and not self.ready:
                    raise PoolBusy(
                        f"the compute processes are still starting ({self.alive} of "
                        f"{self.size} ready after {self.queue_timeout_s:g} s of waiting); "
                        "try again in a moment"
                    )
                if remaining <= 0:
                    raise PoolBusy(
                        f"all {self.size} compute processes stayed busy for "
                        f"{self.queue_timeout_s:g} s"
                    )
                with contextlib.suppress(asyncio.TimeoutError):
                    await asyncio.wait_for(cond.wait(), remaining)

    def _replace(self, worker: _Worker) -> None:
        """End ``worker`` now (SIGKILL) and start a replacement in the background."""
        if worker not in self._all:
            return
        self._all.discard(worker)
        if worker.proc.returncode is None:
            with contextlib.suppress(ProcessLookupError):
                worker.proc.kill()

        async def replace() -> None:
            await self._end(worker)
            await self._start_one()

        self._background(replace())

    async def _end(self, worker: _Worker, grace_s: float = 0.0) -> None:
        self._all.discard(worker)
        proc = worker.proc
        if proc.returncode is None and grace_s > 0 and proc.stdin is not None:
            proc.stdin.close()
            with contextlib.suppress(asyncio.TimeoutError):
                await asyncio.wait_for(proc.wait(), grace_s)
        if proc.returncode is None:
            with contextlib.suppress(ProcessLookupError):
                proc.kill()
        await proc.wait()
        shutil.rmtree(worker.tmpdir, ignore_errors=True)

    async def run(self, job: Job, blobs: Sequence[bytes] = ()) -> WorkerResult:
        """Run one job and return its answer.

        Raises
        ------
        ValueError
            The job holds a number JSON cannot carry (infinity); no worker was used.
        PoolBusy
            No worker became free within ``queue_timeout_s``.
        BudgetExceeded
            The job took longer than ``timeout_s``; its worker was ended and is being
            replaced.
        WorkerLost
            The worker ended during the job (for example killed by the operating system).
        """
        header: dict[str, Any] = {
            "job": job.model_dump(mode="json", exclude_none=True),
            "limits": self.limits,
            "blobs": [len(b) for b in blobs],
        }
        # Encoded before a worker is taken: a value JSON cannot carry (a derived constant
        # that overflowed) is the request's problem (ValueError), never a worker's.
        line = json.dumps(header, allow_nan=False).encode("utf-8") + b"\n"
        for attempt in (1, 2):
            worker = await self._acquire()
            start = time.perf_counter()
            try:
                result = await asyncio.wait_for(self._exchange(worker, line, blobs), self.timeout_s)
            except asyncio.TimeoutError:
                self._replace(worker)
                raise BudgetExceeded(
                    f"the computation took longer than the service's budget of "
                    f"{self.timeout_s:g} s per request (ROCKMECH_COMPUTE_TIMEOUT_S) and was "
                    "stopped; ask for less work (fewer mechanisms, scale factors, frequencies "
                    "or samples, or method library instead of exact envelopes), or run it with "
                    "the rockmech command line"
                ) from None
            except _SendFailed:
                self._replace(worker)
                if attempt == 1:
                    log.warning("compute process gone before its job; retrying on another")
                    continue
                raise WorkerLost(self._lost_message(worker)) from None
            except (OSError, asyncio.IncompleteReadError, ValueError) as exc:
                self._replace(worker)
                raise WorkerLost(self._lost_message(worker)) from exc
            except BaseException:  # cancelled (client gone) mid-exchange: end the worker now
                self._replace(worker)
                raise
            worker.jobs += 1
            log.debug("job %s took %.3f s", job.kind, time.perf_counter() - start)
            await self._release(worker)
            return result
        raise AssertionError("unreachable")  # pragma: no cover

    @staticmethod
    def _lost_message(worker: _Worker) -> str:
        return (
            f"a compute process stopped while working on this request (exit code "
            f"{worker.proc.returncode}); this is a fault of the service, not of the request, "
            f"and the process has been replaced: try again in {RETRY_AFTER_S} s"
        )

    async def _exchange(self, worker: _Worker, line: bytes, blobs: Sequence[bytes]) -> WorkerResult:
        proc = worker.proc
        assert proc.stdin is not None and proc.stdout is not None
        try:
            proc.stdin.write(line)
            for blob in blobs:
                proc.stdin.write(blob)
            await proc.stdin.drain()
        except (BrokenPipeError, ConnectionResetError) as exc:
            raise _SendFailed() from exc
        line = await proc.stdout.readline()
        if not line:
            raise asyncio.IncompleteReadError(b"", None)
        answer = json.loads(line)
        body = await proc.stdout.readexactly(int(answer["size"]))
        return WorkerResult(int(answer["status"]), str(answer["media_type"]), body)

    async def close(self) -> None:
        """Stop every worker (they exit when their stdin closes; stragglers are killed)."""
        self._closing = True
        for task in list(self._tasks):
            task.cancel()
        await asyncio.gather(*self._tasks, return_exceptions=True)
        await asyncio.gather(*(self._end(w, EXIT_GRACE_S) for w in list(self._all)))
        if self._root is not None:
            shutil.rmtree(self._root, ignore_errors=True)

    def info(self) -> dict[str, Optional[int]]:
        """Return worker counts for the health endpoint."""
        return {"alive": self.alive, "idle": len(self._idle)}
