"""The check document: the Circolare 2019 §C8.7.1 checks of every mechanism on a site.

``check_doc`` runs, for every mechanism of a constants file and every stored side, the
linear check (SLV, §C8.7.1.2.1.7) and the nonlinear check (SLV and SLC, §C8.7.1.2.1.6 and
.8) of the Circolare 21 gennaio 2019 n. 7 (``codes.circ2019``), or on request the 2009 forms
(``codes.circ2009``, ``method: "circ2009"``), against the site's NTC 2018 or EN 1998-1
spectrum; mechanisms above ground get the floor spectrum of §C7.2.3
(``codes.floor_spectra``). This module makes the choices the text leaves to the engineer,
each from the site file (``local_mechanisms``, ``building``) or the text's default, and
says in the document which one it made: the building's first period, which mechanisms are
free-standing and their data, the ties (docs/theory.md §11). A mechanism that cannot be
checked gets a note in its row; it never stops the others. Inputs that contradict each
other are refused (``check_site_inputs``).
"""

from __future__ import annotations

import math
from typing import Any, Callable, Optional, Sequence

import numpy as np

from shared_schema.constants import ConstantsFile, Mechanism, SideConstants
from shared_schema.errors import InputError, RockmechError
from shared_schema.site import MechanismOptions, SiteFile

from ..codes.circ2009 import (
    Building,
    VirtualWork,
    linear_check,
    nonlinear_check,
    participating_mass,
)
from ..codes.circ2019 import (
    CIRC2019,
    KAPPA_CANTILEVER,
    KAPPA_SIMPLY_SUPPORTED,
    CapacityCurve,
    CodeDemand,
    FreeStanding,
    RecordDemand,
    linear_check_2019,
    nonlinear_check_2019,
)
from ..codes.floor_spectra import FloorModel, participation_first_mode
from ..codes.hazard import ElasticSpectrum, ec8_spectrum, ntc_spectrum
from ..core.model import G
from .verdict import conclusion

__all__ = [
    "CIRC2009",
    "DECISIONS",
    "NO_VIRTUAL_WORK",
    "T1_COEFFICIENT",
    "T1_TOLERANCE",
    "building_period",
    "check_doc",
    "check_site_inputs",
    "limit_state_spectrum",
    "number_at",
    "recheck_with_records",
    "site_spectrum",
]

#: Circolare 2019 [C7.3.2]: T1 = C1 H^(3/4), C1 = 0.050 "per costruzioni di muratura".
T1_COEFFICIENT = 0.05
#: Relative difference between the site's T1 and a mechanism's 1/f_n refused as a conflict.
T1_TOLERANCE = 0.01
#: The 2009 forms' label (``method: "circ2009"``).
CIRC2009 = "Circolare 2 febbraio 2009 n. 617 §C8A.4 (2009 forms, for comparison only)"

NO_VIRTUAL_WORK = (
    "no virtual_work in the constants (short form or an older file): the code check needs "
    "the masses' virtual displacements; compute the constants from the geometry with "
    "`rockmech constants`"
)
#: Why a check above ground is incomplete: the height demand needs the building.
NO_BUILDING_NOTE = (
    "the mechanism is above ground (Z > 0) but the site file gives no building (height, "
    "storeys): the demand at height was not evaluated and the numbers are the ground's"
)

#: Typologies whose constants hold more than one block ([C8.7.1.5] needs J_blocks).
MULTI_BLOCK_TYPOLOGIES = ("two_block", "multi_block")
#: How e* and d of [C8.7.1.4]-[C8.7.1.5] were summed (each check's ``e_star_rule``).
E_STAR_RULES = {
    "blocks": "Circ. 2019 [C8.7.1.5]: one term per block at the centroid of its forces "
    "(C8.7.1.2.1.1's δ_PQx,k; virtual_work.J_blocks)",
    "one_block": "Circ. 2019 [C8.7.1.5]: one block (the constants give no J_blocks), one term "
    "at the centroid of its forces: e* = 1, d = φ S/mass",
    "integral": "integral over every mass element of the solids (site local_mechanisms.e_star "
    "= integral; not the text's per-block sum): e* = S²/(mass J), d = φ J/S",
}

