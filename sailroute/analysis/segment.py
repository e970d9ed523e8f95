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
from dataclasses import dataclass, replace
from enum import StrEnum

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

RAY_ANGLE_DEG = 30.0
"""A crossing of a mark's rounding ray at this angle or steeper [°] (the fixes either side
of it) is a rounding, if the boat does not come back (:func:`_settled`)."""

SETTLE_M = 4.0
"""A shallower crossing counts when the boat gets this far beyond the ray [m] ..."""

SETTLE_S = 20.0
"""... within this time [s] (:func:`_settled`); no crossing counts when the boat comes back
over the ray within it."""

CLOSE_PASS_TURN_DEG = 60.0
"""A boat that passes within :data:`MARK_TOLERANCE_M` of a mark and turns this much in the
rounding's sense over the 20 s either side [°] has rounded it, at its closest approach,
even where GPS noise keeps its track from crossing the rounding ray (a rounding that
grazes the mark)."""

REVERSAL_DEG = 120.0
"""A close pass that turns this much or more [°] in a sense the noisy track cannot tell
(:func:`turn_sense`) is a rounding too."""

GATE_OUTSIDE_S = 60.0
"""A boat that crosses a gate's line beyond its marks (up to ``detect_m`` off) and does not
pass between them within this time after [s] has passed the gate outside its marks: its leg
ends there, flagged (:attr:`LegIssue.OUTSIDE`), instead of at the next time it passes
between the marks (a lap later)."""

LATE_START_S = 10.0
"""A boat that starts more than this after the gun is a late starter [s] (in a fleet, and
beyond the fleet's clean starts: :attr:`StartClock.late_s`)."""

V_MIN_MS = 0.5
"""Slowest speed towards the course side used to turn a distance over the start line into a
time over it [m s⁻¹] (a boat drifting over the line is over by its distance at this speed)."""


