"""The retrofit document in a few words: one summary per mechanism (table rows, sentences).

``retrofit_summary`` reads a ``RetrofitDoc`` (``workflows.retrofit.retrofit_doc``) into one
plain row per mechanism: its status, the chosen tie (height above the hinge [m], bars, bar
size and grade, ``T*`` [N] in all and per bar, the governing criterion) and the least of its
capacity/demand ratios (``a_g,X/a_g``) before and after the tie. ``rockmech retrofit``
prints these rows as its table and the assessment report's page one shows them
(``rockmech assess --retrofit retrofit.json``), with a sentence per failing mechanism:
"2 Ø20 S275 ties at 7.2 m, 29 kN each, make F1 pass: a_g,SLV/a_g nonlinear 0.40 → 1.02".

Light on purpose (the document's model only): the command line loads it when it prints.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Optional

from shared_schema.documents.check import CheckMechanism, Nonlinear2019
from shared_schema.errors import InputError
from shared_schema.retrofit import (
    CheckFigures,
    MechanismRetrofit,
    RetrofitDoc,
    TieOption,
)

__all__ = [
    "RATIO_LABELS",
    "RetrofitRow",
    "check_retrofit_ids",
    "check_retrofit_matches",
    "records_notes",
    "retrofit_summary",
]

#: Relative difference above which a retrofit document's "before" ratio is not the
#: assessment's own: the document was made from other constants or another site [-].
MATCH_RTOL = 1e-9

#: How each ratio of ``CheckFigures`` is named, in the order they are compared.
RATIO_LABELS = {
    "linear_ratio": "a_g,SLV/a_g linear",
    "SLV_ratio": "a_g,SLV/a_g nonlinear",
    "SLC_ratio": "a_g,SLC/a_g nonlinear",
}
#: What each mechanism status means, in words.
STATUS_WORDS = {
    "passes": "passes: needs no tie",
    "designed": "tie designed",
    "not_achievable": "no tie option makes it pass",
    "not_applicable": "not retrofitted by a tie",
    "not_checked": "code check did not run",
    "not_evaluated": "checks not evaluated",
}


@dataclass(frozen=True)
class RetrofitRow:
    """One mechanism of a retrofit document, summarised.

    Attributes
    ----------
    id, name, status : str
        The mechanism and its retrofit status (``MechanismRetrofit.status``).
    option : TieOption, optional
        The chosen tie (designed), else the first option that has a force, else None.
    before_ratio, after_ratio : float, optional
        The least capacity/demand ratio of the checks evaluated, before and with the tie [-].
    before_label, after_label : str
        Which ratio that is (``RATIO_LABELS``).
    reason : str
        The mechanism's first decision (why it has no tie, what was chosen).
    """

    id: str
    name: str
    status: str
    option: Optional[TieOption]
    before_ratio: Optional[float]
    before_label: str
    after_ratio: Optional[float]
    after_label: str
    reason: str

    @property
    def status_words(self) -> str:
        """The status in words."""
        return STATUS_WORDS.get(self.status, self.status)

    @property
    def bar_text(self) -> str:
        """``"2 Ø20 S275"`` (bars, diameter, grade), or ``"-"`` without a bar."""
        o = self.option
        if o is None or o.bar is None:
            return "-"
        return f"{o.bars} Ø{o.bar.diameter_mm:g} {o.bar.grade}"

    @property
    def sentence(self) -> str:
        """One sentence: the tie that makes the mechanism pass, or why there is none."""
        o = self.option
        if self.status == "designed" and o is not None and o.bar is not None:
            t_star = o.T_star_N or 0.0
            many = o.bars > 1
            return (
                f"{self.bar_text} {'ties' if many else 'tie'} at {o.height_m:.3g} m, "
                f"{t_star / o.bars / 1e3:.3g} kN{' each' if many else ''}, "
                f"{'make' if many else 'makes'} {self.id} pass: {self.before_label} "
                f"{_ratio(self.before_ratio)} → {_ratio(self.after_ratio)}"
                + (
                    ""
                    if self.after_label == self.before_label
                    else f" (then {self.after_label} is the least)"
                )
            )
        return f"{self.id}: {self.status_words}: {self.reason}"


def _ratio(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.2f}"


def _least(fig: Optional[CheckFigures]) -> tuple[Optional[float], str]:
    """Return the least ratio of the checks evaluated and its label (None, "" when none)."""
    if fig is None:
        return None, ""
    got = [(getattr(fig, k), label) for k, label in RATIO_LABELS.items()]
    got = [(v, label) for v, label in got if v is not None]
    if not got:
        return None, ""
    value, label = min(got, key=lambda p: p[0])
    return float(value), label


def _option(m: MechanismRetrofit) -> Optional[TieOption]:
    if m.chosen is not None:
        return m.options[m.chosen]
    return next((o for o in m.options if o.T_star_N is not None), None)


def retrofit_summary(doc: RetrofitDoc) -> list[RetrofitRow]:
    """Return one ``RetrofitRow`` per mechanism of ``doc``, in its order.

    Examples
    --------
    >>> from shared_schema.retrofit import CheckFigures, MechanismRetrofit, RetrofitDoc
    >>> m = MechanismRetrofit(id="W", name="wall", typology="single_block", status="passes",
    ...                       before=CheckFigures(linear_ratio=1.3, SLV_ratio=1.1),
    ...                       decisions=["passes every check evaluated: needs no tie"])
    >>> row = retrofit_summary(RetrofitDoc(standard="", steel={}, decisions=[],
    ...                                    mechanisms=[m]))[0]
    >>> row.before_ratio, row.before_label
    (1.1, 'a_g,SLV/a_g nonlinear')
    >>> row.sentence
    'W: passes: needs no tie: passes every check evaluated: needs no tie'
    """
    rows = []
    for m in doc.mechanisms:
        option = _option(m)
        before, before_label = _least(m.before)
        after, after_label = _least(option.after if option is not None else None)
        reason = m.decisions[0] if m.decisions else ""
        if m.status == "not_achievable" and m.options:
            why = [d for o in m.options for d in o.decisions[:1]]
            reason = "; ".join(why) or reason
        rows.append(
            RetrofitRow(
                id=m.id,
                name=m.name,
                status=m.status,
                option=option,
                before_ratio=before,
                before_label=before_label,
                after_ratio=after,
                after_label=after_label,
                reason=reason,
            )
        )
    return rows


def check_retrofit_ids(doc: RetrofitDoc, ids: list[str]) -> None:
    """Refuse a retrofit document whose mechanisms are not those of the constants.

    Raises
    ------
    InputError
        A mechanism of the document the constants do not have (field ``retrofit``): the
        document was made from other constants.
    """
    missing = [m.id for m in doc.mechanisms if m.id not in ids]
    if missing:
        raise InputError(
            f"the retrofit document's mechanism(s) {', '.join(missing)} are not in the "
            f"constants (ids: {', '.join(ids)}); give the retrofit.json made from these "
            "constants",
            "retrofit",
        )


def _check_ratios(row: CheckMechanism) -> dict[str, Optional[float]]:
    """Return an assessment row's governing ratios, named as ``CheckFigures`` names them."""
    non = row.nonlinear
    slc = non.SLC.capacity_ratio if isinstance(non, Nonlinear2019) else None
    return {
        "linear_ratio": row.linear_ratio,
        "SLV_ratio": row.nonlinear_ratio,
        "SLC_ratio": None if slc is None else float(slc),
    }


