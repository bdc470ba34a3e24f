"""A report whose time-history figure cannot be made says so in the page, without a traceback.

The figures rerun the mechanisms with their time series after the tables are made, so a run
can fail there alone (issue #14). The failure is injected into the run the figure makes (the
tables' runs are left alone), and the page must carry the reason where the figure would be.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from shared_schema.errors import SolverError
from solver_service.core.records import GroundMotion
from solver_service.workflows import pages
from solver_service.workflows.assess import read_site
from solver_service.workflows.documents import frequency_grid
from solver_service.workflows.inputs import read_constants
from solver_service.workflows.pages import build_report
from solver_service.workflows.scaling import Building

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
REASON = "the step size fell below its floor"


def _fail(*args: Any, **kwargs: Any) -> Any:
    raise SolverError(REASON)


@pytest.fixture(scope="module")
def motion() -> GroundMotion:
    return GroundMotion.from_two_column(EXAMPLES / "records" / "elcentro_NS.dat", units="g")


def test_a_failing_history_figure_becomes_a_note(
    motion: GroundMotion, monkeypatch: pytest.MonkeyPatch
) -> None:
    cf = read_constants(EXAMPLES / "constants" / "rect_walls.json")
    monkeypatch.setattr(pages, "dense_runs", _fail)
    page = build_report(
        cf,
        frequency_grid(0.5, 5.0, 5),
        motion=motion,
        scales=[0.5, 1.0],
        history={"sf": "none", "building": Building()},
        method="exact",
    )
    assert f"at scale 1: not drawn ({REASON})" in page
    assert "<h2>Time histories</h2>" in page  # the table is still there


def test_a_failing_assessment_history_becomes_a_note(
    motion: GroundMotion, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("jinja2", reason="the assess page needs the report extra (jinja2)")
    cf = read_constants(EXAMPLES / "constants" / "church_geometry.json")
    site = read_site(EXAMPLES / "sites" / "ntc_site.json")
    monkeypatch.setattr(pages, "simulate", _fail)
    doc, page = pages.assess_report(cf, site, [motion], multiples=[1.0])
    assert any(m.get("dynamics") for m in doc["mechanisms"])  # the tables' runs were made
    assert f"not drawn: {REASON}" in page
