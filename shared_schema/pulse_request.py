"""The pulse request: one mechanism under a one-cycle pulse (``rockmech pulse``, REST ``/pulse``).

``PulseRequest`` is the one pulse request of every front end (the command line, REST, Hops,
the Rhino flows and the Python API), with the rules it shares with the time-domain requests
of ``shared_schema.api`` (which re-exports every name here): the plausible ranges of a
side's constants (``TIME_DOMAIN_RANGES``) and of amplification data
(``AMPLIFICATION_RANGES``), checked per mechanism by ``mechanism_problem``, and the rule
across fields that the published schema states (``PULSE_ETA_RULE``).

Apart from ``shared_schema.api`` so that a pulse loads the constants file's models and no
more: not the models of the other requests, of the site file or of the retrofit
(``rockmech pulse`` starts fast, #38). Units: ``a_p_g`` in g, ``f_p`` in Hz, SI otherwise.
Python 3.9-clean: no ``X | Y`` annotations.
"""

from typing import Any, Dict, List, Optional, Tuple

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator
from pydantic_core import PydanticCustomError

from shared_schema.constants import Mechanism
from shared_schema.errors import InputError
from shared_schema.rules import (
    A_P_G_MAX,
    BUILDING_HEIGHT_MAX_M,
    CRITERIA,
    F_N_RANGE,
    F_P_RANGE,
    LAM_RANGE,
    P_EQ_RANGE,
    PULSE_SHAPES,
    ROTATION_MAX,
    default_rotation_problem,
    rotation_problem,
)

__all__ = [
    "AMPLIFICATION_RANGES",
    "NUMBER",
    "PULSE_ETA_RULE",
    "PULSE_SHORT_FORM",
    "SIDE_RANGES",
    "TIME_DOMAIN_RANGES",
    "PulseRequest",
    "mechanism_problem",
]

#: A number, in JSON Schema (the rules across fields build on it).
NUMBER: Dict[str, Any] = {"type": "number"}

#: Plausible ``p_eq`` [rad/s] and ``lam`` [-] of every side, for time-domain work (the ranges
#: of a pulse request): an envelope's ``Omega = 2 pi f_p / p_eq`` and a time history's steps
#: stay finite. Derived from a physical form they are checked by the service alone.
TIME_DOMAIN_RANGES: Dict[str, Tuple[float, float]] = {"p_eq": P_EQ_RANGE, "lam": LAM_RANGE}
#: Plausible amplification data of a mechanism for time-domain work, as ``/scale-factor``
#: takes them: ``f_n`` [Hz] in ``F_N_RANGE`` (``T_n = 1/f_n`` and ``f_p/f_n`` stay finite),
#: heights ``h`` and ``h_e`` [m] at most ``BUILDING_HEIGHT_MAX_M``.
AMPLIFICATION_RANGES: Dict[str, Tuple[float, float]] = {
    "f_n": F_N_RANGE,
    "h": (0.0, BUILDING_HEIGHT_MAX_M),
    "h_e": (0.0, BUILDING_HEIGHT_MAX_M),
}

#: The ranges of a side's constants, as a JSON Schema fragment.
SIDE_RANGES: Dict[str, Any] = {
    "properties": {
        key: {"minimum": lo, "maximum": hi} for key, (lo, hi) in TIME_DOMAIN_RANGES.items()
    }
}


#: The keys of a pulse's short form: a symmetric mechanism given by its constants.
PULSE_SHORT_FORM = ("p_eq", "lam", "eta", "phi_ov", "one_sided")

#: A short form's overturning rotation, given or defaulted to lam, is at most pi/2 (as in a
#: constants file's side; issue #36).
_SHORT_ROTATION: List[Dict[str, Any]] = [
    {"properties": {"phi_ov": {"type": "number"}}, "required": ["phi_ov"]},
    {"properties": {"phi_ov": {"type": "null"}, "lam": {"maximum": ROTATION_MAX}}},
]

