"""Typed job requests: what the app hands a compute process, one model per kind of job.

The app builds a job from a validated request (JSON body, multipart form or Hops inputs);
the pool sends it to a compute process as JSON, where ``JOB.validate_python`` rebuilds the
same model and ``solver_service.api.jobs`` runs it. Uploaded files travel beside the job as
raw bytes (``blobs``): the constants file first, when uploaded, then the record.

Light on purpose (pydantic and ``shared_schema`` only): the app process imports it, and must
not load the compute modules.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal, Optional, Union, cast

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter

from shared_schema.api import (
    AssessRequest,
    CheckRequest,
    EnvelopeRequest,
    HistoryOptions,
    PulseRequest,
    RecordSamples,
    ReportOptions,
    ScaleFactorRequest,
    SpectrumOptions,
)
from shared_schema.constants import ConstantsFile

__all__ = [
    "JOB",
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
    "ScaleFactorJob",
    "SceneJob",
    "SearchJob",
    "SpectrumJob",
    "WarmupJob",
]

_JOB = ConfigDict(strict=True, extra="forbid", allow_inf_nan=False)

#: The kinds of job a compute process runs.
JobKind = Literal[
    "pulse",
    "envelope",
    "history",
    "spectrum",
    "scale_factor",
    "constants",
    "report",
    "check",
    "assess",
    "assess_html",
    "assess_pdf",
    "search",
    "warmup",
]


class RecordUpload(BaseModel):
    """How to read an uploaded record file (its bytes travel as a blob)."""

    model_config = _JOB

    filename: str = ""
    format: Optional[str] = None
    units: Optional[str] = None
    dt: Optional[float] = None


class PulseJob(PulseRequest):
    """``rockmech pulse``."""

    kind: Literal["pulse"] = "pulse"


class EnvelopeJob(EnvelopeRequest):
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


class HistoryJob(_RecordInput, _ConstantsInput, HistoryOptions):
    """``rockmech history``."""

    model_config = _JOB

    kind: Literal["history"] = "history"


class SpectrumJob(_RecordInput, SpectrumOptions):
    """``rockmech record``."""

    model_config = _JOB

    kind: Literal["spectrum"] = "spectrum"


class ReportJob(_RecordInput, _ConstantsInput, ReportOptions):
    """``rockmech report``."""

    model_config = _JOB

    kind: Literal["report"] = "report"


class ScaleFactorJob(BaseModel):
    """A code or paper scale factor."""

    model_config = _JOB

    kind: Literal["scale_factor"] = "scale_factor"
    request: ScaleFactorRequest


class SceneJob(BaseModel):
    """``rockmech constants``: blobs are the .3dm scene and the spec."""

    model_config = _JOB

    kind: Literal["constants"] = "constants"
    scene_name: str = ""
    spec_name: str = ""
    units: Optional[str] = None


class SearchJob(BaseModel):
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
    record: Optional[RecordUpload] = None


class CheckJob(CheckRequest):
    """``rockmech check``."""

    kind: Literal["check"] = "check"


class AssessJob(AssessRequest):
    """``rockmech assess --json``: the assessment document."""

    kind: Literal["assess"] = "assess"


class AssessHtmlJob(AssessRequest):
    """``rockmech assess``: the assessment's HTML page."""

    kind: Literal["assess_html"] = "assess_html"


class AssessPdfJob(AssessRequest):
    """``rockmech assess --pdf``: the assessment's page printed to PDF."""

    kind: Literal["assess_pdf"] = "assess_pdf"


class WarmupJob(BaseModel):
    """Load every kernel once, before a compute process takes work."""

    model_config = _JOB

    kind: Literal["warmup"] = "warmup"


#: Any job.
Job = Annotated[
    Union[
        PulseJob,
        EnvelopeJob,
        HistoryJob,
        SpectrumJob,
        ReportJob,
        ScaleFactorJob,
        SceneJob,
        SearchJob,
        CheckJob,
        AssessJob,
        AssessHtmlJob,
        AssessPdfJob,
        WarmupJob,
    ],
    Field(discriminator="kind"),
]

#: Validates a job from its JSON form (in the compute process). (mypy cannot match a union of
#: twelve annotated job types against TypeAdapter's overloads: the cast only names the type.)
JOB: TypeAdapter[Job] = TypeAdapter(cast(Any, Job))
