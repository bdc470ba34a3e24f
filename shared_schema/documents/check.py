"""The check document: NTC 2018 / Circolare 2019 §C8.7.1 kinematic checks on a site.

``rockmech check --json``, REST ``/check``; the assessment document (``assess``) adds each
mechanism's ``dynamics`` and ``envelope``. Each check names the clause of each of its
numbers in ``clauses``. Its figures differ by method and by outcome, so each check is one of
its variants, told apart by ``status``, ``method`` and whether it has a capacity curve: a
linear check is ``Linear2019``, ``Linear2009`` or ``NotRun``; a nonlinear check
``Nonlinear2019`` (with its ``SLV`` and ``SLC`` limit states), ``NoCurve2019`` (the static
forces alone overturn the mechanism), ``Nonlinear2009`` or ``NotRun``. The site code (NTC
2018, EC8) changes the hazard's ``params`` (``NtcParams``, ``Ec8Params``). Figures a variant
gives only in some cases (a free-standing element's, a mechanism above ground's floor
spectrum, the ties) are absent where they do not apply. docs/assess.md describes the fields.
Units: accelerations in m/s² (names ending ``_star``, ``demand_activation``, a linear
``demand``) or g (``_g``, ``a_g``), displacements in m (a nonlinear ``demand``), periods in s
(``units``). Python 3.9-clean.
"""

from typing import Annotated, Any, Dict, List, Literal, Optional, Union

from pydantic import ConfigDict, Discriminator, Field, Tag

from .base import DOCUMENT_CONFIG, Document, Part, find_entry
from .history import ScaleFactor

__all__ = [
    "Adrs",
    "AssessEnvelope",
    "CapacityCurve",
    "CheckDocument",
    "CheckMechanism",
    "CheckMethod",
    "CheckSide",
    "CheckSite",
    "CheckSpectrum",
    "CodeCheckRatio",
    "Conclusion",
    "Curve2009",
    "DesignScale",
    "Ec8Params",
    "FloorTerms",
    "FreeStanding",
    "LimitStateCheck",
    "LimitStateHazard",
    "LimitStates",
    "Linear2009",
    "Linear2019",
    "LinearCheck",
    "MechanismVerdict",
    "MultipleRun",
    "NoCurve2019",
    "Nonlinear2009",
    "Nonlinear2019",
    "NonlinearCheck",
    "NotRun",
    "NtcParams",
    "PulseMargin",
    "RecordDemandRow",
    "RecordRuns",
    "TieBar",
    "Ties",
    "TiesCurve",
]

#: A figure of a check: null in the JSON only where it is not finite (extreme inputs).
Num = Optional[float]
_CLAUSES = "The clause and equation of each number above (key: its name)."
_NOTES = "Every note of the check (the floor, T1 against 1/f_n, no SLV, the ties)."


def _free(text: str) -> Any:
    """Return the field of a free-standing element's figure ([C8.7.1.7]; absent otherwise)."""
    return Field(None, description=f"Free-standing element: {text}")


class NtcParams(Part):
    """The NTC 2018 hazard as given, with its derived factors (§3.2.3)."""

    a_g_g: Num = Field(description="Ground acceleration on type A ground, a_g [g].")
    F0: Num = Field(description="Spectral amplification F0 [-].")
    Tc_star_s: Num = Field(description="T_C* [s].")
    soil: str = Field(description="Ground category (A-E).")
    topography: str = Field(description="Topographic category (T1-T4).")
    S_S: Num = Field(description="Stratigraphic amplification S_S [-].")
    S_T: Num = Field(description="Topographic amplification S_T [-].")
    C_C: Num = Field(description="The factor of T_C, C_C [-].")
    xi_percent: Num = Field(description="Damping of the plotted spectrum [%].")


class Ec8Params(Part):
    """The EN 1998-1 hazard as given, with its derived factors (§3.2.2)."""

    a_gR_g: Num = Field(description="Reference peak ground acceleration a_gR [g].")
    gamma_I: Num = Field(description="Importance factor gamma_I [-].")
    a_g_g: Num = Field(description="Design ground acceleration a_g = gamma_I a_gR [g].")
    ground: str = Field(description="Ground type (A-E).")
    spectrum_type: int = Field(description="Spectrum type (1 or 2).")
    xi_percent: Num = Field(description="Damping of the plotted spectrum [%].")


