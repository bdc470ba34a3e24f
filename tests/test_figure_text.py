"""Every figure rockmech draws shows its text as meant (#27).

Each entry point that draws (envelope, history, record, IDA, the HTML report, the
assessment report, the demo) runs with a mechanism id and a record name that hold ``$`` and
nested braces. Every figure saved is read back, text by text, as matplotlib draws it:

* log-axis tick labels are mathtext (``$\\mathdefault{10^{0}}$`` drawn as 10⁰), never shown
  raw; no text shows ``\\mathdefault`` or an escape (``\\$``);
* user text is never read as mathtext, and a ``$`` shows only where the user wrote one.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import matplotlib
import pytest
from matplotlib import cbook
from matplotlib.figure import Figure
from matplotlib.text import Text

from shared_schema.constants import ConstantsFile
from solver_service.demo import run_demo
from solver_service.workflows.assess import read_site
from solver_service.workflows.documents import frequency_grid, record_analysis, record_pulse_doc
from solver_service.workflows.ida import run_ida
from solver_service.workflows.inputs import read_record
from solver_service.workflows.outputs import write_envelope, write_history, write_ida, write_record
from solver_service.workflows.pages import assess_report, build_report

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
#: A "$" pair around nested braces: mathtext, and a parser that recursed without bound.
USER_ID = "W$" + "{" * 8 + "}" * 8 + "$"
RECORD_NAME = "el$centro{}$"


def _dollar_ids(path: Path) -> ConstantsFile:
    """The constants file with its first mechanism renamed to ``USER_ID``."""
    data = json.loads(path.read_text())
    data["mechanisms"][0]["id"] = USER_ID
    return ConstantsFile.model_validate(data)


def _tick_texts(fig: Figure) -> set[int]:
    found: set[int] = set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                found.update((id(tick.label1), id(tick.label2)))
            found.add(id(axis.offsetText))
    return found


class Figures:
    """Every figure saved while installed: its texts as drawn, and its log axes."""

    def __init__(self) -> None:
        self.texts: list[tuple[str, bool, bool]] = []  # (shown, is mathtext, is a tick)
        self.log_axes: list[list[tuple[str, bool]]] = []
        self.count = 0

    def read(self, fig: Figure) -> None:
        self.count += 1
        ticks = _tick_texts(fig)
        for text in fig.findobj(Text):
            raw = text.get_text()
            if not raw or not text.get_visible():
                continue
            math = bool(text.get_parse_math()) and cbook.is_math_text(raw)
            shown = raw if math else raw.replace(r"\$", "$")
            self.texts.append((shown, math, id(text) in ticks))
        for ax in fig.axes:
            for axis, scale in ((ax.xaxis, ax.get_xscale()), (ax.yaxis, ax.get_yscale())):
                if scale == "log":
                    labels = [t for t in axis.get_ticklabels() if t.get_text()]
                    self.log_axes.append([(t.get_text(), bool(t.get_parse_math())) for t in labels])


@pytest.fixture
def figures(monkeypatch: pytest.MonkeyPatch) -> Figures:
    seen = Figures()
    savefig = Figure.savefig

    def spy(self: Figure, *args: Any, **kwargs: Any) -> Any:
        out = savefig(self, *args, **kwargs)  # draws the figure: every tick label exists
        seen.read(self)
        return out

    monkeypatch.setattr(Figure, "savefig", spy)
    return seen


def _draw_everything(tmp: Path) -> None:
    record = tmp / f"{RECORD_NAME}.dat"
    shutil.copy(EXAMPLES / "records" / "elcentro_NS.dat", record)
    motion = read_record(record, None, "g")
    walls = _dollar_ids(EXAMPLES / "constants" / "rect_walls.json")
    f_p = frequency_grid(0.1, 10.0, 40)
    pulse = record_pulse_doc(walls, motion, [1.0, 2.0])
    write_envelope(walls, f_p, tmp / "envelope", title=USER_ID, record_pulse=pulse)
    write_history(walls, motion, [1.0, 2.0], tmp / "history", title=USER_ID)
    doc, spectrum, pulses = record_analysis(motion, frequency_grid(0.1, 10.0, 30))
    write_record(motion, doc, spectrum, pulses, tmp / "record")
    ida = run_ida(walls, [motion], [0.5, 1.0, 2.0], jobs=1)
    write_ida(ida, tmp / "ida", title=USER_ID)
    build_report(walls, f_p, motion=motion, scales=[1.0, 2.0], title=USER_ID)
    church = _dollar_ids(EXAMPLES / "constants" / "church_geometry.json")
    site = read_site(EXAMPLES / "sites" / "ntc_site.json")
    assess_report(church, site, [motion], multiples=[1.0])
    run_demo(tmp / "demo")


@pytest.mark.slow
def test_every_figure_shows_its_labels_as_meant(tmp_path: Path, figures: Figures) -> None:
    _draw_everything(tmp_path)
    assert figures.count >= 12, figures.count
    for shown, math, tick in figures.texts:
        # Only the formatters' tick labels are mathtext; user text never is.
        assert tick or not math, shown
        if math:
            continue
        assert r"\mathdefault" not in shown and r"\$" not in shown, shown
        assert "$" not in shown.replace(USER_ID, "").replace(RECORD_NAME, ""), shown
    assert any(USER_ID in shown for shown, _, _ in figures.texts)
    assert any(RECORD_NAME in shown for shown, _, _ in figures.texts)
    # Every log axis labels its decades as mathtext (10⁰, 10¹), drawn, not shown raw.
    assert len(figures.log_axes) >= 6
    for labels in figures.log_axes:
        decades = [text for text, parsed in labels if r"\mathdefault{10^" in text]
        assert decades, labels
        assert all(parsed for text, parsed in labels if "$" in text), labels


def test_matplotlib_keeps_mathtext_on() -> None:
    """Drawing does not switch mathtext off for everyone (it was a global rcParams change)."""
    from solver_service.report.plots import load_pyplot

    load_pyplot()
    assert matplotlib.rcParams["text.parse_math"] is True
