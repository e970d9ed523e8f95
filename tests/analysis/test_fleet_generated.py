"""Messy fleets with a known answer (``tests/fleetgen.py``): 40 boats each, a 5-10 s tracker
clock lag, GPS error, 1-3 s fixes and every kind of fault injected on chosen boats.  No run
stops for one boat, every injected fault is classified, over-early boats are called with
precision and recall, and leg ends are found within a fix of the truth.

Measured on seeds 1-5 (lags 5, 10, 7.5, 6 with a general recall, 9 s): every fault
classified; 18 of the 20 boats over at the gun called (back or not), none wrongly (the two
missed were 0.4 s / 0.8 m and 4.0 s / 8.3 m over at the gun, 0.5 and 2.7 sd); the lag
found within 0.3-1.0 s; leg ends within half a fix of the truth without GPS error (100 %
of 552), and with the generator's error 91 % within one fix and 99 % within 3 s.  That is
the GPS error's limit, measured as the recorded fixes crossing the truth's own line
without any estimator: at 1-s fixes 76 % of the leg ends within a fix (75 % from the error
alone; windward marks 72 %, gate roundings 70 %, the finish 89 %), at 2 s 94 % (94 %), at
3 s 99 % (98 %); the detected time is the error's within 0.3 s for 98.6 %.  The error
across the line, 1.6 m (the 1.5 m correlated over 60 s, which no smoothing of one track
removes, and the 0.7 m white averaged between two fixes), over the speed across it
(1.8-2.3 m/s) is a normal error of sd 0.7-0.9 s: a second is about one sd.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from sailroute.analysis.segment import detection_geometry
from sailroute.analysis.triage import BoatClass, triage_fleet
from sailroute.track.kinematics import track_xy
from tests.fleetgen import BoatTruth, FaultPlan, Fleet, messy_fleet

pytestmark = pytest.mark.slow

RUNS = ((1, 5.0, False), (2, 10.0, False), (3, 7.5, False), (4, 6.0, True), (5, 9.0, False))
"""Seed, clock lag [s] and general recall of each fleet."""

EXPECTED = {
    "non_starter": BoatClass.NON_STARTER,
    "retired": BoatClass.RETIRED,
    "data_ends": BoatClass.RETIRED,
    "late": BoatClass.LATE_START,
    "two_races": BoatClass.MULTI_RACE,
    "other_fleet": BoatClass.OTHER_FLEET,
    "gate_outside": BoatClass.GATE_OUTSIDE,
    "data_gap": BoatClass.DATA_GAP,
}
"""Injected fault -> the class it must get (over early and duplicates are scored apart)."""


@pytest.fixture(scope="module")
def fleets() -> list[Fleet]:
    return [
        messy_fleet(
            seed=seed,
            n_boats=40,
            faults=replace(FaultPlan(), general_recall=recall),
            clock_lag_s=lag,
        )
        for seed, lag, recall in RUNS
    ]


def _triage(f: Fleet, gun_t: float | None = None):
    return triage_fleet(
        f.course, [(tr.name, tr.name, tr) for tr in f.tracks], gate_end="rounding", gun_t=gun_t
    )


def test_every_injected_fault_is_classified_and_ocs_called(fleets: list[Fleet]) -> None:
    tp = fp = fn = 0
    for f in fleets:
        tri = _triage(f)
        assert abs(tri.start.time_offset_s + f.clock_lag_s) < 2.0, tri.start.describe()
        by = {e.name: e for e in tri.entries}
        for b in f.boats:
            got = set(by[b.name].status.classes)
            for kind in b.kinds:
                if kind in EXPECTED:
                    assert EXPECTED[kind] in got, (f.seed, b.name, kind, got)
            if b.status == "ocs_returned":
                assert BoatClass.OCS_RETURNED in got, (f.seed, b.name, got)
            if b.duplicate_of is not None:  # one of the pair, naming the other
                pair = {b.name, b.duplicate_of}
                dup = [n for n in pair if BoatClass.DUPLICATE in by[n].status.classes]
                assert len(dup) == 1, (f.seed, pair)
                assert by[dup[0]].status.findings[0].detail.endswith((pair - {dup[0]}).pop())
            if b.clean:
                assert not got - {BoatClass.DUPLICATE}, (f.seed, b.name, got)
            # over at the gun (then back or not) against called over early
            called = bool(got & {BoatClass.OCS, BoatClass.OCS_RETURNED})
            over = b.status in ("ocs_not_returned", "ocs_returned")
            tp, fp, fn = (
                tp + (called and over),
                fp + (called and not over),
                fn + (over and not called),
            )
        assert all(e.analysed or not e.status.analysed for e in tri.entries)
    assert tp / (tp + fp) >= 0.95 and tp / (tp + fn) >= 0.90, (tp, fp, fn)


def _truth_normal(f: Fleet, b: BoatTruth, i: int) -> tuple[float, float]:
    """Unit normal [-] of the line whose crossing ends leg ``i`` in the truth: at a gate,
    the gate's line through the mark rounded (the truth's rounding is straight below it,
    moving along the gate away from the other mark); else the target's own crossing
    geometry from where the routed leg began (a mark's rounding ray, a line)."""
    spec = f.course.legs[i]
    if b.gate_marks[i]:
        gate = f.course.gates[spec.to_name]
        m, o = (gate.a, gate.b) if gate.a.name == b.gate_marks[i] else (gate.b, gate.a)
        n = math.hypot(m.x - o.x, m.y - o.y)
        return (m.x - o.x) / n, (m.y - o.y) / n
    tr = b.legs[i].track
    return detection_geometry(f.course, i, (float(tr.x[0]), float(tr.y[0]))).normal


def _gps_limit(f: Fleet, b: BoatTruth, i: int, t_true: float) -> float:
    """The error [s] GPS error alone gives leg ``i``'s end: when the recorded fixes
    (the true path plus the injected error) cross the truth's own line through the true
    position at ``t_true`` [epoch s, the track's clock], interpolated between fixes, the
    crossing nearest ``t_true`` within 20 s (inf: none)."""
    nx, ny = _truth_normal(f, b, i)
    tt = t_true + f.clock_lag_s
    px, py = np.interp(tt, b.path_t, b.path_x), np.interp(tt, b.path_t, b.path_y)
    track = f.track(b.name)
    x, y = track_xy(track, f.course.frame)
    t = track.t_s
    side = (x - px) * nx + (y - py) * ny
    k = np.flatnonzero((np.abs(t[:-1] - t_true) < 20.0) & (side[:-1] < 0.0) & (side[1:] >= 0.0))
    if k.size == 0:
        return math.inf
    tc = t[k] - side[k] / (side[k + 1] - side[k]) * (t[k + 1] - t[k])
    return float(tc[np.argmin(np.abs(tc - t_true))] - t_true)


def _errors(f: Fleet, limit: bool = False) -> list[tuple[float, float, float, float]]:
    """(|detected − true| [s], fix interval [s], |GPS limit| [s], |detected − true − GPS
    limit| [s]) of every leg end of the clean boats (at a gate, the rounding of the mark
    chosen); the GPS limit (:func:`_gps_limit`) only with ``limit`` (else NaN)."""
    tri = _triage(f)
    out = []
    by = {e.name: e for e in tri.entries}
    for b in f.clean:
        seg = by[b.name].segmentation
        if seg is None:  # the first of a duplicate pair (the copy came first)
            continue
        for i, c in enumerate(seg.ends):
            truth = (b.gate_round_t[i] if b.gate_marks[i] else b.leg_end_t[i]) - f.clock_lag_s
            err = c.t - truth if c.known else math.inf
            gps = _gps_limit(f, b, i, truth) if limit else math.nan
            out.append((abs(err), b.sample_s, abs(gps), abs(err - gps)))
    return out


def test_leg_ends_within_a_fix_of_the_truth(fleets: list[Fleet]) -> None:
    """Without GPS error every leg end lies within half a fix interval of the truth; with
    it, at each fix interval, as many lie within a fix of it as the GPS error alone allows
    (the recorded fixes crossing the truth's own line), and the detected time is the one
    the error gives to within 0.3 s."""
    exact = np.array([e for f in fleets for e in _errors(f.resampled(noise=False))])
    assert np.all(exact[:, 0] <= 0.5 * exact[:, 1]), np.max(exact[:, 0] / exact[:, 1])
    noisy = np.array([e for f in fleets for e in _errors(f, limit=True)])
    err, dt, gps, added = noisy.T
    for step in (1.0, 2.0, 3.0):
        m = dt == step
        got, limit = np.mean(err[m] <= step), np.mean(gps[m] <= step)
        assert got >= limit - 0.02, (step, got, limit)
    assert np.mean(added <= 0.3) >= 0.97
    assert np.mean(err <= dt) >= 0.88
    assert np.mean(err <= 3.0) >= 0.98


def test_a_whole_run_is_not_stopped_by_one_boat(fleets: list[Fleet], tmp_path: Path) -> None:
    """The whole command on the fleet with the general recall, its course giving the first
    gun: the recall is found, every boat that can be is debriefed, the rest are named."""
    import json

    from sailroute.commands.analyze import run_analyze_command
    from sailroute.course.load import load_course
    from sailroute.timeutil import parse_time, to_epoch

    f = fleets[3]
    course, paths = f.write(tmp_path / "in", "csv", gun="first")
    res = run_analyze_command(
        load_course(course), paths, out_dir=tmp_path / "out", plots=False, gate_end="rounding"
    )
    doc = json.loads(res.files["fleet_json"].read_text())
    assert doc["general_recall"] is not None
    # the restart's gun taken from the fleet's second start: within seconds of the true
    # one in the tracks' clock
    gun = to_epoch(parse_time(doc["fleet_start"]["gun_time_in_tracks"], "gun"))
    assert abs(gun - (f.gun - f.clock_lag_s)) < 3.0
    left_out = {e["name"] for e in doc["entries"] if not e["analysed"]}
    want = {b.name for b in f.boats if b.status in ("non_starter", "other_fleet")}
    assert want <= left_out and len(left_out) == len(want) + 1  # and one of the duplicates
    assert len(doc["boats"]) == len(f.boats) - len(left_out)
    assert sum(n.startswith("general recall:") for n in doc["notes"]) == 1
