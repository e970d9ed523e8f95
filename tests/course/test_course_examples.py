"""The shipped example courses (courses/*.yaml) load, and their specs build when the factories
are present."""

from __future__ import annotations

import importlib.util
from datetime import datetime, timedelta, timezone

import pytest

from sailroute.course.geometry import nominal_wind_modes, race_time_window
from sailroute.course.load import load_course, validate_specs
from sailroute.timeutil import to_epoch
from tests.conftest import ROOT

COURSES = sorted((ROOT / "courses").glob("*.yaml"))


def test_expected_examples_are_shipped():
    names = {p.name for p in COURSES}
    assert {
        "hyeres-r1.yaml",
        "trieste-coach-wl.yaml",
        "windward-leeward-template.yaml",
        "trapezoid-outer-template.yaml",
    } <= names


@pytest.mark.parametrize("path", COURSES, ids=lambda p: p.stem)
def test_example_loads(path):
    c = load_course(path)
    assert c.n_legs >= 2 and c.scenarios
    if path.stem.startswith("snipe-"):  # analysis example: the sailor noted only two marks
        assert c.legs[0].from_name == "S1" and c.legs[-1].to_name == "S1"
    else:
        assert c.legs[0].from_name == "start" and c.legs[-1].kind == "line"


@pytest.mark.parametrize("path", COURSES, ids=lambda p: p.stem)
def test_example_specs_build(path):
    if importlib.util.find_spec("sailroute.boat.build") is None or (
        importlib.util.find_spec("sailroute.wind.build") is None
    ):
        pytest.skip("boat/wind factories not available")
    c = load_course(path)  # a data file that is missing is reported here, at load
    validate_specs(c)  # raises InputError / OutOfCoverageError listing every problem


def test_trieste_course_lies_within_the_coach_log():
    # data/README (source): positions 45.535..45.574 N, 13.641..13.700 E, 10:34:58..11:48:03 local
    # (CET, UTC+01:00).  The course and its race window must lie inside, or the wind would be
    # extrapolated (the thesis's main failure).
    c = load_course(ROOT / "courses" / "trieste-coach-wl.yaml")
    for m in c.marks.values():
        assert 45.535 < m.lat < 45.574 and 13.641 < m.lon < 13.700, m
    cet = timezone(timedelta(hours=1))
    t0, t1 = race_time_window(c)
    assert t0 >= to_epoch(datetime(2018, 2, 15, 10, 34, 58, tzinfo=cet))
    assert t1 <= to_epoch(datetime(2018, 2, 15, 11, 48, 3, tzinfo=cet))
    assert nominal_wind_modes(c, 65.0) == ("upwind", "downwind", "upwind", "downwind")
