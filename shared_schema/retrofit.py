"""The retrofit spec (tie-bars to design) and the retrofit document (docs/theory.md §11.12).

The spec says where ties may go and what they are made of:

* ``steel``: the grade (``S235``, ``S275``, ``S355``: NTC 2018 Tab. 4.2.I) and the bar
  diameters on offer [mm];
* ``anchorage``: the design resistance of one tie's anchorage [N] with the source it comes
  from (plate punching, pull-out: rockmech has no masonry formula of its own and invents
  none); a mechanism may give its own;
* ``mechanisms``: per mechanism id, the candidate tie heights above its hinge [m] (default:
  one tie at the top of the moving part and one at each level it carries), the number of
  bars at that height sharing the force, and the bar length for the steel mass [m];
* ``tie_lines``: from a scene only, line objects of the scene drawn where ties may go
  (selectors as the search spec's: a name, or ``{"name"|"layer"|"id": ...}``; a layer
  selects every line on it): each line is a candidate tie of the mechanisms whose moving
  part it crosses, in place of the default heights;
* ``records``: ground-motion record files (relative to the spec's folder; formats detected)
  that each mechanism, once tied, must survive at its design scale by the exact solver;
* ``upgrades``: connection upgrades to compare with the ties, from a scene only (a junction
  of the search spec made ``good`` or ``tied``, a level ``tied``): the search runs again
  with each.

The document holds, per mechanism, the least tie force that makes the Circolare 2019 checks
pass, the criterion that governs it, the bar, the anchorage check, the steel mass, and the
checks before and after with their clauses.

The spec's JSON Schema is ``shared_schema/jsonschema/retrofit.schema.json``
(``python -m shared_schema.export``).

The models run on CPython 3.9 inside Rhino 8, so annotations use the ``typing`` forms.
"""

from typing import Any, Dict, List, Literal, Mapping, Optional, Tuple, Union

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    field_validator,
    model_serializer,
    model_validator,
)

from shared_schema.constants import validate_document
from shared_schema.errors import InputError
from shared_schema.paths import Source, read_source
from shared_schema.retrofit_units import RETROFIT_UNITS
from shared_schema.search import Unit
from shared_schema.spec import Selector
from shared_schema.version import __version__

__all__ = [
    "ANCHORAGE_MAX_N",
    "GAMMA_M0",
    "HEIGHTS_MAX",
    "RETROFIT_UNITS",
    "STEEL_DENSITY",
    "STEEL_GRADES",
    "Anchorage",
    "AnchorageCheck",
    "BarChoice",
    "CheckFigures",
    "ConnectionUpgrade",
    "GoverningNext",
    "GoverningRow",
    "MechanismRetrofit",
    "MechanismTies",
    "PlacedTie",
    "RecordScale",
    "RecordTie",
    "RetrofitDoc",
    "RetrofitSpec",
    "SearchAfter",
    "SearchAfterRow",
    "Steel",
    "TieOption",
    "UpgradeAfter",
    "bar_strengths",
    "parse_retrofit_spec",
    "read_retrofit_spec",
]

#: NTC 2018 Tab. 4.2.I (UNI EN 10025-2): f_yk, f_tk [N/mm²] for a nominal thickness t ≤ 40 mm
#: and for 40 mm < t ≤ 80 mm (a round bar's thickness read as its diameter).
STEEL_GRADES: Dict[str, Tuple[Tuple[float, float], Tuple[float, float]]] = {
    "S235": ((235.0, 360.0), (215.0, 360.0)),
    "S275": ((275.0, 430.0), (255.0, 410.0)),
    "S355": ((355.0, 510.0), (335.0, 470.0)),
}
#: NTC 2018 Tab. 4.2.I: the thickness where the second row starts, and the table's end [mm].
THICKNESS_SPLIT_MM, THICKNESS_MAX_MM = 40.0, 80.0
#: NTC 2018 Tab. 4.2.VII: γ_M0, the partial factor of the yield resistance [4.2.6].
GAMMA_M0 = 1.05
#: Density of structural steel [kg/m³] (EN 1993-1-1 §3.2.6), for the steel mass.
STEEL_DENSITY = 7850.0
#: An anchorage resistance above this is refused as a mistake (units?) [N]: 5 MN is some
#: twenty times what a masonry anchorage plate is ever designed for.
ANCHORAGE_MAX_N = 5.0e6
#: Tie heights and bar lengths above these are refused as mistakes [m].
HEIGHT_MAX_M, LENGTH_MAX_M = 200.0, 300.0
#: Candidate tie heights of one mechanism: at most this many.
HEIGHTS_MAX = 20
#: Bars at one height sharing the force: at most this many.
BARS_MAX = 20
#: Connection upgrades in one spec: at most this many (each is one more search).
UPGRADES_MAX = 20
#: Tie-line selectors in one spec: at most this many.
TIE_LINES_MAX = 50

