"""The retrofit document: the least tie force that makes each failing mechanism pass.

``retrofit_doc`` takes a constants file, a site and a retrofit spec
(``shared_schema.retrofit``). For every mechanism that fails the Circolare 2019 checks
(``codecheck.check_doc``: the linear check at SLV, the nonlinear check at SLV and, where the
site gives its hazard, at SLC) and every candidate tie height, it finds the least tie force
``T*`` (docs/theory.md §11.12):

* linear check: ``α0`` is affine in ``T`` ([C8.7.1.1]: the tie's virtual work ``T h_t`` per
  unit rotation) and the demand does not depend on it, so
  ``T_lin = (α0/ratio − α0) g S / h_t`` in closed form, with the check's own ``e*``;
* nonlinear check: bisection on ``T`` (to ``T_REL_TOL``) with the tie counted up to collapse
  (``ties: verified``, §C8.7.1.2.1.6), for the SLV and the SLC apart;

``T*`` is the largest, and the criterion that gives it is named. Then the smallest bar on
offer whose yield resistance ``N_pl,Rd = A f_yk/γ_M0`` (NTC 2018 [4.2.6]) carries its share,
the anchorage against the user's resistance, and the steel mass. Only when the bar and the
anchorage carry ``T*`` is the tie counted as verified; otherwise the check after it leaves
the tie out of ``d0`` and the document says so. Each mechanism is rechecked with its tie.

A tie is added to the positive side's constants exactly as the builder adds a tie-bar
(theory §2.2, Eq. 15: ``M_F −= T h_t cos α_c`` on the outer face through the hinge;
``α0 += T h_t/(g S)``; ``φ_ov``, ``λ`` by Eq. 16) and, where it is not verified, listed in
the geometry's elements so that the check takes it out of ``d0`` (theory §11.7). A tie pulls
on the outward swing only (theory §1.8): the negative side of a two-sided mechanism is the
mechanism without it.
"""

from __future__ import annotations

import functools
import math
from typing import Any, Optional, Sequence

from shared_schema.constants import ConstantsFile, Mechanism
from shared_schema.errors import InputError, RockmechError
from shared_schema.retrofit import (
    GAMMA_M0,
    STEEL_DENSITY,
    AnchorageCheck,
    BarChoice,
    CheckFigures,
    GoverningNext,
    GoverningRow,
    MechanismRetrofit,
    MechanismTies,
    RecordScale,
    RecordTie,
    RetrofitDoc,
    RetrofitSpec,
    TieOption,
    bar_strengths,
)
from shared_schema.site import MechanismOptions, SiteFile

from ..codes.circ2019 import CIRC2019
from ..core.model import G
from .assess import check_doc_with_records
from .codecheck import number_at
from .retrofit_records import RECORD_DECISIONS, MechanismRecords, tie_slope

__all__ = [
    "ALPHA0_MAX",
    "HEIGHT_SAME_M",
    "HEIGHT_SAME_REL",
    "LEVEL_KINDS",
    "RECORDS_DEMAND_DECISION",
    "RETROFIT_DECISIONS",
    "SINGLE_BLOCK_TYPOLOGIES",
    "T_REL_TOL",
    "default_heights",
    "governs_next",
    "least_margin",
    "level_height",
    "retrofit_doc",
    "top_height",
    "with_tie",
]

#: Relative width of the bracket at which the bisection on T stops (the issue's 0.5 %): the
#: reported T is the bracket's passing end.
T_REL_TOL = 0.005
#: The bisection's largest tie force: the one that brings α0 to this [-]. A mechanism
#: that still fails there is reported as not stopped by a tie at that height.
ALPHA0_MAX = 2.0
#: The linear T is nudged up by this relative amount so that the check at T reads ≥ 1
#: despite rounding (the closed form lands on ratio = 1 exactly).
LINEAR_NUDGE = 1e-9
#: Typologies whose one block turns about the hinge: a tie at height h_t above it moves
#: h_t per unit rotation. Multi-block mechanisms need each block's share, which the
#: constants do not carry.
SINGLE_BLOCK_TYPOLOGIES = ("single_block", "single_block_loaded", "user_defined")
#: The element label of the tie the retrofit adds.
TIE_LABEL = "retrofit.tie"

RETROFIT_DECISIONS = [
    "The tie is a constant force T on the outer face through the hinge, at height h_t above "
    "it (the builder's tie-bar, theory §2.2): α0 gains T h_t/(g S) ([C8.7.1.1]), M_F loses "
    "T h_t cos α_c (Eq. 15).",
    "e* ([C8.7.1.5]) does not depend on T (static forces are not in it); it is the code "
    "check's (site local_mechanisms.e_star: one term per block by default, e* = 1 for one "
    "block) and is reported with every T.",
    "FC divides the whole α0 ([C8.7.1.8]), the new tie's share included, as the text reads.",
    "The linear T* is closed form (α0 affine in T, the demand independent of it); the "
    "nonlinear T* is a bisection on T to 0.5 %, with the tie verified to hold up to "
    "collapse (C8.7.1.2.1.6); T* is the largest of the criteria evaluated.",
    "A tie counts as verified only when its bar (NTC 2018 [4.2.6], γ_M0 of Tab. 4.2.VII) "
    "and its anchorage (the user's resistance and source) carry its share of T*; "
    "otherwise the check after leaves it out of d0 and the mechanism is not made to pass.",
    "The capacity-design rule NTC 2018 [4.2.8] (N_pl,Rd ≤ N_u,Rd of the threaded ends) and "
    "the bar's elongation up to collapse are not checked: the ends and their stress area "
    "are the designer's.",
    "A tie pulls on the outward swing only (theory §1.8): the negative side of a two-sided "
    "mechanism is unchanged, and if it fails no tie makes the mechanism pass.",
    "Bars at one height share T* equally; the steel mass is per metre unless the spec "
    "gives the bar length (the constants do not carry where the bar is anchored).",
]

