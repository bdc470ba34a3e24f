"""The kinds of job the service runs: each declared once, in ``JOB_KINDS``.

A kind of job is its typed model (its ``kind`` field's literal names it), the function in
``solver_service.api.jobs`` that computes it, its work estimate (``solver_service.api.
estimates``) and the media type of its answer: one ``JobKind`` line. The union a compute
process validates (``JOB``), its dispatch table (``jobs.JOBS``) and the app's up-front
estimate (``check_job``) are derived from that list.

The app builds a job from a validated request (JSON body, multipart form or Hops inputs);
the pool sends it to a compute process as JSON, where ``JOB.validate_python`` rebuilds the
same model and ``solver_service.api.jobs`` runs it. Uploaded files travel beside the job as
raw bytes (``blobs``): the constants file first, when uploaded, then the record.

Light on purpose (pydantic, ``shared_schema`` and the estimates only): the app process
imports it, and must not load the compute modules; so a declaration names its function
rather than holding it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Any, Literal, Optional, Union, cast

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter

from shared_schema.api import (
    AssessRequest,
    CheckRequest,
    EnvelopeRequest,
    HistoryOptions,
    PulseRequest,
    RecordSamples,
    ReportOptions,
    RetrofitRequest,
    ScaleFactorRequest,
    SpectrumOptions,
)
from shared_schema.constants import ConstantsFile

from .estimates import (
    check_constants,
    estimate_assess,
    estimate_assess_page,
    estimate_envelope,
    estimate_history,
    estimate_pulse,
    estimate_report,
    estimate_retrofit,
    estimate_scale_factor,
    estimate_spectrum,
)

__all__ = [
    "JOB",
    "JOB_KINDS",
    "AssessHtmlJob",
    "AssessJob",
    "AssessPdfJob",
    "CheckJob",
    "EnvelopeJob",
    "HistoryJob",
    "Job",
    "JobKind",
    "PulseJob",
    "RecordUpload",
    "ReportJob",
    "RetrofitJob",
    "RetrofitSceneJob",
    "ScaleFactorJob",
    "SceneJob",
    "SearchJob",
    "SpectrumJob",
    "WarmupJob",
    "check_job",
]

_JOB = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False)
_JSON = "application/json"
_HTML = "text/html; charset=utf-8"


class Job(BaseModel):
    """Any job: the base of every job model below (the static type of a job)."""

    if TYPE_CHECKING:  # each model declares its own literal; a field here would reorder them
        kind: str


class RecordUpload(BaseModel):
    """How to read an uploaded record file (its bytes travel as a blob)."""

    model_config = _JOB

    filename: str = ""
    format: Optional[str] = None
    units: Optional[str] = None
    dt: Optional[float] = None


class PulseJob(PulseRequest, Job):
    """``rockmech pulse``."""

    kind: Literal["pulse"] = "pulse"


class EnvelopeJob(EnvelopeRequest, Job):
    """``rockmech envelope``."""

    kind: Literal["envelope"] = "envelope"


class _RecordInput(BaseModel):
    """A record as samples (JSON) or as an uploaded file (the last blob)."""

    record: Optional[RecordSamples] = None
    upload: Optional[RecordUpload] = None


class _ConstantsInput(BaseModel):
    """Kinematic constants as data (JSON) or as an uploaded file (the first blob)."""

    constants: Optional[ConstantsFile] = None
    constants_label: str = Field("constants", description="Names the constants in messages.")


class HistoryJob(_RecordInput, _ConstantsInput, HistoryOptions, Job):
    """``rockmech history``."""

    model_config = _JOB

    kind: Literal["history"] = "history"


class SpectrumJob(_RecordInput, SpectrumOptions, Job):
    """``rockmech record``."""

    model_config = _JOB

    kind: Literal["spectrum"] = "spectrum"


class ReportJob(_RecordInput, _ConstantsInput, ReportOptions, Job):
    """``rockmech report``."""

    model_config = _JOB

    kind: Literal["report"] = "report"


class ScaleFactorJob(Job):
    """A code or paper scale factor."""

    model_config = _JOB

    kind: Literal["scale_factor"] = "scale_factor"
    request: ScaleFactorRequest


class SceneJob(Job):
    """``rockmech constants``: blobs are the .3dm scene and the spec."""

    model_config = _JOB

    kind: Literal["constants"] = "constants"
    scene_name: str = ""
    spec_name: str = ""
    units: Optional[str] = None


class SearchJob(Job):
    """``rockmech search``: blobs are the scene, the search spec, the site and the record.

    The site file and the record come only when given (``has_site``, ``record``).
    """

    model_config = _JOB

    kind: Literal["search"] = "search"
    scene_name: str = ""
    spec_name: str = ""
    units: Optional[str] = None
    max_evaluations: Optional[int] = None
    exact: bool = False
    has_site: bool = False
    site_name: str = ""
    record: Optional[RecordUpload] = None


class CheckJob(CheckRequest, Job):
    """``rockmech check``."""

    kind: Literal["check"] = "check"


class AssessJob(AssessRequest, Job):
    """``rockmech assess --json``: the assessment document."""

    kind: Literal["assess"] = "assess"


class AssessHtmlJob(AssessRequest, Job):
    """``rockmech assess``: the assessment's HTML page."""

    kind: Literal["assess_html"] = "assess_html"


