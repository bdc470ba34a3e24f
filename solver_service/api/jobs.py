"""The computations behind the service's endpoints, run inside a compute process.

Each job takes JSON-ready parameters (already type-checked by the request models), the raw
bytes of any uploads and the service's size limits, and returns the response body. The
documents are the ones ``rockmech ... --json`` prints, so the service and the CLI agree;
errors are ``RockmechError`` with the CLI's messages.

Uploads never name a path on the server: a record upload is written under a sanitised
version of its file name into a private temporary folder (the readers take files), and that
folder's path is removed from any message.

Units: SI, pulse amplitudes and PGA in g (names end in ``_g``).
"""

from __future__ import annotations

import json
import math
import re
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import numpy as np

from rhino_plugin.mechanisms.build import constants_from_spec
from rhino_plugin.scenes import read_scene
from shared_schema.constants import parse_constants
from shared_schema.errors import InputError, RockmechError
from shared_schema.extras import MissingExtra
from shared_schema.spec import parse_spec

from ..core import codes
from ..core.envelope import OverturningLibrary
from ..core.exact import simulate, simulate_batch
from ..core.excitation import Pulse, SampledAccel
from ..core.model import G, RockingModel, check_positive
from ..core.records import GroundMotion
from ..core.spectra import STEPS_PER_PERIOD, response_spectrum
from ..report.html import SPECTRUM_PERIODS, build_report, input_source
from ..workflows.documents import (
    envelope_doc,
    frequency_grid,
    history_doc,
    log_grid,
    record_analysis,
)
from ..workflows.documents import pulse_doc as doc
from ..workflows.inputs import read_record
from ..workflows.outputs import finite_json
from ..workflows.scaling import Building
from .errors import error_body

__all__ = [
    "JOBS",
    "JobOutput",
    "ServiceUnavailable",
    "check_limit",
    "check_record_work",
    "check_work",
    "dumps",
    "history_options",
    "motion_from_params",
    "pulse_doc",
    "run_job",
    "safe_filename",
]

#: Longest file name kept from an upload (characters).
MAX_NAME = 100
#: Characters kept in an uploaded file's name; others become "_".
_NAME_OK = re.compile(r"[^A-Za-z0-9._-]")

_LIBRARY: Any = None


class ServiceUnavailable(RockmechError):
    """The deployment cannot do the job (an optional dependency is missing)."""


@dataclass(frozen=True)
class JobOutput:
    """A job's answer: HTTP status, media type and body."""

    status: int
    media_type: str
    body: bytes


def dumps(doc: Any) -> bytes:
    """Serialise a result document as compact UTF-8 JSON (non-finite numbers become null)."""
    return json.dumps(finite_json(doc), allow_nan=False, separators=(",", ":")).encode("utf-8")


def safe_filename(name: Optional[str], default: str) -> str:
    """Return the last component of an uploaded file's name, with only safe characters.

    Examples
    --------
    >>> safe_filename("../../etc/passwd", "record.dat")
    'passwd'
    >>> safe_filename("", "record.dat")
    'record.dat'
    """
    base = re.split(r"[\\/]", name or "")[-1]
    base = _NAME_OK.sub("_", base).lstrip(".")[-MAX_NAME:]
    return base or default


def check_limit(count: int, limit: int, what: str, field: str, setting: str) -> None:
    """Raise ``InputError`` (naming the limit) when ``count`` exceeds ``limit``."""
    if count > limit:
        raise InputError(
            f"{count} {what} exceed the service limit of {limit} per request "
            f"(ROCKMECH_{setting.upper()})",
            field,
        )


#: Closed-form steps per record sample the service computes at most, on average: one
#: computation may take ``WORK_PER_SAMPLE * max_samples`` steps (segments of the exact
#: integrator, or sub-steps of the spectrum recurrence), so that absurd but well-formed inputs
#: (a two-sample record a day long, p_eq = 1e300) get 422 at once instead of running into the
#: time budget. Real records stay far below it.
WORK_PER_SAMPLE = 20


