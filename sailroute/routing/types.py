"""Data types shared by all routers and by the course/report layers.

A router takes a :class:`Start`, a :class:`Target`, a start time, a wind field,
a boat and :class:`~sailroute.routing.settings.RoutingSettings`, and returns a
:class:`LegResult` (the signature :class:`~sailroute.routing.api.Router`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final, Literal, get_args

import numpy as np
from numpy.typing import NDArray

from sailroute.errors import InputError

Side = Literal["port", "starboard"]
"""A tack (or a mark's rounding side) at every public boundary: settings, files, JSON,
the CLI.  Arrays hold :func:`side_sign` numbers instead."""
TargetKind = Literal["mark", "gate", "line"]
RouterName = Literal["isochrone", "griddp", "spline"]

SIDE_NAMES: Final[tuple[Side, ...]] = get_args(Side)
"""The valid :data:`Side` names, ``("port", "starboard")``."""
_SIGNS: Final[dict[str, int]] = {"starboard": 1, "port": -1}


def side_sign(name: Side | None) -> int:
    """Array code of a tack: +1 starboard, -1 port, 0 not chosen (``None``).

    Raises
    ------
    InputError
        For any other name (the message lists the valid ones).
    """
    if name is None:
        return 0
    sign = _SIGNS.get(name) if isinstance(name, str) else None
    if sign is None:
        raise InputError(f"side {name!r}: expected 'port' or 'starboard'")
    return sign


def side_name(sign: int | np.integer | float) -> Side:
    """Name of an array tack code: ``"starboard"`` for +1, ``"port"`` for -1.

    The inverse of :func:`side_sign` on ±1; any positive number counts as starboard and
    any negative one as port (e.g. a float array's entries).

    Raises
    ------
    ValueError
        For 0 (no tack chosen) or NaN: there is no name to give.
    """
    if sign > 0:
        return "starboard"
    if sign < 0:
        return "port"
    raise ValueError(f"side code {sign!r} has no name: expected +1 (starboard) or -1 (port)")


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


@dataclass(frozen=True, eq=False)
class RouteTrack:
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
        +1 starboard tack, -1 port tack (:func:`side_sign`, :func:`side_name`).
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
    track : RouteTrack
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
    track: RouteTrack
    router: str
    barrier: Barrier | None = None

    @property
    def time_s(self) -> float:
        """Leg time [s]."""
        return self.t_end - self.t_start
