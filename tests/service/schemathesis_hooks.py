"""Schemathesis hooks: the rules across fields that JSON Schema cannot state.

Loaded by ``test_api_schemathesis.py`` (``SCHEMATHESIS_HOOKS``) into the ``st`` process. The
positive-data check ("a request the schema allows must succeed") runs on every JSON
operation; the schema states every rule but those that compare two fields, or a field with
a setting of the server, which JSON Schema has no keyword for. Positive test cases that
break one are dropped here; negative test cases are left as they are, so the service still
has to refuse them. Each rule is the service's own, called or mirrored, with its reason:

- ``/scale-factor`` (``scale_factor_ok``): ``ec8``: ``z <= H`` (``codes.scale_factors.sf_ec8``; EN
  1998-1 §4.3.5.2 has no element above the building), ``nzs``: ``h_i <= h_n``
  (``codes.scale_factors.sf_nzs``; NZS 1170.5 §8.3 likewise); ``eq28`` from a record: at most
  ``ROCKMECH_MAX_SAMPLES`` samples, and the spectrum at ``T_n = 1/f_n`` within the work
  bound: ``(samples - 1) * max(1, ceil(STEPS_PER_PERIOD * f_n * dt))`` closed-form steps at
  most ``WORK_PER_SAMPLE * ROCKMECH_MAX_SAMPLES`` (``api.jobs.check_record_work``): a period
  far shorter than the record's time step costs sub-steps on every sample.
- the other JSON operations (``json_body_ok``): the body validated with the request model
  as the service does, dropped only for a rule across fields (``CROSS_FIELD_RULES``); for
  ``/check`` and ``/assess`` the site's choices against the constants
  (``workflows.codecheck.check_site_inputs``: the mechanism ids it names exist; its
  ``building.T1`` agrees with the ``1/f_n`` of a mechanism above ground that is checked);
  the options' order (``f_min < f_max``, ``t_min < t_max``); then the server's limits and
  work (``_work_ok``, ``_scale_factors_ok``, ``_assess_spectra_ok``, ``_amplitude_ok``).

The multipart forms are excepted from the positive-data check: ``positive_data_acceptance``
is re-registered to skip them (their uploads are random bytes, which the service rightly
refuses); every other check still runs on them.

It also mends a fault of the client (schemathesis 4.32.5): its JSON Schema generator filters
some draws with ``jsonschema_rs`` (``_validator``: ``allOf`` branches, arrays, ``not``), and
a draw for a multipart form can hold an uploaded file (``Binary``), which ``jsonschema_rs``
cannot read: the run stopped in the client with ``ValueError: Unsupported type: 'Binary'``
on ``/report`` at some seeds (20261123 on main; 20261121 once the record rules were stated),
never in the server. The replacement validates the draw with each file read as "" (as
schemathesis' own negative-data filter does: ``format: binary`` only annotates).
"""

from __future__ import annotations

import json
import math
import os
from typing import Any, Callable

import numpy as np
import schemathesis
from pydantic import BaseModel, ValidationError
from schemathesis import Case, CheckContext, HookContext, Response
from schemathesis.checks import CHECKS
from schemathesis.generation.jsonschema import strategy as jsonschema_strategy
from schemathesis.specs.openapi.checks import (
    positive_data_acceptance as _original_positive_data_acceptance,
)
from schemathesis.specs.openapi.negative import _strip_binary

from shared_schema.api import (
    AssessRequest,
    CheckRequest,
    EnvelopeRequest,
    HistoryRequest,
    PulseRequest,
    ReportRequest,
    SpectrumRequest,
)
from shared_schema.errors import InputError
from solver_service.api.jobs import (
    check_history_work,
    check_record_work,
    check_spectra_work,
    history_options,
    motion_from_params,
    shared_library,
)
from solver_service.api.jobspec import (
    AssessHtmlJob,
    AssessJob,
    AssessPdfJob,
    CheckJob,
    EnvelopeJob,
    HistoryJob,
    PulseJob,
    ReportJob,
    SpectrumJob,
    check_job,
)
from solver_service.api.settings import Settings
from solver_service.core.amplification import pulse_scale_factor
from solver_service.core.exact import MAX_AMPLITUDE_RATIO
from solver_service.core.model import G
from solver_service.core.spectra import STEPS_PER_PERIOD
from solver_service.report.html import SPECTRUM_PERIODS
from solver_service.workflows.assess import check_doc
from solver_service.workflows.codecheck import check_site_inputs
from solver_service.workflows.documents import frequency_grid
from solver_service.workflows.limits import WORK_PER_SAMPLE
from solver_service.workflows.scaling import factor_groups

