"""The boundary document: overturning intervals at one frequency ratio (``rockmech boundary``).

Every quantity is dimensionless: ``omega = omega_p / p_eq``, ``A = a_p / (g lam)``.
Python 3.9-clean.
"""

from typing import List, Literal, Optional, Tuple

from pydantic import Field

from .base import Document, Part

__all__ = ["BoundaryDirections", "BoundaryDocument", "BoundarySearch", "Interval"]

#: An overturning interval ``[A_low, A_high]`` [-]; ``A_high`` null: open up to ``a_max``.
Interval = Tuple[Optional[float], Optional[float]]


class BoundaryDirections(Part):
    """The intervals of a one-sided mechanism for each pulse direction."""

    positive: List[Interval] = Field(description="Intervals of a positive pulse [-].")
    negative: List[Interval] = Field(description="Intervals of a negative pulse [-].")


class BoundarySearch(Part):
    """How the intervals were searched."""

    a_max: float = Field(description="Largest amplitude ratio searched [-].")
    scan_ratio: float = Field(description="Ratio between successive scanned amplitudes [-].")
    rtol: float = Field(description="Relative tolerance of the bisection of each edge [-].")


class BoundaryDocument(Document):
    """Every overturning interval in ``A`` at one ``Omega`` (``rockmech boundary --json``)."""

    omega: float = Field(description="Frequency ratio omega_p / p_eq [-].")
    eta: float = Field(description="Coefficient of restitution [-].")
    rocking: Literal["two_sided", "one_sided"] = Field(description="Rocking kind.")
    shape: Literal["sine", "cosine"] = Field(description="Pulse shape.")
    overturning_intervals: List[Interval] = Field(
        description="Amplitude ratios A = a_p/(g lam) that overturn [-] (one-sided: the "
        "governing direction's)."
    )
    governing_direction: Optional[Literal["positive", "negative"]] = Field(
        None, description="One-sided: the pulse direction with the lower minimum."
    )
    directions: Optional[BoundaryDirections] = Field(
        None, description="One-sided: the intervals of each direction."
    )
    a_min: Optional[float] = Field(
        description="Smallest overturning A [-]; null: none up to the search limit."
    )
    search: BoundarySearch = Field(description="The search's limits.")
