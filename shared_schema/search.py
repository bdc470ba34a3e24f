"""The search spec: what ``rockmech search`` looks for in a scene, and how it ranks it.

A search spec names the walls of a scene (one solid each, with its density), the openings
drawn as solids (voids in the walls need no entry), the levels (floors and roof) that load or
hold the walls, the connection of every wall junction (good, poor, tied, and the masonry
unit that bounds the crack angle of a good one), tie-bars and overburdens as in the
mechanism spec, the mechanism families and directions to search, and the ranking inputs
(pulse frequency band, a site file, records, how many to keep). Lengths are in metres,
densities in kg/m³, forces in N, frequencies in Hz. Unknown keys are errors.

``python -m shared_schema.export`` writes its JSON Schema
(``shared_schema/jsonschema/search.schema.json``).

Python 3.9-clean: imported by Rhino 8.
"""

import json
import math
from typing import Any, List, Literal, Optional, Tuple, Union, cast

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from shared_schema.constants import validation_lines
from shared_schema.errors import InputError
from shared_schema.rules import (
    F_P_RANGE,
    SEARCH_DIRECTIONS,
    SEARCH_FAMILIES,
    quantity_note,
    quantity_problem,
)
from shared_schema.spec import TRIBUTARY_DEFAULT, Overburden, Selector, TieBar
from shared_schema.text import decode_text

__all__ = [
    "SEARCH_SPEC_EXPECTED",
    "SEARCH_VERSION",
    "SEARCH_VERSIONS",
    "Candidates",
    "FirstMode",
    "Junction",
    "JunctionDefault",
    "Level",
    "Ranking",
    "SearchSpec",
    "SearchWall",
    "Unit",
    "parse_search_spec",
]

#: Format version of search specs written today; a file without ``search_version`` is read as it.
SEARCH_VERSION = "1.0"
#: Versions this reader understands.
SEARCH_VERSIONS = ("1.0",)
#: Largest masonry unit side [m] accepted (a 2 m ashlar is already exceptional).
UNIT_MAX_M = 5.0
#: Largest friction coefficient accepted (no masonry joint is rougher than 2).
FRICTION_MAX = 2.0
#: Highest first-mode frequency of a building accepted [Hz] (a one-storey masonry
#: building is about 10-20 Hz).
FIRST_MODE_F_MAX = 100.0
#: Plausible course height of a masonry unit, with its bed joint [m]: thin bricks and
#: Roman bricks are about 4 cm, ashlar courses up to about 1 m; below 2 cm the bond angle
#: atan(l_u / 2 h_u) runs towards 90 degrees and bounds nothing (issue #37).
UNIT_HEIGHT_PLAUSIBLE = (0.02, 1.0)
#: Plausible length of a masonry unit along the course [m]: a half brick is about 5 cm, an
#: ashlar over 2 m is exceptional.
UNIT_LENGTH_PLAUSIBLE = (0.05, 2.0)

_STRICT = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False)

Connection = Literal["good", "poor", "tied"]
Family = Literal[
    "overturning",
    "partial_overturning",
    "wedge_overturning",
    "vertical_flexure",
    "corner",
    "gable",
    "parapet",
]
Direction = Literal["outward", "inward"]


def _all_families() -> List[Family]:
    return cast(List[Family], list(SEARCH_FAMILIES))


def _all_directions() -> List[Direction]:
    return cast(List[Direction], list(SEARCH_DIRECTIONS))


def _density(value: float) -> float:
    problem = quantity_problem(value, "density")
    if problem is not None:
        raise ValueError(problem)
    return value


class Unit(BaseModel):
    """A masonry unit: its length along the course and its height (with the joint) [m].

    The bond of a good connection makes a crack through the return wall run at least at
    ``β_bond = atan(l_u / (2 h_u))`` from the vertical (half a unit of overlap per course).
    """

    model_config = _STRICT
    length: float = Field(gt=0, le=UNIT_MAX_M, description="Unit length l_u [m].")
    height: float = Field(gt=0, le=UNIT_MAX_M, description="Course height h_u [m].")