def check_retrofit_matches(doc: RetrofitDoc, rows: Sequence[CheckMechanism]) -> None:
    """Refuse a retrofit document that was not made from this assessment's inputs.

    Parameters
    ----------
    doc : RetrofitDoc
        A ``retrofit.json`` read back.
    rows : sequence of CheckMechanism
        The mechanism rows of the code checks as the retrofit ran them
        (``assess.check_doc_with_records``: with the records' demand where it had records).

    Raises
    ------
    InputError
        (field ``retrofit``) A mechanism of the document the constants do not have, or one
        whose checks before the tie (``before``: a_g,X/a_g) are not the assessment's own to
        ``MATCH_RTOL``: the document was made from other constants or another site.
    """
    check_retrofit_ids(doc, [r.id for r in rows])
    by_id = {r.id: r for r in rows}
    for m in doc.mechanisms:
        here = _check_ratios(by_id[m.id])
        for key, label in RATIO_LABELS.items():
            theirs, ours = getattr(m.before, key), here[key]
            same = (theirs is None and ours is None) or (
                theirs is not None
                and ours is not None
                and math.isclose(theirs, ours, rel_tol=MATCH_RTOL, abs_tol=0.0)
            )
            if not same:
                names = ", ".join(str(r.get("name", "?")) for r in doc.records)
                records = f" or other records than its {names}" if names else ""
                raise InputError(
                    f"the retrofit document's {m.id} has {label} {_ratio(theirs)} before the "
                    f"tie where these inputs give {_ratio(ours)}: it was made from other "
                    f"constants or another site{records}; run rockmech retrofit again on "
                    "these files, or give the retrofit spec",
                    "retrofit",
                )


def records_notes(doc: RetrofitDoc, rows: Sequence[CheckMechanism]) -> dict[str, str]:
    """Say where the assessment's records raise a demand the retrofit did not size for.

    A retrofit run with the assessment's records takes their demand as the assessment does
    (Circ. 2019 C8.7.1.2.1.8, ``assess.check_doc_with_records``), and this finds nothing. A
    ``retrofit.json`` made without records ran the code checks on the site spectrum alone;
    with records, the assessment's nonlinear check also takes their largest spectral
    displacement, so its ratio may be lower than that document's "before".

    Parameters
    ----------
    doc : RetrofitDoc
        The retrofit.
    rows : sequence of CheckMechanism
        The assessment's mechanism rows (``assessment_document(...).mechanisms``).

    Returns
    -------
    dict
        ``{mechanism id: sentence}`` for the mechanisms whose nonlinear ratio differs.
    """
    by_id = {r.id: r for r in rows}
    notes = {}
    for m in doc.mechanisms:
        row = by_id.get(m.id)
        if row is None:
            continue
        here = _check_ratios(row)
        for key in ("SLV_ratio", "SLC_ratio"):
            theirs, ours = getattr(m.before, key), here[key]
            if theirs is None or ours is None:
                continue
            if not math.isclose(theirs, ours, rel_tol=MATCH_RTOL, abs_tol=0.0):
                notes[m.id] = (
                    f"with the records' demand (Circ. 2019 C8.7.1.2.1.8) this assessment's "
                    f"{RATIO_LABELS[key]} is {ours:.3g}; the retrofit's {theirs:.3g} is the "
                    "site spectrum's alone: the tie is sized without the records"
                )
                break
    return notes