_MODEL = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False)


def bar_strengths(grade: str, diameter_mm: float) -> Tuple[float, float, str]:
    """Return ``f_yk``, ``f_tk`` [N/mm²] of a round bar and the row of Tab. 4.2.I used.

    Raises
    ------
    InputError
        A grade not in the table, or a diameter beyond its 80 mm.

    Examples
    --------
    >>> bar_strengths("S275", 20.0)[:2]
    (275.0, 430.0)
    """
    if grade not in STEEL_GRADES:
        raise InputError(
            f"grade {grade!r} is not in NTC 2018 Tab. 4.2.I; use one of " + ", ".join(STEEL_GRADES),
            "steel.grade",
        )
    thin, thick = STEEL_GRADES[grade]
    if diameter_mm <= THICKNESS_SPLIT_MM:
        return thin[0], thin[1], "NTC 2018 Tab. 4.2.I, t ≤ 40 mm"
    if diameter_mm <= THICKNESS_MAX_MM:
        return thick[0], thick[1], "NTC 2018 Tab. 4.2.I, 40 mm < t ≤ 80 mm"
    raise InputError(
        f"a {diameter_mm:g} mm bar is beyond NTC 2018 Tab. 4.2.I (t ≤ 80 mm)",
        "steel.diameters_mm",
    )


class Anchorage(BaseModel):
    """The design resistance of one tie's anchorage, with its source.

    Attributes
    ----------
    capacity_N : float
        Design resistance of one anchorage (plate punching, plate bending, pull-out,
        whichever is least) [N], > 0.
    source : str
        Where the number comes from (a calculation, a test, a document): rockmech has no
        anchorage formula and reports this beside the check.
    """

    model_config = ConfigDict(
        **_MODEL, json_schema_extra={"description": "One tie's anchorage resistance."}
    )

    capacity_N: float = Field(
        gt=0, le=ANCHORAGE_MAX_N, description="Design resistance of one anchorage [N]."
    )
    source: str = Field(
        min_length=3, max_length=500, description="Where the resistance comes from (required)."
    )

    @field_validator("source")
    @classmethod
    def _source_says_something(cls, v: str) -> str:
        if len(v.strip()) < 3:
            raise ValueError("give the source of the anchorage resistance (a few words at least)")
        return v.strip()


class Steel(BaseModel):
    """The tie-bars' steel and the bar sizes on offer.

    Attributes
    ----------
    grade : str
        ``"S235"``, ``"S275"`` or ``"S355"`` (NTC 2018 Tab. 4.2.I).
    diameters_mm : list of float
        Round-bar diameters on offer [mm], each in (0, 80].
    """

    model_config = ConfigDict(
        **_MODEL, json_schema_extra={"description": "Steel grade and bar diameters on offer."}
    )

    grade: Literal["S235", "S275", "S355"] = Field(description="Steel grade, NTC 2018 Tab. 4.2.I.")
    diameters_mm: List[float] = Field(
        min_length=1,
        max_length=50,
        description="Bar diameters on offer [mm], each in (0, 80].",
        # the schema states the validator's bound (its message cites the table)
        json_schema_extra={
            "items": {"type": "number", "exclusiveMinimum": 0, "maximum": THICKNESS_MAX_MM}
        },
    )

    @field_validator("diameters_mm")
    @classmethod
    def _diameters_in_table(cls, v: List[float]) -> List[float]:
        for d in v:
            if not 0.0 < d <= THICKNESS_MAX_MM:
                raise ValueError(
                    f"bar diameter {d:g} mm is outside (0, 80] mm (NTC 2018 Tab. 4.2.I)"
                )
        return sorted(set(v))


