"""Wall with added masses and static forces (A2, theory §2.2, Eqs. 11-16).

Added elements and how they enter:

* **floors**: classified from how they meet the wall. A floor whose contact with the wall
  is a horizontal face (it rests on the wall top or a ledge; contact normal within
  ``BEARING_ANGLE`` of vertical) is *load-bearing*: its share (``tributary``) of weight and
  inertia acts on the wall. A floor that only abuts the wall's face (vertical contact) is
  *non-load-bearing*: only the horizontal inertia of its share is passed to the wall. Both
  act at the centroid of the contact area. A floor that touches no wall is an error.
* **roof**: its share of weight is a load-bearing mass at its contact with the wall; its
  thrust ``H = W_r L/(8 f)`` (span and rise from its bounding box in the wall's frame) is an
  outward static force there, unless it is a tied truss.
* **vaults**: the thrust table (``thrust.ThrustTable``) gives the vertical load ``V`` and
  thrust ``H`` from the construction class and rise/span (bounding box); ``V/g`` is a
  load-bearing mass and ``H`` an outward static force, both at the springing (the contact
  with the wall).
* **tie-bars**: a restraining (inward) force where the bar meets the façade's outer face
  (the vertical plane through the axis), on the outward swing only: a bar pulls while the
  motion stretches it and goes slack towards its anchorage, so the negative side of a
  two-sided wall with tie-bars alone is the plain wall's (theory §1.8).

Constants (about ``phi_cr = alpha_c``): ``I0 = I_O + sum M_i R_i²`` (added masses as point
masses), ``K = M_c g R_c``, ``Q = M_c* R_c* cos(alpha_c* - alpha_c)``,
``M_F = sum F_k R_k cos(alpha_k - alpha_c)``; ``lam``, ``p_eq`` and ``phi_ov`` follow (Eq. 16).
The summary also reports the exact static multiplier at rest for comparison (§2.2 check).
"""

import math
from dataclasses import dataclass, field
from typing import Any, Dict, List, Tuple

import numpy as np

from cad_maths.geometry.contact import find_contact
from cad_maths.geometry.frames import bounding_box_in_frame
from cad_maths.geometry.massprops import mass_properties
from cad_maths.geometry.validate import check_solid
from cad_maths.mechanisms.base import MechanismSides
from cad_maths.mechanisms.single import find_objects, rigid_body, rigid_body_sides
from cad_maths.mechanisms.thrust import roof_thrust
from shared_schema.errors import GeometryError, InputError
from shared_schema.rules import G

__all__ = [
    "BEARING_ANGLE",
    "SLACK_TIES",
    "contact_tolerance",
    "element_solids",
    "largest_contact",
    "loaded_side",
]

#: A contact whose normal is within this angle of vertical counts as bearing [rad].
BEARING_ANGLE = math.radians(30.0)


def element_solids(
    scene: Any, selectors: Any, where: str
) -> Tuple[List[Any], List[str], List[str]]:
    """Return the validated solids of an element's objects, their ids and repair warnings."""
    meshes, ids, notes = [], [], []
    for obj in find_objects(scene, selectors, where):
        mesh, warn = check_solid(scene.mesh(obj))
        meshes.append(mesh)
        ids.append(obj.id)
        notes.extend(warn)
    return meshes, ids, notes


#: Contact tolerance when the file has no absolute tolerance [m].
CONTACT_TOL = 1e-6


def contact_tolerance(scene: Any) -> float:
    """Return the file's absolute tolerance [m], or ``CONTACT_TOL`` when it has none."""
    tol = float(getattr(scene, "tolerance", 0.0) or 0.0)
    return tol if tol > 0.0 else CONTACT_TOL


#: Face directions of each solid tried as separating axes (the largest faces first).
SEPARATION_AXES = 64


def _separation(a: Any, b: Any) -> float:
    """Gap (> 0) or overlap (< 0) of two solids along the clearest of their face normals [m].

    The separating-axis reading of the solids' convex hulls: along each face normal of
    either solid (the largest ``SEPARATION_AXES`` faces of each) the gap between their
    extents; the largest is the gap (for solids that face each other it is the distance
    between the faces, whatever the scene's orientation), and where every axis overlaps,
    the least overlap.
    """
    axes = [np.eye(3)]
    for m in (a, b):
        tri = m.vertices[m.faces]
        normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        size = np.linalg.norm(normal, axis=1)
        keep = np.argsort(-size)[:SEPARATION_AXES]
        keep = keep[size[keep] > 0.0]
        axes.append(normal[keep] / size[keep, None])
    n = np.vstack(axes)
    pa, pb = a.vertices @ n.T, b.vertices @ n.T
    gaps = np.maximum(pb.min(axis=0) - pa.max(axis=0), pa.min(axis=0) - pb.max(axis=0))
    return float(gaps.max())


