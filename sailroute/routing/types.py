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
    """

    a: tuple[float, float]
    b: tuple[float, float] | None = None
    name: str = ""

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
    """

    kind: TargetKind
    a: tuple[float, float]
    b: tuple[float, float] | None = None
    rounding: Side | None = None
    name: str = ""

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
        Isochrone time step [s].
    heading_step_deg : float
        Heading resolution [°].
    tack_penalty_s, gybe_penalty_s : float
        Time lost per tack / gybe [s], independent of the time step.
    initial_side : {"port", "starboard"} or None
        Tack at the start of a leg; None lets the router choose freely.
    clamp_wind : bool
        Unused by routers (wind fields carry their own clamp flag); kept for reports.
    """

    router: RouterName = "isochrone"
    dt_s: float = 5.0
    heading_step_deg: float = 2.0
    tack_penalty_s: float = 5.0
    gybe_penalty_s: float = 3.0
    initial_side: Side | None = None
    extra: dict[str, float] = field(default_factory=dict)


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

    def __len__(self) -> int:
        return int(self.t.size)

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

    @property
    def time_s(self) -> float:
        """Leg time [s]."""
        return self.t_end - self.t_start
