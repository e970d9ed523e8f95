"""Shared machinery of the grid-DP and multi-spline routers.

* :class:`LegFrame`: the leg's along/across coordinates (A = start centre,
  axis towards the target centre B).
* :class:`Row`: one layer of grid nodes, parametrised by one number per node
  (across offset [m] for free rows, fraction along a line for start/target
  rows), so that mesh refinement only changes the parameters.
* :class:`GridBoat`: a :class:`~sailroute.boat.model.BoatModel` (a
  :class:`~sailroute.boat.polar.Polar` or a :class:`~sailroute.boat.dynamic.DynamicBoat`)
  with its steady polar and its momentum model looked up once.
* :func:`sample_chains`: wind along chains of straight pieces (segments split
  into pieces, or spline chords), sampled at the time the boat is there.
* :func:`default_half_width`: the grid half-width from the laylines.
* :class:`PathLimits`: the rounding constraints on straight pieces (arrive
  across the target segment along its normal; respect the leg's barriers).

See ``docs/design/griddp.md``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.dynamic import DynamicBoat
from sailroute.boat.model import BoatModel
from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.routing.geometry import (
    AIM_MARGIN_M,
    TargetGeometry,
    barrier_blocks,
    leg_barriers,
    leg_label,
    start_centre,
    target_geometry,
)
from sailroute.routing.obstacles import Obstacles
from sailroute.routing.types import Barrier, Start, Target
from sailroute.units import wind_speed_direction, wrap180
from sailroute.wind.base import WindField

LAYLINE_TOLERANCE = 1.15
"""Half-width safety factor on the one-tack layline excursion (Dębski's thesis value)."""
MIN_HALF_WIDTH_FRACTION = 0.25
"""The default half-width is at least this fraction of the leg length."""


# --------------------------------------------------------------------------------------
# frame and rows


@dataclass(frozen=True)
class LegFrame:
    """Along/across coordinates of a leg.

    Attributes
    ----------
    ox, oy : float
        Origin A (start point or start-line centre) [m].
    ex, ey : float
        Unit vector from A towards the target centre B.
    length : float
        |AB| [m].
    """

    ox: float
    oy: float
    ex: float
    ey: float
    length: float

    @property
    def bearing_deg(self) -> float:
        """Compass bearing of the axis [°]."""
        return math.degrees(math.atan2(self.ex, self.ey)) % 360.0

    def point(self, along: Any, across: Any) -> tuple[Any, Any]:
        """Local ``(x, y)`` [m] of along/across coordinates [m] (across: positive to the left)."""
        return (
            self.ox + along * self.ex - across * self.ey,
            self.oy + along * self.ey + across * self.ex,
        )

    def coords(self, x: Any, y: Any) -> tuple[Any, Any]:
        """Along/across coordinates [m] of local points."""
        dx, dy = x - self.ox, y - self.oy
        return dx * self.ex + dy * self.ey, -dx * self.ey + dy * self.ex


@dataclass(frozen=True)
class Row:
    """One layer of nodes.

    Attributes
    ----------
    kind : {"free", "line", "point"}
        ``free``: nodes across the leg at ``along`` (parameter = across offset
        [m]); ``line``: nodes on the segment ``a``-``b`` (parameter = fraction
        in ``[lo, hi]``); ``point``: one fixed node ``a``.
    along : float
        Along-leg position of a free row [m].
    a, b : tuple of float
        Ends of a line row, or the point [m].
    lo, hi : float
        Allowed parameter range of a line row.
    """

    kind: str
    along: float = 0.0
    a: tuple[float, float] = (0.0, 0.0)
    b: tuple[float, float] = (0.0, 0.0)
    lo: float = 0.0
    hi: float = 1.0

    def points(self, frame: LegFrame, p: NDArray) -> tuple[NDArray, NDArray]:
        """Node positions ``(x, y)`` [m] for parameters ``p``."""
        p = np.asarray(p, dtype=float)
        if self.kind == "free":
            return frame.point(self.along, p)
        if self.kind == "line":
            return (
                self.a[0] + p * (self.b[0] - self.a[0]),
                self.a[1] + p * (self.b[1] - self.a[1]),
            )
        return np.full(p.shape, self.a[0]), np.full(p.shape, self.a[1])

    def initial(self, n: int, half_width: float) -> NDArray:
        """Parameters of the first pass: ``n`` nodes over the full range.

        Free rows: spacing ``2 H / (n - 1)`` with node ``n // 2`` on the leg axis
        (so the direct course is always on the grid; for even ``n`` the band is
        ``[-H - Δ/2, H - Δ/2]``).  Line rows: ``n`` nodes from end to end.
        """
        if self.kind == "free":
            return (np.arange(n) - n // 2) * (2.0 * half_width / max(n - 1, 1))
        if self.kind == "line":
            return np.linspace(self.lo, self.hi, n)
        return np.zeros(1)

    def refined(self, n: int, centre: float, scale: float, half_width: float) -> NDArray:
        """Parameters of a refinement pass centred on the incumbent's ``centre``.

        The node ``n // 2`` sits exactly on the incumbent, so the incumbent path
        stays representable (refinement never gets worse).  ``scale`` is the
        band's size relative to the first pass.
        """
        j = np.arange(n) - n // 2
        if self.kind == "free":
            return centre + j * (2.0 * half_width * scale / (n - 1))
        if self.kind == "line":
            return np.clip(centre + j * ((self.hi - self.lo) * scale / (n - 1)), self.lo, self.hi)
        return np.zeros(1)


@dataclass(frozen=True)
class PathLimits:
    """Rounding constraints on the straight pieces of a grid route.

    Attributes
    ----------
    normal : tuple of float
        Crossing direction of the target segment: the last piece must move
        along it (``d · normal > 0``), as the isochrone router's crossing test
        requires.
    barriers : tuple of (Barrier, float)
        The leg's barriers with their mark clearances [m]
        (:func:`~sailroute.routing.geometry.leg_barriers`): the target's entry
        barrier and the previous leg's rounding ray (``Start.barrier``).
    obstacles : Obstacles or None
        The race area: a piece must stay in free water
        (:meth:`~sailroute.routing.obstacles.Obstacles.segments_free`), so nodes inside
        an obstacle or outside the boundary are never reached.
    """

    normal: tuple[float, float]
    barriers: tuple[tuple[Barrier, float], ...] = ()
    obstacles: Obstacles | None = None

    def allowed(self, x0: NDArray, y0: NDArray, x1: NDArray, y1: NDArray, last: bool) -> NDArray:
        """Straight moves ``(x0, y0) → (x1, y1)`` (broadcast) that respect the limits;
        ``last``: the moves end on the target segment."""
        ok = np.ones(np.broadcast_shapes(np.shape(x0), np.shape(x1)), dtype=bool)
        if last:
            ok &= (x1 - x0) * self.normal[0] + (y1 - y0) * self.normal[1] > 0
        for bar, clear in self.barriers:
            ok &= ~barrier_blocks(x0, y0, x1, y1, bar, clear)
        if self.obstacles is not None:
            ok &= self.obstacles.segments_free(x0, y0, x1, y1)
        return ok


@dataclass(frozen=True, eq=False)
class LegGrid:
    """Frame, rows, target geometry and path limits of one leg."""

    frame: LegFrame
    rows: tuple[Row, ...]
    geom: TargetGeometry
    label: str
    limits: PathLimits


def make_grid(start: Start, target: Target, n_rows: int, zone_m: float) -> LegGrid:
    """Rows of a leg: start (point or line), ``n_rows - 2`` free rows, target segment.

    The target row lies on the target's crossing segment
    (:func:`~sailroute.routing.geometry.target_geometry`): the gate or finish
    line, or a mark's rounding segment on the correct side, its nodes kept
    :data:`~sailroute.routing.geometry.AIM_MARGIN_M` from the segment ends.
    ``LegGrid.limits`` holds the crossing direction and the leg's barriers.
    """
    label = leg_label(start, target)
    geom = target_geometry(target, start, zone_m)
    ax, ay = start_centre(start)
    bx, by = target.centre
    length = math.hypot(bx - ax, by - ay)
    frame = LegFrame(ax, ay, (bx - ax) / length, (by - ay) / length, length)
    if start.b is None:
        first = Row("point", a=(float(start.a[0]), float(start.a[1])))
    else:
        first = Row(
            "line",
            a=(float(start.a[0]), float(start.a[1])),
            b=(float(start.b[0]), float(start.b[1])),
        )
    seg_len = math.hypot(geom.b[0] - geom.a[0], geom.b[1] - geom.a[1])
    m = min(AIM_MARGIN_M, 0.5 * seg_len) / seg_len
    last = Row("line", a=geom.a, b=geom.b, lo=m, hi=1.0 - m)
    free = tuple(Row("free", along=length * r / (n_rows - 1)) for r in range(1, n_rows - 1))
    limits = PathLimits(geom.normal, leg_barriers(start, target))
    return LegGrid(frame, (first, *free, last), geom, label, limits)


# --------------------------------------------------------------------------------------
# boat models


@dataclass(frozen=True, eq=False)
class GridBoat:
    """A :class:`~sailroute.boat.model.BoatModel` as the grid routers use it.

    Attributes
    ----------
    boat : BoatModel
        The boat.
    polar : Polar or None
        ``boat.routing_polar()``: the steady polar, None for the dynamic model.
    dynamic : DynamicBoat or None
        ``boat.dynamics()``: the momentum model, None for a polar.
    """

    boat: BoatModel
    polar: Polar | None = None
    dynamic: DynamicBoat | None = None

    @classmethod
    def of(cls, boat: BoatModel, label: str) -> GridBoat:
        """Wrap ``boat``; raises :class:`InputError` for an object that is no boat model."""
        if not isinstance(boat, BoatModel):  # the protocol's contract, not a type switch
            raise InputError(
                f"leg {label}: the grid routers need a boat model (a Polar or a DynamicBoat), "
                f"got {type(boat).__name__}"
            )
        return cls(boat, boat.routing_polar(), boat.dynamics())

    def steady_speed(self, tws: NDArray, beta: NDArray) -> NDArray:
        """Steady boat speed [m s⁻¹] at TWS [m s⁻¹] and |TWA| [rad] (the dynamic model
        through its segment table, as its segment costs)."""
        if self.dynamic is not None:
            return tws * self.dynamic.table().steady(beta)
        return self.boat.steady_speed(tws, np.degrees(beta))

    def vmg_angles_deg(self, tws: float) -> tuple[float, float]:
        """Upwind and downwind VMG angles [°] at ``tws`` [m s⁻¹]."""
        return self.boat.vmg_angles_deg(tws)


# --------------------------------------------------------------------------------------
# wind along chains of pieces


@dataclass(frozen=True, eq=False)
class ChainWind:
    """Wind and geometry of chains of straight pieces, shape ``(..., n)``.

    Attributes
    ----------
    tws : ndarray
        True wind speed at the piece midpoint [m s⁻¹].
    beta : ndarray
        |TWA| of the piece [rad].
    side : ndarray of int8
        +1 starboard, -1 port (TWA 0 counts as starboard).
    length : ndarray
        Piece length [m].
    ux, uy : ndarray
        Unit direction of the piece (east, north).
    valid : ndarray of bool
        Midpoint and time inside the wind coverage (always true for clamped fields).
    """

    tws: NDArray
    beta: NDArray
    side: NDArray
    length: NDArray
    ux: NDArray
    uy: NDArray
    valid: NDArray


def sample_wind(
    wind: WindField, t: NDArray, x: NDArray, y: NDArray
) -> tuple[NDArray, NDArray, NDArray]:
    """Sample ``wind`` without raising: ``(u, v, inside)``.

    Points outside a non-clamping field's coverage are sampled at the nearest
    covered point and flagged ``inside = False`` (routers treat them as
    unusable); non-finite times count as outside.
    """
    t, x, y = np.broadcast_arrays(np.asarray(t, float), np.asarray(x, float), np.asarray(y, float))
    cov = wind.coverage
    finite = np.isfinite(t)
    tt = np.where(finite, t, 0.0)
    if wind.clamp:
        u, v = wind.sample(tt, x, y)
        return u, v, finite
    inside = cov.contains(tt, x, y) & finite
    if not inside.all():
        tt = np.clip(tt, cov.t0, cov.t1)
        x = np.clip(x, cov.xmin, cov.xmax)
        y = np.clip(y, cov.ymin, cov.ymax)
    u, v = wind.sample(tt, x, y)
    return u, v, inside


def _pieces_wind(
    wind: WindField, t: NDArray, mx: NDArray, my: NDArray, ux: NDArray, uy: NDArray
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    u, v, ok = sample_wind(wind, t, mx, my)
    tws = np.hypot(u, v)
    safe = np.where(tws > 0, tws, 1.0)
    fx, fy = -u / safe, -v / safe  # unit vector the wind comes from
    dot = ux * fx + uy * fy
    cross = ux * fy - uy * fx
    twa = np.arctan2(-cross, dot)  # signed, + = starboard (clockwise from heading)
    return tws, np.abs(twa), np.where(twa >= 0, 1, -1).astype(np.int8), ok


def sample_chains(
    wind: WindField,
    px: NDArray,
    py: NDArray,
    t_dep: NDArray,
    model: GridBoat,
    speed: Callable[[NDArray, NDArray], NDArray] | None = None,
) -> ChainWind:
    """Wind along chains of pieces at the time the boat sails each piece.

    Parameters
    ----------
    wind : WindField
        Wind.
    px, py : ndarray, shape (..., n + 1)
        Chain vertices [m].
    t_dep : ndarray, shape (...)
        Departure time at the first vertex [epoch s].
    model : BoatModel
        Gives the steady speeds used to time the pieces.
    speed : callable, optional
        ``speed(tws, beta) -> [m s⁻¹]`` used instead of ``model.steady_speed``
        to time the pieces (a cheaper approximation is enough: it only sets
        the times at which the wind is sampled again).

    Returns
    -------
    ChainWind

    Notes
    -----
    Predictor-corrector: the wind at the departure time gives steady piece
    times, hence the time the boat passes each piece midpoint; the wind is
    then sampled again at those times.  Exact for time-independent wind; for
    time-varying wind the timing error is that of the first pass (the wind's
    change over one segment time).
    """
    dx = np.diff(px, axis=-1)
    dy = np.diff(py, axis=-1)
    length = np.hypot(dx, dy)
    safe = np.where(length > 0, length, 1.0)
    ux, uy = dx / safe, dy / safe
    mx = 0.5 * (px[..., 1:] + px[..., :-1])
    my = 0.5 * (py[..., 1:] + py[..., :-1])
    t1 = np.asarray(t_dep, float)[..., None]
    shape = np.broadcast_shapes(mx.shape, t1.shape)
    t1, mx, my, ux, uy, length = (np.broadcast_to(a, shape) for a in (t1, mx, my, ux, uy, length))
    tws, beta, _, _ = _pieces_wind(wind, t1, mx, my, ux, uy)
    spd = (model.steady_speed if speed is None else speed)(tws, beta)
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(length > 0, length / spd, 0.0)
    tau = np.where(np.isfinite(tau), tau, 0.0)
    mid = np.cumsum(tau, axis=-1) - 0.5 * tau
    tws, beta, side, ok = _pieces_wind(wind, t1 + mid, mx, my, ux, uy)
    return ChainWind(tws, beta, side, length, ux, uy, ok)


def node_inside(wind: WindField, x: NDArray, y: NDArray) -> NDArray:
    """Nodes inside the wind's spatial coverage (all of them for clamped fields)."""
    if wind.clamp:
        return np.ones(np.shape(x), dtype=bool)
    c = wind.coverage
    return (x >= c.xmin) & (x <= c.xmax) & (y >= c.ymin) & (y <= c.ymax)


# --------------------------------------------------------------------------------------
# grid size


def default_half_width(frame: LegFrame, wind: WindField, t0: float, model: GridBoat) -> float:
    """Half-width of the grid [m] from the one-tack laylines.

    The mean wind of A, the leg midpoint and B at ``t0`` fixes the wind angle
    ``φ`` of the leg.  If the leg is upwind (``|φ|`` below the upwind VMG
    angle) or downwind (above the downwind one), the two VMG headings span a
    parallelogram with diagonal AB whose lateral excursion is
    ``L |sin ψ1 sin ψ2 / sin(ψ2 − ψ1)|`` (``ψ`` the headings relative to AB);
    the half-width is :data:`LAYLINE_TOLERANCE` times that, and at least
    :data:`MIN_HALF_WIDTH_FRACTION` of the leg length (also for reaches).
    """
    L = frame.length
    xs, ys = frame.point(np.array([0.0, 0.5 * L, L]), np.zeros(3))
    u, v, _ = sample_wind(wind, np.full(3, float(t0)), xs, ys)
    tws, twd = wind_speed_direction(np.mean(u), np.mean(v))
    floor = MIN_HALF_WIDTH_FRACTION * L
    if not float(tws) > 0:
        return floor
    up, down = model.vmg_angles_deg(float(tws))
    phi = float(wrap180(float(twd) - frame.bearing_deg))  # TWA of a boat sailing along AB
    if abs(phi) < up:
        ang = up
    elif abs(phi) > down:
        ang = down
    else:
        return floor
    p1, p2 = math.radians(phi - ang), math.radians(phi + ang)
    den = abs(math.sin(p2 - p1))
    if den < 1e-9:
        return floor
    exc = L * abs(math.sin(p1) * math.sin(p2)) / den
    return max(LAYLINE_TOLERANCE * exc, floor)


def penalty_of(
    beta_new: NDArray, beta_old: NDArray | None, tack_s: float, gybe_s: float
) -> NDArray:
    """Penalty [s] of a side change: tack if the mean |TWA| is below 90°, else gybe."""
    b = beta_new if beta_old is None else 0.5 * (beta_new + beta_old)
    return np.where(b < 0.5 * np.pi, tack_s, gybe_s)
