"""The live wind blend, the remaining-course routing and the NMEA sentences out."""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pynmea2
import pytest

from sailroute.course.geometry import FAR_FROM_COURSE_M
from sailroute.course.load import build_specs
from sailroute.errors import InputError
from sailroute.live.engine import input_problem
from sailroute.live.livewind import LiveWind
from sailroute.live.nmeaout import ROUTE_ID, route_sentences, steer_sentences
from sailroute.live.replan import laylines, route_remaining
from sailroute.live.sources import NmeaFileSource, NmeaTcpSource, SignalKSource, parse_source
from sailroute.planning.route import route_course
from sailroute.units import wind_speed_direction
from sailroute.wind.uniform import UniformWind
from tests.live.feed import trieste


def load_trieste_file():
    """The Trieste course with the file's own routing settings."""
    return trieste(coarse=False)


def test_live_wind_is_measured_now_and_the_forecast_ahead() -> None:
    course = trieste()
    fc = UniformWind(tws_ms=2.5, twd_deg=65.0)
    now = course.start_epoch
    w = LiveWind(fc, now, 100.0, -50.0, 3.5, 50.0, course.frame, fade_s=600.0)
    s, d = wind_speed_direction(*w.sample(now, 100.0, -50.0))
    # the measured wind is earth-true, the frame's north differs from it by its grid angle
    grid = float(course.frame.grid_north_deg(*course.frame.to_latlon(100.0, -50.0)))
    assert abs(grid) < 0.01  # near the frame's origin
    assert float(s) == pytest.approx(3.5) and float(d) == pytest.approx(50.0, abs=0.01)
    s, d = wind_speed_direction(*w.sample(now + 600.0, 100.0, -50.0))
    # one fade time ahead: a weight of 1/e on the log speed ratio and the shift
    assert float(s) == pytest.approx(2.5 * (3.5 / 2.5) ** math.exp(-1))
    assert float(d) == pytest.approx(65.0 + (50.0 - 65.0) * math.exp(-1), abs=0.01)
    s, d = wind_speed_direction(*w.sample(now + 10 * 3600.0, 0.0, 0.0))
    assert float(s) == pytest.approx(2.5, abs=1e-3) and float(d) == pytest.approx(65.0, abs=0.01)


def test_remaining_course_from_a_mark_matches_the_full_plan() -> None:
    """Routed from where the full plan rounds mark 1, the rest of the course takes what the
    full plan's last three legs take (the full plan also carries mark 1's rounding ray)."""
    course = trieste()
    boat, winds = build_specs(course, ["mean"])
    full = route_course(course, winds["mean"], boat, course.routing)
    rest = route_remaining(
        course, winds["mean"], boat, course.routing, 1, full[0].end_xy, full[0].t_end
    )
    assert len(rest) == 3
    np.testing.assert_allclose([r.time_s for r in rest], [r.time_s for r in full[1:]], rtol=0.03)
    assert rest[-1].t_end == pytest.approx(full[-1].t_end, rel=0, abs=30.0)


def test_laylines_are_the_polars_vmg_angles() -> None:
    course = trieste()
    boat, _ = build_specs(course, ["mean"])
    up, down = boat.vmg_angles_deg(2.5)
    star, port = laylines(boat, 2.5, 65.0, upwind=True)
    assert star.bearing_deg == pytest.approx((65.0 - up) % 360)
    assert port.bearing_deg == pytest.approx((65.0 + up) % 360)
    assert 30.0 < up < 60.0 and 120.0 < down <= 180.0
    star, port = laylines(boat, 2.5, 65.0, upwind=False)
    assert star.bearing_deg == pytest.approx((65.0 - down) % 360)
    assert port.bearing_deg == pytest.approx((65.0 + down) % 360)


def test_layline_distance_and_time_from_below_the_mark() -> None:
    """A boat ``D`` dead downwind of a windward mark in a north wind: on port (heading the
    VMG angle ``a`` east of north) it meets the starboard layline after ``D / (2 cos a)``
    metres (an isosceles triangle), at the polar's speed at ``a``; on starboard it meets
    the port layline after as far.  A boat beyond a layline is past it: negative."""
    course = trieste()
    boat, _ = build_specs(course, ["mean"])
    up, _ = boat.vmg_angles_deg(2.5)
    speed = float(boat.steady_speed(np.array([2.5]), np.array([up]))[0])
    d = 400.0
    star, port = laylines(boat, 2.5, 0.0, True, (0.0, 0.0), (0.0, -d))
    want = d / (2.0 * math.cos(math.radians(up)))
    assert star.distance_m == pytest.approx(want, rel=1e-3)
    assert port.distance_m == pytest.approx(want, rel=1e-3)
    assert star.time_s == pytest.approx(want / speed, rel=2e-3)
    # 300 m east of the mark's line, level with the first boat: past the starboard layline
    # when 300 m exceeds D tan(a)
    far = 300.0 + d * math.tan(math.radians(up))
    star2, port2 = laylines(boat, 2.5, 0.0, True, (0.0, 0.0), (far, -d))
    assert star2.distance_m < 0 < port2.distance_m