class LegIssue(StrEnum):
    """Why a leg end's time is unknown, or what is uncertain about a known one
    (:attr:`Crossing.issue`); a fleet's notes group the boats by it."""

    GAP = "crossed in a data gap"
    DATA_STOP = "the data stop short of the target"
    NOT_REACHED = "never reached"
    WRONG_SIDE = "rounded on the wrong side"
    AFTER_LOST = "after a leg that never ended"
    NO_START = "no start"
    GATE_LINE = "no gate rounding found"
    OUTSIDE = "passed outside the gate's marks"


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
        Why the time is unknown, or what is uncertain about a known time (a gate leg
        timed at the gate line because no rounding was found, a gate passed outside its
        marks); empty otherwise.
    issue : LegIssue or None
        The same as data (None: nothing to say).
    """

    t: float
    x: float
    y: float
    detected: bool = True
    gap: tuple[float, float] | None = None
    note: str = ""
    issue: LegIssue | None = None

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
class StartClock:
    """The gun and the start line a fleet started on, as its tracks see them.

    Without a fleet estimate (one boat), the course's gun and surveyed line
    (:meth:`plain`).  :func:`sailroute.analysis.start.estimate_fleet_start` makes one from
    the fleet itself: the tracks' common clock offset moves the gun, a line laid away from
    the surveyed marks moves the line, and the spread of the fleet's front row sets how
    far over a boat must be to be called over early.

    Attributes
    ----------
    gun_t : float
        The gun in the tracks' clock [epoch s]: the course's start signal plus the
        tracks' clock offset (``time_offset_s`` of :class:`~sailroute.analysis.start.FleetStart`).
    shift_m : float
        The line used lay this far up the course from the surveyed line [m] (along its
        normal; negative: behind it).
    on_time_s : float
        A boat over the line at the gun by this time or less [s] started on time (not over
        early): :data:`OCS_MIN_S` alone, the fleet's uncertainty times
        :data:`~sailroute.analysis.start.Z_OCS` in a fleet.
    sd_s : float
        Standard deviation of a boat's time over the line about the fleet's front row [s]
        (NaN: no fleet estimate); a boat over early is called with its margin in these.
    over_s : float
        The fleet estimate's time the boat was over the line at the gun [s] (negative:
        behind it; NaN: no estimate, the geometry at the gun decides).
    called : bool or None
        The fleet estimate's verdict: over early by more than its uncertainty (None: no
        estimate; over early beyond ``on_time_s``).
    late_s : float
        A start later than this after the gun is late [s]: :data:`LATE_START_S`, or in a
        fleet beyond its clean starts by the boat's uncertainty.
    """

    gun_t: float
    shift_m: float = 0.0
    on_time_s: float = OCS_MIN_S
    sd_s: float = math.nan
    over_s: float = math.nan
    called: bool | None = None
    late_s: float = LATE_START_S

    @classmethod
    def plain(cls, gun_t: float) -> StartClock:
        """The gun as given and the surveyed line, no fleet estimate."""
        return cls(gun_t)


@dataclass(frozen=True)
class StartReport:
    """The start.

    Attributes
    ----------
    gun_t : float
        Start signal [epoch s] in the track's clock (the course's gun, or the fleet's
        estimate: :class:`StartClock`).
    crossing : Crossing
        When and where the boat started (crossed the line after the gun); unknown
        (NaN, with its ``note``) when the boat never started.
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
        Over early: the boat was on the course side at the gun by this time [s] (its
        distance over the line over its speed towards the course side) and more than
        the clock's ``on_time_s`` (None: it was not).  Unless ``ocs_returned``, the
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
    over_s : float
        Time over the line at the gun [s] (NaN: on the pre-start side); over early
        only beyond ``on_time_s``.
    ocs_sd : float
        ``over_s`` in standard deviations of the fleet's front row (NaN: no fleet
        estimate, or not over).
    ocs_p : float
        Probability that the boat was over at the gun, ``Φ(ocs_sd)`` (NaN likewise).
    shift_m : float
        The line the start was searched on lay this far up the course from the
        surveyed one [m] (the clock's ``shift_m``).
    late_limit_s : float
        A start later than this after the gun is late [s] (the clock's ``late_s``).
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
    over_s: float = math.nan
    ocs_sd: float = math.nan
    ocs_p: float = math.nan
    shift_m: float = 0.0
    late_limit_s: float = LATE_START_S

    @property
    def late(self) -> bool:
        """Started (detected) later than ``late_limit_s`` after the gun, not over early."""
        return (
            self.crossing.detected
            and self.ocs_s is None
            and math.isfinite(self.late_s)
            and self.late_s > self.late_limit_s
        )

    @property
    def started(self) -> bool:
        """True when the start time is known (the boat crossed the line, or was timed
        from the gun over early)."""
        return self.crossing.known

    @property
    def ocs(self) -> bool:
        """Over early at the gun and did not come back: called OCS."""
        return self.ocs_s is not None and not self.ocs_returned


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
        """The start's notes, then one per leg end with a note (unknown, or timed in an
        unusual way), each once."""
        return tuple(dict.fromkeys((*self.start.notes, *(c.note for c in self.ends if c.note))))


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
                        issue=LegIssue.GAP,
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
) -> tuple[InputError, LegIssue]:
    """The error for a leg whose target is never crossed, and which: rounded on the wrong
    side, or never reached."""
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
            ), LegIssue.WRONG_SIDE
    dist = f"closest approach {d[k]:.0f} m at {iso(tq)}" if d.size else "no points left"
    return InputError(
        f"{where}: leg {i + 1} ({leg.label}): the track never {_verb(feat)} "
        f"{leg.to_name!r} after {iso(t_from)} ({dist}; detection reaches {detect_m:.0f} m "
        f"from a mark). {how}"
    ), LegIssue.NOT_REACHED


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


