"""The incremental leg tracker against ``analyze``'s segmentation of the same track."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sailroute.analysis.segment import segment_track
from sailroute.course.load import build_specs
from sailroute.live.legs import LegTracker
from tests.live.feed import sailed_track, trieste


@pytest.fixture(scope="module")
def sailed() -> tuple:
    course = trieste()
    boat, winds = build_specs(course, ["measured"])
    polar = boat.routing_polar()
    assert polar is not None
    return course, sailed_track(course, winds["measured"], polar)


def _changes(tracker: LegTracker, t, x, y) -> list:
    out = []
    for a, b, c in zip(t, x, y, strict=True):
        out += tracker.update(float(a), float(b), float(c))
    return out


@pytest.mark.parametrize("every", [1, 3])
def test_leg_changes_at_analyzes_crossings(sailed: tuple, every: int) -> None:
    """A boat routed round the Trieste course in its measured wind (the fleet generator's
    way: 6 m off the marks, drawn roundings), fed fix by fix every 1 or 3 s: the start and
    each leg's end come at the times ``segment_track`` finds in the whole track."""
    course, (t, x, y) = sailed
    t, x, y = t[::every], x[::every], y[::every]
    seg = segment_track(course, t, x, y)
    ch = _changes(LegTracker(course, 0), t, x, y)
    assert [c.how for c in ch] == ["start"] + ["rounding"] * course.n_legs
    assert [c.leg for c in ch] == list(range(course.n_legs + 1))
    np.testing.assert_allclose([c.crossing.t for c in ch], [b.t for b in seg.bounds], atol=1e-6)
    assert seg.ends[-1].t - seg.start.crossing.t > 1200  # a real race: over 20 minutes


def test_leg_set_by_hand_goes_on_from_there(sailed: tuple) -> None:
    """Started on leg 3 (from the gate) while the boat sails leg 3: the next roundings
    are analyze's; a track that begins after the gun on the course side is started."""
    course, (t, x, y) = sailed
    seg = segment_track(course, t, x, y)
    gate = seg.ends[1].t
    k = np.searchsorted(t, gate + 20.0)
    tracker = LegTracker(course, 2)
    ch = _changes(tracker, t[k:], x[k:], y[k:])
    assert [c.leg for c in ch] == [3, 4] and tracker.finished
    # the leg's start is the gate's centre, not the crossing: the ray tilts a little
    assert abs(ch[0].crossing.t - seg.ends[2].t) < 2.0
    assert ch[1].crossing.t == pytest.approx(seg.ends[3].t, abs=1e-6)
    late = LegTracker(course, 0)
    k0 = np.searchsorted(t, course.start_epoch + 60.0)
    first = late.update(float(t[k0]), float(x[k0]), float(y[k0]))
    assert [(c.how, c.crossing.t) for c in first] == [("start", t[k0])]


def test_over_the_line_at_the_gun_starts_from_there() -> None:
    """A boat on the course side at the gun is started at the gun, where it was then."""
    course = trieste()
    gun = course.start_epoch
    (ax, ay), (bx, by) = course.lines["start"].a.xy, course.lines["start"].b.xy
    mx, my = course.marks["1"].xy
    cx, cy = (ax + bx) / 2, (ay + by) / 2
    ux, uy = (mx - cx) / math.hypot(mx - cx, my - cy), (my - cy) / math.hypot(mx - cx, my - cy)
    tracker = LegTracker(course, 0)
    # crossing 10 s before the gun at 1 m/s, 20 m over at the gun
    assert tracker.update(gun - 20.0, cx - 10 * ux, cy - 10 * uy) == []
    ch = tracker.update(gun + 10.0, cx + 20 * ux, cy + 20 * uy)
    assert [c.how for c in ch] == ["start"] and ch[0].crossing.t == gun
    assert ch[0].crossing.x == pytest.approx(cx + 10 * ux)


def test_a_mark_passed_on_the_wrong_side_is_not_rounded() -> None:
    """Mark 1 is left to port: a boat that goes up its left side (mark to starboard) and
    on never advances; one that goes up its right side and over the top does."""
    course = trieste()
    gun = course.start_epoch
    mx, my = course.marks["1"].xy
    (ax, ay), (bx, by) = course.lines["start"].a.xy, course.lines["start"].b.xy
    cx, cy = (ax + bx) / 2, (ay + by) / 2
    d = math.hypot(mx - cx, my - cy)
    ux, uy = (mx - cx) / d, (my - cy) / d
    rx, ry = uy, -ux  # right of the leg's direction
    for side, want in ((-1.0, []), (1.0, [1])):
        tracker = LegTracker(course, 0, detect_m=100.0)
        tracker.set_leg(0, (cx, cy))
        tracker.started = True
        path = [(cx + ux * s + side * 10 * rx, cy + uy * s + side * 10 * ry) for s in (0, d - 20)]
        path += [(mx + ux * 15 + side * 10 * rx, my + uy * 15 + side * 10 * ry)]
        path += [(mx + ux * 15 - side * 40 * rx, my + uy * 15 - side * 40 * ry)]  # across the top
        got = []
        for k, (px, py) in enumerate(path):
            got += [c.leg for c in tracker.update(gun + 100.0 * (k + 1), px, py)]
        assert got == want, side