#: Where the text leaves a choice or reads two ways, and what rockmech does (theory §11).
DECISIONS = [
    "e* and d ([C8.7.1.4]-[C8.7.1.5]) sum one term per block, δ_PQx,k at the centroid of the "
    "forces on block k (C8.7.1.2.1.1): one block gives e* = 1 (site local_mechanisms.e_star "
    "= blocks, the default; 'integral' integrates over the solids, e* = 3/4 for a "
    "rectangular block, and gives a0* 4/3 of the text's).",
    "A tie that breaks at d_SLV (C8.7.1.2.1.6): a(d_SLV) of [C8.7.1.10] is the capacity as "
    "the mechanism reaches the break, the tie still holding (the text's 'raggiungimento "
    "dello SLV'), not the capacity after it.",
    "The code spectrum's displacement demand is the largest S_De over [T0, T_SLV] (and "
    "[T0, T_SLC]), as C8.7.1.2.1.8 states for the SLV ('valore massimo dello spostamento "
    "spettrale ... [T0, T_SLV]'); beyond T_E it is not the falling branch of NTC [3.2.11].",
    "The linear check (C8.7.1.2.1.7) and a_g,SLD (C8.7.1.2.1.5) count every action, ties "
    "not verified up to collapse included: the text restricts only d0 (C8.7.1.2.1.6) to the "
    "actions verified present.",
    "T1 of the building, where the site does not give it, is Circ. 2019 [C7.3.2] "
    "(T1 = 0.050 H^(3/4)), not NTC 2018 [7.3.6] (T1 = 2 sqrt(d), which needs the building's "
    "displacement under its weight applied horizontally).",
    "Circ. 2019 C7.2.3 defines ξ_k 'in percentuale'; rockmech reads it as a fraction in "
    "[C7.2.6]/[C7.2.9] (in percent 1.1 ξ_k^-0.5 = 0.49 at 5 %: the floor spectrum would fall "
    "at resonance below its value at T = 0) and in percent in [C7.2.7] (sqrt(1 + 0.0004 "
    "ξ_k²) = 1.005 at 5 %; with a fraction the term would be 1 + 1e-6).",
    "Floor spectrum: the text bounds S_eZ by the ground spectrum for T > T1 ([C7.2.5]); "
    "rockmech bounds it for every T, and a_Z by the peak ground acceleration (one mode "
    "vanishes at the foundation). Each number says which bound governs.",
    "C8.7.1.2.1.5 cites [C7.2.11] for the activation of a rigid mechanism at height, "
    "C8.7.1.2.1.7 [C7.2.8]; [C7.2.11] is for framed buildings only, so rockmech uses "
    "[C7.2.8].",
    "[C8.7.1.12] writes T1: rockmech uses the floor spectrum's period of the first mode, "
    "T_k = T1 × period_elongation (T1 itself by default).",
    "z of the floor spectrum is the height of the mechanism's base (amplification.h).",
    "The lower bound a_g,SLV >= a_g,SLD is in C8.7.1.2.1.8 (nonlinear check); rockmech "
    "applies it there and reports a_g,SLD beside the linear check.",
    "The capacity curve is linear in the rotation between alpha0 and 0 at phi0 (rockmech's "
    "linearised kinematics, d = phi J/S with J as e_star sums it); the exact curve of a "
    "block is convex and lies up to 1 % below it for slenderness b/h <= 0.2.",
    "[C8.7.1.7] has no added masses: a free-standing element's T0 is the text's, without "
    "the masses it carries.",
    "E of the masonry has no single default in the text (Tab. C8.5.I gives 690-5600 MPa): "
    "without E the free-standing demand is the spectrum's peak, an upper bound for any T0.",
    "Ties not verified to hold up to collapse are left out of d0 (C8.7.1.2.1.6); outward "
    "thrusts are kept (leaving out a destabilising action would raise d0).",
    "With records the demand is the larger of the code spectrum's and the records' "
    "(C8.7.1.2.1.8's largest S_De over [T0, T_SLV]); several records: the largest.",
    "a_g,X = ζ a_g: the site spectrum's shape (S, F0, T_C) is held and its ordinates scale "
    "with a_g.",
]


# --- the site: spectra, limit states, building ---------------------------------------


def site_spectrum(site: SiteFile) -> ElasticSpectrum:
    """Return the site's elastic spectrum (NTC 2018 §3.2.3.2 or EN 1998-1 §3.2.2.2)."""
    hz = site.hazard
    if hz.code == "NTC2018":
        return ntc_spectrum(hz.a_g, hz.F0, hz.Tc_star, hz.soil, hz.topography, hz.xi_percent)
    return ec8_spectrum(hz.a_gR, hz.importance, hz.ground, hz.spectrum_type, hz.xi_percent)


def limit_state_spectrum(site: SiteFile, limit_state: str) -> Optional[ElasticSpectrum]:
    """Return the site's spectrum for a limit state, or None when the site file lacks it.

    The hazard's own parameters belong to ``hazard.limit_state`` (NTC; EC8: SLV); the
    others come from ``hazard.limit_states``.
    """
    hz = site.hazard
    main = hz.limit_state if hz.code == "NTC2018" else "SLV"
    if limit_state == main:
        return site_spectrum(site)
    other = (hz.limit_states or {}).get(limit_state)  # type: ignore[call-overload]
    if other is None:
        return None
    if hz.code == "NTC2018":
        return ntc_spectrum(
            other.a_g, other.F0, other.Tc_star, hz.soil, hz.topography, hz.xi_percent
        )
    return ec8_spectrum(other.a_gR, hz.importance, hz.ground, hz.spectrum_type, hz.xi_percent)


def building_period(site: SiteFile, cf: Optional[ConstantsFile] = None) -> tuple[float, str]:
    """Return the building's first period T1 [s] and its source (one rule for all mechanisms).

    The site's ``building.T1``, else Circolare 2019 [C7.3.2] ``C1 H^(3/4)`` with
    ``C1 = 0.050`` (masonry), else the constants' ``1/f_n`` (when the site gives no
    building; all mechanisms must then agree).

    Raises
    ------
    InputError
        No building and no mechanism with ``f_n``, or mechanisms whose ``1/f_n`` differ.
    """
    b = site.building
    if b is not None and b.T1 is not None:
        return b.T1, "site building.T1"
    if b is not None:
        return (
            T1_COEFFICIENT * b.height**0.75,
            "Circ. 2019 [C7.3.2]: T1 = 0.050 H^(3/4) (C7.3.3.2, masonry)",
        )
    periods = sorted(
        {1.0 / m.amplification.f_n for m in (cf.mechanisms if cf else []) if m.amplification}
    )
    if not periods:
        raise InputError("no building in the site file and no f_n in the constants", "T1")
    if periods[-1] > periods[0] * (1.0 + T1_TOLERANCE):
        raise InputError(
            "the mechanisms' amplification.f_n give different first periods "
            f"({periods[0]:.4g}-{periods[-1]:.4g} s); give building.T1 in the site file",
            "building.T1",
        )
    return periods[0], "the constants' 1/f_n (no building in the site file)"


