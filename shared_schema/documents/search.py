"""The search document: a façade's mechanisms found, built and ranked (``search.json``).

``rockmech search`` writes it (and prints it with ``--json``), REST ``/search`` answers it
and ``rockmech.search`` returns it (``SearchRun.doc``). Fields in the order ``search.json``
has them; a candidate's sections that a step did not reach (not built, not among the top
ranked, no records or site) are absent. Units: lengths in m (names end ``_m``), masses in
kg, forces in N, pulse frequencies in Hz, accelerations in g (``_g``), angles in rad
(``_rad``; ``_deg`` beside them), multipliers λ dimensionless (``units``).
Python 3.9-clean.
"""

from typing import Annotated, Any, Dict, List, Literal, Optional, Union

from pydantic import Field

from shared_schema.constants import SideConstants
from shared_schema.spec import Amplification

from .base import Document, Part, find_entry
from .check import CheckSite, LinearCheck, NonlinearCheck
from .envelope import Band, ExactMethod, LibraryMethod

__all__ = [
    "BuilderAgreement",
    "CandidateCheck",
    "CandidateConstants",
    "CandidateRecord",
    "CrackPatch",
    "CrackPlane",
    "GlobalCheck",
    "LevelLoad",
    "MissedBlock",
    "MissedBody",
    "Overburden",
    "Overturning",
    "Piece",
    "RankDifference",
    "Rankings",
    "RecordScaleFactor",
    "SearchBand",
    "SearchBuilding",
    "SearchCandidate",
    "SearchCodeCheck",
    "SearchCounts",
    "SearchDocument",
    "SearchFailure",
    "SearchInput",
    "SearchJunction",
    "SearchRecord",
    "SearchTimings",
    "SearchWall",
    "Sliding",
    "TieLoad",
]

Point3 = List[float]


class SearchWall(Part):
    """A wall of the scene as the search read it (a prism with openings)."""

    object: str = Field(description="The scene object's selector (id or name).")
    thickness_m: float = Field(description="Thickness [m].")
    length_m: float = Field(description="Length along the wall [m].")
    height_m: float = Field(description="Height from base to top [m].")
    exact_prism: bool = Field(description="The object is an exact prism (else idealised).")
    openings: int = Field(description="Openings cut through it.")
    facade: bool = Field(description="Searched as a façade (else a return wall only).")


class SearchJunction(Part):
    """A return wall at one end of a façade, and how the two are bonded."""

    facade: str = Field(description="The façade's wall id.")
    wall: str = Field(description="The return wall's id.")
    end: Literal["start", "end"] = Field(description="Which end of the façade it meets.")
    connection: str = Field(description="The junction's connection (good, poor, none).")
    beta_bond_rad: float = Field(description="Bond angle of the masonry units [rad].")
    corner: bool = Field(description="The two walls meet at a corner.")


class SearchInput(Part):
    """What was searched: the files, the walls read and the spec's choices."""

    scene: str = Field(description="The scene's name.")
    spec: str = Field(description="The search spec's name.")
    scene_units: Optional[str] = Field(description="The scene's length unit.")
    walls: Dict[str, SearchWall] = Field(description="Per wall id, the wall read.")
    junctions: List[SearchJunction] = Field(description="Per façade end, its return wall.")
    families: List[str] = Field(description="The mechanism families searched.")
    directions: List[str] = Field(description="The directions searched (outward, inward).")
    friction: float = Field(description="Friction coefficient μ of the hinge joints [-].")


class SearchBand(Part):
    """The pulse frequencies the mechanisms are ranked over."""

    f_p: List[float] = Field(description="Pulse frequencies, log-spaced over the band [Hz].")
    band_hz: List[float] = Field(description="The band's ends [Hz].")


class CrackPlane(Part):
    """A plane a candidate's crack lies in, through one wall."""

    wall: str = Field(description="The wall's id.")
    point: Point3 = Field(description="A point of the plane [m].")
    normal: Point3 = Field(description="Its unit normal [-].")


