"""The retrofit from a scene: design the ties, put them in the scene, search again.

``retrofit_search`` takes a scene and a search spec (``rockmech search``'s inputs), a site
and a retrofit spec:

1. the search runs (``workflows.search.search_run``) and builds its mechanisms' constants;
2. the retrofit designs the ties of every failing mechanism on those constants
   (``workflows.retrofit.retrofit_doc``: the least force, the bar, the checks after);
3. each designed tie (a chosen option whose bar and anchorage carry it) goes into the scene
   as a tie-bar line, and into the search spec's ``tie_bars`` with its force;
4. the search runs again on the tied scene, its mechanisms are checked
   (``assess.check_doc_with_records``) and, with records, each is run on them
   (``retrofit_records.MechanismRecords``: the least overturning scale over the design
   one); the document's ``search_after`` names the mechanism that governs after the
   intervention, its margin and λ0, and whether the collapse moved to another wall or family;
5. with connection upgrades in the retrofit spec (``retrofit_upgrades``), the search runs
   again once per upgrade on its own and once with every upgrade and the designed ties,
   each compared the same way (``search_after.upgrades``, ``search_after.together``).

How a designed tie is idealised in the scene (``TIE_IDEALISATION``): one straight tie-bar
line, horizontal, along the wall's inward normal from its outer face to its inner face, at
the designed height above the mechanism's hinge and at the middle of its hinge axis,
carrying the whole designed force ``T*`` of the option (its bars together) as a constant
force: the search's and the builder's tie model (theory §2.2), which pulls the wall inward
and counts only on a motion that stretches the bar.
"""

from __future__ import annotations

import uuid
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Sequence

import numpy as np

from cad_maths.scene_base import BaseScene, SceneObject
from cad_maths.search.families import Candidate
from shared_schema.constants import ConstantsFile, Mechanism
from shared_schema.errors import InputError, RockmechError
from shared_schema.retrofit import (
    HEIGHTS_MAX,
    CheckFigures,
    ConnectionUpgrade,
    MechanismTies,
    PlacedTie,
    RecordScale,
    RetrofitDoc,
    RetrofitSpec,
    SearchAfter,
    SearchAfterRow,
    UpgradeAfter,
)
from shared_schema.search import SearchSpec
from shared_schema.site import SiteFile

from .assess import check_doc_with_records
from .retrofit import default_heights, least_margin, retrofit_doc
from .retrofit_lines import LineCandidates, tie_line_candidates
from .retrofit_records import MechanismRecords
from .retrofit_upgrades import apply_upgrades, check_upgrades, check_upgrades_meet
from .search import SearchRun, search_run

__all__ = [
    "SEARCH_AFTER_BASIS",
    "TIE_IDEALISATION",
    "TIE_LAYER",
    "RetrofitSearch",
    "SceneCandidates",
    "TiedScene",
    "place_ties",
    "retrofit_search",
    "scene_heights",
    "search_after",
]

#: The layer of the designed tie-bars in the tied scene.
TIE_LAYER = "rockmech retrofit::ties"

#: Designed ties whose points are this close (relative to the building's size) are one line.
SAME_POINT_RTOL = 1e-9

#: How a designed tie enters the rerun, stated in the document.
TIE_IDEALISATION = [
    "Each designed tie (a chosen option whose bar and anchorage carry T*) is one tie-bar "
    "line of the scene: horizontal, along the wall's inward normal from its outer face to "
    "its inner face, at the designed height above the mechanism's hinge, at the middle of "
    "the hinge axis.",
    "Ties of several mechanisms at one point are one line carrying the largest of their "
    "forces (each of those mechanisms then has at least its own T* there).",
    "It carries the option's whole T* (its bars together) as a constant force, the "
    "search's and the builder's tie model (theory §2.2): it pulls the wall inward at that "
    "point and counts only on a motion that stretches it; a mechanism of the rerun whose "
    "moving part does not hold that point does not feel it.",
    "A designed tie is verified up to collapse (C8.7.1.2.1.6): the rerun's checks count it "
    "in d0; ties already in the scene keep the site's treatment.",
    "Only a mechanism that turns outward is tied: a tie is slack on an inward motion.",
]