class MechanismTies(BaseModel):
    """Where ties may go on one mechanism.

    Attributes
    ----------
    heights_m : list of float, optional
        Candidate tie heights above the mechanism's hinge [m], each tried alone; default one
        tie at the top of the moving part and one at each level (floor, roof) it carries.
    bars : int
        Bars at that height sharing the force equally (along the wall) [-], default 1.
    length_m : float, optional
        Length of one bar [m], for the steel mass; without it the mass is given per metre.
    anchorage : Anchorage, optional
        This mechanism's anchorage resistance; default the spec's.
    """

    model_config = ConfigDict(
        **_MODEL, json_schema_extra={"description": "Candidate ties of one mechanism."}
    )

    heights_m: Optional[List[float]] = Field(
        None,
        min_length=1,
        max_length=HEIGHTS_MAX,
        description="Candidate tie heights above the hinge [m]; default the moving part's top "
        "and each level it carries.",
    )
    bars: int = Field(1, ge=1, le=BARS_MAX, description="Bars at the height sharing the force.")
    length_m: Optional[float] = Field(
        None, gt=0, le=LENGTH_MAX_M, description="Length of one bar [m] (steel mass)."
    )
    anchorage: Optional[Anchorage] = Field(
        None, description="This mechanism's anchorage resistance; default the spec's."
    )

    @field_validator("heights_m")
    @classmethod
    def _heights_positive(cls, v: Optional[List[float]]) -> Optional[List[float]]:
        for h in v or []:
            if not 0.0 < h <= HEIGHT_MAX_M:
                raise ValueError(f"tie height {h:g} m is outside (0, {HEIGHT_MAX_M:g}] m")
        return v


class ConnectionUpgrade(BaseModel):
    """One connection upgrade, compared with the ties by searching the scene again with it.

    Either a junction of the search spec (``walls``, as the search spec names them, and
    ``to``: ``"good"``, which needs the masonry ``unit`` as the search spec's junction does,
    or ``"tied"``) or a level of the search spec (``level``, its id, and ``tied: true``).
    Whether the junction or level is there, and whether the upgrade changes it, is checked
    against the search spec when the retrofit runs from a scene (a retrofit from constants
    cannot apply it: the search must run again).

    Attributes
    ----------
    walls : [str, str], optional
        The junction's two wall ids.
    to : {"good", "tied"}, optional
        The junction's connection after the upgrade.
    unit : Unit, optional
        The masonry unit of a junction made good (length, height [m]).
    level : str, optional
        The level's id.
    tied : bool, optional
        ``true`` for a level tied into the walls.
    """

    model_config = ConfigDict(
        **_MODEL, json_schema_extra={"description": "A junction or level connection upgrade."}
    )

    walls: Optional[List[str]] = Field(
        None, min_length=2, max_length=2, description="A junction's two wall ids."
    )
    to: Optional[Literal["good", "tied"]] = Field(
        None, description="The junction's connection after the upgrade."
    )
    unit: Optional[Unit] = Field(
        None, description="Masonry unit of a junction made good (length, height [m])."
    )
    level: Optional[str] = Field(None, min_length=1, description="A level's id.")
    tied: Optional[bool] = Field(None, description="A level upgrade: true (tied into the walls).")

    @model_validator(mode="after")
    def _one_kind(self) -> "ConnectionUpgrade":
        if (self.walls is None) == (self.level is None):
            raise ValueError(
                "an upgrade is either a junction ('walls' and 'to') or a level ('level' and "
                "'tied': true)"
            )
        if self.walls is not None:
            if self.tied is not None:
                raise ValueError("'tied' is a level's; a junction takes 'to': \"tied\"")
            if self.to is None:
                raise ValueError('a junction upgrade needs \'to\': "good" or "tied"')
            if self.walls[0] == self.walls[1]:
                raise ValueError(f"a junction joins two different walls, got {self.walls}")
            if self.to == "good" and self.unit is None:
                raise ValueError(
                    "a junction made good needs the masonry 'unit' (length, height [m]): the "
                    "bond bounds the crack angle"
                )
            if self.to == "tied" and self.unit is not None:
                raise ValueError("'unit' is for a junction made good; a tied one takes none")
        else:
            if self.to is not None or self.unit is not None:
                raise ValueError("'to' and 'unit' are a junction's; a level takes 'tied': true")
            if self.tied is not True:
                raise ValueError("a level upgrade is 'tied': true (the level tied into the walls)")
        return self


