"""Marks from the fleet: turns, roundings, clusters, the course, the gun and the lines.

The parts are checked on paths whose answer follows from their construction (a track with
a tack, a mark rounding and a gybe; a knee drawn into a line; two groups of roundings),
the whole on fleets sailed by sailroute's router round known marks (``tests/fleetgen.py``)
and, with ``../shared`` present, on two real races: the 49erFX Worlds 2019 race F13 (25
boats at 1 Hz, no marks, no results) and SailGP Auckland 2025 race 25011905, whose race
XML gives the marks and the start time.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from types import MappingProxyType

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from sailroute.analysis.infer_lines import hinge_knee
from sailroute.analysis.infer_marks import (
    InferredCourse,
    _clusters,
    _consensus,
    _Rounding,
    infer_course,
)
from sailroute.analysis.turns import Turn, find_turns, is_rounding, sail_change_deg, simplify
from sailroute.cli import app
from sailroute.course.formats import ImportedCourse, course_yaml
from sailroute.course.load import load_course
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.timeutil import from_epoch, parse_time, to_epoch
from sailroute.track.model import Track
from sailroute.track.read import read_track
from tests.conftest import SHARED_REAL, requires_shared
from tests.fleetgen import FaultPlan, Fleet, messy_fleet, write_gpx

runner = CliRunner()
FRAME = LocalFrame(43.05, 6.25)
T0 = to_epoch(parse_time("2024-06-01T13:00:00Z"))


# ------------------------------------------------------------------------------ helpers
def path_of(legs: Sequence[tuple[float, float]], speed: float = 4.0, dt: float = 1.0):
    """Fixes every ``dt`` s of a boat sailing ``(course [°], seconds)`` legs at ``speed``."""
    t, x, y = [0.0], [0.0], [0.0]
    for course, seconds in legs:
        c = math.radians(course)
        for _ in range(round(seconds / dt)):
            t.append(t[-1] + dt)
            x.append(x[-1] + speed * dt * math.sin(c))
            y.append(y[-1] + speed * dt * math.cos(c))
    return np.array(t) + T0, np.array(x), np.array(y)


def as_track(t, x, y, name: str) -> Track:
    lat, lon = FRAME.to_latlon(x, y)
    return Track(np.asarray(t, float), lat, lon, name, "test", MappingProxyType({}), ())


def seg_dist(p, a, b) -> float:
    """Distance of the point ``p`` from the segment ``a``-``b`` [m]."""
    p, a, b = (np.asarray(v, float) for v in (p, a, b))
    e = b - a
    f = float(np.clip((p - a) @ e / (e @ e), 0.0, 1.0))
    return float(np.hypot(*(p - (a + f * e))))


def in_frame(ic: InferredCourse, frame: LocalFrame, xy) -> tuple[float, float]:
    """A point of the inferred course's frame in ``frame`` [m]."""
    lat, lon = ic.latlon(xy)
    x, y = frame.to_xy(lat, lon)
    return float(x), float(y)


def nearest(fleet: Fleet, ic: InferredCourse, name: str) -> tuple[str, float]:
    """The true mark nearest the inferred mark ``name``, and how far [m]."""
    m = ic.mark(name)
    x, y = fleet.course.frame.to_xy(m.lat, m.lon)
    d = {k: math.hypot(v[0] - float(x), v[1] - float(y)) for k, v in fleet.marks.items()}
    k = min(d, key=d.get)  # type: ignore[arg-type]
    return k, d[k]


# -------------------------------------------------------------------------------- turns
def test_simplify_keeps_the_corners_of_a_noisy_dogleg():
    _, x, y = path_of([(0.0, 50.0), (90.0, 50.0)])
    rng = np.random.default_rng(1)
    keep = simplify(x + rng.normal(0, 1.0, x.size), y + rng.normal(0, 1.0, y.size), 5.0)
    # the two ends and the corner (fix 50), nothing else within 5 m of the straight legs
    assert keep[0] == 0 and keep[-1] == x.size - 1
    assert any(abs(k - 50) <= 2 for k in keep) and len(keep) <= 5