SEARCH_AFTER_BASIS = [
    "A mechanism's margin is its least capacity/demand, before and after alike: the "
    "Circolare 2019 checks' a_g,X/a_g (linear, nonlinear SLV and SLC where evaluated) and, "
    "where the retrofit has records, each record's least overturning scale over its design "
    "scale, run by the exact solver on every mechanism of the rerun as on the first "
    "search's (the records' demand enters the nonlinear checks, C8.7.1.2.1.8).",
    "The governing mechanism has the least margin; the collapse moved when it is another "
    "mechanism than the first search's governing one (another name: family, façade, "
    "direction, hinge height or crack angles); its façade and family say where it went.",
    "The rerun numbers its mechanisms anew (by λ0): a site's per-mechanism options keyed by "
    "the first search's ids apply to the rerun's mechanisms of the same id.",
    "A connection upgrade (a junction made good or tied, a level tied) is compared the same "
    "way: the search runs again on the scene as given with the search spec so changed, once "
    "per upgrade, and once with every upgrade and the designed ties together.",
]


class TiedScene(BaseScene):
    """A scene with tie-bar lines added (points in metres), the rest read from the base.

    Parameters
    ----------
    base : BaseScene
        The scene the search read.
    lines : list of (SceneObject, (start, end))
        The tie-bars to add: the object and its end points [m].
    """

    def __init__(self, base: BaseScene, lines: Sequence[tuple[SceneObject, Any]]) -> None:
        super().__init__(
            list(base.objects) + [o for o, _ in lines],
            unit_scale=base.unit_scale,
            units=base.units,
            path=base.path,
            tolerance=base.tolerance,
        )
        self._ratio = base._ratio
        self._layer_paths = list(base._layer_paths)
        self.base = base
        self.lines = {o.id: (np.asarray(a, float), np.asarray(b, float)) for o, (a, b) in lines}

    def mesh(self, obj: SceneObject, require_closed: bool = True) -> Any:
        """Return the base scene's mesh of ``obj`` [m]."""
        return self.base.mesh(obj, require_closed)

    def extent(self, obj: SceneObject) -> tuple[np.ndarray, np.ndarray]:
        """Return the object's bounding box [m]."""
        if obj.id in self.lines:
            a, b = self.lines[obj.id]
            return np.minimum(a, b), np.maximum(a, b)
        return self.base.extent(obj)

    def line(self, obj: SceneObject) -> tuple[np.ndarray, np.ndarray]:
        """Return a line's end points [m] (an added tie-bar's, or the base scene's)."""
        if obj.id in self.lines:
            a, b = self.lines[obj.id]
            return a.copy(), b.copy()
        return self.base.line(obj)

    def plane(self, obj: SceneObject) -> tuple[np.ndarray, np.ndarray]:
        """Return the base scene's plane of ``obj``."""
        return self.base.plane(obj)


def _not_placed(mech_id: str, note: str) -> PlacedTie:
    return PlacedTie(mechanism=mech_id, status="not_placed", note=note)


def _group_lines(
    groups: list[dict[str, Any]],
) -> tuple[list[PlacedTie], list[tuple[SceneObject, Any]], list[dict[str, Any]]]:
    """Return one tie-bar line per group of ties at one point, with its placed ties."""
    placed: list[PlacedTie] = []
    lines: list[tuple[SceneObject, Any]] = []
    bars: list[dict[str, Any]] = []
    for group in groups:
        members = group["members"]
        name = "retrofit tie " + "+".join(mid for mid, _, _ in members)
        force = max(t for _, t, _ in members)
        obj = SceneObject(str(uuid.uuid5(uuid.NAMESPACE_URL, name)), name, TIE_LAYER, "line")
        lines.append((obj, (group["at"], group["end"])))
        bars.append({"object": {"id": obj.id}, "force": force})
        for mid, t, h in members:
            note = None
            if len(members) > 1:
                note = (
                    f"one line with {', '.join(x for x, _, _ in members if x != mid)} (the "
                    f"same point): it carries the largest of their forces, {force:.6g} N, "
                    f"this mechanism's {t:.6g} N or more"
                )
            placed.append(
                PlacedTie(
                    mechanism=mid,
                    status="placed",
                    object=name,
                    wall=group["wall"],
                    force_N=force,
                    height_m=h,
                    at_m=[float(v) for v in group["at"]],
                    end_m=[float(v) for v in group["end"]],
                    note=note,
                )
            )
    return placed, lines, bars


