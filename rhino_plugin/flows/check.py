"""RM_CodeCheck: the code's kinematic checks of every mechanism on a site (theory §11).

Runs ``solver_service.workflows.assess.check_document`` through the Python API or, with a service
URL, ``POST <url>/api/v1/check`` with ``{"constants": ..., "site": ...}`` (the same JSON as
the files). The summary has one line per mechanism: its linear and nonlinear verdicts (the
Circolare 2019's SLV checks, and the SLC where the site gives its hazard) with their
capacity/demand ratios, or why a check did not run.

Python 3.9-clean: imported by Rhino 8.
"""

import json
from typing import Any, Dict, List, Optional

from rhino_plugin.flows.analyse import AnalysisResult, ServiceClient
from shared_schema.errors import InputError
from shared_schema.site import parse_site
from solver_service.workflows.assess import check_document

__all__ = ["check_lines", "parse_site_text", "run_check"]


def parse_site_text(text: Any) -> Any:
    """Parse a site file from JSON text (as the components pass it along)."""
    if not isinstance(text, str) or not text.strip():
        raise InputError("connect a site JSON text (SITE.json)", "site")
    return parse_site(text)


def _cell(check: Dict[str, Any]) -> str:
    if check.get("status") != "ok":
        return "not run"
    ratio = "{:.3g}".format(check["capacity_ratio"])
    verdict = {True: "passes", False: "FAILS", None: "incomplete"}[check["passes"]]
    return f"{verdict} ({ratio})"


def check_lines(doc: Dict[str, Any]) -> List[str]:
    """One line per mechanism: linear and nonlinear verdicts (capacity/demand), notes."""
    lines: List[str] = []
    for row in doc.get("mechanisms") or []:
        lin, non = row["linear"], row["nonlinear"]
        line = "{}: linear {}, nonlinear {}".format(row["id"], _cell(lin), _cell(non))
        slc = non.get("SLC") if non.get("status") == "ok" else None
        if slc is not None and slc.get("passes") is not None:
            line += ", SLC {}".format(_cell(dict(slc, status="ok")))
        lines.append(line)
        for note in sorted({lin.get("note") or "", non.get("note") or ""} - {""}):
            lines.append(f"  note: {note}")
    if doc.get("governing"):
        lines.append("governing mechanism: {}".format(doc["governing"]))
    return lines


def run_check(cf: Any, site: Any, *, client: Optional[ServiceClient] = None) -> AnalysisResult:
    """Code checks of every mechanism of ``cf`` on ``site`` (``rockmech check``)."""
    if client is not None:
        payload = {
            "constants": json.loads(cf.model_dump_json(exclude_none=True)),
            "site": json.loads(site.model_dump_json(exclude_none=True)),
        }
        doc = client.post("check", payload)
    else:
        doc = check_document(cf, site).to_dict()
    return AnalysisResult("Check", doc, check_lines(doc))