def check_work(steps: float, limits: dict[str, int], what: str, field: str) -> None:
    """Raise ``InputError`` (naming the limit) when a computation would take too many steps."""
    limit = WORK_PER_SAMPLE * limits["max_samples"]
    if steps > limit:
        raise InputError(
            f"{what} would take {steps:.3g} closed-form steps; the service computes at most "
            f"{limit} per run ({WORK_PER_SAMPLE} x ROCKMECH_MAX_SAMPLES); resample the record "
            "or run it with the rockmech command line",
            field,
        )


def _positive(*values: Any) -> bool:
    return all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0
        for v in values
    )


def _record_steps(motion: Any, rate: float) -> float:
    """Count the steps over ``motion`` at ``rate`` steps per second (one per sample at least)."""
    per_sample = rate * motion.dt
    if not math.isfinite(per_sample):
        return math.inf
    return float((motion.accel.n - 1) * max(1.0, math.ceil(per_sample)))


def check_record_work(
    motion: Any,
    limits: dict[str, int],
    *,
    p_max: Optional[float] = None,
    t_min: Optional[float] = None,
) -> None:
    """Bound the work on a record: the integrator (``p_max`` [rad/s]) or a spectrum (``t_min`` [s]).

    The exact integrator cuts each sample interval into segments of at most ``1/p`` seconds;
    the spectrum into ``STEPS_PER_PERIOD`` sub-steps per shortest period.
    """
    if p_max is not None and _positive(p_max):
        check_work(_record_steps(motion, p_max), limits, "the time history", "record")
    if t_min is not None and _positive(t_min):
        steps = _record_steps(motion, STEPS_PER_PERIOD / t_min)
        check_work(steps, limits, f"the spectrum down to T = {t_min:g} s", "record")


def _history_work(cf: Any, motion: Any, sf: str, limits: dict[str, int]) -> None:
    sides = [s for m in cf.mechanisms for s in (m.positive, m.negative) if s is not None]
    check_record_work(motion, limits, p_max=max(s.p_eq for s in sides))
    if sf == "eq28":
        for mech in cf.mechanisms:
            if mech.amplification is not None:
                check_record_work(motion, limits, t_min=1.0 / mech.amplification.f_n)


def _library() -> Any:
    global _LIBRARY
    if _LIBRARY is None:
        _LIBRARY = OverturningLibrary.load()
    return _LIBRARY


def _constants(data: Any, label: str, limits: dict[str, int]) -> Any:
    """Validate a constants file given as data (JSON body) or bytes (upload)."""
    if isinstance(data, bytes):
        try:
            text = data.decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            raise InputError(f"constants file is not UTF-8 text: {exc}", label) from exc
        data = text
    try:
        cf = parse_constants(data)
    except InputError as exc:
        raise InputError(str(exc), label) from exc
    check_limit(len(cf.mechanisms), limits["max_mechanisms"], "mechanisms", label, "max_mechanisms")
    return cf


def _scales(values: list[float], limits: dict[str, int]) -> list[float]:
    check_limit(len(values), limits["max_scales"], "scale factors", "scales", "max_scales")
    return [float(v) for v in values]


def _strip_folder(exc: InputError, folder: str) -> InputError:
    reason = exc.reason.replace(folder.rstrip("/") + "/", "")
    return InputError(reason, exc.field)


