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

Python 3.9-clean: imported by Rhino 8.
"""

import json
import math
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

from rhino_plugin.flows.analyse import ServiceClient
from rhino_plugin.flows.marks import Mark
from rhino_plugin.flows.prompter import Prompter
from shared_schema.constants import ConstantsFile
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
    "RetrofitFlowResult",
    "retrofit_flow",
    "retrofit_lines",
    "retrofit_marks",
]

#: Layer the command draws the ties on (created when missing).
RETROFIT_LAYER = "rockmech retrofit"

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


def retrofit_flow(
    ask: Prompter,
    folder: str,
    *,
    stem: str,
    unit_scale: float = 1.0,
    service_url: Optional[str] = None,
) -> RetrofitFlowResult:
    """RM_Retrofit: ask for the constants, site and retrofit spec; retrofit, write, draw.

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

    Raises
    ------
    InputError
        A file that cannot be read, an invalid document (naming the field), work past the
        command line's time limit (run ``rockmech retrofit --no-limits``), or the service's
        refusal.
    """
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
        doc = RetrofitDoc.model_validate(ServiceClient(service_url).post("retrofit", payload))
        where = "the service"
    else:
        check_retrofit_work(
            cf, site, spec, CLI_BUDGET_S, "run rockmech retrofit from the command line"
        )
        # The retrofit (the code checks' bisections) is loaded when the command runs.
        from solver_service.workflows.retrofit import retrofit_doc

        doc = retrofit_doc(cf, site, spec)
        where = "the Python API"
    out = os.path.join(folder, f"{stem}.retrofit")
    with run_folder(out, on_note=ask.message, command="retrofit") as tmp:
        write_retrofit(tmp, doc)
    path = os.path.join(out, RETROFIT_FILE)
    result = RetrofitFlowResult(
        doc, retrofit_lines(doc), retrofit_marks(doc, cf, spec, unit_scale), [path]
    )
    ask.message(f"RM_Retrofit: {len(doc.mechanisms)} mechanism(s) via {where}; wrote {path}")
    for line in result.summary:
        ask.message(line)
    return result
