"""The site file (SITE.json): project, seismic hazard, check parameters and the building.

The hazard is given by the building code that defines it:

* ``"NTC2018"`` (Italy, NTC 2018 §3.2.3): ``a_g`` [g], ``F0``, ``Tc_star`` [s] for the limit
  state, the soil category A-E and the topographic category T1-T4;
* ``"EC8"`` (EN 1998-1 §3.2.2.2): ``a_gR`` [g], the importance factor, the ground type A-E
  and the spectrum type 1 or 2.

Both carry the parameters of the code's kinematic check (docs/theory.md §11): the
knowledge-level confidence factor ``FC`` and the behaviour factor ``q`` (default 2), and may
give the hazard of other limit states (``limit_states``: SLD, SLC). The optional
``building`` section (height, storeys, first period, damping, period lengthening) serves the
demand on mechanisms above ground; the optional ``local_mechanisms`` section holds the
choices the Circolare 2019 leaves to the engineer (method, damping of the mechanisms, the
free-standing elements' data, the ties); the optional ``project`` section fills the
report's first page.

The models run on CPython 3.9 inside Rhino 8, so annotations use the ``typing`` forms.
"""

from typing import Annotated, Any, Dict, Literal, Mapping, Optional, Tuple, Union

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    model_validator,
)
from pydantic_core import PydanticCustomError

from shared_schema.constants import (
    JsonInt,
    SchemaVersion,
    schema_version_field,
    validate_document,
    whole_number,
)
from shared_schema.errors import InputError
from shared_schema.rules import BEHAVIOUR_FACTOR_RANGE, DAMPING_PERCENT_RANGE, range_problem
from shared_schema.text import decode_text

__all__ = [
    "LIMIT_STATES",
    "SITE_EXPECTED",
    "SITE_SCHEMA_VERSION",
    "Building",
    "EC8Hazard",
    "EC8LimitState",
    "LocalMechanisms",
    "MechanismOptions",
    "NTCHazard",
    "NTCLimitState",
    "Project",
    "SiteFile",
    "parse_site",
    "read_site",
    "site_from_text",
]

#: The limit states of NTC 2018 §3.2.1 (Tab. 3.2.I), by which the hazard is given.
LIMIT_STATES = ("SLO", "SLD", "SLV", "SLC")
LimitState = Literal["SLO", "SLD", "SLV", "SLC"]


def _no_duplicate_limit_state(main: str, others: Optional[Mapping[Any, Any]]) -> None:
    """Refuse ``limit_states`` repeating the limit state the main hazard already gives."""
    if others and main in others:
        raise PydanticCustomError(
            "duplicate_limit_state",
            "{message}",
            {
                "field": f"limit_states.{main}",
                "message": (
                    f"the hazard's own parameters are the {main} ones; give limit_states "
                    "only for the other limit states"
                ),
            },
        )


