"""Wind-shift models and their Markov-chain discretisation (Shepherd, Haydon & Vermillion)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import norm

from sailroute.errors import InputError
from sailroute.strategy.shiftmodel import (
    DriftDiffusionShift,
    OUShift,
    chain_diagnostics,
    generator_matrix,
    shift_bins,
    stationary_distribution,
    transition_matrix,
    transition_rows,
)

BINS = shift_bins(5.0, 45.0)


def test_shift_bins_are_shepherd_et_al_grid() -> None:
    # 19 states, -45..45 in 5° steps (Shepherd, Haydon & Vermillion)
    assert BINS.size == 19
    assert BINS[0] == -45.0 and BINS[-1] == 45.0
    assert np.all(np.diff(BINS) == 5.0)


@pytest.mark.parametrize("method", ["integrate", "generator"])
@pytest.mark.parametrize(
    "model",
    [
        OUShift(10.0, 600.0),
        OUShift(3.0, 60.0, mean_deg=7.0),
        OUShift(0.0, 600.0),
        DriftDiffusionShift(0.05, 0.5),
        DriftDiffusionShift(-0.2, 0.0),
    ],
)
def test_rows_sum_to_one_and_are_nonnegative(model, method) -> None:
    dts = np.array([0.0, 1.0, 5.0, 20.0, 300.0, 1e5])
    rows = transition_rows(model, BINS, np.arange(BINS.size)[:, None], dts[None, :], method)
    assert rows.shape == (BINS.size, dts.size, BINS.size)
    assert np.all(rows >= 0)
    np.testing.assert_allclose(rows.sum(axis=-1), 1.0, rtol=0, atol=1e-12)


def test_zero_step_is_identity() -> None:
    for method in ("integrate", "generator"):
        m = transition_matrix(OUShift(10.0, 600.0), BINS, 0.0, method)
        np.testing.assert_allclose(m, np.eye(BINS.size), atol=1e-12)


def test_integrate_uses_corrected_bin_limits_and_lumps_tails() -> None:
    # From θ = 20° over 60 s: μ = 20 e^{-0.1}, s = σ sqrt(1 - e^{-0.2}) (exact OU moments).
    model = OUShift(10.0, 600.0)
    i = int(np.flatnonzero(BINS == 20.0)[0])
    mu = 20.0 * math.exp(-60.0 / 600.0)
    sd = 10.0 * math.sqrt(1.0 - math.exp(-120.0 / 600.0))
    row = transition_rows(model, BINS, i, 60.0, "integrate")
    # P(μ + ε in [θ_j - 2.5, θ_j + 2.5)), the edge bins taking the tails
    lo = np.concatenate([[-np.inf], BINS[1:] - 2.5])
    hi = np.concatenate([BINS[:-1] + 2.5, [np.inf]])
    expected = norm.cdf((hi - mu) / sd) - norm.cdf((lo - mu) / sd)
    np.testing.assert_allclose(row, expected, rtol=1e-12, atol=1e-15)
    # the printed eq 13 (A = μ + θ_j - δθ/2) is a different, wrong law: it must not match
    wrong = norm.cdf((mu + BINS + 2.5) / sd) - norm.cdf((mu + BINS - 2.5) / sd)
    assert np.max(np.abs(row - wrong)) > 0.1


@pytest.mark.parametrize(
    ("timescale_min", "sigma", "sd", "lag", "stay"),
    # the "discretisation trap" table (an earlier hand computation):
    # chain by exact bin integration, corrected eq 13, edge lumping, δθ = 5°, 20 s steps
    [
        (10, 10, 11.5, 31, 0.65),
        (10, 5, 6.5, 65, 0.89),
        (40, 10, 12.9, 254, 0.95),
        (120, 10, 13.6, None, 0.999),
    ],
)
def test_integrate_reproduces_trap_table(timescale_min, sigma, sd, lag, stay) -> None:
    model = OUShift(sigma, timescale_min * 60.0)
    m = transition_matrix(model, BINS, 20.0, "integrate")
    d = chain_diagnostics(m, BINS, model, 20.0, max_lag=3000)
    # the table prints one decimal (sd), integers (lag) and 2-3 decimals (stay): half a unit
    assert d.stationary_sd_deg == pytest.approx(sd, abs=0.05)
    if lag is None:
        assert d.efold_lag == math.inf  # ">3000" in the table
    else:
        assert d.efold_lag == lag
    assert d.mean_stay_prob == pytest.approx(stay, abs=0.005 if stay < 0.99 else 0.0005)


@pytest.mark.parametrize("dt", [5.0, 20.0, 300.0])
@pytest.mark.parametrize("sigma", [5.0, 10.0])
def test_generator_chain_is_exact_for_ehrenfest_case(sigma, dt) -> None:
    # N = 4σ²/h² = 4 or 16 is an integer: the chain is the Ehrenfest urn, whose stationary
    # sd is exactly σ and whose mean decays exactly as e^{-t/l} (docstring of generator_matrix)
    model = OUShift(sigma, 600.0)
    m = transition_matrix(model, BINS, dt, "generator")
    d = chain_diagnostics(m, BINS, model, dt)
    assert d.stationary_sd_deg == pytest.approx(sigma, rel=1e-9)
    assert d.lag1_autocorr == pytest.approx(math.exp(-dt / 600.0), rel=1e-9)


def test_generator_chain_is_time_consistent() -> None:
    model = OUShift(7.0, 600.0)
    m1 = transition_matrix(model, BINS, 8.0)
    m2 = transition_matrix(model, BINS, 13.0)
    m12 = transition_matrix(model, BINS, 21.0)
    np.testing.assert_allclose(m1 @ m2, m12, atol=1e-12)


def test_generator_statistics_close_to_target_off_lattice() -> None:
    # σ = 7° (N = 7.84, not an integer): upwind rates at the rim; sd within 1 %,
    # lag-1 autocorrelation within 1e-4 (measured 0.35 % and 7e-7)
    model = OUShift(7.0, 600.0)
    d = chain_diagnostics(transition_matrix(model, BINS, 20.0), BINS, model, 20.0)
    assert abs(d.relative_errors()["sd"]) < 0.01
    assert abs(d.relative_errors()["lag1"]) < 1e-4


def test_generator_rows_match_drift_and_diffusion() -> None:
    # interior rows with central rates reproduce the local drift and diffusion exactly
    model = OUShift(10.0, 600.0)
    q = generator_matrix(model, BINS)
    np.testing.assert_allclose(q.sum(axis=1), 0.0, atol=1e-15)
    inner = slice(2, -2)
    drift = (q @ BINS)[inner]
    second = (q @ BINS**2 - 2 * BINS * (q @ BINS))[inner]
    b, diff = model.drift_diffusion(BINS)
    np.testing.assert_allclose(drift, b[inner], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(second, diff, rtol=1e-12)


def test_ou_transition_moments_exact() -> None:
    model = OUShift(10.0, 600.0, mean_deg=2.0)
    mean, sd = model.transition_moments(12.0, 60.0)
    assert mean == pytest.approx(2.0 + 10.0 * math.exp(-0.1), rel=1e-14)
    assert sd == pytest.approx(10.0 * math.sqrt(1 - math.exp(-0.2)), rel=1e-14)
    # R = 1 - exp(-Δt/l), σ_tr² = σ²(1 - exp(-2Δt/l)) -> stationary σ² = σ_tr²/(R(2-R))
    r = 1 - math.exp(-0.1)
    assert (sd**2) / (r * (2 - r)) == pytest.approx(100.0, rel=1e-12)


def test_brownian_transition_moments_exact() -> None:
    # E φ(t) = φ0 + a t, Var φ(t) = s² t
    model = DriftDiffusionShift(0.05, 0.4)
    mean, sd = model.transition_moments(3.0, 100.0)
    assert mean == pytest.approx(8.0)
    assert sd**2 == pytest.approx(16.0)


def test_stationary_distribution_of_symmetric_chain_is_symmetric() -> None:
    pi = stationary_distribution(transition_matrix(OUShift(10.0, 600.0), BINS, 20.0))
    np.testing.assert_allclose(pi, pi[::-1], atol=1e-12)
    assert pi.sum() == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: OUShift(-1.0, 600.0), "sigma_deg"),
        (lambda: OUShift(10.0, 0.0), "timescale_s"),
        (lambda: DriftDiffusionShift(0.0, -1.0), "sigma"),
        (lambda: shift_bins(5.0, 42.0), "whole number"),
        (lambda: transition_matrix(OUShift(1, 1), BINS, 1.0, "tauchen"), "unknown method"),
        (lambda: transition_matrix(OUShift(1, 1), BINS, -1.0), "finite and >= 0"),
    ],
)
def test_errors_teach(call, match) -> None:
    with pytest.raises(InputError, match=match):
        call()