#: The server's ``ROCKMECH_MAX_SAMPLES`` (the test passes it in the environment).
MAX_SAMPLES = int(os.environ["ROCKMECH_MAX_SAMPLES"])
#: The server's limits and budget, from the same ``ROCKMECH_*`` variables as the server's.
LIMITS = Settings().limits()
#: The service refuses up front only work that cannot finish within its budget even at
#: ``RATE_MARGIN`` times the measured rates on every core (``workflows.limits.shortest_time``),
#: and stops the rest at the budget with 503; positive cases are kept within the budget at
#: this many times less (the test machine is loaded and shared).
LOADED_SLOWDOWN = 20
#: The server's limits with the budget at the loaded machine's rate.
LOADED_LIMITS = {**LIMITS, "budget_s": LIMITS["budget_s"] / LOADED_SLOWDOWN}


def _number(body: dict[str, Any], key: str) -> float | None:
    value = body.get(key)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value)


def scale_factor_ok(body: Any) -> bool:
    """Return False when a schema-valid ``/scale-factor`` body breaks a rule across fields."""
    if not isinstance(body, dict):
        return True
    method = body.get("method")
    if method == "ec8":
        z, top = _number(body, "z"), _number(body, "H")
        return z is None or top is None or z <= top
    if method == "nzs":
        h_i, h_n = _number(body, "h_i"), _number(body, "h_n")
        return h_i is None or h_n is None or h_i <= h_n
    record, f_n = body.get("record"), _number(body, "f_n")
    if method != "eq28" or not isinstance(record, dict) or f_n is None:
        return True
    accel, dt = record.get("accel"), _number(record, "dt")
    if not isinstance(accel, list) or dt is None:
        return True
    if len(accel) > MAX_SAMPLES:
        return False
    per_sample = STEPS_PER_PERIOD * f_n * dt
    steps = (
        (len(accel) - 1) * max(1.0, math.ceil(per_sample))
        if math.isfinite(per_sample)
        else math.inf
    )
    return steps <= WORK_PER_SAMPLE * MAX_SAMPLES


#: Error types of the rules across fields of the request models (``shared_schema``).
CROSS_FIELD_RULES = frozenset(
    {
        "inconsistent_constant",  # forms agreeing to 1e-9; S^2 <= mass J of virtual_work
        "static_collapse",  # lam and phi_ov > 0: K phi_cr above the static moment M_F
        "non_finite_constant",  # p_eq, lam, phi_ov derived from finite inputs overflow
        "duplicate_id",  # unique mechanism ids
        "eta_not_between",  # eta between eta_to_negative and eta_to_positive
        "implausible_constant",  # p_eq and lam derived from a physical form in range
        "duplicate_limit_state",  # site: limit_states repeating the hazard's own limit state
        "verified_ties_break",  # site: ties verified up to collapse with a failure rotation
    }
)

#: The request model and the job of each JSON operation.
JSON_OPERATIONS: dict[str, tuple[type[BaseModel], Callable[..., Any]]] = {
    "pulse": (PulseRequest, PulseJob),
    "envelope": (EnvelopeRequest, EnvelopeJob),
    "history": (HistoryRequest, HistoryJob),
    "spectrum": (SpectrumRequest, SpectrumJob),
    "report": (ReportRequest, ReportJob),
    "check": (CheckRequest, CheckJob),
    "assess": (
        AssessRequest,
        lambda **f: {"html": AssessHtmlJob, "pdf": AssessPdfJob}.get(f["format"], AssessJob)(**f),
    ),
}