class CrackPatch(Part):
    """A crack as a planar patch through a wall's thickness."""

    wall: str = Field(description="The wall's id.")
    segment: List[List[float]] = Field(description="Two (s, z) points in its elevation [m].")
    corners: List[Point3] = Field(description="Four world points of the patch [m].")


class Piece(Part):
    """The part of one wall that moves with the mechanism."""

    wall: str = Field(description="The wall's id.")
    mass_kg: float = Field(description="Its mass [kg].")


class LevelLoad(Part):
    """A floor or roof resting on (or thrusting against) the moving part."""

    level: str = Field(description="The level's id.")
    at_m: Point3 = Field(description="Where it loads the mechanism [m].")
    mass_kg: float = Field(description="Mass it carries onto the mechanism [kg].")
    bearing: bool = Field(description="It bears on the moving part (moves with it).")
    thrust_N: float = Field(description="Horizontal thrust on the mechanism [N].")


class TieLoad(Part):
    """A tie-bar that restrains the moving part."""

    tie_bar: int = Field(description="Index of the tie-bar in the spec's tie_bars.")
    at_m: Point3 = Field(description="Where it acts [m].")
    force_N: float = Field(description="Its force [N].")


class Sliding(Part):
    """The hinge joint would slide before the mechanism rocks."""

    required: float = Field(description="Friction coefficient needed at λ0 [-].")
    friction: float = Field(description="The spec's friction coefficient μ [-].")
    note: str = Field(description="The flag in words.")


class Overburden(Part):
    """The load on the moving part's top from the masonry above it."""

    N: float = Field(description="Vertical force [N].")
    x_m: float = Field(description="Where it acts across the wall [m].")
    xi_from_outer_face: float = Field(description="That place as a fraction of the thickness [-].")


class Overturning(Part):
    """The mechanism's overturning acceleration over the band (its dynamic score)."""

    a_p_min_g: List[Optional[float]] = Field(
        description="Least overturning ground pulse amplitude per frequency [g] (null: none "
        "up to the search limit)."
    )
    band_score_g: Optional[float] = Field(
        description="Geometric mean of a_p_min_g over the band [g] (the ranking's score)."
    )
    min_g: Optional[float] = Field(description="The least a_p_min_g [g].")
    f_at_min_hz: Optional[float] = Field(description="The frequency of min_g [Hz].")
    a_p_min_local_g: Optional[List[Optional[float]]] = Field(
        None, description="Above ground: the amplitude at the mechanism's base [g]."
    )
    scale_factor: Optional[List[Optional[float]]] = Field(
        None, description="Above ground: Eq. 28's SF(f_p) the local envelope is divided by [-]."
    )
    band_score_local_g: Optional[float] = Field(
        None, description="Above ground: the band score of the local envelope [g]."
    )
    sf_formula: Optional[str] = Field(None, description="Above ground: SF(f_p) in words.")


class BuilderAgreement(Part):
    """The constants builder against the search: its λ0 and mass, or why it failed."""

    lam0: Optional[float] = Field(None, description="The builder's exact λ0 [-].")
    lam0_rel: Optional[float] = Field(None, description="Relative difference from the search's.")
    mass_rel: Optional[float] = Field(None, description="Relative difference of the masses.")
    agrees: Optional[bool] = Field(None, description="Both within the tolerance.")
    tolerance: Optional[float] = Field(None, description="The tolerance (relative) [-].")
    error: Optional[str] = Field(None, description="The builder failed: its message.")


class CandidateConstants(Part):
    """The built mechanism's kinematic constants (as ``constants.json`` holds them)."""

    positive: SideConstants = Field(description="Rocking to the positive side.")
    negative: Optional[SideConstants] = Field(description="The negative side (null: one-sided).")
    eta: Optional[float] = Field(description="Coefficient of restitution [-].")
    eta_source: Optional[str] = Field(description="Where eta comes from.")


