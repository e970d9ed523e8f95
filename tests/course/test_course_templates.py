"""Course templates: geometry relative to the wind, leg sequences, rotation invariance.

Tolerances: positions are computed with a few trig operations from round inputs, so they are
exact to floating-point rounding; 1e-9 m / 1e-9° is used throughout.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from sailroute.course.geometry import wind_mode, xy_bearing_deg
from sailroute.course.templates import trapezoid, windward_leeward
from sailroute.errors import InputError
from sailroute.units import signed_twa, wrap180

TWDS = [0.0, 37.0, 90.0, 135.0, 180.0, 222.5, 270.0, 333.0]


def mid(layout, a, b):
    pa, pb = layout.marks[a], layout.marks[b]
    return ((pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2)


def cross(u, v):
    return u[0] * v[1] - u[1] * v[0]


def seq(layout):
    return [leg.to for leg in layout.legs]


@pytest.mark.parametrize("twd", TWDS)
def test_windward_leeward_geometry(twd):
    centre = (120.0, -40.0)
    lay = windward_leeward(
        centre,
        twd,
        900.0,
        2,
        gate_width_m=50.0,
        start_line_length_m=200.0,
        start_offset_m=60.0,
        finish_line_length_m=70.0,
    )
    m1 = lay.marks["1"]
    g4 = mid(lay, "4s", "4p")
    # the windward leg goes straight into the wind, with the requested length, about the centre
    assert xy_bearing_deg(g4, m1) == pytest.approx(twd % 360.0, abs=1e-9)
    assert math.dist(g4, m1) == pytest.approx(900.0, abs=1e-9)
    np.testing.assert_allclose(np.add(g4, m1) / 2, centre, atol=1e-9)
    # gate: width, square to the wind, 4p on the right looking upwind (left of a boat running down)
    assert math.dist(lay.marks["4s"], lay.marks["4p"]) == pytest.approx(50.0, abs=1e-9)
    up = (m1[0] - g4[0], m1[1] - g4[1])
    to_4p = (lay.marks["4p"][0] - g4[0], lay.marks["4p"][1] - g4[1])
    assert cross(up, to_4p) < 0  # clockwise from upwind = right
    assert abs(wrap180(xy_bearing_deg(lay.marks["4s"], lay.marks["4p"]) - twd)) == pytest.approx(
        90.0, abs=1e-9
    )
    # start line: length, square to the wind, start_offset below the gate, boat at the right end
    st = mid(lay, "start_pin", "start_boat")
    assert math.dist(lay.marks["start_pin"], lay.marks["start_boat"]) == pytest.approx(200.0)
    assert xy_bearing_deg(st, g4) == pytest.approx(twd % 360.0, abs=1e-9)
    assert math.dist(st, g4) == pytest.approx(60.0, abs=1e-9)
    pin_to_boat = np.subtract(lay.marks["start_boat"], lay.marks["start_pin"])
    assert cross(up, pin_to_boat) < 0
    # leeward finish: shortened line on the start line's centre
    np.testing.assert_allclose(mid(lay, "finish_pin", "finish_boat"), st, atol=1e-9)
    assert math.dist(lay.marks["finish_pin"], lay.marks["finish_boat"]) == pytest.approx(70.0)
    assert lay.lines == {
        "start": ("start_pin", "start_boat"),
        "finish": ("finish_pin", "finish_boat"),
    }
    assert lay.gates == {"4": ("4s", "4p")}


@pytest.mark.parametrize(
    ("laps", "finish", "expected"),
    [
        (1, "leeward", ["1", "finish"]),
        (2, "leeward", ["1", "4", "1", "finish"]),
        (3, "leeward", ["1", "4", "1", "4", "1", "finish"]),
        (2, "windward", ["1", "4", "finish"]),
        (3, "windward", ["1", "4", "1", "4", "finish"]),
    ],
)
def test_windward_leeward_sequences(laps, finish, expected):
    lay = windward_leeward((0.0, 0.0), 0.0, 1000.0, laps, finish=finish)
    assert seq(lay) == expected
    beats = sum(
        1
        for a, b in zip(["start", *expected], expected, strict=False)
        if b in ("1", "finish") and a in ("start", "4")
    )
    assert beats == laps  # laps counts the beats, as in course codes L2, L3
    assert all(leg.rounding == "port" for leg in lay.legs if leg.to == "1")
    assert all(leg.rounding is None for leg in lay.legs if leg.to in ("4", "finish"))


def test_windward_finish_line_beyond_mark_1():
    lay = windward_leeward((0.0, 0.0), 0.0, 1000.0, 2, finish="windward", finish_offset_m=50.0)
    np.testing.assert_allclose(mid(lay, "finish_pin", "finish_boat"), (0.0, 550.0), atol=1e-9)


@pytest.mark.parametrize("twd", TWDS)
@pytest.mark.parametrize("angle", [60.0, 70.0, 110.0])
def test_trapezoid_geometry(twd, angle):
    L = 1200.0
    lay = trapezoid(
        (0.0, 0.0),
        twd,
        L,
        2,
        loop="outer",
        reach_angle_deg=angle,
        gate_width_m=40.0,
        finish_reach_m=250.0,
        finish_line_length_m=60.0,
    )
    m1, m2 = lay.marks["1"], lay.marks["2"]
    g3, g4 = mid(lay, "3s", "3p"), mid(lay, "4s", "4p")
    # reach 1 -> 2: length 2/3 L, at TWA 180 - angle on starboard tack (after a port rounding)
    assert math.dist(m1, m2) == pytest.approx(2 * L / 3, abs=1e-9)
    twa = float(signed_twa(twd, xy_bearing_deg(m1, m2)))
    assert twa == pytest.approx(180.0 - angle, abs=1e-9)
    # run 2 -> 3 dead downwind, and gate 3 level with gate 4 (same distance along the wind axis)
    assert xy_bearing_deg(m2, g3) == pytest.approx((twd + 180.0) % 360.0, abs=1e-9)
    up = (math.sin(math.radians(twd)), math.cos(math.radians(twd)))
    assert np.dot(g3, up) == pytest.approx(np.dot(g4, up), abs=1e-9)
    # 3p on the right looking upwind; finish line 250 m right of gate 3, along the wind
    assert cross(up, np.subtract(lay.marks["3p"], g3)) < 0
    fin = mid(lay, "finish_pin", "finish_boat")
    assert math.dist(g3, fin) == pytest.approx(250.0, abs=1e-9)
    assert xy_bearing_deg(g3, fin) == pytest.approx((twd + 90.0) % 360.0, abs=1e-9)
    assert abs(
        wrap180(xy_bearing_deg(lay.marks["finish_boat"], lay.marks["finish_pin"]) - twd)
    ) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize(
    ("loop", "laps", "expected"),
    [
        ("inner", 1, ["1", "2", "3p", "finish"]),
        ("inner", 2, ["1", "4", "1", "2", "3p", "finish"]),  # course I2
        ("inner", 3, ["1", "4", "1", "4", "1", "2", "3p", "finish"]),
        ("outer", 1, ["1", "2", "3p", "finish"]),
        ("outer", 2, ["1", "2", "3", "2", "3p", "finish"]),  # course O2
        ("outer", 3, ["1", "2", "3", "2", "3", "2", "3p", "finish"]),
    ],
)
def test_trapezoid_sequences(loop, laps, expected):
    lay = trapezoid((0.0, 0.0), 200.0, 1000.0, laps, loop=loop)
    assert seq(lay) == expected
    assert all(leg.rounding == "port" for leg in lay.legs if leg.to in ("1", "2", "3p"))


def test_trapezoid_outer_wind_modes():
    twd = 200.0
    lay = trapezoid((0.0, 0.0), twd, 1000.0, 2, loop="outer")
    pts = dict(lay.marks)
    pts["start"] = mid(lay, "start_pin", "start_boat")
    pts["3"] = mid(lay, "3s", "3p")
    pts["finish"] = mid(lay, "finish_pin", "finish_boat")
    names = ["start", *seq(lay)]
    modes = [wind_mode(xy_bearing_deg(pts[a], pts[b]), twd) for a, b in itertools.pairwise(names)]
    assert modes == ["upwind", "reach", "downwind", "upwind", "downwind", "reach"]


@pytest.mark.parametrize("twd", TWDS)
def test_rotation_invariance(twd):
    base = windward_leeward((0.0, 0.0), 0.0, 800.0, 2)
    rot = windward_leeward((0.0, 0.0), twd, 800.0, 2)
    t = math.radians(twd)
    # compass rotation by twd: (x, y) -> (x cos t + y sin t, -x sin t + y cos t)
    for k, (x, y) in base.marks.items():
        np.testing.assert_allclose(
            rot.marks[k],
            (x * math.cos(t) + y * math.sin(t), -x * math.sin(t) + y * math.cos(t)),
            atol=1e-9,
        )


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: windward_leeward((0, 0), 0, -1.0), "leg_length_m must be > 0"),
        (lambda: windward_leeward((0, 0), 0, 500.0, 0), "laps must be an integer >= 1"),
        (
            lambda: windward_leeward((0, 0), 0, 500.0, 1, finish="windward"),
            "laps must be an integer >= 2 with a windward finish",
        ),
        (lambda: trapezoid((0, 0), 0, 500.0, loop="middle"), "loop must be 'inner' or 'outer'"),
        (lambda: trapezoid((0, 0), 0, 500.0, reach_angle_deg=180.0), "reach_angle_deg"),
        (
            lambda: trapezoid((0, 0), 0, 500.0, reach_angle_deg=10.0, reach_length_m=600.0),
            "mark 2 lies too close to the leeward gates",
        ),
    ],
)
def test_invalid_parameters(call, match):
    with pytest.raises(InputError, match=match):
        call()