#: With records, the decision on the nonlinear check's demand (listed in the document).
RECORDS_DEMAND_DECISION = (
    "With records, the nonlinear checks before and after the tie, and the bisection of their "
    "T*, take the demand as rockmech assess does (Circ. 2019 C8.7.1.2.1.8; one function, "
    "assess.check_doc_with_records): the larger of the site spectrum's and the records' "
    "largest S_De over [T0, T_SLV], each record matched to the site spectrum over the band "
    "of the mechanism with the tie at that force (its own T_SLV)."
)

_CL = {
    "linear_ratio": "Circ. 2019 C8.7.1.2.1.7: a_g,SLV/a_g (linear kinematic analysis)",
    "SLV_ratio": "Circ. 2019 C8.7.1.2.1.8: a_g,SLV/a_g (nonlinear, a_g,SLV ≥ a_g,SLD)",
    "SLC_ratio": "Circ. 2019 C8.7.1.2.1.8: a_g,SLC/a_g (nonlinear)",
    "alpha0": "Circ. 2019 C8.7.1.2.1.1 [C8.7.1.1]",
    "e_star": "Circ. 2019 C8.7.1.2.1.3 [C8.7.1.5]",
    "ties": "Circ. 2019 C8.7.1.2.1.6 (actions verified present up to collapse)",
}
_BAR_CLAUSES = {
    "f_yk": "NTC 2018 Tab. 4.2.I (UNI EN 10025-2)",
    "gamma_M0": "NTC 2018 Tab. 4.2.VII",
    "N_pl_Rd_N": "NTC 2018 §4.2.4.1.2.1 [4.2.6]: N_pl,Rd = A f_yk/γ_M0",
    "utilisation": "NTC 2018 [4.2.5]: N_Ed/N_t,Rd ≤ 1",
}


# --- one tie on a mechanism -----------------------------------------------------------


def _single_block_problem(mech: Mechanism) -> Optional[str]:
    """Why a tie cannot be put on this mechanism's constants, or None."""
    if mech.typology not in SINGLE_BLOCK_TYPOLOGIES:
        return (
            f"typology {mech.typology}: a tie's virtual displacement on a chain of blocks "
            "needs each block's share, which the constants do not carry; only single-block "
            "mechanisms are retrofitted in this version"
        )
    side = mech.positive
    if side.virtual_work is None or side.K is None or side.M_F is None or side.phi_cr is None:
        return (
            "the constants give no virtual_work or physical form (K, M_F, phi_cr) on the "
            "positive side: compute them from the geometry with `rockmech constants`"
        )
    geo = mech.geometry if isinstance(mech.geometry, dict) else {}
    pos = geo.get("positive")
    if not isinstance(pos, dict) or "axis_point_m" not in pos or "com_m" not in geo:
        return (
            "the constants' geometry gives no hinge (positive.axis_point_m) or centre of mass "
            "(com_m): compute them from the geometry with `rockmech constants`"
        )
    return None


def top_height(mech: Mechanism) -> tuple[Optional[float], str]:
    """Height of the moving part's top above the hinge [m], and where it comes from."""
    geo = mech.geometry
    h = number_at(geo, "h_m")
    if h is not None:
        return h, "the geometry's h_m"
    top = number_at(geo, "top_m")  # the builder's: the moving part's highest point
    if top is not None and top > 0.0:
        return top, "the geometry's top_m (the moving part's highest point)"
    r, a = number_at(geo, "positive", "R_m"), number_at(geo, "positive", "alpha_rad")
    if r is not None and a is not None:
        not_rectangle = _not_a_rectangle(geo, r)
        if not_rectangle is not None:
            return None, not_rectangle
        return 2.0 * r * math.cos(a), "the rectangle of the block's R and alpha (2 R cos α)"
    return None, "the constants' geometry gives no height of the moving part"


#: A homogeneous rectangular block has I_O = 4/3 M R² about its edge: within this, it is one.
RECTANGLE_RTOL = 1e-6


def _not_a_rectangle(geo: Any, r: float) -> Optional[str]:
    """Why 2 R cos α is not the block's top (None: a rectangle, or nothing tells).

    Only a homogeneous rectangle has its top at twice its centre of mass's height; its
    inertia about the hinge is then ``4/3 M R²``, which the constants' geometry can show.
    """
    i_o, mass = number_at(geo, "positive", "I_O_kg_m2"), number_at(geo, "mass_kg")
    if i_o is None or mass is None or mass <= 0:
        return None
    ratio = i_o / (4.0 / 3.0 * mass * r * r)
    if abs(ratio - 1.0) <= RECTANGLE_RTOL:
        return None
    return (
        "the constants' geometry gives no top of the moving part (top_m), and the block is "
        f"not a homogeneous rectangle (I_O = {ratio:.4g} x 4/3 M R^2), so 2 R cos α is not "
        "its top"
    )


