"""A fleet's optimal legs routed as one front per leg against each boat's legs routed alone.

:func:`sailroute.analysis.optimal.route_together` routes every boat's leg in the leg frame
of the first boat's start (:mod:`sailroute.routing.batch`).  The first boat's legs are
its routes alone, bit for bit.  Another boat's leg time differs from its route alone by
the pruning's tolerance (2e-3 of the leg, as ``tests/test_bands_together.py`` holds the
leg-time bands' members), or by that and one manoeuvre's penalty: where the route sets
off close to dead downwind (or head to wind), the common frame's headings may put its
first step on the other side of the wind, one tack or gybe more or less.
"""

from __future__ import annotations

import io

import numpy as np
import pytest

from sailroute.analysis.debrief import (
    analysis_winds,
    analyze_fleet,
    finish_debrief,
    prepare_fleet,
)
from sailroute.analysis.optimal import route_one, route_together
from sailroute.analysis.triage import triage_fleet
from sailroute.course.load import build_specs
from sailroute.planning.route import default_scenario
from sailroute.progress import Progress
from sailroute.track.kinematics import track_xy
from tests.fleetgen import FaultPlan, messy_fleet

REL = 2e-3
"""The pruning's tolerance on a leg time (of the leg time)."""


@pytest.fixture(scope="module")
def prepared():
    """Six boats of 12 min (GPS error, fixes every 1-2 s, one log spanning two races),
    prepared with the projections of the triage, which must be those of their tracks
    (the log cut to the race)."""
    fleet = messy_fleet(
        3,
        n_boats=6,
        minutes=12,
        faults=FaultPlan.clean(noise_white_m=0.7, noise_corr_m=1.5, two_races=1),
        sample_s=(1, 2),
    )
    course = fleet.course
    tri = triage_fleet(course, [(tr.name, tr.name, tr) for tr in fleet.tracks])
    assert any(e.cut is not None for e in tri.analysed)
    for e in tri.analysed:
        assert e.track is not None and e.xy is not None
        for got, want in zip(e.xy, track_xy(e.track, course.frame), strict=True):
            np.testing.assert_array_equal(got, want)
    name = default_scenario(course)
    boat, winds = build_specs(course, [name])
    tracks = [e.track for e in tri.analysed]
    sources, _ = analysis_winds(
        course,
        tracks,
        name,
        winds[name],
        boat,
        gun_t=tri.start.track_gun_t,
        race_end_t=tri.race_end_t,
        xy=[e.xy for e in tri.analysed],
    )
    return prepare_fleet(course, tri.analysed, name, (boat, winds[name]), sources)


@pytest.fixture(scope="module")
def together(prepared):
    """The prepared boats' optimal legs, routed together."""
    first = prepared[0]
    return route_together(
        first.course,
        [p.optimal for p in prepared],
        [p.sources for p in prepared],
        first.boat,
        first.settings,
    )


def test_legs_together_are_the_legs_alone_within_the_pruning(prepared, together) -> None:
    first = prepared[0]
    course, settings = first.course, first.settings
    compared = 0
    for b, p in enumerate(prepared):
        for i, leg in enumerate(p.optimal):
            if leg is None:
                assert together[b][i] is None
                continue
            got = together[b][i]
            assert got is not None
            opt, src = got
            alone, src_alone = route_one(course, leg, p.sources, p.boat, settings)
            assert src is src_alone
            if b == 0:  # the first boat's frame is its own: the same route
                assert opt.time_s == alone.time_s
                np.testing.assert_array_equal(opt.track.x, alone.track.x)
                continue
            # a manoeuvre more or less, at most: the route's first step on the other
            # side of the wind, charged (or not) its penalty
            d_count = abs(opt.n_tacks - alone.n_tacks) + abs(opt.n_gybes - alone.n_gybes)
            assert d_count <= 1, (p.track.name, i, opt, alone)
            pen = (0.0, settings.tack_penalty_s, settings.gybe_penalty_s)
            d = opt.time_s - alone.time_s
            off = min(min(abs(d - q), abs(d + q)) for q in pen)
            assert off <= REL * alone.time_s, (p.track.name, i, opt.time_s, alone.time_s)
            compared += 1
    assert compared >= 4 * course.n_legs  # nearly every boat finished every leg


def test_fleet_debrief_is_the_boats_debriefed_with_their_routes(prepared, together) -> None:
    """``analyze_fleet``: each boat's debrief is the one its own routes give; the progress
    counts the boats (legs routed together, then boats done) with the time left."""
    first = prepared[0]
    stream = io.StringIO()
    progress = Progress(first.course.n_legs, stream, live=True, min_interval_s=0.0)
    fleet = analyze_fleet(prepared, progress)
    assert [a.track.name for a in fleet] == [p.track.name for p in prepared]
    for a, p, r in zip(fleet, prepared, together, strict=True):
        own = finish_debrief(p, r)
        assert [leg.loss_s for leg in a.legs] == pytest.approx(
            [leg.loss_s for leg in own.legs], nan_ok=True
        )
        np.testing.assert_array_equal(a.points.loss_s, own.points.loss_s)
    text = stream.getvalue()
    assert f" of {len(prepared)} boats arrived" in text  # the live line's note
    lines = [part.strip() for part in text.replace("\r", "\n").splitlines() if part.strip()]
    n = len(prepared)
    ends = [line for line in lines if "median of" in line]  # a line per leg routed
    assert len(ends) == first.course.n_legs
    assert f"median of {n} boats" in ends[0]
    assert "s left)" in ends[0]  # the routing's time left
    done = [line for line in lines if line.startswith("boat ")]
    assert done[-1].startswith(f"boat {n} of {n} done ({prepared[-1].track.name}): ")
    assert done[-1].endswith(" elapsed")
