"""RM_Analyse: envelopes, critical bands, time histories or a pulse on a constants file.

The analyses run through the Python API (``solver_service.workflows``; the pure-Python
kernels are used where numba is missing, as in Rhino 8's CPython 3.9) or, when a service
URL is configured, through the REST service: ``POST <url>/api/v1/envelope``, ``/history``
and ``/pulse`` with the JSON bodies of ``shared_schema.api`` (``EnvelopeRequest``,
``HistoryRequest``, ``PulseRequest``). The client is plain ``urllib``; an error answer's
``detail`` is shown as the message.

Units: frequencies [Hz], pulse amplitudes [g], scale factors [-].

Python 3.9-clean: imported by Rhino 8.
"""

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Type, TypeVar, Union

from pydantic import BaseModel

from rhino_plugin.flows.mechanisms import checked_number
from rhino_plugin.flows.prompter import Cancelled, Prompter
from shared_schema.atomic import write_atomic
from shared_schema.constants import ConstantsFile
from shared_schema.documents.check import CheckDocument
from shared_schema.documents.envelope import EnvelopeDocument
from shared_schema.documents.history import HistoryDocument
from shared_schema.documents.pulse import PulseDocument
from shared_schema.errors import InputError, RockmechError
from shared_schema.io import read_constants
from solver_service.workflows.documents import frequency_grid, pick_mechanism, solve_pulse
from solver_service.workflows.inputs import read_record
from solver_service.workflows.outputs import write_envelope, write_history

__all__ = [
    "ANALYSES",
    "AnalysisResult",
    "ServiceClient",
    "analyse_flow",
    "read_constants_files",
    "run_envelopes",
    "run_history",
    "run_pulse",
    "typed_answer",
]

#: What RM_Analyse offers.
ANALYSES = ("Envelopes", "History", "Pulse")
#: Record units as Rhino option names (no "/" allowed there) -> records' unit names.
RECORD_UNITS = {"g": "g", "ms2": "m/s2", "cms2": "cm/s2"}
#: Seconds the service client waits for an answer.
SERVICE_TIMEOUT_S = 300.0
#: Frequencies of the envelopes [-]: log-spaced points between f_min and f_max.
N_FREQUENCIES = 200
#: The documents an analysis gives (``AnalysisResult.doc``).
AnalysisDoc = Union[EnvelopeDocument, HistoryDocument, PulseDocument, CheckDocument]
_D = TypeVar("_D", bound="BaseModel")


@dataclass
class AnalysisResult:
    """What an analysis produced.

    Attributes
    ----------
    kind : str
        One of :data:`ANALYSES`.
    doc : EnvelopeDocument, HistoryDocument, PulseDocument or CheckDocument
        The result (its ``to_dict()`` is what the CLI's ``--json`` prints and the service
        answers; the service's answer is validated into it).
    summary : list of str
        Lines for the command line.
    plot : str, optional
        PNG to show (local runs of envelopes and histories).
    files : list of str
        Files written.
    """

    kind: str
    doc: AnalysisDoc
    summary: List[str] = field(default_factory=list)
    plot: Optional[str] = None
    files: List[str] = field(default_factory=list)


