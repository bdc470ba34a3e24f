"""Code and paper scale factors for the acceleration at a height in a structure (theory §7.3–7.4).

Each function returns a record of the value, the method, the formula and the inputs, so a
report can show how the factor was obtained::

    {"value": float, "method": str, "formula": str, "inputs": {...}}

Notation
--------
S_a, a_g : spectral (pseudo-)acceleration and peak ground acceleration [g]
h, h_e : height of the mechanism and effective (modal) height of the structure [m]
z, H : height of the element and of the building above the foundation [m] (EN 1998-1)
T_a, T_1 : fundamental periods of the element and of the building [s]
S : soil factor [-]
h_i, h_n : height of level i and of the top of the structure [m] (NZS 1170.5)
"""

from __future__ import annotations

from typing import Any

from shared_schema.errors import InputError
from shared_schema.rules import BUILDING_HEIGHT_MAX_M

from ..core.amplification import scale_factor
from ..core.model import check_non_negative, check_positive

__all__ = ["BUILDING_HEIGHT_MAX_M", "check_height", "sf_ec8", "sf_eq28", "sf_nzs"]


#: NZS 1170.5 §8.3: height [m] below which ``C_Hi = 1 + h_i/6`` applies.
NZS_LOW_HEIGHT = 12.0
#: NZS 1170.5 §8.3: fraction of ``h_n`` below which ``C_Hi = 1 + 10 h_i/h_n`` applies.
NZS_LOW_FRACTION = 0.2
#: NZS 1170.5 §8.3: the general value of ``C_Hi``.
NZS_CAP = 3.0


def check_height(value: object, name: str, *, positive: bool = True) -> float:
    """Return a height [m] as a float: finite, > 0 (>= 0 if not ``positive``), at most 1000 m.

    Raises
    ------
    InputError
        Naming ``name``: not finite, not > 0 (>= 0), or above ``BUILDING_HEIGHT_MAX_M``.

    Examples
    --------
    >>> check_height(12.5, "H")
    12.5
    """
    h = check_positive(value, name) if positive else check_non_negative(value, name)
    if h > BUILDING_HEIGHT_MAX_M:
        raise InputError(
            f"must be at most {BUILDING_HEIGHT_MAX_M:g} m (taller than any building), got {h:g} m",
            name,
        )
    return h


def _within(low: float, low_name: str, top: float, top_name: str) -> None:
    """Refuse a height ``low`` above the top of the structure ``top`` (both [m])."""
    if low > top:
        raise InputError(
            f"must be at most {top_name} = {top:g} m (the height of the structure), "
            f"got {low_name} = {low:g} m",
            low_name,
        )


def sf_eq28(sa_g: float, pga_g: float, h: float, h_e: float) -> dict[str, Any]:
    """Scale factor of the paper's Eq. 28 (square-root-sum-of-squares).

    Parameters
    ----------
    sa_g : float
        Spectral acceleration ``S_a(T_n)`` [g], >= 0.
    pga_g : float
        Peak ground acceleration ``a_g`` [g], > 0.
    h : float
        Height of the mechanism [m], >= 0.
    h_e : float
        Effective height of the structure [m], > 0.

    Returns
    -------
    dict
        ``value`` is ``SF = a_sc / a_g`` [-].

    Notes
    -----
    theory Eq. 28: ``SF = sqrt(1 + (S_a/a_g · h/h_e)**2)`` (``amplification.scale_factor``).

    Examples
    --------
    >>> round(sf_eq28(0.19, 0.155, 4.60, 4.54)["value"], 3)
    1.595
    """
    inputs = {
        "sa_g": check_non_negative(sa_g, "sa_g"),
        "pga_g": check_positive(pga_g, "pga_g"),
        "h": check_height(h, "h", positive=False),
        "h_e": check_height(h_e, "h_e"),
    }
    return {
        "value": scale_factor(**inputs),
        "method": "Eq. 28 (SRSS of ground and modal response, theory §7.3)",
        "formula": "sqrt(1 + (S_a/a_g * h/h_e)^2)",
        "inputs": inputs,
    }