def with_tie(mech: Mechanism, force: float, height: float, *, listed: bool) -> Mechanism:
    """Return the mechanism with a tie of ``force`` [N] at ``height`` [m] above the hinge.

    Parameters
    ----------
    mech : Mechanism
        A single-block mechanism in physical form with ``virtual_work`` and its geometry.
    force : float
        The tie's force [N], ≥ 0.
    height : float
        Its height above the hinge on the outer face through the hinge [m], > 0.
    listed : bool
        Whether to list the tie in ``geometry.loaded.elements`` (the code check then takes it
        out of ``d0`` unless the mechanism's ties are verified, theory §11.7).

    Notes
    -----
    Theory §2.2: a tie pulls inward at a point of the outer face at height ``z`` above the
    hinge (``x = 0``), so Eq. 15 gives ``M_F,tie = −T z cos α_c`` with ``α_c = φ_cr``, and
    [C8.7.1.1] ``α0 += T z/(g S)``; Eq. 16 gives ``φ_ov = φ_cr − M_F/K`` and
    ``λ = (K φ_cr − M_F)/(g Q)``. The negative side of a two-sided mechanism is the
    mechanism's own: the tie is slack on that swing (theory §1.8).
    """
    side = mech.positive
    vw = side.virtual_work
    assert vw is not None and side.K is not None and side.M_F is not None
    assert side.phi_cr is not None and side.Q is not None
    m_f = side.M_F - force * height * math.cos(side.phi_cr)
    new_vw = vw.model_copy(update={"alpha0": vw.alpha0 + force * height / (G * vw.S)})
    new_pos = side.model_copy(
        update={
            "M_F": m_f,
            "phi_ov": side.phi_cr - m_f / side.K,
            "lam": (side.K * side.phi_cr - m_f) / (G * side.Q),
            "virtual_work": new_vw,
        }
    )
    update: dict[str, Any] = {"positive": new_pos}
    if mech.rocking == "two_sided" and mech.negative is None:
        update["negative"] = side  # the mirror image, without the tie
    geo: dict[str, Any] = dict(mech.geometry) if isinstance(mech.geometry, dict) else {}
    if listed:
        loaded: dict[str, Any] = dict(geo.get("loaded") or {})
        loaded.setdefault("alpha_c_rad", side.phi_cr)
        pos = geo["positive"]
        axis = [float(v) for v in pos["axis_point_m"]]
        at = [axis[0], axis[1], axis[2] + height]
        elements = list(loaded.get("elements") or [])
        elements.append({"element": TIE_LABEL, "kind": "tie_bar", "force_N": force, "at_m": at})
        loaded["elements"] = elements
        geo["loaded"] = loaded
    update["geometry"] = geo
    return Mechanism.model_validate(mech.model_copy(update=update).model_dump())


def _has_ties(mech: Mechanism) -> bool:
    """Whether the constants' geometry lists tie-bars (theory §11.7)."""
    geo: dict[str, Any] = mech.geometry if isinstance(mech.geometry, dict) else {}
    loaded = geo.get("loaded")
    elements = loaded.get("elements") if isinstance(loaded, dict) else None
    listed: list[Any] = elements if isinstance(elements, list) else []
    return any(isinstance(e, dict) and e.get("kind") == "tie_bar" for e in listed)


def _unlist_ties(mech: Mechanism) -> Mechanism:
    """Return the mechanism with its listed tie-bars baked in (counted up to collapse)."""
    geo: dict[str, Any] = dict(mech.geometry) if isinstance(mech.geometry, dict) else {}
    loaded = geo.get("loaded")
    if not isinstance(loaded, dict):
        return mech
    loaded = dict(loaded)
    elements = loaded.get("elements")
    loaded["elements"] = [
        e
        for e in (elements if isinstance(elements, list) else [])
        if not (isinstance(e, dict) and e.get("kind") == "tie_bar")
    ]
    geo["loaded"] = loaded
    return mech.model_copy(update={"geometry": geo})


# --- the checks of one mechanism ------------------------------------------------------


class _Checker:
    """Runs the code check of one mechanism with a tie, as ``rockmech assess`` does.

    With records (``motions``), the nonlinear demand is also theirs (C8.7.1.2.1.8), by
    ``assess.check_doc_with_records``: each record matched over the band of the mechanism
    with the tie at that force.
    """

    def __init__(
        self, cf: ConstantsFile, site: SiteFile, mech: Mechanism, motions: Sequence[Any] = ()
    ) -> None:
        self.cf = cf
        self.site = site
        self.mech = mech
        self.motions = motions
        lm = site.local_mechanisms
        self.options = lm.mechanisms.get(mech.id) or MechanismOptions()
        self.runs = 0

    def _site(self, options: MechanismOptions) -> SiteFile:
        lm = self.site.local_mechanisms.model_copy(update={"mechanisms": {self.mech.id: options}})
        return self.site.model_copy(update={"local_mechanisms": lm})

    def row(self, force: float, height: float, verified: bool) -> dict[str, Any]:
        """Return the check row of the mechanism with the tie (``force`` 0: as it stands)."""
        self.runs += 1
        mech, opts = self.mech, self.options
        if force > 0.0:
            if verified and (opts.ties == "verified" or not _has_ties(mech)):
                # Listed and verified: the check names the tie and counts it in d0.
                mech = with_tie(mech, force, height, listed=True)
                opts = opts.model_copy(update={"ties": "verified"})
            elif verified:
                # The existing ties are not verified: the new one, baked into the
                # constants but not listed, stays in d0 while they are taken out.
                mech = with_tie(mech, force, height, listed=False)
            else:
                if opts.ties == "verified":
                    # The existing ties stay counted; only the new one is taken out of d0.
                    mech = _unlist_ties(mech)
                    opts = opts.model_copy(update={"ties": "not_verified"})
                mech = with_tie(mech, force, height, listed=True)
        cf = self.cf.model_copy(update={"mechanisms": [mech]})
        # With records, the nonlinear demand is assess's (C8.7.1.2.1.8): the same function.
        doc, _ = check_doc_with_records(cf, self._site(opts), self.motions)
        row: dict[str, Any] = doc["mechanisms"][0]
        return row


