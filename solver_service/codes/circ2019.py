"""Local-mechanism checks of the Circolare 21 gennaio 2019 n. 7 §C8.7.1 (theory §11).

Pure numerics: a mechanism side's virtual-work quantities and capacity curve, a demand (the
site's elastic spectrum or a scaled record, at the ground or through the floor spectrum of
``floor_spectra``) in, a check record out. Every number of a record is named in its
``clauses`` map by the clause and equation of the Circolare 2019 or of NTC 2018 that gives
it (or by "rockmech" where the text leaves the choice to the engineer and rockmech makes
it). The formulas, as transcribed from the official text (``claudiopagani/structural-codes``,
``corpus/assets/circ2019/C8.7-step1a.json``, ``C8.7-step1b.json``)::

    [C8.7.1.3]  a = α(d_C) g / (e* FC)
    [C8.7.1.4]  d = d_C Σ(P+Q)δ² / (δ_Cx Σ(P+Q)δ)       (first order: d = φ J/S)
    [C8.7.1.5]  e* = [Σ(P+Q)δ]² / ([Σ(P+Q)] [Σ(P+Q)δ²])
    [C8.7.1.6]  a = 4π²/T0² d                           (free-standing: elastic branch)
    [C8.7.1.7]  T0 = κ λ L sqrt(W / (E g))
    [C8.7.1.8]  a_Z,SLD = α0 g / (e* FC)
    [C8.7.1.9]  S_eZ,SLD(T0) = a_y / FC ≃ α0 g / (e* FC)
    [C8.7.1.10] T_SLV = 1.68 π sqrt(d_SLV / a(d_SLV))
    [C8.7.1.11] T_SLC = 1.56 π sqrt(d_SLC / a(d_SLC))
    [C8.7.1.12] d_SLV = S_eZ(T_SLV, ξ, z) T_SLV²/(4π²)
                (≥ S_eZ(T_1, ξ, z) b² T_1²/(4π²) per T_SLV > b T_1)

and the text of §C8.7.1.2.1.5–8: the limit displacements ``d_SLV = min(0.4 d0, the
displacement where ties or connections break with a loss of more than half the capacity)``
and ``d_SLC = min(0.6 d0, instability)``, ``d0`` on a curve with only the actions verified
to be present up to collapse; the linear check ``a_g,SLV = q a_g,SLD`` (``q = 2``); the
nonlinear demand ``S_De(T_SLV)`` at the ground, the floor spectrum above it, the largest
spectral displacement over ``[T0, T_SLV]`` with site records; ``a_g,SLV`` not below
``a_g,SLD``; the mechanism's damping 8 % (SLV) and 10 % (SLC).

A ground acceleration ``a_g,X`` that brings the mechanism to a limit state is reported as
``ζ a_g``, with ``ζ`` the capacity/demand ratio on the site's spectrum for that limit state
and ``a_g`` its ground acceleration on type A ground: the spectrum's shape (``S``, ``F0``,
``T_C``) is held and its ordinates scale with ``a_g`` (theory §11.3).

Notation
--------
alpha0 : activation multiplier [-]; e_star : participating mass fraction [-]
FC : confidence factor [-]; q : behaviour factor [-]
d, a : spectral displacement [m] and acceleration [m/s²] of the equivalent oscillator
d0 : displacement where the capacity vanishes [m]; T0 : elastic period [s]
T_SLV, T_SLC : the limit states' periods [s]; xi : damping of the mechanism [%]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Optional, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from shared_schema.errors import InputError

from ..core.model import G, check_number, check_positive
from ..core.spectra import response_spectrum
from .circ2009 import VirtualWork, participating_mass
from .floor_spectra import (
    FLOOR_A,
    FLOOR_B,
    FloorModel,
    floor_acceleration,
    floor_displacement,
    floor_spectrum,
)
from .hazard import ElasticSpectrum

__all__ = [
    "CIRC2019",
    "KAPPA_CANTILEVER",
    "KAPPA_SIMPLY_SUPPORTED",
    "Q_DEFAULT",
    "RECORD_POINTS",
    "T_RECORD_MIN",
    "XI_SLC",
    "XI_SLD",
    "XI_SLV",
    "CapacityCurve",
    "CodeDemand",
    "FreeStanding",
    "RecordDemand",
    "linear_check_2019",
    "nonlinear_check_2019",
]

#: The standard every record of this module cites.
CIRC2019 = "Circolare 21 gennaio 2019 n. 7 §C8.7.1 (NTC 2018 §8.7.1)"
#: §C8.7.1.2.1.3, [C8.7.1.7]: κ for "elementi svettanti (mensola)" ...
KAPPA_CANTILEVER = 6.2
#: ... and for "meccanismi flessionali verticali (trave appoggiata)".
KAPPA_SIMPLY_SUPPORTED = 2.2
#: §C8.7.1.2.1.7: "in assenza di valutazioni più accurate ... si può assumere q = 2".
Q_DEFAULT = 2.0
#: §C8.7.1.2.1.5: the demand on a free-standing element "per uno smorzamento ξ = 5%" [%].
XI_SLD = 5.0
#: §C8.7.1.2.1.8: "lo smorzamento viscoso equivalente ξ del meccanismo locale può essere
#: assunto complessivamente pari all'8% per lo SLV e al 10% per lo SLC" [%].
XI_SLV, XI_SLC = 8.0, 10.0
#: §C8.7.1.2.1.6: d_SLV is 40 % and d_SLC 60 % of d0.
D_SLV_FRACTION, D_SLC_FRACTION = 0.4, 0.6
#: ... and a break counts for the SLV when the capacity drops by more than 50 % of its peak.
BREAK_DROP_FRACTION = 0.5
#: The start of d_rule where the ties' break gives d_SLV.
BREAK_RULE = "the ties break"
#: [C8.7.1.10], [C8.7.1.11]: the factors of π.
T_SLV_FACTOR, T_SLC_FACTOR = 1.68, 1.56
#: Shortest period of the records' demand [s] when T0 is 0 (a rigid mechanism): below it a
#: record's spectral displacement is at most PSA (0.05/2π)² ≈ 0.6 mm per g of PSA.
T_RECORD_MIN = 0.05
#: Periods scanned for the code spectrum's largest displacement over [T0, T] at height
#: (log-spaced from T_SCAN_MIN [s], corners added), and the relative tolerance on the
#: period of the refined maximum.
T_SCAN_MIN, DEMAND_SCAN_POINTS, DEMAND_XATOL = 0.01, 200, 1e-10
#: Spectral displacements within this fraction of the largest are taken as equal: the demand
#: is read at the shortest such period (on a plateau the largest is flat, and the period
#: where a scan finds it would otherwise turn on rounding).
DEMAND_RTOL = 1e-9
#: Periods of the records' demand over [T0, T_SLV] (log-spaced, both ends included).
RECORD_POINTS = 40
#: Periods scanned for the spectrum's peak when a free-standing element's T0 is unknown:
#: 0 to PEAK_SCAN_S [s] in PEAK_SCAN_POINTS (the code spectra peak on their plateau, far
#: below 6 s; a floor spectrum peaks near its building's period).
PEAK_SCAN_S, PEAK_SCAN_POINTS = 6.0, 1201
#: The demand spectrum reported in ADRS form: ADRS_POINTS log-spaced periods from ADRS_T_MIN
#: to the larger of ADRS_T_MAX and 1.5 T of the limit state [s].
ADRS_T_MIN, ADRS_T_MAX, ADRS_POINTS = 0.02, 6.0, 120
#: Points of the reported capacity curve.
CURVE_POINTS = 201

# The clause of each number (what the report and the JSON show beside it).
_C = "Circ. 2019 "
CL = {
    "alpha0": _C + "C8.7.1.2.1.1 [C8.7.1.1] (virtual work at rest)",
    "M_star": _C + "C8.7.1.2.1.3 [C8.7.1.5] (M* = e* Σ P/g)",
    "e_star": _C + "C8.7.1.2.1.3 [C8.7.1.5]",
    "FC": _C + "C8.7.1.2.1.3 (FC applied to the capacity in resistance)",
    "a0_star": _C + "C8.7.1.2.1.5 [C8.7.1.8]: a = α0 g/(e* FC) ([C8.7.1.3] at d = 0)",
    "d_per_rad": _C + "C8.7.1.2.1.3 [C8.7.1.4], first order: d = φ Σm δx²/Σm δx",
    "phi0": "theory §1.7 Eq. 6 (φ_ov of the actions kept, see ties)",
    "d0": _C + "C8.7.1.2.1.6 (d0 where a vanishes, actions present up to collapse only)",
    "T0": _C + "C8.7.1.2.1.3 [C8.7.1.7]: T0 = κ λ L sqrt(W/(E g))",
    "kappa": _C + "C8.7.1.2.1.3 [C8.7.1.7] (6.2 cantilever, 2.2 simply supported)",
    "lambda": _C + "C8.7.1.2.1.3 [C8.7.1.7]: λ = L/t",
    "L": _C + "C8.7.1.2.1.3 [C8.7.1.7]",
    "t": _C + "C8.7.1.2.1.3 [C8.7.1.7]",
    "W": _C + "C8.7.1.2.1.3 [C8.7.1.7] (peso specifico) [N/m³]",
    "E": _C + "C8.7.1.2.1.3 [C8.7.1.7] (Tab. C8.5.I) [Pa]",
    "a_y": _C + "C8.7.1.2.1.3 [C8.7.1.6]: intersection of a = 4π²d/T0² with the curve",
    "d_y": _C + "C8.7.1.2.1.3 [C8.7.1.6]",
    "q": _C + "C8.7.1.2.1.7 (q = 2 unless evaluated)",
    "xi_percent": _C + "C8.7.1.2.1.5 (ξ = 5 % for the activation demand)",
    "demand_activation": _C + "C8.7.1.2.1.5 [C8.7.1.8]/[C8.7.1.9] (see demand_rule)",
    "ratio_SLD": _C + "C8.7.1.2.1.5: a_g,SLD/a_g = a0*/demand_activation",
    "a_g_SLD": _C + "C8.7.1.2.1.5 (spectrum shape held)",
    "a_g_SLV": _C + "C8.7.1.2.1.7: a_g,SLV = q a_g,SLD",
    "a_g": "NTC 2018 §3.2 (the site's a_g for the limit state)",
    "demand": _C + "C8.7.1.2.1.7: demand_activation/q (so that a0*/demand = a_g,SLV/a_g)",
    "capacity_ratio": _C + "C8.7.1.2.1.7: a_g,SLV/a_g",
}
CL_LS = {
    "d": _C + "C8.7.1.2.1.6 (see d_rule)",
    "a": _C + "C8.7.1.2.1.3 [C8.7.1.3]: a(d) on the capacity curve",
    "T_SLV": _C + "C8.7.1.2.1.8 [C8.7.1.10]: T_SLV = 1.68 π sqrt(d_SLV/a(d_SLV))",
    "T_SLC": _C + "C8.7.1.2.1.8 [C8.7.1.11]: T_SLC = 1.56 π sqrt(d_SLC/a(d_SLC))",
    "xi_percent": _C + "C8.7.1.2.1.8 (8 % SLV, 10 % SLC)",
    "demand_code": _C + "C8.7.1.2.1.8: largest S_De over [T0, T] (see demand_rule)",
    "demand_code_at_T": _C + "C8.7.1.2.1.8: the period of [T0, T] where demand_code is [s]",
    "demand_records": _C + "C8.7.1.2.1.8: largest S_De over [T0, T_SLV] of the records",
    "demand": _C + "C8.7.1.2.1.8 (the larger of demand_code and demand_records)",
    "ratio_displacement": _C + "C8.7.1.2.1.8: d/demand = a_g,X/a_g",
    "a_g": "NTC 2018 §3.2 (the site's a_g for the limit state)",
    "a_g_capacity": _C + "C8.7.1.2.1.8 (the a_g that brings the mechanism to d)",
    "a_g_SLD": _C + "C8.7.1.2.1.5 (activation, spectrum shape held)",
    "capacity_ratio": _C + "C8.7.1.2.1.8: a_g,X/a_g (a_g,SLV not below a_g,SLD)",
    "records": _C + "C8.7.1.2.1.8: each record's largest S_De over [T0, T] and where",
    "adrs": _C + "C8.7.1.2.1.8: the demand spectrum of demand_rule, d and a = d (2π/T)²",
}


def _clause(key: str, *tables: dict[str, str]) -> str:
    for table in tables:
        if key in table:
            return table[key]
    raise KeyError(key)


# --- demand ---------------------------------------------------------------------------


class _Demand:
    """Ground spectrum (acceleration [g], displacement [m]) and the optional floor model."""

    label: str = ""
    floor: Optional[FloorModel] = None

    def se_g(self, T: NDArray[np.float64], xi_percent: float) -> NDArray[np.float64]:
        raise NotImplementedError

    def sde_m(self, T: NDArray[np.float64], xi_percent: float) -> NDArray[np.float64]:
        raise NotImplementedError

    @property
    def pga_g(self) -> float:
        raise NotImplementedError

    ground_clause = ""
    disp_clause = ""

    # The demand on the mechanism, at the ground or at height --------------------------

    def activation(self) -> tuple[float, str, dict[str, Any]]:
        """Peak acceleration at the mechanism's base [g], the rule, and floor terms."""
        if self.floor is None or self.floor.psi == 0.0:
            return self.pga_g, f"peak ground acceleration a_g S ({self.ground_clause} at T = 0)", {}
        acc = floor_acceleration(self.se_g, self.floor)
        if acc["a_Z_g"] >= self.pga_g:
            return acc["a_Z_g"], "a_Z(z), Circ. 2019 [C7.2.7]-[C7.2.8] (first mode)", acc
        rule = (
            "peak ground acceleration: rockmech keeps a_Z(z) [C7.2.8] (here "
            f"{acc['a_Z_g']:.4g} g) from falling below the ground's; one mode vanishes at the "
            "foundation"
        )
        return self.pga_g, rule, acc

    def acceleration(self, T: float, xi_percent: float) -> tuple[float, str, dict[str, Any]]:
        """Spectral acceleration of the mechanism at period ``T`` [g], with its rule."""
        if self.floor is None or self.floor.psi == 0.0:
            v = float(self.se_g(np.array([T]), xi_percent)[0])
            return v, f"S_e(T, ξ) at the ground, {self.ground_clause}", {}
        fs = floor_spectrum([T], xi_percent, self.se_g, self.floor)
        rule = fs["rule"][0]
        return float(fs["Se_Z_g"][0]), f"S_eZ(T, ξ, z), Circ. 2019 [C7.2.5]-[C7.2.6]; {rule}", fs

    def accelerations(self, T: NDArray[np.float64], xi_percent: float) -> NDArray[np.float64]:
        """Spectral accelerations of the mechanism at periods ``T`` [g] (as ``acceleration``)."""
        if self.floor is None or self.floor.psi == 0.0:
            return self.se_g(T, xi_percent)
        return np.asarray(
            floor_spectrum(T, xi_percent, self.se_g, self.floor)["Se_Z_g"], dtype=np.float64
        )

    def displacement(
        self, T: ArrayLike, xi_percent: float
    ) -> tuple[NDArray[np.float64], list[str]]:
        """Spectral displacement of the mechanism at periods ``T`` [m], with each rule."""
        t = np.atleast_1d(np.asarray(T, dtype=np.float64))
        if self.floor is None or self.floor.psi == 0.0:
            rule = f"S_De(T, ξ) at the ground, {self.disp_clause}"
            return self.sde_m(t, xi_percent), [rule] * t.size
        fd = floor_displacement(t, xi_percent, self.se_g, self.floor)
        rules = [
            f"S_eZ T²/(4π²) at height, Circ. 2019 C8.7.1.2.1.8 [C7.2.5]-[C7.2.6]; {r}"
            for r in fd["rule"]
        ]
        return np.asarray(fd["SDe_Z_m"], dtype=np.float64), rules

    def corner_periods(self) -> list[float]:
        """Periods where the ground spectrum changes its expression [s] (none known here)."""
        return []

    def largest_displacement(
        self, t_lo: float, t_hi: float, xi_percent: float
    ) -> tuple[float, float, str]:
        """Largest spectral displacement over ``[t_lo, t_hi]`` [m], where [s], and its rule.

        Notes
        -----
        §C8.7.1.2.1.8: "La domanda di spostamento sul meccanismo locale allo SLV corrisponde
        al valore massimo dello spostamento spettrale valutato nell'intervallo di periodi
        [T0, T_SLV]" (and by the text's "espressione analoga" at the SLC). On the ground's
        code spectrum every piece between two corner periods is monotonic (NTC [3.2.10]
        rises to T_E, [3.2.11] falls to T_F, then d_g), so the maximum is at an end or a
        corner and is exact. At height the pieces of [C7.2.6] times T² are smooth but not
        monotonic: the best of a scan (the corners included) is refined by bounded Brent.
        """
        lo, hi = max(float(t_lo), 0.0), float(t_hi)
        corners = self.corner_periods()
        if self.floor is not None and self.floor.psi != 0.0:
            tk = self.floor.T_k
            corners = [*corners, FLOOR_A * tk, FLOOR_B * tk, tk, self.floor.T1]
        inside = [c for c in corners if lo < c < hi]
        smooth = self.floor is not None and self.floor.psi != 0.0
        scan: list[float] = []
        if smooth:
            scan = np.geomspace(max(lo, T_SCAN_MIN), hi, DEMAND_SCAN_POINTS).tolist()
        t = np.unique(np.asarray([lo, hi, *inside, *scan], dtype=np.float64))
        t = t[(t >= lo) & (t <= hi)]
        disp, _ = self.displacement(t, xi_percent)
        k = int(np.argmax(disp >= float(disp.max()) * (1.0 - DEMAND_RTOL)))
        t_best, d_best = float(t[k]), float(disp[k])
        if smooth and 0 < k < t.size - 1:
            # Imported here: only a check at height refines, and scipy.optimize is heavy.
            from scipy.optimize import minimize_scalar

            res = minimize_scalar(
                lambda x: -float(self.displacement([x], xi_percent)[0][0]),
                bounds=(float(t[k - 1]), float(t[k + 1])),
                method="bounded",
                options={"xatol": DEMAND_XATOL * float(t[k])},
            )
            if -float(res.fun) > d_best * (1.0 + DEMAND_RTOL):
                t_best, d_best = float(res.x), -float(res.fun)
        rule_at = self.displacement([t_best], xi_percent)[1][0]
        if t_best >= hi * (1.0 - 1e-12):
            rule = f"{rule_at} (the largest over [T0, T] is at T itself, C8.7.1.2.1.8)"
        else:
            rule = (
                f"largest spectral displacement over [T0 = {lo:.4g} s, T = {hi:.4g} s] "
                f"(C8.7.1.2.1.8), at {t_best:.4g} s: {rule_at}"
            )
        return d_best, t_best, rule