class NTCLimitState(BaseModel):
    """NTC 2018 hazard parameters of one more limit state (§3.2, Tab. 3.2.I).

    The soil and topographic categories are the site's (``NTCHazard``).
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={"description": "a_g, F0, T_C* of one more limit state (NTC 2018)."},
    )

    a_g: float = Field(gt=0, le=2, description="Ground acceleration on type A ground [g].")
    F0: float = Field(gt=0, le=10, description="Maximum spectral amplification F0 [-].")
    Tc_star: float = Field(gt=0, le=5, description="T_C* [s].")


class EC8LimitState(BaseModel):
    """EN 1998-1 reference ground acceleration of one more limit state (return period)."""

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={"description": "a_gR of one more limit state (EN 1998-1)."},
    )

    a_gR: float = Field(gt=0, le=2, description="Reference peak ground acceleration [g].")


#: Version of the site-file format written by this module.
SITE_SCHEMA_VERSION = "1.0"


def _in_range(bounds: Tuple[float, float], unit: str, why: str) -> Any:
    """Return a check that a number lies in ``bounds``, telling the range and ``why``."""

    def check(value: float) -> float:
        problem = range_problem(value, bounds, unit, why)
        if problem is not None:
            raise PydanticCustomError("out_of_range", "{message}", {"message": problem})
        return value

    return AfterValidator(check)


#: The behaviour factor ``q`` [-] in ``rules.BEHAVIOUR_FACTOR_RANGE`` (#25: 0.5 was taken).
BehaviourFactor = Annotated[
    float,
    _in_range(
        BEHAVIOUR_FACTOR_RANGE,
        "",
        "the behaviour factor divides the elastic demand (a_g S / q), so q < 1 would raise "
        "it above the elastic spectrum; the Circolare takes q = 2",
    ),
]
#: The damping ``xi_percent`` [%] in ``rules.DAMPING_PERCENT_RANGE`` (#25: 0.05 was taken).
DampingPercent = Annotated[
    float,
    _in_range(
        DAMPING_PERCENT_RANGE,
        "%",
        "xi_percent is the viscous damping in percent, not a fraction: write 5 for 5 %",
    ),
]


def _ranged_field(default: float, bounds: Tuple[float, float], what: str) -> Any:
    """Return a field whose schema states ``bounds`` (the check is the type's)."""
    lo, hi = bounds
    return Field(
        default,
        description=f"{what}, in [{lo:g}, {hi:g}]; default {default:g}.",
        json_schema_extra={"minimum": lo, "maximum": hi},
    )


def _q_field() -> Any:
    return _ranged_field(2.0, BEHAVIOUR_FACTOR_RANGE, "Behaviour factor q [-]")


def _xi_field(default: float = 5.0, what: str = "Viscous damping [%] (5 means 5 %)") -> Any:
    return _ranged_field(default, DAMPING_PERCENT_RANGE, what)


class Project(BaseModel):
    """Who and what the assessment is for (all optional, shown on the report's first page)."""

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        json_schema_extra={"description": "Project fields for the report's first page."},
    )

    title: Optional[str] = Field(None, description="Title of the assessment.")
    building: Optional[str] = Field(None, description="Name of the building.")
    address: Optional[str] = Field(None, description="Address or location of the site.")
    client: Optional[str] = Field(None, description="Client.")
    engineer: Optional[str] = Field(None, description="Engineer responsible.")
    reference: Optional[str] = Field(None, description="Job or document reference.")
    date: Optional[str] = Field(None, description="Date of the assessment (free text).")


