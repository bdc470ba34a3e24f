"""Grasshopper Hops components (pulse, envelope, history) over ghhops-server's ``HopsBase``.

ghhops-server (pinned to 1.5.5) serves Hops only through Flask or its own HTTP server, and
its Flask middleware answers 405 to POSTs on component URIs, which is how Hops solves. So
this module keeps what ghhops does well (component metadata, parsing Hops' input trees,
encoding outputs) and puts a small ASGI adapter in front of it: ``GET /hops/<name>`` answers
``HopsBase.query`` and ``POST /hops/<name>`` (or the legacy ``POST /hops/solve`` with a
``pointer``) runs the solve.

The components run their computation through the same compute pool, limits and time budget
as the REST endpoints, with the same request models, so a bool is not a number here either.
Errors come back in Hops' own shape, ``{"values": [], "errors": [message]}``, with a 4xx or
503 status and the message the CLI would give.

Three workarounds for ghhops 1.5.5, all local to this module:

* it prints every input with a leftover ``pprint``; that name is rebound to a no-op;
* importing it calls ``logging.basicConfig(level=DEBUG)``; the root logger is restored;
* its output encoders are set up by ``_init_rhino3dm``, which imports rhino3dm; these
  components return only numbers, integers, booleans and text, so plain JSON encoding is
  installed instead and the service needs no Rhino library.
"""

from __future__ import annotations

import json
import logging
import math
import re
from collections.abc import Callable
from typing import Any, ClassVar

from pydantic import BaseModel, ValidationError

from shared_schema.api import EnvelopeRequest, PulseRequest
from shared_schema.constants import parse_constants, validation_lines
from shared_schema.errors import InputError

from .bodies import parse_json
from .errors import clip_echoes
from .jobspec import EnvelopeJob, HistoryJob, Job, PulseJob

log = logging.getLogger("rockmech.hops")

__all__ = ["HOPS_PREFIX", "HopsError", "JobRunner", "RockmechHops"]

#: URL prefix of the Hops components.
HOPS_PREFIX = "/hops"

#: Runs one compute job: job -> (status, media type, body).
JobRunner = Callable[[Job], tuple[int, str, bytes]]


def _default(model: type[BaseModel], name: str) -> Any:
    """Return the REST default of a field (a Hops input defaults to the same value)."""
    return model.model_fields[name].default


def _import_ghhops() -> Any:
    root = logging.getLogger()
    level, handlers = root.level, list(root.handlers)
    import ghhops_server.base as base
    import ghhops_server.params as params

    for handler in root.handlers[:]:
        if handler not in handlers:
            root.removeHandler(handler)
    root.setLevel(level)
    logging.getLogger("Hops").setLevel(logging.WARNING)
    params.pprint = lambda *args, **kwargs: None
    if params.RHINO_TOJSON is None:
        params.RHINO_TOJSON = lambda value: json.dumps(value, allow_nan=False)
        params.CONVERT_VALUE = lambda value: value
    return base, params


