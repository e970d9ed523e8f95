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
from sailroute.routing.startline import distance_to_segment
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

START_EXTENSION_M = 500.0
"""The start line is also searched this far beyond each end [m]: a fleet that starts on a
line laid away from the surveyed marks crosses the surveyed line's extension, and the
distance is reported (``StartReport.line_offset_m``) instead of the start being missed."""

OCS_RETURN_S = 180.0
"""A boat over the start line at the gun that recrosses it back to the pre-start side
within this time after the gun [s] has returned to start; otherwise it is reported over
early (``StartReport.ocs_s``) and its race is timed from the gun."""

OCS_MIN_S = 1.0
"""A crossing this close before the gun [s] is a start on time (``late_s`` in
``[-OCS_MIN_S, 0]``), not over early: the gun and the fixes are known to about a second."""

GATE_ROUNDING_S = 30.0
"""With ``gate_end="rounding"``: the gate mark rounded is the one the boat comes closest to
within this time after passing between the marks, and its rounding is searched in that
time [s]."""

GAP_MIN_S = 10.0
"""Shortest interval between fixes that is a data gap [s] (with :data:`GAP_FACTOR`)."""

GAP_FACTOR = 5.0
"""An interval between fixes longer than ``max(GAP_MIN_S, GAP_FACTOR x median interval)``
is a data gap: a leg end that falls inside it is unknown, not interpolated."""


def gap_limit_s(t: NDArray) -> float:
    """Longest interval between fixes bridged by interpolation [s].

    ``max(GAP_MIN_S, GAP_FACTOR x median interval)``: 10 s for a 1 Hz log, 25 s for a
    fix every 5 s.
    """
    if t.size < 2:
        return GAP_MIN_S
    return max(GAP_MIN_S, GAP_FACTOR * float(np.median(np.diff(t))))


