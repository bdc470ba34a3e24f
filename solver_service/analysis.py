"""Analyses over a kinematic-constants file, as JSON-ready documents (CLI and REST share them).

Units: frequencies in Hz, pulse amplitudes in g (names end in ``_g``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import numpy as np

from shared_schema.constants import ConstantsFile, Mechanism
from shared_schema.errors import InputError

from .adapter import to_rocking_model
from .core.envelope import (
    A_MAX,
    Envelope,
    OverturningLibrary,
    boundary_curve,
    critical_bands,
    governing_one_sided,
    mechanism_envelope,
)
from .core.model import check_positive

__all__ = [
    "SF_METHODS",
    "Building",
    "boundary_doc",
    "dense_runs",
    "envelope_csv",
    "envelope_doc",
    "finite_json",
    "frequency_grid",
    "history_doc",
    "linearisation_notes",
    "log_grid",
    "mechanism_scale_factor",
    "pulse_doc",
    "read_record",
    "record_doc",
    "record_pulse_doc",
    "run_scaled",
    "write_envelope",
    "write_history",
]


def finite_json(value: Any) -> Any:
    """Replace non-finite floats by None and numpy scalars by Python numbers, recursively.

    ``json.dumps`` never calls ``default`` for floats, so NaN and infinity must be cleaned
    before serialising (``allow_nan=False`` then guards the result).
    """
    if isinstance(value, dict):
        return {str(k): finite_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite_json(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def pulse_doc(
    p_eq: float,
    lam: float,
    a_p_g: float,
    f_p: float,
    *,
    eta: Optional[float] = None,
    one_sided: bool = False,
    phi_ov: Optional[float] = None,
    shape: str = "sine",
    criterion: Optional[str] = None,
) -> dict[str, Any]:
    """Response of one mechanism to a one-cycle pulse, as ``rockmech pulse --json`` prints it.

    Parameters
    ----------
    p_eq : float
        Frequency parameter [rad/s].
    lam : float
        Static load multiplier [-].
    a_p_g : float
        Signed pulse amplitude [g] (> 0 first pushes towards negative rotation).
    f_p : float
        Pulse frequency [Hz].
    eta : float, optional
        Coefficient of restitution [-].
    one_sided : bool
        One-sided rocking.
    phi_ov : float, optional
        Overturning rotation [rad]; defaults to ``lam``.
    shape : {"sine", "cosine"}
        Pulse shape.
    criterion : {"exact", "ratio"}, optional
        Overturning verdict (default ``exact`` for pulses).
    """
    from .core.exact import simulate
    from .core.excitation import Pulse
    from .core.model import G, RockingModel

    model = RockingModel.symmetric(p_eq, lam, eta, phi_ov=phi_ov, one_sided=one_sided, name="pulse")
    model.require_eta()
    exc = Pulse(a_p=a_p_g * G, f_p=f_p, shape=shape)
    res = simulate(model, exc, criterion=criterion)
    return {
        "input": {
            "p_eq": p_eq,
            "lam": lam,
            "phi_ov": model.positive.phi_ov,
            "eta": eta,
            "rocking": "one_sided" if one_sided else "two_sided",
            "a_p_g": a_p_g,
            "f_p": f_p,
            "shape": shape,
            "omega_ratio": exc.omega_p / p_eq,
            "amplitude_ratio": abs(a_p_g) / lam,
            "pulse_convention": "A (Zhang & Makris 2001: pulse starts at t = 0)",
        },
        **res.summary(),
    }


def _finite_or_none(values: np.ndarray[Any, Any]) -> list[Optional[float]]:
    return [float(v) if math.isfinite(v) else None for v in values]


#: One-line description of the pulse extraction (``core.pulses``).
PULSE_METHOD = "zero-crossing lobes: two adjacent half-cycles, a_p = the smaller peak"


def log_grid(
    lo: float, hi: float, n: int, *, names: tuple[str, str] = ("f_min", "f_max")
) -> np.ndarray[Any, Any]:
    """Return ``n`` log-spaced values from ``lo`` to ``hi``, validated (errors use ``names``)."""
    for name, value in zip(names, (lo, hi)):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"must be finite and > 0, got {value!r}", name)
    if lo >= hi:
        raise InputError(f"must be below {names[1]} ({hi!r}), got {lo!r}", names[0])
    if n < 2:
        raise InputError(f"must be >= 2, got {n!r}", "n")
    return np.geomspace(lo, hi, n)


def frequency_grid(f_min: float, f_max: float, n: int) -> np.ndarray[Any, Any]:
    """Log-spaced pulse frequencies [Hz], validated."""
    return log_grid(f_min, f_max, n)


def record_doc(motion: Any, spectrum: Any, pulses: list[Any]) -> dict[str, Any]:
    """Describe a record: metadata, its largest sine pulses and its response spectrum.

    Parameters
    ----------
    motion : GroundMotion
        The record.
    spectrum : Spectrum
        Its response spectrum (``core.spectra.response_spectrum``).
    pulses : list of ExtractedPulse
        Its largest sine pulses (``core.pulses.extract_pulses``).
    """
    return {
        "record": {
            "name": motion.name,
            "n_samples": len(motion.accel.acc),
            "dt_s": motion.dt,
            "pga_g": motion.pga_g,
            "duration_s": motion.duration,
            **motion.metadata,
        },
        "pulses": [p.to_dict() for p in pulses],
        "pulse_method": PULSE_METHOD,
        "spectrum": {
            "damping": spectrum.zeta,
            "periods_s": [float(v) for v in spectrum.periods],
            "psa_g": [float(v) for v in spectrum.psa_g],
            "sd_m": [float(v) for v in spectrum.sd],
            "method": "exact piecewise-linear recursion (Nigam-Jennings)",
            "runtime_s": spectrum.runtime_s,
        },
    }


def envelope_doc(
    cf: ConstantsFile,
    f_p: np.ndarray[Any, Any],
    *,
    exact: bool = False,
    library: Optional[OverturningLibrary] = None,
) -> tuple[dict[str, Any], list[Envelope]]:
    """Ground-level envelopes of every mechanism and the critical bands.

    Mechanisms with ``amplification`` are corrected by ``SF(f_p)`` (theory §7); the others
    skip that work entirely.

    Returns
    -------
    doc : dict
        JSON-ready result (see ``rockmech envelope``).
    envelopes : list of Envelope
        The envelopes, for plotting.
    """
    if not cf.mechanisms:
        raise InputError("needs at least one mechanism", "mechanisms")
    if not exact and library is None:
        library = OverturningLibrary.load()
    envelopes: list[Envelope] = []
    entries: list[dict[str, Any]] = []
    for mech in cf.mechanisms:
        model = to_rocking_model(mech)
        sf = None
        if mech.amplification is not None:
            amp = mech.amplification
            if library is not None:
                sf = library.scale_factor(f_p, f_n=amp.f_n, h=amp.h, h_e=amp.h_e)
            else:
                from .core.amplification import pulse_scale_factor

                sf = pulse_scale_factor(f_p, f_n=amp.f_n, h=amp.h, h_e=amp.h_e)
        env = mechanism_envelope(model, f_p, library=library, exact=exact, scale_factor=sf)
        envelopes.append(env)
        entry: dict[str, Any] = {
            "id": mech.id,
            "name": mech.name,
            "rocking": mech.rocking,
            "p_eq": mech.positive.p_eq,
            "lam": mech.positive.lam,
            "a_p_min_g": _finite_or_none(env.a_p_min_g),
        }
        if mech.eta is not None:
            entry["eta"] = mech.eta
        if sf is not None:
            assert mech.amplification is not None
            entry["amplification"] = mech.amplification.model_dump()
            entry["a_p_min_local_g"] = _finite_or_none(env.a_p_min_local_g)
            entry["scale_factor"] = [float(v) for v in env.scale_factor]
        if np.any(env.governing_side != 1):
            entry["governing_side"] = [int(v) for v in env.governing_side]
        entries.append(entry)
    index, bands = critical_bands(envelopes)
    doc: dict[str, Any] = {
        "units": {"f_p": "Hz", "a_p": "g"},
        "f_p": [float(v) for v in f_p],
        "mechanisms": entries,
        "critical": bands,
        "governing": [cf.mechanisms[i].id if i >= 0 else None for i in index],
        "method": (
            {"source": "exact", "a_max": A_MAX}
            if exact or library is None
            else {
                "source": "library",
                "interpolation": "log A_min linear in log Omega and in eta",
                **{
                    k: library.metadata[k]
                    for k in ("library_version", "generated", "scan_ratio", "a_max")
                    if k in library.metadata
                },
            }
        ),
    }
    return doc, envelopes


def boundary_doc(
    omega: float, eta: Optional[float], *, one_sided: bool = False, shape: str = "sine"
) -> dict[str, Any]:
    """Overturning intervals in ``A = a_p/(g lam)`` at one ``Omega = omega_p/p_eq``."""

    def pairs(curve: Any) -> list[list[Optional[float]]]:
        return [[lo, hi] for lo, hi in curve.intervals(0)]

    if one_sided:
        eta_used = 0.0 if eta is None else eta
        pos, neg, a_min, direction = governing_one_sided([omega], eta_used, shape=shape)
        doc: dict[str, Any] = {
            "omega": omega,
            "eta": eta_used,
            "rocking": "one_sided",
            "shape": shape,
            "overturning_intervals": pairs(pos if direction[0] == 1 else neg),
            "governing_direction": "positive" if direction[0] == 1 else "negative",
            "directions": {"positive": pairs(pos), "negative": pairs(neg)},
            "a_min": float(a_min[0]) if math.isfinite(a_min[0]) else None,
        }
        curve = pos
    else:
        if eta is None:
            raise InputError("two-sided rocking needs a coefficient of restitution", "eta")
        curve = boundary_curve([omega], eta, shape=shape)
        doc = {
            "omega": omega,
            "eta": eta,
            "rocking": "two_sided",
            "shape": shape,
            "overturning_intervals": pairs(curve),
            "a_min": float(curve.a_min[0]) if math.isfinite(curve.a_min[0]) else None,
        }
    doc["search"] = {"a_max": curve.a_max, "scan_ratio": curve.scan_ratio, "rtol": curve.rtol}
    return doc


def envelope_csv(doc: dict[str, Any]) -> str:
    """Return an envelope document as CSV: f_p [Hz], a_p_min [g] per mechanism, governing."""
    ids = [m["id"] for m in doc["mechanisms"]]
    lines = ["f_p_Hz," + ",".join(f"a_p_min_g_{i}" for i in ids) + ",governing"]
    for k, f in enumerate(doc["f_p"]):
        vals = [m["a_p_min_g"][k] for m in doc["mechanisms"]]
        cells = ["" if v is None else f"{v:.6g}" for v in vals]
        lines.append(f"{f:.6g}," + ",".join(cells) + f",{doc['governing'][k] or ''}")
    return "\n".join(lines) + "\n"


def write_envelope(
    cf: ConstantsFile,
    f_p: np.ndarray[Any, Any],
    out_dir: Path,
    *,
    stem: str = "envelope",
    title: str = "",
    exact: bool = False,
    record_pulse: Optional[dict[str, Any]] = None,
) -> dict[str, Any]:
    """Write ``<stem>.json``, ``<stem>.csv`` and ``<stem>.png`` (atomically); return the doc.

    ``record_pulse`` (from ``record_pulse_doc``) is added to the JSON and drawn on the plot.
    """
    from shared_schema.io import write_atomic

    from .report.plots import plot_envelopes

    doc, envs = envelope_doc(cf, f_p, exact=exact)
    if record_pulse is not None:
        doc["record_pulse"] = record_pulse
    out_dir.mkdir(parents=True, exist_ok=True)
    write_atomic(out_dir / f"{stem}.json", json.dumps(doc, indent=2) + "\n")
    write_atomic(out_dir / f"{stem}.csv", envelope_csv(doc))
    plot_envelopes(
        envs,
        doc["critical"],
        out_dir / f"{stem}.png",
        labels={m.id: f"{m.id}: {m.name}" for m in cf.mechanisms},
        title=title,
        pulse_points=None if record_pulse is None else record_pulse["points"],
    )
    return doc


def record_pulse_doc(
    cf: ConstantsFile,
    motion: Any,
    scales: list[float],
    *,
    f_min: Optional[float] = None,
    f_max: Optional[float] = None,
    exact: bool = False,
) -> dict[str, Any]:
    """Compare a record's largest sine pulse, at several scale factors, with every envelope.

    Each point ``(f_p, s |a_p|)`` lists the mechanisms whose ground-level envelope lies at
    or below it at ``f_p``: those the pulse alone would overturn at scale ``s``. For
    one-sided mechanisms the envelope is the lower of the two pulse directions, so the
    verdict is the conservative one.

    Parameters
    ----------
    cf : ConstantsFile
        The mechanisms.
    motion : GroundMotion
        The record.
    scales : list of float
        Scale factors on the record [-], each > 0.
    f_min, f_max : float, optional
        Frequency range to search for the pulse [Hz].
    exact : bool
        Evaluate the envelopes at ``f_p`` by the exact boundary search, not the library.
    """
    from .core.pulses import largest_pulse

    for j, value in enumerate(scales):
        check_positive(value, f"scales[{j}]")
    pulse = largest_pulse(motion.accel, f_min=f_min, f_max=f_max)
    at_fp, _ = envelope_doc(cf, np.array([pulse.f_p]), exact=exact)
    a_min = {m["id"]: m["a_p_min_g"][0] for m in at_fp["mechanisms"]}
    points = []
    for scale in scales:
        a_p = scale * abs(pulse.a_p_g)
        points.append(
            {
                "scale": scale,
                "f_p_hz": pulse.f_p,
                "a_p_g": a_p,
                "overturns": [k for k, v in a_min.items() if v is not None and a_p >= v],
            }
        )
    return {
        "record": motion.name,
        "pulse": pulse.to_dict(),
        "method": PULSE_METHOD,
        "a_p_min_g_at_f_p": a_min,
        "points": points,
    }


#: Scale-factor methods of time histories: none, Eq. 28 from the record's spectrum, or the
#: EN 1998-1 and NZS 1170.5 code factors (theory §7.3-7.4).
SF_METHODS = ("none", "eq28", "ec8", "nzs")


@dataclass(frozen=True)
class Building:
    """What the code scale factors need to know about the supporting structure.

    Attributes
    ----------
    height : float, optional
        Height of the building above its foundation, ``H`` (EC8) or ``h_n`` (NZS) [m], > 0.
    soil_factor : float
        EC8 soil factor ``S`` [-], > 0; 1 gives the bare amplification.
    element_period : float
        EC8 fundamental period of the element ``T_a`` [s], >= 0; 0 (the default) takes the
        rocking mechanism as rigid before uplift.
    """

    height: Optional[float] = None
    soil_factor: float = 1.0
    element_period: float = 0.0


def mechanism_scale_factor(
    mech: Mechanism, motion: Any, sf: str, building: Building = Building()
) -> Optional[dict[str, Any]]:
    """Scale factor of the record up the structure for one mechanism, or None at ground level.

    Parameters
    ----------
    mech : Mechanism
        The mechanism; only those with ``amplification {f_n, h_e, h}`` are scaled.
    motion : GroundMotion
        The record (Eq. 28 uses its exact 5 %-damped spectrum at ``T_n = 1/f_n``).
    sf : {"eq28", "ec8", "nzs"}
        Method. EC8 takes ``z = h``, ``T_1 = 1/f_n``; NZS takes ``h_i = h``.
    building : Building
        Building height (EC8 and NZS), soil factor and element period (EC8).

    Returns
    -------
    dict or None
        ``{"value", "method", "formula", "inputs"}`` (``solver_service.core.codes``).
    """
    from .core.codes import sf_ec8, sf_eq28, sf_nzs
    from .core.model import G
    from .core.spectra import response_spectrum

    if sf not in SF_METHODS:
        raise InputError(f"must be one of {list(SF_METHODS)}, got {sf!r}", "sf")
    amp = mech.amplification
    if sf == "none" or amp is None:
        return None
    if sf == "eq28":
        spec = response_spectrum(motion.accel.acc, motion.dt, [1.0 / amp.f_n])
        return sf_eq28(float(spec.psa[0]) / G, motion.pga_g, amp.h, amp.h_e)
    if building.height is None:
        raise InputError(f"--sf {sf} needs the height of the building [m]", "building_height")
    if amp.h > building.height:
        raise InputError(
            f"mechanism {mech.id!r} sits at h = {amp.h:g} m, above the building "
            f"({building.height:g} m)",
            "building_height",
        )
    if sf == "nzs":
        return sf_nzs(amp.h, building.height)
    return sf_ec8(
        amp.h, building.height, building.element_period, 1.0 / amp.f_n, building.soil_factor
    )


def run_scaled(
    cf: ConstantsFile,
    models: list[Any],
    motion: Any,
    scales: list[float],
    sf: str = "none",
    building: Building = Building(),
    criterion: Optional[str] = None,
) -> tuple[dict[str, Any], list[tuple[list[int], Any]]]:
    """Run every mechanism at every scale, each record scaled up the structure by ``sf``.

    Mechanisms that share a factor (all those at ground level) share one compiled batch.

    Returns
    -------
    factors : dict
        Scale-factor record (``mechanism_scale_factor``) per mechanism id that has one.
    batches : list of (indices, BatchResult)
        Which mechanisms (indices into ``cf.mechanisms``) each batch ran; the batch's
        ``scales`` are the effective ones (user scale times factor).
    """
    from .core.exact import simulate_batch

    factors: dict[str, Any] = {}
    groups: dict[float, list[int]] = {}
    for i, mech in enumerate(cf.mechanisms):
        info = mechanism_scale_factor(mech, motion, sf, building)
        if info is not None:
            factors[mech.id] = info
        groups.setdefault(1.0 if info is None else float(info["value"]), []).append(i)
    batches = [
        (
            members,
            simulate_batch(
                [models[i] for i in members],
                motion.accel,
                [s * factor for s in scales],
                criterion=criterion,
            ),
        )
        for factor, members in groups.items()
    ]
    return factors, batches


def history_doc(
    cf: ConstantsFile,
    motion: Any,
    scales: list[float],
    *,
    sf: str = "none",
    building: Building = Building(),
    criterion: Optional[str] = None,
    at_height: Optional[float] = None,
) -> dict[str, Any]:
    """Time histories of every mechanism at every scale, as a JSON-ready document.

    With ``sf`` other than ``"none"`` a mechanism with ``amplification {f_n, h_e, h}``
    receives the record times its scale factor (``mechanism_scale_factor``) on top of each
    user scale; mechanisms at ground level are not scaled. Each row then carries
    ``effective_scale``, and the document the factors with their formulas and inputs.

    With ``at_height = z`` [m] each row also gives ``peak_displacement_m``, the horizontal
    displacement of a point ``z`` above the rotation axis, ``z · max|phi|`` (small
    rotations), to compare with shake-table measurements. For a two-sided mechanism with
    different ``phi_ov`` on its two sides it is the bound ``z · peak_ratio · max(phi_ov)``,
    flagged ``peak_displacement_is_bound``.
    """
    if at_height is not None:
        at_height = check_positive(at_height, "at_height")
    models = [to_rocking_model(m) for m in cf.mechanisms]
    for model in models:
        model.require_eta()
    factors, batches = run_scaled(cf, models, motion, scales, sf, building, criterion)
    per_mech: list[list[dict[str, Any]]] = [[] for _ in models]
    for members, batch in batches:
        rows = batch.rows()
        for k, i in enumerate(members):
            per_mech[i] = rows[k * len(scales) : (k + 1) * len(scales)]
    runtime = sum(batch.runtime_s for _, batch in batches)
    crit, method = batches[0][1].criterion, batches[0][1].method
    for model, mech_rows in zip(models, per_mech):
        pos, neg = model.positive, model.neg
        phi_ov = pos.phi_ov if model.one_sided else max(pos.phi_ov, neg.phi_ov)
        for row, user_scale in zip(mech_rows, scales):
            if sf != "none":
                row["effective_scale"] = row["scale"]
                row["scale"] = user_scale
            if at_height is not None:
                row["peak_displacement_m"] = at_height * row["peak_ratio"] * phi_ov
                if not model.one_sided and pos.phi_ov != neg.phi_ov:
                    row["peak_displacement_is_bound"] = True
    rows = [row for mech_rows in per_mech for row in mech_rows]
    doc: dict[str, Any] = {
        "record": {
            "name": motion.name,
            "dt_s": motion.dt,
            "pga_g": motion.pga_g,
            "duration_s": motion.duration,
            **motion.metadata,
        },
        "criterion": crit,
        "method": method,
        "runtime_s": runtime,
        "results": rows,
    }
    if sf != "none":
        doc["scale_factor_method"] = sf
        doc["scale_factors"] = factors
    if at_height is not None:
        doc["displacement"] = {"height_m": at_height, "formula": "u = z * max|phi| [m]"}
    notes = linearisation_notes(cf, models)
    if notes:
        doc["warnings"] = notes
    return doc


def linearisation_notes(cf: ConstantsFile, models: list[Any]) -> dict[str, list[str]]:
    """Mechanisms whose record response the linear model may miss by more than 10 %.

    Returns ``{mechanism id: [warning, ...]}`` for those only
    (``core.nonlinear.linearisation_warnings``; see docs/numerics.md).
    """
    from .core.nonlinear import linearisation_warnings

    notes = {m.id: linearisation_warnings(model) for m, model in zip(cf.mechanisms, models)}
    return {k: v for k, v in notes.items() if v}


def dense_runs(
    cf: ConstantsFile, motion: Any, doc: dict[str, Any], scale: float
) -> list[tuple[str, float, Any]]:
    """Time series of every mechanism at one user scale, as a history document ran it.

    Each mechanism gets the document's scale factor up the structure on top of ``scale``
    and the document's overturning criterion.

    Returns
    -------
    list of (mechanism id, effective scale, RockingResult)
        The results carry ``t`` and ``ratio`` (``dense=True``).
    """
    from .core.exact import simulate

    factors = {k: v["value"] for k, v in doc.get("scale_factors", {}).items()}
    runs = []
    for mech in cf.mechanisms:
        effective = scale * factors.get(mech.id, 1.0)
        res = simulate(
            to_rocking_model(mech),
            motion.accel,
            scale=effective,
            criterion=doc["criterion"],
            dense=True,
        )
        runs.append((mech.id, effective, res))
    return runs


def read_record(
    path: Path,
    fmt: Optional[str] = None,
    units: Optional[str] = None,
    dt: Optional[float] = None,
) -> Any:
    """Read a record as ``rockmech`` does: format detected, a two-column file in g by default.

    Parameters
    ----------
    path : Path
        The record file.
    fmt, units, dt
        As ``GroundMotion.from_file``; ``units`` defaults to g for a two-column file (the
        t [s], a [g] convention of the bundled record).
    """
    from .core.records import GroundMotion, detect_format

    fmt = fmt or detect_format(path)
    if units is None and fmt == "two_column":
        units = "g"
    return GroundMotion.from_file(path, format=fmt, units=units, dt=dt)


def write_history(
    cf: ConstantsFile,
    motion: Any,
    scales: list[float],
    out_dir: Path,
    *,
    stem: str = "history",
    title: str = "",
    max_panels: int = 6,
    **options: Any,
) -> dict[str, Any]:
    """Write ``<stem>.json``, ``<stem>.png`` and ``<stem>_record.png``; return the doc.

    ``<stem>.png`` shows ``phi/phi_ov`` of every mechanism against time, one panel per
    scale (at most ``max_panels``, evenly chosen, the largest always included);
    ``<stem>_record.png`` the record with its largest sine pulse and its 5 % spectrum.
    ``options`` go to ``history_doc``.
    """
    from shared_schema.io import write_atomic

    from .report.plots import plot_ratio_histories, plot_record

    doc = history_doc(cf, motion, scales, **options)
    out_dir.mkdir(parents=True, exist_ok=True)
    write_atomic(out_dir / f"{stem}.json", json.dumps(doc, indent=2) + "\n")
    order = sorted(set(scales))
    picks = sorted(
        {order[round(k)] for k in np.linspace(0, len(order) - 1, min(max_panels, len(order)))}
    )
    panels = [
        (scale, [(mech_id, res) for mech_id, _, res in dense_runs(cf, motion, doc, scale)])
        for scale in picks
    ]
    plot_ratio_histories(panels, out_dir / f"{stem}.png", title=title or motion.name)
    plot_record(motion, out_dir / f"{stem}_record.png")
    return doc
