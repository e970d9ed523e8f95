"""Fleet debrief: starts over early or off the surveyed line, leg ends across data gaps,
per-boat leg times, one report.html for the fleet, bad input in a fleet."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.analysis.debrief import analyze_track, parse_boat_leg_times
from sailroute.analysis.segment import find_start, gap_limit_s
from sailroute.cli import app
from sailroute.course.load import build_specs
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.planning.route import route_course, settings_for
from sailroute.routing.types import LegResult
from sailroute.timeutil import iso
from sailroute.track.model import Track
from tests.analysis.test_analyze import _course, _sailed


@pytest.fixture(scope="module")
def routed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Course, list[LegResult]]:
    course = _course(tmp_path_factory.mktemp("fleet"))
    boat, winds = build_specs(course, ["steady"])
    return course, route_course(course, winds["steady"], boat, settings_for(course))


def _piecewise(
    course: Course, knots_t: list[float], knots_x: list[float], knots_y: list[float]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A 1 Hz track through the knots (relative to the gun [s], course frame [m])."""
    gun = course.start_epoch
    t = np.arange(knots_t[0], knots_t[-1] + 0.5, 1.0)
    return gun + t, np.interp(t, knots_t, knots_x), np.interp(t, knots_t, knots_y)


# --- the start --------------------------------------------------------------------------


def test_over_early_and_not_back_is_timed_from_the_gun(routed) -> None:
    course, _ = routed
    # north at 5 m/s through the line (y = 0) 8 s before the gun, on up the course
    t, x, y = _piecewise(course, [-60.0, 60.0], [0.0, 0.0], [-260.0, 340.0])
    st = find_start(course, t, x, y)
    assert st.ocs_s == pytest.approx(8.0, abs=1e-6) and not st.ocs_returned
    assert st.crossing.t == st.gun_t and st.late_s == 0.0
    assert st.side_at_gun == "course" and st.distance_at_gun_m == pytest.approx(40.0)
    assert st.notes[0].startswith(
        "OCS by 8 s: crossed the start line 8 s before the gun "
        "and did not come back; 40 m over at the gun"
    )


def test_over_early_and_back_restarts(routed) -> None:
    course, _ = routed
    # over at -8 s, back across at +12 s, restarts at +20 s (5 m/s throughout)
    t, x, y = _piecewise(course, [-60.0, 2.0, 16.0, 60.0], [0.0] * 4, [-260.0, 50.0, -20.0, 200.0])
    st = find_start(course, t, x, y)
    assert st.ocs_s == pytest.approx(8.0, abs=1e-6) and st.ocs_returned
    assert st.late_s == pytest.approx(20.0, abs=1e-6)
    assert "came back at" in st.notes[0] and "restarted" in st.notes[0]


def test_a_start_on_the_lines_extension_reports_the_offset(routed) -> None:
    course, _ = routed
    # the line runs x = -60 .. 60 m; this boat crosses y = 0 at x = 200 m, 10 s after the gun
    t, x, y = _piecewise(course, [-10.0, 30.0], [200.0, 200.0], [-100.0, 100.0])
    st = find_start(course, t, x, y)
    assert st.late_s == pytest.approx(10.0, abs=1e-6) and st.ocs_s is None
    assert st.line_offset_m == pytest.approx(140.0, abs=1e-6)
    assert st.line_fraction == pytest.approx(260.0 / 120.0)
    assert st.notes == (
        "crossed the start line's extension 140 m beyond 'boat', not the "
        "surveyed line: is the line laid elsewhere?",
    )


def test_no_start_anywhere_near_gives_the_closest_approach(routed) -> None:
    course, _ = routed
    t, x, y = _piecewise(course, [-10.0, 30.0], [900.0, 900.0], [-100.0, 100.0])
    with pytest.raises(
        InputError,
        match=r"never crosses the start line \(start\) nor its "
        r"extension \(500 m beyond each end\).*closest approach 840 m",
    ):
        find_start(course, t, x, y)


# --- leg ends in data gaps -----------------------------------------------------------------


def _without(tr: Track, t0: float, t1: float) -> Track:
    keep = (tr.t_s < t0) | (tr.t_s > t1)
    return Track(tr.t_s[keep], tr.lat_deg[keep], tr.lon_deg[keep], tr.name, tr.source)


