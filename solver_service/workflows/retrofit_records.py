"""The retrofit's records: the least tie force with which every record survives its design scale.

A tie is a constant force in the constants (theory §2.2, ``retrofit.with_tie``), so the
exact solver runs the tied mechanism as it runs any other. For each record and each
mechanism (docs/theory.md §11.12):

* the **design scale** is the assessment's: the record's 5 % spectrum matched to the site's
  over the mechanism's band (``assess.record_scale_factor`` over ``assess.matching_band`` of
  the mechanism as it stands, held while the tie force varies), times Eq. 28 up the
  structure where the mechanism has amplification data;
* the **least overturning scale** is the first scale of a log grid that overturns it, bisected
  (``scaling.least_overturning_scales``), the grid stretched by ``λ/λ0`` of the tied
  mechanism (for one block the same runs: the scale found grows as ``λ``); its ratio to
  the design scale is the record's margin (above 1: no scale up to the design one on the
  grid overturns it);
* the **least tie force** ``T*`` is found on a geometric grid of forces of ratio
  ``1/(1 − T_REL_TOL)``, started where ``λ(T) = λ0 s_design/s_ov`` (a block whose
  ``φ_ov`` and ``λ`` grow together responds at ``λ`` as at ``λ0`` to the record scaled by
  ``λ0/λ``: there the least overturning scale reaches the design one), galloping then
  bisecting on the grid index to the pair of neighbours whose verdicts at the design scale
  differ: ``T*`` survives and ``T*(1 − T_REL_TOL)`` overturns. The verdict at
  ``T*(1 + T_REL_TOL)`` is run too, so the document shows the flip; where it overturns
  (rocking is not monotonic in the force) the search goes on above.

Every exact run is counted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

from shared_schema.constants import Mechanism
from shared_schema.errors import InputError, RockmechError
from shared_schema.paths import PathLike, as_path
from shared_schema.retrofit import RecordScale, RecordTie, RetrofitSpec

from ..core.exact import simulate
from ..core.model import G
from .adapter import to_rocking_model
from .assess import matching_band, record_scale_factor
from .codecheck import site_spectrum
from .inputs import read_record
from .scaling import least_overturning_scales, mechanism_scale_factor

__all__ = [
    "MAX_RUNS",
    "RECORD_DECISIONS",
    "T_REL_TOL",
    "MechanismRecords",
    "force_grid_ratio",
    "read_retrofit_records",
    "tie_slope",
]

#: Relative step of the grid of tie forces (the issue's 0.5 %): ``T*(1 − T_REL_TOL)`` is
#: the grid point below ``T*``.
T_REL_TOL = 0.005
#: The most exact runs at the design scale one record's search makes before it stops
#: (the benchmark's target is 20; this cap only ends a search that cannot converge).
MAX_RUNS = 60
#: The most times the search goes on above a ``T*`` whose ``T*(1 + T_REL_TOL)`` overturns.
MAX_RESTARTS = 3

RECORD_DECISIONS = [
    "Records: each must survive at its design scale by the exact solver with the tie as a "
    "constant force (theory §2.2): the design scale matches the record's 5 % spectrum to "
    "the site's over the band of the mechanism as it stands (the assessment's), times "
    "Eq. 28 up the structure, and is held while the tie force varies.",
    "The records' T* is on a geometric grid of forces of ratio 1/(1 − 0.005), started "
    "where λ(T) = λ0 s_design/s_ov, galloping then bisecting to the neighbours whose "
    "verdicts differ; the verdicts at T*(1 − 0.005), T* and T*(1 + 0.005) are given. With "
    "several records, T* is the largest, run again on every record at the design scale.",
    "A record's margin is its least overturning scale (the first of a log grid of scales "
    "that overturns, bisected to 0.1 %; the grid stretched by λ/λ0 with the tie, so that a "
    "block whose λ and φ_ov grow together runs the same motions) over its design scale, "
    "before and after the tie; below 1 the record overturns the mechanism at a scale under "
    "the design one, even where it survives the design scale itself.",
]


def force_grid_ratio() -> float:
    """Return the ratio of the grid of tie forces, ``1/(1 − T_REL_TOL)`` [-]."""
    return 1.0 / (1.0 - T_REL_TOL)


@dataclass
class _Record:
    """One record on one mechanism: its design scale and factor up the structure."""

    motion: Any
    design: Optional[float]
    up: float
    note: Optional[str] = None


@dataclass
class MechanismRecords:
    """The records of one mechanism: design scales, overturning scales, tie forces.

    Parameters
    ----------
    mech : Mechanism
        The mechanism as it stands (single-block, physical form, for the tie forces).
    row : dict
        Its ``check_doc`` row (the band of the design scale comes from its nonlinear check).
    motions : sequence of GroundMotion
        The records.
    site : SiteFile
        The site (its elastic spectrum is the target of the design scale).
    """

    mech: Mechanism
    row: dict[str, Any]
    motions: Sequence[Any]
    site: Any
    records: list[_Record] = field(default_factory=list)
    runs: int = 0

    def __post_init__(self) -> None:
        spectrum = site_spectrum(self.site)
        band = matching_band(self.row)
        for motion in self.motions:
            try:
                design = float(record_scale_factor(motion, spectrum, band)["value"])
                height = mechanism_scale_factor(self.mech, motion, "eq28")
                up = 1.0 if height is None else float(height["value"])
                self.records.append(_Record(motion, design, up))
            except RockmechError as exc:
                self.records.append(_Record(motion, None, 1.0, f"not run: {exc}"))

    # --- runs --------------------------------------------------------------------------

    def scales(self, mech: Mechanism) -> list[RecordScale]:
        """Return each record's design scale, least overturning scale and margin on ``mech``."""
        model = to_rocking_model(mech)
        # The grid of scales follows λ (least_overturning_scales: stretch).
        lam, lam0 = mech.positive.lam, self.mech.positive.lam
        stretch = 1.0 if lam is None or not lam0 else lam / lam0
        out: list[RecordScale] = []
        for rec in self.records:
            name = rec.motion.name
            if rec.design is None:
                out.append(RecordScale(record=name, note=rec.note))
                continue
            found = least_overturning_scales([model], rec.motion, [rec.up], stretch=[stretch])[0]
            self.runs += int(found["runs"])
            s_ov = found["scale"]
            multiple = None if s_ov is None else s_ov / rec.design
            survives = not simulate(model, rec.motion.accel, scale=rec.design * rec.up).overturned
            self.runs += 1
            out.append(
                RecordScale(
                    record=name,
                    design_scale=rec.design,
                    height_factor=None if rec.up == 1.0 else rec.up,
                    overturning_scale=s_ov,
                    multiple=multiple,
                    passes=multiple is None or multiple > 1.0,
                    survives_design=survives,
                    runs=int(found["runs"]) + 1,
                )
            )
        return out

    def _survives(self, rec: _Record, with_tie: Callable[[float], Mechanism], force: float) -> bool:
        assert rec.design is not None
        model = to_rocking_model(with_tie(force))
        return not simulate(model, rec.motion.accel, scale=rec.design * rec.up).overturned

    # --- the least force ---------------------------------------------------------------

    def tie_forces(
        self,
        with_tie: Callable[[float], Mechanism],
        slope: float,
        before: Sequence[RecordScale],
        t_max: float,
        t_from: float = 0.0,
    ) -> tuple[Optional[float], list[RecordTie]]:
        """Return the least force [N] with which every record survives, and each record's.

        Parameters
        ----------
        with_tie : callable
            ``force [N] -> Mechanism`` with the tie at that force.
        slope : float
            ``dλ/dT`` of the tie [1/N] (``h_t cos α_c/(g Q)``, theory §2.2 Eq. 16).
        before : sequence of RecordScale
            ``scales`` of the mechanism as it stands, in record order.
        t_max : float
            The largest force tried [N]; a record that still overturns there gives None.
        t_from : float
            The force the other criteria already need [N]: the records are run together
            at the largest of it and theirs.
        """
        lam0 = self.mech.positive.lam
        assert lam0 is not None
        ties: list[RecordTie] = []
        for rec, sc in zip(self.records, before):
            ties.append(self._one(rec, sc, with_tie, lam0, slope, t_max))
        if any(rec.design is not None and r.T_star_N is None for rec, r in zip(self.records, ties)):
            return None, ties
        return self.together(
            with_tie, max([t_from] + [r.T_star_N or 0.0 for r in ties]), t_max, ties
        )

    def together(
        self,
        with_tie: Callable[[float], Mechanism],
        force: float,
        t_max: float,
        ties: list[RecordTie],
    ) -> tuple[Optional[float], list[RecordTie]]:
        """Run every record at ``force`` [N]; raise it until every one survives.

        A record that overturns there (rocking is not monotonic in the force) is searched
        again above it; returns the force (None: none up to ``t_max``) and the records'
        ties, their runs and notes updated.
        """
        for _ in range(len(self.records) + MAX_RESTARTS):
            failing = []
            for rec, tie in zip(self.records, ties):
                if rec.design is None or force <= 0.0 or tie.T_star_N == force:
                    continue  # not run, no tie, or its own search survived at this force
                tie.runs += 1
                if not self._count(rec, with_tie, force):
                    failing.append((rec, tie))
            if not failing:
                return force, ties
            for rec, tie in failing:
                found, runs, _ = self._search(rec, with_tie, force, t_max, start_overturns=True)
                tie.runs += runs
                if found is None:
                    tie.note = (
                        f"overturns at the design scale with {force:.6g} N, the force the "
                        f"other records or checks need, and no force up to {t_max:.4g} N "
                        "above it survives"
                    )
                    return None, ties
                tie.note = (
                    f"run together at {force:.6g} N it overturned; the next force on the grid "
                    f"above that survives is {found:.6g} N"
                )
                force = max(force, found)
        return None, ties

    def _count(self, rec: _Record, with_tie: Callable[[float], Mechanism], force: float) -> bool:
        self.runs += 1
        return self._survives(rec, with_tie, force)

    def _one(
        self,
        rec: _Record,
        sc: RecordScale,
        with_tie: Callable[[float], Mechanism],
        lam0: float,
        slope: float,
        t_max: float,
    ) -> RecordTie:
        name = rec.motion.name
        if rec.design is None:
            return RecordTie(record=name, note=rec.note)
        if sc.survives_design:
            return RecordTie(
                record=name,
                T_star_N=0.0,
                note="survives at the design scale as it stands: needs no tie",
            )
        s_ov = sc.overturning_scale
        # The grid may step over the design scale's overturning (s_ov None or above it).
        t0 = 0.0
        if s_ov is not None and s_ov < rec.design:
            t0 = (lam0 * rec.design / s_ov - lam0) / slope
        # λ0 s_d/s_ov at or below λ0 (a record that overturns at the design scale only):
        # start one grid step of λ above λ0.
        t0 = max(t0, T_REL_TOL * lam0 / slope)
        t0 = min(t0, t_max)
        found, runs, flip = self._search(rec, with_tie, t0, t_max, start_overturns=None)
        note = None
        if found is None:
            note = f"overturns at the design scale with every force up to {t_max:.4g} N"
        return RecordTie(record=name, T_star_N=found, T_start_N=t0, runs=runs, flip=flip, note=note)

    def _search(
        self,
        rec: _Record,
        with_tie: Callable[[float], Mechanism],
        t0: float,
        t_max: float,
        start_overturns: Optional[bool],
    ) -> tuple[Optional[float], int, list[dict[str, Any]]]:
        """Least grid force ``t0 r^k`` that survives with the one below overturning.

        ``start_overturns`` is the verdict at ``t0`` when known (True: search above it
        only). Returns the force (None: none up to ``t_max``), the runs, and the verdicts
        at ``T*(1 − T_REL_TOL)``, ``T*``, ``T*(1 + T_REL_TOL)``.
        """
        total = 0
        known = start_overturns
        for _ in range(MAX_RESTARTS + 1):
            found, runs, flip = self._grid(rec, with_tie, t0, t_max, known, MAX_RUNS - total)
            total += runs
            if found is None or not flip[-1]["overturned"] or total >= MAX_RUNS:
                return found, total, flip
            # It overturns again just above T*: the grid starts again from there.
            t0, known = flip[-1]["force_N"], True
        return None, total, []

    def _grid(
        self,
        rec: _Record,
        with_tie: Callable[[float], Mechanism],
        t0: float,
        t_max: float,
        start_overturns: Optional[bool],
        budget: int,
    ) -> tuple[Optional[float], int, list[dict[str, Any]]]:
        """One gallop and bisection on the grid ``t0 r^k``, ``r = 1/(1 − T_REL_TOL)``."""
        ratio = force_grid_ratio()
        cache: dict[int, bool] = {}
        runs = 0

        def force(k: int) -> float:
            return t0 * ratio**k

        def survives(k: int) -> bool:
            nonlocal runs
            if k not in cache:
                runs += 1
                self.runs += 1
                cache[k] = self._survives(rec, with_tie, force(k))
            return cache[k]

        k_max = math.floor(math.log(t_max / t0) / math.log(ratio)) if t_max > t0 else 0
        if start_overturns is not None:
            cache[0] = not start_overturns
        lo: Optional[int] = None
        hi: Optional[int] = None
        if survives(0):
            # Gallop down to a force that overturns (T = 0 does, at the design scale).
            hi, step = 0, 1
            while runs < budget:
                k = hi - step
                if not survives(k):
                    lo = k
                    break
                hi, step = k, 2 * step
            if lo is None:
                return force(hi), runs, []
        else:
            # Gallop up to a force that survives.
            lo, step = 0, 1
            while True:
                k = min(lo + step, k_max)
                if k > lo and survives(k):
                    hi = k
                    break
                if k <= lo or k >= k_max or runs >= budget:
                    return None, runs, []
                lo, step = k, 2 * step
        assert lo is not None and hi is not None
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if survives(mid):
                hi = mid
            else:
                lo = mid
        t_star = force(hi)
        runs += 1
        self.runs += 1
        above = not self._survives(rec, with_tie, t_star * (1.0 + T_REL_TOL))
        flip = [
            {"force_N": force(lo), "overturned": True},
            {"force_N": t_star, "overturned": False},
            {"force_N": t_star * (1.0 + T_REL_TOL), "overturned": above},
        ]
        return t_star, runs, flip


