"""Isochrone kernel: the per-step array functions of the isochrone leg router.

One step of :func:`~sailroute.routing.isochrone.route_isochrone` (the driver, which
keeps the setup, the layers and the backtracking) goes from a front to the next:
:func:`_step` prepares the inputs (:func:`_prepare`: wind, aim points, exact columns,
time to go), expands and scores the candidates chunk by chunk (:func:`_expand`), tests
the arrival (:func:`_arrival`) and keeps the best candidate per sector and side
(:func:`_survivors`).  Also the polar tables (:func:`polar_tables`), the leg frame
and the front records.

Glossary of the kernel (symbols of ``docs/design/routing.md`` → names in the code; leg
frame, SI units, angles in degrees):

* ``σ``, the side: ``side`` (``sigma`` for the side a candidate sails): +1 starboard,
  −1 port (:func:`~sailroute.routing.types.side_sign`), 0 free (no side chosen yet, only
  at the leg start; a free point sails as +1 in block ``_KEEP`` and changes side
  without penalty).
* ``ŵ``, the upwind unit vector: ``up_x, up_y``; the TWS interpolation in the polar
  tables: node ``row`` and ``weight`` (:class:`_PointWind`).
* ``S``, boat speed: ``bsp_ms``; ``a``, |TWA|: ``twa_deg``; ``(S cos a, S sin a)``:
  ``sx, sy``; ``v``, velocity through the water: ``vx, vy`` (:func:`_velocity`).
* candidates: block ``_KEEP`` (side ``σ``) and block ``_SWITCH`` (side ``-σ``, a tack or
  gybe), each with the grid columns ``first:stop`` of the tables (the fan) and the exact
  columns VMG up, VMG down, direct to the aim point (:class:`_ExactColumns`).
* ``τ``, the estimated time to go, and ``G``, its gradient: ``tau_s``, ``grad_x, grad_y``
  (:class:`_TimeToGo`); ``G·v``: ``rate``.
* a penalty as time: ``delay`` (stopped), ``move`` (moving), ``debt`` (still owed)
  (:class:`_Timing`); the manoeuvre bookkeeping: :class:`_ManoeuvreState`.
* ``C``, the current: ``current_x, current_y`` (:class:`_Current`); ``Q``, the end point
  of a move (drifted with the current): ``qx, qy``.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from sailroute.backend import to_numpy
from sailroute.boat.polar import Polar
from sailroute.errors import RoutingError
from sailroute.numerics import clip
from sailroute.routing.geometry import (
    AIM_MARGIN_M,
    BARRIER_LENGTH_M,
    TargetGeometry,
    aim_points,
    barrier_blocks,
    segment_crossing,
)
from sailroute.routing.obstacles import Obstacles
from sailroute.routing.types import (
    Barrier,
    RoutingSettings,
)
from sailroute.wind.base import WindField
from sailroute.wind.current import CurrentField

TABLE_TWS_STEP_MS = 0.05
"""TWS spacing of the cached polar table of the grid candidates [m s⁻¹]."""
NEAR_TARGET_STEPS = 3.0
"""The step shrinks to (estimated time to go) / this, once that is below three steps."""
PATH_SAMPLES = 4
"""Wind samples along the line to the target that enter the time-to-go estimate."""
_ROOT_SPEED_MS = 2.0  # progress speed assumed for the sampling horizon at the leg start
_CALM_MS = 1e-9


# --------------------------------------------------------------------------------------
# polar tables (cached per polar and heading step)


@dataclass(frozen=True, eq=False)
class PolarTables:
    """Polar sampled for the isochrone kernel.

    Attributes
    ----------
    twa_deg : ndarray, shape (n_a,)
        Grid of ``|TWA|`` [°], ``180/n_a, 2·180/n_a, ..., 180``.
    cos_a, sin_a : ndarray, shape (n_a,)
        Their cosine and sine.
    tws_ms : ndarray, shape (n_w,)
        TWS nodes [m s⁻¹]: every 0.05 m s⁻¹ from 0 to the polar's top TWS,
        plus the polar's own columns (so a bilinear polar is reproduced exactly).
    speed_ms : ndarray, shape (n_w, n_a)
        Boat speed at the nodes [m s⁻¹].
    up_deg, down_deg : ndarray, shape (n_w,)
        Upwind and downwind VMG angles [°] at the nodes.
    up_vmg_ms, down_vmg_ms : ndarray, shape (n_w,)
        The VMG there [m s⁻¹] (positive).
    vmax_ms : ndarray, shape (n_w,)
        Highest boat speed on the grid at the nodes [m s⁻¹].
    sup_beta_deg : ndarray, shape (n_b,)
        Directions ``beta`` [°] in ``[-180, 180]``, measured from the upwind direction
        towards one side (every 1°).
    sup_ms, sup_deg : ndarray, shape (n_w, n_b)
        Support of the polar: the largest speed component ``S(a) cos(a - beta)`` over
        the headings of that side [m s⁻¹], and the |TWA| ``a`` giving it [°] (grid
        maximum refined by a parabola, or a VMG angle).
    """

    twa_deg: NDArray[np.float64]
    cos_a: NDArray[np.float64]
    sin_a: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    speed_ms: NDArray[np.float64]
    up_deg: NDArray[np.float64]
    down_deg: NDArray[np.float64]
    up_vmg_ms: NDArray[np.float64]
    down_vmg_ms: NDArray[np.float64]
    vmax_ms: NDArray[np.float64]
    sup_beta_deg: NDArray[np.float64]
    sup_ms: NDArray[np.float64]
    sup_deg: NDArray[np.float64]


_TABLE_CACHE: weakref.WeakKeyDictionary[Any, dict[int, PolarTables]] = weakref.WeakKeyDictionary()


def _vmg_angles(polar: Polar, tws: NDArray, upwind: bool) -> tuple[NDArray, NDArray]:
    a, v = polar.vmg_upwind(tws) if upwind else polar.vmg_downwind(tws)
    return np.asarray(a, dtype=float), np.asarray(v, dtype=float)


def polar_tables(polar: Polar, heading_step_deg: float) -> PolarTables:
    """Sample ``polar`` for the kernel (cached per polar object and TWA grid).

    Parameters
    ----------
    polar : Polar
        Boat polar.
    heading_step_deg : float
        Requested TWA step [°]; the grid uses ``n_a = ceil(180/step)`` equal steps.

    Returns
    -------
    PolarTables
    """
    n_a = max(2, math.ceil(180.0 / heading_step_deg - 1e-9))
    try:
        per_polar = _TABLE_CACHE.setdefault(polar, {})
    except TypeError:  # not weak-referenceable: no caching
        per_polar = {}
    cached = per_polar.get(n_a)
    if cached is not None:
        return cached
    a = np.linspace(180.0 / n_a, 180.0, n_a)
    own = np.asarray(polar.tws_ms, dtype=float).ravel()
    top = float(own.max()) if own.size and own.max() > 0 else 30.0
    nodes = np.sort(
        np.concatenate(
            [
                np.linspace(0.0, top, math.ceil(top / TABLE_TWS_STEP_MS) + 1),
                own[(own >= 0) & (own <= top)],
            ]
        )
    )
    # distinct values (np.unique's result without NaNs; np.unique imports numpy.ma, 22 ms
    # of a plan's start-up)
    nodes = nodes[np.concatenate([[True], nodes[1:] != nodes[:-1]])]
    speed = np.asarray(polar.speed(nodes[:, None], a[None, :]), dtype=float)
    up, vu = _vmg_angles(polar, nodes, True)
    down, vd = _vmg_angles(polar, nodes, False)
    up = _backfill_calm(up, vu)
    down = _backfill_calm(down, vd)
    rad = np.radians(a)
    vmax = np.maximum(
        speed.max(axis=1), np.asarray(polar.speed(nodes, np.stack([up, down], 1).T)).max(axis=0)
    )
    vu, vd = np.maximum(vu, 0.0), np.maximum(vd, 0.0)
    beta = np.linspace(-180.0, 180.0, 361)
    sup_ms, sup_deg = _support_table(a, speed, up, down, vu, vd, beta)
    tables = PolarTables(
        a, np.cos(rad), np.sin(rad), nodes, speed, up, down, vu, vd, vmax, beta, sup_ms, sup_deg
    )
    per_polar[n_a] = tables
    return tables


def _support_table(
    a: NDArray,
    speed: NDArray,
    up: NDArray,
    down: NDArray,
    vu: NDArray,
    vd: NDArray,
    beta: NDArray,
) -> tuple[NDArray, NDArray]:
    """Largest speed component towards ``beta`` and its |TWA|, per TWS node (see
    :class:`PolarTables`); grid maxima refined by a parabola through their neighbours."""
    n_w, n_a = speed.shape
    cb, sb = np.cos(np.radians(beta)), np.sin(np.radians(beta))
    ca, sa = np.cos(np.radians(a)), np.sin(np.radians(a))
    cos_ab = ca[None, :] * cb[:, None] + sa[None, :] * sb[:, None]  # (n_b, n_a)
    val = np.empty((n_w, beta.size))
    ang = np.empty((n_w, beta.size))
    step = a[1] - a[0]
    for r0 in range(0, n_w, 64):
        r1 = min(n_w, r0 + 64)
        obj = speed[r0:r1, None, :] * cos_ab[None]  # (rows, n_b, n_a)
        k = np.argmax(obj, axis=2)
        f1 = np.take_along_axis(obj, k[..., None], 2)[..., 0]
        f0 = np.take_along_axis(obj, np.maximum(k - 1, 0)[..., None], 2)[..., 0]
        f2 = np.take_along_axis(obj, np.minimum(k + 1, n_a - 1)[..., None], 2)[..., 0]
        den = f0 - 2.0 * f1 + f2
        inner = (k > 0) & (k < n_a - 1) & (den < 0)
        off = np.where(inner, 0.5 * (f0 - f2) / np.where(inner, den, -1.0), 0.0)
        best, where = f1, a[k] + np.clip(off, -0.5, 0.5) * step
        for ang_c, v_c in ((up[r0:r1], vu[r0:r1]), (down[r0:r1], vd[r0:r1])):
            c = np.abs(np.cos(np.radians(ang_c)))
            v_c = np.where(c > 1e-9, v_c / np.where(c > 1e-9, c, 1.0), 0.0)  # VMG -> speed
            rc = np.radians(ang_c)[:, None]
            o = v_c[:, None] * (np.cos(rc) * cb[None, :] + np.sin(rc) * sb[None, :])
            better = o > best
            best = np.where(better, o, best)
            where = np.where(better, ang_c[:, None], where)
        val[r0:r1] = best
        ang[r0:r1] = where
    return val, ang


def _backfill_calm(angle: NDArray, vmg: NDArray) -> NDArray:
    """Replace the angle at calm nodes (no VMG) by the first windy node's angle."""
    ok = vmg > 0
    if not ok.any():
        return angle
    first = int(np.flatnonzero(ok)[0])
    out = angle.copy()
    out[:first] = angle[first]
    return out


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