def largest_contact(
    meshes: List[Any], wall: List[Any], where: str, tol: float = CONTACT_TOL
) -> Tuple[float, np.ndarray, np.ndarray]:
    """Return the largest planar contact between an element's solids and the wall's solids.

    Faces within ``tol`` [m] of each other count as in contact. When there is none, the
    error gives the gap (or overlap) between the element and the nearest wall solid.
    """
    best = None
    for a in meshes:
        for b in wall:
            hit = find_contact(a, b, tol=tol)
            if hit is not None and (best is None or hit[0] > best[0]):
                best = hit
    if best is None:
        gap = min((_separation(a, b) for a in meshes for b in wall), key=abs)
        how = (
            f"a gap of {1000 * gap:.4g} mm"
            if gap > 0.0
            else f"an overlap of {-1000 * gap:.4g} mm (solids that interpenetrate share no face)"
        )
        raise GeometryError(
            f"{where}: touches no wall (no shared face with the mechanism's solids within the "
            f"tolerance {1000 * tol:.3g} mm): between it and the nearest wall solid, across "
            f"their faces, {how}"
        )
    return best


def _box(meshes: List[Any], side: Any) -> Tuple[float, float, float]:
    """Extent normal to the wall, along the wall, and height of the elements [m]."""
    lo, hi = None, None
    for mesh in meshes:
        a, b = bounding_box_in_frame(mesh, side.point, side.outward, side.direction)
        lo = a if lo is None else np.minimum(lo, a)
        hi = b if hi is None else np.maximum(hi, b)
    assert lo is not None and hi is not None
    ext = hi - lo
    return float(ext[0]), float(ext[1]), float(abs(ext[2]))


Loads = List[Tuple[float, np.ndarray, str]]
Result = Tuple[Dict[str, float], Dict[str, Any], List[str]]


def _default_share(label: str, share: float, mass: float) -> str:
    """Say that a floor's or roof's share on the wall is the default (issue #14)."""
    return (
        f"{label}: tributary not given; the wall carries the default {share:g} of its weight "
        f"and inertia ({mass:.6g} kg, a slab spanning between the wall and one parallel "
        "support). Give 'tributary' to set the share"
    )


@dataclass
class _Loading:
    """What the added elements put on the wall, gathered element by element."""

    #: Load-bearing masses: (mass [kg], point, label).
    bearing: Loads = field(default_factory=list)
    #: Masses whose horizontal inertia alone acts on the wall: (mass [kg], point, label).
    nonbearing: Loads = field(default_factory=list)
    #: Static forces, outward positive: (force [N], point, label).
    forces: Loads = field(default_factory=list)
    #: The summary's record of each element.
    elements: List[Dict[str, Any]] = field(default_factory=list)
    #: Warnings (repairs, defaults used).
    notes: List[str] = field(default_factory=list)


def _add_floors(loading: _Loading, spec: Any, scene: Any, wall: List[Any], tol: float) -> None:
    """Add the floors: load-bearing or not from how they meet the wall (module docstring).

    Parameters
    ----------
    loading : _Loading
        What the elements put on the wall so far; extended in place.
    spec : MechanismSpec
        With ``floors`` as declared.
    scene : Scene
        The scene.
    wall : list of Mesh
        The wall's solids (after cracks).
    tol : float
        Contact tolerance [m].
    """
    for k, floor in enumerate(spec.floors or []):
        label = f"{spec.id}.floors[{k}]"
        meshes, ids, warn = element_solids(scene, floor.objects, label)
        loading.notes.extend(warn)
        mass = floor.tributary * sum(mass_properties(m, floor.density).mass for m in meshes)
        if "tributary" not in floor.model_fields_set:
            loading.notes.append(_default_share(label, floor.tributary, mass))
        area, point, normal = largest_contact(meshes, wall, label, tol)
        is_bearing = abs(float(normal[2])) >= math.cos(BEARING_ANGLE)
        (loading.bearing if is_bearing else loading.nonbearing).append((mass, point, label))
        loading.elements.append(
            {
                "element": label,
                "objects": ids,
                "kind": "floor",
                "load_bearing": is_bearing,
                "mass_kg": mass,
                "contact_area_m2": area,
                "at_m": [float(v) for v in point],
            }
        )