def test_a_leg_end_inside_a_data_gap_is_unknown(routed) -> None:
    course, legs = routed
    tr = _sailed(course, legs)
    assert gap_limit_s(tr.t_s) == 10.0
    te = legs[1].t_end  # the bottom mark
    a = analyze_track(course, _without(tr, te - 20.0, te + 20.0))
    assert [leg.known for leg in a.legs] == [True, False, False]
    assert not a.complete
    mid = a.legs[1]
    assert np.isnan(mid.t_end) and np.isnan(mid.sailed_time_s) and np.isnan(mid.loss_s)
    assert mid.note.startswith("leg 2 (top -> bottom): ")
    assert re.search(
        r"the data stop \d+ m short of 'bottom' at .* \(a gap of 4[01] s, longer "
        r"than 10 s\): time unknown$",
        mid.note,
    ), mid.note
    assert mid.optimal_time_s == pytest.approx(legs[1].time_s, rel=0.1)  # from a known start
    assert a.legs[2].note.startswith("leg 3 (bottom -> top) starts at an unknown time")
    assert a.legs[2].optimal is None and np.isnan(a.legs[2].optimal_time_s)
    assert abs(a.legs[2].t_end - legs[2].t_end) < 1.0  # the search went on after the gap
    assert a.sailed_time_s == pytest.approx(a.legs[0].sailed_time_s)
    assert a.loss_s == pytest.approx(a.legs[0].loss_s)
    assert np.isnan(a.points.loss_s[a.points.leg >= 2]).all()
    # a gap shorter than the limit is bridged: the rounding time is interpolated (the chord
    # across the 6 s gap cuts the corner of the rounding: within the gap)
    b = analyze_track(course, _without(tr, te - 2.5, te + 2.5))
    assert b.complete and abs(b.legs[1].t_end - te) < 3.5


def test_a_track_that_stops_before_the_finish_in_a_fleet(routed) -> None:
    course, legs = routed
    tr = _sailed(course, legs)
    # the data end 30 s short of the top mark, within detect_m of its rounding ray: the
    # leg's end is unknown, as across a data gap, for one boat too
    near = tr.between(tr.t_start, legs[2].t_end - 30.0)
    a = analyze_track(course, near)
    assert [leg.known for leg in a.legs] == [True, True, False]
    assert re.fullmatch(
        r"leg 3 \(bottom -> top\): the data end \d+ m short of 'top' at \S+: time unknown",
        a.legs[2].note,
    ), a.legs[2].note
    assert a.notes == (a.legs[2].note,)
    # 60 s short the track never gets within reach: alone an error, in a fleet unknown
    cut = tr.between(tr.t_start, legs[2].t_end - 60.0)
    with pytest.raises(InputError, match=r"leg 3 \(bottom -> top\): the track never rounds"):
        analyze_track(course, cut)
    a = analyze_track(course, cut, missing="unknown")
    assert [leg.known for leg in a.legs] == [True, True, False]
    assert a.legs[2].note.startswith("leg 3 (bottom -> top): the track never rounds 'top'")
    assert a.notes == (a.legs[2].note,)


# --- the fleet through the CLI -----------------------------------------------------------


def _write_csv(path: Path, tr: Track, dt: float = 0.0) -> Path:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["time", "lat", "lon"])
        for t, la, lo in zip(tr.t_s, tr.lat_deg, tr.lon_deg, strict=True):
            w.writerow([iso(float(t) + dt), f"{la:.8f}", f"{lo:.8f}"])
    return path


def _with_tail(tr: Track, seconds: int = 10) -> Track:
    """``tr`` sailed on for ``seconds`` at its last velocity (past the finish: the written
    file rounds the last fix, which lies on the finish itself)."""
    dt = np.arange(1, seconds + 1, dtype=float)
    k = tr.t_s[-1] - tr.t_s[-2]
    lat = tr.lat_deg[-1] + (tr.lat_deg[-1] - tr.lat_deg[-2]) / k * dt
    lon = tr.lon_deg[-1] + (tr.lon_deg[-1] - tr.lon_deg[-2]) / k * dt
    return Track(
        np.concatenate([tr.t_s, tr.t_s[-1] + dt]),
        np.concatenate([tr.lat_deg, lat]),
        np.concatenate([tr.lon_deg, lon]),
        tr.name,
        tr.source,
    )


def _east(tr: Track, metres: float, name: str) -> Track:
    """``tr`` sailed ``metres`` further east (another boat, abreast of it)."""
    dlon = metres / (111_320.0 * np.cos(np.radians(tr.lat_deg)))
    return Track(tr.t_s, tr.lat_deg, tr.lon_deg + dlon, name, name)