def _group_argmin(key: Any, score: Any, n_keys: int, xp: ModuleType) -> Any:
    """Flat indices of the smallest finite ``score`` per ``key`` (lowest index on ties)."""
    if xp is np:
        best = np.full(n_keys, np.inf)
        np.minimum.at(best, key, score)
        win = np.flatnonzero(score == best[key])
        win = win[score[win] < np.inf]
        first = np.full(n_keys, win.size, dtype=np.int64)  # lowest winning index per key
        np.minimum.at(first, key[win], np.arange(win.size))
        return win[first[first < win.size]]
    order = xp.lexsort(xp.stack([score, key]))
    ks = key[order]
    first = xp.concatenate([xp.ones(1, dtype=bool), ks[1:] != ks[:-1]])
    keep = order[first]
    return keep[score[keep] < np.inf]


@dataclass(frozen=True, eq=False)
class _DeviceTables:
    """The :class:`PolarTables` arrays in the kernel's array module ``xp`` (same units).

    ``n_w`` TWS nodes (rows), ``n_a`` grid |TWA|s, ``n_b`` support directions.
    """

    twa_deg: Any  # (n_a,) grid |TWA| [°]
    cos_a: Any  # (n_a,) its cosine
    sin_a: Any  # (n_a,) its sine
    tws_ms: Any  # (n_w,) TWS nodes [m s⁻¹]
    speed_ms: Any  # (n_w, n_a) boat speed [m s⁻¹]
    up_deg: Any  # (n_w,) upwind VMG angle [°]
    down_deg: Any  # (n_w,) downwind VMG angle [°]
    up_vmg_ms: Any  # (n_w,) upwind VMG [m s⁻¹]
    down_vmg_ms: Any  # (n_w,) downwind VMG [m s⁻¹]
    vmax_ms: Any  # (n_w,) highest boat speed [m s⁻¹]
    sup_ms: Any  # (n_w, n_b) polar support: best speed component [m s⁻¹]
    sup_deg: Any  # (n_w, n_b) the |TWA| giving it [°]


def _device_tables(tab: PolarTables, xp: ModuleType) -> _DeviceTables:
    return _DeviceTables(
        xp.asarray(tab.twa_deg),
        xp.asarray(tab.cos_a),
        xp.asarray(tab.sin_a),
        xp.asarray(tab.tws_ms),
        xp.asarray(tab.speed_ms),
        xp.asarray(tab.up_deg),
        xp.asarray(tab.down_deg),
        xp.asarray(tab.up_vmg_ms),
        xp.asarray(tab.down_vmg_ms),
        xp.asarray(tab.vmax_ms),
        xp.asarray(tab.sup_ms),
        xp.asarray(tab.sup_deg),
    )


# --------------------------------------------------------------------------------------
# one step: the inputs of the candidate kernel

