"""The computations behind the service's endpoints, run inside a compute process.

Each job takes JSON-ready parameters (already type-checked by the request models), the raw
bytes of any uploads and the service's size limits, and returns the response body. The
documents are the ones ``rockmech ... --json`` prints, so the service and the CLI agree;
errors are ``RockmechError`` with the CLI's messages. Each kind's function (``run_<kind>``)
is named by its declaration in ``solver_service.api.jobspec.JOB_KINDS``, from which
``JOBS`` is built.

Uploads never name a path on the server: a record upload is written under a sanitised
version of its file name into a private temporary folder (the readers take files), and that
folder's path is removed from any message.

Units: SI, pulse amplitudes and PGA in g (names end in ``_g``).
"""

from __future__ import annotations

import importlib.util
import json
import math
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, Union

import numpy as np

from cad_maths.mechanisms.build import constants_from_spec
from cad_maths.scenes import read_scene
from cad_maths.search.families import work_estimate
from cad_maths.search.model import building_from_scene
from shared_schema.api import (
    SEARCH_MAX_EVALUATIONS,
    Ec8Request,
    Eq28Request,
    HistoryOptions,
    NzsRequest,
    PulseRequest,
    RecordSamples,
)
from shared_schema.constants import ConstantsFile, parse_constants
from shared_schema.documents.pulse import PulseDocument
from shared_schema.errors import InputError, RockmechError
from shared_schema.extras import MissingExtra
from shared_schema.io import CONSTANTS_EXPECTED, stamped
from shared_schema.retrofit import parse_retrofit_spec
from shared_schema.rules import CRITERIA, F_N_RANGE, SF_METHODS, check_choice
from shared_schema.search import SearchSpec, parse_search_spec
from shared_schema.site import read_site
from shared_schema.spec import parse_spec
from shared_schema.text import decode_text

from ..codes import scale_factors as codes
from ..codes.circ2019 import RECORD_POINTS, T_RECORD_MIN
from ..core.envelope import (
    SERIAL_OMEGA,
    OverturningLibrary,
    boundary_curve,
    governing_one_sided,
)
from ..core.exact import simulate, simulate_batch
from ..core.excitation import Pulse, SampledAccel
from ..core.model import G, RockingModel, check_positive
from ..core.records import GroundMotion
from ..core.spectra import STEPS_PER_PERIOD, response_spectrum
from ..report.assess import chromium, print_pdf
from ..report.html import SPECTRUM_PERIODS, input_source
from ..workflows.assess import (
    BAND_POINTS,
    assessment_doc,
    check_doc,
    check_document,
    matching_band,
    typed_assessment,
)
from ..workflows.documents import (
    envelope_doc,
    frequency_grid,
    history_doc,
    log_grid,
    record_analysis,
    solve_pulse,
)
from ..workflows.inputs import SPEC_EXPECTED, read_record
from ..workflows.limits import check_retrofit_work
from ..workflows.outputs import finite_json
from ..workflows.pages import assess_report, assessment_retrofit, build_report
from ..workflows.retrofit import retrofit_doc
from ..workflows.retrofit_files import retrofit_json
from ..workflows.retrofit_scene import retrofit_search
from ..workflows.scaling import Building
from ..workflows.search import MAX_LP_BLOCKS, search_run
from ..workflows.units import stamp
from .errors import error_body
from .estimates import (
    check_limit,
    check_time,
    check_work,
    estimate_pulse,
    history_steps,
)
from .jobspec import (
    JOB_KINDS,
    AssessHtmlJob,
    AssessJob,
    AssessPdfJob,
    CheckJob,
    EnvelopeJob,
    HistoryJob,
    Job,
    PulseJob,
    RecordUpload,
    ReportJob,
    RetrofitJob,
    RetrofitSceneJob,
    ScaleFactorJob,
    SceneJob,
    SearchJob,
    SpectrumJob,
    WarmupJob,
)
from .uploads import check_record_lines, safe_filename

