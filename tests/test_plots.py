"""Plots are drawn for degenerate inputs too (a report must never fail on a plot)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

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
    out = plot_envelopes(envs, doc["critical"], tmp_path / "e.png")
    assert out.read_bytes()[:8] == PNG
