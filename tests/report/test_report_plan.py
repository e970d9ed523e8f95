"""Plan assembly and scenario comparison; percent-error convention (model - ref) / ref."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sailroute.errors import InputError
from sailroute.planning.result import compare, make_plan, percent_error
from sailroute.routing.track import build_track, make_leg_result
from sailroute.wind.uniform import UniformWind


def test_plan_chaining_modes_and_start_points(plan, course):
    assert [leg.mode for leg in plan.legs] == ["upwind", "downwind", "reach"]
    assert [(leg.result.n_tacks, leg.result.n_gybes) for leg in plan.legs] == [
        (1, 0),
        (0, 1),
        (0, 0),
    ]
    # started at x = -50 on a line from x = -100 (pin) to 100 (boat): 25 % along
    assert plan.legs[0].start_line_fraction == pytest.approx(0.25)
    # leg 2 starts at mark "top": no line position; leg 3 starts at the gate, x = 10 of -25..25
    assert plan.legs[1].start_line_fraction is None
    assert plan.legs[2].start_line_fraction == pytest.approx(0.7)
    # chained legs: total = arrival - start
    assert plan.total_time_s == pytest.approx(plan.t_end - plan.t_start)
    assert plan.t_start == course.start_epoch
    assert plan.router == "test"
    assert plan.references == {"winner": (700.0, 300.0, 100.0), "model": (650.0, 320.0, 110.0)}


def test_make_plan_needs_one_result_per_leg(course, results):
    with pytest.raises(InputError, match="2 leg results for a course of 3 legs"):
        make_plan(course, "north", results[:2])


def test_percent_error_convention():
    # the thesis's errors recomputed with (model - ref)/ref: WRF 10 min race 3071.97 s vs winner
    # 2941 s is +4.45 % (the thesis printed -4.26 % with the model as denominator), and vs the
    # top-10 average 3010.40 s +2.05 %.
    assert percent_error(3071.97, 2941.0) == pytest.approx(4.453, abs=1e-3)
    assert percent_error(3071.97, 3010.40) == pytest.approx(2.045, abs=1e-3)
    # leg 5: 129.03 s vs the winner's 106 s is +21.7 % (thesis: -17.85 %)
    assert percent_error(129.03, 106.0) == pytest.approx(21.726, abs=1e-3)


def _plan_with_times(course, scenario, times, wind, polar):
    """A plan whose legs take exactly ``times`` [s] (straight two-point tracks)."""
    t = course.start_epoch
    results = []
    for k, dt in enumerate(times):
        tr = build_track([t, t + dt], [0.0, 10.0 * (k + 1)], [0.0, 5.0], wind, polar)
        results.append(make_leg_result(tr, "test"))
        t += dt
    return make_plan(course, scenario, results, wind)


def test_compare_thesis_numbers(course, wind, polar):
    # the thesis's WRF-10-min and constant leg times on a 3-leg stand-in (legs 1-3 of R1)
    a = _plan_with_times(course, "north", [1035.11, 537.38, 834.00], wind, polar)
    b = dataclasses.replace(
        _plan_with_times(course, "north", [1054.24, 518.01, 979.12], wind, polar), scenario="const"
    )
    cmp = compare([a, b])
    assert cmp.scenarios == ("north", "const")
    np.testing.assert_allclose(cmp.totals, [2406.49, 2551.37])
    assert set(cmp.references) == {"winner", "model"}  # shared by both plans
    np.testing.assert_allclose(cmp.delta_s("winner")[0], [335.11, 237.38, 734.0])
    np.testing.assert_allclose(
        cmp.percent("winner")[1], 100 * (np.array([1054.24, 518.01, 979.12]) / [700, 300, 100] - 1)
    )
    assert cmp.total_percent("winner")[0] == pytest.approx(100 * (2406.49 / 1100 - 1))


def test_compare_keeps_scenario_specific_references(course, wind, polar):
    a = _plan_with_times(course, "north", [1.0, 2.0, 3.0], wind, polar)
    b = dataclasses.replace(a, scenario="other", references={"winner": (700.0, 300.0, 100.0)})
    cmp = compare([a, b])
    assert set(cmp.references) == {"winner"}
    assert set(cmp.scenario_references) == {"north"}
    np.testing.assert_allclose(cmp.scenario_references["north"]["model"], [650, 320, 110])


def test_compare_rejects_mismatched_plans(course, wind, polar):
    a = _plan_with_times(course, "north", [1.0, 2.0, 3.0], wind, polar)
    b = dataclasses.replace(a, legs=a.legs[:2])
    with pytest.raises(InputError, match="has 2 legs, expected 3"):
        compare([a, b])
    with pytest.raises(InputError, match="no plans"):
        compare([])


def test_modes_follow_the_wind(course, results):
    # the same tracks in a wind from the south: upwind and downwind swap
    plan = make_plan(course, "north", results, UniformWind(5.0, 180.0))
    assert [leg.mode for leg in plan.legs] == ["downwind", "upwind", "reach"]
    assert make_plan(course, "north", results).legs[0].mode is None
