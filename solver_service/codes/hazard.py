"""Elastic design spectra of NTC 2018 (Italy) and EN 1998-1 (Eurocode 8) (theory §11.4).

Both codes share one shape: a rising branch to ``T_B``, a plateau ``a_g S eta F`` to ``T_C``,
``1/T`` to ``T_D`` and ``1/T²`` beyond; the displacement spectrum is
``S_De = S_e (T / 2 pi)²`` up to ``T_E`` and then tends to the ground displacement ``d_g``.
NTC 2018 §3.2.3.2 takes the plateau factor ``F0`` and ``T_C*`` from the hazard map and
builds ``S = S_S S_T`` and ``T_C = C_C T_C*`` from the soil and topographic categories;
EN 1998-1 §3.2.2.2 takes ``S``, ``T_B``, ``T_C``, ``T_D`` from a table per ground type and
spectrum type, with the plateau factor 2.5 and ``a_g = gamma_I a_gR``.

Notation
--------
a_g : design ground acceleration on type A ground [g]
S : soil (and topographic) factor [-]; eta : damping correction [-]
F : plateau amplification (NTC ``F0``; EC8 2.5) [-]
T_B, T_C, T_D : corner periods [s]; T_E, T_F : displacement-spectrum corner periods [s]
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from shared_schema.errors import InputError

from ..core.model import G, check_non_negative, check_positive

__all__ = [
    "EC8_TABLE",
    "NTC_SOIL",
    "NTC_TOPOGRAPHY",
    "ElasticSpectrum",
    "damping_eta",
    "ec8_spectrum",
    "ntc_spectrum",
]

#: NTC 2018 Tab. 3.2.IV: soil category -> (S_S lower bound, a, b, S_S upper bound, C_C factor,
#: C_C exponent) with ``S_S = clip(a - b F0 a_g, lo, hi)`` and ``C_C = f (T_C*)**e``.
NTC_SOIL: dict[str, tuple[float, float, float, float, float, float]] = {
    "A": (1.00, 1.00, 0.00, 1.00, 1.00, 0.00),
    "B": (1.00, 1.40, 0.40, 1.20, 1.10, -0.20),
    "C": (1.00, 1.70, 0.60, 1.50, 1.05, -0.33),
    "D": (0.90, 2.40, 1.50, 1.80, 1.25, -0.50),
    "E": (1.00, 2.00, 1.10, 1.60, 1.15, -0.40),
}
#: NTC 2018 Tab. 3.2.V: topographic amplification S_T (at the top of the relief).
NTC_TOPOGRAPHY: dict[str, float] = {"T1": 1.0, "T2": 1.2, "T3": 1.2, "T4": 1.4}
#: EN 1998-1 Tables 3.2 and 3.3: (spectrum type, ground type) -> (S, T_B, T_C, T_D) [-, s].
EC8_TABLE: dict[tuple[int, str], tuple[float, float, float, float]] = {
    (1, "A"): (1.00, 0.15, 0.40, 2.0),
    (1, "B"): (1.20, 0.15, 0.50, 2.0),
    (1, "C"): (1.15, 0.20, 0.60, 2.0),
    (1, "D"): (1.35, 0.20, 0.80, 2.0),
    (1, "E"): (1.40, 0.15, 0.50, 2.0),
    (2, "A"): (1.00, 0.05, 0.25, 1.2),
    (2, "B"): (1.35, 0.05, 0.25, 1.2),
    (2, "C"): (1.50, 0.10, 0.25, 1.2),
    (2, "D"): (1.80, 0.10, 0.30, 1.2),
    (2, "E"): (1.60, 0.05, 0.25, 1.2),
}
#: Displacement-spectrum corner periods (T_E, T_F) [s] per ground type (NTC 2018
#: Tab. 3.2.VII; EN 1998-1 Annex A, Table A.1).
DISPLACEMENT_CORNERS: dict[str, tuple[float, float]] = {
    "A": (4.5, 10.0),
    "B": (5.0, 10.0),
    "C": (6.0, 10.0),
    "D": (6.0, 10.0),
    "E": (6.0, 10.0),
}
#: Lower bound of the damping correction eta (both codes).
ETA_MIN = 0.55
#: Ground displacement factor: d_g = 0.025 a_g S T_C T_D (NTC 2018 [3.2.12], EC8 Eq. 3.12).
DG_FACTOR = 0.025


def damping_eta(xi_percent: float) -> float:
    """Damping correction ``eta = sqrt(10 / (5 + xi)) >= 0.55``, ``xi`` in percent (-).

    NTC 2018 [3.2.4] ("ξ (espresso in percentuale)"), EN 1998-1 Eq. 3.6.

    Examples
    --------
    >>> round(damping_eta(8.0), 6)
    0.877058
    """
    xi = check_non_negative(xi_percent, "xi_percent")
    return max(math.sqrt(10.0 / (5.0 + xi)), ETA_MIN)


@dataclass(frozen=True)
class ElasticSpectrum:
    """An elastic acceleration and displacement spectrum of the codes' common shape.

    Attributes
    ----------
    code : str
        ``"NTC2018"`` or ``"EC8"``.
    a_g : float
        Design ground acceleration on type A ground [g].
    S : float
        Soil factor (NTC: ``S_S S_T``) [-].
    eta : float
        Damping correction [-].
    F : float
        Plateau amplification (NTC ``F0``, EC8 2.5) [-].
    T_B, T_C, T_D, T_E, T_F : float
        Corner periods [s].
    params : dict
        Every intermediate value, named as the code names it, for the report.
    """

    code: str
    a_g: float
    S: float
    eta: float
    F: float
    T_B: float
    T_C: float
    T_D: float
    T_E: float
    T_F: float
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def pga(self) -> float:
        """Peak ground acceleration ``a_g S`` on the site's ground [g]."""
        return self.a_g * self.S

    @property
    def d_g(self) -> float:
        """Design ground displacement ``0.025 a_g S T_C T_D`` [m]."""
        return DG_FACTOR * self.a_g * G * self.S * self.T_C * self.T_D

    def with_damping(self, xi_percent: float) -> ElasticSpectrum:
        """Return the same spectrum for another viscous damping ``xi_percent`` [%] (``eta`` only).

        Examples
        --------
        >>> sp = ntc_spectrum(0.25, 2.4, 0.3, soil="C")
        >>> round(sp.with_damping(8.0).eta, 6)
        0.877058
        """
        return replace(
            self,
            eta=damping_eta(xi_percent),
            params={**self.params, "xi_percent": float(xi_percent)},
        )

    def Se(self, T: ArrayLike) -> NDArray[np.float64]:
        """Elastic spectral acceleration [g] at periods ``T`` [s] (>= 0).

        Notes
        -----
        NTC 2018 [3.2.2] / EN 1998-1 Eqs. 3.2-3.5 with the plateau factor ``F``::

            0 <= T < T_B:    a_g S eta F [T/T_B + (1 - T/T_B)/(eta F)]
            T_B <= T < T_C:  a_g S eta F
            T_C <= T < T_D:  a_g S eta F T_C / T
            T_D <= T:        a_g S eta F T_C T_D / T²
        """
        t = np.asarray(T, dtype=np.float64)
        if np.any(~np.isfinite(t)) or np.any(t < 0.0):
            raise InputError("periods must be finite and >= 0", "T")
        top = self.a_g * self.S * self.eta * self.F
        out = np.empty_like(t)
        rise = t < self.T_B
        r = t[rise] / self.T_B
        out[rise] = top * (r + (1.0 - r) / (self.eta * self.F))
        flat = (t >= self.T_B) & (t < self.T_C)
        out[flat] = top
        mid = (t >= self.T_C) & (t < self.T_D)
        out[mid] = top * self.T_C / t[mid]
        tail = t >= self.T_D
        out[tail] = top * self.T_C * self.T_D / t[tail] ** 2
        return out

    def SDe(self, T: ArrayLike) -> NDArray[np.float64]:
        """Elastic spectral displacement [m] at periods ``T`` [s] (>= 0).

        Notes
        -----
        NTC 2018 [3.2.10]-[3.2.11] (§3.2.3.2.3) and [3.2.12] (d_g, §3.2.3.3) / EN 1998-1
        Eq. 3.7 and Annex A::

            T <= T_E:         S_e(T) g (T / 2 pi)²
            T_E < T <= T_F:   d_g' [eta F + (1 - eta F)(T - T_E)/(T_F - T_E)]
            T > T_F:          d_g' = 0.025 a_g S T_C T_D

        (both codes leave a small step at ``T_E``, since ``0.025 != 1/(4 pi²)``).
        """
        t = np.asarray(T, dtype=np.float64)
        se = self.Se(t) * G
        out = se * (t / (2.0 * math.pi)) ** 2
        d_g = self.d_g
        band = (t > self.T_E) & (t <= self.T_F)
        ef = self.eta * self.F
        out[band] = d_g * (ef + (1.0 - ef) * (t[band] - self.T_E) / (self.T_F - self.T_E))
        out[t > self.T_F] = d_g
        return out