class AssessPdfJob(AssessRequest, Job):
    """``rockmech assess --pdf``: the assessment's page printed to PDF."""

    kind: Literal["assess_pdf"] = "assess_pdf"


class RetrofitJob(RetrofitRequest, Job):
    """``rockmech retrofit --json``: the retrofit document."""

    kind: Literal["retrofit"] = "retrofit"


class RetrofitSceneJob(Job):
    """``rockmech retrofit --scene --search-spec --json``: the retrofit of a searched scene.

    Blobs: the scene, the search spec, the site, the retrofit spec, and the record when
    ``record`` is given. ``max_evaluations`` bounds the two searches together (the search's
    work estimate counted twice), checked in the compute process before either runs.
    """

    model_config = _JOB

    kind: Literal["retrofit_scene"] = "retrofit_scene"
    scene_name: str = ""
    search_spec_name: str = ""
    site_name: str = ""
    spec_name: str = ""
    units: Optional[str] = None
    max_evaluations: Optional[int] = None
    record: Optional[RecordUpload] = None


class WarmupJob(Job):
    """Load every kernel once, before a compute process takes work."""

    model_config = _JOB

    kind: Literal["warmup"] = "warmup"


#: A job's up-front estimate: ``(job, limits) -> None``, raising ``InputError`` (naming the
#: setting) when the work or the answer would be too large.
Estimate = Callable[[Any, dict[str, Any]], None]


@dataclass(frozen=True)
class JobKind:
    """One kind of job, declared once.

    Attributes
    ----------
    model : type of Job
        The job's model; the literal of its ``kind`` field names the kind.
    run : str
        The function of ``solver_service.api.jobs`` that computes it, ``(job, blobs, limits)
        -> bytes`` (named: the app process must not import the compute modules).
    estimate : callable, optional
        Its work and answer estimate (``solver_service.api.estimates``), run in the app
        before a compute process is spent; None when nothing can be bounded up front.
    media_type : str
        The media type of its answer.
    """

    model: type[Job]
    run: str
    estimate: Optional[Estimate] = None
    media_type: str = _JSON

    @property
    def kind(self) -> str:
        """The kind's name: the default of the model's ``kind`` literal."""
        name: str = self.model.model_fields["kind"].default
        return name


def _by_kind(*kinds: JobKind) -> dict[str, JobKind]:
    """Key the declarations by kind; a kind declared twice is a bug (refused at import)."""
    out = {k.kind: k for k in kinds}
    if len(out) != len(kinds):
        raise ValueError("a job kind is declared twice in JOB_KINDS")
    return out


#: Every kind of job, by name: model, function, estimate, media type.
JOB_KINDS = _by_kind(
    JobKind(PulseJob, "run_pulse", estimate_pulse),
    JobKind(EnvelopeJob, "run_envelope", estimate_envelope),
    JobKind(HistoryJob, "run_history", estimate_history),
    JobKind(SpectrumJob, "run_spectrum", estimate_spectrum),
    JobKind(ScaleFactorJob, "run_scale_factor", estimate_scale_factor),
    JobKind(SceneJob, "run_constants"),
    JobKind(ReportJob, "run_report", estimate_report, media_type=_HTML),
    JobKind(CheckJob, "run_check"),
    JobKind(AssessJob, "run_assess", estimate_assess),
    JobKind(AssessHtmlJob, "run_assess_html", estimate_assess_page, media_type=_HTML),
    JobKind(AssessPdfJob, "run_assess_pdf", estimate_assess_page, media_type="application/pdf"),
    JobKind(SearchJob, "run_search"),
    JobKind(RetrofitJob, "run_retrofit", estimate_retrofit),
    JobKind(RetrofitSceneJob, "run_retrofit_scene"),
    JobKind(WarmupJob, "run_warmup"),
)

#: Validates any job from its JSON form (in the compute process): the union of the models
#: of ``JOB_KINDS``, chosen by ``kind``. (A union built from a list has no static type: the
#: casts only name it.)
JOB: TypeAdapter[Job] = TypeAdapter(
    cast(
        Any,
        Annotated[
            cast(Any, Union)[tuple(k.model for k in JOB_KINDS.values())],
            Field(discriminator="kind"),
        ],
    )
)


def check_job(job: Job, limits: dict[str, Any]) -> None:
    """Refuse a job whose work or answer is too large, before it reaches a compute process.

    The constants of any job are counted and their derived values checked first; then the
    kind's own estimate (``JobKind.estimate``) runs.

    Raises
    ------
    InputError
        The work or the answer exceeds a limit; the message names the setting.
    """
    cf = getattr(job, "constants", None)
    if cf is not None:
        check_constants(cf, limits)
    estimate = JOB_KINDS[job.kind].estimate
    if estimate is not None:
        estimate(job, limits)
