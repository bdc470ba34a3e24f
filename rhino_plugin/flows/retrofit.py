"""RM_Retrofit: tie-bars for the mechanisms that fail the 2019 checks, drawn on a layer.

The command asks for a constants file (with the mechanisms' geometry: ``rockmech
constants`` or RM_SingleBlock/RM_LoadedWall write one), a site file and a retrofit spec, and
runs ``rockmech retrofit`` (``solver_service.workflows.retrofit.retrofit_doc``) or, when a
service URL is set, ``POST <url>/api/v1/retrofit`` with the same three documents. It writes
``retrofit.json`` into ``<model>.retrofit/`` (a run folder: only that file is replaced),
prints one sentence per mechanism and draws each designed tie on the layer
``rockmech retrofit``: per bar a line from its anchorage on the outer face, at the tie's
height above the hinge, inward across the wall (its ``length_m``, else the wall's
thickness), with a dot naming the bar, its size and its force.

Where the bars go along the wall is the designer's choice: they are drawn evenly over the
wall's length as its centre of mass places it (twice its distance along the hinge from the
hinge's point), a schematic, not a setting-out.

In a document (the command passes its objects as a scene), the first question is where the
mechanisms come from: ``Constants`` (the questions above) or ``SceneSearch``, the scene
route of ``rockmech retrofit --scene --search-spec``: it asks for the search spec, the site
and the retrofit spec, searches the document's objects, designs the ties, puts them into
the scene and searches again (``solver_service.workflows.retrofit_scene.retrofit_search``;
with a service URL, ``POST <url>/api/v1/retrofit`` with the saved model as a multipart
form). It draws each tie-bar line the rerun carried (``search_after.ties``): from the
wall's outer face to its inner face, with a dot naming it and its force, and prints what
governs after the intervention.

Python 3.9-clean: imported by Rhino 8.
"""

import json
import math
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

from rhino_plugin.flows.analyse import ServiceClient, typed_answer
from rhino_plugin.flows.marks import Mark
from rhino_plugin.flows.prompter import Prompter
from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError
from shared_schema.io import read_constants
from shared_schema.retrofit import RetrofitDoc, RetrofitSpec, read_retrofit_spec
from shared_schema.site import SiteFile
from solver_service.report.retrofit import retrofit_summary
from solver_service.workflows.inputs import read_site_file
from solver_service.workflows.limits import CLI_BUDGET_S, check_retrofit_work
from solver_service.workflows.retrofit_files import RETROFIT_FILE, write_retrofit
from solver_service.workflows.rundir import run_folder

__all__ = [
    "RETROFIT_LAYER",
    "SOURCES",
    "RetrofitFlowResult",
    "placed_marks",
    "retrofit_flow",
    "retrofit_lines",
    "retrofit_marks",
    "search_after_summary",
]

#: Layer the command draws the ties on (created when missing).
RETROFIT_LAYER = "rockmech retrofit"
#: Where the mechanisms come from, the first question in a document: a constants file, or
#: the search of the document's objects with a search spec (Rhino option names).
SOURCES = ("Constants", "SceneSearch")

Point = Tuple[float, float, float]


@dataclass
class RetrofitFlowResult:
    """What the retrofit produced for the command.

    Attributes
    ----------
    doc : RetrofitDoc
        ``retrofit.json``.
    summary : list of str
        One sentence per mechanism.
    marks : list of Mark
        The designed ties, one line and dot per bar [model units].
    files : list of str
        Files written.
    """

    doc: RetrofitDoc
    summary: List[str] = field(default_factory=list)
    marks: List[Mark] = field(default_factory=list)
    files: List[str] = field(default_factory=list)
    kind: str = "Retrofit"
    plot: Optional[str] = None


def retrofit_lines(doc: RetrofitDoc) -> List[str]:
    """One sentence per mechanism: the tie that makes it pass, or why there is none."""
    return [row.sentence for row in retrofit_summary(doc)]


