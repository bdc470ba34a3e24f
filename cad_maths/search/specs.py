"""Candidates as mechanism specs of the existing typologies, through the constants builder.

Each refined candidate becomes one mechanism of a spec file (``shared_schema.spec``):

* overturning, partial, wedge, gable, parapet and corner mechanisms are ``single_block``
  (``single_block_loaded`` where levels or tie-bars act on the moving part): one density
  group per wall, the axis by its two points, one crack per cutting plane given by three
  points whose normal points to the kept side (``keep: positive``), limited to the walls it
  cuts (``objects``), and the levels and tie-bars the part carries (a level's ``tributary``
  is the spec's share);
* vertical flexure is ``two_block`` with the wall's ``overburden`` and the refined
  ``hinge_height``.

``build_candidates`` runs the existing builder (``cad_maths.mechanisms.build``) on the
search's scene and compares its exact static multiplier and mass with the search's prism
geometry: on walls that are exact prisms they agree to rounding (issue #31: 1e-9).

Python 3.9-clean: imported by Rhino 8.
"""

import math
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from cad_maths.mechanisms.build import MechanismFailure, constants_and_failures
from cad_maths.search.families import Candidate, Plane
from cad_maths.search.model import Building
from shared_schema.constants import ConstantsFile
from shared_schema.spec import SpecFile

__all__ = ["AGREEMENT_RTOL", "build_candidates", "candidate_spec", "spec_file"]

#: Relative agreement expected between the search's geometry and the builder's on exact
#: prisms; a larger difference is reported (an idealised wall, a level the builder reads
#: differently).
AGREEMENT_RTOL = 1e-9
#: A plane cuts a wall when the wall's outline reaches this far (relative to the building's
#: size) on both of its sides.
CUT_RTOL = 1e-12


def _points(point: np.ndarray, normal: np.ndarray, inside: np.ndarray) -> List[List[float]]:
    """Three points of a plane whose normal ``(p1 - p0) × (p2 - p0)`` points along ``normal``.

    ``inside`` is a unit vector lying in the plane.
    """
    m = np.asarray(normal, dtype=float)
    m = m / float(np.linalg.norm(m))
    a1 = np.asarray(inside, dtype=float)
    a1 = a1 - (a1 @ m) * m
    a1 = a1 / float(np.linalg.norm(a1))
    a2 = np.cross(m, a1)
    p = np.asarray(point, dtype=float)
    return [[float(v) for v in q] for q in (p, p + a1, p + a2)]


def _cuts(bld: Building, wall: Any, plane: Plane) -> Optional[bool]:
    """Tell whether a plane cuts a wall (True), keeps all of it (False) or removes it (None)."""
    line = wall.frame.line_of_plane(*plane)
    if line is None:
        return True
    a, b, c = line
    f = a * wall.rings[0][:, 0] + b * wall.rings[0][:, 1] + c
    tol = CUT_RTOL * max(bld.size, 1.0)
    if float(f.min()) >= -tol:
        return False
    if float(f.max()) <= tol:
        return None
    return True


def _group(wall: Any) -> Dict[str, Any]:
    group: Dict[str, Any] = {"objects": [wall.selector], "density": wall.density}
    if wall.label:
        group["label"] = wall.label
    return group


def _name(cand: Candidate) -> str:
    parts = [f"{cand.family.replace('_', ' ')} of {cand.facade} ({cand.direction})"]
    if cand.typology != "two_block" and cand.family != "corner":
        parts.append(f"hinge at z = {cand.hinge_z:.3f} m")
    for k, v in cand.params.items():
        if k.startswith("beta"):
            parts.append(f"{k[:-4]} = {math.degrees(v):.2f} deg")
        elif k == "h1_m":
            parts.append(f"hinge height {v:.4f} m")
    return ", ".join(parts)


