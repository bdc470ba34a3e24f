"""Schemathesis hooks: the rules across fields that JSON Schema cannot state.

Loaded by ``test_api_schemathesis.py`` (``SCHEMATHESIS_HOOKS``) into the ``st`` process. The
positive-data check ("a request the schema allows must succeed") runs on ``/scale-factor``;
the schema states every rule of that operation but these, which compare two fields or a field
with a setting of the server, and which JSON Schema has no keyword for. Positive test cases
that break one are dropped here; negative test cases are left as they are, so the service
still has to refuse them. Each rule is the service's own, with its reason:

- ``ec8``: ``z <= H`` (``core.codes.sf_ec8``; EN 1998-1 §4.3.5.2 has no element above the
  building), ``nzs``: ``h_i <= h_n`` (``core.codes.sf_nzs``; NZS 1170.5 §8.3 likewise);
- ``eq28`` from a record: at most ``ROCKMECH_MAX_SAMPLES`` samples, and the spectrum at
  ``T_n = 1/f_n`` within the work bound: ``(samples - 1) * max(1, ceil(STEPS_PER_PERIOD *
  f_n * dt))`` closed-form steps at most ``WORK_PER_SAMPLE * ROCKMECH_MAX_SAMPLES``
  (``api.jobs.check_record_work``): a period far shorter than the record's time step costs
  sub-steps on every sample.

It also mends a fault of the client (schemathesis 4.32.5): its JSON Schema generator filters
some draws with ``jsonschema_rs`` (``_validator``: ``allOf`` branches, arrays, ``not``), and
a draw for a multipart form can hold an uploaded file (``Binary``), which ``jsonschema_rs``
cannot read: the run stopped in the client with ``ValueError: Unsupported type: 'Binary'``
on ``/report`` at some seeds (20261123 on main; 20261121 once the record rules were stated),
never in the server. The replacement validates the draw with each file read as "" (as
schemathesis' own negative-data filter does: ``format: binary`` only annotates).
"""

from __future__ import annotations

import math
import os
from typing import Any, Callable

import schemathesis
from schemathesis import Case, HookContext
from schemathesis.generation.jsonschema import strategy as jsonschema_strategy
from schemathesis.specs.openapi.negative import _strip_binary

from solver_service.core.spectra import STEPS_PER_PERIOD
from solver_service.workflows.limits import WORK_PER_SAMPLE

#: The server's ``ROCKMECH_MAX_SAMPLES`` (the test passes it in the environment).
MAX_SAMPLES = int(os.environ["ROCKMECH_MAX_SAMPLES"])


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


@schemathesis.hook("filter_case").apply_to(path_regex="/scale-factor$", method="POST")
def scale_factor_rules(context: HookContext, case: Case) -> bool:
    """Drop positive ``/scale-factor`` cases that break a rule JSON Schema cannot state."""
    if not case.meta or not case.meta.generation.mode.is_positive:
        return True
    return scale_factor_ok(case.body)


def _validator(schema: Any) -> Callable[[Any], bool]:
    """schemathesis' ``_validator``, with uploaded files read as "" (see the module docstring)."""
    is_valid = _original_validator(schema)
    return lambda value: bool(is_valid(_strip_binary(value)))


_original_validator = jsonschema_strategy._validator
# schemathesis' generator looks the name up each time it builds a strategy.
jsonschema_strategy._validator = _validator
