"""The assessment document: code checks beside rocking dynamics on records scaled to the site.

``rockmech assess --json``, REST ``/assess``. The check document's keys (``check``), each
mechanism with its ``dynamics`` and ``envelope``, then the ``records`` and ``multiples``.
Units as the check document's; PGA in g, times in s. Python 3.9-clean.
"""

from typing import Dict, List, Optional

from pydantic import Field

from ..retrofit import RetrofitDoc
from .base import Part
from .check import CheckDocument

__all__ = ["AssessDocument", "AssessRecord"]


class AssessRecord(Part):
    """A record of the assessment as read."""

    name: str = Field(description="The record's name.")
    pga_g: Optional[float] = Field(description="Peak ground acceleration [g].")
    dt: Optional[float] = Field(description="Time step [s].")
    duration: Optional[float] = Field(description="Duration [s].")
    warnings: Optional[List[str]] = Field(
        None, description="An implausible PGA or time step, naming the units read."
    )


class AssessDocument(CheckDocument):
    """The assessment document (``rockmech assess --json``)."""

    records: List[AssessRecord] = Field(description="The records, in the order given.")
    multiples: List[float] = Field(description="Multiples of the design scale factor run [-].")
    retrofit: Optional[RetrofitDoc] = Field(
        None,
        description="The retrofit shown on page one (``rockmech assess --retrofit``): the "
        "retrofit document, as ``rockmech retrofit`` writes it.",
    )

    @property
    def survives_design(self) -> Dict[str, Optional[bool]]:
        """Per mechanism id: it survives every record at the design level (multiple 1).

        None without records, or where a record was not run.
        """
        out: Dict[str, Optional[bool]] = {}
        for m in self.mechanisms:
            runs = m.dynamics or []
            verdicts = [r.survives_design for r in runs]
            out[m.id] = None if not runs or None in verdicts else all(verdicts)
        return out

    @property
    def first_overturning_multiple(self) -> Dict[str, Optional[float]]:
        """Per mechanism id: the least multiple of the design scale some record overturns it at.

        None where no record does [-].
        """
        out: Dict[str, Optional[float]] = {}
        for m in self.mechanisms:
            found = [
                float(r.first_overturning_multiple)
                for r in m.dynamics or []
                if r.first_overturning_multiple is not None
            ]
            out[m.id] = min(found) if found else None
        return out
