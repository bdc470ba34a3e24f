"""The pulse document: one mechanism under a one-cycle pulse (``rockmech pulse --json``).

Units: ``a_p_g`` in g, ``f_p`` in Hz, SI otherwise. Python 3.9-clean.
"""

from typing import List, Literal, Optional

from pydantic import Field

from .base import Document, Part

__all__ = ["PulseDocument", "PulseNegativeSide", "PulseProblem"]

Rocking = Literal["two_sided", "one_sided"]


class PulseNegativeSide(Part):
    """The negative side of an asymmetric mechanism, as solved."""

    p_eq: Optional[float] = Field(description="Frequency parameter of the side [rad/s].")
    lam: Optional[float] = Field(description="Static load multiplier of the side [-].")
    phi_ov: Optional[float] = Field(description="Overturning rotation of the side [rad].")


class PulseProblem(Part):
    """The pulse problem as solved, with its dimensionless ratios (positive side first)."""

    mechanism: Optional[str] = Field(
        None, description="Id of the constants file's mechanism (absent for the short form)."
    )
    p_eq: Optional[float] = Field(description="Frequency parameter p_eq [rad/s].")
    lam: Optional[float] = Field(description="Static load multiplier lambda [-].")
    phi_ov: Optional[float] = Field(description="Overturning rotation [rad].")
    eta: Optional[float] = Field(description="Coefficient of restitution [-].")
    rocking: Rocking = Field(description="Two-sided or one-sided rocking.")
    negative: Optional[PulseNegativeSide] = Field(
        None, description="The negative side, where it differs from the positive one."
    )
    eta_to_negative: Optional[float] = Field(
        None, description="Restitution of an impact into negative rotation [-] (directional)."
    )
    eta_to_positive: Optional[float] = Field(
        None, description="Restitution of an impact into positive rotation [-] (directional)."
    )
    a_p_g: Optional[float] = Field(description="Signed pulse amplitude [g].")
    f_p: Optional[float] = Field(description="Pulse frequency [Hz].")
    shape: Literal["sine", "cosine"] = Field(description="Pulse shape.")
    omega_ratio: Optional[float] = Field(description="Omega = omega_p / p_eq [-].")
    amplitude_ratio: Optional[float] = Field(description="A = |a_p| / (g lam) [-].")
    pulse_convention: str = Field(description="Where the pulse starts (Zhang & Makris 2001).")


class PulseDocument(Document):
    """Response of one mechanism to a one-cycle pulse (``rockmech pulse --json``)."""

    input: PulseProblem = Field(description="The problem as solved.")
    peak_ratio: Optional[float] = Field(description="Peak |phi|/phi_ov [-].")
    t_peak: Optional[float] = Field(description="Time of the peak [s].")
    overturned: bool = Field(description="The verdict of the criterion.")
    t_overturn: Optional[float] = Field(
        description="Time of the collapse the verdict refers to [s], or null."
    )
    criterion: Literal["exact", "ratio"] = Field(
        description="exact: the body cannot come back; ratio: peak |phi|/phi_ov >= 1."
    )
    ratio_exceeded: bool = Field(description="peak |phi|/phi_ov reached 1 [-].")
    collapsed: bool = Field(description="The body passed its point of no return.")
    n_impacts: int = Field(description="Impacts counted.")
    n_steps: int = Field(description="Integration steps taken.")
    error_estimate: Optional[float] = Field(
        description="Estimated absolute error of peak_ratio [-]."
    )
    runtime_s: Optional[float] = Field(description="Solver wall time [s].")
    status: int = Field(description="Solver status code (0: done).")
    message: str = Field(description="The status in words.")
    warnings: List[str] = Field(
        description="Where the linearised model may be off by > 10 %, or the peak is unresolved."
    )
    method: str = Field(description="The integration method.")
