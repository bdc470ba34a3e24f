"""Overturning boundaries of one-cycle pulses, their library, and mechanism envelopes.

Notation (theory §6.2)
----------------------
Omega : pulse frequency over the frequency parameter, ``omega_p / p_eq`` [-]
A : pulse amplitude over the uplift acceleration, ``a_p / (g lam)`` [-]
A_min(Omega; eta) : smallest A that overturns (the envelope), one curve per eta
f_p : pulse frequency [Hz]; a_p : pulse amplitude [m/s², or g where named ``_g``]

The dimensionless equation ``x'' = x - sgn(x) + f(tau)`` is self-similar, so one curve per
restitution coefficient serves every mechanism: ``a_p,min(f_p) = g lam A_min(2 pi f_p/p_eq)``.

Boundaries are found with the exact integrator (``_kernels.boundary_grid``): the outcome
(collapse or not, exact criterion) is evaluated on a log-spaced scan of A in
``(1, A_MAX]`` and every change of outcome is bisected to relative width ``RTOL``. All
overturning intervals are reported, including the safe islands above the first
overturning amplitude; an island narrower than the scan step (``scan_ratio``, stated in
every output) can be missed. Close to the uplift threshold at low Omega the outcome
alternates on scales of 1e-4 in A (many impacts, chaotic); the optional ``n_scan_near``
adds a scan log-spaced in ``A - 1`` from ``NEAR_MIN`` to resolve it, at ~10x the cost.

Library (``OverturningLibrary``): ``A_min`` on a log grid of Omega for eta in [0, 1] and for
one-sided rocking, generated once by ``rockmech library build`` and shipped as package data.
The build searches all its curves in one parallel loop and skips the scan points that
overturn whatever eta (``_boundary_kernels``); its edges are those of ``boundary_curve``, bit
for bit.
Between grid points ``log A_min`` is interpolated linearly in ``log Omega`` and in eta. The
curves jump where the overturning mode changes (impact / no impact); across such a jump
(neighbours differing by more than ``JUMP`` in ``log A``) the lower neighbour is used, so
the interpolation errs on the safe side there. Use ``exact=True`` to compute a mechanism's
envelope directly where the exact jump position matters.

One-sided rocking: the envelope is eta-independent (theory §6.4): the pulse is applied in
both directions with no rebound (eta = 0) and the lower curve governs; in practice this is
the pulse that first pushes against the restraint (closed form (b) of §6.3).
"""

from __future__ import annotations

import io
import json
import math
import time
import warnings
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from shared_schema.atomic import write_atomic
from shared_schema.errors import InputError, wrong_type
from shared_schema.version import __version__

from .excitation import PULSE_SHAPES
from .model import RockingModel, RockingSide, check_eta, require_model

# The exact kernels (numba), the pulse spectrum (scipy.optimize) and the kernels' first-use
# notes are imported by the functions that run them, so that reading the library and
# interpolating it (the search's ranking) loads none of them (#37, #38).

__all__ = [
    "A_MAX",
    "LIBRARY_ABOVE",
    "LIBRARY_BELOW",
    "LIBRARY_EDGE_RATIO",
    "LIBRARY_MARGIN",
    "LIBRARY_PATH",
    "N_SCAN",
    "RTOL",
    "BoundaryCurve",
    "Envelope",
    "OverturningLibrary",
    "boundary_curve",
    "build_library",
    "critical_bands",
    "default_library_path",
    "library_curve",
    "mechanism_envelope",
    "user_library_path",
]

