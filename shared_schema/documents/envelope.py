"""The envelope document: overturning envelopes and the critical bands (``rockmech envelope``).

Units: frequencies in Hz, pulse amplitudes in g (names end in ``_g``), SI otherwise.
Python 3.9-clean.
"""

import math
from typing import Dict, List, Literal, Optional, Union

from pydantic import Field

from shared_schema.errors import InputError
from shared_schema.spec import Amplification

from .base import Document, Part, find_entry

__all__ = [
    "Band",
    "BandEdge",
    "EnvelopeDocument",
    "EnvelopeMechanism",
    "ExactMethod",
    "ExtractedPulseInfo",
    "LibraryBound",
    "LibraryMethod",
    "PulsePoint",
    "RecordPulse",
]


class Band(Part):
    """A run of pulse frequencies over which one mechanism overturns first."""

    mechanism: str = Field(description="Id of the mechanism that governs.")
    f_min: Optional[float] = Field(description="First frequency of the band [Hz].")
    f_max: Optional[float] = Field(description="Last frequency of the band [Hz].")


class BandEdge(Part):
    """Where the governing mechanism changes: the frequency interval that holds the edge."""

    below: Optional[str] = Field(description="Mechanism governing below (null: none overturns).")
    above: Optional[str] = Field(description="Mechanism governing above (null: none overturns).")
    f_low: Optional[float] = Field(description="Low end of the interval [Hz].")
    f_high: Optional[float] = Field(description="High end of the interval [Hz].")


class EnvelopeMechanism(Part):
    """The envelope of one mechanism; amplification fields only for mechanisms above ground."""

    id: str = Field(description="The mechanism's id.")
    name: Optional[str] = Field(description="The mechanism's name.")
    rocking: Literal["two_sided", "one_sided"] = Field(description="Rocking kind.")
    p_eq: Optional[float] = Field(description="Frequency parameter, positive side [rad/s].")
    lam: Optional[float] = Field(description="Static load multiplier, positive side [-].")
    a_p_min_g: List[Optional[float]] = Field(
        description="Minimum overturning ground pulse amplitude [g] per frequency; null: "
        "none up to the search limit."
    )
    eta: Optional[float] = Field(None, description="Coefficient of restitution [-].")
    amplification: Optional[Amplification] = Field(
        None, description="The mechanism's amplification data (f_n [Hz], h_e [m], h [m])."
    )
    a_p_min_local_g: Optional[List[Optional[float]]] = Field(
        None, description="Minimum overturning amplitude at the mechanism's base [g]."
    )
    scale_factor: Optional[List[Optional[float]]] = Field(
        None, description="SF(f_p) the local envelope is divided by (theory §7, Eq. 28) [-]."
    )
    governing_side: Optional[List[int]] = Field(
        None, description="One-sided mechanisms: the pulse direction that governs (1 or -1)."
    )
    notes: Optional[List[str]] = Field(None, description="Where the envelope needs care.")


class ExactMethod(Part):
    """The envelopes are the exact integrator's at every frequency."""

    source: Literal["exact"] = Field(description="exact: the integrator at every frequency.")
    a_max: float = Field(description="Largest amplitude ratio A = a_p/(g lam) searched [-].")
    note: str = Field(description="Where the band edges lie.")


class LibraryBound(Part):
    """The library's bound on its error relative to the exact envelope."""

    above_exact: float = Field(description="Largest fraction above the exact value [-].")
    below_exact: float = Field(description="Largest fraction below the exact value [-].")


class LibraryMethod(Part):
    """The envelopes are interpolated from the overturning library (the fast mode)."""

    source: Literal["library"] = Field(description="library: the fast mode.")
    label: str = Field(description="The mode in words.")
    library_file: str = Field(description="Which library file was used.")
    interpolation: str = Field(description="How the library is interpolated.")
    exact_points: int = Field(description="Frequencies computed exactly instead.")
    bound: LibraryBound = Field(description="The error bound of the interpolation.")
    edge_ratio: float = Field(description="Frequency tolerance of a band edge [-].")
    library_version: Optional[str] = Field(None, description="The library's format version.")
    generated: Optional[str] = Field(None, description="When the library was built.")
    scan_ratio: Optional[float] = Field(None, description="The library's amplitude scan [-].")
    a_max: Optional[float] = Field(None, description="The library's largest A [-].")


class PulsePoint(Part):
    """A record's largest pulse at one scale, and the mechanisms it alone would overturn."""

    scale: float = Field(description="Scale factor on the record [-].")
    f_p_hz: float = Field(description="Frequency of the pulse [Hz].")
    a_p_g: float = Field(description="Scaled amplitude of the pulse [g].")
    overturns: List[str] = Field(description="Mechanisms whose envelope lies at or below it.")


class ExtractedPulseInfo(Part):
    """A sine pulse found in a record (two adjacent half-cycles)."""

    a_p_g: float = Field(description="Signed amplitude [g]: the smaller of the two peaks.")
    a_p_m_s2: float = Field(description="Signed amplitude [m/s²].")
    f_p_hz: float = Field(description="Frequency [Hz].")
    t_start_s: float = Field(description="Start in the record [s].")
    half_durations_s: List[float] = Field(description="Durations of the half-cycles [s].")
    peaks_g: List[float] = Field(description="Peaks of the half-cycles [g].")


class RecordPulse(Part):
    """A record's largest sine pulse, at several scales, against every envelope."""

    record: str = Field(description="The record's name.")
    pulse: ExtractedPulseInfo = Field(description="The largest pulse.")
    method: str = Field(description="How the pulse was extracted.")
    a_p_min_g_at_f_p: Dict[str, Optional[float]] = Field(
        description="Per mechanism, its envelope at the pulse's frequency [g]."
    )
    points: List[PulsePoint] = Field(description="One per scale factor.")


class EnvelopeDocument(Document):
    """Envelopes and the critical mechanism per frequency (``rockmech envelope --json``)."""

    f_p: List[Optional[float]] = Field(description="Pulse frequencies [Hz].")
    mechanisms: List[EnvelopeMechanism] = Field(description="One envelope per mechanism.")
    critical: List[Band] = Field(description="The mechanism that overturns first, by band.")
    critical_edges: List[BandEdge] = Field(description="Where the governing mechanism changes.")
    governing: List[Optional[str]] = Field(
        description="Per frequency, the mechanism that overturns first (null: none)."
    )
    method: Union[ExactMethod, LibraryMethod] = Field(
        discriminator="source", description="How the values were computed."
    )
    record_pulse: Optional[RecordPulse] = Field(
        None, description="With a record: its largest pulse against the envelopes."
    )

    def find(self, mechanism_id: str) -> EnvelopeMechanism:
        """Return the envelope of the mechanism ``mechanism_id``."""
        return find_entry(self.mechanisms, mechanism_id)

    def critical_at(self, f_p: float) -> Optional[str]:
        """Return the id of the mechanism that overturns first at ``f_p`` [Hz] (None: none).

        The nearest tabulated frequency (on a log scale) decides.
        """
        if not (isinstance(f_p, (int, float)) and math.isfinite(f_p) and f_p > 0):
            raise InputError(f"must be a finite frequency > 0 [Hz], got {f_p!r}", "f_p")
        logs = [abs(math.log(f) - math.log(f_p)) if f else math.inf for f in self.f_p]
        return self.governing[logs.index(min(logs))]
