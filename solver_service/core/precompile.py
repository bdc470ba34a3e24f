"""Compile every path of the solver ahead: ``rockmech kernels``, the Docker build, ``serve``.

Each path (``jit.PATHS``) is run once on a tiny input, so numba compiles it (or loads it from
its cache) and ``jit.first_use`` stamps it as built. Apart from ``jit`` because it runs the
solver, which itself imports ``jit``.
"""

import contextlib
from typing import Any, Callable, Dict, Optional, Tuple

import numpy as np

from .envelope import boundary_curve, build_library
from .exact import simulate, simulate_batch, single_threaded
from .excitation import Pulse, SampledAccel
from .jit import KernelStatus, kernel_status, notify
from .model import RockingModel
from .spectra import response_spectrum

__all__ = ["SERVICE_PATHS", "build", "main"]


def build(
    progress: Optional[Callable[[str], None]] = None, paths: Optional[Tuple[str, ...]] = None
) -> KernelStatus:
    """Compile every solver path now (or load it from numba's cache), and stamp each.

    Parameters
    ----------
    paths : tuple of str, optional
        The paths to build (default: all of ``jit.PATHS``).
    progress : callable, optional
        Called with each path's name before it is built (paths already built are skipped).

    Returns
    -------
    KernelStatus
        The status afterwards (``built`` lists every path where numba is active; without
        numba nothing runs).
    """
    if not kernel_status().active:  # nothing to compile: the pure-Python kernels need no build
        return kernel_status()
    acc = 3.0 * np.sin(np.linspace(0.0, 6.0, 61))
    wall = RockingModel.symmetric(2.0, 0.2, 0.9)
    one_sided = RockingModel.symmetric(2.0, 0.2, -0.5, one_sided=True)
    batch = ([wall, one_sided], SampledAccel(acc, 0.01), [1.0, 2.0])
    done = set(kernel_status().built)
    steps: Dict[str, Callable[[], object]] = {
        "simulate": lambda: (
            simulate(wall, Pulse(a_p=-3.0, f_p=1.0)),
            simulate(one_sided, SampledAccel(acc, 0.01), dense=True, impact_log=True),
        ),
        "batch": lambda: (simulate_batch(*batch), _serial(single_threaded, simulate_batch, batch)),
        "boundary": lambda: boundary_curve(np.array([1.0, 5.0]), 0.9, n_scan=8),
        "library": lambda: build_library(omega=np.array([1.0, 5.0]), eta=np.array([0.0, 1.0])),
        "spectrum": lambda: response_spectrum(acc, 0.01, [0.5]),
    }
    for name, step in steps.items():
        if name in done or (paths is not None and name not in paths):
            continue
        if progress is not None:
            progress(name)
        step()
    return kernel_status()


def _serial(
    context: Callable[[], "contextlib.AbstractContextManager[None]"],
    fn: Callable[..., object],
    args: Tuple[Any, ...],
) -> object:
    """Run ``fn(*args)`` inside ``context()`` (the batch's single-threaded grid, used by IDA)."""
    with context():
        return fn(*args)


#: The paths the REST service runs (it loads the shipped library, never builds one).
SERVICE_PATHS = ("simulate", "batch", "boundary", "spectrum")


def main(paths: Tuple[str, ...] = SERVICE_PATHS) -> int:
    """Build ``paths``, quietly when they are built (``rockmech serve`` runs it first).

    Returns
    -------
    int
        0 when the compiled kernels are active and built, 1 when they are not active.
    """
    status = build()
    if not status.active:
        notify(f"note: {status.describe()}")
        return 1
    return 0