class LimitStateHazard(Part):
    """The hazard of one limit state."""

    a_g: Num = Field(description="Ground acceleration on type A ground [g].")
    S: Num = Field(description="Soil and topography factor [-].")
    F: Num = Field(description="Spectral amplification [-].")
    T_B: Num = Field(description="Corner period T_B [s].")
    T_C: Num = Field(description="Corner period T_C [s].")
    T_D: Num = Field(description="Corner period T_D [s].")
    pga_g: Num = Field(description="Peak ground acceleration a_g S [g].")
    source: str = Field(description="Where the site file gives it.")


class LimitStates(Part):
    """Each limit state's hazard (null: the site gives none)."""

    SLV: Optional[LimitStateHazard] = Field(description="Life safety.")
    SLC: Optional[LimitStateHazard] = Field(description="Collapse prevention.")


class FloorTerms(Part):
    """The floor spectrum of a mechanism above ground (Circ. 2019 C8.7.1.2.1.4, C7.2.3)."""

    T1: Num = Field(description="The building's first period [s].")
    T_k: Num = Field(description="The building's period, elongated [s].")
    xi_k_percent: Num = Field(description="The building's damping [%].")
    gamma: Num = Field(description="Modal participation factor, 3n/(2n+1) [-].")
    psi: Num = Field(description="First mode at the mechanism's base, z/H [-].")
    a_Z_g: Num = Field(None, description="Floor acceleration at the base [g].")
    Se_Tk_g: Num = Field(None, description="S_e(T_k, xi_k) [g].")
    damping_term: Num = Field(None, description="sqrt(1 + 0.0004 xi_k^2) [-].")
    A: Num = Field(None, description="1.1 xi_k^-0.5 eta(xi) [-].")


class NotRun(Part):
    """A check that could not run, and why."""

    method: Literal["circ2019", "circ2009"] = Field(description="The forms of the check.")
    passes: None = Field(description="No verdict (null).")
    note: str = Field(description="Why the check did not run.")
    status: Literal["not_run"] = Field(description="The check did not run.")
    standard: Optional[str] = Field(None, description="The 2009 forms: the text, in full.")


class Linear2019(Part):
    """The linear check of the 2019 text, SLV with the behaviour factor (C8.7.1.2.1.7)."""

    model_config = ConfigDict(**{**DOCUMENT_CONFIG, "serialize_by_alias": True})

    method: Literal["circ2019"] = Field(description="The forms of the check.")
    standard: str = Field(description="The text and clause, in full.")
    status: Literal["ok"] = Field(description="The check ran.")
    alpha0: Num = Field(description="Static load multiplier at activation [-].")
    M_star: Num = Field(description="Participating mass M* [kg].")
    e_star: Num = Field(description="Participating mass fraction e* [-].")
    FC: Num = Field(description="Confidence factor [-].")
    q: Num = Field(description="Behaviour factor [-].")
    a0_star: Num = Field(description="Spectral acceleration of activation a0* [m/s²].")
    free_standing: bool = Field(description="The activation demand is S_e(T0) ([C8.7.1.9]).")
    xi_percent: Num = Field(description="Damping of the activation demand [%].")
    demand_activation: Num = Field(description="Activation demand [m/s²].")
    demand_rule: str = Field(description="How the activation demand is taken.")
    ratio_SLD: Num = Field(description="a0* over the activation demand, a_g,SLD/a_g [-].")
    a_g: Num = Field(description="The site's SLV a_g [g].")
    a_g_SLD: Num = Field(description="The a_g that activates the mechanism [g].")
    a_g_SLV: Num = Field(description="q a_g,SLD [g].")
    demand: Num = Field(description="Activation demand over q [m/s²].")
    capacity_ratio: Num = Field(description="a_g,SLV/a_g [-]; the check passes at >= 1.")
    notes: List[str] = Field(description=_NOTES)
    T0: Num = _free("its first period T0 [s] (null: data missing).")
    kappa: Num = _free("the factor kappa of T0 [-].")
    lambda_: Num = Field(
        None, alias="lambda", description="Free-standing element: its slenderness L/t [-]."
    )
    L: Num = _free("its free length L [m].")
    t: Num = _free("its thickness t [m].")
    W: Num = _free("the unit weight of its masonry W [N/m³].")
    E: Num = _free("the elastic modulus of its masonry E [Pa].")
    free_standing_sources: Optional[Dict[str, str]] = _free("where each of its data comes from.")
    floor: Optional[FloorTerms] = Field(None, description="Above ground: the floor spectrum.")
    passes: Optional[bool] = Field(description="The verdict (null: incomplete inputs).")
    clauses: Dict[str, str] = Field(description=_CLAUSES)
    note: str = Field(description="The notes, in one line.")
    e_star_rule: str = Field(description="How e* is computed (the site's choice).")