def _vec(value: Any) -> Optional[Tuple[float, float, float]]:
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        return None
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in value):
        return None
    return (float(value[0]), float(value[1]), float(value[2]))


def _frame(geometry: Any) -> Optional[Tuple[Point, Point, Point, float, float]]:
    """Return the hinge's frame and the wall's size, or None where the geometry lacks them.

    The frame is the point on the hinge level with the centre of mass along it, the hinge's
    unit direction and the unit inward direction; the size, the wall's length along the
    hinge and its thickness [m].
    """
    geo: Dict[str, Any] = geometry if isinstance(geometry, dict) else {}
    got = geo.get("positive")
    pos: Dict[str, Any] = got if isinstance(got, dict) else {}
    p, u = _vec(pos.get("axis_point_m")), _vec(pos.get("axis_direction"))
    com = _vec(geo.get("com_m"))
    if p is None or u is None or com is None:
        return None
    norm = math.sqrt(sum(c * c for c in u))
    if norm == 0.0:
        return None
    u = (u[0] / norm, u[1] / norm, u[2] / norm)
    d = (com[0] - p[0], com[1] - p[1], com[2] - p[2])
    along = d[0] * u[0] + d[1] * u[1] + d[2] * u[2]
    # Inward: horizontal, from the hinge towards the centre of mass, square to the hinge.
    w = (d[0] - along * u[0], d[1] - along * u[1], 0.0)
    depth = math.hypot(w[0], w[1])
    if depth == 0.0:
        return None
    inward = (w[0] / depth, w[1] / depth, 0.0)
    centre = (p[0] + along * u[0], p[1] + along * u[1], p[2] + along * u[2])
    return centre, u, inward, 2.0 * abs(along), 2.0 * depth


def retrofit_marks(
    doc: RetrofitDoc, cf: ConstantsFile, spec: RetrofitSpec, unit_scale: float
) -> List[Mark]:
    """Return one line per bar of every designed tie [model units].

    Parameters
    ----------
    doc : RetrofitDoc
        The retrofit of ``cf``.
    cf : ConstantsFile
        The constants, whose geometry places the hinge (``positive.axis_point_m``,
        ``axis_direction``) and the centre of mass (``com_m``) [m].
    spec : RetrofitSpec
        The spec (each mechanism's bar ``length_m``).
    unit_scale : float
        Metres per model unit (> 0).

    Returns
    -------
    list of Mark
        Per bar ``"<id> tie k/n: Ø<d> <grade>, <T> kN"``: from its anchorage on the outer face
        at the tie's height above the hinge, inward by the bar's length (else the wall's
        thickness); the ``n`` bars evenly over the wall's length.
    """
    s = float(unit_scale)
    by_id = {m.id: m for m in cf.mechanisms}
    marks: List[Mark] = []

    def pt(x: Sequence[float]) -> Point:
        return (x[0] / s, x[1] / s, x[2] / s)

    for m in doc.mechanisms:
        if m.status != "designed" or m.chosen is None or m.id not in by_id:
            continue
        tie = m.options[m.chosen]
        frame = _frame(by_id[m.id].geometry)
        if frame is None or tie.bar is None or tie.T_star_N is None:
            continue
        centre, u, inward, length, thickness = frame
        ties = spec.mechanisms.get(m.id)
        reach = ties.length_m if ties is not None and ties.length_m is not None else thickness
        n = tie.bars
        for k in range(n):
            offset = ((k + 0.5) / n - 0.5) * length
            a = (
                centre[0] + offset * u[0],
                centre[1] + offset * u[1],
                centre[2] + offset * u[2] + tie.height_m,
            )
            b = (a[0] + reach * inward[0], a[1] + reach * inward[1], a[2])
            bar, force = tie.bar, tie.T_star_N / n / 1e3
            label = f"{m.id} tie {k + 1}/{n}: Ø{bar.diameter_mm:g} {bar.grade}, {force:.3g} kN"
            marks.append(Mark(label, (pt(a), pt(b))))
    return marks


