"""RM_Search and RM_SearchMechanisms: a façade's mechanisms found and ranked, in Rhino.

The command asks for a search spec (JSON) and runs ``rockmech search`` on the document's
objects (``solver_service.workflows.search.search_run``), or, when a service URL is set,
``POST <url>/api/v1/search`` with the saved model and the spec. Locally it writes
``search.json``, ``search.spec.json``, ``constants.json``, ``search.3dm`` and ``search.png``
into ``<model>.search/`` (a run folder: only rockmech's own files there are replaced) and
draws the best ranked mechanisms' cracks and hinge axes on the layer ``rockmech search``.
The Grasshopper component runs the same search over named geometry.

Python 3.9-clean: imported by Rhino 8.
"""

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, List, Optional, Sequence, Tuple

from rhino_plugin.flows.analyse import ServiceClient, typed_answer
from rhino_plugin.flows.marks import Mark
from rhino_plugin.flows.prepared import PreparedScene
from rhino_plugin.flows.prompter import Prompter
from shared_schema.documents.search import SearchDocument
from shared_schema.errors import InputError
from shared_schema.search import parse_search_spec
from shared_schema.site import parse_site
from solver_service.workflows.rundir import run_folder
from solver_service.workflows.search import read_search_spec, search_run, write_search_files

__all__ = [
    "SEARCH_LAYER",
    "SearchFlowResult",
    "search_flow",
    "search_lines",
    "search_marks",
    "search_prepared",
]

#: Layer the command draws the mechanisms on (created when missing).
SEARCH_LAYER = "rockmech search"
#: How many of the best ranked mechanisms are drawn and listed.
N_SHOWN = 6


@dataclass
class SearchFlowResult:
    """What the search produced for the command or the component.

    Attributes
    ----------
    doc : SearchDocument
        The search's document (``search.json`` is its ``to_dict()``; the service's answer
        is validated into it).
    summary : list of str
        Lines for the command line.
    marks : list of Mark
        The shown mechanisms' hinge axes and cracks [model units].
    plot : str, optional
        ``search.png`` (local runs).
    files : list of str
        Files written.
    """

    doc: SearchDocument
    summary: List[str] = field(default_factory=list)
    marks: List[Mark] = field(default_factory=list)
    plot: Optional[str] = None
    files: List[str] = field(default_factory=list)
    kind: str = "Search"


def search_lines(doc: SearchDocument) -> List[str]:
    """One line per shown mechanism (best ranked first), the checks' verdicts, the summary."""
    lines = []
    for d in doc.ranked[:N_SHOWN]:
        score = None if d.overturning is None else d.overturning.band_score_g
        a_p = "" if score is None else f", a_p,min {score:.3g} g"
        lines.append(
            "{}: {} of {} ({}), lam0 {:.4g}{}".format(
                d.id, d.family.replace("_", " "), d.facade, d.direction, d.lam0, a_p
            )
        )
    for check in doc.lp:
        lines.append(f"{check.facade} {check.direction}: {check.message}")
    lines.extend(doc.rankings.summary)
    return lines


def search_marks(doc: SearchDocument, unit_scale: float) -> List[Mark]:
    """Hinge axes and cracks (their outer-face edge) of the shown mechanisms [model units]."""
    s = float(unit_scale)

    def pt(p: Sequence[float]) -> Tuple[float, float, float]:
        return (p[0] / s, p[1] / s, p[2] / s)

    marks: List[Mark] = []
    for d in doc.ranked[:N_SHOWN]:
        a, b = d.hinge_axis
        marks.append(Mark(f"{d.id} hinge", (pt(a), pt(b))))
        for k, crack in enumerate(d.cracks):
            c = crack.corners
            marks.append(Mark(f"{d.id} crack {k + 1}", (pt(c[0]), pt(c[1]))))
    return marks


def search_flow(
    ask: Prompter,
    scene: Any,
    folder: str,
    *,
    scene_name: str,
    scene_path: Optional[str] = None,
    service_url: Optional[str] = None,
) -> Optional[SearchFlowResult]:
    """RM_Search: ask for the search spec, search the scene, write and summarise.

    Parameters
    ----------
    ask : Prompter
        The questions (Rhino or scripted).
    scene : BaseScene
        The document's objects.
    folder : str
        Where ``<model>.search/`` goes (beside the model).
    scene_name : str
        The model's file name.
    scene_path : str, optional
        The saved model (uploaded to the service).
    service_url : str, optional
        The REST service's URL; without it the search runs here.
    """
    spec_path = Path(ask.get_file("Search spec (JSON)", [".json"]))
    stem = os.path.splitext(scene_name)[0]
    if service_url:
        if not scene_path:
            raise InputError("save the model first: the service searches the saved file", "scene")
        client = ServiceClient(service_url)
        answer = client.post_files(
            "search",
            {
                "scene": (scene_name, Path(scene_path).read_bytes()),
                "spec": (spec_path.name, spec_path.read_bytes()),
            },
        )
        doc = typed_answer(SearchDocument, answer, "search")
        result = SearchFlowResult(doc, search_lines(doc), search_marks(doc, scene.unit_scale))
    else:
        spec = read_search_spec(spec_path)
        run = search_run(
            scene, spec, scene_name=scene_name, spec_name=spec_path.name, spec_dir=spec_path.parent
        )
        out = os.path.join(folder, f"{stem}.search")
        with run_folder(out, on_note=ask.message) as tmp:
            written = write_search_files(run, tmp)
        files = [os.path.join(out, p.name) for p in written]
        plot = os.path.join(out, "search.png")
        result = SearchFlowResult(
            run.doc,
            search_lines(run.doc),
            search_marks(run.doc, scene.unit_scale),
            plot if os.path.isfile(plot) else None,
            files,
        )
        ask.message(f"RM_Search: wrote {out}")
    for line in result.summary:
        ask.message(line)
    return result


def search_prepared(
    records: Sequence[Tuple[str, str, Any]],
    spec_text: str,
    *,
    unit_scale: float = 1.0,
    units: str = "meters",
    tolerance: float = 0.0,
    site_text: Optional[str] = None,
) -> Any:
    """Search named Grasshopper geometry with a search spec's text (RM_SearchMechanisms).

    ``records`` are ``(name, kind, prepared)`` as ``rhino_plugin.rhino.gh.prepare_inputs``
    returns them; the spec selects them by name. Returns the ``SearchRun``.
    """
    if not isinstance(spec_text, str) or not spec_text.strip():
        raise InputError("connect a search spec (JSON text)", "spec")
    spec = parse_search_spec(spec_text, "spec")
    if spec.ranking.site is not None or spec.ranking.records:
        raise InputError(
            "give the site as the component's 'site' input; records are ranked by the "
            "command or the command line",
            "ranking",
        )
    scene = PreparedScene.from_records(
        [(name, name, "", kind, prep) for name, kind, prep in records],
        unit_scale=unit_scale,
        units=units,
        tolerance=tolerance,
    )
    site = parse_site(site_text) if site_text else None
    return search_run(scene, spec, scene_name="Grasshopper", spec_name="spec", site=site)