def motion_from_params(
    record: Optional[dict[str, Any]],
    upload: Optional[dict[str, Any]],
    blob: Optional[bytes],
    limits: dict[str, int],
) -> Any:
    """Build a ``GroundMotion`` from samples (JSON) or from an uploaded file.

    Parameters
    ----------
    record : dict, optional
        ``{"accel", "dt", "units", "name"}`` (``RecordSamples``).
    upload : dict, optional
        ``{"filename", "format", "units", "dt"}`` of an uploaded record file.
    blob : bytes, optional
        The uploaded file.
    limits : dict
        The service's size limits.

    Notes
    -----
    As ``rockmech history``: the format is detected when not given, and a two-column file
    without units is taken to be in g.
    """
    max_samples = limits["max_samples"]
    if record is not None:
        check_limit(len(record["accel"]), max_samples, "samples", "record", "max_samples")
        n = len(record["accel"])
        return GroundMotion.from_samples(
            np.asarray(record["accel"], dtype=float),
            record["dt"],
            units=record["units"],
            name=record.get("name") or "record",
            metadata={"source": "request body", "format": "samples", "npts": n},
        )
    if upload is None or blob is None:
        raise InputError("give a record", "record")
    name = safe_filename(upload.get("filename"), "record.dat")
    with tempfile.TemporaryDirectory(prefix="rockmech-") as folder:
        path = Path(folder) / name
        path.write_bytes(blob)
        try:
            motion = read_record(path, upload.get("format"), upload.get("units"), upload.get("dt"))
        except InputError as exc:
            raise _strip_folder(exc, folder) from None
    check_limit(motion.accel.n, max_samples, "samples", "record", "max_samples")
    return motion


# --- jobs -------------------------------------------------------------------------------------


def pulse_doc(params: dict[str, Any], limits: Optional[dict[str, int]] = None) -> dict[str, Any]:
    """Response of one mechanism to a pulse, as ``rockmech pulse --json`` prints it.

    Parameters
    ----------
    params : dict
        ``PulseRequest`` fields: ``p_eq`` [rad/s], ``lam`` [-], ``a_p_g`` [g], ``f_p`` [Hz],
        ``eta``, ``one_sided``, ``phi_ov`` [rad], ``shape``, ``criterion``.
    limits : dict, optional
        The service's size limits (bound the work); none from the command line.
    """
    p_eq, f_p = params["p_eq"], params["f_p"]
    if limits is not None and _positive(p_eq, f_p):
        # Segments of at most 1/p_eq seconds over the pulse's 1/f_p seconds.
        check_work(p_eq / f_p, limits, "the pulse", "f_p")
    return doc(
        p_eq,
        params["lam"],
        params["a_p_g"],
        f_p,
        eta=params.get("eta"),
        one_sided=bool(params.get("one_sided", False)),
        phi_ov=params.get("phi_ov"),
        shape=params.get("shape", "sine"),
        criterion=params.get("criterion"),
    )


def _pulse(params: dict[str, Any], blobs: list[bytes], limits: dict[str, int]) -> bytes:
    return dumps(pulse_doc(params, limits))


def _grid(f_min: float, f_max: float, n: int, limits: dict[str, int]) -> Any:

    check_limit(n, limits["max_samples"], "frequencies", "n", "max_samples")
    return frequency_grid(f_min, f_max, n)


def _envelope(params: dict[str, Any], blobs: list[bytes], limits: dict[str, int]) -> bytes:

    f_p = _grid(params["f_min"], params["f_max"], params["n"], limits)
    cf = _constants(params["constants"], "constants", limits)
    exact = bool(params.get("exact", False))
    doc, _ = envelope_doc(cf, f_p, exact=exact, library=None if exact else _library())
    return dumps(doc)


def history_options(params: dict[str, Any]) -> dict[str, Any]:
    """Keyword arguments of ``history_doc`` from a request (as ``rockmech history``)."""
    building = Building(params["building_height"], params["soil_factor"], params["element_period"])
    return {
        "sf": params["sf"],
        "building": building,
        "criterion": params.get("criterion"),
        "at_height": params.get("at_height"),
    }


def _history(params: dict[str, Any], blobs: list[bytes], limits: dict[str, int]) -> bytes:

    scales = _scales(params["scales"], limits)
    cf = _constants(_constants_source(params, blobs), params["constants_label"], limits)
    motion = motion_from_params(params.get("record"), params.get("upload"), _blob(blobs), limits)
    _history_work(cf, motion, params["sf"], limits)
    return dumps(history_doc(cf, motion, scales, **history_options(params)))


def _constants_source(params: dict[str, Any], blobs: list[bytes]) -> Any:
    """Return the constants as data (JSON body) or as the first upload."""
    if params.get("constants") is not None:
        return params["constants"]
    return blobs[0]