def _shifted(geom: TargetGeometry, shift_m: float) -> TargetGeometry:
    """``geom`` moved ``shift_m`` along its normal [m]."""
    if shift_m == 0.0:
        return geom
    nx, ny = geom.normal
    return TargetGeometry(
        (geom.a[0] + shift_m * nx, geom.a[1] + shift_m * ny),
        (geom.b[0] + shift_m * nx, geom.b[1] + shift_m * ny),
        geom.normal,
        geom.kind,
        geom.name,
    )


def course_gun(course: Course) -> float:
    """The course's gun [epoch s]: its ``restart_time`` after a general recall, else its
    ``start_time``."""
    return course.gun_epoch


def start_line(course: Course, clock: StartClock | None = None) -> TargetGeometry:
    """The start line a fleet started on: :func:`start_geometry` moved by the clock's
    ``shift_m`` (the surveyed line without a clock)."""
    return _shifted(start_geometry(course), clock.shift_m if clock is not None else 0.0)


def _no_start(
    gun: float, reason: str, dist: float, over: bool, speed: float, shift_m: float
) -> StartReport:
    """The start report of a boat that never started: unknown crossing, ``reason`` its note."""
    nan = math.nan
    return StartReport(
        gun,
        Crossing(nan, nan, nan, note=reason, issue=LegIssue.NO_START),
        nan,
        dist,
        "course" if over else "pre-start",
        nan,
        notes=(reason,),
        speed_at_gun_ms=speed,
        shift_m=shift_m,
    )


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
    clock: StartClock | None = None,
    missing: str = "error",
) -> StartReport:
    """The start: when and where the boat started, and how (late, over early, off the line).

    * On the pre-start side at the gun: the first crossing of the start line after the
      gun (the segment extended by ``line_margin_m``; else its extension, up to
      :data:`START_EXTENSION_M` beyond each end, reported in ``line_offset_m``).
    * On the course side at the gun: over by ``over_s``, the distance over the line
      divided by the speed towards the course side (at least :data:`V_MIN_MS`).  Within
      the clock's ``on_time_s`` (:data:`OCS_MIN_S` alone) a start on time, at the last
      crossing before the gun; beyond it over early (``ocs_s``).  If the boat comes back
      to the pre-start side within :data:`OCS_RETURN_S`, its next crossing is the start;
      if not, the boat is reported over early and the race is timed from the gun (its
      position at the gun).
    * ``given``: that time, nothing detected.

    ``clock`` (:class:`StartClock`) gives the gun in the track's clock, the line the fleet
    started on and how far over is over early; without it, the course's gun and surveyed
    line and :data:`OCS_MIN_S`.

    Raises
    ------
    InputError
        The track ends before the gun, or the boat never crosses the start line (nor
        its extension) after the gun (the message gives the closest approach); with
        ``missing="unknown"`` (a fleet) neither raises: the report's crossing is
        unknown with the reason as its note (:attr:`StartReport.started` False).
    """
    clock = clock if clock is not None else StartClock.plain(course_gun(course))
    gun = clock.gun_t
    sg = start_line(course, clock)
    wide = _extended(sg, START_EXTENSION_M)
    gx, gy = _point_at(t, x, y, gun)
    _, dist = _segment_offset(sg, gx, gy)
    # over: on the course side at the gun, abreast of the line or its searched extension
    abreast = 0.0 <= _segment_offset(wide, gx, gy)[0] <= 1.0
    over = t[0] <= gun <= t[-1] and abreast and _side(sg, gx, gy) > 0
    speed = speed_at(t, x, y, gun, gap_s)
    over_s = math.nan
    if over and clock.called is not None:
        over_s = clock.over_s
    elif over:
        vx, vy = velocity_at(t, x, y, gun, gap_s)
        vn = vx * sg.normal[0] + vy * sg.normal[1]
        over_s = _side(sg, gx, gy) / max(vn if math.isfinite(vn) else 0.0, V_MIN_MS)
    feat0 = course.feature(course.legs[0].from_name)
    line = (
        sg
        if isinstance(feat0, Mark)
        else _shifted(
            TargetGeometry(feat0.a.xy, feat0.b.xy, sg.normal, "line", sg.name), clock.shift_m
        )
    )
    notes: list[str] = []
    ocs: float | None = None
    returned = on_time = False
    fleet = math.isfinite(clock.sd_s) and clock.sd_s > 0
    if given is not None:
        sx, sy = _point_at(t, x, y, given)
        start = Crossing(given, sx, sy, detected=False)
        notes.append(f"start time given: {iso(given)}")
    else:
        if t[-1] < gun:
            reason = f"the track ends at {iso(t[-1])}, before the start signal {iso(gun)}"
            if missing == "error":
                raise InputError(f"{where}: {reason}; is it the right track and day?")
            return _no_start(gun, reason, dist, over, speed, clock.shift_m)
        after = gun
        early = [c for c in _crossings(t, x, y, wide, t[0], gap_s, gun) if c.known] if over else []
        on_time = over and (
            not clock.called if clock.called is not None else over_s <= clock.on_time_s
        )
        crossed = (
            f"crossed the start line {gun - early[-1].t:.0f} s before the gun " if early else ""
        )
        sure = (
            f" ({over_s / clock.sd_s:.1f} sd beyond the fleet's front row, p = "
            f"{_phi(over_s / clock.sd_s):.3f})"
            if fleet and over
            else ""
        )
        if over and not on_time:
            ocs = over_s
            back = [
                c
                for c in _crossings(t, x, y, _reversed(wide), gun, gap_s, gun + OCS_RETURN_S)
                if c.known
            ]
            if back:
                returned = True
                after = back[0].t
                notes.append(
                    f"over early: {over_s:.0f} s over the line at the gun{sure}, "
                    + (crossed.replace("crossed", "had crossed") if crossed else "")
                    + f"came back at {iso(after)} and restarted"
                )
        if on_time:
            start = early[-1] if early else Crossing(gun, gx, gy)
        elif over and not returned:
            start = Crossing(gun, gx, gy)
            notes.append(
                f"OCS by {over_s:.0f} s: "
                + (crossed or "on the course side at the gun ")
                + f"and did not come back; {dist:.0f} m over at the gun{sure}; legs timed "
                "from the gun"
            )
        else:
            found = [c for c in _crossings(t, x, y, wide, after, gap_s) if c.known]
            if not found:
                reason = (
                    f"never crosses the start line ({sg.name}) nor its extension "
                    f"({START_EXTENSION_M:.0f} m beyond each end) from the pre-start side "
                    f"after the gun at {iso(gun)} (closest approach "
                    f"{_closest_m(sg, x[t >= gun], y[t >= gun]):.0f} m)"
                )
                if missing == "error":
                    raise InputError(
                        f"{where}: the boat {reason}. Check the course's start_time and "
                        "start line, or give the start time explicitly (--leg-times)"
                    )
                return _no_start(gun, f"did not start: {reason}", dist, over, speed, clock.shift_m)
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
    sd = over_s / clock.sd_s if fleet and over else math.nan
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
        speed,
        over_s,
        sd,
        _phi(sd) if math.isfinite(sd) else math.nan,
        clock.shift_m,
        clock.late_s,
    )