def _figures(checks: dict[str, Any]) -> CheckFigures:
    """Return the figures of a side's (or a row's governing) linear and nonlinear checks."""
    lin, non = checks["linear"], checks["nonlinear"]
    fig = CheckFigures(clauses=dict(_CL))
    notes: list[str] = []
    if lin.get("status") == "ok":
        fig.linear_ratio = float(lin["capacity_ratio"])
        fig.linear_passes = lin["passes"]
        fig.alpha0 = float(lin["alpha0"])
        fig.e_star = float(lin["e_star"])
    else:
        notes.append("linear check not run: " + str(lin.get("note", "")))
    if non.get("status") == "ok":
        fig.SLV_ratio = float(non["capacity_ratio"])
        fig.SLV_passes = non["passes"]
        slc = non.get("SLC")
        if isinstance(slc, dict):
            fig.SLC_ratio = float(slc["capacity_ratio"])
            fig.SLC_passes = slc.get("passes")
        ties = non.get("ties") or {}
        if ties.get("present"):
            fig.ties = str(ties.get("rule", ties.get("treatment", "")))
    else:
        notes.append("nonlinear check not run: " + str(non.get("note", "")))
    fig.notes = notes + [n for n in (lin.get("notes") or []) + (non.get("notes") or []) if n]
    return fig


def _row_figures(row: dict[str, Any]) -> CheckFigures:
    return _figures({"linear": row["linear"], "nonlinear": row["nonlinear"]})


# --- the least force ------------------------------------------------------------------


def _least_force(ok: Any, hi0: float, t_max: float) -> tuple[Optional[float], int]:
    """Least T in (0, t_max] with ``ok(T)``, by doubling from ``hi0`` then bisection.

    Returns the bracket's passing end (within ``T_REL_TOL`` of the least) and the number of
    evaluations; None when ``ok(t_max)`` is false.
    """
    runs = 0
    lo, hi = 0.0, min(max(hi0, t_max * 1e-6), t_max)
    while True:
        runs += 1
        if ok(hi):
            break
        lo = hi
        if hi >= t_max:
            return None, runs
        hi = min(2.0 * hi, t_max)
    while hi - lo > T_REL_TOL * hi:
        mid = 0.5 * (lo + hi)
        runs += 1
        if ok(mid):
            hi = mid
        else:
            lo = mid
    return hi, runs


def _bar(spec: RetrofitSpec, force: float) -> tuple[Optional[BarChoice], str]:
    """Return the smallest bar on offer whose N_pl,Rd carries ``force`` [N], or why none does."""
    grade = spec.steel.grade
    best = None
    for d in spec.steel.diameters_mm:
        f_yk, f_tk, row = bar_strengths(grade, d)
        area = math.pi * d * d / 4.0
        n_pl = area * f_yk / GAMMA_M0
        if n_pl >= force:
            best = BarChoice(
                grade=grade,
                diameter_mm=d,
                area_mm2=area,
                f_yk=f_yk,
                f_tk=f_tk,
                gamma_M0=GAMMA_M0,
                N_pl_Rd_N=n_pl,
                force_N=force,
                utilisation=force / n_pl,
                clauses={**_BAR_CLAUSES, "f_yk": row},
            )
            break
    if best is not None:
        return best, ""
    d = spec.steel.diameters_mm[-1]
    f_yk, _, _ = bar_strengths(grade, d)
    n_pl = math.pi * d * d / 4.0 * f_yk / GAMMA_M0
    return None, (
        f"no bar on offer carries {force:.4g} N: the largest, Ø{d:g} {grade}, has N_pl,Rd = "
        f"{n_pl:.4g} N (NTC 2018 [4.2.6]); offer larger bars or more bars at the height"
    )


def _criteria(
    checker: _Checker, before: dict[str, Any], height: float, t_max: float
) -> dict[str, Optional[float]]:
    """Return the least force [N] per criterion (None: no force up to ``t_max`` suffices)."""
    vw = checker.mech.positive.virtual_work
    assert vw is not None
    pos = before["sides"]["positive"]
    lin = pos["linear"]
    criteria: dict[str, Optional[float]] = {}
    if lin.get("status") == "ok" and lin["passes"] is not None:
        # [C8.7.1.1]: α0 affine in T, the demand independent of it, the ratio ∝ α0.
        r0, a0 = float(lin["capacity_ratio"]), float(lin["alpha0"])
        t_lin = 0.0 if r0 >= 1.0 else (a0 / r0 - a0) * G * vw.S / height
        criteria["linear SLV"] = t_lin * (1.0 + LINEAR_NUDGE)
    non = pos["nonlinear"]
    if non.get("status") != "ok":
        return criteria
    for ls in ("SLV", "SLC"):
        if non.get(ls, {}).get("passes") is None:
            continue

        def ok(t: float, ls: str = ls) -> bool:
            row = checker.row(t, height, verified=True)
            chk = row["sides"]["positive"]["nonlinear"]
            return bool(chk.get("status") == "ok" and chk[ls]["passes"])

        if non[ls]["passes"]:
            criteria[f"nonlinear {ls}"] = 0.0
            continue
        hi0 = max(criteria.get("linear SLV") or 0.0, 1e-3 * G * vw.mass)
        criteria[f"nonlinear {ls}"] = _least_force(ok, hi0, t_max)[0]
    return criteria


def _carried(
    spec: RetrofitSpec, ties: MechanismTies, per_bar: float, decisions: list[str]
) -> tuple[Optional[BarChoice], AnchorageCheck, bool]:
    """Return the bar, the anchorage check and whether they carry one tie's ``per_bar`` [N].

    What they cannot carry is added to ``decisions``.
    """
    bar, bar_note = _bar(spec, per_bar)
    anc_spec = ties.anchorage or spec.anchorage
    anchorage = AnchorageCheck(
        capacity_N=anc_spec.capacity_N,
        source=anc_spec.source,
        force_N=per_bar,
        passes=per_bar <= anc_spec.capacity_N,
    )
    if bar_note:
        decisions.append(bar_note)
    if not anchorage.passes:
        decisions.append(
            f"the anchorage resistance {anc_spec.capacity_N:.4g} N ({anc_spec.source}) is "
            f"below the {per_bar:.4g} N of one tie: more bars at the height, or a stronger "
            "anchorage"
        )
    verified = bar is not None and anchorage.passes
    if not verified:
        decisions.append(
            "the tie is not verified to hold up to collapse (C8.7.1.2.1.6): the check after "
            "leaves it out of d0, and the mechanism is not made to pass"
        )
    return bar, anchorage, verified


