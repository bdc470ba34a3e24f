"""Single rocking block (A1): objects and densities -> M, G, I_O, R, alpha -> constants.

Notation (theory §0, §2.1)
--------------------------
O : rotation axis (a line through ``point`` along unit ``direction``)
G : centre of mass [m]; M : mass [kg]
R : distance from the axis to G [m]; alpha : angle of OG from the vertical [rad]
I_O : moment of inertia about the axis [kg m²]

Constants per side (Eqs. 7-10): ``I0 = I_O``, ``K = M g R``, ``phi_cr = alpha``, ``Q = M R``,
so ``p_eq = sqrt(M g R / I_O)`` and ``lam = phi_ov = alpha``.

The negative rocking side (two-sided rocking) turns about the opposite base edge: the
user's ``axis_negative``, or the axis moved across the base footprint (the base vertices'
farthest extent from the axis, horizontally towards G).
"""

import math
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from cad_maths.geometry.cut import cut_by_plane
from cad_maths.geometry.massprops import combine, mass_properties
from cad_maths.geometry.validate import check_solid
from cad_maths.mechanisms.base import MechanismSides
from cad_maths.mechanisms.restitution import ONE_SIDED_RULES, housner_general, one_sided
from shared_schema.errors import GeometryError, InputError
from shared_schema.rules import G

__all__ = [
    "AXIS_TILT_TOL",
    "Body",
    "RockingSide",
    "body_from_spec",
    "claim_once",
    "find_objects",
    "negative_axis",
    "resolve_axis",
    "rocking_side",
    "side_virtual_work",
]

#: Largest tilt of a "horizontal" axis [rad] unless the spec allows inclined axes.
AXIS_TILT_TOL = 1e-3
#: Tolerance, relative to the body size, for an axis touching the body's base.
TOUCH_RTOL = 1e-3


@dataclass
class Body:
    """The solids of a mechanism after cracks, with their mass properties."""

    props: Any  # cad_maths.geometry.massprops.MassProps (combined)
    parts: List[Any]  # MassProps per solid
    meshes: List[Any]  # TriMesh per solid, after cracks
    vertices: np.ndarray  # (n, 3) all vertices of the cut solids [m]
    object_ids: List[str]
    warnings: List[str] = field(default_factory=list)

    @property
    def size(self) -> float:
        """Diagonal of the bounding box [m]."""
        return float(np.linalg.norm(self.vertices.max(axis=0) - self.vertices.min(axis=0)))


@dataclass
class RockingSide:
    """Geometry of one rocking side.

    Attributes
    ----------
    point, direction : (3,) float
        Axis point and unit direction [m].
    r_vec : (3,) float
        Perpendicular vector from the axis to G [m].
    outward : (3,) float
        Horizontal unit vector in the direction of collapse (away from G).
    R, alpha, I_O : float
        [m], [rad], [kg m²].
    """

    point: np.ndarray
    direction: np.ndarray
    r_vec: np.ndarray
    outward: np.ndarray
    R: float
    alpha: float
    I_O: float

    def polar(self, p: Sequence[float]) -> Tuple[float, float]:
        """Distance and angle from the vertical (positive towards G) of a point [m, rad]."""
        d = np.asarray(p, dtype=float) - self.point
        r = d - np.dot(d, self.direction) * self.direction
        return float(np.linalg.norm(r)), math.atan2(float(np.dot(r, -self.outward)), float(r[2]))


def find_objects(scene: Any, selectors: Sequence[Any], where: str) -> List[Any]:
    """Return the objects matching every selector; one that matches nothing is an error."""
    found: List[Any] = []
    for sel in selectors:
        hits = scene.find(sel)
        if not hits:
            raise InputError(f"no object matches {sel!r}", where)
        found.extend(hits)
    return found


