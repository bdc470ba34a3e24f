"""The code checks beside rocking dynamics: the check document and the assessment document.

``check_doc`` runs, for every mechanism of a constants file and every stored side, the
linear and nonlinear kinematic checks of NTC 2018 / Circolare §C8.7.1 (docs/theory.md §11)
against the site's elastic spectrum (SITE.json). ``assessment_doc`` adds, per mechanism,
the rocking dynamics on records scaled to the site spectrum and the pulse-envelope margin;
``solver_service.report.assess`` renders it. A mechanism that cannot run an analysis gets a
note in its row; it never stops the others.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from shared_schema.api import MAX_ASSESS_MULTIPLES, MULTIPLE_MAX
from shared_schema.constants import ConstantsFile, Mechanism, SideConstants
from shared_schema.errors import InputError, RockmechError
from shared_schema.rules import check_number
from shared_schema.site import SiteFile

from ..core.exact import simulate
from ..core.hazard import ElasticSpectrum, ec8_spectrum, ntc_spectrum
from ..core.kinematic import Building, VirtualWork, linear_check, nonlinear_check
from ..core.pulses import largest_pulse
from ..core.spectra import response_spectrum
from .adapter import to_rocking_model
from .documents import envelope_doc, log_grid
from .inputs import read_site_file
from .scaling import mechanism_scale_factor

__all__ = [
    "BAND_DEFAULT",
    "MULTIPLE_MAX",
    "T1_COEFFICIENT",
    "assessment_doc",
    "check_doc",
    "check_multiples",
    "matching_band",
    "read_site",
    "record_scale_factor",
    "site_spectrum",
]

#: NTC 2018 §7.3.3.2: T1 = C1 H^(3/4) with C1 = 0.050 for masonry buildings.
T1_COEFFICIENT = 0.05
#: Period band [s] for matching a record to the site spectrum when a mechanism has no Ts
#: (NTC 2018 §3.2.3.6's default band for spectrum compatibility).
BAND_DEFAULT = (0.15, 2.0)
#: The band around a mechanism's secant period Ts: [BAND_LOW Ts, BAND_HIGH Ts].
BAND_LOW, BAND_HIGH = 0.5, 1.5
#: Periods in a matching band.
BAND_POINTS = 40

NO_VIRTUAL_WORK = (
    "no virtual_work in the constants (short form or an older file): the code check needs "
    "the masses' virtual displacements; compute the constants from the geometry with "
    "`rockmech constants`"
)


def read_site(path: Path) -> SiteFile:
    """Read and validate a site file (``inputs.read_site_file``); errors name ``site``."""
    return read_site_file(path)


def site_spectrum(site: SiteFile) -> ElasticSpectrum:
    """Return the site's elastic spectrum (NTC 2018 §3.2.3.2 or EN 1998-1 §3.2.2.2)."""
    hz = site.hazard
    if hz.code == "NTC2018":
        return ntc_spectrum(hz.a_g, hz.F0, hz.Tc_star, hz.soil, hz.topography, hz.xi_percent)
    return ec8_spectrum(hz.a_gR, hz.importance, hz.ground, hz.spectrum_type, hz.xi_percent)


def _building(site: SiteFile, mech: Mechanism) -> tuple[Optional[Building], str]:
    """Return the building for a mechanism's height demand and where T1 came from."""
    b = site.building
    if b is None:
        return None, ""
    if mech.amplification is not None:
        return Building(b.height, b.storeys, 1.0 / mech.amplification.f_n), "1/f_n of the mechanism"
    if b.T1 is not None:
        return Building(b.height, b.storeys, b.T1), "site building.T1"
    return (
        Building(b.height, b.storeys, T1_COEFFICIENT * b.height**0.75),
        "0.05 H^0.75 (NTC 2018 §7.3.3.2)",
    )


def _sides(mech: Mechanism) -> list[tuple[str, SideConstants]]:
    out = [("positive", mech.positive)]
    if mech.negative is not None and not mech.one_sided:
        out.append(("negative", mech.negative))
    return out


def _not_run(method: str, note: str) -> dict[str, Any]:
    return {"method": method, "passes": None, "note": note, "status": "not_run"}