def _blob(blobs: list[bytes]) -> Optional[bytes]:
    """Return the record upload: the last blob (after the constants file, if uploaded)."""
    return blobs[-1] if blobs else None


def _spectrum(params: dict[str, Any], blobs: list[bytes], limits: dict[str, int]) -> bytes:

    check_limit(params["n"], limits["max_samples"], "periods", "n", "max_samples")
    motion = motion_from_params(params.get("record"), params.get("upload"), _blob(blobs), limits)
    periods = log_grid(params["t_min"], params["t_max"], params["n"], names=("t_min", "t_max"))
    check_record_work(motion, limits, t_min=float(periods[0]))
    doc, _, _ = record_analysis(
        motion,
        periods,
        params["zeta"],
        n_pulses=params["pulses"],
        f_min=params.get("f_min"),
        f_max=params.get("f_max"),
    )
    return dumps(doc)


def scale_factor_doc(params: dict[str, Any], limits: dict[str, int]) -> dict[str, Any]:
    """Return a code or paper scale factor (``solver_service.core.codes``) with its inputs."""
    method = params["method"]
    if method == "ec8":
        return codes.sf_ec8(params["z"], params["H"], params["T_a"], params["T_1"], params["S"])
    if method == "nzs":
        return codes.sf_nzs(params["h_i"], params["h_n"])
    given = params.get("sa_g") is not None, params.get("pga_g") is not None
    if params.get("record") is None:
        for key, ok in zip(("sa_g", "pga_g"), given):
            if not ok:
                raise InputError("eq28 needs sa_g and pga_g, or a record and f_n", key)
        if params.get("f_n") is not None:
            raise InputError("f_n is used only with a record", "f_n")
        return codes.sf_eq28(params["sa_g"], params["pga_g"], params["h"], params["h_e"])
    if any(given):
        raise InputError("give either a record or sa_g and pga_g, not both", "record")

    if params.get("f_n") is None:
        raise InputError("eq28 from a record needs the natural frequency f_n [Hz]", "f_n")
    f_n = check_positive(params["f_n"], "f_n")
    motion = motion_from_params(params["record"], None, None, limits)
    check_record_work(motion, limits, t_min=1.0 / f_n)
    spec = response_spectrum(motion.accel.acc, motion.dt, [1.0 / f_n])
    info = codes.sf_eq28(float(spec.psa[0]) / G, motion.pga_g, params["h"], params["h_e"])
    info["inputs"]["T_n"] = 1.0 / f_n
    return info


def _scale_factor(params: dict[str, Any], blobs: list[bytes], limits: dict[str, int]) -> bytes:
    return dumps(scale_factor_doc(params, limits))


def _scene_constants(params: dict[str, Any], blobs: list[bytes], limits: dict[str, int]) -> bytes:

    scene_name = safe_filename(params.get("scene_name"), "scene.3dm")
    spec_name = safe_filename(params.get("spec_name"), "spec.json")
    scene_bytes, spec_bytes = blobs
    spec_file = parse_spec(spec_bytes, spec_name)
    if spec_file.thrust_table is not None:
        raise InputError(
            f"{spec_name}: the service takes no file paths from clients; remove thrust_table "
            "(the shipped table is used) or run rockmech constants locally",
            "thrust_table",
        )
    check_limit(
        len(spec_file.mechanisms), limits["max_mechanisms"], "mechanisms", "spec", "max_mechanisms"
    )
    try:
        scene = read_scene(scene_bytes, name=scene_name, units=params.get("units"))
    except ImportError as exc:
        raise ServiceUnavailable(
            "constants from a .3dm scene need the geometry extra (pip install "
            f"'rockmech[geometry]'), which this deployment lacks ({exc.name} is missing)"
        ) from None
    cf = constants_from_spec(spec_file, scene, scene_name=scene_name, spec_name=spec_name)
    return cf.model_dump_json(exclude_none=True).encode("utf-8")


