"""The search from scene to refined, checked candidates (the maths; no documents).

``run_search`` reads the building (``model``), enumerates and refines the catalogue
(``families``), runs the global upper-bound check per façade and direction (``lp``) over the
candidate lines and the refined candidates' own lines, and flags sliding. The ranking by
rocking response and the documents are ``solver_service.workflows.search``.

Python 3.9-clean: imported by Rhino 8.
"""

import math
import time
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

from cad_maths.search.families import Budget, Candidate, enumerate_candidates
from cad_maths.search.lp import LPModel, LPResult, facade_lp_model, solve_check
from cad_maths.search.model import Building, building_from_scene
from shared_schema.errors import InputError
from shared_schema.rules import G

__all__ = [
    "MISSED_GAP",
    "RANK_RTOL",
    "LPCheck",
    "SearchResult",
    "rank_order",
    "run_search",
    "sliding_check",
]

#: The check's multiplier this far below the best catalogue mechanism's (relative) means the
#: catalogue missed a mechanism (issue #31: 1 %).
MISSED_GAP = 0.01
#: The friction variant of the check this far below the rocking one says sliding governs.
SLIDING_GAP = 0.01
#: Scores within this fraction of each other tie in a ranking: the earlier candidate (in the
#: order the search enumerates them, which the scene's placement does not change) ranks
#: first, so that rounding in a turned or far-away scene cannot swap two equal mechanisms.
RANK_RTOL = 1e-9


@dataclass
class LPCheck:
    """The global check of one façade in one direction.

    Attributes
    ----------
    facade, direction : str
        What was checked.
    lam : float
        The programme's least multiplier, rocking only [-].
    best : float
        The least catalogue λ0 of that façade and direction [-].
    gap : float
        ``(best - lam) / best``; > ``MISSED_GAP``: the catalogue missed a mechanism.
    missed : bool
        Whether it did.
    lam_friction : float or None
        The associative-friction variant's multiplier (hinge joints may slide) [-].
    sliding : bool
        Whether sliding governs the façade (``lam_friction`` below ``lam`` by more than
        ``SLIDING_GAP``).
    result : LPResult
        The solution (moving blocks, bodies, work counters).
    model : LPModel
        The blocks and lines (for the figure and the output).
    """

    facade: str
    direction: str
    lam: float
    best: float
    gap: float
    missed: bool
    lam_friction: Optional[float]
    sliding: bool
    result: LPResult
    model: LPModel


@dataclass
class SearchResult:
    """What ``run_search`` found.

    Attributes
    ----------
    building : Building
        The walls, junctions, levels and ties read.
    candidates : list of Candidate
        Refined candidates, lowest λ0 first (ties broken by the enumeration order).
    notes : list of str
        Readings, idealisations and families left out, with the reason.
    checks : list of LPCheck
        One per façade and direction that has candidates (when the spec asks for it).
    timings : dict of str to float
        Wall-clock seconds per stage.
    counts : dict of str to int
        Work counters: walls, candidates, λ0 evaluations, LP blocks and rows.
    """

    building: Building
    candidates: List[Candidate]
    notes: List[str]
    checks: List[LPCheck] = field(default_factory=list)
    timings: Dict[str, float] = field(default_factory=dict)
    counts: Dict[str, int] = field(default_factory=dict)


def sliding_check(cand: Candidate, friction: float) -> Optional[Dict[str, Any]]:
    """Flag a candidate whose hinge joint would slide before it rocks.

    At the static multiplier the joint carries the horizontal load ``λ0 Σ m* g`` and the
    weight ``Σ m g`` (plus the two-block wall's overburden); friction holds it while
    ``μ >= λ0 Σ m* / Σ m``. Rocking only with infinite friction overestimates λ where that
    fails.

    Returns
    -------
    dict or None
        ``{"required": ..., "friction": μ, "note": ...}`` where sliding governs, else None.
    """
    weight = cand.weight()
    sway = weight
    for c in cand.contacts:
        m = G * c.mass
        sway += m
        if c.bearing:
            weight += m
    if cand.overburden:
        weight += float(cand.overburden["N"])
    if not weight > 0.0:
        return None
    required = cand.lam0 * sway / weight
    if required <= friction:
        return None
    return {
        "required": required,
        "friction": friction,
        "note": (
            f"the hinge joint needs a friction coefficient of {required:.3g} to carry the "
            f"horizontal load at λ0 = {cand.lam0:.4g} without sliding, more than μ = "
            f"{friction:g}: sliding governs, and the rocking-only λ0 overestimates the "
            "capacity"
        ),
    }