_BIG_S = 1e12  # time-to-go standing in for "unknown" (calm) [s]
_CHUNK_ELEMENTS = 15000
"""Candidate rows are processed in chunks of about this many candidates, so that the
float64 work arrays stay below 128 KB: larger NumPy temporaries are mmap-allocated by
glibc on every operation, which costs ~10x in this kernel."""
_KEEP, _SWITCH = 0, 1
"""Candidate blocks of a point: ``_KEEP`` sails on its side, ``_SWITCH`` changes side
(tack or gybe).  A candidate's id is ``(row * 2 + block) * n_columns + column``."""
_EXACT_OF_BLOCK = ([0, 1, 2], [0, 1, 3])
"""The :class:`_ExactColumns` a block tries: VMG up, VMG down, its own direct column."""

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
    dt : float
        Step length [s].
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
    """

    t: Any
    dt: float
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

    def rows(self, r0: int, r1: int, xp: ModuleType) -> _StepInputs:
        """The points ``r0:r1`` only (views)."""
        if r0 == 0 and r1 == self.n:
            return self
        sl = slice(r0, r1)
        still = self.current_x is None
        return _StepInputs(
            t=self.t,
            dt=self.dt,
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
        )


# --------------------------------------------------------------------------------------
# one step: driver and survivors


def _step(
    f: _Layer,
    wind: WindField,
    polar: Polar,
    dev: _DeviceTables,
    ctx: _Context,
    s: RoutingSettings,
    tau_hint: float,
    xp: ModuleType,
) -> _Arrival | tuple[_Layer, bool, float, float]:
    """One isochrone step from the front ``f``.

    Returns the arrival if a candidate crosses the target during the step, else the
    new front, whether any point moved, the front's least estimated time to go [s] and
    its least distance to the target [m].
    """
    pre, tau_min, dist_min = _prepare(f, wind, polar, dev, ctx, s, tau_hint, xp)
    n, n_columns = pre.n, pre.n_columns
    chunk = n if xp is not np else max(1, _CHUNK_ELEMENTS // (n_columns + 3))
    n_keys = 2 * ctx.n_bins
    best = xp.full(n_keys, np.inf)
    who = xp.zeros(n_keys, dtype=xp.int64)  # winner id per key (see _KEEP)
    arrival: _Arrival | None = None
    for r0 in range(0, n, chunk):
        r1 = min(n, r0 + chunk)
        arr, win = _expand(pre, r0, r1, dev, ctx, xp, want_winners=arrival is None)
        if arr is not None and (arrival is None or arr.t < arrival.t):
            arrival = arr
        if arrival is not None or win is None:
            continue
        key, score, wid = win
        better = score < best[key]
        best[key[better]] = score[better]
        who[key[better]] = wid[better]
    if arrival is not None:
        return arrival

    won = xp.flatnonzero(best < np.inf)  # the keys that have a winner
    if won.shape[0] == 0 and ctx.obstacles is not None:
        raise _blocked_error(f, ctx, pre.t)
    if won.shape[0] == 0:
        cov = wind.coverage
        raise RoutingError(
            f"leg {ctx.label}: every candidate position left the wind field's coverage "
            f"({cov.describe()}) {pre.t - ctx.t0:.0f} s after the leg start, so the route "
            "cannot go on.\n  Try: wind data that covers the course with a margin, or a "
            "wind field built with clamp=True (hold the edge values outside)."
        )
    if won.shape[0] > ctx.max_points:  # widen the sectors: merge m neighbours
        m = -(-int(won.shape[0]) // ctx.max_points)
        coarse = (won // 2 // m) * 2 + won % 2
        won = xp.sort(won[_group_argmin(coarse, best[won], int(xp.max(coarse)) + 1, xp)])
    wid = who[won]
    column = wid % n_columns
    block = (wid // n_columns) % 2
    row = wid // (2 * n_columns)
    layer, moved = _survivors(pre, row, block, column, best[won], dev, xp)
    return layer, bool(xp.any(moved)), tau_min, dist_min


def _velocity(up_x: Any, up_y: Any, sigma: Any, sx: Any, sy: Any) -> tuple[Any, Any]:
    """Velocity through the water [m s⁻¹] (leg frame) of headings on side ``sigma``.

    The heading at |TWA| ``a`` on side ``σ`` is ``cos a ŵ + σ sin a ŵ⊥`` with
    ``ŵ = (up_x, up_y)`` and ``ŵ⊥ = (-up_y, up_x)``; ``sx, sy = S cos a, S sin a``
    with ``S`` the boat speed.  Arguments broadcast together.  Shared by the
    candidates (:func:`_block`) and the survivors (:func:`_survivors`), so a
    survivor's position is bit-identical to the candidate that won its sector.
    """
    return up_x * sx - (sigma * up_y) * sy, up_y * sx + (sigma * up_x) * sy


def _penalty(twa_deg: Any, upwind_s: Any, downwind_s: Any, xp: ModuleType) -> Any:
    """Penalty [s] of a side change priced by the first |TWA| [°] sailed after it:
    ``upwind_s`` below 90°, else ``downwind_s``."""
    return xp.where(twa_deg < 90.0, upwind_s, downwind_s)


def _winner_columns(
    pre: _StepInputs, row: Any, block: Any, column: Any, dev: _DeviceTables, xp: ModuleType
) -> tuple[Any, Any, Any, Any]:
    """|TWA| [°], boat speed [m s⁻¹] and ``(S cos|TWA|, S sin|TWA|)`` [m s⁻¹] of the
    winning candidates ``(row, block, column)`` (arrays of shape (m,)).

    The same arithmetic, in the same order, as :func:`_grid_speeds` and :func:`_block`.
    """
    n_grid = pre.n_grid
    grid = column < n_grid
    grid_col = xp.where(grid, column, 0) + pre.first
    exact_col = xp.where(grid, 0, column - n_grid)
    # block _SWITCH aims with its own direct column
    exact_col = xp.where((block == _SWITCH) & (exact_col == 2), 3, exact_col)
    node, weight = pre.wind.row[row], pre.wind.weight[row]
    ex = pre.exact
    s_lo = dev.speed_ms[node, grid_col]
    bsp = xp.where(
        grid, s_lo + weight * (dev.speed_ms[node + 1, grid_col] - s_lo), ex.bsp_ms[row, exact_col]
    )
    twa = xp.where(grid, dev.twa_deg[grid_col], ex.twa_deg[row, exact_col])
    sx = bsp * xp.where(grid, dev.cos_a[grid_col], ex.cos_twa[row, exact_col])
    sy = bsp * xp.where(grid, dev.sin_a[grid_col], ex.sin_twa[row, exact_col])
    return twa, bsp, sx, sy


def _survivors(
    pre: _StepInputs,
    row: Any,
    block: Any,
    column: Any,
    score: Any,
    dev: _DeviceTables,
    xp: ModuleType,
) -> tuple[_Layer, Any]:
    """The new front from the winning ``(row, block, column)`` triples (shape (m,)) and
    their scores (estimated time to go [s]); also which of them moved (bool, (m,))."""
    dt = pre.dt
    twa, bsp, sx, sy = _winner_columns(pre, row, block, column, dev, xp)
    m = pre.manoeuvre
    side = m.side[row]
    switch = block == _SWITCH
    sigma = xp.where(switch, -side, side)
    vx, vy = _velocity(pre.wind.up_x[row], pre.wind.up_y[row], sigma, sx, sy)
    pen = _penalty(twa, m.penalty_up_s[row], m.penalty_down_s[row], xp)
    free = m.free[row]
    pending = m.pending[row]
    debt = xp.where(
        switch,
        xp.where(free, 0.0, pen),
        xp.where(pending, xp.maximum(m.debt_s[row] + pen - m.charged_s[row], 0.0), 0.0),
    )
    delay = xp.minimum(debt, dt)
    move = dt - delay
    in_manoeuvre = xp.where(switch, ~free, pending) & ~(move > 0)
    x, y = pre.x[row] + move * vx, pre.y[row] + move * vy
    if pre.current_x is not None:  # drift with the water for the whole step
        x, y = x + dt * pre.current_x[row], y + dt * pre.current_y[row]
    t_new = pre.t + dt if isinstance(pre.t, float) else pre.t[row] + dt  # per point: members
    layer = _Layer(
        t=t_new,
        x=x,
        y=y,
        side=sigma,
        debt=debt - delay,
        abs_twa=twa,
        pend_old=xp.where(in_manoeuvre, m.base_twa_deg[row], np.nan),
        pend_pen=xp.where(in_manoeuvre, pen, 0.0),
        parent=row,
        heading=xp.mod(xp.degrees(xp.arctan2(vx, vy)), 360.0),
        bsp=bsp,
        delay=delay,
        tau_est=score,
    )
    return layer, (move > 0) & (bsp > 0)


# --------------------------------------------------------------------------------------
# one step: the inputs (wind, aim, exact columns, time to go, manoeuvres)


def _wind_state(u: Any, v: Any, dev: _DeviceTables, fr: _LegFrame, xp: ModuleType) -> _PointWind:
    """The wind ``(u, v)`` [m s⁻¹] (world frame, towards; any shape) for the kernel."""
    tws = xp.sqrt(u * u + v * v)
    windy = tws > _CALM_MS
    inv = 1.0 / xp.where(windy, tws, 1.0)
    up_x, up_y = fr.vec_to_leg(xp.where(windy, -u * inv, 0.0), xp.where(windy, -v * inv, 1.0))
    nodes = dev.tws_ms
    row = clip(xp.searchsorted(nodes, tws, side="right") - 1, 0, nodes.shape[0] - 2, xp=xp)
    weight = clip((tws - nodes[row]) / (nodes[row + 1] - nodes[row]), 0.0, 1.0, xp=xp)
    up_deg = dev.up_deg[row] + weight * (dev.up_deg[row + 1] - dev.up_deg[row])
    down_deg = dev.down_deg[row] + weight * (dev.down_deg[row + 1] - dev.down_deg[row])
    return _PointWind(tws, up_x, up_y, row, weight, up_deg, down_deg)


def _time_to_go(
    wind: _PointWind,
    ex: Any,
    ey: Any,
    dist: Any,
    sides: Any,
    free: Any,
    tack_s: float,
    gybe_s: float,
    dev: _DeviceTables,
    xp: ModuleType,
) -> tuple[Any, Any, Any]:
    """Time to go over ``dist`` [m] along the unit vector ``(ex, ey)``, and its gradient.

    Two ways to get there, the faster counts:

    * straight, at ``S(beta)`` (``beta``: angle between the way and the upwind unit
      vector ``ŵ``), plus a tack or gybe if the way lies on the other side of the
      wind than the point's side (``sides``);
    * inside the upwind (downwind) VMG cone, two boards at the VMG angles,
      ``v·ŵ / VMG_up`` (``-v·ŵ / VMG_dn``), plus one tack (gybe).

    Points with no side yet (``free``) pay no penalty; then this is the time on the
    convex VMG hull of the polar.  The gradient ``G`` (``tau = v·G + penalty``) gives the
    change of ``tau`` for a small move ``d``: ``tau(P + d) ≈ tau(P) - d·G``.  Speeds come
    from the polar tables (this only ranks candidates).  Calm: ``tau`` is huge and
    ``G = 0``.  ``sides`` and the way may have a leading axis (2, n) over the wind's (n,).

    Returns ``tau`` [s] and ``G`` [s m⁻¹] (x and y).
    """
    up_x, up_y, node, weight = wind.up_x, wind.up_y, wind.row, wind.weight
    cos_b = clip(up_y * ey + up_x * ex, -1.0, 1.0, xp=xp)
    sin_b = up_x * ey - up_y * ex
    beta_deg = xp.degrees(xp.arccos(cos_b))
    vmg_up = dev.up_vmg_ms[node] + weight * (dev.up_vmg_ms[node + 1] - dev.up_vmg_ms[node])
    vmg_dn = dev.down_vmg_ms[node] + weight * (dev.down_vmg_ms[node + 1] - dev.down_vmg_ms[node])
    # polar speed and slope dS/dbeta at the direct angle, from the grid table
    na = dev.twa_deg.shape[0]
    step = 180.0 / na
    pos = beta_deg * (1.0 / step) - 1.0
    col = clip(xp.floor(pos).astype(xp.int64), 0, na - 2, xp=xp)
    frac = clip(pos - col, 0.0, 1.0, xp=xp)
    sp = dev.speed_ms
    s_l = sp[node, col] + weight * (sp[node + 1, col] - sp[node, col])
    s_r = sp[node, col + 1] + weight * (sp[node + 1, col + 1] - sp[node, col + 1])
    spd = s_l + frac * (s_r - s_l)
    slope = (s_r - s_l) * (1.0 / math.radians(step))
    cone_up = (beta_deg <= wind.up_deg) & (vmg_up > 0)
    cone_dn = (beta_deg >= wind.down_deg) & (vmg_dn > 0) & ~cone_up
    cone = cone_up | cone_dn
    inv_s = 1.0 / xp.where(spd > 0, spd, 1.0)
    inv_v = xp.where(
        cone_up, 1.0 / xp.where(cone_up, vmg_up, 1.0), -1.0 / xp.where(cone_dn, vmg_dn, 1.0)
    )
    t_straight = xp.where(spd > 0, dist * inv_s, np.inf)
    t_cone = xp.where(cone, dist * cos_b * inv_v, np.inf)
    own = free | (sides * sin_b >= 0)
    paid = ~free
    t_straight = t_straight + xp.where(own | ~paid, 0.0, xp.where(beta_deg < 90.0, tack_s, gybe_s))
    t_cone = t_cone + xp.where(paid, xp.where(cone_up, tack_s, gybe_s), 0.0)
    use_cone = t_cone < t_straight
    tau = xp.minimum(t_cone, t_straight)
    sin_abs = xp.sqrt(xp.maximum(1.0 - cos_b * cos_b, 1e-18))
    k = slope * inv_s * inv_s / sin_abs
    along_up = xp.where(use_cone, inv_v, k)  # G = along_up ŵ + along_way e
    along_way = xp.where(use_cone, 0.0, inv_s - k * cos_b)
    ok = tau < np.inf
    tau = xp.where(dist > 0, xp.where(ok, tau, _BIG_S), 0.0)
    along_up = xp.where(ok, along_up, 0.0)
    along_way = xp.where(ok, along_way, 0.0)
    return tau, along_up * up_x + along_way * ex, along_up * up_y + along_way * ey


def _support(
    node: Any, weight: Any, beta_deg: Any, dev: _DeviceTables, xp: ModuleType
) -> tuple[Any, Any]:
    """Polar support towards ``beta_deg`` (from the upwind direction, towards the side)
    at the table rows ``node, weight``: the best speed component [m s⁻¹] and its |TWA|
    [°], interpolated bilinearly in (TWS, beta) from :attr:`PolarTables.sup_ms`."""
    pos = (beta_deg + 180.0) * (dev.sup_ms.shape[1] - 1) / 360.0
    col = clip(xp.floor(pos).astype(xp.int64), 0, dev.sup_ms.shape[1] - 2, xp=xp)
    frac = clip(pos - col, 0.0, 1.0, xp=xp)
    out = []
    for tab in (dev.sup_ms, dev.sup_deg):
        below = tab[node, col] + frac * (tab[node, col + 1] - tab[node, col])
        above = tab[node + 1, col] + frac * (tab[node + 1, col + 1] - tab[node + 1, col])
        out.append(below + weight * (above - below))
    return out[0], out[1]


def _fastest_aim(
    x: Any,
    y: Any,
    ex: Any,
    ey: Any,
    dist: Any,
    side: Any,
    wind: _PointWind,
    g: TargetGeometry,
    dev: _DeviceTables,
    xp: ModuleType,
    cur: tuple[Any, Any] | None = None,
) -> tuple[Any, Any, Any]:
    """Aim points on the target segment that the local wind reaches soonest, per side.

    The heading that reaches the segment's line soonest maximises the speed component
    along the segment normal ``n`` (:func:`_support`).  For side ``σ = side`` (block
    ``_KEEP``) and side ``-σ`` (block ``_SWITCH``) that heading is taken on the side
    itself if it approaches the line at all, else on the other side.  Followed from
    ``P = (x, y)`` it meets the line at ``Q*``; the aim point is ``Q*`` kept
    ``AIM_MARGIN_M`` inside the segment.  Where no heading approaches the line, the
    projection of ``P`` (``ex, ey, dist`` passed in) is kept.  This makes the direct
    candidate the exact best heading to a line or gate in uniform wind.  In a current
    ``cur`` (leg frame) the same heading is fastest (the current adds the same normal
    speed to every heading) but its track over the ground, ``S·d + C``, meets the line
    elsewhere.

    Returns the unit vectors ``(ex, ey)`` to the aim points and their distances [m],
    each of shape (2, n): row 0 for side ``σ``, row 1 for side ``-σ``.
    """
    up_x, up_y = wind.up_x, wind.up_y
    nx, ny = g.normal
    p = up_x * nx + up_y * ny  # cos and sin of the angle from ŵ to n
    q = up_x * ny - up_y * nx
    sides = xp.stack([side, -side])
    best, ang = _support(wind.row, wind.weight, xp.degrees(xp.arctan2(sides * q, p)), dev, xp)
    use_own = best > 0  # else take the heading of the other side (needs a manoeuvre)
    sig = xp.where(use_own, sides, -sides)
    best = xp.where(use_own, best, best[::-1])
    rb = xp.radians(xp.where(use_own, ang, ang[::-1]))
    ca_b, sa_b = xp.cos(rb), xp.sin(rb)
    dx = up_x * ca_b - sig * up_y * sa_b  # heading unit vector on side sig
    dy = up_y * ca_b + sig * up_x * sa_b
    ax0, ay0 = g.a
    ahead = (ax0 - x) * nx + (ay0 - y) * ny  # distance to the segment's line along n
    dn = dx * nx + dy * ny
    ok = (best > 0) & (dn > 1e-9) & (ahead > 0)
    if cur is not None:  # ground track: speed S = best / dn along d, plus the current
        spd = best / xp.where(ok, dn, 1.0)
        dx, dy = spd * dx + cur[0], spd * dy + cur[1]
        dn = dx * nx + dy * ny
        ok = ok & (dn > 1e-9)
    t = xp.where(ok, ahead / xp.where(ok, dn, 1.0), 0.0)
    length = g.length_m
    ux, uy = (g.b[0] - ax0) / length, (g.b[1] - ay0) / length
    m = min(AIM_MARGIN_M, 0.5 * length)
    r = clip((x + t * dx - ax0) * ux + (y + t * dy - ay0) * uy, m, length - m, xp=xp)
    vx = ax0 + r * ux - x
    vy = ay0 + r * uy - y
    d2 = xp.sqrt(vx * vx + vy * vy)
    use = ok & (d2 > 0)
    inv = 1.0 / xp.where(use, d2, 1.0)
    return xp.where(use, vx * inv, ex), xp.where(use, vy * inv, ey), xp.where(use, d2, dist)


_CRAB_ITERATIONS = 8
"""Fixed-point iterations of the crab angle of the direct column in a current."""
_TTG_ITERATIONS = 4
"""Newton iterations of the time to go in a current."""


def _crab(
    ex: Any,
    ey: Any,
    cx: Any,
    cy: Any,
    wind: _PointWind,
    polar: Polar,
    xp: ModuleType,
) -> tuple[Any, Any, Any, Any]:
    """The direct column in a current: the heading through the water whose velocity
    over the ground, ``S(TWA(h))·w(h) + C``, points along the unit vectors ``(ex, ey)``.

    Fixed-point iteration on the crab angle ``phi`` (from ``e`` towards the
    perpendicular ``p``): ``sin(phi) = -C·p / S(phi)``.  Where no heading can hold the
    line (``|C·p| >= S``, or no speed) the still-water direction ``e`` is kept.

    Returns ``cos``/signed ``sin`` of the heading against the upwind unit vector
    ``ŵ``, its ``|TWA|`` [°] and boat speed [m s⁻¹], as the still-water columns.
    """
    up_x, up_y = wind.up_x, wind.up_y
    px, py = ey, -ex
    cp = cx * px + cy * py
    wx, wy = ex, ey
    tws_h = to_numpy(wind.tws_ms)
    for _ in range(_CRAB_ITERATIONS):
        a_d = xp.degrees(xp.arccos(clip(up_y * wy + up_x * wx, -1.0, 1.0, xp=xp)))
        spd = xp.asarray(polar.speed(tws_h, to_numpy(a_d)), dtype=float)
        q = -cp / xp.where(spd > 0, spd, 1.0)
        q = xp.where((spd > 0) & (xp.abs(q) < 1.0), q, 0.0)
        r = xp.sqrt(1.0 - q * q)
        wx, wy = r * ex + q * px, r * ey + q * py
    cos_d = clip(up_y * wy + up_x * wx, -1.0, 1.0, xp=xp)
    a_d = xp.degrees(xp.arccos(cos_d))
    v_d = xp.asarray(polar.speed(tws_h, to_numpy(a_d)), dtype=float)
    return cos_d, up_x * wy - up_y * wx, a_d, v_d


def _time_to_go_current(
    tau: Any,
    gx: Any,
    gy: Any,
    wind: _PointWind,
    ex: Any,
    ey: Any,
    dist: Any,
    cx: Any,
    cy: Any,
    sides: Any,
    free: Any,
    ctx: _Context,
    dev: _DeviceTables,
    xp: ModuleType,
) -> tuple[Any, Any, Any]:
    """Time to go in a current ``C`` (averaged along the way, leg frame) and its gradient.

    In the water the target drifts by ``-C`` per second, so the time to go solves
    ``tau = T(D - C tau)`` with ``T`` the still-water :func:`_time_to_go` and ``D``
    the way over the ground (Newton iterations from the still-water ``tau``; a plain
    fixed-point step where ``1 + G·C`` is small).  The gradient is
    ``G / (1 + G·C)`` (implicit differentiation).
    """
    dx, dy = dist * ex, dist * ey
    for _ in range(_TTG_ITERATIONS):
        ok = tau < _BIG_S
        tt = xp.where(ok, tau, 0.0)
        wx, wy = dx - cx * tt, dy - cy * tt
        dw = xp.sqrt(wx * wx + wy * wy)
        pos = dw > 0
        inv = 1.0 / xp.where(pos, dw, 1.0)
        t_w, gx, gy = _time_to_go(
            wind,
            xp.where(pos, wx * inv, ex),
            xp.where(pos, wy * inv, ey),
            dw,
            sides,
            free,
            ctx.tack_s,
            ctx.gybe_s,
            dev,
            xp,
        )
        der = 1.0 + gx * cx + gy * cy
        newton = der > 0.25
        tau = xp.where(ok, tt - (tt - t_w) / xp.where(newton, der, 1.0), t_w)
        tau = xp.where(t_w >= _BIG_S, _BIG_S, xp.maximum(tau, 0.0))
    scale = 1.0 / xp.maximum(1.0 + gx * cx + gy * cy, 0.25)
    return tau, gx * scale, gy * scale


def _step_length(s: RoutingSettings, tau_hint: float) -> float:
    """``dt_s``, shortened to ``max(min_dt_s, tau_hint / NEAR_TARGET_STEPS)`` [s] once the
    estimated time to go ``tau_hint`` [s] is below ``NEAR_TARGET_STEPS`` steps."""
    dt = float(s.dt_s)
    if tau_hint < NEAR_TARGET_STEPS * dt and s.min_dt_s < dt:
        dt = max(float(s.min_dt_s), tau_hint / NEAR_TARGET_STEPS)
    return dt


def _direction(dx: Any, dy: Any, xp: ModuleType) -> tuple[Any, Any, Any]:
    """Unit vector and length [m] of ``(dx, dy)``; the unit vector is ``(0, 1)`` where the
    length is zero."""
    dist = xp.sqrt(dx * dx + dy * dy)
    there = dist > 0
    inv_d = 1.0 / xp.where(there, dist, 1.0)
    return xp.where(there, dx * inv_d, 0.0), xp.where(there, dy * inv_d, 1.0), dist


def _sample_step(
    f: _Layer,
    dt: float,
    aim_x: Any,
    aim_y: Any,
    dist: Any,
    wind: WindField,
    ctx: _Context,
    s: RoutingSettings,
    xp: ModuleType,
) -> tuple[Any, Any, _Current | None]:
    """The wind ``(u, v)`` [m s⁻¹] (world frame) of the step, shape
    (``PATH_SAMPLES + 1``, n), and the current (None: still or slack water).

    Row 0: at mid-step time at each point's predicted mid-step position (half a step
    along its previous move); rows 1.. on the straight line to the aim point
    ``(aim_x, aim_y)`` at their estimated passing times.  One ``wind.sample`` call, the
    points clipped to the coverage.
    """
    x, y = f.x, f.y
    n = int(x.shape[0])
    cov = wind.coverage
    t_mid = f.t + 0.5 * dt
    hr = xp.radians(f.heading)
    half = xp.where(f.debt > 0, 0.0, 0.5 * dt * f.bsp)
    horizon = xp.where(
        xp.isnan(f.tau_est),
        dist * (1.0 / _ROOT_SPEED_MS),
        xp.minimum(f.tau_est, float(s.max_leg_time_s)),
    )
    fk = (xp.arange(PATH_SAMPLES, dtype=float) + 0.5) / PATH_SAMPLES
    px = xp.concatenate([x + half * xp.sin(hr), (x + fk[:, None] * (aim_x - x)).reshape(-1)])
    py = xp.concatenate([y + half * xp.cos(hr), (y + fk[:, None] * (aim_y - y)).reshape(-1)])
    pt = xp.concatenate([xp.full(n, t_mid), (t_mid + fk[:, None] * horizon).reshape(-1)])
    wx, wy = ctx.frame.to_world(px, py)
    pts = (
        to_numpy(clip(pt, cov.t0, cov.t1, xp=xp)),
        to_numpy(clip(wx, cov.xmin, cov.xmax, xp=xp)),
        to_numpy(clip(wy, cov.ymin, cov.ymax, xp=xp)),
    )
    u, v = wind.sample(*pts)
    u = xp.asarray(u, dtype=float).reshape(PATH_SAMPLES + 1, n)
    v = xp.asarray(v, dtype=float).reshape(PATH_SAMPLES + 1, n)
    if ctx.current is None:
        return u, v, None
    cu, cv = ctx.current.sample(*pts)
    cu, cv = ctx.frame.vec_to_leg(
        xp.asarray(cu, dtype=float).reshape(PATH_SAMPLES + 1, n),
        xp.asarray(cv, dtype=float).reshape(PATH_SAMPLES + 1, n),
    )
    if not (bool(xp.any(cu != 0.0)) or bool(xp.any(cv != 0.0))):  # slack water: still water
        return u, v, None
    return u, v, _Current(cu[0], cv[0], xp.mean(cu, axis=0), xp.mean(cv, axis=0))


def _fan(dev: _DeviceTables, wind: _PointWind, hull: bool, xp: ModuleType) -> tuple[int, int]:
    """Grid columns ``first:stop`` tried: the whole circle, or (``hull``) those strictly
    between the smallest upwind and the largest downwind VMG angle of the front."""
    first, stop = 0, int(dev.twa_deg.shape[0])
    if hull:
        lo_h = int(xp.searchsorted(dev.twa_deg, xp.min(wind.up_deg), side="right"))
        hi_h = int(xp.searchsorted(dev.twa_deg, xp.max(wind.down_deg), side="left"))
        if hi_h > lo_h:
            first, stop = lo_h, hi_h
    return first, stop


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


def _least(values: Any, groups: Groups | None, xp: ModuleType) -> Any:
    """Smallest of ``values``, as a float, or per member (array of shape (M,))."""
    if groups is None:
        return float(xp.min(values))
    least = np.minimum.reduceat(values, groups.starts, axis=-1)
    return least.min(axis=0) if least.ndim > 1 else least


def _group_fans(
    dev: _DeviceTables, wind: _PointWind, hull: bool, groups: Groups
) -> tuple[int, int, Any, Any]:
    """:func:`_fan` per member: the common grid columns ``first:stop`` (all members'
    fans together) and each point's own ``fan_lo, fan_hi`` (shape (n,))."""
    n_a = int(dev.twa_deg.shape[0])
    lo = np.zeros(groups.n_members, dtype=np.int64)
    hi = np.full(groups.n_members, n_a, dtype=np.int64)
    if hull:
        lo_h = np.searchsorted(
            dev.twa_deg, np.minimum.reduceat(wind.up_deg, groups.starts), side="right"
        )
        hi_h = np.searchsorted(
            dev.twa_deg, np.maximum.reduceat(wind.down_deg, groups.starts), side="left"
        )
        ok = hi_h > lo_h
        lo, hi = np.where(ok, lo_h, lo), np.where(ok, hi_h, hi)
    return int(lo.min()), int(hi.max()), lo[groups.member], hi[groups.member]