def _report(params: dict[str, Any], blobs: list[bytes], limits: dict[str, int]) -> bytes:

    scales = _scales(params["scales"], limits)
    check_limit(params["n"], limits["max_samples"], "frequencies", "n", "max_samples")
    f_p = frequency_grid(params["f_min"], params["f_max"], params["n"])
    label = params["constants_label"]
    source = _constants_source(params, blobs)
    cf = _constants(source, label, limits)
    raw = source if isinstance(source, bytes) else dumps(source)
    sources = [input_source("constants", label, raw)]
    motion = None
    if params.get("record") is not None or params.get("upload") is not None:
        has_upload = params.get("upload") is not None
        motion = motion_from_params(
            params.get("record"), params.get("upload"), _blob(blobs) if has_upload else None, limits
        )
        _history_work(cf, motion, params["sf"], limits)
        check_record_work(motion, limits, t_min=SPECTRUM_PERIODS[0])
        rec_raw = _blob(blobs) if has_upload else dumps(params["record"])
        assert rec_raw is not None
        sources.append(input_source("record", motion.metadata.get("source", "record"), rec_raw))
    keys = ["scales", "sf", "building_height", "soil_factor", "element_period", "at_height"]
    keys += ["criterion", "f_min", "f_max", "n", "exact"]
    html = build_report(
        cf,
        f_p,
        motion=motion,
        scales=scales,
        history=history_options(params),
        exact=bool(params.get("exact", False)),
        title=params.get("title") or "",
        sources=sources,
        request={k: params.get(k) for k in keys},
        library=None if params.get("exact") else _library(),
    )
    return html.encode("utf-8")


def _warmup(params: dict[str, Any], blobs: list[bytes], limits: dict[str, int]) -> bytes:
    """Compile (or load from numba's cache) every kernel a request may need, once."""
    model = RockingModel.symmetric(2.0, 0.2, 0.9)
    simulate(model, Pulse(a_p=-3.0, f_p=1.0))
    acc = 3.0 * np.sin(np.linspace(0.0, 6.0, 61))
    simulate_batch([model], SampledAccel(acc, 0.01), [1.0])
    response_spectrum(acc, 0.01, [0.5])
    _library()
    return dumps({"ok": True})


Job = Callable[[dict[str, Any], list[bytes], dict[str, int]], bytes]

#: Job kinds, their media types and functions.
JOBS: dict[str, tuple[str, Job]] = {
    "pulse": ("application/json", _pulse),
    "envelope": ("application/json", _envelope),
    "history": ("application/json", _history),
    "spectrum": ("application/json", _spectrum),
    "scale_factor": ("application/json", _scale_factor),
    "constants": ("application/json", _scene_constants),
    "report": ("text/html; charset=utf-8", _report),
    "warmup": ("application/json", _warmup),
}


def run_job(
    kind: str, params: dict[str, Any], blobs: list[bytes], limits: dict[str, int]
) -> JobOutput:
    """Run one job and turn rockmech's errors into 4xx answers with their messages.

    Returns
    -------
    JobOutput
        200 with the document; 422 for ``InputError``, ``GeometryError`` and ``SolverError``
        (the message is the CLI's), and for arithmetic overflow on extreme inputs or
        exhausted memory; 501 when an optional dependency is missing; 500 only for an
        unexpected failure (a bug).
    """
    if kind not in JOBS:
        return JobOutput(500, "application/json", error_body("InternalError", f"no job {kind!r}"))
    media_type, fn = JOBS[kind]
    try:
        return JobOutput(200, media_type, fn(params, blobs, limits))
    except (ServiceUnavailable, MissingExtra) as exc:
        return JobOutput(501, "application/json", error_body("NotAvailable", str(exc)))
    except RockmechError as exc:
        field = exc.field if isinstance(exc, InputError) else None
        return JobOutput(422, "application/json", error_body(type(exc).__name__, str(exc), field))
    except OverflowError as exc:  # extreme magnitudes: input, not a fault of the service
        message = (
            f"a number overflowed ({exc}); the inputs are too large or too small for "
            "double precision"
        )
        return JobOutput(422, "application/json", error_body("InputError", message))
    except MemoryError:
        message = "the request needs more memory than the service can give it; ask for less work"
        return JobOutput(422, "application/json", error_body("TooLarge", message))
