#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_BuildSpec: a single-block mechanism spec (A1) from solids, densities, axis and cracks.

Outputs the spec JSON and the geometry with the names the spec uses, for
RM_ComputeConstants. Other typologies: write the spec JSON by hand and name the geometry.
"""

import json

import Grasshopper

from rhino_plugin.flows.params import spec_from_parameters


class RM_BuildSpec(Grasshopper.Kernel.GH_ScriptInstance):
    """Single-block spec from Grasshopper geometry."""

    def RunScript(self, mech_id, rocking, solids, densities, axis, cracks, eta):
        """Return (spec JSON, geometry, names)."""
        solids = list(solids or [])
        cracks = list(cracks or [])
        spec, names = spec_from_parameters(
            str(mech_id or "GH1"),
            str(rocking or "two_sided"),
            len(solids),
            list(densities or []),
            axis is not None,
            len(cracks),
            eta,
        )
        geometry = [*solids, *([axis] if axis is not None else []), *cracks]
        return json.dumps(spec, indent=2), geometry, names
