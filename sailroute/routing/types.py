"""Data types shared by all routers and by the course/report layers.

A router takes a :class:`Start`, a :class:`Target`, a start time, a wind field,
a boat and :class:`RoutingSettings`, and returns a :class:`LegResult`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

Side = Literal["port", "starboard"]
TargetKind = Literal["mark", "gate", "line"]
RouterName = Literal["isochrone", "griddp", "spline"]


@dataclass(frozen=True)
class Barrier:
    """A half-line from a rounded mark that the next leg may not cross backwards.

    A leg to a mark with a rounding side ends on the mark's rounding segment,
    crossed along ``normal``; the next leg starts there.  Crossing the ray
    ``mark + s ray`` (``s >= 0``) against ``normal`` would unwind the rounding
    (the boat would pass the mark on the wrong side), so routers forbid it, and
    they keep moves a small clearance away from the mark itself.

    Attributes
    ----------
    mark : tuple of float
        The mark ``(x, y)`` [m].
    ray : tuple of float
        Unit vector from the mark along the rounding segment.
    normal : tuple of float
        Unit vector of the direction in which the rounding segment was crossed.
    name : str
        The mark's label, for messages.
    """

    mark: tuple[float, float]
    ray: tuple[float, float]
    normal: tuple[float, float]
    name: str = ""


@dataclass(frozen=True)
class Start:
    """Where a leg starts: a point, or anywhere on a line segment.

    Attributes
    ----------
    a : tuple of float
        Point, or first end of the line ``(x, y)`` [m].
    b : tuple of float or None
        Second end of the line [m]; ``None`` for a point start.
    name : str
        Label for reports (e.g. ``"start"``, ``"1"``).
    barrier : Barrier or None
        The rounding ray of the mark the previous leg ended at
        (``LegResult.barrier``): this leg may not cross it backwards, so the
        mark stays on the side it is rounded on.  None: no constraint.
    """

    a: tuple[float, float]
    b: tuple[float, float] | None = None
    name: str = ""
    barrier: Barrier | None = None

    @property
    def is_line(self) -> bool:
        """True if the start is a line segment."""
        return self.b is not None


@dataclass(frozen=True)
class Target:
    """What ends a leg.

    Attributes
    ----------
    kind : {"mark", "gate", "line"}
        ``mark``: round the mark at ``a`` leaving it to ``rounding``;
        ``gate``: pass between the marks ``a`` and ``b``;
        ``line``: cross the line ``a``-``b`` (finish).
    a, b : tuple of float
        Mark position(s) ``(x, y)`` [m]; ``b`` is None for a mark.
    rounding : {"port", "starboard"} or None
        Side on which the mark is left (marks only).
    name : str
        Label for reports.
    exit_xy : tuple of float or None
        Where the course goes after a mark with a rounding side: the next leg's
        target centre ``(x, y)`` [m].  The leg then ends once the mark is rounded
        (the rounding segment lies on the outside of the turn, see
        ``routing/geometry.py``); None: the mark is passed, as for a course that
        goes straight on.
    """

    kind: TargetKind
    a: tuple[float, float]
    b: tuple[float, float] | None = None
    rounding: Side | None = None
    name: str = ""
    exit_xy: tuple[float, float] | None = None

    @property
    def centre(self) -> tuple[float, float]:
        """Mark position, or midpoint of a gate/line [m]."""
        if self.b is None:
            return self.a
        return ((self.a[0] + self.b[0]) / 2.0, (self.a[1] + self.b[1]) / 2.0)


@dataclass(frozen=True)
class RoutingSettings:
    """Numerical and rule settings of a leg route.

    Attributes
    ----------
    router : {"isochrone", "griddp", "spline"}
        Which router to use.
    dt_s : float
        Isochrone time step [s] (default 10 s: with mid-step wind sampling, halving
        it down to 1.25 s moved a 1809 m beat by < 2e-5; see docs/design/routing.md).
    heading_step_deg : float
        Heading resolution [°].
    tack_penalty_s, gybe_penalty_s : float
        Time lost per tack / gybe [s], independent of the time step.
    initial_side : {"port", "starboard"} or None
        Tack at the start of a leg; None lets the router choose freely.
    clamp_wind : bool
        Unused by routers (wind fields carry their own clamp flag); kept for reports.
    zone_m : float
        Length of a mark's rounding segment [m] (see ``routing/geometry.py``):
        the leg ends when the boat crosses it, so it is how close a rounding
        must pass.  Default 13 m, about three Laser hull lengths.
    start_line_spacing_m : float
        Spacing of the candidate start points along a start line [m].
    max_leg_time_s : float
        A leg not finished after this much race time [s] fails with
        :class:`~sailroute.errors.RoutingError`.
    min_dt_s : float
        Isochrone: smallest time step of the refinement near the target [s]
        (steps shrink from ``dt_s`` once the target is a few steps away).
    prune_sector_deg : float
        Isochrone: width of the pruning sectors, in bearing seen from the
        target [°]; one point per sector and tack side survives each step.
    max_front_points : int
        Isochrone: cap on the points kept per step (sectors widen to respect it).
    heading_fan : {"hull", "full"}
        Isochrone: ``"hull"`` tries grid TWAs between the upwind and downwind
        VMG angles only (the rest of the polar is never optimal without a
        tack penalty; the exact VMG angles and the direct bearing to the
        target are always tried); ``"full"`` tries the whole circle.
    dp_rows : int
        Grid DP / multi-spline: rows of nodes including the start and target
        rows (Dębski: 10-16).
    dp_cols : int
        Grid DP: nodes per row, C (Dębski: up to 128).
    dp_refinements : int
        Grid DP: mesh refinements after the first pass (each centred on the
        best route so far, band scaled by ``dp_shrink``).
    dp_half_width_m : float or None
        Grid DP / multi-spline: half-width of the node rows [m]; None derives it
        from the one-tack laylines (see ``docs/design/griddp.md``).
    dp_shrink : float
        Grid DP: band scale factor per refinement (0.5 halves the node spacing).
    dp_samples : int
        Grid DP: pieces per segment along which the wind is sampled.
    spline_cols, spline_slopes, spline_refinements : int
        Multi-spline: nodes per row, tangent slopes per node (n_ts) and
        refinements (ranges shrink by 1/3 each).
    spline_carry_speed : bool
        Multi-spline, dynamic boat: enter each edge at the end speed of the best
        previous edge (the DP carries it, as Dębski's) instead of the steady
        speed of the node's tangent.  No effect with a polar.
    spline_start_from_rest : bool
        Multi-spline, dynamic boat: the first edge starts from rest instead of
        at the steady speed (a flying start).  No effect with a polar.
    """

    router: RouterName = "isochrone"
    dt_s: float = 10.0
    heading_step_deg: float = 2.0
    tack_penalty_s: float = 5.0
    gybe_penalty_s: float = 3.0
    initial_side: Side | None = None
    extra: dict[str, float] = field(default_factory=dict)
    zone_m: float = 13.0
    start_line_spacing_m: float = 5.0
    max_leg_time_s: float = 10800.0
    min_dt_s: float = 1.0
    prune_sector_deg: float = 1.0
    max_front_points: int = 2000
    heading_fan: str = "hull"
    dp_rows: int = 13
    dp_cols: int = 64
    dp_refinements: int = 2
    dp_half_width_m: float | None = None
    dp_shrink: float = 0.5
    dp_samples: int = 4
    spline_cols: int = 25
    spline_slopes: int = 7
    spline_refinements: int = 3
    spline_carry_speed: bool = False
    spline_start_from_rest: bool = False


@dataclass(frozen=True, eq=False)
class Track:
    """A routed track, one row per point.

    Attributes
    ----------
    t : ndarray
        Time [epoch s].
    x, y : ndarray
        Position in the local frame [m].
    heading_deg : ndarray
        Heading sailed from this point [° compass].
    tws_ms, twd_deg : ndarray
        True wind speed [m s⁻¹] and FROM-direction [°] at the point.
    twa_deg : ndarray
        Signed true wind angle [°] (positive: starboard tack).
    bsp_ms : ndarray
        Boat speed through the water [m s⁻¹].
    side : ndarray of int
        +1 starboard tack, -1 port tack.
    sog_ms, cog_deg : ndarray or None
        Speed [m s⁻¹] and course [° compass] over the ground, where a surface current
        was routed (``heading_deg``/``bsp_ms`` are then through the water and
        ``tws``/``twd``/``twa`` relative to the water); None in still water, where they
        equal ``bsp_ms``/``heading_deg`` (:attr:`ground_speed_ms`, :attr:`ground_course_deg`).
    """

    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    heading_deg: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    twd_deg: NDArray[np.float64]
    twa_deg: NDArray[np.float64]
    bsp_ms: NDArray[np.float64]
    side: NDArray[np.int8]
    sog_ms: NDArray[np.float64] | None = None
    cog_deg: NDArray[np.float64] | None = None

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def ground_speed_ms(self) -> NDArray[np.float64]:
        """Speed over the ground [m s⁻¹] (boat speed in still water)."""
        return self.bsp_ms if self.sog_ms is None else self.sog_ms

    @property
    def ground_course_deg(self) -> NDArray[np.float64]:
        """Course over the ground [°] (the heading in still water)."""
        return self.heading_deg if self.cog_deg is None else self.cog_deg

    @property
    def distance_m(self) -> float:
        """Length of the polyline [m]."""
        return float(np.sum(np.hypot(np.diff(self.x), np.diff(self.y))))


@dataclass(frozen=True)
class Manoeuvre:
    """A tack or gybe on the route."""

    kind: Literal["tack", "gybe"]
    t: float
    x: float
    y: float


@dataclass(frozen=True, eq=False)
class LegResult:
    """Result of routing one leg.

    Attributes
    ----------
    t_start, t_end : float
        Start and arrival times [epoch s].
    start_xy, end_xy : tuple of float
        Start point (best point on a start line) and arrival point [m].
    distance_m : float
        Distance sailed [m].
    n_tacks, n_gybes : int
        Manoeuvre counts.
    manoeuvres : tuple of Manoeuvre
        Where and when each happened.
    track : Track
        The route, first row at ``t_start``, last at ``t_end``.
    router : str
        Router that produced it.
    barrier : Barrier or None
        For a leg that ended at a mark with a rounding side: the rounding ray
        the next leg must not cross back (give it to the next leg's
        :class:`Start`, e.g. with :func:`~sailroute.routing.geometry.chain_leg`).
    """

    t_start: float
    t_end: float
    start_xy: tuple[float, float]
    end_xy: tuple[float, float]
    distance_m: float
    n_tacks: int
    n_gybes: int
    manoeuvres: tuple[Manoeuvre, ...]
    track: Track
    router: str
    barrier: Barrier | None = None

    @property
    def time_s(self) -> float:
        """Leg time [s]."""
        return self.t_end - self.t_start