def _ordered(lo: Any, hi: Any) -> bool:
    return lo is None or hi is None or lo < hi


def _work_ok(job: Any) -> bool:
    """Return False when a job exceeds the server's work or size limits (its own checks).

    The app's estimate (``api.jobspec.check_job``), then the compute process's checks of
    the work on a record (``api.jobs``: the integrator's steps per sample, a spectrum's
    shortest period). A PDF is left out: printing it is Chromium's work, which no estimate
    covers and which alone can pass the test server's short budget on a busy machine
    (tests/service/test_api_assess.py checks the PDF and the 501 without a browser).
    """
    if isinstance(job, AssessPdfJob):
        return False
    try:
        check_job(job, LIMITS)
        check_job(job, LOADED_LIMITS)
    except InputError:
        return False
    if isinstance(job, (EnvelopeJob, ReportJob)) and not _scale_factors_ok(job):
        return False
    if isinstance(job, (AssessJob, AssessHtmlJob, AssessPdfJob)):
        return _assess_spectra_ok(job)
    record = getattr(job, "record", None)
    if record is None:
        return True
    try:
        motion = motion_from_params(record, None, None, LIMITS)
    except InputError:
        return True  # the service refuses the record itself: the check sees its answer
    try:
        if isinstance(job, SpectrumJob):
            check_record_work(motion, LIMITS, t_min=job.t_min)
        else:
            check_history_work(job.constants, motion, job.sf, LIMITS, len(job.scales))
            if isinstance(job, ReportJob):
                check_record_work(motion, LIMITS, t_min=SPECTRUM_PERIODS[0])
    except InputError:
        return False
    return isinstance(job, SpectrumJob) or _amplitude_ok(job, motion)


def _scale_factors_ok(job: Any) -> bool:
    """Return False when a pulse's scale factor up the structure is refused or not finite.

    ``core.envelope.mechanism_envelope`` needs ``SF(f_p) = hypot(1, R h/h_e)`` finite at
    every frequency (the library's, or ``core.amplification.pulse_scale_factor``, which
    refuses ``f_p/f_n`` below ``RATIO_MIN``): ``h/h_e`` overflows for an ``h_e`` below about
    1e-305 m; both are ratios of two fields the schema cannot bound.
    """
    f_p = frequency_grid(job.f_min, job.f_max, job.n)
    for mech in job.constants.mechanisms:
        amp = mech.amplification
        if amp is None:
            continue
        try:
            if job.method == "exact":
                sf = pulse_scale_factor(f_p, f_n=amp.f_n, h=amp.h, h_e=amp.h_e)
            else:
                sf = shared_library().scale_factor(f_p, f_n=amp.f_n, h=amp.h, h_e=amp.h_e)
        except InputError:
            return False  # f_p/f_n below RATIO_MIN: the closed form's range, across fields
        if not np.all(np.isfinite(sf)):
            return False
    return True


def _assess_spectra_ok(job: Any) -> bool:
    """Return False when an assessment's spectra exceed the work bound (``api.jobs``).

    The compute process bounds the spectrum of every record down to the shortest period
    of each mechanism's matching band (from its code check) and to ``1/f_n``, one run and
    in total: the service's own ``api.jobs.check_spectra_work``, with the band from the
    constants and the site.
    """
    try:
        rows = check_doc(job.constants, job.site)["mechanisms"]
        motions = [motion_from_params(r, None, None, LIMITS) for r in job.records]
    except InputError:
        return True  # the service refuses the request itself: the check sees its answer
    try:
        check_spectra_work(job.constants, rows, motions, LIMITS)
    except InputError:
        return False
    return True