class RetrofitSpec(BaseModel):
    """A retrofit spec: the steel, the anchorage and the candidate ties per mechanism.

    Examples
    --------
    >>> spec = parse_retrofit_spec(
    ...     '{"steel": {"grade": "S275", "diameters_mm": [16, 20]},'
    ...     ' "anchorage": {"capacity_N": 60000, "source": "plate punching, calc. 12"}}'
    ... )
    >>> spec.steel.grade, spec.mechanisms
    ('S275', {})
    """

    model_config = ConfigDict(
        **_MODEL,
        json_schema_extra={"description": "Tie-bars to design for failing mechanisms."},
    )

    steel: Steel = Field(description="Steel grade and bar diameters on offer.")
    anchorage: Anchorage = Field(description="One tie's anchorage resistance, with its source.")
    mechanisms: Dict[str, MechanismTies] = Field(
        default_factory=dict,
        description="Per mechanism id: candidate ties (mechanisms not listed: the default).",
    )
    tie_lines: Optional[List[Selector]] = Field(
        None,
        min_length=1,
        max_length=TIE_LINES_MAX,
        description="From a scene only: line objects of the scene where ties may go (an "
        "object name, or {name|layer|id: ...}; a layer selects every line on it), each a "
        "candidate tie of the mechanisms whose moving part it crosses, in place of the "
        "default heights.",
    )
    records: List[str] = Field(
        default_factory=list,
        max_length=50,
        description="Record files each tied mechanism must survive at its design scale "
        "(relative to the spec's folder).",
    )
    upgrades: List[ConnectionUpgrade] = Field(
        default_factory=list,
        max_length=UPGRADES_MAX,
        description="Connection upgrades to compare with the ties (from a scene only): each "
        "is one more search.",
    )


def parse_retrofit_spec(source: Union[str, bytes, Mapping[str, Any]]) -> RetrofitSpec:
    """Validate a retrofit spec given as JSON text, the bytes of a file, or plain data.

    Raises
    ------
    InputError
        Malformed JSON or an invalid value; the message names the field
        (``anchorage.source: Field required``).
    """
    return validate_document(
        RetrofitSpec, source, "the retrofit spec", "retrofit", "a retrofit spec (JSON)"
    )


def read_retrofit_spec(path: Source) -> RetrofitSpec:
    """Read and validate a retrofit spec (JSON) from a path or an open file; field ``retrofit``.

    ``path`` is a ``str``, an ``os.PathLike`` or an open file (``paths.read_source``).
    """
    raw, _ = read_source(path, "retrofit")
    return parse_retrofit_spec(raw)


# --- the document ---------------------------------------------------------------------

_DOC = ConfigDict(extra="forbid", allow_inf_nan=False)


class CheckFigures(BaseModel):
    """A mechanism's Circolare 2019 checks, as the retrofit reads them (one side or all).

    Ratios are capacity/demand (``a_g,X/a_g``) [-]; a verdict is None where the check was
    not evaluated (no SLC hazard in the site file, a check that did not run).
    """

    model_config = _DOC

    linear_ratio: Optional[float] = Field(None, description="Linear check, SLV [-].")
    linear_passes: Optional[bool] = None
    SLV_ratio: Optional[float] = Field(None, description="Nonlinear check, SLV [-].")
    SLV_passes: Optional[bool] = None
    SLC_ratio: Optional[float] = Field(None, description="Nonlinear check, SLC [-].")
    SLC_passes: Optional[bool] = None
    alpha0: Optional[float] = Field(None, description="Activation multiplier [-].")
    e_star: Optional[float] = Field(None, description="Participating mass fraction [-].")
    ties: Optional[str] = Field(None, description="How the check counted the ties.")
    clauses: Dict[str, str] = Field(default_factory=dict)
    notes: List[str] = Field(default_factory=list)

    @property
    def passes(self) -> Optional[bool]:
        """Whether every evaluated check passes (None when none was evaluated)."""
        got = [v for v in (self.linear_passes, self.SLV_passes, self.SLC_passes) if v is not None]
        return all(got) if got else None


