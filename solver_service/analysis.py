"""Analyses over a kinematic-constants file, as JSON-ready documents (CLI and REST share them).

Units: frequencies in Hz, pulse amplitudes in g (names end in ``_g``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Optional

import numpy as np

from shared_schema.constants import ConstantsFile
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

__all__ = [
    "SF_METHODS",
    "boundary_doc",
    "envelope_csv",
    "envelope_doc",
    "frequency_grid",
    "history_doc",
    "write_envelope",
]


def _finite_or_none(values: np.ndarray[Any, Any]) -> list[Optional[float]]:
    return [float(v) if math.isfinite(v) else None for v in values]


def frequency_grid(f_min: float, f_max: float, n: int) -> np.ndarray[Any, Any]:
    """Log-spaced pulse frequencies [Hz], validated."""
    for name, value in (("f_min", f_min), ("f_max", f_max)):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"must be finite and > 0, got {value!r}", name)
    if f_min >= f_max:
        raise InputError(f"must be below f_max ({f_max!r}), got {f_min!r}", "f_min")
    if n < 2:
        raise InputError(f"must be >= 2, got {n!r}", "n")
    return np.geomspace(f_min, f_max, n)


def envelope_doc(
    cf: ConstantsFile,
    f_p: np.ndarray[Any, Any],
    *,
    exact: bool = False,
    library: Optional[OverturningLibrary] = None,
) -> tuple[dict[str, Any], list[Envelope]]:
    """Ground-level envelopes of every mechanism and the critical bands.

    Mechanisms with ``amplification`` are corrected by ``SF(f_p)`` (THEORY §7); the others
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
) -> dict[str, Any]:
    """Write ``<stem>.json``, ``<stem>.csv`` and ``<stem>.png`` (atomically); return the doc."""
    from shared_schema.io import write_atomic

    from .report.plots import plot_envelopes

    doc, envs = envelope_doc(cf, f_p, exact=exact)
    out_dir.mkdir(parents=True, exist_ok=True)
    write_atomic(out_dir / f"{stem}.json", json.dumps(doc, indent=2) + "\n")
    write_atomic(out_dir / f"{stem}.csv", envelope_csv(doc))
    plot_envelopes(
        envs,
        doc["critical"],
        out_dir / f"{stem}.png",
        labels={m.id: f"{m.id}: {m.name}" for m in cf.mechanisms},
        title=title,
    )
    return doc


#: Scale-factor methods of time histories: none, or Eq. 28 from the record's spectrum.
SF_METHODS = ("none", "eq28")


def history_doc(
    cf: ConstantsFile,
    motion: Any,
    scales: list[float],
    *,
    sf: str = "none",
    criterion: Optional[str] = None,
) -> dict[str, Any]:
    """Time histories of every mechanism at every scale, as a JSON-ready document.

    With ``sf = "eq28"`` a mechanism with ``amplification {f_n, h_e, h}`` receives the record
    scaled by ``SF = sqrt(1 + (S_a(T_n)/PGA · h/h_e)²)`` (Eq. 28; ``S_a`` from the record's
    exact 5 %-damped spectrum at ``T_n = 1/f_n``) on top of each user scale; mechanisms at
    ground level are not scaled. Each row then carries ``effective_scale``, and the document
    the factor with its formula and inputs.
    """
    from .core.codes import sf_eq28
    from .core.exact import simulate_batch
    from .core.model import G
    from .core.spectra import response_spectrum

    if sf not in SF_METHODS:
        raise InputError(f"must be one of {list(SF_METHODS)}, got {sf!r}", "sf")
    models = [to_rocking_model(m) for m in cf.mechanisms]
    for model in models:
        model.require_eta()
    factors: dict[str, Any] = {}
    rows: list[dict[str, Any]] = []
    runtime = 0.0
    crit, method = "", ""
    groups: list[tuple[list[Any], float, Optional[str]]] = []
    if sf == "none":
        groups.append((models, 1.0, None))
    else:
        for mech, model in zip(cf.mechanisms, models):
            factor = 1.0
            if mech.amplification is not None:
                amp = mech.amplification
                spec = response_spectrum(motion.accel.acc, motion.dt, [1.0 / amp.f_n])
                info = sf_eq28(float(spec.psa[0]) / G, motion.pga_g, amp.h, amp.h_e)
                factor = float(info["value"])
                factors[mech.id] = info
            groups.append(([model], factor, mech.id))
    for group, factor, _ in groups:
        batch = simulate_batch(
            group, motion.accel, [s * factor for s in scales], criterion=criterion
        )
        runtime += batch.runtime_s
        crit, method = batch.criterion, batch.method
        for row in batch.rows():
            if sf != "none":
                row["effective_scale"] = row["scale"]
                row["scale"] = row["scale"] / factor
            rows.append(row)
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
    return doc