class NTCHazard(BaseModel):
    """Seismic hazard and check parameters under NTC 2018 (Italy).

    Attributes
    ----------
    a_g : float
        Ground acceleration on type A ground for the limit state [g], > 0.
    F0 : float
        Maximum spectral amplification [-], > 0.
    Tc_star : float
        ``T_C*`` [s], > 0.
    soil : str
        Soil category A-E.
    topography : str
        Topographic category T1-T4.
    limit_state : str
        The limit state the parameters belong to (informative); default ``"SLV"``.
    FC : float
        Confidence factor of the knowledge level [-], >= 1 (LC1 1.35, LC2 1.2, LC3 1).
    q : float
        Behaviour factor of the linear kinematic check [-], in [1, 10]; default 2.
    xi_percent : float
        Viscous damping of the spectrum [%], in [1, 50] (5 means 5 %); default 5 (the
        plotted spectrum and the records' matching; the checks use the dampings of
        ``LocalMechanisms``).
    limit_states : dict, optional
        ``a_g``, ``F0``, ``T_C*`` of other limit states, keyed SLO, SLD, SLV, SLC.
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={"description": "Hazard under NTC 2018 §3.2.3 and check parameters."},
    )

    code: Literal["NTC2018"] = Field(description="The code: NTC 2018 (Italy).")
    a_g: float = Field(gt=0, le=2, description="Ground acceleration on type A ground [g].")
    F0: float = Field(gt=0, le=10, description="Maximum spectral amplification F0 [-].")
    Tc_star: float = Field(gt=0, le=5, description="T_C* [s].")
    soil: Literal["A", "B", "C", "D", "E"] = Field("A", description="Soil category.")
    topography: Literal["T1", "T2", "T3", "T4"] = Field("T1", description="Topography.")
    limit_state: Literal["SLV", "SLC", "SLD", "SLO"] = Field(
        "SLV", description="Limit state of a_g, F0, Tc_star (the checks are the SLV ones)."
    )
    FC: float = Field(ge=1, le=2, description="Confidence factor FC [-] (LC1 1.35 ... LC3 1).")
    q: BehaviourFactor = _q_field()
    xi_percent: DampingPercent = _xi_field()
    limit_states: Optional[Dict[LimitState, NTCLimitState]] = Field(
        None,
        description=(
            "a_g, F0, T_C* of other limit states (e.g. SLC for the collapse check, SLD), "
            "besides the one of limit_state."
        ),
    )

    @model_validator(mode="after")
    def _other_limit_states(self) -> "NTCHazard":
        _no_duplicate_limit_state(self.limit_state, self.limit_states)
        return self


class EC8Hazard(BaseModel):
    """Seismic hazard under EN 1998-1 (Eurocode 8), with the kinematic check's parameters.

    Attributes
    ----------
    a_gR : float
        Reference peak ground acceleration on type A ground [g], > 0.
    importance : float
        Importance factor ``gamma_I`` [-], > 0; default 1.
    ground : str
        Ground type A-E.
    spectrum_type : int
        1 or 2.
    FC : float
        Confidence factor [-], >= 1 (EN 1998-3 CF: KL1 1.35, KL2 1.2, KL3 1).
    q : float
        Behaviour factor of the linear kinematic check [-], in [1, 10]; default 2.
    xi_percent : float
        Viscous damping [%], in [1, 50] (5 means 5 %); default 5.
    limit_states : dict, optional
        ``a_gR`` of other limit states, keyed SLO, SLD, SLC (``a_gR`` is the SLV's).
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={"description": "Hazard under EN 1998-1 §3.2.2.2 and check parameters."},
    )

    code: Literal["EC8"] = Field(description="The code: EN 1998-1 (Eurocode 8).")
    a_gR: float = Field(gt=0, le=2, description="Reference peak ground acceleration [g].")
    importance: float = Field(1.0, gt=0, le=3, description="Importance factor gamma_I [-].")
    ground: Literal["A", "B", "C", "D", "E"] = Field("A", description="Ground type.")
    spectrum_type: Annotated[Literal[1, 2], BeforeValidator(whole_number)] = Field(
        1, description="Spectrum type 1 or 2."
    )
    FC: float = Field(ge=1, le=2, description="Confidence factor [-] (EN 1998-3 CF).")
    q: BehaviourFactor = _q_field()
    xi_percent: DampingPercent = _xi_field()
    limit_states: Optional[Dict[LimitState, EC8LimitState]] = Field(
        None,
        description=(
            "a_gR of other limit states (SLD, SLC), besides the SLV of a_gR; the Circolare's "
            "limit-state names are used since its checks are applied."
        ),
    )

    @model_validator(mode="after")
    def _other_limit_states(self) -> "EC8Hazard":
        _no_duplicate_limit_state("SLV", self.limit_states)
        return self