def _together(
    recs: MechanismRecords,
    mech: Mechanism,
    height: float,
    governing: str,
    t_star: float,
    t_max: float,
    ties: list[RecordTie],
) -> Optional[tuple[str, float, list[RecordScale]]]:
    """Run the records at the largest criterion's force, raise it where one overturns.

    Returns the governing criterion, the force [N] and the records with the tie at it, or
    None where no force up to ``t_max`` makes every record survive there (``ties`` keep
    the runs and notes of the search, in place).
    """

    def tied(force: float) -> Mechanism:
        return with_tie(mech, force, height, listed=False)

    if governing == "records":  # tie_forces ran them together at this force
        return governing, t_star, recs.scales(tied(t_star))
    t_all, _ = recs.together(tied, t_star, t_max, ties)
    if t_all is None:
        return None
    if t_all > t_star:
        governing, t_star = "records", t_all
    return governing, t_star, recs.scales(tied(t_star))


def _above_moving_part(
    height: float, height_source: str, top: Optional[float], bars: int
) -> Optional[TieOption]:
    """Return the option of a tie above the moving part's top (None: it is not above)."""
    if top is None or height <= top * (1.0 + 1e-9):
        return None
    return TieOption(
        height_m=height,
        height_source=height_source,
        status="above_moving_part",
        bars=bars,
        verified=False,
        decisions=[
            f"the tie at {height:g} m is above the moving part (its top is {top:.4g} m "
            "above the hinge): it meets no block that moves, so it restrains nothing and "
            "changes no check; put it at or below the top"
        ],
    )


def _option_criteria(
    checker: _Checker,
    before: dict[str, Any],
    height: float,
    t_max: float,
    recs: Optional[MechanismRecords],
    records_before: Sequence[RecordScale],
) -> tuple[dict[str, Optional[float]], list[RecordTie]]:
    """Return the least force [N] per criterion, the records' included, and each record's."""
    criteria = _criteria(checker, before, height, t_max)
    record_ties: list[RecordTie] = []
    if recs is not None and recs.records:
        tied = functools.partial(with_tie, checker.mech, height=height, listed=False)
        slope = tie_slope(checker.mech, height)
        criteria["records"], record_ties = recs.tie_forces(tied, slope, records_before, t_max)
    return criteria, record_ties


def _option_notes(
    before: dict[str, Any], e_star: Optional[float], governing: str, t_star: float
) -> list[str]:
    """Return the decisions of a designed option: its e* and an inward side a tie cannot help."""
    notes = []
    if e_star is not None:
        notes.append(
            f"T* = {t_star:.6g} N, governed by the {governing} check, with e* = {e_star:.4g} "
            "([C8.7.1.5] as the code check sums it)"
        )
    neg = before["sides"].get("negative")
    if neg is not None and _figures(neg).passes is False:
        notes.append(
            "the negative (inward) side fails and a tie, slack on that swing (theory "
            "§1.8), does not help it: the mechanism still fails there"
        )
    return notes


def _steel_mass(
    bar: Optional[BarChoice], ties: MechanismTies, decisions: list[str]
) -> tuple[Optional[float], Optional[float]]:
    """Return the bars' steel mass [kg] and per metre [kg/m] (None: no bar, no length)."""
    if bar is None:
        return None, None
    per_m = ties.bars * bar.area_mm2 * 1e-6 * STEEL_DENSITY
    if ties.length_m is None:
        decisions.append("steel mass per metre: the spec gives no bar length (length_m)")
        return None, per_m
    return per_m * ties.length_m, per_m


def _designed(
    checker: _Checker,
    spec: RetrofitSpec,
    ties: MechanismTies,
    before: dict[str, Any],
    common: dict[str, Any],
    governing: str,
    t_star: float,
    records_after: list[RecordScale],
) -> TieOption:
    """Return the option with its force: the bar, the anchorage, the checks after, the steel."""
    decisions: list[str] = []
    bar, anchorage, verified = _carried(spec, ties, t_star / ties.bars, decisions)
    after = _row_figures(checker.row(t_star, common["height_m"], verified=verified))
    decisions += _option_notes(before, common["e_star"], governing, t_star)
    mass, per_m = _steel_mass(bar, ties, decisions)
    return TieOption(
        **common,
        status="designed" if verified and after.passes else "not_carried",
        T_star_N=t_star,
        governing=governing,
        bar=bar,
        anchorage=anchorage,
        verified=verified,
        steel_mass_kg=mass,
        steel_mass_per_m_kg=per_m,
        after=after,
        records_after=records_after,
        decisions=decisions,
    )


def _option(
    checker: _Checker,
    spec: RetrofitSpec,
    ties: MechanismTies,
    before: dict[str, Any],
    height: float,
    height_source: str,
    top: Optional[float],
    recs: Optional[MechanismRecords] = None,
    records_before: Sequence[RecordScale] = (),
) -> TieOption:
    above = _above_moving_part(height, height_source, top, ties.bars)
    if above is not None:
        return above
    vw = checker.mech.positive.virtual_work
    assert vw is not None
    t_max = (ALPHA0_MAX - vw.alpha0) * G * vw.S / height
    lin = before["sides"]["positive"]["linear"]
    criteria, record_ties = _option_criteria(checker, before, height, t_max, recs, records_before)
    common = {
        "height_m": height,
        "height_source": height_source,
        "T_linear_N": criteria.get("linear SLV"),
        "T_nonlinear_SLV_N": criteria.get("nonlinear SLV"),
        "T_nonlinear_SLC_N": criteria.get("nonlinear SLC"),
        "e_star": float(lin["e_star"]) if lin.get("status") == "ok" else None,
        "bars": ties.bars,
        "T_records_N": criteria.get("records"),
        "records": record_ties,
    }
    stuck = [k for k, v in criteria.items() if v is None]
    if stuck:
        return TieOption(
            **common,
            status="no_force_suffices",
            verified=False,
            decisions=[
                f"no tie force at {height:g} m up to {t_max:.4g} N (α0 = {ALPHA0_MAX:g}) makes "
                f"the {', '.join(stuck)} check pass"
            ],
        )
    governing, t_star = max(
        ((k, v) for k, v in criteria.items() if v is not None), key=lambda p: p[1]
    )
    records_after: list[RecordScale] = []
    if recs is not None and recs.records:
        together = _together(recs, checker.mech, height, governing, t_star, t_max, record_ties)
        if together is None:
            return TieOption(
                **common,
                status="no_force_suffices",
                verified=False,
                decisions=[
                    f"with the {t_star:.6g} N the {governing} check needs, a record "
                    f"overturns at its design scale and no force up to {t_max:.4g} N "
                    "above it survives"
                ],
            )
        governing, t_star, records_after = together
    return _designed(checker, spec, ties, before, common, governing, t_star, records_after)


