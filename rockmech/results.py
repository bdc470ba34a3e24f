"""Typed results of the analyses in ``rockmech.analysis`` (IDA).

Each result keeps the numbers a script reads as typed fields (units in brackets) and the
whole JSON-ready document the command line writes (``doc``), so nothing the command line
reports is out of reach. SI units, except where a name says otherwise (``a_p_min_g`` in g).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Fragility",
    "IDAResult",
]


def _opt_float(value: Any) -> Optional[float]:
    return None if value is None else float(value)


@dataclass(frozen=True)
class Fragility:
    """A lognormal fragility fit of one mechanism (binomial maximum likelihood).

    Attributes
    ----------
    median : float or None
        Median intensity of overturning, in the IDA's measure (scale [-] or PGA [g]); None
        where the levels cannot place it (every record overturned, or none did).
    beta : float or None
        Lognormal dispersion [-].
    note : str
        Why the fit is missing or weak ("" when it is sound).
    """

    median: Optional[float]
    beta: Optional[float]
    note: str


@dataclass(frozen=True)
class IDAResult:
    """Incremental dynamic analysis over records (``rockmech.ida``).

    Attributes
    ----------
    measure : str
        Intensity measure, ``"scale"`` [-] or ``"pga"`` [g].
    levels : (k,) float array
        Intensity levels, in ``measure``'s units.
    fraction : dict of str to (k,) float array
        Per mechanism id, the fraction of records that overturned it at each level [-].
    fragility : dict of str to Fragility
        Per mechanism id, its lognormal fit.
    doc : dict
        The whole document, as ``rockmech ida`` writes it (``ida.json``).
    """

    measure: str
    levels: NDArray[np.float64]
    fraction: dict[str, NDArray[np.float64]]
    fragility: dict[str, Fragility]
    doc: dict[str, Any]

    @classmethod
    def from_doc(cls, doc: dict[str, Any]) -> IDAResult:
        """Read the typed fields of an IDA document."""
        mechs = doc["mechanisms"]
        return cls(
            measure=str(doc["intensity"]["measure"]),
            levels=np.asarray(doc["intensity"]["levels"], dtype=float),
            fraction={str(m["id"]): np.asarray(m["fraction"], dtype=float) for m in mechs},
            fragility={
                str(m["id"]): Fragility(
                    _opt_float(m["fragility"].get("median")),
                    _opt_float(m["fragility"].get("beta")),
                    str(m["fragility"].get("note", "")),
                )
                for m in mechs
            },
            doc=doc,
        )