def _phi(z: float) -> float:
    """Standard normal cumulative distribution at ``z``."""
    return 0.5 * math.erfc(-z / math.sqrt(2.0))


def velocity_at(
    t: NDArray, x: NDArray, y: NDArray, tq: float, gap_s: float = math.inf
) -> tuple[float, float]:
    """Velocity over the ground at ``tq`` [m s⁻¹]: the displacement between the fixes 2
    either side over their time span (NaN outside the track or when they span more than
    ``2 gap_s``)."""
    k = int(np.searchsorted(t, tq))
    if k <= 0 or k >= t.size:
        return math.nan, math.nan
    lo, hi = max(k - 2, 0), min(k + 2, t.size - 1)
    dt = float(t[hi] - t[lo])
    if dt > 2.0 * gap_s:
        return math.nan, math.nan
    return float(x[hi] - x[lo]) / dt, float(y[hi] - y[lo]) / dt


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
        d = _short_of(geom, float(x[k]), float(y[k]))
        if d <= reach_m:
            t0, t1 = float(t[k]), float(t[k + 1])
            return Crossing(
                math.nan,
                float(x[k]),
                float(y[k]),
                gap=(t0, t1),
                note=(
                    f"the data stop {d:.0f} m short of {geom.name!r} at {iso(t0)} (a gap of "
                    f"{t1 - t0:.0f} s, longer than {gap_s:.0f} s): time unknown"
                ),
                issue=LegIssue.DATA_STOP,
            )
    return None