class RecordDemandRow(Part):
    """A record's largest spectral displacement over the band of a limit state."""

    record: str = Field(description="The record's name.")
    demand: Num = Field(description="Largest S_De [m].")
    at_T: Num = Field(description="The period where it is [s].")


class Adrs(Part):
    """The demand spectrum in ADRS form, for plotting."""

    T: List[Num] = Field(description="Periods [s].")
    d: List[Num] = Field(description="Spectral displacement [m].")
    a: List[Num] = Field(description="Spectral acceleration d (2 pi/T)^2 [m/s²].")


class LimitStateCheck(Part):
    """The displacement check of one limit state, SLV or SLC (C8.7.1.2.1.8)."""

    d: Num = Field(description="The limit state's displacement [m].")
    d_rule: str = Field(description="How d is taken (0.4 d0, 0.6 d0, the ties' break, ...).")
    a: Num = Field(description="Capacity curve's acceleration at d [m/s²].")
    T_SLV: Num = Field(None, description="SLV: the secant period 1.68 pi sqrt(d/a) [s].")
    T_SLC: Num = Field(None, description="SLC: the secant period 1.56 pi sqrt(d/a) [s].")
    xi_percent: Num = Field(description="The mechanism's damping [%].")
    demand_code: Num = Field(description="Largest S_De of the code over [T0, T] [m].")
    demand_code_at_T: Num = Field(description="The period where demand_code is [s].")
    demand_rule: str = Field(description="Which spectrum gives the demand.")
    demand_records: Num = Field(description="The records' largest S_De (null: no records) [m].")
    records: List[RecordDemandRow] = Field(description="Each record's demand.")
    demand: Num = Field(description="The larger of demand_code and demand_records [m].")
    ratio_displacement: Num = Field(description="d/demand [-].")
    a_g: Num = Field(description="The site's a_g of the limit state [g].")
    a_g_capacity: Num = Field(description="The a_g that brings the mechanism to d [g].")
    a_g_SLD: Num = Field(None, description="SLV: the activation's a_g, the lower bound [g].")
    lower_bound_applied: Optional[bool] = Field(
        None, description="SLV: a_g,SLD is above a_g_capacity and governs."
    )
    capacity_ratio: Num = Field(description="a_g_capacity/a_g [-]; passes at >= 1.")
    passes: Optional[bool] = Field(description="The verdict (null: not evaluated).")
    adrs: Adrs = Field(description="The demand spectrum, for plotting.")
    clauses: Dict[str, str] = Field(description=_CLAUSES)
    note: Optional[str] = Field(None, description="SLC without its hazard: why not evaluated.")


class CapacityCurve(Part):
    """The capacity curve of the 2019 text ([C8.7.1.3], [C8.7.1.6])."""

    d: List[Num] = Field(description="Displacement of the control point [m].")
    a: List[Num] = Field(description="Spectral acceleration [m/s²].")


class TiesCurve(Part):
    """The ties' line of the capacity curve, until their failure rotation."""

    alpha0: Num = Field(description="alpha0 with the ties [-].")
    phi0: Num = Field(description="phi0 with the ties [rad].")
    phi_break: Num = Field(description="Rotation where the ties fail [rad].")
    d_break: Num = Field(description="Displacement where the ties fail [m].")


