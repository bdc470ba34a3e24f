#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_SearchMechanisms: a façade's collapse mechanisms, found and ranked (Python API).

The same search as ``rockmech search`` over named Grasshopper geometry (the spec selects
walls, levels and tie-bars by these names); with a folder, writes search.json,
search.spec.json, constants.json, search.3dm and search.png there (a run folder).
"""

import json

import Grasshopper
import Rhino.Geometry as rg

from rhino_plugin.flows.search import search_lines, search_marks, search_prepared
from rhino_plugin.rhino.gh import model_units, prepare_inputs
from solver_service.workflows.rundir import run_folder
from solver_service.workflows.search import write_search_files


class RM_SearchMechanisms(Grasshopper.Kernel.GH_ScriptInstance):
    """Geometry + search spec -> ranked mechanisms, their cracks and hinge axes."""

    def RunScript(self, geometry, names, spec, site, folder):
        """Return (result JSON, summary lines, crack and hinge lines)."""
        scale, units, tol = model_units()
        records = prepare_inputs(list(geometry or []), [str(n) for n in names or []])
        run = search_prepared(
            records,
            str(spec or ""),
            unit_scale=scale,
            units=units,
            tolerance=tol * scale,
            site_text=str(site) if site else None,
        )
        if folder:
            with run_folder(str(folder)) as tmp:
                write_search_files(run, tmp)
        lines = [
            rg.Line(rg.Point3d(*m.points[0]), rg.Point3d(*m.points[1]))
            for m in search_marks(run.doc, scale)
        ]
        return json.dumps(run.doc.to_dict(), indent=1), search_lines(run.doc), lines
