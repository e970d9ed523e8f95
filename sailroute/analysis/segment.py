"""Split a sailed track into the course's legs: start, mark roundings, gates, lines.

The targets are the routers' own crossing geometry (``routing/geometry.py``), so a
leg of the sailed track ends exactly where a routed leg would:

* **line** (start, finish): the first crossing of the segment, extended by
  ``line_margin_m`` at both ends (GPS error), from the course side of the previous
  leg to the other side;
* **gate**: the first crossing of the segment between its marks, same margin;
* **mark**: the first crossing of the mark's *rounding ray*, in the rounding
  direction: from the mark, perpendicular to the apex heading (the bisector of the
  turn from this leg's bearing to the next one's, taken in the rounding sense), on
  the side the boat passes, ``detect_m`` long, and starting ``MARK_TOLERANCE_M``
  behind the mark.  For a windward mark left to port that
  ray points upwind from the mark and is crossed moving to the left (looking
  upwind): the boat has gone over the top.  A mark passed on the wrong side never
  crosses it forwards.

The **start** is the first crossing of the start line from the pre-start side after
the gun (a boat over early must come back).  A leg that starts at a mark (``from:``
a mark) uses the line through that mark square to the first leg, ``2 detect_m`` long.

Each leg searches only after the previous leg's end, so repeated marks
(windward-leeward loops) are found in order.  Explicit boundary times override
the detection.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sailroute.course.geometry import feature_centre, leg_endpoints, target_of
from sailroute.course.model import Course, Mark
from sailroute.errors import InputError
from sailroute.routing.geometry import TargetGeometry, segment_crossing, target_geometry
from sailroute.routing.types import Start, Target
from sailroute.timeutil import iso
from sailroute.units import bearing_deg, wrap180

DETECT_M = 100.0
"""Default length of a mark's rounding ray for detection [m]: marks in real data are
placed to within some tens of metres and boats round wide in traffic."""

MARK_TOLERANCE_M = 15.0
"""A mark's rounding ray starts this far on the other side of the mark [m], so a
rounding that passes within it (mark position error, GPS error) still counts; a boat
passing further off on the wrong side never crosses the ray."""

MARK_START_HALF_M = 300.0
"""Half-length of the start line assumed through a start mark [m]."""

LINE_MARGIN_M = 10.0
"""Lines and gates are extended by this at each end for detection [m] (GPS error)."""


@dataclass(frozen=True)
class Crossing:
    """Where and when the track crossed a target.

    Attributes
    ----------
    t : float
        Time [epoch s] (interpolated between fixes).
    x, y : float
        Position [m].
    detected : bool
        True if found from the geometry, False if given explicitly.
    """

    t: float
    x: float
    y: float
    detected: bool = True


@dataclass(frozen=True)
class StartReport:
    """The start.

    Attributes
    ----------
    gun_t : float
        Start signal [epoch s] (the course's ``start_time``).
    crossing : Crossing
        When and where the boat started (crossed the line after the gun).
    late_s : float
        ``crossing.t − gun_t`` [s].
    distance_at_gun_m : float
        Distance from the start line (segment) at the gun [m].
    side_at_gun : {"pre-start", "course"}
        Side of the line the boat was on at the gun (course side = over early).
    line_fraction : float
        Where on the line the boat crossed: 0 at its first end, 1 at its second.
    """

    gun_t: float
    crossing: Crossing
    late_s: float
    distance_at_gun_m: float
    side_at_gun: str
    line_fraction: float


@dataclass(frozen=True)
class Segmentation:
    """A track split into legs.

    Attributes
    ----------
    start : StartReport
    ends : tuple of Crossing
        End of each leg, in course order; leg *i* runs from ``ends[i-1]`` (leg 0:
        ``start.crossing``) to ``ends[i]``.
    """

    start: StartReport
    ends: tuple[Crossing, ...]

    @property
    def bounds(self) -> tuple[Crossing, ...]:
        """Start crossing followed by every leg end (``n_legs + 1`` entries)."""
        return (self.start.crossing, *self.ends)


def _crossings(t: NDArray, x: NDArray, y: NDArray, geom: TargetGeometry, t_after: float
               ) -> list[Crossing]:
    """Every forward crossing of ``geom`` by the polyline after ``t_after``, in time order."""
    hit, s, _ = segment_crossing(x[:-1], y[:-1], x[1:], y[1:], geom)
    out = []
    for k in np.flatnonzero(hit):
        tc = t[k] + s[k] * (t[k + 1] - t[k])
        if tc >= t_after:
            out.append(Crossing(float(tc), float(x[k] + s[k] * (x[k + 1] - x[k])),
                                float(y[k] + s[k] * (y[k + 1] - y[k]))))
    return out


def _extended(geom: TargetGeometry, margin: float) -> TargetGeometry:
    ex, ey = geom.b[0] - geom.a[0], geom.b[1] - geom.a[1]
    n = math.hypot(ex, ey)
    ux, uy = ex / n, ey / n
    return TargetGeometry((geom.a[0] - margin * ux, geom.a[1] - margin * uy),
                          (geom.b[0] + margin * ux, geom.b[1] + margin * uy),
                          geom.normal, geom.kind, geom.name)


def start_geometry(course: Course, detect_m: float = DETECT_M) -> TargetGeometry:
    """The start line of leg 0, directed from the pre-start side to the course side.

    A line start uses the line; a mark start the line through the mark square to the
    bearing of the first leg, :data:`MARK_START_HALF_M` to either side.
    """
    start, target = leg_endpoints(course, 0)
    tc = target.centre
    if start.b is None:
        mx, my = start.a
        th = math.atan2(tc[0] - mx, tc[1] - my)
        rx, ry = math.cos(th), -math.sin(th)
        h = MARK_START_HALF_M
        a = (mx - h * rx, my - h * ry)
        b = (mx + h * rx, my + h * ry)
        return TargetGeometry(a, b, (math.sin(th), math.cos(th)), "line", start.name)
    # crossed from the side away from the first target: the "finish" geometry of a
    # leg that starts at the first target
    g = target_geometry(Target("line", start.a, start.b, None, name=start.name),
                        Start((tc[0], tc[1]), None))
    return TargetGeometry(g.a, g.b, (-g.normal[0], -g.normal[1]), "line", start.name)


def leg_target(course: Course, i: int) -> Target:
    """Target of leg ``i`` with the next leg's target centre as its rounding exit."""
    target = target_of(course, i)
    if target.kind == "mark" and target.rounding is not None and i + 1 < course.n_legs:
        from dataclasses import replace

        target = replace(target, exit_xy=target_of(course, i + 1).centre)
    return target


def detection_geometry(course: Course, i: int, from_xy: tuple[float, float],
                       detect_m: float = DETECT_M, line_margin_m: float = LINE_MARGIN_M
                       ) -> TargetGeometry:
    """Crossing geometry of leg ``i``'s target for a leg that starts at ``from_xy`` [m]."""
    target = leg_target(course, i)
    geom = target_geometry(target, Start(from_xy, None, course.legs[i].from_name),
                           zone_m=detect_m)
    if target.kind != "mark":
        return _extended(geom, line_margin_m)
    # the ray starts MARK_TOLERANCE_M behind the mark: marks noted from a track lie on
    # the boat's own turning point, and buoys are placed to some metres
    ex, ey = geom.b[0] - geom.a[0], geom.b[1] - geom.a[1]
    n = math.hypot(ex, ey)
    a = (geom.a[0] - MARK_TOLERANCE_M * ex / n, geom.a[1] - MARK_TOLERANCE_M * ey / n)
    return TargetGeometry(a, geom.b, geom.normal, geom.kind, geom.name)


def _point_at(t: NDArray, x: NDArray, y: NDArray, tq: float) -> tuple[float, float]:
    return float(np.interp(tq, t, x)), float(np.interp(tq, t, y))


def turn_deg(x: NDArray, y: NDArray) -> float:
    """Net turn of the course over ground along a polyline [°]: − = to the left (the sense
    of a rounding that leaves the mark to port), + = to the right.

    The turn, not the winding angle around the mark, is used: marks noted from a track
    lie on the boat's own path, where the bearing from the mark is undefined.
    """
    dx, dy = np.diff(x), np.diff(y)
    moving = np.hypot(dx, dy) > 0.2
    h = bearing_deg(dx[moving], dy[moving])
    return float(np.sum(wrap180(np.diff(h)))) if h.size > 1 else 0.0


def _not_found(course: Course, i: int, t: NDArray, x: NDArray, y: NDArray, t_from: float,
               where: str, detect_m: float) -> InputError:
    """The error for a leg whose target is never crossed (wrong side, or never reached)."""
    leg = course.legs[i]
    feat = course.feature(leg.to_name)
    cx, cy = feature_centre(feat)
    m = t >= t_from
    d = np.hypot(x[m] - cx, y[m] - cy)
    k = int(np.argmin(d)) if d.size else 0
    tq = t[m][k] if d.size else t_from
    how = ("Check the mark positions and the leg order in the course file, or give the leg "
           "times explicitly (--leg-times)")
    if isinstance(feat, Mark) and leg.rounding is not None and d.size and d[k] <= detect_m:
        # came close: which way did it go round?
        # the pass around the closest approach: the contiguous run within 2 detect_m
        far = d > 2.0 * detect_m
        before = np.flatnonzero(far[:k])
        after = np.flatnonzero(far[k:])
        seg = slice(int(before[-1]) + 1 if before.size else 0,
                    k + int(after[0]) if after.size else d.size)
        turn = turn_deg(x[m][seg], y[m][seg])
        went = "port" if turn < 0 else "starboard"
        if went != leg.rounding and abs(turn) >= 90.0:
            return InputError(
                f"{where}: leg {i + 1} ({leg.label}): the boat rounded mark {leg.to_name!r} "
                f"leaving it to {went} (closest {d[k]:.0f} m at {iso(tq)}), but the course "
                f"says {leg.rounding}. {how}"
            )
    dist = f"closest approach {d[k]:.0f} m at {iso(tq)}" if d.size else "no points left"
    return InputError(
        f"{where}: leg {i + 1} ({leg.label}): the track never {_verb(feat)} "
        f"{leg.to_name!r} after {iso(t_from)} ({dist}; detection reaches {detect_m:.0f} m "
        f"from a mark). {how}"
    )


def _verb(feat: object) -> str:
    return "rounds" if isinstance(feat, Mark) else "crosses"


def segment_track(
    course: Course,
    t: NDArray,
    x: NDArray,
    y: NDArray,
    *,
    leg_times: Sequence[float | None] | None = None,
    detect_m: float = DETECT_M,
    line_margin_m: float = LINE_MARGIN_M,
    where: str = "track",
) -> Segmentation:
    """Find the start and the end of every leg in a track.

    Parameters
    ----------
    course : Course
        The course (its ``start_time`` is the gun).
    t : ndarray
        Track times [epoch s], increasing.
    x, y : ndarray
        Track positions in the course frame [m].
    leg_times : sequence of float or None, optional
        ``n_legs + 1`` boundary times [epoch s]: the start crossing, then each leg's
        end.  A number overrides the detection for that boundary; None detects it.
    detect_m : float
        Length of a mark's rounding ray [m].
    line_margin_m : float
        Extension of lines and gates at both ends [m].
    where : str
        Track name for messages.

    Returns
    -------
    Segmentation

    Raises
    ------
    InputError
        The boat never starts after the gun, never rounds/crosses a target (the
        message gives the closest approach), or rounds a mark on the wrong side;
        ``leg_times`` of the wrong length, not increasing, or outside the track.
    """
    n = course.n_legs
    given: list[float | None] = list(leg_times) if leg_times is not None else [None] * (n + 1)
    if len(given) != n + 1:
        raise InputError(
            f"{where}: leg times: got {len(given)} times for {n} legs; give {n + 1} (the "
            "start crossing, then the end of each leg), or none to detect them"
        )
    vals = [g for g in given if g is not None]
    if any(b <= a for a, b in itertools.pairwise(vals)):
        raise InputError(f"{where}: leg times must increase; got "
                         + ", ".join(iso(v) for v in vals))
    for v in vals:
        if not t[0] <= v <= t[-1]:
            raise InputError(f"{where}: leg time {iso(v)} is outside the track "
                             f"({iso(t[0])} .. {iso(t[-1])})")
    gun = course.start_epoch
    sg = start_geometry(course, detect_m)
    sg_ext = _extended(sg, line_margin_m)
    if given[0] is not None:
        sx, sy = _point_at(t, x, y, given[0])
        start = Crossing(given[0], sx, sy, detected=False)
    else:
        found = _crossings(t, x, y, sg_ext, gun)
        if not found:
            if t[-1] < gun:
                raise InputError(f"{where}: the track ends at {iso(t[-1])}, before the start "
                                 f"signal {iso(gun)}; is it the right track and day?")
            raise InputError(
                f"{where}: the boat never crosses the start line ({sg.name}) from the "
                f"pre-start side after the gun at {iso(gun)}. Check the course's start_time "
                "and start line, or give the start time explicitly (--leg-times)"
            )
        start = found[0]
    gx, gy = _point_at(t, x, y, gun)
    ex, ey = sg.b[0] - sg.a[0], sg.b[1] - sg.a[1]
    length2 = ex * ex + ey * ey
    f = ((gx - sg.a[0]) * ex + (gy - sg.a[1]) * ey) / length2
    fc = min(max(f, 0.0), 1.0)
    dist = math.hypot(gx - (sg.a[0] + fc * ex), gy - (sg.a[1] + fc * ey))
    over = (gx - sg.a[0]) * sg.normal[0] + (gy - sg.a[1]) * sg.normal[1] > 0
    fs = ((start.x - sg.a[0]) * ex + (start.y - sg.a[1]) * ey) / length2
    feat0 = course.feature(course.legs[0].from_name)
    if not isinstance(feat0, Mark):  # report along the real line
        la, lb = feat0.a.xy, feat0.b.xy
        lex, ley = lb[0] - la[0], lb[1] - la[1]
        fs = ((start.x - la[0]) * lex + (start.y - la[1]) * ley) / (lex * lex + ley * ley)
    report = StartReport(gun, start, start.t - gun, dist, "course" if over else "pre-start",
                         float(fs))

    ends: list[Crossing] = []
    prev = start
    for i in range(n):
        g = given[i + 1]
        if g is not None:
            px, py = _point_at(t, x, y, g)
            end = Crossing(g, px, py, detected=False)
        else:
            geom = detection_geometry(course, i, (prev.x, prev.y), detect_m, line_margin_m)
            found = _crossings(t, x, y, geom, prev.t + 1e-6)
            nxt = [v for v in given[i + 2:] if v is not None]
            if nxt:
                found = [c for c in found if c.t < nxt[0]]
            if not found:
                raise _not_found(course, i, t, x, y, prev.t, where, detect_m)
            end = found[0]
        ends.append(end)
        prev = end
    return Segmentation(report, tuple(ends))