class SearchWall(BaseModel):
    """A wall: one solid of the scene, its density, and what loads its top.

    Attributes
    ----------
    id : str
        Name of the wall in the search's output and in the junctions.
    object : selector
        The wall's solid: a name, or ``{"name"|"layer"|"id": ...}`` matching one object.
    density : float
        [kg/m³].
    facade : bool
        Search this wall's own out-of-plane mechanisms (default true); false: the wall only
        takes part as a return wall of the others.
    overburden : Overburden, optional
        What loads the wall's top in vertical flexure (objects or a force [N]), as in the
        mechanism spec's two-block wall.
    """

    model_config = _STRICT
    id: str = Field(min_length=1, description="Wall id (unique).")
    object: Selector = Field(description="The wall's solid (one object).")
    density: float = Field(gt=0, description="Density [kg/m^3].")
    label: Optional[str] = Field(default=None, description="Material name for reports.")
    facade: bool = Field(default=True, description="Search its out-of-plane mechanisms.")
    overburden: Optional[Overburden] = Field(
        default=None, description="Load on its top in vertical flexure (objects or force [N])."
    )

    _check_density = field_validator("density")(classmethod(lambda cls, v: _density(v)))


class Level(BaseModel):
    """A floor or the roof: objects of one density that load, or hold, the walls they touch.

    Whether it bears on a wall or only abuts it follows from the contact (a horizontal
    contact bears), as in the mechanism spec; ``tributary`` is the share of its weight and
    inertia a wall carries. ``tied``: the level is tied into the walls (ties, a ring beam,
    anchored joists), so it holds them horizontally at its height. A roof pushes the walls
    it bears on (``thrust``, its horizontal thrust from span and rise, theory §5) unless it
    is a tied truss (``thrust: false``).
    """

    model_config = _STRICT
    id: str = Field(min_length=1, description="Level id (unique).")
    kind: Literal["floor", "roof"] = Field(description="A floor or the roof.")
    objects: List[Selector] = Field(min_length=1, description="Object selectors.")
    density: float = Field(gt=0, description="Density [kg/m^3].")
    tributary: float = Field(
        default=TRIBUTARY_DEFAULT, gt=0, le=1, description="Share carried by a wall."
    )
    tied: bool = Field(default=False, description="Tied into the walls (holds them there).")
    thrust: Optional[bool] = Field(
        default=None, description="Roof only: pushes the walls (default true; false: tied truss)."
    )

    _check_density = field_validator("density")(classmethod(lambda cls, v: _density(v)))

    @model_validator(mode="after")
    def _thrust_for_roofs(self) -> "Level":
        if self.thrust is not None and self.kind != "roof":
            raise ValueError("'thrust' applies to a roof only")
        return self

    @property
    def pushes(self) -> bool:
        """Whether the level thrusts on the walls (a roof that is not a tied truss)."""
        return self.kind == "roof" and self.thrust is not False


class Junction(BaseModel):
    """How two walls that meet are connected.

    ``good`` needs the ``unit`` (the bond bounds the crack angle), ``poor`` lets the walls
    part along the junction, ``tied`` holds them together.
    """

    model_config = _STRICT
    walls: List[str] = Field(min_length=2, max_length=2, description="The two wall ids.")
    connection: Connection = Field(description="good, poor or tied.")
    unit: Optional[Unit] = Field(default=None, description="Masonry unit (good connections).")

    @model_validator(mode="after")
    def _unit_for_good(self) -> "Junction":
        if self.walls[0] == self.walls[1]:
            raise ValueError(f"a junction joins two different walls, got {self.walls}")
        if self.connection == "good" and self.unit is None:
            raise ValueError(
                "a good connection needs the masonry 'unit' (length, height [m]): the bond "
                "bounds the crack angle"
            )
        return self


class JunctionDefault(BaseModel):
    """The connection of every junction the spec does not list."""

    model_config = _STRICT
    connection: Connection
    unit: Optional[Unit] = None

    @model_validator(mode="after")
    def _unit_for_good(self) -> "JunctionDefault":
        if self.connection == "good" and self.unit is None:
            raise ValueError("a good connection needs the masonry 'unit' (length, height [m])")
        return self


class Candidates(BaseModel):
    """How densely the search samples its mechanisms.

    Attributes
    ----------
    grid : int
        Seed-grid points per continuous parameter before the local polish.
    spacing : float, optional
        Add a candidate hinge line every ``spacing`` metres of height (besides levels,
        sills and lintels).
    keep : int
        How many mechanisms (lowest λ0 first) get their rocking constants from the
        builder and are ranked by their rocking response.
    """

    model_config = _STRICT
    grid: int = Field(default=13, ge=3, le=401, description="Seed-grid points per parameter.")
    spacing: Optional[float] = Field(
        default=None, gt=0, description="Extra hinge lines every spacing metres [m]."
    )
    keep: int = Field(default=50, ge=1, le=500, description="Mechanisms built and ranked.")


