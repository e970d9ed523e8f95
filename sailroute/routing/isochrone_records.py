"""Records of the isochrone kernel: the leg frame, the front and the inputs of one step.

:class:`_LegFrame` puts a leg in its own frame (target centre at the origin, +Y towards
the start centre).  :class:`_Layer` is the front at one time, with the move that led to
each point; :class:`_Arrival` the first crossing of the target; :class:`_Context` the
per-leg constants; :class:`Groups` the members routed as one front
(:mod:`sailroute.routing.batch`).  :class:`_StepInputs` and its parts
(:class:`_PointWind`, :class:`_ExactColumns`, :class:`_TimeToGo`,
:class:`_ManoeuvreState`, :class:`_Current`) are what
:func:`~sailroute.routing.isochrone_inputs._prepare` hands to the candidate kernel of
:mod:`sailroute.routing.isochrone_kernel` each step.

Used by the driver (:mod:`sailroute.routing.isochrone`), the other modules of the kernel
(:mod:`~sailroute.routing.isochrone_polar`, :mod:`~sailroute.routing.isochrone_togo`,
:mod:`~sailroute.routing.isochrone_inputs`, :mod:`~sailroute.routing.isochrone_kernel`)
and :mod:`sailroute.routing.batch`; it imports none of them.  The symbols and names are
those of the glossary in :mod:`sailroute.routing.isochrone_kernel`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np

from sailroute.routing.geometry import TargetGeometry
from sailroute.routing.obstacles import Obstacles
from sailroute.routing.types import Barrier
from sailroute.wind.current import CurrentField

_CHUNK_ELEMENTS = 15000
"""The candidate kernel takes the rows of a front in chunks of about this many
candidates, so that the float64 work arrays stay below 128 KB: larger NumPy
temporaries are mmap-allocated by glibc on every operation, which costs ~10x in this
kernel.  The chunks also fix the order in which equal scores are ranked (the compiled
kernel follows them)."""

# --------------------------------------------------------------------------------------
# leg frame: target centre at the origin, +Y towards the start centre


@dataclass(frozen=True)
class _LegFrame:
    """Rotation/translation to the leg frame (right-handed, compass-like).

    ``Y`` points from the target centre towards the start centre and ``X`` 90°
    clockwise from it, so the bearing of a point seen from the target,
    ``atan2(X, Y)``, is 0 on the target→start axis and mirror images about the
    leg axis have opposite ``X``.
    """

    cx: float
    cy: float
    fx: float
    fy: float

    @classmethod
    def for_leg(cls, centre: tuple[float, float], start_xy: tuple[float, float]) -> _LegFrame:
        dx, dy = start_xy[0] - centre[0], start_xy[1] - centre[1]
        d = math.hypot(dx, dy)
        fx, fy = (dx / d, dy / d) if d > 1e-9 else (0.0, 1.0)
        return cls(centre[0], centre[1], fx, fy)

    @property
    def offset_deg(self) -> float:
        """World heading = leg heading + this [°]."""
        return math.degrees(math.atan2(self.fx, self.fy))

    def to_leg(self, x: Any, y: Any) -> tuple[Any, Any]:
        dx, dy = x - self.cx, y - self.cy
        return dx * self.fy - dy * self.fx, dx * self.fx + dy * self.fy

    def to_world(self, X: Any, Y: Any) -> tuple[Any, Any]:
        return self.cx + X * self.fy + Y * self.fx, self.cy - X * self.fx + Y * self.fy

    def vec_to_leg(self, vx: Any, vy: Any) -> tuple[Any, Any]:
        return vx * self.fy - vy * self.fx, vx * self.fx + vy * self.fy

    def barrier(self, b: Barrier) -> Barrier:
        """The barrier in the leg frame."""
        mark = _floats(self.to_leg(b.mark[0], b.mark[1]))
        ray = _floats(self.vec_to_leg(b.ray[0], b.ray[1]))
        n = _floats(self.vec_to_leg(b.normal[0], b.normal[1]))
        return Barrier(mark, ray, n, b.name)

    def geometry(self, g: TargetGeometry) -> TargetGeometry:
        a = _floats(self.to_leg(g.a[0], g.a[1]))
        b = _floats(self.to_leg(g.b[0], g.b[1]))
        n = _floats(self.vec_to_leg(g.normal[0], g.normal[1]))
        return TargetGeometry(a, b, n, g.kind, g.name)


def _floats(p: tuple[Any, Any]) -> tuple[float, float]:
    """A point or vector as two Python floats."""
    return float(p[0]), float(p[1])


# --------------------------------------------------------------------------------------
# the front and its history


@dataclass(frozen=True, eq=False)
class _Layer:
    """Front at one time (leg frame), with the move that led to each point."""

    t: Any  # time of this front [epoch s] (per point for members routed together)
    x: Any  # leg-frame position [m]
    y: Any
    side: Any  # +1, -1 (0 only at the leg start: free)
    debt: Any  # penalty time still owed [s]
    abs_twa: Any  # |TWA| of the move into this point [°] (NaN at the start)
    pend_old: Any  # |TWA| before a manoeuvre not yet sailed out of (NaN: none)
    pend_pen: Any  # penalty charged for that manoeuvre so far [s]
    parent: Any  # index into the previous layer (-1 at the start)
    heading: Any  # leg-frame heading of the move into this point [°]
    bsp: Any  # boat speed of that move [m s⁻¹]
    delay: Any  # time stopped at the start of that move [s]
    tau_est: Any  # estimated time to go [s] (NaN at the start)


@dataclass(frozen=True)
class _Arrival:
    parent: int
    t_start: float
    t: float
    x: float  # leg frame
    y: float
    heading: float  # leg frame
    bsp: float
    delay: float
    side: int


@dataclass(frozen=True)
class _Context:
    """Per-leg constants of the kernel."""

    label: str
    t0: float
    frame: _LegFrame
    geom: TargetGeometry  # in the leg frame
    tack_s: float
    gybe_s: float
    sector_rad: float
    n_bins: int  # sectors around the target
    max_points: int
    fan_hull: bool
    box: tuple[float, float, float, float] | None  # world coverage box to stay in, or None
    barriers: tuple[tuple[Barrier, float], ...] = ()  # (leg frame, mark clearance [m])
    current: CurrentField | None = None  # surface current (None: still water)
    obstacles: Obstacles | None = None  # race area, world frame (None: open water)
    # when an obstacle blocks the straight line from the start to the target, the pruning
    # sectors are seen from the start centre (this point, leg frame), not from the target:
    # a detour's points then keep their own sectors instead of losing them to the points
    # held up behind the obstacle (nearer the target); None: seen from the target
    bin_origin: tuple[float, float] | None = None


# --------------------------------------------------------------------------------------
# the records of one step

# The records below are built every step and per chunk of rows: immutable NamedTuples
# rather than frozen dataclasses, which take about 3x longer to construct (2.3 against
# 0.7 µs for 8 fields) and made a leg about 1 % slower.


class _PointWind(NamedTuple):
    """The wind at the front points as the kernel uses it; arrays of shape (n,).

    Attributes
    ----------
    tws_ms : array
        True wind speed [m s⁻¹].
    up_x, up_y : array
        Upwind unit vector ``ŵ`` (pointing where the wind comes from), leg frame;
        ``(0, 1)`` in a calm.
    row, weight : array
        TWS interpolation in the polar tables: the node ``row`` (int) at or below the
        TWS and the weight of node ``row + 1``, in [0, 1].
    up_deg, down_deg : array
        Upwind and downwind VMG angles at that TWS [°].
    """

    tws_ms: Any
    up_x: Any
    up_y: Any
    row: Any
    weight: Any
    up_deg: Any
    down_deg: Any

    def rows(self, sl: slice) -> _PointWind:
        """The points ``sl`` only."""
        return _PointWind(
            self.tws_ms[sl],
            self.up_x[sl],
            self.up_y[sl],
            self.row[sl],
            self.weight[sl],
            self.up_deg[sl],
            self.down_deg[sl],
        )


class _ExactColumns(NamedTuple):
    """The four exact (off-grid) candidate headings of every point.

    Columns: 0 upwind VMG angle, 1 downwind VMG angle, 2 direct to the aim point of the
    point's own side (block ``_KEEP``), 3 direct to the aim point of the other side
    (block ``_SWITCH``).

    Attributes
    ----------
    twa_deg, bsp_ms : array, shape (n, 4)
        Their |TWA| [°] and boat speed [m s⁻¹].
    cos_twa, sin_twa : array, shape (n, 4)
        Cosine and sine of that |TWA| (``sin_twa >= 0``).
    direct_sin_keep, direct_sin_switch : array, shape (n,)
        Signed sine of the TWA of columns 2 and 3 (positive: starboard): a direct
        column exists only on its own side.
    """

    twa_deg: Any
    bsp_ms: Any
    cos_twa: Any
    sin_twa: Any
    direct_sin_keep: Any
    direct_sin_switch: Any

    def rows(self, sl: slice) -> _ExactColumns:
        """The points ``sl`` only."""
        return _ExactColumns(
            self.twa_deg[sl],
            self.bsp_ms[sl],
            self.cos_twa[sl],
            self.sin_twa[sl],
            self.direct_sin_keep[sl],
            self.direct_sin_switch[sl],
        )


class _TimeToGo(NamedTuple):
    """Estimated time to go ``τ`` of the points on one side, and its gradient ``G``.

    ``τ(P + d) ≈ τ(P) - d·G`` for a small move ``d`` [m]; arrays of shape (n,).

    Attributes
    ----------
    tau_s : array
        ``τ`` [s].
    grad_x, grad_y : array
        ``G`` [s m⁻¹] (leg frame).
    """

    tau_s: Any
    grad_x: Any
    grad_y: Any

    def rows(self, sl: slice) -> _TimeToGo:
        """The points ``sl`` only."""
        return _TimeToGo(self.tau_s[sl], self.grad_x[sl], self.grad_y[sl])


class _ManoeuvreState(NamedTuple):
    """Side and penalty bookkeeping of the front points; arrays of shape (n,).

    Attributes
    ----------
    side : array
        ``σ``, the side sailed by block ``_KEEP``: the point's side, +1 for a free point.
    free : array of bool
        No side chosen yet (leg start): its first side change costs nothing.
    pending : array of bool
        Inside a manoeuvre whose penalty is re-priced by the next heading sailed.
    base_twa_deg : array
        |TWA| before the manoeuvre a side change would start [°] (NaN: unknown).
    penalty_up_s, penalty_down_s : array
        Penalty of a side change onto an upwind (|TWA| < 90°) or a downwind heading [s].
    debt_s : array
        Penalty time still owed [s].
    charged_s : array
        Penalty charged so far for the pending manoeuvre [s].
    any_pending : bool
        Whether any point is pending (the pending work is skipped when none is).
    """

    side: Any
    free: Any
    pending: Any
    base_twa_deg: Any
    penalty_up_s: Any
    penalty_down_s: Any
    debt_s: Any
    charged_s: Any
    any_pending: bool

    def rows(self, sl: slice, xp: ModuleType) -> _ManoeuvreState:
        """The points ``sl`` only."""
        pending = self.pending[sl]
        return _ManoeuvreState(
            self.side[sl],
            self.free[sl],
            pending,
            self.base_twa_deg[sl],
            self.penalty_up_s[sl],
            self.penalty_down_s[sl],
            self.debt_s[sl],
            self.charged_s[sl],
            self.any_pending and bool(xp.any(pending)),
        )


class _Current(NamedTuple):
    """Current at the front points (leg frame) [m s⁻¹]; arrays of shape (n,).

    ``move_*``: at the point's mid-step sample, moves the candidates;
    ``mean_*``: averaged along the way to the target, enters the time to go.
    """

    move_x: Any
    move_y: Any
    mean_x: Any
    mean_y: Any


class _StepInputs(NamedTuple):
    """What the candidate kernel needs about the ``n`` front points of one step.

    Built by :func:`_prepare`; :meth:`rows` restricts it to a chunk of points.  Leg
    frame; arrays of shape (n,).

    Attributes
    ----------
    t : float or array
        Start of the step [epoch s] (per point for members routed together).
    dt : float or array
        Step length [s]: one value, or one per point (members routed together, each
        member's own, :mod:`sailroute.routing.batch`).
    first, stop : int
        The grid columns ``first:stop`` of the polar tables that are tried (the fan).
    x, y : array
        Positions [m].
    wind : _PointWind
        The wind of the move.
    exact : _ExactColumns
        The exact columns.
    keep, switch : _TimeToGo
        Time to go on the point's side ``σ`` and on the other side ``-σ``.
    manoeuvre : _ManoeuvreState
        Sides and penalties.
    near_target : array of bool
        Within one step of the target segment.
    near_barrier : tuple
        Per barrier of the leg (:attr:`_Context.barriers`): bool array, within one
        step of it, or None where no point is.
    current_x, current_y : array or None
        Current of the move [m s⁻¹]; None: still water.
    group : array of int or None
        Members routed together (:mod:`sailroute.routing.batch`): the member of each
        point (0 .. ``n_groups - 1``), which the pruning keeps apart; None: one route.
    n_groups : int
        Number of members.
    fan_lo, fan_hi : array of int or None
        Each point's own fan of grid columns ``fan_lo:fan_hi`` (its member's,
        :func:`_group_fans`) inside the common ``first:stop``; None: ``first:stop``.
    box_clear : bool
        No move of the step can leave the coverage box (:func:`_box_holds`), so the
        candidates are not tested against it.
    first_clear : array or None
        Members: each point's clearance from the mark of the first barrier of the leg
        (the start's, :attr:`Groups.clearance`) [m]; None: the barrier's own.
    starts_free : bool
        Every point ends a move found in free water (no point of the leg's start
        layer), so the race-area test need not test the points themselves.
    reach_m : array or None
        An upper bound of each point's move length in the step [m] (the fastest polar
        speed of its wind, plus the current, times the step); None: unknown.
    packed : isochrone_fast.Packed or None
        The compiled path's arrays these are views of (None on the NumPy path).
    """

    t: Any
    dt: float | Any
    first: int
    stop: int
    x: Any
    y: Any
    wind: _PointWind
    exact: _ExactColumns
    keep: _TimeToGo
    switch: _TimeToGo
    manoeuvre: _ManoeuvreState
    near_target: Any
    near_barrier: tuple[Any, ...]
    current_x: Any = None
    current_y: Any = None
    group: Any = None
    n_groups: int = 1
    fan_lo: Any = None
    fan_hi: Any = None
    box_clear: bool = True
    first_clear: Any = None
    starts_free: bool = False
    reach_m: Any = None
    packed: Any = None

    @property
    def n(self) -> int:
        """Number of points."""
        return int(self.x.shape[0])

    @property
    def n_grid(self) -> int:
        """Number of grid columns."""
        return self.stop - self.first

    @property
    def n_columns(self) -> int:
        """Candidates per point and block: the grid columns and three exact ones."""
        return self.stop - self.first + 3

    @property
    def dt_rows(self) -> float | Any:
        """The step length as a column, one row per point (shape (n, 1)), to go with
        arrays of one row per point and one column per candidate; a float as it is."""
        return self.dt if isinstance(self.dt, float) else self.dt[:, None]

    def dt_of(self, rows: Any) -> float | Any:
        """The step length of the points ``rows`` (an index array); a float as it is."""
        return self.dt if isinstance(self.dt, float) else self.dt[rows]

    def rows(self, r0: int, r1: int, xp: ModuleType) -> _StepInputs:
        """The points ``r0:r1`` only (views)."""
        if r0 == 0 and r1 == self.n:
            return self
        sl = slice(r0, r1)
        still = self.current_x is None
        return _StepInputs(
            t=self.t,
            dt=self.dt if isinstance(self.dt, float) else self.dt[sl],
            first=self.first,
            stop=self.stop,
            x=self.x[sl],
            y=self.y[sl],
            wind=self.wind.rows(sl),
            exact=self.exact.rows(sl),
            keep=self.keep.rows(sl),
            switch=self.switch.rows(sl),
            manoeuvre=self.manoeuvre.rows(sl, xp),
            near_target=self.near_target[sl],
            near_barrier=tuple(None if c is None else c[sl] for c in self.near_barrier),
            current_x=None if still else self.current_x[sl],
            current_y=None if still else self.current_y[sl],
            group=None if self.group is None else self.group[sl],
            n_groups=self.n_groups,
            fan_lo=None if self.fan_lo is None else self.fan_lo[sl],
            fan_hi=None if self.fan_hi is None else self.fan_hi[sl],
            box_clear=self.box_clear,
            first_clear=None if self.first_clear is None else self.first_clear[sl],
            starts_free=self.starts_free,
            reach_m=None if self.reach_m is None else self.reach_m[sl],
        )


# --------------------------------------------------------------------------------------
# members routed as one front


class Groups(NamedTuple):
    """Members routed as one front (:mod:`sailroute.routing.batch`): each member's
    points are consecutive.

    Attributes
    ----------
    starts : ndarray of int, shape (M,)
        Index of each member's first point.
    member : ndarray of int, shape (n,)
        The member of each point, 0 .. M - 1.
    clearance : ndarray, shape (M,), or None
        Each member's clearance from the mark of the leg's first barrier, the start's
        (:func:`~sailroute.routing.geometry.barrier_clearance`) [m]; None: no start
        barrier.
    """

    starts: Any
    member: Any
    clearance: Any = None

    @property
    def n_members(self) -> int:
        """Number of members ``M``."""
        return int(self.starts.shape[0])

    @classmethod
    def of_sizes(cls, sizes: Any, clearance: Any = None) -> Groups:
        """Members of ``sizes[k]`` consecutive points each (every size > 0)."""
        sizes = np.asarray(sizes, dtype=np.int64)
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        return cls(starts, np.repeat(np.arange(sizes.shape[0]), sizes), clearance)
