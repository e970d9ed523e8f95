"""A long 10 Hz log analyses like the 1 Hz track it was made from, and is drawn decimated.

The shipped Snipe track (1 Hz, 33 min) interpolated to 10 Hz and repeated before and after
the race (as ``benchmarks/bench_analyze.py`` builds its 300 000-point log, here 60 000
points to keep the test quick): the GPX reader, the leg detection and the points table
must give the same race; the page must draw at most ``MAX_ROUTE_POINTS`` points per track
with every leg change kept.  Not a timing test (the timings are the benchmark's).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from sailroute.analysis.debrief import analyze_track
from sailroute.course.load import load_course
from sailroute.report.html import analysis_report
from sailroute.report.page import MAX_ROUTE_POINTS, decimated
from sailroute.track.read import read_track
from tests.conftest import ROOT

sys.path.insert(0, str(ROOT / "benchmarks"))
import bench_analyze


def test_a_60000_point_10hz_log_gives_the_same_race(tmp_path: Path) -> None:
    course = load_course(bench_analyze.COURSE)
    # judged in one wind: the test is of the reader and the leg detection (the direction
    # inferred from a track resampled at 10 Hz moves by a little, and with it a manoeuvre)
    base = analyze_track(course, read_track(bench_analyze.TRACK), wind="scenario")
    log = bench_analyze.long_log(tmp_path, 60_000)
    tr = read_track(log)
    assert len(tr) == 60_000
    assert np.allclose(np.diff(tr.t_s), 0.1, atol=1e-3)  # ms in the file
    assert tr.t_start < course.start_epoch - 1200 and tr.t_end > course.start_epoch + 3600
    a = analyze_track(course, tr, wind="scenario")
    assert len(a.legs) == len(base.legs)
    for leg, ref in zip(a.legs, base.legs, strict=True):
        # the same polyline, sampled 10 times denser: the same crossings
        assert leg.t_end == pytest.approx(ref.t_end, abs=0.05), leg.label
        assert leg.sailed_distance_m == pytest.approx(ref.sailed_distance_m, rel=0.01)
        assert leg.sailed_tacks + leg.sailed_gybes == ref.sailed_tacks + ref.sailed_gybes
    assert a.segmentation.start.crossing.t == pytest.approx(
        base.segmentation.start.crossing.t, abs=0.05
    )
    n_race = int(np.sum((tr.t_s > a.legs[0].t_start) & (tr.t_s < a.legs[-1].t_end)))
    assert a.points.t.size == n_race + 2 * len(a.legs)  # boundaries twice
    # the page: the sailed track decimated, leg changes where they are
    rep = analysis_report(a)
    sailed = rep.routes[0]
    assert a.points.t.size > 3 * MAX_ROUTE_POINTS
    assert sailed.t.size <= MAX_ROUTE_POINTS + 2 * len(a.legs) + 1
    changes = np.flatnonzero(np.diff(sailed.leg) != 0)
    full = np.flatnonzero(np.diff(a.points.leg) != 0)
    assert np.array_equal(sailed.t[changes], a.points.t[full])
    assert np.array_equal(sailed.t[changes + 1], a.points.t[full + 1])
    assert decimated(sailed) is sailed  # already small: unchanged