def _exact_columns(
    wind: _PointWind,
    aim_x: Any,
    aim_y: Any,
    cur: _Current | None,
    polar: Polar,
    xp: ModuleType,
) -> _ExactColumns:
    """VMG up, VMG down and the direct columns to the aim points ``(aim_x, aim_y)`` (unit
    vectors, shape (2, n): own side, other side); boat speeds from :meth:`Polar.speed`.
    In a current the direct heading is the one whose ground track goes to the aim
    (:func:`_crab`)."""
    tws_h = to_numpy(wind.tws_ms)
    v_vmg = xp.asarray(
        polar.speed(tws_h[:, None], to_numpy(xp.stack([wind.up_deg, wind.down_deg], 1))),
        dtype=float,
    )
    if cur is None:
        cos_d = clip(wind.up_y * aim_y + wind.up_x * aim_x, -1.0, 1.0, xp=xp)  # (2, n)
        sin_d = wind.up_x * aim_y - wind.up_y * aim_x
        a_d = xp.degrees(xp.arccos(cos_d))
        v_d = xp.asarray(polar.speed(to_numpy(wind.tws_ms), to_numpy(a_d)), dtype=float)
    else:
        cos_d, sin_d, a_d, v_d = _crab(aim_x, aim_y, cur.move_x, cur.move_y, wind, polar, xp)
    twa = xp.concatenate([wind.up_deg[:, None], wind.down_deg[:, None], a_d.T], axis=1)
    rad = xp.radians(twa[:, :2])
    return _ExactColumns(
        twa_deg=twa,
        bsp_ms=xp.concatenate([v_vmg, v_d.T], axis=1),
        cos_twa=xp.concatenate([xp.cos(rad), cos_d.T], axis=1),
        sin_twa=xp.concatenate([xp.sin(rad), xp.abs(sin_d).T], axis=1),
        direct_sin_keep=sin_d[0],
        direct_sin_switch=sin_d[1],
    )


