"""A small routed course for the report tests, built without a router.

Course (local frame around 45 N, 13 E), wind 5 m/s from the north:
start line y = 0 from x = -100 to 100; windward mark "top" at (0, 1000); leeward gate
"gate" (g1, g2) at y = 200, x = ±25; finish line at y = 100, x = 300..340.
Legs: start -> top (upwind, one tack), top -> gate (downwind, one gybe), gate -> finish (reach).
Times come from the polar speed on each segment, so the tracks are physically consistent.
"""

from __future__ import annotations

import numpy as np
import pytest

from sailroute.boat.polar import Polar
from sailroute.course.load import course_from_mapping
from sailroute.planning.result import make_plan
from sailroute.routing.track import build_track, make_leg_result
from sailroute.units import bearing_deg, signed_twa
from sailroute.wind.uniform import UniformWind

COURSE = {
    "name": "report test",
    "start_time": "2024-05-01T12:00:00+02:00",
    "origin": {"lat": 45.0, "lon": 13.0},
    "marks": {
        "pin": {"x": -100, "y": 0},
        "boat": {"x": 100, "y": 0},
        "top": {"x": 0, "y": 1000},
        "g1": {"x": -25, "y": 200},
        "g2": {"x": 25, "y": 200},
        "f1": {"x": 300, "y": 100},
        "f2": {"x": 340, "y": 100},
    },
    "lines": {"start": ["pin", "boat"], "finish": ["f1", "f2"]},
    "gates": {"gate": ["g1", "g2"]},
    "legs": [{"to": "top"}, {"to": "gate"}, {"to": "finish"}],
    "references": {"winner": [700.0, 300.0, 100.0]},
    "scenarios": {
        "north": {
            "wind": {"type": "uniform", "tws_ms": 5.0, "twd_deg": 0.0},
            "references": {"model": [650.0, 320.0, 110.0]},
        }
    },
}

POLAR = Polar.from_arrays(
    np.array([0.0, 40.0, 45.0, 90.0, 135.0, 180.0]),
    np.array([2.0, 5.0, 8.0]),
    np.array(
        [
            [0, 0, 0],
            [1.0, 1.6, 1.9],
            [1.1, 1.8, 2.1],
            [1.6, 2.6, 3.0],
            [1.5, 2.4, 2.9],
            [1.2, 2.0, 2.5],
        ]
    ),
    name="synthetic",
)


def timed_track(points, t0, wind, polar=POLAR):
    """Track through ``points`` starting at ``t0``; segment times from the polar speed."""
    p = np.asarray(points, dtype=float)
    h = bearing_deg(np.diff(p[:, 0]), np.diff(p[:, 1]))
    u, v = wind.sample(t0, p[:-1, 0], p[:-1, 1])
    tws = np.hypot(u, v)
    twd = np.degrees(np.arctan2(-u, -v)) % 360.0
    speed = polar.speed(tws, signed_twa(twd, h))
    dt = np.hypot(np.diff(p[:, 0]), np.diff(p[:, 1])) / speed
    t = t0 + np.concatenate([[0.0], np.cumsum(dt)])
    return build_track(t, p[:, 0], p[:, 1], wind, polar)


@pytest.fixture
def polar():
    return POLAR


@pytest.fixture
def course():
    return course_from_mapping(COURSE)


@pytest.fixture
def wind():
    return UniformWind(5.0, 0.0)


@pytest.fixture
def results(course, wind):
    t0 = course.start_epoch
    # leg 1: from 25% along the start line (x = -50), starboard tack to the left, one tack, fetch
    r1 = make_leg_result(timed_track([(-50, 0), (-550, 500), (0, 1000)], t0, wind), "test")
    # leg 2: broad reach one way, gybe, the other way through the gate at x = 10
    r2 = make_leg_result(timed_track([(0, 1000), (200, 600), (10, 200)], r1.t_end, wind), "test")
    # leg 3: straight reach to the finish line centre
    r3 = make_leg_result(timed_track([(10, 200), (320, 100)], r2.t_end, wind), "test")
    return [r1, r2, r3]


@pytest.fixture
def plan(course, results, wind):
    return make_plan(course, "north", results, wind)
