"""The kinematic-constants file: the constants of each rocking mechanism of a structure.

The file is what the Rhino side writes and the solver reads (CONTRIBUTING.md, "The house").
It holds,
per mechanism, the constants of the linearised rocking equation (docs/theory.md §1) for the
positive side and, when the mechanism is not symmetric, the negative side.

Notation
--------
I0 : generalised inertia of the mechanism at ``phi_cr`` [kg m^2]
K : rotational stiffness of the linearised system (acts as a negative stiffness) [N m/rad]
Q : ground-motion coefficient [kg m]
phi_cr : critical rotation, the unstable equilibrium under gravity alone [rad]
M_F : moment of the external static forces about the side's hinge(s), signed in the
    mechanism's positive sense on *both* sides: positive when it drives positive rotation
    [N m]. On the negative side a moment that drives that side towards collapse is
    therefore negative (theory §1.8)
p_eq : equivalent frequency parameter, ``sqrt(K / I0)`` (Eq. 4) [rad/s]
lam : linearised static load multiplier (Eq. 5; §1.8 for the negative side) [-]
phi_ov : overturning rotation (Eq. 6; §1.8 for the negative side) [rad]
eta : coefficient of restitution on the angular velocity at impact [-]
eta_to_negative, eta_to_positive : restitution at an impact after which the mechanism rocks
    on its negative (positive) side, for asymmetric two-sided mechanisms whose two impact
    directions differ [-]
f_n : natural frequency of the supporting structure [Hz]
h_e : effective (modal) height of the supporting structure [m]
h : height of the mechanism's base above the ground [m]

Sign conventions per side. ``I0``, ``K``, ``Q``, ``phi_cr``, ``p_eq``, ``lam`` and
``phi_ov`` are magnitudes (> 0) on both sides, each measured for the motion of that side
(``phi_cr`` and ``phi_ov`` are the sizes of the negative rotations on the negative side).
``M_F`` alone keeps a global sign, positive when it drives positive rotation, so that one
force can be written with the same sign on both sides; ``s = +1`` on the positive side and
``-1`` on the negative side turns it into the side's own driving moment ``s * M_F`` in
Eqs. 5-6. A builder that computes the negative side in a mirrored frame (where its moment
is positive when it drives the negative collapse) must change its sign before writing it.

A side is given either by its physical constants (``I0``, ``K``, ``Q``, ``phi_cr`` and
optionally ``M_F``), from which ``p_eq``, ``lam`` and ``phi_ov`` are derived, or in the short
form that published tables print: ``p_eq``, ``lam`` and optionally ``phi_ov`` (default
``lam``, exact for a single block). A mechanism may also be written flat, with ``p_eq``,
``lam`` and ``phi_ov`` next to its ``id``; they then describe the positive side.

The models run on CPython 3.9 inside Rhino 8, so annotations use the ``typing`` forms.
"""

import json
import math
from typing import (
    TYPE_CHECKING,
    Annotated,
    Any,
    Dict,
    List,
    Literal,
    Mapping,
    Optional,
    Sequence,
    Tuple,
    Type,
    TypeVar,
    Union,
    get_args,
)

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    JsonValue,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)
from pydantic_core import PydanticCustomError

from shared_schema.errors import InputError, per_side_error
from shared_schema.rules import (
    PRINTABLE_PATTERN,
    ROTATION_MAX,
    SCHEMA_VERSION_PATTERN,
    G,
    control_character,
    default_rotation_problem,
    eta_problem,
    rotation_problem,
    schema_version_problem,
)
from shared_schema.spec import TYPOLOGIES, Amplification
from shared_schema.text import decode_text
from shared_schema.validation import validation_lines

__all__ = [
    "CONSISTENCY_RTOL",
    "ETA_SOURCES",
    "FLAT_SIDE_KEYS",
    "ROCKING_KINDS",
    "SCHEMA_VERSION",
    "Amplification",
    "ConstantsFile",
    "EtaSource",
    "G",
    "JsonInt",
    "Mechanism",
    "Rocking",
    "SchemaVersion",
    "SideConstants",
    "Typology",
    "Units",
    "VirtualWork",
    "input_error_from_validation",
    "json_document",
    "parse_constants",
    "validation_lines",
    "whole_number",
]

#: Version of the file format written by this module.
SCHEMA_VERSION = "1.0"


#: Nesting depth past which a JSON document is refused (Python's own recursion limit).
MAX_JSON_DEPTH = 1000
#: Relative tolerance within which given ``p_eq``/``lam``/``phi_ov`` must match the values
#: derived from the physical constants.
CONSISTENCY_RTOL = 1e-9

if TYPE_CHECKING:
    Typology = str
else:
    #: Typologies of a constants file: those of the spec (``shared_schema.spec.TYPOLOGIES``)
    #: and ``user_defined`` (constants given by hand or from a table).
    Typology = Literal[(*TYPOLOGIES, "user_defined")]
Rocking = Literal["two_sided", "one_sided"]
EtaSource = Literal[
    "housner_general",
    "housner_rectangular",
    "one_sided_eq26",
    "one_sided_alt",
    "one_sided_energy",
    "momentum_projection",
    "user",
    "published",
]

#: Allowed values of ``Mechanism.rocking``.
ROCKING_KINDS: Tuple[str, ...] = get_args(Rocking)
#: Allowed values of ``Mechanism.eta_source``.
ETA_SOURCES: Tuple[str, ...] = get_args(EtaSource)

#: Keys of the short (published-table) form that may be written flat in a mechanism.
FLAT_SIDE_KEYS = ("p_eq", "lam", "phi_ov")

_PHYSICAL_KEYS = ("I0", "K", "Q", "phi_cr")