@dataclass
class CodeDemand(_Demand):
    """The site's elastic spectrum for a limit state (``hazard.ElasticSpectrum``).

    Attributes
    ----------
    spectrum : ElasticSpectrum
        Its damping is replaced by the one each use asks for (``with_damping``).
    floor : FloorModel, optional
        The building's first mode at the mechanism's height; None at the ground.
    label : str
        What the report calls it (e.g. ``"NTC 2018 SLV spectrum"``).
    """

    spectrum: ElasticSpectrum
    floor: Optional[FloorModel] = None
    label: str = "site spectrum"
    _cache: dict[float, ElasticSpectrum] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        ntc = self.spectrum.code == "NTC2018"
        self.ground_clause = "NTC 2018 §3.2.3.2.1 [3.2.2]" if ntc else "EN 1998-1 §3.2.2.2"
        self.disp_clause = (
            "NTC 2018 §3.2.3.2.3 [3.2.10]-[3.2.11]" if ntc else "EN 1998-1 Eq. 3.7 and Annex A"
        )

    def _at(self, xi_percent: float) -> ElasticSpectrum:
        if xi_percent not in self._cache:
            self._cache[xi_percent] = self.spectrum.with_damping(xi_percent)
        return self._cache[xi_percent]

    def se_g(self, T: NDArray[np.float64], xi_percent: float) -> NDArray[np.float64]:
        """Elastic spectral acceleration at ``T`` [s] for damping ``xi_percent`` [g]."""
        return self._at(xi_percent).Se(T)

    def sde_m(self, T: NDArray[np.float64], xi_percent: float) -> NDArray[np.float64]:
        """Elastic spectral displacement at ``T`` [s] for damping ``xi_percent`` [m]."""
        return self._at(xi_percent).SDe(T)

    def corner_periods(self) -> list[float]:
        """``T_B, T_C, T_D, T_E, T_F`` of the spectrum [s]."""
        sp = self.spectrum
        return [sp.T_B, sp.T_C, sp.T_D, sp.T_E, sp.T_F]

    @property
    def pga_g(self) -> float:
        """Peak ground acceleration ``a_g S`` [g]."""
        return self.spectrum.pga