def check_site_inputs(cf: ConstantsFile, site: SiteFile) -> None:
    """Refuse site choices that contradict the constants (the rules JSON Schema cannot state).

    Raises
    ------
    InputError
        ``local_mechanisms.mechanisms`` names a mechanism the constants do not have; or the
        site's ``building.T1`` differs by more than ``T1_TOLERANCE`` from the ``1/f_n`` of a
        mechanism above ground that the check can run on (one T1 decides the check: remove
        one or make them agree).
    """
    ids = {m.id for m in cf.mechanisms}
    for key in site.local_mechanisms.mechanisms:
        if key not in ids:
            raise InputError(
                f"no mechanism {key!r} in the constants (ids: {', '.join(sorted(ids))})",
                f"local_mechanisms.mechanisms.{key}",
            )
    b = site.building
    if b is None or b.T1 is None:
        return
    for m in cf.mechanisms:
        if m.amplification is None or m.amplification.h <= 0.0:
            continue
        if all(side.virtual_work is None for _, side in _sides(m)):
            continue  # its check does not run: T1 is not used for it
        t_fn = 1.0 / m.amplification.f_n
        if abs(t_fn - b.T1) > T1_TOLERANCE * b.T1:
            raise InputError(
                f"building.T1 = {b.T1:g} s conflicts with mechanism {m.id}'s "
                f"amplification.f_n = {m.amplification.f_n:g} Hz (1/f_n = {t_fn:.4g} s): one "
                "first period decides the check; remove one or make them agree",
                "building.T1",
            )


# --- per mechanism: free-standing, ties, floor ----------------------------------------


def _options(site: SiteFile, mech: Mechanism) -> MechanismOptions:
    return site.local_mechanisms.mechanisms.get(mech.id) or MechanismOptions()


def number_at(mapping: Any, *keys: str) -> Optional[float]:
    """Return the real number at ``mapping[keys[0]][keys[1]]...`` (None: absent, or no number).

    A free-form JSON part of the constants (``geometry``) read safely: a missing key, a
    non-mapping on the way, a boolean or a text give None, never an error.

    Examples
    --------
    >>> number_at({"positive": {"R_m": 2}}, "positive", "R_m"), number_at({"h_m": True}, "h_m")
    (2.0, None)
    """
    node = mapping
    for key in keys:
        if not isinstance(node, dict) or key not in node:
            return None
        node = node[key]
    return float(node) if isinstance(node, (int, float)) and not isinstance(node, bool) else None


def _free_standing(
    site: SiteFile, mech: Mechanism
) -> tuple[Optional[FreeStanding], dict[str, Any]]:
    """Whether the mechanism is free-standing, and its data for [C8.7.1.7]."""
    opts = _options(site, mech)
    where = f"local_mechanisms.mechanisms.{mech.id}"
    if opts.free_standing is not None:
        flag, why = opts.free_standing, f"site {where}.free_standing"
    else:
        flag = mech.rocking == "two_sided" and mech.typology in ("single_block", "user_defined")
        why = (
            f"default for typology {mech.typology}, {mech.rocking.replace('_', '-')} rocking: "
            + (
                "free to vibrate before activation (C8.7.1.2.1.3: parapets, pinnacles, "
                "free-standing portions)"
                if flag
                else "restrained, rigid until activation (C8.7.1.2.1.3)"
            )
            + f"; set {where}.free_standing to change"
        )
    info: dict[str, Any] = {"value": flag, "source": why}
    if not flag:
        return None, info
    geo = mech.geometry or {}
    sources: dict[str, str] = {}
    kappa = opts.kappa
    sources["kappa"] = f"site {where}.kappa"
    if kappa is None:
        strip = mech.typology == "two_block"
        kappa = KAPPA_SIMPLY_SUPPORTED if strip else KAPPA_CANTILEVER
        sources["kappa"] = "Circ. 2019 [C8.7.1.7]: " + (
            "2.2, vertical flexural mechanism (simply supported)"
            if strip
            else "6.2, cantilever (elemento svettante)"
        )
    L, t = opts.L, opts.t
    sources["L"] = sources["t"] = f"site {where}"
    if L is None or t is None:
        geo_l, geo_t, how = _geometry_size(geo)
        if L is None and geo_l is not None:
            L, sources["L"] = geo_l, how
        if t is None and geo_t is not None:
            t, sources["t"] = geo_t, how
    w = opts.unit_weight or site.local_mechanisms.unit_weight
    sources["W"] = (
        f"site {where}.unit_weight" if opts.unit_weight else "site local_mechanisms.unit_weight"
    )
    if w is None:
        rho = number_at(geo, "density_kg_m3")
        mass, vol = number_at(geo, "mass_kg"), number_at(geo, "volume_m3")
        if rho is None and mass is not None and vol:
            rho = mass / vol
        if rho is not None:
            w, sources["W"] = rho * G, "the geometry's density × g"
    e = opts.E or site.local_mechanisms.E
    sources["E"] = f"site {where}.E" if opts.E else "site local_mechanisms.E"
    given = {"kappa": kappa, "L": L, "t": t, "W": w, "E": e}
    free = FreeStanding(
        kappa=kappa,
        L=L,
        t=t,
        W=w,
        E=e,
        sources={k: v for k, v in sources.items() if given[k] is not None},
    )
    if free.missing:
        info["missing"] = free.missing
    return free, info


