"""An IDA's tasks on a dask.distributed cluster.

The constants travel to every worker once (broadcast); each worker thread holds ``IN_FLIGHT``
tasks, and a task's records are scattered to the worker that runs it just before it is sent,
once per worker, and released when their tasks are done (``_DaskFeed``). Ctrl+C and the time
limit are taken only where they cannot cut one of distributed's calls in half
(``_Interrupts``), and the noise such an interrupt leaves in distributed's logs is dropped.
Every worker must run this rockmech (``worker_version``); workers without rockmech's Dask
settings (``DASK_SETTINGS``) are named in the document.
"""

from __future__ import annotations

import contextlib
import logging
import math
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable, Sequence
from concurrent.futures import CancelledError
from typing import Any, Optional

from shared_schema.errors import InputError
from shared_schema.extras import require
from shared_schema.version import __version__

from .plan import Task, plan_tasks, task_seconds
from .task import run_task

__all__ = [
    "CONNECT_TIMEOUT_S",
    "DASK_SETTINGS",
    "IN_FLIGHT",
    "REFRESH_S",
    "RETRIES",
    "SCHEMES",
    "run_on_cluster",
    "settings_differ",
    "worker_settings",
    "worker_version",
]

#: Seconds to wait for a Dask scheduler, and for its first worker, before giving up.
CONNECT_TIMEOUT_S = 10.0
#: Address schemes of a Dask scheduler that rockmech connects to.
SCHEMES = ("tcp", "tls", "ws", "wss")
#: Tasks a Dask worker holds per thread (one running, the next ones ready).
IN_FLIGHT = 2
#: Times a task lost with a worker is run again before the run stops.
RETRIES = 3
#: Interval at which a Dask run reads the list of workers again [s].
REFRESH_S = 1.0
#: Dask's settings for a rockmech cluster (docs/cluster.md, "Dask's settings"), in Dask's
#: dotted keys. Dask's defaults wake every process 50 times a second to time its event loop
#: (``tick``) and sample each worker thread's stack 100 times a second (``profile``): an idle
#: 2-worker cluster took 10-14 % of a core with them, 3.4 % with these settings
#: (``benchmarks/cluster.py``). The tick only feeds the "event loop was unresponsive" warning
#: (after 3 s), which a 1 s tick still gives; the profile feeds the dashboard's profile page.
DASK_SETTINGS: dict[str, Any] = {
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.profile.enabled": False,
}


def _check_address(address: str) -> None:
    """Refuse a scheduler address that is not ``scheme://host:port`` (or ``host:port``)."""
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    host, colon, port = rest.rpartition(":")
    problem = ""
    if scheme not in SCHEMES:
        problem = f"unknown scheme {scheme!r} (use one of {', '.join(SCHEMES)})"
    elif not colon or not host or not port.isdigit() or not 0 < int(port) < 65536:
        problem = "it needs a host and a port number 1-65535"
    if problem:
        raise InputError(
            f"expected a Dask scheduler address like tcp://host:8786, got {address!r}: {problem}",
            "scheduler",
        )