class Ranking(BaseModel):
    """What the mechanisms are ranked on.

    Attributes
    ----------
    band_hz : [float, float]
        Pulse frequency band [Hz] of the overturning acceleration.
    n_frequencies : int
        Frequencies in the band (log-spaced).
    site : str, optional
        Site file (SITE.json) for the code check, relative to the search spec.
    records : list of str
        Record files, relative to the search spec, for the scale factors to overturn.
    keep : int
        How many of the best ranked mechanisms run the records and the code check.
    """

    model_config = _STRICT
    band_hz: List[float] = Field(
        default_factory=lambda: [0.5, 10.0],
        min_length=2,
        max_length=2,
        description="[f_min, f_max] [Hz].",
    )
    n_frequencies: int = Field(default=400, ge=2, le=4000, description="Frequencies in the band.")
    site: Optional[str] = Field(default=None, description="Site file, relative to the spec.")
    records: List[str] = Field(default_factory=list, description="Record files.")
    keep: int = Field(default=10, ge=1, le=100, description="Top mechanisms run on records.")

    @field_validator("band_hz")
    @classmethod
    def _band(cls, band: List[float]) -> List[float]:
        lo, hi = F_P_RANGE
        if not lo <= band[0] < band[1] <= hi:
            raise ValueError(
                f"must be [f_min, f_max] with {lo:g} <= f_min < f_max <= {hi:g} Hz, got "
                f"{list(band)}"
            )
        return band


class FirstMode(BaseModel):
    """The building's first mode, for ranking each mechanism where it sits (theory §7).

    Attributes
    ----------
    f_n : float
        Natural frequency of the building's first mode [Hz].
    h_e : float
        Its effective (modal) height, ``sum(m h²)/sum(m h)`` [m].

    Without it the site's ``building`` gives them (``T1``, or Circolare 2019 [C7.3.2] from
    its height; ``h_e = H (2n + 1)/(3n)``, the linear first mode of ``n`` equal storeys).
    """

    model_config = _STRICT
    f_n: float = Field(gt=0, le=FIRST_MODE_F_MAX, description="First-mode frequency [Hz].")
    h_e: float = Field(gt=0, le=UNIT_MAX_M * 100, description="Effective (modal) height [m].")


class SearchSpec(BaseModel):
    """A search spec file (see the module docstring).

    Attributes
    ----------
    walls : list of SearchWall
        At least one; ids unique.
    openings : list of selectors
        Openings drawn as solids (subtracted from the walls they cross); voids need none.
    levels : list of Level
        Floors and roof.
    junctions : list of Junction
        The connection of each pair of walls that meet.
    default_junction : JunctionDefault, optional
        The connection of junctions not listed; without it an unlisted junction is an error.
    tie_bars : list of TieBar
        As in the mechanism spec (a line object and a restraining force [N]).
    families, directions
        What to search (``rules.SEARCH_FAMILIES``, ``rules.SEARCH_DIRECTIONS``).
    friction : float
        Friction coefficient of the joints, for the sliding check [-].
    candidates, ranking
        Sampling and ranking options.
    first_mode : FirstMode, optional
        The building's first mode (f_n, h_e) for the mechanisms above ground (default: from
        the site's ``building``).
    lp : bool
        Run the global upper-bound check (a linear programme over all candidate lines).
    """

    model_config = _STRICT
    search_version: str = SEARCH_VERSION
    walls: List[SearchWall] = Field(min_length=1)
    openings: List[Selector] = Field(default_factory=list)
    levels: List[Level] = Field(default_factory=list)
    junctions: List[Junction] = Field(default_factory=list)
    default_junction: Optional[JunctionDefault] = None
    tie_bars: List[TieBar] = Field(default_factory=list)
    families: List[Family] = Field(default_factory=_all_families, min_length=1)
    directions: List[Direction] = Field(default_factory=_all_directions, min_length=1)
    friction: float = Field(default=0.6, gt=0, le=FRICTION_MAX, description="Joint friction [-].")
    candidates: Candidates = Field(default_factory=Candidates)
    ranking: Ranking = Field(default_factory=Ranking)
    first_mode: Optional[FirstMode] = Field(
        default=None, description="The building's first mode (f_n [Hz], h_e [m])."
    )
    lp: bool = Field(default=True, description="Run the global upper-bound check.")

    @field_validator("search_version")
    @classmethod
    def _known_version(cls, version: str) -> str:
        if version not in SEARCH_VERSIONS:
            raise ValueError(
                f"unknown search_version {version!r}; this rockmech reads "
                f"{', '.join(repr(v) for v in SEARCH_VERSIONS)}"
            )
        return version

    @model_validator(mode="after")
    def _consistent(self) -> "SearchSpec":
        for kind, items in (("wall", self.walls), ("level", self.levels)):
            seen: List[str] = []
            for item in items:
                if item.id in seen:
                    raise ValueError(f"duplicate {kind} id {item.id!r}")
                seen.append(item.id)
        ids = [w.id for w in self.walls]
        pairs: List[Any] = []
        for k, j in enumerate(self.junctions):
            for name in j.walls:
                if name not in ids:
                    raise ValueError(f"junctions[{k}]: no wall with id {name!r}; walls: {ids}")
            pair = sorted(j.walls)
            if pair in pairs:
                raise ValueError(f"junctions[{k}]: the junction {pair} is listed twice")
            pairs.append(pair)
        for name, values in (("families", self.families), ("directions", self.directions)):
            if len(set(values)) != len(values):
                raise ValueError(f"{name}: a value is listed twice: {values}")
        if not any(w.facade for w in self.walls):
            raise ValueError(
                "no wall is a facade ('facade': false on every wall): nothing to search"
            )
        return self

    def connection_of(self, a: str, b: str) -> Optional[Tuple[Connection, Optional[Unit], str]]:
        """Return the connection the spec gives the junction of walls ``a`` and ``b``, or None.

        The junction listed in ``junctions`` (either order), else ``default_junction``:
        ``(connection, unit, where)`` with ``where`` ``"junctions[k]"`` or
        ``"default_junction"``; None where the spec covers neither.
        """
        pair = sorted([a, b])
        for k, j in enumerate(self.junctions):
            if sorted(j.walls) == pair:
                return j.connection, j.unit, f"junctions[{k}]"
        if self.default_junction is not None:
            d = self.default_junction
            return d.connection, d.unit, "default_junction"
        return None

    def plausibility_notes(self) -> List[str]:
        """Warnings for admissible but implausible inputs (``rules.QUANTITY_RANGES``)."""
        notes = []
        for k, w in enumerate(self.walls):
            notes.append(quantity_note(w.density, "density", f"walls[{k}].density"))
        for k, lv in enumerate(self.levels):
            notes.append(quantity_note(lv.density, "density", f"levels[{k}].density"))
        for k, tie in enumerate(self.tie_bars):
            notes.append(quantity_note(tie.force, "force", f"tie_bars[{k}].force"))
        units = [(f"junctions[{k}].unit", j.unit) for k, j in enumerate(self.junctions)]
        if self.default_junction is not None:
            units.append(("default_junction.unit", self.default_junction.unit))
        for where, unit in units:
            if unit is not None:
                notes.extend(_unit_notes(unit, where))
        return [n for n in notes if n is not None]


