"""Three blocks, four hinges (A4) from CAD solids.

Each block is a list of density groups; the hinges A, B, C, D are points or line objects
(a line's mid-point is used). The mechanism moves in the vertical plane fitted through all
the hinges (``_plane``: each hinge must lie on it, each hinge line must be normal to it):
planar x runs horizontally from A towards D, z up; each block's inertia is taken about
the horizontal axis normal to that plane.

Without ``hinges_negative`` a two-sided mechanism gets a derived negative set (each hinge
reflected across its column at its height, ``_mirrored``), and a warning says so and gives
the derived points.

For each hinge set the sense of motion is the one in which the weight resists at rest
(the hinges open; the other sense is not kinematically admissible for unilateral
contacts). The constants follow theory §2.4 (``multi_block.four_bar_constants``); the
restitution is the momentum projection of §3.4 from the positive to the negative mode.
"""

import math
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from cad_maths.geometry.massprops import combine, mass_properties
from cad_maths.geometry.validate import check_solid
from cad_maths.mechanisms.base import MechanismSides, virtual_work_of
from cad_maths.mechanisms.multi_block import four_bar_constants, four_bar_restitution
from cad_maths.mechanisms.single import claim_once, find_objects
from cad_maths.mechanisms.two_block import PlanarBody
from shared_schema.errors import GeometryError, InputError

__all__ = ["multi_block_sides"]


#: Largest distance of a hinge from the mechanism's plane, relative to the largest distance
#: between hinges (the file's absolute tolerance when that is larger).
PLANE_RTOL = 1e-3
#: Largest angle between a hinge line object and the normal of the mechanism's plane [rad]
#: (the single block's tolerance on a horizontal axis).
HINGE_AXIS_TOL = 1e-3


def _hinge(scene: Any, hinge: Any, where: str) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """Return a hinge's point [m] and, for a line object, its unit direction (else None)."""
    if isinstance(hinge, list):
        return np.asarray(hinge, dtype=float), None
    obj = find_objects(scene, [hinge], where)[0]
    start, end = scene.line(obj)
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    d = end - start
    return 0.5 * (start + end), d / float(np.linalg.norm(d))


def hinge_point(scene: Any, hinge: Any, where: str) -> np.ndarray:
    """Return a hinge's point [m] (a line object's mid-point); used by the flows' marks."""
    return _hinge(scene, hinge, where)[0]


def _plane(
    points: Dict[str, np.ndarray],
    lines: Dict[str, np.ndarray],
    tolerance: float,
    where: str,
) -> Tuple[np.ndarray, np.ndarray, Dict[str, Any]]:
    """Fit the vertical plane through every hinge and check it; return x axis, normal, record.

    The plane is the vertical plane that best fits the hinges in plan (least squares), with
    x running from A towards D. Every hinge must lie within the tolerance of it, and every
    hinge drawn as a line must be normal to it; a hinge given as a point is taken to turn
    about the plane's normal.

    Raises
    ------
    InputError
        The hinges are all above one point, a hinge is off the plane, or a hinge line is
        not normal to the plane; the message names the hinge and the amount.
    """
    names = list(points)
    xyz = np.array([points[n] for n in names])
    size = max(float(np.linalg.norm(p - q)) for p in xyz for q in xyz)
    plan = xyz[:, :2] - xyz[:, :2].mean(axis=0)
    _, sv, vt = np.linalg.svd(plan, full_matrices=False)
    if sv[0] <= 1e-9 * max(size, 1e-300):
        raise InputError(
            "the hinges are vertically above one another; the mechanism's plane is undefined",
            f"{where}.hinges",
        )
    ex = np.array([vt[0][0], vt[0][1], 0.0])
    a, d = points["hinges.A"], points["hinges.D"]
    if float((d - a) @ ex) < 0.0:
        ex = -ex
    normal = np.cross(np.array([0.0, 0.0, 1.0]), ex)
    centre = xyz.mean(axis=0)
    offsets = {n: float((points[n] - centre) @ normal) for n in names}
    tol = max(PLANE_RTOL * size, tolerance)
    worst = max(names, key=lambda n: abs(offsets[n]))
    if abs(offsets[worst]) > tol:
        listing = ", ".join(f"{n} {offsets[n]:+.4g}" for n in names)
        raise InputError(
            f"the hinges do not lie in one vertical plane: {worst} is {abs(offsets[worst]):.4g} m "
            f"off the plane fitted through all of them (tolerance {tol:.3g} m; offsets [m]: "
            f"{listing}). The mechanism is planar: put A, B, C and D (and the negative set) "
            "in the plane in which it moves",
            f"{where}.{worst}",
        )
    for n, u in lines.items():
        skew = math.asin(min(float(np.linalg.norm(np.cross(u, normal))), 1.0))
        if skew > HINGE_AXIS_TOL:
            tilt = math.degrees(math.asin(min(abs(float(u[2])), 1.0)))
            raise InputError(
                f"the hinge line is {math.degrees(skew):.3f} deg off the normal of the "
                f"mechanism's plane ({tilt:.3f} deg of it from the horizontal); a hinge turns "
                "about the plane's normal, so draw it horizontal and across the plane",
                f"{where}.{n}",
            )
    record = {
        "method": "vertical plane fitted through all hinges (least squares in plan); x from A "
        "towards D, z up; each hinge projected onto it",
        "x_axis": [float(v) for v in ex],
        "normal": [float(v) for v in normal],
        "hinge_offsets_m": {n: offsets[n] for n in names},
        "tolerance_m": tol,
        "hinge_axes": "line objects checked normal to the plane"
        if lines
        else "given as points: taken to turn about the plane's normal",
    }
    if lines and len(lines) < len(names):
        record["hinge_axes"] = (
            "line objects checked normal to the plane; points taken to turn about its normal"
        )
    return ex, normal, record