class Building(BaseModel):
    """The building the mechanisms sit in, for the demand above ground.

    Attributes
    ----------
    height : float
        Height above the foundation [m], > 0.
    storeys : int
        Number of storeys, >= 1.
    T1 : float, optional
        First period [s]; default ``C1 height^(3/4)`` with ``C1 = 0.050`` (Circolare 2019
        [C7.3.2], masonry).
    xi_percent : float
        Equivalent viscous damping ``ξ_k`` of the building in the floor spectrum [%]
        (Circolare 2019 [C7.2.6]-[C7.2.7]); default 5. §C8.7.1.2.1.4 recalls 10-20 % for a
        masonry building at the ultimate limit state.
    period_elongation : float
        ``T_k / T1`` in the floor spectrum, >= 1; default 1. §C8.7.1.2.1.4 recalls 1.5-2 at
        the ultimate limit state.
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={"description": "The building, for mechanisms above ground."},
    )

    height: float = Field(gt=0, le=300, description="Height above the foundation [m].")
    storeys: JsonInt = Field(ge=1, le=100, description="Number of storeys.")
    T1: Optional[float] = Field(
        None,
        gt=0,
        le=10,
        description="First period [s]; default 0.050 height^0.75 (Circolare 2019 [C7.3.2]).",
    )
    xi_percent: DampingPercent = _xi_field(
        5.0, "Damping xi_k of the building in the floor spectrum [%] (Circ. 2019 C7.2.3)"
    )
    period_elongation: float = Field(
        1.0,
        ge=1,
        le=3,
        description="T_k/T1 in the floor spectrum (Circ. 2019 C8.7.1.2.1.4: 1.5-2 at the ULS).",
    )


class MechanismOptions(BaseModel):
    """The engineer's choices for one mechanism of the code check (Circolare 2019 §C8.7.1).

    Attributes
    ----------
    free_standing : bool, optional
        Whether the element is free to vibrate before it activates (§C8.7.1.2.1.3:
        parapets, free-standing portions of façades, pinnacles); default by typology
        (single-block or user-defined mechanisms rocking two-sided are).
    kappa : float, optional
        κ of [C8.7.1.7] [-]; default 6.2 (cantilever), 2.2 for a two-block strip.
    L, t : float, optional
        Length (height) and thickness of the element [m]; default from the geometry.
    unit_weight : float, optional
        Unit weight of the masonry [N/m³]; default from the geometry's density.
    E : float, optional
        Elastic modulus of the masonry [Pa] (Tab. C8.5.I); default ``LocalMechanisms.E``.
    ties : str, optional
        ``"verified"`` (the ties are verified to hold up to collapse: d0 with them) or
        ``"not_verified"`` (default: d0 without them, §C8.7.1.2.1.6).
    tie_failure_rotation : float, optional
        Rotation at which the ties break [rad] (their elongation at failure over their
        height): until then the curve has them.
    instability_rotation : float, optional
        Rotation at which the mechanism becomes locally unstable [rad] (beam unseating,
        vault collapse): a candidate for d_SLC.
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={"description": "Choices for one mechanism (Circolare 2019 §C8.7.1)."},
    )

    free_standing: Optional[bool] = Field(
        None, description="Free to vibrate before activation (C8.7.1.2.1.3); default by typology."
    )
    kappa: Optional[float] = Field(
        None, gt=0, le=20, description="kappa of [C8.7.1.7]; default 6.2 (2.2 two-block)."
    )
    L: Optional[float] = Field(None, gt=0, le=300, description="Length of the element [m].")
    t: Optional[float] = Field(None, gt=0, le=20, description="Thickness of the element [m].")
    unit_weight: Optional[float] = Field(
        None, gt=0, le=100000, description="Unit weight of the masonry [N/m³]."
    )
    E: Optional[float] = Field(
        None, gt=0, le=1e12, description="Elastic modulus of the masonry [Pa] (Tab. C8.5.I)."
    )
    ties: Optional[Literal["verified", "not_verified"]] = Field(
        None, description="Whether the ties are verified to hold up to collapse (C8.7.1.2.1.6)."
    )
    tie_failure_rotation: Optional[float] = Field(
        None, gt=0, le=1.5, description="Rotation at which the ties break [rad]."
    )
    instability_rotation: Optional[float] = Field(
        None, gt=0, le=1.5, description="Rotation of local instability, for d_SLC [rad]."
    )

    @model_validator(mode="after")
    def _verified_ties_do_not_break(self) -> "MechanismOptions":
        if self.ties == "verified" and self.tie_failure_rotation is not None:
            raise PydanticCustomError(
                "verified_ties_break",
                "{message}",
                {
                    "field": "tie_failure_rotation",
                    "message": (
                        "ties verified to hold up to collapse have no failure rotation: set "
                        "ties to not_verified or drop tie_failure_rotation"
                    ),
                },
            )
        return self