class RecordScaleFactor(Part):
    """Eq. 28's scale factor of a record up the building (a mechanism above ground)."""

    value: float = Field(description="SF [-].")
    method: str = Field(description="The method (eq28).")
    formula: str = Field(description="The formula in words.")
    inputs: Dict[str, Any] = Field(description="Its inputs (heights [m], accelerations [g]).")


class CandidateRecord(Part):
    """A record's least scale factor that overturns the mechanism (exact solver)."""

    record: str = Field(description="The record's name.")
    scale: Optional[float] = Field(
        description="Least ground scale factor that overturns it [-] (null: none up to the "
        "grid's top)."
    )
    bracket: Optional[List[float]] = Field(
        description="The bracket [safe, overturns] it was bisected in [-]."
    )
    pga_g: Optional[float] = Field(description="The record's PGA at that scale [g].")
    criterion: str = Field(description="The overturning criterion.")
    scale_local: Optional[float] = Field(
        None, description="Above ground: the scale at the mechanism's base [-]."
    )
    scale_factor: Optional[RecordScaleFactor] = Field(
        None, description="Above ground: Eq. 28's SF the local scale is divided by."
    )


class CandidateCheck(Part):
    """The code check of a top mechanism (``rockmech check``'s row)."""

    alpha0: Optional[float] = Field(description="Activation multiplier α0 [-].")
    passes: Optional[bool] = Field(description="Both checks pass at SLV (null: not run).")
    linear: LinearCheck = Field(description="The governing linear check.")
    nonlinear: NonlinearCheck = Field(description="The governing nonlinear check.")
    Z: float = Field(description="Height of its base above the ground [m].")
    Z_source: str = Field(description="Where Z comes from.")
    T1: Optional[float] = Field(description="The building's first period [s].")
    T1_source: Optional[str] = Field(description="Where T1 comes from.")


class SearchCandidate(Part):
    """A refined mechanism: where it is, its λ0, and what the later steps found."""

    id: str = Field(description="The mechanism's id (S01, S02, ... by λ0).")
    rank_static: int = Field(description="Its rank by λ0 (1: least).")
    family: str = Field(description="The catalogue family.")
    facade: str = Field(description="The façade's wall id.")
    direction: Literal["outward", "inward"] = Field(description="The direction it rocks.")
    typology: str = Field(description="The mechanism typology it is built as.")
    rocking: Literal["two_sided", "one_sided"] = Field(description="Rocking kind.")
    parameters: Dict[str, float] = Field(
        description="Its refined parameters (names end in their unit: _m, _rad, _deg)."
    )
    bounds: Dict[str, List[float]] = Field(description="Each parameter's search interval.")
    on_bound: List[str] = Field(description="Parameters whose optimum lies on a bound.")
    lam0: float = Field(description="Exact static multiplier λ0 [-].")
    hinge_axis: List[Point3] = Field(description="Two points of the hinge line [m].")
    direction_vector: Point3 = Field(description="The horizontal load's direction [-].")
    crack_planes: List[CrackPlane] = Field(description="The planes of its cracks.")
    cracks: List[CrackPatch] = Field(description="The cracks as patches through the walls.")
    pieces: List[Piece] = Field(description="The moving part of each wall.")
    mass_kg: float = Field(description="Mass of the moving part [kg].")
    levels: List[LevelLoad] = Field(description="The floors and roofs on it.")
    tie_bars: List[TieLoad] = Field(description="The tie-bars that restrain it.")
    Z_m: float = Field(description="Height of its base above the ground [m].")
    n_evaluations: int = Field(description="Evaluations of λ0 its refinement took.")
    sliding: Optional[Sliding] = Field(description="Sliding governs (null: rocking holds).")
    notes: List[str] = Field(description="Where it needs care.")
    lam0_negative: Optional[float] = Field(None, description="λ0 rocking the other way [-].")
    overburden: Optional[Overburden] = Field(None, description="The masonry above it.")
    overturning: Optional[Overturning] = Field(
        None, description="Built: its overturning acceleration over the band."
    )
    amplification: Optional[Amplification] = Field(
        None, description="Above ground: the building's first mode (f_n [Hz], h_e [m], h [m])."
    )
    builder: Optional[BuilderAgreement] = Field(
        None, description="Built or tried: the builder's agreement, or its error."
    )
    lam_linearised: Optional[float] = Field(
        None, description="Built: the builder's linearised λ [-]."
    )
    constants: Optional[CandidateConstants] = Field(
        None, description="Built: its kinematic constants."
    )
    rank_dynamic: Optional[int] = Field(
        None, description="Built: its rank by band score (1: least)."
    )
    records: Optional[List[CandidateRecord]] = Field(
        None, description="Top ranked, with records: each record's scale to overturn it."
    )
    code_check: Optional[CandidateCheck] = Field(
        None, description="Top ranked, with a site: its code check."
    )