def place_ties(
    run: SearchRun, doc: RetrofitDoc
) -> tuple[list[PlacedTie], list[tuple[SceneObject, Any]], list[dict[str, Any]]]:
    """Return the designed ties as tie-bar lines of the search's scene.

    Parameters
    ----------
    run : SearchRun
        The first search (its building, candidates and constants).
    doc : RetrofitDoc
        The retrofit of its constants.

    Returns
    -------
    placed : list of PlacedTie
        One per designed mechanism: where the line is, or why it is not placed.
    lines : list of (SceneObject, (start, end))
        The lines to add to the scene (``TiedScene``) [m].
    tie_bars : list of dict
        The search spec's ``tie_bars`` entries of the lines (``object`` by id, ``force``).
    """
    bld = run.result.building
    by_id = run.candidates_by_id()
    mechs = {} if run.constants is None else {m.id: m for m in run.constants.mechanisms}
    placed: list[PlacedTie] = []
    groups: list[dict[str, Any]] = []
    for m in doc.mechanisms:
        if m.chosen is None:
            continue
        o = m.options[m.chosen]
        cand, mech = by_id.get(m.id), mechs.get(m.id)
        if cand is None or mech is None or o.T_star_N is None:
            placed.append(_not_placed(m.id, "the search has no candidate of this id"))
            continue
        if cand.direction != "outward":
            placed.append(
                _not_placed(m.id, f"the mechanism turns {cand.direction}: a tie is slack there")
            )
            continue
        wall = bld.walls[cand.facade]
        f = wall.frame
        geo: dict[str, Any] = mech.geometry if isinstance(mech.geometry, dict) else {}
        hinge_z = float(geo["positive"]["axis_point_m"][2])
        mid = 0.5 * (np.asarray(cand.axis[0], float) + np.asarray(cand.axis[1], float))
        s = float(f.to_frame(mid)[0])
        z = hinge_z + o.height_m
        if not (wall.z_lo - 1e-9 <= z <= wall.z_hi + 1e-9):
            placed.append(
                _not_placed(
                    m.id,
                    f"the tie at {o.height_m:g} m above the hinge (z = {z:.4g} m) is off "
                    f"the wall {wall.id} (z {wall.z_lo:.4g} to {wall.z_hi:.4g} m)",
                )
            )
            continue
        start = f.to_world(s, 0.0, z)
        end = f.to_world(s, f.thickness, z)
        tol = SAME_POINT_RTOL * max(bld.size, 1.0)
        for group in groups:
            if group["wall"] == wall.id and float(np.linalg.norm(group["at"] - start)) <= tol:
                group["members"].append((m.id, float(o.T_star_N), o.height_m))
                break
        else:
            groups.append(
                {
                    "wall": wall.id,
                    "at": start,
                    "end": end,
                    "members": [(m.id, o.T_star_N, o.height_m)],
                }
            )
    made, lines, bars = _group_lines(groups)
    return placed + made, lines, bars


#: The first search's α0 and a run folder's agree to this (relative) when they are one run.
SAME_RUN_RTOL = 1e-9


def _alpha0(mech: Mechanism) -> Optional[float]:
    vw = mech.positive.virtual_work
    return None if vw is None else float(vw.alpha0)


def _same_run(got: ConstantsFile, want: ConstantsFile) -> None:
    """Refuse a search whose mechanisms are not a run folder's ``constants.json``."""
    a = [(m.id, m.name) for m in got.mechanisms]
    b = [(m.id, m.name) for m in want.mechanisms]
    same = a == b
    for m, n in zip(got.mechanisms, want.mechanisms):
        x, y = _alpha0(m), _alpha0(n)
        if same and x is not None and y is not None:
            same = abs(x - y) <= SAME_RUN_RTOL * max(abs(y), 1e-12)
    if not same:
        raise InputError(
            "the search of the run folder's search.3dm with this search spec does not build "
            "the run's constants.json (other mechanisms or multipliers): give the search spec "
            "that made the run",
            "search_spec",
        )


