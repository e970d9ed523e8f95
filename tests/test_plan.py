"""Planning (``sailroute.planning.route``) on the shipped courses: chaining, closed forms, errors.

Tolerances: in uniform wind a leg between two points sailed at the best VMG angle
takes exactly ``(upwind distance) / VMG* + n_tacks * tack_penalty``, whatever the
cross-wind offset (as long as the mark is inside the VMG cone); the isochrone router
reproduces it to < 1e-4 relative (its heading fan contains the VMG angle; the rest
is the arrival interpolation), so 1e-3 leaves margin without hiding a wrong answer
(one heading step of 2° off the VMG angle costs > 2e-3).  A reach is ``L / speed``.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import pickle

import numpy as np
import pytest

from sailroute.commands.plan import run_plan_command
from sailroute.course.load import build_boat, course_from_mapping, load_course
from sailroute.errors import InputError, OutOfCoverageError
from sailroute.planning.route import RunOptions, compare_scenarios, plan_course
from sailroute.units import wrap180
from tests.conftest import COURSES, ROOT


@pytest.fixture(scope="module")
def hyeres():
    return load_course(COURSES / "hyeres-r1.yaml")


@pytest.fixture(scope="module")
def hyeres_constant(hyeres):
    return plan_course(hyeres, "constant")


def upwind_component(res, twd_deg: float) -> float:
    """Displacement of a leg towards the wind [m]."""
    dx = res.end_xy[0] - res.start_xy[0]
    dy = res.end_xy[1] - res.start_xy[1]
    return dx * math.sin(math.radians(twd_deg)) + dy * math.cos(math.radians(twd_deg))


def test_legs_are_chained_in_space_and_time(hyeres, hyeres_constant):
    plan = hyeres_constant.plan
    legs = plan.results
    assert len(legs) == hyeres.n_legs == 5
    assert legs[0].t_start == hyeres.start_epoch
    for prev, nxt in itertools.pairwise(legs):
        assert nxt.t_start == prev.t_end
        assert nxt.start_xy == pytest.approx(prev.end_xy, abs=1e-9)
    assert plan.total_time_s == pytest.approx(legs[-1].t_end - legs[0].t_start, rel=1e-12)
    # each leg starts on the feature it comes from: leg 1 on the start line
    frac = plan.legs[0].start_line_fraction
    assert frac is not None and 0.0 <= frac <= 1.0


def test_constant_wind_matches_closed_forms(hyeres, hyeres_constant):
    boat = build_boat(hyeres)
    tws, twd, pen = 5.61, 108.0, hyeres.routing.tack_penalty_s
    _, vmg = boat.vmg_upwind(tws)
    legs = hyeres_constant.plan.legs
    assert [leg.mode for leg in legs] == ["upwind", "downwind", "upwind", "downwind", "reach"]
    for i in (0, 2):  # beats: one tack, L_up / VMG* + penalty
        r = legs[i].result
        assert r.n_tacks == 1 and r.n_gybes == 0
        expected = upwind_component(r, twd) / float(vmg) + pen
        assert r.time_s == pytest.approx(expected, rel=1e-3)
    # the reach to the finish: straight, L / polar speed (TWA 91.5°: the race polar's
    # pumping weight and wave share are smoothsteps, so no kink makes a bent route faster)
    r = legs[4].result
    dx, dy = r.end_xy[0] - r.start_xy[0], r.end_xy[1] - r.start_xy[1]
    twa = abs(float(wrap180(math.degrees(math.atan2(dx, dy)) - twd)))
    assert r.n_tacks == r.n_gybes == 0
    assert r.time_s == pytest.approx(math.hypot(dx, dy) / float(boat.speed(tws, twa)), rel=1e-3)


@pytest.mark.parametrize(
    ("course_file", "router"),
    [
        ("windward-leeward-template.yaml", "isochrone"),
        ("hyeres-r1.yaml", "isochrone"),
        ("trapezoid-outer-template.yaml", "griddp"),
    ],
)
def test_every_mark_is_rounded_on_its_side(course_file, router):
    """The track of the two legs meeting at a mark winds round it like the taut string.

    Winding angle of the joined track around the mark, against the string pulled from
    the arrival leg's start round the mark on its side to the next leg's end (see
    tests/routing/test_rounding.py; equal to 1e-6 deg exactly when the mark is on the
    required side).  Routed legs chained by ``plan_course``, where the bug lived.
    """
    from tests.routing.test_rounding import string_winding_deg, winding_deg

    course = load_course(COURSES / course_file)
    legs = plan_course(course, options=RunOptions(router=router)).plan.legs
    checked = 0
    for a, b in itertools.pairwise(legs):
        if a.spec.rounding is None:
            continue
        mark = course.feature(a.spec.to_name).xy
        x = np.concatenate([a.result.track.x, b.result.track.x])
        y = np.concatenate([a.result.track.y, b.result.track.y])
        expected = string_winding_deg((x[0], y[0]), (x[-1], y[-1]), mark, a.spec.rounding)
        assert winding_deg(x, y, mark) == pytest.approx(expected, abs=1e-6), a.spec.label
        checked += 1
    assert checked >= 2


def test_later_legs_see_later_wind():
    """A wind that turns at a known time: the leg sailed after it is a beat, not a reach."""
    course = course_from_mapping(
        {
            "name": "switch",
            "start_time": "2024-05-01T12:00:00Z",
            "origin": {"lat": 45.0, "lon": 13.0},
            "marks": {"a": {"x": 0, "y": 0}, "b": {"x": 0, "y": 600}, "c": {"x": 0, "y": 1200}},
            "legs": [{"from": "a", "to": "b", "rounding": "port"}, {"to": "c", "rounding": "port"}],
            "scenarios": {
                "turn": {
                    "wind": {
                        "type": "uniform",
                        "interpolation": "previous",  # a step change at 12:02:30
                        "table": [
                            {"time": "2024-05-01T12:00:00Z", "tws_ms": 5.0, "twd_deg": 90.0},
                            {"time": "2024-05-01T12:02:30Z", "tws_ms": 5.0, "twd_deg": 0.0},
                            {"time": "2024-05-01T14:00:00Z", "tws_ms": 5.0, "twd_deg": 0.0},
                        ],
                    }
                }
            },
        }
    )
    legs = plan_course(course).plan.legs
    r1, r2 = legs[0].result, legs[1].result
    assert r1.t_end > course.start_epoch + 151  # the first leg is still sailing when it turns
    assert legs[0].mode == "reach" and legs[1].mode == "upwind"
    assert r2.n_tacks == 1


def test_compare_equals_individual_plans(hyeres, hyeres_constant):
    cmp, _plans = compare_scenarios(hyeres, ["constant", "wrf10", "constant"])
    assert cmp.scenarios == ("constant", "wrf10")  # duplicates dropped, order kept
    np.testing.assert_array_equal(cmp.times[0], [leg.time_s for leg in hyeres_constant.plan.legs])
    wrf10 = plan_course(hyeres, "wrf10").plan
    np.testing.assert_array_equal(cmp.times[1], [leg.time_s for leg in wrf10.legs])
    assert set(cmp.references) == {"winner", "top10"}
    np.testing.assert_array_equal(cmp.references["winner"], [984, 500, 871, 480, 106])


def test_course_pickles_for_workers(hyeres):
    back = pickle.loads(pickle.dumps(hyeres))
    assert back.scenarios["wrf10"].wind == hyeres.scenarios["wrf10"].wind
    assert back.scenarios["wrf10"].wind.time_step_s == 600.0  # type: ignore[union-attr]
    np.testing.assert_allclose(
        back.frame.to_latlon(500.0, -300.0),
        hyeres.frame.to_latlon(500.0, -300.0),
        rtol=0,
        atol=1e-12,
    )
    with pytest.raises(TypeError):  # still read-only after the round trip
        back.scenarios["wrf10"].references["x"] = (1.0,)  # type: ignore[index]
    with pytest.raises(dataclasses.FrozenInstanceError):  # the parsed wind spec too
        back.scenarios["wrf10"].wind.time_step_s = 60.0  # type: ignore[misc,union-attr]


def test_bad_names_fail_before_routing(hyeres):
    with pytest.raises(InputError, match=r"no scenario .wrf5.*scenarios are: constant, wrf60"):
        plan_course(hyeres, "wrf5")
    with pytest.raises(InputError, match="unknown router 'fast'"):
        plan_course(hyeres, "constant", RunOptions(router="fast"))
    with pytest.raises(InputError, match="backend 'gpu'"):
        plan_course(hyeres, "constant", RunOptions(backend="gpu"))


def test_wind_not_covering_the_race_is_an_error(tmp_path):
    text = (COURSES / "trieste-coach-wl.yaml").read_text()
    text = text.replace("10:45:00+01:00", "15:45:00+01:00")
    text = text.replace("../data/", str(ROOT / "data") + "/")
    path = tmp_path / "late.yaml"
    path.write_text(text)
    with pytest.raises(OutOfCoverageError) as err:
        run_plan_command(path, scenario="measured", out_dir=tmp_path / "out")
    msg = str(err.value)
    assert "needed:  time 2018-02-15T14:45:00.000Z" in msg
    assert "covered: time 2018-02-15T09:35:30.000Z" in msg
    assert not (tmp_path / "out").exists()  # nothing written on failure


def test_compare_checks_the_scheduler_name_before_building_any_wind(tmp_path):
    text = (COURSES / "trieste-coach-wl.yaml").read_text()
    text = text.replace("10:45:00+01:00", "15:45:00+01:00")  # wind no longer covers it
    text = text.replace("../data/", str(ROOT / "data") + "/")
    path = tmp_path / "late.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match="scheduler 'tcp:/bad': expected 'serial'"):
        compare_scenarios(load_course(path), options=RunOptions(scheduler="tcp:/bad"))
    with pytest.raises(OutOfCoverageError):  # a valid name gets as far as the wind
        compare_scenarios(load_course(path), options=RunOptions(scheduler=" Serial "))
