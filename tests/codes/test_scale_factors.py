"""Scale factors of Eq. 28, EN 1998-1 §4.3.5.2 and NZS 1170.5 §8.3 (theory §7.3–7.4)."""

from __future__ import annotations

import pytest

from shared_schema.errors import InputError
from solver_service.codes.scale_factors import sf_ec8, sf_eq28, sf_nzs


@pytest.mark.parametrize(("pga_g", "expected"), [(0.155, 1.595), (0.158, 1.576)])
def test_eq28_reproduces_basantapur_check(pga_g: float, expected: float) -> None:
    # theory §7.3: S_a = 0.19 g, h = 4.60 m, h_e = 4.54 m.
    out = sf_eq28(0.19, pga_g, 4.60, 4.54)
    assert round(out["value"], 3) == expected
    assert out["inputs"] == {"sa_g": 0.19, "pga_g": pga_g, "h": 4.60, "h_e": 4.54}
    assert "sqrt" in out["formula"] and "Eq. 28" in out["method"]


def test_nzs_floor_coefficient_for_basantapur_is_1_77() -> None:
    out = sf_nzs(4.6, 4.6)
    assert round(out["value"], 2) == 1.77
    assert out["formula"].startswith("C_Hi = 1 + h_i/6")
    assert out["inputs"] == {"h_i": 4.6, "h_n": 4.6}


@pytest.mark.parametrize(
    ("h_i", "h_n", "expected"),
    [
        (1.0, 50.0, 1.0 + 1.0 / 6.0),  # both low-height rules apply: 1.167 < 1.2
        (6.0, 100.0, 1.6),  # 1 + 10*6/100 = 1.6 < 1 + 6/6 = 2
        (11.0, 11.0, 1.0 + 11.0 / 6.0),  # only h_i < 12 m applies
        (12.0, 30.0, 3.0),  # neither applies
        (20.0, 200.0, 2.0),  # only h_i < 0.2 h_n applies
        (0.0, 10.0, 1.0),
    ],
)
def test_nzs_takes_the_lesser_of_the_applicable_values(
    h_i: float, h_n: float, expected: float
) -> None:
    assert sf_nzs(h_i, h_n)["value"] == pytest.approx(expected, rel=1e-15)


@pytest.mark.parametrize(
    ("T_a", "T_1", "S", "expected"),
    [(0.0, 0.5, 1.0, 2.5), (0.0, 0.5, 1.15, 2.875), (0.125, 1.0, 1.0, 2.898)],
)
def test_ec8_top_of_building_values_of_theory_7_4(
    T_a: float, T_1: float, S: float, expected: float
) -> None:
    # theory §7.4 quotes the last as 2.90 (two decimals): 6/1.765625 - 0.5 = 2.8982.
    out = sf_ec8(z=8.0, H=8.0, T_a=T_a, T_1=T_1, S=S)
    assert round(out["value"], 3) == expected
    assert out["inputs"]["S"] == S and out["inputs"]["z"] == 8.0
    assert "3(1 + z/H)" in out["formula"]


def test_ec8_never_below_the_ground_acceleration() -> None:
    # At the base with a very flexible element (T_a >> T_1) the bracket falls below 1:
    # it is floored to 1, so the value is S.
    out = sf_ec8(z=0.0, H=10.0, T_a=10.0, T_1=0.5, S=1.2)
    assert out["inputs"]["bracket"] < 1.0
    assert out["value"] == pytest.approx(1.2)


@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda: sf_eq28(0.19, 0.155, 4.6, 0.0), "h_e"),
        (lambda: sf_eq28(0.19, 0.155, -1.0, 4.5), "h"),
        (lambda: sf_eq28(0.19, 0.0, 4.6, 4.5), "pga_g"),
        (lambda: sf_ec8(1.0, 0.0, 0.1, 0.5), "H"),
        (lambda: sf_ec8(1.0, 5.0, 0.1, 0.0), "T_1"),
        (lambda: sf_ec8(1.0, 5.0, -0.1, 0.5), "T_a"),
        (lambda: sf_ec8(-1.0, 5.0, 0.1, 0.5), "z"),
        (lambda: sf_ec8(1.0, 5.0, 0.1, 0.5, S=0.0), "S"),
        (lambda: sf_nzs(-1.0, 5.0), "h_i"),
        (lambda: sf_nzs(1.0, 0.0), "h_n"),
        (lambda: sf_nzs(float("nan"), 5.0), "h_i"),
    ],
)
def test_invalid_inputs_name_the_field(call: object, field: str) -> None:
    with pytest.raises(InputError) as info:
        call()  # type: ignore[operator]
    assert info.value.field == field


def test_booleans_are_not_numbers() -> None:
    with pytest.raises(InputError, match="h_i"):
        sf_nzs(True, 10.0)  # type: ignore[arg-type]


def test_ec8_extreme_period_ratio_is_finite() -> None:
    # (1 - T_a/T_1)^2 overflows a float: the bracket goes to -0.5 and the floor 1 holds.
    info = sf_ec8(5.0, 10.0, 1e300, 1e-10)
    assert info["value"] == 1.0 and info["inputs"]["bracket"] == -0.5