@dataclass
class RecordDemand(_Demand):
    """A ground-motion record at a scale, as the demand of §C8.7.1.2.1.8's record criterion.

    Attributes
    ----------
    acc : array of float
        Ground acceleration [m/s²], unscaled.
    dt : float
        Sample interval [s].
    scale : float
        Factor on ``acc`` (the design scale of the record), > 0.
    name : str
        The record's name.
    floor : FloorModel, optional
        As ``CodeDemand``: above ground the floor spectrum is built on the record's spectrum.
    """

    acc: NDArray[np.float64]
    dt: float
    scale: float
    name: str
    floor: Optional[FloorModel] = None
    label: str = ""

    def __post_init__(self) -> None:
        check_positive(self.scale, "scale")
        self.label = f"record {self.name} × {self.scale:.4g}"
        self.ground_clause = f"the 5 %-normalised pseudo-acceleration of {self.label}"
        self.disp_clause = f"the spectral displacement of {self.label}"

    def _spectrum(self, T: NDArray[np.float64], xi_percent: float) -> Any:
        t = np.maximum(np.asarray(T, dtype=np.float64), 1e-6)
        return response_spectrum(self.acc * self.scale, self.dt, t, xi_percent / 100.0)

    def se_g(self, T: NDArray[np.float64], xi_percent: float) -> NDArray[np.float64]:
        """Pseudo-spectral acceleration of the scaled record [g]."""
        return np.asarray(self._spectrum(T, xi_percent).psa_g, dtype=np.float64)

    def sde_m(self, T: NDArray[np.float64], xi_percent: float) -> NDArray[np.float64]:
        """Spectral displacement of the scaled record [m]."""
        return np.asarray(self._spectrum(T, xi_percent).sd, dtype=np.float64)

    @property
    def pga_g(self) -> float:
        """Peak ground acceleration of the scaled record [g]."""
        return float(np.max(np.abs(self.acc))) * self.scale / G