def _failing(fig: CheckFigures) -> bool:
    return False in (fig.linear_passes, fig.SLV_passes, fig.SLC_passes)


def _records(
    mech: Mechanism, row: dict[str, Any], site: SiteFile, motions: Sequence[Any]
) -> tuple[Optional[MechanismRecords], list[RecordScale], list[str]]:
    """Return the records of one mechanism as it stands, or why they cannot run on it."""
    if not motions:
        return None, [], []
    try:
        recs = MechanismRecords(mech, row, motions, site)
        return recs, recs.scales(mech), []
    except RockmechError as exc:
        return None, [], [f"the records are not run on this mechanism: {exc}"]


def _records_fail(scales: Sequence[RecordScale]) -> bool:
    return any(sc.survives_design is False for sc in scales)


def _standing(
    head: dict[str, Any],
    mech: Mechanism,
    row: dict[str, Any],
    records_fail: bool,
    record_notes: list[str],
) -> Optional[MechanismRetrofit]:
    """Return a mechanism that takes no tie option (why, as it stands), or None."""
    before: CheckFigures = head["before"]
    if before.linear_ratio is None and before.SLV_ratio is None:
        return MechanismRetrofit(
            **head,
            status="not_checked",
            decisions=["the code check did not run", *before.notes, *record_notes],
        )
    if not _failing(before) and not records_fail:
        if before.SLV_passes is None and before.linear_passes is None:
            return MechanismRetrofit(
                **head,
                status="not_evaluated",
                decisions=["the site's checks are not evaluated (see the notes)"],
            )
        said = "passes every check evaluated"
        if head["records_before"]:
            said += " and survives every record at its design scale"
        return MechanismRetrofit(
            **head, status="passes", decisions=[f"{said}: needs no tie", *record_notes]
        )
    if not records_fail and not _failing(_figures(row["sides"]["positive"])):
        return MechanismRetrofit(
            **head,
            status="not_achievable",
            decisions=[
                "only the negative (inward) side fails: a tie is slack on that swing "
                "(theory §1.8) and cannot help it"
            ],
        )
    problem = _single_block_problem(mech)
    if problem is not None:
        return MechanismRetrofit(
            **head, status="not_applicable", decisions=[problem, *record_notes]
        )
    return None


#: The element kinds of the constants' ``geometry.loaded.elements`` that are levels: each
#: one the moving part carries is a default candidate tie height (docs/theory.md §11.12).
LEVEL_KINDS = ("floor", "roof")
#: Candidate heights closer than the larger of these are one candidate (a level at the top
#: is the top's): 1 mm [m], or 0.5 % of the top's height [-] (the top read as 2 R cos α of a
#: block that is not a rectangle is a few millimetres off the wall's top).
HEIGHT_SAME_M, HEIGHT_SAME_REL = 1e-3, 0.005


def level_height(mech: Mechanism, at: Sequence[float]) -> Optional[float]:
    """Return the height [m] of a point above the mechanism's hinge axis, along the vertical.

    The height is the point's ``z`` less the ``z`` of the hinge axis where the axis passes
    below (or above) the point in plan: the lever arm of a horizontal tie about a horizontal
    hinge, as ``with_tie`` takes it. None without a hinge in the geometry, or for a vertical
    axis.
    """
    geo: dict[str, Any] = mech.geometry if isinstance(mech.geometry, dict) else {}
    got = geo.get("positive")
    pos: dict[str, Any] = got if isinstance(got, dict) else {}
    p, d = pos.get("axis_point_m"), pos.get("axis_direction", [0.0, 0.0, 0.0])
    if not isinstance(p, list) or len(p) != 3 or len(at) != 3:
        return None
    dh = math.hypot(float(d[0]), float(d[1]))
    if dh == 0.0 and float(d[2]) != 0.0:
        return None
    t = 0.0
    if dh > 0.0:
        t = ((at[0] - p[0]) * d[0] + (at[1] - p[1]) * d[1]) / (dh * dh)
    return float(at[2]) - (float(p[2]) + t * float(d[2]))


def _level_points(mech: Mechanism) -> list[tuple[float, str]]:
    """Return the heights [m] above the hinge of the levels the moving part carries."""
    geo: dict[str, Any] = mech.geometry if isinstance(mech.geometry, dict) else {}
    loaded = geo.get("loaded")
    elements = loaded.get("elements") if isinstance(loaded, dict) else None
    out = []
    for e in elements if isinstance(elements, list) else []:
        if not isinstance(e, dict) or e.get("kind") not in LEVEL_KINDS:
            continue
        at = e.get("at_m")
        h = level_height(mech, at) if isinstance(at, list) else None
        if h is not None:
            out.append((h, f"{e['kind']} {e.get('element', '?')}"))
    return sorted(out)


