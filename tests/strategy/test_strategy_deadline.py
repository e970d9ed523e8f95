"""Risk-aware (deadline) and risk-neutral target-relative solvers (Wang et al. 2024).

Default tests run the paper's nondimensional set-up on a coarse grid (100 x 128 nodes per
tack, Δs = 0.4 instead of 1600 x 1600, 0.025) and assert qualitative facts and closed forms;
the paper's numbers are compared in the slow test and in benchmarks/bench_strategy.py.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.strategy.deadline import (
    GH3_OFFSETS,
    GH3_WEIGHTS,
    DeadlineGrid,
    brownian_equivalent,
    simulate_deadline,
    solve_deadline,
    solve_risk_neutral,
    start_budget,
)
from sailroute.strategy.shiftmodel import DriftDiffusionShift, OUShift

# Sun Odyssey 40, TWS 8 kn column (Wang et al. 2024, Table 1), scaled to f_max = 0.05
SO40_TWA = np.array(
    [
        0,
        5,
        10,
        15,
        20,
        25,
        32,
        36,
        40,
        45,
        52,
        60,
        70,
        80,
        90,
        100,
        110,
        120,
        130,
        140,
        150,
        160,
        170,
        180,
    ],
    dtype=float,
)
SO40_KN = np.array(
    [
        0.0,
        0.6,
        1.2,
        1.8,
        2.1,
        2.5,
        4.1,
        4.6,
        5.0,
        5.4,
        5.8,
        6.2,
        6.4,
        6.5,
        6.5,
        6.5,
        6.4,
        6.2,
        5.7,
        5.2,
        4.7,
        4.2,
        3.9,
        3.6,
    ]
)
SO40 = Polar.from_arrays(
    SO40_TWA,
    np.array([1.0]),
    (SO40_KN * 0.05 / 6.5)[:, None],
    name="SO40 8kn",
    interpolation="linear",
)
C = 2.0
SIGMA = 0.05  # rad per sqrt(time unit)


def model(a: float, sigma: float) -> DriftDiffusionShift:
    # Wang et al.'s a is counter-clockwise; sailroute's drift is a compass veer: opposite sign
    return DriftDiffusionShift(-math.degrees(a), math.degrees(sigma))


def grid(s_max: float) -> DeadlineGrid:
    return DeadlineGrid(2.0, 100, 128, 0.1, 0.4, s_max)


def test_wang_2024_polar_vmg_known_answers() -> None:
    # Wang et al. (2024) (continuous, linear interpolation): 41.73°, 0.029498 up; 148.93°,
    # 0.031320 down; on the 49 controls: 41.25°, 0.029495 up; 150.00°, 0.031310 down
    ang, vmg = SO40.vmg_upwind(1.0)
    assert float(ang) == pytest.approx(41.73, abs=0.005)
    assert float(vmg) == pytest.approx(0.029498, abs=5e-7)
    ang, vmg = SO40.vmg_downwind(1.0)
    assert float(ang) == pytest.approx(148.93, abs=0.005)
    assert float(vmg) == pytest.approx(0.031320, abs=5e-7)
    u = np.degrees(grid(10.0).controls_rad)
    f = SO40.speed(1.0, u)
    up = f * np.cos(np.radians(u))
    assert u[np.argmax(up)] == pytest.approx(41.25)
    assert up.max() == pytest.approx(0.029495, abs=5e-7)
    assert u[np.argmax(-up)] == pytest.approx(150.0)
    assert (-up).max() == pytest.approx(0.031310, abs=5e-7)


def test_three_node_gauss_hermite_is_exact_to_degree_five() -> None:
    # nodes m + {-1, 0, 1} sqrt(3 v), weights 1/6, 2/3, 1/6; Gaussian moments of N(m, v)
    m, v = 0.3, 0.02
    nodes = m + np.array(GH3_OFFSETS) * math.sqrt(3 * v)
    w = np.array(GH3_WEIGHTS)
    exact = [
        1,
        m,
        m**2 + v,
        m**3 + 3 * m * v,
        m**4 + 6 * m**2 * v + 3 * v**2,
        m**5 + 10 * m**3 * v + 15 * m * v**2,
    ]
    for k, e in enumerate(exact):
        assert float(w @ nodes**k) == pytest.approx(e, rel=1e-12)


def test_brownian_equivalent_matches_ou_change_over_horizon() -> None:
    # Var[θ(T) - θ(0)] = 2σ²(1 - e^{-T/l}) for the OU shift, s² T for the Brownian one
    s = brownian_equivalent(10.0, 600.0, 800.0)
    assert s**2 * 800.0 == pytest.approx(2 * 100 * (1 - math.exp(-800 / 600)), rel=1e-12)
    # short horizon: the OU's own short-term diffusion sqrt(2σ²/l)
    assert brownian_equivalent(10.0, 600.0, 1e-3) == pytest.approx(
        math.sqrt(2 * 100 / 600), rel=1e-5
    )
    assert brownian_equivalent(10.0, math.inf, 800.0) == 0.0


@pytest.fixture(scope="module")
def fig4a():
    """Wang et al. (2024) Fig. 4(a): a = σ = 0.05, C = 2, start (1.80, 2.67, starboard), ŝ = 42."""
    g = grid(46.0)
    m = model(0.05, SIGMA)
    ra = solve_deadline(SO40, 1.0, m, g, C)
    rn = solve_risk_neutral(SO40, 1.0, m, g, C, tol_s=1e-2)
    start = (1.80, 2.67, 1)
    sim_rn = simulate_deadline(rn, 2000, 7, start)
    sim_ra = simulate_deadline(rn, 2000, 7, start, ra=ra, deadline_s=42.0)
    return ra, rn, start, sim_rn, sim_ra


def test_w_is_a_probability_non_decreasing_in_budget(fig4a) -> None:
    ra = fig4a[0]
    g = ra.grid
    assert np.all(ra.w >= 0.0) and np.all(ra.w <= 1.0)
    assert np.all(np.diff(ra.w, axis=0) >= -1e-6)  # more time never hurts
    r = np.tile(np.repeat(g.r_m, g.n_theta), 2)
    assert np.all(ra.w[:, r <= g.target_radius_m] == 1.0)  # inside the mark
    f_max = float(np.max(ra.speeds_ms))
    s = ra.s_s[:, None]
    unreachable = (r[None, :] - g.target_radius_m) / f_max > s
    assert np.all(ra.w[unreachable] == 0.0)  # cannot get there even at top speed
    assert np.all(ra.w[0, r > g.target_radius_m] == 0.0)


def test_switching_needs_a_budget_of_at_least_c(fig4a) -> None:
    ra = fig4a[0]
    k_c = round(C / ra.grid.ds_s)
    assert not ra.switch[:k_c].any()
    assert ra.switch[k_c:].any()


def test_risk_aware_beats_risk_neutral_at_its_deadline(fig4a) -> None:
    # Wang et al. (2024) Fig. 4(a): P(T <= 42) 5.8 % (μ*) -> 17.2 % (α^42), "nearly triples";
    # μ* switches twice in 99.9 % of runs, α^42 never in 99.1 %.  On this coarse grid we
    # assert the ordering within MC error, a factor >= 2, and the switch patterns.
    _, _, _, sim_rn, sim_ra = fig4a
    p_rn = np.mean(sim_rn.leg_time_s <= 42.0)
    p_ra = np.mean(sim_ra.leg_time_s <= 42.0)
    se = math.sqrt(p_ra * (1 - p_ra) / 2000 + p_rn * (1 - p_rn) / 2000)
    assert p_ra >= p_rn - 3 * se
    assert p_ra >= 2.0 * p_rn
    assert np.mean(sim_rn.n_switches == 2) > 0.9
    assert np.mean(sim_ra.n_switches == 0) > 0.9


def test_risk_neutral_has_the_lower_mean(fig4a) -> None:
    # E[T_μ*] <= E[T_α] (paper 43.83 vs 44.30), within MC error
    _, _, _, sim_rn, sim_ra = fig4a
    se = math.hypot(np.std(sim_rn.leg_time_s), np.std(sim_ra.leg_time_s)) / math.sqrt(2000)
    assert np.mean(sim_rn.leg_time_s) <= np.mean(sim_ra.leg_time_s) + 3 * se
    # and its value function predicts its own mean (coarse grid: within 1 %)
    _ra, rn, start, _, _ = fig4a
    assert rn.expected_time(*start) == pytest.approx(np.mean(sim_rn.leg_time_s), rel=0.01)


def test_ecdf_of_any_policy_stays_below_w(fig4a) -> None:
    # F_π(s) <= w(s).  On a coarse grid w is the true curve smeared by numerical
    # diffusion: too high left of the median arrival time, too low right of it (at s = 44
    # here w = 0.52 while μ* already achieves 0.60).  The bound is checked on the left tail,
    # where deadlines are interesting, with 3 MC standard errors plus 0.03.
    ra, _, start, sim_rn, _ = fig4a
    curve = ra.success_curve(*start)
    for s in (40.0, 41.0, 42.0, 43.0):
        f = np.mean(sim_rn.leg_time_s <= s)
        k = round(s / ra.grid.ds_s)
        assert f <= curve[k] + 3 * math.sqrt(max(f * (1 - f), 0.01) / 2000) + 0.03


def test_deadline_upgrade_and_fallback(fig4a) -> None:
    ra, _, _start, _, sim_ra = fig4a
    # close to the mark a generous deadline is sure: the budget is lowered to the least
    # sure one
    near = (0.6, 0.0, 1)
    s_up = start_budget(ra, *near, deadline_s=46.0)
    curve = ra.success_curve(*near)
    k = round(s_up / ra.grid.ds_s)
    assert s_up < 46.0 and curve[k] >= 1 - 1e-6 and curve[k - 1] < 1 - 1e-6
    assert sim_ra.deadline_s == 42.0  # not sure at 42: no upgrade
    # runs that miss the deadline continue with μ* and still finish
    assert sim_ra.fell_back.mean() > 0.5
    assert np.all(np.isfinite(sim_ra.leg_time_s))


def test_deadline_monte_carlo_is_chunk_independent(fig4a) -> None:
    ra, rn, start, _, sim_ra = fig4a
    again = simulate_deadline(rn, 1200, 7, start, ra=ra, deadline_s=42.0)
    np.testing.assert_array_equal(again.leg_time_s, sim_ra.leg_time_s[:1200])


@pytest.fixture(scope="module")
def steady():
    """σ = 0, a = 0 from the Fig. 3 start: the deterministic problem (closed form)."""
    g = grid(60.0)
    m = model(0.0, 0.0)
    rn = solve_risk_neutral(SO40, 1.0, m, g, C, tol_s=1e-2)
    return solve_deadline(SO40, 1.0, m, g, C), rn, g


def test_zero_volatility_matches_deterministic_two_leg_answer(steady) -> None:
    # T_det = 1.5352 / 0.029498 + C = 54.04 from (1.93, 0.56, starboard): starboard
    # 6.56, one switch, port 45.49 (one switch at the lay line).  The Monte Carlo of the
    # risk-neutral policy is deterministic and must be within 0.3 (0.6 %: headings of
    # 3.75° steps, Δr = 0.02, Euler steps); w(s) smeared by numerical diffusion crosses 1/2
    # within 1.0 of T_det.
    ra, rn, g = steady
    t_det = (1.93 * math.cos(0.56) - 0.1) / 0.029498 + C
    assert t_det == pytest.approx(54.04, abs=0.01)
    sim = simulate_deadline(rn, 50, 1, (1.93, 0.56, 1))
    assert np.ptp(sim.leg_time_s) < 1e-9  # no randomness left
    assert sim.leg_time_s[0] == pytest.approx(t_det, abs=0.3)
    assert np.all(sim.n_switches == 1)
    curve = ra.success_curve(1.93, 0.56, 1)
    s_half = ra.s_s[np.argmax(curve >= 0.5)]
    assert abs(s_half - t_det) < 1.0
    assert curve[round(50.0 / g.ds_s)] < 0.5 < curve[round(58.0 / g.ds_s)]


def test_ou_model_is_refused_by_the_deadline_solver() -> None:
    with pytest.raises(InputError, match="drift-diffusion"):
        solve_deadline(SO40, 1.0, OUShift(10.0, 600.0), grid(10.0), C)


def test_penalty_must_be_whole_budget_steps() -> None:
    with pytest.raises(InputError, match="whole"):
        solve_deadline(SO40, 1.0, model(0.0, SIGMA), grid(10.0), 1.0)


def test_grid_checks() -> None:
    with pytest.raises(InputError, match="target radius"):
        DeadlineGrid(2.0, 10, 16, 3.0, 0.4, 10.0)
    with pytest.raises(InputError, match="interpolation"):
        DeadlineGrid(2.0, 10, 16, 0.1, 0.4, 10.0, interpolation="eno")


def test_cubic_interpolation_runs_and_stays_a_probability() -> None:
    g = DeadlineGrid(2.0, 40, 48, 0.1, 0.4, 20.0, interpolation="cubic")
    ra = solve_deadline(SO40, 1.0, model(0.0, SIGMA), g, C)
    assert np.all((ra.w >= 0) & (ra.w <= 1))
    assert np.all(np.diff(ra.w, axis=0) >= -1e-6)


@pytest.mark.slow
def test_wang_2024_fig3_numbers_on_a_finer_grid() -> None:
    # Paper (1601 x 1601, Δs = 0.025, bicubic ENO, 1e5 runs): E[T] μ* 54.46;
    # P(T <= 56) 52.5 % (μ*) -> 58.9 % (α^56).  Here 200 x 256, Δs = 0.2, bilinear,
    # 4000 runs: allow 0.5 in the mean and 3 percentage points (+ MC error ~0.8 pp).
    g = DeadlineGrid(2.0, 200, 256, 0.1, 0.2, 60.0)
    m = model(0.0, SIGMA)
    ra = solve_deadline(SO40, 1.0, m, g, C)
    rn = solve_risk_neutral(SO40, 1.0, m, g, C, tol_s=1e-3)
    start = (1.93, 0.56, 1)
    sim_rn = simulate_deadline(rn, 4000, 1, start, dt_s=0.02)
    sim_ra = simulate_deadline(rn, 4000, 1, start, ra=ra, deadline_s=56.0, dt_s=0.02)
    assert np.mean(sim_rn.leg_time_s) == pytest.approx(54.46, abs=0.5)
    assert np.mean(sim_rn.leg_time_s <= 56) == pytest.approx(0.525, abs=0.03)
    assert np.mean(sim_ra.leg_time_s <= 56) == pytest.approx(0.589, abs=0.03)


def _reference_solve(g: DeadlineGrid, m: DriftDiffusionShift) -> np.ndarray:
    """Every node in every slice (no reach or sure window): the scheme as written."""
    from sailroute.strategy.deadline import (
        SURE,
        SWITCH_EPS,
        ZERO_CLIP,
        _model_rates,
        _RingRows,
        _steer_operator,
        _switch_operator,
    )

    a, sigma = _model_rates(m)
    f = SO40.speed(1.0, np.degrees(g.controls_rad))
    kc = g.penalty_steps(C)
    if g.interpolation == "cubic":
        s_op = _steer_operator(g, f, a, sigma, g.ds_s, "fail", "cubic")
    else:  # the ring-relative bilinear rows as the NumPy path multiplies them
        s_op = _RingRows.build(g, f, a, sigma, g.ds_s, np.float32, compiled=False).operator()
    c_op = _switch_operator(g, a, sigma, C)
    r = np.tile(np.repeat(g.r_m, g.n_theta), 2)
    out = r > g.target_radius_m
    w = np.zeros((g.n_s + 1, g.n_nodes + 2), dtype=np.float32)
    w[:, : g.n_nodes][:, ~out] = 1.0
    w[:, g.n_nodes] = 1.0
    reach = (r - g.target_radius_m) / float(np.max(f))
    for k in range(1, g.n_s + 1):
        wk = np.max(s_op.apply(w[k - 1], 0, g.n_nodes), axis=1)
        if k >= kc:
            ws = c_op.apply(w[k - kc], 0, g.n_nodes)[:, 0]
            wk = np.where(ws > wk + SWITCH_EPS, ws, wk)
        wk = np.where((reach > k * g.ds_s) | (wk < ZERO_CLIP), 0.0, np.minimum(wk, 1.0))
        prev = w[k - 1, : g.n_nodes]
        new = np.where((prev >= SURE) | (prev > wk), prev, wk)
        w[k, : g.n_nodes] = np.where(out, new, 1.0)
    return w[:, : g.n_nodes]


@pytest.mark.parametrize("interpolation", ["linear", "cubic"])
def test_windowed_solve_equals_updating_every_node(interpolation: str) -> None:
    # the solver skips rings out of reach at top speed and rings already sure; the
    # result must be bit-identical to updating every node of every slice
    g = DeadlineGrid(1.0, 24, 32, 0.1, 0.4, 30.0, interpolation=interpolation)
    m = model(0.05, SIGMA)
    ra = solve_deadline(SO40, 1.0, m, g, C)
    np.testing.assert_array_equal(ra.w, _reference_solve(g, m))
    assert (ra.w[-1] >= 1 - 1e-6).sum() > (ra.w[-1] > 0.5).sum() / 4  # sure rings exist


def test_bilinear_is_the_default() -> None:
    from sailroute.strategy.study import StrategySettings, deadline_grid_for

    assert DeadlineGrid(2.0, 10, 16, 0.1, 0.4, 10.0).interpolation == "linear"
    assert DeadlineGrid(2.0, 10, 16, 0.1, 0.4, 10.0).refine_controls == "none"
    st = StrategySettings(deadlines_s=(800.0,))
    g = deadline_grid_for(st, 2.0, 800.0)
    assert (g.interpolation, g.refine_controls) == ("linear", "none")
    g = deadline_grid_for(
        StrategySettings(deadlines_s=(800.0,), interpolation="cubic", refine_controls="golden"),
        2.0,
        800.0,
    )
    assert (g.interpolation, g.refine_controls) == ("cubic", "golden")
    with pytest.raises(InputError, match="refine_controls"):
        DeadlineGrid(2.0, 10, 16, 0.1, 0.4, 10.0, refine_controls="brent")


def test_float64_agrees_with_float32() -> None:
    g = DeadlineGrid(2.0, 40, 48, 0.1, 0.4, 30.0)
    m = model(0.05, SIGMA)
    w32 = solve_deadline(SO40, 1.0, m, g, C).w
    w64 = solve_deadline(SO40, 1.0, m, g, C, dtype="float64").w
    assert w64.dtype == np.float64 and w32.dtype == np.float32
    assert np.max(np.abs(w64 - w32)) < 1e-4
    with pytest.raises(InputError, match="dtype"):
        solve_deadline(SO40, 1.0, m, g, C, dtype="float16")


@pytest.fixture(scope="module")
def golden():
    g = DeadlineGrid(2.0, 40, 48, 0.1, 0.4, 46.0)
    gg = DeadlineGrid(2.0, 40, 48, 0.1, 0.4, 46.0, refine_controls="golden")
    m = model(0.05, SIGMA)
    return solve_deadline(SO40, 1.0, m, g, C), solve_deadline(SO40, 1.0, m, gg, C), m


def test_golden_refinement_never_lowers_w(golden) -> None:
    # the scheme is monotone (bilinear weights >= 0): a larger control set can only raise
    # w, slice by slice
    coarse, fine, _ = golden
    assert coarse.steer_offset is None and fine.steer_offset is not None
    assert np.all(fine.w >= coarse.w - 1e-6)
    assert np.mean(fine.w) > np.mean(coarse.w)
    assert np.any(fine.steer_offset != 0)
    assert np.all(np.abs(fine.steer_offset.astype(int)) <= 127)


def test_golden_refined_angles_lie_between_the_neighbours(golden) -> None:
    _, fine, _ = golden
    g = fine.grid
    k = np.arange(g.n_s + 1)[:, None]
    node = np.arange(g.n_nodes)[None, :]
    u, f = fine.steering(k, node)
    du = math.pi / (g.n_controls - 1)
    assert np.all(np.abs(u - g.controls_rad[fine.steer]) <= du + 1e-12)
    assert np.all((u >= 0) & (u <= math.pi))
    # the speed is the polar's between the controls
    np.testing.assert_allclose(f, SO40.speed(1.0, np.degrees(u)), atol=1e-6)


def test_golden_policy_simulates(golden) -> None:
    _, fine, m = golden
    rn = solve_risk_neutral(SO40, 1.0, m, fine.grid, C, tol_s=1e-2)
    sim = simulate_deadline(rn, 400, 3, (1.80, 2.67, 1), ra=fine, deadline_s=42.0)
    assert np.all(np.isfinite(sim.leg_time_s))
    assert np.mean(sim.n_switches == 0) > 0.5  # the bet on the shift, as the coarse policy


# (interpolation, (drift a, s_max, sigma), dtype, (n_r, n_theta)) of the engine comparisons
# (also tests/test_gpu.py): drift both ways, both dtypes, bicubic, and 4 angles with a wide
# diffusion, whose feet reach more than once round the ring
ENGINE_CASES = [
    ("linear", (0.05, 46.0, SIGMA), "float32", (40, 48)),
    ("linear", (-0.15, 30.0, SIGMA), "float64", (40, 48)),
    ("linear", (0.15, 20.0, 8.0), "float32", (12, 4)),
    ("cubic", (0.0, 20.0, SIGMA), "float32", (40, 48)),
]


@pytest.mark.parametrize(("interpolation", "fig", "dtype", "shape"), ENGINE_CASES)
def test_compiled_engine_is_bit_for_bit_the_numpy_path(interpolation, fig, dtype, shape) -> None:
    # the numba kernels do the NumPy arithmetic in the same order: the same w and actions
    pytest.importorskip("numba")
    a, s_max, sigma = fig
    g = DeadlineGrid(2.0, shape[0], shape[1], 0.1, 0.4, s_max, interpolation=interpolation)
    m = model(a, sigma)
    if shape[1] == 4:
        from sailroute.strategy.deadline import _model_rates, _RingRows

        rows = _RingRows.build(
            g,
            SO40.speed(1.0, np.degrees(g.controls_rad)),
            *_model_rates(m),
            g.ds_s,
            np.float32,
            compiled=False,
        )
        assert rows.pad > g.n_theta
    ref = solve_deadline(SO40, 1.0, m, g, C, engine="numpy", dtype=dtype)
    jit = solve_deadline(SO40, 1.0, m, g, C, engine="numba", dtype=dtype)
    assert ref.w.max() > 0.5  # a solve with something to compare
    assert (ref.w[-1] >= 1 - 1e-6).any()  # sure nodes
    assert ref.switch.any() or sigma > 1  # switches (none when the wind is all noise)
    assert np.array_equal(jit.w, ref.w)
    assert np.array_equal(jit.action, ref.action)


@pytest.mark.parametrize(("interpolation", "fig", "dtype", "shape"), ENGINE_CASES)
def test_array_module_engine_is_bit_for_bit_the_numpy_path(
    monkeypatch, interpolation, fig, dtype, shape
) -> None:
    # engine "cupy" runs the NumPy path's operations on another array module, with its own
    # row sums (_deadline_xp.DeviceRows) and one block per tack band; a stand-in for NumPy
    # takes that code path without a GPU (tests/test_gpu.py runs it on CuPy) and must give
    # the same w and actions
    import types

    from sailroute.strategy import deadline

    fake = types.ModuleType("numpy_standin")
    fake.__getattr__ = lambda name: getattr(np, name)  # type: ignore[method-assign]
    monkeypatch.setattr(deadline, "get_xp", lambda name: fake if name == "cupy" else np)
    a, s_max, sigma = fig
    g = DeadlineGrid(2.0, shape[0], shape[1], 0.1, 0.4, s_max, interpolation=interpolation)
    m = model(a, sigma)
    ref = solve_deadline(SO40, 1.0, m, g, C, engine="numpy", dtype=dtype)
    dev = solve_deadline(SO40, 1.0, m, g, C, engine="cupy", dtype=dtype)
    assert ref.w.max() > 0.5 and (ref.w[-1] >= 1 - 1e-6).any()
    assert np.array_equal(dev.w, ref.w)
    assert np.array_equal(dev.action, ref.action)
    with pytest.raises(InputError, match="engine 'cupy' does not refine"):
        solve_deadline(SO40, 1.0, m, replace(g, refine_controls="golden"), C, engine="cupy")


def test_ring_rows_agree_with_the_sparse_bilinear_rows() -> None:
    # the ring-relative rows are the bilinear scheme of _feet_stencil up to rounding:
    # every node and control of a random slice (float64: to 1e-12)
    from sailroute.strategy.deadline import _model_rates, _RingRows, _steer_operator

    g = DeadlineGrid(2.0, 30, 40, 0.1, 0.4, 10.0)
    a, sigma = _model_rates(model(0.1, SIGMA))
    f = SO40.speed(1.0, np.degrees(g.controls_rad))
    x = np.random.default_rng(3).random(g.n_nodes + 2)
    x[g.n_nodes], x[g.n_nodes + 1] = 1.0, 0.0  # the ghosts: in the mark, beyond r_max
    ring = _RingRows.build(g, f, a, sigma, g.ds_s, np.float64, compiled=False).operator()
    n_in = int(np.count_nonzero(g.r_m <= g.target_radius_m))
    lo = n_in * g.n_theta  # rows of nodes outside the mark (inside, w = 1 anyway)
    per_tack = (g.n_r + 1) * g.n_theta
    csr = _steer_operator(g, f, a, sigma, g.ds_s, "fail", "linear", np.float64)
    for q in (0, 1):
        n0, n1 = q * per_tack + lo, (q + 1) * per_tack
        np.testing.assert_allclose(ring.apply(x, n0, n1), csr.apply(x, n0, n1), rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    "sure", [[], [0, 1, 2], [5, 6, 7, 0, 1], [3], list(range(8)), [0, 2, 3, 4, 7], [7]]
)
def test_unsure_arc_covers_every_unsure_node(sure: list[int]) -> None:
    pytest.importorskip("numba")
    from sailroute.strategy._deadline_jit import unsure_arc

    nt = 8
    prev = np.full(nt + 4, 0.5, dtype=np.float32)
    prev[2 + np.array(sure, dtype=int)] = 1.0
    start, length = unsure_arc(prev, 2, nt, np.float32(1 - 1e-6))
    covered = {(start + k) % nt for k in range(length)}
    unsure = set(range(nt)) - set(sure)
    assert unsure <= covered
    # the complement of the longest circular run of sure nodes
    longest = max(
        (
            n
            for s0 in range(nt)
            for n in range(nt + 1)
            if all((s0 + k) % nt in sure for k in range(n))
        ),
        default=0,
    )
    assert length == nt - min(longest, nt)


def test_policy_action_packs_steer_and_switch(fig4a) -> None:
    ra, g = fig4a[0], fig4a[0].grid
    assert ra.action.dtype == np.uint8
    np.testing.assert_array_equal(ra.steer, ra.action & 127)
    np.testing.assert_array_equal(ra.switch, ra.action >= 128)
    k, node = np.array([g.n_s, g.n_s]), np.array([5, 2 * g.n_nodes // 3])
    np.testing.assert_array_equal(ra.switches(k, node), ra.switch[k, node])
    u, _ = ra.steering(k, node)
    np.testing.assert_array_equal(u, g.controls_rad[ra.steer[k, node]])
    with pytest.raises(InputError, match="n_controls <= 128"):
        DeadlineGrid(2.0, 10, 16, 0.1, 0.4, 10.0, n_controls=129)


def test_engine_errors(monkeypatch) -> None:
    from sailroute.strategy import _deadline_jit

    g = DeadlineGrid(2.0, 10, 16, 0.1, 0.4, 2.0)
    with pytest.raises(InputError, match="engine 'cuda': expected one of auto, numpy, numba, cupy"):
        solve_deadline(SO40, 1.0, model(0.0, SIGMA), g, C, engine="cuda")
    monkeypatch.setattr(_deadline_jit, "AVAILABLE", False)
    with pytest.raises(InputError, match=r"pip install 'sailroute\[fast\]'"):
        solve_deadline(SO40, 1.0, model(0.0, SIGMA), g, C, engine="numba")
    # auto falls back to NumPy
    assert solve_deadline(SO40, 1.0, model(0.0, SIGMA), g, C).w.shape == (g.n_s + 1, g.n_nodes)
