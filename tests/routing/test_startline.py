"""Start line numbers and the approach to the line against closed forms.

Geometry: wind from the north (TWD 0°) unless said otherwise, so "upwind" is +y, a
square line runs east-west, and looking upwind the east end is the starboard end.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sailroute.routing.startline import (
    SQUARE_TOL_DEG,
    line_approach,
    line_bias_deg,
    ray_segment_distance,
    start_line_numbers,
)
from sailroute.wind.uniform import UniformWind
from tests.routing.polars import laser_like_polar

POLAR = laser_like_polar()
TWS = 5.0
T_GUN = 1_700_000_000.0


def rotated_line(length: float, rot_deg: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """A line of ``length`` centred on the origin, square to a north wind when
    ``rot_deg = 0``, turned anticlockwise by ``rot_deg`` (its east end moves north).
    Returns (west end, east end)."""
    h = 0.5 * length
    c, s = math.cos(math.radians(rot_deg)), math.sin(math.radians(rot_deg))
    return (-h * c, -h * s), (h * c, h * s)


def test_square_line_has_no_bias_and_no_favoured_end():
    west, east = rotated_line(300.0, 0.0)
    sl = start_line_numbers(west, east, UniformWind(TWS, 0.0), POLAR, T_GUN, names=("pin", "boat"))
    assert sl.length_m == pytest.approx(300.0, abs=1e-9)
    assert sl.bias_deg == pytest.approx(0.0, abs=1e-9)
    assert sl.favoured_end is None and sl.favoured_xy is None
    assert sl.gain_m == 0.0 and sl.gain_s == 0.0
    assert sl.starboard_end == "boat" and sl.port_end == "pin"  # east is right looking north
    assert sl.bias_min_deg == pytest.approx(0.0, abs=1e-9)
    assert sl.bias_max_deg == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("b", [3.0, 7.5, -4.0, -12.0])
def test_rotated_line_bias_favoured_end_and_gain(b):
    """Turning the line by b (east end up for b > 0) gives bias b; the upwind end is
    favoured by L sin|b| metres, L sin|b| / VMG* seconds."""
    length = 400.0
    west, east = rotated_line(length, b)
    sl = start_line_numbers(west, east, UniformWind(TWS, 0.0), POLAR, T_GUN, names=("pin", "boat"))
    assert sl.bias_deg == pytest.approx(b, abs=1e-9)
    upwind_end = "boat" if east[1] > west[1] else "pin"
    assert sl.favoured_end == upwind_end
    assert sl.favoured_side == ("starboard" if b > 0 else "port")
    gain = length * math.sin(math.radians(abs(b)))
    assert sl.gain_m == pytest.approx(gain, rel=1e-12)
    # the gain is the difference of the ends' upwind coordinates
    assert sl.gain_m == pytest.approx(abs(east[1] - west[1]), rel=1e-12)
    _, vmg = POLAR.vmg_upwind(TWS)
    assert sl.vmg_ms == pytest.approx(float(vmg), rel=1e-9)
    assert sl.gain_s == pytest.approx(gain / float(vmg), rel=1e-9)


def test_bias_is_independent_of_end_order_and_wind_direction():
    """The same line in the same relative wind: swapping a and b or turning the whole
    picture changes neither the bias nor which mark is favoured."""
    west, east = rotated_line(250.0, 6.0)
    for twd in (0.0, 90.0, 233.0):
        rot = np.radians(-twd)  # turn the picture clockwise by twd (compass)

        def turn(p, rot=rot):
            return (
                p[0] * math.cos(rot) - p[1] * math.sin(rot),
                p[0] * math.sin(rot) + p[1] * math.cos(rot),
            )

        w, e = turn(west), turn(east)
        wind = UniformWind(TWS, twd)
        one = start_line_numbers(w, e, wind, POLAR, T_GUN, names=("pin", "boat"))
        two = start_line_numbers(e, w, wind, POLAR, T_GUN, names=("boat", "pin"))
        assert one.bias_deg == pytest.approx(6.0, abs=1e-9)
        assert two.bias_deg == pytest.approx(6.0, abs=1e-9)
        assert one.favoured_end == two.favoured_end == "boat"


def test_nearly_square_line_is_square():
    west, east = rotated_line(300.0, 0.5 * SQUARE_TOL_DEG)
    assert start_line_numbers(west, east, UniformWind(TWS, 0.0), POLAR, T_GUN).favoured_end is None


def test_bias_range_over_the_five_minutes_before_the_gun():
    """The wind veers linearly from 350° to 0° over the last five minutes: the bias of a
    square line runs from −10° (port end up) to 0."""
    wind = UniformWind([TWS, TWS], [350.0, 0.0], times=[T_GUN - 300.0, T_GUN + 600.0])
    west, east = rotated_line(300.0, 0.0)
    sl = start_line_numbers(west, east, wind, POLAR, T_GUN)
    # twd(t_gun) = 350 + 10 * 300/900 (interpolated in u, v: close to linear for 10°)
    twd_gun = float(np.degrees(np.arctan2(*(-np.array(wind.sample(T_GUN, 0.0, 0.0))))) % 360)
    assert sl.twd_deg == pytest.approx(twd_gun, abs=1e-9)
    assert sl.bias_deg == pytest.approx(twd_gun - 360.0, abs=1e-9)
    assert sl.bias_min_deg == pytest.approx(-10.0, abs=1e-6)
    assert sl.bias_max_deg == pytest.approx(sl.bias_deg, abs=1e-9)
    assert sl.window_s == 300.0


def test_bias_range_is_cut_to_the_wind_coverage():
    wind = UniformWind([TWS, TWS], [0.0, 0.0], times=[T_GUN - 60.0, T_GUN + 600.0])
    west, east = rotated_line(300.0, 0.0)
    assert start_line_numbers(west, east, wind, POLAR, T_GUN).window_s == 60.0


def test_line_bias_sign_convention():
    """Wind from 090°: looking upwind (east) the south end is the starboard end; a line
    whose south end lies further east (upwind) has a positive bias."""
    bias, b_is_starboard = line_bias_deg((0.0, 100.0), (10.0, -100.0), 90.0)
    assert b_is_starboard  # b (south) is the starboard end
    assert float(bias) == pytest.approx(math.degrees(math.atan2(10.0, 200.0)), abs=1e-9)


# --- the approach to the line -----------------------------------------------------------


def test_ray_segment_distance_hits_and_misses():
    d, f = ray_segment_distance((0.0, -100.0), [0.0, 45.0, 180.0], (-50.0, 0.0), (50.0, 0.0))
    assert d[0] == pytest.approx(100.0) and f[0] == pytest.approx(0.5)
    assert np.isinf(d[1])  # 45°: passes x = 100 at the line, beyond its end
    assert np.isinf(d[2]) and np.isnan(f[2])  # away from the line


@pytest.mark.parametrize("d", [60.0, 150.0])
def test_time_to_line_close_hauled_from_straight_downwind(d):
    """From a point d below the middle of a long square line, close-hauled on either tack
    the path is d / cos(TWA*) long and takes that over the polar speed at TWA*."""
    west, east = rotated_line(2000.0, 0.0)
    ap = line_approach(
        (0.0, -d),
        T_GUN - 120.0,
        west,
        east,
        UniformWind(TWS, 0.0),
        POLAR,
        T_GUN,
        names=("pin", "boat"),
    )
    twa, _ = POLAR.vmg_upwind(TWS)
    twa = float(twa)
    path = d / math.cos(math.radians(twa))
    speed = float(POLAR.speed(TWS, twa))
    assert ap.distance_m == pytest.approx(d, abs=1e-9)
    assert not ap.course_side
    star, port = ap.close_hauled
    assert (star.tack, port.tack) == ("starboard", "port")
    assert star.heading_deg == pytest.approx(360.0 - twa, abs=1e-9)  # wind over the right
    assert port.heading_deg == pytest.approx(twa, abs=1e-9)
    for a in (star, port):
        assert a.distance_m == pytest.approx(path, rel=1e-9)
        assert a.time_s == pytest.approx(path / speed, rel=1e-9)
    # the point on the line: d tan(TWA*) west (starboard) or east (port) of the middle
    assert star.point_xy[0] == pytest.approx(-d * math.tan(math.radians(twa)), abs=1e-6)
    assert port.point_xy[0] == pytest.approx(d * math.tan(math.radians(twa)), abs=1e-6)


def test_fastest_approach_and_time_to_burn():
    """The fastest straight course to a long line from below it beats close-hauled (it
    can bear away to a faster angle) and is the minimum of d / (V(θ) cos θ) over θ;
    the time to burn is the time to the gun minus it."""
    d = 100.0
    west, east = rotated_line(4000.0, 0.0)
    ap = line_approach((0.0, -d), T_GUN - 90.0, west, east, UniformWind(TWS, 0.0), POLAR, T_GUN)
    theta = np.linspace(1.0, 89.0, 88_001)
    expected = float(np.min(d / (POLAR.speed(TWS, theta) * np.cos(np.radians(theta)))))
    assert ap.fastest.time_s == pytest.approx(expected, rel=2e-4)  # 0.5° heading scan
    assert ap.fastest.time_s <= min(a.time_s for a in ap.close_hauled)
    assert ap.time_to_gun_s == 90.0
    assert ap.time_to_burn_s == pytest.approx(90.0 - ap.fastest.time_s, abs=1e-12)
    assert {a.tack for a in ap.tacks} == {"starboard", "port"}


def test_straight_to_each_end():
    """Straight to an end: its distance over the polar speed at that heading's TWA."""
    west, east = (-100.0, 0.0), (100.0, 0.0)
    p = (0.0, -100.0)
    ap = line_approach(
        p, T_GUN - 60.0, west, east, UniformWind(TWS, 0.0), POLAR, T_GUN, names=("pin", "boat")
    )
    to_pin, to_boat = ap.to_ends
    assert to_pin.label == "to pin" and to_boat.label == "to boat"
    assert to_pin.heading_deg == pytest.approx(315.0) and to_pin.tack == "starboard"
    assert to_boat.heading_deg == pytest.approx(45.0) and to_boat.tack == "port"
    for a in (to_pin, to_boat):
        assert a.twa_deg == pytest.approx(45.0)
        assert a.time_s == pytest.approx(math.hypot(100, 100) / float(POLAR.speed(TWS, 45.0)))