#: Largest pulse amplitude searched, as ``a_p / (g lam)``.
A_MAX = 200.0
#: Number of log-spaced amplitudes scanned in ``(1, A_MAX]``.
N_SCAN = 300
#: Smallest ``A - 1`` of the optional near-threshold scan.
NEAR_MIN = 1e-5
#: Relative width to which each boundary is bisected.
RTOL = 1e-6
#: Rest rule of the boundary search [1/s per rad/s]: excursions it drops are below 5e-9
#: in |phi|/phi_ov, far below what can change a verdict resolved to ``RTOL``.
V_REST_BOUNDARY = 1e-4
#: Most outcome changes stored per Omega.
MAX_EDGES = 64
#: Up to this many Omega are searched on the calling thread, not in the parallel kernel: the
#: thread pool costs more than it saves there, and a process forked from one that ran the
#: parallel kernel (GNU OpenMP) may not start its threads.
SERIAL_OMEGA = 16
#: No scan point known in advance (``_kernels.search``'s ``known``).
_NO_KNOWN = np.zeros(0, dtype=np.bool_)
#: Library grid: Omega points (log-spaced in [0.05, 500], 133 a decade) and eta step. Up to
#: 500: a tall wall (p_eq about 1 rad/s) meets Omega = 63 at a 10 Hz pulse, and the
#: one-sided curve stays finite up to about 400 (A_min about Omega/2 < A_MAX).
LIBRARY_OMEGA = (0.05, 500.0, 533)
LIBRARY_ETA_STEP = 0.02
#: The library shipped with the package (never rewritten by rockmech: ``user_library_path``).
LIBRARY_PATH = Path(__file__).resolve().parents[1] / "data" / "overturning_library.npz"
#: File name of a library built by ``rockmech library build`` in the user's cache folder,
#: per rockmech version (a library built by another version is not read).
USER_LIBRARY_NAME = "overturning_library-{version}.npz"
#: Format version of the library file.
LIBRARY_VERSION = "1"
#: Largest change of ``log A_min`` between neighbouring library points that counts as a smooth
#: curve; across a larger one (a change of overturning mode) interpolation takes the lower
#: neighbour, so its error falls on the safe side.
JUMP = 0.04
#: Factor on the library's interpolated ``A_min`` in the fast mode: next to the uplift
#: threshold the interpolation sits up to ~1.7 % above the exact boundary (the scan step,
#: tests/solver_core/test_library_bound.py); lowered by 2 % it errs on the safe side.
LIBRARY_MARGIN = 0.98
#: Documented bound of the fast mode: at most this fraction above the exact ground-level
#: ``a_p,min`` (the tabulated pulse spectrum's interpolation; the curves never above).
LIBRARY_ABOVE = 1e-4
#: Documented bound of the fast mode: at most this fraction below the exact ``A_min``
#: (measured 3.9 %; tests/solver_core/test_library_bound.py).
LIBRARY_BELOW = 0.05
#: Documented frequency tolerance of the fast mode's critical-band edges: each lies within
#: this factor of where the exact envelopes put it [-].
LIBRARY_EDGE_RATIO = 1.05
#: Tabulated pulse response spectrum (5 % damping, sine pulse, pseudo-acceleration):
#: ratios f_p/f_n log-spaced over [1e-3, 1e3]; linear interpolation in log ratio.
SPECTRUM_GRID = (1e-3, 1e3, 4001)
SPECTRUM_ZETA = 0.05
#: Pulse directions: +1 first pushes towards negative rotation (against a one-sided
#: mechanism's restraint), -1 first opens the mechanism (Housner's sign convention).
DIRECTIONS = {1: "positive", -1: "negative"}
#: The library's curves are searched in this many parallel calls (progress between them).
LIBRARY_GROUPS = 8


def _scan(a_max: float, n_scan: int, n_scan_near: int) -> NDArray[np.float64]:
    scan = np.geomspace(1.0 + 1e-9, a_max, n_scan)
    if n_scan_near > 0:
        near = 1.0 + np.geomspace(NEAR_MIN, a_max - 1.0, n_scan_near)
        scan = np.unique(np.concatenate([scan, near]))
    return scan


@dataclass
class BoundaryCurve:
    """Overturning intervals in A at each Omega, for one eta, shape and pulse direction.

    Attributes
    ----------
    omega : (n,) float
        Frequency ratios ``omega_p / p_eq`` [-].
    edges : (n, MAX_EDGES) float
        Amplitudes ``a_p/(g lam)`` where the outcome changes, NaN-padded.
    n_edges : (n,) int
        Number of valid edges per Omega.
    collapsed_at_start : (n,) bool
        Outcome just above A = 1 (normally False).
    eta, one_sided, shape, direction
        Inputs; ``direction`` is +1 or -1 (see ``DIRECTIONS``).
    a_max, scan_ratio, rtol : float
        Search limits: largest A, ratio between scanned amplitudes, bisection width.
    runtime_s : float
        Wall-clock time [s].
    eta_neg : float or None
        Restitution of the impacts into side -1 when it differs from ``eta`` (which then
        is that of the impacts into side +1); None: ``eta`` for both.
    """

    omega: NDArray[np.float64]
    edges: NDArray[np.float64]
    n_edges: NDArray[np.int64]
    collapsed_at_start: NDArray[np.bool_]
    eta: float
    one_sided: bool
    shape: str
    direction: int
    a_max: float
    scan_ratio: float
    rtol: float
    runtime_s: float
    eta_neg: Optional[float] = None

    def intervals(self, i: int) -> list[tuple[float, Optional[float]]]:
        """Return the overturning intervals ``(A_lo, A_hi)`` at ``omega[i]``.

        ``A_hi`` is None when the interval extends to ``a_max``.
        """
        pts = list(self.edges[i, : int(self.n_edges[i])])
        if self.collapsed_at_start[i]:
            pts.insert(0, 1.0)
        out: list[tuple[float, Optional[float]]] = []
        for k in range(0, len(pts), 2):
            hi = pts[k + 1] if k + 1 < len(pts) else None
            out.append((float(pts[k]), None if hi is None else float(hi)))
        return out

    @property
    def a_min(self) -> NDArray[np.float64]:
        """First overturning amplitude the scan finds per Omega; ``inf`` if none to ``a_max``.

        An overturning interval below it that is narrower than ``scan_ratio`` can be
        missed (near the uplift threshold at low Omega; see ``n_scan_near``).
        """
        first = np.where(self.n_edges > 0, self.edges[:, 0], np.inf)
        return np.where(self.collapsed_at_start, 1.0, first)