def _side_checks(
    side: SideConstants, spectrum: ElasticSpectrum, site: SiteFile, z: float, bld: Any
) -> tuple[dict[str, Any], dict[str, Any]]:
    lin_m = "NTC 2018 / Circolare §C8.7.1: linear kinematic analysis (SLV)"
    non_m = "NTC 2018 / Circolare §C8.7.1: nonlinear kinematic analysis (SLV)"
    if side.virtual_work is None:
        return _not_run(lin_m, NO_VIRTUAL_WORK), _not_run(non_m, NO_VIRTUAL_WORK)
    v = side.virtual_work
    vw = VirtualWork(v.alpha0, v.mass, v.S, v.J)
    hz = site.hazard
    try:
        lin = linear_check(vw, spectrum, FC=hz.FC, q=hz.q, Z=z, building=bld)
        lin["status"] = "ok"
    except RockmechError as exc:
        lin = _not_run(lin_m, str(exc))
    try:
        assert side.phi_ov is not None  # filled in by validation
        non = nonlinear_check(vw, side.phi_ov, spectrum, FC=hz.FC, Z=z, building=bld)
        non["status"] = "ok"
    except RockmechError as exc:
        non = _not_run(non_m, str(exc))
    return lin, non


def _worst(checks: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Return the governing side: the lowest capacity ratio among the checks that ran."""
    ran = [c for c in checks if c.get("status") == "ok"]
    if not ran:
        return checks[0]
    return min(ran, key=lambda c: c["capacity_ratio"])


def check_doc(cf: ConstantsFile, site: SiteFile) -> dict[str, Any]:
    """Code checks of every mechanism of ``cf`` on ``site`` (theory §11).

    Parameters
    ----------
    cf : ConstantsFile
        Mechanisms; those with ``virtual_work`` per side can be checked.
    site : SiteFile
        Hazard, FC, q and the building.

    Returns
    -------
    dict
        ``site`` (the code, the spectrum's parameters and corner periods), ``spectrum``
        (``T`` [s], ``Se_g`` [g], ``SDe_m`` [m] for plotting), ``mechanisms`` (per
        mechanism: ``id``, ``name``, ``Z`` [m] and its source, per side ``linear`` and
        ``nonlinear``, the governing ``linear`` and ``nonlinear`` and ``passes``), and
        ``governing`` (the id with the lowest capacity ratio, or None).
    """
    spectrum = site_spectrum(site)
    t = np.linspace(0.0, 4.0, 161)
    rows: list[dict[str, Any]] = []
    for mech in cf.mechanisms:
        if mech.amplification is not None:
            z, z_source = mech.amplification.h, "amplification.h"
        else:
            z, z_source = 0.0, "ground level (the constants give no amplification.h)"
        bld, t1_source = _building(site, mech)
        sides: dict[str, Any] = {}
        for name, side in _sides(mech):
            lin, non = _side_checks(side, spectrum, site, z, bld)
            sides[name] = {"linear": lin, "nonlinear": non}
        lin_g = _worst([s["linear"] for s in sides.values()])
        non_g = _worst([s["nonlinear"] for s in sides.values()])
        verdicts = [c["passes"] for c in (lin_g, non_g) if c.get("status") == "ok"]
        rows.append(
            {
                "id": mech.id,
                "name": mech.name,
                "typology": mech.typology,
                "rocking": mech.rocking,
                "Z": z,
                "Z_source": z_source,
                "T1_source": t1_source or None,
                "sides": sides,
                "linear": lin_g,
                "nonlinear": non_g,
                "passes": None if not verdicts or None in verdicts else all(verdicts),
            }
        )
    ratios = [
        (min(c["capacity_ratio"] for c in (r["linear"], r["nonlinear"]) if c["status"] == "ok"), r)
        for r in rows
        if any(c.get("status") == "ok" for c in (r["linear"], r["nonlinear"]))
    ]
    governing = min(ratios, key=lambda p: p[0])[1]["id"] if ratios else None
    hz = site.hazard
    return {
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
            "method_note": (
                "the Circolare's kinematic checks applied to the EN 1998-1 spectrum "
                "(EN 1998-3 has no kinematic check of its own)"
                if hz.code == "EC8"
                else ""
            ),
            "building": None if site.building is None else site.building.model_dump(),
        },
        "spectrum": {
            "T": t.tolist(),
            "Se_g": spectrum.Se(t).tolist(),
            "SDe_m": spectrum.SDe(t).tolist(),
        },
        "mechanisms": rows,
        "governing": governing,
    }


def record_scale_factor(
    motion: Any, spectrum: ElasticSpectrum, band: tuple[float, float]
) -> dict[str, Any]:
    """Scale factor that matches a record's 5 % spectrum to the site spectrum over a band.

    Parameters
    ----------
    motion : GroundMotion
        The record.
    spectrum : ElasticSpectrum
        The target (site) spectrum.
    band : (float, float)
        Periods [s], ``0 < T_lo < T_hi``.

    Returns
    -------
    dict
        ``value`` (the factor), ``band`` [s], ``method``.

    Notes
    -----
    ``SF = exp(mean(ln(S_e(T) / S_a(T))))`` over ``BAND_POINTS`` log-spaced periods: the
    scaled record's pseudo-acceleration spectrum matches the target in the geometric mean
    over the band (theory §11.4).
    """
    lo, hi = band
    periods = log_grid(lo, hi, BAND_POINTS, names=("band[0]", "band[1]"))
    sa = response_spectrum(motion.accel.acc, motion.dt, periods, 0.05).psa_g
    if np.any(sa <= 0.0):
        raise InputError("the record's spectrum is zero in the matching band", "record")
    target = spectrum.Se(periods)
    value = float(np.exp(np.mean(np.log(target / sa))))
    return {
        "value": value,
        "band": [lo, hi],
        "method": "geometric mean of S_e/S_a (5 %) over the band",
    }


def matching_band(row: dict[str, Any]) -> tuple[float, float]:
    """Periods [s] over which records are matched to the site spectrum for one mechanism.

    ``[BAND_LOW Ts, BAND_HIGH Ts]`` from the row's nonlinear check (``check_doc``), else
    ``BAND_DEFAULT``.
    """
    non = row["nonlinear"]
    if non.get("status") == "ok" and math.isfinite(non["Ts"]):
        return BAND_LOW * non["Ts"], BAND_HIGH * non["Ts"]
    return BAND_DEFAULT


def _record_runs(
    model: Any, mech: Mechanism, motion: Any, design: dict[str, Any], multiples: Sequence[float]
) -> dict[str, Any]:
    """Run one mechanism on one record at multiples of its design scale."""
    height = mechanism_scale_factor(mech, motion, "eq28")
    up = 1.0 if height is None else float(height["value"])
    runs = []
    first_ov = None
    for k in multiples:
        scale = design["value"] * k
        res = simulate(model, motion.accel, scale=scale * up)
        runs.append(
            {
                "multiple": k,
                "scale": scale,
                "peak_ratio": float(res.peak_ratio),
                "overturned": bool(res.overturned),
            }
        )
        if res.overturned and first_ov is None:
            first_ov = k
    at_design = [r for r in runs if r["multiple"] == 1.0]
    return {
        "record": motion.name,
        "scale_factor": design,
        "height_factor": height,
        "runs": runs,
        "first_overturning_multiple": first_ov,
        "survives_design": (not at_design[0]["overturned"]) if at_design else None,
    }


def _envelope_margin(
    mech: Mechanism, motions: Sequence[Any], designs: Sequence[Optional[float]], freq: Any
) -> dict[str, Any]:
    """Margin ``a_p,min / a_p`` of each record's largest pulse at its design scale."""
    if mech.eta is None:
        return {"note": "no eta in the constants: the envelope needs it"}
    try:
        env, _ = envelope_doc(ConstantsFile(mechanisms=[mech]), np.asarray(freq, dtype=float))
    except RockmechError as exc:
        return {"note": f"not run: {exc}"}
    curve = np.array([np.nan if v is None else v for v in env["mechanisms"][0]["a_p_min_g"]])
    out: dict[str, Any] = {"f_p": [float(v) for v in freq], "a_p_min_g": curve.tolist()}
    pulses = []
    for motion, design in zip(motions, designs):
        if design is None:
            continue
        try:
            p = largest_pulse(motion.accel)
        except RockmechError:
            continue
        a_p = abs(p.a_p_g) * design
        ok = np.isfinite(curve)
        a_min = float(np.interp(p.f_p, np.asarray(freq)[ok], curve[ok])) if ok.any() else math.nan
        pulses.append(
            {
                "record": motion.name,
                "f_p": float(p.f_p),
                "a_p_g": a_p,
                "a_p_min_g": a_min,
                "margin": a_min / a_p if a_p > 0.0 and math.isfinite(a_min) else None,
            }
        )
    out["pulses"] = pulses
    return out


def check_multiples(multiples: Sequence[float]) -> list[float]:
    """Return the multiples of the design scale as floats: 1 to 8 of them, each in (0, 100].

    Raises
    ------
    InputError
        Too few or too many (field ``multiples``), or one outside ``(0, MULTIPLE_MAX]``
        (field ``multiples[j]``).

    Examples
    --------
    >>> check_multiples([0.5, 1])
    [0.5, 1.0]
    """
    if not 1 <= len(multiples) <= MAX_ASSESS_MULTIPLES:
        raise InputError(
            f"give 1 to {MAX_ASSESS_MULTIPLES} multiples of the design scale, got {len(multiples)}",
            "multiples",
        )
    out = []
    for j, value in enumerate(multiples):
        v = check_number(value, f"multiples[{j}]")
        if not 0.0 < v <= MULTIPLE_MAX:
            raise InputError(
                f"a multiple of the design scale must be in (0, {MULTIPLE_MAX:g}], got {v:g}",
                f"multiples[{j}]",
            )
        out.append(v)
    return out


def assessment_doc(
    cf: ConstantsFile,
    site: SiteFile,
    motions: Sequence[Any],
    *,
    multiples: Sequence[float] = (0.5, 1.0, 1.5, 2.0),
    f_p: Optional[Sequence[float]] = None,
) -> dict[str, Any]:
    """Return the check document plus rocking dynamics on records scaled to the site spectrum.

    Parameters
    ----------
    cf, site
        As ``check_doc``.
    motions : sequence of GroundMotion
        Records; each is scaled per mechanism to the site spectrum over the mechanism's band
        (``[0.5 Ts, 1.5 Ts]`` from the nonlinear check, else ``BAND_DEFAULT``) and, above
        ground, amplified by Eq. 28; then run at ``multiples`` of that design scale.
    multiples : sequence of float
        Multiples of the design scale factor to run (1 is the design level): 1 to 8, each in
        ``(0, MULTIPLE_MAX]`` (``check_multiples``).
    f_p : sequence of float, optional
        Pulse frequencies [Hz] of the envelope margin (default 0.1-10 Hz, 120 points).

    Returns
    -------
    dict
        ``check_doc``'s keys and ``records``; each mechanism row gains ``dynamics`` (per
        record: the design scale factor and band, per multiple the peak ratio and verdict,
        the first multiple that overturns, ``survives_design``) and ``envelope`` (the
        envelope and each record's largest pulse at design scale with the margin
        ``a_p,min / a_p``); a part that cannot run carries a ``note`` instead.
    """
    multiples = check_multiples(multiples)
    doc = check_doc(cf, site)
    spectrum = site_spectrum(site)
    freq = np.asarray(f_p if f_p is not None else log_grid(0.1, 10.0, 120), dtype=float)
    for row, mech in zip(doc["mechanisms"], cf.mechanisms):
        band = matching_band(row)
        try:
            model = to_rocking_model(mech)
        except RockmechError as exc:
            row["dynamics"] = []
            row["dynamics_note"] = f"not run: {exc}"
            row["envelope"] = {"note": f"not run: {exc}"}
            continue
        dyn: list[dict[str, Any]] = []
        designs: list[Optional[float]] = []
        for motion in motions:
            try:
                design = record_scale_factor(motion, spectrum, band)
                designs.append(design["value"])
                dyn.append(_record_runs(model, mech, motion, design, multiples))
            except RockmechError as exc:
                designs.append(None)
                dyn.append({"record": motion.name, "note": f"not run: {exc}"})
        row["dynamics"] = dyn
        row["envelope"] = _envelope_margin(mech, motions, designs, freq)
    doc["records"] = [
        {"name": m.name, "pga_g": m.pga_g, "dt": m.dt, "duration": m.duration} for m in motions
    ]
    doc["multiples"] = list(multiples)
    return doc
