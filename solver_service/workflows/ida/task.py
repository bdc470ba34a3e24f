"""One task of an IDA: every record of a pack at a block of levels, its runs reduced.

What a local thread or a Dask worker runs (``run_task``): the constants are prepared once per
process (``_setup``), each record runs every mechanism at every level of the block in one
single-threaded batch (``workflows.scaling.run_scaled``), and the runs are reduced to counts,
first overturning levels and the largest error estimate before they travel back.
"""

from __future__ import annotations

import os
import socket
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from shared_schema.constants import ConstantsFile

from ...core.exact import single_threaded
from ...core.model import RockingModel
from ...core.records import GroundMotion
from ..adapter import to_rocking_model
from ..scaling import Building, run_scaled

__all__ = ["SETUPS_KEPT", "run_record", "run_task"]

#: Prepared constants kept per process (a Dask worker keeps those of its latest runs).
SETUPS_KEPT = 4


@dataclass(frozen=True)
class _Setup:
    """What every task of one run shares, prepared once per process (``_setup``)."""

    cf: ConstantsFile
    models: list[RockingModel]
    levels: list[float]
    measure: str
    sf: str
    building: Building
    criterion: Optional[str]
    peaks: bool

    @classmethod
    def build(
        cls,
        constants: dict[str, Any],
        levels: Sequence[float],
        measure: str,
        options: Optional[dict[str, Any]],
        peaks: bool = False,
    ) -> _Setup:
        opts = dict(options or {})
        cf = ConstantsFile.model_validate(constants)
        return cls(
            cf=cf,
            models=[to_rocking_model(m) for m in cf.mechanisms],
            levels=[float(v) for v in levels],
            measure=measure,
            sf=opts.get("sf", "none"),
            building=Building(**opts.get("building", {})),
            criterion=opts.get("criterion"),
            peaks=peaks,
        )


_SETUPS: dict[str, _Setup] = {}
_SETUPS_LOCK = threading.Lock()


def _setup(ctx: dict[str, Any]) -> _Setup:
    """Return the prepared constants of run ``ctx["token"]``, validated once per process."""
    with _SETUPS_LOCK:
        found = _SETUPS.get(ctx["token"])
        if found is None:
            found = _Setup.build(
                ctx["constants"], ctx["levels"], ctx["measure"], ctx["options"], ctx["peaks"]
            )
            _SETUPS[ctx["token"]] = found
            while len(_SETUPS) > SETUPS_KEPT:
                del _SETUPS[next(iter(_SETUPS))]
        return found


def _run_one(
    setup: _Setup, acc: np.ndarray[Any, Any], dt: float, name: str, levels: Sequence[float]
) -> dict[str, Any]:
    """One record against every mechanism at ``levels`` (see ``run_record``)."""
    motion = GroundMotion.from_samples(acc, dt, name=name)
    if setup.measure == "pga":
        scales = [level / motion.pga_g for level in levels]
    else:
        scales = list(levels)
    factors, batches = run_scaled(
        setup.cf, setup.models, motion, scales, setup.sf, setup.building, setup.criterion
    )
    shape = (len(setup.models), len(scales))
    out = {
        "overturned": np.zeros(shape, dtype=bool),
        "peak_ratio": np.zeros(shape),
        "error_estimate": np.zeros(shape),
        "status": np.zeros(shape, dtype=np.int64),
    }
    for members, batch in batches:
        for key in out:
            out[key][members] = getattr(batch, key)
    return {
        **out,
        "name": name,
        "pga_g": motion.pga_g,
        "dt_s": dt,
        "n_samples": len(acc),
        "scale_factors": {k: float(v["value"]) for k, v in factors.items()},
        "criterion": batches[0][1].criterion,
        "method": batches[0][1].method,
        "runtime_s": sum(b.runtime_s for _, b in batches),
    }


