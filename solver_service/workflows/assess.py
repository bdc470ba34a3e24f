"""The code checks beside rocking dynamics: the check document and the assessment document.

``check_doc`` (``workflows.codecheck``) runs, for every mechanism of a constants file and
every stored side, the linear and nonlinear checks of the Circolare 21 gennaio 2019 n. 7
§C8.7.1 (docs/theory.md §11) against the site's elastic spectrum (SITE.json).
``assessment_doc`` adds, per mechanism, the records' demand of §C8.7.1.2.1.8, the rocking
dynamics on records scaled to the site spectrum and the pulse-envelope margin;
``solver_service.report.assess`` renders it. A mechanism that cannot run an analysis gets a
note in its row; it never stops the others.
"""

from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import numpy as np

from shared_schema.api import MAX_ASSESS_MULTIPLES, MULTIPLE_MAX
from shared_schema.constants import ConstantsFile, Mechanism
from shared_schema.documents.assess import AssessDocument
from shared_schema.documents.check import CheckDocument
from shared_schema.errors import InputError, RockmechError
from shared_schema.paths import Source
from shared_schema.rules import check_number
from shared_schema.site import SiteFile

from ..codes.hazard import ElasticSpectrum
from ..core.exact import simulate
from ..core.pulses import largest_pulse
from ..core.spectra import response_spectrum
from .adapter import to_rocking_model
from .codecheck import (
    NO_VIRTUAL_WORK,
    T1_COEFFICIENT,
    check_doc,
    recheck_with_records,
    site_spectrum,
)
from .documents import envelope_doc, log_grid
from .inputs import read_site_file
from .limits import ASSESS_ENVELOPE
from .scaling import mechanism_scale_factor
from .units import stamp
from .verdict import conclusion

__all__ = [
    "BAND_DEFAULT",
    "MULTIPLE_MAX",
    "NO_VIRTUAL_WORK",
    "T1_COEFFICIENT",
    "assessment_doc",
    "assessment_document",
    "check_doc",
    "check_doc_with_records",
    "check_document",
    "check_multiples",
    "matching_band",
    "read_site",
    "record_scale_factor",
    "site_spectrum",
    "typed_assessment",
    "typed_check",
]

#: Period band [s] for matching a record to the site spectrum when a mechanism has no T_SLV
#: (NTC 2018 §3.2.3.6's default band for spectrum compatibility).
BAND_DEFAULT = (0.15, 2.0)
#: The band around a mechanism's period T_SLV: [BAND_LOW T_SLV, BAND_HIGH T_SLV].
BAND_LOW, BAND_HIGH = 0.5, 1.5
#: Periods in a matching band.
BAND_POINTS = 40