#: What a search spec must be, for the messages on empty, binary or non-UTF-8 files.
SEARCH_SPEC_EXPECTED = 'a search spec (JSON, {"walls": [...], "levels": [...], ...})'


def _unit_notes(unit: Unit, where: str) -> List[str]:
    """Warnings for a masonry unit of implausible size (each names its field)."""
    notes = []
    for name, value, (lo, hi), what in (
        ("height", unit.height, UNIT_HEIGHT_PLAUSIBLE, "a course (unit and bed joint)"),
        ("length", unit.length, UNIT_LENGTH_PLAUSIBLE, "a unit along its course"),
    ):
        if not lo <= value <= hi:
            notes.append(
                f"{where}.{name} = {value:g} m is outside the plausible range "
                f"[{lo:g}, {hi:g}] m for {what}; the bond angle atan(l_u / 2 h_u) = "
                f"{math.degrees(math.atan(unit.length / (2.0 * unit.height))):.1f} deg bounds the "
                "cracks through the return walls: check the unit's size and that it is in metres"
            )
    return notes


def parse_search_spec(text: Union[str, bytes], source: str = "search spec") -> SearchSpec:
    """Validate a search spec's JSON text, or a file's bytes; every error is listed, one per line.

    Bytes are decoded by ``shared_schema.text.decode_text``: an empty or binary file, or
    text that is not UTF-8 (nor UTF-16/32 with a byte-order mark), is an ``InputError``
    naming ``spec`` and the file, never a codec's or the JSON parser's error.

    Raises
    ------
    InputError
        ``search.json: walls[0].density: ...`` (one line per error), field = the source;
        ``spec: search.json is not a text file ...`` for bytes that are not text.
    """
    if isinstance(text, bytes):
        text = decode_text(text, source, "spec", SEARCH_SPEC_EXPECTED)
    try:
        return SearchSpec.model_validate_json(text)
    except ValidationError as exc:
        data: Any = None
        try:
            data = json.loads(text)
        except (ValueError, RecursionError):  # pydantic has named the error already
            pass
        lines = [f"{path}: {msg}" if path else msg for path, msg in validation_lines(exc, data)]
        raise InputError("\n".join(lines), source) from None