def test_boat_above_the_line_is_on_the_course_side():
    west, east = rotated_line(300.0, 0.0)
    ap = line_approach((0.0, 50.0), T_GUN - 60.0, west, east, UniformWind(TWS, 0.0), POLAR, T_GUN)
    assert ap.course_side
    assert ap.distance_m == pytest.approx(50.0)
    assert all(not a.reaches for a in ap.close_hauled)  # close-hauled leads away from it
    assert ap.fastest.reaches and ap.fastest.twa_deg > 90.0  # back down to it


def test_wind_outside_its_time_span_is_taken_at_the_edge_with_a_note():
    wind = UniformWind([TWS, TWS], [0.0, 0.0], times=[T_GUN - 60.0, T_GUN + 600.0])
    west, east = rotated_line(300.0, 0.0)
    ap = line_approach((0.0, -100.0), T_GUN - 120.0, west, east, wind, POLAR, T_GUN)
    assert ap.tws_ms == pytest.approx(TWS) and ap.twd_deg == pytest.approx(0.0)
    assert "the wind data cover" in ap.wind_note and "is used" in ap.wind_note
    inside = line_approach((0.0, -100.0), T_GUN - 30.0, west, east, wind, POLAR, T_GUN)
    assert inside.wind_note == ""
    assert inside.fastest.time_s == pytest.approx(ap.fastest.time_s, rel=1e-12)


def test_a_line_of_zero_length_is_refused():
    from sailroute.errors import InputError

    with pytest.raises(InputError, match="both ends are at the same place"):
        start_line_numbers(
            (1.0, 2.0), (1.0, 2.0), UniformWind(TWS, 0.0), POLAR, T_GUN, names=("p", "q")
        )