class BarChoice(BaseModel):
    """The smallest bar on offer whose yield resistance carries the force."""

    model_config = _DOC

    grade: str
    diameter_mm: float
    area_mm2: float = Field(description="Gross area π d²/4 [mm²].")
    f_yk: float = Field(description="Yield strength [N/mm²] (Tab. 4.2.I).")
    f_tk: float = Field(description="Tensile strength [N/mm²] (Tab. 4.2.I).")
    gamma_M0: float
    N_pl_Rd_N: float = Field(description="A f_yk/γ_M0 [N] (NTC 2018 [4.2.6]).")
    force_N: float = Field(description="The force one bar carries [N].")
    utilisation: float = Field(description="force_N/N_pl_Rd_N [-] (NTC 2018 [4.2.5]).")
    clauses: Dict[str, str] = Field(default_factory=dict)


class AnchorageCheck(BaseModel):
    """One tie's force against the user's anchorage resistance."""

    model_config = _DOC

    capacity_N: float
    source: str
    force_N: float
    passes: bool


class RecordScale(BaseModel):
    """One record on one mechanism: its design scale and the least scale that overturns it.

    ``design_scale`` matches the record's 5 % spectrum to the site's over the mechanism's
    band (the assessment's, ``workflows.assess.record_scale_factor``); the factor up the
    structure (Eq. 28) multiplies both scales. ``overturning_scale`` is the least scale of
    the record that overturns the mechanism (the first of a log grid, bisected; every grid
    scale below it survives), None when none up to the grid's top does.
    """

    model_config = _DOC

    record: str
    design_scale: Optional[float] = Field(None, description="Record scale at the design level [-].")
    height_factor: Optional[float] = Field(None, description="Eq. 28 factor up the structure [-].")
    overturning_scale: Optional[float] = Field(
        None, description="Least record scale that overturns [-] (None: none on the grid)."
    )
    multiple: Optional[float] = Field(
        None, description="overturning_scale/design_scale [-] (None: none overturns)."
    )
    passes: Optional[bool] = Field(
        None, description="No scale up to the design one overturns (multiple > 1)."
    )
    survives_design: Optional[bool] = Field(
        None, description="The run at the design scale does not overturn."
    )
    runs: int = Field(0, description="Exact runs made (the grid, the bisection, the design).")
    note: Optional[str] = None


class RecordTie(BaseModel):
    """The least tie force with which one record no longer overturns at its design scale."""

    model_config = _DOC

    record: str
    T_star_N: Optional[float] = Field(
        None, description="Least force [N] on the grid of ratio 1/(1 − 0.005) (None: none)."
    )
    T_start_N: Optional[float] = Field(
        None, description="Where the grid starts: λ(T) = λ0 s_design/s_ov [N]."
    )
    runs: int = Field(0, description="Exact runs at the design scale the search made.")
    flip: List[Dict[str, Any]] = Field(
        default_factory=list,
        description="Verdicts at T*(1 − 0.005), T*, T*(1 + 0.005): force_N, overturned.",
    )
    note: Optional[str] = None


class TieOption(BaseModel):
    """One candidate tie height of a mechanism and what it takes there."""

    model_config = _DOC

    height_m: float = Field(description="Height of the tie above the hinge [m].")
    height_source: str
    status: Literal["designed", "not_carried", "no_force_suffices", "above_moving_part"]
    T_linear_N: Optional[float] = Field(None, description="Least T for the linear check [N].")
    T_nonlinear_SLV_N: Optional[float] = Field(
        None, description="Least T for the nonlinear SLV check, tie verified [N]."
    )
    T_nonlinear_SLC_N: Optional[float] = Field(
        None, description="Least T for the nonlinear SLC check, tie verified [N]."
    )
    T_records_N: Optional[float] = Field(
        None, description="Least T for every record at its design scale (exact solver) [N]."
    )
    records: List[RecordTie] = Field(default_factory=list, description="Per record.")
    T_star_N: Optional[float] = Field(None, description="The larger of the criteria [N].")
    governing: Optional[str] = Field(None, description="The criterion that gives T_star_N.")
    e_star: Optional[float] = Field(None, description="e* of the checks ([C8.7.1.5]) [-].")
    bars: int = Field(description="Bars at this height sharing T_star_N.")
    bar: Optional[BarChoice] = None
    anchorage: Optional[AnchorageCheck] = None
    verified: bool = Field(
        description="Bar and anchorage carry the force: the tie counts up to collapse."
    )
    steel_mass_kg: Optional[float] = Field(None, description="Steel of the bars [kg].")
    steel_mass_per_m_kg: Optional[float] = Field(
        None, description="Steel of the bars per metre of length [kg/m]."
    )
    after: Optional[CheckFigures] = None
    records_after: List[RecordScale] = Field(
        default_factory=list, description="The records with the tie at T_star_N."
    )
    decisions: List[str] = Field(default_factory=list)


