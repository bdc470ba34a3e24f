"""Domain rules and units of rockmech: one home for each, standard library only.

Every floor may import this module: the file formats beside it (``shared_schema``), the
maths (``solver_service.core``, ``rhino_plugin``), the workflows and the front ends. It pulls
in neither numpy nor pydantic, so Rhino 8's CPython 3.9 and the numerical core can share it.

What lives here
---------------
- ``G``: standard gravity [m/s²], the only definition in the package;
- the vocabularies other modules mirror (rocking kinds, record formats and units, scale-factor
  methods, overturning criteria, pulse shapes); the pydantic enums are built from these tuples,
  and a test fails if a copy drifts;
- the coefficient-of-restitution sign rule (docs/theory.md §1.8, §3);
- the number checks every input goes through (finite, bounds, booleans refused).
"""

import math
import numbers
import os
from pathlib import Path
from typing import Dict, Optional, Tuple, Union

from shared_schema.errors import InputError

__all__ = [
    "ACCEL_MIN",
    "A_P_G_MAX",
    "CRITERIA",
    "F_P_RANGE",
    "LAM_RANGE",
    "LENGTH_UNITS",
    "PULSE_SHAPES",
    "P_EQ_RANGE",
    "RECORD_FORMATS",
    "RECORD_UNITS",
    "ROCKING_KINDS",
    "SF_METHODS",
    "TYPOLOGIES",
    "G",
    "check_choice",
    "check_eta",
    "check_file",
    "check_non_negative",
    "check_number",
    "check_positive",
    "eta_problem",
    "eta_range",
]

#: Standard gravity [m/s²].
G = 9.80665

#: Mechanism typologies a spec can ask for; each has a builder in
#: ``rhino_plugin.mechanisms.build.MECHANISMS`` (constants files also take ``user_defined``).
TYPOLOGIES: Tuple[str, ...] = ("single_block", "single_block_loaded", "two_block", "multi_block")

#: Rocking kinds: two-sided (rocks about both edges) or one-sided (rebounds off a restraint).
ROCKING_KINDS: Tuple[str, ...] = ("two_sided", "one_sided")

#: Ground-motion file formats the readers take (``solver_service.core.records``): PEER AT2,
#: plain columns and CSV, then the strong-motion databases' own (``solver_service.core.formats``):
#: ESM/ITACA ASCII, NIED K-NET/KiK-net, COSMOS V2, CSMIP/DMG V2 and GeoNet V2A.
RECORD_FORMATS: Tuple[str, ...] = (
    "at2",
    "two_column",
    "one_column",
    "csv",
    "esm",
    "knet",
    "cosmos",
    "dmg",
    "geonet",
)

#: Acceleration units of records, with the factor that turns each into m/s² (cm/s² is the
#: gal; mg is a thousandth of g; in/s² is the inch per second squared of COSMOS files).
RECORD_UNITS: Dict[str, float] = {
    "g": G,
    "m/s2": 1.0,
    "cm/s2": 0.01,
    "mm/s2": 0.001,
    "mg": G / 1000.0,
    "in/s2": 0.0254,
}

#: Length units of a scan mesh (``rhino_plugin.scene_mesh.UNITS``; a .3dm states its own).
LENGTH_UNITS: Tuple[str, ...] = ("mm", "cm", "m", "in", "ft")

#: Scale-factor methods of time histories up the structure: none, Eq. 28 from the record's
#: spectrum, or the EN 1998-1 and NZS 1170.5 code factors (docs/theory.md §7.3-7.4).
SF_METHODS: Tuple[str, ...] = ("none", "eq28", "ec8", "nzs")

#: Overturning verdicts: ``ratio`` (|phi|/phi_ov >= 1, the method's) or ``exact`` (cannot return).
CRITERIA: Tuple[str, ...] = ("ratio", "exact")

#: One-cycle acceleration pulse shapes.
PULSE_SHAPES: Tuple[str, ...] = ("sine", "cosine")

# Plausible ranges of the numbers a pulse request gives directly (the REST service's
# ``/pulse``; its OpenAPI schema states them). Each bound lies far past any masonry body and
# any ground-motion pulse, so no real case is refused; inside them the closed forms stay
# far from overflow and a pulse takes at most ``P_EQ_RANGE[1] / F_P_RANGE[0]`` = 1e6
# closed-form steps, within the service's work bound at its default settings
# (``20 x ROCKMECH_MAX_SAMPLES`` = 1e7; a test checks).

