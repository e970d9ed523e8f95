"""Targets and starts as geometry: crossing segments, rounding side, course side, sampling.

All expected values are worked out by hand from the definitions in
``sailroute/routing/geometry.py`` (exact arithmetic; tolerances are float64 round-off).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sailroute.errors import InputError
from sailroute.routing.geometry import (
    TargetGeometry,
    aim_points,
    leg_bearing_deg,
    rounding_segment,
    sample_line,
    segment_crossing,
    start_points,
    target_geometry,
)
from sailroute.routing.types import Start, Target

EPS = 1e-12  # float64 round-off on metre-scale coordinates


def crossing(geom: TargetGeometry, p, q):
    hit, s, r = segment_crossing(
        np.array([p[0]]), np.array([p[1]]), np.array([q[0]]), np.array([q[1]]), geom
    )
    return bool(hit[0]), float(s[0]), float(r[0])


# --- rounding segments ---------------------------------------------------------------


@pytest.mark.parametrize("bearing", [0.0, 45.0, 90.0, 200.0, 333.0])
def test_rounding_segment_is_perpendicular_and_on_the_passing_side(bearing):
    mark = (100.0, -50.0)
    th = math.radians(bearing)
    along = (math.sin(th), math.cos(th))
    right = (math.cos(th), -math.sin(th))  # 90° clockwise from the approach
    a, b = rounding_segment(mark, bearing, "port", 13.0)
    # leaving the mark to port: the boat passes on the mark's right, seen along the leg
    assert a == mark
    d = (b[0] - a[0], b[1] - a[1])
    assert math.hypot(*d) == pytest.approx(13.0, abs=EPS * 100)
    assert d[0] * along[0] + d[1] * along[1] == pytest.approx(0.0, abs=1e-9)
    assert d[0] * right[0] + d[1] * right[1] == pytest.approx(13.0, abs=1e-9)
    a2, b2 = rounding_segment(mark, bearing, "starboard", 13.0)
    assert a2 == mark
    assert (b2[0] - mark[0]) * right[0] + (b2[1] - mark[1]) * right[1] == pytest.approx(
        -13.0, abs=1e-9
    )
    # no side given: 2 zone_m centred on the mark
    a3, b3 = rounding_segment(mark, bearing, None, 13.0)
    assert ((a3[0] + b3[0]) / 2, (a3[1] + b3[1]) / 2) == pytest.approx(mark, abs=1e-9)
    assert math.hypot(b3[0] - a3[0], b3[1] - a3[1]) == pytest.approx(26.0, abs=1e-9)


def test_rounding_segment_rejects_unknown_side():
    with pytest.raises(InputError, match="'prot'"):
        rounding_segment((0.0, 0.0), 0.0, "prot")


def test_mark_passed_on_the_wrong_side_does_not_count():
    # leg north to a mark at (0, 100), to be left to port: pass east of it
    g = target_geometry(Target("mark", (0.0, 100.0), rounding="port"), Start((0.0, 0.0)))
    assert g.normal == pytest.approx((0.0, 1.0), abs=1e-15)
    hit, s, r = crossing(g, (5.0, 90.0), (5.0, 110.0))  # 5 m east: correct side
    assert hit and s == pytest.approx(0.5) and r == pytest.approx(5.0 / 13.0)
    assert not crossing(g, (-5.0, 90.0), (-5.0, 110.0))[0]  # 5 m west: wrong side
    assert not crossing(g, (20.0, 90.0), (20.0, 110.0))[0]  # beyond the 13 m zone
    assert not crossing(g, (5.0, 110.0), (5.0, 90.0))[0]  # backwards
    g2 = target_geometry(Target("mark", (0.0, 100.0), rounding="starboard"), Start((0.0, 0.0)))
    assert crossing(g2, (-5.0, 90.0), (-5.0, 110.0))[0]
    assert not crossing(g2, (5.0, 90.0), (5.0, 110.0))[0]


# --- lines and gates -----------------------------------------------------------------


@pytest.mark.parametrize("kind", ["line", "gate"])
def test_line_is_crossed_from_the_start_side_only(kind):
    # line y = 0 from x = -50 to 50; the leg starts north of it (course side)
    g = target_geometry(Target(kind, (-50.0, 0.0), (50.0, 0.0)), Start((10.0, 300.0)))
    assert g.normal == pytest.approx((0.0, -1.0), abs=1e-15)
    hit, s, r = crossing(g, (10.0, 4.0), (10.0, -6.0))  # southwards through x = 10
    assert hit and s == pytest.approx(0.4) and r == pytest.approx(0.6)
    assert not crossing(g, (10.0, -6.0), (10.0, 4.0))[0]  # from the far side
    assert not crossing(g, (60.0, 4.0), (60.0, -6.0))[0]  # outside the ends
    # same line, start on the other side: the crossing direction flips
    g2 = target_geometry(Target(kind, (-50.0, 0.0), (50.0, 0.0)), Start((0.0, -300.0)))
    assert crossing(g2, (10.0, -6.0), (10.0, 4.0))[0]
    assert not crossing(g2, (10.0, 4.0), (10.0, -6.0))[0]


def test_crossing_ends_inclusive_and_degenerate_moves():
    g = target_geometry(Target("line", (0.0, 0.0), (10.0, 0.0)), Start((5.0, 50.0)))
    # a move ending exactly on the line counts (s = 1); one starting on it going on (s = 0)
    assert crossing(g, (5.0, 2.0), (5.0, 0.0)) == (True, 1.0, 0.5)
    assert crossing(g, (5.0, 0.0), (5.0, -2.0)) == (True, 0.0, 0.5)
    # through an end point
    assert crossing(g, (0.0, 1.0), (0.0, -1.0))[0]
    # a boat that does not move, or moves along the line, crosses nothing
    assert not crossing(g, (5.0, 0.0), (5.0, 0.0))[0]
    assert not crossing(g, (1.0, 0.0), (9.0, 0.0))[0]


def test_crossing_is_vectorised_and_broadcasts():
    g = target_geometry(Target("line", (0.0, 0.0), (10.0, 0.0)), Start((5.0, 50.0)))
    px = np.array([[1.0], [5.0], [20.0]])
    qx = np.array([1.0, 3.0])
    hit, s, r = segment_crossing(px, np.ones((3, 1)), qx, -np.ones(2), g)
    assert hit.shape == (3, 2)
    assert hit.tolist() == [[True, True], [True, True], [False, False]]
    assert s[0, 0] == pytest.approx(0.5) and r[1, 1] == pytest.approx(0.4)
    assert s[2, 0] == 0.0 and r[2, 0] == 0.0  # zeros where not hit


def test_target_geometry_errors():
    with pytest.raises(InputError, match="lies on the line"):
        target_geometry(Target("line", (0.0, 0.0), (10.0, 0.0)), Start((20.0, 0.0)))
    with pytest.raises(InputError, match="ends coincide"):
        target_geometry(Target("gate", (1.0, 1.0), (1.0, 1.0)), Start((0.0, 50.0)))
    with pytest.raises(InputError, match="same point"):
        target_geometry(Target("mark", (3.0, 4.0), rounding="port"), Start((3.0, 4.0)))
    with pytest.raises(InputError, match="zone_m"):
        target_geometry(Target("mark", (3.0, 4.0), rounding="port"), Start((0.0, 0.0)), 0.0)
    with pytest.raises(InputError, match="two ends"):
        target_geometry(Target("line", (0.0, 0.0)), Start((0.0, 50.0)))


def test_leg_bearing_uses_the_start_line_midpoint():
    start = Start((-100.0, 0.0), (100.0, 0.0))
    assert leg_bearing_deg(start, Target("mark", (0.0, 500.0), rounding="port")) == 0.0
    assert leg_bearing_deg(Start((0.0, 0.0)), Target("mark", (-1.0, 0.0))) == pytest.approx(270)


# --- aim points and sampling -----------------------------------------------------------


def test_aim_points_project_and_keep_clear_of_the_ends():
    g = target_geometry(Target("line", (0.0, 0.0), (10.0, 0.0)), Start((5.0, 50.0)))
    ax, ay = aim_points(np.array([4.0, -30.0, 30.0]), np.array([7.0, 5.0, 5.0]), g, 1.0)
    assert ax.tolist() == pytest.approx([4.0, 1.0, 9.0])
    assert ay.tolist() == pytest.approx([0.0, 0.0, 0.0])
    # a segment shorter than twice the margin: aim at its middle
    ax, _ = aim_points(np.array([-5.0]), np.array([1.0]), g, 8.0)
    assert ax[0] == pytest.approx(5.0)


def test_sample_line_spacing_and_ends():
    x, y = sample_line((0.0, 0.0), (30.0, 40.0), 5.0)  # 50 m long
    assert x.size == 11
    assert (x[0], y[0], x[-1], y[-1]) == (0.0, 0.0, 30.0, 40.0)
    assert np.hypot(np.diff(x), np.diff(y)) == pytest.approx(np.full(10, 5.0))
    x, _ = sample_line((0.0, 0.0), (1000.0, 0.0), 1.0, max_points=11)  # capped
    assert x.size == 11
    x, _ = sample_line((0.0, 0.0), (3.0, 0.0), 5.0)  # shorter than the spacing
    assert x.tolist() == [0.0, 3.0]
    with pytest.raises(InputError, match="spacing"):
        sample_line((0.0, 0.0), (1.0, 0.0), 0.0)


def test_start_points_point_and_line():
    x, y = start_points(Start((3.0, 4.0)))
    assert (x.tolist(), y.tolist()) == ([3.0], [4.0])
    x, y = start_points(Start((0.0, 0.0), (0.0, 20.0)), spacing_m=5.0)
    assert y.tolist() == [0.0, 5.0, 10.0, 15.0, 20.0]
