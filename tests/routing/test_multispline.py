"""Adaptive multi-spline refinement: Hermite edges, the paper's fitting problem, routing."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.optimize import minimize

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.routing.multispline import (
    fit_function,
    fitting_target,
    hermite_y,
    route_spline,
    solve_spline,
)
from sailroute.routing.settings import routing_settings
from sailroute.routing.types import Start, Target
from sailroute.wind.uniform import UniformWind

ISO = Polar.from_arrays(
    np.array([0.0, 40.0, 180.0]),
    np.array([0.0, 20.0]),
    np.array([[0.0, 0.0], [0.0, 6.0], [0.0, 6.0]]),
    interpolation="linear",
)


def test_hermite_edge_matches_end_values_and_slopes() -> None:
    y0, m0, y1, m1, dx = 1.5, -0.7, -2.0, 2.5, 3.0
    t = np.array([0.0, 1.0])
    assert hermite_y(y0, m0, y1, m1, dx, t) == pytest.approx([y0, y1], abs=1e-15)
    h = 1e-6
    d0 = (hermite_y(y0, m0, y1, m1, dx, h) - y0) / (h * dx)
    d1 = (y1 - hermite_y(y0, m0, y1, m1, dx, 1 - h)) / (h * dx)
    assert d0 == pytest.approx(m0, abs=1e-5) and d1 == pytest.approx(m1, abs=1e-5)
    # a cubic is reproduced exactly
    xs = np.linspace(0.0, dx, 7)
    cubic = 0.3 * xs**3 - xs**2 + 0.5 * xs + 1.0
    dcub = 0.9 * xs**2 - 2 * xs + 0.5
    y = hermite_y(cubic[0], dcub[0], cubic[-1], dcub[-1], dx, xs / dx)
    assert y == pytest.approx(cubic, abs=1e-12)


def _continuous_optimum(n_rows: int = 10) -> float:
    """Best squared L2 error over all Hermite splines with free node values and slopes."""
    xs = np.linspace(0.0, math.pi, n_rows)
    g, w = np.polynomial.legendre.leggauss(8)
    tq = 0.5 * (g + 1.0)

    def obj(p: np.ndarray) -> float:
        yv = np.concatenate([[0.0], p[: n_rows - 2], [0.0]])
        m = p[n_rows - 2 :]
        tot = 0.0
        for r in range(n_rows - 1):
            dx = xs[r + 1] - xs[r]
            y = hermite_y(yv[r], m[r], yv[r + 1], m[r + 1], dx, tq)
            tot += 0.5 * dx * np.sum(w * (y - fitting_target(xs[r] + tq * dx)) ** 2)
        return float(tot)

    p0 = np.concatenate([fitting_target(xs[1:-1]), np.gradient(fitting_target(xs), xs)])
    return float(minimize(obj, p0, method="BFGS", options={"gtol": 1e-12}).fun)


def test_function_fitting_problem_converges() -> None:
    # the paper's test: fit r_t(θ) on [0, π] with r(0) = r(π) = 0 (10 rows, 25 nodes,
    # 7 slopes).  Measured L2 errors per pass: 0.064, 0.023, 0.0071, 0.0035, 0.0031;
    # the best possible with 10 Hermite nodes is 0.0011 (continuous optimum), so after
    # 4 refinements the error must be below 0.004 and within 3.5x of that optimum
    fit = fit_function(n_refine=4)
    err = np.sqrt([p.cost for p in fit.passes])
    assert np.all(np.diff(err) <= 1e-15)
    assert np.all(np.diff(err[:4]) < 0)
    assert err[0] / err[3] > 10.0  # three refinements gain more than an order of magnitude
    opt = math.sqrt(_continuous_optimum())
    assert opt < err[-1] < min(0.004, 3.5 * opt)
    # the reported cost is the squared L2 distance of the returned curve
    x, y = fit.curve(200)
    dense = np.trapezoid((y - fitting_target(x)) ** 2, x)
    assert dense == pytest.approx(fit.cost, rel=1e-3)
    assert fit.across[0] == 0.0 and fit.across[-1] == 0.0


def test_spline_reach_is_straight_and_exact() -> None:
    wind = UniformWind(8.0, 270.0)
    s = routing_settings(
        router="spline", dp_rows=7, spline_cols=11, spline_slopes=5, spline_refinements=1
    )
    r = route_spline(
        Start((0.0, 0.0)), Target("line", (-20.0, 400.0), (20.0, 400.0)), 0.0, wind, ISO, s
    )
    assert r.router == "spline"
    assert r.time_s == pytest.approx(400.0 / 2.4, rel=1e-12)
    assert np.allclose(r.track.x, 0.0, atol=1e-9)


def test_spline_refinement_costs_never_increase() -> None:
    wind = UniformWind([8.0, 9.0], [260.0, 300.0], times=[0.0, 300.0])
    s = routing_settings(
        router="spline",
        dp_rows=7,
        spline_cols=11,
        spline_slopes=5,
        spline_refinements=3,
        dp_half_width_m=150.0,
    )
    res, fit = solve_spline(Start((0.0, 0.0)), Target("mark", (50.0, 400.0)), 0.0, wind, ISO, s)
    costs = [p.cost for p in fit.passes]
    assert all(b <= a + 1e-9 for a, b in itertools.pairwise(costs))
    assert res.time_s == pytest.approx(fit.cost, rel=1e-12)
    assert [p.slope_half_deg for p in fit.passes] == pytest.approx([36.0, 12.0, 4.0, 4.0 / 3])


def test_invalid_spline_settings() -> None:
    s = routing_settings(router="spline", spline_slopes=0)
    with pytest.raises(InputError, match=r"spline\.slopes"):
        route_spline(
            Start((0.0, 0.0)), Target("mark", (0.0, 300.0)), 0.0, UniformWind(8.0, 270.0), ISO, s
        )


# ---------------------------------------------------------------------------------------
# pruned dynamic rows, the separable fitting cost, carried speed, start from rest


def _debski_small(carry: bool = False, rest: bool = False) -> tuple:
    from sailroute.boat.dynamic import DynamicBoat
    from sailroute.wind.analytic import debski_test_wind

    s = routing_settings(
        router="spline",
        dp_rows=6,
        spline_cols=9,
        spline_slopes=5,
        spline_refinements=1,
        dp_half_width_m=400.0,
        tack_penalty_s=0.0,
        gybe_penalty_s=0.0,
        zone_m=0.01,
        spline_carry_speed=carry,
        spline_start_from_rest=rest,
    )
    return solve_spline(
        Start((0.0, 0.0)), Target("mark", (500.0, 0.0)), 0.0, debski_test_wind(), DynamicBoat(), s
    )


def test_edge_time_bound_is_a_lower_bound_of_the_sailed_time() -> None:
    # the pruning is exact only if the bound never exceeds the chain time: random
    # chains shaped like a spline edge's chords (heading and wind change smoothly from
    # chord to chord; angles in and out of the no-drive zone; entry speeds from rest to
    # 1.5x steady).  chain_time books a transient's whole loss on the piece where it
    # starts, which is second order only when the next pieces are alike: on chains that
    # jump from 12° to 89° between 0.2 m chords it can come out below this bound.
    from sailroute.boat.dynamic import DynamicBoat, chain_time
    from sailroute.routing._dp_grid import ChainWind
    from sailroute.routing.multispline import edge_time_bound

    boat = DynamicBoat()
    rng = np.random.default_rng(7)
    n, k = 4000, 6
    turns = np.radians(rng.normal(0.0, 3.0, (n, k)))
    beta = np.abs(rng.uniform(0.0, math.pi, (n, 1)) + np.cumsum(turns, axis=1))
    beta = np.minimum(beta, 2 * math.pi - beta)
    tws = rng.uniform(2.0, 15.0, (n, 1)) * np.cumprod(1 + rng.normal(0, 0.02, (n, k)), axis=1)
    length = rng.uniform(0.0, 60.0, (n, 1)) * rng.uniform(0.8, 1.2, (n, k))
    heading = np.cumsum(turns, axis=1)
    ux, uy = np.cos(heading), np.sin(heading)
    cw = ChainWind(tws, beta, np.ones((n, k), np.int8), length, ux, uy, np.ones((n, k), bool))
    cos_t = np.ones((n, k))
    cos_t[:, 1:] = ux[:, 1:] * ux[:, :-1] + uy[:, 1:] * uy[:, :-1]
    v_in = rng.uniform(0.0, 1.5, n) * tws[:, 0] * boat.table().steady(beta[:, 0])
    t, _ = chain_time(boat, beta, tws, length, cos_t, v_in)
    bound = edge_time_bound(boat, cw, v_in)
    fin = np.isfinite(t)
    assert fin.sum() > n // 2
    # the pruning margin is 1e-3 relative + 1e-2 s: the bound must hold within it
    assert np.all(bound[fin] * (1.0 - 1e-3) - 1e-2 <= t[fin])
    assert np.median(bound[fin] / t[fin]) > 0.5  # and be tight enough to prune


def test_pruned_dynamic_rows_equal_sailing_every_edge(monkeypatch: pytest.MonkeyPatch) -> None:
    # with an infinite margin nothing is pruned: the DP must pick the same route
    import sailroute.routing.multispline as ms

    res, fit = _debski_small()
    monkeypatch.setattr(ms, "PRUNE_ABS_S", 1e12)
    full, full_fit = _debski_small()
    assert res.time_s == full.time_s
    assert [p.cost for p in fit.passes] == [p.cost for p in full_fit.passes]
    assert np.array_equal(res.track.x, full.track.x)


def test_start_from_rest_is_never_faster_and_carried_speed_counts() -> None:
    # entering every edge slower can only arrive later (the model is monotone in the
    # entry speed), so the optimum from rest is >= the flying start's optimum
    fly, _ = _debski_small()
    rest, _ = _debski_small(rest=True)
    assert rest.time_s >= fly.time_s - 1e-9
    assert rest.track.bsp_ms[0] == 0.0
    carry, _ = _debski_small(carry=True)
    assert carry.time_s != fly.time_s and abs(carry.time_s - fly.time_s) < 0.01 * fly.time_s


def test_reach_from_rest_costs_the_acceleration_loss_and_carrying_changes_nothing() -> None:
    # straight reach in uniform wind: flying start = L / steady speed; from rest adds
    # the transient's loss Λ(β, 0) / v_t; carrying the (steady) end speed changes nothing
    from sailroute.boat.dynamic import DynamicBoat

    boat, vt, length = DynamicBoat(), 8.0, 400.0
    tab = boat.table()
    beta = np.radians(90.0)

    def route(**kw: bool) -> float:
        s = routing_settings(
            router="spline", dp_rows=5, spline_cols=7, spline_slopes=3, spline_refinements=1, **kw
        )
        return route_spline(
            Start((0.0, 0.0)),
            Target("line", (-0.01, length), (0.01, length)),
            0.0,
            UniformWind(vt, 270.0),
            boat,
            s,
        ).time_s

    ws = float(tab.steady(beta))
    fly = length / (ws * vt)
    assert route() == pytest.approx(fly, rel=1e-6)
    assert route(spline_carry_speed=True) == pytest.approx(fly, rel=1e-6)
    loss = float(tab.loss_at(np.array(beta), np.array(0.0), np.array(ws))) / vt
    assert loss > 0.3
    # the straight line from rest takes fly + loss; the DP may bear away a little to
    # accelerate sooner, never more than that
    rest = route(spline_start_from_rest=True)
    assert fly + 0.5 * loss < rest <= fly + loss + 1e-6


def test_separable_fitting_cost_equals_quadrature_per_edge() -> None:
    from sailroute.routing.multispline import Edges, l2_edge_cost

    rng = np.random.default_rng(3)
    c0, s0, c1, s1 = 4, 3, 5, 2
    e = Edges(
        np.full((c0, 1, 1, 1), 0.4),
        rng.normal(size=(c0, 1, 1, 1)),
        rng.normal(size=(1, s0, 1, 1)),
        np.full((1, 1, c1, 1), 0.9),
        rng.normal(size=(1, 1, c1, 1)),
        rng.normal(size=(1, 1, 1, s1)),
        np.zeros((c0, s0, 1, 1)),
    )
    fast = l2_edge_cost(fitting_target)(0, e)
    # the same edges with per-edge X (not all equal) take the quadrature path
    g, w = np.polynomial.legendre.leggauss(8)
    t = 0.5 * (g + 1.0)
    y = hermite_y(e.y0[..., None], e.m0[..., None], e.y1[..., None], e.m1[..., None], 0.5, t)
    slow = 0.25 * np.sum(w * (y - fitting_target(0.4 + 0.5 * t)) ** 2, axis=-1)
    assert fast.shape == (c0, s0, c1, s1)
    assert np.allclose(fast, slow, rtol=1e-10, atol=1e-14)


def test_invalid_spline_options_are_named() -> None:
    s = routing_settings(router="spline", spline_carry_speed="yes")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"spline\.carry_speed"):
        route_spline(
            Start((0.0, 0.0)), Target("mark", (0.0, 300.0)), 0.0, UniformWind(8.0, 270.0), ISO, s
        )