class TieBar(Part):
    """A tie-bar of the mechanism's geometry."""

    element: Optional[str] = Field(description="The element's name.")
    force_N: Num = Field(description="Its force [N].")
    z_m: Num = Field(description="Height above the rotation axis [m].")
    x_m: Num = Field(description="Horizontal lever [m].")


class Ties(Part):
    """The tie-bars of the mechanism and how the capacity curve treats them (C8.7.1.2.1.6)."""

    present: bool = Field(description="The geometry has tie-bars.")
    note: Optional[str] = Field(None, description="No ties but M_F < 0: what that may hide.")
    clauses: Optional[Dict[str, str]] = Field(None, description=_CLAUSES)
    ties: Optional[List[TieBar]] = Field(None, description="The tie-bars.")
    M_F_ties: Num = Field(None, description="The ties' share of M_F [N m].")
    M_F_without: Num = Field(None, description="M_F without the ties [N m].")
    alpha0_with: Num = Field(None, description="alpha0 with every action [-].")
    alpha0_without: Num = Field(None, description="alpha0 without the ties [-].")
    phi0_with: Num = Field(None, description="phi0 with every static force [rad].")
    phi0_without: Num = Field(None, description="phi0 without the ties [rad].")
    phi0_no_static_forces: Num = Field(None, description="phi0 with M_F = 0 [rad].")
    treatment: Optional[str] = Field(None, description="verified or not_verified.")
    source: Optional[str] = Field(None, description="Where the treatment comes from.")
    rule: Optional[str] = Field(None, description="What the curve counts, and why.")


class Nonlinear2019(Part):
    """The nonlinear check of the 2019 text: SLV and SLC displacements (C8.7.1.2.1.6, 8)."""

    model_config = ConfigDict(**{**DOCUMENT_CONFIG, "serialize_by_alias": True})

    method: Literal["circ2019"] = Field(description="The forms of the check.")
    standard: str = Field(description="The text and clauses, in full.")
    status: Literal["ok"] = Field(description="The check ran.")
    alpha0: Num = Field(description="alpha0 of the actions kept in the curve [-].")
    e_star: Num = Field(description="Participating mass fraction e* [-].")
    FC: Num = Field(description="Confidence factor [-].")
    a0_star: Num = Field(description="a0* of every action (activation) [m/s²].")
    d_per_rad: Num = Field(description="Control displacement per radian [m/rad].")
    phi0: Num = Field(description="Rotation where the capacity vanishes [rad].")
    d0: Num = Field(description="Displacement where the capacity vanishes [m].")
    free_standing: bool = Field(description="A free-standing element ([C8.7.1.6] curve).")
    demand_activation: Num = Field(description="Activation demand, for a_g,SLD [m/s²].")
    activation_rule: str = Field(description="How the activation demand is taken.")
    SLV: LimitStateCheck = Field(description="The SLV displacement check.")
    SLC: LimitStateCheck = Field(description="The SLC displacement check.")
    T_SLV: Num = Field(description="SLV secant period [s].")
    d_SLV: Num = Field(description="SLV displacement [m].")
    demand: Num = Field(description="SLV displacement demand [m].")
    capacity_ratio: Num = Field(description="The SLV a_g ratio [-]; passes at >= 1.")
    passes: Optional[bool] = Field(description="The SLV verdict (null: not evaluated).")
    curve: CapacityCurve = Field(description="The capacity curve, for plotting.")
    notes: List[str] = Field(description=_NOTES)
    T0: Num = _free("its first period T0 [s] (null: data missing).")
    kappa: Num = _free("the factor kappa of T0 [-].")
    lambda_: Num = Field(
        None, alias="lambda", description="Free-standing element: its slenderness L/t [-]."
    )
    L: Num = _free("its free length L [m].")
    t: Num = _free("its thickness t [m].")
    W: Num = _free("the unit weight of its masonry W [N/m³].")
    E: Num = _free("the elastic modulus of its masonry E [Pa].")
    free_standing_sources: Optional[Dict[str, str]] = _free("where each of its data comes from.")
    d_y: Num = _free("the displacement of the yield point [C8.7.1.6] [m].")
    a_y: Num = _free("the acceleration of the yield point [m/s²].")
    ties_curve: Optional[TiesCurve] = Field(
        None, description="Ties failing at a given rotation: their line of the curve."
    )
    floor: Optional[FloorTerms] = Field(None, description="Above ground: the floor spectrum.")
    clauses: Dict[str, str] = Field(description=_CLAUSES)
    note: str = Field(description="The notes, in one line.")
    ties: Ties = Field(description="The tie-bars and how the curve treats them.")
    e_star_rule: str = Field(description="How e* is computed (the site's choice).")


