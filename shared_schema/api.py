"""Request and response models of the rockmech REST service (``/api/v1``).

Requests are strict: a boolean is not a number, a string is not a number, NaN and infinity
are refused, and unknown keys are errors. Range checks that the command line also makes
(``p_eq > 0``, ``eta`` in [-1, 1], ...) are left to the solver, so that the service gives the
same message as ``rockmech``; their limits are still stated in the published schema.

The analyses answer with their documents, the models of ``shared_schema.documents`` (what
``rockmech ... --json`` prints; the routes declare them as ``response_model``). Optional
sections that do not apply are absent, not ``null``; a number is ``null`` only where its
value is not finite (an overflow on extreme inputs, or "none up to the search limit").
The responses left here: errors, health and the scale factor (the search's document is
``shared_schema.documents.search.SearchDocument``).

The published schema states every rule JSON Schema can state, so that clients learn them
from the contract: the ranges of ``shared_schema.rules``, the options' bounds, and the rules
across fields that ``oneOf``/``anyOf`` can say (``PULSE_ETA_RULE``, ``EQ28_RULE``,
``RECORD_SAMPLE_RULE``, ``REPORT_RECORD_RULE``, the constants file's own). Requests that
work in the time domain (``/envelope``, ``/history``, ``/report``, ``/assess``) also bound
the constants by plausible ranges (``TIME_DOMAIN_RANGES``, ``AMPLIFICATION_RANGES``): stated
for the values a file gives, enforced for the derived ones too (``time_domain_problem``),
so that no derived value (``Omega = 2 pi f_p / p_eq``, ``T_n = 1/f_n``) overflows. Integer
fields take a number without a fractional part (``100.0``), as JSON Schema's ``integer``.

Units are SI, except where a name says otherwise (``a_p_g`` and ``pga_g`` are in g).
Python 3.9-clean: no ``X | Y`` annotations.
"""

import math
from typing import Annotated, Any, Dict, List, Literal, Optional, Tuple, Union

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator
from pydantic_core import PydanticCustomError

from shared_schema.constants import ConstantsFile, JsonInt
from shared_schema.errors import InputError
from shared_schema.pulse_request import (
    AMPLIFICATION_RANGES,
    NUMBER,
    PULSE_ETA_RULE,
    PULSE_SHORT_FORM,
    SIDE_RANGES,
    TIME_DOMAIN_RANGES,
    PulseRequest,
    mechanism_problem,
)
from shared_schema.retrofit import RetrofitDoc, RetrofitSpec
from shared_schema.rules import (
    ACCEL_MAX_G,
    ACCEL_MIN,
    BUILDING_HEIGHT_MAX_M,
    CRITERIA,
    DT_RANGE_S,
    ENVELOPE_METHODS,
    F_N_RANGE,
    F_P_RANGE,
    LAM_RANGE,
    LENGTH_UNITS,
    P_EQ_RANGE,
    RECORD_FORMATS,
    RECORD_UNITS,
    SF_METHODS,
    accel_max,
    check_choice,
)
from shared_schema.site import SiteFile

__all__ = [
    "ASSESS_FORMATS",
    "EQ28_RULE",
    "MAX_ASSESS_MULTIPLES",
    "MAX_ASSESS_RECORDS",
    "MULTIPLE_MAX",
    "PULSE_ETA_RULE",
    "PULSE_SHORT_FORM",
    "RECORD_SAMPLE_RULE",
    "RECORD_UNITS",
    "REPORT_RECORD_RULE",
    "SEARCH_MAX_EVALUATIONS",
    "TIME_DOMAIN_RANGES",
    "AssessRequest",
    "BuildingOptions",
    "CheckRequest",
    "ConstantsForm",
    "ConstantsResponse",
    "Ec8Request",
    "EnvelopeRequest",
    "Eq28Request",
    "ErrorResponse",
    "HealthResponse",
    "HistoryForm",
    "HistoryOptions",
    "HistoryRequest",
    "NzsRequest",
    "PulseRequest",
    "RecordFileOptions",
    "RecordSamples",
    "ReportForm",
    "ReportOptions",
    "ReportRequest",
    "RetrofitForm",
    "RetrofitRequest",
    "RetrofitResponse",
    "ScaleFactorRequest",
    "ScaleFactorResponse",
    "SearchForm",
    "SpectrumForm",
    "SpectrumOptions",
    "SpectrumRequest",
    "mechanism_problem",
    "time_domain_problem",
]


