"""Pulse extraction: synthetic records with known pulses, and a brute-force reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shared_schema.errors import InputError
from solver_service.core.excitation import SampledAccel
from solver_service.core.model import G
from solver_service.core.pulses import extract_pulses, largest_pulse
from solver_service.core.records import GroundMotion


def _sine(t: np.ndarray, a_p: float, f_p: float, t0: float) -> np.ndarray:
    inside = (t >= t0 - 1e-9) & (t <= t0 + 1.0 / f_p + 1e-9)
    a = np.where(inside, a_p * np.sin(2 * math.pi * f_p * (t - t0)), 0.0)
    return np.where(np.abs(a) < 1e-9 * abs(a_p), 0.0, a)  # sin(k pi) rounds to ~1e-16


@pytest.mark.parametrize("a_p", [3.0, -3.0])
def test_embedded_pulse_is_recovered_with_sign_time_and_frequency(a_p: float) -> None:
    dt = 0.005
    t = np.arange(0.0, 20.0, dt)
    # A smaller, faster pulse and a background oscillation that never reaches 1 m/s².
    acc = (
        _sine(t, a_p, 0.8, 5.125)
        + _sine(t, 2.0, 4.0, 12.0)
        + 0.9 * np.sin(2 * math.pi * 7.3 * t) * (t > 14.0)
    )
    p = largest_pulse(SampledAccel(acc, dt))
    assert p.a_p == pytest.approx(a_p, rel=1 - math.cos(math.pi * 0.8 * dt) + 1e-12)
    assert np.sign(p.a_p) == np.sign(a_p)
    assert p.f_p == pytest.approx(0.8, rel=1e-9)
    assert p.t_start == pytest.approx(5.125, abs=1e-9)
    assert p.half_durations[0] == pytest.approx(p.half_durations[1], rel=1e-9)
    assert p.a_p_g == pytest.approx(p.a_p / G)
    # Ranking: the second one is the 4 Hz pulse.
    both = extract_pulses(SampledAccel(acc, dt), n=2)
    assert both[1].f_p == pytest.approx(4.0, rel=1e-2)
    assert both[1].a_p == pytest.approx(2.0, rel=1 - math.cos(math.pi * 4.0 * dt))


def test_frequency_range_selects_the_slower_pulse() -> None:
    dt = 0.002
    t = np.arange(0.0, 10.0, dt)
    acc = _sine(t, 1.0, 0.5, 1.0) + _sine(t, 4.0, 5.0, 6.0)
    assert largest_pulse(SampledAccel(acc, dt)).f_p == pytest.approx(5.0, rel=1e-2)
    slow = largest_pulse(SampledAccel(acc, dt), f_max=1.0)
    assert slow.f_p == pytest.approx(0.5, rel=1e-3)
    assert slow.a_p == pytest.approx(1.0, rel=1e-4)


def _brute_force(acc: np.ndarray, dt: float) -> tuple[float, float, float]:
    """Independent loop: walk the samples, build lobes, pair neighbours."""
    pieces = []  # [start, end, sign, peak] between sign changes
    start = None
    sign = 0.0
    peak = 0.0
    for i in range(1, len(acc)):
        s_prev, s_cur = np.sign(acc[i - 1]), np.sign(acc[i])
        if s_prev != s_cur:
            tc = (i - 1) * dt + dt * acc[i - 1] / (acc[i - 1] - acc[i])
            if start is not None:
                pieces.append([start, tc, sign, peak])
            start, sign, peak = tc, s_cur, 0.0
        peak = max(peak, abs(acc[i]))
    lobes: list[list[float]] = []
    for piece in pieces:
        if piece[2] == 0 and piece[1] == piece[0]:
            continue  # a zero the record only passes through
        if lobes and lobes[-1][2] == piece[2]:
            lobes[-1][1] = piece[1]
            lobes[-1][3] = max(lobes[-1][3], piece[3])
        else:
            lobes.append(piece)
    best = (0.0, 0.0, 0.0)
    for (s1, e1, g1, p1), (s2, e2, g2, p2) in zip(lobes, lobes[1:]):
        if g1 * g2 >= 0 or e1 != s2:
            continue
        amp = min(p1, p2)
        if amp > abs(best[0]):
            best = (g1 * amp, 1.0 / (e2 - s1), s1)
    return best


def test_el_centro_matches_a_brute_force_walk(elcentro_path) -> None:
    motion = GroundMotion.from_file(elcentro_path, units="g")
    acc = motion.accel.acc
    p = largest_pulse(motion.accel)
    a_ref, f_ref, t_ref = _brute_force(acc, motion.dt)
    assert p.a_p == pytest.approx(a_ref, rel=1e-14)
    assert p.f_p == pytest.approx(f_ref, rel=1e-12)
    assert p.t_start == pytest.approx(t_ref, rel=1e-12)
    # Contained: both half-cycles reach |a_p|, which cannot exceed the PGA.
    assert min(p.peaks) == pytest.approx(abs(p.a_p))
    assert abs(p.a_p) <= motion.pga


def test_zero_padding_and_touching_zeros() -> None:
    dt = 0.01
    acc = np.array([0, 0, 1, 2, 1, 0, 1, 0, -1, -2, -1, 0, 0, 0], dtype=float)
    # + lobe touching zero at index 5 is one lobe; the - lobe follows; zeros pad both ends.
    p = largest_pulse(SampledAccel(acc, dt))
    assert p.a_p == 2.0
    assert p.t_start == pytest.approx(0.01)
    assert p.half_durations == pytest.approx((0.06, 0.04))
    assert p.f_p == pytest.approx(10.0)


@pytest.mark.parametrize("acc", [[0.1, 0.0, -0.1], [0.0, 0.1, 0.0, -0.1]])
def test_one_crossing_through_a_zero_sample_holds_no_cycle(acc: list[float]) -> None:
    # issue #19: the crossing's lobe had zero length and was dropped, leaving nothing to
    # group: an IndexError (a 500 from /assess), not the record's own message.
    accel = SampledAccel(np.array(acc), 0.01)
    assert extract_pulses(accel) == []
    with pytest.raises(InputError, match="no complete acceleration cycle") as err:
        largest_pulse(accel)
    assert err.value.field == "record"


def test_bad_input() -> None:
    acc = SampledAccel(np.sin(np.linspace(0, 20, 500)), 0.01)
    with pytest.raises(InputError, match="f_min"):
        extract_pulses(acc, f_min=-1.0)
    with pytest.raises(InputError, match="f_min"):
        extract_pulses(acc, f_min=3.0, f_max=1.0)
    with pytest.raises(InputError, match="n"):
        extract_pulses(acc, n=0)
    with pytest.raises(InputError, match="no complete acceleration cycle"):
        largest_pulse(SampledAccel(np.ones(10), 0.1))
    with pytest.raises(InputError, match="record"):
        largest_pulse(acc, f_min=50.0)