_P_EQ_DESCRIPTION = "Equivalent frequency parameter p_eq = sqrt(K/I0) (theory Eq. 4) [rad/s], > 0."
_LAM_DESCRIPTION = (
    "Linearised static load multiplier: the ground acceleration that starts rocking, as a "
    "fraction of g (theory Eq. 5; §1.8 for the negative side) [-], > 0."
)
_PHI_OV_DESCRIPTION = (
    "Overturning rotation (theory Eq. 6; §1.8 for the negative side) [rad], in (0, pi/2] "
    "(a rocking body on its side; degrees are refused), given or defaulted; derived from the "
    "physical form it is not bounded. "
    "In the short form it defaults to lam (exact for a single block)."
)


def whole_number(value: Any) -> Any:
    """Return a float without a fractional part as an int, any other value as it is.

    Examples
    --------
    >>> whole_number(100.0), whole_number(2.5), whole_number(True)
    (100, 2.5, True)
    """
    # JSON Schema's "integer" is a number without a fractional part, so 100.0 is one (draft
    # 2020-12 §6.1.1); strict pydantic refuses a float for an int unless it is made one here.
    if isinstance(value, float) and value.is_integer():
        return int(value)
    return value


#: An integer field of a JSON document: an int, or a float without a fractional part (as
#: JSON Schema's ``integer``); booleans, strings and fractions are still refused.
JsonInt = Annotated[int, BeforeValidator(whole_number)]


def _schema_version(value: str) -> str:
    problem = schema_version_problem(value)
    if problem is not None:
        raise PydanticCustomError("schema_version", "{message}", {"message": problem})
    return value


#: A file's format version, ``1.<minor>`` (``rules.SCHEMA_VERSION_PATTERN``): the schema
#: states the pattern, a wrong value is told in words, never by quoting the regex (#25).
SchemaVersion = Annotated[str, AfterValidator(_schema_version)]


def schema_version_field(default: str, description: str) -> Any:
    """Return the ``schema_version`` field of a file model (pattern stated in the schema)."""
    return Field(
        default, description=description, json_schema_extra={"pattern": SCHEMA_VERSION_PATTERN}
    )


def _error(field: str, message: str, error_type: str = "rockmech_value") -> PydanticCustomError:
    """Build a validation error whose context names the offending sub-field.

    ``input_error_from_validation`` appends ``field`` to the error location, because a
    model-level validator cannot place an error on one of its fields itself.
    """
    # The message goes in through the context, not the template, so that braces in user
    # values (ids) are not taken for placeholders; "field" is substituted first.
    return PydanticCustomError(error_type, "{message}", {"field": field, "message": message})


class Units(BaseModel):
    """SI units of the quantities in the file.

    The values are fixed: the file is always in SI. The section documents this for a reader
    and lets a file that claims other units be rejected rather than misread.
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        json_schema_extra={"description": "SI units of the quantities in the file (fixed)."},
    )

    length: Literal["m"] = "m"
    mass: Literal["kg"] = "kg"
    angle: Literal["rad"] = "rad"
    p_eq: Literal["rad/s"] = "rad/s"
    I0: Literal["kg m^2"] = "kg m^2"
    K: Literal["N m/rad"] = "N m/rad"
    Q: Literal["kg m"] = "kg m"
    M_F: Literal["N m"] = "N m"
    f_n: Literal["Hz"] = "Hz"
    h: Literal["m"] = "m"


#: Relative slack allowed on the Cauchy-Schwarz bound ``S² <= mass * J`` (``e* <= 1``).
VIRTUAL_WORK_RTOL = 1e-9


class VirtualWork(BaseModel):
    """What the code's kinematic check needs of a side, in the configuration at rest.

    The virtual horizontal displacements ``δx`` of the mechanism's masses for a unit
    virtual rotation of the mechanism's coordinate at rest (``phi = 0``), summed over the
    masses whose inertia the mechanism mobilises (docs/theory.md §11.1).

    Attributes
    ----------
    alpha0 : float
        Activation multiplier: the exact static multiplier at rest by virtual work, with the
        static forces at their own points [-]. Not ``lam``, which linearises about
        ``phi_cr`` (a block has ``alpha0 = tan(alpha)``, ``lam = alpha``).
    mass : float
        Mass that the mechanism's horizontal inertia mobilises, ``sum P_i / g`` [kg], > 0.
    S : float
        First moment ``sum m δx`` at rest [kg m], > 0 (``Q`` is the same sum at ``phi_cr``).
    J : float
        Second moment ``sum ∫ δx² dm`` at rest [kg m²], > 0; for one block the second moment
        of its mass about the horizontal plane through the axis.
    J_blocks : float, optional
        The same sum as Circolare 2019 [C8.7.1.5] takes it, one term ``m_k δx_k²`` per
        block at the centroid of its forces [kg m²], ``S²/mass <= J_blocks <= J``.

    Notes
    -----
    ``S² <= mass * J`` (Cauchy-Schwarz), i.e. the participating mass fraction
    ``e* = S² / (mass J)`` is at most 1; a file that breaks it is rejected, and so is one
    whose ``M* = S²/J`` or ``e*`` is not finite and > 0 in double precision.
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={
            "description": (
                "Virtual-work quantities of a side at rest for the code's kinematic check "
                "(NTC 2018 / Circolare 2019 §C8.7.1): alpha0, mass, S = sum m dx, "
                "J = sum m dx^2 for a unit virtual rotation (docs/theory.md §11.1)."
            )
        },
    )

    alpha0: float = Field(
        description=(
            "Activation multiplier at rest by virtual work (exact static multiplier with the "
            "static forces at their own points) [-]."
        )
    )
    mass: float = Field(
        gt=0, description="Mass mobilised by the mechanism's horizontal inertia [kg], > 0."
    )
    S: float = Field(
        gt=0, description="First moment sum(m dx) for a unit virtual rotation at rest [kg m], > 0."
    )
    J: float = Field(
        gt=0,
        description=(
            "Second moment sum(m dx^2) for a unit virtual rotation at rest [kg m^2], > 0 "
            "(one block: second moment of its mass about the horizontal plane through the axis)."
        ),
    )
    J_blocks: Optional[float] = Field(
        None,
        gt=0,
        description=(
            "Second moment as Circ. 2019 [C8.7.1.5] sums it: one term m_k dx_k^2 per block, "
            "dx_k the virtual displacement of the centroid of the forces on block k [kg m^2], "
            "> 0, <= J (one block: S^2/mass). Absent: a single-block or user-defined "
            "mechanism is taken as one block."
        ),
    )

    @model_validator(mode="after")
    def _check_bound(self) -> "VirtualWork":
        # The code check divides by both (codes.circ2009.participating_mass): issue #19,
        # S = 1e-200 made e* = 0 and the check a ZeroDivisionError.
        m_star = self.S * self.S / self.J
        e_star = m_star / self.mass
        if not (math.isfinite(m_star) and m_star > 0.0 and math.isfinite(e_star) and e_star > 0.0):
            raise _error(
                "S",
                f"M* = S^2/J = {m_star!r} and e* = M*/mass = {e_star!r} must be finite and "
                f"> 0: S = {self.S!r}, J = {self.J!r}, mass = {self.mass!r} are out of any "
                "physical range (overflow or underflow)",
                "non_finite_constant",
            )
        if self.J_blocks is not None:
            if self.S * self.S > self.mass * self.J_blocks * (1.0 + VIRTUAL_WORK_RTOL):
                raise _error(
                    "J_blocks",
                    f"S^2 = {self.S * self.S:.6g} exceeds mass*J_blocks = "
                    f"{self.mass * self.J_blocks:.6g}: the mass fraction of [C8.7.1.5] would "
                    "exceed 1 (inconsistent virtual-work quantities)",
                    "inconsistent_constant",
                )
            if self.J_blocks > self.J * (1.0 + VIRTUAL_WORK_RTOL):
                raise _error(
                    "J_blocks",
                    f"J_blocks = {self.J_blocks:.6g} exceeds J = {self.J:.6g}: the blocks' "
                    "centroids cannot move more than their masses do on average "
                    "(inconsistent virtual-work quantities)",
                    "inconsistent_constant",
                )
        if self.S * self.S > self.mass * self.J * (1.0 + VIRTUAL_WORK_RTOL):
            raise _error(
                "J",
                f"S^2 = {self.S * self.S:.6g} exceeds mass*J = {self.mass * self.J:.6g}: the "
                "participating mass fraction S^2/(mass J) would exceed 1 (inconsistent "
                "virtual-work quantities)",
                "inconsistent_constant",
            )
        return self


