#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_ComputeConstants: kinematic constants of a spec over named Grasshopper geometry.

The same computation as ``rockmech constants``; with a folder, writes
<id>.spec.json and <id>.constants.json there (atomically).
"""

import os

import Grasshopper

from rhino_plugin.flows.mechanisms import write_outputs
from rhino_plugin.flows.params import constants_from_prepared
from rhino_plugin.rhino.gh import model_units, prepare_inputs


class RM_ComputeConstants(Grasshopper.Kernel.GH_ScriptInstance):
    """Spec + geometry -> constants."""

    def RunScript(self, geometry, names, spec, folder):
        """Return (constants JSON, summary)."""
        scale, units, tol = model_units()
        records = prepare_inputs(list(geometry or []), [str(n) for n in names or []])
        cf = constants_from_prepared(
            records, str(spec or ""), unit_scale=scale, units=units, tolerance=tol * scale
        )
        text = cf.model_dump_json(indent=2, exclude_none=True)
        summary = [
            f"{m.id}: p_eq = {m.positive.p_eq:.4f} rad/s, lambda = {m.positive.lam:.4f}, "
            f"phi_ov = {m.positive.phi_ov:.4f} rad, eta = {m.eta}"
            for m in cf.mechanisms
        ]
        if folder:
            stem = os.path.join(str(folder), cf.mechanisms[0].id)
            write_outputs(f"{stem}.spec.json", str(spec), f"{stem}.constants.json", cf)
        return text, summary
