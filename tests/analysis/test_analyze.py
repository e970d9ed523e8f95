"""Race analysis: synthetic tracks from sailroute's own routes, real Snipe tracks, bad input."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.analysis.debrief import analyze_track
from sailroute.cli import app
from sailroute.commands.analyze import run_analyze_command
from sailroute.course.load import build_specs, load_course
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.planning.route import route_course, settings_for
from sailroute.routing.types import LegResult
from sailroute.timeutil import iso, parse_time, to_epoch
from sailroute.track.model import Track
from sailroute.track.read import read_track
from tests.conftest import ROOT, SHARED_REAL, requires_shared

COURSE = """\
name: synthetic windward-leeward
start_time: "2024-05-01T12:00:00Z"
time_limit_min: 60
origin: {lat: 45.0, lon: 13.0}
marks:
  pin:  {x: -60, y: 0}
  boat: {x: 60, y: 0}
  top:  {x: 0, y: 500}
  bottom: {x: 0, y: 40}
lines:
  start: [pin, boat]
legs:
  - {to: top, rounding: ROUND}
  - {to: bottom, rounding: port}
  - {to: top, rounding: port}
routing: {dt_s: 5}
scenarios:
  steady: {type: uniform, tws_kn: 10, twd_deg: 0}
"""

LOSS_TOL_S = 4.0
"""A track that sails the optimal route analyses as lost within this per leg [s]: the
crossing times are interpolated on 1 Hz fixes, and a leg re-routed from the detected
rounding point may find a route one manoeuvre penalty (3-5 s) apart from the chained
plan's where two routes are that close (measured: 0.0, 3.0, 1.0 s)."""


def _course(tmp_path: Path, rounding: str = "port") -> Course:
    p = tmp_path / f"wl-{rounding}.yaml"
    p.write_text(COURSE.replace("ROUND", rounding), encoding="utf-8")
    return load_course(p)


@pytest.fixture(scope="module")
def routed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Course, list[LegResult]]:
    course = _course(tmp_path_factory.mktemp("wl"))
    boat, winds = build_specs(course, ["steady"])
    return course, route_course(course, winds["steady"], boat, settings_for(course))


def _sailed(
    course: Course,
    legs: list[LegResult],
    turn_at_s: float | None = None,
    turn_s: float = 20.0,
    radius_m: float = 4.0,
) -> Track:
    """The routed legs as a 1 Hz track with a 20 s lead-in to the line; optionally a
    360° turn (anticlockwise circle of ``radius_m`` taking ``turn_s``) ``turn_at_s``
    after the start."""
    t = np.concatenate([leg.track.t for leg in legs])
    x = np.concatenate([leg.track.x for leg in legs])
    y = np.concatenate([leg.track.y for leg in legs])
    keep = np.concatenate([[True], np.diff(t) > 1e-9])
    t, x, y = t[keep], x[keep], y[keep]
    # lead-in: the first 20 s of the route, mirrored back below the line
    t0 = t[0]
    lead = np.arange(-20.0, 0.0, 1.0)
    dx, dy = x[1] - x[0], y[1] - y[0]
    v = np.hypot(dx, dy) / (t[1] - t[0])
    ux, uy = dx / np.hypot(dx, dy), dy / np.hypot(dx, dy)
    tq = np.concatenate([t0 + lead, np.arange(t0, t[-1], 1.0), [t[-1]]])
    xq = np.where(tq < t0, x[0] + ux * v * (tq - t0), np.interp(tq, t, x))
    yq = np.where(tq < t0, y[0] + uy * v * (tq - t0), np.interp(tq, t, y))
    if turn_at_s is not None:
        tm = t0 + turn_at_s
        k = int(np.searchsorted(tq, tm))
        xm, ym = xq[k], yq[k]
        ang = np.linspace(0.0, 2 * np.pi, int(turn_s) + 1)[1:-1]
        # circle through the point, centred to its left
        cx, cy = xm - radius_m, ym
        xc, yc = cx + radius_m * np.cos(ang), cy + radius_m * np.sin(ang)
        tc = tq[k] + np.arange(1, ang.size + 1) * (turn_s / (ang.size + 1))
        tq = np.concatenate([tq[: k + 1], tc, tq[k + 1 :] + turn_s])
        xq = np.concatenate([xq[: k + 1], xc, xq[k + 1 :]])
        yq = np.concatenate([yq[: k + 1], yc, yq[k + 1 :]])
    lat, lon = course.frame.to_latlon(xq, yq)
    return Track(tq, lat, lon, "synthetic", "synthetic.gpx")