def test_a_tack_and_a_gybe_keep_the_point_of_sail_and_a_rounding_changes_it():
    """Wind from 0°: a port-tack beat (45°), a tack to starboard (315°), the windward mark
    left to port (a bear-away left to a broad reach, 160°) and a gybe (200°)."""
    t, x, y = path_of([(45.0, 60.0), (315.0, 60.0), (160.0, 60.0), (200.0, 60.0)])
    turns, courses, seconds = find_turns(t, x, y, 5.0)
    assert len(turns) == 3
    tack, rounding, gybe = turns
    assert tack.turn_deg == pytest.approx(-90.0, abs=1.0)
    assert rounding.turn_deg == pytest.approx(-155.0, abs=1.0) and rounding.side == "port"
    assert gybe.turn_deg == pytest.approx(40.0, abs=1.0) and gybe.side == "starboard"
    assert [sail_change_deg(u, 0.0) for u in turns] == pytest.approx([0.0, 115.0, 0.0], abs=1.0)
    assert [is_rounding(u, 0.0) for u in turns] == [False, True, False]
    # the wind's end does not matter, only its axis
    assert [is_rounding(u, 180.0) for u in turns] == [False, True, False]
    # the rounding's apex is the corner (after 120 s), the boards are the four legs
    assert math.hypot(rounding.x - x[120], rounding.y - y[120]) < 5.0
    assert sorted(np.round(courses)) == [45.0, 160.0, 200.0, 315.0]
    assert seconds.sum() == pytest.approx(240.0, abs=8.0)


def test_a_gybe_between_two_reaches_is_a_gybe_mark():
    """|TWA| 100° on both boards (wind from 0°): a turn of 160° only a gybe mark makes."""
    t, x, y = path_of([(100.0, 60.0), (260.0, 60.0)])
    (turn,), *_ = find_turns(t, x, y, 5.0)
    assert sail_change_deg(turn, 0.0) == pytest.approx(0.0, abs=1.0)
    assert is_rounding(turn, 0.0)


def test_outward_points_from_the_inside_of_the_turn_to_the_apex():
    u = Turn(0.0, 0.0, 0.0, 90.0, 270.0, -180.0, 5.0)  # east, then back west: a U-turn
    assert u.outward == pytest.approx((1.0, 0.0), abs=1e-9)
    corner = Turn(0.0, 0.0, 0.0, 0.0, 90.0, 90.0, 0.0)  # north, then right to east
    assert corner.outward == pytest.approx((-math.sqrt(0.5), math.sqrt(0.5)), abs=1e-9)


# ---------------------------------------------------------------------- gun, clusters
def test_hinge_knee_finds_a_drawn_knee_under_noise():
    t = np.arange(0.0, 300.0)
    r = np.where(t < 120.0, 1000.0, 1000.0 - 3.0 * (t - 120.0))
    r = r + np.random.default_rng(2).normal(0.0, 5.0, t.size)
    knee, before, after = hinge_knee(t, r, 20.0, 280.0)
    assert knee == pytest.approx(120.0, abs=3.0)
    assert before == pytest.approx(0.0, abs=0.2) and after == pytest.approx(-3.0, abs=0.1)


def _rounding(boat: int, xy: tuple[float, float], turn_deg: float = -120.0) -> _Rounding:
    return _Rounding(boat, Turn(0.0, *xy, 0.0, 120.0, turn_deg, 5.0), xy)


def test_a_cluster_needs_boats_not_roundings():
    """Six boats round at one place, one boat six times at another: only the first is a mark;
    the same place rounded the other way is not a neighbour."""
    fleet = [_rounding(b, (b * 2.0, 0.0)) for b in range(6)]
    alone = [_rounding(9, (500.0 + k, 0.0)) for k in range(6)]
    other_way = [_rounding(b, (b * 2.0, 1.0), turn_deg=120.0) for b in range(2)]
    label = _clusters([*fleet, *alone, *other_way], 30.0, 3)
    assert set(label[:6]) == {0}
    assert set(label[6:]) == {-1}


def test_the_course_is_the_sequence_most_boats_share():
    seqs = [[0, 1, 0, 2], [0, 1, 0, 2], [0, 0, 2], [0, 1, 0, 2, 3], [0, 1, 2]]
    course, support = _consensus(seqs)
    assert course == [0, 1, 0, 2]
    # each boat: items shared minus half the course's length
    assert support == pytest.approx((4 + 4 + 3 + 4 + 3) - 5 * 2.0)