_REQUEST = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False)
_RESPONSE = ConfigDict(extra="allow")


def _gt0(description: str) -> Any:
    return Field(description=description, json_schema_extra={"exclusiveMinimum": 0})


def _gt0_default(default: Optional[float], description: str) -> Any:
    return Field(default, description=description, json_schema_extra={"exclusiveMinimum": 0})


def _height(description: str, *, positive: bool = True, below: str = "") -> Any:
    """Return a height field [m]: > 0 (>= 0 unless ``positive``), <= ``BUILDING_HEIGHT_MAX_M``.

    ``below`` names a height it may not exceed either (a rule across fields, told in words).
    """
    low = ("> 0" if positive else ">= 0") + (f", at most {below}" if below else "")
    bounds: Dict[str, Any] = {
        "exclusiveMinimum" if positive else "minimum": 0,
        "maximum": BUILDING_HEIGHT_MAX_M,
    }
    return Field(
        description=f"{description} [m], {low} and at most {BUILDING_HEIGHT_MAX_M:g} m "
        "(taller than any building).",
        json_schema_extra=bounds,
    )


# --- rules across fields, stated in the schema ------------------------------------------------
# The service enforces these in the solver, with the messages ``rockmech`` prints; the schema
# states them too (``oneOf``), so that clients learn them from the contract.


#: Eq. 28 from S_a and PGA, or from a record and f_n, never both.
EQ28_RULE: Dict[str, Any] = {
    "oneOf": [
        {
            "properties": {
                "sa_g": {**NUMBER, "minimum": 0},
                "pga_g": {**NUMBER, "exclusiveMinimum": 0},
                "record": {"type": "null"},
                "f_n": {"type": "null"},
            },
            "required": ["sa_g", "pga_g"],
        },
        {
            "properties": {
                "record": {
                    "type": "object",
                    # A peak ground acceleration: a sample of magnitude ACCEL_MIN at least.
                    "properties": {
                        "accel": {
                            "contains": {"anyOf": [{"minimum": ACCEL_MIN}, {"maximum": -ACCEL_MIN}]}
                        }
                    },
                },
                "f_n": {**NUMBER, "minimum": F_N_RANGE[0], "maximum": F_N_RANGE[1]},
                "sa_g": {"type": "null"},
                "pga_g": {"type": "null"},
            },
            "required": ["record", "f_n"],
        },
    ]
}

#: A record's samples are at most ``ACCEL_MAX_G`` in magnitude, stated in its own units.
RECORD_SAMPLE_RULE: Dict[str, Any] = {
    "oneOf": [
        {
            "properties": {
                "units": {"const": units},
                "accel": {"items": {**NUMBER, "minimum": -top, "maximum": top}},
            }
        }
        for units, top in ((u, accel_max(u)) for u in RECORD_UNITS)
    ]
}

#: Time-domain work (envelopes, time histories) needs ``eta`` for every two-sided mechanism.
_TWO_SIDED_ETA: Dict[str, Any] = {
    "properties": {
        "mechanisms": {
            "items": {
                "anyOf": [
                    {"properties": {"rocking": {"const": "one_sided"}}, "required": ["rocking"]},
                    {"properties": {"eta": NUMBER}, "required": ["eta"]},
                ]
            }
        }
    }
}


_PLAUSIBLE_SIDES: Dict[str, Any] = {
    "properties": {
        "mechanisms": {
            "items": {
                "properties": {
                    **SIDE_RANGES["properties"],
                    "positive": SIDE_RANGES,
                    "negative": SIDE_RANGES,
                    "amplification": {
                        "properties": {
                            key: {"minimum": lo, "maximum": hi}
                            for key, (lo, hi) in AMPLIFICATION_RANGES.items()
                        }
                    },
                }
            }
        }
    }
}


#: What the constants of a time-domain request need, in words.
_TIME_DOMAIN_CONSTANTS = (
    "The kinematic-constants file; each side's p_eq [rad/s] and lam [-] (given or derived) "
    f"in the ranges of a pulse, [{P_EQ_RANGE[0]:g}, {P_EQ_RANGE[1]:g}] and "
    f"[{LAM_RANGE[0]:g}, {LAM_RANGE[1]:g}]; amplification f_n in [{F_N_RANGE[0]:g}, "
    f"{F_N_RANGE[1]:g}] Hz, h and h_e at most {BUILDING_HEIGHT_MAX_M:g} m; eta for every "
    "two-sided mechanism."
)


