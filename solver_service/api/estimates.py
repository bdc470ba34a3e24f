"""Work and answer size of a job, estimated before any compute process is spent on it.

A request whose work cannot finish within the compute budget, or whose answer would be
larger than ``ROCKMECH_MAX_ANSWER_BYTES``, is refused with 422 at once instead of holding a
compute process for the whole budget (or the server's memory for a huge answer). The app
estimates every JSON job before sending it to the pool (``jobspec.check_job`` runs the
``estimate_*`` function its kind declares in ``jobspec.JOB_KINDS``); a compute process
repeats the history estimate after reading an uploaded record (the app cannot count its
samples).

Light on purpose (standard library and the request models only): the app process uses it.

Notes
-----
Work is counted in closed-form steps of the exact integrator, which cuts each record sample
interval (or a pulse of ``1/f_p`` seconds) into segments of at most ``1/p_eq`` seconds:

* a pulse: ``p_eq / f_p`` steps;
* exact envelopes: per mechanism side (both directions for one-sided rocking) and
  frequency, ``N_SCAN`` pulse runs of ``max(1, p_eq / f_p)`` steps; with amplification
  data, the pulse scale factor's grid points too (``scale_factor_points``, counted at
  ``PULSE_POINTS_PER_CORE_S``);
* time histories: per mechanism side and scale factor, ``(n - 1) max(1, ceil(p_eq dt))``;
* an assessment: the time histories of every record at every multiple (one more run per
  record for the HTML page's figures) and the exact envelopes of its envelope margin
  (``ASSESS_ENVELOPE``, with the pulse scale factors of the mechanisms above ground),
  then, once the check has given each mechanism's matching band (in the compute process),
  ``BAND_POINTS`` spectrum periods per mechanism and record of
  ``(n - 1) max(1, ceil(STEPS_PER_PERIOD dt / T))`` steps each.

A retrofit is counted in 2019 code checks (``workflows.limits.retrofit_checks``: per
mechanism and candidate tie height, the check after the tie and the bisection steps per limit
state), at ``RETROFIT_CHECKS_PER_S``, as ``rockmech retrofit`` counts them for its time limit.

An assessment's HTML page draws ``1 + n_mechanisms (2 + n_records)`` figures; it is refused
when they cannot be drawn within the budget at ``FIGURES_PER_S`` or would make the page
larger than ``ROCKMECH_MAX_ANSWER_BYTES`` at ``ANSWER_BYTES_PER_FIGURE``.

A job is refused when its work cannot finish within the budget even at ``RATE_MARGIN``
times the rates measured by ``benchmarks/work_rates.py`` on every core
(``workflows.limits.shortest_time``; the rates and the margin, with their calibration, are
in ``workflows.limits`` and ``docs/service.md``); the budget still catches the rest.
"""

from __future__ import annotations

import math
from typing import Any, Optional

from shared_schema.api import AssessRequest, EnvelopeRequest, PulseRequest, RetrofitRequest
from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError

from ..workflows.limits import (  # the numbers and estimates shared with the command line
    ASSESS_ENVELOPE,
    FIGURES_PER_S,
    N_SCAN,
    RATE_MARGIN,
    WORK_PER_SAMPLE,
    check_retrofit_work,
    cores,
    envelope_steps,
    history_steps,
    scale_factor_points,
    shortest_time,
    work_words,
)

__all__ = [
    "ANSWER_BYTES_PER_FIGURE",
    "ANSWER_BYTES_PER_NUMBER",
    "N_SCAN",
    "WORK_PER_SAMPLE",
    "assess_figures",
    "check_constants",
    "check_limit",
    "check_time",
    "check_work",
    "envelope_steps",
    "estimate_assess",
    "estimate_assess_page",
    "estimate_envelope",
    "estimate_history",
    "estimate_pulse",
    "estimate_report",
    "estimate_retrofit",
    "estimate_scale_factor",
    "estimate_spectrum",
    "history_steps",
]

#: Bytes of JSON per number in an answer (17 significant digits, sign, exponent, comma).
ANSWER_BYTES_PER_NUMBER = 24
#: Bytes of HTML per embedded figure (base64 PNG) [bytes]: 69 kB measured on the El Centro
#: church page (``benchmarks/work_rates.py``'s), taken a little low so that only pages
#: certainly too large are refused.
ANSWER_BYTES_PER_FIGURE = 60_000


def check_limit(count: int, limit: int, what: str, field: str, setting: str) -> None:
    """Raise ``InputError`` (naming the limit) when ``count`` exceeds ``limit``."""
    if count > limit:
        raise InputError(
            f"{count} {what} exceed the service limit of {limit} per request "
            f"(ROCKMECH_{setting.upper()})",
            field,
        )