# JSON Schema pieces for rules across fields. A null value means "not given" in these models
# (pydantic's None), so a rule says "is a number" or "is null or absent", never only
# "present" (``required``/``dependentRequired`` would call a null given).


def _numbers(*keys: str) -> Dict[str, Any]:
    """Return the schema saying each of ``keys`` is present and a number."""
    return {"required": list(keys), "properties": {k: {"type": "number"} for k in keys}}


def _not_given(*keys: str) -> Dict[str, Any]:
    """Return the schema saying each of ``keys`` is absent or null."""
    return {"properties": {k: {"type": "null"} for k in keys}}


#: SideConstants._check_form: in the short form phi_ov, given or defaulted to lam, is at most
#: pi/2 (the physical form derives it).
_SHORT_ROTATION: List[Dict[str, Any]] = [
    {"properties": {"phi_ov": {"type": "number", "maximum": ROTATION_MAX}}, "required": ["phi_ov"]},
    {"properties": {"phi_ov": {"type": "null"}, "lam": {"maximum": ROTATION_MAX}}},
]


def _side_schema_extra(schema: Dict[str, Any]) -> None:
    schema["description"] = (
        "Constants of one rocking side: either the physical constants I0, K, Q, phi_cr "
        "(and optionally M_F), from which p_eq, lam and phi_ov are derived, or the short form "
        "p_eq, lam (and optionally phi_ov, default lam; no M_F). When both are given they "
        "must agree to a relative 1e-9."
    )
    # SideConstants._check_form: all four physical constants, or none of them, no M_F, and
    # p_eq and lam.
    short = _not_given(*_PHYSICAL_KEYS, "M_F")
    short["properties"].update(_numbers("p_eq", "lam")["properties"])
    schema["oneOf"] = [
        _numbers(*_PHYSICAL_KEYS),
        {**short, "required": ["p_eq", "lam"], "anyOf": _SHORT_ROTATION},
    ]