def boundary_curve(
    omega: ArrayLike,
    eta: float,
    *,
    one_sided: bool = False,
    shape: str = "sine",
    direction: int = -1,
    a_max: float = A_MAX,
    n_scan: int = N_SCAN,
    n_scan_near: int = 0,
    rtol: float = RTOL,
    backend: str = "auto",
    eta_neg: Optional[float] = None,
) -> BoundaryCurve:
    """Every overturning interval in A at each Omega (exact integrator, exact criterion).

    Parameters
    ----------
    omega : array_like
        Frequency ratios ``omega_p / p_eq`` [-], each > 0.
    eta : float
        Restitution: [0, 1] two-sided, [-1, 0] one-sided.
    one_sided : bool
        One-sided rocking.
    shape : {"sine", "cosine"}
        Pulse shape.
    direction : {-1, +1}
        Sign of the pulse (see ``DIRECTIONS``); irrelevant for symmetric two-sided rocking.
    a_max, n_scan, n_scan_near, rtol
        Search limits (see module docstring).
    backend : str
        Kernel back end.
    eta_neg : float, optional
        Two-sided only: restitution [-] of the impacts into side -1 when the two impact
        directions differ (``eta`` is then that of the impacts into side +1; theory §6.6).

    Returns
    -------
    BoundaryCurve

    Examples
    --------
    Zhang & Makris (2001), eta = 0.9, Omega = 5: overturning from A = 3.0186, a safe band
    from 6.3181 to 7.1681, overturning beyond.

    >>> c = boundary_curve([5.0], 0.9)
    >>> [(round(lo, 4), hi if hi is None else round(hi, 4)) for lo, hi in c.intervals(0)]
    [(3.0186, 6.3181), (7.1681, None)]
    """
    t0 = time.perf_counter()
    om = np.atleast_1d(np.asarray(omega, dtype=float))
    if om.ndim != 1 or om.size == 0 or not np.all(np.isfinite(om) & (om > 0)):
        raise InputError("must be finite and > 0 (at least one value)", "omega")
    eta = check_eta(eta, one_sided)
    if eta_neg is not None:
        if one_sided:
            raise InputError("applies to two-sided rocking only", "eta_neg")
        eta_neg = check_eta(eta_neg, False, "eta_neg")
    if shape not in PULSE_SHAPES:
        raise InputError(f"must be one of {sorted(PULSE_SHAPES)}, got {shape!r}", "shape")
    if direction not in DIRECTIONS:
        raise InputError(f"must be +1 or -1, got {direction!r}", "direction")
    if not (math.isfinite(a_max) and a_max > 1.0):
        raise InputError(f"must be finite and > 1, got {a_max!r}", "a_max")
    if not (0.0 < rtol < 0.1):
        raise InputError(f"must be in (0, 0.1), got {rtol!r}", "rtol")
    if int(n_scan) < 2:
        raise InputError(f"must be >= 2, got {n_scan!r}", "n_scan")
    if int(n_scan_near) < 0:
        raise InputError(f"must be >= 0, got {n_scan_near!r}", "n_scan_near")
    # the exact kernels (numba) and their first-use note, loaded when a boundary is searched
    from .exact import kernels

    # (the note of the kernels' first use: numba's cache stamps)
    from .jit import first_use

    scan = _scan(a_max, int(n_scan), int(n_scan_near))
    kern = kernels(backend)
    compiled = first_use("boundary", backend)
    args = (eta, one_sided, float(direction), PULSE_SHAPES[shape], scan, rtol)
    eta_n = math.nan if eta_neg is None else eta_neg
    if om.size <= SERIAL_OMEGA:
        # The same search as boundary_grid's, one Omega after the other on this thread.
        edges = np.full((om.size, MAX_EDGES), np.nan)
        n_edges = np.zeros(om.size, dtype=np.int64)
        first = np.zeros(om.size, dtype=np.bool_)
        for i in range(om.size):
            n_edges[i], first[i] = kern.search(
                *args[:3], om[i], *args[3:], V_REST_BOUNDARY, edges[i], _NO_KNOWN,
                kern.KNOWN_IGNORE, eta_n,
            )  # fmt: skip
    else:
        edges, n_edges, first = kern.boundary_grid(om, *args, MAX_EDGES, V_REST_BOUNDARY, eta_n)
    if compiled is not None:
        compiled()
    return _curve(
        om,
        (eta, one_sided, direction),
        (edges, n_edges, first),
        shape,
        scan_ratio=float(np.max(scan[1:] / scan[:-1])),
        runtime_s=time.perf_counter() - t0,
        a_max=float(a_max),
        rtol=rtol,
        eta_neg=eta_neg,
        stacklevel=3,
    )


def governing_one_sided(
    omega: ArrayLike, eta: float = 0.0, **kwargs: Any
) -> tuple[BoundaryCurve, BoundaryCurve, NDArray[np.float64], NDArray[np.int64]]:
    """Both pulse directions for a one-sided mechanism; returns (pos, neg, a_min, direction)."""
    pos = boundary_curve(omega, eta, one_sided=True, direction=1, **kwargs)
    neg = boundary_curve(omega, eta, one_sided=True, direction=-1, **kwargs)
    a_min = np.minimum(pos.a_min, neg.a_min)
    direction = np.where(pos.a_min <= neg.a_min, 1, -1).astype(np.int64)
    return pos, neg, a_min, direction


# --- Library ----------------------------------------------------------------------------------


