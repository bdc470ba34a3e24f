"""RM_CodeCheck: the code's kinematic checks of every mechanism on a site (theory §11).

Runs ``solver_service.workflows.assess.check_document`` through the Python API or, with a service
URL, ``POST <url>/api/v1/check`` with ``{"constants": ..., "site": ...}`` (the same JSON as
the files). The summary has one line per mechanism: its linear and nonlinear verdicts (the
Circolare 2019's SLV checks, and the SLC where the site gives its hazard) with their
capacity/demand ratios, or why a check did not run.

Python 3.9-clean: imported by Rhino 8.
"""

import json
from typing import Any, List, Optional, Union

from rhino_plugin.flows.analyse import AnalysisResult, ServiceClient, typed_answer
from shared_schema.documents.check import (
    CheckDocument,
    LimitStateCheck,
    LinearCheck,
    Nonlinear2019,
    NonlinearCheck,
    NotRun,
)
from shared_schema.errors import InputError
from shared_schema.site import parse_site
from solver_service.workflows.assess import check_document

__all__ = ["check_lines", "parse_site_text", "run_check"]


def parse_site_text(text: Any) -> Any:
    """Parse a site file from JSON text (as the components pass it along)."""
    if not isinstance(text, str) or not text.strip():
        raise InputError("connect a site JSON text (SITE.json)", "site")
    return parse_site(text)


def _cell(check: Union[LinearCheck, NonlinearCheck, LimitStateCheck]) -> str:
    if isinstance(check, NotRun):
        return "not run"
    ratio = "-" if check.capacity_ratio is None else f"{check.capacity_ratio:.3g}"
    verdict = {True: "passes", False: "FAILS", None: "incomplete"}[check.passes]
    return f"{verdict} ({ratio})"


def check_lines(doc: CheckDocument) -> List[str]:
    """One line per mechanism: linear and nonlinear verdicts (capacity/demand), notes."""
    lines: List[str] = []
    for row in doc.mechanisms:
        lin, non = row.linear, row.nonlinear
        line = f"{row.id}: linear {_cell(lin)}, nonlinear {_cell(non)}"
        slc = non.SLC if isinstance(non, Nonlinear2019) else None
        if slc is not None and slc.passes is not None:
            line += f", SLC {_cell(slc)}"
        lines.append(line)
        for note in sorted({lin.note or "", non.note or ""} - {""}):
            lines.append(f"  note: {note}")
    if doc.governing:
        lines.append(f"governing mechanism: {doc.governing}")
    return lines


def run_check(cf: Any, site: Any, *, client: Optional[ServiceClient] = None) -> AnalysisResult:
    """Code checks of every mechanism of ``cf`` on ``site`` (``rockmech check``)."""
    if client is not None:
        payload = {
            "constants": json.loads(cf.model_dump_json(exclude_none=True)),
            "site": json.loads(site.model_dump_json(exclude_none=True)),
        }
        doc = typed_answer(CheckDocument, client.post("check", payload), "check")
    else:
        doc = check_document(cf, site)
    return AnalysisResult("Check", doc, check_lines(doc))