#: What the constants of an assessment need, in words (a mechanism without eta gets its
#: code checks and a note instead of time histories).
_ASSESS_CONSTANTS = _TIME_DOMAIN_CONSTANTS.replace("; eta for every two-sided mechanism", "")


def _constants_need_eta(schema: Dict[str, Any]) -> None:
    """State in the schema what time-domain constants need: ``eta``, plausible values."""
    prop = schema["properties"]["constants"]
    schema["properties"]["constants"] = {"allOf": [prop, _TWO_SIDED_ETA, _PLAUSIBLE_SIDES]}


#: Time histories run the mechanisms that give ``eta`` (the others get a note): one at least.
_SOME_ETA: Dict[str, Any] = {
    "properties": {"mechanisms": {"contains": {"properties": {"eta": NUMBER}, "required": ["eta"]}}}
}


def _history_schema(schema: Dict[str, Any]) -> None:
    """State what the constants of time histories need: ``_constants_need_eta``, one ``eta``."""
    _constants_need_eta(schema)
    schema["properties"]["constants"]["allOf"].append(_SOME_ETA)


def _plausible_constants(schema: Dict[str, Any]) -> None:
    """State in the schema the plausible values of an assessment's constants (eta optional)."""
    prop = schema["properties"]["constants"]
    schema["properties"]["constants"] = {"allOf": [prop, _PLAUSIBLE_SIDES]}


def time_domain_problem(cf: ConstantsFile) -> Optional[Tuple[str, str]]:
    """Return ``(field, message)`` of the first value out of its time-domain range, or None.

    The ranges: ``AMPLIFICATION_RANGES`` of a mechanism's amplification data, then
    ``TIME_DOMAIN_RANGES`` of each side.

    Parameters
    ----------
    cf : ConstantsFile
        A validated file (derived ``p_eq`` and ``lam`` filled in).

    Examples
    --------
    >>> cf = ConstantsFile.model_validate({"mechanisms": [{"id": "W", "p_eq": 2e3, "lam": 0.2}]})
    >>> time_domain_problem(cf)[0]
    'mechanisms[0].positive.p_eq'
    """
    for i, mech in enumerate(cf.mechanisms):
        problem = mechanism_problem(mech)
        if problem is not None:
            return f"mechanisms[{i}].{problem[0]}", problem[1]
    return None


def _time_domain_constants(cls: Any, cf: ConstantsFile) -> ConstantsFile:
    problem = time_domain_problem(cf)
    if problem is not None:
        raise PydanticCustomError(
            "implausible_constant", "{message}", {"field": problem[0], "message": problem[1]}
        )
    return cf


def _frequency(description: str, default: float, rule: str = "") -> Any:
    """Return a pulse frequency field [Hz], in ``F_P_RANGE`` (and ``rule``, told in words)."""
    lo, hi = F_P_RANGE
    return Field(
        default,
        description=f"{description} [Hz], {rule}in [{lo:g}, {hi:g}] (pulses of 1000 s down "
        "to 1 ms).",
        json_schema_extra={"minimum": lo, "maximum": hi},
    )


def _in_f_p_range(cls: Any, value: float, info: Any) -> float:
    lo, hi = F_P_RANGE
    if not (math.isfinite(value) and value > 0):
        # The command line's message (documents.log_grid).
        raise ValueError(f"must be finite and > 0, got {value!r}")
    if not lo <= value <= hi:
        raise ValueError(f"must be in [{lo:g}, {hi:g}] Hz (a plausible range), got {value!r}")
    return value


def _envelope_method(cls: Any, value: str) -> str:
    return check_choice(value, ENVELOPE_METHODS, "method")


# --- requests ---------------------------------------------------------------------------------