def claim_once(seen: Dict[str, str], obj: Any, where: str) -> None:
    """Refuse an object that two selectors of one body pick (it would be counted twice).

    ``seen`` maps the ids claimed so far to the group that claimed them; the spec refuses a
    selector written twice, this catches one object reached two ways (by name and by id, or
    by its name and its layer).
    """
    if obj.id in seen:
        raise InputError(
            f"{obj.label()} is selected twice ({seen[obj.id]} and {where}); it would be counted "
            "twice (its mass, I0 and Q doubled): select each object once",
            where,
        )
    seen[obj.id] = where


def _crack_plane(scene: Any, crack: Any, where: str) -> Tuple[np.ndarray, np.ndarray]:
    if crack.object is not None:
        objs = find_objects(scene, [crack.object], where)
        return scene.plane(objs[0])
    p = np.asarray(crack.points, dtype=float)
    n = np.cross(p[1] - p[0], p[2] - p[0])
    norm = float(np.linalg.norm(n))
    if norm == 0.0:
        raise InputError("the three points are collinear", where)
    return p[0], n / norm


def body_from_spec(spec: Any, scene: Any, axis_mid: np.ndarray) -> Body:
    """Validate the spec's solids, cut them by its cracks and compute their mass properties."""
    where = f"{spec.id}"
    solids: List[Tuple[Any, float, str]] = []  # (mesh, density, object id)
    ids: List[str] = []
    warnings: List[str] = []
    seen: Dict[str, str] = {}
    for k, group in enumerate(spec.groups):
        for obj in find_objects(scene, group.objects, f"{where}.groups[{k}]"):
            claim_once(seen, obj, f"{where}.groups[{k}]")
            mesh, notes = check_solid(scene.mesh(obj))
            warnings.extend(notes)
            solids.append((mesh, group.density, obj.id))
            ids.append(obj.id)
    for k, crack in enumerate(getattr(spec, "cracks", [])):  # a two-block wall has none
        point, normal = _crack_plane(scene, crack, f"{where}.cracks[{k}]")
        keep = crack.keep
        said = f"keep = {crack.keep!r}"
        if crack.keep_point is not None:
            # The user's point on the side to keep decides, whatever the plane's normal.
            said = f"keep_point = {list(crack.keep_point)}"
            side = float(np.dot(np.asarray(crack.keep_point, dtype=float) - point, normal))
            if abs(side) <= 1e-9:  # [m]: on the plane, the side is undefined
                raise InputError("keep_point lies on the crack plane", f"{where}.cracks[{k}]")
            keep = "positive" if side > 0.0 else "negative"
        elif keep == "axis_side":
            keep = "positive" if float(np.dot(axis_mid - point, normal)) >= 0.0 else "negative"
        sign = 1.0 if keep == "positive" else -1.0
        only = None
        if getattr(crack, "objects", None) is not None:
            only = {o.id for o in find_objects(scene, crack.objects, f"{where}.cracks[{k}]")}
            missing = only - set(ids)
            if missing:
                raise InputError(
                    f"objects {sorted(missing)} are not in the body (list them in its groups)",
                    f"{where}.cracks[{k}].objects",
                )
        kept: List[Tuple[Any, float, str]] = []
        cut_any = False
        for mesh, density, oid in solids:
            if only is not None and oid not in only:
                kept.append((mesh, density, oid))
                continue
            dist = (mesh.vertices - point) @ normal * sign
            if dist.min() >= 0.0:
                kept.append((mesh, density, oid))
            elif dist.max() > 0.0:
                kept.append((cut_by_plane(mesh, point, normal, keep=keep), density, oid))
                cut_any = True
        if not cut_any:
            raise GeometryError(
                f"{where}.cracks[{k}] ({said}): the crack plane misses the body (it cuts no solid)"
            )
        if not kept:
            raise GeometryError(
                f"{where}.cracks[{k}] ({said}): nothing is left of the body on the kept side "
                f"(the {keep} side of the plane through {[round(float(v), 6) for v in point]} "
                f"with normal {[round(float(v), 6) for v in normal]})"
            )
        solids = kept
    parts = [mass_properties(mesh, density) for mesh, density, _ in solids]
    props = combine(parts, name=spec.id)
    verts = np.vstack([mesh.vertices for mesh, _, _ in solids])
    return Body(props, parts, [mesh for mesh, _, _ in solids], verts, ids, warnings)


