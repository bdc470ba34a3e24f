"""Floor spectra of the Circolare 2019 §C7.2.3, Eqs. [C7.2.5]–[C7.2.10] (theory §11.5).

The Circolare 21 gennaio 2019 n. 7 gives, for the local mechanisms of a masonry building
(§C8.7.1.2.1.4 sends the reader here), the acceleration spectrum at a height ``z`` from the
building's modes and the ground spectrum. rockmech keeps the first mode only, as
§C7.2.3 and §C8.7.1.2.1.8 allow ("è sufficiente considerare il solo primo modo di
vibrazione"), with the linear mode shape of [C7.2.10]. The formulas, as transcribed from
the official text (``claudiopagani/structural-codes``, ``corpus/assets/circ2019/7.2.json``)::

    [C7.2.5]  S_eZ(T, ξ, z) = sqrt(Σ_k S_eZ,k(T, ξ, z)²)  (≥ S_e(T, ξ) per T > T_1)
    [C7.2.6]  S_eZ,k = A a_Z,k / (1 + (A - 1)(1 - T/(a T_k))^1.6)   per T < a T_k
              S_eZ,k = A a_Z,k                                       per a T_k ≤ T < b T_k
              S_eZ,k = A a_Z,k / (1 + (A - 1)(T/(b T_k) - 1)^1.2)   per T ≥ b T_k
              with A = 1.1 ξ_k^-0.5 η(ξ)
    [C7.2.7]  a_Z,k(z) = S_e(T_k, ξ_k) |γ_k ψ_k(z)| sqrt(1 + 0.0004 ξ_k²)
    [C7.2.8]  a_Z(z) = sqrt(Σ_k a_Z,k(z)²)
    [C7.2.9]  S_eZ,k(T_k, ξ_k, z) = 1.1 ξ_k^-0.5 η(ξ) a_Z,k(z)
    [C7.2.10] γ_1 = 3n / (2n + 1)      (linear first mode, normalised at the top: ψ = z/H)

with ``a = 0.8`` and ``b = 1.1`` ("possono essere assunti pari a 0,8 e 1,1") and ``η`` from
NTC 2018 [3.2.4]. The text defines ``ξ_k`` "in percentuale" for the whole list; rockmech reads
it as a fraction in [C7.2.6] and [C7.2.9] and in percent in [C7.2.7] (theory §11.5 works
the example: in percent, ``A`` at ``ξ_k = 5`` would be 0.49 and the floor spectrum would
fall at resonance below its own value at ``T = 0``).

The displacement spectrum at height is ``S_eZ T²/(4π²)`` (§C8.7.1.2.1.8), bounded from
below, for ``T > b T_1``, by its value at ``b T_1`` ([C8.7.1.12]).

Notation
--------
T, T_1, T_k : period of the mechanism, of the building's first mode and the (possibly
    lengthened) period of mode k used in the spectrum [s]
xi_percent : damping of the mechanism [%]; xi_k_percent : damping of the building [%]
gamma, psi : participation [C7.2.10] and mode shape z/H [-]
se_ground : callable ``(T [s] array, xi [%]) -> S_e [g]``, the ground spectrum
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from shared_schema.errors import InputError

from ..core.model import G, check_non_negative, check_positive
from .hazard import damping_eta

__all__ = [
    "FLOOR_A",
    "FLOOR_B",
    "FloorModel",
    "floor_acceleration",
    "floor_displacement",
    "floor_spectrum",
    "participation_first_mode",
]

#: [C7.2.6]: start and end of the range of maximum amplification, a T_k to b T_k (C7.2.3:
#: "possono essere assunti pari a 0,8 e 1,1 rispettivamente").
FLOOR_A, FLOOR_B = 0.8, 1.1
#: [C7.2.6] and [C7.2.9]: the peak factor 1.1 ξ_k^-0.5 η(ξ).
PEAK_FACTOR = 1.1
#: [C7.2.6]: exponents of the rising and the falling branches.
RISE_EXP, FALL_EXP = 1.6, 1.2
#: [C7.2.7]: the damping term sqrt(1 + 0.0004 ξ_k²), ξ_k in percent.
DAMPING_TERM = 0.0004

#: Why a point of the floor spectrum has the value it has (the ``rule`` of each evaluation).
RULE_C726 = "[C7.2.6]"
RULE_GROUND_T1 = "[C7.2.5]: ≥ S_e(T, ξ) for T > T_1"
RULE_GROUND_ALL = (
    "rockmech: ≥ S_e(T, ξ) also for T ≤ T_1 (one mode omits the ground motion and vanishes "
    "at the foundation; the text bounds only T > T_1)"
)
RULE_C8712 = "[C8.7.1.12]: ≥ S_eZ(T_1) b² T_1²/(4π²) for T > b T_1"

GroundSpectrum = Callable[[NDArray[np.float64], float], NDArray[np.float64]]


def participation_first_mode(storeys: int) -> float:
    """Participation of the linear first mode normalised at the top, [C7.2.10] (-).

    Examples
    --------
    >>> participation_first_mode(4)
    1.3333333333333333
    """
    if not (isinstance(storeys, int) and storeys >= 1):
        raise InputError(f"must be an integer >= 1, got {storeys!r}", "storeys")
    return 3.0 * storeys / (2.0 * storeys + 1.0)


@dataclass(frozen=True)
class FloorModel:
    """The building's first mode at the mechanism's height (theory §11.5).

    Attributes
    ----------
    T1 : float
        First period of the building [s], > 0.
    elongation : float
        ``T_k / T_1``, the period lengthening of the damaged building (§C8.7.1.2.1.4: "un
        incremento del periodo equivalente compreso tra il 50% ed il 100%"), >= 1.
    xi_k_percent : float
        Equivalent viscous damping of the building [%], > 0.
    gamma : float
        Modal participation [-], > 0 ([C7.2.10]).
    psi : float
        Mode shape at the mechanism's height, ``z/H`` [-], in [0, 1].
    """

    T1: float
    elongation: float
    xi_k_percent: float
    gamma: float
    psi: float

    def __post_init__(self) -> None:
        check_positive(self.T1, "T1")
        check_positive(self.xi_k_percent, "xi_k_percent")
        check_positive(self.gamma, "gamma")
        if not self.elongation >= 1.0:
            raise InputError(f"must be >= 1, got {self.elongation!r}", "period_elongation")
        if not 0.0 <= self.psi <= 1.0 + 1e-12:
            raise InputError(f"must be in [0, 1], got {self.psi!r}", "psi")

    @property
    def T_k(self) -> float:
        """The period of the first mode used in [C7.2.6]–[C7.2.7] [s]."""
        return self.T1 * self.elongation

    @property
    def xi_k_fraction(self) -> float:
        """``ξ_k`` as a fraction, the reading of [C7.2.6] and [C7.2.9] (module docstring)."""
        return self.xi_k_percent / 100.0


def floor_acceleration(se_ground: GroundSpectrum, model: FloorModel) -> dict[str, Any]:
    """Peak floor acceleration ``a_Z(z)`` of the first mode, [C7.2.7]–[C7.2.8] [g].

    Parameters
    ----------
    se_ground : callable
        ``(T [s], xi [%]) -> S_e [g]``.
    model : FloorModel

    Returns
    -------
    dict
        ``a_Z_g`` [g], ``Se_Tk_g`` (``S_e(T_k, ξ_k)`` [g]) and ``damping_term``
        (``sqrt(1 + 0.0004 ξ_k²)`` with ``ξ_k`` in percent).
    """
    se_tk = float(se_ground(np.array([model.T_k]), model.xi_k_percent)[0])
    term = math.sqrt(1.0 + DAMPING_TERM * model.xi_k_percent**2)
    a_z = se_tk * abs(model.gamma * model.psi) * term  # [C7.2.7]; [C7.2.8] with one mode
    return {"a_Z_g": a_z, "Se_Tk_g": se_tk, "damping_term": term}


def _peak_factor(model: FloorModel, xi_percent: float) -> float:
    # [C7.2.6], [C7.2.9]: 1.1 ξ_k^-0.5 η(ξ), ξ_k as a fraction, η of the mechanism's ξ.
    return float(PEAK_FACTOR * model.xi_k_fraction**-0.5 * damping_eta(xi_percent))


def floor_spectrum(
    T: ArrayLike, xi_percent: float, se_ground: GroundSpectrum, model: FloorModel
) -> dict[str, Any]:
    """Acceleration spectrum at the mechanism's height, [C7.2.5]–[C7.2.6] [g].

    Parameters
    ----------
    T : array_like of float
        Periods of the mechanism [s], >= 0.
    xi_percent : float
        Damping of the mechanism [%], >= 0 (it enters through ``η(ξ)`` and the ground
        bound ``S_e(T, ξ)``).
    se_ground : callable
        ``(T [s], xi [%]) -> S_e [g]``.
    model : FloorModel

    Returns
    -------
    dict
        ``Se_Z_g`` (array [g]), ``rule`` (per period: which expression gives the value:
        ``RULE_C726``, ``RULE_GROUND_T1`` or ``RULE_GROUND_ALL``), ``A`` (the peak factor),
        ``a_Z_g`` and the floor-acceleration terms.
    """
    t = np.atleast_1d(np.asarray(T, dtype=np.float64))
    if np.any(~np.isfinite(t)) or np.any(t < 0.0):
        raise InputError("periods must be finite and >= 0", "T")
    xi = check_non_negative(xi_percent, "xi_percent")
    acc = floor_acceleration(se_ground, model)
    big_a = _peak_factor(model, xi)
    peak = big_a * acc["a_Z_g"]  # [C7.2.9]
    lo, hi = FLOOR_A * model.T_k, FLOOR_B * model.T_k
    out = np.full_like(t, peak)
    rise = t < lo
    out[rise] = peak / (1.0 + (big_a - 1.0) * (1.0 - t[rise] / lo) ** RISE_EXP)
    fall = t >= hi
    out[fall] = peak / (1.0 + (big_a - 1.0) * (t[fall] / hi - 1.0) ** FALL_EXP)
    ground = se_ground(t, xi)
    rule = np.full(t.shape, RULE_C726, dtype=object)
    above = ground > out
    rule[above & (t > model.T1)] = RULE_GROUND_T1
    rule[above & (t <= model.T1)] = RULE_GROUND_ALL
    return {
        "Se_Z_g": np.maximum(out, ground),
        "rule": rule.tolist(),
        "A": big_a,
        **acc,
    }


def floor_displacement(
    T: ArrayLike, xi_percent: float, se_ground: GroundSpectrum, model: FloorModel
) -> dict[str, Any]:
    """Displacement spectrum at the mechanism's height [m] (§C8.7.1.2.1.8, [C8.7.1.12]).

    ``S_DeZ(T) = S_eZ(T) g T²/(4π²)``, and for ``T > b T_1`` at least
    ``S_eZ(T_1) g b² T_1²/(4π²)`` ([C8.7.1.12]; ``T_1`` is the period of the first mode in
    the spectrum, ``T_k``).

    Returns
    -------
    dict
        ``SDe_Z_m`` (array [m]), ``rule`` (per period, as ``floor_spectrum`` or
        ``RULE_C8712``) and ``floor_spectrum``'s other keys.
    """
    t = np.atleast_1d(np.asarray(T, dtype=np.float64))
    fs = floor_spectrum(t, xi_percent, se_ground, model)
    disp = fs["Se_Z_g"] * G * (t / (2.0 * math.pi)) ** 2
    hi = FLOOR_B * model.T_k
    at_t1 = float(floor_spectrum([model.T_k], xi_percent, se_ground, model)["Se_Z_g"][0])
    bound = at_t1 * G * (hi / (2.0 * math.pi)) ** 2
    rule = list(fs.pop("rule"))
    for i in np.nonzero((t > hi) & (bound > disp))[0]:
        rule[int(i)] = RULE_C8712
    fs.pop("Se_Z_g")
    return {"SDe_Z_m": np.where(t > hi, np.maximum(disp, bound), disp), "rule": rule, **fs}
