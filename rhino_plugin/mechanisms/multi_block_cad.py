"""Three blocks, four hinges (A4) from CAD solids.

Each block is a list of density groups; the hinges A, B, C, D are points or line objects
(a line's mid-point is used). The mechanism moves in the vertical plane through A and D:
planar x runs horizontally from A towards D, z up; each block's inertia is taken about
the horizontal axis normal to that plane.

For each hinge set the sense of motion is the one in which the weight resists at rest
(the hinges open; the other sense is not kinematically admissible for unilateral
contacts). The constants follow theory §2.4 (``multi_block.four_bar_constants``); the
restitution is the momentum projection of §3.4 from the positive to the negative mode.
"""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from rhino_plugin.geometry.massprops import combine, mass_properties
from rhino_plugin.geometry.validate import check_solid
from rhino_plugin.mechanisms.base import MechanismSides
from rhino_plugin.mechanisms.multi_block import four_bar_constants, four_bar_restitution
from rhino_plugin.mechanisms.single import find_objects
from rhino_plugin.mechanisms.two_block import PlanarBody
from shared_schema.errors import GeometryError, InputError

__all__ = ["multi_block_sides"]


def _hinge_point(scene: Any, hinge: Any, where: str) -> np.ndarray:

    if isinstance(hinge, list):
        return np.asarray(hinge, dtype=float)
    obj = find_objects(scene, [hinge], where)[0]
    start, end = scene.line(obj)
    return 0.5 * (np.asarray(start, dtype=float) + np.asarray(end, dtype=float))


def _blocks(scene: Any, spec: Any) -> Tuple[List[Any], List[np.ndarray], List[str], List[str]]:

    props, verts, ids, notes = [], [], [], []
    for k, groups in enumerate(spec.blocks):
        parts = []
        pts = []
        for j, group in enumerate(groups):
            for obj in find_objects(scene, group.objects, f"{spec.id}.blocks[{k}][{j}]"):
                mesh, warn = check_solid(scene.mesh(obj))
                notes.extend(warn)
                parts.append(mass_properties(mesh, group.density))
                pts.append(mesh.vertices)
                ids.append(obj.id)
        props.append(combine(parts, name=f"{spec.id}.blocks[{k}]"))
        verts.append(np.vstack(pts))
    return props, verts, ids, notes


#: Band (fraction of a block's height) around a hinge in which the block's width is taken.
MIRROR_BAND = 0.01


def _mirrored(hinges: List[Tuple[float, float]], columns: List[np.ndarray]) -> List[Any]:
    """Return the derived negative set: each hinge reflected across its column at its height.

    A and B are reflected within block 1, C and D within block 3 (``columns`` are those
    blocks' vertices in planar (x, z)). For rectangular columns this swaps each column's
    corners, as for a portal frame.
    """
    out = []
    for k, (x, z) in enumerate(hinges):
        xz = columns[0] if k < 2 else columns[1]
        band = MIRROR_BAND * float(np.ptp(xz[:, 1]))
        near = xz[np.abs(xz[:, 1] - z) <= band, 0]
        xs = near if near.size else xz[:, 0]
        out.append((float(xs.min() + xs.max() - x), z))
    return out


def _solve(blocks: Any, pts: List[Any], where: str) -> Any:

    last: Optional[Exception] = None
    for direction in (1, -1):
        try:
            return four_bar_constants(blocks, *pts, direction=direction), direction
        except GeometryError as exc:
            if "does not resist" not in str(exc):
                raise GeometryError(f"{where}: {exc}") from None
            last = exc
    raise GeometryError(f"{where}: {last}")


def multi_block_sides(
    spec: Any, scene: Any
) -> Tuple[
    Dict[str, float], Optional[Dict[str, float]], Optional[float], Dict[str, Any], List[str]
]:
    """Constants of both hinge sets, eta (or None), a summary and object ids."""
    where = spec.id
    props, verts, ids, notes = _blocks(scene, spec)
    names = ("A", "B", "C", "D")
    pos3 = [_hinge_point(scene, getattr(spec.hinges, n), f"{where}.hinges.{n}") for n in names]
    origin = pos3[0]
    span = pos3[3] - pos3[0]
    span[2] = 0.0
    if float(np.linalg.norm(span)) < 1e-9:
        raise InputError(
            "A and D are vertically above each other; the mechanism's plane is undefined",
            f"{where}.hinges",
        )
    ex = span / float(np.linalg.norm(span))
    normal = np.cross(np.array([0.0, 0.0, 1.0]), ex)

    def planar(p: np.ndarray) -> Tuple[float, float]:
        d = np.asarray(p, dtype=float) - origin
        return float(d @ ex), float(d[2])

    blocks = tuple(
        PlanarBody(float(p.mass), planar(p.com), float(normal @ np.asarray(p.inertia_com) @ normal))
        for p in props
    )
    hinges_pos = [planar(p) for p in pos3]
    res, direction = _solve(blocks, hinges_pos, f"{where}.hinges")
    positive = res.constants()
    negative = None
    eta = None
    summary: Dict[str, Any] = {
        "plane_x_axis": [float(v) for v in ex],
        "block_masses_kg": [b.mass for b in blocks],
        "positive": {"collapse_sense": direction, **{k: float(v) for k, v in res.details.items()}},
    }
    if spec.rocking == "two_sided":
        if spec.hinges_negative is not None:
            neg3 = [
                _hinge_point(
                    scene, getattr(spec.hinges_negative, n), f"{where}.hinges_negative.{n}"
                )
                for n in names
            ]
            hinges_neg = [planar(p) for p in neg3]
        else:
            cols = [
                np.column_stack([(verts[k] - origin) @ ex, verts[k][:, 2] - origin[2]])
                for k in (0, 2)
            ]
            hinges_neg = _mirrored(hinges_pos, cols)
            summary["hinges_negative_derived"] = [list(h) for h in hinges_neg]
        res_n, dir_n = _solve(blocks, hinges_neg, f"{where}.hinges_negative")
        if dir_n == direction:
            raise InputError(
                "the negative hinge set moves in the same sense as the positive "
                "one; give the mirrored set",
                f"{where}.hinges_negative",
            )
        negative = res_n.constants("negative")
        eta = four_bar_restitution(blocks, tuple(hinges_pos), tuple(hinges_neg))
        summary["negative"] = {
            "collapse_sense": dir_n,
            **{k: float(v) for k, v in res_n.details.items()},
        }
    summary["warnings"] = notes
    return positive, negative, eta, summary, ids


def build_multi_block(spec: Any, scene: Any, table: Any) -> MechanismSides:
    """Builder of typology ``multi_block`` (docs/theory.md §2.4); ``table`` is unused."""
    positive, negative, eta, summary, ids = multi_block_sides(spec, scene)
    warnings = summary.pop("warnings")
    return MechanismSides(
        positive, negative, eta, "momentum_projection", {"multi_block": summary}, ids, warnings
    )
