"""Kernels of the exact rocking integrator (compiled by numba when available): their entries.

The kernels are split by what they integrate:

* ``_closed_form``: the closed-form flow between events, the exact location of every event
  (its docstring holds the argument that no event is missed), the layout of a run, free
  rocking after the excitation and the cells of a pulse; shared by every path;
* ``_stepping``: one run, event by event (``simulate_cells``, ``simulate_cells_logged``:
  ``exact.simulate``);
* ``_batch_kernels``: batches of runs (``simulate_grid``, ``simulate_grid_serial``:
  ``exact.simulate_batch``);
* ``_boundary_kernels``: overturning boundaries of pulses (``boundary_grid``, ``search``;
  ``boundary_grids`` and ``probe_grid`` for the library).

This module gathers their entries and constants. ``MODULES`` lists the kernel modules, whose
uncompiled twins ``exact.kernels("python")`` returns (``_compile.python_twins``): in a twin
of this module, ``_closed_form`` and the others are their twins.
"""

from . import _batch_kernels, _boundary_kernels, _closed_form, _stepping
from ._batch_kernels import DOZE, simulate_grid, simulate_grid_serial
from ._boundary_kernels import (
    KNOWN_FILL,
    KNOWN_IGNORE,
    KNOWN_USE,
    boundary_grid,
    boundary_grids,
    probe_grid,
    pulse_work,
    search,
)
from ._closed_form import (
    CELL_ROWS,
    ERR_CAP,
    LOG_ROWS,
    MAX_PH,
    NOUT,
    OUT_COLLAPSED,
    OUT_ERROR,
    OUT_N_IMPACTS,
    OUT_N_LOG,
    OUT_N_RESTS,
    OUT_N_STEPS,
    OUT_N_TRACE,
    OUT_N_UPLIFTS,
    OUT_PEAK,
    OUT_STATUS,
    OUT_T_COLLAPSE,
    OUT_T_EXCEED,
    OUT_T_PEAK,
    OUT_TRACE_FULL,
    free_rocking_kernel,
    pulse_cells,
)
from ._compile import JIT, JIT_REASON
from ._stepping import simulate_cells, simulate_cells_logged

__all__ = [
    "CELL_ROWS",
    "DOZE",
    "ERR_CAP",
    "JIT",
    "JIT_REASON",
    "KNOWN_FILL",
    "KNOWN_IGNORE",
    "KNOWN_USE",
    "LOG_ROWS",
    "MAX_PH",
    "MODULES",
    "NOUT",
    "OUT_COLLAPSED",
    "OUT_ERROR",
    "OUT_N_IMPACTS",
    "OUT_N_LOG",
    "OUT_N_RESTS",
    "OUT_N_STEPS",
    "OUT_N_TRACE",
    "OUT_N_UPLIFTS",
    "OUT_PEAK",
    "OUT_STATUS",
    "OUT_TRACE_FULL",
    "OUT_T_COLLAPSE",
    "OUT_T_EXCEED",
    "OUT_T_PEAK",
    "boundary_grid",
    "boundary_grids",
    "free_rocking_kernel",
    "probe_grid",
    "pulse_cells",
    "pulse_work",
    "search",
    "simulate_cells",
    "simulate_cells_logged",
    "simulate_grid",
    "simulate_grid_serial",
]

#: The kernel modules, in the order they import one another.
MODULES = (_closed_form, _stepping, _batch_kernels, _boundary_kernels)