__all__ = [
    "JOBS",
    "JobOutput",
    "Runner",
    "ServiceUnavailable",
    "check_limit",
    "check_record_work",
    "check_spectra_work",
    "check_work",
    "dumps",
    "history_options",
    "motion_from_params",
    "pulse_doc",
    "run_assess",
    "run_assess_html",
    "run_assess_pdf",
    "run_check",
    "run_constants",
    "run_envelope",
    "run_history",
    "run_job",
    "run_pulse",
    "run_report",
    "run_retrofit_scene",
    "run_scale_factor",
    "run_search",
    "run_spectrum",
    "run_warmup",
    "safe_filename",
]


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
    limits: dict[str, Any],
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


def check_history_work(
    cf: Any, motion: Any, sf: str, limits: dict[str, Any], n_scales: int = 1
) -> None:
    """Bound the work of time histories of every mechanism of ``cf`` at ``n_scales`` levels.

    The integrator's segments per sample (the largest ``p_eq``), the closed-form steps in
    all, and with the eq. 28 scale factor the spectrum down to each ``1/f_n``.
    """
    sides = [s for m in cf.mechanisms for s in (m.positive, m.negative) if s is not None]
    check_record_work(motion, limits, p_max=max(s.p_eq for s in sides))
    steps = history_steps(cf, motion.accel.n, motion.dt, n_scales)
    check_time(limits, "the time histories", "record", history_steps=steps)
    if sf == "eq28":
        for mech in cf.mechanisms:
            if mech.amplification is not None:
                check_record_work(motion, limits, t_min=1.0 / mech.amplification.f_n)


def shared_library() -> Any:
    """Return the shipped overturning library, loaded once per process."""
    global _LIBRARY
    if _LIBRARY is None:
        _LIBRARY = OverturningLibrary.load()
    return _LIBRARY


def _constants(data: Any, label: str, limits: dict[str, Any]) -> Any:
    """Validate a constants file given as data (JSON body) or bytes (upload)."""
    if isinstance(data, bytes):
        # empty, binary and non-UTF-8 uploads are said as the CLI says them
        data = decode_text(data, "the upload", label, CONSTANTS_EXPECTED)
    try:
        cf = parse_constants(data)
    except InputError as exc:
        raise InputError(str(exc), label) from exc
    check_limit(len(cf.mechanisms), limits["max_mechanisms"], "mechanisms", label, "max_mechanisms")
    return cf


def _scales(values: list[float], limits: dict[str, Any]) -> list[float]:
    check_limit(len(values), limits["max_scales"], "scale factors", "scales", "max_scales")
    return [float(v) for v in values]


def _strip_folder(exc: InputError, folder: str) -> InputError:
    reason = exc.reason.replace(folder.rstrip("/") + "/", "")
    return InputError(reason, exc.field)


def motion_from_params(
    record: Optional[RecordSamples],
    upload: Optional[RecordUpload],
    blob: Optional[bytes],
    limits: dict[str, Any],
) -> Any:
    """Build a ``GroundMotion`` from samples (JSON) or from an uploaded file.

    Parameters
    ----------
    record : RecordSamples, optional
        Samples given in the request.
    upload : RecordUpload, optional
        Name and reading options of an uploaded record file.
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
        n = len(record.accel)
        check_limit(n, max_samples, "samples", "record", "max_samples")
        return GroundMotion.from_samples(
            np.asarray(record.accel, dtype=float),
            record.dt,
            units=record.units,
            name=record.name or "record",
            metadata={"source": "request body", "format": "samples", "npts": n},
        )
    if upload is None or blob is None:
        raise InputError("give a record", "record")
    check_record_lines(blob, max_samples)  # before parsing: bounded memory
    name = safe_filename(upload.filename, "record.dat")
    with tempfile.TemporaryDirectory(prefix="rockmech-") as folder:
        path = Path(folder) / name
        path.write_bytes(blob)
        try:
            motion = read_record(path, upload.format, upload.units, upload.dt)
        except InputError as exc:
            raise _strip_folder(exc, folder) from None
    check_limit(motion.accel.n, max_samples, "samples", "record", "max_samples")
    return motion


# --- jobs -------------------------------------------------------------------------------------


def pulse_doc(job: PulseRequest, limits: Optional[dict[str, Any]] = None) -> PulseDocument:
    """Response of one mechanism to a pulse, as ``rockmech pulse --json`` prints it.

    Parameters
    ----------
    job : PulseRequest
        The request; ``workflows.documents.solve_pulse`` runs it, as on every other path.
    limits : dict, optional
        The service's size limits (bound the work); none from the command line.
    """
    if limits is not None:
        estimate_pulse(job, limits)  # again: run_job also runs without the app (benchmarks)
    return solve_pulse(job)


def run_pulse(job: PulseJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer ``rockmech pulse --json``'s document."""
    return dumps(pulse_doc(job, limits))


