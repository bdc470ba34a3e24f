#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_RunPulse: one mechanism under a one-cycle sine pulse (Python API or REST service)."""

import json

import Grasshopper

from rhino_plugin.flows.analyse import ServiceClient, run_pulse
from rhino_plugin.flows.params import parse_constants_text


class RM_RunPulse(Grasshopper.Kernel.GH_ScriptInstance):
    """Constants -> pulse response."""

    def RunScript(self, constants, mechanism, a_p_g, f_p, service):
        """Return (result JSON, summary)."""
        cf = parse_constants_text(constants)
        client = ServiceClient(str(service)) if service else None
        mech = str(mechanism) if mechanism else cf.mechanisms[0].id
        result = run_pulse(cf, mech, a_p_g=float(a_p_g), f_p=float(f_p), client=client)
        return json.dumps(result.doc.to_dict(), indent=2), result.summary
