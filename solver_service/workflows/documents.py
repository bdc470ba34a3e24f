"""JSON-ready documents of every analysis (CLI ``--json``, REST answers, Rhino flows).

Units: frequencies in Hz, pulse amplitudes and PGA in g (names end in ``_g``), SI otherwise.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from shared_schema.constants import ConstantsFile
from shared_schema.documents.boundary import BoundaryDocument
from shared_schema.documents.envelope import EnvelopeDocument, RecordPulse
from shared_schema.documents.history import HistoryDocument
from shared_schema.documents.record import RecordDocument
from shared_schema.errors import InputError
from shared_schema.rules import ENVELOPE_METHODS, check_choice

from ..core.amplification import pulse_scale_factor
from ..core.envelope import (
    A_MAX,
    LIBRARY_ABOVE,
    LIBRARY_BELOW,
    LIBRARY_EDGE_RATIO,
    LIBRARY_MARGIN,
    LIBRARY_PATH,
    Envelope,
    OverturningLibrary,
    boundary_curve,
    critical_bands,
    governing_one_sided,
    mechanism_envelope,
)
from ..core.linearisation import linearisation_warnings
from ..core.model import check_positive
from ..core.pulses import extract_pulses, largest_pulse
from ..core.records import GroundMotion
from ..core.spectra import Spectrum, response_spectrum
from .adapter import to_rocking_model
from .scaling import Building, option_notes, run_scaled
from .units import stamp

__all__ = [
    "PULSE_METHOD",
    "band_edges",
    "boundary_doc",
    "envelope_doc",
    "frequency_grid",
    "history_doc",
    "linearisation_notes",
    "log_grid",
    "pick_mechanism",
    "pulse_model",
    "record_analysis",
    "record_doc",
    "record_pulse_doc",
    "solve_pulse",
    "time_domain_mechanisms",
]

if TYPE_CHECKING:
    from .pulse import pick_mechanism, pulse_model, solve_pulse

#: The pulse analysis's names, re-exported from ``workflows.pulse`` on first use (``__getattr__``).
_PULSE_NAMES = ("pick_mechanism", "pulse_model", "solve_pulse")


def __getattr__(name: str) -> Any:
    # workflows.pulse loads the exact solver (numba); the envelopes' importers (the search's
    # ranking) need none of it, so it is imported when one of its names is asked for (#38).
    if name in _PULSE_NAMES:
        # the pulse analysis (the exact solver, numba), on first use of one of its names
        from . import pulse

        return getattr(pulse, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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


def record_doc(motion: Any, spectrum: Any, pulses: list[Any]) -> RecordDocument:
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
    doc = {
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
    return RecordDocument.model_validate(stamp(doc, "record"))


def record_analysis(
    motion: GroundMotion,
    periods: Any,
    zeta: float = 0.05,
    *,
    n_pulses: int = 5,
    f_min: Optional[float] = None,
    f_max: Optional[float] = None,
) -> tuple[RecordDocument, Spectrum, list[Any]]:
    """Compute the spectrum and largest sine pulses of a record once, with their document.

    Parameters
    ----------
    motion : GroundMotion
        The record.
    periods : array_like of float
        Periods of the spectrum [s].
    zeta : float
        Damping ratio [-].
    n_pulses : int
        How many of the largest pulses to list, >= 1 (field ``pulses``).
    f_min, f_max : float, optional
        Pulse search range [Hz].

    Returns
    -------
    doc : RecordDocument
        ``record_doc`` (``rockmech record --json``, ``POST /spectrum``).
    spectrum : Spectrum
        The spectrum, for plots.
    pulses : list of ExtractedPulse
        The pulses, for plots.
    """
    if isinstance(n_pulses, bool) or int(n_pulses) < 1:  # the user's name for it, not n
        raise InputError(f"must be >= 1, got {n_pulses!r}", "pulses")
    found = extract_pulses(motion.accel, f_min=f_min, f_max=f_max, n=n_pulses)
    spectrum = response_spectrum(motion.accel.acc, motion.dt, periods, zeta)
    return record_doc(motion, spectrum, found), spectrum, found


def library_label(library: OverturningLibrary) -> str:
    """Say which library file a result used: the shipped one, or the user's own build."""
    if library.path is None:
        return "built in this process"
    if library.path.resolve() == LIBRARY_PATH.resolve():
        return "shipped with rockmech"
    return f"{library.path} (not the shipped library)"


