"""The history document: time histories of every mechanism at every scale factor.

``rockmech history --json``, REST ``/history``, Hops ``history``. Units: times in s,
displacements in m, PGA in g; ratios and scale factors dimensionless. Python 3.9-clean.
"""

from typing import Dict, List, Literal, Optional

from pydantic import Field

from shared_schema.errors import InputError

from .base import Document, Part
from .record import RecordInfo

__all__ = [
    "Displacement",
    "HistoryDocument",
    "HistoryRow",
    "ScaleFactor",
    "SkippedMechanism",
]


class HistoryRow(Part):
    """One mechanism at one scale factor of the record."""

    mechanism: str = Field(description="The mechanism's id.")
    scale: Optional[float] = Field(description="The user's scale factor on the record [-].")
    peak_ratio: Optional[float] = Field(
        description="Peak |phi|/phi_ov over the motion, the free-rocking tail included [-]."
    )
    overturned: bool = Field(description="The verdict of the criterion.")
    t_overturn: Optional[float] = Field(description="Time of overturning [s], or null.")
    ratio_exceeded: bool = Field(description="peak |phi|/phi_ov reached 1.")
    collapsed: bool = Field(description="The body passed its point of no return.")
    n_impacts: int = Field(description="Impacts counted.")
    error_estimate: Optional[float] = Field(
        description="The solver's estimate of the error of peak_ratio [-]."
    )
    status: int = Field(description="Solver status code (0: done).")
    message: str = Field(description="The status in words.")
    warnings: Optional[List[str]] = Field(None, description="Present when the peak is unresolved.")
    effective_scale: Optional[float] = Field(
        None,
        description="With a scale factor up the structure: the scale applied to the mechanism, "
        "scale times its factor [-].",
    )
    peak_displacement_m: Optional[float] = Field(
        None, description="With at_height: peak displacement of that point, z max|phi| [m]."
    )
    peak_displacement_is_bound: Optional[bool] = Field(
        None, description="True where peak_displacement_m is a bound (sides with two phi_ov)."
    )

    @property
    def applied_scale(self) -> Optional[float]:
        """The scale applied to the mechanism [-]: ``effective_scale``, else ``scale``."""
        return self.scale if self.effective_scale is None else self.effective_scale


class ScaleFactor(Part):
    """A scale factor up the structure with its method, formula and inputs."""

    value: Optional[float] = Field(description="The factor [-].")
    method: str = Field(description="Where the formula comes from.")
    formula: str = Field(description="The formula.")
    inputs: Dict[str, Optional[float]] = Field(description="Its inputs (SI; accelerations in g).")


class Displacement(Part):
    """Where the peak displacements are measured."""

    height_m: float = Field(description="Height of the point above the rotation axis [m].")
    formula: str = Field(description="The formula.")


class SkippedMechanism(Part):
    """A mechanism the analysis left out, and why."""

    mechanism: str = Field(description="The mechanism's id.")
    reason: str = Field(description="Why it was left out.")


class HistoryDocument(Document):
    """Time histories (``rockmech history --json``)."""

    record: RecordInfo = Field(description="The record as read.")
    criterion: Literal["ratio", "exact"] = Field(description="The overturning verdict.")
    method: str = Field(description="The integration method.")
    runtime_s: Optional[float] = Field(description="Solver wall time [s].")
    results: List[HistoryRow] = Field(description="One per mechanism and scale, mechanism-major.")
    scale_factor_method: Optional[str] = Field(
        None, description="The scale factor up the structure (eq28, ec8, nzs), when used."
    )
    scale_factors: Optional[Dict[str, ScaleFactor]] = Field(
        None, description="Per mechanism above ground, its scale factor."
    )
    displacement: Optional[Displacement] = Field(
        None, description="With at_height: where peak displacements are measured."
    )
    skipped: Optional[List[SkippedMechanism]] = Field(
        None, description="Mechanisms left out (no coefficient of restitution)."
    )
    option_warnings: Optional[List[str]] = Field(
        None, description="Options that have no effect on these mechanisms."
    )
    warnings: Optional[Dict[str, List[str]]] = Field(
        None, description="Per mechanism, where the linearised model may be off by > 10 %."
    )

    def find(self, mechanism_id: str, scale: float) -> HistoryRow:
        """Return the run of ``mechanism_id`` at the user's scale factor ``scale`` [-]."""
        for row in self.results:
            if row.mechanism == mechanism_id and row.scale == scale:
                return row
        known = sorted({f"{r.mechanism} x{_g(r.scale)}" for r in self.results})
        raise InputError(f"no run '{mechanism_id} x{_g(scale)}'; the document has {known}", "run")


def _g(value: Optional[float]) -> str:
    return "null" if value is None else f"{value:g}"