class SideConstants(BaseModel):
    """Constants of one rocking side of a mechanism.

    Give either the physical constants ``I0``, ``K``, ``Q``, ``phi_cr`` (and optionally
    ``M_F``), or the short form ``p_eq``, ``lam`` (and optionally ``phi_ov``). Inside a
    validated ``Mechanism`` the derived ``p_eq``, ``lam`` and ``phi_ov`` are always filled in;
    when both forms are given they must agree to a relative 1e-9.

    Attributes
    ----------
    I0 : float, optional
        Generalised inertia at ``phi_cr`` [kg m^2], > 0.
    K : float, optional
        Rotational stiffness [N m/rad], > 0.
    Q : float, optional
        Ground-motion coefficient [kg m], > 0.
    phi_cr : float, optional
        Critical rotation [rad], > 0.
    M_F : float, optional
        Moment of the static forces about this side's hinge(s) [N m], signed in the
        mechanism's positive sense on both sides: positive when it drives positive rotation,
        so negative on the negative side when it drives that side towards collapse. Defaults
        to 0 in the physical form; absent in the short form.
    p_eq : float, optional
        Equivalent frequency parameter [rad/s], > 0.
    lam : float, optional
        Linearised static load multiplier [-], > 0.
    phi_ov : float, optional
        Overturning rotation [rad], > 0.
    virtual_work : VirtualWork, optional
        The side's virtual-work quantities at rest for the code's kinematic check.

    Notes
    -----
    Derivation (theory §1, Eqs. 4-6 and §1.8), with ``s = +1`` on the positive side and
    ``s = -1`` on the negative side::

        p_eq = sqrt(K / I0)
        lam = (K * phi_cr - s * M_F) / (g * Q)
        phi_ov = phi_cr - s * M_F / K
    """

    model_config = ConfigDict(
        strict=True, extra="forbid", allow_inf_nan=False, json_schema_extra=_side_schema_extra
    )

    I0: Optional[float] = Field(
        None, gt=0, description="Generalised inertia of the mechanism at phi_cr [kg m^2], > 0."
    )
    K: Optional[float] = Field(
        None,
        gt=0,
        description=(
            "Rotational stiffness K = -V''(phi_cr) of the linearised system [N m/rad], > 0 "
            "(it acts as a destabilising stiffness)."
        ),
    )
    Q: Optional[float] = Field(
        None, gt=0, description="Ground-motion coefficient sum(m dx_G/dphi) at phi_cr [kg m], > 0."
    )
    phi_cr: Optional[float] = Field(
        None,
        gt=0,
        description="Critical rotation (unstable equilibrium under gravity alone) [rad], in "
        "(0, pi/2].",
        json_schema_extra={"maximum": ROTATION_MAX},
    )
    M_F: Optional[float] = Field(
        None,
        description=(
            "Moment of the external static forces about this side's hinge(s) at phi_cr [N m], "
            "any finite value, signed in the mechanism's positive sense on both sides: positive "
            "when it drives positive rotation. On the negative side a moment that drives that "
            "side towards collapse is negative (lam = (K*phi_cr + M_F)/(g*Q) there). The other "
            "constants are magnitudes on both sides. Defaults to 0 in the physical form."
        ),
    )
    p_eq: Optional[float] = Field(None, gt=0, description=_P_EQ_DESCRIPTION)
    lam: Optional[float] = Field(None, gt=0, description=_LAM_DESCRIPTION)
    phi_ov: Optional[float] = Field(None, gt=0, description=_PHI_OV_DESCRIPTION)
    virtual_work: Optional[VirtualWork] = Field(
        None,
        description=(
            "Virtual-work quantities at rest for the code's kinematic check (alpha0, mass, "
            "S, J); optional, in either form."
        ),
    )

    @field_validator("phi_cr")
    @classmethod
    def _check_rotation(cls, value: Optional[float]) -> Optional[float]:
        # issue #25: degrees written as radians (phi_cr = 5) were taken as 286 deg.
        problem = None if value is None else rotation_problem(value)
        if problem is not None:
            raise PydanticCustomError("rotation_too_large", "{message}", {"message": problem})
        return value

    @model_validator(mode="after")
    def _check_form(self) -> "SideConstants":
        given = [k for k in _PHYSICAL_KEYS if getattr(self, k) is not None]
        if given:
            missing = [k for k in _PHYSICAL_KEYS if getattr(self, k) is None]
            if missing:
                raise _error(
                    missing[0],
                    "the physical form needs I0, K, Q and phi_cr; missing " + ", ".join(missing),
                    "missing_constant",
                )
            return self
        if self.M_F is not None:
            raise _error(
                "M_F",
                "M_F is only meaningful with the physical constants I0, K, Q and phi_cr; "
                "in the short form it is already contained in lam and phi_ov",
            )
        for key in ("p_eq", "lam"):
            if getattr(self, key) is None:
                raise _error(
                    key,
                    "give either the physical constants I0, K, Q and phi_cr, or p_eq and lam "
                    f"(short form); {key} is missing",
                    "missing_constant",
                )
        # issue #25: degrees written as radians (phi_ov = 5) were taken as 286 deg. The
        # physical form derives phi_ov (Eq. 6, a linearisation that static forces may carry
        # past pi/2); its phi_cr is checked instead.
        if self.phi_ov is not None:
            problem = rotation_problem(self.phi_ov)
            if problem is not None:
                raise _error("phi_ov", problem, "rotation_too_large")
        else:
            assert self.lam is not None
            problem = default_rotation_problem(self.lam)
            if problem is not None:
                raise _error("lam", problem, "rotation_too_large")
        return self

    @property
    def is_physical(self) -> bool:
        """True when the side was given by its physical constants (I0, K, Q, phi_cr)."""
        return self.I0 is not None


