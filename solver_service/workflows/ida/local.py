"""An IDA's tasks on threads of this process."""

from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, as_completed
from typing import Any

from .plan import Task
from .task import run_task

__all__ = ["run_local"]


def run_local(
    ctx: dict[str, Any],
    records: list[tuple[int, Any, float, str]],
    packs: list[list[int]],
    tasks: list[Task],
    jobs: int,
    on_part: Callable[[dict[str, Any]], None],
) -> None:
    """Run the tasks on ``jobs`` threads of this process, longest first."""
    stop = threading.Event()
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = [
            pool.submit(
                run_task, ctx, [records[i] for i in packs[t.pack]], t.lo, t.hi, stop, t.step
            )
            for t in tasks
        ]
        try:
            for future in as_completed(futures):
                on_part(future.result())
        except BaseException:
            # Stopped (time limit, Ctrl+C, an error): drop the queued tasks; the running ones
            # end after their current record, and the pool waits for them.
            stop.set()
            pool.shutdown(wait=False, cancel_futures=True)
            raise
