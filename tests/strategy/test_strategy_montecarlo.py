"""Seeded, chunk-independent Monte Carlo of lattice policies."""

from __future__ import annotations

import numpy as np
import pytest

from sailroute.boat.build import builtin_polar
from sailroute.errors import InputError
from sailroute.strategy.montecarlo import (
    CHUNK_SIZE,
    concatenate,
    simulate,
    simulate_chunk,
    time_summary,
)
from sailroute.strategy.sdp import BeatGrid, segment_transitions, solve_expected_time
from sailroute.strategy.shiftmodel import OUShift
from sailroute.units import KNOT


@pytest.fixture(scope="module")
def policy():
    grid = BeatGrid(length_m=800.0, half_width_m=400.0, lateral_m=8.0, row_m=20.0)
    return solve_expected_time(builtin_polar("ilca7"), 10 * KNOT, OUShift(10.0, 600.0), grid)


def test_results_do_not_depend_on_chunking(policy) -> None:
    big = simulate(policy, 2 * CHUNK_SIZE + 500, seed=42)
    parts = [simulate_chunk(policy, k, 42) for k in range(3)]
    joined = concatenate(parts, 2 * CHUNK_SIZE + 500)
    np.testing.assert_array_equal(big.leg_time_s, joined.leg_time_s)
    np.testing.assert_array_equal(big.x_m, joined.x_m)
    # a smaller run count is a prefix of a larger one (same streams per chunk)
    small = simulate(policy, CHUNK_SIZE + 10, seed=42)
    np.testing.assert_array_equal(small.leg_time_s, big.leg_time_s[: CHUNK_SIZE + 10])
    # chunk order does not matter: chunk 2 alone equals the third block
    np.testing.assert_array_equal(simulate_chunk(policy, 2, 42).n_tacks, parts[2].n_tacks)


def test_seed_reproducible_and_sensitive(policy) -> None:
    a = simulate(policy, 300, seed=1)
    b = simulate(policy, 300, seed=1)
    c = simulate(policy, 300, seed=2)
    np.testing.assert_array_equal(a.leg_time_s, b.leg_time_s)
    assert not np.array_equal(a.leg_time_s, c.leg_time_s)


def test_tracks_are_consistent(policy) -> None:
    sim = simulate(policy, 500, seed=4)
    g = policy.grid
    assert sim.x_m.shape == (500, g.n_rows + 1)
    assert np.all(sim.x_m[:, 0] == 0.0) and np.all(sim.x_m[:, -1] == 0.0)  # start and mark
    np.testing.assert_allclose(sim.t_s[:, -1], sim.leg_time_s, rtol=1e-6)
    assert np.all(np.diff(sim.t_s, axis=1) > 0)
    bands = sim.lateral_bands()
    assert bands.shape == (5, g.n_rows + 1)
    assert np.all(np.diff(bands, axis=0) >= 0)  # P10 <= P30 <= ... <= P90


def test_mismatched_truth_is_accepted_and_checked(policy) -> None:
    truth = segment_transitions(OUShift(20.0, 120.0), policy.grid, policy.segments)
    sim = simulate(policy, 500, seed=5, transitions=truth)
    assert np.all(np.isfinite(sim.leg_time_s))
    # a faster-changing, wider wind makes the same policy's time more variable
    own = simulate(policy, 500, seed=5)
    assert np.std(sim.leg_time_s) > np.std(own.leg_time_s)
    with pytest.raises(InputError, match="shape"):
        simulate(policy, 10, seed=1, transitions=truth[:, :5])


def test_time_summary_counts() -> None:
    t = np.array([10.0, 20.0, 30.0, np.inf])
    s = time_summary(t, np.array([1, 1, 2, 3]), deadlines_s=(20.0,))
    assert s["n_failed"] == 1
    assert s["mean_s"] == pytest.approx(20.0)
    assert s["p_within_deadline"]["20"]["p"] == pytest.approx(0.5)
    assert s["p_within_deadline"]["20"]["se"] == pytest.approx(0.25)
    assert s["tacks"]["distribution"] == {"1": 0.5, "2": 0.25, "3": 0.25}


def test_run_count_and_tack_checked(policy) -> None:
    with pytest.raises(InputError, match="runs"):
        simulate(policy, 0, seed=1)
    with pytest.raises(InputError, match="tack"):
        simulate(policy, 10, seed=1, tack0=0)


def test_percentiles_reaching_failures_are_infinite() -> None:
    t = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, np.inf])
    pct = time_summary(t)["percentiles_s"]
    assert pct["50"] == pytest.approx(5.5)
    assert pct["95"] == np.inf  # between the 9 s run and a failure