def resolve_axis(scene: Any, axis: Any, where: str) -> Tuple[np.ndarray, np.ndarray]:
    """Axis end points [m] from a line object or from the spec's two points."""
    if axis.object is not None:
        objs = find_objects(scene, [axis.object], where)
        start, end = scene.line(objs[0])
    else:
        start, end = np.asarray(axis.start, dtype=float), np.asarray(axis.end, dtype=float)
    if float(np.linalg.norm(end - start)) == 0.0:
        raise InputError("the axis has zero length", where)
    return np.asarray(start, dtype=float), np.asarray(end, dtype=float)


def _base_hint(body: Body, start: np.ndarray, end: np.ndarray, tol: float) -> str:
    """Say where the body's base is, for an axis that does not touch the body (issue #36).

    A rocking axis is an edge of the base the body stands on; an axis drawn at mid-height,
    or beside the body, gets the base's height and plan extent and, where it is above the
    base, its own height.
    """
    v = body.vertices
    z0 = float(v[:, 2].min())
    base = v[v[:, 2] <= z0 + tol]
    (x0, y0), (x1, y1) = base[:, :2].min(axis=0), base[:, :2].max(axis=0)
    hint = (
        f"; a rocking axis is an edge of the body's base, where it rests on its support: the "
        f"base is at z = {z0:.4g} m, over x {x0:.4g} to {x1:.4g} m, y {y0:.4g} to {y1:.4g} m"
    )
    z_axis = 0.5 * float(start[2] + end[2])
    if z_axis > z0 + tol:
        hint += (
            f", and the axis is at z = {z_axis:.4g} m, {z_axis - z0:.4g} m above it: draw it "
            "along the bottom edge the body rocks about"
        )
    return hint


def rocking_side(
    body: Body, start: np.ndarray, end: np.ndarray, *, where: str, allow_tilt: bool = False
) -> RockingSide:
    """Check an axis against the body and compute R, alpha and I_O about it.

    Raises
    ------
    GeometryError
        Axis not horizontal (unless allowed), not touching the body's base, or the centre
        of mass not above it.
    """
    u = (end - start) / float(np.linalg.norm(end - start))
    tilt = math.asin(min(abs(float(u[2])), 1.0))
    if tilt > AXIS_TILT_TOL and not allow_tilt:
        raise GeometryError(
            f"{where}: the axis is inclined by {math.degrees(tilt):.3f} deg; a rocking axis "
            "must be horizontal (set allow_non_horizontal_axis to accept it)"
        )
    tol = TOUCH_RTOL * body.size
    d = body.vertices - start
    perp = d - np.outer(d @ u, u)
    dist = np.linalg.norm(perp, axis=1)
    if dist.min() > tol:
        raise GeometryError(
            f"{where}: the axis does not touch the body (closest vertex {dist.min():.4f} m away)"
            + _base_hint(body, start, end, tol)
        )
    # Height of the axis where each vertex projects on it (an inclined axis rises along u).
    below = float(np.max(start[2] + u[2] * (d @ u) - body.vertices[:, 2]))
    if below > tol:
        raise GeometryError(
            f"{where}: the axis is not at the body's base (the body reaches {below:.4f} m below it)"
        )
    g = np.asarray(body.props.com, dtype=float)
    dg = g - start
    r_vec = dg - np.dot(dg, u) * u
    horiz = r_vec.copy()
    horiz[2] = 0.0
    h_norm = float(np.linalg.norm(horiz))
    if r_vec[2] <= 0.0:
        raise GeometryError(f"{where}: the centre of mass is not above the axis")
    if h_norm <= tol * 1e-3:
        raise GeometryError(
            f"{where}: the centre of mass is vertically above the axis (alpha = 0): the "
            "body is in unstable equilibrium; check the axis"
        )
    outward = -horiz / h_norm
    big_r = float(np.linalg.norm(r_vec))
    alpha = math.atan2(h_norm, float(r_vec[2]))
    i_o = float(body.props.inertia_about_axis(start, u))
    return RockingSide(start, u, r_vec, outward, big_r, alpha, i_o)


