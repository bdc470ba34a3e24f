"""The job kinds are declared once (``jobspec.JOB_KINDS``); the union and the dispatch follow."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from solver_service.api import jobs
from solver_service.api.jobspec import JOB, JOB_KINDS, JobKind, PulseJob, _by_kind

PULSE = {"p_eq": 2.0, "lam": 0.2, "eta": 0.9, "a_p_g": -0.61, "f_p": 1.59}


def test_the_compute_process_rebuilds_each_job_as_its_declared_model() -> None:
    job = JOB.validate_python(PulseJob(**PULSE).model_dump(mode="json", exclude_none=True))
    assert type(job) is PulseJob and job.f_p == 1.59
    assert type(JOB.validate_python({"kind": "warmup"})) is JOB_KINDS["warmup"].model


def test_an_undeclared_kind_is_refused_naming_the_declared_ones() -> None:
    with pytest.raises(ValidationError) as info:
        JOB.validate_python({"kind": "teleport"})
    message = str(info.value)
    assert "teleport" in message and all(f"'{kind}'" in message for kind in JOB_KINDS)


def test_every_declared_kind_runs_its_named_function_with_its_media_type() -> None:
    assert set(jobs.JOBS) == set(JOB_KINDS)
    for kind, decl in JOB_KINDS.items():
        media, run = jobs.JOBS[kind]
        assert media == decl.media_type and run.__name__ == decl.run
    assert jobs.JOBS["report"][0].startswith("text/html")
    assert jobs.JOBS["assess_pdf"][0] == "application/pdf"


def test_a_kind_declared_twice_is_refused() -> None:
    with pytest.raises(ValueError, match="declared twice"):
        _by_kind(JobKind(PulseJob, "run_pulse"), JobKind(PulseJob, "run_pulse"))