#: A pulse's mechanism: the short form (``p_eq``, ``lam`` and ``eta``: in [0, 1] for
#: two-sided rocking, in [-1, 0] for one-sided), or ``mechanism`` (one mechanism of a
#: constants file, with ``eta`` and each side's ``p_eq`` and ``lam`` in the ranges of a
#: pulse), never both.
PULSE_ETA_RULE: Dict[str, Any] = {
    "oneOf": [
        {
            "properties": {
                "p_eq": NUMBER,
                "lam": NUMBER,
                "one_sided": {"const": False},
                "eta": {**NUMBER, "minimum": 0, "maximum": 1},
                "mechanism": {"type": "null"},
            },
            "required": ["p_eq", "lam", "eta"],
            "anyOf": _SHORT_ROTATION,
        },
        {
            "properties": {
                "p_eq": NUMBER,
                "lam": NUMBER,
                "one_sided": {"const": True},
                "eta": {**NUMBER, "minimum": -1, "maximum": 0},
                "mechanism": {"type": "null"},
            },
            "required": ["p_eq", "lam", "eta", "one_sided"],
            "anyOf": _SHORT_ROTATION,
        },
        {
            "properties": {
                **{key: {"type": "null"} for key in PULSE_SHORT_FORM if key != "one_sided"},
                "one_sided": {"const": False},
                "mechanism": {
                    "type": "object",
                    "properties": {
                        "eta": NUMBER,
                        **SIDE_RANGES["properties"],
                        "positive": SIDE_RANGES,
                        "negative": SIDE_RANGES,
                    },
                    "required": ["eta"],
                },
            },
            "required": ["mechanism"],
        },
    ]
}


def mechanism_problem(mech: Mechanism, amplification: bool = True) -> Optional[Tuple[str, str]]:
    """Return ``(field, message)`` of a mechanism's first value out of its time-domain range.

    The ranges: ``AMPLIFICATION_RANGES`` of its amplification data (unless not
    ``amplification``), then ``TIME_DOMAIN_RANGES`` of each side; ``field`` is relative to
    the mechanism (``positive.p_eq``).
    """
    parts = (
        ("amplification", AMPLIFICATION_RANGES if amplification else {}, "a scale factor"),
        ("positive", TIME_DOMAIN_RANGES, "a pulse"),
        ("negative", TIME_DOMAIN_RANGES, "a pulse"),
    )
    for part, ranges, like in parts:
        data = getattr(mech, part)
        for key, (lo, hi) in [] if data is None else ranges.items():
            value = getattr(data, key)
            if not lo <= value <= hi:
                return (
                    f"{part}.{key}",
                    f"must be in [{lo:g}, {hi:g}] for a time-domain analysis (a plausible "
                    f"range, as for {like}), got {value!r} (mechanism {mech.id!r})",
                )
    return None