# --- free-standing elements and the capacity curve -------------------------------------


@dataclass(frozen=True)
class FreeStanding:
    """A free-standing element's data for its elastic period, [C8.7.1.7].

    Attributes
    ----------
    kappa : float
        κ [-], > 0 (6.2 cantilever, 2.2 simply supported).
    L : float, optional
        Length (height) of the element [m], > 0.
    t : float, optional
        Thickness [m], > 0.
    W : float, optional
        Unit weight of the masonry ("peso specifico") [N/m³], > 0.
    E : float, optional
        Elastic modulus of the masonry [Pa], > 0 (Tab. C8.5.I; a reduced value for cracked
        masonry is suggested).
    sources : dict
        Where each value comes from (for the report).
    """

    kappa: float
    L: Optional[float] = None
    t: Optional[float] = None
    W: Optional[float] = None
    E: Optional[float] = None
    sources: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_positive(self.kappa, "kappa")
        for name in ("L", "t", "W", "E"):
            value = getattr(self, name)
            if value is not None:
                check_positive(value, name)

    @property
    def missing(self) -> list[str]:
        """The inputs of [C8.7.1.7] not given."""
        return [n for n in ("L", "t", "W", "E") if getattr(self, n) is None]

    @property
    def T0(self) -> Optional[float]:
        """``T0 = κ λ L sqrt(W/(E g))`` with ``λ = L/t`` [s], or None if an input is missing."""
        if self.missing:
            return None
        assert self.L is not None and self.t is not None and self.W is not None
        assert self.E is not None
        return self.kappa * (self.L / self.t) * self.L * math.sqrt(self.W / (self.E * G))


