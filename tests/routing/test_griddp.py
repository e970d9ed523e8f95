"""Layered-grid DP router: analytic legs, exactness on the grid, refinement, time, errors."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from sailroute.boat.dynamic import DynamicBoat
from sailroute.boat.polar import Polar
from sailroute.errors import InputError, RoutingError
from sailroute.routing._dp_grid import GridBoat, make_grid
from sailroute.routing.geometry import target_geometry
from sailroute.routing.griddp import evaluate_path, route_griddp, solve_griddp
from sailroute.routing.settings import RoutingSettings, routing_settings
from sailroute.routing.types import Start, Target
from sailroute.wind.analytic import debski_test_wind
from sailroute.wind.uniform import UniformWind

BOAT = DynamicBoat()
TOY_POLAR = BOAT.steady_polar(np.arange(0.0, 61.0, 2.0), twa_step=1.0)
# 0.3 TWS for every TWA >= 40°: the straight line is the unique optimum of any reach
ISO = Polar.from_arrays(
    np.array([0.0, 40.0, 180.0]),
    np.array([0.0, 20.0]),
    np.array([[0.0, 0.0], [0.0, 6.0], [0.0, 6.0]]),
    interpolation="linear",
)
A = Start((0.0, 0.0), name="A")


def settings(**kw: object) -> RoutingSettings:
    base = dict(router="griddp", dp_cols=17, dp_rows=9, dp_refinements=1)
    base.update(kw)
    return routing_settings(**base)  # type: ignore[arg-type]


def test_reach_in_uniform_wind_is_straight_and_exact() -> None:
    # wind from the west, leg north: TWA 90 on port; odd C puts a node on the axis
    wind = UniformWind(8.0, 270.0)
    r = route_griddp(
        A, Target("line", (-20.0, 400.0), (20.0, 400.0)), 0.0, wind, ISO, settings(dp_cols=33)
    )
    assert r.router == "griddp"
    assert r.time_s == pytest.approx(400.0 / 2.4, rel=1e-12)
    assert np.allclose(r.track.x, 0.0, atol=1e-9)
    assert r.n_tacks == 0 and r.n_gybes == 0
    assert r.end_xy == pytest.approx((0.0, 400.0))
    assert np.all(r.track.twa_deg == pytest.approx(-90.0))


@pytest.mark.parametrize("boat", [TOY_POLAR, BOAT], ids=["polar", "dynamic"])
def test_upwind_leg_tends_to_vmg_bound(boat: Polar | DynamicBoat) -> None:
    # dead upwind to a mark (rounding segment perpendicular to the wind): the optimum
    # is L / VMG* plus one manoeuvre: 5 s penalty (polar) or two restarts from rest
    # (dynamic: the start and the tack, each the from-rest loss Λ(β*, 0)/v_t)
    wind = UniformWind(12.0, 0.0)
    tgt = Target("mark", (0.0, 500.0), rounding="port")
    if isinstance(boat, Polar):
        bound = 500.0 / float(boat.vmg_upwind(12.0)[1]) + 5.0
    else:
        ang, vmg = boat.best_vmg()
        t100 = float(boat.segment(100.0, ang, 12.0, 0.0)[0])
        loss = t100 - 100.0 / float(boat.steady_speed(12.0, ang))
        bound = 500.0 / (12.0 * vmg) + 2.0 * loss
    errs = []
    for cols, ref in [(33, 0), (33, 3), (65, 3)]:
        r = route_griddp(
            A, tgt, 0.0, wind, boat, settings(dp_cols=cols, dp_rows=13, dp_refinements=ref)
        )
        assert r.n_tacks == 1
        errs.append(r.time_s - bound)
    # the polar bound is a true lower bound (any grid path is a feasible route); the
    # dynamic estimate assumes the VMG angle exactly, hence the small slack
    assert min(errs) > (-1e-9 if isinstance(boat, Polar) else -0.02)
    assert errs[1] < errs[0] and errs[2] <= errs[1] + 1e-9
    assert errs[2] < 0.05  # measured: 0.02 s (polar), 0.013 s (dynamic)


def test_mesh_convergence_reproduces_the_paper() -> None:
    # Dębski (2016): 12 m/s wind 5° off the leg axis, 800 m x 500 m, B a point (1 cm
    # rounding segment here), one pass.  With R = 30 rows (the paper does not state
    # its row count) our t_f are 655.6, 405.2, 357.4 s for C = 16, 32, 64 against the
    # paper's 655.36, 411.25, 357.85 s; asserted within 2 %.  Times fall with C
    # towards the bound L cos5°/VMG* (plus the momentum lost at the start and tack)
    wind = UniformWind(12.0, 5.0)
    tgt = Target("mark", (0.0, 500.0))
    times = [
        solve_griddp(
            A,
            tgt,
            0.0,
            wind,
            BOAT,
            settings(
                dp_cols=c,
                dp_rows=30,
                dp_refinements=0,
                dp_half_width_m=400.0,
                dp_samples=1,
                zone_m=0.01,
            ),
        ).result.time_s
        for c in (16, 32, 64)
    ]
    assert times == pytest.approx([655.36, 411.25, 357.85], rel=0.02)
    bound = 500.0 * math.cos(math.radians(5.0)) / (12.0 * BOAT.best_vmg()[1])
    assert bound < times[2] < times[1] < times[0]


def _brute_force(boat: Polar | DynamicBoat, wind, tgt: Target, s: RoutingSettings) -> float:
    grid = make_grid(A, tgt, s.griddp.rows, s.zone_m)
    half = s.griddp.half_width_m
    xy = [row.points(grid.frame, row.initial(s.griddp.cols, half)) for row in grid.rows]
    model = GridBoat.of(boat, "test")
    best = math.inf
    for path in itertools.product(*[range(p[0].size) for p in xy]):
        xs = np.array([xy[r][0][c] for r, c in enumerate(path)])
        ys = np.array([xy[r][1][c] for r, c in enumerate(path)])
        best = min(
            best,
            evaluate_path(model, wind, xs, ys, 0.0, s.griddp.samples, s, limits=grid.limits).time_s,
        )
    return best


@pytest.mark.parametrize("boat", [TOY_POLAR, BOAT], ids=["polar", "dynamic"])
@pytest.mark.parametrize("case", ["uniform", "debski"])
def test_dp_equals_brute_force_on_a_small_grid(boat: Polar | DynamicBoat, case: str) -> None:
    # every node path enumerated and sailed exactly: the DP optimum must be the minimum
    # (principle of optimality; the dynamic state carries the end speed)
    if case == "uniform":
        wind, tgt = UniformWind(8.0, 10.0), Target("mark", (30.0, 300.0))
    else:
        wind, tgt = debski_test_wind(), Target("mark", (500.0, 0.0))
    s = settings(
        dp_cols=4,
        dp_rows=5,
        dp_refinements=0,
        dp_half_width_m=150.0,
        tack_penalty_s=4.0,
        gybe_penalty_s=2.0,
    )
    sol = solve_griddp(A, tgt, 0.0, wind, boat, s)
    brute = _brute_force(boat, wind, tgt, s)
    assert sol.passes[0].dp_time_s == pytest.approx(brute, rel=1e-12)
    assert sol.result.time_s == pytest.approx(brute, rel=1e-12)


@pytest.mark.parametrize("boat", [TOY_POLAR, BOAT], ids=["polar", "dynamic"])
def test_refinement_never_gets_worse(boat: Polar | DynamicBoat) -> None:
    s = settings(dp_cols=24, dp_rows=11, dp_refinements=4, dp_half_width_m=400.0)
    sol = solve_griddp(A, Target("mark", (500.0, 0.0)), 0.0, debski_test_wind(), boat, s)
    times = [p.time_s for p in sol.passes]
    assert all(b <= a + 1e-9 for a, b in itertools.pairwise(times))
    assert times[-1] < times[0]
    assert sol.result.time_s == pytest.approx(min(times))
    spacing = [p.node_spacing_m for p in sol.passes]
    assert spacing[1] == pytest.approx(spacing[0] / 2)  # dp_shrink 0.5 halves the spacing


def test_runs_are_deterministic() -> None:
    s = settings(dp_cols=20, dp_rows=9, dp_refinements=2, dp_half_width_m=400.0)
    tgt = Target("mark", (500.0, 0.0))
    r1 = route_griddp(A, tgt, 0.0, debski_test_wind(), BOAT, s)
    r2 = route_griddp(A, tgt, 0.0, debski_test_wind(), BOAT, s)
    for name in ("t", "x", "y", "bsp_ms", "side"):
        assert np.array_equal(getattr(r1.track, name), getattr(r2.track, name))


def test_later_start_sees_later_wind() -> None:
    wind = UniformWind(
        [8.0, 4.0], [270.0, 270.0], times=[0.0, 100.0], interpolation="previous", clamp=True
    )
    tgt = Target("line", (-20.0, 400.0), (20.0, 400.0))
    early = route_griddp(A, tgt, -1000.0, wind, ISO, settings())
    late = route_griddp(A, tgt, 200.0, wind, ISO, settings())
    assert early.time_s == pytest.approx(400.0 / 2.4, rel=1e-12)
    assert late.time_s == pytest.approx(400.0 / 1.2, rel=1e-12)
    assert late.t_start == 200.0 and late.t_end == pytest.approx(200.0 + 400.0 / 1.2)
    # the wind drops mid-leg: 50 s at 2.4 m/s, then 280 m at 1.2 m/s; pieces of
    # 400/24/16 m take at most 0.87 s, which bounds the timing error of the switch
    mid = route_griddp(A, tgt, 50.0, wind, ISO, settings(dp_rows=25, dp_samples=16))
    assert mid.time_s == pytest.approx(50.0 + 280.0 / 1.2, abs=0.87)


def test_start_line_reports_best_start_point() -> None:
    # isotropic reach: any path straight north between the lines is optimal
    wind = UniformWind(8.0, 270.0)
    line = Start((-50.0, 0.0), (150.0, 0.0))
    r = route_griddp(
        line,
        Target("line", (-20.0, 300.0), (20.0, 300.0)),
        0.0,
        wind,
        ISO,
        settings(dp_cols=33, dp_refinements=3),
    )
    assert r.time_s == pytest.approx(300.0 / 2.4, rel=1e-4)
    assert r.start_xy[1] == 0.0 and -20.0 <= r.start_xy[0] <= 20.0
    assert abs(r.start_xy[0] - r.end_xy[0]) < 2.0


@pytest.mark.parametrize("rounding", ["port", "starboard"])
def test_mark_rounding_side(rounding: str) -> None:
    # leg north to a mark: the route ends on the rounding segment on the correct side
    wind = UniformWind(8.0, 270.0)
    tgt = Target("mark", (0.0, 300.0), rounding=rounding)  # type: ignore[arg-type]
    r = route_griddp(A, tgt, 0.0, wind, ISO, settings())
    geom = target_geometry(tgt, A)
    ex, ey = geom.b[0] - geom.a[0], geom.b[1] - geom.a[1]
    fx, fy = r.end_xy[0] - geom.a[0], r.end_xy[1] - geom.a[1]
    assert abs(ex * fy - ey * fx) < 1e-9  # on the segment's line
    u = (ex * fx + ey * fy) / (ex * ex + ey * ey)
    assert 0.0 < u <= 1.0
    assert (r.end_xy[0] > 0) == (rounding == "port")  # leaving it to port: pass east


def test_gate_target_ends_between_the_marks() -> None:
    wind = UniformWind(8.0, 0.0)  # downwind leg south to a gate
    tgt = Target("gate", (-30.0, -400.0), (30.0, -400.0))
    r = route_griddp(A, tgt, 0.0, wind, TOY_POLAR, settings(dp_cols=21, dp_rows=11))
    assert r.end_xy[1] == pytest.approx(-400.0)
    assert -30.0 < r.end_xy[0] < 30.0
    # downwind: gybing on the VMG angle beats running dead downwind for this boat?
    run = 400.0 / float(TOY_POLAR.speed(8.0, 180.0))
    assert r.time_s <= run + 1e-9


def test_route_stays_inside_wind_coverage() -> None:
    # the analytic field covers |y| <= 400 m; a wider grid must not leave it
    s = settings(dp_cols=21, dp_rows=9, dp_half_width_m=600.0)
    r = route_griddp(A, Target("mark", (500.0, 0.0)), 0.0, debski_test_wind(), TOY_POLAR, s)
    assert np.all(np.abs(r.track.y) <= 400.0)


def test_track_is_consistent() -> None:
    s = settings(dp_cols=20, dp_rows=9, dp_half_width_m=400.0, tack_penalty_s=7.0)
    r = route_griddp(A, Target("mark", (500.0, 0.0)), 100.0, debski_test_wind(), TOY_POLAR, s)
    tr = r.track
    assert tr.t[0] == 100.0 and tr.t[-1] == r.t_end
    assert np.all(np.diff(tr.t) >= 0)
    # every side change is a manoeuvre that stopped the boat for its penalty
    stops = np.flatnonzero((np.diff(tr.t) > 0) & (np.hypot(np.diff(tr.x), np.diff(tr.y)) == 0))
    assert len(stops) == r.n_tacks + r.n_gybes
    for i in stops:
        assert tr.t[i + 1] - tr.t[i] == pytest.approx(7.0 if r.n_tacks else 3.0)


def test_calm_wind_gives_routing_error() -> None:
    with pytest.raises(RoutingError, match="no feasible path"):
        route_griddp(A, Target("mark", (0.0, 300.0)), 0.0, UniformWind(0.0, 0.0), ISO, settings())


@pytest.mark.parametrize(
    ("kw", "key"),
    [
        (dict(dp_cols=1), r"griddp\.cols"),
        (dict(dp_shrink=0.0), r"griddp\.shrink"),
        (dict(dp_half_width_m=-5.0), r"griddp\.half_width_m"),
        (dict(dp_samples=0), r"griddp\.samples"),
        (dict(tack_penalty_s=-1.0), "tack_penalty_s"),
    ],
)
def test_invalid_settings(kw: dict, key: str) -> None:
    with pytest.raises(InputError, match=key):
        route_griddp(
            A, Target("mark", (0.0, 300.0)), 0.0, UniformWind(8.0, 270.0), ISO, settings(**kw)
        )


def test_wrong_boat_type() -> None:
    with pytest.raises(InputError, match="Polar or a DynamicBoat"):
        route_griddp(
            A, Target("mark", (0.0, 300.0)), 0.0, UniformWind(8.0, 270.0), "laser", settings()
        )  # type: ignore[arg-type]


def test_progress_is_reported_up_to_one() -> None:
    seen: list[float] = []
    route_griddp(
        A,
        Target("mark", (0.0, 300.0)),
        0.0,
        UniformWind(8.0, 270.0),
        ISO,
        settings(),
        progress=seen.append,
    )
    assert seen[-1] == 1.0 and all(0.0 <= f <= 1.0 for f in seen)
    assert all(b >= a for a, b in itertools.pairwise(seen))


@pytest.mark.timing
@pytest.mark.slow
def test_c128_dynamic_finishes_in_seconds() -> None:
    # the paper needed 874 s (serial C) and 21 s (GPU) for C = 128; one pass here
    # takes ~1.0 s on one core (benchmarks/bench_griddp.py); bound generously
    import time

    s = settings(dp_cols=128, dp_rows=13, dp_refinements=0, dp_half_width_m=400.0)
    tic = time.perf_counter()
    sol = solve_griddp(A, Target("mark", (0.0, 500.0)), 0.0, UniformWind(12.0, 5.0), BOAT, s)
    assert time.perf_counter() - tic < 30.0
    # from the start point: 128 segments, then 128² triples, then 10 rows of 128³
    assert sol.passes[0].segment_evals == 128 + 128**2 + 10 * 128**3


def test_gpu_code_path_matches_numpy() -> None:
    # CuPy is not available here; an array module that is not ``numpy`` itself takes
    # the GPU code path (whole-row batches, ``xp.take`` gathers) and must agree
    import types

    fake = types.ModuleType("numpy")
    fake.__dict__.update({k: v for k, v in np.__dict__.items() if not k.startswith("__")})
    s = settings(dp_cols=16, dp_rows=9, dp_refinements=1, dp_half_width_m=400.0)
    tgt = Target("mark", (500.0, 0.0))
    for boat in (BOAT, TOY_POLAR):
        a = route_griddp(A, tgt, 0.0, debski_test_wind(), boat, s)
        b = route_griddp(A, tgt, 0.0, debski_test_wind(), boat, s, xp=fake)
        assert b.time_s == pytest.approx(a.time_s, rel=1e-12)
        assert np.allclose(a.track.x, b.track.x) and np.allclose(a.track.y, b.track.y)


def test_max_leg_time_is_enforced() -> None:
    with pytest.raises(RoutingError, match="max_leg_time_s"):
        route_griddp(
            A,
            Target("mark", (0.0, 300.0)),
            0.0,
            UniformWind(8.0, 270.0),
            ISO,
            settings(max_leg_time_s=60.0),
        )
