"""The site file (SITE.json): project, seismic hazard, check parameters and the building.

The hazard is given by the building code that defines it:

* ``"NTC2018"`` (Italy, NTC 2018 §3.2.3): ``a_g`` [g], ``F0``, ``Tc_star`` [s] for the limit
  state, the soil category A-E and the topographic category T1-T4;
* ``"EC8"`` (EN 1998-1 §3.2.2.2): ``a_gR`` [g], the importance factor, the ground type A-E
  and the spectrum type 1 or 2.

Both carry the parameters of the code's kinematic check (docs/theory.md §11): the
knowledge-level confidence factor ``FC`` and the behaviour factor ``q`` (default 2). The
optional ``building`` section (height, storeys, first period) serves the demand on
mechanisms above ground; the optional ``project`` section fills the report's first page.

The models run on CPython 3.9 inside Rhino 8, so annotations use the ``typing`` forms.
"""

from typing import Annotated, Any, Literal, Mapping, Optional, Tuple, Union

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
)
from pydantic_core import PydanticCustomError

from shared_schema.constants import (
    JsonInt,
    SchemaVersion,
    input_error_from_validation,
    json_document,
    schema_version_field,
    whole_number,
)
from shared_schema.rules import BEHAVIOUR_FACTOR_RANGE, DAMPING_PERCENT_RANGE, range_problem

__all__ = [
    "SITE_SCHEMA_VERSION",
    "Building",
    "EC8Hazard",
    "NTCHazard",
    "Project",
    "SiteFile",
    "parse_site",
]

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


def _xi_field() -> Any:
    return _ranged_field(5.0, DAMPING_PERCENT_RANGE, "Viscous damping [%] (5 means 5 %)")


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
        Viscous damping of the spectrum [%], in [1, 50] (5 means 5 %); default 5.
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


class Building(BaseModel):
    """The building the mechanisms sit in, for the demand above ground.

    Attributes
    ----------
    height : float
        Height above the foundation [m], > 0.
    storeys : int
        Number of storeys, >= 1.
    T1 : float, optional
        First period [s]; default ``0.05 height^0.75`` (NTC 2018 §7.3.3.2, masonry).
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
        None, gt=0, le=10, description="First period [s]; default 0.05 height^0.75."
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


def parse_site(source: Union[str, bytes, Mapping[str, Any]]) -> SiteFile:
    """Validate a site file given as JSON text or plain data.

    Raises
    ------
    InputError
        Malformed JSON or an invalid value; the message names the field
        (``hazard.NTC2018.a_g: Input should be greater than 0``).
    """
    if isinstance(source, SiteFile):
        return source
    if isinstance(source, (str, bytes)):
        text = source.decode("utf-8-sig") if isinstance(source, bytes) else source
        data = json_document(text)
        try:
            return SiteFile.model_validate_json(text)
        except ValidationError as exc:
            raise input_error_from_validation(exc, data) from exc
    try:
        return SiteFile.model_validate(source)
    except ValidationError as exc:
        raise input_error_from_validation(exc, source) from exc
