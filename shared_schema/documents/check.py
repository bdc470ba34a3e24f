"""The check document: NTC 2018 / Circolare 2019 §C8.7.1 kinematic checks on a site.

``rockmech check --json``, REST ``/check``. Each check names the clause of each of its
numbers in ``clauses``; its figures differ by method (the 2019 text's forms, or the 2009
ones kept for comparison) and by site code (NTC 2018, EC8), so a check's own block is a
mapping, described field by field in docs/assess.md. Units: accelerations in m/s² (names
ending ``_star``) or g (``_g``), displacements in m, periods in s (``units``).
Python 3.9-clean.
"""

from typing import Any, Dict, List, Literal, Optional

from pydantic import Field

from .base import Document, Part, find_entry

__all__ = [
    "CheckDocument",
    "CheckMechanism",
    "CheckMethod",
    "CheckSide",
    "CheckSite",
    "CheckSpectrum",
    "FreeStanding",
]

#: A linear or nonlinear check: ``status`` (``ok``, or ``not_run`` with a note), its
#: figures, ``capacity_ratio`` [-], ``passes`` and ``clauses``.
Check = Dict[str, Any]


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
    params: Dict[str, Any] = Field(description="The hazard as given, with derived factors.")
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
    limit_states: Dict[str, Optional[Dict[str, Any]]] = Field(
        description="Per limit state its hazard: a_g [g], S, F, T_B, T_C, T_D [s], pga_g [g] "
        "(null: the site gives none)."
    )
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

    linear: Check = Field(description="The linear check (Circ. 2019 C8.7.1.2.1.7).")
    nonlinear: Check = Field(description="The nonlinear check (Circ. 2019 C8.7.1.2.1.8).")


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
    linear: Check = Field(description="The governing linear check.")
    nonlinear: Check = Field(description="The governing nonlinear check (with SLC).")
    passes: Optional[bool] = Field(
        description="Both checks pass at SLV (null where a check could not run)."
    )
    passes_SLC: Optional[bool] = Field(
        description="The nonlinear check at SLC passes (null: no SLC hazard or not run)."
    )
    dynamics: Optional[List[Dict[str, Any]]] = Field(
        None,
        description="Assessment: per record, its design scale factor and band, per multiple "
        "the peak ratio and verdict, first_overturning_multiple and survives_design.",
    )
    dynamics_note: Optional[str] = Field(None, description="Assessment: why dynamics did not run.")
    envelope: Optional[Dict[str, Any]] = Field(
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


def _ratio(check: Check) -> Optional[float]:
    value = check.get("capacity_ratio") if check.get("status") == "ok" else None
    return None if value is None else float(value)


class CheckDocument(Document):
    """Code checks of every mechanism on a site (``rockmech check --json``)."""

    method: CheckMethod = Field(description="Which text the checks follow.")
    site: CheckSite = Field(description="Code, spectrum parameters, corner periods, FC, q.")
    spectrum: CheckSpectrum = Field(description="The site spectrum, for plotting.")
    mechanisms: List[CheckMechanism] = Field(description="One per mechanism, in file order.")
    governing: Optional[str] = Field(description="The mechanism with the lowest capacity ratio.")
    conclusion: Dict[str, Any] = Field(
        description="The verdict in words: verdict, sentence, the rule it applies."
    )

    def find(self, mechanism_id: str) -> CheckMechanism:
        """Return the checks of the mechanism ``mechanism_id``."""
        return find_entry(self.mechanisms, mechanism_id)
