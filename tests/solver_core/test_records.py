"""Reading two-column records: every sample kept, bad files rejected with a reason."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from shared_schema.errors import InputError
from solver_service.core.model import G
from solver_service.core.records import GroundMotion


def test_el_centro_is_read_completely(elcentro_path: Path) -> None:
    raw = np.loadtxt(elcentro_path)
    motion = GroundMotion.from_two_column(elcentro_path, units="g")
    assert motion.accel.n == raw.shape[0] == 2688
    assert motion.dt == pytest.approx(0.02, rel=1e-12)
    np.testing.assert_array_equal(motion.accel.acc, raw[:, 1] * G)  # last line included
    assert motion.pga_g == pytest.approx(0.349, abs=5e-4)
    assert motion.metadata["units"] == "g" and motion.name == "elcentro_NS"


@pytest.mark.parametrize(("units", "factor"), [("m/s2", 1.0), ("cm/s2", 0.01)])
def test_units_are_converted_to_si(tmp_path: Path, units: str, factor: float) -> None:
    f = tmp_path / "r.txt"
    f.write_text("# t a\n0, 1.5\n0.1, -2.0\n0.2, 0.5\n")
    motion = GroundMotion.from_two_column(f, units=units)
    np.testing.assert_allclose(motion.accel.acc, np.array([1.5, -2.0, 0.5]) * factor)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("0 0.1\n0.02 nan\n0.04 0.2\n", "not finite"),
        ("0 0.1\n0.04 0.2\n0.02 0.3\n", "strictly increasing"),
        ("0 0.1\n0.02 0.2\n0.05 0.3\n", "not uniform"),
        ("0 0.1\n", "at least 2 samples"),
        ("", "at least 2 samples"),
        ("0 0.1 7\n0.02 0.2 7\n", "expected 2 columns"),
        ("0 0.1\n0.02 abc\n", "not a number"),
    ],
)
def test_bad_records_are_rejected_with_a_reason(tmp_path: Path, text: str, match: str) -> None:
    f = tmp_path / "bad.dat"
    f.write_text(text)
    with pytest.raises(InputError, match=match) as err:
        GroundMotion.from_two_column(f)
    assert err.value.field == "record"


def test_missing_file_and_unknown_units(tmp_path: Path, elcentro_path: Path) -> None:
    with pytest.raises(InputError, match="not found"):
        GroundMotion.from_two_column(tmp_path / "nope.dat")
    with pytest.raises(InputError, match="units"):
        GroundMotion.from_two_column(elcentro_path, units="furlongs")
