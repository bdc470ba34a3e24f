"""One verdict per mechanism and one for the building, from a check or assessment document.

The report's page one, the JSON of ``rockmech check`` and ``rockmech assess`` (CLI, REST,
Python) all carry the ``conclusion`` this module writes, so the verdict a client reads is
the one every path gives (#27).

The rule (``RULE``): a mechanism passes only where every code check that ran passes
(Circolare 2019 §C8.7.1: linear and nonlinear kinematic checks at SLV; a capacity/demand
ratio >= 1 passes) and no record scaled to the site spectrum overturns it at the design
scale (x1) in the rocking time history. Where the two disagree, the more severe governs,
and the conclusion says so. The pulse-envelope margin screens the record's largest pulse
alone, idealised as one sine: it never governs, and where it disagrees with the time history
(which holds that pulse and everything else in the record) the conclusion says which governs
and why.
"""

from __future__ import annotations

from typing import Any, Optional

from ..report.labels import ratio_label, worst_pulse

__all__ = ["RULE", "check_label", "conclusion"]

#: The rule that turns the analyses into one verdict, printed with it.
RULE = (
    "A mechanism passes only where every code check that ran passes (capacity/demand >= 1) "
    "and no record scaled to the site spectrum overturns it at the design scale (x1) in the "
    "rocking time history; where they disagree, the more severe governs. The pulse margin "
    "(the record's largest pulse alone, as one sine; > 1: that pulse does not overturn it) is "
    "a screening and never governs."
)


def check_label(method: str, check: str) -> str:
    """Return the name of a code check with its clause (Circolare 2019 or the 2009 forms)."""
    if method == "circ2019":
        clause = "C8.7.1.2.1.7" if check == "linear" else "C8.7.1.2.1.8"
        return f"{check} kinematic check at SLV (Circ. 2019 §{clause})"
    return f"{check} kinematic check at SLV (2009 forms, C8A.4)"


def _fmt(value: float) -> str:
    return f"{value:.3g}"


def _code_part(row: dict[str, Any], method: str) -> dict[str, Any]:
    """Return the code check's verdict of one mechanism: passes, the worst check, its ratio."""
    ran = [
        (name, row[name])
        for name in ("linear", "nonlinear")
        if row.get(name, {}).get("status") == "ok" and row[name].get("passes") is not None
    ]
    worst = min(ran, key=lambda p: p[1]["capacity_ratio"]) if ran else None
    out: dict[str, Any] = {"passes": row.get("passes")}
    if worst is not None:
        name, check = worst
        out.update(
            check=name,
            label=check_label(method, name),
            ratio_name=ratio_label(method, name),
            ratio=float(check["capacity_ratio"]),
        )
    notes = [
        f"{name}: {row[name].get('note', '')}".rstrip(": ")
        for name in ("linear", "nonlinear")
        if row.get(name, {}).get("status") != "ok" or row[name].get("passes") is None
    ]
    if notes:
        out["not_run"] = notes
    return out


def _margin_note(row: dict[str, Any], overturns: list[str]) -> Optional[str]:
    """Say where the largest-pulse margin disagrees with the time history, and which governs."""
    worst = worst_pulse(row)
    if worst is None or "dynamics" not in row:
        return None
    margin = float(worst["margin"])
    record = worst["record"]
    if margin >= 1.0 and record in overturns:
        return (
            f"the largest pulse of {record} alone would not overturn it (margin "
            f"{_fmt(margin)} > 1), but the whole record does: the pulses that follow add up; "
            "the time history governs"
        )
    survived = [d["record"] for d in row.get("dynamics", []) if d.get("survives_design") is True]
    if margin < 1.0 and record in survived:
        return (
            f"the largest pulse of {record}, idealised as one isolated sine, would overturn it "
            f"(margin {_fmt(margin)} < 1), but the whole record's time history does not: the "
            "time history, which holds that pulse as it is, governs"
        )
    return None


