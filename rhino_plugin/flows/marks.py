"""What a mechanism command draws for checking: axes, centres of mass and hinges.

:func:`check_marks` reads them from the spec, the scene and the computed constants (the
geometry summary), and returns them in model units, so the Rhino glue only has to add a
line or a text dot per :class:`Mark` on the check layer.

Python 3.9-clean: imported by Rhino 8.
"""

from dataclasses import dataclass
from typing import Any, List, Tuple

import numpy as np

from cad_maths.mechanisms.multi_block_cad import hinge_point
from cad_maths.mechanisms.single import resolve_axis

__all__ = ["Mark", "check_marks"]

Point = Tuple[float, float, float]


@dataclass(frozen=True)
class Mark:
    """A labelled point (one point) or line (two points) [model units]."""

    label: str
    points: Tuple[Point, ...]


def _pt(xyz: Any, unit_scale: float) -> Point:
    a = np.asarray(xyz, dtype=np.float64) / unit_scale
    return (float(a[0]), float(a[1]), float(a[2]))


def check_marks(spec_file: Any, scene: Any, constants: Any) -> List[Mark]:
    """Return the axes, centres of mass and hinges of every mechanism [model units].

    Parameters
    ----------
    spec_file : shared_schema.spec.SpecFile
    scene : cad_maths.scene_3dm.Scene
    constants : shared_schema.constants.ConstantsFile
        Computed from ``spec_file`` and ``scene``.

    Returns
    -------
    list of Mark
        Per mechanism: the axis (``"<id> axis"``), the other side's axis when two-sided
        (``"<id> axis (negative)"``, as given or as derived from the base), the centre of
        mass ``"<id> G"``, the two-block hinge height ``"<id> h_c"``, and the multi-block
        hinges ``"<id> A"`` ... ``"<id> D"`` (and ``"<id> A-"`` ... for the negative set).
    """
    s = float(scene.unit_scale)
    marks: List[Mark] = []
    for spec, mech in zip(spec_file.mechanisms, constants.mechanisms):
        geo = mech.geometry or {}
        axis = getattr(spec, "axis", None)  # a multi-block mechanism has hinges instead
        if axis is not None:
            start, end = resolve_axis(scene, axis, f"{spec.id}.axis")
            marks.append(Mark(f"{spec.id} axis", (_pt(start, s), _pt(end, s))))
            neg = geo.get("negative")
            if neg is not None:
                length = float(np.linalg.norm(end - start))
                p = np.asarray(neg["axis_point_m"], dtype=np.float64)
                u = np.asarray(neg["axis_direction"], dtype=np.float64)
                marks.append(
                    Mark(f"{spec.id} axis (negative)", (_pt(p, s), _pt(p + length * u, s)))
                )
        if "com_m" in geo:
            marks.append(Mark(f"{spec.id} G", (_pt(geo["com_m"], s),)))
        two = geo.get("two_block")
        if two is not None and axis is not None:
            start, end = resolve_axis(scene, axis, f"{spec.id}.axis")
            mid = 0.5 * (start + end) + np.array([0.0, 0.0, float(two["h_c_m"])])
            marks.append(Mark(f"{spec.id} h_c", (_pt(mid, s),)))
        for attr, suffix in (("hinges", ""), ("hinges_negative", "-")):
            hinges = getattr(spec, attr, None)
            if hinges is None:
                continue
            for name in ("A", "B", "C", "D"):
                p = hinge_point(scene, getattr(hinges, name), f"{spec.id}.{attr}.{name}")
                marks.append(Mark(f"{spec.id} {name}{suffix}", (_pt(p, s),)))
    return marks