class RecordSamples(BaseModel):
    """A ground-acceleration record given as samples at a uniform time step."""

    model_config = ConfigDict(
        strict=True, extra="forbid", allow_inf_nan=False, json_schema_extra=RECORD_SAMPLE_RULE
    )

    accel: List[float] = Field(
        min_length=2,
        description="Acceleration samples, in `units`, at a uniform step `dt`; each of "
        f"magnitude at most {ACCEL_MAX_G:g} g in those units ("
        + ", ".join(f"{accel_max(u):.6g} {u}" for u in RECORD_UNITS)
        + ").",
    )
    dt: float = Field(
        description=f"Time step [s], in [{DT_RANGE_S[0]:g}, {DT_RANGE_S[1]:g}] (an "
        "accelerograph samples at 1 MHz at most and once a second at least).",
        json_schema_extra={"minimum": DT_RANGE_S[0], "maximum": DT_RANGE_S[1]},
    )
    units: str = Field(
        description="Units of `accel`.", json_schema_extra={"enum": list(RECORD_UNITS)}
    )
    name: str = Field(
        "record", min_length=1, max_length=200, description="Name used in results and reports."
    )

    @field_validator("units")
    @classmethod
    def _known_units(cls, units: str) -> str:
        return check_choice(units, tuple(RECORD_UNITS), "units")


class EnvelopeRequest(BaseModel):
    """Overturning envelopes of every mechanism and the critical bands (``rockmech envelope``)."""

    model_config = ConfigDict(
        strict=True, extra="forbid", allow_inf_nan=False, json_schema_extra=_constants_need_eta
    )

    constants: ConstantsFile = Field(description=_TIME_DOMAIN_CONSTANTS)
    f_min: float = _frequency("Lowest pulse frequency", 0.1)
    f_max: float = _frequency("Highest pulse frequency", 10.0, "> f_min, ")
    n: JsonInt = Field(
        200, description="Number of log-spaced frequencies, >= 2.", json_schema_extra={"minimum": 2}
    )
    method: str = Field(
        "exact",
        description="How the envelopes are computed: exact (the exact integrator at every "
        "frequency) or library (the fast mode: interpolated, exact where the library cannot "
        "interpolate safely; never above the exact value, at most 5 % below).",
        json_schema_extra={"enum": list(ENVELOPE_METHODS)},
    )

    _plausible = field_validator("constants")(classmethod(_time_domain_constants))
    _frequencies = field_validator("f_min", "f_max")(classmethod(_in_f_p_range))
    _method = field_validator("method")(classmethod(_envelope_method))


class BuildingOptions(BaseModel):
    """Code scale factors and displacements of time histories (``rockmech history``)."""

    building_height: Optional[float] = Field(
        None,
        description="Height of the building H = h_n [m] (sf ec8 and nzs), > 0 and at most "
        f"{BUILDING_HEIGHT_MAX_M:g} m.",
        json_schema_extra={"exclusiveMinimum": 0, "maximum": BUILDING_HEIGHT_MAX_M},
    )
    soil_factor: float = Field(
        1.0, description="EC8 soil factor S [-], > 0.", json_schema_extra={"exclusiveMinimum": 0}
    )
    element_period: float = Field(
        0.0,
        description="EC8 period of the element T_a [s], >= 0; 0 = rigid.",
        json_schema_extra={"minimum": 0},
    )
    at_height: Optional[float] = Field(
        None,
        description="Also report the peak displacement [m] of a point this far [m] above each "
        "mechanism's rotation axis, > 0.",
        json_schema_extra={"exclusiveMinimum": 0},
    )


class HistoryOptions(BuildingOptions):
    """Scale factors and verdict of time histories (``rockmech history``)."""

    scales: List[float] = Field(
        [1.0],
        min_length=1,
        description="Scale factors on the record [-], each > 0.",
        json_schema_extra={"items": {"type": "number", "exclusiveMinimum": 0}},
    )
    sf: str = Field(
        "none",
        description="Scale factor up the structure for mechanisms with amplification data: "
        "none; eq28 (from the record's 5 % spectrum at T_n = 1/f_n); ec8 (EN 1998-1 "
        "§4.3.5.2) or nzs (NZS 1170.5 C_Hi), both with building_height.",
        json_schema_extra={"enum": list(SF_METHODS)},
    )
    criterion: Optional[str] = Field(
        None,
        description="Overturning verdict: ratio (default for records) or exact.",
        json_schema_extra={"enum": [*CRITERIA, None]},
    )


