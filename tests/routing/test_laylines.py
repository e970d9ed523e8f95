"""Laylines traced back from a mark: straight at the best-VMG angle in a uniform wind,
turning with the wind where it veers across the course.

The midpoint rule is second order: with 50 steps over 1 km in a wind veering 10° per km
the heading error per step is far below 0.01°, so a tolerance of 0.1° is loose
for the uniform case (exact to rounding) and for the local-heading check.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sailroute.routing.laylines import leg_layline_kind, trace_laylines
from sailroute.units import bearing_deg, wind_components, wrap180
from sailroute.wind.analytic import AnalyticWind
from sailroute.wind.base import Coverage
from sailroute.wind.uniform import UniformWind
from tests.routing.polars import laser_like_polar

POLAR = laser_like_polar()
TWS = 5.0
T = 1_700_000_000.0
MARK = ("1", (200.0, 300.0))


@pytest.mark.parametrize(("kind", "twd"), [("tack", 0.0), ("tack", 108.0), ("gybe", 250.0)])
def test_uniform_wind_laylines_are_straight_at_the_vmg_angle(kind, twd):
    up, down = POLAR.vmg_angles_deg(TWS)
    twa = up if kind == "tack" else down
    star, port = trace_laylines([MARK], T, UniformWind(TWS, twd), POLAR, kind, 1000.0)
    for ll, sign in ((star, 1.0), (port, -1.0)):
        assert ll.mark == "1" and ll.kind == kind
        assert (ll.x[0], ll.y[0]) == MARK[1]
        assert ll.x.size == 51
        assert ll.length_m == pytest.approx(1000.0, rel=1e-9)
        # every point lies on the bearing (heading + 180°) from the mark, heading = TWD ∓ TWA*
        back = bearing_deg(ll.x[1:] - MARK[1][0], ll.y[1:] - MARK[1][1])
        expected = (twd - sign * twa + 180.0) % 360.0
        assert np.abs(wrap180(back - expected)).max() < 0.1
        assert np.abs(wrap180(back - expected)).max() < 1e-6  # in fact exact
        np.testing.assert_allclose(ll.heading_deg, (twd - sign * twa) % 360.0, atol=1e-9)
        # sailing it takes length / V(TWA*): the time runs back from the rounding
        assert T - ll.t[-1] == pytest.approx(1000.0 / float(POLAR.speed(TWS, twa)), abs=1e-4)
    assert star.tack == "starboard" and port.tack == "port"


def veering_wind(k_deg_per_m: float) -> AnalyticWind:
    """Wind of constant speed whose direction is ``k x`` degrees (veers eastwards)."""

    def f(t, x, y):
        return wind_components(np.full(np.shape(x), TWS), k_deg_per_m * np.asarray(x))

    return AnalyticWind(f, name="veering")


def test_laylines_curve_with_a_linearly_veering_wind():
    """TWD = k x, k = 0.01 °/m (10° per km), mark at the origin.  The starboard tack
    layline runs back to the south-east, into wind that has veered: its heading and
    hence its bearing turn clockwise (increase) the further out; the port one runs back
    to the south-west, into backed wind, and turns anticlockwise.  At every step its
    direction is the local heading + 180°."""
    k = 0.01
    up, _ = POLAR.vmg_angles_deg(TWS)
    star, port = trace_laylines([("1", (0.0, 0.0))], T, veering_wind(k), POLAR, "tack", 1000.0)
    for ll, sign in ((star, 1.0), (port, -1.0)):
        seg = bearing_deg(np.diff(ll.x), np.diff(ll.y))
        turn = wrap180(np.diff(seg))
        assert np.all(sign * turn > 0), "turns clockwise (starboard) / anticlockwise (port)"
        xm = 0.5 * (ll.x[1:] + ll.x[:-1])
        local = (k * xm - sign * up + 180.0) % 360.0
        assert np.abs(wrap180(seg - local)).max() < 0.1
        # total turn: the veer between the mark and the far end
        total = float(wrap180(seg[-1] - seg[0]))
        assert total == pytest.approx(k * (xm[-1] - xm[0]), abs=0.05)
        assert ll.length_m == pytest.approx(1000.0, rel=1e-9)
    assert star.x[-1] > 0 > port.x[-1]
    # straight laylines of the wind at the mark would end elsewhere: the curve is real
    straight = (
        1000.0 * math.sin(math.radians(180.0 - up)),
        1000.0 * math.cos(math.radians(180.0 - up)),
    )
    assert math.hypot(star.x[-1] - straight[0], star.y[-1] - straight[1]) > 20.0


def test_gate_laylines_and_coverage_edge():
    """Two gate marks: starboard and port at each, in order; a trace stops at the wind's
    coverage edge (its last point inside)."""
    cover = Coverage(-math.inf, math.inf, -400.0, 400.0, -400.0, 400.0)

    def f(t, x, y):
        return wind_components(np.full(np.shape(x), TWS), np.zeros(np.shape(x)))

    wind = AnalyticWind(f, cover)
    lls = trace_laylines(
        [("4p", (-50.0, 0.0)), ("4s", (50.0, 0.0))], T, wind, POLAR, "gybe", 1000.0
    )
    assert [(ll.mark, ll.tack) for ll in lls] == [
        ("4p", "starboard"),
        ("4p", "port"),
        ("4s", "starboard"),
        ("4s", "port"),
    ]
    for ll in lls:
        assert 0 < ll.length_m < 1000.0
        assert np.all(np.abs(ll.x) <= 400.0) and np.all(np.abs(ll.y) <= 400.0)
        assert ll.heading_deg.size == ll.x.size


def test_leg_kind():
    assert leg_layline_kind("upwind") == "tack"
    assert leg_layline_kind("downwind") == "gybe"
    assert leg_layline_kind("reach") is None and leg_layline_kind(None) is None