class PulseRequest(BaseModel):
    """One mechanism under a one-cycle sine or cosine pulse (``rockmech pulse``).

    The one pulse request of every front end: the command line, REST ``/pulse``, Hops, the
    Rhino and Grasshopper flows and the Python API build it, and
    ``solver_service.workflows.documents.solve_pulse`` runs it. The mechanism is given
    either in the short form, ``p_eq``, ``lam`` (and ``phi_ov``, ``eta``, ``one_sided``): a
    symmetric mechanism; or as ``mechanism``, one mechanism of a kinematic-constants file
    whose two sides and impact directions may differ (``PULSE_ETA_RULE``). The pulse acts at
    the mechanism's base: amplification data of the mechanism are not applied.
    """

    model_config = ConfigDict(
        strict=True, extra="forbid", allow_inf_nan=False, json_schema_extra=PULSE_ETA_RULE
    )

    p_eq: Optional[float] = Field(
        None,
        description=f"Frequency parameter p_eq [rad/s], in [{P_EQ_RANGE[0]:g}, "
        f"{P_EQ_RANGE[1]:g}] (blocks of half-diagonal 74 km down to 7 µm); short form.",
        json_schema_extra={"minimum": P_EQ_RANGE[0], "maximum": P_EQ_RANGE[1]},
    )
    lam: Optional[float] = Field(
        None,
        description=f"Static load multiplier lambda [-], in [{LAM_RANGE[0]:g}, "
        f"{LAM_RANGE[1]:g}]; short form.",
        json_schema_extra={"minimum": LAM_RANGE[0], "maximum": LAM_RANGE[1]},
    )
    a_p_g: float = Field(
        description=f"Signed pulse amplitude [g], in [{-A_P_G_MAX:g}, {A_P_G_MAX:g}]; > 0 "
        "first pushes towards negative rotation (Housner's convention), < 0 first opens the "
        "mechanism.",
        json_schema_extra={"minimum": -A_P_G_MAX, "maximum": A_P_G_MAX},
    )
    f_p: float = Field(
        description=f"Pulse frequency [Hz], in [{F_P_RANGE[0]:g}, {F_P_RANGE[1]:g}] (pulses "
        "of 1000 s down to 1 ms).",
        json_schema_extra={"minimum": F_P_RANGE[0], "maximum": F_P_RANGE[1]},
    )
    eta: Optional[float] = Field(
        None,
        description="Coefficient of restitution [-], in [0, 1] two-sided, [-1, 0] one-sided; "
        "short form (required there).",
        json_schema_extra={"minimum": -1, "maximum": 1},
    )
    one_sided: bool = Field(False, description="One-sided rocking; short form.")
    phi_ov: Optional[float] = Field(
        None,
        description=f"Overturning rotation [rad], in (0, pi/2 = {ROTATION_MAX:.5g}] (a rocking "
        "body on its side; degrees are refused); defaults to lambda, which must then be at "
        "most pi/2; short form.",
        json_schema_extra={"exclusiveMinimum": 0, "maximum": ROTATION_MAX},
    )
    mechanism: Optional[Mechanism] = Field(
        None,
        description="One mechanism of a kinematic-constants file instead of the short form: "
        "its sides (each side's p_eq and lam, given or derived, in the ranges above), eta "
        "(required) and the restitution of each impact direction.",
    )
    shape: str = Field(
        "sine", description="Pulse shape.", json_schema_extra={"enum": list(PULSE_SHAPES)}
    )
    criterion: Optional[str] = Field(
        None,
        description="Overturning verdict: exact (default for pulses) or ratio.",
        json_schema_extra={"enum": [*CRITERIA, None]},
    )

    @field_validator("p_eq", "lam", "f_p", "a_p_g")
    @classmethod
    def _plausible(cls, value: Optional[float], info: Any) -> Optional[float]:
        # Zero and negative values get the command line's message (the solver's check);
        # the others the plausible range of shared_schema.rules.
        name = info.field_name
        if value is None:
            return value
        lo, hi = _PULSE_RANGES[name]
        if name != "a_p_g" and not value > 0:
            raise ValueError(f"must be finite and > 0, got {value!r}")
        if not lo <= value <= hi:
            raise ValueError(f"must be in [{lo:g}, {hi:g}] (a plausible range), got {value!r}")
        return value

    @field_validator("phi_ov")
    @classmethod
    def _rotation(cls, value: Optional[float]) -> Optional[float]:
        # issue #36: phi_ov = 10 rad (degrees?) was taken, as a constants file refuses it.
        problem = None if value is None else rotation_problem(value)
        if problem is not None:
            raise PydanticCustomError("rotation_too_large", "{message}", {"message": problem})
        return value

    @model_validator(mode="after")
    def _one_form(self) -> "PulseRequest":
        if self.mechanism is None:
            for key in ("p_eq", "lam"):
                if getattr(self, key) is None:
                    raise InputError(
                        "required, unless the mechanism is given (mechanism; on the command "
                        "line --constants)",
                        key,
                    )
            assert self.lam is not None
            rotation = None if self.phi_ov is not None else default_rotation_problem(self.lam)
            if rotation is not None:
                raise InputError(rotation, "lam")
            return self
        for key in PULSE_SHORT_FORM:
            if getattr(self, key) not in (None, False):
                raise InputError(
                    "give the mechanism's constants either in the short form (p_eq, lam, "
                    "eta, phi_ov, one_sided) or as mechanism, not both",
                    key,
                )
        problem = mechanism_problem(self.mechanism, amplification=False)
        if problem is not None:
            raise PydanticCustomError(
                "implausible_constant",
                "{message}",
                {"field": f"mechanism.{problem[0]}", "message": problem[1]},
            )
        return self

    @property
    def p_eq_max(self) -> Optional[float]:
        """The larger ``p_eq`` of the mechanism's sides [rad/s] (it sets the work), or None."""
        if self.mechanism is None:
            return self.p_eq
        sides = (self.mechanism.positive, self.mechanism.negative)
        values = [side.p_eq for side in sides if side is not None and side.p_eq is not None]
        return max(values) if values else None


#: (lowest, highest) of each number of a pulse request (shared_schema.rules).
_PULSE_RANGES: Dict[str, Tuple[float, float]] = {
    "p_eq": P_EQ_RANGE,
    "lam": LAM_RANGE,
    "f_p": F_P_RANGE,
    "a_p_g": (-A_P_G_MAX, A_P_G_MAX),
}
