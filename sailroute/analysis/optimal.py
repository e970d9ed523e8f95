"""The optimal legs of a debrief: each boat's leg routed from its own leg start point and time.

:func:`sailroute.analysis.debrief.analyze_track` asks, for every leg whose start is
known, the optimal route from where and when the boat started it (an
:class:`OptimalLeg`).  One boat's legs are routed one by one (:func:`route_one`,
:func:`sailroute.routing.api.route_leg`).  A fleet's are routed one leg at a time for
all its boats as one isochrone front (:func:`route_together`,
:func:`sailroute.routing.batch.route_leg_batch`): the fixed cost of a step is paid once
for the fleet, not once per boat.  Each boat keeps its own start, time, wind and
clearance from the mark it rounded; the leg frame and the pruning's sectors are those of
the first boat's start, so a boat's optimal leg time differs from its route alone by the
pruning's tolerance (``docs/analysis.md``; ``tests/analysis/test_optimal_together.py``
bounds it).  A boat whose leg starts inside the race area's clearances, a race area
(obstacles), a router other than the isochrone and a leg the front cannot route are
routed one by one, as alone.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.segment import Crossing, leg_target
from sailroute.analysis.windsource import WindSource, first_covering
from sailroute.course.model import Course
from sailroute.errors import OutOfCoverageError, RoutingError
from sailroute.progress import Progress
from sailroute.routing.api import route_leg
from sailroute.routing.batch import batchable, route_leg_batch
from sailroute.routing.geometry import target_barrier
from sailroute.routing.obstacles import Obstacles, land_filled
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import LegResult, Start

__all__ = ["OptimalLeg", "leg_start", "route_one", "route_together"]

Routed = tuple[LegResult, WindSource]
"""An optimal leg and the wind it was routed in."""


@dataclass(frozen=True)
class OptimalLeg:
    """Where and when one boat's optimal leg starts, and in which wind it is routed.

    Attributes
    ----------
    index : int
        The leg (0-based).
    start : Start
        The boat's leg start point, with the barrier of the mark it rounded
        (:func:`leg_start`).
    t0 : float
        The boat's leg start time [epoch s].
    k : int
        The boat's wind source (index in its candidates) routed in first.
    points : (t, x, y) arrays
        The leg's sailed points [epoch s, m, m]: when the wind ``k`` ends before the
        optimal route does, the next source that covers them is used.
    obstacles : Obstacles or None
        The race area the route keeps to (None: open water).
    """

    index: int
    start: Start
    t0: float
    k: int
    points: tuple[NDArray, NDArray, NDArray]
    obstacles: Obstacles | None


def leg_start(
    course: Course, i: int, bounds: Sequence[Crossing], settings: RoutingSettings
) -> Start:
    """The start of leg ``i`` at the boat's own crossing ``bounds[i]``, behind the barrier
    of the mark it rounded (the previous leg's target seen from that leg's start)."""
    a = bounds[i]
    barrier = None
    if i > 0 and np.isfinite(bounds[i - 1].x):
        prev_start = (bounds[i - 1].x, bounds[i - 1].y)
        barrier = target_barrier(
            leg_target(course, i - 1),
            Start(prev_start, None, course.legs[i - 1].from_name),
            settings.zone_m,
        )
    return Start((a.x, a.y), None, course.legs[i].from_name, barrier)


def route_one(
    course: Course,
    leg: OptimalLeg,
    sources: Sequence[WindSource],
    boat: Any,
    settings: RoutingSettings,
    progress: Progress | None = None,
) -> Routed:
    """The optimal route of one boat's leg, alone.

    Routed in ``sources[leg.k]`` inside ``leg.obstacles``; when that wind ends before
    the optimal route does (or the route crosses a hole of a measured wind), in the next
    source that covers the leg's sailed points.

    Raises
    ------
    OutOfCoverageError
        No source covers the route.
    RoutingError
        The leg cannot be routed.
    """
    i, k = leg.index, leg.k
    if progress is not None:
        progress.start_leg(i, course.legs[i].label)
    while True:
        try:
            opt = route_leg(
                leg.start,
                leg_target(course, i),
                leg.t0,
                land_filled(course.area, sources[k].for_routing),
                boat,
                settings,
                progress=progress.update if progress is not None else None,
                obstacles=leg.obstacles,
            )
            _check_holes(sources[k], opt)
            break
        except OutOfCoverageError:
            nxt = first_covering(sources, *leg.points, skip=k)
            if nxt is None:
                raise
            k = nxt
    if progress is not None:
        progress.end_leg(opt.time_s, f"{opt.n_tacks} tacks, {opt.n_gybes} gybes")
    return opt, sources[k]


def _check_holes(source: WindSource, opt: LegResult) -> None:
    """Raise OutOfCoverageError when a route routed across the holes of a measured wind
    (its :attr:`~sailroute.analysis.windsource.WindSource.route_field` bridges them)
    crosses one of the field the leg is judged in."""
    if source.route_field is not None:
        source.field.sample(opt.track.t, opt.track.x, opt.track.y)


def route_together(
    course: Course,
    legs: Sequence[Sequence[OptimalLeg | None]],
    sources: Sequence[Sequence[WindSource]],
    boat: Any,
    settings: RoutingSettings,
    progress: Progress | None = None,
) -> list[list[Routed | None]]:
    """The optimal legs of a fleet, each leg of the course routed for all boats as one front.

    Parameters
    ----------
    course : Course
        The course.
    legs : sequence of sequence of OptimalLeg or None
        Per boat, per leg of the course: its optimal leg (None: its start is unknown,
        nothing to route).
    sources : sequence of sequence of WindSource
        Per boat, its candidate winds (:attr:`OptimalLeg.k` indexes them).
    boat : BoatModel
        The boat of every member.
    settings : RoutingSettings
        The routing settings.
    progress : Progress, optional
        Per leg of the course: ``start_leg``, ``update`` (share of the leg done, boats
        arrived) and ``end_leg`` (the boats' median optimal leg time).

    Returns
    -------
    list of list
        Per boat, per leg: the optimal leg and the wind it was routed in (None where
        ``legs`` has None).

    Raises
    ------
    OutOfCoverageError, RoutingError
        A boat's leg cannot be routed, alone either (:func:`route_one`).
    """
    out: list[list[Routed | None]] = [[None] * course.n_legs for _ in legs]
    front = batchable(settings, "numpy", [None])
    for i, spec in enumerate(course.legs):
        asked = [(b, leg) for b, own in enumerate(legs) if (leg := own[i]) is not None]
        if not asked:
            continue
        if progress is not None:
            progress.start_leg(i, spec.label)
        together = [(b, leg) for b, leg in asked if front and leg.obstacles is None]
        if len(together) >= 2:
            for b, res in zip(
                (b for b, _ in together),
                _front(course, i, together, sources, boat, settings, progress),
                strict=True,
            ):
                out[b][i] = res
        for b, leg in asked:  # alone: the race area, the odd one out, a failed front
            if out[b][i] is None:
                out[b][i] = route_one(course, leg, sources[b], boat, settings)
        if progress is not None:
            times = [r[0].time_s for r in (out[b][i] for b, _ in asked) if r is not None]
            progress.end_leg(float(np.median(times)), f"median of {len(times)} boats")
    return out


def _boats_arrived(progress: Progress) -> Callable[[float, str], None]:
    """The front's progress callback, its members called boats (``12 of 60 boats
    arrived``)."""

    def update(fraction: float, note: str = "") -> None:
        progress.update(fraction, note.replace(" members arrived", " boats arrived"))

    return update


def _front(
    course: Course,
    i: int,
    members: Sequence[tuple[int, OptimalLeg]],
    sources: Sequence[Sequence[WindSource]],
    boat: Any,
    settings: RoutingSettings,
    progress: Progress | None,
) -> list[Routed | None]:
    """Leg ``i`` of ``members`` (boat index, its leg) as one front; None for a member
    whose route crosses a hole of its wind, and for all when the front fails (they are
    then routed alone)."""
    winds: dict[int, Any] = {}  # one routing field per source: the front samples it once
    member_winds = []
    for b, leg in members:
        src = sources[b][leg.k]
        if id(src) not in winds:
            winds[id(src)] = land_filled(course.area, src.for_routing)
        member_winds.append(winds[id(src)])
    try:
        done = route_leg_batch(
            [leg.start for _, leg in members],
            leg_target(course, i),
            [leg.t0 for _, leg in members],
            member_winds,
            boat,
            settings,
            progress=None if progress is None else _boats_arrived(progress),
        )
    except (OutOfCoverageError, RoutingError):
        return [None] * len(members)
    out: list[Routed | None] = []
    for (b, leg), opt in zip(members, done, strict=True):
        src = sources[b][leg.k]
        try:
            _check_holes(src, opt)
        except OutOfCoverageError:
            out.append(None)
            continue
        out.append((opt, src))
    return out