@dataclass(frozen=True)
class CapacityCurve:
    """The capacity curve of a side in spectral coordinates (theory §11.3, §11.7).

    The multiplier is linear in the rotation, ``α(φ) = α0 (1 - φ/φ0)`` (rockmech's
    linearised kinematics); ``d = φ J/S`` ([C8.7.1.4] to first order) and
    ``a = α g/(e* FC)`` ([C8.7.1.3]). With ``before``, actions (ties) act until the rotation
    ``phi_break`` with their own line ``(alpha0, phi0)``; from there on the curve is the
    main one. With ``T0`` the elastic branch ``a = 4π² d/T0²`` ([C8.7.1.6]) leads up to the
    curve.

    Attributes
    ----------
    e_star, FC, d_per_rad : float
        Mass fraction [-], confidence factor [-] and ``J/S`` [m/rad].
    alpha0, phi0 : float
        The line of the actions present up to collapse [-], [rad].
    before : (alpha0, phi0, phi_break), optional
        The line while the ties hold and the rotation at which they break.
    T0 : float, optional
        Elastic period of a free-standing element [s].
    """

    e_star: float
    FC: float
    d_per_rad: float
    alpha0: float
    phi0: float
    before: Optional[tuple[float, float, float]] = None
    T0: Optional[float] = None

    def __post_init__(self) -> None:
        check_positive(self.alpha0, "alpha0")
        check_positive(self.phi0, "phi0")
        if self.before is not None:
            for name, v in zip(("alpha0", "phi0", "phi_break"), self.before):
                check_positive(v, f"ties.{name}")

    def _rigid(self, d: NDArray[np.float64], held_at_break: bool = False) -> NDArray[np.float64]:
        phi = d / self.d_per_rad
        alpha = self.alpha0 * (1.0 - phi / self.phi0)
        if self.before is not None:
            a0, p0, pb = self.before
            held = phi <= pb if held_at_break else phi < pb
            alpha = np.where(held, a0 * (1.0 - phi / p0), alpha)
        return np.maximum(alpha, 0.0) * G / (self.e_star * self.FC)

    def a(self, d: ArrayLike, held_at_break: bool = False) -> NDArray[np.float64]:
        """Capacity ``a(d)`` [m/s²] at spectral displacements ``d`` [m] (>= 0).

        At the ties' failure displacement the curve has two values: the one after the break
        (default) and, with ``held_at_break``, the one as the mechanism reaches the break
        with the ties still holding (the limit from the left).
        """
        dd = np.atleast_1d(np.asarray(d, dtype=np.float64))
        rigid = self._rigid(dd, held_at_break)
        if self.T0 is None:
            return rigid
        return np.minimum(rigid, (2.0 * math.pi / self.T0) ** 2 * dd)

    @property
    def d0(self) -> float:
        """Displacement where the main line's capacity vanishes [m]."""
        return self.phi0 * self.d_per_rad

    @property
    def a0(self) -> float:
        """``a`` of the main line at ``d = 0`` [m/s²]."""
        return self.alpha0 * G / (self.e_star * self.FC)

    def yield_point(self) -> Optional[tuple[float, float]]:
        """``(d_y, a_y)`` where the elastic branch meets the curve (free-standing), or None."""
        if self.T0 is None:
            return None
        k = (2.0 * math.pi / self.T0) ** 2
        a0, p0 = (self.before[0], self.before[1]) if self.before else (self.alpha0, self.phi0)
        # k d = c (1 - d/d0') on the first line, c = a0 g/(e* FC), d0' = p0 J/S.
        c = a0 * G / (self.e_star * self.FC)
        d0 = p0 * self.d_per_rad
        d_y = c / (k + c / d0)
        if self.before is not None and d_y > self.before[2] * self.d_per_rad:
            c, d0 = self.a0, self.d0
            d_y = c / (k + c / d0)
        return d_y, k * d_y

    def peak(self) -> float:
        """Return the largest capacity on the curve [m/s²] (at a vertex of the line)."""
        vertices = [0.0]
        yp = self.yield_point()
        if yp is not None:
            vertices.append(yp[0])
        if self.before is not None:
            vertices.append(self.before[2] * self.d_per_rad)
        return float(np.max(self.a(np.array(vertices))))

    def points(self, d_max: float) -> dict[str, list[float]]:
        """Return the curve on ``CURVE_POINTS`` displacements up to ``d_max`` [m] and vertices."""
        d = np.linspace(0.0, d_max, CURVE_POINTS)
        extra = [self.d0]
        yp = self.yield_point()
        if yp is not None:
            extra.append(yp[0])
        if self.before is not None:
            db = self.before[2] * self.d_per_rad
            extra += [db * (1 - 1e-9), db]
        d = np.unique(np.concatenate([d, [x for x in extra if 0.0 <= x <= d_max]]))
        return {"d": d.tolist(), "a": self.a(d).tolist()}


# --- the checks -------------------------------------------------------------------------


def _activation_demand(
    demand: _Demand, free: Optional[FreeStanding]
) -> tuple[float, str, dict[str, Any]]:
    """Acceleration demand at activation [m/s²] (§C8.7.1.2.1.5), its rule and terms."""
    t0 = None if free is None else free.T0
    if free is None:
        v, rule, terms = demand.activation()
        return v * G, "rigid until activation, [C8.7.1.8]: " + rule, terms
    if t0 is None:
        # No T0: the spectrum's peak over every period bounds S_e(T0) for any T0.
        t = np.linspace(0.0, PEAK_SCAN_S, PEAK_SCAN_POINTS)
        values = demand.accelerations(t, XI_SLD)
        k = int(np.argmax(values))
        rule = (
            "free-standing, [C8.7.1.9] with T0 unknown (missing "
            f"{', '.join(free.missing)}): the spectrum's peak over 0-{PEAK_SCAN_S:g} s "
            f"(at {t[k]:.3g} s), an upper bound of S_e(T0) for any T0"
        )
        floor_terms: dict[str, Any] = {}
        if demand.floor is not None and demand.floor.psi != 0.0:
            floor_terms = floor_acceleration(demand.se_g, demand.floor)  # a_Z for the record
        return float(values[k]) * G, rule, floor_terms
    v, rule, terms = demand.acceleration(t0, XI_SLD)
    return v * G, f"free-standing, [C8.7.1.9]: S_e(T0 = {t0:.4g} s, 5 %): " + rule, terms


def _floor_terms(terms: dict[str, Any], floor: Optional[FloorModel]) -> dict[str, Any]:
    if floor is None:
        return {}
    out: dict[str, Any] = {
        "T1": floor.T1,
        "T_k": floor.T_k,
        "xi_k_percent": floor.xi_k_percent,
        "gamma": floor.gamma,
        "psi": floor.psi,
    }
    for key in ("a_Z_g", "Se_Tk_g", "damping_term", "A"):
        if key in terms:
            out[key] = float(terms[key])
    return out


FLOOR_CLAUSES = {
    "T1": "site building.T1, else Circ. 2019 [C7.3.2] (see T1_source)",
    "T_k": "Circ. 2019 C8.7.1.2.1.4: T_k = T1 × period_elongation",
    "xi_k_percent": "Circ. 2019 C8.7.1.2.1.4 (building damping ξ_k; site building.xi_percent)",
    "gamma": "Circ. 2019 [C7.2.10]: γ = 3n/(2n+1)",
    "psi": "Circ. 2019 C7.2.3: linear first mode normalised at the top, ψ = z/H",
    "a_Z_g": "Circ. 2019 [C7.2.7]-[C7.2.8] [g]",
    "Se_Tk_g": "Circ. 2019 [C7.2.7]: S_e(T_k, ξ_k) [g]",
    "damping_term": "Circ. 2019 [C7.2.7]: sqrt(1 + 0.0004 ξ_k²), ξ_k in percent",
    "A": "Circ. 2019 [C7.2.6]/[C7.2.9]: 1.1 ξ_k^-0.5 η(ξ), ξ_k as a fraction",
}