class ReportOptions(HistoryOptions):
    """Envelope options and title of a report (``rockmech report``)."""

    f_min: float = _frequency("Lowest pulse frequency of the envelopes", 0.1)
    f_max: float = _frequency("Highest pulse frequency of the envelopes", 10.0, "> f_min, ")
    n: JsonInt = Field(
        200,
        description="Number of log-spaced envelope frequencies, >= 2.",
        json_schema_extra={"minimum": 2},
    )
    method: str = Field(
        "exact",
        description="How the envelopes are computed: exact, or library (the fast mode).",
        json_schema_extra={"enum": list(ENVELOPE_METHODS)},
    )
    title: Optional[str] = Field(None, max_length=200, description="Title of the report.")

    _frequencies = field_validator("f_min", "f_max")(classmethod(_in_f_p_range))
    _method = field_validator("method")(classmethod(_envelope_method))


class HistoryRequest(HistoryOptions):
    """Time histories of every mechanism at every scale factor (``rockmech history``)."""

    model_config = ConfigDict(
        strict=True, extra="forbid", allow_inf_nan=False, json_schema_extra=_history_schema
    )

    constants: ConstantsFile = Field(description=_TIME_DOMAIN_CONSTANTS)
    record: RecordSamples = Field(description="The ground motion.")

    _plausible = field_validator("constants")(classmethod(_time_domain_constants))


class SpectrumOptions(BaseModel):
    """Spectrum and pulse-search options (``rockmech record``)."""

    zeta: float = Field(
        0.05,
        description="Damping ratio of the spectrum [-], in [0, 1).",
        json_schema_extra={"minimum": 0, "exclusiveMaximum": 1},
    )
    t_min: float = _gt0_default(0.02, "Shortest period of the spectrum [s], > 0.")
    t_max: float = _gt0_default(10.0, "Longest period of the spectrum [s], > t_min.")
    n: JsonInt = Field(
        100, description="Number of log-spaced periods, >= 2.", json_schema_extra={"minimum": 2}
    )
    pulses: JsonInt = Field(
        5,
        description="How many of the largest sine pulses to list, >= 1.",
        json_schema_extra={"minimum": 1},
    )
    f_min: Optional[float] = _gt0_default(None, "Pulse search: lowest f_p [Hz], > 0.")
    f_max: Optional[float] = _gt0_default(None, "Pulse search: highest f_p [Hz], >= f_min.")


class SpectrumRequest(SpectrumOptions):
    """A record's exact elastic response spectrum and largest sine pulses (``rockmech record``)."""

    model_config = _REQUEST

    record: RecordSamples = Field(description="The ground motion.")


class Eq28Request(BaseModel):
    """Eq. 28 scale factor ``sqrt(1 + (S_a/a_g h/h_e)^2)``: from S_a and PGA, or from a record."""

    model_config = ConfigDict(
        strict=True, extra="forbid", allow_inf_nan=False, json_schema_extra=EQ28_RULE
    )

    method: Literal["eq28"]
    h: float = _height("Height of the mechanism", positive=False)
    h_e: float = _height("Effective (modal) height of the structure")
    sa_g: Optional[float] = Field(None, description="Spectral acceleration S_a(T_n) [g], >= 0.")
    pga_g: Optional[float] = Field(None, description="Peak ground acceleration [g], > 0.")
    record: Optional[RecordSamples] = Field(
        None,
        description="A record instead of sa_g and pga_g (needs f_n); one sample at least "
        f"must be of magnitude {ACCEL_MIN:g} or more, in its units (a peak ground "
        "acceleration).",
    )
    f_n: Optional[float] = Field(
        None,
        description=f"Natural frequency of the structure [Hz], in [{F_N_RANGE[0]:g}, "
        f"{F_N_RANGE[1]:g}] (periods of 1000 s down to 1 ms; with record).",
    )

    @model_validator(mode="after")
    def _record_has_a_pga(self) -> "Eq28Request":
        if self.record is not None and not any(abs(a) >= ACCEL_MIN for a in self.record.accel):
            raise InputError(
                f"needs a sample of magnitude {ACCEL_MIN:g} at least (a peak ground "
                "acceleration) for Eq. 28",
                "record.accel",
            )
        return self