# ------------------------------------------------------------------------------ writer
def test_comments_never_spill_into_keys():
    """Line breaks (``\\n``, NEL, LS, PS: YAML breaks lines at each) in the header and the
    mark notes stay in their comment."""
    ic = ImportedCourse("c", (("A", 43.0, 6.0), ("B", 43.01, 6.0)), (), (), "A", (("B", "port"),))
    evil = "x\nstart_time: 1\x85marks: {}\u2028legs: []\u2029name: y"
    text = course_yaml(
        ic,
        source="",
        fmt="",
        twd_deg=0.0,
        tws_kn=10.0,
        start_time=from_epoch(T0),
        header=[evil],
        mark_notes={"A": evil},
    )
    data = yaml.safe_load(text)
    assert set(data) == {"name", "start_time", "marks", "legs", "scenarios"}
    assert data["name"] == "c" and set(data["marks"]) == {"A", "B"}


# --------------------------------------------------------------------------- bad input
def test_bad_fleets_are_refused_in_one_line():
    t, x, y = path_of([(45.0, 60.0), (315.0, 60.0), (160.0, 60.0)])
    one = as_track(t, x, y, "a")
    with pytest.raises(InputError, match="1 track given; the marks are where a fleet turns"):
        infer_course([one])
    far = as_track(t, x + 300_000.0, y, "b")
    with pytest.raises(InputError, match="lies 300 km from the rest of the fleet"):
        infer_course([one, far, as_track(t, x + 1.0, y, "c")])
    st, sx, sy = path_of([(45.0, 300.0)])
    with pytest.raises(InputError, match="no mark roundings in the tracks"):
        infer_course([as_track(st, sx, sy, "a"), as_track(st, sx + 20.0, sy, "b")])
    with pytest.raises(InputError, match="do not overlap in time"):
        infer_course([one, as_track(t + 86_400.0, x, y, "d")])


def test_course_infer_errors_are_one_line_and_exit_2(tmp_path):
    t, x, y = path_of([(45.0, 60.0), (315.0, 60.0), (160.0, 60.0)])
    a = write_gpx(tmp_path / "a.gpx", as_track(t, x, y, "a"))
    b = write_gpx(tmp_path / "b.gpx", as_track(t + 86_400.0, x, y, "b"))
    out = str(tmp_path / "c.yaml")
    for args, text in (
        ([str(a)], "1 track given"),
        ([str(a), str(b)], "do not overlap in time"),
        ([str(a), str(a)], "the 2 files hold one track (left out as copies: "),
    ):
        res = runner.invoke(app, ["course", "infer", *args, "-o", out, "--wind-tws", "10"])
        assert res.exit_code == 2, res.output
        assert res.output.startswith("error: ") and text in res.output
        assert res.output.count("\n") == 1
    res = runner.invoke(app, ["course", "infer", str(a), str(a), "-o", out])
    assert res.exit_code == 2 and "--wind-tws is required" in res.output


# ---------------------------------------------------------------------- generated fleet
@pytest.fixture(scope="module")
def fleet() -> Fleet:
    """20 boats round a windward mark, a leeward gate and the mark again, with GPS noise
    (1.5 m white, 2 m correlated) and fixes every 1-3 s."""
    plan = FaultPlan.clean(noise_white_m=1.5, noise_corr_m=2.0)
    return messy_fleet(seed=3, n_boats=20, minutes=20, faults=plan, clock_lag_s=0.0)


@pytest.fixture(scope="module")
def inferred(fleet: Fleet) -> InferredCourse:
    return infer_course(list(fleet.tracks))


@pytest.mark.slow
def test_generated_fleet_marks_within_10_m(fleet, inferred):
    """Every inferred mark lies within 10 m of a true one; the windward mark is rounded by
    every boat, to port; the course goes round it twice and ends on the finish line."""
    for m in inferred.marks:
        assert nearest(fleet, inferred, m.name)[1] < 10.0, m
    first = inferred.legs[0][0]
    assert nearest(fleet, inferred, first)[0] == "1"
    assert inferred.mark(first).rounding == "port" and inferred.mark(first).n_boats == 20
    assert [leg[0] for leg in inferred.legs][2] == first
    assert inferred.legs[-1] == ("finish", None) and len(inferred.legs) == 4
    # the mark's spread is what GPS noise and steering leave: a few metres
    assert inferred.mark(first).spread_m < 10.0


