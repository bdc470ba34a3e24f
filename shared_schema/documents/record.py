"""The record document: a record's largest sine pulses and its response spectrum.

``rockmech record --json`` and REST ``/spectrum``; the record block (``RecordInfo``) is also
the history document's. Units: periods and times in s, accelerations in g (names end in
``_g``), displacements in m. Python 3.9-clean.
"""

from typing import List, Optional

from pydantic import ConfigDict, Field

from .base import DOCUMENT_CONFIG, Document, Part
from .envelope import ExtractedPulseInfo

__all__ = ["RecordDocument", "RecordInfo", "RecordSummary", "SpectrumCurve"]

#: A record block carries, after its typed fields, what the record's reader found in the
#: file (``source``, ``format``, ``units``, ``station``, ``component``, ``warnings``, ...):
#: that set depends on the format, so it is the one open part of a document.
_READER_METADATA = ConfigDict(**{**DOCUMENT_CONFIG, "extra": "allow"})


class RecordInfo(Part):
    """The record as read: name, step, PGA, duration, then what the reader found."""

    model_config = _READER_METADATA

    name: str = Field(description="The record's name.")
    dt_s: Optional[float] = Field(description="Time step [s].")
    pga_g: Optional[float] = Field(description="Peak ground acceleration [g].")
    duration_s: Optional[float] = Field(description="Duration [s].")


class RecordSummary(Part):
    """The record block of the record document: ``RecordInfo`` with its sample count."""

    model_config = _READER_METADATA

    name: str = Field(description="The record's name.")
    n_samples: int = Field(description="Samples in the record.")
    dt_s: Optional[float] = Field(description="Time step [s].")
    pga_g: Optional[float] = Field(description="Peak ground acceleration [g].")
    duration_s: Optional[float] = Field(description="Duration [s].")


class SpectrumCurve(Part):
    """An elastic response spectrum."""

    damping: Optional[float] = Field(description="Damping ratio [-].")
    periods_s: List[Optional[float]] = Field(description="Periods [s].")
    psa_g: List[Optional[float]] = Field(description="Pseudo-spectral acceleration [g].")
    sd_m: List[Optional[float]] = Field(description="Spectral displacement [m].")
    method: str = Field(description="How the spectrum was computed.")
    runtime_s: Optional[float] = Field(description="Wall time [s].")


class RecordDocument(Document):
    """A record's spectrum and largest sine pulses (``rockmech record --json``)."""

    record: RecordSummary = Field(description="The record as read.")
    pulses: List[ExtractedPulseInfo] = Field(description="Largest one-cycle sine pulses.")
    pulse_method: str = Field(description="How the pulses were extracted.")
    spectrum: SpectrumCurve = Field(description="The response spectrum.")