def _mechanism(row: dict[str, Any], method: str) -> dict[str, Any]:
    code = _code_part(row, method)
    dyn = row.get("dynamics")
    at_design = [d for d in dyn or [] if d.get("survives_design") is not None]
    overturns = [d["record"] for d in at_design if d["survives_design"] is False]
    out: dict[str, Any] = {"id": row["id"], "name": row.get("name", "")}
    code_text = (
        f"{code['label']}: {code['ratio_name']} = {_fmt(code['ratio'])}"
        if "ratio" in code
        else "the code check could not be run"
    )
    if code["passes"] is False:
        out["verdict"] = "fails"
        out["governs"] = code["label"]
        out["reason"] = f"fails the {code_text} < 1"
        if overturns:
            out["reason"] += (
                f"; the rocking time history on {', '.join(overturns)} also overturns it at "
                "the design scale"
            )
        elif at_design:
            out["reason"] += (
                f"; the rocking time histories on {len(at_design)} record(s) at the design "
                "scale do not overturn it, which does not lift the code check's verdict"
            )
    elif overturns:
        out["verdict"] = "fails"
        out["governs"] = "rocking time history at the design scale"
        passed = "passes the code check" if code["passes"] else "has no complete code check"
        out["reason"] = (
            f"{passed} ({code_text}), but {', '.join(overturns)} scaled to the site spectrum "
            "overturns it at the design scale (x1): the more severe result governs"
        )
    elif code["passes"] is True:
        out["verdict"] = "passes"
        out["governs"] = code["label"]
        tail = (
            f"; no record overturns it at the design scale ({len(at_design)} record(s))"
            if at_design
            else ("; no record was run at the design scale" if dyn is not None else "")
        )
        out["reason"] = f"passes every code check that ran; the lowest: {code_text} >= 1{tail}"
        if code.get("not_run"):
            out["reason"] += f" (not run: {'; '.join(code['not_run'])})"
    else:
        out["verdict"] = "incomplete"
        out["governs"] = None
        out["reason"] = "; ".join(code.get("not_run", [])) or "no check could be run"
    note = _margin_note(row, overturns)
    if note:
        out["pulse_margin"] = note
    if "ratio" in code:
        out["code_check"] = {
            "check": code["check"],
            "ratio_name": code["ratio_name"],
            "capacity_ratio": code["ratio"],
        }
    return out


def conclusion(doc: dict[str, Any], building: Optional[str] = None) -> dict[str, Any]:
    """Return the ``conclusion`` block of a check or assessment document.

    Parameters
    ----------
    doc : dict
        ``check_doc`` or ``assessment_doc``: its ``mechanisms`` rows, ``method`` and
        ``site`` (the limit state); ``records`` where records were run.
    building : str, optional
        The building's name, for the sentence (the site file's ``project.building``).

    Returns
    -------
    dict
        ``verdict`` (``passes``, ``fails`` or ``incomplete``), ``sentence`` (the one line a
        client can quote), ``rule`` (``RULE``) and per mechanism its ``verdict``, the
        analysis that ``governs`` and the ``reason``; ``pulse_margin`` where the margin
        disagrees with the time history.
    """
    method = doc.get("method", {}).get("name", "circ2019")
    standard = doc.get("method", {}).get("standard", "the code")
    rows = [_mechanism(r, method) for r in doc.get("mechanisms", [])]
    n = len(rows)
    failing = [r for r in rows if r["verdict"] == "fails"]
    incomplete = [r for r in rows if r["verdict"] == "incomplete"]
    state = doc.get("site", {}).get("limit_state", "SLV")
    subject = f"The local collapse mechanisms of {building}" if building else "The mechanisms"
    records = doc.get("records")
    if failing:
        coded = [r for r in failing if "code_check" in r and r["reason"].startswith("fails")]
        worst = min(coded, key=lambda r: r["code_check"]["capacity_ratio"]) if coded else None
        verdict = "fails"
        if worst is not None:
            c = worst["code_check"]
            sentence = (
                f"{subject} do not satisfy {standard} at {state}: {len(failing)} of {n} "
                f"mechanisms fail, the most critical being {worst['id']} ({worst['name']}), "
                f"whose capacity is {_fmt(c['capacity_ratio'])} of the demand "
                f"({c['ratio_name']} < 1)."
            )
        else:
            first = failing[0]
            sentence = (
                f"{subject} do not satisfy {standard} at {state}: {len(failing)} of {n} "
                f"mechanisms fail, {first['id']} ({first['name']}) because it overturns at "
                "the design level in the rocking time history on the records scaled to the "
                "site spectrum."
            )
    elif incomplete:
        verdict = "incomplete"
        sentence = (
            f"{subject} could not all be verified: the code check could not be run for "
            f"{len(incomplete)} of {n} mechanisms ({', '.join(r['id'] for r in incomplete)}); "
            "no mechanism fails where it was run."
        )
    else:
        verdict = "passes"
        lowest = min(
            (r for r in rows if "code_check" in r),
            key=lambda r: r["code_check"]["capacity_ratio"],
            default=None,
        )
        low = (
            f" (lowest capacity/demand {_fmt(lowest['code_check']['capacity_ratio'])}, "
            f"{lowest['id']})"
            if lowest is not None
            else ""
        )
        dyn = (
            f", and none overturns at the design level in the rocking time histories on "
            f"{len(records)} record(s) scaled to the site spectrum"
            if records
            else ""
        )
        sentence = f"{subject} satisfy {standard} at {state}: all {n} mechanisms pass{low}{dyn}."
    return {
        "verdict": verdict,
        "sentence": sentence,
        "rule": RULE,
        "mechanisms": rows,
    }