def test_sailing_the_optimal_route_loses_nothing(routed: tuple[Course, list[LegResult]]) -> None:
    course, legs = routed
    # judged in the wind the route was planned in (the default also infers one from the
    # track, a few degrees off, where the optimal side of a near-square leg can differ)
    a = analyze_track(course, _sailed(course, legs), wind="scenario")
    assert abs(a.segmentation.start.late_s) < 0.5  # crossed the line at the gun
    for leg, ref in zip(a.legs, legs, strict=True):
        assert abs(leg.t_end - ref.t_end) < 1.0, leg.label  # detected where the route ended
        assert abs(leg.loss_s) <= LOSS_TOL_S, (leg.label, leg.loss_s)
        assert (leg.sailed_tacks, leg.sailed_gybes) == (ref.n_tacks, ref.n_gybes), leg.label
        assert abs(leg.optimal_tacks + leg.optimal_gybes - ref.n_tacks - ref.n_gybes) <= 1
        s = leg.split
        assert s.manoeuvres + s.speed + s.route == pytest.approx(s.total)
        assert abs(s.speed) < 0.05 * leg.sailed_time_s  # sailed at polar speed
        assert leg.mean_polar_pct == pytest.approx(100.0, abs=5.0)
        assert leg.side_sailed == leg.side_optimal
    assert a.points.loss_s[-1] == pytest.approx(a.loss_s)
    assert np.all(np.abs(a.points.loss_s) < 3 * LOSS_TOL_S + 15)


def test_a_360_turn_shows_as_manoeuvre_loss(routed: tuple[Course, list[LegResult]]) -> None:
    course, legs = routed
    # both in the planned wind: a wind inferred from each track would differ between them
    base = analyze_track(course, _sailed(course, legs), wind="scenario")
    turned = analyze_track(
        course, _sailed(course, legs, turn_at_s=60.0, turn_s=20.0), wind="scenario"
    )
    extra = turned.legs[0].loss_s - base.legs[0].loss_s
    assert extra == pytest.approx(20.0, abs=4.0)
    # a full circle is one tack and one gybe more
    assert (
        turned.legs[0].sailed_tacks + turned.legs[0].sailed_gybes
        == base.legs[0].sailed_tacks + base.legs[0].sailed_gybes + 2
    )
    dm = turned.legs[0].split.manoeuvres - base.legs[0].split.manoeuvres
    assert dm > 0.6 * extra  # most of it is booked as manoeuvres
    for b, t in zip(base.legs[1:], turned.legs[1:], strict=True):
        assert abs(t.loss_s - b.loss_s) < LOSS_TOL_S


def test_explicit_leg_times_override(routed: tuple[Course, list[LegResult]]) -> None:
    course, legs = routed
    tr = _sailed(course, legs)
    given = [None, legs[0].t_end + 5.0, None, None]
    a = analyze_track(course, tr, leg_times=given)
    assert a.legs[0].t_end == legs[0].t_end + 5.0 and not a.legs[0].detected
    assert a.legs[1].detected
    with pytest.raises(InputError, match="got 2 times for 3 legs"):
        analyze_track(course, tr, leg_times=[None, None])


