"""The CuPy backend on a GPU gives the NumPy results (skipped without CuPy and a CUDA device).

CI has no GPU: these run on a machine with one (``python -m pytest -m gpu tests/test_gpu.py``;
``docs/performance.md`` says when they last ran).  Tolerances: the routers do the same
float64 arithmetic in another order of reductions, so leg times agree to 1e-9 relative and
tracks to 1e-6 m; the deadline solver sums each row in SciPy's order with unfused
round-to-nearest operations, so its policy is the same bit for bit.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from sailroute.backend import _cupy_or_none
from sailroute.boat.dynamic import DynamicBoat
from sailroute.boat.io import read_polar
from sailroute.course.load import load_course
from sailroute.planning.route import RunOptions, plan_course
from sailroute.routing.api import route_leg
from sailroute.routing.settings import RoutingSettings, routing_settings
from sailroute.routing.types import Start, Target
from sailroute.strategy.deadline import DeadlineGrid, solve_deadline
from sailroute.units import KNOT
from sailroute.wind.analytic import debski_test_wind
from sailroute.wind.uniform import UniformWind
from tests.strategy.test_strategy_deadline import ENGINE_CASES, SIGMA, SO40, C, model

pytestmark = [
    pytest.mark.gpu,
    pytest.mark.skipif(_cupy_or_none() is None, reason="needs CuPy and a CUDA device"),
]

ROOT = Path(__file__).resolve().parents[1]
POLAR = read_polar(ROOT / "sailroute" / "boat" / "data" / "ilca7.pol")


def _same_leg(a, b) -> None:
    assert b.time_s == pytest.approx(a.time_s, rel=1e-9)
    assert (b.n_tacks, b.n_gybes) == (a.n_tacks, a.n_gybes)
    assert np.allclose(a.track.x, b.track.x, rtol=0, atol=1e-6)
    assert np.allclose(a.track.y, b.track.y, rtol=0, atol=1e-6)


@pytest.mark.parametrize("start", [Start((0.0, 0.0)), Start((-100.0, 0.0), (100.0, 30.0))])
def test_isochrone_on_cupy_is_the_numpy_route(start) -> None:
    wind, tgt = UniformWind(8.5 * KNOT, 10.0), Target("mark", (0.0, 1809.0), rounding="port")
    st = RoutingSettings(tack_penalty_s=6.0)
    a = route_leg(start, tgt, 0.0, wind, POLAR, st)
    b = route_leg(start, tgt, 0.0, wind, POLAR, st, backend="cupy")
    assert a.n_tacks >= 1
    _same_leg(a, b)


@pytest.mark.parametrize("boat", ["dynamic", "polar"])
def test_griddp_on_cupy_is_the_numpy_route(boat) -> None:
    model = DynamicBoat() if boat == "dynamic" else POLAR
    st = routing_settings(
        router="griddp", dp_cols=32, dp_rows=9, dp_refinements=1, dp_half_width_m=400.0
    )
    tgt = Target("mark", (500.0, 0.0))
    a = route_leg(Start((0.0, 0.0)), tgt, 0.0, debski_test_wind(), model, st)
    b = route_leg(Start((0.0, 0.0)), tgt, 0.0, debski_test_wind(), model, st, backend="cupy")
    _same_leg(a, b)


def test_plan_on_cupy_is_the_numpy_plan() -> None:
    course = load_course(ROOT / "courses" / "hyeres-r1.yaml")
    a = plan_course(course, "constant").plan
    b = plan_course(course, "constant", RunOptions(backend="cupy")).plan
    assert b.total_time_s == pytest.approx(a.total_time_s, rel=1e-9)
    for la, lb in zip(a.results, b.results, strict=True):
        _same_leg(la, lb)


def test_plan_round_obstacles_on_cupy_is_the_numpy_plan(tmp_path) -> None:
    """A boundary and ten obstacles (benchmarks/bench_obstacles.py's course, one lap): the
    race-area move test runs on the host from the device's front, the same routes."""
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    import bench_obstacles

    text = bench_obstacles.COURSE.replace("LAPS", "1").replace("ROUTER", "isochrone")
    path = tmp_path / "area.yaml"
    path.write_text(text + bench_obstacles.area_yaml(), encoding="utf-8")
    course = load_course(path)
    a = plan_course(course, "steady").plan
    b = plan_course(course, "steady", RunOptions(backend="cupy")).plan
    assert b.total_time_s == pytest.approx(a.total_time_s, rel=1e-9)
    for la, lb in zip(a.results, b.results, strict=True):
        _same_leg(la, lb)


@pytest.mark.parametrize(
    ("interpolation", "fig", "dtype", "shape"),
    [*ENGINE_CASES, ("linear", (0.05, 46.0, SIGMA), "float32", (100, 128))],
)
def test_deadline_on_cupy_is_the_numpy_policy(interpolation, fig, dtype, shape) -> None:
    a, s_max, sigma = fig
    g = DeadlineGrid(2.0, shape[0], shape[1], 0.1, 0.4, s_max, interpolation=interpolation)
    ref = solve_deadline(SO40, 1.0, model(a, sigma), g, C, engine="numpy", dtype=dtype)
    dev = solve_deadline(SO40, 1.0, model(a, sigma), g, C, engine="cupy", dtype=dtype)
    assert ref.w.max() > 0.5 and (ref.switch.any() or sigma > 1)
    assert np.array_equal(dev.w, ref.w)
    assert np.array_equal(dev.action, ref.action)


def test_strategy_deadline_engine_cupy_gives_the_numpy_probabilities(tmp_path) -> None:
    from sailroute.boat.build import builtin_polar
    from sailroute.strategy.shiftmodel import OUShift
    from sailroute.strategy.study import StrategySettings, run_strategy

    st = StrategySettings(
        deadlines_s=(190.0,),
        n_r=40,
        n_theta=48,
        length_m=400.0,
        half_width_m=200.0,
        lateral_m=4.0,
        runs=300,
        deadline_engine="cupy",
    )
    a = run_strategy(builtin_polar("ilca7"), OUShift(10.0, 600.0), st).summary["deadline"]
    b = run_strategy(
        builtin_polar("ilca7"), OUShift(10.0, 600.0), replace(st, deadline_engine="numpy")
    ).summary["deadline"]
    assert a["engine"] == "cupy"
    assert a["risk_aware"] == b["risk_aware"]