def _add_roof(
    loading: _Loading, spec: Any, scene: Any, wall: List[Any], tol: float, side: Any
) -> None:
    """Add the roof: its share of weight as a bearing mass, its thrust ``W_r L/(8 f)`` outward.

    Parameters
    ----------
    loading : _Loading
        What the elements put on the wall so far; extended in place.
    spec : MechanismSpec
        With ``roof`` as declared (nothing is added without one).
    scene : Scene
        The scene.
    wall : list of Mesh
        The wall's solids (after cracks).
    tol : float
        Contact tolerance [m].
    side : single.RockingSide
        The rocking side (the frame of the roof's span and rise).
    """
    if spec.roof is None:
        return
    label = f"{spec.id}.roof"
    roof = spec.roof
    meshes, ids, warn = element_solids(scene, roof.objects, label)
    loading.notes.extend(warn)
    weight = G * sum(mass_properties(m, roof.density).mass for m in meshes)
    _, point, _ = largest_contact(meshes, wall, label, tol)
    span, _, rise = _box(meshes, side)
    thrust = roof_thrust(weight, span, rise, roof.tied)
    loading.bearing.append((roof.tributary * weight / G, point, label))
    if "tributary" not in roof.model_fields_set:
        loading.notes.append(_default_share(label, roof.tributary, roof.tributary * weight / G))
    if thrust > 0.0:
        loading.forces.append((thrust, point, label))
    loading.elements.append(
        {
            "element": label,
            "objects": ids,
            "kind": "roof",
            "weight_N": weight,
            "bearing_mass_kg": roof.tributary * weight / G,
            "span_m": span,
            "rise_m": rise,
            "thrust_N": thrust,
            "tied": roof.tied,
            "at_m": [float(v) for v in point],
        }
    )


def _add_vaults(
    loading: _Loading, spec: Any, scene: Any, wall: List[Any], tol: float, side: Any, table: Any
) -> None:
    """Add the vaults: ``V/g`` a bearing mass and ``H`` an outward force at the springing.

    Parameters
    ----------
    loading : _Loading
        What the elements put on the wall so far; extended in place.
    spec : MechanismSpec
        With ``vaults`` as declared.
    scene : Scene
        The scene.
    wall : list of Mesh
        The wall's solids (after cracks).
    tol : float
        Contact tolerance [m].
    side : single.RockingSide
        The rocking side (the frame of the vault's span, length and rise).
    table : thrust.ThrustTable
        Vault thrust table: ``V`` and ``H`` per plan area [N/m²].
    """
    for k, vault in enumerate(spec.vaults or []):
        label = f"{spec.id}.vaults[{k}]"
        meshes, ids, warn = element_solids(scene, vault.objects, label)
        loading.notes.extend(warn)
        span_n, span_p, rise = _box(meshes, side)
        if span_n <= 0.0 or span_p <= 0.0 or rise <= 0.0:
            raise GeometryError(f"{label}: degenerate bounding box (span or rise is zero)")
        v_area, h_area = table.per_area(vault.construction_class, rise / span_n, label)
        plan = span_n * span_p
        _, point, _ = largest_contact(meshes, wall, label, tol)
        loading.bearing.append((v_area * plan / G, point, label))
        loading.forces.append((h_area * plan, point, label))
        loading.elements.append(
            {
                "element": label,
                "objects": ids,
                "kind": "vault",
                "construction_class": vault.construction_class,
                "span_m": span_n,
                "length_m": span_p,
                "rise_m": rise,
                "rise_span": rise / span_n,
                "V_N": v_area * plan,
                "H_N": h_area * plan,
                "table": table.name,
                "at_m": [float(v) for v in point],
            }
        )


def _add_tie_bars(loading: _Loading, spec: Any, scene: Any, body: Any, side: Any) -> None:
    """Add the tie-bars: a restraining (inward) force where each meets the façade's outer face.

    Parameters
    ----------
    loading : _Loading
        What the elements put on the wall so far; extended in place.
    spec : MechanismSpec
        With ``tie_bars`` as declared.
    scene : Scene
        The scene.
    body : single.Body
        The wall (its size sets the tolerance of the crossing).
    side : single.RockingSide
        The rocking side (its outer face).
    """
    for k, tie in enumerate(spec.tie_bars or []):
        label = f"{spec.id}.tie_bars[{k}]"

        obj = find_objects(scene, [tie.object], label)[0]
        start, end = scene.line(obj)
        point = _face_point(start, end, side, body.size, label)
        loading.forces.append((-tie.force, point, label))
        loading.elements.append(
            {
                "element": label,
                "objects": [obj.id],
                "kind": "tie_bar",
                "force_N": tie.force,
                "at_m": [float(v) for v in point],
            }
        )