def _blocks(scene: Any, spec: Any) -> Tuple[List[Any], List[np.ndarray], List[str], List[str]]:

    props, verts, ids, notes = [], [], [], []
    seen: Dict[str, str] = {}
    for k, groups in enumerate(spec.blocks):
        parts = []
        pts = []
        for j, group in enumerate(groups):
            for obj in find_objects(scene, group.objects, f"{spec.id}.blocks[{k}][{j}]"):
                claim_once(seen, obj, f"{spec.id}.blocks[{k}][{j}]")
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


#: The hinges' names, in order along the linkage.
_NAMES = ("A", "B", "C", "D")


def _hinge_sets(
    spec: Any, scene: Any, where: str
) -> Tuple[Dict[str, np.ndarray], Dict[str, np.ndarray]]:
    """Return the points [m] and line directions of the spec's hinge sets, by ``set.name``.

    The positive set (``hinges``) always; the negative one (``hinges_negative``) when the
    mechanism is two-sided and gives it. Only the hinges that are line objects have a
    direction.
    """
    points: Dict[str, np.ndarray] = {}
    lines: Dict[str, np.ndarray] = {}
    sets = [("hinges", spec.hinges)]
    if spec.rocking == "two_sided" and spec.hinges_negative is not None:
        sets.append(("hinges_negative", spec.hinges_negative))
    for key, hinges in sets:
        for n in _NAMES:
            point, line = _hinge(scene, getattr(hinges, n), f"{where}.{key}.{n}")
            points[f"{key}.{n}"] = point
            if line is not None:
                lines[f"{key}.{n}"] = line
    return points, lines


def _derived_negative(
    hinges_pos: List[Tuple[float, float]],
    verts: List[np.ndarray],
    origin: np.ndarray,
    ex: np.ndarray,
    where: str,
) -> Tuple[List[Any], str]:
    """Derive the negative hinge set when the spec gives none, and the warning that says so.

    Parameters
    ----------
    hinges_pos : list of (x, z)
        The positive hinges in the mechanism's plane [m].
    verts : list of ndarray
        Each block's vertices [m]; the first and the last blocks are the columns.
    origin : ndarray
        Hinge A, the plane's origin [m].
    ex : ndarray
        The plane's horizontal unit axis, from A towards D.
    where : str
        The mechanism's id (for the warning).

    Returns
    -------
    hinges_neg : list of (x, z)
        Each hinge reflected across its column at its height (``_mirrored``) [m].
    note : str
        The warning, with the derived points in the scene's frame [m].
    """
    cols = [np.column_stack([(verts[k] - origin) @ ex, verts[k][:, 2] - origin[2]]) for k in (0, 2)]
    hinges_neg = _mirrored(hinges_pos, cols)
    derived = ", ".join(
        f"{n}' = {[round(float(v), 6) for v in origin + x * ex + np.array([0, 0, z])]}"
        for n, (x, z) in zip(_NAMES, hinges_neg)
    )
    note = (
        f"{where}: hinges_negative not given; derived by reflecting each hinge across "
        f"its column at its height: {derived} [m]. Give hinges_negative to set them"
    )
    return hinges_neg, note