class ServiceClient:
    """A minimal JSON client of the rockmech REST service (``/api/v1``).

    Parameters
    ----------
    base_url : str
        E.g. ``http://127.0.0.1:8000`` (with or without a trailing ``/``).
    timeout_s : float
        Seconds to wait for an answer [s].
    """

    def __init__(self, base_url: str, timeout_s: float = SERVICE_TIMEOUT_S) -> None:
        url = base_url.strip().rstrip("/")
        if not url.startswith(("http://", "https://")):
            raise InputError(f"the service URL must start with http:// or https://, got {url!r}")
        self.base_url = url
        self.timeout_s = float(timeout_s)

    def post(self, endpoint: str, payload: Dict[str, Any]) -> Dict[str, Any]:
        """POST ``payload`` as JSON to ``/api/v1/<endpoint>`` and return the JSON answer.

        Raises
        ------
        InputError
            The service refused the request (its ``detail`` is the message, field
            ``service``), could not be reached, or did not answer JSON.
        """
        return self.request(endpoint, json.dumps(payload).encode("utf-8"), "application/json")

    def post_files(
        self,
        endpoint: str,
        files: Dict[str, Tuple[str, bytes]],
        fields: Optional[Dict[str, str]] = None,
    ) -> Dict[str, Any]:
        """POST files (name -> (file name, bytes)) and text fields as a multipart form."""
        return _post_files(self, endpoint, files, fields)

    def request(self, endpoint: str, body: bytes, content_type: str) -> Dict[str, Any]:
        """POST a body to ``/api/v1/<endpoint>`` and return the JSON answer (see ``post``)."""
        import urllib.error
        import urllib.request

        url = f"{self.base_url}/api/v1/{endpoint}"
        request = urllib.request.Request(
            url,
            data=body,
            headers={"Content-Type": content_type, "Accept": "application/json"},
            method="POST",
        )
        try:
            with urllib.request.urlopen(request, timeout=self.timeout_s) as response:
                body = response.read()
        except urllib.error.HTTPError as exc:
            raw = exc.read()
            try:
                detail = json.loads(raw.decode("utf-8")).get("detail")
            except (ValueError, AttributeError):
                detail = None
            text = detail if isinstance(detail, str) else raw.decode("utf-8", "replace")[:500]
            raise InputError(f"{url} answered {exc.code}: {text}", "service") from None
        except (urllib.error.URLError, OSError) as exc:
            reason = getattr(exc, "reason", exc)
            raise InputError(
                f"cannot reach the rockmech service at {url}: {reason}", "service"
            ) from None
        try:
            doc = json.loads(body.decode("utf-8"))
        except ValueError:
            raise InputError(f"{url} did not answer JSON", "service") from None
        if not isinstance(doc, dict):
            raise InputError(f"{url} answered {type(doc).__name__}, expected an object", "service")
        return doc


def _post_files(
    client: "ServiceClient",
    endpoint: str,
    files: Dict[str, Tuple[str, bytes]],
    fields: Optional[Dict[str, str]] = None,
) -> Dict[str, Any]:
    """POST a multipart form to ``/api/v1/<endpoint>`` (``ServiceClient.post_files``)."""
    import uuid

    boundary = "rockmech-" + uuid.uuid4().hex
    parts: List[bytes] = []
    for name, value in (fields or {}).items():
        parts.append(
            f'--{boundary}\r\nContent-Disposition: form-data; name="{name}"\r\n\r\n'
            f"{value}\r\n".encode()
        )
    for name, (filename, data) in files.items():
        head = (
            f'--{boundary}\r\nContent-Disposition: form-data; name="{name}"; '
            f'filename="{filename}"\r\nContent-Type: application/octet-stream\r\n\r\n'
        )
        parts.append(head.encode("utf-8") + data + b"\r\n")
    body = b"".join(parts) + f"--{boundary}--\r\n".encode()
    return client.request(endpoint, body, f"multipart/form-data; boundary={boundary}")


def read_constants_files(paths: Sequence[str]) -> Any:
    """Read one or more constants files as one (mechanism ids must differ)."""
    if not paths:
        raise InputError("no constants file was given", "constants")
    mechanisms: List[Any] = []
    seen: Dict[str, str] = {}
    for path in paths:
        for mech in read_constants(path).mechanisms:
            if mech.id in seen:
                raise InputError(
                    f"mechanism id {mech.id!r} is in both {seen[mech.id]} and {path}", "constants"
                )
            seen[mech.id] = str(path)
            mechanisms.append(mech)
    return ConstantsFile(mechanisms=mechanisms)


def typed_answer(model: Type[_D], answer: Dict[str, Any], endpoint: str) -> _D:
    """Return the service's answer validated into its document.

    Raises
    ------
    InputError
        The answer is not that document (field ``service``, naming the first wrong field).
    """
    from pydantic import ValidationError

    try:
        return model.model_validate(answer)
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(part) for part in first["loc"]) or "the document"
        raise InputError(
            f"the service's answer to /{endpoint} is not its {model.__name__}: "
            f"{where}: {first['msg']}",
            "service",
        ) from None


def _constants_json(cf: Any) -> Dict[str, Any]:
    return dict(json.loads(cf.model_dump_json(exclude_none=True)))