def placed_marks(doc: RetrofitDoc, unit_scale: float) -> List[Mark]:
    """Return one line per tie-bar the search rerun carried (``search_after``) [model units].

    Each placed line once (ties of several mechanisms at one point are one line), from its
    point on the wall's outer face (``at_m``) to the inner face (``end_m``), labelled with its
    name, its force [kN] and its wall.
    """
    sa = doc.search_after
    if sa is None:
        return []
    s = float(unit_scale)
    marks: List[Mark] = []
    seen = set()
    for t in sa.ties:
        if t.status != "placed" or t.object in seen or t.force_N is None:
            continue
        if t.at_m is None or t.end_m is None:
            continue
        seen.add(t.object)
        a = (t.at_m[0] / s, t.at_m[1] / s, t.at_m[2] / s)
        b = (t.end_m[0] / s, t.end_m[1] / s, t.end_m[2] / s)
        marks.append(Mark(f"{t.object}: {t.force_N / 1e3:.3g} kN on {t.wall}", (a, b)))
    return marks


def _ratio(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.3f}"


def search_after_summary(doc: RetrofitDoc) -> List[str]:
    """Lines on the search again with the ties: the ties not placed, what governs after."""
    sa = doc.search_after
    if sa is None:
        return []
    out = [
        f"{t.mechanism}: not put in the scene: {t.note}" for t in sa.ties if t.status != "placed"
    ]
    if sa.after is None:
        return out + list(sa.notes)
    where = "the same mechanism governs"
    if sa.moved:
        where = "the collapse moves to another mechanism"
        if sa.after_facade != sa.before_facade:
            where = f"the collapse moves to another wall ({sa.before_facade} -> {sa.after_facade})"
    out.append(
        f"Searched again with the ties: {sa.after} governs at margin {_ratio(sa.after_margin)} "
        f"({sa.after_criterion}); before, {sa.before} at {_ratio(sa.before_margin)}: {where}"
    )
    return out


def _scene_here(
    scene: Any, scene_name: str, search_path: str, site: SiteFile, spec: RetrofitSpec
) -> RetrofitDoc:
    """Run ``rockmech retrofit --scene`` on the document's objects (the command line's limits)."""
    # The searches and the retrofit (scipy, the geometry) are loaded when the command runs.
    from solver_service.workflows.retrofit_scene import retrofit_search

    # The search spec's reader and the search's work limits, with the search.
    from solver_service.workflows.search import MAX_EVALUATIONS, MAX_LP_BLOCKS, read_search_spec

    def check_work(cf: ConstantsFile, rspec: RetrofitSpec) -> None:
        how = "run rockmech retrofit --scene from the command line"
        check_retrofit_work(cf, site, rspec, CLI_BUDGET_S, how)

    run = retrofit_search(
        scene,
        read_search_spec(search_path),
        site,
        spec,
        scene_name=scene_name,
        spec_name=os.path.basename(search_path),
        max_evaluations=MAX_EVALUATIONS,
        max_lp_blocks=MAX_LP_BLOCKS,
        check_work=check_work,
    )
    return run.doc


def _read(path: str) -> Tuple[str, bytes]:
    with open(path, "rb") as fh:
        return os.path.basename(path), fh.read()


def _scene_retrofit(
    ask: Prompter,
    scene: Any,
    scene_name: str,
    scene_path: Optional[str],
    service_url: Optional[str],
) -> Tuple[RetrofitDoc, str]:
    """Run the scene route: ask for the search spec, site and retrofit spec."""
    search_path = ask.get_file("Search spec (JSON)", [".json"])
    site_path = ask.get_file("Site file (SITE.json)", [".json"])
    spec_path = ask.get_file("Retrofit spec (JSON)", [".json"])
    site: SiteFile = read_site_file(site_path)
    spec = read_retrofit_spec(spec_path)
    if not service_url:
        return _scene_here(scene, scene_name, search_path, site, spec), "the Python API"
    if not scene_path:
        raise InputError("save the model first: the service searches the saved file", "scene")
    files = {
        "scene": (scene_name, _read(scene_path)[1]),
        "search_spec": _read(search_path),
        "site": _read(site_path),
        "spec": _read(spec_path),
    }
    answer = ServiceClient(service_url).post_files("retrofit", files)
    return typed_answer(RetrofitDoc, answer, "retrofit"), "the service"