class RankDifference(Part):
    """A built mechanism whose static and dynamic ranks differ."""

    id: str = Field(description="The mechanism's id.")
    static: int = Field(description="Its rank by λ0 among the built.")
    dynamic: int = Field(description="Its rank by band score.")


class Rankings(Part):
    """The static (λ0) and dynamic (overturning acceleration) rankings."""

    static: List[str] = Field(description="Every candidate, least λ0 first.")
    dynamic: List[str] = Field(description="The built ones, least band score first.")
    differences: List[RankDifference] = Field(description="Where the two rankings differ.")
    summary: List[str] = Field(description="The difference at the top, in words.")
    governing: List[Optional[str]] = Field(
        description="Per frequency of band.f_p, the mechanism that overturns first."
    )
    critical: List[Band] = Field(description="The mechanism that overturns first, by band.")
    envelope_method: Optional[
        Annotated[Union[ExactMethod, LibraryMethod], Field(discriminator="source")]
    ] = Field(description="How the envelopes were computed (null: none built).")
    band_score: str = Field(description="The score, in words.")


class MissedBlock(Part):
    """A macro-block of the global check's mechanism."""

    wall: str = Field(description="Its wall's id.")
    rings: List[List[List[float]]] = Field(description="Its outline in the wall's elevation [m].")


class MissedBody(Part):
    """A rigid body of the global check's mechanism (blocks that move together)."""

    blocks: List[MissedBlock] = Field(description="Its macro-blocks.")
    rotation: Point3 = Field(description="Its virtual rotation [-].")
    velocity_at_centre: Point3 = Field(description="Its virtual velocity at the centre [m].")


class GlobalCheck(Part):
    """The global upper-bound check of one façade and direction (a linear programme)."""

    facade: str = Field(description="The façade's wall id.")
    direction: Literal["outward", "inward"] = Field(description="The load's direction.")
    lam: Optional[float] = Field(description="The check's least multiplier [-].")
    best_catalogue_lam0: float = Field(description="The catalogue's least λ0 there [-].")
    gap: float = Field(description="(best - lam) / best [-].")
    missed: bool = Field(description="The gap exceeds the threshold: a mechanism was missed.")
    threshold: float = Field(description="The gap that counts as missed [-].")
    message: str = Field(description="The verdict in words.")
    lam_friction: Optional[float] = Field(
        description="The multiplier with associative friction [-] (null: none found)."
    )
    sliding_governs: bool = Field(description="Friction lowers the multiplier: sliding governs.")
    status: str = Field(description="The solver's status.")
    n_blocks: int = Field(description="Macro-blocks.")
    n_rows: int = Field(description="Constraint rows.")
    n_columns: int = Field(description="Unknowns.")
    lines: Dict[str, Any] = Field(
        description="The crack lines it may use: heights [m], per return wall its diagonals [rad]."
    )
    mechanism: Optional[List[MissedBody]] = Field(
        description="Missed: the check's mechanism (null otherwise)."
    )
    sliding_note: Optional[str] = Field(None, description="Sliding governs: why.")


class SearchRecord(Part):
    """A record the top mechanisms ran, or why it could not."""

    record: str = Field(description="The record's name.")
    pga_g: Optional[float] = Field(None, description="Its peak ground acceleration [g].")
    dt: Optional[float] = Field(None, description="Its time step [s].")
    note: Optional[str] = Field(None, description="Not run: why.")