def linear_check_2019(
    vw: VirtualWork,
    demand: _Demand,
    *,
    FC: float,
    a_g: float,
    q: float = Q_DEFAULT,
    free: Optional[FreeStanding] = None,
) -> dict[str, Any]:
    """Linear kinematic analysis, SLV with the behaviour factor q (§C8.7.1.2.1.7).

    Parameters
    ----------
    vw : VirtualWork
        The side's virtual-work quantities (``alpha0 > 0`` for a verdict).
    demand : CodeDemand
        The site's SLV spectrum (with the floor model above ground).
    FC : float
        Confidence factor [-], >= 1.
    a_g : float
        The SLV ground acceleration on type A ground [g], > 0.
    q : float
        Behaviour factor [-], > 0 (2 by default, as the text).
    free : FreeStanding, optional
        A free-standing element: the activation demand is ``S_e(T0)`` ([C8.7.1.9]).

    Returns
    -------
    dict
        The numbers (``a0_star`` [m/s²], ``demand_activation`` [m/s²], ``a_g_SLD``,
        ``a_g_SLV``, ``a_g`` [g], ``capacity_ratio``, ...), ``passes``, ``demand_rule``,
        ``notes`` and ``clauses`` (the clause of every number).

    Notes
    -----
    ``a_g,SLD = a_g a0*/demand_activation`` (the spectrum's shape held);
    ``a_g,SLV = q a_g,SLD`` and the check is ``a_g,SLV >= a_g``.
    """
    FC = check_number(FC, "FC", at_least=1.0)
    q = check_positive(q, "q")
    a_g = check_positive(a_g, "a_g")
    m_star, e_star = participating_mass(vw)
    a0_star = vw.alpha0 * G / (e_star * FC)
    dem, rule, terms = _activation_demand(demand, free)
    ratio_sld = a0_star / dem
    out: dict[str, Any] = {
        "method": "circ2019",
        "standard": CIRC2019 + ": linear kinematic analysis, SLV (C8.7.1.2.1.7)",
        "status": "ok",
        "alpha0": vw.alpha0,
        "M_star": m_star,
        "e_star": e_star,
        "FC": FC,
        "q": q,
        "a0_star": a0_star,
        "free_standing": free is not None,
        "xi_percent": XI_SLD,
        "demand_activation": dem,
        "demand_rule": rule,
        "ratio_SLD": ratio_sld,
        "a_g": a_g,
        "a_g_SLD": ratio_sld * a_g,
        "a_g_SLV": q * ratio_sld * a_g,
        "demand": dem / q,
        "capacity_ratio": q * ratio_sld,
        "notes": [],
    }
    clauses = {k: CL[k] for k in out if k in CL}
    if free is not None:
        out.update(_free_terms(free))
        clauses.update({k: CL[k] for k in ("T0", "kappa", "lambda", "L", "t", "W", "E")})
    floor = _floor_terms(terms, demand.floor)
    if floor:
        out["floor"] = floor
        clauses.update({f"floor.{k}": FLOOR_CLAUSES[k] for k in floor})
    if vw.alpha0 <= 0.0:
        out["notes"].append("alpha0 <= 0: the static loads alone activate the mechanism")
    out["passes"] = bool(out["capacity_ratio"] >= 1.0)
    out["clauses"] = clauses
    out["note"] = "; ".join(out["notes"])
    return out


def _free_terms(free: FreeStanding) -> dict[str, Any]:
    lam = None if free.L is None or free.t is None else free.L / free.t
    return {
        "T0": free.T0,
        "kappa": free.kappa,
        "lambda": lam,
        "L": free.L,
        "t": free.t,
        "W": free.W,
        "E": free.E,
        "free_standing_sources": dict(free.sources),
    }


def _record_demand(
    records: Sequence[RecordDemand], t_lo: float, t_hi: float, xi_percent: float
) -> tuple[Optional[float], list[dict[str, Any]]]:
    """Largest spectral displacement over [t_lo, t_hi] of each record, and the largest [m]."""
    if not records:
        return None, []
    lo = max(t_lo, T_RECORD_MIN)
    if lo >= t_hi:
        periods = np.array([t_hi])
    else:
        periods = np.geomspace(lo, t_hi, RECORD_POINTS)
    rows: list[dict[str, Any]] = []
    largest = 0.0
    for rec in records:
        disp, _ = rec.displacement(periods, xi_percent)
        k = int(np.argmax(disp))
        largest = max(largest, float(disp[k]))
        rows.append({"record": rec.label, "demand": float(disp[k]), "at_T": float(periods[k])})
    return largest, rows


def _limit_period(
    name: str, curve: CapacityCurve, d_limit: float, at_break: bool
) -> tuple[float, float]:
    """Return ``a(d)`` at a limit state's displacement [m/s²] and the state's period [s].

    [C8.7.1.10] ``T_SLV = 1.68 π sqrt(d_SLV / a(d_SLV))``, [C8.7.1.11] ``T_SLC = 1.56 π
    sqrt(d_SLC / a(d_SLC))``; ``a(d)`` on the capacity curve by [C8.7.1.3]. A vanishing
    ``a(d)`` is an error (no period).
    """
    factor = T_SLV_FACTOR if name == "SLV" else T_SLC_FACTOR
    a_d = float(curve.a([d_limit], held_at_break=at_break)[0])
    if not a_d > 0.0:
        raise InputError(
            f"the capacity vanishes at d_{name} = {d_limit:.4g} m: no period for {name}",
            f"d_{name}",
        )
    return a_d, factor * math.pi * math.sqrt(d_limit / a_d)


def _displacement_demand(
    demand: _Demand,
    records: Sequence[RecordDemand],
    t0: float,
    period: float,
    xi_percent: float,
) -> dict[str, Any]:
    """Return the displacement demand of a limit state (§C8.7.1.2.1.8), its terms by key.

    The code spectrum's largest ``S_De`` over ``[T0, T]`` (the mechanism's damping, at its
    height) and the records' largest over the same periods; the larger governs
    (``demand``). Keys: ``demand_code``, ``demand_code_at_T``, ``demand_rule``,
    ``demand_records`` (None without records), ``records``, ``demand`` [m, s].
    """
    code_v, code_at, code_rule = demand.largest_displacement(t0, period, xi_percent)
    rec_v, rec_rows = _record_demand(records, t0, period, xi_percent)
    governing = code_v if rec_v is None else max(code_v, rec_v)
    return {
        "demand_code": code_v,
        "demand_code_at_T": code_at,
        "demand_rule": code_rule,
        "demand_records": rec_v,
        "records": rec_rows,
        "demand": governing,
    }


def _adrs(demand: _Demand, period: float, xi_percent: float) -> dict[str, list[float]]:
    """Return the demand spectrum in ADRS form (for the report's plot): ``d(T)``, ``a``.

    ``a = d (2π/T)²`` [m/s²] over ``ADRS_POINTS`` periods from ``ADRS_T_MIN`` to the larger
    of ``ADRS_T_MAX`` and 1.5 times the limit state's period [s].
    """
    t = np.geomspace(ADRS_T_MIN, max(ADRS_T_MAX, 1.5 * period), ADRS_POINTS)
    d_spec, _ = demand.displacement(t, xi_percent)
    return {
        "T": t.tolist(),
        "d": d_spec.tolist(),
        "a": (d_spec * (2.0 * math.pi / t) ** 2).tolist(),
    }