def _band_lines(doc: EnvelopeDocument) -> List[str]:
    lines = ["critical mechanism by pulse frequency:"]
    for band in doc.critical:
        lines.append(f"  {band.mechanism}: {_g3(band.f_min)} to {_g3(band.f_max)} Hz")
    return lines


def _g3(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.3g}"


def run_envelopes(
    cf: Any,
    *,
    f_min: float = 0.1,
    f_max: float = 10.0,
    n: int = N_FREQUENCIES,
    out_dir: str,
    stem: str = "envelope",
    client: Optional[ServiceClient] = None,
) -> AnalysisResult:
    """Overturning envelopes of every mechanism and the critical bands (``rockmech envelope``)."""
    from pathlib import Path

    os.makedirs(out_dir, exist_ok=True)
    json_path = os.path.join(out_dir, f"{stem}.json")
    if client is not None:
        payload = {"constants": _constants_json(cf), "f_min": f_min, "f_max": f_max, "n": n}
        doc = typed_answer(EnvelopeDocument, client.post("envelope", payload), "envelope")
        write_atomic(json_path, json.dumps(doc.to_dict(), indent=2) + "\n")
        return AnalysisResult("Envelopes", doc, _band_lines(doc), None, [json_path])

    doc = write_envelope(
        cf, frequency_grid(f_min, f_max, n), Path(out_dir), stem=stem, title="Overturning envelopes"
    )
    plot = os.path.join(out_dir, f"{stem}.png")
    files = [json_path, os.path.join(out_dir, f"{stem}.csv"), plot]
    return AnalysisResult("Envelopes", doc, _band_lines(doc), plot, files)


def _history_lines(doc: HistoryDocument) -> List[str]:
    lines = []
    for row in doc.results:
        verdict = "OVERTURNS" if row.overturned else "survives"
        scale = "-" if row.scale is None else f"{row.scale:g}"
        peak = "-" if row.peak_ratio is None else f"{row.peak_ratio:.4f}"
        lines.append(f"  {row.mechanism} x {scale}: peak |phi|/phi_ov = {peak}, {verdict}")
    return lines


def run_history(
    cf: Any,
    record: str,
    *,
    units: Optional[str],
    scales: Sequence[float],
    out_dir: str,
    stem: str = "history",
    client: Optional[ServiceClient] = None,
) -> AnalysisResult:
    """Time histories of every mechanism at every scale factor (``rockmech history``)."""
    from pathlib import Path

    notes: List[str] = []
    motion = read_record(Path(record), units=units, on_warning=notes.append)
    # the record's warnings (implausible PGA or time step, naming the units read) come first
    said = [f"  warning: record: {note}" for note in notes]
    os.makedirs(out_dir, exist_ok=True)
    json_path = os.path.join(out_dir, f"{stem}.json")
    if client is not None:
        samples = {
            "accel": [float(a) for a in motion.accel.acc],
            "dt": float(motion.dt),
            "units": "m/s2",
            "name": motion.name,
        }
        payload = {"constants": _constants_json(cf), "record": samples, "scales": list(scales)}
        doc = typed_answer(HistoryDocument, client.post("history", payload), "history")
        write_atomic(json_path, json.dumps(doc.to_dict(), indent=2) + "\n")
        return AnalysisResult("History", doc, said + _history_lines(doc), None, [json_path])

    doc = write_history(cf, motion, list(scales), Path(out_dir), stem=stem, title=motion.name)
    plot = os.path.join(out_dir, f"{stem}.png")
    files = [json_path, plot, os.path.join(out_dir, f"{stem}_record.png")]
    return AnalysisResult("History", doc, said + _history_lines(doc), plot, files)


