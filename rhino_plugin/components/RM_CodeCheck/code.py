#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_CodeCheck: the code's kinematic checks of every mechanism (Python API or REST service)."""

import json

import Grasshopper

from rhino_plugin.flows.analyse import ServiceClient
from rhino_plugin.flows.check import parse_site_text, run_check
from rhino_plugin.flows.params import parse_constants_text


class RM_CodeCheck(Grasshopper.Kernel.GH_ScriptInstance):
    """Constants + site -> linear and nonlinear code verdicts per mechanism."""

    def RunScript(self, constants, site, service):
        """Return (result JSON, summary lines)."""
        cf = parse_constants_text(constants)
        site_file = parse_site_text(site)
        client = ServiceClient(str(service)) if service else None
        result = run_check(cf, site_file, client=client)
        return json.dumps(result.doc.to_dict(), indent=2), result.summary