def _limit_state(
    name: str,
    curve: CapacityCurve,
    d_limit: float,
    d_rule: str,
    demand: _Demand,
    a_g: float,
    xi_percent: float,
    records: Sequence[RecordDemand],
    ratio_sld: Optional[float],
    evaluated: bool,
) -> dict[str, Any]:
    """One limit state of the displacement check (§C8.7.1.2.1.8).

    When ``d_rule`` says the ties break (``BREAK_RULE``), ``d_limit`` is where they do;
    ``a(d)`` of [C8.7.1.10] is then taken as the mechanism reaches that displacement
    ("raggiungimento dello SLV"), with the ties still holding. The demand is over
    ``[T0, T]``, ``T0`` the curve's (0 for a rigid mechanism).

    Parameters
    ----------
    name : str
        ``"SLV"`` or ``"SLC"``.
    curve : CapacityCurve
        The capacity curve.
    d_limit : float
        The limit displacement [m] (§C8.7.1.2.1.6).
    d_rule : str
        What gives it.
    demand : _Demand
        The limit state's spectrum.
    a_g : float
        Its ground acceleration on type A ground [g].
    xi_percent : float
        The mechanism's damping [%].
    records : sequence of RecordDemand
        Records at their design scale (their demand over ``[T0, T]`` also counts).
    ratio_sld : float or None
        ``a_g,SLD / a_g`` of the activation, the lower bound of ``a_g,SLV``; None for the SLC.
    evaluated : bool
        False when the hazard is not the site's (the verdict is then None).
    """
    at_break = d_rule.startswith(BREAK_RULE)
    t0 = curve.T0 or 0.0
    # [C8.7.1.10] / [C8.7.1.11]: the period at the limit displacement.
    a_d, period = _limit_period(name, curve, d_limit, at_break)
    # C8.7.1.2.1.8: the demand over [T0, T], and d/demand = a_g,X/a_g.
    terms = _displacement_demand(demand, records, t0, period, xi_percent)
    ratio_d = d_limit / terms["demand"]
    out: dict[str, Any] = {
        "d": d_limit,
        "d_rule": d_rule,
        "a": a_d,
        f"T_{name}": period,
        "xi_percent": xi_percent,
        **terms,
        "ratio_displacement": ratio_d,
        "a_g": a_g,
        "a_g_capacity": ratio_d * a_g,
    }
    # C8.7.1.2.1.8: a_g,SLV not below a_g,SLD of the activation (C8.7.1.2.1.5).
    ratio = ratio_d
    if ratio_sld is not None:
        out["a_g_SLD"] = ratio_sld * a_g
        out["lower_bound_applied"] = bool(ratio_sld > ratio_d)
        if ratio_sld > ratio_d:
            ratio = ratio_sld
            out["a_g_capacity"] = ratio_sld * a_g
    out["capacity_ratio"] = ratio
    out["passes"] = bool(ratio >= 1.0) if evaluated else None
    out["adrs"] = _adrs(demand, period, xi_percent)
    out["clauses"] = {k: CL_LS[k] for k in out if k in CL_LS}
    out["clauses"]["a_g_SLD"] = CL_LS["a_g_SLD"]
    if terms["demand_records"] is None:
        out["clauses"].pop("demand_records", None)
    return out


def _thresholds(
    curve: CapacityCurve, instability_rotation: Optional[float]
) -> tuple[tuple[float, str], tuple[float, str], list[str]]:
    """Return ``(d_SLV, rule)``, ``(d_SLC, rule)`` and notes (§C8.7.1.2.1.6)."""
    notes: list[str] = []
    d0 = curve.d0
    candidates = [(D_SLV_FRACTION * d0, "0.4 d0 (C8.7.1.2.1.6)")]
    if curve.before is not None:
        d_b = curve.before[2] * curve.d_per_rad
        drop = float(
            curve._rigid(np.array([d_b]), held_at_break=True)[0] - curve._rigid(np.array([d_b]))[0]
        )
        peak = curve.peak()
        if drop > BREAK_DROP_FRACTION * peak:
            candidates.append(
                (
                    d_b,
                    f"{BREAK_RULE} (C8.7.1.2.1.6: capacity loss "
                    f"{drop / peak:.0%} of the peak > 50 %)",
                )
            )
        else:
            notes.append(
                f"the ties break at d = {d_b:.4g} m with a capacity loss of {drop / peak:.0%} of "
                "the peak (not more than 50 %): not an SLV threshold (C8.7.1.2.1.6)"
            )
    d_slv, rule_slv = min(candidates)
    slc_candidates = [(D_SLC_FRACTION * d0, "0.6 d0 (C8.7.1.2.1.6)")]
    if instability_rotation is not None:
        slc_candidates.append(
            (
                check_positive(instability_rotation, "instability_rotation") * curve.d_per_rad,
                "local instability (C8.7.1.2.1.6, given)",
            )
        )
    d_slc, rule_slc = min(slc_candidates)
    return (d_slv, rule_slv), (d_slc, rule_slc), notes


