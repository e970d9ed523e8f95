"""Leg starts and targets as geometry: crossing segments, rounding segments, line sampling.

Every target is reduced to one **directed segment** ``a``-``b`` with a unit
``normal``: the leg ends at the first instant the boat's track crosses the
segment while moving along ``normal`` (``d · normal > 0`` for a step ``d``).
Routers test each time step's straight move against it
(:func:`segment_crossing`) and interpolate the arrival time inside the step.

=========  ==================================================================
target     crossing segment
=========  ==================================================================
line       the line ``a``-``b``, crossed from the side of the leg start (the
           course side, RRS "finish") to the other side.
gate       the segment between the two marks, crossed from the side of the
           leg start.
mark       a **rounding segment**: from the mark, perpendicular to the
           *apex heading* h, ``zone_m`` long, on the side where the boat
           passes; crossed in the direction of h.  Leaving the mark to port
           (mark on the boat's left) means passing on its right as seen along
           h, so the segment points to the right of h, ``(cos h, −sin h)``;
           starboard mirrors it.  Without ``Target.exit_xy`` h is the leg
           bearing θ (start → mark): the mark is passed.  With it, h bisects
           the turn from θ to the bearing θ' of the next leg taken in the
           rounding sense (:func:`rounding_apex_deg`), so the segment lies on
           the outside of the turn and the leg ends once the mark is rounded
           (for a windward-leeward turn: on the far side of the mark).  A mark
           without a rounding side gets a segment of ``2 zone_m`` centred on
           the mark, perpendicular to θ (pass within ``zone_m`` on either
           side).  Passing on the wrong side crosses nothing and does not end
           the leg.
=========  ==================================================================

**Barriers** (:class:`~sailroute.routing.types.Barrier`, half-lines from a mark
that may not be crossed one way, :func:`barrier_blocks`) keep a rounding on the
required side where one crossing segment cannot:

* *entry* (:func:`entry_barrier`): on the way to a mark with a rounding side
  the boat may not cross the half-line from the mark perpendicular to θ on the
  wrong side, moving along θ: that is passing the mark on the wrong side.
  Without it, a rounding segment on the far side of a turn of more than 180°
  could be reached by passing the mark on the wrong side and turning back.
* *exit* (``Start.barrier``, :func:`chain_leg`): the next leg starts where this
  one ended, on the rounding segment, and may not cross the half-line from the
  mark along the segment backwards, which would unwind the rounding, nor pass
  within :data:`MARK_CLEARANCE_M` of the mark.

Together the legs then keep the mark on the required side (the "string" of
RRS 28, tested by its winding angle around the mark).

All functions are pure; the array kernels take the array module ``xp``
(NumPy by default; only operations CuPy also has) and never divide by zero.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from types import ModuleType

import numpy as np
from numpy.typing import NDArray

from sailroute.errors import InputError
from sailroute.numerics import clip
from sailroute.routing.types import Barrier, LegResult, Start, Target

XY = tuple[float, float]

DEFAULT_ZONE_M = 13.0
"""Default rounding-segment length [m]: about three Laser hull lengths (3 × 4.23 m)."""

AIM_MARGIN_M = 1.0
"""Routers aim at the target segment no closer than this to its ends [m] (a mark is
passed at 1 m, not touched)."""

MARK_CLEARANCE_M = 0.1
"""A leg that starts by finishing a rounding may not pass closer than this to the
mark [m] (at most half its start distance from the mark); it only removes routes
that run *through* the mark, whose side is undefined."""

BARRIER_SLACK_M = 1e-6
"""A barrier is tested this far behind its ray [m], so a start lying on the ray up to
round-off is always in front of it."""

BARRIER_LENGTH_M = 1e6
"""Length of the barrier half-line as a segment [m] (far beyond any course)."""


@dataclass(frozen=True)
class TargetGeometry:
    """A target reduced to a directed crossing segment.

    Attributes
    ----------
    a, b : tuple of float
        Segment ends ``(x, y)`` [m].  For a mark, ``a`` is the mark.
    normal : tuple of float
        Unit vector perpendicular to the segment: the leg ends when the boat
        crosses the segment moving along it.
    kind : {"mark", "gate", "line"}
        The target kind it was built from.
    name : str
        Label for messages.
    """

    a: XY
    b: XY
    normal: XY
    kind: str
    name: str = ""

    @property
    def centre(self) -> XY:
        """Midpoint of the segment [m]."""
        return ((self.a[0] + self.b[0]) / 2.0, (self.a[1] + self.b[1]) / 2.0)

    @property
    def length_m(self) -> float:
        """Segment length [m]."""
        return math.hypot(self.b[0] - self.a[0], self.b[1] - self.a[1])


def start_centre(start: Start) -> XY:
    """Start point, or the midpoint of a start line [m]."""
    if start.b is None:
        return (float(start.a[0]), float(start.a[1]))
    return ((start.a[0] + start.b[0]) / 2.0, (start.a[1] + start.b[1]) / 2.0)


def leg_label(start: Start, target: Target) -> str:
    """``"start -> 1"``-style label used in messages."""
    return f"{start.name or 'start'} -> {target.name or target.kind}"


def leg_bearing_deg(start: Start, target: Target) -> float:
    """Compass bearing [°] from the start (centre) to the target (centre).

    Raises
    ------
    InputError
        If the two coincide (the leg has no direction).
    """
    sx, sy = start_centre(start)
    tx, ty = target.centre
    dx, dy = tx - sx, ty - sy
    if math.hypot(dx, dy) < 1e-6:
        raise InputError(
            f"leg {leg_label(start, target)}: the start and the target are at the same "
            f"point ({sx:.1f}, {sy:.1f}) m; a leg needs two different places"
        )
    return math.degrees(math.atan2(dx, dy)) % 360.0


def rounding_apex_deg(bearing_in_deg: float, bearing_out_deg: float, rounding: str) -> float:
    """Heading [°] of a boat at the apex of a mark rounding.

    Parameters
    ----------
    bearing_in_deg : float
        Bearing θ of the leg to the mark [°].
    bearing_out_deg : float
        Bearing θ' from the mark to the next target [°].
    rounding : {"port", "starboard"}
        Side the mark is left on: the boat turns left (port) or right
        (starboard) around it.

    Returns
    -------
    float
        ``θ − φ/2`` (port) or ``θ + φ/2`` (starboard), in [0, 360), with ``φ``
        the turn from θ to θ' in the rounding sense, in [0, 360): a port
        rounding followed by a right turn of 90° is a left turn of 270°.
        ``φ = 0`` (going straight on) gives θ.
    """
    if rounding == "port":
        phi = (bearing_in_deg - bearing_out_deg) % 360.0
        return (bearing_in_deg - 0.5 * phi) % 360.0
    if rounding == "starboard":
        phi = (bearing_out_deg - bearing_in_deg) % 360.0
        return (bearing_in_deg + 0.5 * phi) % 360.0
    raise InputError(f"mark rounding {rounding!r}: expected 'port' or 'starboard'")


def rounding_segment(
    mark: XY, bearing_deg: float, rounding: str | None, zone_m: float = DEFAULT_ZONE_M
) -> tuple[XY, XY]:
    """Rounding segment of a mark approached along ``bearing_deg``.

    Parameters
    ----------
    mark : tuple of float
        Mark position [m].
    bearing_deg : float
        Heading h of the boat crossing the segment [°]: the leg bearing θ, or
        the apex heading of :func:`rounding_apex_deg`.
    rounding : {"port", "starboard"} or None
        Side on which the mark is left.  ``None``: either side.
    zone_m : float
        Segment length [m].

    Returns
    -------
    a, b : tuple of float
        Segment ends [m]; ``a`` is the mark (or, for ``None``, the end at
        ``mark − zone_m r`` where ``r`` points to the right of θ).
    """
    th = math.radians(bearing_deg)
    rx, ry = math.cos(th), -math.sin(th)  # unit vector to the right of the approach
    mx, my = float(mark[0]), float(mark[1])
    if rounding == "port":
        return (mx, my), (mx + zone_m * rx, my + zone_m * ry)
    if rounding == "starboard":
        return (mx, my), (mx - zone_m * rx, my - zone_m * ry)
    if rounding is None:
        return (mx - zone_m * rx, my - zone_m * ry), (mx + zone_m * rx, my + zone_m * ry)
    raise InputError(f"mark rounding {rounding!r}: expected 'port', 'starboard' or None")


def target_geometry(target: Target, start: Start, zone_m: float = DEFAULT_ZONE_M) -> TargetGeometry:
    """The directed crossing segment of ``target`` for a leg from ``start``.

    Parameters
    ----------
    target : Target
        Mark (with rounding side), gate or line.
    start : Start
        Leg start (point or line); its centre fixes the leg bearing and the
        course side.
    zone_m : float
        Rounding-segment length for marks [m].

    Returns
    -------
    TargetGeometry

    Raises
    ------
    InputError
        For a zero-length gate/line, a non-positive ``zone_m``, a start lying on
        the line through a gate/line, a start at the mark, or a mark whose
        ``exit_xy`` is the mark itself.
    """
    label = leg_label(start, target)
    if target.kind == "mark":
        if not zone_m > 0:
            raise InputError(f"leg {label}: zone_m must be > 0 m, got {zone_m!r}")
        th = leg_bearing_deg(start, target)
        if target.exit_xy is not None and target.rounding is not None:
            ox = float(target.exit_xy[0]) - float(target.a[0])
            oy = float(target.exit_xy[1]) - float(target.a[1])
            if math.hypot(ox, oy) < 1e-6:
                raise InputError(
                    f"leg {label}: the next leg's target (exit_xy) is at the mark "
                    f"({target.a[0]:.1f}, {target.a[1]:.1f}) m, so the rounding has no "
                    "direction; give the next target's centre, or exit_xy=None"
                )
            th = rounding_apex_deg(th, math.degrees(math.atan2(ox, oy)) % 360.0, target.rounding)
        a, b = rounding_segment(target.a, th, target.rounding, zone_m)
        n = (math.sin(math.radians(th)), math.cos(math.radians(th)))
        return TargetGeometry(a, b, n, "mark", target.name)
    if target.kind not in ("gate", "line") or target.b is None:
        raise InputError(
            f"leg {label}: target kind {target.kind!r} needs two ends (gate or line) "
            "or must be 'mark'"
        )
    a = (float(target.a[0]), float(target.a[1]))
    b = (float(target.b[0]), float(target.b[1]))
    ex, ey = b[0] - a[0], b[1] - a[1]
    length = math.hypot(ex, ey)
    if length < 1e-6:
        raise InputError(f"leg {label}: the {target.kind} ends coincide; give two different ends")
    nx, ny = ey / length, -ex / length
    sx, sy = start_centre(start)
    side = (sx - a[0]) * nx + (sy - a[1]) * ny
    if abs(side) < 1e-6:
        raise InputError(
            f"leg {label}: the leg start ({sx:.1f}, {sy:.1f}) m lies on the line through the "
            f"{target.kind}, so the side it must be crossed from is undefined; move the start "
            "off that line"
        )
    if side > 0:
        nx, ny = -nx, -ny
    return TargetGeometry(a, b, (nx, ny), target.kind, target.name)


def segment_crossing(
    px: NDArray,
    py: NDArray,
    qx: NDArray,
    qy: NDArray,
    geom: TargetGeometry,
    *,
    xp: ModuleType = np,
) -> tuple[NDArray, NDArray, NDArray]:
    """Which straight moves ``P → Q`` cross the target segment forwards, and where.

    Parameters
    ----------
    px, py, qx, qy : ndarray
        Move starts and ends [m] (broadcast).
    geom : TargetGeometry
        The directed target segment.
    xp : module
        Array module.

    Returns
    -------
    hit : ndarray of bool
        The move crosses the segment (ends included) moving along ``normal``.
    s : ndarray
        Fraction of the move at the crossing, in ``[0, 1]`` (0 where not hit).
    r : ndarray
        Fraction along ``a → b`` of the crossing point, in ``[0, 1]`` (0 where not hit).

    Notes
    -----
    Solves ``P + s d = A + r e`` with ``d = Q − P``, ``e = B − A``:
    ``s = (w × e)/(d × e)``, ``r = (w × d)/(d × e)``, ``w = A − P``.  The range
    tests use the numerators times ``sign(d × e)``, so nothing is divided by 0.
    """
    ax, ay = geom.a
    ex, ey = geom.b[0] - ax, geom.b[1] - ay
    nx, ny = geom.normal
    dx = qx - px
    dy = qy - py
    wx = ax - px
    wy = ay - py
    den = dx * ey - dy * ex
    sgn = xp.where(den < 0, -1.0, 1.0)
    ns = (wx * ey - wy * ex) * sgn
    nr = (wx * dy - wy * dx) * sgn
    ad = den * sgn
    hit = (dx * nx + dy * ny > 0) & (ad > 0) & (ns >= 0) & (ns <= ad) & (nr >= 0) & (nr <= ad)
    safe = xp.where(hit, ad, 1.0)
    s = xp.where(hit, ns / safe, 0.0)
    r = xp.where(hit, nr / safe, 0.0)
    return hit, s, r


def aim_points(
    px: NDArray,
    py: NDArray,
    geom: TargetGeometry,
    margin_m: float = AIM_MARGIN_M,
    *,
    xp: ModuleType = np,
) -> tuple[NDArray, NDArray]:
    """Nearest point of the target segment, kept ``margin_m`` from its ends [m].

    Routers steer the "direct" candidate heading at this point: the projection
    of ``P`` onto the segment, clipped to ``[m, L − m]`` from ``a`` with
    ``m = min(margin_m, L/2)``.
    """
    ax, ay, ux, uy, m, length = segment_frame(geom, margin_m)
    r = clip((px - ax) * ux + (py - ay) * uy, m, length - m, xp=xp)
    return ax + r * ux, ay + r * uy


def segment_frame(
    geom: TargetGeometry, margin_m: float = AIM_MARGIN_M
) -> tuple[float, float, float, float, float, float]:
    """``(ax, ay, ux, uy, m, length)`` of the target segment: its end ``a`` [m], the unit
    vector from ``a`` to ``b``, the margin ``m = min(margin_m, L/2)`` kept from its ends
    and its length ``L`` [m] (:func:`aim_points`, the isochrone's fastest aim points)."""
    ax, ay = geom.a
    length = geom.length_m
    ux, uy = (geom.b[0] - ax) / length, (geom.b[1] - ay) / length
    return ax, ay, ux, uy, min(margin_m, 0.5 * length), length


def sample_line(
    a: XY, b: XY, spacing_m: float, max_points: int = 401
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Evenly spaced points on the segment ``a``-``b``, both ends included.

    Parameters
    ----------
    a, b : tuple of float
        Ends [m].
    spacing_m : float
        Largest spacing [m] (> 0).
    max_points : int
        Upper bound on the number of points (the spacing grows if needed).

    Returns
    -------
    x, y : ndarray
        Point coordinates [m], from ``a`` to ``b``.
    """
    if not spacing_m > 0:
        raise InputError(f"line spacing must be > 0 m, got {spacing_m!r}")
    length = math.hypot(b[0] - a[0], b[1] - a[1])
    n = int(min(max(2, math.ceil(length / spacing_m - 1e-9) + 1), max(2, max_points)))
    f = np.linspace(0.0, 1.0, n)
    return a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])


def start_points(
    start: Start, spacing_m: float = 5.0, max_points: int = 401
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Initial positions of a leg: the start point, or points along the start line [m]."""
    if start.b is None:
        return np.array([float(start.a[0])]), np.array([float(start.a[1])])
    return sample_line(start.a, start.b, spacing_m, max_points)


# --------------------------------------------------------------------------------------
# roundings across legs


def target_barrier(target: Target, start: Start, zone_m: float = DEFAULT_ZONE_M) -> Barrier | None:
    """The barrier a leg to ``target`` leaves for the next leg (None unless a mark
    with a rounding side): the ray from the mark along its rounding segment."""
    if target.kind != "mark" or target.rounding is None:
        return None
    g = target_geometry(target, start, zone_m)
    ex, ey = g.b[0] - g.a[0], g.b[1] - g.a[1]
    n = math.hypot(ex, ey)
    return Barrier(g.a, (ex / n, ey / n), g.normal, target.name)


def entry_barrier(target: Target, start: Start) -> Barrier | None:
    """The barrier on the way to a mark with a rounding side (None otherwise).

    The half-line from the mark perpendicular to the leg bearing θ on the side
    the mark must *not* be passed on (left of θ for a port rounding), which the
    boat may not cross moving along θ.
    """
    if target.kind != "mark" or target.rounding is None:
        return None
    th = math.radians(leg_bearing_deg(start, target))
    dx, dy = math.sin(th), math.cos(th)
    rx, ry = math.cos(th), -math.sin(th)  # right of the approach
    wrong = (-rx, -ry) if target.rounding == "port" else (rx, ry)
    mark = (float(target.a[0]), float(target.a[1]))
    return Barrier(mark, wrong, (-dx, -dy), target.name)


def leg_barriers(start: Start, target: Target) -> tuple[tuple[Barrier, float], ...]:
    """Every barrier of a leg with its mark clearance [m]: the start's (the previous
    rounding, :func:`barrier_clearance`) and the target's entry barrier (clearance 0)."""
    out = []
    if start.barrier is not None:
        out.append((start.barrier, barrier_clearance(start)))
    entry = entry_barrier(target, start)
    if entry is not None:
        out.append((entry, 0.0))
    return tuple(out)


def barrier_clearance(start: Start) -> float:
    """Clearance kept from the barrier's mark [m]: :data:`MARK_CLEARANCE_M`, at most
    half the distance of the start from the mark (so the start is never inside it);
    0 without a barrier."""
    if start.barrier is None:
        return 0.0
    sx, sy = start_centre(start)
    d = math.hypot(sx - start.barrier.mark[0], sy - start.barrier.mark[1])
    return min(MARK_CLEARANCE_M, 0.5 * d)


def barrier_blocks(
    px: NDArray,
    py: NDArray,
    qx: NDArray,
    qy: NDArray,
    barrier: Barrier,
    clearance_m: float | NDArray = 0.0,
    *,
    xp: ModuleType = np,
) -> NDArray:
    """Which straight moves ``P → Q`` a barrier forbids.

    Parameters
    ----------
    px, py, qx, qy : ndarray
        Move starts and ends [m] (broadcast).
    barrier : Barrier
        Ray of the mark just rounded.
    clearance_m : float or ndarray
        Moves passing closer than this to the mark are forbidden too [m]
        (:func:`barrier_clearance`); an array broadcasts with the moves.
    xp : module
        Array module.

    Returns
    -------
    ndarray of bool
        True where the move crosses the ray against ``barrier.normal`` (tested
        :data:`BARRIER_SLACK_M` behind the ray, ends inclusive) or passes within
        ``clearance_m`` of the mark.
    """
    mx, my = barrier.mark
    blocked, _, _ = segment_crossing(px, py, qx, qy, barrier_segment(barrier), xp=xp)
    if isinstance(clearance_m, np.ndarray) or clearance_m > 0:  # an array: one per move
        dx, dy = qx - px, qy - py
        wx, wy = mx - px, my - py
        dd = dx * dx + dy * dy
        f = clip((wx * dx + wy * dy) / xp.where(dd > 0, dd, 1.0), 0.0, 1.0, xp=xp)
        cx, cy = wx - f * dx, wy - f * dy
        blocked = blocked | (cx * cx + cy * cy < clearance_m * clearance_m)
    return blocked


def barrier_segment(barrier: Barrier) -> TargetGeometry:
    """The segment :func:`barrier_blocks` tests a move against: the barrier's ray,
    :data:`BARRIER_SLACK_M` behind it and :data:`BARRIER_LENGTH_M` long, crossed against
    its normal."""
    mx, my = barrier.mark
    rx, ry = barrier.ray
    nx, ny = barrier.normal
    ax, ay = mx - BARRIER_SLACK_M * nx, my - BARRIER_SLACK_M * ny
    return TargetGeometry(
        (ax, ay),
        (ax + BARRIER_LENGTH_M * rx, ay + BARRIER_LENGTH_M * ry),
        (-nx, -ny),
        "barrier",
        barrier.name,
    )


def chain_leg(
    start: Start,
    target: Target,
    previous: LegResult | None = None,
    following: Target | None = None,
) -> tuple[Start, Target]:
    """Link a leg to its neighbours so that mark roundings hold across legs.

    Parameters
    ----------
    start, target : Start, Target
        The leg as the course describes it.
    previous : LegResult, optional
        The routed previous leg: this leg starts at its ``end_xy`` and carries
        its ``barrier`` (if it ended at a mark with a rounding side).
    following : Target, optional
        The next leg's target: a mark with a rounding side gets
        ``exit_xy = following.centre``, so the leg ends once it is rounded.

    Returns
    -------
    (Start, Target)
    """
    if previous is not None:
        ex, ey = previous.end_xy
        start = Start((float(ex), float(ey)), None, start.name, previous.barrier)
    if following is not None and target.kind == "mark" and target.rounding is not None:
        target = replace(target, exit_xy=following.centre)
    return start, target