def loaded_side(spec: Any, scene: Any, body: Any, side: Any, table: Any) -> Result:
    """Constants of a loaded wall about one axis, its summary and warnings.

    The elements are added in the spec's order of kinds (floors, roof, vaults, tie-bars),
    then the constants follow from the gathered masses and forces (``_constants``).

    Parameters
    ----------
    spec : MechanismSpec
        With ``floors``, ``roof``, ``vaults`` and ``tie_bars`` as declared.
    scene : Scene
        The scene.
    body : single.Body
        The wall (and adjacent walls) after cracks.
    side : single.RockingSide
        The rocking side.
    table : thrust.ThrustTable
        Vault thrust table.
    """
    loading = _Loading()
    wall = body.meshes
    tol = contact_tolerance(scene)
    _add_floors(loading, spec, scene, wall, tol)
    _add_roof(loading, spec, scene, wall, tol, side)
    _add_vaults(loading, spec, scene, wall, tol, side, table)
    _add_tie_bars(loading, spec, scene, body, side)
    return _constants(
        body,
        side,
        loading.bearing,
        loading.nonbearing,
        loading.forces,
        loading.elements,
        loading.notes,
    )


def _face_point(
    start: np.ndarray, end: np.ndarray, side: Any, size: float, where: str
) -> np.ndarray:
    """Where a tie-bar line crosses the façade's outer face (vertical plane through the axis)."""
    d = end - start
    denom = float(np.dot(d, side.outward))
    if abs(denom) < 1e-12 * max(float(np.linalg.norm(d)), 1.0):
        raise GeometryError(f"{where}: the tie-bar is parallel to the façade and never meets it")
    t = float(np.dot(side.point - start, side.outward)) / denom
    tol = 1e-3 * size / max(float(np.linalg.norm(d)), 1e-12)
    if not -tol <= t <= 1.0 + tol:
        raise GeometryError(f"{where}: the tie-bar does not reach the façade's outer face")
    point = start + t * d
    # A tie pulls the wall towards its anchorage, the line's end farther from the face: the
    # force enters as restraining (inward) only when that end lies inside the building.
    far = max((start, end), key=lambda q: abs(float(np.dot(q - point, side.outward))))
    if float(np.dot(far - point, side.outward)) > 0.0:
        raise GeometryError(
            f"{where}: the tie-bar runs outward from the façade's outer face (the face "
            "through the axis), so the positive swing would not stretch it; a tie-bar is "
            "anchored inside the building and pulls the wall towards it: draw it from the "
            "outer face into the building, with the axis on the outer face"
        )
    return point