class NoCurve2019(Part):
    """The nonlinear check without a capacity curve: the static forces alone overturn it."""

    method: Literal["circ2019"] = Field(description="The forms of the check.")
    standard: str = Field(description="The text, in full.")
    status: Literal["ok"] = Field(description="The check ran (and fails).")
    passes: Optional[bool] = Field(description="False (null: incomplete inputs).")
    capacity_ratio: Num = Field(description="0 [-].")
    demand: None = Field(description="No demand (null).")
    d_SLV: Num = Field(description="0 [m].")
    T_SLV: None = Field(description="No period (null).")
    note: str = Field(description="The notes, in one line.")
    notes: List[str] = Field(description=_NOTES)
    clauses: Dict[str, str] = Field(description=_CLAUSES)
    ties: Ties = Field(description="The tie-bars and why there is no curve.")
    e_star_rule: str = Field(description="How e* is computed (the site's choice).")


class Linear2009(Part):
    """The linear check of the 2009 forms (Circolare 617/2009 C8A.4), kept for comparison."""

    method: Literal["circ2009"] = Field(description="The forms of the check.")
    alpha0: Num = Field(description="Static load multiplier at activation [-].")
    M_star: Num = Field(description="Participating mass M* [kg].")
    e_star: Num = Field(description="Participating mass fraction e* [-].")
    FC: Num = Field(description="Confidence factor [-].")
    q: Num = Field(description="Behaviour factor [-].")
    a0_star: Num = Field(description="Spectral acceleration of activation a0* [m/s²].")
    Z: Num = Field(description="Height of the mechanism's base [m].")
    demand_ground: Num = Field(description="a_g S/q [m/s²].")
    demand_height: Num = Field(description="Above ground: S_e(T1) psi gamma/q [m/s²].")
    note: str = Field(description="Why the verdict is missing, if it is.")
    psi: Num = Field(None, description="Above ground: z/H [-].")
    gamma: Num = Field(None, description="Above ground: 3N/(2N+1) [-].")
    T1: Num = Field(None, description="Above ground: the building's period [s].")
    demand: Num = Field(description="The larger demand [m/s²].")
    capacity_ratio: Num = Field(description="a0*/demand [-]; passes at >= 1.")
    passes: Optional[bool] = Field(description="The verdict (null: no building above ground).")
    status: Literal["ok"] = Field(description="The check ran.")
    standard: str = Field(description="The text, in full.")


class Curve2009(Part):
    """The linear capacity curve of the 2009 forms."""

    d_star: List[Num] = Field(description="Spectral displacement d* [m].")
    a_star: List[Num] = Field(description="Spectral acceleration a* [m/s²].")
    alpha: List[Num] = Field(description="Load multiplier [-].")


class Nonlinear2009(Part):
    """The nonlinear check of the 2009 forms (Circolare 617/2009 C8A.4), kept for comparison."""

    method: Literal["circ2009"] = Field(description="The forms of the check.")
    FC: Num = Field(description="Confidence factor [-].")
    e_star: Num = Field(description="Participating mass fraction e* [-].")
    a0_star: Num = Field(description="Spectral acceleration of activation a0* [m/s²].")
    phi0: Num = Field(description="Rotation where the capacity vanishes [rad].")
    d0_star: Num = Field(description="Spectral displacement where it vanishes d0* [m].")
    du_star: Num = Field(description="Ultimate displacement 0.4 d0* [m].")
    ds_star: Num = Field(description="Secant displacement 0.4 du* [m].")
    as_star: Num = Field(description="Secant acceleration [m/s²].")
    Ts: Num = Field(description="Secant period [s].")
    Z: Num = Field(description="Height of the mechanism's base [m].")
    demand_ground: Num = Field(description="S_De(Ts) [m].")
    demand_height: Num = Field(description="Above ground: the floor's demand [m].")
    curve: Curve2009 = Field(description="The capacity curve, for plotting.")
    note: str = Field(description="Why the verdict is missing, if it is.")
    psi: Num = Field(None, description="Above ground: z/H [-].")
    gamma: Num = Field(None, description="Above ground: 3N/(2N+1) [-].")
    T1: Num = Field(None, description="Above ground: the building's period [s].")
    demand: Num = Field(description="The larger demand [m].")
    capacity_ratio: Num = Field(description="du*/demand [-]; passes at >= 1.")
    passes: Optional[bool] = Field(description="The verdict (null: no building above ground).")
    status: Literal["ok"] = Field(description="The check ran.")
    standard: str = Field(description="The text, in full.")