class Ec8Request(BaseModel):
    """EN 1998-1 §4.3.5.2 amplification for an element at height z."""

    model_config = _REQUEST

    method: Literal["ec8"]
    z: float = _height("Height of the element above the foundation", positive=False, below="H")
    H: float = _height("Height of the building")
    T_a: float = Field(
        description="Fundamental period of the element [s], >= 0.",
        json_schema_extra={"minimum": 0},
    )
    T_1: float = _gt0("Fundamental period of the building [s], > 0.")
    S: float = Field(
        1.0, description="Soil factor [-], > 0.", json_schema_extra={"exclusiveMinimum": 0}
    )


class NzsRequest(BaseModel):
    """NZS 1170.5 §8.3 floor height coefficient C_Hi."""

    model_config = _REQUEST

    method: Literal["nzs"]
    h_i: float = _height("Height of the level above the base", positive=False, below="h_n")
    h_n: float = _height("Height of the top of the structure")


#: One scale-factor request, chosen by ``method``.
ScaleFactorRequest = Annotated[
    Union[Eq28Request, Ec8Request, NzsRequest], Field(discriminator="method")
]


#: The time-history options of a report keep their defaults without a record
#: (``report.html``: each acts on the time histories of a record).
REPORT_RECORD_RULE: Dict[str, Any] = {
    "anyOf": [
        {"required": ["record"], "properties": {"record": {"type": "object"}}},
        {
            "properties": {
                "scales": {"const": [1]},
                "sf": {"const": "none"},
                "building_height": {"type": "null"},
                "soil_factor": {"const": 1},
                "element_period": {"const": 0},
                "criterion": {"type": "null"},
                "at_height": {"type": "null"},
            }
        },
    ]
}


def _report_schema(schema: Dict[str, Any]) -> None:
    _constants_need_eta(schema)
    schema.update(REPORT_RECORD_RULE)
    # With a record, time histories run: one mechanism at least gives eta.
    schema["if"] = {"required": ["record"], "properties": {"record": {"type": "object"}}}
    schema["then"] = {"properties": {"constants": _SOME_ETA}}


class ReportRequest(ReportOptions):
    """An HTML report: constants, envelopes, and with a record its time histories and spectrum.

    Without a record, the time-history options (``scales``, ``sf``, the building's,
    ``criterion``, ``at_height``) keep their defaults (``REPORT_RECORD_RULE``).
    """

    model_config = ConfigDict(
        strict=True, extra="forbid", allow_inf_nan=False, json_schema_extra=_report_schema
    )

    constants: ConstantsFile = Field(description=_TIME_DOMAIN_CONSTANTS)
    record: Optional[RecordSamples] = Field(
        None, description="A ground motion for time histories and its spectrum."
    )

    _plausible = field_validator("constants")(classmethod(_time_domain_constants))


#: Most records of one assessment request.
MAX_ASSESS_RECORDS = 5
#: Most multiples of the design scale in one assessment request.
MAX_ASSESS_MULTIPLES = 8
#: Largest multiple of the design scale factor [-]: a hundred times the design earthquake.
MULTIPLE_MAX = 100.0
#: What ``/assess`` answers: the assessment document, its HTML page, or that page as PDF
#: (printed by a headless Chromium where the deployment has one; else 501 naming it).
ASSESS_FORMATS = ("json", "html", "pdf")


class CheckRequest(BaseModel):
    """Code checks of every mechanism on a site (``rockmech check``)."""

    model_config = _REQUEST

    constants: ConstantsFile = Field(
        description="The kinematic-constants file; mechanisms need each side's virtual_work "
        "for the checks (the others get a note)."
    )
    site: SiteFile = Field(description="The site file (SITE.json): hazard, FC, q, building.")


class RetrofitRequest(BaseModel):
    """Tie-bars for the mechanisms that fail the 2019 checks (``rockmech retrofit``)."""

    model_config = _REQUEST

    constants: ConstantsFile = Field(
        description="The kinematic-constants file; mechanisms need virtual_work and their "
        "geometry (hinge, centre of mass) for a tie to be put on them."
    )
    site: SiteFile = Field(description="The site file (SITE.json): hazard, FC, q, building.")
    spec: RetrofitSpec = Field(
        description="The retrofit spec: steel grade and bar diameters [mm], one tie's "
        "anchorage resistance [N] with its source, candidate tie heights per mechanism [m] "
        "(schema: shared_schema/jsonschema/retrofit.schema.json)."
    )


