"""The 2009 forms of the kinematic checks (Circolare 617/2009 C8A.4; theory §11.8).

Kept for comparison only (``local_mechanisms.method: "circ2009"``); the checks rockmech
runs by default are the Circolare 2019's (``codes.circ2019``). Also the virtual-work
quantities both use (``VirtualWork``, ``participating_mass``; theory §11.1).

Pure numerics: the virtual-work quantities of a mechanism side (``alpha0``, ``mass``, ``S``,
``J``) and an elastic spectrum (``hazard.ElasticSpectrum``) in, a check record out, each
field named as the 2009 Circolare names it. These forms were written from memory of the
2009 text, not read in it (theory §11.8).

Notation (theory §11)
---------------------
alpha0 : activation multiplier [-]
M_star, e_star : participating mass [kg] and mass fraction [-]
a0_star : spectral acceleration that activates the mechanism [m/s²]
FC : confidence factor [-]; q : behaviour factor [-]
Z, H : height of the mechanism's base and of the building above the foundation [m]
N : number of storeys [-]; T1 : building's first period [s]
psi, gamma : first-mode shape Z/H and participation 3N/(2N+1) [-]
d0_star, du_star, ds_star : spectral displacement where the capacity vanishes, ultimate
    (0.4 d0*) and secant (0.4 du*) [m]; Ts : secant period [s]
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from shared_schema.errors import InputError

from ..core.model import G, check_number, check_positive
from .hazard import ElasticSpectrum

__all__ = [
    "DS_FRACTION",
    "DU_FRACTION",
    "Building",
    "VirtualWork",
    "linear_check",
    "nonlinear_check",
    "participating_mass",
]

#: Circolare 617/2009 C8A.4 (from memory): ultimate displacement du* = 0.4 d0*.
DU_FRACTION = 0.4
#: ... and the secant point ds* = 0.4 du* that defines the period Ts.
DS_FRACTION = 0.4
#: Damping term of the floor-displacement demand (Circolare 617/2009 C8A.4.10): 0.02 Ts/T1.
FLOOR_DAMPING_TERM = 0.02
#: Points of the reported capacity curve.
CURVE_POINTS = 41


@dataclass(frozen=True)
class VirtualWork:
    """Virtual-work quantities of one mechanism side at rest (theory §11.1).

    Attributes
    ----------
    alpha0 : float
        Activation multiplier [-].
    mass : float
        Mass mobilised, ``sum P_i / g`` [kg], > 0.
    S : float
        ``sum m δx`` for a unit virtual rotation [kg m], > 0.
    J : float
        ``sum m δx²`` for a unit virtual rotation [kg m²], > 0.
    """

    alpha0: float
    mass: float
    S: float
    J: float

    def __post_init__(self) -> None:
        check_number(self.alpha0, "alpha0")
        for name in ("mass", "S", "J"):
            check_positive(getattr(self, name), name)


@dataclass(frozen=True)
class Building:
    """The building a mechanism sits in, for the 2009 demand above ground (theory §11.8).

    Attributes
    ----------
    H : float
        Height of the building above the foundation [m], > 0.
    N : int
        Number of storeys, >= 1.
    T1 : float
        First period of the building [s], > 0.
    """

    H: float
    N: int
    T1: float

    def __post_init__(self) -> None:
        check_positive(self.H, "H")
        check_positive(self.T1, "T1")
        if not (isinstance(self.N, int) and self.N >= 1):
            raise InputError(f"must be an integer >= 1, got {self.N!r}", "N")


#: Why a check above ground is incomplete: the height demand needs the building.
NO_BUILDING_NOTE = (
    "the mechanism is above ground (Z > 0) but the site file gives no building "
    "(height, storeys, T1): the height demand was not evaluated"
)


def participating_mass(vw: VirtualWork) -> tuple[float, float]:
    """Participating mass ``M*`` [kg] and mass fraction ``e*`` [-] (theory §11.1).

    Notes
    -----
    Circolare 2019 [C8.7.1.5] (and the 2009 C8A.4.3-4): ``e* = (Σ P δx)²/(Σ P Σ P δx²)``,
    i.e. ``S²/(mass J)``, and ``M* = e* Σ P/g = S²/J``.

    Examples
    --------
    A rectangular block of mass 1 and height 3: ``S = 1.5``, ``J = 3``:

    >>> participating_mass(VirtualWork(0.1, 1.0, 1.5, 3.0))
    (0.75, 0.75)
    """
    m_star = vw.S * vw.S / vw.J
    return m_star, m_star / vw.mass


def _height_terms(z: float, building: Building) -> tuple[float, float]:
    if not 0.0 <= z <= building.H * (1.0 + 1e-12):
        raise InputError(
            f"the mechanism's base height Z = {z:g} m is outside the building (H = "
            f"{building.H:g} m)",
            "Z",
        )
    return z / building.H, 3.0 * building.N / (2.0 * building.N + 1.0)


def linear_check(
    vw: VirtualWork,
    spectrum: ElasticSpectrum,
    *,
    FC: float,
    q: float = 2.0,
    Z: float = 0.0,
    building: Optional[Building] = None,
) -> dict[str, Any]:
    """Linear kinematic analysis, SLV, in the 2009 forms (theory §11.8).

    Parameters
    ----------
    vw : VirtualWork
        The side's virtual-work quantities.
    spectrum : ElasticSpectrum
        The site's elastic spectrum for the limit state.
    FC : float
        Confidence factor [-], >= 1.
    q : float
        Behaviour factor [-], > 0 (the Circolare's value is 2).
    Z : float
        Height of the mechanism's base above the foundation [m], >= 0.
    building : Building, optional
        Needed when ``Z > 0``; without it the height demand is not evaluated and the record
        says so.

    Returns
    -------
    dict
        ``alpha0``, ``M_star`` [kg], ``e_star``, ``a0_star`` [m/s²], ``demand_ground``
        [m/s²], ``demand_height`` [m/s²] (or None), ``demand`` (the governing one),
        ``capacity_ratio`` (``a0_star / demand``), ``passes`` (None when a needed demand
        could not be evaluated) and ``note``.

    Notes
    -----
    ``a0* = alpha0 g / (e* FC)``; at ground ``a0* >= a_g S / q``; above ground, with
    ``psi = Z/H`` and ``gamma = 3N/(2N+1)``, also ``a0* >= S_e(T1) psi gamma / q``.
    """
    FC = check_number(FC, "FC", at_least=1.0)
    q = check_positive(q, "q")
    m_star, e_star = participating_mass(vw)
    a0_star = vw.alpha0 * G / (e_star * FC)
    demand_ground = spectrum.pga * G / q
    out: dict[str, Any] = {
        "method": "Circolare 617/2009 C8A.4: linear kinematic analysis (SLV), 2009 forms",
        "alpha0": vw.alpha0,
        "M_star": m_star,
        "e_star": e_star,
        "FC": FC,
        "q": q,
        "a0_star": a0_star,
        "Z": Z,
        "demand_ground": demand_ground,
        "demand_height": None,
        "note": "",
    }
    demand = demand_ground
    complete = True
    if Z > 0.0:
        if building is None:
            complete = False
            out["note"] = NO_BUILDING_NOTE
        else:
            psi, gamma = _height_terms(Z, building)
            se_t1 = float(spectrum.Se([building.T1])[0]) * G
            demand_height = se_t1 * psi * gamma / q
            out.update(
                {"psi": psi, "gamma": gamma, "T1": building.T1, "demand_height": demand_height}
            )
            demand = max(demand, demand_height)
    if vw.alpha0 <= 0.0:
        out["note"] = "alpha0 <= 0: the static loads alone activate the mechanism"
    out["demand"] = demand
    out["capacity_ratio"] = a0_star / demand
    out["passes"] = bool(a0_star >= demand) if complete else None
    return out


def nonlinear_check(
    vw: VirtualWork,
    phi0: float,
    spectrum: ElasticSpectrum,
    *,
    FC: float,
    Z: float = 0.0,
    building: Optional[Building] = None,
) -> dict[str, Any]:
    """Nonlinear kinematic analysis, SLV, in the 2009 forms (theory §11.8).

    Parameters
    ----------
    vw : VirtualWork
        The side's virtual-work quantities.
    phi0 : float
        Rotation at which the multiplier vanishes [rad], > 0 (``phi_ov`` of the constants).
    spectrum : ElasticSpectrum
        The site's elastic spectrum.
    FC : float
        Confidence factor [-], >= 1.
    Z : float
        Height of the mechanism's base [m], >= 0.
    building : Building, optional
        Needed when ``Z > 0``.

    Returns
    -------
    dict
        ``a0_star`` [m/s²], ``d0_star``, ``du_star``, ``ds_star`` [m], ``as_star`` [m/s²],
        ``Ts`` [s], ``demand_ground``, ``demand_height`` (or None), ``demand`` [m],
        ``capacity_ratio`` (``du_star / demand``), ``passes`` (None when a needed demand
        could not be evaluated), ``curve`` (``d_star`` [m], ``a_star`` [m/s²], ``alpha``)
        and ``note``.

    Notes
    -----
    Capacity curve of the rigid mechanism, linear between ``alpha0`` at rest and 0 at
    ``phi0``: ``alpha(phi) = alpha0 (1 - phi/phi0)``; ``d* = phi J/S`` (first-order virtual
    displacements), ``a* = alpha g / (e* FC)``. ``du* = 0.4 d0*``, ``ds* = 0.4 du*``,
    ``Ts = 2 pi sqrt(ds*/a*(ds*))``. At ground ``du* >= S_De(Ts)``; above ground also
    ``du* >= S_De(T1) psi gamma (Ts/T1)² / sqrt((1 - Ts/T1)² + 0.02 Ts/T1)``.
    """
    FC = check_number(FC, "FC", at_least=1.0)
    phi0 = check_positive(phi0, "phi0")
    _, e_star = participating_mass(vw)
    if vw.alpha0 <= 0.0:
        raise InputError(
            "alpha0 <= 0: the static loads alone activate the mechanism; there is no "
            "capacity curve",
            "alpha0",
        )
    a0_star = vw.alpha0 * G / (e_star * FC)
    d0_star = phi0 * vw.J / vw.S
    du_star = DU_FRACTION * d0_star
    ds_star = DS_FRACTION * du_star
    as_star = a0_star * (1.0 - ds_star / d0_star)
    ts = 2.0 * math.pi * math.sqrt(ds_star / as_star)
    demand_ground = float(spectrum.SDe([ts])[0])
    if not (math.isfinite(a0_star) and math.isfinite(d0_star) and ts > 0.0 and demand_ground > 0):
        # issue #25: extreme virtual-work quantities (a mass of 1e308 kg, phi0 of 1e-29 rad)
        # gave an infinite a0*, a zero secant period and demand, and a division by zero
        raise InputError(
            f"the capacity curve is out of any physical range (a0* = {a0_star:g} m/s², "
            f"d0* = {d0_star:g} m, Ts = {ts:g} s from alpha0 = {vw.alpha0:g}, e* = "
            f"{e_star:g}, J/S = {vw.J / vw.S:g} m, phi0 = {phi0:g} rad); check the side's "
            "virtual_work and phi_ov",
            "virtual_work",
        )
    d = np.linspace(0.0, d0_star, CURVE_POINTS)
    alpha = vw.alpha0 * (1.0 - d / d0_star)
    out: dict[str, Any] = {
        "method": "Circolare 617/2009 C8A.4: nonlinear kinematic analysis (SLV), 2009 forms",
        "FC": FC,
        "e_star": e_star,
        "a0_star": a0_star,
        "phi0": phi0,
        "d0_star": d0_star,
        "du_star": du_star,
        "ds_star": ds_star,
        "as_star": as_star,
        "Ts": ts,
        "Z": Z,
        "demand_ground": demand_ground,
        "demand_height": None,
        "curve": {
            "d_star": d.tolist(),
            "a_star": (alpha * G / (e_star * FC)).tolist(),
            "alpha": alpha.tolist(),
        },
        "note": "",
    }
    demand = demand_ground
    complete = True
    if Z > 0.0:
        if building is None:
            complete = False
            out["note"] = NO_BUILDING_NOTE
        else:
            psi, gamma = _height_terms(Z, building)
            r = ts / building.T1
            sde_t1 = float(spectrum.SDe([building.T1])[0])
            demand_height = (
                sde_t1 * psi * gamma * r * r / math.sqrt((1.0 - r) ** 2 + FLOOR_DAMPING_TERM * r)
            )
            out.update(
                {"psi": psi, "gamma": gamma, "T1": building.T1, "demand_height": demand_height}
            )
            demand = max(demand, demand_height)
    out["demand"] = demand
    out["capacity_ratio"] = du_star / demand
    out["passes"] = bool(du_star >= demand) if complete else None
    return out