def multi_block_sides(
    spec: Any, scene: Any
) -> Tuple[
    Dict[str, float], Optional[Dict[str, float]], Optional[float], Dict[str, Any], List[str]
]:
    """Constants of both hinge sets, eta (or None), a summary and object ids."""
    where = spec.id
    props, verts, ids, notes = _blocks(scene, spec)
    points, lines = _hinge_sets(spec, scene, where)
    pos3 = [points[f"hinges.{n}"] for n in _NAMES]
    origin = pos3[0]
    ex, normal, plane = _plane(points, lines, float(getattr(scene, "tolerance", 0.0)), where)

    def planar(p: np.ndarray) -> Tuple[float, float]:
        d = np.asarray(p, dtype=float) - origin
        return float(d @ ex), float(d[2])

    up = np.array([0.0, 0.0, 1.0])
    blocks = tuple(
        PlanarBody(
            float(p.mass),
            planar(p.com),
            float(normal @ np.asarray(p.inertia_com) @ normal),
            float(p.second_moment_about_plane(p.com, up)),
        )
        for p in props
    )
    hinges_pos = [planar(p) for p in pos3]
    res, direction = _solve(blocks, hinges_pos, f"{where}.hinges")
    positive = res.constants()
    negative = None
    eta = None
    virtual_work: Dict[str, Dict[str, float]] = {}
    vw = virtual_work_of(res.details, "lam_static")
    if vw is not None:
        virtual_work["positive"] = vw
    summary: Dict[str, Any] = {
        "plane_x_axis": [float(v) for v in ex],
        "plane": plane,
        "block_masses_kg": [b.mass for b in blocks],
        "positive": {"collapse_sense": direction, **{k: float(v) for k, v in res.details.items()}},
    }
    if spec.rocking == "two_sided":
        if spec.hinges_negative is not None:
            hinges_neg = [planar(points[f"hinges_negative.{n}"]) for n in _NAMES]
        else:
            hinges_neg, note = _derived_negative(hinges_pos, verts, origin, ex, where)
            summary["hinges_negative_derived"] = [list(h) for h in hinges_neg]
            notes.append(note)
        res_n, dir_n = _solve(blocks, hinges_neg, f"{where}.hinges_negative")
        if dir_n == direction:
            raise InputError(
                "the negative hinge set moves in the same sense as the positive "
                "one; give the mirrored set",
                f"{where}.hinges_negative",
            )
        negative = res_n.constants("negative")
        vw = virtual_work_of(res_n.details, "lam_static")
        if vw is not None:
            virtual_work["negative"] = vw
        eta = four_bar_restitution(blocks, tuple(hinges_pos), tuple(hinges_neg))
        # Both impact directions (theory §3.4); they differ for an asymmetric linkage.
        summary["restitution"] = {
            "rule": "momentum projection (theory §3.4); eta is the positive-to-negative value",
            "eta_pos_to_neg": eta,
            "eta_neg_to_pos": four_bar_restitution(blocks, tuple(hinges_neg), tuple(hinges_pos)),
        }
        summary["negative"] = {
            "collapse_sense": dir_n,
            **{k: float(v) for k, v in res_n.details.items()},
        }
    summary["warnings"] = notes
    summary["virtual_work"] = virtual_work
    return positive, negative, eta, summary, ids


def build_multi_block(spec: Any, scene: Any, table: Any) -> MechanismSides:
    """Builder of typology ``multi_block`` (docs/theory.md §2.4); ``table`` is unused."""
    positive, negative, eta, summary, ids = multi_block_sides(spec, scene)
    warnings = summary.pop("warnings")
    virtual_work = summary.pop("virtual_work")
    eta_info = summary.pop("restitution", {})
    return MechanismSides(
        positive,
        negative,
        eta,
        "momentum_projection",
        {"multi_block": summary},
        ids,
        warnings,
        eta_info,
        virtual_work=virtual_work,
    )