def envelope_doc(
    cf: ConstantsFile,
    f_p: np.ndarray[Any, Any],
    *,
    method: Optional[str] = None,
    library: Optional[OverturningLibrary] = None,
    record_pulse: Optional[RecordPulse] = None,
) -> tuple[EnvelopeDocument, list[Envelope]]:
    """Ground-level envelopes of every mechanism and the critical bands.

    Mechanisms with ``amplification`` are corrected by ``SF(f_p)`` (theory §7); the others
    skip that work entirely.

    Parameters
    ----------
    cf : ConstantsFile
        The mechanisms.
    f_p : (n,) float
        Pulse frequencies [Hz], increasing.
    method : {"exact", "library"}, optional
        ``exact`` (the default unless ``library`` is given): the exact integrator at every
        frequency. ``library``: the fast
        mode, interpolated from the library (loaded unless given), exact where it cannot
        interpolate safely; never above the exact value, at most ``LIBRARY_BELOW`` below,
        band edges within ``LIBRARY_EDGE_RATIO`` (docs/envelopes.md).
    library : OverturningLibrary, optional
        The library of the fast mode (the shipped one by default).
    record_pulse : RecordPulse, optional
        A record's largest pulse against the envelopes (``record_pulse_doc``), kept in the
        document.

    Returns
    -------
    doc : EnvelopeDocument
        The document ``rockmech envelope --json`` prints: ``critical`` bands and
        ``critical_edges``, the frequency interval [Hz] that holds each edge between two
        bands as the exact envelopes place it.
    envelopes : list of Envelope
        The envelopes, for plotting.
    """
    if method is None:
        method = "exact" if library is None else "library"
    method = check_choice(method, ENVELOPE_METHODS, "method")
    if not cf.mechanisms:
        raise InputError("needs at least one mechanism", "mechanisms")
    if method == "library" and library is None:
        library = OverturningLibrary.load()
    fast = library if method == "library" else None
    envelopes: list[Envelope] = []
    entries: list[dict[str, Any]] = []
    for mech in cf.mechanisms:
        model = to_rocking_model(mech)
        sf = None
        if mech.amplification is not None:
            amp = mech.amplification
            if fast is not None:
                sf = fast.scale_factor(f_p, f_n=amp.f_n, h=amp.h, h_e=amp.h_e)
            else:
                sf = pulse_scale_factor(f_p, f_n=amp.f_n, h=amp.h, h_e=amp.h_e)
        env = mechanism_envelope(model, f_p, library=fast, exact=fast is None, scale_factor=sf)
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
        if env.notes:
            entry["notes"] = list(env.notes)
        entries.append(entry)
    index, bands = critical_bands(envelopes)
    edge_ratio = 1.0 if fast is None else LIBRARY_EDGE_RATIO
    doc: dict[str, Any] = {
        "units": {"f_p": "Hz", "a_p": "g"},
        "f_p": [float(v) for v in f_p],
        "mechanisms": entries,
        "critical": bands,
        "critical_edges": band_edges(np.asarray(f_p, dtype=float), index, cf, edge_ratio),
        "governing": [cf.mechanisms[i].id if i >= 0 else None for i in index],
        "method": _envelope_method(fast, envelopes),
    }
    if record_pulse is not None:
        doc["record_pulse"] = record_pulse
    return EnvelopeDocument.model_validate(stamp(doc, "envelope")), envelopes


def _envelope_method(
    library: Optional[OverturningLibrary], envelopes: list[Envelope]
) -> dict[str, Any]:
    """Return the ``method`` block of an envelope document: how the values were computed."""
    if library is None:
        return {
            "source": "exact",
            "a_max": A_MAX,
            "note": "exact integrator at every frequency; band edges lie between the last "
            "frequency of one band and the first of the next",
        }
    return {
        "source": "library",
        "label": "fast mode (interpolated library)",
        "library_file": library_label(library),
        "interpolation": "log A_min linear in log Omega and in eta, times "
        f"{LIBRARY_MARGIN:g}; exact where the interpolation crosses a jump or leaves the grid",
        "exact_points": int(sum(e.n_exact for e in envelopes)),
        "bound": {"above_exact": LIBRARY_ABOVE, "below_exact": LIBRARY_BELOW},
        "edge_ratio": LIBRARY_EDGE_RATIO,
        **{
            k: library.metadata[k]
            for k in ("library_version", "generated", "scan_ratio", "a_max")
            if k in library.metadata
        },
    }


def band_edges(
    f_p: np.ndarray[Any, Any], index: np.ndarray[Any, Any], cf: ConstantsFile, ratio: float = 1.0
) -> list[dict[str, Any]]:
    """Where the governing mechanism changes: the frequency interval that holds each edge.

    Parameters
    ----------
    f_p : (n,) float
        Pulse frequencies [Hz], increasing.
    index : (n,) int
        Governing mechanism per frequency (-1: none overturns), as ``critical_bands``.
    cf : ConstantsFile
        The mechanisms (for their ids).
    ratio : float
        Frequency tolerance of the method (1 when exact): the interval is widened by this
        factor on each side [-].

    Returns
    -------
    list of dict
        ``{"below", "above", "f_low", "f_high"}``: the mechanism governing below and above
        the edge (None: none overturns), and the interval [Hz] in which the exact
        envelopes change over: ``[f_k / ratio, f_(k+1) * ratio]`` between the last
        frequency ``f_k`` of one band and the first of the next.
    """
    ids = [m.id for m in cf.mechanisms]
    edges = []
    for k in range(len(f_p) - 1):
        if index[k] != index[k + 1]:
            edges.append(
                {
                    "below": ids[index[k]] if index[k] >= 0 else None,
                    "above": ids[index[k + 1]] if index[k + 1] >= 0 else None,
                    "f_low": float(f_p[k] / ratio),
                    "f_high": float(f_p[k + 1] * ratio),
                }
            )
    return edges