class AssessRequest(BaseModel):
    """Code checks beside rocking dynamics on records scaled to the site (``rockmech assess``)."""

    model_config = ConfigDict(
        strict=True, extra="forbid", allow_inf_nan=False, json_schema_extra=_plausible_constants
    )

    constants: ConstantsFile = Field(description=_ASSESS_CONSTANTS)
    site: SiteFile = Field(description="The site file (SITE.json): hazard, FC, q, building.")
    records: List[RecordSamples] = Field(
        min_length=1,
        max_length=MAX_ASSESS_RECORDS,
        description="Ground motions (1 to 5), each scaled per mechanism to the site spectrum.",
    )
    multiples: List[Annotated[float, Field(gt=0)]] = Field(
        [0.5, 1.0, 1.5, 2.0],
        min_length=1,
        max_length=MAX_ASSESS_MULTIPLES,
        description="Multiples of the design scale factor to run [-], each in (0, "
        f"{MULTIPLE_MAX:g}] (1 is the design level); at most {MAX_ASSESS_MULTIPLES}.",
        # workflows.assess enforces the top, with the command line's message.
        json_schema_extra={
            "items": {"type": "number", "exclusiveMinimum": 0, "maximum": MULTIPLE_MAX}
        },
    )
    format: Literal["json", "html", "pdf"] = Field(
        "json",
        description="Answer with the assessment document (json), its HTML page (html), or the "
        "page printed to PDF (pdf; needs a headless Chromium in the deployment, else 501).",
    )
    retrofit: Optional[RetrofitSpec] = Field(
        None,
        description="A retrofit spec, as rockmech assess --retrofit takes it: the retrofit is "
        "run on the constants, the site and the records (as rockmech retrofit --record), the "
        "document holds it under retrofit and page one shows its table; its errors name "
        "retrofit.<field> (schema: shared_schema/jsonschema/retrofit.schema.json).",
    )

    _plausible = field_validator("constants")(classmethod(_time_domain_constants))


# --- multipart forms (the text fields next to uploaded files) ---------------------------------

# Form fields arrive as text, so these models convert text to numbers (lax mode); NaN,
# infinity and unknown fields are still refused, and "true" is not a number.
_FORM = ConfigDict(strict=False, extra="forbid", allow_inf_nan=False)


class RecordFileOptions(BaseModel):
    """How to read an uploaded record file (as ``rockmech history`` options)."""

    model_config = _FORM

    format: Optional[str] = Field(
        None,
        description=f"One of {', '.join(RECORD_FORMATS)} (default: detected from the content).",
        json_schema_extra={"enum": list(RECORD_FORMATS)},
    )
    units: Optional[str] = Field(
        None,
        description=f"Acceleration units: {', '.join(RECORD_UNITS)}; files that state their "
        "units use them, two-column files default to g, other formats need it.",
        json_schema_extra={"enum": list(RECORD_UNITS)},
    )
    dt: Optional[float] = Field(
        None,
        description="Time step [s] of a record without a time column.",
        json_schema_extra={"exclusiveMinimum": 0},
    )


class HistoryForm(RecordFileOptions, HistoryOptions):
    """Multipart form of ``history``: files ``constants`` and ``record``, plus these fields."""


class SpectrumForm(RecordFileOptions, SpectrumOptions):
    """Multipart form of ``spectrum``: file ``record``, plus these fields."""


class ReportForm(RecordFileOptions, ReportOptions):
    """Multipart form of ``report``: file ``constants``, optional file ``record``, and these."""


class ConstantsForm(BaseModel):
    """Multipart form of ``constants``: files ``scene`` and ``spec`` (JSON), and ``units``.

    The scene is a Rhino ``.3dm`` file or a scan mesh (``.ply``, ``.obj``, ``.stl``, ``.off``,
    told apart by the file name); a scan needs ``units``.
    """

    model_config = _FORM

    units: Optional[str] = Field(
        None,
        description=f"Length unit of a scan mesh: {', '.join(LENGTH_UNITS)} (required there; "
        "a .3dm file states its own).",
        json_schema_extra={"enum": list(LENGTH_UNITS)},
    )

    @field_validator("units")
    @classmethod
    def _known_length_unit(cls, units: Optional[str]) -> Optional[str]:
        return None if units is None else check_choice(units, LENGTH_UNITS, "units")