def _manoeuvre_state(f: _Layer, ctx: _Context, xp: ModuleType) -> _ManoeuvreState:
    """Sides and penalty prices of the front ``f``.

    The penalty of a side change depends on the |TWA| before it (``base_twa_deg``: the
    one before the pending manoeuvre, else the last one sailed) and the first one
    sailed after it (upwind < 90° <= downwind): a tack if both are upwind, a gybe if
    both downwind, the larger of the two if mixed or the old one unknown at the start
    (then: tack onto upwind, gybe onto downwind).
    """
    pending = ~xp.isnan(f.pend_old)
    base = xp.where(pending, f.pend_old, f.abs_twa)
    mixed = max(ctx.tack_s, ctx.gybe_s)
    unknown = xp.isnan(base)
    return _ManoeuvreState(
        side=xp.where(f.side < 0, -1.0, 1.0),
        free=f.side == 0,
        pending=pending,
        base_twa_deg=base,
        penalty_up_s=xp.where(unknown | (base < 90.0), ctx.tack_s, mixed),
        penalty_down_s=xp.where(unknown | (base >= 90.0), ctx.gybe_s, mixed),
        debt_s=f.debt,
        charged_s=f.pend_pen,
        any_pending=bool(xp.any(pending)),
    )


def _within_reach(
    x: Any,
    y: Any,
    step_m: Any,
    ctx: _Context,
    xp: ModuleType,
    first_clear: Any = None,
) -> tuple[Any, tuple[Any, ...]]:
    """Points whose move (at most ``step_m`` [m], shape (n,)) can reach the target segment,
    and per barrier of the leg those that can reach its ray (None where no point can);
    ``first_clear``: the first barrier's clearance per point [m] (shape (n,)), or None."""
    near = _segment_distance(x, y, ctx.geom, xp) <= step_m + 1e-6
    near_barrier = []
    for i, (b, clear) in enumerate(ctx.barriers):
        if i == 0 and first_clear is not None:
            clear = first_clear
        ray = TargetGeometry(
            b.mark,
            (b.mark[0] + BARRIER_LENGTH_M * b.ray[0], b.mark[1] + BARRIER_LENGTH_M * b.ray[1]),
            b.normal,
            "ray",
        )
        close = _segment_distance(x, y, ray, xp) <= step_m + clear + 1e-3
        near_barrier.append(close if bool(xp.any(close)) else None)
    return near, tuple(near_barrier)


