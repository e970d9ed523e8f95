"""A fleet never stops for one boat: every kind of bad or odd track is classified before the
debrief, once per class, and the rest is analysed.  Tracks are made from sailroute's own
route round the windward-leeward course of ``test_analyze.py``."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.analysis.fleet import LegTable
from sailroute.analysis.segment import LegIssue, segment_track
from sailroute.analysis.triage import BoatClass, class_notes, cut_at_gaps, triage_fleet
from sailroute.cli import app
from sailroute.course.load import build_specs, load_course
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.planning.route import route_course, settings_for
from sailroute.routing.types import LegResult
from sailroute.track.model import Track
from tests.analysis.test_analyze import _course, _sailed
from tests.analysis.test_fleet import GATE_COURSE, _east, _with_tail, _write_csv


@pytest.fixture(scope="module")
def routed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Course, list[LegResult]]:
    course = _course(tmp_path_factory.mktemp("triage"))
    boat, winds = build_specs(course, ["steady"])
    return course, route_course(course, winds["steady"], boat, settings_for(course))


def _lead(tr: Track, seconds: float) -> Track:
    """``tr`` with ``seconds`` more of its first heading before it (a longer approach to
    the line), at its first speed, 1 Hz."""
    dt = tr.t_s[1] - tr.t_s[0]
    back = np.arange(seconds, 0.0, -1.0)
    lat = tr.lat_deg[0] - (tr.lat_deg[1] - tr.lat_deg[0]) / dt * back
    lon = tr.lon_deg[0] - (tr.lon_deg[1] - tr.lon_deg[0]) / dt * back
    return Track(
        np.concatenate([tr.t_s[0] - back, tr.t_s]),
        np.concatenate([lat, tr.lat_deg]),
        np.concatenate([lon, tr.lon_deg]),
        tr.name,
        tr.source,
    )


def _boat(base: Track, name: str, east: float = 0.0, dt: float = 0.0) -> Track:
    """Another boat: ``base`` sailed ``east`` metres further east, ``dt`` seconds later."""
    tr = _east(base, east, name)
    return Track(tr.t_s + dt, tr.lat_deg, tr.lon_deg, name, f"{name}.csv")


def _stretched(tr: Track, gun: float, factor: float, name: str) -> Track:
    """``tr`` sailed ``factor`` times as long from the gun (0.7: a faster class)."""
    return Track(gun + (tr.t_s - gun) * factor, tr.lat_deg, tr.lon_deg, name, f"{name}.csv")


def _joined(a: Track, b: Track, name: str) -> Track:
    return Track(
        np.concatenate([a.t_s, b.t_s]),
        np.concatenate([a.lat_deg, b.lat_deg]),
        np.concatenate([a.lon_deg, b.lon_deg]),
        name,
        f"{name}.csv",
    )


CLEAN = ((-10.0, 0.0), (-6.0, 1.0), (-2.0, 2.0), (2.0, 1.0), (6.0, 0.0), (10.0, 2.5))
"""East offset [m] and start delay [s] of the clean boats (a boat more than the marks'
tolerance, 15 m, to one side would round one of them on the wrong side)."""


@pytest.fixture(scope="module")
def fleet(routed) -> tuple[Course, list[LegResult], dict[str, Track | Exception]]:
    course, legs = routed
    gun = course.start_epoch
    base = _lead(_with_tail(_sailed(course, legs)), 120.0)
    boats: dict[str, Track | Exception] = {
        f"c{k}": _boat(base, f"c{k}", e, dt) for k, (e, dt) in enumerate(CLEAN)
    }
    late = _boat(base, "late", 4.0, 45.0)
    ocs = _boat(base, "ocs", -4.0, -8.0)
    # below the line all along, reaching to and fro 80 m short of it
    t = gun + np.arange(-300.0, 1500.0)
    x, y = 60.0 * np.sin(t / 60.0), np.full(t.size, -80.0)
    lat, lon = course.frame.to_latlon(x, y)
    nostart = Track(t, lat, lon, "nostart", "nostart.csv")
    retired = base.between(base.t_start, legs[1].t_start + 60.0)
    gap = _boat(base, "gap", 0.0, 1.5)
    mid = legs[0].t_start + 100.0
    keep = (gap.t_s < mid) | (gap.t_s > mid + 40.0)
    multi = _boat(base, "multi", 8.0, 0.5)
    boats.update(
        {
            "late": late,
            "ocs": ocs,
            "nostart": nostart,
            "retired": _boat(retired, "retired", -8.0, 0.5),
            "copy": _boat(boats["c0"], "copy"),  # type: ignore[arg-type]
            "day": _boat(base, "day", 0.0, 86400.0),
            "far": Track(base.t_s, base.lat_deg + 0.45, base.lon_deg, "far", "far.csv"),
            "empty": InputError("empty.csv: the file has a header but no data rows"),
            "fast": _stretched(_boat(base, "fast", 12.0, 0.0), gun, 0.7, "fast"),
            # the next race on the same course an hour later, after a gap
            "multi": _joined(multi, _boat(multi, "multi", 0.0, 4000.0), "multi"),
            "gap": Track(gap.t_s[keep], gap.lat_deg[keep], gap.lon_deg[keep], "gap", "gap.csv"),
        }
    )
    return course, legs, boats


@pytest.fixture(scope="module")
def triaged(fleet):
    course, _, boats = fleet
    entries = [(n, f"{n}.csv", tr) for n, tr in boats.items()]
    return triage_fleet(course, entries)


EXPECTED = {
    "late": {BoatClass.LATE_START},
    "ocs": {BoatClass.OCS},
    "nostart": {BoatClass.NON_STARTER},
    "retired": {BoatClass.RETIRED},
    "copy": {BoatClass.DUPLICATE},
    "day": {BoatClass.OTHER_FLEET},
    "far": {BoatClass.OTHER_FLEET},
    "empty": {BoatClass.EMPTY},
    "fast": {BoatClass.OTHER_FLEET},
    "multi": {BoatClass.MULTI_RACE},
    "gap": {BoatClass.DATA_GAP},
}


def test_every_kind_of_track_is_classified(triaged) -> None:
    got = {e.name: set(e.status.classes) for e in triaged.entries}
    for k in range(len(CLEAN)):
        assert got[f"c{k}"] == set(), got[f"c{k}"]
    for name, want in EXPECTED.items():
        assert got[name] == want, (name, got[name])
    analysed = {e.name for e in triaged.analysed}
    left_out = {"nostart", "copy", "day", "far", "empty", "fast"}
    assert analysed == set(got) - left_out
    ranked = {e.name for e in triaged.entries if e.status.ranked and e.analysed}
    assert ranked == analysed - {"ocs", "retired"}


def test_one_note_per_class_naming_its_boats(triaged) -> None:
    notes = class_notes(triaged.entries)
    by_class = {}
    for k in BoatClass:
        mine = [n for n in notes if n.startswith(k.value + " (")]
        assert len(mine) <= 1, mine
        if mine:
            by_class[k] = mine[0]
    assert by_class[BoatClass.OTHER_FLEET].startswith("another fleet (left out): day (the track")
    assert (
        "; far (during the race the track never comes within 3 km"
        in by_class[BoatClass.OTHER_FLEET]
    )
    assert "; fast (its legs take 0.70 times the fleet's median" in by_class[BoatClass.OTHER_FLEET]
    assert by_class[BoatClass.DUPLICATE] == (
        "duplicate track (left out): copy (the same data as c0)"
    )
    assert by_class[BoatClass.EMPTY] == (
        "empty or unreadable track (left out): empty (empty.csv: the file has a header but "
        "no data rows)"
    )
    assert by_class[BoatClass.RETIRED].startswith(
        "retired or data end mid-race (analysed, no place in the results): retired ("
    )
    assert re.fullmatch(
        r"data gap during the race \(analysed and ranked\): gap \(4\d s in leg 1\)",
        by_class[BoatClass.DATA_GAP],
    ), by_class[BoatClass.DATA_GAP]
    assert by_class[BoatClass.NON_STARTER].startswith(
        "did not start (left out): nostart (never crosses the start line"
    )


def test_late_starter_seconds_and_metres_behind_the_line(triaged, fleet) -> None:
    course, _, boats = fleet
    late = next(e for e in triaged.entries if e.name == "late")
    st = late.segmentation.start
    # 45 s after the others, less the fleet's clock offset (its front row 0-2.5 s late)
    assert st.late and st.late_s == pytest.approx(45.0 - triaged.start.time_offset_s, abs=1.5)
    # ... from where it was at the gun, behind the line (y = 0 from x = -60 to 60 m)
    x, y = course.frame.to_xy(boats["late"].lat_deg, boats["late"].lon_deg)
    t = boats["late"].t_s
    gx, gy = np.interp(st.gun_t, t, x), np.interp(st.gun_t, t, y) - st.shift_m
    assert gy < -50.0 and st.side_at_gun == "pre-start"
    behind = np.hypot(max(abs(gx) - 60.0, 0.0), gy)
    assert st.distance_at_gun_m == pytest.approx(behind, abs=0.01)
    (finding,) = late.status.findings
    assert finding.detail == (
        f"+{st.late_s:.0f} s, {st.distance_at_gun_m:.0f} m behind the line at the gun"
    )


def test_over_early_called_with_its_margin(triaged) -> None:
    ocs = next(e for e in triaged.entries if e.name == "ocs")
    st = ocs.segmentation.start
    assert st.ocs and not st.ocs_returned and st.ocs_s == pytest.approx(8.0, abs=1.5)
    assert st.ocs_sd > 3.0 and st.ocs_p > 0.998
    # the clean boats 0-2.5 s late are not called, nor timed from the gun
    for k in range(len(CLEAN)):
        c = next(e for e in triaged.entries if e.name == f"c{k}").segmentation.start
        assert c.ocs_s is None and not c.late and c.crossing.detected


def test_a_log_of_two_races_is_cut_and_never_bridged(triaged, fleet) -> None:
    course, legs, _ = fleet
    multi = next(e for e in triaged.entries if e.name == "multi")
    assert multi.cut is not None and multi.track.t_end < course.start_epoch + 3000.0
    (finding,) = multi.status.findings
    assert re.search(r", a gap of \d+ s after$", finding.detail), finding.detail
    ends = [c.t for c in multi.segmentation.ends]
    np.testing.assert_allclose(ends, [leg.t_end + 0.5 for leg in legs], atol=1.5)


def test_data_that_end_mid_race_are_not_bridged_into_the_next(routed) -> None:
    """A log that stops in the middle of leg 2 and goes on an hour later in the next race
    on the same course: leg 2 and the later ones are unknown, not a leg of an hour."""
    course, legs = routed
    base = _lead(_with_tail(_sailed(course, legs)), 120.0)
    boats = [_boat(base, f"c{k}", e, dt) for k, (e, dt) in enumerate(CLEAN)]
    first = base.between(base.t_start, legs[1].t_start + 60.0)
    boats.append(_joined(first, _boat(base, "x", 0.0, 3600.0), "stop"))
    tri = triage_fleet(course, [(b.name, b.source, b) for b in boats])
    stop = tri.entries[-1]
    assert set(stop.status.classes) == {BoatClass.MULTI_RACE, BoatClass.RETIRED}
    seg = stop.segmentation
    assert seg.ends[0].known and not any(c.known for c in seg.ends[1:])
    assert seg.ends[1].issue in (LegIssue.NOT_REACHED, LegIssue.DATA_STOP)
    # without the cut, the next race's rounding would end leg 2 an hour later
    x, y = course.frame.to_xy(boats[-1].lat_deg, boats[-1].lon_deg)
    raw = segment_track(course, boats[-1].t_s, x, y, missing="unknown")
    assert raw.ends[1].t - raw.ends[0].t > 3000.0


def test_cut_at_gaps_keeps_the_race_around_the_gun() -> None:
    t = np.concatenate(
        [np.arange(0.0, 100.0), np.arange(1000.0, 1500.0), np.arange(3000.0, 3100.0)]
    )
    assert cut_at_gaps(t, 1200.0, 300.0) == (100, 600)
    # the gun in a long gap: the part after it
    assert cut_at_gaps(t, 500.0, 300.0) == (100, 600)
    # and at the race's end: the data gap that ends after it, then the end itself
    assert cut_at_gaps(t, 1200.0, 5000.0, end_t=2000.0, gap_s=10.0) == (0, 600)
    assert cut_at_gaps(t, 50.0, 5000.0, end_t=900.0, gap_s=10.0) == (0, 100)
    assert cut_at_gaps(t, 50.0, 5000.0, end_t=1200.0, gap_s=10.0) == (0, 301)


def test_leg_table_totals_over_common_legs_and_the_leader_from_known_legs() -> None:
    """The real leader's finish is unknown: it is not the first finisher with a known
    time who leads, and totals are over the legs every ranked boat has."""
    nan = np.nan
    time_s = np.array(
        [
            [100.0, 200.0, 300.0, nan],  # A: fastest, finish unknown
            [110.0, 210.0, 310.0, 90.0],  # B: finish known
            [120.0, nan, 330.0, 95.0],  # C: leg 2 unknown (a gap)
            [130.0, 220.0, nan, nan],  # D: retired (not ranked)
        ]
    )
    end_s = np.array(
        [
            [100.0, 300.0, 600.0, nan],
            [110.0, 320.0, 630.0, 720.0],
            [120.0, nan, 660.0, 755.0],
            [130.0, 350.0, nan, nan],
        ]
    )
    tab = LegTable(
        ("A", "B", "C", "D"),
        ("1", "2", "3", "4"),
        time_s,
        end_s,
        np.zeros_like(time_s),
        np.array([True, True, True, False]),
    )
    assert tab.common_legs() == (0, 2)  # legs 1 and 3: every ranked boat has them
    np.testing.assert_allclose(tab.totals()[:3], [400.0, 420.0, 450.0])
    assert np.isnan(tab.totals()[3])
    assert tab.last_common_end() == 2 and tab.leader() == "A"
    assert tab.positions(3) == [None, 1, 2, None]  # the finish: unknown stays unknown
    assert tab.leg_ranks(1) == [1, 2, None, 3]


def test_bad_input_in_a_fleet_is_one_line_each(fleet, tmp_path: Path) -> None:
    """An empty track, a track of another day, the same file twice: one note each, the
    rest analysed (exit 0); a fleet where nobody starts: exit 2, nothing written."""
    course, _, boats = fleet
    cp = Path(course.source)
    c0 = _write_csv(tmp_path / "c0.csv", boats["c0"])  # type: ignore[arg-type]
    c1 = _write_csv(tmp_path / "c1.csv", boats["c1"])  # type: ignore[arg-type]
    empty = tmp_path / "empty.csv"
    empty.write_text("time,lat,lon\n", encoding="utf-8")
    day = _write_csv(tmp_path / "day.csv", boats["c2"], dt=86400.0)  # type: ignore[arg-type]
    out = tmp_path / "out"
    run = CliRunner().invoke(
        app,
        [
            *("analyze", str(cp), str(c0), str(c1), str(empty), str(day), str(c0)),
            *("-o", str(out), "-q", "--no-plots"),
        ],
    )
    assert run.exit_code == 0, run.output
    notes = [n for n in run.output.splitlines() if n.startswith("note: ")]
    assert [n for n in notes if "empty" in n] == [
        "note: empty or unreadable track (left out): empty ("
        + str(empty)
        + ": the file has a header but no data rows)"
    ]
    assert sum("another fleet (left out): day (the track runs" in n for n in notes) == 1
    assert [n for n in notes if "duplicate" in n] == [
        "note: duplicate track (left out): c0-2 (the same data as c0)"
    ]
    doc = json.loads((out / "fleet.json").read_text())
    assert [b["name"] for b in doc["boats"]] == ["c0", "c1"]
    assert [e["analysed"] for e in doc["entries"]] == [True, True, False, False, False]
    # nobody starts: one error, nothing written
    ns = _write_csv(tmp_path / "nostart.csv", boats["nostart"])  # type: ignore[arg-type]
    ns2 = _write_csv(tmp_path / "nostart2.csv", _east(boats["nostart"], 30.0, "n2"))  # type: ignore[arg-type]
    bad = tmp_path / "bad"
    run = CliRunner().invoke(app, ["analyze", str(cp), str(ns), str(ns2), "-o", str(bad), "-q"])
    assert run.exit_code == 2
    assert "no boat of the 2 tracks can be analysed: did not start (left out): nostart (" in (
        run.output
    )
    assert "Traceback" not in run.output and not bad.exists()


GATE_LEGS = """\
legs:
  - {to: G}
  - {to: start}