def _geometry_size(geo: dict[str, Any]) -> tuple[Optional[float], Optional[float], str]:
    """Length and thickness of the element from the constants' geometry [m]."""
    h, b = number_at(geo, "h_m"), number_at(geo, "b_m")
    if h is not None and b is not None:
        return h, b, "the geometry's h_m, b_m"
    h, b = number_at(geo, "two_block", "height_m"), number_at(geo, "two_block", "thickness_m")
    if h is not None and b is not None:
        return h, b, "the geometry's two_block height_m, thickness_m"
    r = number_at(geo, "R_m") or number_at(geo, "positive", "R_m")
    a = number_at(geo, "alpha_rad") or number_at(geo, "positive", "alpha_rad")
    if r is not None and a is not None:
        return (
            2.0 * r * math.cos(a),
            2.0 * r * math.sin(a),
            "the rectangle of the geometry's R and alpha (L = 2R cos α, t = 2R sin α)",
        )
    return None, None, ""


def _tie_terms(mech: Mechanism, side: SideConstants) -> Optional[dict[str, Any]]:
    """Return the tie-bars' share of a loaded wall's alpha0, M_F and phi_ov (theory §11.7).

    Each tie pulls the façade inward with its force ``F`` at its point on the outer face:
    it enters ``M_F`` as ``-F (z cos α_c + x sin α_c)`` (theory Eq. 15) and the virtual
    work at rest as ``-F z`` (``alpha0 g S``), ``z`` its height above the axis and ``x`` its
    distance from the axis towards the centre of mass. None on a negative side: a tie goes
    slack on the swing towards its anchorage, and the builder leaves it out of that side's
    constants (theory §1.8), so there is nothing to take out.
    """
    if mech.negative is not None and side is mech.negative:
        return None
    geo = mech.geometry or {}
    loaded = geo.get("loaded") if isinstance(geo, dict) else None
    pos = geo.get("positive") if isinstance(geo, dict) else None
    if not isinstance(loaded, dict) or not isinstance(pos, dict):
        return None
    elements = loaded.get("elements")
    ties = [e for e in (elements if isinstance(elements, list) else []) if isinstance(e, dict)]
    ties = [e for e in ties if e.get("kind") == "tie_bar"]
    if not ties:
        return None
    axis_p = np.asarray(pos.get("axis_point_m"), dtype=float)
    axis_u = np.asarray(pos.get("axis_direction"), dtype=float)
    com = np.asarray(geo.get("com_m"), dtype=float)
    a_c = number_at(loaded, "alpha_c_rad")
    vw = side.virtual_work
    if axis_p.shape != (3,) or axis_u.shape != (3,) or com.shape != (3,) or a_c is None:
        return None
    if vw is None or side.K is None or side.M_F is None or side.phi_cr is None:
        return None
    axis_u = axis_u / float(np.linalg.norm(axis_u))
    up = np.array([0.0, 0.0, 1.0])

    def plane(p: np.ndarray) -> tuple[float, np.ndarray]:
        rel = p - axis_p
        rel = rel - float(np.dot(rel, axis_u)) * axis_u
        z = float(np.dot(rel, up))
        return z, rel - z * up

    _, toward = plane(com)
    inward = toward / float(np.linalg.norm(toward))
    m_f_tie = 0.0
    work_tie = 0.0
    listed = []
    for e in ties:
        force = number_at(e, "force_N") or 0.0
        z, horiz = plane(np.asarray(e.get("at_m"), dtype=float))
        x = float(np.dot(horiz, inward))
        m_f_tie += -force * (z * math.cos(a_c) + x * math.sin(a_c))
        work_tie += -force * z
        listed.append({"element": e.get("element"), "force_N": force, "z_m": z, "x_m": x})
    alpha0_without = vw.alpha0 + work_tie / (G * vw.S)
    phi0_without = side.phi_cr - (side.M_F - m_f_tie) / side.K
    return {
        "clauses": {
            "M_F_ties": "theory Eq. 15: Σ -F (z cos α_c + x sin α_c) of the tie-bars",
            "M_F_without": "theory Eq. 15 without the tie-bars",
            "alpha0_with": "Circ. 2019 [C8.7.1.1] with every action",
            "alpha0_without": "Circ. 2019 [C8.7.1.1] without the tie-bars (-F z each)",
            "phi0_with": "theory §1.7 Eq. 6 with every static force",
            "phi0_without": "theory §1.7 Eq. 6 without the tie-bars (C8.7.1.2.1.6)",
            "phi0_no_static_forces": "theory §1.7 Eq. 6 with M_F = 0 (φ_cr)",
        },
        "ties": listed,
        "M_F_ties": m_f_tie,
        "M_F_without": side.M_F - m_f_tie,
        "alpha0_with": vw.alpha0,
        "alpha0_without": alpha0_without,
        "phi0_with": side.phi_ov,
        "phi0_without": phi0_without,
        "phi0_no_static_forces": side.phi_cr,
    }