@pytest.fixture(scope="module")
def fleet_files(routed, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    course, legs = routed
    d = tmp_path_factory.mktemp("tracks")
    tr = _with_tail(_sailed(course, legs))
    # a boat 20 m east of "fast" whose data end a minute before the top mark
    cut = _east(tr, 20.0, "short").between(tr.t_start, legs[0].t_end - 60.0)
    return {
        "course": Path(course.source),
        "fast": _write_csv(d / "fast.csv", tr),
        "slow": _write_csv(d / "slow.csv", _with_tail(_sailed(course, legs, turn_at_s=60.0))),
        "short": _write_csv(d / "short.csv", cut),
        "odd": _write_csv(d / "<b>odd.csv", tr, dt=4.0),
        "day": _write_csv(d / "other-day.csv", tr, dt=86400.0),
        "far": _write_csv(
            d / "far.csv", Track(tr.t_s, tr.lat_deg + 0.45, tr.lon_deg, "far", "far")
        ),
    }


def _run(*args: str):
    return CliRunner().invoke(app, ["analyze", *args, "-q"])


def test_fleet_with_a_track_that_stops_early(fleet_files, tmp_path: Path) -> None:
    f = fleet_files
    out = tmp_path / "out"
    res = _run(str(f["course"]), str(f["fast"]), str(f["slow"]), str(f["short"]), "-o", str(out))
    assert res.exit_code == 0, res.output
    rows = list(csv.DictReader((out / "fleet.csv").open()))
    short = [r for r in rows if r["boat"] == "short"]
    assert [r["leg_rank"] for r in short] == ["", "", ""]
    assert "the track never rounds 'top'" in short[0]["note"]
    assert short[1]["note"] == "leg 1 never ended: later legs unknown"
    # the 360° turn costs the slow boat the first leg
    leg1 = {r["boat"]: r for r in rows if r["leg"] == "1"}
    assert (leg1["fast"]["leg_rank"], leg1["slow"]["leg_rank"]) == ("1", "2")
    doc = json.loads((out / "fleet.json").read_text())
    assert [b["complete"] for b in doc["boats"]] == [True, True, False]
    assert (out / "report.html").is_file() and (out / "short" / "analysis.json").is_file()
    # alone, the same track is a one-line error and nothing is written
    out2 = tmp_path / "alone"
    res = _run(str(f["course"]), str(f["short"]), "-o", str(out2))
    assert res.exit_code == 2 and "the track never rounds 'top'" in res.output
    assert "Traceback" not in res.output and not out2.exists()


def test_fleet_with_a_boat_from_another_day_or_place_leaves_it_out(
    fleet_files, tmp_path: Path
) -> None:
    f = fleet_files
    out = tmp_path / "out"
    res = _run(str(f["course"]), str(f["fast"]), str(f["day"]), str(f["far"]), "-o", str(out))
    assert res.exit_code == 0, res.output
    # one note for the class, naming both boats with their reasons
    line = next(n for n in res.output.splitlines() if n.startswith("note: another fleet"))
    assert line.startswith("note: another fleet (left out): other-day (the track runs")
    assert "another day" in line
    assert "far (during the race the track never comes within 3 km" in line
    assert sum(n.startswith("note: another fleet") for n in res.output.splitlines()) == 1
    doc = json.loads((out / "fleet.json").read_text())
    assert [b["name"] for b in doc["boats"]] == ["fast"]
    status = {e["name"]: (e["analysed"], e["status"]) for e in doc["entries"]}
    assert status == {
        "fast": (True, []),
        "other-day": (False, ["other_fleet"]),
        "far": (False, ["other_fleet"]),
    }
    assert not (out / "far").exists() and (out / "fast" / "analysis.json").is_file()
    # no boat left: one error, nothing written
    bad = tmp_path / "bad"
    res = _run(str(f["course"]), str(f["day"]), str(f["far"]), "-o", str(bad))
    assert res.exit_code == 2
    msg = "no boat of the 2 tracks can be analysed: another fleet (left out): other-day"
    assert msg in res.output
    assert "Traceback" not in res.output and not bad.exists()


def test_per_boat_leg_times(fleet_files, routed, tmp_path: Path) -> None:
    f = fleet_files
    course, _ = routed
    t0 = iso(course.start_epoch + 5.0)
    out = tmp_path / "out"
    res = _run(
        str(f["course"]),
        str(f["fast"]),
        str(f["slow"]),
        "-o",
        str(out),
        "--leg-times",
        f"slow={t0},-,-,-",
        "--no-plots",
    )
    assert res.exit_code == 0, res.output
    doc = {b["name"]: b for b in json.loads((out / "fleet.json").read_text())["boats"]}
    assert doc["slow"]["start"]["start_time"] == t0 and not doc["slow"]["start"]["detected"]
    assert doc["fast"]["start"]["detected"]
    for bad, msg in (
        (f"{t0},-,-,-", "with several tracks name the boat"),
        (
            f"nobody={t0},-,-,-",
            "no track named 'nobody'; boats are the track file names without extension: fast, slow",
        ),
    ):
        res = _run(
            str(f["course"]),
            str(f["fast"]),
            str(f["slow"]),
            "-o",
            str(tmp_path / "bad"),
            "--leg-times",
            bad,
        )
        assert res.exit_code == 2 and msg in res.output, res.output
        assert not (tmp_path / "bad").exists()
    with pytest.raises(InputError, match="boat 'a' given twice"):
        parse_boat_leg_times([f"a={t0},-,-,-", f"a={t0},-,-,-"], ["a", "b"], 3)
    assert parse_boat_leg_times(f"{t0},-,-,-", ["a"], 3)["a"] == [
        course.start_epoch + 5.0,
        None,
        None,
        None,
    ]


def test_fleet_page_escapes_names_and_draws_every_boat(fleet_files, tmp_path: Path) -> None:
    from sailroute.report.page_render import read_figure

    f = fleet_files
    out = tmp_path / "out"
    res = _run(str(f["course"]), str(f["fast"]), str(f["slow"]), str(f["odd"]), "-o", str(out))
    assert res.exit_code == 0, res.output
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "<b>odd" not in page and "&lt;b&gt;odd" in page
    fig = read_figure(page)
    names = [t["name"] for t in fig["data"] if t.get("mode") == "lines"]
    for boat in ("fast", "slow", "&lt;b&gt;odd"):
        assert boat in names
    assert any(n.startswith("optimal from fast") for n in names)  # the leader's
    markers = [t for t in fig["data"] if t["name"].startswith("boat: ")]
    assert len(markers) == 3 and all("<" not in t["name"] for t in markers)
    assert len(fig["frames"]) == 60
    for caption in ("<h2>Results: ", "<h2>Leg times", "<h2>Start</h2>", "<summary>Leg 1: "):
        assert caption in page


@pytest.mark.browser
def test_fleet_page_in_chromium(fleet_files, tmp_path: Path) -> None:
    from tests.report.test_report_browser import CHROMIUM, REQUIRED, dom

    if CHROMIUM is None and not REQUIRED:
        pytest.skip("no Chromium installed")
    f = fleet_files
    out = tmp_path / "out"
    res = _run(str(f["course"]), str(f["fast"]), str(f["slow"]), str(f["short"]), "-o", str(out))
    assert res.exit_code == 0, res.output
    html = dom(out / "report.html", step=30)  # asserts a silent console
    assert 'data-map="drawn"' in html and 'id="sailroute-error"></div>' in html
    for entry in ("fast", "slow", "short", "optimal from fast's leg starts"):
        assert f">{entry}</text>" in html, entry


GATE_COURSE = """\
name: gate
start_time: "2024-05-01T12:00:00Z"
origin: {lat: 45.0, lon: 13.0}
marks:
  pin: {x: -60, y: 0}
  boat: {x: 60, y: 0}
  G1: {x: -50, y: 500}
  G2: {x: 50, y: 500}
lines:
  start: [pin, boat]
gates:
  G: [G1, G2]
legs:
  - {to: G}
  - {to: start}
scenarios:
  steady: {type: uniform, tws_kn: 10, twd_deg: 180}
"""


def test_a_gate_leg_ends_at_the_line_or_at_the_rounding(tmp_path: Path) -> None:
    from sailroute.analysis.segment import segment_track
    from sailroute.course.load import load_course

    p = tmp_path / "gate.yaml"
    p.write_text(GATE_COURSE, encoding="utf-8")
    course = load_course(p)
    # 5 m/s north at x = -20 through the gate (y = 500 at t = 120 s), round G1 (x = -50)
    # to port on a 30 m circle, then south-east back through the line
    gun = course.start_epoch
    t1 = np.arange(0.0, 120.0)
    x1, y1 = np.full(t1.size, -20.0), -100.0 + 5.0 * t1
    ang = np.linspace(0.0, np.pi, 20)  # from east of G1, anticlockwise over the top
    ta = 120.0 + ang * 30.0 / 5.0
    xa, ya = -50.0 + 30.0 * np.cos(ang), 500.0 + 30.0 * np.sin(ang)
    t2 = ta[-1] + np.arange(1.0, 130.0)
    x2 = -80.0 + 80.0 * (t2 - ta[-1]) / 120.0
    y2 = 500.0 - 4.5 * (t2 - ta[-1])
    t, x, y = (np.concatenate(v) for v in ((t1, ta, t2), (x1, xa, x2), (y1, ya, y2)))
    line = segment_track(course, gun - 20.0 + t, x, y)
    rnd = segment_track(course, gun - 20.0 + t, x, y, gate_end="rounding")
    assert line.ends[0].t == pytest.approx(gun - 20.0 + 120.0, abs=1e-6)
    late = rnd.ends[0].t - line.ends[0].t
    assert 3.0 < late < 12.0  # over the top of G1 (a half circle takes 18.8 s)
    assert np.hypot(rnd.ends[0].x + 50.0, rnd.ends[0].y - 500.0) == pytest.approx(30.0, abs=2.0)
    assert abs(rnd.ends[1].t - line.ends[1].t) < 1.0  # the finish is the same
    with pytest.raises(InputError, match="gate end 'mark': expected 'line' or 'rounding'"):
        segment_track(course, gun - 20.0 + t, x, y, gate_end="mark")