"""


@pytest.fixture()
def gate_course(tmp_path: Path) -> Course:
    p = tmp_path / "gate.yaml"
    p.write_text(GATE_COURSE, encoding="utf-8")
    return load_course(p)


def _polyline(course: Course, pts: list[tuple[float, float]], speed: float = 5.0):
    """A 1 Hz track along the points (course frame [m]) at ``speed``, from 20 s before the
    gun."""
    p = np.array(pts, float)
    seg = np.hypot(*np.diff(p, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    tq = np.arange(0.0, s[-1] / speed, 1.0)
    x = np.interp(tq * speed, s, p[:, 0])
    y = np.interp(tq * speed, s, p[:, 1])
    return course.start_epoch - 20.0 + tq, x, y


def test_a_gate_passed_outside_its_marks_ends_the_leg_there(gate_course: Course) -> None:
    # north through the line at x = 0, then 20 m east of G2 (x = 50) over the gate's line,
    # round and back south through the start line
    t, x, y = _polyline(gate_course, [(0, -100), (70, 480), (70, 530), (40, 540), (0, -30)])
    seg = segment_track(gate_course, t, x, y, missing="unknown")
    end = seg.ends[0]
    assert end.known and end.issue is LegIssue.OUTSIDE
    assert end.note == "leg 1 (start -> G): passed outside the gate's marks, 20 m beyond 'G2'"
    assert end.y == pytest.approx(500.0, abs=1e-6) and end.x == pytest.approx(70.0, abs=1.0)
    assert seg.ends[1].known  # the next leg goes on from there
    # between the marks: no flag
    t, x, y = _polyline(gate_course, [(0, -100), (20, 480), (20, 530), (0, 540), (0, -30)])
    assert segment_track(gate_course, t, x, y).ends[0].issue is None


def test_a_gate_rounding_not_found_says_so(gate_course: Course) -> None:
    # through the gate and straight on north, no turn round either mark within 30 s, then
    # a wide loop back to the line
    t, x, y = _polyline(gate_course, [(0, -100), (0, 800), (-300, 800), (-300, 300), (0, -30)])
    seg = segment_track(gate_course, t, x, y, gate_end="rounding", missing="unknown")
    end = seg.ends[0]
    assert end.known and end.issue is LegIssue.GATE_LINE
    assert end.y == pytest.approx(500.0, abs=1e-6)  # timed at the gate line
    assert end.note == (
        "leg 1 (start -> G): no rounding of a gate mark found within 30 s of passing "
        "between the marks: timed at the gate line"
    )


def _recalled(course: Course, base: Track, k: int, restart_s: float) -> Track:
    """A boat that starts at the gun, sails on 60 s, comes back below the line and starts
    again ``restart_s`` after the gun along ``base`` (``k`` spreads the boats along the line
    and over the first seconds)."""
    gun = course.start_epoch
    knots_t = [-60.0, 0.0 + k, 60.0, 140.0, restart_s - 40.0]
    knots_y = [-150.0, 0.0, 150.0, -60.0, -60.0]
    t1 = np.arange(-60.0, restart_s - 40.0)
    x1 = np.full(t1.size, 10.0 * k - 20.0)
    y1 = np.interp(t1, knots_t, knots_y)
    lat, lon = course.frame.to_latlon(x1, y1)
    again = _boat(base, f"r{k}", 3.0 * k - 6.0, restart_s + 0.7 * k)
    keep = again.t_s >= gun + restart_s - 39.0
    return Track(
        np.concatenate([gun + t1, again.t_s[keep]]),
        np.concatenate([lat, again.lat_deg[keep]]),
        np.concatenate([lon, again.lon_deg[keep]]),
        f"r{k}",
        f"r{k}.csv",
    )


def _with_restart(course: Course, restart: str, folder: Path) -> Path:
    """The course file with a ``restart_time``."""
    text = Path(course.source).read_text(encoding="utf-8")
    start = 'start_time: "2024-05-01T12:00:00Z"'
    p = folder / "restart.yaml"
    p.write_text(text.replace(start, f'{start}\nrestart_time: "{restart}"'), encoding="utf-8")
    return p


def test_a_general_recall_found_in_the_tracks(routed, tmp_path: Path) -> None:
    course, legs = routed
    base = _lead(_with_tail(_sailed(course, legs)), 120.0)
    boats = [_recalled(course, base, k, 300.0) for k in range(5)]
    entries = [(b.name, b.source, b) for b in boats]
    tri = triage_fleet(course, entries)
    assert tri.recall is not None and tri.restart_estimated
    assert tri.recall.boats == tuple(f"r{k}" for k in range(5)) and tri.recall.n_started == 5
    # the restart's gun from the fleet's second start, and the legs timed from it
    gun = course.start_epoch
    assert 299.0 <= tri.start.gun_t - gun <= 301.0
    for e, b in zip(tri.entries, boats, strict=True):
        assert e.analysed and not e.status.findings, e.status
        assert abs(e.segmentation.start.crossing.t - (gun + 300.0 + 0.7 * int(b.name[1]))) < 1.5
    note = tri.notes()[0]
    assert note.startswith("general recall: 5 of 5 boats started at ")
    assert "the restart's gun is not in the course (restart_time) nor given (--gun)" in note
    # the restart given (--gun, or the course's restart_time): the race is timed from it and
    # the recall before it is noted
    given = triage_fleet(course, entries, gun_t=gun + 300.0)
    assert given.start.gun_t == gun + 300.0 and not given.restart_estimated
    assert given.notes()[0].startswith("general recall: 5 of 5 boats started at ")
    assert "came back and started again at the gun" in given.notes()[0]
    restart = load_course(_with_restart(course, "2024-05-01T12:05:00Z", tmp_path))
    assert restart.gun_epoch == gun + 300.0 and restart.start_epoch == gun
    tri = triage_fleet(restart, entries)
    assert tri.start.gun_t == gun + 300.0 and tri.recall is not None


def test_restart_time_must_follow_the_start(routed, tmp_path: Path) -> None:
    course, _ = routed
    p = _with_restart(course, "2024-05-01T11:55:00Z", tmp_path)
    with pytest.raises(InputError, match="restart_time: the restart after a general recall"):
        load_course(p)


def test_gun_option_checks_the_day(fleet, tmp_path: Path) -> None:
    course, _, boats = fleet
    c0 = _write_csv(tmp_path / "c0.csv", boats["c0"])  # type: ignore[arg-type]
    res = CliRunner().invoke(
        app,
        [
            "analyze",
            str(course.source),
            str(c0),
            "--gun",
            "2024-05-02T12:00:00Z",
            "-o",
            str(tmp_path / "o"),
        ],
    )
    assert res.exit_code == 2
    assert "--gun 2024-05-02T12:00:00Z: expected the gun of this race, within 6 h" in res.output


MARK_COURSE = (
    GATE_COURSE.replace("  G1: {x: -50, y: 500}\n  G2: {x: 50, y: 500}\n", "  M: {x: 0, y: 500}\n")
    .replace("gates:\n  G: [G1, G2]\n", "")
    .replace("  - {to: G}\n", "  - {to: M, rounding: port}\n")
)
"""Start line at y = 0, then round M (0, 500) to port and back to the line."""


def test_a_close_pass_is_timed_where_it_crosses_the_rounding_ray(tmp_path: Path) -> None:
    # north 8 m east of M, over the top (the ray points north from the mark, crossed
    # westwards) at 21° to the ray, then back south 2.5 m beside the ray's line: the
    # crossing is too shallow and never gets 4 m beyond the ray to be settled, but the
    # pass turns 180° round the mark
    p = tmp_path / "mark.yaml"
    p.write_text(MARK_COURSE, encoding="utf-8")
    course = load_course(p)
    pts = [(8, -100), (8, 495), (3, 503), (-2, 490), (-2.5, 440), (-2.5, -30)]
    t, x, y = _polyline(course, pts, speed=2.0)
    end = segment_track(course, t, x, y).ends[0]
    # where the path crosses the ray (x = 0, leaning 0.5° towards the start at x = 8, the
    # fixes cutting the corner at (3, 503)): 3/5 of the way from (3, 503) to (−2, 490),
    # not at the fix closest to the mark (1.7 m east of the ray)
    assert end.x == pytest.approx(0.0, abs=0.1)
    assert end.y == pytest.approx(503.0 - 0.6 * 13.0, abs=0.3)
    s = 595.0 + math.hypot(5.0, 8.0) + 0.6 * math.hypot(5.0, 13.0)
    assert end.t == pytest.approx(course.start_epoch - 20.0 + s / 2.0, abs=0.1)