class MechanismRetrofit(BaseModel):
    """One mechanism: its checks before, the tie options, the chosen one."""

    model_config = _DOC

    id: str
    name: str
    typology: str
    status: Literal[
        "passes", "designed", "not_achievable", "not_applicable", "not_checked", "not_evaluated"
    ]
    before: CheckFigures
    records_before: List[RecordScale] = Field(
        default_factory=list, description="The records on the mechanism as it stands."
    )
    options: List[TieOption] = Field(default_factory=list)
    chosen: Optional[int] = Field(None, description="Index of the chosen option (least T).")
    decisions: List[str] = Field(default_factory=list)


class GoverningRow(BaseModel):
    """One mechanism's least margin, before the intervention and after it."""

    model_config = _DOC

    id: str
    tied: bool = Field(description="The intervention ties this mechanism (its chosen option).")
    before_margin: Optional[float] = Field(None, description="Least margin before [-].")
    before_criterion: Optional[str] = None
    after_margin: Optional[float] = Field(None, description="Least margin after [-].")
    after_criterion: Optional[str] = None


class GoverningNext(BaseModel):
    """The mechanism that governs before and after the intervention, and its margin.

    A margin is a capacity over a demand [-]: the code checks' ``a_g,X/a_g`` and, with
    records, the least ``overturning_scale/design_scale``; a mechanism's margin is its
    least, and the one that governs has the least of all (below 1: it fails).
    """

    model_config = _DOC

    before: Optional[str] = Field(None, description="The governing mechanism as it stands.")
    before_margin: Optional[float] = None
    before_criterion: Optional[str] = None
    after: Optional[str] = Field(None, description="The governing one with the ties in.")
    after_margin: Optional[float] = None
    after_criterion: Optional[str] = None
    moved: bool = Field(description="Another mechanism governs after the intervention.")
    rows: List[GoverningRow] = Field(default_factory=list)
    basis: List[str] = Field(default_factory=list)


class PlacedTie(BaseModel):
    """A designed tie put into the scene as a tie-bar for the search's rerun."""

    model_config = _DOC

    mechanism: str = Field(description="The mechanism the tie is designed for.")
    status: Literal["placed", "not_placed"]
    object: Optional[str] = Field(None, description="Name of the tie-bar line in the scene.")
    wall: Optional[str] = Field(None, description="The search's wall the tie meets.")
    force_N: Optional[float] = Field(None, description="The tie-bar's constant force [N].")
    height_m: Optional[float] = Field(None, description="Height above the hinge [m].")
    at_m: Optional[List[float]] = Field(
        None, description="Where the line meets the wall's outer face [m]."
    )
    end_m: Optional[List[float]] = Field(
        None, description="The line's other end, on the wall's inner face [m]."
    )
    note: Optional[str] = None


class SearchAfterRow(BaseModel):
    """One mechanism of the search rerun with the ties in."""

    model_config = _DOC

    id: str
    name: str
    family: str
    facade: str
    direction: str
    lam0: float = Field(description="Exact static multiplier of the rerun [-].")
    margin: Optional[float] = Field(
        None,
        description="Least margin: its checks' a_g,X/a_g and, with records, each record's "
        "overturning_scale/design_scale [-].",
    )
    criterion: Optional[str] = None
    ties: List[str] = Field(
        default_factory=list, description="The designed tie-bars its moving part carries."
    )
    records: List[RecordScale] = Field(
        default_factory=list,
        description="The retrofit spec's records on this mechanism: design scale, least "
        "overturning scale (exact solver).",
    )


