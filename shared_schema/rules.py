"""Domain rules and units of rockmech: one home for each, standard library only.

Every floor may import this module: the file formats beside it (``shared_schema``), the
maths (``solver_service.core``, ``cad_maths``), the workflows and the front ends. It pulls
in neither numpy nor pydantic, so Rhino 8's CPython 3.9 and the numerical core can share it.

What lives here
---------------
- ``G``: standard gravity [m/s²], the only definition in the package;
- the vocabularies other modules mirror (rocking kinds, record formats and units, scale-factor
  methods, overturning criteria, pulse shapes); the pydantic enums are built from these tuples,
  and a test fails if a copy drifts;
- the coefficient-of-restitution sign rule (docs/theory.md §1.8, §3);
- the number checks every input goes through (finite, bounds, booleans refused);
- the physical ranges of user inputs (densities, forces, strengths, coordinates, body
  sizes): a hard limit refused with the range named, and a plausible band outside which a
  warning says what was most likely meant (issue #14).
"""

import math
import numbers
import os
import re
from pathlib import Path
from typing import Dict, NamedTuple, Optional, Sequence, Tuple, Union

from shared_schema.errors import InputError
from shared_schema.paths import readable_file

__all__ = [
    "ACCEL_MAX_G",
    "ACCEL_MIN",
    "A_P_G_MAX",
    "BEHAVIOUR_FACTOR_RANGE",
    "BODY_SIZE_PLAUSIBLE",
    "BUILDING_HEIGHT_MAX_M",
    "CONNECTIONS",
    "COORDINATE_LIMIT",
    "CRITERIA",
    "DAMPING_PERCENT_RANGE",
    "DT_RANGE_S",
    "ENVELOPE_METHODS",
    "F_N_RANGE",
    "F_P_RANGE",
    "IM_MEASURES",
    "LAM_RANGE",
    "LENGTH_UNITS",
    "PEAKS_FILE",
    "PRINTABLE_PATTERN",
    "PULSE_SHAPES",
    "P_EQ_RANGE",
    "QUANTITY_RANGES",
    "RECORD_FORMATS",
    "RECORD_UNITS",
    "ROCKING_KINDS",
    "ROTATION_MAX",
    "SCHEMA_VERSION_PATTERN",
    "SEARCH_DIRECTIONS",
    "SEARCH_FAMILIES",
    "SF_METHODS",
    "G",
    "QuantityRange",
    "accel_max",
    "body_size_note",
    "check_choice",
    "check_eta",
    "check_file",
    "check_non_negative",
    "check_number",
    "check_positive",
    "check_quantity",
    "control_character",
    "coordinate_problem",
    "default_rotation_problem",
    "eta_problem",
    "eta_range",
    "printable",
    "quantity_note",
    "quantity_problem",
    "range_problem",
    "rotation_problem",
    "schema_version_problem",
]

#: Standard gravity [m/s²].
G = 9.80665

#: Mechanism families ``rockmech search`` enumerates (issue #31): overturning of a whole
#: façade, of its part above a hinge line, with wedges of its return walls, vertical
#: flexure between restraints (two-block), the corner wedge, and the part above the top
#: level (a gable, or a parapet).
SEARCH_FAMILIES: Tuple[str, ...] = (
    "overturning",
    "partial_overturning",
    "wedge_overturning",
    "vertical_flexure",
    "corner",
    "gable",
    "parapet",
)

#: Out-of-plane directions of a façade the search tries: away from the building or into it.
SEARCH_DIRECTIONS: Tuple[str, ...] = ("outward", "inward")

#: Connection quality of a wall junction: good interlocking (a crack through the return
#: wall runs at least at the bond angle), poor (the walls part along the junction), or tied
#: (ties or a ring beam hold them together: the façade does not part from that wall).
CONNECTIONS: Tuple[str, ...] = ("good", "poor", "tied")

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

#: Length units of a scan mesh (``cad_maths.scene_mesh.UNITS``; a .3dm states its own).
LENGTH_UNITS: Tuple[str, ...] = ("mm", "cm", "m", "in", "ft")

#: Scale-factor methods of time histories up the structure: none, Eq. 28 from the record's
#: spectrum, or the EN 1998-1 and NZS 1170.5 code factors (docs/theory.md §7.3-7.4).
SF_METHODS: Tuple[str, ...] = ("none", "eq28", "ec8", "nzs")

