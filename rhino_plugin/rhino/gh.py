"""Grasshopper inputs -> prepared geometry for ``rhino_plugin.flows.params``."""

from typing import Any, List, Sequence, Tuple

import Rhino
import Rhino.Geometry as rg

from rhino_plugin.flows.prepared import Prepared
from rhino_plugin.rhino.docscene import kind_of, prepare

__all__ = ["model_units", "prepare_inputs"]


def model_units() -> Tuple[float, str, float]:
    """Metres per model unit, unit name and absolute tolerance [model units] of the document."""
    doc = Rhino.RhinoDoc.ActiveDoc
    if doc is None:
        return 1.0, "meters", 1e-6
    scale = Rhino.RhinoMath.UnitScale(doc.ModelUnitSystem, Rhino.UnitSystem.Meters)
    return scale, str(doc.ModelUnitSystem).lower(), float(doc.ModelAbsoluteTolerance)


def prepare_inputs(
    geometry: Sequence[Any], names: Sequence[str]
) -> List[Tuple[str, str, Prepared]]:
    """Pair each geometry with its name and prepare it (a Line becomes a LineCurve)."""
    if len(geometry) != len(names):
        raise ValueError(f"{len(geometry)} geometries but {len(names)} names")
    _, _, tol = model_units()
    records = []
    for geo, name in zip(geometry, names):
        if isinstance(geo, rg.Line):
            geo = rg.LineCurve(geo)
        records.append((str(name), kind_of(geo), prepare(geo, tol)))
    return records
