"""The Hyères R1 course (courses/hyeres-r1.yaml) against the thesis's geometry (Pardo 2018).

The marks are back-projected from the thesis's Fig 5.6 leg lengths and bearings, which are printed
to 0.01 m / 0.01°.  Legs between two marks of the file must therefore reproduce Fig 5.6 to about
the printing precision: we allow 0.01 m and 0.01° (measured: at most 0.0052 m and 0.001°).  Legs
through a line/gate *midpoint* differ more: the thesis had separate midpoint buoys (start_mid,
4_mid) that are not exactly the midpoints of the ends (start_mid by 0.08 m, 4_mid by 0.15 m), and
we use true midpoints; the tolerances there are 0.02 m / 0.01° (start_mid, 1→4_mid) and 0.1 m /
0.01° (4_mid→finish_mid, measured 0.074 m), i.e. the size of that 0.1–0.15 m disagreement."""

from __future__ import annotations

import math
from datetime import UTC, datetime

import numpy as np
import pytest

from sailroute.course.geometry import (
    course_bbox,
    leg_endpoints,
    nominal_legs,
    nominal_wind_modes,
    start_of,
    target_of,
    xy_bearing_deg,
)
from sailroute.course.load import load_course
from tests.conftest import ROOT

R1 = ROOT / "courses" / "hyeres-r1.yaml"


@pytest.fixture(scope="module")
def r1():
    return load_course(R1)


def _points(course):
    pts = {k: m.xy for k, m in course.marks.items()}
    pts["start_mid"] = course.lines["start"].midpoint
    pts["4_mid"] = course.gates["gate4"].midpoint
    pts["finish_mid"] = course.lines["finish"].midpoint
    return pts


# (from, to, distance [m], bearing [°], distance tolerance [m]) from thesis Fig 5.6
FIG_5_6 = [
    ("start2", "1", 1793.11, 112.02, 0.01),
    ("1", "4_2", 1689.37, 283.67, 0.01),
    ("4_2", "1", 1689.37, 103.67, 0.01),
    ("1", "4p", 1689.63, 280.60, 0.01),
    ("4p", "fn_2", 409.52, 197.49, 0.01),
    ("start1", "1", 1850.86, 98.51, 0.01),
    ("4p", "finish_mid", 415.67, 200.29, 0.01),
    ("start_mid", "1", 1809.35, 105.16, 0.02),
    ("1", "4_mid", 1688.90, 282.14, 0.02),
    ("4_mid", "finish_mid", 460.46, 199.50, 0.1),
]


@pytest.mark.parametrize(("a", "b", "dist", "brg", "tol"), FIG_5_6)
def test_fig_5_6_distances_and_bearings(r1, a, b, dist, brg, tol):
    p = _points(r1)
    assert math.dist(p[a], p[b]) == pytest.approx(dist, abs=tol)
    assert xy_bearing_deg(p[a], p[b]) == pytest.approx(brg, abs=0.01)


def test_line_lengths(r1):
    # from the thesis's marks: 432.4, 90.5 and 42.2 m (thesis text: "430", "about 90", "42")
    assert r1.lines["start"].length_m == pytest.approx(432.4, abs=0.05)
    assert r1.gates["gate4"].length_m == pytest.approx(90.5, abs=0.05)
    assert r1.lines["finish"].length_m == pytest.approx(42.2, abs=0.05)


def test_total_straight_line_distance_midpoints(r1):
    # 7336.5 m through the midpoints; our leg 4 goes to 4p itself (as sailed in
    # the thesis), so the sum is start_mid-1 + 1-4_mid + 4_mid-1 + 1-4p + 4p-finish_mid.
    p = _points(r1)
    expected = 1809.35 + 1688.90 + 1688.90 + 1689.63 + 415.67
    got = sum(leg.distance_m for leg in nominal_legs(r1))
    assert got == pytest.approx(expected, abs=0.05)
    assert nominal_legs(r1)[0].from_xy == p["start_mid"]


def test_wind_modes_at_108(r1):
    # thesis eq 4.64
    assert nominal_wind_modes(r1, 108.0) == ("upwind", "downwind", "upwind", "downwind", "reach")


def test_leg_sequence_and_rounding(r1):
    seq = [(leg.from_name, leg.to_name, leg.kind, leg.rounding) for leg in r1.legs]
    assert seq == [
        ("start", "1", "mark", "port"),
        ("1", "gate4", "gate", None),
        ("gate4", "1", "mark", "port"),
        ("1", "4p", "mark", "port"),
        ("4p", "finish", "line", None),
    ]


def test_start_time_is_utc_1210_local(r1):
    assert r1.start_time == datetime(2018, 4, 24, 10, 10, tzinfo=UTC)


def test_leg_endpoints_for_routers(r1):
    s0, t0 = leg_endpoints(r1, 0)
    assert s0.is_line and s0.a == r1.marks["start1"].xy and s0.b == r1.marks["start2"].xy
    assert t0.kind == "mark" and t0.a == (0.0, 0.0) and t0.rounding == "port"
    t1 = target_of(r1, 1)
    assert t1.kind == "gate" and {t1.a, t1.b} == {r1.marks["4p"].xy, r1.marks["4_2"].xy}
    # later legs start where the previous one arrived ...
    s2 = start_of(r1, 2, (-1650.0, 350.0))
    assert not s2.is_line and s2.a == (-1650.0, 350.0) and s2.name == "gate4"
    # ... or, without an arrival point, at the nominal point (gate midpoint)
    assert start_of(r1, 2).a == pytest.approx(r1.gates["gate4"].midpoint)
    t4 = target_of(r1, 4)
    assert t4.kind == "line" and t4.centre == pytest.approx(r1.lines["finish"].midpoint)


def test_placement_east_of_echo_centre(r1):
    # The assumption stated in the YAML: the course lies east of the Echo centre, mark 1 the
    # east-most mark, bbox centre about 1.6 km east and 0.2 km south of the Echo centre.
    ex, ey = r1.frame.to_xy(43.069067, 6.198550)
    x0, x1, y0, y1 = course_bbox(r1)
    assert r1.marks["1"].x == pytest.approx(x1)
    cx, cy = (x0 + x1) / 2 - float(ex), (y0 + y1) / 2 - float(ey)
    assert 1300 < cx < 1900 and -500 < cy < 100


def test_marks_latlon_consistent_with_frame(r1):
    for m in r1.marks.values():
        x, y = r1.frame.to_xy(m.lat, m.lon)
        np.testing.assert_allclose([x, y], [m.x, m.y], atol=1e-6)


def test_references(r1):
    assert r1.references["winner"] == (984.0, 500.0, 871.0, 480.0, 106.0)
    assert sum(r1.references["winner"]) == pytest.approx(2941.0)
    assert sum(r1.references["top10"]) == pytest.approx(3010.40, abs=1e-9)
    refs = r1.references_for("constant")
    # thesis Fig 5.22 prints 3190.38 s; its leg times (rounded to 0.01 s) sum to 3190.37 s
    assert sum(refs["thesis"]) == pytest.approx(3190.38, abs=0.015)