def tie_slope(mech: Mechanism, height: float) -> float:
    """Return ``dλ/dT`` of a tie at ``height`` [1/N]: ``h_t cos α_c/(g Q)`` (Eq. 16)."""
    side = mech.positive
    assert side.phi_cr is not None and side.Q is not None
    return height * math.cos(side.phi_cr) / (G * side.Q)


def read_retrofit_records(
    spec: RetrofitSpec,
    spec_dir: Optional[PathLike] = None,
    records: Optional[Sequence[PathLike]] = None,
    on_warning: Optional[Callable[[str], None]] = None,
) -> list[Any]:
    """Read the retrofit's records: ``records`` if given, else the spec's ``records``.

    Parameters
    ----------
    spec : RetrofitSpec
        The spec; its ``records`` are relative to ``spec_dir``.
    spec_dir : str or os.PathLike, optional
        The spec's folder (default: the working folder).
    records : sequence of str or os.PathLike, optional
        Record files instead of the spec's (formats detected, as ``rockmech history``).
    on_warning : callable, optional
        Called with each record's warnings as it is read.

    Raises
    ------
    InputError
        A spec's record that is not there (field ``records[k]``), a file that is not a
        record (the reader's message).
    """
    if records is not None and len(records) > 0:
        return [read_record(as_path(r, "record"), on_warning=on_warning) for r in records]
    folder = None if spec_dir is None else as_path(spec_dir, "spec_dir")
    out = []
    for k, name in enumerate(spec.records):
        path = Path(name)
        if not path.is_absolute() and folder is not None:
            path = folder / path
        if not path.is_file():
            raise InputError(
                f"file not found: {name} (relative to the retrofit spec)", f"records[{k}]"
            )
        out.append(read_record(path, on_warning=on_warning))
    return out