def _short_of(geom: TargetGeometry, px: float, py: float) -> float:
    """Distance of a point from the target segment [m] when it lies short of it (a line or
    gate: on the near side; a mark: anywhere near its rounding ray), else infinity."""
    short = geom.kind == "mark" or _side(geom, px, py) <= 0
    return _segment_offset(geom, px, py)[1] if short else math.inf


def _data_end_near(
    t: NDArray, x: NDArray, y: NDArray, geom: TargetGeometry, reach_m: float
) -> Crossing | None:
    """The end of the data, when its last fix lies within ``reach_m`` short of the target
    (as :func:`_stop_near`): the target is reached after the data end, at an unknown time."""
    d = _short_of(geom, float(x[-1]), float(y[-1]))
    if d > reach_m:
        return None
    return Crossing(
        math.nan,
        float(x[-1]),
        float(y[-1]),
        note=f"the data end {d:.0f} m short of {geom.name!r} at {iso(float(t[-1]))}: time unknown",
        issue=LegIssue.DATA_STOP,
    )


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
    it is left to port when it is the gate's left end looking along the crossing
    direction, and its rounding is the settled crossing of its rounding ray (as for a mark
    leg, towards the next leg's target), or a close pass that turns round it
    (:func:`_close_pass`).  Official leg counters (SailGP's ``TRK_LEG_NUM``) change
    there.

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
    k = int(np.argmin(d))
    mark, other = ends[k], ends[1 - k]
    line = detection_geometry(course, i, from_xy, detect_m)
    nx, ny = line.normal  # the crossing direction
    # the mark's side from the other mark, not from where the boat passed: a boat that
    # passes at the mark itself leaves it on the gate's side
    left = nx * (mark.y - other.y) - ny * (mark.x - other.x) > 0
    exit_xy = leg_target(course, i + 1).centre if i + 1 < course.n_legs else None
    target = Target(
        "mark", mark.xy, None, "port" if left else "starboard", exit_xy=exit_xy, name=mark.name
    )
    geom = _behind_mark(target_geometry(target, Start(from_xy, None), zone_m=detect_m))
    end = passed.t + GATE_ROUNDING_S
    found = _settled(_crossings(t, x, y, geom, passed.t, gap_s, end), geom, t, x, y)
    found = [c for c in found if c.known]
    if found:
        return found[0]
    return _close_pass(mark.xy, target.rounding, t, x, y, passed.t, end, geom, gap_s)


def _settled(
    found: Sequence[Crossing], geom: TargetGeometry, t: NDArray, x: NDArray, y: NDArray
) -> list[Crossing]:
    """The crossings of a rounding ray that are a rounding, not GPS noise (those inside a
    data gap kept).

    A boat that rounds tight sails close alongside the ray (for a 180° turn the ray lies
    along its approach and its exit) and can wander across it on GPS noise before it turns.
    A crossing counts when the boat does not come back over the ray within
    :data:`SETTLE_S`, and either crosses it steeply (the fixes either side of the crossing
    move at :data:`RAY_ANGLE_DEG` or more to it) or gets :data:`SETTLE_M` beyond it in that
    time."""
    out = []
    lim = math.sin(math.radians(RAY_ANGLE_DEG))
    for c in found:
        if not c.known:
            out.append(c)
            continue
        k = np.flatnonzero((t > c.t) & (t <= c.t + SETTLE_S))
        side = (x[k] - geom.a[0]) * geom.normal[0] + (y[k] - geom.a[1]) * geom.normal[1]
        # back over the ray beyond the mark (the part behind it is where a boat that has
        # rounded a leeward mark tight crosses on its way back up)
        ex, ey = geom.b[0] - geom.a[0], geom.b[1] - geom.a[1]
        n2 = ex * ex + ey * ey
        along = ((x[k] - geom.a[0]) * ex + (y[k] - geom.a[1]) * ey) / n2
        if ((side < -0.5) & (along >= MARK_TOLERANCE_M / math.sqrt(n2)) & (along <= 1.0)).any():
            continue
        j = min(max(int(np.searchsorted(t, c.t, side="left")), 1), t.size - 1)
        i = j - 1  # the fixes either side of the crossing
        dx, dy = float(x[j] - x[i]), float(y[j] - y[i])
        step = math.hypot(dx, dy)
        steep = step > 0 and dx * geom.normal[0] + dy * geom.normal[1] >= lim * step
        if steep or (side >= SETTLE_M).any():
            out.append(c)
    return out


def turn_sense(t: NDArray, x: NDArray, y: NDArray, t0: float, t1: float) -> tuple[float, bool]:
    """Net turn of the course over ground from ``t0`` to ``t1`` [°] (− to the left), and
    whether its sense is decided.

    The track is resampled every 1, 2, 3 and 4 s; the turn is their median.  Its sense is
    decided when they agree: a boat that reverses at a mark within GPS error of it (a
    rounding that grazes the mark) turns 180° in one or two steps, and its sense is then
    noise; the turn is then the median of their sizes (positive).
    """
    turns = []
    for step in (1.0, 2.0, 3.0, 4.0):
        tq = np.arange(t0, t1 + 1e-9, step)
        if tq.size >= 3:
            turns.append(turn_deg(np.interp(tq, t, x), np.interp(tq, t, y)))
    if not turns:
        return 0.0, True
    if all(v < 0 for v in turns) or all(v > 0 for v in turns):
        return float(np.median(turns)), True
    return float(np.median(np.abs(turns))), False


def _close_pass(
    mark: tuple[float, float],
    rounding: str | None,
    t: NDArray,
    x: NDArray,
    y: NDArray,
    t_from: float,
    t_before: float,
    geom: TargetGeometry | None = None,
    gap_s: float = math.inf,
) -> Crossing | None:
    """The first pass within :data:`MARK_TOLERANCE_M` of ``mark`` after ``t_from`` (before
    ``t_before``) that turns :data:`CLOSE_PASS_TURN_DEG` in the rounding's sense, or
    reverses (:data:`REVERSAL_DEG`) in a sense the track cannot tell
    (:func:`turn_sense`).

    It is timed where the pass crosses the mark's rounding ray ``geom`` forwards (the
    crossing nearest its closest approach, while the boat is within the tolerance of the
    mark, a fix either side): a crossing :func:`_settled` did not count (the boat leaves
    alongside the ray, or wanders back over it on GPS noise) still says when the boat went
    round.  Only a pass that never crosses the ray is timed at its closest fix, which is
    flat in time at a rounding and as noisy as the fixes."""
    idx = np.flatnonzero((t > t_from) & (t < t_before))
    if idx.size == 0 or rounding is None:
        return None
    d = np.hypot(x[idx] - mark[0], y[idx] - mark[1])
    near = d <= MARK_TOLERANCE_M
    edges = np.flatnonzero(np.diff(np.concatenate([[0], near.astype(int), [0]])))
    for a, b in zip(edges[::2], edges[1::2], strict=True):
        k = int(idx[a + int(np.argmin(d[a:b]))])
        turn, decided = turn_sense(t, x, y, float(t[k]) - 20.0, float(t[k]) + 20.0)
        sense = -turn if rounding == "port" else turn
        if sense >= CLOSE_PASS_TURN_DEG or (not decided and abs(turn) >= REVERSAL_DEG):
            lo, hi = float(t[max(idx[a] - 1, 0)]), float(t[min(idx[b - 1] + 1, t.size - 1)])
            over = [] if geom is None else _crossings(t, x, y, geom, lo, gap_s, hi)
            over = [c for c in over if c.known]
            if over:
                return min(over, key=lambda c: abs(c.t - float(t[k])))
            return Crossing(float(t[k]), float(x[k]), float(y[k]))
    return None


def _mark_crossings(
    geom: TargetGeometry,
    mark: tuple[float, float],
    rounding: str | None,
    t: NDArray,
    x: NDArray,
    y: NDArray,
    t_from: float,
    gap_s: float,
    t_before: float,
) -> list[Crossing]:
    """The roundings of a mark after ``t_from``: its rounding ray's settled crossings
    (:func:`_settled`), led by a close pass (:func:`_close_pass`) that comes
    :data:`GATE_ROUNDING_S` or more before the first of them (or when there is none)."""
    found = _settled(_crossings(t, x, y, geom, t_from, gap_s, t_before), geom, t, x, y)
    first = next((c.t_lo for c in found), math.inf)
    close = _close_pass(mark, rounding, t, x, y, t_from, min(first, t_before), geom, gap_s)
    if close is not None and close.t + GATE_ROUNDING_S < first:
        return [close, *found]
    return found


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
    clock: StartClock | None = None,
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
        official leg counters change; when none is found the gate line's time stands and
        the leg end says so, :attr:`LegIssue.GATE_LINE`).
    clock : StartClock, optional
        The gun and start line the fleet started on (:func:`find_start`).

    Returns
    -------
    Segmentation
        A leg end inside a data gap longer than :func:`gap_limit_s` has an unknown time
        (``Crossing.known`` False, ``gap`` set); the search for the next target goes on
        after the gap.  A gate passed outside its marks ends its leg where the boat
        crossed the gate's line beyond them (:func:`_outside_pass`).  Every leg end with a
        note carries its :class:`LegIssue`.

    Raises
    ------
    InputError
        The boat never starts (see :func:`find_start`) or never rounds/crosses a target
        (the message gives the closest approach), or rounds a mark on the wrong side:
        only with ``missing="error"``; ``leg_times`` of the wrong length, not
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
        clock=clock,
        missing=missing,
    )
    ends: list[Crossing] = []
    prev = report.crossing
    lost: Crossing | None = (
        None
        if report.started
        else Crossing(
            math.nan,
            math.nan,
            math.nan,
            note="the boat did not start: no leg is timed",
            issue=LegIssue.NO_START,
        )
    )
    for i in range(n):
        g = given[i + 1]
        label = f"leg {i + 1} ({course.legs[i].label})"
        if g is not None:
            px, py = _point_at(t, x, y, g)
            end = Crossing(g, px, py, detected=False)
        elif lost is not None:
            end = lost
        else:
            end, lost = _leg_end(
                course,
                i,
                prev,
                t,
                x,
                y,
                given=given,
                gap_s=gap_s,
                detect_m=detect_m,
                line_margin_m=line_margin_m,
                where=where,
                missing=missing,
                gate_end=gate_end,
            )
            if end.note:
                end = replace(end, note=f"{label}: {end.note}")
        ends.append(end)
        prev = end
    return Segmentation(report, tuple(ends))


