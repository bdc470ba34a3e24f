#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_RunEnvelope: overturning envelopes and critical bands (Python API or REST service)."""

import json
import os
import tempfile

import Grasshopper

from rhino_plugin.flows.analyse import ServiceClient, run_envelopes
from rhino_plugin.flows.params import parse_constants_text


class RM_RunEnvelope(Grasshopper.Kernel.GH_ScriptInstance):
    """Constants -> envelopes, critical bands and their plot."""

    def RunScript(self, constants, f_min, f_max, service, folder):
        """Return (result JSON, summary, plot PNG path)."""
        cf = parse_constants_text(constants)
        client = ServiceClient(str(service)) if service else None
        out = str(folder) if folder else os.path.join(tempfile.gettempdir(), "rockmech")
        result = run_envelopes(
            cf,
            f_min=float(f_min) if f_min else 0.1,
            f_max=float(f_max) if f_max else 10.0,
            out_dir=out,
            client=client,
        )
        return json.dumps(result.doc.to_dict(), indent=2), result.summary, result.plot