def _blocks_virtual_work(mech: Mechanism, v: Any, reading: str) -> tuple[VirtualWork, str]:
    """Return the side's virtual-work quantities as [C8.7.1.4]-[C8.7.1.5] sum them, and how.

    ``reading`` is the site's ``local_mechanisms.e_star``: ``"blocks"`` (the text: one term
    per block at the centroid of its forces, ``J_blocks``) or ``"integral"`` (``J``).
    """
    if reading == "integral":
        return VirtualWork(v.alpha0, v.mass, v.S, v.J), E_STAR_RULES["integral"]
    if v.J_blocks is not None:
        return VirtualWork(v.alpha0, v.mass, v.S, v.J_blocks), E_STAR_RULES["blocks"]
    if mech.typology in MULTI_BLOCK_TYPOLOGIES:
        raise InputError(
            f"mechanism {mech.id}: the constants give no virtual_work.J_blocks, which "
            f"[C8.7.1.5] needs for a {mech.typology} mechanism (one term per block); "
            "recompute the constants with `rockmech constants`, or set the site's "
            "local_mechanisms.e_star to 'integral'",
            "virtual_work.J_blocks",
        )
    return VirtualWork(v.alpha0, v.mass, v.S, v.S * v.S / v.mass), E_STAR_RULES["one_block"]


def _curve(
    mech: Mechanism,
    side: SideConstants,
    vw: VirtualWork,
    e_star: float,
    fc: float,
    free: Optional[FreeStanding],
    opts: MechanismOptions,
) -> tuple[Optional[CapacityCurve], dict[str, Any]]:
    """Return the side's capacity curve with the ties' choice made, and that choice."""
    assert side.phi_ov is not None
    d_per_rad = vw.J / vw.S
    t0 = free.T0 if free is not None else None
    terms = _tie_terms(mech, side)
    where = f"local_mechanisms.mechanisms.{mech.id}"
    if terms is None:
        record: dict[str, Any] = {"present": False}
        if side.M_F is not None and side.M_F < 0.0:
            record["note"] = (
                f"M_F = {side.M_F:.4g} N m < 0: a restraining static force is in alpha0 and "
                "phi_ov and the constants do not say what it is; if it is a tie not verified "
                "to hold up to collapse, d0 is too large (C8.7.1.2.1.6)"
            )
        curve = CapacityCurve(e_star, fc, d_per_rad, vw.alpha0, side.phi_ov, T0=t0)
        return curve, record
    record = {"present": True, **terms}
    choice = opts.ties or "not_verified"
    record["treatment"] = choice
    record["source"] = f"site {where}.ties" if opts.ties else "default (C8.7.1.2.1.6)"
    if choice == "verified":
        record["rule"] = "ties verified to hold up to collapse: d0 with them (C8.7.1.2.1.6)"
        return CapacityCurve(e_star, fc, d_per_rad, vw.alpha0, side.phi_ov, T0=t0), record
    a0, p0 = terms["alpha0_without"], terms["phi0_without"]
    if not (a0 > 0.0 and p0 > 0.0):
        record["rule"] = (
            "without the ties the static forces alone overturn the mechanism "
            f"(alpha0 = {a0:.4g}, phi0 = {p0:.4g}): no capacity curve of the actions "
            "present up to collapse (C8.7.1.2.1.6)"
        )
        return None, record
    before = None
    if opts.tie_failure_rotation is not None:
        before = (vw.alpha0, side.phi_ov, opts.tie_failure_rotation)
        record["rule"] = (
            "ties not verified up to collapse: d0 without them; the curve has them up to "
            f"their failure rotation {opts.tie_failure_rotation:g} rad "
            f"(site {where}.tie_failure_rotation), C8.7.1.2.1.6"
        )
    else:
        record["rule"] = (
            "ties not verified to hold up to collapse: d0 and the curve without them "
            "(C8.7.1.2.1.6: only actions verified present up to collapse); give "
            f"{where}.tie_failure_rotation or ties = verified to count them"
        )
    return CapacityCurve(e_star, fc, d_per_rad, a0, p0, before=before, T0=t0), record


def _floor(
    site: SiteFile, z: float, t1: Optional[float]
) -> tuple[Optional[FloorModel], Optional[str]]:
    """Return the floor model at height ``z`` [m], or the note saying why there is none."""
    b = site.building
    if z <= 0.0:
        return None, None
    if b is None or t1 is None:
        return None, NO_BUILDING_NOTE
    if z > b.height * (1.0 + 1e-12):
        raise InputError(
            f"the mechanism's base height Z = {z:g} m is above the building (H = {b.height:g} m)",
            "Z",
        )
    model = FloorModel(
        T1=t1,
        elongation=b.period_elongation,
        xi_k_percent=b.xi_percent,
        gamma=participation_first_mode(int(b.storeys)),
        psi=z / b.height,
    )
    return model, None


# --- the checks of one side -----------------------------------------------------------


def _not_run(method: str, note: str) -> dict[str, Any]:
    return {"method": method, "passes": None, "note": note, "status": "not_run"}


def _no_curve(note: str) -> dict[str, Any]:
    return {
        "method": "circ2019",
        "standard": CIRC2019,
        "status": "ok",
        "passes": False,
        "capacity_ratio": 0.0,
        "demand": None,
        "d_SLV": 0.0,
        "T_SLV": None,
        "note": note,
        "notes": [note],
        "clauses": {"capacity_ratio": "Circ. 2019 C8.7.1.2.1.6 (no capacity curve)"},
    }