def test_leg_times_where_the_boat_is_not_are_refused(
    tmp_path: Path, routed: tuple[Course, list[LegResult]]
) -> None:
    """Leg times 1 ms apart timed leg 1 as a millisecond: exit 0 and "lost -1051 s".  A
    given time must find the boat near what it ends (segment.GIVEN_NEAR_M)."""
    course, legs = routed
    tr = _sailed(course, legs)
    track = tmp_path / "boat.csv"
    track.write_text(
        "time,lat,lon\n"
        + "".join(
            f"{iso(float(t))},{la:.8f},{lo:.8f}\n"
            for t, la, lo in zip(tr.t_s, tr.lat_deg, tr.lon_deg, strict=True)
        )
    )
    t0 = course.start_epoch + 2.0
    x, y = course.frame.to_xy(np.interp(t0, tr.t_s, tr.lat_deg), np.interp(t0, tr.t_s, tr.lon_deg))
    top = course.marks["top"].xy
    gap = float(np.hypot(x - top[0], y - top[1]))  # the boat near the line, the mark 500 m up
    assert 450 < gap < 510
    out = tmp_path / "out"
    res = CliRunner().invoke(
        app,
        [
            "analyze",
            str(course.source),
            str(track),
            "-q",
            "-o",
            str(out),
            "--leg-times",
            f"{iso(t0)},{iso(t0 + 0.001)},-,-",
        ],
    )
    assert res.exit_code == 2, res.output
    assert res.stderr.count("\n") == 1 and "Traceback" not in res.output
    assert re.fullmatch(
        rf"error: {re.escape(str(track))}: leg time {re.escape(iso(t0 + 0.001))} "
        rf"\(--leg-times, the end of leg 1\): the boat is then {gap:.0f} m from 'top'; "
        r"expected it within 300 m \(check the time, or give '-' to detect it\)\n",
        res.stderr,
    ), res.stderr
    assert not out.exists()
    # the times the route itself ends its legs at are accepted
    given = [t0, *(leg.t_end for leg in legs)]
    a = analyze_track(course, tr, leg_times=given)
    assert [leg.t_end for leg in a.legs] == given[1:]


def test_bad_tracks_are_refused(tmp_path: Path, routed: tuple[Course, list[LegResult]]) -> None:
    course, legs = routed
    tr = _sailed(course, legs)
    # never reaches the top mark: cut the track before it
    cut = tr.between(tr.t_start, legs[0].t_end - 60.0)
    with pytest.raises(InputError, match=r"leg 1 \(start -> top\): the track never rounds 'top'"):
        analyze_track(course, cut)
    # another day
    day = Track(tr.t_s - 86400.0, tr.lat_deg, tr.lon_deg, "d", "day.gpx")
    with pytest.raises(InputError, match="another day"):
        analyze_track(course, day)
    # another place: 50 km north
    far = Track(tr.t_s, tr.lat_deg + 0.45, tr.lon_deg, "f", "far.gpx")
    with pytest.raises(InputError, match="another place"):
        analyze_track(course, far)
    # the course says starboard, the boat left the top mark to port
    with pytest.raises(InputError, match=r"leaving it to port.*course says starboard"):
        analyze_track(_course(tmp_path, "starboard"), tr)


def test_cli_bad_input_exit_2_and_nothing_written(tmp_path: Path) -> None:
    empty = tmp_path / "empty.gpx"
    empty.write_text("", encoding="utf-8")
    out = tmp_path / "out"
    res = CliRunner().invoke(
        app,
        [
            "analyze",
            str(ROOT / "courses" / "snipe-valencia-p01.yaml"),
            str(empty),
            "--out",
            str(out),
            "-q",
        ],
    )
    assert res.exit_code == 2
    assert "empty.gpx: the track file is empty" in res.output
    assert "Traceback" not in res.output
    assert not out.exists()