def run_record(
    constants: dict[str, Any],
    acc: np.ndarray[Any, Any],
    dt: float,
    name: str,
    levels: list[float],
    measure: str = "scale",
    options: Optional[dict[str, Any]] = None,
) -> dict[str, Any]:
    """Run one record against every mechanism at every intensity level.

    Parameters
    ----------
    constants : dict
        The kinematic-constants document (``ConstantsFile.model_dump()``).
    acc : (n,) float
        Ground acceleration [m/s²].
    dt : float
        Sampling interval [s].
    name : str
        Record name.
    levels : list of float
        Intensity levels, ascending (units of ``measure``).
    measure : {"scale", "pga"}
        Intensity measure.
    options : dict, optional
        ``sf``, ``building`` (dict of ``analysis.Building``) and ``criterion``.

    Returns
    -------
    dict
        ``overturned``, ``peak_ratio``, ``error_estimate`` and ``status`` as (m, k) arrays
        (mechanisms × levels), ``scale_factors`` per mechanism id, ``pga_g`` and
        ``runtime_s``.
    """
    return _run_one(_Setup.build(constants, levels, measure, options), acc, dt, name, levels)


def run_task(
    ctx: dict[str, Any],
    pack: Sequence[tuple[int, np.ndarray[Any, Any], float, str]],
    lo: int,
    hi: int,
    stop: Optional[threading.Event] = None,
    step: int = 1,
) -> dict[str, Any]:
    """One task: every record of ``pack`` at levels ``range(lo, hi, step)``, its runs reduced.

    Runs the single-threaded batch kernel on the calling thread, one record after the other.

    Parameters
    ----------
    ctx : dict
        The run's shared data: ``token``, ``constants`` (JSON data), ``levels`` (all of
        them, ascending), ``measure``, ``options`` and ``peaks`` (bool).
    pack : sequence of (int, ndarray, float, str)
        ``(record index, acceleration [m/s²], dt [s], name)`` of each record.
    lo, hi : int
        The block of levels, ``0 <= lo < hi <= len(levels)``.
    stop : threading.Event, optional
        Set by a stopped local run: the task ends after the record it is on.
    step : int
        Every ``step``-th level of the block, >= 1 (``plan_tasks``'s interleaved blocks).

    Returns
    -------
    dict
        ``records`` (indices), ``lo``, ``hi``, ``step``, ``counts`` ((m, k) records that
        overturn, ``k`` levels in the block), ``first`` ((records, m) index of the first
        level in the block that overturns, ``len(levels)`` where none does), ``max_error``,
        ``incomplete``,
        ``factors`` (per record, only in the block that starts at level 0), ``criterion``,
        ``method``, ``peaks`` (``peak_ratio``, ``overturned``, ``error_estimate``,
        ``status`` as (records, m, k) arrays, or None) and the timing: ``kernel_s``
        (inside the batches), ``start``, ``end`` (``time.time()`` of this process) and
        ``lane`` (host, process and thread).
    """
    start = time.time()
    setup = _setup(ctx)
    levels = setup.levels[lo:hi:step]
    n_mech, none = len(setup.models), len(setup.levels)
    counts = np.zeros((n_mech, len(levels)), dtype=np.int64)
    first = np.full((len(pack), n_mech), none, dtype=np.int64)
    max_error, incomplete, kernel_s = 0.0, 0, 0.0
    factors: Optional[list[dict[str, float]]] = [] if lo == 0 else None
    peaks: dict[str, list[Any]] = {k: [] for k in ("peak_ratio", "overturned", "error_estimate")}
    peaks["status"] = []
    criterion = method = ""
    with single_threaded():
        for j, (_, acc, dt, name) in enumerate(pack):
            if stop is not None and stop.is_set():
                break
            res = _run_one(setup, acc, dt, name, levels)
            over = res["overturned"]
            counts += over
            first[j] = np.where(over.any(axis=1), lo + step * over.argmax(axis=1), none)
            max_error = float(np.maximum(max_error, np.max(res["error_estimate"])))
            incomplete += int(np.count_nonzero(res["status"] < 0))
            kernel_s += res["runtime_s"]
            criterion, method = res["criterion"], res["method"]
            if factors is not None:
                factors.append(res["scale_factors"])
            if setup.peaks:
                for key, rows in peaks.items():
                    rows.append(res[key])
    return {
        "records": [int(index) for index, *_ in pack],
        "lo": lo,
        "hi": hi,
        "step": step,
        "counts": counts,
        "first": first,
        "max_error": max_error,
        "incomplete": incomplete,
        "factors": factors,
        "criterion": criterion,
        "method": method,
        "peaks": {k: np.stack(v) for k, v in peaks.items()} if setup.peaks else None,
        "kernel_s": kernel_s,
        "start": start,
        "end": time.time(),
        "lane": f"{socket.gethostname()}:{os.getpid()}:{threading.get_ident()}",
    }