def ntc_spectrum(
    a_g: float,
    F0: float,
    Tc_star: float,
    soil: str = "A",
    topography: str = "T1",
    xi_percent: float = 5.0,
) -> ElasticSpectrum:
    """Horizontal elastic spectrum of NTC 2018 §3.2.3.2.1.

    Parameters
    ----------
    a_g : float
        Ground acceleration on type A ground for the limit state [g], > 0.
    F0 : float
        Maximum spectral amplification on type A ground [-], > 0.
    Tc_star : float
        ``T_C*``, start of the constant-velocity branch on type A ground [s], > 0.
    soil : {"A", "B", "C", "D", "E"}
        Soil category (Tab. 3.2.II).
    topography : {"T1", "T2", "T3", "T4"}
        Topographic category (Tab. 3.2.III); ``S_T`` at the top of the relief.
    xi_percent : float
        Viscous damping [%], default 5.

    Returns
    -------
    ElasticSpectrum

    Notes
    -----
    ``S = S_S S_T`` [3.2.3]; ``S_S = clip(a - b F0 a_g)`` and ``C_C = f (T_C*)^e``
    (Tab. 3.2.IV); ``T_C = C_C T_C*`` [3.2.5], ``T_B = T_C / 3`` [3.2.6],
    ``T_D = 4 a_g + 1.6`` [3.2.7] (``a_g`` in g); ``eta`` [3.2.4].

    Examples
    --------
    >>> sp = ntc_spectrum(0.25, 2.4, 0.3, soil="C")
    >>> round(sp.params["S_S"], 4), round(sp.T_D, 4)
    (1.34, 2.6)
    """
    a_g = check_positive(a_g, "a_g")
    F0 = check_positive(F0, "F0")
    Tc_star = check_positive(Tc_star, "Tc_star")
    if soil not in NTC_SOIL:
        raise InputError(f"must be one of {sorted(NTC_SOIL)}, got {soil!r}", "soil")
    if topography not in NTC_TOPOGRAPHY:
        raise InputError(
            f"must be one of {sorted(NTC_TOPOGRAPHY)}, got {topography!r}", "topography"
        )
    lo, a, b, hi, f, e = NTC_SOIL[soil]
    s_s = min(max(a - b * F0 * a_g, lo), hi)
    c_c = f * Tc_star**e
    s_t = NTC_TOPOGRAPHY[topography]
    t_c = c_c * Tc_star
    t_e, t_f = DISPLACEMENT_CORNERS[soil]
    eta = damping_eta(xi_percent)
    return ElasticSpectrum(
        code="NTC2018",
        a_g=a_g,
        S=s_s * s_t,
        eta=eta,
        F=F0,
        T_B=t_c / 3.0,
        T_C=t_c,
        T_D=4.0 * a_g + 1.6,
        T_E=t_e,
        T_F=t_f,
        params={
            "a_g_g": a_g,
            "F0": F0,
            "Tc_star_s": Tc_star,
            "soil": soil,
            "topography": topography,
            "S_S": s_s,
            "S_T": s_t,
            "C_C": c_c,
            "xi_percent": xi_percent,
        },
    )


