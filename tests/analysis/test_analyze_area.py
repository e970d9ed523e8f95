"""``analyze`` on a course with a race area: the optimal legs round the obstacles.

A reach from a start line to a mark 1000 m east, in a steady 12 kn northerly, with a
rectangular obstacle (no clearance) across the direct line.  The fastest way round a
convex obstacle in a uniform wind is the taut string: straight pieces from the start over
the obstacle's two corners on one side to the mark, each sailed at the polar speed of its
own wind angle (no manoeuvre on a reach), to the nearest point of the mark's rounding
ray (its far end, ``zone_m`` = 13 m off the mark: where a leg to a mark ends).  The sailed
track is the plan's own route, then round the mark.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sailroute.analysis.debrief import analyze_track
from sailroute.analysis.segment import leg_target
from sailroute.course.load import build_specs, load_course
from sailroute.planning.route import route_course, settings_for
from sailroute.routing.api import route_leg
from sailroute.routing.geometry import target_geometry
from sailroute.routing.obstacles import obstacles_for
from sailroute.routing.types import Start
from sailroute.track.model import Track
from sailroute.units import KNOT
from tests.analysis.test_analyze import _sailed

COURSE = """\
name: reach round a pontoon
start_time: "2024-05-01T12:00:00Z"
time_limit_min: 60
origin: {lat: 45.0, lon: 13.0}
marks:
  pin:  {x: 0, y: -60}
  boat: {x: 0, y: 60}
  east: {x: 1000, y: 0}
lines:
  start: [boat, pin]
legs:
  - {to: east, rounding: port}
routing: {dt_s: 5, router: ROUTER}
boat: {builtin: ilca7}
scenarios:
  steady: {type: uniform, tws_kn: 12, twd_deg: 0}
AREA"""

PONTOON = (400.0, 600.0, -100.0, 100.0)
"""x0, x1, y0, y1 of the obstacle [m]."""
AREA = """
obstacles:
  - name: pontoon
    points: [{x: 400, y: -100}, {x: 600, y: -100}, {x: 600, y: 100}, {x: 400, y: 100}]
"""
TWS_MS = 12 * KNOT


def _course(tmp_path: Path, area: str = AREA, router: str = "isochrone", name: str = "c"):
    p = tmp_path / f"{name}.yaml"
    p.write_text(COURSE.replace("ROUTER", router).replace("AREA", area), encoding="utf-8")
    return load_course(p)


def _time_along(boat, points) -> float:
    """Time [s] of straight pieces through ``points`` [m], each at the polar speed of its
    wind angle in the northerly."""
    p = np.asarray(points, dtype=float)
    d = np.diff(p, axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    heading = np.degrees(np.arctan2(d[:, 0], d[:, 1])) % 360.0
    twa = np.minimum(heading, 360.0 - heading)  # wind from 0°
    speed = np.asarray(boat.speed(np.full(twa.shape, TWS_MS), twa), dtype=float)
    return float(np.sum(length / speed))


def ray_end(course, a: tuple[float, float]) -> tuple[float, float]:
    """The far end of the mark's rounding ray for a leg from ``a`` [m]."""
    geom = target_geometry(leg_target(course, 0), Start(a, None, "start"), zone_m=13.0)
    return geom.b


def closed_form_detour(boat, a: tuple[float, float], end: tuple[float, float]) -> float:
    """The faster of the two taut strings from ``a`` round the pontoon to ``end`` [s]."""
    x0, x1, y0, y1 = PONTOON
    return min(_time_along(boat, [a, (x0, y), (x1, y), end]) for y in (y0, y1))


def _round_the_mark(course, track: Track) -> Track:
    """``track`` continued round the mark ``east`` (1000, 0) to port at about 5 m/s."""
    x, y = course.frame.to_xy(track.lat_deg, track.lon_deg)
    turn = np.array([(1012.0, -12.0), (1022.0, -2.0), (1022.0, 12.0), (1010.0, 22.0)])
    turn = np.vstack([turn, turn[-1] + np.outer(np.arange(1, 9), (-5.0, 0.0))])
    step = np.hypot(*np.diff(np.vstack([(x[-1], y[-1]), turn]), axis=0).T)
    t = np.concatenate([track.t_s, track.t_s[-1] + np.cumsum(step) / 5.0])
    lat, lon = course.frame.to_latlon(np.append(x, turn[:, 0]), np.append(y, turn[:, 1]))
    return Track(t, lat, lon, track.name, track.source)


@pytest.fixture(scope="module")
def analysed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("area")
    course = _course(tmp)
    open_water = _course(tmp, area="", name="open")
    boat, winds = build_specs(course, ["steady"])
    legs = route_course(course, winds["steady"], boat, settings_for(course))
    track = _round_the_mark(course, _sailed(course, legs))
    return course, open_water, boat, legs, track


