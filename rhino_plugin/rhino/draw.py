"""Draw a command's check marks (axes, centres of mass, hinges) on a layer."""

from typing import Sequence

import Rhino
import Rhino.Geometry as rg

from rhino_plugin.flows.marks import Mark

__all__ = ["CHECK_LAYER", "draw_marks"]

#: Layer of the check geometry (created when missing).
CHECK_LAYER = "rockmech check"


def _layer_index(doc: Rhino.RhinoDoc, name: str) -> int:
    index = doc.Layers.FindByFullPath(name, -1)
    if index >= 0:
        return int(index)
    layer = Rhino.DocObjects.Layer()
    layer.Name = name
    return int(doc.Layers.Add(layer))


def draw_marks(doc: Rhino.RhinoDoc, marks: Sequence[Mark], layer: str = CHECK_LAYER) -> int:
    """Add a line and a text dot per mark on ``layer``; return the number of objects added."""
    attr = Rhino.DocObjects.ObjectAttributes()
    attr.LayerIndex = _layer_index(doc, layer)
    added = 0
    for mark in marks:
        pts = [rg.Point3d(*p) for p in mark.points]
        if len(pts) == 2:
            doc.Objects.AddLine(pts[0], pts[1], attr)
            added += 1
            dot_at = rg.Point3d(0.5 * (pts[0].X + pts[1].X), 0.5 * (pts[0].Y + pts[1].Y),
                                0.5 * (pts[0].Z + pts[1].Z))  # fmt: skip
        else:
            dot_at = pts[0]
        doc.Objects.AddTextDot(mark.label, dot_at, attr)
        added += 1
    doc.Views.Redraw()
    return added