def ec8_spectrum(
    a_gR: float,
    importance: float = 1.0,
    ground: str = "A",
    spectrum_type: int = 1,
    xi_percent: float = 5.0,
) -> ElasticSpectrum:
    """Horizontal elastic spectrum of EN 1998-1:2004 §3.2.2.2 (recommended values).

    Parameters
    ----------
    a_gR : float
        Reference peak ground acceleration on type A ground [g], > 0.
    importance : float
        Importance factor ``gamma_I`` [-], > 0; ``a_g = gamma_I a_gR``.
    ground : {"A", "B", "C", "D", "E"}
        Ground type (Table 3.1).
    spectrum_type : {1, 2}
        Type 1 (Ms > 5.5) or Type 2.
    xi_percent : float
        Viscous damping [%], default 5.

    Returns
    -------
    ElasticSpectrum

    Examples
    --------
    >>> sp = ec8_spectrum(0.2, 1.2, "C", 1)
    >>> round(float(sp.Se([0.3])[0]), 4)  # plateau: 0.24 g x 1.15 x 2.5
    0.69
    """
    a_gR = check_positive(a_gR, "a_gR")
    importance = check_positive(importance, "importance")
    if (spectrum_type, ground) not in EC8_TABLE:
        raise InputError(
            f"ground must be one of A-E and spectrum_type 1 or 2, got {ground!r}, "
            f"{spectrum_type!r}",
            "ground",
        )
    s, t_b, t_c, t_d = EC8_TABLE[(spectrum_type, ground)]
    t_e, t_f = DISPLACEMENT_CORNERS[ground]
    a_g = importance * a_gR
    return ElasticSpectrum(
        code="EC8",
        a_g=a_g,
        S=s,
        eta=damping_eta(xi_percent),
        F=2.5,
        T_B=t_b,
        T_C=t_c,
        T_D=t_d,
        T_E=t_e,
        T_F=t_f,
        params={
            "a_gR_g": a_gR,
            "gamma_I": importance,
            "a_g_g": a_g,
            "ground": ground,
            "spectrum_type": spectrum_type,
            "xi_percent": xi_percent,
        },
    )
