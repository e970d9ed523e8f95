"""Bearings, wind modes (thesis eq 4.64), time windows (eqs 4.65-4.67), bounding box."""

from __future__ import annotations

from datetime import datetime, timedelta, timezone

import pytest

from sailroute.course.geometry import (
    course_bbox,
    leg_wind_mode,
    omega_deg,
    race_time_window,
    thesis_time_window,
    wind_mode,
    xy_bearing_deg,
)
from sailroute.course.load import load_course
from sailroute.timeutil import to_epoch
from sailroute.wind.uniform import UniformWind
from tests.conftest import TESTS_DATA

CEST = timezone(timedelta(hours=2))


@pytest.mark.parametrize(
    ("dx", "dy", "bearing"),
    [(0, 1, 0.0), (1, 0, 90.0), (0, -1, 180.0), (-1, 0, 270.0), (1, 1, 45.0), (-1, 1, 315.0)],
)
def test_leg_bearing_is_compass(dx, dy, bearing):
    assert xy_bearing_deg((10.0, 20.0), (10.0 + dx, 20.0 + dy)) == pytest.approx(bearing)


@pytest.mark.parametrize(
    ("bearing", "twd", "mode"),
    [
        (108.0, 108.0, "upwind"),
        (153.0, 108.0, "upwind"),  # Ω = 45 exactly: upwind (≤ 45)
        (63.0, 108.0, "upwind"),
        (153.1, 108.0, "reach"),
        (243.0, 108.0, "downwind"),  # Ω = 135 exactly: downwind (≥ 135)
        (242.9, 108.0, "reach"),
        (288.0, 108.0, "downwind"),
        (350.0, 10.0, "upwind"),  # across north
        (190.0, 10.0, "downwind"),
        (100.0, 10.0, "reach"),
    ],
)
def test_wind_mode_boundaries(bearing, twd, mode):
    assert wind_mode(bearing, twd) == mode


def test_omega_is_symmetric_and_bounded():
    assert float(omega_deg(10.0, 350.0)) == pytest.approx(20.0)
    assert float(omega_deg(350.0, 10.0)) == pytest.approx(20.0)
    assert float(omega_deg(0.0, 180.0)) == pytest.approx(180.0)


def test_leg_wind_mode_samples_the_wind_at_start():
    wind = UniformWind(5.0, 270.0)  # from the west
    assert leg_wind_mode(wind, 0.0, (0.0, 0.0), (-100.0, 0.0)) == "upwind"
    assert leg_wind_mode(wind, 0.0, (0.0, 0.0), (100.0, 0.0)) == "downwind"
    assert leg_wind_mode(wind, 0.0, (0.0, 0.0), (0.0, 100.0)) == "reach"


@pytest.mark.parametrize(
    ("start", "lo", "hi"),
    [
        # thesis eqs 4.68-4.70: a 13:25 start gives [11:00, 18:00]
        (
            datetime(2018, 4, 24, 13, 25, tzinfo=CEST),
            datetime(2018, 4, 24, 11, 0, tzinfo=CEST),
            datetime(2018, 4, 24, 18, 0, tzinfo=CEST),
        ),
        # eq 5.1: a 12:00 start gives [10:00, 16:00]
        (
            datetime(2018, 4, 24, 12, 0, tzinfo=CEST),
            datetime(2018, 4, 24, 10, 0, tzinfo=CEST),
            datetime(2018, 4, 24, 16, 0, tzinfo=CEST),
        ),
    ],
)
def test_thesis_time_window(start, lo, hi):
    t0, t1 = thesis_time_window(to_epoch(start))
    assert (t0, t1) == (to_epoch(lo), to_epoch(hi))
    if start.minute == 25:
        assert round((t1 - t0) / 600) + 1 == 43  # "43 of the 145 ten-minute slices"


def test_race_window_and_bbox():
    c = load_course(TESTS_DATA / "course" / "minimal.yaml")
    t0, t1 = race_time_window(c)
    assert t0 == c.start_epoch and t1 - t0 == 90 * 60.0
    x0, x1, y0, y1 = course_bbox(c)
    xs = [m.x for m in c.marks.values()]
    ys = [m.y for m in c.marks.values()]
    assert (x0, x1, y0, y1) == (min(xs), max(xs), min(ys), max(ys))
    assert course_bbox(c, 100.0) == (x0 - 100.0, x1 + 100.0, y0 - 100.0, y1 + 100.0)