def nonlinear_check_2019(
    vw: VirtualWork,
    curve: CapacityCurve,
    demand_slv: _Demand,
    *,
    a_g_slv: float,
    demand_slc: Optional[_Demand] = None,
    a_g_slc: Optional[float] = None,
    free: Optional[FreeStanding] = None,
    records: Sequence[RecordDemand] = (),
    instability_rotation: Optional[float] = None,
    xi_slv: float = XI_SLV,
    xi_slc: float = XI_SLC,
    evaluated_slv: bool = True,
) -> dict[str, Any]:
    """Nonlinear kinematic analysis, SLV and SLC displacement checks (§C8.7.1.2.1.6, .8).

    Parameters
    ----------
    vw : VirtualWork
        The side's virtual-work quantities (for ``e*`` and the activation).
    curve : CapacityCurve
        The capacity curve (with the ties' choice and the elastic branch already made).
    demand_slv : CodeDemand
        The SLV spectrum (with the floor model above ground).
    a_g_slv : float
        The SLV ground acceleration on type A ground [g], > 0.
    demand_slc, a_g_slc : optional
        The SLC spectrum and its ``a_g``; without them the SLC displacement is compared with
        the SLV spectrum's shape to report ``a_g,SLC``, and its verdict is None.
    free : FreeStanding, optional
        A free-standing element (the activation demand for the lower bound).
    records : sequence of RecordDemand
        Records at their design scale: the demand is also the largest spectral
        displacement over ``[T0, T_SLV]`` (``[T0, T_SLC]``), and the larger one governs.
    instability_rotation : float, optional
        Rotation [rad] where the mechanism becomes locally unstable (beam unseating, vault
        collapse), a candidate for ``d_SLC``.
    xi_slv, xi_slc : float
        Damping of the mechanism [%] (8 and 10 by default, as the text).
    evaluated_slv : bool
        False when the SLV hazard is not the site's (the verdict is then None).

    Returns
    -------
    dict
        ``d0``, ``T0``, ``SLV`` and ``SLC`` records (``d``, ``a``, ``T_SLV``/``T_SLC``,
        ``demand``, ``a_g_capacity``, ``capacity_ratio``, ``passes``, ``clauses``), the
        curve, and at the top ``T_SLV``, ``d_SLV``, ``demand``, ``capacity_ratio`` and
        ``passes`` of the SLV.
    """
    _, e_star = participating_mass(vw)
    a_g_slv = check_positive(a_g_slv, "a_g")
    d0 = curve.d0
    # C8.7.1.2.1.6: the limit displacements.
    (d_slv, rule_slv), (d_slc, rule_slc), notes = _thresholds(curve, instability_rotation)
    # C8.7.1.2.1.5: a_g,SLD on the SLV spectrum (for the lower bound of C8.7.1.2.1.8).
    dem_act, act_rule, _ = _activation_demand(demand_slv, free)
    a0_star = vw.alpha0 * G / (e_star * curve.FC)
    ratio_sld = a0_star / dem_act
    # C8.7.1.2.1.8: the SLV and the SLC.
    slv = _limit_state(
        "SLV",
        curve,
        d_slv,
        rule_slv,
        demand_slv,
        a_g_slv,
        xi_slv,
        records,
        ratio_sld,
        evaluated_slv,
    )
    slc = _slc(curve, d_slc, rule_slc, demand_slv, demand_slc, a_g_slv, a_g_slc, xi_slc, records)
    d_max = 1.15 * max(d0, d_slc, slv["demand"], slc["demand"])
    out: dict[str, Any] = {
        "method": "circ2019",
        "standard": CIRC2019 + ": nonlinear kinematic analysis, SLV and SLC (C8.7.1.2.1.6, 8)",
        "status": "ok",
        "alpha0": curve.alpha0,
        "e_star": e_star,
        "FC": curve.FC,
        "a0_star": a0_star,
        "d_per_rad": curve.d_per_rad,
        "phi0": curve.phi0,
        "d0": d0,
        "free_standing": free is not None,
        "demand_activation": dem_act,
        "activation_rule": act_rule,
        "SLV": slv,
        "SLC": slc,
        "T_SLV": slv["T_SLV"],
        "d_SLV": d_slv,
        "demand": slv["demand"],
        "capacity_ratio": slv["capacity_ratio"],
        "passes": slv["passes"],
        "curve": curve.points(d_max),
        "notes": notes,
    }
    clauses = _nonlinear_clauses()
    if free is not None:
        _free_standing(out, clauses, curve, free)
    clauses["curve"] = CL_LS["a"] + " with d = φ J/S; [C8.7.1.6] for a free-standing element"
    _ties_and_floor(out, clauses, curve, demand_slv)
    out["clauses"] = clauses
    out["note"] = "; ".join(notes)
    return out


def _slc(
    curve: CapacityCurve,
    d_slc: float,
    rule_slc: str,
    demand_slv: _Demand,
    demand_slc: Optional[_Demand],
    a_g_slv: float,
    a_g_slc: Optional[float],
    xi_slc: float,
    records: Sequence[RecordDemand],
) -> dict[str, Any]:
    """Return the SLC's displacement check (§C8.7.1.2.1.8, [C8.7.1.11]).

    On the SLC spectrum and its ``a_g`` where the site gives them; without them on the SLV
    spectrum's shape and ``a_g`` (a note says so), and the verdict is not evaluated.
    ``nonlinear_check_2019`` gives the parameters.
    """
    slc_demand = demand_slc if demand_slc is not None else demand_slv
    slc_ag = a_g_slc if (demand_slc is not None and a_g_slc is not None) else a_g_slv
    slc = _limit_state(
        "SLC",
        curve,
        d_slc,
        rule_slc,
        slc_demand,
        slc_ag,
        xi_slc,
        records,
        None,
        demand_slc is not None,
    )
    if demand_slc is None:
        slc["note"] = (
            "no SLC hazard in the site file (hazard.limit_states.SLC): a_g_capacity is on the "
            "SLV spectrum's shape and a_g is the SLV one; the SLC verdict is not evaluated"
        )
    return slc


def _nonlinear_clauses() -> dict[str, str]:
    """Return the clauses of the nonlinear check's own numbers (its limit states' apart)."""
    clauses = {k: CL[k] for k in ("alpha0", "e_star", "FC", "a0_star", "d_per_rad", "phi0", "d0")}
    clauses["alpha0"] = (
        _C + "C8.7.1.2.1.1 [C8.7.1.1] of the actions kept in the curve (C8.7.1.2.1.6)"
    )
    clauses["a0_star"] = CL["a0_star"] + ", every action (activation, for a_g,SLD)"
    clauses.update(
        {
            "demand_activation": CL["demand_activation"],
            "T_SLV": CL_LS["T_SLV"],
            "d_SLV": CL_LS["d"],
            "demand": CL_LS["demand"],
            "capacity_ratio": CL_LS["capacity_ratio"],
        }
    )
    return clauses


def _free_standing(
    out: dict[str, Any], clauses: dict[str, str], curve: CapacityCurve, free: FreeStanding
) -> None:
    """Add a free-standing element's terms: [C8.7.1.7] ``T0`` and [C8.7.1.6] the yield point."""
    out.update(_free_terms(free))
    clauses.update({k: CL[k] for k in ("T0", "kappa", "lambda", "L", "t", "W", "E")})
    yp = curve.yield_point()
    if yp is not None:
        out["d_y"], out["a_y"] = yp
        clauses.update({"d_y": CL["d_y"], "a_y": CL["a_y"]})


def _ties_and_floor(
    out: dict[str, Any], clauses: dict[str, str], curve: CapacityCurve, demand: _Demand
) -> None:
    """Add the ties' line of the curve and the floor spectrum's terms, where there are any."""
    if curve.before is not None:
        clauses["ties_curve"] = _C + "C8.7.1.2.1.6: the ties' line until their failure rotation"
        out["ties_curve"] = {
            "alpha0": curve.before[0],
            "phi0": curve.before[1],
            "phi_break": curve.before[2],
            "d_break": curve.before[2] * curve.d_per_rad,
        }
    if demand.floor is not None:
        terms = floor_acceleration(demand.se_g, demand.floor)
        floor = _floor_terms(terms, demand.floor)
        out["floor"] = floor
        clauses.update({f"floor.{k}": FLOOR_CLAUSES[k] for k in floor})
