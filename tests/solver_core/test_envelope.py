"""Overturning boundaries, the library, envelopes and the critical mechanism (theory §6-§7)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from shared_schema.constants import parse_constants
from shared_schema.errors import InputError
from solver_service.core import _boundary_kernels as _bk
from solver_service.core.amplification import pulse_scale_factor
from solver_service.core.envelope import (
    A_MAX,
    LIBRARY_ETA_STEP,
    MAX_EDGES,
    N_SCAN,
    RTOL,
    V_REST_BOUNDARY,
    Envelope,
    OverturningLibrary,
    _scan,
    boundary_curve,
    build_library,
    critical_bands,
    governing_one_sided,
    mechanism_envelope,
)
from solver_service.core.exact import simulate
from solver_service.core.excitation import Pulse
from solver_service.core.model import G, RockingModel
from solver_service.core.reference import simulate_ivp
from solver_service.workflows.documents import envelope_doc, frequency_grid

OMEGA = np.array([0.25, 0.5, 1, 2, 3, 4, 5, 6, 8, 10], dtype=float)
# theory §6.5, minimum overturning A = a_p/(g lam) (3 decimals printed).
TABLE = {
    0.7: [1.029, 1.076, 1.142, 1.256, 1.552, 5.239, 7.168, 9.417, 14.871, 21.600],
    0.8: [1.028, 1.071, 1.137, 1.239, 1.457, 2.398, 7.168, 9.417, 14.871, 21.600],
    0.9: [1.026, 1.054, 1.132, 1.225, 1.404, 1.795, 3.019, 5.164, 14.871, 21.600],
    0.96: [1.018, 1.040, 1.099, 1.218, 1.380, 1.695, 2.441, 3.906, 8.160, 14.669],
    1.0: [1.009, 1.034, 1.094, 1.214, 1.367, 1.648, 2.221, 3.417, 6.871, 11.600],
}
ONE_SIDED = [1.031, 1.109, 1.322, 1.801, 2.294, 2.791, 3.289, 3.788, 4.787, 5.787]
# Entries at Omega <= 0.5 where the printed table is 0.1-0.5 % above the boundary that both
# the exact integrator and solve_ivp (rtol 1e-12) find; see test_low_omega_entries_...
LOW_OMEGA_DISAGREEMENTS = {(0.7, 0.5), (0.8, 0.5), (0.9, 0.25), (1.0, 0.5)}


def closed_form(omega: float, case: str) -> float:
    """Mode-2 (no impact) overturning amplitude, theory §6.3 (a) and (b)."""
    sign, span = (1.0, 2 * math.pi) if case == "a" else (-1.0, math.pi)

    def f(psi: float) -> float:
        return omega * math.sin(psi) - math.cos(psi) + sign * math.exp(-(span - psi) / omega)

    return 1.0 / math.sin(brentq(f, 1e-12, math.pi / 2, xtol=1e-15))


@pytest.fixture(scope="module")
def library() -> OverturningLibrary:
    return OverturningLibrary.load()


# --- Exact boundaries -------------------------------------------------------------------------


def test_zhang_makris_overturning_intervals() -> None:
    (lo1, hi1), (lo2, hi2) = boundary_curve([5.0], 0.9).intervals(0)
    assert lo1 == pytest.approx(3.0186, abs=0.5e-4)
    assert hi1 == pytest.approx(6.3181, abs=0.5e-4)
    assert lo2 == pytest.approx(7.1681, abs=0.5e-4)
    assert hi2 is None


@pytest.mark.parametrize("eta", sorted(TABLE))
def test_two_sided_minimum_amplitudes_match_theory_table(eta: float) -> None:
    a_min = boundary_curve(OMEGA, eta).a_min
    for omega, got, printed in zip(OMEGA, a_min, TABLE[eta]):
        if (eta, omega) in LOW_OMEGA_DISAGREEMENTS:
            continue
        assert got == pytest.approx(printed, abs=6e-4), (eta, omega)


def test_one_sided_curve_matches_theory_table_and_closed_form_b() -> None:
    _, neg, a_min, direction = governing_one_sided(OMEGA)
    np.testing.assert_allclose(a_min, ONE_SIDED, atol=6e-4)
    assert np.all(direction == 1)  # the pulse that first pushes against the restraint governs
    for omega, got in zip(OMEGA, a_min):
        assert got == pytest.approx(closed_form(omega, "b"), rel=2e-6)
    # Opening first with no rebound: no-impact closed form (a).
    for omega, got in zip(OMEGA, neg.a_min):
        assert got == pytest.approx(closed_form(omega, "a"), rel=2e-6)


@pytest.mark.parametrize("omega", [5.0, 6.0, 8.0, 10.0])
def test_without_mode_1_the_two_sided_curve_is_closed_form_a(omega: float) -> None:
    assert boundary_curve([omega], 0.7).a_min[0] == pytest.approx(closed_form(omega, "a"), rel=2e-6)


@pytest.mark.parametrize(("eta", "omega"), sorted(LOW_OMEGA_DISAGREEMENTS))
def test_low_omega_entries_are_confirmed_by_an_independent_integrator(
    eta: float, omega: float
) -> None:
    """The printed table is 0.1-0.5 % high here; solve_ivp (rtol 1e-12) sides with us."""
    a_min = boundary_curve([omega], eta).a_min[0]
    model = RockingModel.symmetric(1.0, 1.0 / G, eta)
    for factor, expected in [(1 - 1e-4, False), (1 + 1e-4, True)]:
        pulse = Pulse(a_p=-a_min * factor, f_p=omega / (2 * math.pi))
        ref = simulate_ivp(model, pulse, rtol=1e-12, atol=1e-14)
        if factor < 1 and ref.collapsed:
            # Close to the threshold the outcome alternates on 1e-4 scales (theory §10): the
            # scan resolves the first edge only to its step; the edge itself must be real.
            continue
        assert ref.collapsed is expected
    printed = TABLE[eta][list(OMEGA).index(omega)]
    assert a_min < printed


def test_boundary_reports_its_resolution_and_validates_input() -> None:
    curve = boundary_curve([2.0], 0.9)
    assert 1.0 < curve.scan_ratio < 1.02 and curve.rtol == 1e-6 and curve.a_max == 200.0
    with pytest.raises(InputError, match="eta"):
        boundary_curve([2.0], 1.2)
    with pytest.raises(InputError, match="eta"):
        boundary_curve([2.0], 0.5, one_sided=True)
    with pytest.raises(InputError, match="omega"):
        boundary_curve([0.0], 0.9)


# --- Library ----------------------------------------------------------------------------------


def test_library_grid_and_metadata(library: OverturningLibrary) -> None:
    assert library.omega.size >= 400
    assert library.omega[0] <= 0.05 and library.omega[-1] >= 50.0
    assert library.eta[0] == 0.0 and library.eta[-1] == 1.0
    assert np.max(np.diff(library.eta)) <= LIBRARY_ETA_STEP + 1e-12
    meta = library.metadata
    assert {"library_version", "generated", "scan_ratio", "rtol", "a_max"} <= set(meta)


def test_rebuilding_a_sample_reproduces_the_stored_library(library: OverturningLibrary) -> None:
    idx = np.arange(0, library.omega.size, 37)
    for j in (0, 20, 45, library.eta.size - 1):
        fresh = boundary_curve(library.omega[idx], float(library.eta[j])).a_min
        np.testing.assert_allclose(fresh, library.a_min_two_sided[j, idx], rtol=1e-12)
    fresh_one = governing_one_sided(library.omega[idx])[2]
    np.testing.assert_allclose(fresh_one, library.a_min_one_sided[idx], rtol=1e-12)


@pytest.mark.parametrize("etas", [(0.0, 0.4, 0.9, 1.0), (0.3, 0.96)])
def test_build_library_is_boundary_curve_bit_for_bit(
    library: OverturningLibrary, etas: tuple[float, ...]
) -> None:
    # The library's parallel search skips the scan points that the eta = 0 probe shows to
    # overturn whatever eta; every curve must still be boundary_curve's, to the bit, and the
    # shipped library's rows (with or without eta = 0 in the grid).
    idx = np.arange(3, library.omega.size, 23)
    om = library.omega[idx]
    ticks: list[tuple[int, int]] = []
    built = build_library(omega=om, eta=etas, progress=lambda d, n: ticks.append((d, n)))
    assert ticks[-1] == (len(etas) + 2, len(etas) + 2)
    assert [d for d, _ in ticks] == sorted(d for d, _ in ticks)
    direct = [boundary_curve(om, e) for e in etas]
    pos, neg, a_one, direction = governing_one_sided(om)
    offsets = built.edges_offsets
    for k, curve in enumerate([*direct, pos, neg]):
        for i in range(om.size):
            row = k * om.size + i
            got = built.edges_flat[offsets[row] : offsets[row + 1]]
            want = curve.edges[i, : curve.n_edges[i]]
            np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(built.a_min_two_sided, np.stack([c.a_min for c in direct]))
    np.testing.assert_array_equal(built.a_min_one_sided, a_one)
    np.testing.assert_array_equal(built.direction_one_sided, direction)
    for k, eta in enumerate(etas):
        j = int(np.argmin(np.abs(library.eta - eta)))
        np.testing.assert_array_equal(built.a_min_two_sided[k], library.a_min_two_sided[j, idx])
    np.testing.assert_array_equal(built.a_min_one_sided, library.a_min_one_sided[idx])


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"eta": []}, "eta"),
        ({"eta": [0.5, 1.2]}, "eta"),
        ({"omega": [0.5, -1.0]}, "omega"),
        ({"omega": []}, "omega"),
        ({"shape": "square"}, "shape"),
    ],
)
def test_build_library_refuses_bad_grids_naming_the_field(
    kwargs: dict[str, object], field: str
) -> None:
    with pytest.raises(InputError) as err:
        build_library(**{"omega": [1.0, 2.0], "eta": [0.5], **kwargs})  # type: ignore[arg-type]
    assert err.value.field == field


def test_eta_zero_probe_marks_only_collapses_that_hold_for_every_eta() -> None:
    # The skipped scan points (restitution-free collapses) are most of the scan, and each one
    # overturns at every eta when run directly.
    om = np.array([0.3, 2.0, 9.0])
    scan = _scan(A_MAX, N_SCAN, 0)
    probe = _bk.probe_grid(om, -1.0, 0.0, scan, RTOL, MAX_EDGES, V_REST_BOUNDARY)
    known = probe[3]
    assert 0.3 < known.mean() < 1.0
    rng = np.random.default_rng(7)
    for i, omega in enumerate(om):
        for j in rng.choice(np.flatnonzero(known[i]), 5, replace=False):
            for eta in (0.0, 0.5, 1.0):
                model = RockingModel.symmetric(1.0, 1.0 / G, eta)
                pulse = Pulse(a_p=-scan[j], f_p=omega / (2 * math.pi))
                assert simulate(model, pulse, criterion="exact").collapsed


def test_interpolation_is_close_and_errs_on_the_safe_side(library: OverturningLibrary) -> None:
    mid = np.sqrt(library.omega[:-1] * library.omega[1:])[::6]
    for eta in (0.37, 0.9):
        exact = boundary_curve(mid, eta).a_min
        interp = library.a_min(mid, eta)
        # Never "no overturning" where it overturns below a_max.
        assert not np.any(np.isfinite(exact) & ~np.isfinite(interp))
        both = np.isfinite(exact) & np.isfinite(interp)
        # two-sided curves stop below a_max near Omega = 50; the grid goes on to 500 for the
        # one-sided curve
        assert np.isfinite(exact).sum() > 0.6 * mid.size
        assert both.sum() > 0.95 * np.isfinite(exact).sum()
        rel = (interp[both] - exact[both]) / exact[both]
        assert np.median(np.abs(rel)) < 1e-3
        assert rel.max() < 0.015  # measured 0.6 %: above the exact value only by this much


def test_one_sided_curve_is_tabulated_up_to_omega_400(library: OverturningLibrary) -> None:
    # A tall wall (p_eq about 1 rad/s) meets Omega = 63 at a 10 Hz pulse: the library covers
    # it, and interpolates the exact one-sided curve there as closely as below Omega = 50.
    assert library.omega[-1] == pytest.approx(500.0, rel=1e-12)
    grid = library.omega[(library.omega > 50.0) & (library.omega < 380.0)]
    mid = np.sqrt(grid[:-1] * grid[1:])[::9]
    exact = governing_one_sided(mid, 0.0)[2]
    interp, flagged = library.a_min_flagged(mid, one_sided=True)
    assert np.all(np.isfinite(exact)) and not np.any(flagged)
    rel = (interp - exact) / exact
    assert np.max(np.abs(rel)) < 1e-3
    # about Omega/2 (A_max = 200 is reached near Omega = 400)
    assert np.all((exact > 0.4 * mid) & (exact < 0.6 * mid))


def test_tabulated_spectrum_matches_the_exact_scale_factor(library: OverturningLibrary) -> None:
    f = np.geomspace(0.1, 20.0, 60)
    tab = library.scale_factor(f, f_n=4.0, h=6.0, h_e=5.0)
    exact = pulse_scale_factor(f, f_n=4.0, h=6.0, h_e=5.0)
    np.testing.assert_allclose(tab, exact, rtol=3e-4)


# --- Mechanism envelopes and cross-validation ----------------------------------------------------


def test_envelope_is_scaled_dimensionless_curve() -> None:
    model = RockingModel.symmetric(2.5, 0.15, 0.9)
    f = np.array([0.3, 1.0, 2.0, 4.0])
    env = mechanism_envelope(model, f, exact=True)
    expected = 0.15 * boundary_curve(2 * np.pi * f / 2.5, 0.9).a_min
    np.testing.assert_allclose(env.a_p_min_local_g, expected, rtol=1e-12)
    np.testing.assert_array_equal(env.a_p_min_g, env.a_p_min_local_g)  # at ground level


@pytest.mark.parametrize(
    ("model", "direction"),
    [
        (RockingModel.symmetric(2.2, 0.12, 0.92, name="gable"), -1.0),
        (RockingModel.symmetric(3.0, 0.2, 0.0, one_sided=True, name="facade"), 1.0),
    ],
)
def test_envelope_points_agree_with_direct_simulation(
    model: RockingModel, direction: float
) -> None:
    """Just below each envelope point the pulse does not overturn; just above it does."""
    f = np.array([0.2, 0.7, 1.5, 3.0, 6.0])
    env = mechanism_envelope(model, f, exact=True)
    for f_p, a_g in zip(f, env.a_p_min_g):
        for factor, expected in [(1 - 1e-4, False), (1 + 1e-4, True)]:
            pulse = Pulse(a_p=direction * factor * a_g * G, f_p=f_p)
            assert simulate(model, pulse).collapsed is expected, (model.name, f_p, factor)


def test_ground_envelope_is_local_over_scale_factor_and_absent_at_ground() -> None:
    cf = parse_constants(
        {
            "mechanisms": [
                {"id": "G", "p_eq": 2.0, "lam": 0.2, "eta": 0.9},
                {
                    "id": "T",
                    "p_eq": 3.0,
                    "lam": 0.25,
                    "eta": 0.95,
                    "amplification": {"f_n": 5.0, "h_e": 8.0, "h": 10.0},
                },
            ]
        }
    )
    f = frequency_grid(0.5, 8.0, 30)
    doc = envelope_doc(cf, f)[0].to_dict()  # the JSON form: absent keys are absent
    ground, tower = doc["mechanisms"]
    assert "scale_factor" not in ground and "a_p_min_local_g" not in ground
    sf = pulse_scale_factor(f, f_n=5.0, h=10.0, h_e=8.0)
    np.testing.assert_allclose(tower["scale_factor"], sf, rtol=3e-4)
    np.testing.assert_allclose(
        np.array(tower["a_p_min_g"]),
        np.array(tower["a_p_min_local_g"]) / np.array(tower["scale_factor"]),
        rtol=1e-12,
    )
    assert max(tower["scale_factor"]) > 2.0


def test_critical_bands_follow_the_lowest_envelope() -> None:
    f = np.geomspace(0.1, 10, 9)
    a = Envelope("A", f, np.full(9, 0.2), np.ones(9), np.ones(9, dtype=np.int64))
    b = Envelope("B", f, np.linspace(0.4, 0.05, 9), np.ones(9), np.ones(9, dtype=np.int64))
    c = Envelope("C", f, np.full(9, np.inf), np.ones(9), np.ones(9, dtype=np.int64))
    index, bands = critical_bands([a, b, c])
    assert [band["mechanism"] for band in bands] == ["A", "B"]
    assert bands[0]["f_min"] == f[0] and bands[1]["f_max"] == f[-1]
    assert bands[0]["f_max"] < bands[1]["f_min"]
    assert list(index) == [0 if v > 0.2 else 1 for v in np.linspace(0.4, 0.05, 9)]


def test_envelope_bad_input() -> None:
    with pytest.raises(InputError, match="f_min"):
        frequency_grid(5.0, 1.0, 10)
    with pytest.raises(InputError, match="eta"):
        mechanism_envelope(RockingModel.symmetric(2.0, 0.2, None, name="W9"), [1.0])
    with pytest.raises(InputError, match="mechanisms"):
        critical_bands([])
    with pytest.raises(InputError, match=r"h_e"):
        parse_constants(
            {
                "mechanisms": [
                    {
                        "id": "T",
                        "p_eq": 3.0,
                        "lam": 0.2,
                        "eta": 0.9,
                        "amplification": {"f_n": 5.0, "h_e": 0.0, "h": 10.0},
                    }
                ]
            }
        )


def test_envelope_document_says_a_two_eta_mechanism_was_computed_exactly() -> None:
    cf = parse_constants(
        {
            "mechanisms": [
                {"id": "S", "p_eq": 2.0, "lam": 0.2, "eta": 0.9},
                {
                    "id": "D",
                    "p_eq": 2.0,
                    "lam": 0.2,
                    "eta": 0.9,
                    "eta_to_negative": 0.9,
                    "eta_to_positive": 0.7,
                },
            ]
        }
    )
    doc, envs = envelope_doc(cf, frequency_grid(0.5, 4.0, 6))
    same, directional = doc.to_dict()["mechanisms"]
    assert "notes" not in same
    assert directional["notes"] == envs[1].notes
    assert "exact" in directional["notes"][0]