def candidate_spec(
    bld: Building, cand: Candidate, mech_id: str, mode: Optional[Tuple[float, float]] = None
) -> Dict[str, Any]:
    """One candidate as a mechanism of the spec file (plain data, ``MechanismSpec``'s form).

    Parameters
    ----------
    bld : Building
        The building the candidate belongs to.
    cand : Candidate
        The refined candidate.
    mech_id : str
        The mechanism's id.
    mode : (f_n [Hz], h_e [m]), optional
        The building's first mode: a candidate above ground (``z_base > 0``) gets
        ``amplification {f_n, h_e, h = Z}`` (theory §7); one at ground level none.
    """
    spec: Dict[str, Any] = {
        "id": mech_id,
        "name": _name(cand),
        "typology": cand.typology,
        "rocking": cand.rocking,
        "axis": {
            "start": [float(v) for v in cand.axis[0]],
            "end": [float(v) for v in cand.axis[1]],
        },
    }
    if mode is not None and cand.z_base > 0.0:
        spec["amplification"] = {"f_n": mode[0], "h_e": mode[1], "h": cand.z_base}
    if cand.typology == "two_block":
        wall = cand.pieces[0].wall
        spec["groups"] = [_group(wall)]
        spec["hinge_height"] = float(cand.params["h1_m"])
        if wall.overburden is not None:
            ob = wall.overburden.model_dump(exclude_none=True, exclude_unset=True)
            if cand.direction == "inward" and "xi" in ob:
                # the search's xi is from the outer face, the mechanism's from its own H
                ob["xi"] = 1.0 - float(ob["xi"])
            spec["overburden"] = ob
        return spec
    groups = []
    planes: List[Tuple[Plane, List[Any]]] = []
    for piece in cand.pieces:
        groups.append(_group(piece.wall))
        for plane in piece.planes:
            cut = _cuts(bld, piece.wall, plane)
            if cut is False:
                continue
            for known, walls in planes:
                if np.array_equal(known[0], plane[0]) and np.array_equal(known[1], plane[1]):
                    walls.append(piece.wall)
                    break
            else:
                planes.append((plane, [piece.wall]))
    spec["groups"] = groups
    cracks = []
    for (point, normal), walls in planes:
        inside = walls[0].frame.e_n
        if abs(float(np.asarray(normal) @ inside)) > 1e-9:
            inside = np.cross(np.asarray(normal), np.array([0.0, 0.0, 1.0]))
        cracks.append(
            {
                "points": _points(point, normal, inside),
                "keep": "positive",
                "objects": [w.selector for w in walls],
            }
        )
    if cracks:
        spec["cracks"] = cracks
    if cand.typology == "single_block_loaded":
        floors = []
        for c in cand.contacts:
            lv = c.level
            objects = list(c.contact.objects) if c.contact.objects else list(lv.objects)
            entry = {"objects": objects, "density": lv.density, "tributary": lv.tributary}
            if lv.kind == "roof":
                spec["roof"] = {**entry, "tied": not lv.pushes}
            else:
                floors.append(entry)
        if floors:
            spec["floors"] = floors
        ties = [{"object": t.tie.object, "force": t.tie.force} for t in cand.ties]
        if ties:
            spec["tie_bars"] = ties
    return spec


def spec_file(
    bld: Building,
    cands: Sequence[Candidate],
    ids: Sequence[str],
    mode: Optional[Tuple[float, float]] = None,
) -> SpecFile:
    """Return a validated spec file of candidates (points in metres; ``mode`` as above)."""
    return SpecFile.model_validate(
        {
            "units": "m",
            "mechanisms": [candidate_spec(bld, c, i, mode) for c, i in zip(cands, ids)],
        }
    )


def _builder_lam0(mech: Any) -> Optional[float]:
    vw = mech.positive.virtual_work
    if vw is not None:
        return float(vw.alpha0)
    geo = mech.geometry or {}
    for key in ("loaded", "two_block"):
        if isinstance(geo.get(key), dict) and "static_multiplier_exact" in geo[key]:
            return float(geo[key]["static_multiplier_exact"])
    return None


def _builder_mass(mech: Any) -> Optional[float]:
    geo = mech.geometry or {}
    if "two_block" in geo:
        return float(geo["two_block"]["lower_mass_kg"] + geo["two_block"]["upper_mass_kg"])
    return float(geo["mass_kg"]) if "mass_kg" in geo else None


def build_candidates(
    bld: Building,
    cands: Sequence[Candidate],
    ids: Sequence[str],
    *,
    scene_name: str = "search scene",
    mode: Optional[Tuple[float, float]] = None,
) -> Tuple[Optional[ConstantsFile], List[MechanismFailure], Dict[str, Dict[str, Any]], SpecFile]:
    """Constants of candidates from the builder, and their agreement with the search.

    ``mode`` (f_n [Hz], h_e [m]) is the building's first mode, written into the
    ``amplification`` of every candidate above ground (``candidate_spec``).

    Returns
    -------
    constants : ConstantsFile or None
        The mechanisms the builder computed.
    failures : list of MechanismFailure
        Those it refused, with the reason.
    agreement : dict
        Per id: ``lam0`` (the builder's exact multiplier), ``lam0_rel`` and ``mass_rel``
        (relative differences from the search's), ``lam`` (the builder's linearised λ) and
        ``agrees`` (both within ``AGREEMENT_RTOL``).
    spec : SpecFile
        The spec that was built.
    """
    sf = spec_file(bld, cands, ids, mode)
    cf, failures = constants_and_failures(
        sf, bld.scene, scene_name=scene_name, spec_name="search.spec.json"
    )
    agreement: Dict[str, Dict[str, Any]] = {}
    if cf is not None:
        by_id = {m.id: m for m in cf.mechanisms}
        for cand, mid in zip(cands, ids):
            mech = by_id.get(mid)
            if mech is None:
                continue
            lam0 = _builder_lam0(mech)
            mass = _builder_mass(mech)
            mine = sum(p.lump().mass for p in cand.pieces)
            rel_l = abs(lam0 - cand.lam0) / abs(cand.lam0) if lam0 is not None else None
            rel_m = abs(mass - mine) / mine if mass is not None and mine > 0 else None
            agreement[mid] = {
                "lam0": lam0,
                "lam0_rel": rel_l,
                "mass_rel": rel_m,
                "lam": float(mech.positive.lam) if mech.positive.lam is not None else None,
                "agrees": rel_l is not None
                and rel_m is not None
                and rel_l <= AGREEMENT_RTOL
                and rel_m <= AGREEMENT_RTOL,
            }
    return cf, failures, agreement, sf
