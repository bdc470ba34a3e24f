"""Two-block wall (A3) from CAD solids: hinge height, split, constants for both sides.

The wall (the spec's groups) is restrained at top and bottom. In its rocking plane
(x outward from the base axis O, z up):

* thickness ``b`` and height ``h`` come from the wall's extent (inner face at ``x = -b``);
* the overburden N is the weight share of the objects bearing on the wall top (acting at the
  centroid of their contact with the wall, which fixes its eccentricity), or a given force
  (acting on the wall's centre line); ``overburden.xi`` puts it at ``xi b`` from H instead;
* the intermediate hinge height follows Eq. 17, ``h_c = h / (1 + sqrt((N + f_mt l b) /
  (N + W + f_mt l b)))``, unless the spec gives ``hinge_height`` (the search's minimum of
  the exact λ0), and the wall is cut by the horizontal plane at ``h_c``;
* hinges: O at the base outer edge, C at ``h_c`` on the inner face, H at the top outer edge
  (theory §2.3); the negative side mirrors them about the wall's mid-plane;
* restitution: the momentum projection of theory §3.4 between the two hinge sets, unless
  the spec gives ``eta``.

The maths of the linkage is in ``two_block``.
"""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from cad_maths.geometry.cut import cut_by_plane
from cad_maths.geometry.massprops import combine, mass_properties
from cad_maths.mechanisms.base import MechanismSides, virtual_work_of
from cad_maths.mechanisms.loaded import contact_tolerance, element_solids, largest_contact
from cad_maths.mechanisms.single import rigid_body
from cad_maths.mechanisms.two_block import (
    PlanarBody,
    hinge_height,
    two_block_constants,
    two_block_restitution,
)
from shared_schema.errors import GeometryError
from shared_schema.rules import G

__all__ = ["two_block_sides"]


def _planar(parts: List[Any], origin: np.ndarray, outward: np.ndarray, axis: np.ndarray) -> Any:

    props = combine(parts, name="block")
    d = np.asarray(props.com, dtype=float) - origin
    i_g = float(axis @ np.asarray(props.inertia_com) @ axis)
    j_z = float(props.second_moment_about_plane(props.com, np.array([0.0, 0.0, 1.0])))
    return PlanarBody(float(props.mass), (float(d @ outward), float(d[2])), i_g, j_z)


def _mirror(body: Any, b: float) -> Any:

    x, z = body.com
    return PlanarBody(body.mass, (-b - x, z), body.i_g, body.j_z)


def _split(body: Any, plane_point: np.ndarray) -> Tuple[List[Any], List[Any]]:
    """Mass properties of the body's parts below and above the horizontal plane at the hinge."""
    up = np.array([0.0, 0.0, 1.0])
    lower: List[Any] = []
    upper: List[Any] = []
    for mesh, part in zip(body.meshes, body.parts):
        z = mesh.vertices[:, 2] - plane_point[2]
        if z.max() <= 0.0:
            lower.append(part)
        elif z.min() >= 0.0:
            upper.append(part)
        else:
            for side, keep in ((lower, "negative"), (upper, "positive")):
                cut = cut_by_plane(mesh, plane_point, up, keep=keep)
                side.append(mass_properties(cut, part.density))
    return lower, upper


def _wall_extent(body: Any, pos: Any, where: str) -> Tuple[float, float, float]:
    """Return the wall's thickness ``b`` behind its axis, height ``h`` and length [m]."""
    o, out, ax = pos.point, pos.outward, pos.direction
    rel = body.vertices - o
    xs, zs, ys = rel @ out, rel[:, 2], rel @ ax
    b = float(-xs.min())
    h = float(zs.max())
    length = float(ys.max() - ys.min())
    if b <= 0.0 or h <= 0.0:
        raise GeometryError(f"{where}: the wall has no thickness or height behind its axis")
    return b, h, length