def _prepare(
    f: _Layer,
    wind: WindField,
    polar: Polar,
    dev: _DeviceTables,
    ctx: _Context,
    s: RoutingSettings,
    tau_hint: float,
    xp: ModuleType,
    groups: Groups | None = None,
) -> tuple[_StepInputs, Any, Any]:
    """Step length, wind, VMG angles, direct bearing and time to go of the front points.

    * The step is ``dt_s``, shortened to ``max(min_dt_s, tau / 3)`` once the estimated
      time to go ``tau`` (from the previous step, ``tau_hint``) is below three steps.
    * Each move uses one wind sample, taken at mid-step time at the point's predicted
      mid-step position (half a step along its previous move): second order in time and,
      for a boat holding its course, in space.
    * The time to go that ranks candidates is the gauge of the VMG hull in the wind
      averaged along the straight line to the target (the point, and ``PATH_SAMPLES``
      points on the line at their estimated passing times), so the pruning judges a
      position by the wind still ahead rather than by the wind where it is now.

    All wind samples of the step go through one ``wind.sample`` call.  Returns the
    inputs of the kernel, the front's least estimated time to go [s] and its least
    distance to the aim points [m] (with ``groups``: per member, arrays of shape (M,)).
    """
    x, y = f.x, f.y
    dt = _step_length(s, tau_hint)
    aim_x, aim_y = aim_points(x, y, ctx.geom, xp=xp)  # direct bearing to the aim point
    ex, ey, dist = _direction(aim_x - x, aim_y - y, xp)
    u, v, cur = _sample_step(f, dt, aim_x, aim_y, dist, wind, ctx, s, xp)
    move_wind = _wind_state(u[0], v[0], dev, ctx.frame, xp)
    if groups is None:
        first, stop = _fan(dev, move_wind, ctx.fan_hull, xp)
        fan_lo = fan_hi = None
    else:
        first, stop, fan_lo, fan_hi = _group_fans(dev, move_wind, ctx.fan_hull, groups)

    # aim, per side, at the point of the target segment reached fastest in this wind
    man = _manoeuvre_state(f, ctx, xp)
    sides = xp.stack([man.side, -man.side])
    aex, aey, adist = _fastest_aim(
        x,
        y,
        ex,
        ey,
        dist,
        man.side,
        move_wind,
        ctx.geom,
        dev,
        xp,
        None if cur is None else (cur.move_x, cur.move_y),
    )
    exact = _exact_columns(move_wind, aex, aey, cur, polar, xp)

    # time to go on either side, in the wind averaged along the way
    mean_wind = _wind_state(xp.mean(u, axis=0), xp.mean(v, axis=0), dev, ctx.frame, xp)
    tau, gx, gy = _time_to_go(
        mean_wind, aex, aey, adist, sides, man.free, ctx.tack_s, ctx.gybe_s, dev, xp
    )
    if cur is not None:
        tau, gx, gy = _time_to_go_current(
            tau,
            gx,
            gy,
            mean_wind,
            aex,
            aey,
            adist,
            cur.mean_x,
            cur.mean_y,
            sides,
            man.free,
            ctx,
            dev,
            xp,
        )
    tau_min = _least(f.debt + tau[0], groups, xp)
    if cur is not None:  # the drift of the step is common to all candidates of a point
        tau = tau - dt * (gx * cur.move_x + gy * cur.move_y)
    dist_min = _least(adist, groups, xp)

    # the points a move can take to the target or a barrier
    top_ms = xp.maximum(
        xp.maximum(dev.vmax_ms[move_wind.row], dev.vmax_ms[move_wind.row + 1]),
        xp.max(exact.bsp_ms, axis=1),
    )
    if cur is not None:
        top_ms = top_ms + xp.sqrt(cur.move_x * cur.move_x + cur.move_y * cur.move_y)
    first_clear = (
        None if groups is None or groups.clearance is None else groups.clearance[groups.member]
    )
    near, near_barrier = _within_reach(x, y, top_ms * dt * 1.0001, ctx, xp, first_clear)
    box_clear = ctx.box is None or _box_holds(x, y, top_ms * dt * 1.0001, ctx, xp)

    pre = _StepInputs(
        t=f.t,
        dt=dt,
        first=first,
        stop=stop,
        x=x,
        y=y,
        wind=move_wind,
        exact=exact,
        keep=_TimeToGo(tau[0], gx[0], gy[0]),
        switch=_TimeToGo(tau[1], gx[1], gy[1]),
        manoeuvre=man,
        near_target=near,
        near_barrier=near_barrier,
        current_x=None if cur is None else cur.move_x,
        current_y=None if cur is None else cur.move_y,
        group=None if groups is None else groups.member,
        n_groups=1 if groups is None else groups.n_members,
        fan_lo=fan_lo,
        fan_hi=fan_hi,
        box_clear=box_clear,
        first_clear=first_clear,
    )
    return pre, tau_min, dist_min


# --------------------------------------------------------------------------------------
# one step: the candidate kernel


class _Block(NamedTuple):
    """The candidates of one block for a chunk of rows; arrays of shape (rows, columns).

    Columns: the block's grid columns, then its three exact columns
    (:data:`_EXACT_OF_BLOCK`).

    Attributes
    ----------
    block : int
        ``_KEEP`` or ``_SWITCH``.
    sigma : array, shape (rows,)
        The side sailed, +1 or -1.
    first : int
        The block's first grid column, counted from :attr:`_StepInputs.first`.
    bsp_ms, twa_deg : array
        Boat speed [m s⁻¹] and |TWA| [°].
    vx, vy : array
        Velocity through the water [m s⁻¹] (leg frame).
    rate : array
        Decrease of the time to go per second of move, ``G·v`` (no unit).
    """

    block: int
    sigma: Any
    first: int
    bsp_ms: Any
    twa_deg: Any
    vx: Any
    vy: Any
    rate: Any


class _Timing(NamedTuple):
    """Penalty timing of moves [s]: stopped first for ``delay``, then moving for
    ``move`` (``delay + move = dt``); ``debt`` still owed after the step."""

    delay: Any
    move: Any
    debt: Any


def _grid_speeds(c: _StepInputs, dev: _DeviceTables) -> Any:
    """Boat speed [m s⁻¹] of the grid columns, shape (rows, n_grid)."""
    node, weight = c.wind.row, c.wind.weight
    s_lo = dev.speed_ms[node, c.first : c.stop]
    return s_lo + weight[:, None] * (dev.speed_ms[node + 1, c.first : c.stop] - s_lo)


def _block(
    c: _StepInputs, grid_bsp: Any, block: int, first: int, dev: _DeviceTables, xp: ModuleType
) -> _Block:
    """Speed, |TWA|, velocity and time-to-go rate of the candidates of ``block``: grid
    columns from ``first`` on (of ``grid_bsp``, shape (rows, n_grid)), then the exact
    columns of the block."""
    rows = c.n
    lo, n_grid = c.first + first, c.n_grid - first
    exact = _EXACT_OF_BLOCK[block]
    bsp = xp.concatenate([grid_bsp[:, first:], c.exact.bsp_ms[:, exact]], axis=1)
    twa = xp.concatenate(
        [xp.broadcast_to(dev.twa_deg[lo : c.stop], (rows, n_grid)), c.exact.twa_deg[:, exact]],
        axis=1,
    )
    sx = bsp * xp.concatenate(
        [xp.broadcast_to(dev.cos_a[lo : c.stop], (rows, n_grid)), c.exact.cos_twa[:, exact]], axis=1
    )
    sy = bsp * xp.concatenate(
        [xp.broadcast_to(dev.sin_a[lo : c.stop], (rows, n_grid)), c.exact.sin_twa[:, exact]], axis=1
    )
    side = c.manoeuvre.side
    sigma = side if block == _KEEP else -side
    vx, vy = _velocity(c.wind.up_x[:, None], c.wind.up_y[:, None], sigma[:, None], sx, sy)
    ttg = c.keep if block == _KEEP else c.switch
    rate = ttg.grad_x[:, None] * vx + ttg.grad_y[:, None] * vy
    return _Block(block, sigma, first, bsp, twa, vx, vy, rate)