class _Context:
    """What the checks of every mechanism share: spectra, limit states, T1, the method."""

    def __init__(
        self, cf: ConstantsFile, site: SiteFile, heights: Optional[dict[str, float]] = None
    ) -> None:
        check_site_inputs(cf, site)
        self.site = site
        self.heights = dict(heights or {})
        self.method = site.local_mechanisms.method
        self.spectrum = site_spectrum(site)
        main = site.hazard.limit_state if site.hazard.code == "NTC2018" else "SLV"
        slv = limit_state_spectrum(site, "SLV")
        self.slv_given = slv is not None
        self.slv = slv if slv is not None else self.spectrum
        self.slc = limit_state_spectrum(site, "SLC")
        self.main = main
        self.t1: Optional[float] = None
        self.t1_source: Optional[str] = None
        try:
            self.t1, self.t1_source = building_period(site, cf)
        except InputError:
            pass  # no building and no (single) 1/f_n: the demand at height needs a building
        if site.building is None and self.t1 is not None:
            self.t1_source = (self.t1_source or "") + "; the demand at height needs a building"

    def limit_states(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for name, sp in (("SLV", self.slv if self.slv_given else None), ("SLC", self.slc)):
            if sp is None:
                out[name] = None
                continue
            out[name] = {
                "a_g": sp.a_g,
                "S": sp.S,
                "F": sp.F,
                "T_B": sp.T_B,
                "T_C": sp.T_C,
                "T_D": sp.T_D,
                "pga_g": sp.pga,
                "source": ("hazard" if name == self.main else f"hazard.limit_states.{name}"),
            }
        return out


def _check_notes(
    ctx: _Context, mech: Mechanism, floor: Any, floor_note: Optional[str]
) -> list[str]:
    """Return the notes both 2019 checks of a side carry: the floor, T1 against 1/f_n, no SLV."""
    notes = [floor_note] if floor_note else []
    amp = mech.amplification
    if floor is not None and amp is not None and ctx.t1 is not None:
        t_fn = 1.0 / amp.f_n
        if abs(t_fn - ctx.t1) > T1_TOLERANCE * ctx.t1:
            notes.append(
                f"the constants' 1/f_n = {t_fn:.4g} s (the dynamics' Eq. 28) is not the check's "
                f"T1 = {ctx.t1:.4g} s ({ctx.t1_source}); give building.T1 to use one period"
            )
    if not ctx.slv_given:
        notes.append(
            f"the site's hazard is for {ctx.main} and gives no SLV (hazard.limit_states.SLV): "
            "the SLV checks use its spectrum's shape and are not evaluated"
        )
    return notes


def _record_demands(records: Sequence[tuple[Any, float]], floor: Any) -> list[RecordDemand]:
    """Return each (record, scale) as a demand of the nonlinear check (on the floor, if any)."""
    return [
        RecordDemand(np.asarray(m.accel.acc, dtype=float), float(m.dt), scale, m.name, floor)
        for m, scale in records
    ]


def _side_checks_2019(
    ctx: _Context,
    mech: Mechanism,
    side: SideConstants,
    z: float,
    records: Sequence[tuple[Any, float]] = (),
) -> tuple[dict[str, Any], dict[str, Any]]:
    lin_m = "circ2019"
    if side.virtual_work is None:
        return _not_run(lin_m, NO_VIRTUAL_WORK), _not_run(lin_m, NO_VIRTUAL_WORK)
    site = ctx.site
    hz = site.hazard
    v = side.virtual_work
    opts = _options(site, mech)
    extra_notes: list[str] = []
    try:
        vw, e_star_rule = _blocks_virtual_work(mech, v, site.local_mechanisms.e_star)
        _, e_star = participating_mass(vw)
        free, _ = _free_standing(site, mech)
        floor, floor_note = _floor(site, z, ctx.t1)
    except RockmechError as exc:
        return _not_run(lin_m, str(exc)), _not_run(lin_m, str(exc))
    extra_notes += _check_notes(ctx, mech, floor, floor_note)
    complete = floor_note is None and ctx.slv_given
    slv = CodeDemand(ctx.slv, floor, "SLV spectrum")
    try:
        if vw.alpha0 <= 0.0:
            raise InputError("alpha0 <= 0: the static loads alone activate the mechanism", "alpha0")
        lin = linear_check_2019(vw, slv, FC=hz.FC, a_g=ctx.slv.a_g, q=hz.q, free=free)
        lin["e_star_rule"] = e_star_rule
        lin["notes"] = extra_notes + lin["notes"]
        if not complete:
            lin["passes"] = None
        lin["note"] = "; ".join(lin["notes"])
    except RockmechError as exc:
        lin = _not_run(lin_m, str(exc))
    try:
        if vw.alpha0 <= 0.0:
            raise InputError(
                "alpha0 <= 0: the static loads alone activate the mechanism; there is no "
                "capacity curve",
                "alpha0",
            )
        curve, ties = _curve(mech, side, vw, e_star, hz.FC, free, opts)
        if curve is None:
            non = _no_curve(ties["rule"])
        else:
            slc = None if ctx.slc is None else CodeDemand(ctx.slc, floor, "SLC spectrum")
            recs = _record_demands(records, floor)
            non = nonlinear_check_2019(
                vw,
                curve,
                slv,
                a_g_slv=ctx.slv.a_g,
                demand_slc=slc,
                a_g_slc=None if ctx.slc is None else ctx.slc.a_g,
                free=free,
                records=recs,
                instability_rotation=opts.instability_rotation,
                xi_slv=site.local_mechanisms.xi_SLV_percent,
                xi_slc=site.local_mechanisms.xi_SLC_percent,
                evaluated_slv=complete,
            )
        non["ties"] = ties
        if ties.get("note"):
            extra_notes.append(ties["note"])
        non["e_star_rule"] = e_star_rule
        non["notes"] = extra_notes + list(non.get("notes", []))
        if not complete:
            non["passes"] = None
            if "SLV" in non:
                non["SLV"]["passes"] = None
                non["SLC"]["passes"] = None
        non["note"] = "; ".join(non["notes"])
    except RockmechError as exc:
        non = _not_run(lin_m, str(exc))
    return lin, non


def _side_checks_2009(
    ctx: _Context, side: SideConstants, z: float
) -> tuple[dict[str, Any], dict[str, Any]]:
    if side.virtual_work is None:
        return _not_run("circ2009", NO_VIRTUAL_WORK), _not_run("circ2009", NO_VIRTUAL_WORK)
    v = side.virtual_work
    vw = VirtualWork(v.alpha0, v.mass, v.S, v.J)
    b = ctx.site.building
    bld = None if b is None or ctx.t1 is None else Building(b.height, int(b.storeys), ctx.t1)
    hz = ctx.site.hazard
    phi_ov = side.phi_ov
    assert phi_ov is not None  # filled in by validation
    runs: list[Callable[[], dict[str, Any]]] = [
        lambda: linear_check(vw, ctx.slv, FC=hz.FC, q=hz.q, Z=z, building=bld),
        lambda: nonlinear_check(vw, phi_ov, ctx.slv, FC=hz.FC, Z=z, building=bld),
    ]
    out = []
    for run in runs:
        try:
            res = run()
            res["status"] = "ok"
        except RockmechError as exc:
            res = _not_run("circ2009", str(exc))
        res["method"] = "circ2009"
        res["standard"] = CIRC2009
        out.append(res)
    return out[0], out[1]


def _sides(mech: Mechanism) -> list[tuple[str, SideConstants]]:
    out = [("positive", mech.positive)]
    if mech.negative is not None and not mech.one_sided:
        out.append(("negative", mech.negative))
    return out


def _worst(checks: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Return the governing side: the lowest capacity ratio among the checks that ran."""
    ran = [c for c in checks if c.get("status") == "ok"]
    if not ran:
        return checks[0]
    return min(ran, key=lambda c: c["capacity_ratio"])


def _mechanism_row(
    ctx: _Context, mech: Mechanism, records: Sequence[tuple[Any, float]] = ()
) -> dict[str, Any]:
    if mech.amplification is not None:
        z, z_source = mech.amplification.h, "amplification.h (the mechanism's base)"
    elif mech.id in ctx.heights:
        z = ctx.heights[mech.id]
        z_source = "the height of the mechanism's base in its scene (no amplification data)"
    else:
        z, z_source = 0.0, "ground level (the constants give no amplification.h)"
    sides: dict[str, Any] = {}
    for name, side in _sides(mech):
        if ctx.method == "circ2009":
            lin, non = _side_checks_2009(ctx, side, z)
        else:
            lin, non = _side_checks_2019(ctx, mech, side, z, records)
        sides[name] = {"linear": lin, "nonlinear": non}
    lin_g = _worst([s["linear"] for s in sides.values()])
    non_g = _worst([s["nonlinear"] for s in sides.values()])
    verdicts = [c["passes"] for c in (lin_g, non_g) if c.get("status") == "ok"]
    free_info: Optional[dict[str, Any]] = None
    if ctx.method == "circ2019":
        try:
            free_info = _free_standing(ctx.site, mech)[1]
        except RockmechError as exc:
            free_info = {"value": None, "source": str(exc)}
    slc = non_g.get("SLC") if non_g.get("status") == "ok" else None
    return {
        "id": mech.id,
        "name": mech.name,
        "typology": mech.typology,
        "rocking": mech.rocking,
        "Z": z,
        "Z_source": z_source,
        "T1": ctx.t1 if z > 0.0 else None,
        "T1_source": ctx.t1_source if z > 0.0 else None,
        "free_standing": free_info,
        "sides": sides,
        "linear": lin_g,
        "nonlinear": non_g,
        "passes": None if not verdicts or None in verdicts else all(verdicts),
        "passes_SLC": None if slc is None else slc.get("passes"),
    }


def _governing(rows: list[dict[str, Any]]) -> Optional[str]:
    ratios = [
        (min(c["capacity_ratio"] for c in (r["linear"], r["nonlinear"]) if c["status"] == "ok"), r)
        for r in rows
        if any(c.get("status") == "ok" for c in (r["linear"], r["nonlinear"]))
    ]
    return min(ratios, key=lambda p: p[0])[1]["id"] if ratios else None


def _site_clauses(code: str) -> dict[str, str]:
    """Return the clause of each number of the document's ``site`` section."""
    both = {
        "FC": "Circ. 2019 C8.7.1.2.1.3 (the confidence factor of the knowledge level)",
        "q": "Circ. 2019 C8.7.1.2.1.7 (q = 2 unless evaluated)",
    }
    if code == "NTC2018":
        return {
            **both,
            "S": "NTC 2018 §3.2.3.2.1 [3.2.3]: S = S_S S_T (Tab. 3.2.IV, 3.2.V)",
            "eta": "NTC 2018 [3.2.4] (the plotted spectrum's damping)",
            "F": "NTC 2018 §3.2.3.2.1: F0 of the hazard",
            "T_B": "NTC 2018 [3.2.6]",
            "T_C": "NTC 2018 [3.2.5] (C_C of Tab. 3.2.IV)",
            "T_D": "NTC 2018 [3.2.7]",
            "pga_g": "NTC 2018 [3.2.2] at T = 0: a_g S",
            "T1": "site building.T1, else Circ. 2019 [C7.3.2] (see T1_source)",
            "spectrum": "NTC 2018 [3.2.2] and [3.2.10]-[3.2.11] at the hazard's damping",
        }
    return {
        **both,
        "S": "EN 1998-1 Tables 3.2-3.3 (cross-checked, theory §11.4)",
        "eta": "EN 1998-1 Eq. 3.6",
        "F": "EN 1998-1 §3.2.2.2: 2.5",
        "T_B": "EN 1998-1 Tables 3.2-3.3",
        "T_C": "EN 1998-1 Tables 3.2-3.3",
        "T_D": "EN 1998-1 Tables 3.2-3.3",
        "pga_g": "EN 1998-1 §3.2.2.2: a_g S, a_g = γ_I a_gR",
        "T1": "site building.T1, else Circ. 2019 [C7.3.2] (see T1_source)",
        "spectrum": "EN 1998-1 Eqs. 3.2-3.5, 3.7 and Annex A",
    }


def check_doc(
    cf: ConstantsFile, site: SiteFile, heights: Optional[dict[str, float]] = None
) -> dict[str, Any]:
    """Code checks of every mechanism of ``cf`` on ``site`` (theory §11).

    Parameters
    ----------
    cf : ConstantsFile
        Mechanisms; those with ``virtual_work`` per side can be checked.
    site : SiteFile
        Hazard (per limit state), FC, q, the building and the check's choices.
    heights : dict of str to float, optional
        Z [m] of mechanisms without ``amplification`` (by id), where the caller knows it
        (``rockmech search``: the base of the moving part): above ground and without a
        building in the site, their check is incomplete as for ``amplification.h > 0``.

    Returns
    -------
    dict
        ``method`` (name, standard, the decisions rockmech takes where the text leaves a
        choice), ``site`` (the code, the spectrum's parameters, the limit states' hazard),
        ``spectrum`` (``T`` [s], ``Se_g`` [g], ``SDe_m`` [m] for plotting), ``mechanisms``
        (per mechanism: ``id``, ``Z`` [m], ``T1`` [s] and their sources, ``free_standing``,
        per side ``linear`` and ``nonlinear``, the governing ones, ``passes`` (SLV) and
        ``passes_SLC``) and ``governing`` (the id with the lowest capacity ratio, or None).
        Every check names the clause of each of its numbers in ``clauses``.

    Raises
    ------
    InputError
        Site choices that contradict the constants (``check_site_inputs``).
    """
    ctx = _Context(cf, site, heights)
    spectrum = ctx.spectrum
    t = np.linspace(0.0, 4.0, 161)
    rows = [_mechanism_row(ctx, mech) for mech in cf.mechanisms]
    hz = site.hazard
    method = {
        "name": ctx.method,
        "standard": CIRC2019 if ctx.method == "circ2019" else CIRC2009,
        "decisions": DECISIONS if ctx.method == "circ2019" else [],
        "xi_SLV_percent": site.local_mechanisms.xi_SLV_percent,
        "xi_SLC_percent": site.local_mechanisms.xi_SLC_percent,
        "note": (
            ""
            if ctx.method == "circ2019"
            else "the Circolare 617/2009 C8A.4 forms, kept for comparison: not the 2019 text"
        ),
    }
    doc: dict[str, Any] = {
        "method": method,
        "site": {
            "code": hz.code,
            "params": spectrum.params,
            "S": spectrum.S,
            "eta": spectrum.eta,
            "F": spectrum.F,
            "T_B": spectrum.T_B,
            "T_C": spectrum.T_C,
            "T_D": spectrum.T_D,
            "pga_g": spectrum.pga,
            "FC": hz.FC,
            "q": hz.q,
            "limit_state": ctx.main,
            "limit_states": ctx.limit_states(),
            "T1": ctx.t1,
            "T1_source": ctx.t1_source,
            "method_note": (
                "the Circolare's kinematic checks applied to the EN 1998-1 spectrum "
                "(EN 1998-3 has no kinematic check of its own)"
                if hz.code == "EC8"
                else ""
            ),
            "building": None if site.building is None else site.building.model_dump(),
            "clauses": _site_clauses(hz.code),
        },
        "spectrum": {
            "T": t.tolist(),
            "Se_g": spectrum.Se(t).tolist(),
            "SDe_m": spectrum.SDe(t).tolist(),
        },
        "mechanisms": rows,
        "governing": _governing(rows),
    }
    doc["conclusion"] = conclusion(doc, site.project.building)
    return doc


def recheck_with_records(
    doc: dict[str, Any],
    cf: ConstantsFile,
    site: SiteFile,
    scaled: Sequence[Sequence[tuple[Any, float]]],
) -> None:
    """Add the records' demand of §C8.7.1.2.1.8 to the nonlinear checks of ``doc``, in place.

    Parameters
    ----------
    doc : dict
        ``check_doc(cf, site)``.
    cf, site
        Its inputs.
    scaled : sequence
        Per mechanism, the records at their design scale: ``(motion, scale)`` pairs.
    """
    if site.local_mechanisms.method != "circ2019":
        return
    ctx = _Context(cf, site)
    for i, (mech, recs) in enumerate(zip(cf.mechanisms, scaled)):
        if not recs:
            continue
        doc["mechanisms"][i] = _mechanism_row(ctx, mech, recs)
    doc["governing"] = _governing(doc["mechanisms"])