def default_heights(
    mech: Mechanism, top: float, top_words: str, label: str = "default"
) -> tuple[list[tuple[float, str]], list[str]]:
    """Return the default candidate heights [m] with their sources, and notes.

    ``top`` is the moving part's top above the hinge [m], ``top_words`` where it comes from
    (``"the top of the moving part (the geometry's h_m)"``) and ``label`` the sources' first
    words (``"default"``).

    One tie at the top of the moving part and one at each level (``LEVEL_KINDS`` of the
    constants' ``geometry.loaded.elements``) strictly between the hinge and the top, in
    ascending order; heights within ``max(HEIGHT_SAME_M, HEIGHT_SAME_REL top)`` are one
    candidate whose source names each level (a level at the top is the top's candidate, at
    the top's height).
    """
    tol = max(HEIGHT_SAME_M, HEIGHT_SAME_REL * top)
    groups: list[tuple[float, list[str]]] = []
    notes: list[str] = []
    top_names: list[str] = []
    for h, name in _level_points(mech):
        if abs(h - top) <= tol:
            top_names.append(f"{name} at {h:.4g} m")
        elif not 0.0 < h < top:
            notes.append(
                f"the {name} at {h:.4g} m above the hinge is not between the hinge and the "
                f"moving part's top ({top:.4g} m): no default tie there"
            )
        elif groups and h - groups[-1][0] <= tol:
            groups[-1][1].append(name)
        else:
            groups.append((h, [name]))
    heights = [
        (h, f"{label}: {' and '.join(names)} at {h:.4g} m above the hinge") for h, names in groups
    ]
    src = f"{label}: {top_words}"
    if top_names:
        src += ", with the " + " and the ".join(top_names)
    return [*heights, (top, src)], notes


def _heights(
    mech: Mechanism, ties: MechanismTies
) -> tuple[list[tuple[float, str]], Optional[float], list[str]]:
    """Return the candidate tie heights [m] with their sources, the moving part's top, notes."""
    top, top_source = top_height(mech)
    if ties.heights_m is not None:
        heights = [(h, f"retrofit spec mechanisms.{mech.id}.heights_m") for h in ties.heights_m]
        return heights, top, []
    if top is None:
        raise InputError(
            f"mechanism {mech.id}: {top_source}; give the tie heights",
            f"mechanisms.{mech.id}.heights_m",
        )
    heights, notes = default_heights(mech, top, f"the top of the moving part ({top_source})")
    return heights, top, notes


def _choice(options: list[TieOption]) -> tuple[Optional[int], list[str]]:
    """Return the designed option of least force (None: none) and the decision it makes."""
    done = [i for i, o in enumerate(options) if o.status == "designed"]
    chosen = min(done, key=lambda i: (options[i].T_star_N or 0.0, i)) if done else None
    if chosen is None:
        return None, ["no tie option makes every check pass (see each option's decisions)"]
    o = options[chosen]
    assert o.bar is not None and o.T_star_N is not None
    return chosen, [
        f"{o.bars} Ø{o.bar.diameter_mm:g} {o.bar.grade} tie(s) at {o.height_m:g} m, "
        f"{o.T_star_N:.4g} N in all ({o.governing} governs): the least force of the "
        "options that make every check pass"
    ]


def _mechanism(
    cf: ConstantsFile,
    site: SiteFile,
    spec: RetrofitSpec,
    mech: Mechanism,
    row: dict[str, Any],
    motions: Sequence[Any] = (),
) -> MechanismRetrofit:
    before = _row_figures(row)
    recs, records_before, record_notes = _records(mech, row, site, motions)
    head = {
        "id": mech.id,
        "name": mech.name,
        "typology": mech.typology,
        "before": before,
        "records_before": records_before,
    }
    standing = _standing(head, mech, row, _records_fail(records_before), record_notes)
    if standing is not None:
        return standing
    ties = spec.mechanisms.get(mech.id) or MechanismTies()
    heights, top, height_notes = _heights(mech, ties)
    checker = _Checker(cf, site, mech, motions)
    options = [
        _option(checker, spec, ties, row, h, src, top, recs, records_before) for h, src in heights
    ]
    chosen, decisions = _choice(options)
    return MechanismRetrofit(
        **head,
        status="designed" if chosen is not None else "not_achievable",
        options=options,
        chosen=chosen,
        decisions=decisions + height_notes + record_notes,
    )