def test_optimal_leg_rounds_the_obstacle_in_the_closed_form_time(analysed):
    course, open_water, boat, _, track = analysed
    a = analyze_track(course, track)
    (leg,) = a.legs
    want = closed_form_detour(boat, leg.start_xy, ray_end(course, leg.start_xy))
    assert leg.optimal_time_s == pytest.approx(want, rel=0.005)
    obs = obstacles_for(course.area)
    assert obs is not None
    tr = leg.optimal.track
    assert np.all(obs.segments_free(tr.x[:-1], tr.y[:-1], tr.x[1:], tr.y[1:]))
    # the track sailed is the plan's route round the pontoon: nothing lost
    assert abs(leg.loss_s) < 0.01 * leg.sailed_time_s
    # without the area the optimal leg goes straight through, faster: the same track then
    # loses the detour
    (free,) = analyze_track(open_water, track).legs
    straight = _time_along(boat, [free.start_xy, ray_end(course, free.start_xy)])
    assert free.optimal_time_s == pytest.approx(straight, rel=0.005)
    assert free.optimal_time_s < leg.optimal_time_s - 5.0
    assert free.loss_s == pytest.approx(leg.optimal_time_s - free.optimal_time_s, abs=2.0)
    assert np.any((np.abs(free.optimal.track.y) < 100) & (np.abs(free.optimal.track.x - 500) < 100))
    # the analysis maps show the pontoon: the leg map and the page's figure
    from sailroute.report.analysis import plot_legs
    from sailroute.report.html import analysis_report
    from sailroute.report.page_figure import figure

    (ax,) = plot_legs(a).axes
    (patch,) = [p for p in ax.patches if p.get_gid() == "obstacle:pontoon"]
    np.testing.assert_allclose(
        patch.get_xy()[:4], [(400, -100), (600, -100), (600, 100), (400, 100)]
    )
    names = [t.get("name") for t in figure(analysis_report(a))["data"]]
    assert names.count("obstacle: pontoon") == 1


def test_no_area_gives_the_same_analysis_as_before(analysed):
    """Without a boundary or obstacles nothing is passed to the router: the optimal leg is
    the open-water route from the same start, point for point."""
    _, open_water, boat, _, track = analysed
    assert obstacles_for(open_water.area) is None
    (free,) = analyze_track(open_water, track).legs
    _, winds = build_specs(open_water, ["steady"])
    direct = route_leg(
        Start(free.start_xy, None, "start"),
        leg_target(open_water, 0),
        free.t_start,
        winds["steady"],
        boat,
        settings_for(open_water),
    )
    assert free.optimal_time_s == direct.time_s
    np.testing.assert_array_equal(free.optimal.track.x, direct.track.x)
    np.testing.assert_array_equal(free.optimal.track.y, direct.track.y)


def test_spline_router_refuses_the_area_as_plan_does(analysed, tmp_path):
    from sailroute.errors import InputError

    _, _, _, _, track = analysed
    course = _course(tmp_path, router="spline")
    with pytest.raises(InputError, match="honoured by the isochrone and griddp routers only"):
        analyze_track(course, track)
    assert math.isfinite(analyze_track(_course(tmp_path, "", "spline", "o"), track).loss_s)


def test_a_leg_starting_inside_a_clearance_is_analysed_without_the_area(tmp_path):
    """A boat may cross the line inside an obstacle's clearance (the clearance is the
    router's margin, not the water's edge): that leg's optimal route cannot keep to the
    area, so it ignores it, the note says so, and the other numbers are those of open
    water (nothing is lost to an error)."""
    near = """
obstacles:
  - name: committee boat
    clearance_m: 30
    points: [{x: 20, y: -20}, {x: 60, y: -20}, {x: 60, y: 20}, {x: 20, y: 20}]
"""
    course = _course(tmp_path, area=near, name="near")
    open_water = _course(tmp_path, area="", name="open")
    obs = obstacles_for(course.area)
    assert obs is not None and not obs.points_free(0.0, 0.0)  # the line's middle
    # a straight reach along y = 0 at 5 m/s from 50 m behind the line, round the mark
    x = np.arange(-50.0, 1000.0, 5.0)
    t = course.start_epoch + 10.0 + np.arange(x.size, dtype=float)
    lat, lon = course.frame.to_latlon(x, np.zeros_like(x))
    track = _round_the_mark(course, Track(t, lat, lon, "reach", "synthetic"))
    (leg,) = analyze_track(course, track).legs
    (free,) = analyze_track(open_water, track).legs
    assert "starts inside the clearance of obstacle 'committee boat'" in leg.note
    assert "ignores the race area" in leg.note
    assert free.note == ""
    assert leg.optimal_time_s == free.optimal_time_s
    assert leg.loss_s == free.loss_s