def check_work(steps: float, limits: dict[str, Any], what: str, field: str) -> None:
    """Raise ``InputError`` (naming the limit) when one run would take too many steps."""
    limit = WORK_PER_SAMPLE * limits["max_samples"]
    if steps > limit:
        raise InputError(
            f"{what} would take {steps:.3g} closed-form steps; the service computes at most "
            f"{limit} per run ({WORK_PER_SAMPLE} x ROCKMECH_MAX_SAMPLES); resample the record "
            "or run it with the rockmech command line",
            field,
        )


def check_time(limits: dict[str, Any], what: str, field: str, **work: float) -> None:
    """Raise ``InputError`` when ``work`` cannot be computed within the compute budget.

    Parameters
    ----------
    limits : dict
        The service's limits (``budget_s``: the budget [s]; none: no check).
    what, field : str
        What the work is, for the message, and the field it is blamed on.
    **work : float
        The work by kind, as ``workflows.limits.shortest_time`` takes it.
    """
    budget = limits.get("budget_s")
    if budget is None:
        return
    seconds = shortest_time(**work)
    if not seconds > budget:
        return
    raise InputError(
        f"{what} would take {work_words(**work)}: at least {seconds:.3g} s even at "
        f"{RATE_MARGIN:g} times the rates measured (benchmarks/work_rates.py) on all "
        f"{cores()} cores, past the service's budget of {budget:g} s per request "
        "(ROCKMECH_COMPUTE_TIMEOUT_S); ask for less work or run it with the rockmech "
        "command line",
        field,
    )


def _check_answer(n_numbers: float, limits: dict[str, Any], what: str, field: str) -> None:
    size = n_numbers * ANSWER_BYTES_PER_NUMBER
    limit = limits.get("max_answer_bytes")
    if limit is not None and size > limit:
        raise InputError(
            f"{what} would be about {size / 2**20:.0f} MiB; the service answers at most "
            f"{limit} bytes (ROCKMECH_MAX_ANSWER_BYTES); ask for fewer points",
            field,
        )


def _positive(*values: Any) -> bool:
    return all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0
        for v in values
    )


def _check_derived(cf: ConstantsFile) -> None:
    """Refuse constants whose derived side values overflowed (``p_eq = sqrt(K/I0)`` = inf)."""
    for i, mech in enumerate(cf.mechanisms):
        for name in ("positive", "negative"):
            side = getattr(mech, name)
            for key in ("p_eq", "lam", "phi_ov"):
                value = getattr(side, key, None) if side is not None else None
                if isinstance(value, float) and not math.isfinite(value):
                    raise InputError(
                        f"mechanisms[{i}] (id {mech.id!r}).{name}.{key}: derived value {value} "
                        "is not finite; the inputs are too large or too small for double "
                        "precision",
                        "constants",
                    )


def _envelope(
    cf: ConstantsFile, f_min: float, f_max: float, n: int, exact: bool, limits: dict[str, Any]
) -> None:
    check_limit(n, limits["max_samples"], "frequencies", "n", "max_samples")
    columns = sum(4 if m.amplification is not None else 1 for m in cf.mechanisms) + 2
    _check_answer(n * columns, limits, "the envelopes", "n")
    # Mechanisms with a restitution per impact direction are computed exactly anyway.
    what = (
        "the exact envelopes (method library is faster)"
        if exact
        else (
            "the envelopes of the mechanisms with a restitution per impact direction (always "
            "computed with the exact integrator)"
        )
    )
    check_time(
        limits,
        what,
        "method" if exact else "constants",
        envelope_steps=envelope_steps(cf, f_min, f_max, n, exact=exact),
        pulse_points=scale_factor_points(cf, f_min, f_max, n) if exact else 0.0,
    )


def _history(job: Any, cf: Optional[ConstantsFile], limits: dict[str, Any]) -> None:
    check_limit(len(job.scales), limits["max_scales"], "scale factors", "scales", "max_scales")
    if job.record is None:
        return
    n, dt = len(job.record.accel), job.record.dt
    check_limit(n, limits["max_samples"], "samples", "record", "max_samples")
    if cf is not None:
        check_work(history_steps(cf, n, dt, 1, worst=True), limits, "the time history", "record")
        steps = history_steps(cf, n, dt, len(job.scales))
        check_time(limits, "the time histories", "record", history_steps=steps)


def assess_figures(n_mechanisms: int, n_records: int) -> int:
    """Count the figures of an assessment page.

    The site spectrum; per mechanism the capacity curve, the envelope and one time history
    per record.
    """
    return 1 + n_mechanisms * (2 + n_records)