def _constants(
    body: Any,
    side: Any,
    bearing: Loads,
    nonbearing: Loads,
    forces: Loads,
    elements: List[Dict[str, Any]],
    notes: List[str],
) -> Result:
    m_w = float(body.props.mass)
    g_w = np.asarray(body.props.com, dtype=float)
    m_c = m_w + sum(m for m, _, _ in bearing)
    g_c = (m_w * g_w + sum(m * p for m, p, _ in bearing)) / m_c
    m_cs = m_c + sum(m for m, _, _ in nonbearing)
    g_cs = (m_c * g_c + sum(m * p for m, p, _ in nonbearing)) / m_cs
    r_c, a_c = side.polar(g_c)
    r_cs, a_cs = side.polar(g_cs)
    if not 0.0 < a_c < math.pi / 2:
        raise GeometryError("the loaded wall's centre of mass is not inside its base")
    i0 = side.I_O + sum(m * side.polar(p)[0] ** 2 for m, p, _ in bearing)
    f_tot = sum(f for f, _, _ in forces)
    m_f = 0.0
    fx = 0.0
    fz = 0.0
    for f, p, _ in forces:
        r_k, a_k = side.polar(p)
        m_f += f * r_k * math.cos(a_k - a_c)
        fz += f * r_k * math.cos(a_k)
        fx += f * r_k * math.sin(a_k)
    k = m_c * G * r_c
    q = m_cs * r_cs * math.cos(a_cs - a_c)
    # Exact static multiplier at rest (virtual work at phi = 0), for comparison with lam.

    def z(p: np.ndarray) -> float:  # height above the axis
        r, a = side.polar(p)
        return float(r * math.cos(a))

    def x(p: np.ndarray) -> float:  # horizontal distance from the axis towards G
        r, a = side.polar(p)
        return float(r * math.sin(a))

    over = m_w * z(g_w) + sum(m * z(p) for m, p, _ in bearing + nonbearing)
    lam_exact = (G * m_c * x(g_c) - sum(f * z(p) for f, p, _ in forces)) / (G * over)
    # theory §11.1: a unit virtual rotation moves each mass by its height above the axis;
    # the added masses are points, the wall a solid (second moment about the axis plane).
    plane_n = np.cross(side.outward, side.direction)
    plane_n = plane_n / float(np.linalg.norm(plane_n))
    j_wall = float(body.props.second_moment_about_plane(side.point, plane_n))
    virtual_work = {
        "alpha0": lam_exact,
        "mass": m_cs,
        "S": over,
        "J": j_wall + sum(m * z(p) ** 2 for m, p, _ in bearing + nonbearing),
        # Circolare 2019 [C8.7.1.5]: the wall and what it carries are one block, one term
        # at the centroid of its forces.
        "J_blocks": over * over / m_cs,
    }
    summary: Dict[str, Any] = {
        "M_c_kg": m_c,
        "R_c_m": r_c,
        "alpha_c_rad": a_c,
        "M_c_star_kg": m_cs,
        "R_c_star_m": r_cs,
        "alpha_c_star_rad": a_cs,
        "F_N": f_tot,
        "static_multiplier_exact": lam_exact,
        "virtual_work": virtual_work,
        "elements": elements,
    }
    if f_tot != 0.0:
        summary["R_f_m"] = math.hypot(fx, fz) / abs(f_tot)
        summary["alpha_f_rad"] = math.atan2(fx / f_tot, fz / f_tot)
    if m_f >= k * a_c:
        raise InputError(
            f"the static forces alone overturn the wall (M_F = {m_f:.4g} N m >= K phi_cr = "
            f"{k * a_c:.4g} N m)",
            "forces",
        )
    return {"I0": i0, "K": k, "Q": q, "phi_cr": a_c, "M_F": m_f}, summary, notes


#: What a two-sided loaded wall's negative side carries (geometry summary, theory §1.8).
SLACK_TIES = (
    "the tie-bars go slack when the wall swings towards their anchorage (a bar does not "
    "push): the negative side is the wall's own, without them"
)


def build_loaded_wall(spec: Any, scene: Any, table: Any) -> MechanismSides:
    """Builder of typology ``single_block_loaded`` (docs/theory.md §2.2).

    Floors, a roof and vaults act on one side only, so a wall carrying them rocks
    one-sided. A wall whose only added elements are tie-bars may rock two-sided: a tie
    pulls only while the motion stretches it (the positive, outward swing), so the negative
    side is the plain wall's (theory §1.8).
    """
    if spec.rocking == "two_sided":
        one_side = [name for name in ("floors", "roof", "vaults") if getattr(spec, name)]
        if one_side:
            raise InputError(
                "two-sided rocking of a loaded wall is supported with tie-bars only (they go "
                "slack on the inward swing); its " + ", ".join(one_side) + " act on one side: "
                "use one_sided",
                f"{spec.id}.rocking",
            )
    body, pos, geometry = rigid_body(spec, scene)
    warnings = list(body.warnings)
    positive, summary, notes = loaded_side(spec, scene, body, pos, table)
    warnings.extend(notes)
    if spec.rocking == "two_sided":
        summary["negative_side"] = SLACK_TIES
        if "rocking" not in spec.model_fields_set:
            # a loaded wall without 'rocking' was refused before tie-bars alone could rock
            # two-sided: say what the default now makes of it
            warnings.append(
                f"{spec.id}.rocking: not given; the wall rocks two-sided (the default), its "
                "tie-bars pulling on the outward swing only. A façade held on its inner face "
                "(transverse walls, floors) is one_sided: give 'rocking'"
            )
    geometry["loaded"] = summary
    inertia = (summary["M_c_kg"], summary["R_c_m"], summary["alpha_c_rad"], positive["I0"])
    virtual_work = {"positive": dict(summary["virtual_work"])}
    return rigid_body_sides(
        spec, scene, body, pos, geometry, positive, inertia, warnings, virtual_work
    )