class SearchCodeCheck(Part):
    """The site of the top mechanisms' code checks and the one that governs."""

    site: CheckSite = Field(description="The site, as ``rockmech check`` reports it.")
    governing: Optional[str] = Field(description="The mechanism with the lowest capacity ratio.")


class SearchFailure(Part):
    """A candidate the constants builder could not build."""

    id: str = Field(description="The mechanism's id.")
    error: str = Field(description="The builder's message.")


class SearchCounts(Part):
    """Work counters."""

    walls: int = Field(description="Walls read.")
    candidates: int = Field(description="Candidates refined.")
    evaluations: int = Field(description="Evaluations of λ0.")
    lp_blocks: int = Field(description="Macro-blocks of the global checks.")
    lp_rows: int = Field(description="Constraint rows of the global checks.")
    built: int = Field(description="Mechanisms built.")


class SearchTimings(Part):
    """Wall-clock time per stage [s]."""

    read_s: float = Field(description="Reading the building [s].")
    search_s: float = Field(description="Refining the candidates [s].")
    lp_s: float = Field(description="The global checks [s].")
    constants_and_ranking_s: float = Field(description="Building and ranking [s].")
    records_s: float = Field(description="The records [s].")
    code_check_s: float = Field(description="The code check [s].")
    total_s: float = Field(description="The whole search [s].")


class SearchBuilding(Part):
    """The building's first mode for the mechanisms above ground, and its source."""

    given: bool = Field(description="There is building data (else all at ground level).")
    f_n_hz: Optional[float] = Field(description="First natural frequency [Hz].")
    T1_s: Optional[float] = Field(description="First period [s].")
    T1_source: Optional[str] = Field(description="Where T1 comes from.")
    h_e_m: Optional[float] = Field(description="Effective height of the first mode [m].")
    h_e_source: Optional[str] = Field(description="Where h_e comes from.")
    ground_z_m: float = Field(description="The ground: the lowest base of the walls [m].")
    Z_rule: str = Field(description="Where Z is measured from.")
    notes: List[str] = Field(description="Where the building data needs care.")


class SearchDocument(Document):
    """A façade's mechanisms found, built and ranked (``search.json``)."""

    kind: Literal["search"] = Field(description="The document's kind.")
    input: SearchInput = Field(description="What was searched.")
    band: SearchBand = Field(description="The pulse frequencies of the ranking.")
    candidates: List[SearchCandidate] = Field(description="Every candidate, least λ0 first.")
    rankings: Rankings = Field(description="The static and dynamic rankings.")
    lp: List[GlobalCheck] = Field(description="The global check per façade and direction.")
    records: List[SearchRecord] = Field(description="The records run (empty: none).")
    code_check: Optional[SearchCodeCheck] = Field(description="The code check (null: no site).")
    not_built: List[str] = Field(description="Candidates past candidates.keep, not built.")
    failures: List[SearchFailure] = Field(description="Candidates the builder could not build.")
    counts: SearchCounts = Field(description="Work counters.")
    timings: SearchTimings = Field(description="Wall-clock time per stage [s].")
    building: SearchBuilding = Field(description="The building's first mode.")
    assumptions: List[str] = Field(description="What the search assumes.")
    warnings: List[str] = Field(
        description="The spec's admissible but implausible values, each with what it most "
        "likely means."
    )
    notes: List[str] = Field(description="Where the results need care.")

    def find(self, mechanism_id: str) -> SearchCandidate:
        """Return the candidate ``mechanism_id``."""
        return find_entry(self.candidates, mechanism_id)

    @property
    def ranked(self) -> List[SearchCandidate]:
        """The candidates best ranked first: the dynamic ranking, else the static one."""
        order = self.rankings.dynamic or self.rankings.static
        by_id = {c.id: c for c in self.candidates}
        return [by_id[mid] for mid in order]
