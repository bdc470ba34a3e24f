"""Plots are drawn for degenerate inputs too (a report must never fail on a plot)."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from shared_schema.constants import ConstantsFile
from solver_service.report.plots import plot_envelopes
from solver_service.workflows.documents import envelope_doc

PNG = b"\x89PNG\r\n\x1a\n"


def test_envelope_plot_of_degenerate_constants(tmp_path: Path) -> None:
    cf = ConstantsFile.model_validate(
        {"mechanisms": [{"id": "X", "p_eq": 5e-324, "lam": 5e-324, "eta": 0.9}]}
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # omega_p/p_eq overflows to inf
        doc, envs = envelope_doc(cf, np.geomspace(0.1, 10.0, 12))
    assert not any(np.isfinite(v) and v > 0 for v in envs[0].a_p_min_g)
    out = plot_envelopes(envs, [b.to_dict() for b in doc.critical], tmp_path / "e.png")
    assert out.read_bytes()[:8] == PNG


def _x_span(patch: Any) -> tuple[float, float]:
    """Data x-extent of an ``axvspan`` (a Rectangle, or a Polygon in older matplotlib)."""
    if hasattr(patch, "get_width"):
        return patch.get_x(), patch.get_x() + patch.get_width()
    xs = [x for x, _ in patch.get_xy()]
    return min(xs), max(xs)


def test_envelope_plot_draws_where_each_band_edge_lies(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each edge between two critical bands is hatched over the interval that holds it."""
    from matplotlib.figure import Figure
    from matplotlib.patches import Polygon, Rectangle

    from shared_schema.io import read_constants
    from solver_service.workflows.documents import frequency_grid
    from solver_service.workflows.outputs import write_envelope

    seen: list[Figure] = []
    savefig = Figure.savefig

    def spy(self: Figure, *args: Any, **kwargs: Any) -> Any:
        seen.append(self)
        return savefig(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", spy)
    cf = read_constants(Path(__file__).resolve().parents[1] / "examples/constants/church.json")
    for method, label in (("exact", "between two grid frequencies"), ("library", "×1.05")):
        seen.clear()
        doc = write_envelope(
            cf, frequency_grid(0.1, 10.0, 60), tmp_path / method, method=method
        ).to_dict()
        assert len(doc["critical_edges"]) == len(doc["critical"]) - 1 >= 2
        (fig,) = seen
        ax = fig.axes[0]
        hatched = [p for p in ax.patches if isinstance(p, (Polygon, Rectangle)) and p.get_hatch()]
        spans = sorted(_x_span(p) for p in hatched)
        want = sorted((e["f_low"], e["f_high"]) for e in doc["critical_edges"])
        assert np.allclose(spans, want, rtol=1e-12), (spans, want)
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any("band edge" in t and label in t for t in texts), texts