def retrofit_doc(
    cf: ConstantsFile, site: SiteFile, spec: RetrofitSpec, motions: Sequence[Any] = ()
) -> RetrofitDoc:
    """Find the least tie force per failing mechanism, the bar and the checks after it.

    Parameters
    ----------
    cf : ConstantsFile
        Mechanisms with ``virtual_work`` and their geometry (``rockmech constants``).
    site : SiteFile
        Hazard (SLV, and SLC where given), FC, q, the check's choices.
    spec : RetrofitSpec
        Steel, bars on offer, anchorage resistance, candidate tie heights per mechanism.
    motions : sequence of GroundMotion
        Records (``spec.records`` as the front ends read them): each tied mechanism must
        survive every one at its design scale (``workflows.retrofit_records``), and the
        nonlinear checks take their demand as ``rockmech assess`` does (C8.7.1.2.1.8,
        ``assess.check_doc_with_records``), before the tie, in the bisections and after.

    Returns
    -------
    RetrofitDoc
        Per mechanism: ``status``, the checks ``before``, per candidate height the least
        forces per criterion [N], ``T_star_N`` [N] and its ``governing`` criterion, ``e_star``,
        the ``bar``, the ``anchorage`` check, the steel mass [kg] and the checks ``after``.

    Raises
    ------
    InputError
        The spec gives connection upgrades (field ``upgrades``) or tie lines (field
        ``tie_lines``): they need the scene (``retrofit_scene.retrofit_search``); it names a
        mechanism the constants do not have; the site contradicts the constants
        (``codecheck.check_site_inputs``); a default tie height with no height of the moving
        part in the constants.
    """
    if spec.upgrades:
        raise InputError(
            "connection upgrades are compared by searching the scene again with each, which "
            "a constants file cannot do: retrofit from the scene with --scene and --search-spec",
            "upgrades",
        )
    if spec.tie_lines is not None:
        raise InputError(
            "tie lines are line objects of a scene, which a constants file does not have: "
            "retrofit from the scene with --scene and --search-spec",
            "tie_lines",
        )
    ids = [m.id for m in cf.mechanisms]
    for key in spec.mechanisms:
        if key not in ids:
            raise InputError(
                f"no mechanism {key!r} in the constants (ids: {', '.join(sorted(ids))})",
                f"mechanisms.{key}",
            )
    for d in spec.steel.diameters_mm:
        bar_strengths(spec.steel.grade, d)
    if site.local_mechanisms.method != "circ2019":
        raise InputError(
            "the retrofit follows the Circolare 2019 checks; set local_mechanisms.method to "
            "circ2019",
            "local_mechanisms.method",
        )
    doc, _ = check_doc_with_records(cf, site, motions)
    rows = doc["mechanisms"]
    out = []
    for mech, row in zip(cf.mechanisms, rows):
        try:
            out.append(_mechanism(cf, site, spec, mech, row, motions))
        except InputError:
            raise
        except RockmechError as exc:
            out.append(
                MechanismRetrofit(
                    id=mech.id,
                    name=mech.name,
                    typology=mech.typology,
                    status="not_applicable",
                    before=_row_figures(row),
                    decisions=[str(exc)],
                )
            )
    f_yk = {d: bar_strengths(spec.steel.grade, d)[0] for d in spec.steel.diameters_mm}
    steel = {
        "grade": spec.steel.grade,
        "diameters_mm": list(spec.steel.diameters_mm),
        "f_yk": {f"{d:g}": v for d, v in f_yk.items()},
        "gamma_M0": GAMMA_M0,
        "density_kg_m3": STEEL_DENSITY,
        "clauses": {
            **_BAR_CLAUSES,
            "density_kg_m3": "EN 1993-1-1 §3.2.6",
        },
    }
    return RetrofitDoc(
        standard=CIRC2019 + "; NTC 2018 §4.2.4.1.2.1 (tie-bars)",
        steel=steel,
        decisions=RETROFIT_DECISIONS
        + ([RECORDS_DEMAND_DECISION, *RECORD_DECISIONS] if motions else []),
        records=[
            {
                "name": m.name,
                "pga_g": float(m.pga_g),
                "dt": float(m.dt),
                "duration": float(m.duration),
            }
            for m in motions
        ],
        mechanisms=out,
        governs_next=governs_next(out),
    )


# --- what governs next ----------------------------------------------------------------

GOVERNS_BASIS = [
    "A mechanism's margin is its least capacity/demand: the code checks' a_g,X/a_g "
    "(linear, nonlinear SLV and SLC where evaluated) and, with records, the least "
    "overturning scale over the design scale of each record; the least margin governs.",
    "After the intervention, a mechanism with a chosen tie takes its checks and records "
    "with the tie; every other is as it stands: each tie acts on the mechanism it is "
    "designed for (the constants carry no tie line shared between mechanisms).",
]


def least_margin(
    fig: Optional[CheckFigures], scales: Sequence[RecordScale] = ()
) -> tuple[Optional[float], Optional[str]]:
    """Return the least margin and its criterion (None: nothing evaluated).

    The margins are the code checks' a_g,X/a_g (linear SLV, nonlinear SLV and SLC) and,
    with records, each record's least overturning scale over its design scale [-].
    """
    found: list[tuple[float, str]] = []
    if fig is not None:
        for value, name in (
            (fig.linear_ratio, "linear SLV"),
            (fig.SLV_ratio, "nonlinear SLV"),
            (fig.SLC_ratio, "nonlinear SLC"),
        ):
            if value is not None:
                found.append((value, name))
    for sc in scales:
        if sc.multiple is not None:
            found.append((sc.multiple, f"record {sc.record}"))
    if not found:
        return None, None
    value, name = min(found, key=lambda p: p[0])
    return value, name


def governs_next(mechanisms: Sequence[MechanismRetrofit]) -> GoverningNext:
    """Name the mechanism that governs before and after the intervention, and its margin.

    Parameters
    ----------
    mechanisms : sequence of MechanismRetrofit
        The retrofit's mechanisms, in file order (ties broken by it).

    Returns
    -------
    GoverningNext
        The governing mechanism and its least margin [-] before and after, whether it
        moved, and every mechanism's row.
    """
    rows = []
    for m in mechanisms:
        b, b_name = least_margin(m.before, m.records_before)
        tied = m.chosen is not None
        if tied:
            assert m.chosen is not None
            o = m.options[m.chosen]
            a, a_name = least_margin(o.after, o.records_after if m.records_before else [])
        else:
            a, a_name = b, b_name
        rows.append(
            GoverningRow(
                id=m.id,
                tied=tied,
                before_margin=b,
                before_criterion=b_name,
                after_margin=a,
                after_criterion=a_name,
            )
        )

    def least(which: str) -> Optional[GoverningRow]:
        got = [r for r in rows if getattr(r, which) is not None]
        return min(got, key=lambda r: getattr(r, which)) if got else None

    first, then = least("before_margin"), least("after_margin")
    return GoverningNext(
        before=None if first is None else first.id,
        before_margin=None if first is None else first.before_margin,
        before_criterion=None if first is None else first.before_criterion,
        after=None if then is None else then.id,
        after_margin=None if then is None else then.after_margin,
        after_criterion=None if then is None else then.after_criterion,
        moved=first is not None and then is not None and first.id != then.id,
        rows=rows,
        basis=GOVERNS_BASIS,
    )