def _get(value: Any, key: str) -> Any:
    return value.get(key) if isinstance(value, dict) else getattr(value, key, None)


def _linear_kind(value: Any) -> str:
    """Return the variant of a linear check: not_run, or the method's forms."""
    if _get(value, "status") == "not_run":
        return "not_run"
    return "circ2009" if _get(value, "method") == "circ2009" else "circ2019"


def _nonlinear_kind(value: Any) -> str:
    """Return the variant of a nonlinear check: not_run, the 2009 forms, the 2019 curve or none."""
    kind = _linear_kind(value)
    if kind == "circ2019" and _get(value, "SLV") is None:
        return "no_curve"
    return kind


#: A linear check, by its ``status`` and ``method``.
LinearCheck = Annotated[
    Union[
        Annotated[NotRun, Tag("not_run")],
        Annotated[Linear2019, Tag("circ2019")],
        Annotated[Linear2009, Tag("circ2009")],
    ],
    Discriminator(_linear_kind),
]
#: A nonlinear check, by its ``status``, ``method`` and whether it has a capacity curve.
NonlinearCheck = Annotated[
    Union[
        Annotated[NotRun, Tag("not_run")],
        Annotated[Nonlinear2019, Tag("circ2019")],
        Annotated[NoCurve2019, Tag("no_curve")],
        Annotated[Nonlinear2009, Tag("circ2009")],
    ],
    Discriminator(_nonlinear_kind),
]


class CheckMethod(Part):
    """Which text the checks follow, and the choices rockmech makes where it leaves one."""

    name: Literal["circ2019", "circ2009"] = Field(description="The forms of the checks.")
    standard: str = Field(description="The text, in full.")
    decisions: List[str] = Field(description="Where the text leaves a choice: rockmech's.")
    xi_SLV_percent: float = Field(description="Damping of the SLV check [%].")
    xi_SLC_percent: float = Field(description="Damping of the SLC check [%].")
    note: str = Field(description="What the method is for (empty for the 2019 text).")


class CheckSite(Part):
    """The site: its code, the spectrum's parameters and each limit state's hazard.

    A number is null only where it is not finite (inputs at the edge of double precision).
    """

    code: Literal["NTC2018", "EC8"] = Field(description="The hazard's code.")
    params: Union[NtcParams, Ec8Params] = Field(
        description="The hazard as given, with derived factors (by code)."
    )
    S: Optional[float] = Field(description="Soil and topography factor [-].")
    eta: Optional[float] = Field(description="Damping correction of the plotted spectrum [-].")
    F: Optional[float] = Field(description="Spectral amplification F0 [-].")
    T_B: Optional[float] = Field(description="Corner period T_B [s].")
    T_C: Optional[float] = Field(description="Corner period T_C [s].")
    T_D: Optional[float] = Field(description="Corner period T_D [s].")
    pga_g: Optional[float] = Field(description="Peak ground acceleration a_g S [g].")
    FC: Optional[float] = Field(description="Confidence factor [-].")
    q: Optional[float] = Field(description="Behaviour factor [-].")
    limit_state: str = Field(description="The limit state of the checks (SLV).")
    limit_states: LimitStates = Field(description="Per limit state (SLV, SLC) its hazard.")
    T1: Optional[float] = Field(description="The building's first period [s].")
    T1_source: Optional[str] = Field(description="Where T1 comes from.")
    method_note: str = Field(description="How the checks apply to this code.")
    building: Optional[Dict[str, Any]] = Field(description="The site file's building block.")
    clauses: Dict[str, str] = Field(description="The clause of each number above.")