def _derive_side(side: SideConstants, which: str) -> SideConstants:
    """Fill in ``p_eq``, ``lam`` and ``phi_ov`` of ``side`` (``which``: positive/negative)."""
    if not side.is_physical:
        if side.phi_ov is None:
            return side.model_copy(update={"phi_ov": side.lam})
        return side
    assert side.I0 is not None and side.K is not None
    assert side.Q is not None and side.phi_cr is not None
    # theory §1.8: M_F keeps its sign (positive drives positive rotation), so it helps the
    # positive side overturn and resists the negative side.
    s = 1.0 if which == "positive" else -1.0
    m_f = 0.0 if side.M_F is None else side.M_F
    sign = "-" if s > 0 else "+"
    derived = {
        "p_eq": math.sqrt(side.K / side.I0),  # Eq. 4
        "lam": (side.K * side.phi_cr - s * m_f) / (G * side.Q),  # Eq. 5
        "phi_ov": side.phi_cr - s * m_f / side.K,  # Eq. 6
    }
    inputs = {
        "p_eq": ("sqrt(K/I0)", ("K", "I0")),
        "lam": (f"(K*phi_cr {sign} M_F)/(g*Q)", ("K", "phi_cr", "M_F", "Q")),
        "phi_ov": (f"phi_cr {sign} M_F/K", ("phi_cr", "M_F", "K")),
    }
    for key, (formula, names) in inputs.items():
        # issue #14: huge or tiny inputs can overflow a derived constant; never store inf
        if not math.isfinite(derived[key]):
            given = ", ".join(f"{n} = {m_f if n == 'M_F' else getattr(side, n):g}" for n in names)
            raise _error(
                key,
                f"{formula} = {derived[key]!r} is not finite: the inputs {given} are out of "
                "any physical range (overflow)",
                "non_finite_constant",
            )
    if not derived["p_eq"] > 0.0:
        # issue #19: K/I0 below the smallest double made p_eq 0, which no file may hold.
        raise _error(
            "p_eq",
            f"sqrt(K/I0) = {derived['p_eq']!r} is not > 0: the inputs K = {side.K:g}, "
            f"I0 = {side.I0:g} are out of any physical range (underflow)",
            "non_finite_constant",
        )
    for key, formula in (
        ("lam", f"(K*phi_cr {sign} M_F)/(g*Q)"),
        ("phi_ov", f"phi_cr {sign} M_F/K"),
    ):
        if not derived[key] > 0.0:
            raise _error(
                key,
                f"{formula} = {derived[key]:.6g} is not > 0: the static forces alone overturn "
                f"the mechanism on its {which} side (M_F = {m_f:g} N m against "
                f"K*phi_cr = {side.K * side.phi_cr:g} N m)",
                "static_collapse",
            )
    for key, value in derived.items():
        given = getattr(side, key)
        if given is not None and not math.isclose(
            given, value, rel_tol=CONSISTENCY_RTOL, abs_tol=0.0
        ):
            raise _error(
                key,
                f"given {key} = {given!r} disagrees with {value!r} derived from the physical "
                f"constants (relative tolerance {CONSISTENCY_RTOL:g})",
                "inconsistent_constant",
            )
    return side.model_copy(update={"M_F": m_f, **derived})