def _overburden(
    spec: Any, scene: Any, body: Any, pos: Any, b: float
) -> Tuple[float, float, List[str], List[str]]:
    """Return the overburden N and where it acts on the wall top (theory §2.3).

    Parameters
    ----------
    spec : MechanismSpec
        With ``overburden`` (a force, or objects with a density and a tributary share) or
        none.
    scene : Scene
        The scene.
    body : single.Body
        The wall.
    pos : single.RockingSide
        The positive side (axis point O, outward direction).
    b : float
        The wall's thickness [m].

    Returns
    -------
    n : float
        The overburden [N] (0 without one).
    x_p : float
        Its point on the wall top, along the outward direction from H [m]: ``xi b`` from H
        when ``xi`` is given, else the centroid of the objects' contact with the wall, else
        the wall's centre line.
    ids : list of str
        The overburden's objects.
    notes : list of str
        Repairs of its solids and the default share used.
    """
    where = spec.id
    o, out = pos.point, pos.outward
    ob = spec.overburden
    n = 0.0
    x_p = -(0.5 if ob is None or ob.xi is None else float(ob.xi)) * b  # xi b from H, §2.3
    overburden_ids: List[str] = []
    notes: List[str] = []
    if ob is not None and ob.force is not None:
        n = float(ob.force)
    elif ob is not None:
        meshes, overburden_ids, repairs = element_solids(scene, ob.objects, f"{where}.overburden")
        notes.extend(repairs)
        n = ob.tributary * G * sum(mass_properties(m, ob.density).mass for m in meshes)
        if "tributary" not in ob.model_fields_set:
            notes.append(
                f"{where}.overburden: tributary not given; the wall carries the default "
                f"{ob.tributary:g} of the overburden's weight (N = {n:.6g} N). Give "
                "'tributary' to set the share"
            )
        _, point, _ = largest_contact(
            meshes, body.meshes, f"{where}.overburden", contact_tolerance(scene)
        )
        x_p = float((point - o) @ out) if ob.xi is None else x_p  # else xi b from H
    return n, x_p, overburden_ids, notes


def _hinge_at(
    spec: Any, h: float, weight: float, n: float, f_mt: float, area: float
) -> Tuple[float, bool]:
    """Return the intermediate hinge's height ``h_c`` [m] and whether the spec gave it.

    Eq. 17 (``two_block.hinge_height``) from the wall's height ``h`` [m], weight [N], the
    overburden ``n`` [N], the mortar's tensile strength ``f_mt`` [Pa] over the bed joint's
    ``area`` [m²], unless the spec gives ``hinge_height``; a hinge at the top is no
    two-block mechanism (an error).
    """
    where = spec.id
    given = getattr(spec, "hinge_height", None)
    if given is not None:
        h_c = float(given)
        if not 0.0 < h_c < h:
            raise GeometryError(
                f"{where}.hinge_height: {h_c:g} m is not inside the wall (0, {h:g}) m above "
                "its base"
            )
    else:
        h_c = hinge_height(h, weight, n, f_mt, area)
    if h_c >= h * (1.0 - 1e-9):
        raise GeometryError(
            f"{where}: with no overburden and no mortar tensile strength the hinge forms at the "
            "top (Eq. 17), so there is no two-block mechanism; give 'overburden' or 'f_mt'"
        )
    return h_c, given is not None


_Hinges = Tuple[Tuple[float, float], Tuple[float, float], Tuple[float, float]]


def _negative_side(
    b1: Any,
    b2: Any,
    hinges: _Hinges,
    mirrored: _Hinges,
    b: float,
    overburden: Tuple[float, float, float],
    ecc: str,
) -> Tuple[Dict[str, float], Dict[str, float], Optional[Dict[str, float]], float, Dict[str, Any]]:
    """Return the negative side of a two-sided wall: its linkage and the restitution.

    Parameters
    ----------
    b1, b2 : PlanarBody
        The lower and upper blocks (positive side's frame).
    hinges, mirrored : tuple of (x, z)
        The hinges O, C, H of the positive side and their mirror images [m].
    b : float
        The wall's thickness [m] (the mirror is about its mid-plane).
    overburden : tuple of float
        The overburden N [N] and its point ``(x_p, h)`` on the positive side [m].
    ecc : str
        The overburden's eccentricity rule.

    Returns
    -------
    negative : dict
        The negative side's constants (M_F signed in the positive sense).
    details : dict
        The mirrored wall's details (in the mirrored wall's frame, x inward).
    virtual_work : dict or None
        Its virtual-work check (``base.virtual_work_of``).
    eta : float
        Restitution from the positive to the negative mode (theory §3.4).
    restitution : dict
        Both impact directions' values and the rule.
    """
    n, x_p, h = overburden
    neg = two_block_constants(
        _mirror(b1, b),
        _mirror(b2, b),
        *hinges,
        overburden=n,
        overburden_point=(-b - x_p, h),
        eccentricity=ecc,
    )
    # neg is the mirrored wall: its M_F drives the inward collapse, which the file
    # writes with a negative sign (shared_schema.constants: M_F per side is signed in
    # the positive sense).
    negative = neg.constants("negative")
    details = {k: float(v) for k, v in neg.details.items()}
    vw = virtual_work_of(neg.details, "lam_static_exact")
    eta = two_block_restitution(b1, b2, *hinges, *mirrored)
    # Both impact directions (theory §3.4); they differ for an asymmetric wall.
    restitution = {
        "rule": "momentum projection (theory §3.4); eta is the positive-to-negative value",
        "eta_pos_to_neg": eta,
        "eta_neg_to_pos": two_block_restitution(b1, b2, *mirrored, *hinges),
    }
    return negative, details, vw, eta, restitution