def _dask_client(distributed: Any, address: str, timeout: float) -> Any:
    _check_address(address)
    try:
        return distributed.Client(address, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(
            f"cannot reach the Dask scheduler at {address} within {timeout:g} s ({exc})",
            "scheduler",
        ) from exc


def worker_version() -> str:
    """Return this process's rockmech version (asked of every Dask worker before a run)."""
    return __version__


def worker_settings() -> dict[str, Any]:
    """Return this process's values of the keys of ``DASK_SETTINGS`` (asked of the workers)."""
    import dask

    return {key: dask.config.get(key, None) for key in DASK_SETTINGS}


def _same_setting(value: Any, wanted: Any) -> bool:
    """Whether a Dask setting has the value wanted (times compared as seconds)."""
    if isinstance(wanted, str):
        from dask.utils import parse_timedelta

        try:
            return bool(parse_timedelta(value) == parse_timedelta(wanted))
        except (TypeError, ValueError, KeyError):
            return False
    return bool(value == wanted)


def settings_differ(client: Any) -> list[str]:
    """Return the ``DASK_SETTINGS`` the cluster's workers run otherwise, one line each.

    Empty where every worker has rockmech's settings (or where they cannot be read: the run
    goes on, this only tells how fast it could go).
    """
    try:
        found = client.run(worker_settings)
    except Exception:  # only a hint about speed: what fails here, the run itself reports
        return []
    lines = []
    for key, wanted in DASK_SETTINGS.items():
        off = [str(v[key]) for v in found.values() if not _same_setting(v[key], wanted)]
        if off:
            values = " / ".join(sorted(set(off)))
            lines.append(
                f"{key}: {values} on {len(off)} of {len(found)} workers (rockmech: {wanted})"
            )
    return lines


def _wait_for_workers(client: Any, address: str, timeout: float, left: str) -> None:
    """Wait up to ``timeout`` [s] for a worker; else an error naming ``left`` (work left)."""
    try:
        client.wait_for_workers(1, timeout=timeout)
    except (OSError, TimeoutError) as exc:
        raise InputError(
            f"no worker {'is left on' if left else 'joined'} the Dask scheduler at {address} "
            f"within {timeout:g} s{f' ({left})' if left else ''}; start workers with "
            f"`dask worker {address}`",
            "scheduler",
        ) from exc


def _cluster_threads(client: Any, address: str, timeout: float) -> tuple[int, int]:
    """(workers, threads) of the cluster, once one worker is there and all run this rockmech.

    Raises
    ------
    InputError
        No worker within ``timeout``, a worker that cannot import rockmech, or one with
        another version (field ``scheduler``).
    """
    _wait_for_workers(client, address, timeout, "")
    try:
        versions = client.run(worker_version)
    except Exception as exc:  # any failure on a worker: one line, not a traceback
        raise InputError(
            f"the Dask workers at {address} cannot run rockmech ({type(exc).__name__}: {exc}); "
            f"install rockmech {__version__} with the dask extra on every worker",
            "scheduler",
        ) from exc
    other = {w: v for w, v in versions.items() if v != __version__}
    if other:
        worker, version = sorted(other.items())[0]
        raise InputError(
            f"worker {worker} runs rockmech {version}, this machine {__version__} "
            f"({len(other)} of {len(versions)} workers differ); install the same version on "
            "every worker",
            "scheduler",
        )
    threads = client.nthreads()
    return len(threads), sum(int(n) for n in threads.values())


class _DaskFeed:
    """Tasks fed to the workers as they free up: each holds ``IN_FLIGHT`` per thread.

    A task goes to the worker with the most free places, and its records are scattered to
    that worker just before (once per worker: the blocks of levels of a long record that
    land on the same worker share them); a finished task frees its place there, so a slow
    worker gets fewer tasks, and records are in the cluster's memory only while their tasks
    are. Workers that join during the run get tasks from then on (the list of workers is
    read again every ``REFRESH_S``).
    """

    def __init__(
        self,
        client: Any,
        distributed: Any,
        ctx: dict[str, Any],
        records: list[tuple[int, Any, float, str]],
        packs: list[list[int]],
        tasks: list[Task],
    ) -> None:
        self.client, self.distributed = client, distributed
        self.records, self.packs, self.n = records, packs, len(tasks)
        self.retries: dict[Task, int] = {}
        self.queue = list(enumerate(tasks))[::-1]  # popped from the end: longest first
        self.left = [0] * len(packs)
        for task in tasks:
            self.left[task.pack] += 1
        self.held: dict[tuple[int, str], Any] = {}  # (pack, worker) -> scattered records
        self.places: dict[str, int] = {}  # worker -> free places
        self.running: dict[str, tuple[Task, str, Any]] = {}  # key -> (task, worker, future)
        self.done = distributed.as_completed()
        self.refreshed = -math.inf
        # In a list: a dict given alone would be scattered as one key per entry.
        [self.shared] = client.scatter([ctx], broadcast=True, hash=False)

    def refresh(self) -> None:
        """Read the workers again: new ones get places, those gone lose theirs."""
        if time.monotonic() - self.refreshed < REFRESH_S:
            return
        self.refreshed = time.monotonic()
        threads = self.client.nthreads()
        for worker, n in threads.items():
            if worker not in self.places:
                self.places[worker] = IN_FLIGHT * int(n)
        for worker in set(self.places) - set(threads):
            del self.places[worker]

    def fill(self) -> None:
        """Submit tasks, longest first, while a worker has a free place."""
        while self.queue and self.places:
            worker = max(self.places, key=lambda w: self.places[w])
            if self.places[worker] <= 0:
                return
            k, task = self.queue.pop()
            held = self.held.get((task.pack, worker))
            if held is None:
                data = [self.records[i] for i in self.packs[task.pack]]
                [held] = self.client.scatter([data], workers=[worker], hash=False)
                self.held[(task.pack, worker)] = held
            future = self.client.submit(
                run_task,
                self.shared,
                held,
                task.lo,
                task.hi,
                step=task.step,
                workers=[worker],
                allow_other_workers=True,  # a worker that leaves does not strand its tasks
                pure=False,
                priority=self.n - k,
            )
            self.places[worker] -= 1
            self.running[future.key] = (task, worker, future)
            self.done.add(future)

    def finish(self, future: Any) -> Optional[dict[str, Any]]:
        """Take a finished task's result; free its place; release records no task needs.

        A task lost with a worker (its records went with it, or the worker died while
        running it) is queued again, up to ``RETRIES`` times: None is returned for it.
        """
        task, worker, _ = self.running.pop(future.key)
        if worker in self.places:
            self.places[worker] += 1
        try:
            part: dict[str, Any] = future.result()
        except (CancelledError, self.distributed.KilledWorker) as exc:
            self.held.pop((task.pack, worker), None)
            self.retries[task] = self.retries.get(task, 0) + 1
            if self.retries[task] > RETRIES:
                raise InputError(
                    f"a task was lost {RETRIES + 1} times with the workers that ran it "
                    f"({type(exc).__name__}: {exc}); check that the workers stay up",
                    "scheduler",
                ) from exc
            self.queue.append((-1, task))  # next to start, first on its worker
            self.places.pop(worker, None)  # until the next refresh finds it alive
            return None
        self.left[task.pack] -= 1
        if self.left[task.pack] == 0:
            for key in [key for key in self.held if key[0] == task.pack]:
                del self.held[key]
        return part

    def cancel(self) -> None:
        """Cancel what this run has on the cluster: its tasks and its data."""
        futures = [f for *_, f in self.running.values()] + [*self.held.values(), self.shared]
        with contextlib.suppress(Exception):  # a lost connection: the scheduler drops them
            self.client.cancel(futures, force=True)


class _Interrupts:
    """Ctrl+C and the time limit on a Dask run, taken only where they cannot cut a call in half.

    On the main thread, where SIGINT raises ``KeyboardInterrupt`` (Python's own handler) and
    where the command line's time limit (``workflows.limits.time_limit``) handles SIGALRM:
    while the client scatters, submits, takes a result or cancels, either signal is held, and
    acted on when the client next waits (``taken``), Ctrl+C first; while it waits for a task
    to finish or for a worker, it is acted on at once. An interrupt inside distributed's calls
    left half-built futures and tracebacks after the one-line message. Elsewhere (another
    thread, other handlers) nothing changes.
    """

    def __init__(self) -> None:
        self.open = False
        self.held: dict[int, Any] = {}  # signal held -> the frame it came in
        self.previous: dict[int, Any] = {}

    def __enter__(self) -> _Interrupts:
        if threading.current_thread() is not threading.main_thread():
            return self
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self.previous[signal.SIGINT] = signal.signal(signal.SIGINT, self._handler)
        alarm = getattr(signal, "SIGALRM", None)
        if alarm is not None and callable(signal.getsignal(alarm)):
            self.previous[alarm] = signal.signal(alarm, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        for signum, handler in self.previous.items():
            signal.signal(signum, handler)
        if exc[0] is None:  # held to the end: acted on now
            self._release()

    def _handler(self, signum: int, frame: Any) -> None:
        if self.open:
            self._act(signum, frame)
        else:
            self.held[signum] = frame

    def _act(self, signum: int, frame: Any) -> None:
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        self.previous[signum](signum, frame)  # the time limit's: raises TimeLimitExceeded

    def _release(self) -> None:
        for signum in sorted(self.held, key=lambda s: s != signal.SIGINT):  # Ctrl+C first
            frame = self.held.pop(signum)
            self._act(signum, frame)

    @contextlib.contextmanager
    def taken(self) -> Any:
        """Act on a held signal now, and on one at once while the block runs (a wait)."""
        self._release()
        self.open = True
        try:
            yield
        finally:
            self.open = False


def _completed(done: Any, stops: _Interrupts) -> Any:
    """Yield the finished futures of ``done``, taking Ctrl+C only while waiting for one."""
    futures = iter(done)
    while True:
        with stops.taken():
            future = next(futures, None)
        if future is None:
            return
        yield future


class _OnPart(Exception):
    """An error of the caller's handling of a result, carried past the connection's errors."""

    def __init__(self, error: OSError) -> None:
        super().__init__(str(error))
        self.error = error


def _run_dask(
    client: Any,
    distributed: Any,
    address: str,
    timeout: float,
    ctx: dict[str, Any],
    records: list[tuple[int, Any, float, str]],
    packs: list[list[int]],
    tasks: list[Task],
    on_part: Callable[[dict[str, Any]], None],
    stops: _Interrupts,
) -> None:
    """Run the tasks on the cluster: constants broadcast, records scattered, each once."""
    feed: Optional[_DaskFeed] = None
    try:
        with client.as_current():
            feed = _DaskFeed(client, distributed, ctx, records, packs, tasks)
            feed.refresh()
            feed.fill()
            while True:
                for future in _completed(feed.done, stops):
                    part = feed.finish(future)
                    if part is not None:
                        try:
                            on_part(part)
                        except OSError as exc:  # writing the peaks, not the connection
                            raise _OnPart(exc) from exc
                    feed.refresh()
                    feed.fill()
                if not feed.queue:
                    break
                # Tasks left and none running: the workers left (or lost tasks); wait for one.
                with stops.taken():
                    _wait_for_workers(client, address, timeout, f"{len(feed.queue)} tasks to run")
                feed.refreshed = -math.inf
                feed.refresh()
                feed.fill()
    except _OnPart as wrapped:
        if feed is not None:
            feed.cancel()
        raise wrapped.error from None
    except (OSError, TimeoutError) as exc:  # the connection to the scheduler was lost
        if feed is not None:
            feed.cancel()
        raise InputError(
            f"lost the connection to the Dask scheduler at {address} during the run ({exc})",
            "scheduler",
        ) from exc
    except BaseException:
        # Stopped (time limit, Ctrl+C, a task's error): nothing of this run stays queued
        # or running on the cluster.
        if feed is not None:
            feed.cancel()
        raise


def _drop_interrupt_noise(record: logging.LogRecord) -> bool:
    """Drop the traceback distributed logs when Ctrl+C lands inside one of its calls.

    ``distributed.utils.sync`` schedules a cancel callback that reads a variable set only
    once its call started; an interrupt before that logs a ``NameError`` traceback through
    tornado after rockmech's own one-line message. The interrupt itself is handled (the
    run's tasks are cancelled), so that log says nothing to the user.
    """
    exc = record.exc_info[1] if record.exc_info else None
    if not isinstance(exc, NameError):
        return True
    frames = traceback.extract_tb(exc.__traceback__)
    return not (frames and "distributed" in frames[-1].filename)


class _QuietHalfBuilt:
    """``sys.unraisablehook`` that drops the error of a half-built distributed object's ``__del__``.

    Ctrl+C inside ``distributed.Future.__init__`` leaves an object whose ``__del__`` raises
    ``AttributeError`` when it is collected, printed as "Exception ignored in ..." after
    rockmech's one-line message. The interrupt itself is handled; every other unraisable error
    goes to the hook there was before.
    """

    def __init__(self, previous: Callable[[Any], Any]) -> None:
        self.previous = previous

    def __call__(self, unraisable: Any) -> None:
        module = getattr(unraisable.object, "__module__", "") or ""
        if isinstance(unraisable.exc_value, AttributeError) and module.startswith("distributed"):
            return
        self.previous(unraisable)


def run_on_cluster(
    ctx: dict[str, Any],
    records: list[tuple[int, Any, float, str]],
    costs: Sequence[float],
    scheduler: str,
    timeout: float,
    task_s: Optional[float],
    on_part: Callable[[dict[str, Any]], None],
) -> dict[str, Any]:
    """Plan the tasks for the cluster's worker threads and run them there.

    Parameters
    ----------
    ctx : dict
        The run's shared data (``task.run_task``).
    records : list of (int, ndarray, float, str)
        ``(index, acceleration [m/s²], dt [s], name)`` of every record.
    costs : sequence of float
        Estimated work of each record at all levels [s] (``plan.record_costs``).
    scheduler : str
        Address of the dask.distributed scheduler (``tcp://host:8786``).
    timeout : float
        Seconds to wait for the scheduler, and for a worker [s].
    task_s : float, optional
        Work per task aimed at [s] (default ``plan.task_seconds``).
    on_part : callable
        Called with each finished task's result.

    Returns
    -------
    dict
        The ``backend`` entry of the document: ``kind``, ``scheduler``, ``n_workers``,
        ``threads``, ``tasks`` and, where workers run other Dask settings, ``settings_differ``.
    """
    # Checked before anything else touches dask: a missing extra names its install line.
    distributed = require("dask.distributed", "dask", "for ida --scheduler")
    client = _dask_client(distributed, scheduler, timeout)
    # Kept for the process: the callback may run after the run has ended.
    logging.getLogger("tornado.application").addFilter(_drop_interrupt_noise)
    if not isinstance(sys.unraisablehook, _QuietHalfBuilt):
        sys.unraisablehook = _QuietHalfBuilt(sys.unraisablehook)
    n_levels = len(ctx["levels"])
    with _Interrupts() as stops:
        try:
            with stops.taken():  # waits for the first worker
                n_workers, n_threads = _cluster_threads(client, scheduler, timeout)
            differ = settings_differ(client)
            packs, tasks = plan_tasks(
                costs, n_levels, task_s or task_seconds(sum(costs), n_threads)
            )
            _run_dask(
                client, distributed, scheduler, timeout, ctx, records, packs, tasks, on_part, stops
            )
        finally:
            client.close()
    backend: dict[str, Any] = {"kind": "dask", "scheduler": scheduler, "n_workers": n_workers}
    backend.update(threads=n_threads, tasks=len(tasks))
    if differ:
        backend["settings_differ"] = differ
    return backend
