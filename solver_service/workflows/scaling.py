"""Scale factors of records up the structure, and the batched runs that apply them.

Mechanisms above ground level (those with ``amplification {f_n, h_e, h}``) receive the record
times a scale factor: Eq. 28 from the record's own spectrum, or the EN 1998-1 and NZS 1170.5
code factors (docs/theory.md §7.3-7.4). Mechanisms at ground level are not scaled.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional, Sequence

import numpy as np

from shared_schema.constants import ConstantsFile, Mechanism
from shared_schema.errors import InputError
from shared_schema.rules import SF_METHODS, G, check_choice, check_non_negative, check_positive

from ..codes.scale_factors import check_height, sf_ec8, sf_eq28, sf_nzs
from ..core.spectra import response_spectrum
from .adapter import to_rocking_model

__all__ = [
    "SCALE_GRID",
    "SCALE_RTOL",
    "SF_METHODS",
    "Building",
    "dense_runs",
    "factor_groups",
    "least_overturning_scales",
    "mechanism_scale_factor",
    "option_notes",
    "run_scaled",
]

#: Scale factors of a record tried for overturning: log-spaced (lowest, highest, count).
SCALE_GRID = (0.05, 50.0, 60)
#: Relative width to which the first overturning scale factor is bisected.
SCALE_RTOL = 1e-3


@dataclass(frozen=True)
class Building:
    """What the code scale factors need to know about the supporting structure.

    Attributes
    ----------
    height : float, optional
        Height of the building above its foundation, ``H`` (EC8) or ``h_n`` (NZS) [m], > 0
        and at most ``codes.scale_factors.BUILDING_HEIGHT_MAX_M``.
    soil_factor : float
        EC8 soil factor ``S`` [-], > 0; 1 gives the bare amplification.
    element_period : float
        EC8 fundamental period of the element ``T_a`` [s], >= 0; 0 (the default) takes the
        rocking mechanism as rigid before uplift.
    """

    height: Optional[float] = None
    soil_factor: float = 1.0
    element_period: float = 0.0

    def __post_init__(self) -> None:
        if self.height is not None:
            check_height(self.height, "building_height")
        check_positive(self.soil_factor, "soil_factor")
        check_non_negative(self.element_period, "element_period")


def option_notes(cf: ConstantsFile, sf: str, building: Building) -> list[str]:
    """Warnings for scale-factor options that cannot apply to these mechanisms.

    ``sf`` other than ``none`` acts only on mechanisms with ``amplification`` data; the
    building options act only with ``sf`` ``ec8`` (all three) or ``nzs`` (the height).
    """
    check_choice(sf, SF_METHODS, "sf")
    notes = []
    if sf != "none" and not any(m.amplification is not None for m in cf.mechanisms):
        notes.append(
            f"sf {sf} has no effect: no mechanism has amplification data (f_n, h_e, h), so "
            "every mechanism takes the record as given (ground level)"
        )
    used = {
        "ec8": ("building_height", "soil_factor", "element_period"),
        "nzs": ("building_height",),
    }
    given = {
        "building_height": building.height is not None,
        "soil_factor": building.soil_factor != Building.soil_factor,
        "element_period": building.element_period != Building.element_period,
    }
    for name, is_given in given.items():
        if is_given and name not in used.get(sf, ()):
            notes.append(f"{name} has no effect with sf {sf}")
    return notes


def mechanism_scale_factor(
    mech: Mechanism, motion: Any, sf: str, building: Building = Building()
) -> Optional[dict[str, Any]]:
    """Scale factor of the record up the structure for one mechanism, or None at ground level.

    Parameters
    ----------
    mech : Mechanism
        The mechanism; only those with ``amplification {f_n, h_e, h}`` are scaled.
    motion : GroundMotion
        The record (Eq. 28 uses its exact 5 %-damped spectrum at ``T_n = 1/f_n``).
    sf : {"eq28", "ec8", "nzs"}
        Method. EC8 takes ``z = h``, ``T_1 = 1/f_n``; NZS takes ``h_i = h``.
    building : Building
        Building height (EC8 and NZS), soil factor and element period (EC8).

    Returns
    -------
    dict or None
        ``{"value", "method", "formula", "inputs"}`` (``solver_service.codes.scale_factors``).
    """
    check_choice(sf, SF_METHODS, "sf")
    amp = mech.amplification
    if sf == "none" or amp is None:
        return None
    if sf == "eq28":
        spec = response_spectrum(motion.accel.acc, motion.dt, [1.0 / amp.f_n])
        return sf_eq28(float(spec.psa[0]) / G, motion.pga_g, amp.h, amp.h_e)
    if building.height is None:
        raise InputError(f"--sf {sf} needs the height of the building [m]", "building_height")
    if amp.h > building.height:
        raise InputError(
            f"mechanism {mech.id!r} sits at h = {amp.h:g} m, above the building "
            f"({building.height:g} m)",
            "building_height",
        )
    if sf == "nzs":
        return sf_nzs(amp.h, building.height)
    return sf_ec8(
        amp.h, building.height, building.element_period, 1.0 / amp.f_n, building.soil_factor
    )


def factor_groups(
    cf: ConstantsFile, motion: Any, sf: str, building: Building
) -> tuple[dict[str, Any], dict[float, list[int]]]:
    """Scale-factor records per mechanism id, and the mechanisms (indices) per factor."""
    factors: dict[str, Any] = {}
    groups: dict[float, list[int]] = {}
    for i, mech in enumerate(cf.mechanisms):
        info = mechanism_scale_factor(mech, motion, sf, building)
        if info is not None:
            factors[mech.id] = info
        groups.setdefault(1.0 if info is None else float(info["value"]), []).append(i)
    return factors, groups


def run_scaled(
    cf: ConstantsFile,
    models: list[Any],
    motion: Any,
    scales: list[float],
    sf: str = "none",
    building: Building = Building(),
    criterion: Optional[str] = None,
    runs: Optional[dict[tuple[str, float], Any]] = None,
) -> tuple[dict[str, Any], list[tuple[list[int], Any]]]:
    """Run every mechanism at every scale, each record scaled up the structure by ``sf``.

    Mechanisms that share a factor (all those at ground level) share one compiled batch.
    Given a ``runs`` dict, every run is instead made once with its time series
    (``simulate(dense=True)``), kept in ``runs[(mechanism id, user scale)]``, and collected
    into the same batch results (identical numbers), for plots that need the traces.

    Returns
    -------
    factors : dict
        Scale-factor record (``mechanism_scale_factor``) per mechanism id that has one.
    batches : list of (indices, BatchResult)
        Which mechanisms (indices into ``cf.mechanisms``) each batch ran; the batch's
        ``scales`` are the effective ones (user scale times factor).
    """
    # the exact solver (numba), when runs are made: the scale factors alone need none (#38)
    from ..core.exact import BatchResult, simulate, simulate_batch

    factors, groups = factor_groups(cf, motion, sf, building)
    batches = []
    for factor, members in groups.items():
        effective = [s * factor for s in scales]
        chosen = [models[i] for i in members]
        if runs is None:
            batch = simulate_batch(chosen, motion.accel, effective, criterion=criterion)
        else:
            dense = [
                [
                    simulate(m, motion.accel, scale=e, criterion=criterion, dense=True)
                    for e in effective
                ]
                for m in chosen
            ]
            for i, row in zip(members, dense):
                runs.update({(cf.mechanisms[i].id, s): r for s, r in zip(scales, row)})
            batch = BatchResult.from_runs([m.name for m in chosen], effective, dense)
        batches.append((members, batch))
    return factors, batches


def dense_runs(
    cf: ConstantsFile, motion: Any, doc: dict[str, Any], scale: float
) -> list[tuple[str, float, Any]]:
    """Time series of every mechanism at one user scale, as a history document ran it.

    Each mechanism gets the document's scale factor up the structure on top of ``scale``
    and the document's overturning criterion; those the document skipped are left out.

    Returns
    -------
    list of (mechanism id, effective scale, RockingResult)
        The results carry ``t`` and ``ratio`` (``dense=True``).
    """
    # the exact solver (numba), when runs are made (#38)
    from ..core.exact import simulate

    factors = {k: v["value"] for k, v in doc.get("scale_factors", {}).items()}
    skipped = {s["mechanism"] for s in doc.get("skipped", [])}
    runs = []
    for mech in cf.mechanisms:
        if mech.id in skipped:
            continue
        effective = scale * factors.get(mech.id, 1.0)
        res = simulate(
            to_rocking_model(mech),
            motion.accel,
            scale=effective,
            criterion=doc["criterion"],
            dense=True,
        )
        runs.append((mech.id, effective, res))
    return runs


def least_overturning_scales(
    models: Sequence[Any],
    motion: Any,
    factors: Optional[Sequence[float]] = None,
    grid: tuple[float, float, int] = SCALE_GRID,
    stretch: Optional[Sequence[float]] = None,
) -> list[dict[str, Any]]:
    """Find the smallest scale factor of a record that overturns each model (exact solver).

    Parameters
    ----------
    models : sequence of RockingModel
        The solver's models.
    motion : GroundMotion
        The record.
    factors : sequence of float, optional
        Per model, the scale factor up the structure that multiplies the record's scale
        (``mechanism_scale_factor``; default 1: the record as given).
    grid : (float, float, int)
        Scale factors of the record tried: log-spaced from the first to the second, that many.
    stretch : sequence of float, optional
        Per model, a factor on the grid's scales (default 1). A block whose ``λ`` and
        ``φ_ov`` grow by ``c`` responds to the record scaled by ``c s`` as it did to ``s``
        (theory §2.2): with the grid stretched by ``c`` its runs are the same, and the
        scale found is ``c`` times the one before (a fixed grid may step over a narrow
        window of overturning at one ``λ`` and not at the other).

    Returns
    -------
    list of dict
        Per model: ``scale`` (the record's scale [-], before the factor up the structure;
        None when none up to the grid's top overturns), the bracket ``[safe, overturns]``
        it was bisected in (relative width ``SCALE_RTOL``), ``pga_g`` (the record's PGA at
        that scale [g]), the criterion and ``runs`` (exact runs made, the grid's included).

    Notes
    -----
    Overturning is not monotonic in the scale (a stronger record may rock a block back):
    the scale reported is the first on the grid that overturns, refined between it and the
    grid point below, which did not. Every scale below it on the grid survives.
    """
    # the exact solver (numba), when runs are made (#38)
    from ..core.exact import simulate_batch

    ups = [1.0] * len(models) if factors is None else [float(f) for f in factors]
    stretches = [1.0] * len(models) if stretch is None else [float(c) for c in stretch]
    base = np.geomspace(grid[0], grid[1], int(grid[2]))
    groups: dict[tuple[float, float], list[int]] = {}
    for i, key in enumerate(zip(ups, stretches)):
        groups.setdefault(key, []).append(i)
    out: list[dict[str, Any]] = [{} for _ in models]
    for (up, c), members in groups.items():
        scales = base * c
        batch = simulate_batch([models[i] for i in members], motion.accel, scales * up)
        for row, i in enumerate(members):
            out[i] = _refine(models[i], motion, up, scales, batch.overturned[row], batch.criterion)
    return out


def _refine(
    model: Any, motion: Any, up: float, scales: Any, overturned: Any, criterion: str
) -> dict[str, Any]:
    """Bisect between the first grid scale that overturns and the one below it."""
    # the exact solver (numba), when runs are made (#38)
    from ..core.exact import simulate

    runs = len(scales)
    hit = np.flatnonzero(overturned)
    if hit.size == 0:
        return {"scale": None, "bracket": None, "pga_g": None, "criterion": criterion, "runs": runs}
    k = int(hit[0])
    hi = float(scales[k])
    lo = float(scales[k - 1]) if k > 0 else 0.0
    while hi - lo > SCALE_RTOL * hi:
        mid = 0.5 * (lo + hi) if lo > 0.0 else 0.5 * hi
        runs += 1
        if simulate(model, motion.accel, scale=mid * up).overturned:
            hi = mid
        else:
            lo = mid
    return {
        "scale": hi,
        "bracket": [lo, hi],
        "pga_g": hi * float(motion.pga_g),
        "criterion": criterion,
        "runs": runs,
    }