def _switch_timing(c: _StepInputs, switch: _Block, any_free: bool, xp: ModuleType) -> _Timing:
    """Timing of block ``_SWITCH``: the penalty of the new manoeuvre, priced by the
    heading sailed (none for a free point), is served first."""
    m = c.manoeuvre
    owed = _penalty(switch.twa_deg, m.penalty_up_s[:, None], m.penalty_down_s[:, None], xp)
    if any_free:
        owed[m.free] = 0.0
    delay = xp.minimum(owed, c.dt)
    return _Timing(delay, c.dt - delay, owed - delay)


def _keep_timing(c: _StepInputs, keep: _Block, sub: Any, xp: ModuleType) -> _Timing:
    """Timing of block ``_KEEP`` for the rows ``sub`` (shape (len(sub), n_columns)).

    A pending point re-prices its manoeuvre with the heading it now sails: it owes its
    debt plus the new price minus what was charged so far (at least 0); the others owe
    nothing.
    """
    m = c.manoeuvre
    owed = xp.zeros((sub.shape[0], c.n_columns))
    if m.any_pending and bool(xp.any(m.pending[sub])):
        pr = sub[m.pending[sub]]
        pos = xp.flatnonzero(m.pending[sub])
        price = _penalty(keep.twa_deg[pr], m.penalty_up_s[pr, None], m.penalty_down_s[pr, None], xp)
        owed[pos] = xp.maximum(m.debt_s[pr, None] + price - m.charged_s[pr, None], 0.0)
    delay = xp.minimum(owed, c.dt)
    return _Timing(delay, c.dt - delay, owed - delay)


def _drifted(c: _StepInputs, qx: Any, qy: Any) -> tuple[Any, Any]:
    """End points moved by the current over the whole step, stopped or not."""
    if c.current_x is None:
        return qx, qy
    return qx + c.dt * c.current_x[:, None], qy + c.dt * c.current_y[:, None]


def _keep_ends(
    c: _StepInputs, keep: _Block, pending: Any, pending_timing: _Timing | None
) -> tuple[Any, Any]:
    """End points [m] of the moves of block ``_KEEP``: a whole step, except for the
    pending rows (``pending``, with their ``pending_timing``), which may still owe time."""
    qx = c.x[:, None] + c.dt * keep.vx
    qy = c.y[:, None] + c.dt * keep.vy
    if pending_timing is not None:
        qx[pending] = c.x[pending, None] + pending_timing.move * keep.vx[pending]
        qy[pending] = c.y[pending, None] + pending_timing.move * keep.vy[pending]
    return _drifted(c, qx, qy)


def _switch_ends(c: _StepInputs, switch: _Block, timing: _Timing) -> tuple[Any, Any]:
    """End points [m] of the moves of block ``_SWITCH``, after the penalty stop."""
    return _drifted(
        c, c.x[:, None] + timing.move * switch.vx, c.y[:, None] + timing.move * switch.vy
    )


def _barrier_blocked(
    c: _StepInputs, ends: tuple[tuple[Any, Any], ...], ctx: _Context, xp: ModuleType
) -> list[Any] | None:
    """Per block, the moves (shape (rows, columns)) that pass a rounded mark on the wrong
    side (:func:`~sailroute.routing.geometry.barrier_blocks`, rows near a barrier
    only); None where no row is near one."""
    blocked = None
    for i, ((bar, clear), close) in enumerate(zip(ctx.barriers, c.near_barrier, strict=True)):
        nb = None if close is None else xp.flatnonzero(close)
        if nb is None or nb.shape[0] == 0:
            continue
        if i == 0 and c.first_clear is not None:  # members: each its own clearance
            clear = c.first_clear[nb][:, None]
        if blocked is None:
            blocked = [xp.zeros(qx.shape, dtype=bool) for qx, _ in ends]
        px_b, py_b = c.x[nb][:, None], c.y[nb][:, None]
        for mask, (qx, qy) in zip(blocked, ends, strict=True):
            mask[nb] |= barrier_blocks(px_b, py_b, qx[nb], qy[nb], bar, clear, xp=xp)
    return blocked


def _obstacle_blocked(
    c: _StepInputs,
    ends: tuple[tuple[Any, Any], ...],
    blocked: list[Any] | None,
    frame: _LegFrame,
    obstacles: Obstacles,
    xp: ModuleType,
) -> list[Any] | None:
    """``blocked`` (:func:`_barrier_blocked`) with the moves that leave free water added:
    each move from its row's point to its end, in the world frame
    (:meth:`~sailroute.routing.obstacles.Obstacles.moves_free`, which moves to the
    world frame only the ends it tests; the drift during a penalty pause is not tested
    separately)."""
    px, py = to_numpy(c.x), to_numpy(c.y)
    qx = np.concatenate([to_numpy(q[0]) for q in ends], axis=1)  # both blocks in one call
    qy = np.concatenate([to_numpy(q[1]) for q in ends], axis=1)
    bad = ~obstacles.moves_free(px, py, qx, qy, frame.to_world)
    if not bad.any():  # nothing more to mask
        return blocked
    cut = int(ends[0][0].shape[1])
    out = [xp.asarray(bad[:, :cut]), xp.asarray(bad[:, cut:])]
    return out if blocked is None else [b | o for b, o in zip(blocked, out, strict=True)]


def _blocked_error(f: _Layer, ctx: _Context, t: float) -> RoutingError:
    """No candidate move of the front ``f`` stays in free water."""
    assert ctx.obstacles is not None
    wx, wy = (to_numpy(v) for v in ctx.frame.to_world(f.x, f.y))
    name = ctx.obstacles.nearest_name(wx, wy)
    what = name if name.startswith("the ") else f"obstacle {name!r}"
    return RoutingError(
        f"leg {ctx.label}: no route round {what}: every move from the front "
        f"{t - ctx.t0:.0f} s after the leg start leaves free water ({ctx.obstacles.describe()}) "
        "or the wind coverage.\n  Try: check that the obstacles leave a passage to the "
        "target wider than their clearances, and that the boundary encloses the leg."
    )


def _arrival(
    c: _StepInputs,
    r0: int,
    blocks: tuple[_Block, _Block],
    ends: tuple[tuple[Any, Any], ...],
    timings: tuple[_Timing, _Timing],
    direct_ok: tuple[Any, Any],
    blocked: list[Any] | None,
    ctx: _Context,
    xp: ModuleType,
) -> _Arrival | None:
    """The earliest forward crossing of the target segment (rows within reach only).

    ``timings`` are those of the rows near the target (:attr:`_StepInputs.near_target`);
    a move crosses from its start (drifted by the current during its stop) to its end
    point, and counts if allowed: direct column on its side, no barrier passed on the
    wrong side, no second manoeuvre during a pending one, inside the coverage box.
    ``r0`` is the chunk's first row in the front.
    """
    m = c.manoeuvre
    near = xp.flatnonzero(c.near_target)
    arrival = None
    best_t = np.inf
    for blk, (qx, qy), timing, ok in zip(blocks, ends, timings, direct_ok, strict=True):
        px = c.x[near][:, None]
        py = c.y[near][:, None]
        if c.current_x is not None:  # the move starts after the drift of the penalty stop
            px = px + timing.delay * c.current_x[near, None]
            py = py + timing.delay * c.current_y[near, None]
        hit, frac, _ = segment_crossing(px, py, qx[near], qy[near], ctx.geom, xp=xp)
        hit[:, -1] &= ok[near]
        if blocked is not None:
            hit &= ~blocked[blk.block][near]
        if blk.block == _SWITCH and m.any_pending:
            hit &= ~m.pending[near, None]
        if ctx.box is not None and not c.box_clear:
            hit &= _in_box(qx[near], qy[near], ctx.frame, ctx.box)
        if not bool(xp.any(hit)):
            continue
        t_hit = xp.where(hit, timing.delay + frac * timing.move, np.inf)
        k = int(xp.argmin(t_hit.reshape(-1)))
        rr, col = divmod(k, int(t_hit.shape[1]))
        if float(t_hit[rr, col]) >= best_t:
            continue
        best_t = float(t_hit[rr, col])
        p = int(near[rr])
        ds = float(frac[rr, col])
        x0, y0 = float(px[rr, 0]), float(py[rr, 0])
        end_x, end_y = float(qx[p, col]), float(qy[p, col])
        hd = (
            _heading_deg(end_x - x0, end_y - y0)
            if c.current_x is None  # through the water:
            else _heading_deg(float(blk.vx[p, col]), float(blk.vy[p, col]))
        )
        arrival = _Arrival(
            parent=r0 + p,
            t_start=c.t,
            t=c.t + best_t,
            x=x0 + ds * (end_x - x0),
            y=y0 + ds * (end_y - y0),
            heading=hd,
            bsp=float(blk.bsp_ms[p, col]),
            delay=float(timing.delay[rr, col]),
            side=int(blk.sigma[p]),
        )
    return arrival


def _keep_scores(c: _StepInputs, keep: _Block, pending: Any, pending_timing: _Timing | None) -> Any:
    """Estimated time to go after the moves of block ``_KEEP`` [s], ``τ - dt G·v`` (the
    pending rows: ``τ + debt - move G·v``)."""
    score = c.keep.tau_s[:, None] - c.dt * keep.rate
    if pending_timing is not None:
        score[pending] = (
            c.keep.tau_s[pending, None]
            + pending_timing.debt
            - pending_timing.move * keep.rate[pending]
        )
    return score