#: Overturning verdicts: ``ratio`` (|phi|/phi_ov >= 1, the method's) or ``exact`` (cannot return).
CRITERIA: Tuple[str, ...] = ("ratio", "exact")

#: One-cycle acceleration pulse shapes.
PULSE_SHAPES: Tuple[str, ...] = ("sine", "cosine")

#: How overturning envelopes are computed: ``exact`` (the exact integrator at every
#: frequency, the default) or ``library`` (the fast mode: the interpolated library, exact
#: where it cannot interpolate safely; docs/envelopes.md).
ENVELOPE_METHODS: Tuple[str, ...] = ("exact", "library")

#: Intensity measures of an incremental dynamic analysis, with their units: ``scale`` (the
#: factor on each record) or ``pga`` (the record's peak ground acceleration, in g).
IM_MEASURES: Dict[str, str] = {"scale": "-", "pga": "g"}
#: Name of the per-run peaks file ``rockmech ida --peaks`` writes into ``--out`` (Parquet).
PEAKS_FILE = "ida_peaks.parquet"

# Plausible ranges of the numbers a pulse request gives directly (the REST service's
# ``/pulse``; its OpenAPI schema states them). Each bound lies far past any masonry body and
# any ground-motion pulse, so no real case is refused; inside them the closed forms stay
# far from overflow and a pulse takes at most ``P_EQ_RANGE[1] / F_P_RANGE[0]`` = 1e6
# closed-form steps, within the service's work bound at its default settings
# (``20 x ROCKMECH_MAX_SAMPLES`` = 1e7; a test checks).

#: Frequency parameter ``p_eq`` [rad/s]: a block of half-diagonal ``R = 3 g / (4 p²)`` from
#: 74 km down to 7 µm (the top is ``core.exact.P_EQ_PLAUSIBLE``; a test checks the copy).
P_EQ_RANGE: Tuple[float, float] = (1e-2, 1e3)
#: Natural frequency ``f_n`` [Hz] of a structure whose spectrum a record gives (Eq. 28 from a
#: record): periods of 1000 s down to 1 ms, far past the tallest building (about 10 s) and
#: the stiffest wall; below 5.6e-309 Hz, ``T_n = 1/f_n`` would overflow.
F_N_RANGE: Tuple[float, float] = (1e-3, 1e3)
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
#: Tallest structure [m] a height may describe: above the tallest building (828 m), so a
#: larger value is a slip of units or digits, never a building.
BUILDING_HEIGHT_MAX_M = 1000.0
#: Time step [s] outside which a record is refused: no accelerograph samples faster than
#: 1 MHz or slower than once a second (issue #14: a dt of 1e300 s overflows the spectrum).
DT_RANGE_S: Tuple[float, float] = (1e-6, 1.0)
#: Largest acceleration [g] a record may hold: 200 times the strongest ground motion
#: recorded (about 5 g); beyond it the numbers are wrong units, not an earthquake.
ACCEL_MAX_G = 1e3

# Ranges of the site file's check parameters (``shared_schema.site``; the REST service's
# ``/check`` and ``/assess`` take the same model, so both front ends share them; issue #25).

#: Behaviour factor ``q`` [-] of the code's linear kinematic check (docs/theory.md §11.2,
#: demand ``a_g S / q``; the Circolare takes q = 2). Below 1 the demand would exceed the
#: elastic spectrum (q = 0.5 quadruples the demand of q = 2), which no code allows; 10 is
#: far above any behaviour factor of masonry.
BEHAVIOUR_FACTOR_RANGE: Tuple[float, float] = (1.0, 10.0)
#: Viscous damping ``xi_percent`` [%] of the site's elastic spectrum (docs/theory.md §11.4,
#: ``eta = sqrt(10/(5 + xi))``), in percent: 5 means 5 %. No masonry building damps less
#: than 1 % (cracked masonry: 3-10 %), and every damping written as a fraction (0.05 for
#: 5 %) falls below 1, where it would read as 0.05 % (eta = 1.41, a demand 41 % too high):
#: refused, not warned. Above 50 % the codes' correction has long reached its floor 0.55.
DAMPING_PERCENT_RANGE: Tuple[float, float] = (1.0, 50.0)
#: Largest rotation [rad] of a rocking body: a block rotated by pi/2 lies on its side, so
#: an overturning or critical rotation (``phi_ov``, ``phi_cr``) above it is no rocking
#: angle; degrees written as radians (a wall's 5-30 deg) all fall above it.
ROTATION_MAX = math.pi / 2
#: Text without control characters (``control_character``), as a JSON Schema pattern.
PRINTABLE_PATTERN = "^[^\\u0000-\\u001f\\u007f-\\u009f\\u2028\\u2029]*$"
# The same characters, for Python.
_CONTROL = re.compile("[\u0000-\u001f\u007f-\u009f\u2028\u2029]")
#: Format versions of the constants and site files this version reads: ``1.<minor>``.
SCHEMA_VERSION_PATTERN = r"^1\.[0-9]+$"