#: The service's work limit of one search [evaluations of the static multiplier λ0]; a
#: request may ask for less (``solver_service.workflows.search.MAX_EVALUATIONS``, a test checks
#: the copy).
SEARCH_MAX_EVALUATIONS = 200_000


class SceneRecordFields(BaseModel):
    """How to read the optional record uploaded beside a scene (``search``, ``retrofit``)."""

    model_config = _FORM

    record_format: Optional[str] = Field(
        None,
        description=f"Format of the record: {', '.join(RECORD_FORMATS)} (default: detected).",
        json_schema_extra={"enum": list(RECORD_FORMATS)},
    )
    record_units: Optional[str] = Field(
        None,
        description=f"Acceleration units of the record: {', '.join(RECORD_UNITS)}.",
        json_schema_extra={"enum": list(RECORD_UNITS)},
    )
    record_dt: Optional[float] = Field(
        None,
        description="Time step [s] of a record without a time column.",
        json_schema_extra={"exclusiveMinimum": 0},
    )


class SearchForm(ConstantsForm, SceneRecordFields):
    """Multipart form of ``search``: files ``scene``, ``spec``, ``site``, ``record``, and fields.

    ``spec`` is the search spec (JSON); ``site`` (SITE.json) and ``record`` are optional. The
    spec's ``ranking.site`` and ``ranking.records`` (paths) are refused: upload the files.
    """

    # ``units`` (a scan mesh's length unit) and its check are ConstantsForm's.
    max_evaluations: Optional[int] = Field(
        None,
        ge=1,
        le=SEARCH_MAX_EVALUATIONS,
        description="Work limit: most evaluations of the static multiplier λ0 "
        f"(default and largest {SEARCH_MAX_EVALUATIONS}); a search that needs more is refused "
        "before it runs them.",
    )
    exact: bool = Field(False, description="Envelopes by the exact solver (not the library).")


class RetrofitForm(ConstantsForm, SceneRecordFields):
    """Multipart form of ``retrofit`` from a scene: the scene, its search spec and these fields.

    Files ``scene``, ``search_spec``, ``site``, ``spec`` (the retrofit spec) and an optional
    ``record``. As ``rockmech retrofit --scene SCENE --search-spec SPEC``: the scene is searched,
    the ties of its failing mechanisms designed, put in the scene, and the scene searched again.
    The search spec's ``ranking.site`` and ``ranking.records`` are not read (the uploaded
    site and record are the retrofit's, as on the command line).
    """

    # ``units`` (a scan mesh's length unit) and its check are ConstantsForm's.
    max_evaluations: Optional[int] = Field(
        None,
        ge=1,
        le=SEARCH_MAX_EVALUATIONS,
        description="Work limit of the searches together (the scene, the scene with the "
        "designed ties, and one per connection upgrade and one with them all): most "
        f"evaluations of the static multiplier λ0 (default and largest {SEARCH_MAX_EVALUATIONS}"
        "); the search's work estimate counts once per search, and a retrofit past the limit "
        "is refused before any search runs; each search may use its share.",
    )


# --- responses --------------------------------------------------------------------------------


class ErrorResponse(BaseModel):
    """An error: the message ``rockmech`` would print after ``error:``."""

    detail: str = Field(description="What is wrong, naming the field or file.")
    field: Optional[str] = Field(None, description="Path of the offending field, when known.")
    error: str = Field(description="Kind of error, e.g. InputError or BudgetExceeded.")


class HealthResponse(BaseModel):
    """Service status."""

    status: Literal["ok", "starting"] = Field(
        description="ok: every compute process has warmed up; starting: not yet (HTTP 503)."
    )
    version: str = Field(description="rockmech version.")
    rockmech_version: str = Field(description="rockmech version (as every document names it).")
    units: Dict[str, str] = Field(description="Units of the quantities.")
    compute_workers: int = Field(description="Compute processes ready or busy.")
    compute_timeout_s: float = Field(description="Compute time budget per request [s].")


class ScaleFactorResponse(BaseModel):
    """A scale factor with its method, formula and inputs."""

    model_config = _RESPONSE

    value: Optional[float]
    method: str
    formula: str
    inputs: Dict[str, Optional[float]]


#: The retrofit endpoint answers with the retrofit document (``retrofit.json``).
RetrofitResponse = RetrofitDoc

#: The constants endpoint answers with a kinematic-constants file.
ConstantsResponse = ConstantsFile