def _check_json_safe(value: Any, path: str) -> None:
    # JsonValue lets NaN through in JSON mode, and NaN cannot be written back as JSON.
    if isinstance(value, float) and not math.isfinite(value):
        raise _error(path, f"must be finite, got {value!r}", "finite_number")
    if isinstance(value, dict):
        for key, item in value.items():
            _check_json_safe(item, f"{path}.{key}" if path else str(key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            _check_json_safe(item, f"{path}[{i}]")


def _mechanism_schema_extra(schema: Dict[str, Any]) -> None:
    schema["description"] = (
        "One rocking mechanism. Give the positive side as 'positive', or flat as p_eq, lam "
        "(and optionally phi_ov) next to the id, as published tables print them."
    )
    # The published-table short form may be written flat (see Mechanism._move_flat_keys).
    props = schema["properties"]
    props["p_eq"] = {"type": "number", "exclusiveMinimum": 0, "description": _P_EQ_DESCRIPTION}
    props["lam"] = {"type": "number", "exclusiveMinimum": 0, "description": _LAM_DESCRIPTION}
    # As inside a side, null means "not given" (lam is used).
    props["phi_ov"] = {
        "anyOf": [
            {"type": "number", "exclusiveMinimum": 0},
            {"type": "null"},
        ],
        "description": _PHI_OV_DESCRIPTION,
    }
    for key in ("p_eq", "lam", "phi_ov"):
        props[key]["description"] += " Flat short form: describes the positive side."
    schema["required"] = [k for k in schema.get("required", []) if k != "positive"]
    directional = _numbers("eta_to_negative", "eta_to_positive", "eta")
    directional["properties"]["rocking"] = {"const": "two_sided"}
    schema["allOf"] = [
        # Mechanism._check_eta_sign: eta >= 0 two-sided (the default), <= 0 one-sided.
        {
            "oneOf": [
                {"properties": {"rocking": {"const": "two_sided"}, "eta": {"minimum": 0}}},
                {
                    "properties": {"rocking": {"const": "one_sided"}, "eta": {"maximum": 0}},
                    "required": ["rocking"],
                },
            ]
        },
        # Mechanism._fill_defaults: the two impact restitutions go together, with eta, for
        # two-sided rocking only; eta_source describes an eta.
        {"anyOf": [_not_given("eta_to_negative", "eta_to_positive"), directional]},
        {"anyOf": [_not_given("eta_source"), _numbers("eta")]},
    ]
    schema["oneOf"] = [
        {
            "required": ["positive"],
            "not": {"anyOf": [{"required": [k]} for k in FLAT_SIDE_KEYS]},
        },
        {"required": ["p_eq", "lam"], "not": {"required": ["positive"]}, "anyOf": _SHORT_ROTATION},
    ]


class Mechanism(BaseModel):
    """One rocking mechanism and its kinematic constants.

    Attributes
    ----------
    id : str
        Unique identifier in the file, e.g. ``"W1"``.
    name : str
        Descriptive name; defaults to ``id``.
    typology : str
        One of ``TYPOLOGIES``; ``"user_defined"`` by default.
    rocking : str
        ``"two_sided"`` (default) or ``"one_sided"`` (e.g. a façade restrained by
        transverse walls, which can only rotate outward).
    positive : SideConstants
        Constants for positive rotation (the collapse direction).
    negative : SideConstants, optional
        Constants for negative rotation; absent for a symmetric mechanism. Ignored by the
        solver for one-sided rocking.
    eta : float, optional
        Coefficient of restitution [-] in [-1, 1]: >= 0 for two-sided, <= 0 for one-sided.
    eta_source : str, optional
        Where ``eta`` comes from (one of ``ETA_SOURCES``); ``"user"`` when ``eta`` is given
        without it.
    eta_to_negative, eta_to_positive : float, optional
        Two-sided rocking only, given together and with ``eta``: the restitution at an
        impact after which the mechanism rocks on its negative side (the hinges switch from
        the positive to the negative set) and on its positive side [-], each in [0, 1] and
        the ratio of the angular speeds after/before. ``eta`` must lie between them (it is
        the one value a solver uses when it does not tell the impacts apart).
    amplification : Amplification, optional
        Data for amplifying the ground motion up the structure.
    geometry : dict, optional
        Free-form, JSON-safe summary of the geometry (for reports and provenance).
    provenance : dict, optional
        Free-form, JSON-safe record of where the constants come from.

    Notes
    -----
    The flat short form ``{"id": "W1", "p_eq": 2.15, "lam": 0.25}`` is accepted and moved
    into ``positive`` before validation.
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra=_mechanism_schema_extra,
    )

    id: str = Field(
        min_length=1,
        description="Unique identifier of the mechanism in the file (printable text).",
        json_schema_extra={"pattern": PRINTABLE_PATTERN},
    )
    name: Optional[str] = Field(
        None,
        description="Descriptive name (printable text); defaults to id.",
        json_schema_extra={"pattern": PRINTABLE_PATTERN},
    )
    typology: Typology = Field("user_defined", description="Typology of the mechanism.")
    rocking: Rocking = Field(
        "two_sided",
        description=(
            "two_sided: rocks both ways with impacts at phi = 0; one_sided: only positive "
            "rotation, rebounding off a restraint (e.g. a façade held by transverse walls)."
        ),
    )
    positive: SideConstants = Field(
        description="Constants for positive rotation (the collapse direction)."
    )
    negative: Optional[SideConstants] = Field(
        None,
        description=(
            "Constants for negative rotation, as magnitudes except M_F, which keeps the "
            "positive sense; absent for a symmetric mechanism (the positive side's mirror "
            "image: the same magnitudes and M_F of opposite sign). Ignored for one-sided "
            "rocking."
        ),
    )
    eta: Optional[float] = Field(
        None,
        ge=-1,
        le=1,
        description=(
            "Coefficient of restitution on the angular velocity at impact [-], in [-1, 1]: "
            ">= 0 for two-sided rocking, <= 0 (rebound) for one-sided rocking."
        ),
    )
    eta_source: Optional[EtaSource] = Field(
        None, description="Where eta comes from; 'user' when eta is given without it."
    )
    eta_to_negative: Optional[float] = Field(
        None,
        ge=0,
        le=1,
        description=(
            "Two-sided rocking: coefficient of restitution at an impact after which the "
            "mechanism rocks on its negative side (hinges switch from the positive to the "
            "negative set), |dphi after| / |dphi before| [-], in [0, 1]. Given together with "
            "eta_to_positive and eta, for mechanisms whose two impact directions differ."
        ),
    )
    eta_to_positive: Optional[float] = Field(
        None,
        ge=0,
        le=1,
        description=(
            "Two-sided rocking: coefficient of restitution at an impact after which the "
            "mechanism rocks on its positive side (hinges switch from the negative to the "
            "positive set), |dphi after| / |dphi before| [-], in [0, 1]. Given together with "
            "eta_to_negative and eta."
        ),
    )
    amplification: Optional[Amplification] = Field(
        None, description="Data for amplifying the ground motion up the structure (theory §7)."
    )
    geometry: Optional[Dict[str, JsonValue]] = Field(
        None, description="Free-form JSON summary of the geometry (lengths in m, masses in kg)."
    )
    provenance: Optional[Dict[str, JsonValue]] = Field(
        None, description="Free-form JSON record of where the constants come from."
    )

    @model_validator(mode="before")
    @classmethod
    def _move_flat_keys(cls, data: Any) -> Any:
        if not isinstance(data, Mapping):
            return data
        flat = [k for k in FLAT_SIDE_KEYS if k in data]
        if not flat:
            return data
        if "positive" in data:
            raise _error(
                flat[0],
                "give the positive side either flat (p_eq, lam, phi_ov next to id) or as "
                "'positive', not both",
            )
        out = {k: v for k, v in data.items() if k not in FLAT_SIDE_KEYS}
        out["positive"] = {k: data[k] for k in flat}
        return out

    @field_validator("positive", "negative")
    @classmethod
    def _derive(
        cls, side: Optional[SideConstants], info: ValidationInfo
    ) -> Optional[SideConstants]:
        if side is None:
            return None
        return _derive_side(side, info.field_name or "positive")

    @field_validator("eta")
    @classmethod
    def _check_eta_sign(cls, eta: Optional[float], info: ValidationInfo) -> Optional[float]:
        rocking = info.data.get("rocking")
        if eta is None or rocking is None:
            return eta
        problem = eta_problem(eta, rocking == "one_sided")
        if problem is not None:
            raise PydanticCustomError("eta_sign", problem)
        return eta

    @field_validator("id", "name")
    @classmethod
    def _check_printable(cls, value: Optional[str]) -> Optional[str]:
        # issue #25: a line break or escape code in an id broke the terminal tables.
        bad = None if value is None else control_character(value)
        if bad is not None:
            raise PydanticCustomError(
                "control_character",
                "{message}",
                {
                    "message": f"must be printable text, got the control character {bad} in "
                    f"{value!r}; ids and names go into tables and file names"
                },
            )
        return value

    @field_validator("geometry", "provenance")
    @classmethod
    def _check_finite(cls, value: Optional[Dict[str, JsonValue]]) -> Optional[Dict[str, JsonValue]]:
        if value is not None:
            _check_json_safe(value, "")
        return value

    @model_validator(mode="after")
    def _fill_defaults(self) -> "Mechanism":
        if self.eta_source is not None and self.eta is None:
            raise _error("eta_source", "eta_source is given but eta is not")
        if self.eta is not None and self.eta_source is None:
            self.eta_source = "user"
        to_neg, to_pos = self.eta_to_negative, self.eta_to_positive
        if to_neg is not None or to_pos is not None:
            if to_neg is None or to_pos is None:
                missing = "eta_to_positive" if to_pos is None else "eta_to_negative"
                raise _error(missing, "eta_to_negative and eta_to_positive go together")
            if self.rocking == "one_sided":
                raise _error(
                    "eta_to_negative",
                    "eta_to_negative and eta_to_positive apply to two-sided rocking only",
                )
            if self.eta is None:
                raise _error(
                    "eta",
                    "eta_to_negative and eta_to_positive need eta, the value used where the "
                    "two impacts are not told apart",
                )
            lo, hi = min(to_neg, to_pos), max(to_neg, to_pos)
            if not lo <= self.eta <= hi:
                raise _error(
                    "eta",
                    f"eta = {self.eta!r} is not between eta_to_negative = "
                    f"{self.eta_to_negative!r} and eta_to_positive = {self.eta_to_positive!r}",
                    "eta_not_between",
                )
        if self.name is None:
            self.name = self.id
        return self

    @property
    def one_sided(self) -> bool:
        """True for one-sided rocking."""
        return self.rocking == "one_sided"

    if not TYPE_CHECKING:  # for type checkers the fields are the attributes, as they are

        def __getattr__(self, name: str) -> Any:
            """Point a side's constant read on the mechanism (``mech.p_eq``) to its side."""
            if name in SideConstants.model_fields:
                negative = None if self.negative is None else getattr(self.negative, name)
                raise per_side_error(
                    f"Mechanism {self.id!r}",
                    name,
                    getattr(self.positive, name),
                    negative,
                    self.one_sided,
                )
            return super().__getattr__(name)


class ConstantsFile(BaseModel):
    """A kinematic-constants file: format version, units and the mechanisms.

    Attributes
    ----------
    schema_version : str
        Format version, ``"1.<minor>"``; defaults to ``SCHEMA_VERSION``.
    units : Units
        SI units of the quantities (fixed; filled in by default).
    rockmech_version : str, optional
        The rockmech version that wrote the file (``shared_schema.io.stamped``).
    mechanisms : list of Mechanism
        At least one mechanism; ids are unique.

    Examples
    --------
    >>> cf = ConstantsFile.model_validate({"mechanisms": [{"id": "W1", "p_eq": 2.15, "lam": 0.25}]})
    >>> cf.mechanisms[0].positive.phi_ov
    0.25
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={
            "description": (
                "Kinematic constants of the rocking mechanisms of a structure (rockmech). "
                "All quantities in SI units."
            )
        },
    )

    schema_version: SchemaVersion = schema_version_field(
        SCHEMA_VERSION, "Version of the file format, '1.<minor>'."
    )
    units: Units = Field(
        default_factory=Units, description="SI units of the quantities (fixed, informative)."
    )
    rockmech_version: Optional[str] = Field(
        None,
        max_length=100,
        description="Version of rockmech that wrote the file (informative; rockmech fills "
        "it in whenever it writes one).",
    )
    mechanisms: List[Mechanism] = Field(
        min_length=1, description="The mechanisms; at least one, with unique ids."
    )

    @field_validator("mechanisms")
    @classmethod
    def _check_unique_ids(cls, mechanisms: List[Mechanism]) -> List[Mechanism]:
        first: Dict[str, int] = {}
        for i, mech in enumerate(mechanisms):
            if mech.id in first:
                raise _error(
                    f"[{i}]",
                    f"duplicate mechanism id {mech.id!r} (also mechanisms[{first[mech.id]}]); "
                    "ids must be unique",
                    "duplicate_id",
                )
            first[mech.id] = i
        return mechanisms

    def get_mechanism(self, mechanism_id: str) -> Mechanism:
        """Return the mechanism with id ``mechanism_id``.

        Raises
        ------
        InputError
            If there is no such mechanism.
        """
        for mech in self.mechanisms:
            if mech.id == mechanism_id:
                return mech
        known = ", ".join(repr(m.id) for m in self.mechanisms)
        raise InputError(f"no mechanism with id {mechanism_id!r}; the file has {known}", "id")


def input_error_from_validation(exc: ValidationError, data: Any = None) -> InputError:
    """Turn a pydantic ``ValidationError`` into an ``InputError`` naming mechanism and field.

    Parameters
    ----------
    exc : pydantic.ValidationError
        The error raised while validating a ``ConstantsFile``.
    data : object, optional
        The input as plain Python data (e.g. from ``json.loads``), used to name the
        mechanism by its id.

    Returns
    -------
    InputError
        One line per error, each ``<path>: <message>`` (``validation_lines``), e.g.
        ``mechanisms[1] (id 'W2').positive.p_eq: Input should be greater than 0``.
        ``field`` is the path of the first error.
    """
    errors = validation_lines(exc, data)
    if not errors:  # pragma: no cover - pydantic never raises an empty ValidationError
        return InputError(str(exc))
    lines = [f"{path}: {msg}" if path else msg for path, msg in errors]
    return InputError("\n".join([errors[0][1], *lines[1:]]), errors[0][0] or None)


def json_document(text: str) -> Any:
    """Decode JSON text; malformed or too deeply nested text is an ``InputError``.

    Examples
    --------
    >>> json_document('{"a": [1, 2]}')
    {'a': [1, 2]}
    >>> json_document("[" * 5000 + "]" * 5000)
    Traceback (most recent call last):
    ...
    shared_schema.errors.InputError: invalid JSON: nested deeper than 1000 levels
    """
    if not text.strip():
        raise InputError("invalid JSON: there is no document, only blank space") from None
    try:
        return json.loads(text, parse_int=_json_int)
    except json.JSONDecodeError as exc:
        raise InputError(
            f"invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}; the file is "
            "not JSON (a CSV or a workbook?) or is cut short"
        ) from None
    except ValueError as exc:
        raise InputError(f"invalid JSON: {exc}") from None
    except RecursionError:
        raise InputError(f"invalid JSON: nested deeper than {MAX_JSON_DEPTH} levels") from None


_Doc = TypeVar("_Doc", bound=BaseModel)


def validate_document(model: Type[_Doc], source: Any, what: str, field: str, expected: str) -> _Doc:
    """Validate a document given as a model, JSON text, the bytes of a file, or plain data.

    Bytes are decoded by ``shared_schema.text.decode_text`` (``what``, ``field`` and
    ``expected`` word its messages on an empty, binary or non-UTF text); JSON is decoded
    by ``json_document``; a validation error becomes an ``InputError`` naming the field.

    Raises
    ------
    InputError
        Bytes that are not text, malformed JSON or an invalid value.
    """
    if isinstance(source, model):
        return source
    if isinstance(source, (str, bytes)):
        if isinstance(source, bytes):
            source = decode_text(source, what, field, expected)
        data = json_document(source)
        try:
            return model.model_validate_json(source)
        except ValidationError as exc:
            raise input_error_from_validation(exc, data) from exc
    try:
        return model.model_validate(source)
    except ValidationError as exc:
        raise input_error_from_validation(exc, source) from exc


def _json_invalid_fields(exc: ValidationError, data: Any) -> ValidationError:
    """Return the errors of a JSON text field by field, when pydantic refused it whole.

    Pydantic's parser refuses a number beyond double precision for the whole text ("number
    out of range at line 1 column 4338"); its data (``json_document`` reads such a number as
    infinity) names the field. ``exc`` itself otherwise.
    """
    if not any(e["type"] == "json_invalid" for e in exc.errors(include_url=False)):
        return exc
    try:
        ConstantsFile.model_validate(data)
    except ValidationError as fields:
        return fields
    return exc


def _json_int(text: str) -> Union[int, float]:
    """Read a JSON integer; one longer than Python reads as an int becomes a float.

    Python refuses to read more than 4300 digits as an int; as a float such a number is
    infinite, which the models refuse naming the field.
    """
    return int(text) if len(text) <= 4000 else float(text)


#: Keys of a whole constants file (not of a mechanism), for a file given inside a list.
_FILE_KEYS = ("schema_version", "mechanisms", "units", "rockmech_version")


def _check_bare_list(items: List[Any]) -> None:
    """Refuse a top-level list that is not a list of mechanisms, saying what it holds.

    A bare list is read as the list of mechanisms (``parse_constants``); a whole file inside
    one (``[{"schema_version": ..., "mechanisms": [...]}]``) or an item that is no object
    got pydantic's "positive: Field required" or "Input should be an object" (issue #36).
    """
    example = '{"id": "W1", "p_eq": 2.15, "lam": 0.25, "eta": 0.9}'
    for i, item in enumerate(items):
        if isinstance(item, Mapping):
            keys = [k for k in _FILE_KEYS if k in item]
            if keys:
                raise InputError(
                    f"the file's top level is a list, which is read as the list of "
                    f"mechanisms, but item {i} is a whole constants file (it has "
                    f"{', '.join(repr(k) for k in keys)}): remove the [ ] around it, so that "
                    'the file is {"schema_version": ..., "mechanisms": [...]}',
                    f"mechanisms[{i}]",
                )
            continue
        if isinstance(item, list):
            found = "a list"
        elif isinstance(item, str):
            found = f"the text {item[:40]!r}"
        elif item is None or isinstance(item, bool):
            found = json.dumps(item)
        else:
            found = f"the number {item!r}"
        raise InputError(
            f"the file's top level is a list, which is read as the list of mechanisms, but "
            f"item {i} is {found}, not a mechanism: each item is an object like {example}; "
            'or write the file as {"mechanisms": [...]}',
            f"mechanisms[{i}]",
        )


def parse_constants(source: Union[str, bytes, Mapping[str, Any], Sequence[Any]]) -> ConstantsFile:
    """Validate a kinematic-constants file given as JSON text or as plain Python data.

    Parameters
    ----------
    source : str, bytes, dict or list
        JSON text (parsed with pydantic's JSON mode), or data as ``json.load`` returns it.
        A bare list is taken as the list of mechanisms.

    Returns
    -------
    ConstantsFile
        The validated file, with derived constants filled in.

    Raises
    ------
    InputError
        If the JSON is malformed or a value is invalid; the message names the mechanism
        (index and id) and the field.

    Examples
    --------
    >>> cf = parse_constants('[{"id": "W1", "p_eq": 2.15, "lam": 0.25, "eta": 0.9}]')
    >>> cf.mechanisms[0].eta_source
    'user'
    """
    if isinstance(source, ConstantsFile):
        return source
    if isinstance(source, (str, bytes)):
        text = source.decode("utf-8-sig") if isinstance(source, bytes) else source
        data = json_document(text)
        if isinstance(data, list):
            _check_bare_list(data)
            text = '{"mechanisms": ' + text + "}"
            data = {"mechanisms": data}
        try:
            return ConstantsFile.model_validate_json(text)
        except ValidationError as exc:
            raise input_error_from_validation(_json_invalid_fields(exc, data), data) from exc
    if not isinstance(source, Mapping):
        _check_bare_list(list(source))
    data = {"mechanisms": list(source)} if not isinstance(source, Mapping) else source
    try:
        return ConstantsFile.model_validate(data)
    except ValidationError as exc:
        raise input_error_from_validation(exc, data) from exc