def run_pulse(
    cf: Any, mechanism: str, *, a_p_g: float, f_p: float, client: Optional[ServiceClient] = None
) -> AnalysisResult:
    """Response of one mechanism to a one-cycle sine pulse (``rockmech pulse --constants``).

    Both paths send the same ``PulseRequest`` (the whole mechanism: both sides, each impact
    direction's restitution) to the same function, ``solve_pulse``: here, or on the service
    behind ``POST /api/v1/pulse``.
    """
    payload = {"mechanism": pick_mechanism(cf, mechanism), "a_p_g": a_p_g, "f_p": f_p}
    if client is not None:
        doc = typed_answer(PulseDocument, client.post("pulse", payload), "pulse")
    else:
        doc = solve_pulse(payload)
    verdict = "OVERTURNS" if doc.overturned else "survives"
    line = f"  {mechanism}: sine pulse a_p = {a_p_g:g} g, f_p = {f_p:g} Hz: {verdict}"
    if doc.peak_ratio is not None:
        line += f" (peak |phi|/phi_ov = {doc.peak_ratio:.4f})"
    return AnalysisResult("Pulse", doc, [line])


def _num(prompter: Prompter, prompt: str, what: str, default: Optional[float] = None) -> float:
    return checked_number(prompter.get_number(prompt, default), what, what, above=0.0)


def analyse_flow(
    prompter: Prompter,
    out_dir: str,
    *,
    current: Sequence[str] = (),
    service_url: Optional[str] = None,
) -> Optional[AnalysisResult]:
    """Ask what to analyse and run it; messages go to ``prompter.message``.

    Parameters
    ----------
    prompter : Prompter
    out_dir : str
        Folder of the result files.
    current : sequence of str
        Constants files of the current document's mechanisms (offered as "Current").
    service_url : str, optional
        The REST service; when given, the user may run there instead of locally.

    Returns
    -------
    AnalysisResult or None
        ``None`` when cancelled or refused (the reason was shown).
    """
    try:
        sources = ["File", "Current"] if current else ["File"]
        source = prompter.get_option("Constants from", sources, 1 if current else 0)
        if source == "Current":
            paths = list(current)
        else:
            paths = [prompter.get_file("Kinematic-constants file", [".json"])]
        cf = read_constants_files(paths)
        kind = prompter.get_option("Analysis", list(ANALYSES), 0)
        client = None
        if service_url:
            if prompter.get_option("Run on", ["Local", "Service"], 0) == "Service":
                client = ServiceClient(service_url)
        if kind == "Envelopes":
            f_min = _num(prompter, "Lowest pulse frequency [Hz]", "f_min [Hz]", 0.1)
            f_max = _num(prompter, "Highest pulse frequency [Hz]", "f_max [Hz]", 10.0)
            result = run_envelopes(cf, f_min=f_min, f_max=f_max, out_dir=out_dir, client=client)
        elif kind == "History":
            record = prompter.get_file("Ground-motion record", [".at2", ".txt", ".dat", ".csv"])
            units = RECORD_UNITS[prompter.get_option("Record units", list(RECORD_UNITS), 0)]
            scales = [_num(prompter, "Scale factor", "scale factor", 1.0)]
            while True:
                more = prompter.get_number("Another scale factor (Enter when done)", None, True)
                if more is None:
                    break
                scales.append(checked_number(more, "scale factor", "scale factor", above=0.0))
            fmt_units = None if record.lower().endswith(".at2") else units
            result = run_history(
                cf, record, units=fmt_units, scales=scales, out_dir=out_dir, client=client
            )
        else:
            ids = [m.id for m in cf.mechanisms]
            mechanism = prompter.get_option("Mechanism", ids, 0)
            a_p = prompter.get_number("Pulse amplitude a_p [g] (signed)", None)
            a_p_g = checked_number(a_p, "a_p [g]", "a_p_g")
            f_p = _num(prompter, "Pulse frequency f_p [Hz]", "f_p [Hz]", 1.0)
            result = run_pulse(cf, mechanism, a_p_g=a_p_g, f_p=f_p, client=client)
    except Cancelled:
        prompter.message("RM_Analyse: cancelled.")
        return None
    except (RockmechError, ValueError) as exc:
        prompter.message(f"RM_Analyse: {exc}")
        return None
    where = "the service" if client is not None else "the Python API"
    prompter.message(
        f"RM_Analyse: {result.kind.lower()} of {len(cf.mechanisms)} mechanism(s) via {where}"
    )
    for line in result.summary:
        prompter.message(line)
    for path in result.files:
        prompter.message(f"  wrote {path}")
    return result