class HopsError(Exception):
    """A component failed for a reason the caller can act on (HTTP ``status``)."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status


def _strict_number(value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise HopsError(422, f"expected a number, got {value!r}")
    try:
        number = float(value)
    except OverflowError:  # an integer of hundreds of digits
        raise HopsError(422, "a number is out of the range of double precision") from None
    if not math.isfinite(number):
        raise HopsError(422, f"expected a finite number, got {value!r}")
    return number


def _strict_integer(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise HopsError(422, f"expected an integer, got {value!r}")
    return int(value)


def _strict_boolean(value: Any) -> bool:
    if not isinstance(value, bool):
        raise HopsError(422, f"expected true or false, got {value!r}")
    return value


def _param_types(params: Any) -> tuple[Any, Any, Any, Any]:
    """Hops parameter types whose coercion refuses a bool as a number (and vice versa)."""

    class Number(params.HopsNumber):  # type: ignore[misc]
        coercers: ClassVar[dict[str, Any]] = {
            "System.Double": _strict_number,
            "System.Int32": _strict_number,
        }

    class Integer(params.HopsInteger):  # type: ignore[misc]
        coercers: ClassVar[dict[str, Any]] = {"System.Int32": _strict_integer}

    class Boolean(params.HopsBoolean):  # type: ignore[misc]
        coercers: ClassVar[dict[str, Any]] = {"System.Boolean": _strict_boolean}

    return Number, Integer, Boolean, params.HopsString


def _finite_list(values: list[Any]) -> list[float]:
    return [float(v) if v is not None and math.isfinite(v) else -1.0 for v in values]


class RockmechHops:
    """rockmech's Hops components on a ``HopsBase``.

    Parameters
    ----------
    run_job : callable
        ``job -> (status, media_type, body)``; runs a compute job (the app passes
        one that goes through its compute pool, from a worker thread).
    """

    def __init__(self, run_job: JobRunner) -> None:
        base, params = _import_ghhops()
        self._run_job = run_job
        self.hops = base.HopsBase(None)
        Number, Integer, Boolean, Text = _param_types(params)
        item, many = params.HopsParamAccess.ITEM, params.HopsParamAccess.LIST
        component = self.hops.component

        types, access = (Number, Integer, Boolean, Text), (item, many)
        self.components = {
            "pulse": self._pulse(component, types, access),
            "envelope": self._envelope(component, types, access),
            "history": self._history(component, types, access),
        }

    def _pulse(self, component: Any, types: tuple[Any, ...], access: tuple[Any, Any]) -> Any:
        """Register the ``pulse`` component; return its handler."""
        Number, Integer, Boolean, Text = types
        item, _many = access

        @component(  # type: ignore[untyped-decorator]
            rule="/pulse",
            name="rockmech pulse",
            nickname="RMPulse",
            description="Response of one mechanism to a one-cycle sine or cosine pulse (exact).",
            category="rockmech",
            subcategory="Solver",
            inputs=[
                Number("p_eq", "p", "Frequency parameter p_eq [rad/s]", access=item),
                Number("lam", "λ", "Static load multiplier lambda [-]", access=item),
                Number("a_p_g", "a", "Signed pulse amplitude [g]", access=item),
                Number("f_p", "f", "Pulse frequency [Hz]", access=item),
                Number("eta", "η", "Coefficient of restitution [-]", access=item),
                Boolean("one_sided", "1s", "One-sided rocking", access=item),
                Text("shape", "S", "Pulse shape: sine or cosine", access=item),
            ],
            outputs=[
                Boolean("overturned", "O", "Overturns (exact criterion)"),
                Number("peak_ratio", "P", "Peak |phi|/phi_ov [-]"),
                Number("t_overturn", "T", "Time of overturning [s]; -1 if none"),
                Integer("n_impacts", "N", "Number of impacts"),
                Number("error_estimate", "E", "Estimated error of peak_ratio [-]"),
                Text("json", "J", "The whole result as JSON"),
            ],
        )
        def pulse(
            p_eq: float,
            lam: float,
            a_p_g: float,
            f_p: float,
            eta: float,
            one_sided: bool = _default(PulseRequest, "one_sided"),
            shape: str = _default(PulseRequest, "shape"),
        ) -> tuple[Any, ...]:
            request = {
                "p_eq": p_eq,
                "lam": lam,
                "a_p_g": a_p_g,
                "f_p": f_p,
                "eta": eta,
                "one_sided": one_sided,
                "shape": shape,
            }
            doc = self._job(PulseJob.model_validate(request))
            t_ov = doc["t_overturn"]
            return (
                doc["overturned"],
                doc["peak_ratio"],
                -1.0 if t_ov is None else t_ov,
                doc["n_impacts"],
                doc["error_estimate"] if doc["error_estimate"] is not None else -1.0,
                json.dumps(doc),
            )

        return pulse

    def _envelope(self, component: Any, types: tuple[Any, ...], access: tuple[Any, Any]) -> Any:
        """Register the ``envelope`` component; return its handler."""
        Number, Integer, _Boolean, Text = types
        item, many = access

        @component(  # type: ignore[untyped-decorator]
            rule="/envelope",
            name="rockmech envelope",
            nickname="RMEnvelope",
            description="Minimum overturning sine-pulse amplitude of every mechanism and the "
            "critical mechanism per frequency.",
            category="rockmech",
            subcategory="Solver",
            inputs=[
                Text("constants", "C", "Kinematic-constants JSON", access=item),
                Number("f_min", "f0", "Lowest pulse frequency [Hz]", access=item),
                Number("f_max", "f1", "Highest pulse frequency [Hz]", access=item),
                Integer("n", "n", "Number of log-spaced frequencies", access=item),
            ],
            outputs=[
                Number("f_p", "f", "Pulse frequencies [Hz]", access=many),
                Text("governing", "G", "Governing mechanism per frequency", access=many),
                Number("a_p_min_g", "A", "Governing a_p,min per frequency [g]; -1: none", many),
                Text("bands", "B", "Critical bands 'id: f_min-f_max Hz'", access=many),
                Text("json", "J", "The whole result as JSON"),
            ],
        )
        def envelope(
            constants: str,
            f_min: float = _default(EnvelopeRequest, "f_min"),
            f_max: float = _default(EnvelopeRequest, "f_max"),
            n: int = _default(EnvelopeRequest, "n"),
        ) -> Any:
            request = {"constants": _constants_json(constants), "f_min": f_min, "f_max": f_max}
            doc = self._job(EnvelopeJob.model_validate({**request, "n": n}))
            lowest = [
                min((v for v in col if v is not None), default=None)
                for col in zip(*(m["a_p_min_g"] for m in doc["mechanisms"]))
            ]
            bands = [
                f"{b['mechanism']}: {b['f_min']:.4g}-{b['f_max']:.4g} Hz" for b in doc["critical"]
            ]
            governing = [g or "" for g in doc["governing"]]
            return doc["f_p"], governing, _finite_list(lowest), bands, json.dumps(doc)

        return envelope

    def _history(self, component: Any, types: tuple[Any, ...], access: tuple[Any, Any]) -> Any:
        """Register the ``history`` component; return its handler."""
        Number, _Integer, Boolean, Text = types
        item, many = access

        @component(  # type: ignore[untyped-decorator]
            rule="/history",
            name="rockmech history",
            nickname="RMHistory",
            description="Time history of every mechanism under a record at each scale factor.",
            category="rockmech",
            subcategory="Solver",
            inputs=[
                Text("constants", "C", "Kinematic-constants JSON", access=item),
                Number("accel_g", "a", "Ground acceleration samples [g]", access=many),
                Number("dt", "dt", "Time step [s]", access=item),
                Number("scales", "s", "Scale factors [-]", access=many),
            ],
            outputs=[
                Text("mechanism", "M", "Mechanism per row", access=many),
                Number("scale", "s", "Scale factor per row", access=many),
                Number("peak_ratio", "P", "Peak |phi|/phi_ov per row", access=many),
                Boolean("overturned", "O", "Overturned per row", access=many),
                Number("error_estimate", "E", "Error estimate per row", access=many),
                Text("json", "J", "The whole result as JSON"),
            ],
        )
        def history(constants: str, accel_g: list[float], dt: float, scales: list[float]) -> Any:
            request = {
                "constants": _constants_json(constants),
                "record": {"accel": accel_g, "dt": dt, "units": "g", "name": "grasshopper"},
                "scales": scales,
            }
            doc = self._job(HistoryJob.model_validate(request))
            rows = doc["results"]
            return (
                [r["mechanism"] for r in rows],
                [r["scale"] for r in rows],
                _finite_list([r["peak_ratio"] for r in rows]),
                [r["overturned"] for r in rows],
                _finite_list([r["error_estimate"] for r in rows]),
                json.dumps(doc),
            )

        return history

    def _job(self, job: Job) -> dict[str, Any]:
        status, _, body = self._run_job(job)
        if status != 200:
            detail = json.loads(body).get("detail", "error")
            raise HopsError(status, detail)
        result: dict[str, Any] = json.loads(body)
        return result

    def query(self, uri: str) -> tuple[int, bytes]:
        """Answer ``GET`` on a component URI (metadata) or the root (every component)."""
        found, text = self.hops.query(uri=uri)
        return (200 if found else 404), text.encode("utf-8")

    def solve(self, uri: str, payload: bytes) -> tuple[int, bytes]:
        """Answer ``POST`` on a component URI, or on ``/solve`` with a ``pointer``."""
        try:
            data = parse_json(payload)
            if not isinstance(data, dict):
                raise HopsError(400, "a Hops solve request is a JSON object")
            if uri == "/solve":
                pointer = data.get("pointer")
                if not isinstance(pointer, str):
                    raise HopsError(400, "pointer: the legacy /solve request needs a pointer")
                uri = "/" + pointer.rsplit("/", 1)[-1]
            comp = self.hops._components.get(uri)
            if comp is None:
                raise HopsError(404, f"no Hops component at {HOPS_PREFIX}{uri}")
            values = data.get("values")
            if not isinstance(values, list) or not all(isinstance(v, dict) for v in values):
                raise HopsError(400, "values: a Hops solve request needs a list of inputs")
            _refuse_numbers_out_of_range(values)
            try:
                ok, inputs = self.hops._prepare_inputs(comp, json.dumps(data))
            except HopsError:
                raise
            except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
                message = f"malformed Hops input tree ({type(exc).__name__}: {exc})"
                raise HopsError(422, message) from None
            if not ok:
                raise HopsError(422, str(inputs))
            try:
                returned = comp.handler(*inputs)
            except InputError as exc:
                raise HopsError(422, str(exc)) from None
            _, text = self.hops._prepare_outputs(comp, returned)
            return 200, text.encode("utf-8")
        except HopsError as exc:
            return exc.status, self.hops._return_with_err(clip_echoes(str(exc))).encode("utf-8")
        except ValueError as exc:  # json.JSONDecodeError and pydantic's ValidationError
            message = clip_echoes(_validation_text(exc))
            return 422, self.hops._return_with_err(message).encode("utf-8")
        except RecursionError:  # an input's JSON text (the body's depth is bounded)
            message = "an input's JSON text is nested too deeply"
            return 422, self.hops._return_with_err(message).encode("utf-8")
        except OverflowError:
            message = "a number is out of the range of double precision"
            return 422, self.hops._return_with_err(message).encode("utf-8")
        except Exception:  # a bug: logged; the caller gets Hops' error shape, no traceback
            log.exception("Hops solve of %s failed", uri)
            message = "internal error; see the service log"
            return 500, self.hops._return_with_err(message).encode("utf-8")


def _constants_json(text: Any) -> Any:
    """Validate a constants file given as text; errors are labelled ``constants``."""
    if not isinstance(text, str):
        raise InputError(f"must be the JSON text of a constants file, got {text!r}", "constants")
    try:
        return json.loads(parse_constants(text).model_dump_json(exclude_none=True))
    except InputError as exc:
        raise InputError(str(exc), "constants") from None


#: A number as Hops sends one in an input tree's ``data`` text.
_NUMBER_TEXT = re.compile(r"\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*")


def _refuse_numbers_out_of_range(values: list[dict[str, Any]]) -> None:
    """Refuse, naming the input, a number no double can hold in a Hops input tree.

    ghhops reads each item's text with ``json.loads``: Python's own message for an integer
    of more than 4300 digits ("Exceeds the limit (4300 digits) ...") would reach the caller.

    Raises
    ------
    HopsError
        422 naming the input (``ParamName``).
    """
    for value in values:
        tree = value.get("InnerTree")
        if not isinstance(tree, dict):
            continue
        for items in tree.values():
            for item in items if isinstance(items, list) else ():
                data = item.get("data") if isinstance(item, dict) else None
                if isinstance(data, str) and _NUMBER_TEXT.fullmatch(data):
                    if not math.isfinite(float(data)):
                        raise HopsError(
                            422,
                            f"{value.get('ParamName')}: the number {data.strip()} is out of "
                            "the range of double precision (magnitudes up to 1.8e308)",
                        )


def _validation_text(exc: ValueError) -> str:
    if isinstance(exc, ValidationError):
        return "\n".join(f"{p}: {m}" if p else m for p, m in validation_lines(exc))
    if isinstance(exc, json.JSONDecodeError):
        return f"invalid JSON: {exc}"
    return str(exc)
