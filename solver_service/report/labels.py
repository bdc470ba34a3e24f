"""What a page and a verdict read off a check or assessment document: names and the worst pulse.

The capacity/demand ratios' names (``ratio_label``) and the record pulse a mechanism row holds
with the least margin (``worst_pulse``) are read the same by the report's page and by the
verdict the documents carry (``solver_service.workflows.verdict``).
"""

from __future__ import annotations

from typing import Any, Optional

__all__ = ["ratio_label", "worst_pulse"]


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


def worst_pulse(row: dict[str, Any]) -> Optional[dict[str, Any]]:
    """Return the record pulse of a mechanism row with the smallest margin, or None."""
    env = row.get("envelope") or {}
    pulses = [p for p in env.get("pulses", []) if p.get("margin") is not None]
    return min(pulses, key=lambda p: p["margin"]) if pulses else None