@dataclass
class OverturningLibrary:
    """Dimensionless first-overturning curves ``A_min(Omega; eta)`` and their intervals.

    Attributes
    ----------
    omega : (n,) float
        Log-spaced frequency ratios [-].
    eta : (m,) float
        Restitution coefficients of the two-sided curves [-].
    a_min_two_sided : (m, n) float
        ``A_min`` per eta and Omega (``inf``: none up to ``a_max``).
    a_min_one_sided : (n,) float
        Eta-independent one-sided curve (governing direction).
    direction_one_sided : (n,) int
        Governing pulse direction of the one-sided curve (+1 / -1).
    edges_flat, edges_offsets : float / int arrays
        All outcome changes (two-sided, then one-sided per direction), ragged.
    spectrum_ratio, spectrum : (k,) float
        Pulse response spectrum ``R(f_p/f_n)`` (``SPECTRUM_ZETA``, sine, pseudo-acceleration).
    metadata : dict
        Version, generation date, parameters and timing.
    """

    omega: NDArray[np.float64]
    eta: NDArray[np.float64]
    a_min_two_sided: NDArray[np.float64]
    a_min_one_sided: NDArray[np.float64]
    direction_one_sided: NDArray[np.int64]
    edges_flat: NDArray[np.float64]
    edges_offsets: NDArray[np.int64]
    spectrum_ratio: NDArray[np.float64]
    spectrum: NDArray[np.float64]
    metadata: dict[str, Any] = field(default_factory=dict)
    #: The file it was read from (None: built in this process).
    path: Optional[Path] = None

    def scale_factor(
        self, f_p: ArrayLike, *, f_n: float, h: float, h_e: float
    ) -> NDArray[np.float64]:
        """Eq. 28 for pulses, ``sqrt(1 + (R(f_p/f_n) h/h_e)**2)``, from the tabulated spectrum.

        Interpolation error of R is below 1e-4 relative (ratio step 0.35 %); ratios outside
        the table use its end values.
        """
        r = np.asarray(f_p, dtype=float) / f_n
        big_r = np.interp(np.log(r), np.log(self.spectrum_ratio), self.spectrum)
        return np.asarray(np.sqrt(1.0 + (big_r * h / h_e) ** 2), dtype=np.float64)

    def a_min(
        self, omega: ArrayLike, eta: Optional[float] = None, *, one_sided: bool = False
    ) -> NDArray[np.float64]:
        """Interpolated ``A_min`` at ``omega`` [-] (log-linear in Omega, linear in eta).

        Outside the Omega grid the end values are used (``A -> 1`` as ``Omega -> 0``).
        """
        return self.a_min_flagged(omega, eta, one_sided=one_sided)[0]

    def a_min_flagged(
        self, omega: ArrayLike, eta: Optional[float] = None, *, one_sided: bool = False
    ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        """Interpolated ``A_min`` [-] at ``omega``, and where the interpolation is uncertain.

        Returns
        -------
        a_min : (n,) float
            As ``a_min``.
        uncertain : (n,) bool
            True where the interpolation crossed a jump of the curve (in Omega or in eta;
            the lower neighbour was taken, which can be far below the exact value) or
            ``omega`` lies outside the grid (end values were taken).
        """
        om = np.log(np.atleast_1d(np.asarray(omega, dtype=float)))
        x = np.log(self.omega)
        if one_sided:
            return _interp_log_flagged(om, x, self.a_min_one_sided)
        if eta is None:
            raise InputError("two-sided envelopes need a coefficient of restitution", "eta")
        eta = check_eta(eta, False)
        j = int(np.clip(np.searchsorted(self.eta, eta) - 1, 0, self.eta.size - 2))
        w = (eta - self.eta[j]) / (self.eta[j + 1] - self.eta[j])
        lo, jump_lo = _interp_log_flagged(om, x, self.a_min_two_sided[j])
        hi, jump_hi = _interp_log_flagged(om, x, self.a_min_two_sided[j + 1])
        value, jump = _blend_flagged(lo, hi, np.full(lo.shape, w))
        # A neighbour row that jumps matters only where it carries weight.
        jump |= (jump_lo & (w < 1.0)) | (jump_hi & (w > 0.0))
        return value, jump

    def save(self, path: Union[str, Path]) -> Path:
        """Write the library atomically as a compressed ``.npz`` (no pickled objects)."""
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        buf = io.BytesIO()
        np.savez_compressed(
            buf,
            omega=self.omega,
            eta=self.eta,
            a_min_two_sided=self.a_min_two_sided,
            a_min_one_sided=self.a_min_one_sided,
            direction_one_sided=self.direction_one_sided,
            edges_flat=self.edges_flat,
            edges_offsets=self.edges_offsets,
            spectrum_ratio=self.spectrum_ratio,
            spectrum=self.spectrum,
            metadata=np.array(json.dumps(self.metadata, sort_keys=True)),
        )
        write_atomic(out, buf.getvalue())
        return out

    @classmethod
    def load(cls, path: Union[str, Path, None] = None) -> OverturningLibrary:
        """Read a library file.

        The default is the user's own build (``rockmech library build``, at
        ``user_library_path()``) when there is one for this version, else the library
        shipped with the package. ``path`` records which file was read.
        """
        p = Path(path) if path is not None else default_library_path()
        if not p.is_file():
            raise InputError(
                f"overturning library not found at {p}; build it with `rockmech library build`",
                "library",
            )
        with np.load(p, allow_pickle=False) as data:
            return cls(
                omega=data["omega"],
                eta=data["eta"],
                a_min_two_sided=data["a_min_two_sided"],
                a_min_one_sided=data["a_min_one_sided"],
                direction_one_sided=data["direction_one_sided"].astype(np.int64),
                edges_flat=data["edges_flat"],
                edges_offsets=data["edges_offsets"].astype(np.int64),
                spectrum_ratio=data["spectrum_ratio"],
                spectrum=data["spectrum"],
                metadata=json.loads(str(data["metadata"])),
                path=p,
            )


def user_library_path() -> Optional[Path]:
    """Return where ``rockmech library build`` writes a library by default, and reads it first.

    The user's cache folder (platformdirs: ``~/.cache/rockmech`` on Linux,
    ``~/Library/Caches/rockmech`` on macOS, ``%LOCALAPPDATA%/rockmech/Cache`` on Windows),
    never the installed package. None where platformdirs is missing (Rhino's Python): there
    only the shipped library is read.
    """
    try:
        import platformdirs
    except ImportError:
        return None
    folder = Path(platformdirs.user_cache_dir("rockmech", appauthor=False))
    return folder / USER_LIBRARY_NAME.format(version=__version__)


def default_library_path() -> Path:
    """Return the library ``OverturningLibrary.load()`` reads: the user's build, or the shipped."""
    user = user_library_path()
    return user if user is not None and user.is_file() else LIBRARY_PATH


def _blend_flagged(
    lo: NDArray[np.float64], hi: NDArray[np.float64], w: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Log-linear blend of two bracketing values; the lower one across a jump (``JUMP``).

    ``inf`` (no overturning up to ``a_max``) counts as a jump, so the finite neighbour wins.
    Returns the values and where a jump was crossed (a weight of 0 or 1 crosses none).
    """
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        smooth = np.exp((1.0 - w) * np.log(lo) + w * np.log(hi))
        jump = ~(np.abs(np.log(hi / lo)) <= JUMP)
    value = np.where(jump, np.minimum(lo, hi), smooth)
    at_lo, at_hi = w <= 0.0, w >= 1.0
    value = np.where(at_lo, lo, np.where(at_hi, hi, value))
    return np.asarray(value, dtype=np.float64), jump & ~(at_lo | at_hi)


def _interp_log_flagged(
    x_new: NDArray[np.float64], x: NDArray[np.float64], a: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Interpolate ``a`` in ``x`` with ``_blend_flagged``; end values outside the grid.

    Returns the values and where they are uncertain: a jump crossed, or outside the grid.
    """
    xc = np.clip(x_new, x[0], x[-1])
    idx = np.clip(np.searchsorted(x, xc), 1, x.size - 1)
    w = (xc - x[idx - 1]) / (x[idx] - x[idx - 1])
    value, jump = _blend_flagged(a[idx - 1], a[idx], w)
    return value, jump | (x_new < x[0]) | (x_new > x[-1])


def _ragged(curves: Sequence[BoundaryCurve]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    flat: list[float] = []
    offsets = [0]
    for c in curves:
        for i in range(c.omega.size):
            flat.extend(float(e) for e in c.edges[i, : int(c.n_edges[i])])
            offsets.append(len(flat))
    return np.array(flat), np.array(offsets, dtype=np.int64)


def _curve(
    om: NDArray[np.float64],
    spec: tuple[float, bool, int],
    found: tuple[Any, Any, Any],
    shape: str,
    *,
    scan_ratio: float,
    runtime_s: float,
    a_max: float = A_MAX,
    rtol: float = RTOL,
    eta_neg: Optional[float] = None,
    stacklevel: int = 4,
) -> BoundaryCurve:
    """Build a curve from the kernel's ``(edges, n_edges, first)`` of one library spec.

    ``stacklevel`` points the warning (more edges than kept) at the public caller.
    """
    eta, one_sided, direction = spec
    edges, n_edges, first = found
    if np.any(n_edges > MAX_EDGES):
        warnings.warn(
            f"more than {MAX_EDGES} outcome changes at some Omega; only the first "
            f"{MAX_EDGES} are kept",
            RuntimeWarning,
            stacklevel=stacklevel,
        )
    return BoundaryCurve(
        omega=om,
        edges=edges,
        n_edges=np.minimum(n_edges, MAX_EDGES).astype(np.int64),
        collapsed_at_start=first.astype(bool),
        eta=eta,
        one_sided=one_sided,
        shape=shape,
        direction=direction,
        a_max=a_max,
        scan_ratio=scan_ratio,
        rtol=rtol,
        runtime_s=runtime_s,
        eta_neg=eta_neg,
    )


def _library_curves(
    om: NDArray[np.float64],
    specs: list[tuple[float, bool, int]],
    shape: str,
    progress: Any,
) -> list[BoundaryCurve]:
    """Boundary curves for ``(eta, one_sided, direction)`` specs, searched in parallel.

    Each is ``boundary_curve`` with the defaults, bit for bit (``_boundary_kernels``): first
    the two-sided ``eta = 0`` curve, which marks the scan points that overturn whatever
    ``eta`` (the other two-sided curves skip them), then the rest in ``LIBRARY_GROUPS``
    parallel calls over (curve, Omega), with ``progress(done, total)`` after each.
    """
    # the library's kernels (numba), loaded when the library is built
    from . import _boundary_kernels as _bk

    # (the note of the kernels' first use: numba's cache stamps)
    from .jit import first_use

    scan = _scan(A_MAX, N_SCAN, 0)
    scan_ratio = float(np.max(scan[1:] / scan[:-1]))
    phase = PULSE_SHAPES[shape]
    probe_dir = -1
    t0 = time.perf_counter()
    compiled = first_use("library")
    *probe, known = _bk.probe_grid(
        om, float(probe_dir), phase, scan, RTOL, MAX_EDGES, V_REST_BOUNDARY
    )
    probe_spec = (0.0, False, probe_dir)
    out: dict[int, BoundaryCurve] = {}
    for k, spec in enumerate(specs):
        if spec == probe_spec:
            out[k] = _curve(
                om,
                spec,
                tuple(probe),
                shape,
                scan_ratio=scan_ratio,
                runtime_s=time.perf_counter() - t0,
            )
    todo = [k for k in range(len(specs)) if k not in out]
    if progress is not None:
        progress(len(out), len(specs))
    step = max(1, -(-len(todo) // LIBRARY_GROUPS))
    for lo in range(0, len(todo), step):
        t0 = time.perf_counter()
        group = [specs[k] for k in todo[lo : lo + step]]
        found = _bk.boundary_grids(
            om,
            np.array([e for e, _, _ in group], dtype=float),
            np.array([one for _, one, _ in group], dtype=np.bool_),
            np.array([d for _, _, d in group], dtype=float),
            phase,
            scan,
            RTOL,
            MAX_EDGES,
            V_REST_BOUNDARY,
            known,
            np.array([not one and d == probe_dir for _, one, d in group], dtype=np.bool_),
        )
        each_s = (time.perf_counter() - t0) / len(group)
        for c, k in enumerate(todo[lo : lo + step]):
            parts = (found[0][c], found[1][c], found[2][c])
            out[k] = _curve(om, specs[k], parts, shape, scan_ratio=scan_ratio, runtime_s=each_s)
        if progress is not None:
            progress(len(out), len(specs))
    if compiled is not None:
        compiled()
    return [out[k] for k in range(len(specs))]


def build_library(
    *,
    omega: Optional[ArrayLike] = None,
    eta: Optional[ArrayLike] = None,
    shape: str = "sine",
    progress: Any = None,
) -> OverturningLibrary:
    """Compute the library (two-sided curves over eta, and the one-sided curve).

    Parameters
    ----------
    omega, eta : array_like, optional
        Grids; default ``LIBRARY_OMEGA`` (533 log-spaced in [0.05, 500]) and eta from 0 to 1
        in steps of ``LIBRARY_ETA_STEP``.
    shape : {"sine", "cosine"}
        Pulse shape.
    progress : callable, optional
        Called as ``progress(done, total)`` as the curves are done.

    Notes
    -----
    Every curve is ``boundary_curve`` with the defaults (the one-sided ones as in
    ``governing_one_sided``), to the bit; all of them are searched in one parallel loop over
    (curve, Omega), while the pulse response spectrum (Python, holding the GIL) is computed
    on a second thread beside the compiled search, which releases it.
    """
    # the pulse spectrum (scipy.optimize), loaded when the library is built
    from .amplification import pulse_response_spectrum

    t0 = time.perf_counter()
    om = (
        np.geomspace(LIBRARY_OMEGA[0], LIBRARY_OMEGA[1], LIBRARY_OMEGA[2])
        if omega is None
        else np.asarray(omega, dtype=float)
    )
    if om.ndim != 1 or om.size == 0 or not np.all(np.isfinite(om) & (om > 0)):
        raise InputError("must be finite and > 0 (at least one value)", "omega")
    om = np.ascontiguousarray(om)
    etas = (
        np.round(np.arange(0.0, 1.0 + 1e-9, LIBRARY_ETA_STEP), 12)
        if eta is None
        else np.asarray(eta, dtype=float)
    )
    if etas.ndim != 1 or etas.size == 0:
        raise InputError("needs at least one value", "eta")
    if shape not in PULSE_SHAPES:
        raise InputError(f"must be one of {sorted(PULSE_SHAPES)}, got {shape!r}", "shape")
    specs = [(check_eta(float(e), False), False, -1) for e in etas]
    specs += [(0.0, True, 1), (0.0, True, -1)]
    ratio = np.geomspace(*SPECTRUM_GRID[:2], SPECTRUM_GRID[2])
    with ThreadPoolExecutor(max_workers=1) as pool:
        spectrum_job = pool.submit(pulse_response_spectrum, ratio, zeta=SPECTRUM_ZETA)
        curves = _library_curves(om, specs, shape, progress)
        spectrum = spectrum_job.result()
    pos, neg = curves[-2:]
    curves = curves[:-2]
    a_one = np.minimum(pos.a_min, neg.a_min)
    direction = np.where(pos.a_min <= neg.a_min, 1, -1).astype(np.int64)
    flat, offsets = _ragged([*curves, pos, neg])
    meta = {
        "library_version": LIBRARY_VERSION,
        "rockmech": __version__,
        "generated": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "shape": shape,
        "a_max": A_MAX,
        "n_scan": N_SCAN,
        "scan_ratio": curves[0].scan_ratio,
        "rtol": RTOL,
        "v_rest_rel": V_REST_BOUNDARY,
        "criterion": "exact (the body cannot return)",
        "pulse_convention": "A (Zhang & Makris 2001: pulse starts at t = 0)",
        "one_sided": "eta = 0 (no rebound), both pulse directions, lower curve",
        "edges_layout": "two-sided curves in eta order, then one-sided +1, then -1; "
        "each Omega's edges between consecutive offsets",
        "spectrum": f"pseudo-acceleration, sine pulse, zeta = {SPECTRUM_ZETA}",
        "build_seconds": round(time.perf_counter() - t0, 3),
    }
    return OverturningLibrary(
        omega=om,
        eta=etas,
        a_min_two_sided=np.stack([c.a_min for c in curves]),
        a_min_one_sided=a_one,
        direction_one_sided=direction,
        edges_flat=flat,
        edges_offsets=offsets,
        spectrum_ratio=ratio,
        spectrum=spectrum,
        metadata=meta,
    )


# --- Mechanism envelopes and the critical mechanism ------------------------------------------


@dataclass
class Envelope:
    """Minimum overturning pulse amplitude of one mechanism against pulse frequency.

    Attributes
    ----------
    name : str
        Mechanism name.
    f_p : (n,) float
        Pulse frequencies [Hz].
    a_p_min_local_g : (n,) float
        Minimum amplitude at the mechanism [g] (``inf``: none up to the search limit).
    scale_factor : (n,) float
        Amplification from the ground to the mechanism (1 at ground level) [-].
    governing_side : (n,) int
        +1 or -1: the side (two-sided asymmetric) or pulse direction (one-sided) that governs.
    notes : list of str
        How the envelope was computed, where a user should know it (e.g. the exact
        integrator used for a mechanism with two restitution coefficients).
    n_exact : int
        Side curves' frequencies computed with the exact integrator (all of them unless in
        the fast mode, where only those the library cannot interpolate safely).
    """

    name: str
    f_p: NDArray[np.float64]
    a_p_min_local_g: NDArray[np.float64]
    scale_factor: NDArray[np.float64]
    governing_side: NDArray[np.int64]
    notes: list[str] = field(default_factory=list)
    n_exact: int = 0

    @property
    def a_p_min_g(self) -> NDArray[np.float64]:
        """Minimum overturning amplitude of the ground pulse [g]."""
        return self.a_p_min_local_g / self.scale_factor


#: Note of an envelope of a mechanism whose two impact directions have different restitution.
DIRECTIONAL_NOTE = (
    "two restitution coefficients (eta_to_negative {neg:g}, eta_to_positive {pos:g}): the "
    "envelope is computed with the exact integrator, both pulse directions, since the "
    "library's single-eta curves are not conservative for every Omega with either value "
    "(theory §6.6)"
)


def _directional_curve(omega: NDArray[np.float64], model: RockingModel) -> NDArray[np.float64]:
    """``A_min`` with the restitution of each impact direction, lower over both pulses."""
    pos, neg = model.eta_into(1), model.eta_into(-1)
    curves = [boundary_curve(omega, pos, direction=d, eta_neg=neg).a_min for d in DIRECTIONS]
    return np.minimum(curves[0], curves[1])


def _exact_curve(omega: NDArray[np.float64], model: RockingModel) -> NDArray[np.float64]:
    """``A_min`` at ``omega`` with the exact integrator (both pulses when one-sided).

    An ``omega`` that overflowed (``2 pi f_p / p_eq`` of a degenerate mechanism) is a pulse
    infinitely short for the body: it never overturns it (``inf``).
    """
    a_min = np.full(omega.shape, np.inf)
    finite = np.isfinite(omega)
    if np.any(finite):
        if model.one_sided:
            a_min[finite] = governing_one_sided(omega[finite], 0.0)[2]
        else:
            a_min[finite] = boundary_curve(omega[finite], model.require_eta()).a_min
    return a_min


def library_curve(
    omega: NDArray[np.float64], model: RockingModel, library: OverturningLibrary
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """``A_min`` at ``omega`` in the fast mode: the library, exact where it is uncertain.

    Where the interpolation crossed a jump of the curve or left the grid
    (``OverturningLibrary.a_min_flagged``) the exact integrator gives the value; elsewhere
    the interpolated value times ``LIBRARY_MARGIN`` (the interpolation overshoots the exact
    boundary by up to ~1.7 % near the uplift threshold, tests/solver_core/test_library_bound.py).

    Returns
    -------
    a_min : (n,) float
        ``A_min`` [-].
    computed : (n,) bool
        Where the exact integrator gave the value.
    """
    eta = None if model.one_sided else model.require_eta()
    a_min, uncertain = library.a_min_flagged(omega, eta, one_sided=model.one_sided)
    a_min = a_min * LIBRARY_MARGIN
    if np.any(uncertain):
        a_min[uncertain] = _exact_curve(omega[uncertain], model)
    return a_min, uncertain


def _side_curve(
    side: RockingSide,
    f_p: NDArray[np.float64],
    model: RockingModel,
    library: Optional[OverturningLibrary],
) -> tuple[NDArray[np.float64], int]:
    """``a_p,min`` [g] of one side, and the frequencies the exact integrator computed."""
    omega = 2.0 * np.pi * f_p / side.p_eq
    if model.is_directional:
        return side.lam * _directional_curve(omega, model), omega.size
    if library is None:
        return side.lam * _exact_curve(omega, model), omega.size
    a_min, computed = library_curve(omega, model, library)
    return side.lam * a_min, int(np.count_nonzero(computed))


def mechanism_envelope(
    model: RockingModel,
    f_p: ArrayLike,
    *,
    library: Optional[OverturningLibrary] = None,
    exact: Optional[bool] = None,
    scale_factor: Optional[ArrayLike] = None,
) -> Envelope:
    """Envelope ``a_p,min(f_p) = g lam A_min(2 pi f_p / p_eq)`` of one mechanism.

    Parameters
    ----------
    model : RockingModel
        The mechanism. Two-sided needs ``eta``; one-sided does not (theory §6.4).
    f_p : array_like
        Pulse frequencies [Hz], > 0.
    library : OverturningLibrary, optional
        The fast mode: interpolate these curves (exact where the interpolation is uncertain,
        ``library_curve``).
    exact : bool, optional
        True: the exact integrator at every frequency (the default unless ``library`` is
        given); False: the fast mode with ``library`` (default: the shipped library).
    scale_factor : array_like, optional
        Amplification ``SF(f_p)`` from the ground to the mechanism (1 if omitted).

    Notes
    -----
    Asymmetric two-sided mechanisms take, per frequency, the lower of the two sides'
    envelopes (each side's constants used as a symmetric mechanism). A mechanism with two
    restitution coefficients (``eta_to_negative != eta_to_positive``) is always computed
    with the exact integrator, each impact with its direction's value and the pulse applied
    in both directions, and says so in ``notes`` (theory §6.6).
    """
    model = require_model(model)
    f = np.atleast_1d(np.asarray(f_p, dtype=float))
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f) & (f > 0)):
        raise InputError("must be finite and > 0 (at least one value)", f"{model.name}.f_p")
    if not model.one_sided and model.eta is None:
        raise InputError(
            "a two-sided envelope needs a coefficient of restitution", f"{model.name}.eta"
        )
    notes = []
    if exact is None:
        exact = library is None
    if exact:
        library = None
    elif library is None:
        library = OverturningLibrary.load()
    if model.is_directional:
        notes.append(DIRECTIONAL_NOTE.format(neg=model.eta_into(-1), pos=model.eta_into(1)))
    pos, n_pos = _side_curve(model.positive, f, model, library)
    n_exact = n_pos
    if model.one_sided or model.is_symmetric:
        local, side = pos, np.ones(f.size, dtype=np.int64)
    else:
        neg, n_neg = _side_curve(model.neg, f, model, library)
        local = np.minimum(pos, neg)
        side = np.where(pos <= neg, 1, -1).astype(np.int64)
        n_exact += n_neg
    sf = np.ones(f.size) if scale_factor is None else np.asarray(scale_factor, dtype=float)
    if sf.shape != f.shape or not np.all(np.isfinite(sf) & (sf >= 1.0)):
        raise InputError("must be finite and >= 1 at every frequency", f"{model.name}.scale_factor")
    return Envelope(model.name, f, local, sf, side, notes, n_exact)


def critical_bands(envelopes: Sequence[Envelope]) -> tuple[NDArray[np.int64], list[dict[str, Any]]]:
    """Find the governing mechanism at each frequency and the bands where each governs.

    Returns
    -------
    index : (n,) int
        Index of the mechanism with the lowest ground-level ``a_p,min`` (-1 where none
        overturns within the search limit).
    bands : list of dict
        ``{"mechanism", "f_min", "f_max"}`` [Hz] for each run of frequencies with the same
        governing mechanism (limits are the first and last frequency of the run).
    """
    if isinstance(envelopes, (Envelope, str)) or not isinstance(envelopes, Sequence):
        hint = "give a list of them: [envelope]" if isinstance(envelopes, Envelope) else ""
        raise wrong_type(envelopes, "envelopes", "a sequence of Envelopes", hint)
    for k, env in enumerate(envelopes):
        if not isinstance(env, Envelope):
            hint = "rockmech.mechanism_envelope(model, f_p) gives a mechanism's envelope"
            raise wrong_type(env, f"envelopes[{k}]", "an Envelope", hint)
    if not envelopes:
        raise InputError("needs at least one mechanism", "mechanisms")
    f = envelopes[0].f_p
    stack = np.stack([e.a_p_min_g for e in envelopes])
    index = np.argmin(stack, axis=0).astype(np.int64)
    index[~np.isfinite(stack.min(axis=0))] = -1
    bands: list[dict[str, Any]] = []
    start = 0
    for k in range(1, f.size + 1):
        if k == f.size or index[k] != index[start]:
            if index[start] >= 0:
                bands.append(
                    {
                        "mechanism": envelopes[index[start]].name,
                        "f_min": float(f[start]),
                        "f_max": float(f[k - 1]),
                    }
                )
            start = k
    return index, bands