def _switch_scores(c: _StepInputs, switch: _Block, timing: _Timing) -> Any:
    """Estimated time to go after the moves of block ``_SWITCH`` [s],
    ``τ + debt - move G·v``."""
    return c.switch.tau_s[:, None] + timing.debt - timing.move * switch.rate


def _drop_forbidden(
    c: _StepInputs,
    scores: list[Any],
    ends: tuple[tuple[Any, Any], ...],
    direct_ok: tuple[Any, Any],
    blocked: list[Any] | None,
    ctx: _Context,
    xp: ModuleType,
) -> list[Any]:
    """Scores with the forbidden candidates at infinity: a direct column on the wrong
    side, a side change during a pending manoeuvre, a move past a rounded mark on the
    wrong side or out of the coverage box."""
    for score, ok in zip(scores, direct_ok, strict=True):
        score[:, -1] = xp.where(ok, score[:, -1], np.inf)
    if c.manoeuvre.any_pending:
        scores[_SWITCH][c.manoeuvre.pending] = np.inf
    if c.fan_lo is not None:  # members: only the grid columns of each one's own fan
        col = xp.arange(c.first, c.stop)[None, :]
        outside = (col < c.fan_lo[:, None]) | (col >= c.fan_hi[:, None])
        for score in scores:
            if score.shape[1] == c.n_columns:  # the block has the grid columns
                score[:, : c.n_grid][outside] = np.inf
    if blocked is not None:
        scores = [
            xp.where(mask, np.inf, score) for score, mask in zip(scores, blocked, strict=True)
        ]
    if ctx.box is not None and not c.box_clear:
        scores = [
            xp.where(_in_box(qx, qy, ctx.frame, ctx.box), score, np.inf)
            for score, (qx, qy) in zip(scores, ends, strict=True)
        ]
    return scores


def _sector_winners(
    c: _StepInputs,
    r0: int,
    blocks: tuple[_Block, _Block],
    ends: tuple[tuple[Any, Any], ...],
    scores: list[Any],
    ctx: _Context,
    xp: ModuleType,
) -> tuple[Any, Any, Any] | None:
    """The best candidate per bin: sector of the bearing seen from the target and side.

    Bins are ``ctx.sector_rad`` wide (float32 bearings are ample for binning); key =
    ``sector * 2 + side index`` (0 starboard, 1 port).  Returns the keys, scores [s]
    and candidate ids (see :data:`_KEEP`) of the winners, or None if every score is
    infinite.
    """
    scale = np.float32(1.0 / ctx.sector_rad)
    off = np.float32(ctx.n_bins // 2 + 0.5)  # keeps the argument positive: astype = floor
    port = (c.manoeuvre.side < 0).astype(xp.int64)[:, None]  # side index of block _KEEP
    keys = []
    for (qx, qy), side_index in zip(ends, (port, 1 - port), strict=True):
        phi = xp.arctan2(qx.astype(xp.float32), qy.astype(xp.float32))
        kb = (phi * scale + off).astype(xp.int64)
        kb *= 2
        kb += side_index
        keys.append(kb.reshape(-1))
    key = xp.concatenate(keys)
    if c.group is not None:  # one set of bins per member
        offset = (c.group * (2 * ctx.n_bins))[:, None]
        key += xp.concatenate([xp.broadcast_to(offset, s.shape).reshape(-1) for s in scores])
    score = xp.concatenate([scores[0].reshape(-1), scores[1].reshape(-1)])
    flat = _group_argmin(key, score, 2 * ctx.n_bins * c.n_groups, xp)
    if flat.shape[0] == 0:
        return None
    h = c.n_columns
    n_keep = c.n * h
    in_keep = flat < n_keep
    f1 = flat - n_keep
    first = blocks[_SWITCH].first
    h1 = h - first
    wid = xp.where(
        in_keep,
        ((r0 + flat // h) * 2 + _KEEP) * h + flat % h,
        ((r0 + f1 // h1) * 2 + _SWITCH) * h + first + f1 % h1,
    )
    return key[flat], score[flat], wid


def _expand(
    pre: _StepInputs,
    r0: int,
    r1: int,
    dev: _DeviceTables,
    ctx: _Context,
    xp: ModuleType,
    want_winners: bool,
) -> tuple[_Arrival | None, tuple[Any, Any, Any] | None]:
    """Candidates of front points ``r0:r1``: arrival check and per-sector winners.

    Two blocks of candidates: block ``_KEEP`` keeps the point's side ``σ`` (+1 for a
    free start) and tries every column (grid slice, VMG up, VMG down, direct to its aim
    point); block ``_SWITCH`` changes side and tries the exact columns only (VMG up, VMG
    down, direct to the other side's aim point; all grid columns too when a free start
    point is in the chunk, which pays no penalty).  Any other heading on the new side is
    one step away at no cost, so this loses at most one step at a slightly different
    angle.  Each block is scored with the time to go of its own side.

    Steps: velocities of the two blocks (:func:`_block`), manoeuvre timing
    (:func:`_switch_timing`, :func:`_keep_timing`), end points with the current's drift,
    barrier blocking, arrival (:func:`_arrival`); then, unless arrived, scores
    (estimated time to go after the move) and the best candidate per sector and side
    (:func:`_sector_winners`).
    """
    c = pre.rows(r0, r1, xp)
    m = c.manoeuvre
    any_free = bool(xp.any(m.free))
    grid_bsp = _grid_speeds(c, dev)
    keep = _block(c, grid_bsp, _KEEP, 0, dev, xp)
    switch = _block(c, grid_bsp, _SWITCH, 0 if any_free else c.n_grid, dev, xp)

    # penalties as time debt: the penalty of a manoeuvre is fixed by the first heading
    # actually sailed after it (pending points re-price it); no turning back inside one
    switch_timing = _switch_timing(c, switch, any_free, xp)
    pending = xp.flatnonzero(m.pending) if m.any_pending else None
    pending_timing = None if pending is None else _keep_timing(c, keep, pending, xp)
    ends = (_keep_ends(c, keep, pending, pending_timing), _switch_ends(c, switch, switch_timing))
    # the direct columns exist on their own side only
    direct_ok = (m.side * c.exact.direct_sin_keep >= 0, m.side * c.exact.direct_sin_switch <= 0)
    blocked = _barrier_blocked(c, ends, ctx, xp)
    if ctx.obstacles is not None:
        blocked = _obstacle_blocked(c, ends, blocked, ctx.frame, ctx.obstacles, xp)

    arrival = None
    near = xp.flatnonzero(c.near_target)
    if near.shape[0] > 0:
        near_timing = (
            _keep_timing(c, keep, near, xp),
            _Timing(switch_timing.delay[near], switch_timing.move[near], None),
        )
        arrival = _arrival(c, r0, (keep, switch), ends, near_timing, direct_ok, blocked, ctx, xp)
    if not want_winners or arrival is not None:
        return arrival, None

    scores = [
        _keep_scores(c, keep, pending, pending_timing),
        _switch_scores(c, switch, switch_timing),
    ]
    scores = _drop_forbidden(c, scores, ends, direct_ok, blocked, ctx, xp)
    if ctx.bin_origin is not None:  # sectors seen from the start: see _Context.bin_origin
        ox, oy = ctx.bin_origin
        ends = ((ends[0][0] - ox, ends[0][1] - oy), (ends[1][0] - ox, ends[1][1] - oy))
    return None, _sector_winners(c, r0, (keep, switch), ends, scores, ctx, xp)


def _in_box(qx: Any, qy: Any, fr: _LegFrame, box: tuple[float, float, float, float]) -> Any:
    """Candidates (leg frame) whose world position lies inside the coverage box."""
    wx, wy = fr.to_world(qx, qy)
    return (wx >= box[0]) & (wx <= box[1]) & (wy >= box[2]) & (wy <= box[3])


def _box_holds(x: Any, y: Any, reach_m: Any, ctx: _Context, xp: ModuleType) -> bool:
    """Whether every move of the step stays in the coverage box ``ctx.box``: each point
    (leg frame) with its reach [m] (shape (n,)) lies that far inside it."""
    assert ctx.box is not None
    wx, wy = ctx.frame.to_world(x, y)
    xmin, xmax, ymin, ymax = ctx.box
    return bool(
        xp.all(
            (wx - reach_m >= xmin)
            & (wx + reach_m <= xmax)
            & (wy - reach_m >= ymin)
            & (wy + reach_m <= ymax)
        )
    )


def _segment_distance(x: Any, y: Any, g: TargetGeometry, xp: ModuleType) -> Any:
    """Distance from the points ``(x, y)`` to the segment ``g.a``-``g.b`` [m]."""
    ax, ay = g.a
    ex, ey = g.b[0] - ax, g.b[1] - ay
    ll = ex * ex + ey * ey
    r = clip(((x - ax) * ex + (y - ay) * ey) / ll, 0.0, 1.0, xp=xp)
    dx = x - (ax + r * ex)
    dy = y - (ay + r * ey)
    return xp.sqrt(dx * dx + dy * dy)


def _heading_deg(ux: float, uy: float) -> float:
    return math.degrees(math.atan2(ux, uy)) % 360.0