class UpgradeAfter(BaseModel):
    """The search rerun with connection upgrades: what governs after them.

    One per upgrade on its own (the scene and the search spec as given, with that upgrade),
    and one with every upgrade and the designed ties together. The margin is the rerun's,
    by the same rule as ``SearchAfter``; ``moved`` compares with the first search's
    governing mechanism.
    """

    model_config = _DOC

    upgrades: List[str] = Field(
        description="The upgrades applied, in words ('junction F-L: poor -> tied')."
    )
    indices: List[int] = Field(description="Their indices in the retrofit spec's upgrades.")
    with_ties: bool = Field(description="The designed ties are in the scene too.")
    after: Optional[str] = Field(None, description="Governing mechanism of the rerun.")
    after_name: Optional[str] = None
    after_facade: Optional[str] = Field(None, description="The wall it turns.")
    after_family: Optional[str] = None
    after_margin: Optional[float] = Field(None, description="Its least margin [-].")
    after_criterion: Optional[str] = None
    after_lam0: Optional[float] = Field(None, description="Its static multiplier [-].")
    least_lam0: Optional[str] = Field(None, description="The rerun's mechanism of least λ0.")
    least_lam0_value: Optional[float] = Field(None, description="That λ0 [-].")
    moved: bool = Field(description="Another mechanism governs than before the intervention.")
    rows: List[SearchAfterRow] = Field(default_factory=list)
    notes: List[str] = Field(default_factory=list)


class SearchAfter(BaseModel):
    """The search rerun on the scene with the designed ties: what governs after.

    The margin is the least capacity/demand of the Circolare 2019 checks (``a_g,X/a_g``) of
    the mechanisms the search builds; ``moved`` compares the governing mechanism's family,
    façade and direction before and after (the rerun numbers its mechanisms anew).
    """

    model_config = _DOC

    ties: List[PlacedTie] = Field(default_factory=list)
    before: Optional[str] = Field(None, description="Governing mechanism of the first search.")
    before_name: Optional[str] = None
    before_facade: Optional[str] = Field(None, description="The wall it turns.")
    before_family: Optional[str] = None
    before_margin: Optional[float] = None
    before_criterion: Optional[str] = None
    after: Optional[str] = Field(None, description="Governing mechanism of the rerun.")
    after_name: Optional[str] = None
    after_facade: Optional[str] = Field(None, description="The wall it turns.")
    after_family: Optional[str] = None
    after_margin: Optional[float] = None
    after_criterion: Optional[str] = None
    after_lam0: Optional[float] = Field(None, description="Its static multiplier [-].")
    least_lam0: Optional[str] = Field(None, description="The rerun's mechanism of least λ0.")
    least_lam0_value: Optional[float] = Field(None, description="That λ0 [-].")
    moved: bool = Field(description="Another mechanism governs after the intervention.")
    rows: List[SearchAfterRow] = Field(default_factory=list)
    upgrades: List[UpgradeAfter] = Field(
        default_factory=list,
        description="Per connection upgrade of the retrofit spec: the search rerun with it.",
    )
    together: Optional[UpgradeAfter] = Field(
        None, description="The search rerun with every upgrade and the designed ties."
    )
    basis: List[str] = Field(default_factory=list)
    notes: List[str] = Field(default_factory=list)


class RetrofitDoc(BaseModel):
    """The retrofit document: per mechanism the least tie force and what it takes.

    Like every rockmech document it starts with ``rockmech_version`` (the version that wrote
    it) and ``units`` (``RETROFIT_UNITS``), both filled in when the document is made.
    """

    model_config = _DOC

    rockmech_version: str = Field(
        default_factory=lambda: __version__,
        max_length=100,
        description="Version of rockmech that wrote the document.",
    )
    units: Dict[str, str] = Field(
        default_factory=lambda: dict(RETROFIT_UNITS),
        description="Unit of each quantity whose name does not state it ('-': none).",
    )
    standard: str
    steel: Dict[str, Any]
    decisions: List[str]
    records: List[Dict[str, Any]] = Field(
        default_factory=list, description="The records: name, PGA [g], dt [s], duration [s]."
    )
    mechanisms: List[MechanismRetrofit]
    governs_next: Optional[GoverningNext] = Field(
        None, description="What governs before and after the intervention."
    )
    search_after: Optional[SearchAfter] = Field(
        None, description="From a scene: the search rerun with the designed ties."
    )

    @model_serializer(mode="wrap")
    def _without_search_after(self, handler: Any) -> Any:
        # A retrofit from a constants file keeps the bytes it had before the key existed.
        data = handler(self)
        if isinstance(data, dict) and data.get("search_after", 0) is None:
            del data["search_after"]
        return data

    def find(self, mechanism_id: str) -> MechanismRetrofit:
        """Return the mechanism with this id."""
        for m in self.mechanisms:
            if m.id == mechanism_id:
                return m
        known = ", ".join(repr(m.id) for m in self.mechanisms)
        raise InputError(f"no mechanism with id {mechanism_id!r}; the document has {known}", "id")