def test_shipped_example_runs_and_writes_every_file(tmp_path: Path) -> None:
    out = tmp_path / "ex"
    res = run_analyze_command(
        ROOT / "courses" / "snipe-valencia-p01.yaml",
        [ROOT / "data" / "snipe-valencia-2025-06-21-ESP30782-P01.gpx"],
        out_dir=out,
    )
    assert set(res.files) == {
        "analysis_json",
        "analysis_csv",
        "points_csv",
        "legs_png",
        "loss_png",
        "html",
        "plotly_js",
    }
    assert res.files["plotly_js"] == out / "plotly.min.js" and res.files["plotly_js"].is_file()
    doc = json.loads((out / "analysis.json").read_text())
    assert doc["schema_version"] == 1 and len(doc["legs"]) == 4
    ends = [leg["end_time"][11:19] for leg in doc["legs"]]
    assert ends == ["11:31:48", "11:37:14", "11:44:40", "11:49:10"]
    rows = (out / "points.csv").read_text().splitlines()
    assert rows[0].startswith("leg,time,x_m,y_m,lat,lon,sog_ms")
    assert len(rows) > 1400
    # report.html: the sailed track point by point, the optimal legs in 4 pieces
    from sailroute.report.page_render import read_figure

    fig = read_figure((out / "report.html").read_text(encoding="utf-8"))
    (sailed,) = [
        t for t in fig["data"] if t["name"].startswith("sailed: ") and t["mode"] == "lines"
    ]
    assert len(sailed["x"]) == len(rows) - 1
    assert [c[3] for c in sailed["customdata"][:3]] == [r.split(",")[1][11:19] for r in rows[1:4]]
    (optimal,) = [t for t in fig["data"] if t["name"].startswith("optimal")]
    assert optimal["x"].count(None) == 3 and optimal["line"]["dash"] == "dash"
    leg1 = doc["legs"][0]
    split = leg1["loss_split_s"]
    assert split["manoeuvres"] + split["speed"] + split["route"] == pytest.approx(
        leg1["loss_s"], abs=0.01
    )


# README of the shared data: closest approach within 40 m of the metadata marks
SNIPE_ROUNDINGS = {
    ("P01", "ESP30782"): ["11:31:49", "11:37:14", "11:44:40", "11:49:10"],
    ("P01", "ESP29375"): ["11:31:52", "11:37:16", "11:44:27", "11:48:49"],
    ("P02", "ESP30782"): ["12:15:58", "12:21:29", "12:30:34", "12:36:32"],
    ("P02", "ESP29375"): ["12:15:51", "12:21:20", "12:29:46", "12:35:35"],
}


def snipe_course(tmp_path: Path, race: str) -> Course:
    """The shipped P01 course, or the P02 one (B1 moved, 8 kn, start 12:06:30)."""
    text = (ROOT / "courses" / "snipe-valencia-p01.yaml").read_text(encoding="utf-8")
    if race == "P02":
        text = (
            text.replace("11:23:30Z", "12:06:30Z")
            .replace("tws_kn: 6", "tws_kn: 8")
            .replace("B1: {lat: 39.40691, lon: -0.31500}", "B1: {lat: 39.40615, lon: -0.31310}")
        )
    p = tmp_path / f"snipe-{race}.yaml"
    p.write_text(text, encoding="utf-8")
    return load_course(p)


@requires_shared
@pytest.mark.parametrize(("race", "boat"), list(SNIPE_ROUNDINGS))
def test_snipe_roundings_match_the_readme(tmp_path: Path, race: str, boat: str) -> None:
    course = snipe_course(tmp_path, race)
    gpx = SHARED_REAL / "races" / "snipe-valencia-2025" / f"2025-06-21-{boat}-{race}.gpx"
    a = analyze_track(course, read_track(gpx))
    day = "2025-06-21T"
    for leg, hhmmss in zip(a.legs, SNIPE_ROUNDINGS[(race, boat)], strict=True):
        ref = to_epoch(parse_time(f"{day}{hhmmss}Z"))
        assert abs(leg.t_end - ref) <= 10.0, (leg.label, iso(leg.t_end), hhmmss)
    assert 0 < a.segmentation.start.late_s < 120
