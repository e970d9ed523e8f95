"""Route the rest of a course from where the boat is now, and summarise it for the coach.

* :func:`route_remaining` — the legs from the one being sailed to the finish, the first
  from the boat's position and time, each next one chained as
  :func:`sailroute.planning.route.route_course` chains them
  (:func:`~sailroute.routing.geometry.chain_leg`);
* :func:`side_that_pays` — the side of the rhumb line the route of the current leg
  favours, and by how much: the time of the best route through the mirror point on the
  other side, minus the best route's time;
* :func:`laylines` — the two laylines into the next mark at the best VMG angle in the
  measured wind, and the boat's distance and time to each;
* :func:`summarise` -> :class:`LivePlan` — the numbers the page and the plotter show.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from sailroute.boat.model import BoatModel
from sailroute.course.geometry import leg_endpoints, target_of
from sailroute.course.model import Course
from sailroute.planning.route import route_course
from sailroute.progress import Progress
from sailroute.routing.api import route_leg
from sailroute.routing.geometry import chain_leg, start_centre
from sailroute.routing.laylines import LaylineKind, vmg_angles
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import LegResult, Start, Target
from sailroute.units import bearing_deg, heading_unit, wrap180, wrap360
from sailroute.wind.base import WindField

DEFAULT_REACH_M: float = 25.0
"""A turning point of the route counts as reached once the boat is this close [m] (the
plotter's steering then goes on to the next one)."""
MIN_SIDE_M: float = 20.0
"""A route that leaves the rhumb line by less than this favours no side [m]."""

XY = tuple[float, float]


def leg_target(course: Course, leg: int) -> Target:
    """The target of ``leg`` as :func:`route_remaining` routes it (with its exit, for a
    mark rounded on a side)."""
    following = target_of(course, leg + 1) if leg + 1 < course.n_legs else None
    return chain_leg(Start((0.0, 0.0)), target_of(course, leg), None, following)[1]


def route_remaining(
    course: Course,
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
    leg: int,
    xy: XY,
    t: float,
    progress: Progress | None = None,
) -> list[LegResult]:
    """Route legs ``leg`` .. last from the boat at ``xy`` [m] at epoch ``t`` [s]
    (:func:`~sailroute.planning.route.route_course` from a boat under way: inside the
    course's boundary and round its obstacles, as ``plan`` routes; ``progress`` gets its
    calls).

    Returns
    -------
    list of LegResult
        One per remaining leg, chained: each starts where and when the previous one
        ended, and marks are rounded on their sides.
    """
    return route_course(
        course,
        wind,
        boat,
        settings,
        from_leg=leg,
        under_way=((float(xy[0]), float(xy[1])), t),
        progress=progress,
    )


@dataclass(frozen=True)
class SidePays:
    """Which side of the rhumb line pays on the current leg.

    Attributes
    ----------
    side : {"left", "right", "none"}
        Looking from the boat to the mark; ``"none"``: the route keeps within
        :data:`MIN_SIDE_M` of the rhumb line (a reach, or a leg with no shift).
    gain_s : float
        Time the favoured side saves over the best route through the mirror point on
        the other side [s] (0 for ``"none"``; 0 also when the router finds both about
        equal: its times resolve to about one time step).
    offset_m : float
        How far the route goes to that side of the rhumb line [m].
    """

    side: str
    gain_s: float
    offset_m: float


def _cross_track(route: LegResult, a: XY, b: XY) -> tuple[float, float, float]:
    """``(signed offset [m], along [m], at index)`` of the point furthest off ``a``-``b``.

    Positive: right of the line looking from ``a`` to ``b``.
    """
    dx, dy = b[0] - a[0], b[1] - a[1]
    n = math.hypot(dx, dy) or 1.0
    ex, ey = dx / n, dy / n
    rx, ry = route.track.x - a[0], route.track.y - a[1]
    cross = rx * ey - ry * ex  # right of the line > 0
    i = int(np.argmax(np.abs(cross)))
    return float(cross[i]), float(rx[i] * ex + ry[i] * ey), float(i)


def side_that_pays(
    route: LegResult,
    target: Target,
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
    progress: Callable[[float], None] | None = None,
) -> SidePays:
    """The side of the rhumb line the best route of a leg takes, and what it gains.

    The alternative is the best route through the mirror image (across the rhumb line)
    of the route's point furthest from it: two legs routed with
    :func:`~sailroute.routing.api.route_leg`, the first to that point as a mark passed
    on neither side.

    Parameters
    ----------
    route : LegResult
        The best route of the leg (its first point is the boat).
    target : Target
        The leg's target.
    wind, boat, settings
        As for the route.
    progress : callable, optional
        The routers' progress callback (it may stop them by raising).

    Returns
    -------
    SidePays
    """
    a = route.start_xy
    b = target.centre
    off, along, _ = _cross_track(route, a, b)
    if abs(off) < MIN_SIDE_M:
        return SidePays("none", 0.0, abs(off))
    dx, dy = b[0] - a[0], b[1] - a[1]
    n = math.hypot(dx, dy) or 1.0
    ex, ey = dx / n, dy / n
    # mirror point: same distance along the rhumb line, same offset on the other side
    mx, my = a[0] + along * ex - off * ey, a[1] + along * ey + off * ex
    via = route_leg(
        Start(a, None, name="boat"),
        Target("mark", (mx, my), name="mirror"),
        route.t_start,
        wind,
        boat,
        settings,
        progress=progress,
    )
    rest = route_leg(
        Start(via.end_xy, None, name="mirror"),
        target,
        via.t_end,
        wind,
        boat,
        settings,
        progress=progress,
    )
    # the router resolves times to about its time step: a mirror route found a little
    # faster than the best one means that both sides are worth the same
    gain = max(float(rest.t_end - route.t_end), 0.0)
    return SidePays("right" if off > 0 else "left", gain, abs(off))


@dataclass(frozen=True)
class Layline:
    """One layline into a mark, and how far the boat is from it.

    Attributes
    ----------
    tack : {"starboard", "port"}
        The tack sailed along it.
    bearing_deg : float
        Course sailed along it towards the mark [° true].
    distance_m : float
        Distance the boat sails on the other tack, at the best VMG angle, to reach it
        [m]; below 0: the boat is beyond it (it has overstood); NaN: no boat position.
    time_s : float
        That distance at the polar's speed [s].
    """

    tack: str
    bearing_deg: float
    distance_m: float = math.nan
    time_s: float = math.nan


def laylines(
    boat: BoatModel,
    tws_ms: float,
    twd_deg: float,
    upwind: bool,
    mark_xy: XY | None = None,
    boat_xy: XY | None = None,
    grid_north_deg: float = 0.0,
) -> tuple[Layline, ...]:
    """The two laylines into a mark at the best VMG angle in a uniform wind, and the
    boat's distance and time to each.

    The best-VMG angle is :func:`sailroute.routing.laylines.vmg_angles`'s (in a uniform
    wind its traced laylines are these straight lines).  A boat on port reaches the
    starboard layline: its distance is along the port course from the boat to that
    line, and the other way round.

    Parameters
    ----------
    boat : BoatModel
        Gives the VMG angles and the speed at them.
    tws_ms, twd_deg : float
        The wind [m s⁻¹, ° from].
    upwind : bool
        A windward mark (beat angles) or a leeward one (run angles).
    mark_xy, boat_xy : (float, float), optional
        The mark and the boat [m, course frame]; without both, no distances.
    grid_north_deg : float
        Angle from the frame's +y to true north [°]
        (:meth:`~sailroute.geo.LocalFrame.grid_north_deg`).

    Returns
    -------
    tuple of Layline
        Starboard first.
    """
    kind: LaylineKind = "tack" if upwind else "gybe"
    twa = float(vmg_angles(boat, np.array([tws_ms]), kind)[0])
    speed = float(np.asarray(boat.steady_speed(np.array([tws_ms]), np.array([twa])))[0])
    # on starboard the wind comes over the right side: course = twd - twa
    course = {"starboard": float(wrap360(twd_deg - twa)), "port": float(wrap360(twd_deg + twa))}
    out = []
    for tack, other in (("starboard", "port"), ("port", "starboard")):
        dist = math.nan
        if mark_xy is not None and boat_xy is not None:
            # boat + a u_other = mark - s u_tack  ->  a u_other + s u_tack = mark - boat
            ux, uy = heading_unit(course[other] + grid_north_deg)
            vx, vy = heading_unit(course[tack] + grid_north_deg)
            rx, ry = mark_xy[0] - boat_xy[0], mark_xy[1] - boat_xy[1]
            det = float(ux * vy - uy * vx)
            if abs(det) > 1e-9:
                dist = float(rx * vy - ry * vx) / det
        out.append(
            Layline(
                tack,
                course[tack],
                dist,
                dist / speed if speed > 0 and math.isfinite(dist) else math.nan,
            )
        )
    return tuple(out)


@dataclass(frozen=True)
class LivePlan:
    """One re-plan, as the page, the plotter and the log show it.

    Attributes
    ----------
    number : int
        Re-plan count (1 first).
    t : float
        Data time it starts from [epoch s].
    leg : int
        The leg being sailed (0-based).
    leg_labels : tuple of str
        Labels of the remaining legs.
    leg_times_s : tuple of float
        Their routed times [s].
    mark_eta : tuple of float
        Arrival at each remaining target [epoch s].
    time_to_mark_s, time_to_finish_s : float
        From ``t`` to the next target and to the finish [s].
    route_lat, route_lon : tuple of float
        The route ahead (all remaining legs) [°].
    waypoints : tuple of (str, float, float)
        ``(name, lat, lon)`` of the turning points ahead: tacks, gybes and targets.
    wind_tws_ms, wind_twd_deg : float
        The measured wind the re-plan started from [m s⁻¹, °].
    side : SidePays or None
        The current leg's favoured side (None: not computed).
    laylines : tuple of Layline
        Into the next mark (upwind or downwind legs only).
    reason : str
        What triggered it (``"interval"``, ``"wind"``, ``"first"``).
    compute_s : float
        Wall time the routing took [s].
    compute_cpu_s : float
        CPU time of the thread that routed [s] (wall minus CPU: time spent waiting for
        a core).
    wind_note : str
        Empty when routed in the scenario's wind blended with the measured one; else why
        it was routed in the measured wind only (:mod:`sailroute.live.planner`).
    """

    number: int
    t: float
    leg: int
    leg_labels: tuple[str, ...]
    leg_times_s: tuple[float, ...]
    mark_eta: tuple[float, ...]
    time_to_mark_s: float
    time_to_finish_s: float
    route_lat: tuple[float, ...]
    route_lon: tuple[float, ...]
    waypoints: tuple[tuple[str, float, float], ...]
    wind_tws_ms: float
    wind_twd_deg: float
    side: SidePays | None
    laylines: tuple[Layline, ...]
    reason: str
    compute_s: float
    compute_cpu_s: float = 0.0
    wind_note: str = ""

    def as_dict(self) -> dict[str, object]:
        """JSON-ready form (for the page, the log)."""
        return {
            "number": self.number,
            "t": self.t,
            "leg": self.leg,
            "leg_labels": list(self.leg_labels),
            "leg_times_s": [round(v, 1) for v in self.leg_times_s],
            "mark_eta": [round(v, 1) for v in self.mark_eta],
            "time_to_mark_s": round(self.time_to_mark_s, 1),
            "time_to_finish_s": round(self.time_to_finish_s, 1),
            "route": [
                [round(a, 7), round(b, 7)]
                for a, b in zip(self.route_lat, self.route_lon, strict=True)
            ],
            "waypoints": [[n, round(a, 7), round(b, 7)] for n, a, b in self.waypoints],
            "wind_tws_ms": round(self.wind_tws_ms, 3),
            "wind_twd_deg": round(self.wind_twd_deg, 2),
            "side": None
            if self.side is None
            else {
                "side": self.side.side,
                "gain_s": round(self.side.gain_s, 1),
                "offset_m": round(self.side.offset_m, 1),
            },
            "laylines": [
                {"tack": ll.tack, "bearing_deg": round(ll.bearing_deg, 1)} for ll in self.laylines
            ],
            "reason": self.reason,
            "compute_s": round(self.compute_s, 3),
            "compute_cpu_s": round(self.compute_cpu_s, 3),
            "wind_note": self.wind_note,
        }


def upwind_or_downwind_laylines(
    course: Course,
    leg: int,
    boat: BoatModel,
    wind: tuple[float, float],
    boat_xy: XY | None,
    grid_north_deg: float = 0.0,
) -> tuple[Layline, ...]:
    """The laylines into the mark of ``leg`` in the uniform wind ``(tws, twd)``, with the
    boat's distances: none for a gate, a line, or a leg that is a reach (its bearing more
    than 60° from dead up- or downwind)."""
    tg = target_of(course, leg)
    if tg.kind != "mark":
        return ()
    fx, fy = boat_xy if boat_xy is not None else start_centre(leg_endpoints(course, leg)[0])
    brg = float(bearing_deg(tg.a[0] - fx, tg.a[1] - fy))
    off = abs(float(wrap180(brg - wind[1])))
    if 60.0 <= off <= 120.0:  # a reach
        return ()
    return laylines(boat, wind[0], wind[1], off < 60.0, tg.a, boat_xy, grid_north_deg)


def summarise(
    course: Course,
    results: Sequence[LegResult],
    *,
    number: int,
    t: float,
    leg: int,
    boat: BoatModel,
    measured: tuple[float, float],
    reason: str,
    compute_s: float,
    side: SidePays | None = None,
    compute_cpu_s: float = 0.0,
) -> LivePlan:
    """Assemble the :class:`LivePlan` of routed remaining legs ``results`` (from ``leg``)."""
    frame = course.frame
    x = np.concatenate([r.track.x for r in results])
    y = np.concatenate([r.track.y for r in results])
    lat, lon = frame.to_latlon(x, y)
    points: list[tuple[str, float, float]] = []
    for i, r in enumerate(results):
        for m in r.manoeuvres:
            la, lo = frame.to_latlon(m.x, m.y)
            points.append(
                (f"{m.kind[0].upper()}{i + leg + 1}{len(points) + 1:02d}", float(la), float(lo))
            )
        tg = target_of(course, leg + i)
        la, lo = frame.to_latlon(*tg.centre)
        points.append((tg.name or f"M{leg + i + 1}", float(la), float(lo)))
    start = results[0].start_xy
    lls = upwind_or_downwind_laylines(
        course, leg, boat, measured, start, float(frame.grid_north_deg(*frame.to_latlon(*start)))
    )
    etas = tuple(float(r.t_end) for r in results)
    return LivePlan(
        number=number,
        t=t,
        leg=leg,
        leg_labels=tuple(course.legs[leg + i].label for i in range(len(results))),
        leg_times_s=tuple(float(r.time_s) for r in results),
        mark_eta=etas,
        time_to_mark_s=etas[0] - t,
        time_to_finish_s=etas[-1] - t,
        route_lat=tuple(map(float, lat)),
        route_lon=tuple(map(float, lon)),
        waypoints=tuple(points),
        wind_tws_ms=measured[0],
        wind_twd_deg=measured[1],
        side=side,
        laylines=lls,
        reason=reason,
        compute_s=compute_s,
        compute_cpu_s=compute_cpu_s,
    )