@dataclass
class SceneCandidates:
    """The candidate tie heights of a retrofit from a scene, and the rule that gave them.

    Attributes
    ----------
    spec : RetrofitSpec
        The retrofit spec with each mechanism's candidate heights [m] filled in.
    sources : dict of str to list of str
        Per mechanism id whose heights were filled in: each height's source, in order.
    decisions : dict of str to list of str
        Per mechanism id: the rule that gave its candidates, and the notes on lines and
        levels that are not its candidates.
    notes : list of str
        The document's: tie lines that are nobody's candidate.
    """

    spec: RetrofitSpec
    sources: dict[str, list[str]] = field(default_factory=dict)
    decisions: dict[str, list[str]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


#: The rules that give a mechanism's candidate ties from a scene, as the document states them.
RULE_LINES = "candidate ties: the retrofit spec's tie lines that cross its moving part"
RULE_HEIGHTS = "candidate ties: the retrofit spec's heights_m"
RULE_SCENE = (
    "candidate ties (default from the scene): the top of its wall above the hinge and each "
    "level its moving part carries"
)
RULE_CONSTANTS = (
    "candidate ties (default of the constants): the top of the moving part and each level it "
    "carries"
)


def _scene_default(
    run: SearchRun, mech: Mechanism, cand: Optional[Candidate]
) -> Optional[tuple[list[tuple[float, str]], list[str]]]:
    """Return the scene's default heights [m] of an outward mechanism, with notes, or None.

    ``cand`` is the search's candidate of ``mech`` (None: the search has none of its id).
    """
    geo: dict[str, Any] = mech.geometry if isinstance(mech.geometry, dict) else {}
    pos = geo.get("positive")
    if cand is None or cand.direction != "outward":
        return None
    if not isinstance(pos, dict) or "axis_point_m" not in pos:
        return None
    wall = run.result.building.walls[cand.facade]
    h = wall.z_hi - float(pos["axis_point_m"][2])
    if not h > 0.0:
        return None
    words = f"the top of wall {wall.id} (z = {wall.z_hi:.4g} m) above the hinge"
    return default_heights(mech, h, words, "default from the scene")


def scene_heights(
    run: SearchRun, rspec: RetrofitSpec, lines: Optional[LineCandidates] = None
) -> SceneCandidates:
    """Give each built mechanism its candidate tie heights from the scene.

    A mechanism crossed by the spec's tie lines (``lines``, ``retrofit_lines``) takes their
    heights after its own ``heights_m``, and no default. Otherwise one with ``heights_m``
    keeps them; one without takes the default: the top of its wall above the mechanism's
    hinge (``z_hi − z_hinge``, on the façade the tie goes through), and each level the moving
    part carries (``retrofit.default_heights``). Mechanisms that turn
    inward are left to the retrofit's default (a tie is slack on that motion).

    Returns
    -------
    SceneCandidates
        The spec with those heights [m], their sources and each mechanism's rule.

    Raises
    ------
    InputError
        A mechanism given more candidates than a spec may list (field ``tie_lines``).
    """
    out = SceneCandidates(rspec, notes=list(lines.decisions) if lines else [])
    if run.constants is None:
        return out
    ties = dict(rspec.mechanisms)
    by_id = run.candidates_by_id()
    for mech in run.constants.mechanisms:
        given = ties.get(mech.id)
        own = list(given.heights_m or []) if given is not None else []
        from_lines = lines.heights.get(mech.id, []) if lines else []
        notes = list(lines.notes.get(mech.id, [])) if lines else []
        got: list[tuple[float, str]] = []
        if from_lines:
            src = f"retrofit spec mechanisms.{mech.id}.heights_m"
            got = [(h, src) for h in own] + from_lines
            rule = RULE_LINES + (" and its heights_m" if own else "") + " (no default heights)"
        elif own:
            rule = RULE_HEIGHTS
        else:
            default = _scene_default(run, mech, by_id.get(mech.id))
            rule = RULE_CONSTANTS if default is None else RULE_SCENE
            if default is not None:
                got, level_notes = default
                notes += level_notes
        if len(got) > HEIGHTS_MAX:
            raise InputError(
                f"mechanism {mech.id} gets {len(got)} candidate ties; at most {HEIGHTS_MAX}",
                "tie_lines",
            )
        if got:
            base = given if given is not None else MechanismTies()
            ties[mech.id] = base.model_copy(update={"heights_m": [h for h, _ in got]})
            out.sources[mech.id] = [s for _, s in got]
        out.decisions[mech.id] = [rule, *notes]
    out.spec = rspec.model_copy(update={"mechanisms": ties})
    return out


def _with_sources(doc: RetrofitDoc, cands: SceneCandidates) -> RetrofitDoc:
    """Name the scene (or its lines) as the source of the heights, and each rule."""
    out = []
    for m in doc.mechanisms:
        srcs = cands.sources.get(m.id)
        if srcs is not None and len(srcs) == len(m.options):
            opts = [o.model_copy(update={"height_source": s}) for o, s in zip(m.options, srcs)]
            m = m.model_copy(update={"options": opts})
        said = cands.decisions.get(m.id, [])
        if not m.options:
            said = said[1:]  # no candidate was tried: the rule says nothing
        if said:
            m = m.model_copy(update={"decisions": [*m.decisions, *said]})
        out.append(m)
    return doc.model_copy(update={"mechanisms": out, "decisions": [*doc.decisions, *cands.notes]})


def _row_margin(
    row: dict[str, Any], scales: Sequence[RecordScale] = ()
) -> tuple[Optional[float], Optional[str]]:
    """Return the least margin of a ``check_doc`` row and its records, and its criterion."""
    lin, non = row.get("linear") or {}, row.get("nonlinear") or {}
    fig = CheckFigures()
    if lin.get("status") == "ok":
        fig.linear_ratio = float(lin["capacity_ratio"])
    if non.get("status") == "ok":
        fig.SLV_ratio = float(non["capacity_ratio"])
        slc = non.get("SLC")
        if isinstance(slc, dict) and slc.get("capacity_ratio") is not None:
            fig.SLC_ratio = float(slc["capacity_ratio"])
    return least_margin(fig, scales)


def _bake_designed(cf: ConstantsFile, ids: set[str]) -> tuple[ConstantsFile, dict[str, list[str]]]:
    """Unlist the designed tie-bars (verified: counted in d0); name those each carries."""
    out: list[Mechanism] = []
    carried: dict[str, list[str]] = {}
    for mech in cf.mechanisms:
        geo: dict[str, Any] = dict(mech.geometry) if isinstance(mech.geometry, dict) else {}
        loaded = geo.get("loaded")
        elements = loaded.get("elements") if isinstance(loaded, dict) else None
        if not isinstance(loaded, dict) or not isinstance(elements, list):
            out.append(mech)
            continue
        mine = [
            e
            for e in elements
            if isinstance(e, dict)
            and e.get("kind") == "tie_bar"
            and any(i in ids for i in e.get("objects") or [])
        ]
        carried[mech.id] = [i for e in mine for i in e["objects"] if i in ids]
        loaded = {**loaded, "elements": [e for e in elements if e not in mine]}
        geo["loaded"] = loaded
        out.append(mech.model_copy(update={"geometry": geo}))
    return cf.model_copy(update={"mechanisms": out}), carried


def _rerun_records(
    mech: Mechanism, row: dict[str, Any], site: SiteFile, motions: Sequence[Any]
) -> tuple[list[RecordScale], Optional[str]]:
    """Return the records' scales on one mechanism of a rerun, or why they do not run."""
    if not motions:
        return [], None
    try:
        return MechanismRecords(mech, row, motions, site).scales(mech), None
    except RockmechError as exc:
        return [], f"{mech.id}: the records are not run on this mechanism: {exc}"


def _rerun_rows(
    after: SearchRun, site: SiteFile, motions: Sequence[Any], names: dict[str, str]
) -> tuple[list[SearchAfterRow], list[str]]:
    """Return the rows of a rerun (checks, records, margins) and its notes."""
    if after.constants is None:
        return [], ["the rerun built no mechanism"]
    notes: list[str] = []
    cf, carried = _bake_designed(after.constants, set(names))
    # The records' demand enters the nonlinear checks as in the first run (C8.7.1.2.1.8).
    checked = check_doc_with_records(cf, site, motions)[0]["mechanisms"]
    rows: list[SearchAfterRow] = []
    for mech, row in zip(cf.mechanisms, checked):
        d = after.doc.find(mech.id)
        scales, note = _rerun_records(mech, row, site, motions)
        if note is not None:
            notes.append(note)
        margin, crit = _row_margin(row, scales)
        rows.append(
            SearchAfterRow(
                id=mech.id,
                name=mech.name,
                family=d.family,
                facade=d.facade,
                direction=d.direction,
                lam0=d.lam0,
                margin=margin,
                criterion=crit,
                ties=[names[i] for i in carried.get(mech.id, [])],
                records=scales,
            )
        )
    return rows, notes


def _after_fields(rows: Sequence[SearchAfterRow], before_name: Optional[str]) -> dict[str, Any]:
    """Return the governing mechanism of a rerun's rows (least margin), as document fields."""
    got = [r for r in rows if r.margin is not None]
    a = min(got, key=lambda r: r.margin or 0.0) if got else None
    least = min(rows, key=lambda r: r.lam0) if rows else None
    return {
        "after": None if a is None else a.id,
        "after_name": None if a is None else a.name,
        "after_facade": None if a is None else a.facade,
        "after_family": None if a is None else a.family,
        "after_margin": None if a is None else a.margin,
        "after_criterion": None if a is None else a.criterion,
        "after_lam0": None if a is None else a.lam0,
        "least_lam0": None if least is None else least.id,
        "least_lam0_value": None if least is None else least.lam0,
        "moved": before_name is not None and a is not None and a.name != before_name,
        "rows": list(rows),
    }


def _first_governing(doc: RetrofitDoc) -> Optional[tuple[float, str, Optional[str]]]:
    """Return the first search's least margin, its mechanism and criterion (None: none)."""
    first: list[tuple[float, str, Optional[str]]] = []
    for m in doc.mechanisms:
        margin, crit = least_margin(m.before, m.records_before)
        if margin is not None:
            first.append((margin, m.id, crit))
    return min(first, key=lambda p: p[0]) if first else None


def _before_fields(before: SearchRun, doc: RetrofitDoc) -> dict[str, Any]:
    """Return the first search's governing mechanism (least margin), as document fields."""
    b = _first_governing(doc)
    if b is None:
        return {"before_name": None}
    cand = before.doc.find(b[1])
    return {
        "before": b[1],
        "before_name": doc.find(b[1]).name,
        "before_facade": cand.facade,
        "before_family": cand.family,
        "before_margin": b[0],
        "before_criterion": b[2],
    }


def search_after(
    before: SearchRun,
    after: SearchRun,
    doc: RetrofitDoc,
    site: SiteFile,
    placed: list[PlacedTie],
    names: dict[str, str],
    motions: Sequence[Any] = (),
) -> SearchAfter:
    """Compare the first search's governing mechanism with the rerun's (``SearchAfter``).

    Parameters
    ----------
    before, after : SearchRun
        The first search and the rerun on the tied scene.
    doc : RetrofitDoc
        The retrofit of the first search's constants (its ``before`` checks and records).
    site : SiteFile
        The site of the checks.
    placed : list of PlacedTie
        The ties put into the scene.
    names : dict of str to str
        Object id of each designed tie-bar line -> its name.
    motions : sequence of GroundMotion
        The retrofit's records: run on every mechanism of the rerun at its design scale by
        the exact solver (``retrofit_records.MechanismRecords``); each row's margin counts
        them as ``least_margin`` does.
    """
    rows, notes = _rerun_rows(after, site, motions, names)
    first = _before_fields(before, doc)
    return SearchAfter(
        ties=placed,
        **first,
        **_after_fields(rows, first["before_name"]),
        basis=TIE_IDEALISATION + SEARCH_AFTER_BASIS,
        notes=notes,
    )


@dataclass
class RetrofitSearch:
    """A retrofit from a scene.

    Attributes
    ----------
    doc : RetrofitDoc
        The retrofit document, with ``search_after``.
    before, after : SearchRun
        The first search and the rerun on the tied scene (None: no tie was placed).
    upgrades : list of SearchRun
        The reruns with each connection upgrade, in the spec's order.
    together : SearchRun, optional
        The rerun with every upgrade and the designed ties (None: no upgrade given).
    """

    doc: RetrofitDoc
    before: SearchRun
    after: Optional[SearchRun]
    upgrades: list[SearchRun] = field(default_factory=list)
    together: Optional[SearchRun] = None


@dataclass
class _Reruns:
    """What every search of a retrofit from a scene shares."""

    site: SiteFile
    motions: Sequence[Any]
    common: dict[str, Any]
    scene_name: str
    spec_name: str

    def search(self, scene: BaseScene, spec: SearchSpec, what: str = "") -> SearchRun:
        """Run the search (``search_run``) on ``scene`` with ``spec``; ``what`` names it."""
        name = f"{self.scene_name} {what}".strip()
        return search_run(scene, spec, scene_name=name, spec_name=self.spec_name, **self.common)


def _tied_spec(spec: SearchSpec, bars: list[dict[str, Any]]) -> SearchSpec:
    """Return the search spec with the designed tie-bars added to its own."""
    return SearchSpec.model_validate(
        {
            **spec.model_dump(exclude_none=True),
            "tie_bars": [*[t.model_dump() for t in spec.tie_bars], *bars],
        }
    )


def _upgrade_after(
    reruns: _Reruns,
    run: SearchRun,
    words: Sequence[str],
    indices: list[int],
    names: dict[str, str],
    before_name: Optional[str],
) -> UpgradeAfter:
    """Return the governing mechanism of a rerun with upgrades (``UpgradeAfter``)."""
    rows, notes = _rerun_rows(run, reruns.site, reruns.motions, names)
    return UpgradeAfter(
        upgrades=[words[i] for i in indices],
        indices=indices,
        with_ties=bool(names),
        **_after_fields(rows, before_name),
        notes=notes,
    )


def _upgrades_after(
    reruns: _Reruns,
    block: SearchAfter,
    scene: BaseScene,
    spec: SearchSpec,
    upgrades: Sequence[ConnectionUpgrade],
    tied: tuple[list[tuple[SceneObject, Any]], list[dict[str, Any]]],
) -> tuple[SearchAfter, list[SearchRun], Optional[SearchRun]]:
    """Search again with each upgrade, then with every upgrade and the designed ties."""
    if not upgrades:
        return block, [], None
    words = check_upgrades(spec, upgrades)
    lines, bars = tied
    runs = []
    rows = []
    for k, up in enumerate(upgrades):
        run = reruns.search(scene, apply_upgrades(spec, [up]), f"with {words[k]}")
        runs.append(run)
        rows.append(_upgrade_after(reruns, run, words, [k], {}, block.before_name))
    both = apply_upgrades(_tied_spec(spec, bars), upgrades)
    where = TiedScene(scene, lines) if lines else scene
    together = reruns.search(where, both, "with the upgrades and the designed ties")
    names = {o.id: o.name for o, _ in lines}
    every = list(range(len(upgrades)))
    last = _upgrade_after(reruns, together, words, every, names, block.before_name)
    if not lines:
        last.notes.insert(0, "no designed tie was placed in the scene: the upgrades alone")
    return block.model_copy(update={"upgrades": rows, "together": last}), runs, together


def retrofit_search(
    scene: BaseScene,
    spec: SearchSpec,
    site: SiteFile,
    rspec: RetrofitSpec,
    motions: Sequence[Any] = (),
    *,
    scene_name: str = "scene",
    spec_name: str = "search spec",
    max_evaluations: Optional[int] = None,
    max_lp_blocks: Optional[int] = None,
    check_work: Optional[Callable[[ConstantsFile, RetrofitSpec], None]] = None,
    expected: Optional[ConstantsFile] = None,
) -> RetrofitSearch:
    """Design the ties of a searched scene's mechanisms, then search the tied scene again.

    With connection upgrades in the retrofit spec (``upgrades``), the search also runs once
    with each upgrade on its own and once with every upgrade and the designed ties: one
    more search per upgrade, and one for them all (``search_after.upgrades``,
    ``search_after.together``).

    Parameters
    ----------
    scene : BaseScene
        The scene (``cad_maths.scenes.read_scene``).
    spec : SearchSpec
        The search spec; its ranking's records are not run (the retrofit takes ``motions``).
    site : SiteFile
        The site: hazard, FC, q (the search's code check and the retrofit's).
    rspec : RetrofitSpec
        Steel, bars, anchorage, candidate tie heights per mechanism id of the first search,
        connection upgrades (junctions and levels of ``spec``).
    motions : sequence of GroundMotion
        Records each tied mechanism must survive (``retrofit_doc``), run too on every
        mechanism of the reruns.
    scene_name, spec_name : str
        For the searches' provenance.
    max_evaluations, max_lp_blocks : int, optional
        The searches' work limits (``search_run``), each search's.
    check_work : callable, optional
        Called with the first search's constants and the retrofit spec (its tie heights
        filled in from the scene) before the retrofit runs: a front end's work limit.
    expected : ConstantsFile, optional
        The constants a search run folder holds (``constants.json``): the first search must
        build the same mechanisms (ids, names, α0 to ``SAME_RUN_RTOL``), else the search spec
        is not the one that made the run.

    Returns
    -------
    RetrofitSearch
        The document (``search_after``: the governing mechanism after, its margin [-] and
        λ0 [-], whether it moved; per upgrade the same) and the searches.

    Raises
    ------
    InputError
        The first search builds no mechanism, or not the ``expected`` ones (field
        ``search_spec``); an upgrade the search spec or the scene does not admit (field
        ``upgrades[k]...``, ``retrofit_upgrades.check_upgrades``); any input error of the
        search or retrofit.
    """
    check_upgrades(spec, rspec.upgrades)
    reruns = _Reruns(
        site,
        motions,
        {
            "site": site,
            "motions": [],
            "max_evaluations": max_evaluations,
            "max_lp_blocks": max_lp_blocks,
        },
        scene_name,
        spec_name,
    )
    before = reruns.search(scene, spec)
    if before.constants is None:
        raise InputError("the search built no mechanism: nothing to retrofit", "scene")
    if expected is not None:
        _same_run(before.constants, expected)
    check_upgrades_meet(before.result.building, rspec.upgrades)
    drawn = tie_line_candidates(scene, before, rspec) if rspec.tie_lines else None
    cands = scene_heights(before, rspec, drawn)
    rspec = cands.spec
    if check_work is not None:
        check_work(before.constants, rspec)
    designed = retrofit_doc(
        before.constants,
        site,
        rspec.model_copy(update={"upgrades": [], "tie_lines": None}),
        motions,
    )
    doc = _with_sources(designed, cands)
    placed, lines, bars = place_ties(before, doc)
    after = None
    if lines:
        where = TiedScene(scene, lines)
        after = reruns.search(where, _tied_spec(spec, bars), "with the designed ties")
        names = {o.id: o.name for o, _ in lines}
        block = search_after(before, after, doc, site, placed, names, motions)
    else:
        block = SearchAfter(
            ties=placed,
            **_before_fields(before, doc),
            moved=False,
            basis=TIE_IDEALISATION + SEARCH_AFTER_BASIS,
            notes=["no designed tie was placed in the scene: the search is not rerun"],
        )
    block, runs, together = _upgrades_after(
        reruns, block, scene, spec, rspec.upgrades, (lines, bars)
    )
    final = doc.model_copy(update={"search_after": block})
    return RetrofitSearch(final, before, after, runs, together)
