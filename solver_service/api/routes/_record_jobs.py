"""Jobs on a record, from a JSON body or a multipart form: history, spectrum and report."""

from __future__ import annotations

from typing import Any, Union

from fastapi import Request, Response
from pydantic import BaseModel

from shared_schema.errors import InputError

from ..bodies import validate_json
from ..compute import compute
from ..deps import JSON, media_type
from ..forms import FORMS, parse_form, read_form, read_upload
from ..jobspec import HistoryJob, RecordUpload, ReportJob, SpectrumJob
from ..pool import ComputePool
from ..problems import Problem
from ..uploads import check_record_lines

__all__ = ["RecordJob", "run_record_job"]

#: A job on a record.
RecordJob = Union[type[HistoryJob], type[SpectrumJob], type[ReportJob]]


async def run_record_job(
    request: Request, pool: ComputePool, job_model: RecordJob, json_model: type[BaseModel]
) -> Response:
    """Validate a JSON body with ``json_model``, or a multipart form; run the job."""
    if media_type(request) == JSON:
        model = validate_json(json_model, await request.body())
        return await compute(pool, job_model(**dict(model)))
    form = await read_form(request)
    try:
        spec = FORMS[job_model.model_fields["kind"].default]
        fields: dict[str, Any] = parse_form(form, spec)
        options = {k: fields.pop(k) for k in ("format", "units", "dt")}
        blobs: list[bytes] = []
        if spec.constants:
            data, name = await read_upload(form, "constants", True) or (b"", "")
            fields["constants_label"] = name.rsplit("/", 1)[-1] or "constants"
            blobs.append(data)
        record = await read_upload(form, "record", spec.record_required)
        if record is not None:
            try:  # before a compute process parses it (and holds it in memory)
                check_record_lines(record[0], pool.limits["max_samples"])
            except InputError as exc:
                raise Problem(422, "InputError", str(exc), exc.field) from None
            fields["upload"] = RecordUpload(filename=record[1], **options)
            blobs.append(record[0])
    finally:
        await form.close()
    return await compute(pool, job_model(**fields), blobs)