def negative_axis(body: Body, side: RockingSide) -> Tuple[np.ndarray, np.ndarray]:
    """Return the opposite base edge: the axis moved across the base footprint towards G."""
    tol = TOUCH_RTOL * body.size
    z0 = float(side.point[2])
    base = body.vertices[body.vertices[:, 2] <= z0 + tol]
    inward = -side.outward
    reach = float(np.max((base - side.point) @ inward))
    if reach <= tol:
        raise GeometryError("cannot derive the negative-side axis: the base has no width")
    start = side.point + reach * inward
    return start, start + side.direction


def side_constants(body: Body, side: RockingSide) -> Dict[str, float]:
    """Eqs. 7-10: I0, K, Q, phi_cr, M_F of a plain block about one axis."""
    m = float(body.props.mass)
    return {"I0": side.I_O, "K": m * G * side.R, "Q": m * side.R, "phi_cr": side.alpha, "M_F": 0.0}


def side_virtual_work(body: Body, side: RockingSide) -> Dict[str, float]:
    """Virtual-work quantities at rest of a plain block about one axis (theory §11.1).

    A unit virtual rotation moves a point at height ``z`` above the axis by ``δx = z``
    horizontally, so ``S = M z_G``, ``J`` is the second moment of the mass about the
    horizontal plane through the axis, and ``alpha0 = x_G / z_G = tan(alpha)``. The block
    is one term of Circolare 2019 [C8.7.1.5]: ``J_blocks = M z_G² = S²/M``.
    """
    m = float(body.props.mass)
    n = np.cross(side.outward, side.direction)
    n = n / float(np.linalg.norm(n))
    if n[2] < 0.0:
        n = -n
    j = float(body.props.second_moment_about_plane(side.point, n))
    s = m * side.R * math.cos(side.alpha)
    return {"alpha0": math.tan(side.alpha), "mass": m, "S": s, "J": j, "J_blocks": s * s / m}


def side_summary(side: RockingSide) -> Dict[str, Any]:
    """Geometry of a side for the constants file's summary."""
    return {
        "axis_point_m": [float(v) for v in side.point],
        "axis_direction": [float(v) for v in side.direction],
        "R_m": side.R,
        "alpha_rad": side.alpha,
        "I_O_kg_m2": side.I_O,
    }


def eta_two_sided(body: Body, pos: RockingSide, neg: RockingSide) -> Tuple[float, Dict[str, float]]:
    """Housner's general form for both impact directions; the larger (conservative) is used."""
    m = float(body.props.mass)
    u = pos.direction
    i_g = float(u @ np.asarray(body.props.inertia_com) @ u)
    g = np.asarray(body.props.com, dtype=float)

    def perp(point: np.ndarray) -> np.ndarray:
        d = g - point
        return d - np.dot(d, u) * u

    r_pos, r_neg = perp(pos.point), perp(neg.point)
    to_neg = housner_general(m, i_g, r_pos, r_neg, neg.I_O)
    to_pos = housner_general(m, i_g, r_neg, r_pos, pos.I_O)
    return max(to_neg, to_pos), {"eta_pos_to_neg": to_neg, "eta_neg_to_pos": to_pos}


