"""The linearisation error map and the warnings built on it (issue 7, part 4).

The shipped table (``solver_service/data/linearisation_map.npz``) is written by
``benchmarks/linearisation_map.py``; these tests recompute points of it with the solvers,
check its trends against the uplift-threshold argument of theory §8.5, and check that the
API and the CLI warn where the linear model is off by more than 10 %.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import linearisation_map

from solver_service.cli import app
from solver_service.core.exact import simulate
from solver_service.core.excitation import Pulse
from solver_service.core.model import G, RockingModel
from solver_service.core.nonlinear import (
    LINEARISATION_MAP_PATH,
    WARN_LINEARISATION,
    linearisation_estimate,
    linearisation_warnings,
)

pytestmark = pytest.mark.skipif(
    not LINEARISATION_MAP_PATH.exists(), reason="run benchmarks/linearisation_map.py first"
)


def _table() -> dict[str, np.ndarray]:
    with np.load(LINEARISATION_MAP_PATH) as data:
        return {k: np.asarray(data[k]) for k in data.files}


@pytest.mark.parametrize(("alpha", "omega"), [(0.6, 1.0), (0.2, 8.0)])
def test_shipped_map_reproduces_a_fresh_measurement(alpha: float, omega: float) -> None:
    tab = _table()
    i = int(np.flatnonzero(np.isclose(tab["alpha"], alpha))[0])
    j = int(np.flatnonzero(np.isclose(tab["omega"], omega))[0])
    a_lin, a_nl = linearisation_map.amplitude_point(alpha, omega)
    assert tab["amplitude_error_signed"][i, j] == pytest.approx(a_lin / a_nl - 1.0, abs=1e-3)


def test_slender_blocks_are_linear_and_stocky_ones_are_not() -> None:
    tab = _table()
    err = np.abs(tab["amplitude_error"])
    assert np.all(err[tab["alpha"] <= 0.03] < 0.01)
    assert np.all(err[tab["alpha"] >= 1.0] > WARN_LINEARISATION)
    # At low Omega the error is the uplift-threshold mismatch: the linear model uplifts at
    # g alpha, the block at g tan(alpha) (theory §8.5), so a_lin/a_nl ~ alpha/tan(alpha).
    j = 0
    for i, alpha in enumerate(tab["alpha"]):
        ratio = alpha / math.tan(alpha)
        assert tab["amplitude_error_signed"][i, j] == pytest.approx(ratio - 1.0, abs=0.05)


def test_estimate_errs_high_between_grid_points() -> None:
    tab = _table()
    # Between two alphas of the grid the estimate is at least both neighbours' errors.
    a0, a1 = tab["alpha"][5], tab["alpha"][6]
    j = 3
    mid = math.sqrt(a0 * a1)
    assert linearisation_estimate(mid, tab["omega"][j]) >= max(
        tab["amplitude_error"][5, j], tab["amplitude_error"][6, j]
    )
    assert math.isfinite(linearisation_estimate(0.3))  # records: no Omega


def test_record_estimate_is_the_median_over_the_maps_p() -> None:
    # At a node alpha_i of the grid the record estimate is the larger of the medians (over
    # the map's p) of rows i-1 and i, missing values counting as infinite.
    tab = _table()
    median = np.median(np.nan_to_num(tab["record_error"], nan=np.inf), axis=1)
    for i, alpha in enumerate(tab["alpha"]):
        expected = max(median[max(i - 1, 0)], median[i])
        assert linearisation_estimate(float(alpha)) == expected


def test_warnings_name_the_case_and_are_silent_for_slender_mechanisms() -> None:
    stocky = RockingModel.symmetric(2.0, 0.9, 0.3)
    notes = linearisation_warnings(stocky, omega_p=2.0)
    assert len(notes) == 1 and "lam = 0.9" in notes[0] and "%" in notes[0]
    assert linearisation_warnings(RockingModel.symmetric(2.0, 0.02, 0.95), omega_p=2.0) == []
    # Asymmetric: the stocky side decides.
    from solver_service.core.model import RockingSide

    asym = RockingModel(RockingSide(2.0, 0.02), RockingSide(2.0, 0.9), eta=0.5)
    assert linearisation_warnings(asym, omega_p=2.0)
    # One-sided: only the positive side rocks.
    one = RockingModel(RockingSide(2.0, 0.02), RockingSide(2.0, 0.9), eta=-0.5, one_sided=True)
    assert linearisation_warnings(one, omega_p=2.0) == []


def test_simulate_and_the_cli_warn_for_a_stocky_mechanism() -> None:
    model = RockingModel.symmetric(2.0, 0.9, 0.3)
    res = simulate(model, Pulse(a_p=-1.5 * G, f_p=1.0))
    assert any("linearised model may be off" in w for w in res.warnings)
    runner = CliRunner()
    args = ["pulse", "--p-eq", "2", "--lam", "0.9", "--eta", "0.3", "--a-p-g", "-1.5"]
    out = runner.invoke(app, [*args, "--f-p", "1"])
    assert out.exit_code == 0
    assert "warning: The linearised model may be off" in out.stderr
    doc = json.loads(runner.invoke(app, [*args, "--f-p", "1", "--json"]).stdout)
    assert any("linearised" in w for w in doc["warnings"])
    calm = runner.invoke(
        app,
        ["pulse", "--p-eq", "2", "--lam", "0.05", "--eta", "0.9", "--a-p-g", "-0.1", "--f-p", "1"],
    )
    assert calm.exit_code == 0 and "warning" not in calm.stderr