#: Frequency parameter ``p_eq`` [rad/s]: a block of half-diagonal ``R = 3 g / (4 p²)`` from
#: 74 km down to 7 µm (the top is ``core.exact.P_EQ_PLAUSIBLE``; a test checks the copy).
P_EQ_RANGE: Tuple[float, float] = (1e-2, 1e3)
#: Static load multiplier ``lam`` [-]: a block's slenderness ``b/h`` from 1/1000 to 100.
LAM_RANGE: Tuple[float, float] = (1e-3, 1e2)
#: Pulse frequency ``f_p`` [Hz]: pulses of 1000 s down to 1 ms.
F_P_RANGE: Tuple[float, float] = (1e-3, 1e3)
#: Largest pulse amplitude ``|a_p_g|`` [g]; with ``LAM_RANGE`` the ratio to the uplift
#: acceleration stays below ``core.exact.MAX_AMPLITUDE_RATIO``.
A_P_G_MAX = 1e2
#: A record used for Eq. 28 needs a peak ground acceleration: one sample at least this large
#: in magnitude [in the record's units] (smaller ones could round to zero when converted).
ACCEL_MIN = 1e-300


def check_number(
    value: object,
    name: str,
    *,
    above: Optional[float] = None,
    at_least: Optional[float] = None,
    at_most: Optional[float] = None,
) -> float:
    """Return ``value`` as a float, or raise ``InputError`` naming ``name``.

    Parameters
    ----------
    value : object
        Any real number (Python or numpy); booleans and non-finite values are refused.
    name : str
        Field path for the message, e.g. ``"eta"`` or ``"mechanisms[1].p_eq"``.
    above, at_least, at_most : float, optional
        Bounds: ``value > above``, ``value >= at_least``, ``value <= at_most``.

    Examples
    --------
    >>> check_number(2, "n", at_least=1)
    2.0
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(f"must be a number, got {value!r}", name)
    v = float(value)
    if not math.isfinite(v):
        raise InputError(f"must be finite, got {value!r}", name)
    if above is not None and not v > above:
        raise InputError(f"must be finite and > {above:g}, got {value!r}", name)
    if at_least is not None and v < at_least:
        raise InputError(f"must be >= {at_least:g}, got {value!r}", name)
    if at_most is not None and v > at_most:
        raise InputError(f"must be <= {at_most:g}, got {value!r}", name)
    return v


def check_positive(value: object, name: str) -> float:
    """Return ``value`` as a float; raise ``InputError`` naming ``name`` unless finite and > 0."""
    return check_number(value, name, above=0.0)


def check_non_negative(value: object, name: str) -> float:
    """Return ``value`` as a float; raise ``InputError`` naming ``name`` unless finite and >= 0."""
    return check_number(value, name, at_least=0.0)


def check_file(path: Union[str, "os.PathLike[str]"], label: str) -> Path:
    """Return ``path`` as a Path if it names a readable file; raise ``InputError`` naming ``label``.

    A folder is reported as a folder, not as a missing file.
    """
    p = Path(path)
    if p.is_dir():
        raise InputError(f"is a folder, not a file: {p}", label)
    if not p.is_file():
        raise InputError(f"file not found: {p}", label)
    return p


def check_choice(value: object, choices: Tuple[str, ...], name: str) -> str:
    """Return ``value`` if it is one of ``choices``; raise ``InputError`` naming ``name``."""
    if not isinstance(value, str) or value not in choices:
        raise InputError(f"must be one of {list(choices)}, got {value!r}", name)
    return value


def eta_range(one_sided: bool) -> Tuple[float, float]:
    """Admissible coefficients of restitution: [0, 1] two-sided, [-1, 0] one-sided (rebound)."""
    return (-1.0, 0.0) if one_sided else (0.0, 1.0)


def eta_problem(eta: float, one_sided: bool) -> Optional[str]:
    """Return what is wrong with a finite ``eta`` for the rocking kind, or None if admissible.

    Two-sided rocking keeps the sense of rotation at impact, ``0 <= eta <= 1``; one-sided
    rocking rebounds off the restraint, which reverses it, ``-1 <= eta <= 0`` (docs/theory.md
    §1.8 and §3).
    """
    if not -1.0 <= eta <= 1.0:
        return f"must be in [-1, 1], got {eta!r}"
    if one_sided and eta > 0.0:
        return f"must be <= 0 for one-sided rocking (rebound off the restraint), got {eta}"
    if not one_sided and eta < 0.0:
        return (
            "must be >= 0 for two-sided rocking (a negative value means rebound, which is "
            f"one-sided), got {eta}"
        )
    return None


def check_eta(value: object, one_sided: bool, name: str = "eta") -> float:
    """Return a coefficient of restitution as a float, checked against the rocking kind."""
    eta = check_number(value, name)
    problem = eta_problem(eta, one_sided)
    if problem is not None:
        raise InputError(problem, name)
    return eta