def range_problem(
    value: float, bounds: Tuple[float, float], unit: str = "", why: str = ""
) -> Optional[str]:
    """Return why a finite ``value`` is outside the closed range ``bounds``, or None.

    Parameters
    ----------
    value : float
        The value, finite.
    bounds : (float, float)
        Lowest and highest admissible value.
    unit : str
        Unit for the message (``"%"``); none for a pure number.
    why : str
        What the range means, appended to the message.

    Examples
    --------
    >>> range_problem(0.5, BEHAVIOUR_FACTOR_RANGE)
    'must be in [1, 10], got 0.5'
    >>> range_problem(2.0, BEHAVIOUR_FACTOR_RANGE) is None
    True
    """
    lo, hi = bounds
    if lo <= value <= hi:
        return None
    u = f" {unit}" if unit else ""
    return f"must be in [{lo:g}, {hi:g}]{u}, got {value!r}" + (f": {why}" if why else "")


def rotation_problem(value: float) -> Optional[str]:
    """Return why a rotation [rad] is above ``ROTATION_MAX``, naming the unit, or None.

    Examples
    --------
    >>> rotation_problem(5.0)[-54:]
    'the value is in radians: if it is 5 deg, write 0.08727'
    >>> rotation_problem(0.2) is None
    True
    """
    if value <= ROTATION_MAX:
        return None
    return (
        f"must be at most pi/2 = {ROTATION_MAX:.5g} rad (a rocking body on its side), got "
        f"{value:g} rad = {math.degrees(value):.4g} deg; the value is in radians: if it is "
        f"{value:g} deg, write {math.radians(value):.4g}"
    )


def default_rotation_problem(lam: float) -> Optional[str]:
    """Return why ``lam`` cannot stand for a missing ``phi_ov`` (above ``ROTATION_MAX``), or None.

    ``phi_ov`` defaults to ``lam``, exact for a single block, whose ``lam`` is its angle
    ``alpha < pi/2``; a larger ``lam`` would be taken as a rotation past the block on its side.

    Examples
    --------
    >>> default_rotation_problem(5.0)[-31:]
    'give phi_ov [rad] for this side'
    >>> default_rotation_problem(0.2) is None
    True
    """
    if lam <= ROTATION_MAX:
        return None
    return (
        f"phi_ov defaults to lam (exact for a single block, whose lam is its angle alpha < "
        f"pi/2), and lam = {lam!r} is above pi/2 = {ROTATION_MAX:.5g} rad: give phi_ov [rad] "
        "for this side"
    )


def schema_version_problem(value: str) -> Optional[str]:
    """Return why a file's ``schema_version`` is not one this version reads, or None.

    Examples
    --------
    >>> schema_version_problem("v1")
    "must look like 1.0 (format 1.<minor>; this rockmech reads 1.x files), got 'v1'"
    >>> schema_version_problem("1.3") is None
    True
    """
    if re.match(SCHEMA_VERSION_PATTERN, value):
        return None
    newer = re.match(r"^([0-9]+)\.[0-9]+$", value)
    hint = "; a newer format: update rockmech" if newer and int(newer.group(1)) > 1 else ""
    return (
        f"must look like 1.0 (format 1.<minor>; this rockmech reads 1.x files), got {value!r}{hint}"
    )


def control_character(text: str) -> Optional[str]:
    r"""Return the first control character of ``text`` as Python writes it, or None.

    Line breaks, tabs, escape sequences and the other control characters (C0, DEL, C1 and
    the Unicode line and paragraph separators) in a name would break a terminal table or
    send codes to the terminal; names must be printable (``PRINTABLE_PATTERN``).

    Examples
    --------
    >>> control_character("W1\nW2")
    "'\\n'"
    >>> control_character("façade W1") is None
    True
    """
    for ch in text:
        if _CONTROL.match(ch):
            return repr(ch)
    return None