def _leg_end(
    course: Course,
    i: int,
    prev: Crossing,
    t: NDArray,
    x: NDArray,
    y: NDArray,
    *,
    given: Sequence[float | None],
    gap_s: float,
    detect_m: float,
    line_margin_m: float,
    where: str,
    missing: str,
    gate_end: str,
) -> tuple[Crossing, Crossing | None]:
    """The end of leg ``i`` after ``prev``, and, when it leaves the later leg ends
    unknown (never found, or the data end), the crossing they get."""
    geom = detection_geometry(course, i, (prev.x, prev.y), detect_m, line_margin_m)
    nxt = [v for v in given[i + 2 :] if v is not None]
    t_before = nxt[0] if nxt else math.inf
    spec = course.legs[i]
    if spec.kind == "mark":
        mark = course.marks[spec.to_name]
        found = _mark_crossings(
            geom, mark.xy, spec.rounding, t, x, y, prev.t_hi + 1e-6, gap_s, t_before
        )
    else:
        found = _crossings(t, x, y, geom, prev.t_hi + 1e-6, gap_s, t_before)
    is_gate = spec.kind == "gate"
    if is_gate:
        found = _outside_pass(course, i, prev, t, x, y, geom, found, gap_s, detect_m, t_before)
    stop = _stop_near(t, x, y, geom, prev.t_hi, gap_s, detect_m)
    if stop is not None and (not found or stop.t_lo < found[0].t_lo):
        found = [stop]
    nan = math.nan
    if not found:
        err, issue = _not_found(course, i, t, x, y, prev.t_hi, where, detect_m)
        stopped = _data_end_near(t, x, y, geom, detect_m) if issue is LegIssue.NOT_REACHED else None
        if stopped is not None:
            later = f"the data end before leg {i + 1} ends: later legs unknown"
            return stopped, Crossing(nan, nan, nan, note=later, issue=LegIssue.AFTER_LOST)
        if missing == "error":
            raise err
        label = f"leg {i + 1} ({course.legs[i].label}): "
        note = str(err).removeprefix(f"{where}: ").removeprefix(label)
        end = Crossing(nan, nan, nan, note=note, issue=issue)
        later = f"leg {i + 1} never ended: later legs unknown"
        return end, Crossing(nan, nan, nan, note=later, issue=LegIssue.AFTER_LOST)
    end = found[0]
    if gate_end == "rounding" and is_gate and end.known:
        rounded = gate_rounding(
            course, i, end, (prev.x, prev.y), t, x, y, gap_s=gap_s, detect_m=detect_m
        )
        if rounded is not None:
            end = replace(rounded, note=end.note, issue=end.issue)
        elif end.issue is None:
            end = replace(
                end,
                note=(
                    f"no rounding of a gate mark found within {GATE_ROUNDING_S:.0f} s of "
                    "passing between the marks: timed at the gate line"
                ),
                issue=LegIssue.GATE_LINE,
            )
    return end, None