def test_nmea_out_sentences_parse_and_measure() -> None:
    wps = [
        ("T301", 45.5633, 13.6751),
        ("1", 45.566951, 13.676702),
        ("finish", 45.564859, 13.6703175),
    ]
    out = route_sentences(wps)
    msgs = [pynmea2.parse(s.strip()) for s in out]  # checksums verified by pynmea2
    wpl = [m for m in msgs if m.sentence_type == "WPL"]
    assert [m.waypoint_id for m in wpl] == ["T301", "1", "FINISH"]
    assert wpl[1].lat == "4534.0171" and wpl[1].lon == "01340.6021"  # ddmm.mmmm
    # a mark name outside ASCII goes out as its ASCII letters (it stopped the re-plans)
    (named,) = [pynmea2.parse(x.strip()) for x in route_sentences([("Bóia-2", 45.5, 13.6)])][:1]
    assert named.waypoint_id == "BIA-2"
    rte = [m for m in msgs if m.sentence_type == "RTE"]
    assert rte[0].data[3] == ROUTE_ID and rte[0].data[4:] == ["T301", "1", "FINISH"]
    # 1 nm due north of the waypoint, steering to it: range 1 nm, bearing 180°
    lat = 45.566951 + 1852.0 / 111_132.0
    rmb, apb = (
        pynmea2.parse(s.strip())
        for s in steer_sentences(lat, 13.676702, 2.0, 180.0, ("BOAT", lat, 13.676702), wps[1])
    )
    assert float(rmb.data[9]) == pytest.approx(1.0, abs=0.01)
    assert float(rmb.data[10]) == pytest.approx(180.0, abs=0.1)
    assert float(rmb.data[11]) == pytest.approx(2.0 * 3600 / 1852, abs=0.05)  # closing speed
    assert apb.data[9] == "1" and float(apb.data[10]) == pytest.approx(180.0, abs=0.1)


def test_parse_source() -> None:
    assert parse_source("nmea+tcp://10.0.0.5:10110") == NmeaTcpSource("10.0.0.5", 10110)
    sk = parse_source("signalk://boat.local:3000")
    assert isinstance(sk, SignalKSource)
    assert sk.url == "ws://boat.local:3000/signalk/v1/stream?subscribe=all"
    path = "tests/data/live/tallinn-2023-09-27.nmea"
    assert parse_source(path, 5.0) == NmeaFileSource(__import__("pathlib").Path(path), 5.0)
    with pytest.raises(InputError, match="no port number"):
        parse_source("nmea+tcp://host")
    with pytest.raises(InputError, match="unknown scheme 'http'"):
        parse_source("http://host:80")
    with pytest.raises(InputError, match="no such file"):
        parse_source("missing.nmea")
    with pytest.raises(InputError, match="--speed 0"):
        parse_source(path, 0.0)


def test_a_far_position_or_a_wind_above_the_polar_is_said_not_routed() -> None:
    course = trieste()
    boat, _ = build_specs(course, ["mean"])
    mark = next(iter(course.marks.values())).xy
    top = float(np.max(boat.routing_polar().tws_ms))
    assert input_problem(course, boat, mark, 5.0) is None
    far = input_problem(course, boat, (mark[0] + FAR_FROM_COURSE_M + 5000.0, mark[1]), 5.0)
    assert far is not None and "km from the course area" in far
    strong = input_problem(course, boat, mark, top + 1.0)
    assert strong is not None and "above the polar's highest wind speed" in strong


def test_an_urgent_request_stops_the_older_one_and_routes_coarse() -> None:
    """A route under way stops at its next step once a newer urgent request is made; the
    urgent one routes with twice the time and heading steps (the Trieste file: 5 s and
    2°), and its leg times stay within 3 % of the course's settings."""
    import threading

    from sailroute.live.planner import PlanCore, PlanRequest, Superseded, ThreadPlanner

    course = load_trieste_file()
    boat, winds = build_specs(course, ["mean"])
    core = PlanCore(course, winds["mean"], boat, course.routing)
    assert core.coarse is not None
    assert (core.coarse.isochrone.dt_s, core.coarse.isochrone.heading_step_deg) == (10.0, 4.0)
    planner = ThreadPlanner(core)
    sx, sy = course.lines["start"].midpoint
    req = PlanRequest(1, "interval", course.start_epoch, sx, sy, 0, 2.5, 65.0, 600.0)
    out: list[object] = []

    def run() -> None:
        try:
            out.append(planner.route(req))
        except Superseded as exc:
            out.append(exc)

    th = threading.Thread(target=run)
    th.start()
    time.sleep(0.05)
    planner.supersede(2)
    th.join(30)
    assert len(out) == 1 and isinstance(out[0], Superseded)
    fine, _ = core.route(replace(req, number=3))
    coarse, _ = core.route(replace(req, number=3, coarse=True))
    np.testing.assert_allclose(coarse.leg_times_s, fine.leg_times_s, rtol=0.03)