def printable(text: str) -> str:
    r"""Return ``text`` with each control character written as its Python escape.

    For names printed on a terminal (tables, progress lines): nothing a file or a file name
    holds can break a line or send codes to the terminal.

    Examples
    --------
    >>> print(printable("W1\n\x1b[31mW2"))
    W1\n\x1b[31mW2
    """
    return _CONTROL.sub(lambda m: repr(m.group())[1:-1], text)


def accel_max(units: str) -> float:
    """Return the largest sample magnitude a record may hold, in ``units`` (``ACCEL_MAX_G``).

    The readers compare each sample with this value in the record's own units, so that a
    huge sample cannot overflow on the way to m/s²; the REST schema states the same value.

    Examples
    --------
    >>> accel_max("mg")
    1000000.0
    """
    return ACCEL_MAX_G * G / RECORD_UNITS[units]


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

    ``shared_schema.paths.readable_file``: a ``str`` or ``os.PathLike``; a folder is reported
    as a folder, not as a missing file, and anything but a path as the type it is.
    """
    return readable_file(path, label)


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


# ---------------------------------------------------------------- physical ranges (#14)


class QuantityRange(NamedTuple):
    """The admissible and the plausible range of one kind of physical input.

    Attributes
    ----------
    unit : str
        SI unit the values are in, for messages (``"kg/m^3"``).
    limit : float
        Largest admissible value; above it the input is refused (> 0 always required).
    low, high : float
        Plausible band; outside it (but admissible) the input gets a warning.
    hint : str
        What a value outside the band most likely means, for the warning.
    """

    unit: str
    limit: float
    low: float
    high: float
    hint: str


#: Ranges of the physical inputs of a mechanism spec, by kind. Every spec field of that kind
#: goes through ``check_quantity`` (refused beyond ``limit``) and ``quantity_note`` (a warning
#: outside the band), so the CLI, the REST service and the Rhino flows answer alike.
QUANTITY_RANGES: Dict[str, QuantityRange] = {
    # Densities: timber floors (~350) to bronze and steel (~8500); the densest element,
    # osmium, is 22,590 kg/m^3, so anything above 30,000 is no material at all.
    "density": QuantityRange(
        "kg/m^3",
        30000.0,
        300.0,
        9000.0,
        "masonry is 1500-2800 kg/m^3; a value near 2 is likely in t/m^3 or g/cm^3, one "
        "near 18,000 a unit weight in N/m^3",
    ),
    # Forces on one wall: a tie-bar carries at most a few hundred kN and the overburden of a
    # wall is its share of the floors above; 10 MN is already 1000 t on one element, 1 GN is
    # beyond the weight of any masonry building.
    "force": QuantityRange(
        "N",
        1e9,
        0.0,
        1e7,
        "a tie-bar carries at most a few hundred kN; check that the value is in N, not in "
        "mN or kgf",
    ),
    # Mortar tensile strength: lime mortar 0.05-0.5 MPa, cement mortar up to about 2 MPa;
    # above 100 MPa no mortar (nor concrete) exists.
    "tensile_strength": QuantityRange(
        "Pa",
        1e8,
        0.0,
        2e6,
        "mortar tensile strength is 0.05-2 MPa; check that the value is in Pa, not in kPa or MPa",
    ),
}

#: Largest magnitude of a coordinate, in the unit it is written in (a scene file's model
#: units, a spec's ``units``); beyond it the point is refused before any geometry is done,
#: so that overflow cannot reach the maths (1e6 m is a thousand kilometres).
COORDINATE_LIMIT = 1e6

#: Plausible size (bounding-box diagonal) of one rocking body [m]: from a 1 cm fragment to a
#: 200 m tower. Outside it, the scene was most likely read in the wrong length unit.
BODY_SIZE_PLAUSIBLE: Tuple[float, float] = (0.01, 200.0)

#: Metres per length unit, for suggesting the unit a scene was meant to be read in.
_METRES_PER_UNIT: Dict[str, float] = {
    "mm": 0.001,
    "cm": 0.01,
    "m": 1.0,
    "in": 0.0254,
    "ft": 0.3048,
}


def quantity_problem(value: object, kind: str) -> Optional[str]:
    """Return why a value of ``kind`` (a key of ``QUANTITY_RANGES``) is refused, or None.

    The value must be a finite number, > 0 and at most the kind's ``limit``.

    Examples
    --------
    >>> quantity_problem(1e300, "force")
    'must be at most 1e+09 N (the admissible range is (0, 1e+09] N), got 1e+300'
    >>> quantity_problem(2e4, "force") is None
    True
    """
    r = QUANTITY_RANGES[kind]
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return f"must be a number [{r.unit}], got {value!r}"
    v = float(value)
    if not math.isfinite(v):
        return f"must be finite [{r.unit}], got {value!r}"
    if not v > 0.0:
        return f"must be > 0 [{r.unit}], got {value!r}"
    if v > r.limit:
        return (
            f"must be at most {r.limit:g} {r.unit} (the admissible range is (0, {r.limit:g}] "
            f"{r.unit}), got {value!r}"
        )
    return None


def check_quantity(value: object, kind: str, name: str) -> float:
    """Return ``value`` as a float if admissible for ``kind``; else raise ``InputError``.

    Examples
    --------
    >>> check_quantity(1800, "density", "density")
    1800.0
    """
    problem = quantity_problem(value, kind)
    if problem is not None:
        raise InputError(problem, name)
    return check_number(value, name)


def quantity_note(value: float, kind: str, name: str) -> Optional[str]:
    """Return a warning for a value of ``kind`` outside its plausible band, or None.

    Examples
    --------
    >>> quantity_note(1.8, "density", "groups[0].density")[:60]
    'groups[0].density = 1.8 kg/m^3 is outside the plausible rang'
    """
    r = QUANTITY_RANGES[kind]
    if r.low <= value <= r.high:
        return None
    band = f"[{r.low:g}, {r.high:g}]" if r.low > 0.0 else f"up to {r.high:g}"
    return f"{name} = {value:g} {r.unit} is outside the plausible range {band} {r.unit}: {r.hint}"


def coordinate_problem(values: Sequence[float], unit: str = "m") -> Optional[str]:
    """Return why a point's coordinates are refused (non-finite, or beyond the limit), or None.

    Parameters
    ----------
    values : sequence of float
        The coordinates, in the unit they were written in.
    unit : str
        That unit, for the message.

    Examples
    --------
    >>> print(coordinate_problem([0.0, 1e300, 0.0]).split("; ")[0])
    coordinate 1e+300 is beyond the largest magnitude accepted, 1e+06 m
    """
    for v in values:
        if not math.isfinite(v):
            return f"coordinates must be finite, got {v!r}"
    for v in values:
        if abs(v) > COORDINATE_LIMIT:
            return (
                f"coordinate {v:g} is beyond the largest magnitude accepted, "
                f"{COORDINATE_LIMIT:g} {unit}; check the units, or for georeferenced points "
                "(UTM, a national grid) use the local origin the scene was moved to"
            )
    return None


def body_size_note(
    size_m: float, unit_scale: float, units: str, what: str, scan: bool
) -> Optional[str]:
    """Return a warning for a body of implausible size, naming the unit it was read in.

    Parameters
    ----------
    size_m : float
        Diagonal of the body's bounding box [m].
    unit_scale : float
        Metres per unit of the file [m/unit].
    units : str
        Name of that unit (``"millimeters"``), for the message.
    what : str
        What the body is, for the message (the mechanism's id).
    scan : bool
        A scan mesh (its unit is given with ``units``/``--units``) rather than a ``.3dm``
        file (whose model units are set in Rhino).

    Examples
    --------
    >>> print(body_size_note(3041.4, 1.0, "meters", "W", scan=True).split(": ")[-1])
    if the file is in mm, give units mm (--units mm)
    >>> body_size_note(3.04, 1.0, "meters", "W", scan=True) is None
    True
    """
    lo, hi = BODY_SIZE_PLAUSIBLE
    if lo <= size_m <= hi:
        return None
    in_file = size_m / unit_scale  # the size as the file's numbers give it
    # The unit in which the file's numbers give the most ordinary size (about 5 m).
    fits = sorted(
        (abs(math.log10(in_file * m / 5.0)), u)
        for u, m in _METRES_PER_UNIT.items()
        if lo <= in_file * m <= hi
    )
    if fits:
        u = fits[0][1]
        how = f"give units {u} (--units {u})" if scan else f"set its model units to {u} in Rhino"
        advice = f"if the file is in {u}, {how}"
    else:
        advice = "check the file's length unit"
    return (
        f"{what}: the body is {size_m:.4g} m across as read in {units}, but a rocking body is "
        f"between {lo:g} and {hi:g} m: {advice}"
    )