@dataclass(frozen=True)
class Crossing:
    """Where and when the track crossed a target.

    Attributes
    ----------
    t : float
        Time [epoch s] (interpolated between fixes); NaN when unknown: the crossing
        lies inside a data gap (``gap``) or was never found.
    x, y : float
        Position [m] (inside a gap: where the straight line across the gap crosses;
        never found: NaN).
    detected : bool
        True if found from the geometry, False if given explicitly.
    gap : (float, float) or None
        The data gap ``(last fix before, first fix after)`` [epoch s] the crossing
        lies in, longer than :func:`gap_limit_s`.
    note : str
        Why the time is unknown (empty when known).
    """

    t: float
    x: float
    y: float
    detected: bool = True
    gap: tuple[float, float] | None = None
    note: str = ""

    @property
    def known(self) -> bool:
        """True when the crossing time is known."""
        return math.isfinite(self.t)

    @property
    def t_lo(self) -> float:
        """Earliest time the crossing can have happened [epoch s] (NaN: never found)."""
        return self.gap[0] if self.gap is not None else self.t

    @property
    def t_hi(self) -> float:
        """Latest time the crossing can have happened [epoch s] (NaN: never found)."""
        return self.gap[1] if self.gap is not None else self.t


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
        Side of the line the boat was on at the gun (course side = over early: abreast of
        the line or its :data:`START_EXTENSION_M` extension, on the course side).
    line_fraction : float
        Where on the line the boat crossed: 0 at its first end, 1 at its second
        (outside [0, 1]: on the line's extension).
    ocs_s : float or None
        Over early: the boat crossed the line this long before the gun [s] and was on
        the course side at the gun (None: it was not).  Unless ``ocs_returned``, the
        race is timed from the gun (``crossing`` is the boat at the gun).
    ocs_returned : bool
        The boat over early came back to the pre-start side within
        :data:`OCS_RETURN_S` and ``crossing`` is its restart.
    line_offset_m : float
        Distance from the surveyed line (segment) of the point where the boat crossed
        the line's extension [m]; 0 when it crossed the line itself.
    notes : tuple of str
        One sentence per finding (over early, line's extension, given time).
    speed_at_gun_ms : float
        Speed over the ground at the gun [m s⁻¹] (the fixes 2 either side; NaN outside
        the track or across a data gap).
    """

    gun_t: float
    crossing: Crossing
    late_s: float
    distance_at_gun_m: float
    side_at_gun: str
    line_fraction: float
    ocs_s: float | None = None
    ocs_returned: bool = False
    line_offset_m: float = 0.0
    notes: tuple[str, ...] = ()
    speed_at_gun_ms: float = math.nan


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

    @property
    def notes(self) -> tuple[str, ...]:
        """The start's notes, then one per leg end whose time is unknown."""
        return (*self.start.notes, *(c.note for c in self.ends if c.note))


def _crossings(
    t: NDArray,
    x: NDArray,
    y: NDArray,
    geom: TargetGeometry,
    t_after: float,
    gap_s: float = math.inf,
    t_before: float = math.inf,
) -> list[Crossing]:
    """Every forward crossing of ``geom`` by the polyline after ``t_after`` (and before
    ``t_before``), in time order.

    A crossing between two fixes more than ``gap_s`` apart has an unknown time
    (``Crossing.gap``); it counts when the gap ends after ``t_after``.
    """
    lo = max(int(np.searchsorted(t, t_after, side="left")) - 1, 0)
    hi = min(int(np.searchsorted(t, t_before, side="right")) + 1, t.size)
    ts, xs, ys = t[lo:hi], x[lo:hi], y[lo:hi]
    if ts.size < 2:
        return []
    hit, s, _ = segment_crossing(xs[:-1], ys[:-1], xs[1:], ys[1:], geom)
    out = []
    for k in np.flatnonzero(hit):
        cx = float(xs[k] + s[k] * (xs[k + 1] - xs[k]))
        cy = float(ys[k] + s[k] * (ys[k + 1] - ys[k]))
        t0, t1 = float(ts[k]), float(ts[k + 1])
        if t1 - t0 > gap_s:
            if t1 > t_after and t0 < t_before:
                out.append(
                    Crossing(
                        math.nan,
                        cx,
                        cy,
                        gap=(t0, t1),
                        note=(
                            f"{geom.name!r} crossed inside a data gap of {t1 - t0:.0f} s "
                            f"({iso(t0)} .. {iso(t1)}, longer than {gap_s:.0f} s): time unknown"
                        ),
                    )
                )
            continue
        tc = t0 + float(s[k]) * (t1 - t0)
        if t_after <= tc <= t_before:
            out.append(Crossing(tc, cx, cy))
    return out


def _extended(geom: TargetGeometry, margin: float) -> TargetGeometry:
    ex, ey = geom.b[0] - geom.a[0], geom.b[1] - geom.a[1]
    n = math.hypot(ex, ey)
    ux, uy = ex / n, ey / n
    return TargetGeometry(
        (geom.a[0] - margin * ux, geom.a[1] - margin * uy),
        (geom.b[0] + margin * ux, geom.b[1] + margin * uy),
        geom.normal,
        geom.kind,
        geom.name,
    )


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
    g = target_geometry(
        Target("line", start.a, start.b, None, name=start.name), Start((tc[0], tc[1]), None)
    )
    return TargetGeometry(g.a, g.b, (-g.normal[0], -g.normal[1]), "line", start.name)


def start_search_geometry(course: Course, detect_m: float = DETECT_M) -> TargetGeometry:
    """The start line as :func:`find_start` searches it after the gun: the
    :func:`start_geometry` extended by :data:`START_EXTENSION_M` beyond each end."""
    return _extended(start_geometry(course, detect_m), START_EXTENSION_M)


def leg_target(course: Course, i: int) -> Target:
    """Target of leg ``i`` with the next leg's target centre as its rounding exit."""
    target = target_of(course, i)
    if target.kind == "mark" and target.rounding is not None and i + 1 < course.n_legs:
        from dataclasses import replace

        target = replace(target, exit_xy=target_of(course, i + 1).centre)
    return target


def detection_geometry(
    course: Course,
    i: int,
    from_xy: tuple[float, float],
    detect_m: float = DETECT_M,
    line_margin_m: float = LINE_MARGIN_M,
) -> TargetGeometry:
    """Crossing geometry of leg ``i``'s target for a leg that starts at ``from_xy`` [m]."""
    target = leg_target(course, i)
    geom = target_geometry(target, Start(from_xy, None, course.legs[i].from_name), zone_m=detect_m)
    if target.kind != "mark":
        return _extended(geom, line_margin_m)
    return _behind_mark(geom)


def _behind_mark(geom: TargetGeometry) -> TargetGeometry:
    """A mark's rounding ray started :data:`MARK_TOLERANCE_M` behind the mark: marks noted
    from a track lie on the boat's own turning point, and buoys are placed to some metres."""
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


def _not_found(
    course: Course,
    i: int,
    t: NDArray,
    x: NDArray,
    y: NDArray,
    t_from: float,
    where: str,
    detect_m: float,
) -> InputError:
    """The error for a leg whose target is never crossed (wrong side, or never reached)."""
    leg = course.legs[i]
    feat = course.feature(leg.to_name)
    cx, cy = feature_centre(feat)
    m = t >= t_from
    d = np.hypot(x[m] - cx, y[m] - cy)
    k = int(np.argmin(d)) if d.size else 0
    tq = t[m][k] if d.size else t_from
    how = (
        "Check the mark positions and the leg order in the course file, or give the leg "
        "times explicitly (--leg-times)"
    )
    if isinstance(feat, Mark) and leg.rounding is not None and d.size and d[k] <= detect_m:
        # came close: which way did it go round?
        # the pass around the closest approach: the contiguous run within 2 detect_m
        far = d > 2.0 * detect_m
        before = np.flatnonzero(far[:k])
        after = np.flatnonzero(far[k:])
        seg = slice(
            int(before[-1]) + 1 if before.size else 0, k + int(after[0]) if after.size else d.size
        )
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


GIVEN_NEAR_M = 300.0
"""At a leg time given by hand (``--leg-times``) the boat must be within this distance
of what that time ends (the start line, the leg's mark, gate or line) [m]: some tens of
seconds of a fast boat, so that a time off by more (a typing error, legs given
milliseconds apart) is refused instead of timing a leg the boat did not sail."""


def _check_leg_times(
    course: Course, given: Sequence[float | None], t: NDArray, x: NDArray, y: NDArray, where: str
) -> None:
    """Refuse leg times given by hand: the wrong count, not increasing, outside the
    track, or at a moment the boat is not near what they end (:data:`GIVEN_NEAR_M`)."""
    n = course.n_legs
    if len(given) != n + 1:
        raise InputError(
            f"{where}: leg times: got {len(given)} times for {n} legs; give {n + 1} (the "
            "start crossing, then the end of each leg), or none to detect them"
        )
    vals = [g for g in given if g is not None]
    if any(b <= a for a, b in itertools.pairwise(vals)):
        raise InputError(
            f"{where}: leg times must increase; got " + ", ".join(iso(v) for v in vals)
        )
    for v in vals:
        if not t[0] <= v <= t[-1]:
            raise InputError(
                f"{where}: leg time {iso(v)} is outside the track ({iso(t[0])} .. {iso(t[-1])})"
            )
    for k, g in enumerate(given):
        if g is not None:
            _check_given(course, k, g, t, x, y, where)


def _check_given(
    course: Course,
    k: int,
    tq: float,
    t: NDArray,
    x: NDArray,
    y: NDArray,
    where: str,
) -> None:
    """Refuse the given time ``tq`` of boundary ``k`` (0: the start crossing, ``i + 1``:
    the end of leg ``i``) if the boat is then further than :data:`GIVEN_NEAR_M` from
    its feature."""
    name = course.legs[0].from_name if k == 0 else course.legs[k - 1].to_name
    feat = course.feature(name)
    px, py = _point_at(t, x, y, tq)
    if isinstance(feat, Mark):
        gap = math.hypot(px - feat.xy[0], py - feat.xy[1])
    else:
        gap = distance_to_segment((px, py), feat.a.xy, feat.b.xy)[0]
    if gap > GIVEN_NEAR_M:
        what = "the start crossing" if k == 0 else f"the end of leg {k}"
        raise InputError(
            f"{where}: leg time {iso(tq)} (--leg-times, {what}): the boat is then "
            f"{gap:.0f} m from {name!r}; expected it within {GIVEN_NEAR_M:.0f} m (check "
            "the time, or give '-' to detect it)"
        )


def _verb(feat: object) -> str:
    return "rounds" if isinstance(feat, Mark) else "crosses"


def _side(geom: TargetGeometry, px: float, py: float) -> float:
    """Signed distance of a point from the line through ``geom`` [m] (+ along ``normal``)."""
    return (px - geom.a[0]) * geom.normal[0] + (py - geom.a[1]) * geom.normal[1]


def _segment_offset(geom: TargetGeometry, px: float, py: float) -> tuple[float, float]:
    """Fraction along ``a → b`` of the point's projection, and its distance from the segment [m]."""
    ex, ey = geom.b[0] - geom.a[0], geom.b[1] - geom.a[1]
    f = ((px - geom.a[0]) * ex + (py - geom.a[1]) * ey) / (ex * ex + ey * ey)
    fc = min(max(f, 0.0), 1.0)
    return f, math.hypot(px - (geom.a[0] + fc * ex), py - (geom.a[1] + fc * ey))


def _reversed(geom: TargetGeometry) -> TargetGeometry:
    return TargetGeometry(geom.a, geom.b, (-geom.normal[0], -geom.normal[1]), geom.kind, geom.name)


def find_start(
    course: Course,
    t: NDArray,
    x: NDArray,
    y: NDArray,
    *,
    given: float | None = None,
    detect_m: float = DETECT_M,
    line_margin_m: float = LINE_MARGIN_M,
    gap_s: float = math.inf,
    where: str = "track",
) -> StartReport:
    """The start: when and where the boat started, and how (late, over early, off the line).

    * On the pre-start side at the gun: the first crossing of the start line after the
      gun (the segment extended by ``line_margin_m``; else its extension, up to
      :data:`START_EXTENSION_M` beyond each end, reported in ``line_offset_m``).
    * On the course side at the gun (over early): the last crossing before the gun gives
      ``ocs_s`` (within :data:`OCS_MIN_S` of the gun: a start on time).  If the boat
      comes back to the pre-start side within :data:`OCS_RETURN_S`, its next crossing is
      the start; if not, the boat is reported over early and the race is timed from the
      gun (its position at the gun).
    * ``given``: that time, nothing detected.

    Raises
    ------
    InputError
        The track ends before the gun, or the boat never crosses the start line (nor
        its extension) after the gun; the message gives the closest approach.
    """
    gun = course.start_epoch
    sg = start_geometry(course, detect_m)
    wide = _extended(sg, START_EXTENSION_M)
    gx, gy = _point_at(t, x, y, gun)
    _, dist = _segment_offset(sg, gx, gy)
    # over: on the course side at the gun, abreast of the line or its searched extension
    abreast = 0.0 <= _segment_offset(wide, gx, gy)[0] <= 1.0
    over = t[0] <= gun <= t[-1] and abreast and _side(sg, gx, gy) > 0
    feat0 = course.feature(course.legs[0].from_name)
    line = (
        sg
        if isinstance(feat0, Mark)
        else TargetGeometry(feat0.a.xy, feat0.b.xy, sg.normal, "line", sg.name)
    )
    notes: list[str] = []
    ocs: float | None = None
    returned = on_time = False
    if given is not None:
        sx, sy = _point_at(t, x, y, given)
        start = Crossing(given, sx, sy, detected=False)
        notes.append(f"start time given: {iso(given)}")
    else:
        if t[-1] < gun:
            raise InputError(
                f"{where}: the track ends at {iso(t[-1])}, before the start "
                f"signal {iso(gun)}; is it the right track and day?"
            )
        after = gun
        early = [c for c in _crossings(t, x, y, wide, t[0], gap_s, gun) if c.known] if over else []
        on_time = bool(early) and gun - early[-1].t <= OCS_MIN_S
        if over and not on_time:
            back = [
                c
                for c in _crossings(t, x, y, _reversed(wide), gun, gap_s, gun + OCS_RETURN_S)
                if c.known
            ]
            if early:
                ocs = gun - early[-1].t
            if back:
                returned = True
                after = back[0].t
                notes.append(
                    (
                        f"over early: crossed the line {ocs:.0f} s before the gun, "
                        if ocs is not None
                        else "over the line at the gun, "
                    )
                    + f"came back at {iso(after)} and restarted"
                )
        if on_time:
            start = early[-1]
        elif over and not returned:
            start = Crossing(gun, gx, gy)
            notes.append(
                (
                    f"OCS by {ocs:.0f} s: crossed the start line {ocs:.0f} s before the gun "
                    if ocs is not None
                    else "on the course side at the gun "
                )
                + f"and did not come back; {dist:.0f} m over at the gun; legs timed from "
                "the gun"
            )
        else:
            found = [c for c in _crossings(t, x, y, wide, after, gap_s) if c.known]
            if not found:
                raise InputError(
                    f"{where}: the boat never crosses the start line ({sg.name}) nor its "
                    f"extension ({START_EXTENSION_M:.0f} m beyond each end) from the "
                    f"pre-start side after the gun at {iso(gun)} (closest approach "
                    f"{_closest_m(sg, x[t >= gun], y[t >= gun]):.0f} m). Check the course's "
                    "start_time and start line, or give the start time explicitly "
                    "(--leg-times)"
                )
            start = found[0]
    f_line, off = _segment_offset(line, start.x, start.y)
    from_gun = over and not on_time and not returned
    if not start.detected or from_gun or off <= line_margin_m:
        off = 0.0
    else:
        if isinstance(feat0, Mark):
            end = f"the line through {feat0.name!r}"
        else:
            end = repr(feat0.a.name if f_line < 0.5 else feat0.b.name)
        notes.append(
            f"crossed the start line's extension {off:.0f} m beyond {end}, not the "
            "surveyed line: is the line laid elsewhere?"
        )
    return StartReport(
        gun,
        start,
        start.t - gun,
        dist,
        "course" if over else "pre-start",
        float(f_line),
        ocs,
        returned,
        float(off),
        tuple(notes),
        speed_at(t, x, y, gun, gap_s),
    )


def speed_at(t: NDArray, x: NDArray, y: NDArray, tq: float, gap_s: float = math.inf) -> float:
    """Speed over the ground at ``tq`` [m s⁻¹]: distance sailed over the fixes 2 either side
    divided by their time span (NaN outside the track or when they span more than
    ``2 gap_s``)."""
    k = int(np.searchsorted(t, tq))
    if k <= 0 or k >= t.size:
        return math.nan
    lo, hi = max(k - 2, 0), min(k + 2, t.size - 1)
    if t[hi] - t[lo] > 2.0 * gap_s:
        return math.nan
    dist = float(np.sum(np.hypot(np.diff(x[lo : hi + 1]), np.diff(y[lo : hi + 1]))))
    return dist / float(t[hi] - t[lo])


def _stop_near(
    t: NDArray,
    x: NDArray,
    y: NDArray,
    geom: TargetGeometry,
    t_from: float,
    gap_s: float,
    reach_m: float,
) -> Crossing | None:
    """The first data gap after ``t_from`` whose last fix lies within ``reach_m`` of the
    target segment (a line or gate: on the near side of it; a mark: its rounding ray): the
    target is reached inside the gap, at an unknown time."""
    k0 = int(np.searchsorted(t, t_from, side="right"))
    if k0 >= t.size - 1:
        return None
    idx = k0 + np.flatnonzero(np.diff(t[k0:]) > gap_s)
    for k in idx:
        px, py = float(x[k]), float(y[k])
        d = _segment_offset(geom, px, py)[1]
        short = geom.kind == "mark" or _side(geom, px, py) <= 0
        if short and d <= reach_m:
            t0, t1 = float(t[k]), float(t[k + 1])
            return Crossing(
                math.nan,
                px,
                py,
                gap=(t0, t1),
                note=(
                    f"the data stop {d:.0f} m short of {geom.name!r} at {iso(t0)} (a gap of "
                    f"{t1 - t0:.0f} s, longer than {gap_s:.0f} s): time unknown"
                ),
            )
    return None


def gate_rounding(
    course: Course,
    i: int,
    passed: Crossing,
    from_xy: tuple[float, float],
    t: NDArray,
    x: NDArray,
    y: NDArray,
    *,
    gap_s: float = math.inf,
    detect_m: float = DETECT_M,
) -> Crossing | None:
    """When the boat, having passed between the marks of leg ``i``'s gate, went round one.

    The mark is the one it comes closest to within :data:`GATE_ROUNDING_S` of ``passed``;
    it is left to port when it lies left of the boat's crossing direction, and its rounding
    is the crossing of its rounding ray (as for a mark leg, towards the next leg's
    target).  Official leg counters (SailGP's ``TRK_LEG_NUM``) change there.

    Returns
    -------
    Crossing or None
        None when the gate was passed at an unknown time or no rounding is found in the
        window (the gate line crossing then stands).
    """
    if not passed.known:
        return None
    w = (t >= passed.t) & (t <= passed.t + GATE_ROUNDING_S)
    if not w.any():
        return None
    gate = course.feature(course.legs[i].to_name)
    if isinstance(gate, Mark):
        return None
    ends = (gate.a, gate.b)
    d = [float(np.min(np.hypot(x[w] - m.x, y[w] - m.y))) for m in ends]
    mark = ends[int(np.argmin(d))]
    line = detection_geometry(course, i, from_xy, detect_m)
    nx, ny = line.normal  # the crossing direction
    left = nx * (mark.y - passed.y) - ny * (mark.x - passed.x) > 0
    exit_xy = leg_target(course, i + 1).centre if i + 1 < course.n_legs else None
    target = Target(
        "mark", mark.xy, None, "port" if left else "starboard", exit_xy=exit_xy, name=mark.name
    )
    geom = _behind_mark(target_geometry(target, Start(from_xy, None), zone_m=detect_m))
    found = [
        c for c in _crossings(t, x, y, geom, passed.t, gap_s, passed.t + GATE_ROUNDING_S) if c.known
    ]
    return found[0] if found else None


def _closest_m(geom: TargetGeometry, x: NDArray, y: NDArray) -> float:
    """Closest approach of the points to the segment ``geom`` [m] (NaN: no points)."""
    if x.size == 0:
        return math.nan
    ex, ey = geom.b[0] - geom.a[0], geom.b[1] - geom.a[1]
    f = np.clip(((x - geom.a[0]) * ex + (y - geom.a[1]) * ey) / (ex * ex + ey * ey), 0.0, 1.0)
    return float(np.min(np.hypot(x - (geom.a[0] + f * ex), y - (geom.a[1] + f * ey))))


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
    missing: str = "error",
    gate_end: str = "line",
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
    missing : {"error", "unknown"}
        A leg end never found: raise (one boat), or mark it and every later leg end
        unknown with the reason as its note (a fleet).
    gate_end : {"line", "rounding"}
        A gate leg ends when the boat passes between the marks (the routers' target), or
        when it has gone round the gate mark it chose (:func:`gate_rounding`; where
        official leg counters change).

    Returns
    -------
    Segmentation
        A leg end inside a data gap longer than :func:`gap_limit_s` has an unknown time
        (``Crossing.known`` False, ``gap`` set); the search for the next target goes on
        after the gap.

    Raises
    ------
    InputError
        The boat never starts (see :func:`find_start`), never rounds/crosses a target
        (the message gives the closest approach; only with ``missing="error"``), or
        rounds a mark on the wrong side; ``leg_times`` of the wrong length, not
        increasing, or outside the track.
    """
    n = course.n_legs
    if gate_end not in ("line", "rounding"):
        raise InputError(f"gate end {gate_end!r}: expected 'line' or 'rounding'")
    given: list[float | None] = list(leg_times) if leg_times is not None else [None] * (n + 1)
    _check_leg_times(course, given, t, x, y, where)
    gap_s = gap_limit_s(t)
    report = find_start(
        course,
        t,
        x,
        y,
        given=given[0],
        detect_m=detect_m,
        line_margin_m=line_margin_m,
        gap_s=gap_s,
        where=where,
    )
    ends: list[Crossing] = []
    prev = report.crossing
    lost = ""
    for i in range(n):
        g = given[i + 1]
        if g is not None:
            px, py = _point_at(t, x, y, g)
            end = Crossing(g, px, py, detected=False)
        elif lost:
            end = Crossing(math.nan, math.nan, math.nan, note=lost)
        else:
            geom = detection_geometry(course, i, (prev.x, prev.y), detect_m, line_margin_m)
            nxt = [v for v in given[i + 2 :] if v is not None]
            found = _crossings(t, x, y, geom, prev.t_hi + 1e-6, gap_s, nxt[0] if nxt else math.inf)
            stop = _stop_near(t, x, y, geom, prev.t_hi, gap_s, detect_m)
            if stop is not None and (not found or stop.t_lo < found[0].t_lo):
                found = [stop]
            if not found:
                err = _not_found(course, i, t, x, y, prev.t_hi, where, detect_m)
                if missing == "error":
                    raise err
                lost = str(err).removeprefix(f"{where}: ")
                end = Crossing(math.nan, math.nan, math.nan, note=lost)
                lost = f"leg {i + 1} never ended: later legs unknown"
            else:
                end = found[0]
                if gate_end == "rounding" and course.legs[i].kind == "gate":
                    end = (
                        gate_rounding(
                            course,
                            i,
                            end,
                            (prev.x, prev.y),
                            t,
                            x,
                            y,
                            gap_s=gap_s,
                            detect_m=detect_m,
                        )
                        or end
                    )
                if end.note:
                    end = Crossing(
                        end.t,
                        end.x,
                        end.y,
                        end.detected,
                        end.gap,
                        f"leg {i + 1} ({course.legs[i].label}): {end.note}",
                    )
        ends.append(end)
        prev = end
    return Segmentation(report, tuple(ends))


FLEET_OVER_M = 50.0
"""A fleet every boat of which is this far or more over the start line at the gun [m]
(or crossed the line's extension this far off) is reported as starting on a line laid
away from the surveyed one (:func:`fleet_start_notes`)."""


def fleet_start_notes(starts: Sequence[StartReport]) -> tuple[str, ...]:
    """What the starts of a fleet say together about the start line.

    Parameters
    ----------
    starts : sequence of StartReport
        One per boat (two or more to say anything).

    Returns
    -------
    tuple of str
        A note when every boat was at least :data:`FLEET_OVER_M` over the line at the gun
        (the line used lay up the course from the surveyed marks, or the start time is
        late), or when every boat crossed the line's extension.
    """
    if len(starts) < 2:
        return ()
    notes = []
    d = np.array([s.distance_at_gun_m for s in starts])
    if all(s.side_at_gun == "course" for s in starts) and d.min() >= FLEET_OVER_M:
        notes.append(
            f"every boat was on the course side of the surveyed start line at the gun, "
            f"{d.min():.0f}-{d.max():.0f} m over (median {float(np.median(d)):.0f} m): the "
            "line used probably lay that far up the course from the surveyed marks (or the "
            "start time is early); the over-early times are against the surveyed line"
        )
    off = np.array([s.line_offset_m for s in starts])
    if off.min() >= FLEET_OVER_M:
        notes.append(
            f"every boat crossed the start line's extension, {off.min():.0f}-{off.max():.0f} m "
            "from the surveyed line: the line used probably lay elsewhere"
        )
    return tuple(notes)