class CheckSpectrum(Part):
    """The site's elastic spectrum, for plotting."""

    T: List[Optional[float]] = Field(description="Periods [s].")
    Se_g: List[Optional[float]] = Field(
        description="Elastic spectral acceleration [g] (null where not finite: extreme inputs)."
    )
    SDe_m: List[Optional[float]] = Field(
        description="Elastic spectral displacement [m] (null where not finite)."
    )


class FreeStanding(Part):
    """Whether the mechanism stands free (not restrained until activation), and why."""

    value: Optional[bool] = Field(description="Free-standing (None where it is not known).")
    source: str = Field(description="Why.")
    missing: Optional[List[str]] = Field(
        None, description="Free-standing: the data of [C8.7.1.7] the inputs do not give."
    )


class CheckSide(Part):
    """The checks of one side of a mechanism."""

    linear: LinearCheck = Field(description="The linear check (Circ. 2019 C8.7.1.2.1.7).")
    nonlinear: NonlinearCheck = Field(description="The nonlinear check (Circ. 2019 C8.7.1.2.1.8).")


class DesignScale(Part):
    """The design scale of a record: its spectrum matched to the site's over a band."""

    value: Num = Field(description="The scale factor [-].")
    band: List[Num] = Field(description="The matching band [s], low and high.")
    method: str = Field(description="How the factor is found.")


class MultipleRun(Part):
    """The mechanism on a record at one multiple of the design scale."""

    multiple: Num = Field(description="Multiple of the design scale [-].")
    scale: Num = Field(description="The scale factor on the record [-].")
    peak_ratio: Num = Field(description="Peak |phi|/phi_ov [-].")
    overturned: bool = Field(description="The verdict of the time history.")


class RecordRuns(Part):
    """Assessment: the mechanism on one record, at multiples of its design scale."""

    record: str = Field(description="The record's name.")
    note: Optional[str] = Field(None, description="Why the record was not run.")
    scale_factor: Optional[DesignScale] = Field(None, description="The design scale.")
    height_factor: Optional[ScaleFactor] = Field(
        None,
        description="Above ground: the scale factor up the structure (Eq. 28; null at ground).",
    )
    runs: Optional[List[MultipleRun]] = Field(None, description="One per multiple.")
    first_overturning_multiple: Num = Field(
        None, description="The least multiple that overturns it (null: none) [-]."
    )
    survives_design: Optional[bool] = Field(
        None, description="It does not overturn at the design scale (multiple 1)."
    )


class PulseMargin(Part):
    """A record's largest pulse at design scale against the overturning envelope."""

    record: str = Field(description="The record's name.")
    f_p: Num = Field(description="The pulse's frequency [Hz].")
    a_p_g: Num = Field(description="Its amplitude at design scale [g].")
    a_p_min_g: Num = Field(description="The envelope at f_p [g].")
    margin: Num = Field(description="a_p,min / a_p [-] (null: not defined).")


class AssessEnvelope(Part):
    """Assessment: the overturning envelope and each record's largest pulse, or a note."""

    note: Optional[str] = Field(None, description="Why the envelope did not run.")
    f_p: Optional[List[Num]] = Field(None, description="Pulse frequencies [Hz].")
    a_p_min_g: Optional[List[Num]] = Field(
        None, description="Least overturning pulse amplitude [g] (null: none found)."
    )
    pulses: Optional[List[PulseMargin]] = Field(None, description="One per record run.")