def _grid(f_min: float, f_max: float, n: int, limits: dict[str, Any]) -> Any:
    check_limit(n, limits["max_samples"], "frequencies", "n", "max_samples")
    return frequency_grid(f_min, f_max, n)


def run_envelope(job: EnvelopeJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer ``rockmech envelope --json``'s document."""
    f_p = _grid(job.f_min, job.f_max, job.n, limits)
    cf = _constants(job.constants.model_dump(exclude_none=True), "constants", limits)
    library = shared_library() if job.method == "library" else None
    doc, _ = envelope_doc(cf, f_p, method=job.method, library=library)
    return dumps(doc)


def history_options(job: HistoryOptions) -> dict[str, Any]:
    """Keyword arguments of ``history_doc`` from a request (as ``rockmech history``)."""
    building = Building(job.building_height, job.soil_factor, job.element_period)
    return {
        "sf": job.sf,
        "building": building,
        "criterion": job.criterion,
        "at_height": job.at_height,
    }


def run_history(job: HistoryJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer ``rockmech history --json``'s document (constants and record as data or uploads)."""
    scales = _scales(job.scales, limits)
    cf = _constants(_constants_source(job.constants, blobs), job.constants_label, limits)
    motion = motion_from_params(job.record, job.upload, _blob(blobs), limits)
    check_history_work(cf, motion, job.sf, limits, len(scales))
    return dumps(history_doc(cf, motion, scales, **history_options(job)))


def _constants_source(constants: Optional[ConstantsFile], blobs: list[bytes]) -> Any:
    """Return the constants as data (JSON body) or as the first upload."""
    if constants is not None:
        return constants.model_dump(exclude_none=True)
    return blobs[0]


def _blob(blobs: list[bytes]) -> Optional[bytes]:
    """Return the record upload: the last blob (after the constants file, if uploaded)."""
    return blobs[-1] if blobs else None


def run_spectrum(job: SpectrumJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer ``rockmech record --json``'s document."""
    check_limit(job.n, limits["max_samples"], "periods", "n", "max_samples")
    motion = motion_from_params(job.record, job.upload, _blob(blobs), limits)
    periods = log_grid(job.t_min, job.t_max, job.n, names=("t_min", "t_max"))
    check_record_work(motion, limits, t_min=float(periods[0]))
    doc, _, _ = record_analysis(
        motion, periods, job.zeta, n_pulses=job.pulses, f_min=job.f_min, f_max=job.f_max
    )
    return dumps(doc)


def scale_factor_doc(
    request: Union[Eq28Request, Ec8Request, NzsRequest], limits: dict[str, Any]
) -> dict[str, Any]:
    """Return a code or paper scale factor (``codes.scale_factors``) with its inputs."""
    if isinstance(request, Ec8Request):
        return codes.sf_ec8(request.z, request.H, request.T_a, request.T_1, request.S)
    if isinstance(request, NzsRequest):
        return codes.sf_nzs(request.h_i, request.h_n)
    if request.record is None:
        if request.sa_g is None or request.pga_g is None:
            key = "sa_g" if request.sa_g is None else "pga_g"
            raise InputError("eq28 needs sa_g and pga_g, or a record and f_n", key)
        if request.f_n is not None:
            raise InputError("f_n is used only with a record", "f_n")
        return codes.sf_eq28(request.sa_g, request.pga_g, request.h, request.h_e)
    if request.sa_g is not None or request.pga_g is not None:
        raise InputError("give either a record or sa_g and pga_g, not both", "record")
    if request.f_n is None:
        raise InputError("eq28 from a record needs the natural frequency f_n [Hz]", "f_n")
    f_n = check_positive(request.f_n, "f_n")
    lo, hi = F_N_RANGE
    if not lo <= f_n <= hi:
        raise InputError(
            f"must be in [{lo:g}, {hi:g}] Hz (periods of {1 / lo:g} s down to {1 / hi:g} s, "
            f"a plausible range), got {request.f_n!r}",
            "f_n",
        )
    motion = motion_from_params(request.record, None, None, limits)
    check_record_work(motion, limits, t_min=1.0 / f_n)
    spec = response_spectrum(motion.accel.acc, motion.dt, [1.0 / f_n])
    info = codes.sf_eq28(float(spec.psa[0]) / G, motion.pga_g, request.h, request.h_e)
    info["inputs"]["T_n"] = 1.0 / f_n
    return info


def run_scale_factor(job: ScaleFactorJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer a code or paper scale factor, stamped."""
    return dumps(stamp(scale_factor_doc(job.request, limits), "scale_factor"))


def _uploaded_scene(data: bytes, name: str, units: Optional[str], needs: str) -> Any:
    """Read an uploaded scene; a deployment without the geometry extra says what needs it.

    ``needs`` starts the 503's message (``"the search needs"``): the geometry extra, which
    this deployment lacks, follows, with the missing module.
    """
    try:
        return read_scene(data, name=name, units=units)
    except ImportError as exc:
        raise ServiceUnavailable(
            f"{needs} the geometry extra (pip install 'rockmech[geometry]'), which this "
            f"deployment lacks ({exc.name} is missing)"
        ) from None


def run_constants(job: SceneJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer the kinematic-constants file ``rockmech constants`` writes (blobs: scene, spec)."""
    scene_name = safe_filename(job.scene_name, "scene.3dm")
    spec_name = safe_filename(job.spec_name, "spec.json")
    scene_bytes, spec_bytes = blobs
    spec_file = parse_spec(decode_text(spec_bytes, spec_name, "spec", SPEC_EXPECTED), spec_name)
    if spec_file.thrust_table is not None:
        raise InputError(
            f"{spec_name}: the service takes no file paths from clients; remove thrust_table "
            "(the shipped table is used) or run rockmech constants locally",
            "thrust_table",
        )
    check_limit(
        len(spec_file.mechanisms), limits["max_mechanisms"], "mechanisms", "spec", "max_mechanisms"
    )
    scene = _uploaded_scene(
        scene_bytes, scene_name, job.units, "constants from a scene (.3dm or scan mesh) need"
    )
    cf = constants_from_spec(spec_file, scene, scene_name=scene_name, spec_name=spec_name)
    return stamped(cf).model_dump_json(exclude_none=True).encode("utf-8")


def run_search(job: SearchJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer ``rockmech search --json``'s document (blobs: scene, spec, site, record)."""
    scene_name = safe_filename(job.scene_name, "scene.3dm")
    spec_name = safe_filename(job.spec_name, "search.json")
    scene_bytes, spec_bytes, *rest = blobs
    spec = parse_search_spec(spec_bytes, spec_name)
    if spec.ranking.site is not None or spec.ranking.records:
        raise InputError(
            f"{spec_name}: the service takes no file paths from clients; upload the site file "
            "and the record as the form's 'site' and 'record' parts",
            "ranking",
        )
    site = None
    if job.has_site:
        site = read_site(rest.pop(0), safe_filename(job.site_name, "site.json"))
    motions = []
    if job.record is not None:
        motions.append(motion_from_params(None, job.record, rest[0], limits))
    scene = _uploaded_scene(scene_bytes, scene_name, job.units, "the search needs")
    run = search_run(
        scene,
        spec,
        scene_name=scene_name,
        spec_name=spec_name,
        site=site,
        motions=motions,
        exact=job.exact,
        max_evaluations=min(job.max_evaluations or SEARCH_MAX_EVALUATIONS, SEARCH_MAX_EVALUATIONS),
        max_lp_blocks=MAX_LP_BLOCKS,
        max_built=limits["max_mechanisms"],
    )
    return dumps(run.doc.to_dict())


#: Request fields a report lists under "Inputs and provenance", in this order.
REPORT_KEYS = (
    "scales",
    "sf",
    "building_height",
    "soil_factor",
    "element_period",
    "at_height",
    "criterion",
    "f_min",
    "f_max",
    "n",
    "method",
)


def run_report(job: ReportJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer the HTML page ``rockmech report`` writes."""
    # Checked with or without a record, as the schema states them.
    check_choice(job.sf, SF_METHODS, "sf")
    if job.criterion is not None:
        check_choice(job.criterion, CRITERIA, "criterion")
    scales = _scales(job.scales, limits)
    check_limit(job.n, limits["max_samples"], "frequencies", "n", "max_samples")
    f_p = frequency_grid(job.f_min, job.f_max, job.n)
    label = job.constants_label
    source = _constants_source(job.constants, blobs)
    cf = _constants(source, label, limits)
    raw = source if isinstance(source, bytes) else dumps(source)
    sources = [input_source("constants", label, raw)]
    motion = None
    if job.record is not None or job.upload is not None:
        has_upload = job.upload is not None
        motion = motion_from_params(
            job.record, job.upload, _blob(blobs) if has_upload else None, limits
        )
        check_history_work(cf, motion, job.sf, limits, len(scales))
        check_record_work(motion, limits, t_min=SPECTRUM_PERIODS[0])
        if has_upload:
            rec_raw = _blob(blobs)
        else:
            assert job.record is not None
            rec_raw = dumps(job.record.model_dump())
        assert rec_raw is not None
        sources.append(input_source("record", motion.metadata.get("source", "record"), rec_raw))
    html = build_report(
        cf,
        f_p,
        motion=motion,
        scales=scales,
        history=history_options(job),
        method=job.method,
        title=job.title or "",
        sources=sources,
        request={k: getattr(job, k) for k in REPORT_KEYS},
        library=shared_library() if job.method == "library" else None,
    )
    return html.encode("utf-8")


def run_check(job: CheckJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer ``rockmech check --json``'s document."""
    cf = _constants(job.constants.model_dump(exclude_none=True), "constants", limits)
    return dumps(check_document(cf, job.site))


#: The sections of a retrofit request that a retrofit's own errors name without the
#: request's key (the CLI's words are relative to the spec or site file).
_RETROFIT_SECTIONS = {
    "mechanisms": "spec",
    "steel": "spec",
    "anchorage": "spec",
    "tie_lines": "spec",
    "local_mechanisms": "site",
    "building": "site",
    "hazard": "site",
}


def _retrofit_field(exc: InputError) -> InputError:
    """Return the error with its field as the request holds it (``spec.mechanisms.F9``)."""
    head = (exc.field or "").split(".", 1)[0].split("[", 1)[0]
    if head not in _RETROFIT_SECTIONS:
        return exc
    return InputError(exc.reason, f"{_RETROFIT_SECTIONS[head]}.{exc.field}")


def run_retrofit(job: RetrofitJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer ``rockmech retrofit --json``'s document: the bytes of its ``retrofit.json``.

    An error the retrofit raises about the spec or the site names the field as the request
    holds it (``spec.mechanisms.F9``, ``site.local_mechanisms.method``).
    """
    cf = _constants(job.constants.model_dump(exclude_none=True), "constants", limits)
    try:
        doc = retrofit_doc(cf, job.site, job.spec)
    except InputError as exc:
        raise _retrofit_field(exc) from None
    return retrofit_json(doc).encode("utf-8")


#: How a client lifts the budget of a retrofit, ending its refusal.
_RETROFIT_HOW = (
    "run rockmech retrofit with the command line (ROCKMECH_COMPUTE_TIMEOUT_S is the "
    "service's budget per request)"
)


def retrofit_searches(rspec: Any) -> int:
    """Return how many searches a retrofit from a scene runs (``retrofit_search``).

    The scene as given, then with the designed ties; with connection upgrades, one more per
    upgrade and one with them all and the ties.
    """
    n = len(getattr(rspec, "upgrades", None) or [])
    return 2 + n + (1 if n else 0)


def check_scene_searches(scene: Any, spec: SearchSpec, searches: int, limit: int) -> None:
    """Refuse a retrofit from a scene whose searches need more than ``limit`` λ0 evaluations.

    The search's work estimate (``cad_maths.search.families.work_estimate``, the least
    evaluations of its refinements' seed grids) counts once per search the retrofit runs
    (``retrofit_searches``: the scene as given, with the designed ties, and once per
    connection upgrade and for them all). Counted before any search runs.

    Raises
    ------
    InputError
        On ``work_limit``, with the counts and the limit.
    """
    est = work_estimate(building_from_scene(scene, spec), limit)
    if searches * est.evaluations > limit:
        least = "" if est.complete else "at least "
        what = (
            "twice (as given, then with the designed ties)"
            if searches == 2
            else f"{searches} times (as given, with the designed ties, once per connection "
            "upgrade and once with them all)"
        )
        raise InputError(
            f"the retrofit searches the scene {what}, each search needing {est.describe()}: "
            f"{least}{searches * est.evaluations} in all, more than the work limit's {limit} "
            "(max_evaluations); ask for fewer families or directions, a coarser "
            "candidates.grid or a wider candidates.spacing in the search spec, fewer "
            "upgrades, or raise the work limit (counted before any search ran)",
            "work_limit",
        )


def _scene_retrofit_work(
    site: Any, motions: list[Any], limits: dict[str, Any]
) -> Callable[[ConstantsFile, Any], None]:
    """Return the check of a scene retrofit's work, run once the first search has built."""

    def check(cf: ConstantsFile, rspec: Any) -> None:
        check_limit(
            len(cf.mechanisms),
            limits["max_mechanisms"],
            "mechanisms built by the search",
            "search_spec.candidates.keep",
            "max_mechanisms",
        )
        budget = limits.get("budget_s")
        if budget is not None:
            check_retrofit_work(cf, site, rspec, budget, _RETROFIT_HOW, motions)

    return check


def run_retrofit_scene(job: RetrofitSceneJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer ``rockmech retrofit --scene --search-spec --json``'s document (its bytes).

    Blobs: scene, search spec, site, retrofit spec and the record when given. The
    searches stay within ``max_evaluations`` together (``check_scene_searches``; each may use
    its share); the built mechanisms within ``max_mechanisms`` and the retrofit's checks
    within the budget, checked before the retrofit runs.
    """
    scene_bytes, search_bytes, site_bytes, spec_bytes, *rest = blobs
    scene_name = safe_filename(job.scene_name, "scene.3dm")
    search_name = safe_filename(job.search_spec_name, "search.json")
    spec = parse_search_spec(search_bytes, search_name)
    site = read_site(site_bytes, safe_filename(job.site_name, "site.json"))
    try:
        rspec = parse_retrofit_spec(spec_bytes)
    except InputError as exc:
        raise InputError(exc.reason, "spec" if not exc.field else f"spec.{exc.field}") from None
    motions = []
    if job.record is not None:
        motions.append(motion_from_params(None, job.record, rest[0], limits))
    scene = _uploaded_scene(scene_bytes, scene_name, job.units, "the retrofit of a scene needs")
    limit = min(job.max_evaluations or SEARCH_MAX_EVALUATIONS, SEARCH_MAX_EVALUATIONS)
    searches = retrofit_searches(rspec)
    check_scene_searches(scene, spec, searches, limit)
    try:
        run = retrofit_search(
            scene,
            spec,
            site,
            rspec,
            motions,
            scene_name=scene_name,
            spec_name=search_name,
            max_evaluations=limit // searches,
            max_lp_blocks=MAX_LP_BLOCKS,
            check_work=_scene_retrofit_work(site, motions, limits),
        )
    except InputError as exc:
        raise _retrofit_field(exc) from None
    return retrofit_json(run.doc).encode("utf-8")


def _assess_inputs(
    job: AssessJob | AssessHtmlJob | AssessPdfJob, limits: dict[str, Any]
) -> tuple[Any, list[Any]]:
    """Validate the constants and records and bound the spectrum work (as ``rockmech assess``).

    The matching band of each mechanism comes from its nonlinear check (``Ts``), so the
    spectrum work is bounded here, after the check, rather than in the app.
    """
    cf = _constants(job.constants.model_dump(exclude_none=True), "constants", limits)
    motions = []
    for i, record in enumerate(job.records):
        try:
            motions.append(motion_from_params(record, None, None, limits))
        except InputError as exc:
            # the samples' own field: a sample beyond ACCEL_MAX_G is records[i].accel
            part = {None: "", "record": ".accel"}.get(exc.field, f".{exc.field}")
            raise InputError(exc.reason, f"records[{i}]{part}") from None
    check_spectra_work(cf, check_doc(cf, job.site)["mechanisms"], motions, limits)
    budget = limits.get("budget_s")
    if job.retrofit is not None and budget is not None:
        try:  # as rockmech retrofit --record counts it, before the retrofit runs
            check_retrofit_work(cf, job.site, job.retrofit, budget, _RETROFIT_HOW, motions)
        except InputError as exc:
            raise InputError(exc.reason, "retrofit") from None
    return cf, motions


def check_spectra_work(
    cf: Any, rows: list[dict[str, Any]], motions: list[Any], limits: dict[str, Any]
) -> None:
    """Bound the spectrum work of an assessment, one record and in total.

    Every record's spectrum is computed down to the shortest period of each mechanism's
    matching band (``rows``: the mechanisms of the code check, ``check_doc``), over the
    periods of the records' demand in the nonlinear checks (``[T0, T_SLV]``, ``[T0, T_SLC]``
    from ``T_RECORD_MIN``, Circolare 2019 §C8.7.1.2.1.8) and at ``1/f_n`` of each mechanism
    with amplification data.

    Raises
    ------
    InputError
        When one record, or all of them together, would take more closed-form steps than
        the limits allow (naming the record).
    """
    # (shortest period [s], periods computed): the matching bands, the records' demand of
    # the nonlinear checks over [T0, T_SLV] and [T0, T_SLC] (twice over at height, where
    # the floor spectrum also needs the records' ground spectrum), and 1/f_n.
    grids = [(matching_band(row)[0], BAND_POINTS) for row in rows]
    for row in rows:
        for side in (row.get("sides") or {}).values():
            non = side.get("nonlinear") or {}
            if non.get("status") != "ok" or non.get("method") != "circ2019" or "SLV" not in non:
                continue
            t_lo = max(non.get("T0") or 0.0, T_RECORD_MIN)
            per = RECORD_POINTS * (2 if row.get("Z", 0.0) > 0.0 else 1)
            grids += [(min(t_lo, non["SLV"]["T_SLV"]), per), (min(t_lo, non["SLC"]["T_SLC"]), per)]
    grids += [(1.0 / m.amplification.f_n, 1) for m in cf.mechanisms if m.amplification]
    steps = 0.0
    for i, motion in enumerate(motions):
        for t_lo, count in grids:
            check_record_work(motion, limits, t_min=t_lo)
            steps += count * _record_steps(motion, STEPS_PER_PERIOD / t_lo)
        if steps > 0.0:
            check_time(limits, "the records' spectra", f"records[{i}]", spectrum_steps=steps)


def run_assess(job: AssessJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Answer ``rockmech assess --json``'s document."""
    cf, motions = _assess_inputs(job, limits)
    doc = assessment_doc(cf, job.site, motions, multiples=list(job.multiples))
    if job.retrofit is not None:
        # as rockmech assess --retrofit: the retrofit on the constants, site and records
        made = assessment_retrofit(cf, job.site, job.retrofit, motions)
        doc["retrofit"] = made.model_dump(mode="json")
    return dumps(typed_assessment(doc))


def run_assess_pdf(job: AssessPdfJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Print the assessment page to PDF with a headless Chromium, if the deployment has one."""
    if chromium() is None:
        raise ServiceUnavailable(
            "printing the assessment to PDF needs a headless Chromium, which this deployment "
            "lacks (Debian: apt-get install chromium; the Docker image: build it with "
            "--build-arg PDF=chromium); format html gives the page to print locally"
        )
    page = run_assess_html(job, blobs, limits)
    with tempfile.TemporaryDirectory(prefix="rockmech-pdf-") as tmp:
        html = Path(tmp) / "assessment.html"
        html.write_bytes(page)
        try:
            pdf = print_pdf(html, Path(tmp) / "assessment.pdf")
        except InputError as exc:  # Chromium present but failing: the deployment's fault
            raise ServiceUnavailable(str(exc)) from None
        return pdf.read_bytes()


def run_assess_html(
    job: AssessHtmlJob | AssessPdfJob, blobs: list[bytes], limits: dict[str, Any]
) -> bytes:
    """Answer the assessment's HTML page, as ``rockmech assess`` writes it."""
    if importlib.util.find_spec("jinja2") is None:
        raise ServiceUnavailable(
            "the assessment page needs the report extra (pip install 'rockmech[report]'), "
            "which this deployment lacks (jinja2 is missing)"
        )
    cf, motions = _assess_inputs(job, limits)
    sources = [
        input_source("constants", "constants", dumps(job.constants.model_dump(exclude_none=True))),
        input_source("site", "site", dumps(job.site.model_dump())),
    ] + [input_source("record", r.name, dumps(r.model_dump())) for r in job.records]
    if job.retrofit is not None:
        spec = dumps(job.retrofit.model_dump(exclude_none=True))
        sources.append(input_source("retrofit", "retrofit", spec))
    multiples = list(job.multiples)
    options = {"multiples": multiples}
    _, page = assess_report(
        cf,
        job.site,
        motions,
        multiples=multiples,
        sources=sources,
        options=options,
        retrofit=job.retrofit,
    )
    return page.encode("utf-8")


def run_warmup(job: WarmupJob, blobs: list[bytes], limits: dict[str, Any]) -> bytes:
    """Compile (or load from numba's cache) every kernel a request may need, once."""
    model = RockingModel.symmetric(2.0, 0.2, 0.9)
    simulate(model, Pulse(a_p=-3.0, f_p=1.0))
    acc = 3.0 * np.sin(np.linspace(0.0, 6.0, 61))
    simulate_batch([model], SampledAccel(acc, 0.01), [1.0])
    response_spectrum(acc, 0.01, [0.5])
    # The exact envelopes' boundary search (/envelope, /assess): two-sided, directional and
    # one-sided, one frequency at a time and the parallel grid (more than SERIAL_OMEGA).
    # Left to the first request, their compilation outlasted a 5 s budget.
    for omega in (np.array([5.0]), np.linspace(2.0, 8.0, SERIAL_OMEGA + 1)):
        boundary_curve(omega, 0.9)
        boundary_curve(omega, 0.9, direction=-1, eta_neg=0.8)
        governing_one_sided(omega, 0.0)
    shared_library()
    return dumps({"ok": True})


_JSON = "application/json"

#: A job's function: ``(job, blobs, limits) -> body``.
Runner = Callable[[Any, list[bytes], dict[str, Any]], bytes]


def _runners() -> dict[str, tuple[str, Runner]]:
    """Each kind of ``JOB_KINDS``: the media type of its answer and the function it names."""
    here = globals()
    missing = [k.run for k in JOB_KINDS.values() if not callable(here.get(k.run))]
    if missing:
        raise ImportError(f"jobspec.JOB_KINDS names functions this module lacks: {missing}")
    return {kind: (k.media_type, here[k.run]) for kind, k in JOB_KINDS.items()}


#: Job kinds: media type of the answer and the function that computes it.
JOBS = _runners()


def run_job(job: Job, blobs: list[bytes], limits: dict[str, Any]) -> JobOutput:
    """Run one job and turn rockmech's errors into 4xx answers with their messages.

    Returns
    -------
    JobOutput
        200 with the document; 422 for ``InputError``, ``GeometryError`` and ``SolverError``
        (the message is the CLI's), and for arithmetic overflow on extreme inputs or
        exhausted memory; 501 when an optional dependency is missing; 500 only for an
        unexpected failure (a bug).
    """
    media_type, fn = JOBS[job.kind]
    try:
        return JobOutput(200, media_type, fn(job, blobs, limits))
    except (ServiceUnavailable, MissingExtra) as exc:
        return JobOutput(501, _JSON, error_body("NotAvailable", str(exc)))
    except RockmechError as exc:
        field = exc.field if isinstance(exc, InputError) else None
        return JobOutput(422, _JSON, error_body(type(exc).__name__, str(exc), field))
    except OverflowError as exc:  # extreme magnitudes: input, not a fault of the service
        message = (
            f"a number overflowed ({exc}); the inputs are too large or too small for "
            "double precision"
        )
        return JobOutput(422, _JSON, error_body("InputError", message))
    except MemoryError:
        message = "the request needs more memory than the service can give it; ask for less work"
        return JobOutput(422, _JSON, error_body("TooLarge", message))
