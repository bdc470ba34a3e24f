"""The rates of the up-front work estimates are the ones the benchmark recorded.

``benchmarks/work_rates.py`` measures each rate and writes its table to the ``work_rates``
section of ``docs/benchmarks.md``; ``solver_service.workflows.limits`` holds them to two
significant digits. Rerunning the benchmark on another machine changes the table, and this
test then asks for the constants (and docs/service.md) to follow.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from solver_service.core.spectra import STEPS_PER_PERIOD
from solver_service.workflows import limits

REPO = Path(__file__).resolve().parents[2]
BENCHMARKS = REPO / "docs" / "benchmarks.md"
SERVICE = REPO / "docs" / "service.md"
#: The constants of ``workflows.limits`` the benchmark's table names.
CONSTANTS = {
    "ENVELOPE_STEPS_PER_CORE_S",
    "PULSE_POINTS_PER_CORE_S",
    "HISTORY_STEPS_PER_CORE_S",
    "SPECTRUM_STEPS_PER_CORE_S",
    "FIGURES_PER_S",
}


def _recorded() -> tuple[dict[str, float], str]:
    """(measured rate by constant name, the section's text) of ``docs/benchmarks.md``."""
    text = BENCHMARKS.read_text(encoding="utf-8")
    section = text.split("<!-- BEGIN work_rates -->", 1)[1].split("<!-- END work_rates -->")[0]
    rates = {}
    for line in section.splitlines():
        match = re.search(r"\| ([0-9.e+-]+) /s[^|]*\| `([A-Z_]+)` \|$", line)
        if match:
            rates[match.group(2)] = float(match.group(1))
    return rates, section


def test_every_rate_constant_is_the_rate_the_benchmark_recorded() -> None:
    rates, section = _recorded()
    assert set(rates) == CONSTANTS
    for name, measured in rates.items():
        constant = getattr(limits, name)
        # Two significant digits of the measured rate.
        assert float(f"{measured:.2g}") == constant, (name, measured, constant)
    assert f"`RATE_MARGIN` = {limits.RATE_MARGIN:g} times" in section


def test_the_service_docs_state_the_calibration() -> None:
    text = SERVICE.read_text(encoding="utf-8")
    for name in CONSTANTS:
        assert f"`{name}`" in text, name
    assert f"`RATE_MARGIN` = {limits.RATE_MARGIN:g}" in text
    assert "benchmarks/work_rates.py" in text


def test_the_copies_of_solver_constants_agree() -> None:
    assert limits.SPECTRUM_SUBSTEPS == STEPS_PER_PERIOD


def test_the_least_time_is_the_work_at_the_margin_on_every_core() -> None:
    cores = limits.cores()
    one = limits.shortest_time(envelope_steps=limits.ENVELOPE_STEPS_PER_CORE_S)
    assert math.isclose(one, 1.0 / (limits.RATE_MARGIN * cores))
    figures = limits.shortest_time(figures=limits.FIGURES_PER_S)
    assert math.isclose(figures, 1.0 / limits.RATE_MARGIN)  # drawn on one thread
    both = limits.shortest_time(
        history_steps=limits.HISTORY_STEPS_PER_CORE_S,
        spectrum_steps=limits.SPECTRUM_STEPS_PER_CORE_S,
        pulse_points=limits.PULSE_POINTS_PER_CORE_S,
    )
    assert math.isclose(both, 3.0 / (limits.RATE_MARGIN * cores))
    assert limits.work_words(envelope_steps=3.75e8, pulse_points=2.2e7) == (
        "3.75e+08 closed-form steps of exact envelopes and 2.2e+07 grid points of pulse spectra"
    )