def sf_ec8(z: float, H: float, T_a: float, T_1: float, S: float = 1.0) -> dict[str, Any]:
    """Amplification of EN 1998-1 §4.3.5.2 for a non-structural element at height ``z``.

    Parameters
    ----------
    z : float
        Height of the element above the foundation [m], ``0 <= z <= H``.
    H : float
        Height of the building [m], > 0 and at most ``BUILDING_HEIGHT_MAX_M``.
    T_a : float
        Fundamental period of the element [s], >= 0 (0: rigid).
    T_1 : float
        Fundamental period of the building [s], > 0.
    S : float, optional
        Soil factor [-], > 0. Default 1 (the bare bracket).

    Returns
    -------
    dict
        ``value`` is ``S · max(1, bracket)`` with
        ``bracket = 3(1 + z/H)/(1 + (1 - T_a/T_1)**2) - 0.5``: the element acceleration
        divided by the design ground acceleration on rock, ``alpha g`` (``alpha`` cancels).
        With ``S = 1`` it is the bracket, the amplification relative to the ground.

    Notes
    -----
    theory §7.4: ``S_a = alpha S [3(1 + z/H)/(1 + (1 - T_a/T_1)**2) - 0.5] >= alpha S``. The
    floor means the element is never taken to accelerate less than the ground, i.e. the
    bracket is at least 1. Top of the building, rigid element: 2.5; with ``S = 1.15``: 2.875;
    with ``S = 1``, ``T_a/T_1 = 0.125``: 2.90.

    Examples
    --------
    >>> sf_ec8(10.0, 10.0, 0.0, 0.5)["value"]
    2.5
    """
    zz = check_non_negative(z, "z")
    hh = check_height(H, "H")
    _within(zz, "z", hh, "H")
    ta = check_non_negative(T_a, "T_a")
    t1 = check_positive(T_1, "T_1")
    s = check_positive(S, "S")
    gap = 1.0 - ta / t1
    bracket = 3.0 * (1.0 + zz / hh) / (1.0 + gap * gap) - 0.5  # gap * gap: inf, never OverflowError
    return {
        "value": s * max(1.0, bracket),
        "method": "EN 1998-1 §4.3.5.2 (non-structural elements)",
        "formula": "S * max(1, 3(1 + z/H)/(1 + (1 - T_a/T_1)^2) - 0.5)",
        "inputs": {"z": zz, "H": hh, "T_a": ta, "T_1": t1, "S": s, "bracket": bracket},
    }


def sf_nzs(h_i: float, h_n: float) -> dict[str, Any]:
    """Floor height coefficient ``C_Hi`` of NZS 1170.5 §8.3.

    Parameters
    ----------
    h_i : float
        Height of the level (the mechanism) above the base [m], ``0 <= h_i <= h_n``.
    h_n : float
        Height of the top of the structure [m], > 0 and at most ``BUILDING_HEIGHT_MAX_M``.

    Returns
    -------
    dict
        ``value`` is ``C_Hi`` [-], the floor acceleration divided by the ground's.

    Notes
    -----
    theory §7.4 (quoted from memory there): ``1 + h_i/6`` applies for ``h_i < 12 m``,
    ``1 + 10 h_i/h_n`` for ``h_i < 0.2 h_n``, and ``3.0`` always; the result is the lesser of
    the applicable values. Read this way ``C_Hi <= 3`` everywhere and ``C_Hi = 3`` where
    neither condition holds. Basantapur: ``1 + 4.6/6 = 1.77``.

    Examples
    --------
    >>> round(sf_nzs(4.6, 4.6)["value"], 2)
    1.77
    """
    hi = check_non_negative(h_i, "h_i")
    hn = check_height(h_n, "h_n")
    _within(hi, "h_i", hn, "h_n")
    candidates = {"3.0": NZS_CAP}
    if hi < NZS_LOW_HEIGHT:
        candidates["1 + h_i/6"] = 1.0 + hi / 6.0
    if hi < NZS_LOW_FRACTION * hn:
        candidates["1 + 10 h_i/h_n"] = 1.0 + 10.0 * hi / hn
    governing = min(candidates, key=lambda k: candidates[k])
    return {
        "value": candidates[governing],
        "method": "NZS 1170.5 §8.3 floor height coefficient C_Hi",
        "formula": f"C_Hi = {governing} (lesser of the applicable: {', '.join(candidates)})",
        "inputs": {"h_i": hi, "h_n": hn},
    }