def _constants_retrofit(
    ask: Prompter, unit_scale: float, service_url: Optional[str]
) -> Tuple[RetrofitDoc, List[Mark], str]:
    """Run the constants route: ask for the constants, site and retrofit spec."""
    constants_path = ask.get_file("Kinematic-constants file", [".json"])
    site_path = ask.get_file("Site file (SITE.json)", [".json"])
    spec_path = ask.get_file("Retrofit spec (JSON)", [".json"])
    cf = read_constants(constants_path)
    site: SiteFile = read_site_file(site_path)
    spec = read_retrofit_spec(spec_path)
    if service_url:
        payload = {
            "constants": json.loads(cf.model_dump_json(exclude_none=True)),
            "site": json.loads(site.model_dump_json(exclude_none=True)),
            "spec": json.loads(spec.model_dump_json(exclude_none=True)),
        }
        answer = ServiceClient(service_url).post("retrofit", payload)
        doc = typed_answer(RetrofitDoc, answer, "retrofit")
        where = "the service"
    else:
        check_retrofit_work(
            cf, site, spec, CLI_BUDGET_S, "run rockmech retrofit from the command line"
        )
        # The retrofit (the code checks' bisections) is loaded when the command runs.
        from solver_service.workflows.retrofit import retrofit_doc

        doc = retrofit_doc(cf, site, spec)
        where = "the Python API"
    return doc, retrofit_marks(doc, cf, spec, unit_scale), where


def retrofit_flow(
    ask: Prompter,
    folder: str,
    *,
    stem: str,
    unit_scale: float = 1.0,
    service_url: Optional[str] = None,
    scene: Any = None,
    scene_name: Optional[str] = None,
    scene_path: Optional[str] = None,
) -> RetrofitFlowResult:
    """RM_Retrofit: ask for the mechanisms' source and the files; retrofit, write, draw.

    Parameters
    ----------
    ask : Prompter
        The questions (Rhino or scripted).
    folder : str
        Where ``<stem>.retrofit/`` goes (beside the model).
    stem : str
        The model's file name without its extension.
    unit_scale : float
        Metres per model unit (the marks are in model units).
    service_url : str, optional
        The REST service's URL; without it the retrofit runs here.
    scene : BaseScene, optional
        The document's objects: the first question then offers ``SOURCES`` (a constants
        file, or the search of this scene with a search spec); without it, constants.
    scene_name : str, optional
        The model's file name (default ``<stem>.3dm``).
    scene_path : str, optional
        The saved model (uploaded to the service by the scene route).

    Raises
    ------
    InputError
        A file that cannot be read, an invalid document (naming the field), work past the
        command line's time limit (run ``rockmech retrofit --no-limits``), an unsaved model
        for the service, or the service's refusal.
    """
    from_scene = scene is not None and ask.get_option("Mechanisms from", SOURCES, 0) == SOURCES[1]
    if from_scene:
        name = scene_name or f"{stem}.3dm"
        doc, where = _scene_retrofit(ask, scene, name, scene_path, service_url)
        marks = placed_marks(doc, unit_scale)
        summary = retrofit_lines(doc) + search_after_summary(doc)
    else:
        doc, marks, where = _constants_retrofit(ask, unit_scale, service_url)
        summary = retrofit_lines(doc)
    out = os.path.join(folder, f"{stem}.retrofit")
    with run_folder(out, on_note=ask.message, command="retrofit") as tmp:
        write_retrofit(tmp, doc)
    path = os.path.join(out, RETROFIT_FILE)
    result = RetrofitFlowResult(doc, summary, marks, [path])
    ask.message(f"RM_Retrofit: {len(doc.mechanisms)} mechanism(s) via {where}; wrote {path}")
    for line in result.summary:
        ask.message(line)
    return result