def _outside_pass(
    course: Course,
    i: int,
    prev: Crossing,
    t: NDArray,
    x: NDArray,
    y: NDArray,
    geom: TargetGeometry,
    found: list[Crossing],
    gap_s: float,
    detect_m: float,
    t_before: float,
) -> list[Crossing]:
    """The gate leg's crossings, led by a pass outside its marks when there is one.

    A forward crossing of the gate's line up to ``detect_m`` beyond its marks (outside
    ``geom``) that is not followed within :data:`GATE_OUTSIDE_S` by a pass between them
    ends the leg there, flagged :attr:`LegIssue.OUTSIDE` (the next pass between the marks
    may come a lap later)."""
    wide = detection_geometry(course, i, (prev.x, prev.y), detect_m, detect_m)
    first = found[0].t_lo if found else math.inf
    for c in _crossings(t, x, y, wide, prev.t_hi + 1e-6, gap_s, min(first, t_before)):
        f = _segment_offset(geom, c.x, c.y)[0]
        if not c.known or 0.0 <= f <= 1.0:
            continue
        if first <= c.t + GATE_OUTSIDE_S:
            break
        gate = course.feature(course.legs[i].to_name)
        ends = (gate.a, gate.b) if not isinstance(gate, Mark) else (gate, gate)
        mark = ends[0] if f < 0.5 else ends[1]
        off = math.hypot(c.x - mark.x, c.y - mark.y)
        note = f"passed outside the gate's marks, {off:.0f} m beyond {mark.name!r}"
        return [replace(c, note=note, issue=LegIssue.OUTSIDE), *found]
    return found