@pytest.mark.slow
def test_generated_fleet_lines_and_gun(fleet, inferred):
    """The start line lies on the true one (its ends within 15 m of it); the gun is within
    three standard errors (and 10 s) of the truth; the wind within 10° of the mean TWD."""
    a, b = fleet.marks["start_pin"], fleet.marks["start_boat"]
    for end in (inferred.start.pin, inferred.start.committee):
        assert seg_dist(in_frame(inferred, fleet.course.frame, end), a, b) < 15.0
    err = inferred.gun.t - fleet.gun
    assert abs(err) <= max(3.0 * inferred.gun.sd_s, 3.0) and abs(err) < 10.0
    assert inferred.gun.source == "inferred"
    assert abs((inferred.twd_deg - fleet.wind.twd_deg + 180.0) % 360.0 - 180.0) < 10.0
    assert inferred.finish is not None and inferred.finish.n_boats >= 15


def test_course_infer_writes_a_course_that_loads_with_spreads(tmp_path):
    """The CLI writes the course file (each mark's spread in its comment) and the JSON;
    the tracks' names never reach the YAML, even one with a line break in it."""
    plan = FaultPlan.clean(noise_white_m=1.5, noise_corr_m=2.0)
    small = messy_fleet(seed=1, n_boats=8, minutes=15, faults=plan, clock_lag_s=0.0)
    _, paths = small.write(tmp_path / "in", "gpx")
    evil = (
        paths[0]
        .read_text(encoding="utf-8")
        .replace(f"<name>{small.tracks[0].name}</name>", "<name>boat\nname: evil</name>")
    )
    paths[0].write_text(evil, encoding="utf-8")
    out = tmp_path / "race.yaml"
    gun = "2024-06-01T13:00:00Z"
    res = runner.invoke(
        app,
        [
            "course",
            "infer",
            *map(str, paths),
            "-o",
            str(out),
            "--wind-tws",
            "10",
            "--start-time",
            gun,
            "--json",
        ],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    text = out.read_text(encoding="utf-8")
    assert "evil" not in text and all(tr.name not in text for tr in small.tracks)
    course = load_course(out)
    assert course.start_epoch == to_epoch(parse_time(gun))
    assert course.legs[0].to_name == course.legs[2].to_name == "M1"
    assert course.legs[-1].to_name == "finish"
    marks = {m["name"]: m for m in doc["marks"]}
    assert set(marks) <= set(course.marks) and doc["course_file"] == "race.yaml"
    for name, m in marks.items():
        line = next(t for t in text.splitlines() if t.startswith(f'  "{name}":'))
        assert f"spread {m['spread_m']:.0f} m" in line
    assert doc["gun"] == {
        "time": "2024-06-01T13:00:00.000Z",
        "source": "given",
        "sd_s": 0.0,
        "boats_spread_s": None,
    }
    assert (tmp_path / "race.marks.json").is_file()


@pytest.mark.slow
def test_messy_fleets_marks_and_start():
    """40 boats with every fault of the generator (non-starter, over early, late, gaps,
    retired, two races in one log, a copy, another class, a gate passed outside) and a
    7 s tracker lag, five seeds: the windward mark and each gate mark 5 boats or more
    rounded within 10 m, and the course round them; the start line's ends within 40 m of
    it; the gun (in the tracker's clock) within 30 s, and within three standard errors in
    four seeds of five (the start line of a fleet that reaches it from far off at speed is
    found only by where it speeds up; analysis.md, "Limits")."""
    within = 0
    for seed in (1, 2, 3, 4, 5):
        fl = messy_fleet(seed=seed, n_boats=40, minutes=30, faults=FaultPlan(), clock_lag_s=7.0)
        ic = infer_course(list(fl.tracks))
        found = {nearest(fl, ic, m.name)[0]: nearest(fl, ic, m.name)[1] for m in ic.marks}
        rounded = [b.gate_marks[1] for b in fl.boats if len(b.gate_marks) > 1]
        want = {"1"} | {g for g in ("4s", "4p") if rounded.count(g) >= 5}
        assert want <= set(found) and all(found[k] < 10.0 for k in want), (seed, found)
        first = ic.legs[0][0]
        assert nearest(fl, ic, first)[0] == "1" and ic.legs[2][0] == first, seed
        a, b = fl.marks["start_pin"], fl.marks["start_boat"]
        for end in (ic.start.pin, ic.start.committee):
            assert seg_dist(in_frame(ic, fl.course.frame, end), a, b) < 40.0, seed
        err = ic.gun.t - (fl.gun - fl.clock_lag_s)
        assert abs(err) < 30.0, (seed, err)
        within += abs(err) <= 3.0 * ic.gun.sd_s
    assert within >= 4


# -------------------------------------------------------------------------------- real
FX = SHARED_REAL / "races" / "49erfx-worlds-2019-f13"
FX_COLUMNS = {"lat": "Latitude [Deg N]", "lon": "Longitude [Deg E]", "time": "TimeStamp"}
GP = SHARED_REAL / "races" / "sailgp-auckland-2025"


@pytest.fixture(scope="module")
def fx() -> InferredCourse:
    tracks = [
        read_track(p, columns=FX_COLUMNS, speed_unit="kn", time_zone="UTC", name=p.stem)
        for p in sorted(FX.glob("*.csv"))
    ]
    return infer_course(tracks)


@requires_shared
def test_49erfx_course_from_25_boats(fx):
    """The race F13 of the 49erFX Worlds 2019: a windward mark, a leeward gate, a second
    windward mark 240 m further up the course (laid anew for the second beat), and the
    finish.  Each mark is rounded by 20 boats or more within a few metres; the gate's two
    marks are rounded opposite ways; the start line is crossed by all 25 boats."""
    assert len(fx.boats) == 25
    names = [leg[0] for leg in fx.legs]
    assert len(names) == 4 and names[1].startswith("G") and names[3] == "finish"
    w1, w2 = fx.mark(names[0]), fx.mark(names[2])
    assert w1.rounding == w2.rounding == "port" and w1.name != w2.name
    assert 200.0 < math.hypot(w2.x - w1.x, w2.y - w1.y) < 280.0
    gate = [m for m in fx.marks if m.gate == names[1]]
    assert {m.rounding for m in gate} == {"port", "starboard"}
    assert sum(m.n_boats for m in gate) >= 23
    for m in fx.marks:
        assert m.spread_m < 10.0 and (m.n_boats >= 20 or m.gate is not None)
    assert fx.start.n_boats == 25 and fx.finish is not None and fx.finish.n_boats >= 20
    # the start sequence runs on whole minutes: the inferred gun lies near one
    assert abs(fx.gun.t - round(fx.gun.t / 60.0) * 60.0) < max(3.0 * fx.gun.sd_s, 5.0)


def _xml_marks(frame: LocalFrame) -> dict[str, tuple[float, float]]:
    root = ET.parse(GP / "Race_XMLs" / "25011905_03-13-55.xml").getroot()
    out = {}
    for m in root.iter("Mark"):
        x, y = frame.to_xy(float(m.get("TargetLat", "")), float(m.get("TargetLng", "")))
        out[m.get("Name", "")] = (float(x), float(y))
    return out


@requires_shared
def test_sailgp_25011905_against_its_race_xml():
    """Three F50 logs, cut to the race: the sequence of the race XML (M1 to port, the
    leeward and windward gates twice, LG1 to port, the finish) and the gun within 3 s of
    its RaceStartTime.  The marks the XML still places where the boats rounded lie within
    30 m of it (the boats round a catamaran's length or two off a mark); the leeward gate's
    first mark was rounded ~90 m from where the XML (written at 03:13:59) puts it, where the
    fleet rounded LG1 at the end, so it had been moved."""
    cut = [to_epoch(parse_time(f"2025-01-19T03:{m}:00Z")) for m in ("05", "20")]
    tracks = [
        read_track(GP / "Boat_logs" / f"data_{b}.csv", time_zone="UTC")
        for b in ("NZL", "AUS", "GBR")
    ]
    ic = infer_course(tracks, t_from=cut[0], t_until=cut[1])
    names = [leg[0] for leg in ic.legs]
    assert names[0] == "M1" and ic.legs[0][1] == "port"
    assert names[1] == names[3] and names[2] == names[4] and names[1] != names[2]
    assert all(n.startswith("G") for n in names[1:5])
    assert ic.legs[5][1] == "port" and names[6] == "finish"
    assert abs(ic.gun.t - to_epoch(parse_time("2025-01-19T16:08:00+13:00"))) < 3.0
    xml = _xml_marks(ic.frame)

    def err(name: str, target: str) -> float:
        m = ic.mark(name)
        return math.hypot(m.x - xml[target][0], m.y - xml[target][1])

    lg, wg = (sorted(m.name for m in ic.marks if m.gate == g) for g in (names[1], names[2]))
    assert err("M1", "M1") < 30.0 and err(names[5], "LG1") < 30.0
    wg_err = sorted(min(err(n, "WG1"), err(n, "WG2")) for n in wg)
    assert wg_err[-1] < 30.0
    lg_err = sorted(min(err(n, "LG1"), err(n, "LG2")) for n in lg)
    assert lg_err[0] < 30.0 and 60.0 < lg_err[1] < 120.0


@pytest.mark.slow
@requires_shared
def test_49erfx_analyzed_in_the_inferred_course(tmp_path):
    """``course infer`` then ``analyze`` on the 49erFX race: every boat's finish is found,
    so the 25 have a finishing order, and it follows the order in which they rounded the
    last windward mark (Spearman ≥ 0.9: a run of 4-5 minutes reshuffles few places); every
    leg end not found lies in a data gap of the boat's log."""
    from sailroute.commands.analyze import run_analyze_command
    from sailroute.commands.course_infer import run_course_infer_command

    paths = sorted(FX.glob("*.csv"))
    read = {"columns": FX_COLUMNS, "speed_unit": "kn", "time_zone": "UTC"}
    res = run_course_infer_command(
        paths, out=tmp_path / "fx.yaml", wind_tws_kn=15.0, boat="{builtin: ilca7}", **read
    )
    ic = res.data
    analyses = run_analyze_command(
        load_course(tmp_path / "fx.yaml"), paths, out_dir=tmp_path / "out", plots=False, **read
    ).data
    assert len(analyses) == 25
    finish = np.array([a.legs[-1].t_end for a in analyses])
    assert np.isfinite(finish).all() and np.unique(finish).size == 25
    for a in analyses:
        for leg in a.legs:
            assert math.isfinite(leg.t_end) or "gap" in leg.note, (a.track.name, leg.note)
    last_mark = np.array(ic.leg_roundings[-2])  # the last windward mark, by boat
    order = {n: k for k, n in enumerate(ic.boats)}
    ok = np.isfinite(last_mark[[order[a.track.name] for a in analyses]])
    rank_f = np.argsort(np.argsort(finish[ok]))
    rank_m = np.argsort(np.argsort(last_mark[[order[a.track.name] for a in analyses]][ok]))
    rho = 1.0 - 6.0 * np.sum((rank_f - rank_m) ** 2) / (ok.sum() * (ok.sum() ** 2 - 1))
    assert rho >= 0.9 and ok.sum() >= 22


def test_analyze_marks_infer_needs_a_wind_speed_without_a_course_file(tmp_path):
    t, x, y = path_of([(45.0, 60.0), (315.0, 60.0), (160.0, 60.0)])
    a = write_gpx(tmp_path / "a.gpx", as_track(t, x, y, "a"))
    b = write_gpx(tmp_path / "b.gpx", as_track(t, x + 20.0, y, "b"))
    res = runner.invoke(app, ["analyze", "--marks", "infer", str(a), str(b), "-q"])
    assert res.exit_code == 2 and res.output.count("\n") == 1
    assert "--wind-tws is required: --marks infer without a course file" in res.output


@pytest.mark.slow
def test_analyze_marks_infer_keeps_the_course_file_but_its_marks(tmp_path):
    """``analyze --marks infer COURSE.yaml``: the course file's marks are 300 m off (moved),
    its boat, wind and gun are kept; the analysis runs in the inferred course (the report
    starts with it) and times every boat's finish."""
    plan = FaultPlan.clean(noise_white_m=1.5, noise_corr_m=2.0)
    small = messy_fleet(seed=1, n_boats=8, minutes=15, faults=plan, clock_lag_s=0.0)
    course, paths = small.write(tmp_path / "in", "gpx")
    data = yaml.safe_load(course.read_text(encoding="utf-8"))
    for m in data["marks"].values():
        m["x"] += 300.0
    course.write_text(yaml.safe_dump(data), encoding="utf-8")
    res = runner.invoke(
        app,
        [
            "analyze",
            "--marks",
            "infer",
            str(course),
            *map(str, paths),
            "--no-plots",
            "-q",
            "-o",
            str(tmp_path / "out"),
        ],
    )
    assert res.exit_code == 0, res.output
    assert res.output.startswith("course inferred from the tracks:\ngun ")
    assert "(given)" in res.output.splitlines()[1]
    fleet = json.loads((tmp_path / "out" / "fleet.json").read_text(encoding="utf-8"))
    finish = [r for r in fleet["legs"] if r["leg"] == 4]
    assert len(finish) == 8 and all(r["elapsed_s"] is not None for r in finish)