def boundary_doc(
    omega: float, eta: Optional[float], *, one_sided: bool = False, shape: str = "sine"
) -> BoundaryDocument:
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
    return BoundaryDocument.model_validate(stamp(doc, "boundary"))


def record_pulse_doc(
    cf: ConstantsFile,
    motion: Any,
    scales: list[float],
    *,
    f_min: Optional[float] = None,
    f_max: Optional[float] = None,
    method: str = "exact",
) -> RecordPulse:
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
    method : {"exact", "library"}
        How the envelopes are evaluated at ``f_p`` (``envelope_doc``).
    """
    for j, value in enumerate(scales):
        check_positive(value, f"scales[{j}]")
    pulse = largest_pulse(motion.accel, f_min=f_min, f_max=f_max)
    at_fp, _ = envelope_doc(cf, np.array([pulse.f_p]), method=method)
    a_min = {m.id: m.a_p_min_g[0] for m in at_fp.mechanisms}
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
    return RecordPulse.model_validate(
        {
            "record": motion.name,
            "pulse": pulse.to_dict(),
            "method": PULSE_METHOD,
            "a_p_min_g_at_f_p": a_min,
            "points": points,
        }
    )


def history_doc(
    cf: ConstantsFile,
    motion: Any,
    scales: list[float],
    *,
    sf: str = "none",
    building: Building = Building(),
    criterion: Optional[str] = None,
    at_height: Optional[float] = None,
    runs: Optional[dict[tuple[str, float], Any]] = None,
) -> HistoryDocument:
    """Time histories of every mechanism at every scale (``rockmech history --json``).

    With ``sf`` other than ``"none"`` a mechanism with ``amplification {f_n, h_e, h}``
    receives the record times its scale factor (``mechanism_scale_factor``) on top of each
    user scale; mechanisms at ground level are not scaled. Each row then carries
    ``effective_scale``, and the document the factors with their formulas and inputs.

    With ``at_height = z`` [m] each row also gives ``peak_displacement_m``, the horizontal
    displacement of a point ``z`` above the rotation axis, ``z · max|phi|`` (small
    rotations), to compare with shake-table measurements. For a two-sided mechanism with
    different ``phi_ov`` on its two sides it is the bound ``z · peak_ratio · max(phi_ov)``,
    flagged ``peak_displacement_is_bound``.

    Given a ``runs`` dict, each run is made once with its time series, which is kept in
    ``runs[(mechanism id, user scale)]`` for plots (``run_scaled``); the document is the same.
    """
    if at_height is not None:
        at_height = check_positive(at_height, "at_height")
    cf, skipped = time_domain_mechanisms(cf)
    models = [to_rocking_model(m) for m in cf.mechanisms]
    factors, batches = run_scaled(cf, models, motion, scales, sf, building, criterion, runs)
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
    if skipped:
        doc["skipped"] = skipped
    options = option_notes(cf, sf, building)
    if options:
        doc["option_warnings"] = options
    notes = linearisation_notes(cf, models)
    if notes:
        doc["warnings"] = notes
    return HistoryDocument.model_validate(stamp(doc, "history"))


def time_domain_mechanisms(cf: ConstantsFile) -> tuple[ConstantsFile, list[dict[str, str]]]:
    """Split a constants file into the mechanisms a time history can run and the others.

    A time-domain analysis needs a coefficient of restitution; a mechanism without one
    (envelope-only data) is skipped with a note rather than stopping the others.

    Returns
    -------
    runnable : ConstantsFile
        The mechanisms with ``eta``.
    skipped : list of dict
        ``{"mechanism": id, "reason": ...}`` for each mechanism left out.

    Raises
    ------
    InputError
        If no mechanism can run (``mechanisms``).
    """
    keep, skipped = [], []
    for mech in cf.mechanisms:
        if mech.eta is None:
            kind = mech.rocking.replace("_", "-")
            skipped.append(
                {
                    "mechanism": mech.id,
                    "reason": f"a time history of a {kind} mechanism needs a coefficient of "
                    "restitution (eta), which the constants file does not give",
                }
            )
        else:
            keep.append(mech)
    if not keep:
        reasons = "; ".join(f"{s['mechanism']}: {s['reason']}" for s in skipped)
        raise InputError(f"no mechanism can run a time history ({reasons})", "mechanisms")
    return cf.model_copy(update={"mechanisms": keep}), skipped


def linearisation_notes(cf: ConstantsFile, models: list[Any]) -> dict[str, list[str]]:
    """Mechanisms whose record response the linear model may miss by more than 10 %.

    Returns ``{mechanism id: [warning, ...]}`` for those only
    (``core.nonlinear.linearisation_warnings``; see docs/numerics.md).
    """
    notes = {m.id: linearisation_warnings(model) for m, model in zip(cf.mechanisms, models)}
    return {k: v for k, v in notes.items() if v}