def rank_order(scores: List[float], rtol: float = RANK_RTOL) -> List[int]:
    """Return the indices of ``scores`` from least to greatest, near-ties in index order.

    Scores are sorted; every run of neighbours within ``rtol`` (relative) of the one
    before is then put in index order.

    Parameters
    ----------
    scores : list of float
        One score per item (``inf`` last).
    rtol : float
        Relative difference below which two neighbouring scores tie.

    Returns
    -------
    list of int

    Examples
    --------
    >>> rank_order([0.3, 0.1 + 1e-12, 0.1, 0.2])
    [1, 2, 3, 0]
    """
    order = sorted(range(len(scores)), key=lambda k: (scores[k], k))
    out: List[int] = []
    run: List[int] = []
    for k in order:
        if run and not scores[k] - scores[run[-1]] <= rtol * abs(scores[run[-1]]):
            out.extend(sorted(run))
            run = []
        run.append(k)
    out.extend(sorted(run))
    return out


def _lines(
    cands: List[Candidate], facade: str, direction: str
) -> Tuple[List[float], Dict[str, List[float]]]:
    heights: List[float] = []
    angles: Dict[str, List[float]] = {}
    for c in cands:
        if c.facade != facade or c.direction != direction:
            continue
        heights.append(c.hinge_z)
        if "h1_m" in c.params:
            heights.append(c.pieces[0].wall.z_lo + c.params["h1_m"])
        for piece in c.pieces[1:]:
            for k, v in c.params.items():
                if k.startswith("beta_") and k != "beta_facade_rad":
                    angles.setdefault(piece.wall.id, []).append(v)
    return heights, angles


def run_search(
    scene: Any,
    spec: Any,
    *,
    lp: Optional[bool] = None,
    max_evaluations: Optional[int] = None,
    max_lp_blocks: Optional[int] = None,
) -> SearchResult:
    """Search a scene's mechanisms as the spec asks.

    Parameters
    ----------
    scene : BaseScene
        The input scene (``cad_maths.scenes.read_scene``).
    spec : SearchSpec
        The search spec.
    lp : bool, optional
        Run the global check (default: the spec's ``lp``).
    max_evaluations : int, optional
        Work limit: most λ0 evaluations of the refinements (none by default).
    max_lp_blocks : int, optional
        Work limit: most macro-blocks of one check (none by default).

    Raises
    ------
    InputError
        On field ``work_limit``: the search would exceed a limit (before doing that work).

    Returns
    -------
    SearchResult
    """
    t0 = time.perf_counter()
    bld = building_from_scene(scene, spec)
    t1 = time.perf_counter()
    cands, notes = enumerate_candidates(bld, Budget(max_evaluations))
    for c in cands:
        flag = sliding_check(c, spec.friction)
        if flag is not None:
            c.notes.append(flag["note"])
    order = rank_order([c.lam0 for c in cands])
    cands = [cands[k] for k in order]
    t2 = time.perf_counter()
    checks: List[LPCheck] = []
    do_lp = spec.lp if lp is None else lp
    if do_lp:
        # the check loads the façade along its normal: corner mechanisms, loaded along the
        # corner's diagonal, are not compared with it
        along = [c for c in cands if c.family != "corner"]
        if len(along) < len(cands):
            notes.append(
                "the global check loads each façade along its normal; the corner mechanisms "
                "(loaded along the corner's diagonal) are not compared with it"
            )
        pairs = []
        for c in along:
            if (c.facade, c.direction) not in pairs:
                pairs.append((c.facade, c.direction))
        for facade, direction in pairs:
            heights, angles = _lines(along, facade, direction)
            first = next(c for c in along if c.facade == facade and c.direction == direction)
            model = facade_lp_model(bld, facade, direction, heights, angles, loads=first.contacts)
            if max_lp_blocks is not None and len(model.blocks) > max_lp_blocks:
                raise InputError(
                    f"the global check of {facade} {direction} has {len(model.blocks)} "
                    f"macro-blocks, more than the work limit's {max_lp_blocks}: set lp false "
                    "or no candidates.spacing, or raise the work limit",
                    "work_limit",
                )
            res, fric = solve_check(model, spec.friction)
            best = min(c.lam0 for c in along if c.facade == facade and c.direction == direction)
            gap = (best - res.lam) / best if math.isfinite(res.lam) and best > 0 else 0.0
            lam_f = fric.lam if math.isfinite(fric.lam) else None
            sliding = lam_f is not None and lam_f < res.lam * (1.0 - SLIDING_GAP)
            checks.append(
                LPCheck(
                    facade,
                    direction,
                    res.lam,
                    best,
                    gap,
                    gap > MISSED_GAP,
                    lam_f,
                    sliding,
                    res,
                    model,
                )
            )
    t3 = time.perf_counter()
    counts = {
        "walls": len(bld.walls),
        "candidates": len(cands),
        "evaluations": sum(c.n_evaluations for c in cands),
        "lp_blocks": sum(ch.result.n_blocks for ch in checks),
        "lp_rows": sum(ch.result.n_rows for ch in checks),
    }
    timings = {"read_s": t1 - t0, "search_s": t2 - t1, "lp_s": t3 - t2}
    return SearchResult(bld, cands, list(bld.notes) + notes, checks, timings, counts)