def two_block_sides(
    spec: Any, scene: Any, body: Any, pos: Any
) -> Tuple[Dict[str, float], Optional[Dict[str, float]], Optional[float], Dict[str, Any]]:
    """Constants of both sides of a two-block wall, eta (or None) and a summary.

    The summary's ``warnings`` (popped by the builder) state the defaults that were used.
    """
    where = spec.id
    o, out, ax = pos.point, pos.outward, pos.direction
    b, h, length = _wall_extent(body, pos, where)
    weight = float(body.props.mass) * G
    n, x_p, overburden_ids, notes = _overburden(spec, scene, body, pos, b)
    ob = spec.overburden
    f_mt = float(spec.f_mt or 0.0)
    h_c, given = _hinge_at(spec, h, weight, n, f_mt, length * b)
    lower, upper = _split(body, o + np.array([0.0, 0.0, h_c]))
    if not lower or not upper:
        raise GeometryError(f"{where}: the split plane at h_c = {h_c:.3f} m misses the wall")
    b1 = _planar(lower, o, out, ax)
    b2 = _planar(upper, o, out, ax)
    hinges = ((0.0, 0.0), (-b, h_c), (0.0, h))
    mirrored = ((-b, 0.0), (0.0, h_c), (-b, h))
    ecc = spec.eccentricity or "static_moment"
    res = two_block_constants(
        b1, b2, *hinges, overburden=n, overburden_point=(x_p, h), eccentricity=ecc
    )
    positive = res.constants()
    negative = None
    neg_details: Optional[Dict[str, float]] = None
    summary_eta: Dict[str, Any] = {}
    eta = None
    virtual_work: Dict[str, Dict[str, float]] = {}
    vw = virtual_work_of(res.details, "lam_static_exact")
    if vw is not None:
        virtual_work["positive"] = vw
    if spec.rocking == "two_sided":
        negative, neg_details, vw, eta, summary_eta = _negative_side(
            b1, b2, hinges, mirrored, b, (n, x_p, h), ecc
        )
        if vw is not None:
            virtual_work["negative"] = vw
    summary: Dict[str, Any] = {
        "thickness_m": b,
        "height_m": h,
        "length_m": length,
        "weight_N": weight,
        "overburden_N": n,
        "overburden_x_m": x_p,
        "f_mt_Pa": f_mt,
        "h_c_m": h_c,
        "h_c_source": "hinge_height (given)" if given else "Eq. 17",
        "eccentricity": ecc,
        "lower_mass_kg": b1.mass,
        "upper_mass_kg": b2.mass,
        "static_multiplier_exact": res.details.get("lam_static_exact"),
        "details": {k: float(v) for k, v in res.details.items()},
        "virtual_work": virtual_work,
    }
    if neg_details is not None:
        # The negative side's details are in the mirrored wall's frame (x inward).
        summary["negative_details"] = neg_details
    if overburden_ids:
        summary["overburden_objects"] = overburden_ids
        summary["overburden_tributary"] = float(ob.tributary) if ob is not None else None
    summary["warnings"] = notes
    summary["restitution"] = summary_eta
    return positive, negative, eta, summary


def build_two_block(spec: Any, scene: Any, table: Any) -> MechanismSides:
    """Builder of typology ``two_block`` (docs/theory.md §2.3); ``table`` is unused."""
    body, pos, geometry = rigid_body(spec, scene)
    positive, negative, eta, summary = two_block_sides(spec, scene, body, pos)
    virtual_work = summary.pop("virtual_work")
    warnings = list(body.warnings) + summary.pop("warnings")
    eta_info = summary.pop("restitution")
    geometry["two_block"] = summary
    return MechanismSides(
        positive,
        negative,
        eta,
        "momentum_projection",
        geometry,
        body.object_ids,
        warnings,
        eta_info,
        virtual_work=virtual_work,
    )
