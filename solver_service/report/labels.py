"""What a page and a verdict read off a check or assessment document: names and the worst pulse.

The capacity/demand ratios' names (``ratio_label``) and the record pulse a mechanism row holds
with the least margin (``worst_pulse``) are read the same by the report's page and by the
verdict the documents carry (``solver_service.workflows.verdict``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any, Optional, TypeVar

__all__ = ["least_margin_pulse", "ratio_label", "worst_pulse"]

_P = TypeVar("_P")


def ratio_label(method: str, check: str) -> str:
    """Return the capacity/demand ratio a check reports, as the report and the JSON name it.

    Examples
    --------
    >>> ratio_label("circ2019", "nonlinear"), ratio_label("circ2009", "linear")
    ('a_g,SLV/a_g', 'a0*/demand')
    """
    if method == "circ2019":
        return "a_g,SLV/a_g"
    return "a0*/demand" if check == "linear" else "du*/demand"


def least_margin_pulse(
    pulses: Iterable[_P], margin: Callable[[_P], Optional[float]]
) -> Optional[_P]:
    """Return the record pulse of least margin ``a_p,min / a_p`` [-], or None.

    The one rule for the worst pulse, on the working rows (dicts) and on the typed document's
    parts alike: pulses without a margin are left out; of equal margins the first is kept.

    Examples
    --------
    >>> least_margin_pulse([{"m": 2.0}, {"m": None}, {"m": 0.5}], lambda p: p["m"])
    {'m': 0.5}
    """
    best: Optional[_P] = None
    best_margin = 0.0
    for p in pulses:
        m = margin(p)
        if m is not None and (best is None or m < best_margin):
            best, best_margin = p, float(m)
    return best


def worst_pulse(row: dict[str, Any]) -> Optional[dict[str, Any]]:
    """Return the record pulse of a mechanism row (a working dict) with the smallest margin."""
    env = row.get("envelope") or {}
    return least_margin_pulse(env.get("pulses", []), lambda p: p.get("margin"))