def _amplitude_ok(job: Any, motion: Any) -> bool:
    """Return False when a scaled record is beyond the solver's range (``core.exact.check_range``).

    Per group of mechanisms sharing a scale factor up the structure (``workflows.scaling``),
    the largest effective scale times the record's peak [m/s^2] over ``g lam`` of the
    weakest side must stay within ``MAX_AMPLITUDE_RATIO``.
    """
    cf = job.constants
    try:
        _, groups = factor_groups(cf, motion, job.sf, history_options(job)["building"])
    except InputError:
        return True  # the service refuses the options itself: the check sees its answer
    peak = float(np.max(np.abs(motion.accel.acc)))
    for factor, members in groups.items():
        sides = [s for i in members for s in (cf.mechanisms[i].positive, cf.mechanisms[i].negative)]
        lam_min = min(s.lam for s in sides if s is not None)
        ratio = max(job.scales) * factor * peak / (G * lam_min)
        if not ratio <= MAX_AMPLITUDE_RATIO * (1.0 + 1e-9):
            return False
    return True


def json_body_ok(operation: str, body: Any) -> bool:
    """Return False when a schema-valid JSON body breaks a rule JSON Schema cannot state.

    The body is validated as the service validates it (the request model, in JSON mode): a
    refusal by one of ``CROSS_FIELD_RULES`` drops the case, any other is left to the check.
    Then the rules across two fields of the options, and the server's limits.
    """
    model, job_model = JSON_OPERATIONS[operation]
    if operation == "assess" and isinstance(body, dict) and body.get("retrofit") is not None:
        # A retrofit spec's rules span two documents, as on /retrofit (excepted from the
        # positive check): its mechanisms must be the constants', with their geometry.
        return False
    try:
        request = model.model_validate_json(json.dumps(body))
    except ValidationError as exc:
        return not any(err["type"] in CROSS_FIELD_RULES for err in exc.errors())
    fields = dict(request)
    if operation in ("check", "assess"):
        # The site's choices against the constants: known mechanism ids, one T1 (the site's
        # building.T1 against the 1/f_n of a mechanism above ground that can be checked).
        try:
            check_site_inputs(request.constants, request.site)
        except InputError:
            return False
    # log_grid: f_min < f_max, t_min < t_max; extract_pulses: f_min <= f_max.
    if operation == "spectrum":
        if not _ordered(request.t_min, request.t_max):
            return False
        f_min, f_max = fields["f_min"], fields["f_max"]
        if f_min is not None and f_max is not None and f_min > f_max:
            return False
    elif "f_min" in fields and not _ordered(fields["f_min"], fields["f_max"]):
        return False
    return _work_ok(job_model(**fields))


def _positive(case: Case) -> bool:
    return bool(case.meta and case.meta.generation.mode.is_positive)


@schemathesis.hook("filter_case").apply_to(path_regex="/scale-factor$", method="POST")
def scale_factor_rules(context: HookContext, case: Case) -> bool:
    """Drop positive ``/scale-factor`` cases that break a rule JSON Schema cannot state."""
    return not _positive(case) or scale_factor_ok(case.body)


@schemathesis.hook("filter_case").apply_to(
    path_regex="/(pulse|envelope|history|spectrum|report|check|assess)$", method="POST"
)
def json_body_rules(context: HookContext, case: Case) -> bool:
    """Drop positive JSON cases that break a rule JSON Schema cannot state."""
    if not _positive(case) or case.media_type != "application/json":
        return True
    return json_body_ok(case.path.rsplit("/", 1)[-1], case.body)


def positive_data_acceptance(ctx: CheckContext, response: Response, case: Case) -> bool | None:
    """schemathesis' check, on JSON bodies only: uploaded files are excepted (module docstring)."""
    if case.media_type == "multipart/form-data":
        return None
    return _original_positive_data_acceptance(ctx, response, case)


CHECKS.unregister("positive_data_acceptance")
CHECKS.register(positive_data_acceptance)


def _validator(schema: Any) -> Callable[[Any], bool]:
    """schemathesis' ``_validator``, with uploaded files read as "" (see the module docstring)."""
    is_valid = _original_validator(schema)
    return lambda value: bool(is_valid(_strip_binary(value)))


_original_validator = jsonschema_strategy._validator
# schemathesis' generator looks the name up each time it builds a strategy.
jsonschema_strategy._validator = _validator