def _assess(job: Any, cf: ConstantsFile, limits: dict[str, Any], html: bool) -> None:
    total = sum(len(r.accel) for r in job.records)
    check_limit(total, limits["max_samples"], "record samples", "records", "max_samples")
    runs = len(job.multiples) + (1 if html else 0)
    steps = 0.0
    for i, record in enumerate(job.records):
        n, dt = len(record.accel), record.dt
        worst = history_steps(cf, n, dt, 1, worst=True)
        check_work(worst, limits, "the time history", f"records[{i}]")
        steps += history_steps(cf, n, dt, runs)
    # then the envelope margin: exact envelopes of every mechanism, and the pulse scale
    # factors of those above ground (issue #36's fuzz run: 3.4 s of an /assess went there)
    check_time(
        limits,
        "the time histories and the envelope margins",
        "records",
        history_steps=steps,
        envelope_steps=envelope_steps(cf, *ASSESS_ENVELOPE, exact=True),
        pulse_points=scale_factor_points(cf, *ASSESS_ENVELOPE),
    )
    if not html:
        return
    figures = assess_figures(len(cf.mechanisms), len(job.records))
    budget = limits.get("budget_s")
    if budget is not None and shortest_time(figures=figures) > budget:
        raise InputError(
            f"the HTML page would draw {figures} figures: at least "
            f"{shortest_time(figures=figures):.3g} s even at {RATE_MARGIN:g} times the "
            f"{FIGURES_PER_S:g} figures/s measured, past the service's budget of {budget:g} s "
            "per request (ROCKMECH_COMPUTE_TIMEOUT_S); send fewer mechanisms or records, ask "
            "for format json, or run rockmech assess",
            "format",
        )
    size = figures * ANSWER_BYTES_PER_FIGURE
    limit = limits.get("max_answer_bytes")
    if limit is not None and size > limit:
        raise InputError(
            f"the HTML page would be about {size / 2**20:.0f} MiB ({figures} figures); the "
            f"service answers at most {limit} bytes (ROCKMECH_MAX_ANSWER_BYTES); send fewer "
            "mechanisms or records, or ask for format json",
            "format",
        )


def check_constants(cf: ConstantsFile, limits: dict[str, Any]) -> None:
    """Count the mechanisms of any job's constants, and refuse non-finite derived values."""
    check_limit(
        len(cf.mechanisms),
        limits["max_mechanisms"],
        "mechanisms",
        "constants",
        "max_mechanisms",
    )
    _check_derived(cf)


# --- the estimates of the job kinds (``jobspec.JOB_KINDS``), each ``(job, limits) -> None`` ---


def estimate_pulse(job: PulseRequest, limits: dict[str, Any]) -> None:
    """Bound a pulse: ``p_eq / f_p`` closed-form steps."""
    p_eq = job.p_eq_max
    if p_eq is not None and _positive(p_eq, job.f_p):
        # Segments of at most 1/p_eq seconds over the pulse's 1/f_p seconds.
        check_work(p_eq / job.f_p, limits, "the pulse", "f_p")


def estimate_envelope(job: EnvelopeRequest, limits: dict[str, Any]) -> None:
    """Bound envelopes: the frequencies, the answer's size and the pulse runs."""
    _envelope(job.constants, job.f_min, job.f_max, job.n, job.method == "exact", limits)


def estimate_history(job: Any, limits: dict[str, Any]) -> None:
    """Bound time histories of a record given as samples (an upload: where it is read)."""
    _history(job, job.constants, limits)


def estimate_report(job: Any, limits: dict[str, Any]) -> None:
    """Bound a report: its time histories and its envelopes."""
    cf = job.constants
    _history(job, cf, limits)
    if cf is not None:
        _envelope(cf, job.f_min, job.f_max, job.n, job.method == "exact", limits)


def estimate_spectrum(job: Any, limits: dict[str, Any]) -> None:
    """Bound a spectrum: the periods, and the samples of a record given as samples."""
    check_limit(job.n, limits["max_samples"], "periods", "n", "max_samples")
    if job.record is not None:
        n = len(job.record.accel)
        check_limit(n, limits["max_samples"], "samples", "record", "max_samples")


def estimate_assess(job: AssessRequest, limits: dict[str, Any]) -> None:
    """Bound the assessment document: every record's time histories at every multiple."""
    _assess(job, job.constants, limits, False)


def estimate_assess_page(job: AssessRequest, limits: dict[str, Any]) -> None:
    """Bound the assessment page (HTML or PDF): the time histories and the figures."""
    _assess(job, job.constants, limits, True)


def estimate_retrofit(job: RetrofitRequest, limits: dict[str, Any]) -> None:
    """Bound a retrofit: its planned code checks (``workflows.limits.retrofit_checks``)."""
    budget = limits.get("budget_s")
    if budget is None:
        return
    check_retrofit_work(
        job.constants,
        job.site,
        job.spec,
        budget,
        "run rockmech retrofit with the command line (ROCKMECH_COMPUTE_TIMEOUT_S is the "
        "service's budget per request)",
    )


def estimate_scale_factor(job: Any, limits: dict[str, Any]) -> None:
    """Bound a scale factor: the samples of a record (eq. 28 from a record)."""
    record = getattr(job.request, "record", None)
    if record is not None:
        n = len(record.accel)
        check_limit(n, limits["max_samples"], "samples", "record", "max_samples")
