#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_RunHistory: time histories of every mechanism at several scale factors."""

import json
import os
import tempfile

import Grasshopper

from rhino_plugin.flows.analyse import RECORD_UNITS, ServiceClient, run_history
from rhino_plugin.flows.params import parse_constants_text


class RM_RunHistory(Grasshopper.Kernel.GH_ScriptInstance):
    """Constants + record -> peak |phi|/phi_ov and overturning, with a plot."""

    def RunScript(self, constants, record, units, scales, service, folder):
        """Return (result JSON, summary, plot PNG path)."""
        cf = parse_constants_text(constants)
        client = ServiceClient(str(service)) if service else None
        out = str(folder) if folder else os.path.join(tempfile.gettempdir(), "rockmech")
        unit = RECORD_UNITS.get(str(units), str(units)) if units else None
        result = run_history(
            cf,
            str(record),
            units=unit,
            scales=[float(s) for s in scales or [1.0]],
            out_dir=out,
            client=client,
        )
        return json.dumps(result.doc.to_dict(), indent=2), result.summary, result.plot