class CheckMechanism(Part):
    """The checks of one mechanism: per side, and the governing (worst) ones."""

    id: str = Field(description="The mechanism's id.")
    name: Optional[str] = Field(description="The mechanism's name.")
    typology: Optional[str] = Field(description="The mechanism's typology.")
    rocking: Literal["two_sided", "one_sided"] = Field(description="Rocking kind.")
    Z: float = Field(description="Height of the mechanism's base above the ground [m].")
    Z_source: str = Field(description="Where Z comes from.")
    T1: Optional[float] = Field(description="The building's first period, above ground [s].")
    T1_source: Optional[str] = Field(description="Where T1 comes from.")
    free_standing: Optional[FreeStanding] = Field(
        description="Circ. 2019: whether it stands free (null for the 2009 forms)."
    )
    sides: Dict[str, CheckSide] = Field(description="Per side (positive, negative), its checks.")
    linear: LinearCheck = Field(description="The governing linear check.")
    nonlinear: NonlinearCheck = Field(description="The governing nonlinear check (with SLC).")
    passes: Optional[bool] = Field(
        description="Both checks pass at SLV (null where a check could not run)."
    )
    passes_SLC: Optional[bool] = Field(
        description="The nonlinear check at SLC passes (null: no SLC hazard or not run)."
    )
    dynamics: Optional[List[RecordRuns]] = Field(
        None,
        description="Assessment: per record, its design scale factor and band, per multiple "
        "the peak ratio and verdict, first_overturning_multiple and survives_design.",
    )
    dynamics_note: Optional[str] = Field(None, description="Assessment: why dynamics did not run.")
    envelope: Optional[AssessEnvelope] = Field(
        None,
        description="Assessment: the envelope (f_p [Hz], a_p_min_g [g]) and each record's "
        "largest pulse at design scale with the margin a_p,min / a_p, or a note.",
    )

    @property
    def linear_ratio(self) -> Optional[float]:
        """Capacity over demand of the governing linear check [-] (None where it did not run)."""
        return _ratio(self.linear)

    @property
    def nonlinear_ratio(self) -> Optional[float]:
        """Capacity over demand of the governing nonlinear check [-] (None: did not run)."""
        return _ratio(self.nonlinear)


def _ratio(check: Union[LinearCheck, NonlinearCheck]) -> Optional[float]:
    value = getattr(check, "capacity_ratio", None) if check.status == "ok" else None
    return None if value is None else float(value)


class CodeCheckRatio(Part):
    """The code check that decides a mechanism's verdict, and its ratio."""

    check: Literal["linear", "nonlinear"] = Field(description="Which check.")
    ratio_name: str = Field(description="The ratio, in words.")
    capacity_ratio: Num = Field(description="Its capacity over demand [-].")


class MechanismVerdict(Part):
    """One mechanism's verdict, the analysis that governs it and why."""

    id: str = Field(description="The mechanism's id.")
    name: Optional[str] = Field(description="The mechanism's name.")
    verdict: Literal["passes", "fails", "incomplete"] = Field(description="The verdict.")
    governs: Optional[str] = Field(description="The analysis that governs (null: none ran).")
    reason: str = Field(description="Why, in words.")
    pulse_margin: Optional[str] = Field(
        None, description="Where the largest pulse's margin disagrees with the time history."
    )
    code_check: Optional[CodeCheckRatio] = Field(
        None, description="The code check that decides, where one ran."
    )


class Conclusion(Part):
    """The one verdict of the document, as the report prints it."""

    verdict: Literal["passes", "fails", "incomplete"] = Field(description="The verdict.")
    sentence: str = Field(description="The line a client can quote.")
    rule: str = Field(description="The rule that combines the checks.")
    mechanisms: List[MechanismVerdict] = Field(description="One per mechanism, in file order.")


class CheckDocument(Document):
    """Code checks of every mechanism on a site (``rockmech check --json``)."""

    method: CheckMethod = Field(description="Which text the checks follow.")
    site: CheckSite = Field(description="Code, spectrum parameters, corner periods, FC, q.")
    spectrum: CheckSpectrum = Field(description="The site spectrum, for plotting.")
    mechanisms: List[CheckMechanism] = Field(description="One per mechanism, in file order.")
    governing: Optional[str] = Field(description="The mechanism with the lowest capacity ratio.")
    conclusion: Conclusion = Field(
        description="The verdict in words: verdict, sentence, the rule it applies."
    )

    def find(self, mechanism_id: str) -> CheckMechanism:
        """Return the checks of the mechanism ``mechanism_id``."""
        return find_entry(self.mechanisms, mechanism_id)