def read_site(path: Source) -> SiteFile:
    """Read and validate a site file, a path or an open file (``inputs.read_site_file``).

    Errors name ``site``.
    """
    return read_site_file(path)


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

    ``[BAND_LOW T, BAND_HIGH T]`` around the period of the row's nonlinear check
    (``check_doc``: ``T_SLV`` of the Circolare 2019, ``Ts`` of the 2009 forms), else
    ``BAND_DEFAULT``.
    """
    non = row["nonlinear"]
    period = non.get("T_SLV", non.get("Ts")) if non.get("status") == "ok" else None
    if isinstance(period, (int, float)) and math.isfinite(period) and period > 0.0:
        return BAND_LOW * period, BAND_HIGH * period
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
    curve = np.array([np.nan if v is None else v for v in env.mechanisms[0].a_p_min_g])
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


def check_doc_with_records(
    cf: ConstantsFile, site: SiteFile, motions: Sequence[Any]
) -> tuple[dict[str, Any], list[list[Any]]]:
    """Return the code checks with the records' demand of §C8.7.1.2.1.8, as assess runs them.

    The one home of the rule (``rockmech assess`` and ``rockmech retrofit`` both call it):
    each record is matched to the site spectrum over the band of each mechanism's own
    nonlinear check (``matching_band``, ``record_scale_factor``), and at that design scale
    the nonlinear check's demand becomes the larger of the spectrum's and the records'
    (``codecheck.recheck_with_records``).

    Parameters
    ----------
    cf, site
        As ``check_doc``.
    motions : sequence of GroundMotion
        Records (none: ``check_doc`` alone).

    Returns
    -------
    doc : dict
        ``check_doc(cf, site)`` with the records' demand in its nonlinear checks.
    matched : list of list
        Per mechanism and record, the design scale (``record_scale_factor``'s dict) or the
        ``RockmechError`` that kept the record from being matched.
    """
    doc = check_doc(cf, site)
    spectrum = site_spectrum(site)
    # The design scale of each record per mechanism (its band comes from the code check).
    matched: list[list[Any]] = []
    for row in doc["mechanisms"]:
        band = matching_band(row)
        per_record: list[Any] = []
        for motion in motions:
            try:
                per_record.append(record_scale_factor(motion, spectrum, band))
            except RockmechError as exc:
                per_record.append(exc)
        matched.append(per_record)
    if motions:
        # C8.7.1.2.1.8: with records, the demand is also their largest S_De over [T0, T_SLV].
        recheck_with_records(
            doc,
            cf,
            site,
            [
                [(m, d["value"]) for m, d in zip(motions, per) if isinstance(d, dict)]
                for per in matched
            ],
        )
    return doc, matched


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
        (``[0.5 T_SLV, 1.5 T_SLV]`` from the nonlinear check, else ``BAND_DEFAULT``); at that
        design scale it adds its demand to the nonlinear check (§C8.7.1.2.1.8) and, above
        ground amplified by Eq. 28, it is run at ``multiples`` of that design scale.
    multiples : sequence of float
        Multiples of the design scale factor to run (1 is the design level): 1 to 8, each in
        ``(0, MULTIPLE_MAX]`` (``check_multiples``).
    f_p : sequence of float, optional
        Pulse frequencies [Hz] of the envelope margin (default 0.1-10 Hz, 120 points).

    Returns
    -------
    dict
        ``check_doc``'s keys and ``records`` (name, PGA, dt, duration and, where there
        are any, the record's ``warnings``); each mechanism row gains ``dynamics`` (per
        record: the design scale factor and band, per multiple the peak ratio and verdict,
        the first multiple that overturns, ``survives_design``) and ``envelope`` (the
        envelope and each record's largest pulse at design scale with the margin
        ``a_p,min / a_p``); a part that cannot run carries a ``note`` instead.
    """
    multiples = check_multiples(multiples)
    doc, matched = check_doc_with_records(cf, site, motions)
    freq = np.asarray(f_p if f_p is not None else log_grid(*ASSESS_ENVELOPE), dtype=float)
    for row, mech, per_record in zip(doc["mechanisms"], cf.mechanisms, matched):
        try:
            model = to_rocking_model(mech)
        except RockmechError as exc:
            row["dynamics"] = []
            row["dynamics_note"] = f"not run: {exc}"
            row["envelope"] = {"note": f"not run: {exc}"}
            continue
        dyn: list[dict[str, Any]] = []
        designs: list[Optional[float]] = []
        for motion, design in zip(motions, per_record):
            if not isinstance(design, dict):
                designs.append(None)
                dyn.append({"record": motion.name, "note": f"not run: {design}"})
                continue
            try:
                designs.append(design["value"])
                dyn.append(_record_runs(model, mech, motion, design, multiples))
            except RockmechError as exc:
                designs[-1] = None
                dyn.append({"record": motion.name, "note": f"not run: {exc}"})
        row["dynamics"] = dyn
        row["envelope"] = _envelope_margin(mech, motions, designs, freq)
    # a record's warnings (implausible PGA or time step, naming the units read) go with it
    doc["records"] = [
        {
            "name": m.name,
            "pga_g": m.pga_g,
            "dt": m.dt,
            "duration": m.duration,
            **({"warnings": m.warnings} if m.warnings else {}),
        }
        for m in motions
    ]
    doc["multiples"] = list(multiples)
    doc["conclusion"] = conclusion(doc, site.project.building)
    return doc


def typed_check(doc: dict[str, Any]) -> CheckDocument:
    """Return a ``check_doc`` as the typed document, stamped (units, version) and validated."""
    return CheckDocument.model_validate(stamp(doc, "check"))


def typed_assessment(doc: dict[str, Any]) -> AssessDocument:
    """Return an ``assessment_doc`` as the typed document, stamped and validated."""
    return AssessDocument.model_validate(stamp(doc, "assess"))


def check_document(cf: ConstantsFile, site: SiteFile) -> CheckDocument:
    """Code checks of every mechanism on a site: the document ``rockmech check --json`` prints.

    ``check_doc`` (the working form the retrofit and the search read) as a ``CheckDocument``.
    """
    return typed_check(check_doc(cf, site))


def assessment_document(
    cf: ConstantsFile,
    site: SiteFile,
    motions: Sequence[Any],
    *,
    multiples: Sequence[float] = (0.5, 1.0, 1.5, 2.0),
) -> AssessDocument:
    """Return the assessment as the document ``rockmech assess --json`` prints."""
    return typed_assessment(assessment_doc(cf, site, motions, multiples=multiples))