class LocalMechanisms(BaseModel):
    """The choices the Circolare 2019 §C8.7.1 leaves to the engineer, with its defaults.

    Attributes
    ----------
    method : str
        ``"circ2019"`` (default: Circolare 21 gennaio 2019 n. 7 §C8.7.1) or ``"circ2009"``
        (the Circolare 617/2009 C8A.4 forms, kept for comparison).
    xi_SLV_percent, xi_SLC_percent : float
        Equivalent viscous damping of the mechanism [%]: 8 and 10 (§C8.7.1.2.1.8).
    E : float, optional
        Elastic modulus of the masonry [Pa] for the free-standing elements' T0 ([C8.7.1.7],
        Tab. C8.5.I); without it T0 is unknown and the spectrum's peak is used.
    unit_weight : float, optional
        Unit weight of the masonry [N/m³] where the geometry gives no density.
    e_star : str
        How the sums of [C8.7.1.4]-[C8.7.1.5] run: ``"blocks"`` (default, the text: one
        term per block, at the centroid of the forces acting on it, so one block gives
        ``e* = 1``) or ``"integral"`` (over every mass element of the solids, ``e* = 3/4``
        for a rectangular block; docs/theory.md §11.1).
    mechanisms : dict
        ``MechanismOptions`` by mechanism id.
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={
            "description": "Choices of the local-mechanism check (Circolare 2019 §C8.7.1)."
        },
    )

    method: Literal["circ2019", "circ2009"] = Field(
        "circ2019",
        description="circ2019 (Circolare 2019 §C8.7.1) or circ2009 (the 2009 C8A.4 forms).",
    )
    xi_SLV_percent: DampingPercent = _xi_field(
        8.0, "Damping of the mechanism at SLV [%] (C8.7.1.2.1.8: 8)"
    )
    xi_SLC_percent: DampingPercent = _xi_field(
        10.0, "Damping of the mechanism at SLC [%] (C8.7.1.2.1.8: 10)"
    )
    E: Optional[float] = Field(
        None, gt=0, le=1e12, description="Elastic modulus of the masonry [Pa] (Tab. C8.5.I)."
    )
    unit_weight: Optional[float] = Field(
        None, gt=0, le=100000, description="Unit weight of the masonry [N/m³]."
    )
    e_star: Literal["blocks", "integral"] = Field(
        "blocks",
        description=(
            "How the sums of Circ. 2019 [C8.7.1.4]-[C8.7.1.5] run: blocks (the text: one term "
            "per block at the centroid of its forces; one block gives e* = 1) or integral "
            "(over every mass element of the solids; e* = 3/4 for a rectangular block)."
        ),
    )
    mechanisms: Dict[str, MechanismOptions] = Field(
        default_factory=dict, description="Choices per mechanism id."
    )


class SiteFile(BaseModel):
    """A site file: format version, project, hazard and building.

    Examples
    --------
    >>> site = parse_site('{"hazard": {"code": "EC8", "a_gR": 0.2, "FC": 1.2}}')
    >>> site.hazard.ground, site.hazard.q
    ('A', 2.0)
    """

    model_config = ConfigDict(
        strict=True,
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={
            "description": "Site hazard and project data for rockmech's code checks."
        },
    )

    schema_version: SchemaVersion = schema_version_field(
        SITE_SCHEMA_VERSION, "Format version '1.<minor>'."
    )
    project: Project = Field(default_factory=Project, description="Project fields.")
    hazard: Union[NTCHazard, EC8Hazard] = Field(
        discriminator="code", description="Seismic hazard, by code."
    )
    building: Optional[Building] = Field(
        None, description="The building (mechanisms above ground)."
    )
    local_mechanisms: LocalMechanisms = Field(
        default_factory=LocalMechanisms,
        description="Choices of the local-mechanism check (Circolare 2019 §C8.7.1).",
    )


#: What a site file must be, for the messages on empty, binary or non-JSON files.
SITE_EXPECTED = 'a site file (JSON, {"hazard": {...}, "building": {...}})'


def parse_site(source: Union[str, bytes, Mapping[str, Any]]) -> SiteFile:
    """Validate a site file given as JSON text, the bytes of a file, or plain data.

    Bytes are decoded by ``shared_schema.text.decode_text`` (UTF-8, or UTF-16/32 with a
    byte-order mark): an empty or binary file, or one in another encoding, is an
    ``InputError`` naming ``site``, never a codec's error.

    Raises
    ------
    InputError
        Bytes that are not text, malformed JSON or an invalid value; the message names the
        field (``hazard.NTC2018.a_g: Input should be greater than 0``).
    """
    return validate_document(SiteFile, source, "the site file", "site", SITE_EXPECTED)


def site_from_text(text: str, name: str) -> SiteFile:
    """Validate the text of the site file ``name``; every error names a field.

    An error of the whole document (malformed JSON) names ``site`` and the file, and says
    what a site file is.

    Raises
    ------
    InputError
        As ``parse_site``; field ``site`` where the error has no field of its own.
    """
    try:
        return parse_site(text)
    except InputError as exc:
        if exc.field:
            raise
        raise InputError(f"{name}: {exc.reason}; expected {SITE_EXPECTED}", "site") from None


def read_site(raw: bytes, name: str) -> SiteFile:
    """Validate a site file's bytes as every entry point reads it (the CLI, the service).

    Parameters
    ----------
    raw : bytes
        The file's content.
    name : str
        The file's name, for the messages.

    Raises
    ------
    InputError
        An empty or binary file, text that is not UTF-8 (``decode_text``), malformed JSON or
        an invalid value (``site_from_text``).
    """
    return site_from_text(decode_text(raw, name, "site", SITE_EXPECTED), name)