def rigid_body(spec: Any, scene: Any) -> Tuple[Body, RockingSide, Dict[str, Any]]:
    """Load a mechanism's body and its positive rocking side, with the geometry summary.

    The start of every typology that rocks one rigid body about a drawn axis (single
    block, loaded wall, and the two-block wall before its split).

    Returns
    -------
    body : Body
        The solids with their densities, cracks applied.
    side : RockingSide
        The positive side about ``spec.axis``.
    geometry : dict
        ``mass_kg``, ``volume_m3``, ``com_m``, ``top_m`` (the height of the moving part's
        highest point above the positive hinge's axis point [m]: where a tie at the top of
        the moving part goes) and the positive side's summary.
    """
    where = spec.id
    start, end = resolve_axis(scene, spec.axis, f"{where}.axis")
    body = body_from_spec(spec, scene, 0.5 * (start + end))
    pos = rocking_side(
        body, start, end, where=f"{where}.axis", allow_tilt=spec.allow_non_horizontal_axis
    )
    geometry: Dict[str, Any] = {
        "mass_kg": float(body.props.mass),
        "volume_m3": float(sum(p.volume for p in body.parts)),
        "com_m": [float(v) for v in body.props.com],
        "top_m": float(body.vertices[:, 2].max() - pos.point[2]),
        "positive": side_summary(pos),
    }
    return body, pos, geometry


def _negative_side(spec: Any, scene: Any, body: Body, pos: RockingSide) -> RockingSide:
    """Return the negative side of a two-sided body (``axis_negative`` or the opposite edge)."""
    where = spec.id
    if spec.axis_negative is not None:
        n_start, n_end = resolve_axis(scene, spec.axis_negative, f"{where}.axis_negative")
    else:
        n_start, n_end = negative_axis(body, pos)
    neg = rocking_side(
        body,
        n_start,
        n_end,
        where=f"{where}.axis_negative",
        allow_tilt=spec.allow_non_horizontal_axis,
    )
    if float(np.dot(neg.outward, pos.outward)) >= 0.0:
        com = ", ".join(f"{c:.4g}" for c in body.props.com)
        raise GeometryError(
            f"{where}.axis_negative: the negative-side axis must lie on the other side of the "
            f"centre of mass from the axis, but both lie on the same side of it (the centre of "
            f"mass is at ({com}) m); the negative side rocks about the base's opposite edge"
        )
    return neg


def rigid_body_sides(
    spec: Any,
    scene: Any,
    body: Body,
    pos: RockingSide,
    geometry: Dict[str, Any],
    positive: Dict[str, float],
    restitution_body: Tuple[float, float, float, float],
    warnings: List[str],
    virtual_work: Optional[Dict[str, Dict[str, float]]] = None,
) -> MechanismSides:
    """Finish a rigid body's sides: the negative side (two-sided) and eta.

    Parameters
    ----------
    restitution_body : (M [kg], R [m], alpha [rad], I_O [kg m²])
        The body the one-sided restitution rule (Eq. 26) sees.
    virtual_work : dict, optional
        The positive side's virtual-work quantities (``{"positive": {...}}``); default
        those of the plain block. The negative side's are always the plain block's.
    """
    negative = None
    eta_info: Dict[str, Any]
    if virtual_work is None:
        virtual_work = {"positive": side_virtual_work(body, pos)}
    if spec.rocking == "two_sided":
        neg = _negative_side(spec, scene, body, pos)
        negative = side_constants(body, neg)
        virtual_work["negative"] = side_virtual_work(body, neg)
        geometry["negative"] = side_summary(neg)
        eta, eta_info = eta_two_sided(body, pos, neg)
        source = "housner_general"
    else:
        source = spec.eta_rule or "one_sided_eq26"
        eta = one_sided(*restitution_body, source)
        eta_info = {"rule": ONE_SIDED_RULES[source]}
    return MechanismSides(
        positive,
        negative,
        eta,
        source,
        geometry,
        body.object_ids,
        warnings,
        eta_info,
        virtual_work,
    )


def build_single_block(spec: Any, scene: Any, table: Any) -> MechanismSides:
    """Builder of typology ``single_block`` (docs/theory.md §2.1); ``table`` is unused."""
    body, pos, geometry = rigid_body(spec, scene)
    positive = side_constants(body, pos)
    inertia = (float(body.props.mass), pos.R, pos.alpha, pos.I_O)
    return rigid_body_sides(
        spec, scene, body, pos, geometry, positive, inertia, list(body.warnings)
    )
