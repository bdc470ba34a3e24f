"""Typed results of the analyses in ``rockmech.analysis`` (IDA, check, assess).

Each result keeps the numbers a script reads as typed fields (units in brackets) and the
whole JSON-ready document the command line writes (``doc``), so nothing the command line
reports is out of reach. SI units, except where a name says otherwise (``a_p_min_g`` in g).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np
from numpy.typing import NDArray

from shared_schema.errors import InputError

__all__ = [
    "AssessmentResult",
    "CheckResult",
    "Fragility",
    "IDAResult",
    "MechanismCheck",
]


def _opt_float(value: Any) -> Optional[float]:
    return None if value is None else float(value)


def _unknown(kind: str, name: str, known: list[str]) -> InputError:
    return InputError(f"no {kind} {name!r}; the result has {known}", kind)


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


@dataclass(frozen=True)
class MechanismCheck:
    """The code check of one mechanism (NTC 2018 / Circolare 2019 §C8.7.1), worst side.

    Attributes
    ----------
    mechanism : str
        The mechanism's id.
    passes : bool or None
        Both checks pass at SLV (None where a check could not run: see ``doc``).
    linear_ratio, nonlinear_ratio : float or None
        Capacity over demand of the linear and the nonlinear kinematic check [-] (>= 1
        passes; None where the check did not run).
    z : float
        Height of the mechanism's base above the ground [m].
    passes_slc : bool or None
        The nonlinear check at SLC passes (§C8.7.1.2.1.6); None where the site gives no SLC
        hazard or the check could not run. A mechanism can pass at SLV and fail at SLC.
    """

    mechanism: str
    passes: Optional[bool]
    linear_ratio: Optional[float]
    nonlinear_ratio: Optional[float]
    z: float
    passes_slc: Optional[bool] = None


def _ratio(check: dict[str, Any]) -> Optional[float]:
    return _opt_float(check.get("capacity_ratio")) if check.get("status") == "ok" else None


def _checks(doc: dict[str, Any]) -> tuple[MechanismCheck, ...]:
    return tuple(
        MechanismCheck(
            mechanism=str(m["id"]),
            passes=m["passes"],
            linear_ratio=_ratio(m["linear"]),
            nonlinear_ratio=_ratio(m["nonlinear"]),
            z=float(m["Z"]),
            passes_slc=m.get("passes_SLC"),
        )
        for m in doc["mechanisms"]
    )


@dataclass(frozen=True)
class CheckResult:
    """Code checks of every mechanism on a site (``rockmech.check``).

    Attributes
    ----------
    mechanisms : tuple of MechanismCheck
        One per mechanism, in the constants file's order.
    governing : str or None
        The id with the lowest capacity ratio (None when no check ran).
    doc : dict
        The whole document, as ``rockmech check --json`` prints it.
    """

    mechanisms: tuple[MechanismCheck, ...]
    governing: Optional[str]
    doc: dict[str, Any]

    @classmethod
    def from_doc(cls, doc: dict[str, Any]) -> CheckResult:
        """Read the typed fields of a check document."""
        return cls(_checks(doc), doc.get("governing"), doc)

    def mechanism(self, mechanism: str) -> MechanismCheck:
        """Return the check of ``mechanism`` (its id)."""
        for m in self.mechanisms:
            if m.mechanism == mechanism:
                return m
        raise _unknown("mechanism", mechanism, [m.mechanism for m in self.mechanisms])


@dataclass(frozen=True)
class AssessmentResult(CheckResult):
    """Code checks beside rocking dynamics on records scaled to the site (``rockmech.assess``).

    Attributes
    ----------
    survives_design : dict of str to bool or None
        Per mechanism id, whether it survives every record at the design level (multiple 1;
        None without records or where it was not run).
    first_overturning_multiple : dict of str to float or None
        Per mechanism id, the smallest multiple of the design scale at which some record
        overturns it [-] (None where none does).
    """

    survives_design: dict[str, Optional[bool]]
    first_overturning_multiple: dict[str, Optional[float]]

    @classmethod
    def from_doc(cls, doc: dict[str, Any]) -> AssessmentResult:
        """Read the typed fields of an assessment document."""
        survives: dict[str, Optional[bool]] = {}
        first: dict[str, Optional[float]] = {}
        for m in doc["mechanisms"]:
            runs = m.get("dynamics") or []
            verdicts = [r.get("survives_design") for r in runs]
            survives[m["id"]] = None if not runs or None in verdicts else all(verdicts)
            multiples = [
                r["first_overturning_multiple"]
                for r in runs
                if r.get("first_overturning_multiple") is not None
            ]
            first[m["id"]] = float(min(multiples)) if multiples else None
        return cls(_checks(doc), doc.get("governing"), doc, survives, first)
