"""Isochrone leg router: array fronts, per-side sector pruning, exact arrival.

The front at time ``t`` is a set of points, each with a position, a tack side
(+1 starboard, −1 port, 0 = not chosen yet at the leg start), a time debt
(penalty still to serve) and a parent index into the previous front.  One step
of length ``dt`` (10 s by default, shorter near the target):

1. one ``wind.sample`` call: each point's wind at mid-step time at its predicted
   mid-step position, plus samples along the straight line to the target;
2. candidates per point: keeping its side, a uniform grid of TWAs
   (``heading_step_deg``; with ``heading_fan="hull"`` only between the upwind and
   downwind VMG angles) plus three exact columns (VMG up, VMG down, direct to the
   point of the target reached soonest); changing side, the three exact columns;
3. boat speeds from the polar (grid columns through a cached table, exact columns
   through :meth:`Polar.speed`); every candidate moves in a straight line;
4. a side change owes ``tack_penalty_s`` or ``gybe_penalty_s`` as time: the point
   does not move until its debt is paid, so a 5 s penalty costs exactly 5 s whatever
   ``dt`` is; the penalty is priced with the first heading sailed after it;
5. every move near the target is tested against its crossing segment
   (:func:`~sailroute.routing.geometry.segment_crossing`); the earliest crossing,
   interpolated inside the step, ends the leg; moves that would pass a rounded mark on
   the wrong side (the leg's barriers: the target's entry barrier and
   ``Start.barrier``, :func:`~sailroute.routing.geometry.leg_barriers`) are dropped;
6. pruning: candidates are binned by their bearing seen from the target (sectors of
   ``prune_sector_deg``, symmetric about the leg axis) and side, and per bin the one
   with the least estimated time to go survives (VMG-hull time in the wind averaged
   along the way, with the manoeuvre the point still needs).

The route is then backtracked through the parent indices and turned into a
:class:`~sailroute.routing.types.Track` with the shared
:func:`~sailroute.routing.track.build_track`.  See ``docs/design/routing.md`` for the
method, the defaults and the measured accuracy and speed.
"""

from __future__ import annotations

import dataclasses
import math
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.model import BoatModel
from sailroute.boat.polar import Polar
from sailroute.current import CurrentField, RelativeWind, current_rate_set
from sailroute.errors import InputError, OutOfCoverageError, RoutingError
from sailroute.routing.geometry import (
    AIM_MARGIN_M,
    BARRIER_LENGTH_M,
    TargetGeometry,
    aim_points,
    barrier_blocks,
    leg_barriers,
    leg_label,
    segment_crossing,
    start_centre,
    start_points,
    target_barrier,
    target_geometry,
)
from sailroute.routing.track import build_track, make_leg_result
from sailroute.routing.types import (
    Barrier,
    LegResult,
    Router,
    RoutingSettings,
    Start,
    Target,
    Track,
    check_settings,
    side_sign,
)
from sailroute.wind.base import WindField

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


_TABLE_CACHE: weakref.WeakKeyDictionary[Any, dict[int, PolarTables]] = (
    weakref.WeakKeyDictionary()
)


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
    nodes = np.unique(np.concatenate([
        np.linspace(0.0, top, math.ceil(top / TABLE_TWS_STEP_MS) + 1),
        own[(own >= 0) & (own <= top)],
    ]))
    speed = np.asarray(polar.speed(nodes[:, None], a[None, :]), dtype=float)
    up, vu = _vmg_angles(polar, nodes, True)
    down, vd = _vmg_angles(polar, nodes, False)
    up = _backfill_calm(up, vu)
    down = _backfill_calm(down, vd)
    rad = np.radians(a)
    vmax = np.maximum(speed.max(axis=1), np.asarray(polar.speed(nodes, np.stack([up, down], 1).T)
                                                    ).max(axis=0))
    vu, vd = np.maximum(vu, 0.0), np.maximum(vd, 0.0)
    beta = np.linspace(-180.0, 180.0, 361)
    sup_ms, sup_deg = _support_table(a, speed, up, down, vu, vd, beta)
    tables = PolarTables(a, np.cos(rad), np.sin(rad), nodes, speed, up, down, vu, vd, vmax,
                         beta, sup_ms, sup_deg)
    per_polar[n_a] = tables
    return tables


def _support_table(
    a: NDArray, speed: NDArray, up: NDArray, down: NDArray, vu: NDArray, vd: NDArray,
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

    t: float  # time of this front [epoch s]
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


def _host(a: Any) -> NDArray:
    get = getattr(a, "get", None)
    if callable(get) and type(a).__module__.startswith("cupy"):
        return np.asarray(get())
    return np.asarray(a)


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


# --------------------------------------------------------------------------------------
# public entry point


def route_isochrone(
    start: Start,
    target: Target,
    t0: float,
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
    *,
    progress: Callable[[float], None] | None = None,
    xp: ModuleType = np,
    current: CurrentField | None = None,
) -> LegResult:
    """Fastest route of one leg by isochrones.

    Parameters
    ----------
    start : Start
        Start point, or start line (points every ``start_line_spacing_m`` are
        tried; the one the best route leaves from is ``LegResult.start_xy``).
    target : Target
        Mark with rounding side, gate or line (see ``routing/geometry.py``).
    t0 : float
        Start time [epoch s].
    wind : WindField
        Wind, sampled once per step at the front points.
    boat : BoatModel
        The boat: its steady polar (:meth:`~sailroute.boat.model.BoatModel.routing_polar`)
        is routed; a boat without one (the dynamic model) is refused.
    settings : RoutingSettings
        ``dt_s``, ``heading_step_deg``, penalties, ``initial_side`` and the
        isochrone options (``min_dt_s``, ``prune_sector_deg``,
        ``max_front_points``, ``heading_fan``, ``zone_m``,
        ``start_line_spacing_m``, ``max_leg_time_s``).
    progress : callable, optional
        Called after each step with the estimated fraction done, in [0, 1].
    xp : module
        Array module of the kernel (NumPy; the kernel uses CuPy-compatible
        operations, the wind and polar are sampled on the host).
    current : CurrentField, optional
        Surface current (water velocity over the ground, towards).  The polar is then
        entered with the wind relative to the water (:class:`~sailroute.current.RelativeWind`),
        each move goes over the ground by (velocity through the water + current) and
        the track carries SOG/COG; a boat stopped by a penalty drifts with the water.
        None (default): still water, the unchanged code path.

    Returns
    -------
    LegResult
        Built with :func:`~sailroute.routing.track.make_leg_result`; the track
        has one vertex per step of the chosen route, extra vertices where a
        penalty stops the boat, and the exact arrival point.

    Raises
    ------
    InputError
        Invalid settings or target geometry.
    RoutingError
        The front leaves the wind coverage entirely, or no route arrives
        within ``max_leg_time_s``.
    OutOfCoverageError
        The wind field cannot be sampled at the start, or the race outlasts
        its time span (propagated from the wind field).
    """
    label = leg_label(start, target)
    if current is not None:
        wind = RelativeWind(wind, current)
    check_settings(settings, label)
    _check_start_time(t0, label)
    polar = _routing_polar(boat, label)
    geom = target_geometry(target, start, settings.zone_m)
    tab = polar_tables(polar, settings.heading_step_deg)
    frame = _LegFrame.for_leg(geom.centre, start_centre(start))
    ctx = _context(label, float(t0), frame, geom, wind, settings,
                   leg_barriers(start, target), current)
    if ctx.box is not None:
        _check_target_covered(geom, ctx.box, wind, label)
    dev = _device_tables(tab, xp)

    wx0, wy0 = start_points(start, settings.start_line_spacing_m)
    x0, y0 = frame.to_leg(xp.asarray(wx0), xp.asarray(wy0))
    n0 = int(x0.shape[0])
    nan = xp.full(n0, np.nan)
    layers = [_Layer(
        t=float(t0), x=x0, y=y0, side=xp.full(n0, float(side_sign(settings.initial_side))),
        debt=xp.zeros(n0), abs_twa=nan, pend_old=nan, pend_pen=xp.zeros(n0),
        parent=xp.full(n0, -1, dtype=xp.int64), heading=xp.zeros(n0), bsp=xp.zeros(n0),
        delay=xp.zeros(n0), tau_est=nan,
    )]
    calm_since: float | None = None
    tau_hint = np.inf  # estimated time to go of the front [s]
    while True:
        out = _step(layers[-1], wind, polar, dev, ctx, settings, tau_hint, xp)
        if isinstance(out, _Arrival):
            track = _backtrack(layers, out, frame, wind, polar, (wx0, wy0), current)
            if progress is not None:
                progress(1.0)
            return make_leg_result(track, "isochrone",
                                   target_barrier(target, start, settings.zone_m))
        layer, moved, tau_min, dist_min = out
        if moved:
            calm_since = None
        elif calm_since is None:
            calm_since = layers[-1].t
        tau_hint = tau_min - (layer.t - layers[-1].t)
        layers.append(layer)
        elapsed = layer.t - t0
        if progress is not None:
            progress(float(elapsed / (elapsed + tau_min)) if tau_min < np.inf else 0.0)
        if elapsed >= settings.max_leg_time_s:
            raise _timeout_error(label, settings, elapsed, dist_min, calm_since, layer.t)


# --------------------------------------------------------------------------------------
# setup


def _check_start_time(t0: float, label: str) -> None:
    if not (isinstance(t0, int | float) and math.isfinite(t0)):
        raise InputError(
            f"leg {label}: the start time must be finite epoch seconds, got {t0!r}"
        )


def _routing_polar(boat: BoatModel, label: str) -> Polar:
    """The boat's steady polar; refuses a boat without one (the dynamic boat model)."""
    polar = boat.routing_polar() if isinstance(boat, BoatModel) else None
    if polar is not None:
        return polar
    hint = ""
    if isinstance(boat, BoatModel) and boat.dynamics() is not None:
        hint = (" For the dynamic boat model use router 'griddp' or 'spline', or route "
                "its steady polar (boat.steady_polar(tws_ms)) with the isochrone router.")
    raise InputError(
        f"leg {label}: the isochrone router needs a Polar (with .speed(tws, twa)), got "
        f"{type(boat).__name__}.{hint}"
    )


def _check_target_covered(
    geom: TargetGeometry, box: tuple[float, float, float, float], wind: WindField, label: str
) -> None:
    """Refuse a target that lies wholly outside the wind field's box."""
    inside = [box[0] <= x <= box[1] and box[2] <= y <= box[3] for x, y in (geom.a, geom.b)]
    if not any(inside):
        raise OutOfCoverageError(
            f"leg {label}: the target ({geom.kind} {geom.name!r} at ({geom.a[0]:.0f}, "
            f"{geom.a[1]:.0f}) - ({geom.b[0]:.0f}, {geom.b[1]:.0f}) m) lies outside the wind "
            f"field's coverage ({wind.coverage.describe()}).\n  Try: wind data that covers "
            "the whole course with a margin, or a wind field built with clamp=True."
        )


def _context(
    label: str, t0: float, frame: _LegFrame, geom: TargetGeometry, wind: WindField,
    s: RoutingSettings, barriers: tuple[tuple[Barrier, float], ...] = (),
    current: CurrentField | None = None,
) -> _Context:
    cov = wind.coverage
    bounded = any(math.isfinite(v) for v in (cov.xmin, cov.xmax, cov.ymin, cov.ymax))
    box = None
    if bounded and not wind.clamp:
        box = (cov.xmin, cov.xmax, cov.ymin, cov.ymax)
    return _Context(
        label=label, t0=t0, frame=frame, geom=frame.geometry(geom),
        tack_s=float(s.tack_penalty_s), gybe_s=float(s.gybe_penalty_s),
        sector_rad=math.radians(s.prune_sector_deg),
        n_bins=math.ceil(2.0 * math.pi / math.radians(s.prune_sector_deg)) + 3,
        max_points=int(s.max_front_points),
        fan_hull=s.heading_fan == "hull", box=box,
        barriers=tuple((frame.barrier(b), c) for b, c in barriers), current=current,
    )


@dataclass(frozen=True, eq=False)
class _DeviceTables:
    a: Any
    cos_a: Any
    sin_a: Any
    tws: Any
    speed: Any
    up: Any
    down: Any
    up_vmg: Any
    down_vmg: Any
    vmax: Any
    sup_ms: Any
    sup_deg: Any


def _device_tables(tab: PolarTables, xp: ModuleType) -> _DeviceTables:
    return _DeviceTables(
        xp.asarray(tab.twa_deg), xp.asarray(tab.cos_a), xp.asarray(tab.sin_a),
        xp.asarray(tab.tws_ms), xp.asarray(tab.speed_ms), xp.asarray(tab.up_deg),
        xp.asarray(tab.down_deg), xp.asarray(tab.up_vmg_ms), xp.asarray(tab.down_vmg_ms),
        xp.asarray(tab.vmax_ms), xp.asarray(tab.sup_ms), xp.asarray(tab.sup_deg),
    )


# --------------------------------------------------------------------------------------
# one step

_BIG_S = 1e12  # time-to-go standing in for "unknown" (calm) [s]
_CHUNK_ELEMENTS = 15000
"""Candidate rows are processed in chunks of about this many candidates, so that the
float64 work arrays stay below 128 KB: larger NumPy temporaries are mmap-allocated by
glibc on every operation, which costs ~10x in this kernel."""


@dataclass(frozen=True, eq=False)
class _Prep:
    """Per-point quantities of one step (all arrays of length n)."""

    t: float
    dt: float
    n: int
    h: int
    lo: int
    hi: int
    X: Any
    Y: Any
    sw: Any  # upwind unit vector (leg frame)
    cw: Any
    j: Any  # TWS table row and weight
    fw: Any
    angles: Any  # (n, 4) |TWA| of VMG up, VMG down, direct (side s0), direct (side -s0)
    v_extra: Any  # (n, 4) their boat speeds
    cos_x: Any  # (n, 4)
    sin_x: Any  # (n, 4) (non-negative: sines of |TWA|)
    sin_d0: Any  # signed sine of the direct TWA of side s0 (positive: starboard)
    sin_d1: Any  # ... of side -s0
    tau0: Any  # time to go on side s0 (block 0) [s]
    gx0: Any  # its gradient
    gy0: Any
    tau1: Any  # time to go on side -s0 (block 1) [s]
    gx1: Any
    gy1: Any
    s0: Any  # side kept by block k = 0
    free: Any  # no side yet
    pending: Any  # inside a manoeuvre
    base: Any  # |TWA| before the manoeuvre a switch would start (NaN: none)
    pen_up: Any  # penalty of a side change onto an upwind heading (|TWA| < 90) [s]
    pen_dn: Any  # ... onto a downwind heading [s]
    debt: Any
    pend_pen: Any
    near: Any  # bool: within one step of the target segment
    bar_near: list  # per barrier of ctx: bool, within one step of it (None: no point is)
    any_pending: bool
    cx: Any = None  # current of the move (leg frame) [m s⁻¹]; None: still water
    cy: Any = None


def _step(
    f: _Layer, wind: WindField, polar: Polar, dev: _DeviceTables, ctx: _Context,
    s: RoutingSettings, tau_hint: float, xp: ModuleType,
) -> _Arrival | tuple[_Layer, bool, float, float]:
    pre, tau_min, dist_min = _prepare(f, wind, polar, dev, ctx, s, tau_hint, xp)
    n, h = pre.n, pre.h
    rows = n if xp is not np else max(1, _CHUNK_ELEMENTS // (h + 3))
    nk = 2 * ctx.n_bins
    best = xp.full(nk, np.inf)
    who = xp.zeros(nk, dtype=xp.int64)  # winner id per key: (row * 2 + block) * h + column
    arrival: _Arrival | None = None
    for r0 in range(0, n, rows):
        r1 = min(n, r0 + rows)
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

    keep = xp.flatnonzero(best < np.inf)
    if keep.shape[0] == 0:
        cov = wind.coverage
        raise RoutingError(
            f"leg {ctx.label}: every candidate position left the wind field's coverage "
            f"({cov.describe()}) {pre.t - ctx.t0:.0f} s after the leg start, so the route "
            "cannot go on.\n  Try: wind data that covers the course with a margin, or a "
            "wind field built with clamp=True (hold the edge values outside)."
        )
    if keep.shape[0] > ctx.max_points:  # widen the sectors: merge m neighbours
        m = -(-int(keep.shape[0]) // ctx.max_points)
        coarse = (keep // 2 // m) * 2 + keep % 2
        keep = xp.sort(keep[_group_argmin(coarse, best[keep], int(xp.max(coarse)) + 1, xp)])
    wid = who[keep]
    col = wid % h
    blk = (wid // h) % 2
    row = wid // (2 * h)
    layer, moved = _survivors(pre, row, blk, col, best[keep], dev, ctx, xp)
    return layer, moved, tau_min, dist_min


def _column_velocity(
    pre: _Prep, row: Any, blk: Any, col: Any, dev: _DeviceTables, xp: ModuleType
) -> tuple[Any, Any, Any, Any, Any]:
    """|TWA|, boat speed and the velocity parts (a1, a3, sy) of (row, block, column).

    The same arithmetic, in the same order, as the matrices of :func:`_expand`, so a
    survivor's position is bit-identical to the candidate that won its sector.
    """
    lo, hi = pre.lo, pre.hi
    hg = hi - lo
    grid = col < hg
    cg = xp.where(grid, col, 0) + lo
    ce = xp.where(grid, 0, col - hg)
    ce = xp.where((blk == 1) & (ce == 2), 3, ce)  # block 1 aims with its own direct column
    j, fw = pre.j[row], pre.fw[row]
    s_lo = dev.speed[j, cg]
    bsp = xp.where(grid, s_lo + fw * (dev.speed[j + 1, cg] - s_lo), pre.v_extra[row, ce])
    twa = xp.where(grid, dev.a[cg], pre.angles[row, ce])
    sx = bsp * xp.where(grid, dev.cos_a[cg], pre.cos_x[row, ce])
    sy = bsp * xp.where(grid, dev.sin_a[cg], pre.sin_x[row, ce])
    return twa, bsp, pre.sw[row] * sx, pre.cw[row] * sx, sy


def _survivors(
    pre: _Prep, row: Any, blk: Any, col: Any, score: Any, dev: _DeviceTables, ctx: _Context,
    xp: ModuleType,
) -> tuple[_Layer, bool]:
    """The new front from the winning (row, block, column) triples."""
    dt = pre.dt
    twa, bsp, a1, a3, sy = _column_velocity(pre, row, blk, col, dev, xp)
    s0 = pre.s0[row]
    b2 = (s0 * pre.cw[row]) * sy
    b4 = (s0 * pre.sw[row]) * sy
    switch = blk == 1
    vx = xp.where(switch, a1 + b2, a1 - b2)
    vy = xp.where(switch, a3 - b4, a3 + b4)
    pen = xp.where(twa < 90.0, pre.pen_up[row], pre.pen_dn[row])
    free = pre.free[row]
    pending = pre.pending[row]
    debt = xp.where(switch, xp.where(free, 0.0, pen),
                    xp.where(pending, xp.maximum(pre.debt[row] + pen - pre.pend_pen[row], 0.0),
                             0.0))
    delay = xp.minimum(debt, dt)
    move = dt - delay
    in_man = xp.where(switch, ~free, pending) & ~(move > 0)
    nx_, ny_ = pre.X[row] + move * vx, pre.Y[row] + move * vy
    if pre.cx is not None:  # drift with the water for the whole step
        nx_, ny_ = nx_ + dt * pre.cx[row], ny_ + dt * pre.cy[row]
    layer = _Layer(
        t=pre.t + dt, x=nx_, y=ny_,
        side=xp.where(switch, -s0, s0), debt=debt - delay, abs_twa=twa,
        pend_old=xp.where(in_man, pre.base[row], np.nan), pend_pen=xp.where(in_man, pen, 0.0),
        parent=row, heading=xp.mod(xp.degrees(xp.arctan2(vx, vy)), 360.0), bsp=bsp,
        delay=delay, tau_est=score,
    )
    return layer, bool(xp.any((move > 0) & (bsp > 0)))


def _wind_state(
    u: Any, v: Any, dev: _DeviceTables, fr: _LegFrame, xp: ModuleType
) -> tuple[Any, Any, Any, Any, Any, Any, Any]:
    """TWS, upwind unit vector (leg frame), table row/weight and VMG angles of winds."""
    tws = xp.sqrt(u * u + v * v)
    windy = tws > _CALM_MS
    inv = 1.0 / xp.where(windy, tws, 1.0)
    sw, cw = fr.vec_to_leg(xp.where(windy, -u * inv, 0.0), xp.where(windy, -v * inv, 1.0))
    nodes = dev.tws
    j = xp.clip(xp.searchsorted(nodes, tws, side="right") - 1, 0, nodes.shape[0] - 2)
    fw = xp.clip((tws - nodes[j]) / (nodes[j + 1] - nodes[j]), 0.0, 1.0)
    a_up = dev.up[j] + fw * (dev.up[j + 1] - dev.up[j])
    a_dn = dev.down[j] + fw * (dev.down[j + 1] - dev.down[j])
    return tws, sw, cw, j, fw, a_up, a_dn


def _time_to_go(
    tws: Any, sw: Any, cw: Any, j: Any, fw: Any, a_up: Any, a_dn: Any, ex: Any, ey: Any,
    dist: Any, s0: Any, free: Any, tack_s: float, gybe_s: float, dev: _DeviceTables,
    xp: ModuleType,
) -> tuple[Any, Any, Any]:
    """Time to go over ``dist`` along the unit vector ``(ex, ey)``, and its gradient.

    Two ways to get there, the faster counts:

    * straight, at ``S(beta)`` (``beta``: angle between the way and the upwind unit
      vector ``w_hat = (sw, cw)``), plus a tack or gybe if the way lies on the other
      side of the wind than the point's side ``s0``;
    * inside the upwind (downwind) VMG cone, two boards at the VMG angles,
      ``v·w_hat / VMG_up`` (``-v·w_hat / VMG_dn``), plus one tack (gybe).

    Points with no side yet pay no penalty; then this is the time on the convex VMG hull
    of the polar.  The gradient ``G`` (``tau = v·G + penalty``) gives the change of
    ``tau`` for a small move ``d``: ``tau(P + d) ≈ tau(P) - d·G``.  Speeds come from the
    polar tables (this only ranks candidates).  Calm: ``tau`` is huge and ``G = 0``.
    """
    del tws
    cos_d = xp.clip(cw * ey + sw * ex, -1.0, 1.0)
    sin_d = sw * ey - cw * ex
    a_d = xp.degrees(xp.arccos(cos_d))
    vmg_up = dev.up_vmg[j] + fw * (dev.up_vmg[j + 1] - dev.up_vmg[j])
    vmg_dn = dev.down_vmg[j] + fw * (dev.down_vmg[j + 1] - dev.down_vmg[j])
    # polar speed and slope dS/dbeta at the direct angle, from the grid table
    na = dev.a.shape[0]
    step = 180.0 / na
    g = a_d * (1.0 / step) - 1.0
    kl = xp.clip(xp.floor(g).astype(xp.int64), 0, na - 2)
    fa = xp.clip(g - kl, 0.0, 1.0)
    sp = dev.speed
    s_l = sp[j, kl] + fw * (sp[j + 1, kl] - sp[j, kl])
    s_r = sp[j, kl + 1] + fw * (sp[j + 1, kl + 1] - sp[j, kl + 1])
    spd = s_l + fa * (s_r - s_l)
    slope = (s_r - s_l) * (1.0 / math.radians(step))
    cone_up = (a_d <= a_up) & (vmg_up > 0)
    cone_dn = (a_d >= a_dn) & (vmg_dn > 0) & ~cone_up
    cone = cone_up | cone_dn
    inv_s = 1.0 / xp.where(spd > 0, spd, 1.0)
    inv_v = xp.where(cone_up, 1.0 / xp.where(cone_up, vmg_up, 1.0),
                     -1.0 / xp.where(cone_dn, vmg_dn, 1.0))
    t_straight = xp.where(spd > 0, dist * inv_s, np.inf)
    t_cone = xp.where(cone, dist * cos_d * inv_v, np.inf)
    own = free | (s0 * sin_d >= 0)
    paid = ~free
    t_straight = t_straight + xp.where(own | ~paid, 0.0, xp.where(a_d < 90.0, tack_s, gybe_s))
    t_cone = t_cone + xp.where(paid, xp.where(cone_up, tack_s, gybe_s), 0.0)
    use_cone = t_cone < t_straight
    tau = xp.minimum(t_cone, t_straight)
    sin_b = xp.sqrt(xp.maximum(1.0 - cos_d * cos_d, 1e-18))
    k = slope * inv_s * inv_s / sin_b
    alpha = xp.where(use_cone, inv_v, k)
    beta = xp.where(use_cone, 0.0, inv_s - k * cos_d)
    ok = tau < np.inf
    tau = xp.where(dist > 0, xp.where(ok, tau, _BIG_S), 0.0)
    alpha = xp.where(ok, alpha, 0.0)
    beta = xp.where(ok, beta, 0.0)
    return tau, alpha * sw + beta * ex, alpha * cw + beta * ey


def _support(j: Any, fw: Any, beta_deg: Any, dev: _DeviceTables, xp: ModuleType
             ) -> tuple[Any, Any]:
    """Polar support towards ``beta`` (from the upwind direction, towards the side) at
    the table rows ``j, fw``: the best speed component [m s⁻¹] and its |TWA| [°],
    interpolated bilinearly in (TWS, beta) from :attr:`PolarTables.sup_ms`."""
    g = (beta_deg + 180.0) * (dev.sup_ms.shape[1] - 1) / 360.0
    kb = xp.clip(xp.floor(g).astype(xp.int64), 0, dev.sup_ms.shape[1] - 2)
    fb = xp.clip(g - kb, 0.0, 1.0)
    out = []
    for tab in (dev.sup_ms, dev.sup_deg):
        lo_ = tab[j, kb] + fb * (tab[j, kb + 1] - tab[j, kb])
        hi_ = tab[j + 1, kb] + fb * (tab[j + 1, kb + 1] - tab[j + 1, kb])
        out.append(lo_ + fw * (hi_ - lo_))
    return out[0], out[1]


def _fastest_aim(
    X: Any, Y: Any, ex: Any, ey: Any, dist: Any, s0: Any, sw: Any, cw: Any, j: Any,
    fw: Any, g: TargetGeometry, dev: _DeviceTables, xp: ModuleType,
    cur: tuple[Any, Any] | None = None,
) -> tuple[Any, Any, Any]:
    """Aim points on the target segment that the local wind reaches soonest, per side.

    The heading that reaches the segment's line soonest maximises the speed component
    along the segment normal ``n`` (:func:`_support`).  For side ``s0`` (block 0) and
    side ``-s0`` (block 1) that heading is taken on the side itself if it approaches the
    line at all, else on the other side.  Followed from ``P`` it meets the line at
    ``Q*``; the aim point is ``Q*`` kept ``AIM_MARGIN_M`` inside the segment.  Where no
    heading approaches the line, the projection of ``P`` (``ex, ey, dist`` passed in)
    is kept.  This makes the direct candidate the exact best heading to a line or gate
    in uniform wind.  In a current ``cur`` (leg frame) the same heading is fastest (the
    current adds the same normal speed to every heading) but its track over the ground,
    ``S·d + C``, meets the line elsewhere.

    Returns the unit vectors ``(ex, ey)`` to the aim points and their distances, each of
    shape (2, n): row 0 for side ``s0``, row 1 for side ``-s0``.
    """
    nx, ny = g.normal
    p = sw * nx + cw * ny
    q = sw * ny - cw * nx
    sides = xp.stack([s0, -s0])
    best, ang = _support(j, fw, xp.degrees(xp.arctan2(sides * q, p)), dev, xp)
    use_own = best > 0  # else take the heading of the other side (needs a manoeuvre)
    sig = xp.where(use_own, sides, -sides)
    best = xp.where(use_own, best, best[::-1])
    rb = xp.radians(xp.where(use_own, ang, ang[::-1]))
    ca_b, sa_b = xp.cos(rb), xp.sin(rb)
    dx = sw * ca_b - sig * cw * sa_b  # heading unit vector on side sig
    dy = cw * ca_b + sig * sw * sa_b
    ax0, ay0 = g.a
    ahead = (ax0 - X) * nx + (ay0 - Y) * ny  # distance to the segment's line along n
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
    r = xp.clip((X + t * dx - ax0) * ux + (Y + t * dy - ay0) * uy, m, length - m)
    vx = ax0 + r * ux - X
    vy = ay0 + r * uy - Y
    d2 = xp.sqrt(vx * vx + vy * vy)
    use = ok & (d2 > 0)
    inv = 1.0 / xp.where(use, d2, 1.0)
    return xp.where(use, vx * inv, ex), xp.where(use, vy * inv, ey), xp.where(use, d2, dist)


_CRAB_ITERATIONS = 8
"""Fixed-point iterations of the crab angle of the direct column in a current."""
_TTG_ITERATIONS = 4
"""Newton iterations of the time to go in a current."""


def _crab(
    ex: Any, ey: Any, cx: Any, cy: Any, tws: Any, sw: Any, cw: Any, polar: Polar,
    xp: ModuleType,
) -> tuple[Any, Any, Any, Any]:
    """The direct column in a current: the heading through the water whose velocity
    over the ground, ``S(TWA(h))·w(h) + C``, points along the unit vectors ``(ex, ey)``.

    Fixed-point iteration on the crab angle ``phi`` (from ``e`` towards the
    perpendicular ``p``): ``sin(phi) = -C·p / S(phi)``.  Where no heading can hold the
    line (``|C·p| >= S``, or no speed) the still-water direction ``e`` is kept.

    Returns ``cos``/signed ``sin`` of the heading against the upwind unit vector
    ``(sw, cw)``, its ``|TWA|`` [°] and boat speed [m s⁻¹], as the still-water columns.
    """
    px, py = ey, -ex
    cp = cx * px + cy * py
    wx, wy = ex, ey
    tws_h = _host(tws)
    for _ in range(_CRAB_ITERATIONS):
        a_d = xp.degrees(xp.arccos(xp.clip(cw * wy + sw * wx, -1.0, 1.0)))
        spd = xp.asarray(polar.speed(tws_h, _host(a_d)), dtype=float)
        q = -cp / xp.where(spd > 0, spd, 1.0)
        q = xp.where((spd > 0) & (xp.abs(q) < 1.0), q, 0.0)
        r = xp.sqrt(1.0 - q * q)
        wx, wy = r * ex + q * px, r * ey + q * py
    cos_d = xp.clip(cw * wy + sw * wx, -1.0, 1.0)
    a_d = xp.degrees(xp.arccos(cos_d))
    v_d = xp.asarray(polar.speed(tws_h, _host(a_d)), dtype=float)
    return cos_d, sw * wy - cw * wx, a_d, v_d


def _time_to_go_current(
    tau: Any, gx: Any, gy: Any, avg: tuple[Any, Any, Any, Any, Any, Any, Any], ex: Any, ey: Any,
    dist: Any, cx: Any, cy: Any, sides: Any, free: Any, ctx: _Context, dev: _DeviceTables,
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
        t_w, gx, gy = _time_to_go(*avg, xp.where(pos, wx * inv, ex), xp.where(pos, wy * inv, ey),
                                  dw, sides, free, ctx.tack_s, ctx.gybe_s, dev, xp)
        der = 1.0 + gx * cx + gy * cy
        newton = der > 0.25
        tau = xp.where(ok, tt - (tt - t_w) / xp.where(newton, der, 1.0), t_w)
        tau = xp.where(t_w >= _BIG_S, _BIG_S, xp.maximum(tau, 0.0))
    scale = 1.0 / xp.maximum(1.0 + gx * cx + gy * cy, 0.25)
    return tau, gx * scale, gy * scale


def _prepare(
    f: _Layer, wind: WindField, polar: Polar, dev: _DeviceTables, ctx: _Context,
    s: RoutingSettings, tau_hint: float, xp: ModuleType,
) -> tuple[_Prep, float, float]:
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

    All wind samples of the step go through one ``wind.sample`` call.
    """
    X, Y = f.x, f.y
    n = int(X.shape[0])
    fr = ctx.frame
    cov = wind.coverage
    dt = float(s.dt_s)
    if tau_hint < NEAR_TARGET_STEPS * dt and s.min_dt_s < dt:
        dt = max(float(s.min_dt_s), tau_hint / NEAR_TARGET_STEPS)
    t_mid = f.t + 0.5 * dt

    # direct bearing to the aim point
    ax, ay = aim_points(X, Y, ctx.geom, xp=xp)
    ex, ey = ax - X, ay - Y
    dist = xp.sqrt(ex * ex + ey * ey)
    there = dist > 0
    inv_d = 1.0 / xp.where(there, dist, 1.0)
    ex = xp.where(there, ex * inv_d, 0.0)
    ey = xp.where(there, ey * inv_d, 1.0)

    # sample points: predicted mid-step positions, then PATH_SAMPLES points on the way
    hr = xp.radians(f.heading)
    half = xp.where(f.debt > 0, 0.0, 0.5 * dt * f.bsp)
    horizon = xp.where(xp.isnan(f.tau_est), dist * (1.0 / _ROOT_SPEED_MS),
                       xp.minimum(f.tau_est, float(s.max_leg_time_s)))
    fk = (xp.arange(PATH_SAMPLES, dtype=float) + 0.5) / PATH_SAMPLES
    px = xp.concatenate([X + half * xp.sin(hr), (X + fk[:, None] * (ax - X)).reshape(-1)])
    py = xp.concatenate([Y + half * xp.cos(hr), (Y + fk[:, None] * (ay - Y)).reshape(-1)])
    pt = xp.concatenate([xp.full(n, t_mid), (t_mid + fk[:, None] * horizon).reshape(-1)])
    wx, wy = fr.to_world(px, py)
    pts = (_host(xp.clip(pt, cov.t0, cov.t1)), _host(xp.clip(wx, cov.xmin, cov.xmax)),
           _host(xp.clip(wy, cov.ymin, cov.ymax)))
    u, v = wind.sample(*pts)
    u = xp.asarray(u, dtype=float).reshape(PATH_SAMPLES + 1, n)
    v = xp.asarray(v, dtype=float).reshape(PATH_SAMPLES + 1, n)
    cur = None  # current (leg frame): of the move, and averaged along the way
    if ctx.current is not None:
        cu, cv = ctx.current.sample(*pts)
        cu, cv = fr.vec_to_leg(xp.asarray(cu, dtype=float).reshape(PATH_SAMPLES + 1, n),
                               xp.asarray(cv, dtype=float).reshape(PATH_SAMPLES + 1, n))
        if bool(xp.any(cu != 0.0)) or bool(xp.any(cv != 0.0)):  # slack water: still water
            cur = (cu[0], cv[0], xp.mean(cu, axis=0), xp.mean(cv, axis=0))

    # the move's wind: speed, direction, VMG angles
    tws, sw, cw, j, fw, a_up, a_dn = _wind_state(u[0], v[0], dev, fr, xp)
    v_vmg = xp.asarray(polar.speed(_host(tws)[:, None], _host(xp.stack([a_up, a_dn], 1))),
                       dtype=float)

    # grid columns: the whole circle, or between the VMG angles ("hull")
    na = int(dev.a.shape[0])
    lo, hi = 0, na
    if ctx.fan_hull:
        lo_h = int(xp.searchsorted(dev.a, xp.min(a_up), side="right"))
        hi_h = int(xp.searchsorted(dev.a, xp.max(a_dn), side="left"))
        if hi_h > lo_h:
            lo, hi = lo_h, hi_h

    # aim, per side, at the point of the target segment reached fastest in this wind
    s0 = xp.where(f.side < 0, -1.0, 1.0)
    free = f.side == 0
    aex, aey, adist = _fastest_aim(X, Y, ex, ey, dist, s0, sw, cw, j, fw, ctx.geom, dev, xp,
                                   None if cur is None else cur[:2])

    # the exact columns: VMG up, VMG down, direct to the aim (side s0), direct (side -s0)
    if cur is None:
        cos_d = xp.clip(cw * aey + sw * aex, -1.0, 1.0)  # (2, n)
        sin_d = sw * aey - cw * aex
        a_d = xp.degrees(xp.arccos(cos_d))
        v_d = xp.asarray(polar.speed(_host(tws), _host(a_d)), dtype=float)
    else:  # the heading through the water whose track over the ground goes to the aim
        cos_d, sin_d, a_d, v_d = _crab(aex, aey, cur[0], cur[1], tws, sw, cw, polar, xp)
    angles = xp.concatenate([a_up[:, None], a_dn[:, None], a_d.T], axis=1)
    v_extra = xp.concatenate([v_vmg, v_d.T], axis=1)
    rad = xp.radians(angles[:, :2])
    cos_x = xp.concatenate([xp.cos(rad), cos_d.T], axis=1)
    sin_x = xp.concatenate([xp.sin(rad), xp.abs(sin_d).T], axis=1)

    # time to go on either side, in the wind averaged along the way
    avg = _wind_state(xp.mean(u, axis=0), xp.mean(v, axis=0), dev, fr, xp)
    tau, gx, gy = _time_to_go(*avg, aex, aey, adist, xp.stack([s0, -s0]), free, ctx.tack_s,
                              ctx.gybe_s, dev, xp)
    if cur is not None:
        tau, gx, gy = _time_to_go_current(tau, gx, gy, avg, aex, aey, adist, cur[2], cur[3],
                                          xp.stack([s0, -s0]), free, ctx, dev, xp)
    tau_min = float(xp.min(f.debt + tau[0]))
    if cur is not None:  # the drift of the step is common to all candidates of a point
        tau = tau - dt * (gx * cur[0] + gy * cur[1])
    dist_min = float(xp.min(adist))

    # manoeuvre state
    pending = ~xp.isnan(f.pend_old)
    base = xp.where(pending, f.pend_old, f.abs_twa)
    # penalty of a side change by the new |TWA| (upwind < 90 <= downwind): tack if old and
    # new are upwind, gybe if both downwind, the larger of the two if mixed
    mixed = max(ctx.tack_s, ctx.gybe_s)
    unknown = xp.isnan(base)
    pen_up = xp.where(unknown | (base < 90.0), ctx.tack_s, mixed)
    pen_dn = xp.where(unknown | (base >= 90.0), ctx.gybe_s, mixed)
    reach = xp.maximum(xp.maximum(dev.vmax[j], dev.vmax[j + 1]), xp.max(v_extra, axis=1))
    if cur is not None:
        reach = reach + xp.sqrt(cur[0] * cur[0] + cur[1] * cur[1])
    near = _segment_distance(X, Y, ctx.geom, xp) <= reach * dt * 1.0001 + 1e-6
    bar_near = []  # per barrier: the points within one step of its ray (None: none)
    for b, clear in ctx.barriers:
        ray = TargetGeometry(b.mark, (b.mark[0] + BARRIER_LENGTH_M * b.ray[0],
                                      b.mark[1] + BARRIER_LENGTH_M * b.ray[1]), b.normal, "ray")
        close = _segment_distance(X, Y, ray, xp) <= reach * dt * 1.0001 + clear + 1e-3
        bar_near.append(close if bool(xp.any(close)) else None)

    pre = _Prep(
        t=f.t, dt=dt, n=n, h=hi - lo + 3, lo=lo, hi=hi, X=X, Y=Y, sw=sw, cw=cw, j=j, fw=fw,
        angles=angles, v_extra=v_extra, cos_x=cos_x, sin_x=sin_x, sin_d0=sin_d[0],
        sin_d1=sin_d[1], tau0=tau[0], gx0=gx[0], gy0=gy[0], tau1=tau[1], gx1=gx[1],
        gy1=gy[1], s0=s0, free=free,
        pending=pending, base=base, pen_up=pen_up, pen_dn=pen_dn, debt=f.debt,
        pend_pen=f.pend_pen, near=near, bar_near=bar_near, any_pending=bool(xp.any(pending)),
        cx=None if cur is None else cur[0], cy=None if cur is None else cur[1],
    )
    return pre, tau_min, dist_min


def _expand(
    pre: _Prep, r0: int, r1: int, dev: _DeviceTables, ctx: _Context, xp: ModuleType,
    want_winners: bool,
) -> tuple[_Arrival | None, tuple[Any, Any, Any] | None]:
    """Candidates of front points ``r0:r1``: arrival check and per-sector winners.

    Two blocks of candidates: block 0 keeps the point's side ``s0`` (+1 for a free
    start) and tries every column (grid slice, VMG up, VMG down, direct to its aim
    point); block 1 changes side and tries the exact columns only (VMG up, VMG down,
    direct to the other side's aim point; all grid columns too for free start points,
    which pay no penalty).  Any other heading on the new side is one step away at no
    cost, so this loses at most one step at a slightly different angle.  Each block is
    scored with the time to go of its own side.
    """
    r = r1 - r0
    h, lo, hi = pre.h, pre.lo, pre.hi
    hg = hi - lo
    dt = pre.dt
    sl = slice(r0, r1)
    X, Y = pre.X[sl], pre.Y[sl]
    j, fw = pre.j[sl], pre.fw[sl]
    sw, cw, s0 = pre.sw[sl], pre.cw[sl], pre.s0[sl]
    free = pre.free[sl]
    pending = pre.pending[sl]
    any_free = bool(xp.any(free))
    any_pend = pre.any_pending and bool(xp.any(pending))
    cb = 0 if any_free else hg  # first grid column of block 1

    # boat speed, |TWA| and (speed cos|TWA|, speed sin|TWA|) of every column
    sp = dev.speed
    s_lo = sp[j, lo:hi]
    grid_bsp = s_lo + fw[:, None] * (sp[j + 1, lo:hi] - s_lo)
    ext = [0, 1, 2], [0, 1, 3]  # exact columns of block 0 and block 1
    blocks = []
    for b, c0 in ((0, 0), (1, cb)):
        e = ext[b]
        bsp = xp.concatenate([grid_bsp[:, c0:], pre.v_extra[sl][:, e]], axis=1)
        twa = xp.concatenate([xp.broadcast_to(dev.a[lo + c0:hi], (r, hg - c0)),
                              pre.angles[sl][:, e]], axis=1)
        sx = bsp * xp.concatenate([xp.broadcast_to(dev.cos_a[lo + c0:hi], (r, hg - c0)),
                                   pre.cos_x[sl][:, e]], axis=1)
        sy = bsp * xp.concatenate([xp.broadcast_to(dev.sin_a[lo + c0:hi], (r, hg - c0)),
                                   pre.sin_x[sl][:, e]], axis=1)
        blocks.append((bsp, twa, sx, sy))

    # On side sigma (heading = twd - sigma |twa|) the velocity is (a1 - sigma a2,
    # a3 + sigma a4), a1 = sw sx, a2 = cw sy, a3 = cw sx, a4 = sw sy; block 0 has
    # sigma = s0, block 1 sigma = -s0.  Rate of decrease of the time to go: G · velocity.
    vel, rate = [], []
    for b, (_, _, sx, sy) in enumerate(blocks):
        a1 = sw[:, None] * sx
        a3 = cw[:, None] * sx
        b2 = (s0 * cw)[:, None] * sy
        b4 = (s0 * sw)[:, None] * sy
        gx = (pre.gx0 if b == 0 else pre.gx1)[sl, None]
        gy = (pre.gy0 if b == 0 else pre.gy1)[sl, None]
        if b == 0:
            vel.append((a1 - b2, a3 + b4))
            rate.append(gx * (a1 - b2) + gy * (a3 + b4))
        else:
            vel.append((a1 + b2, a3 - b4))
            rate.append(gx * (a1 + b2) + gy * (a3 - b4))

    # Penalties as time debt.  The penalty of a manoeuvre is fixed by the first heading
    # actually sailed after it (pending points re-price it); no turning back inside one.
    twa1 = blocks[1][1]
    pen1 = xp.where(twa1 < 90.0, pre.pen_up[sl, None], pre.pen_dn[sl, None])
    if any_free:
        pen1[free] = 0.0
    delay1 = xp.minimum(pen1, dt)
    move1 = dt - delay1
    debt1 = pen1 - delay1

    def timing0(sub: Any) -> tuple[Any, Any, Any]:
        """Delay, move time and remaining debt of block 0 for rows ``sub`` (pending rows
        re-price their manoeuvre with the new heading)."""
        dl = xp.zeros((sub.shape[0], h))
        if any_pend and bool(xp.any(pending[sub])):
            pr = sub[pending[sub]]
            pos = xp.flatnonzero(pending[sub])
            pen_r = xp.where(blocks[0][1][pr] < 90.0, pre.pen_up[sl][pr, None],
                             pre.pen_dn[sl][pr, None])
            dl[pos] = xp.maximum(
                pre.debt[sl][pr, None] + pen_r - pre.pend_pen[sl][pr, None], 0.0)
        d = xp.minimum(dl, dt)
        return d, dt - d, dl - d

    (vx0, vy0), (vx1, vy1) = vel
    qx0 = X[:, None] + dt * vx0
    qy0 = Y[:, None] + dt * vy0
    prow = xp.flatnonzero(pending) if any_pend else None
    if prow is not None:
        _, move_p, debt_p = timing0(prow)
        qx0[prow] = X[prow, None] + move_p * vx0[prow]
        qy0[prow] = Y[prow, None] + move_p * vy0[prow]
    qx1 = X[:, None] + move1 * vx1
    qy1 = Y[:, None] + move1 * vy1
    if pre.cx is not None:  # drift with the water for the whole step, stopped or not
        drx, dry = dt * pre.cx[sl, None], dt * pre.cy[sl, None]
        qx0, qy0, qx1, qy1 = qx0 + drx, qy0 + dry, qx1 + drx, qy1 + dry

    # the direct columns exist on their own side only
    ok0 = s0 * pre.sin_d0[sl] >= 0
    ok1 = s0 * pre.sin_d1[sl] <= 0

    # moves that pass a rounded mark on the wrong side (rows near a barrier only)
    blocked = None
    for (bar, clear), close in zip(ctx.barriers, pre.bar_near, strict=True):
        nb = None if close is None else xp.flatnonzero(close[sl])
        if nb is None or nb.shape[0] == 0:
            continue
        if blocked is None:
            blocked = [xp.zeros(qx0.shape, dtype=bool), xp.zeros(qx1.shape, dtype=bool)]
        px_b, py_b = X[nb][:, None], Y[nb][:, None]
        for m, qx_b, qy_b in zip(blocked, (qx0, qx1), (qy0, qy1), strict=True):
            m[nb] |= barrier_blocks(px_b, py_b, qx_b[nb], qy_b[nb], bar, clear, xp=xp)

    # arrival: earliest forward crossing of the target segment (rows within reach only)
    arrival = None
    near = xp.flatnonzero(pre.near[sl])
    if near.shape[0] > 0:
        best_t = np.inf
        delay0, move0, _ = timing0(near)
        for blk, (qx_b, qy_b, dl_n, mv_n, ok_b) in enumerate((
                (qx0, qy0, delay0, move0, ok0),
                (qx1, qy1, delay1[near], move1[near], ok1))):
            px = X[near][:, None]
            py = Y[near][:, None]
            if pre.cx is not None:  # the move starts after the drift of the penalty stop
                px = px + dl_n * pre.cx[sl][near, None]
                py = py + dl_n * pre.cy[sl][near, None]
            hit, sfrac, _ = segment_crossing(px, py, qx_b[near], qy_b[near], ctx.geom, xp=xp)
            hit[:, -1] &= ok_b[near]
            if blocked is not None:
                hit &= ~blocked[blk][near]
            if blk == 1 and any_pend:
                hit &= ~pending[near, None]
            if ctx.box is not None:
                hit &= _in_box(qx_b[near], qy_b[near], ctx.frame, ctx.box)
            if not bool(xp.any(hit)):
                continue
            t_arr = xp.where(hit, dl_n + sfrac * mv_n, np.inf)
            kk = int(xp.argmin(t_arr.reshape(-1)))
            rr, c = divmod(kk, int(t_arr.shape[1]))
            if float(t_arr[rr, c]) >= best_t:
                continue
            best_t = float(t_arr[rr, c])
            p = int(near[rr])
            ds = float(sfrac[rr, c])
            x0, y0 = float(px[rr, 0]), float(py[rr, 0])
            q_x, q_y = float(qx_b[p, c]), float(qy_b[p, c])
            hd = (_heading_deg(q_x - x0, q_y - y0) if pre.cx is None  # through the water:
                  else _heading_deg(float(vel[blk][0][p, c]), float(vel[blk][1][p, c])))
            arrival = _Arrival(
                parent=r0 + p, t_start=pre.t, t=pre.t + best_t,
                x=x0 + ds * (q_x - x0), y=y0 + ds * (q_y - y0),
                heading=hd, bsp=float(blocks[blk][0][p, c]),
                delay=float(dl_n[rr, c]), side=int(s0[p]) * (1 - 2 * blk),
            )
    if not want_winners or arrival is not None:
        return arrival, None

    # score: estimated time to go after the move, tau + debt - move * (G · velocity)
    score0 = pre.tau0[sl, None] - dt * rate[0]
    if prow is not None:
        score0[prow] = pre.tau0[sl][prow, None] + debt_p - move_p * rate[0][prow]
    score1 = pre.tau1[sl, None] + debt1 - move1 * rate[1]
    score0[:, -1] = xp.where(ok0, score0[:, -1], np.inf)
    score1[:, -1] = xp.where(ok1, score1[:, -1], np.inf)
    if any_pend:
        score1[pending] = np.inf
    if blocked is not None:
        score0 = xp.where(blocked[0], np.inf, score0)
        score1 = xp.where(blocked[1], np.inf, score1)
    if ctx.box is not None:
        score0 = xp.where(_in_box(qx0, qy0, ctx.frame, ctx.box), score0, np.inf)
        score1 = xp.where(_in_box(qx1, qy1, ctx.frame, ctx.box), score1, np.inf)

    # sector of the bearing seen from the target (float32 is ample for binning) and side
    scale = np.float32(1.0 / ctx.sector_rad)
    off = np.float32(ctx.n_bins // 2 + 0.5)  # keeps the argument positive: astype = floor
    port = (s0 < 0).astype(xp.int64)[:, None]  # side index: 0 starboard, 1 port
    keys = []
    for qx_b, qy_b, side_b in ((qx0, qy0, port), (qx1, qy1, 1 - port)):
        phi = xp.arctan2(qx_b.astype(xp.float32), qy_b.astype(xp.float32))
        kb = (phi * scale + off).astype(xp.int64)
        kb *= 2
        kb += side_b
        keys.append(kb.reshape(-1))
    n0 = r * h
    key = xp.concatenate(keys)
    score = xp.concatenate([score0.reshape(-1), score1.reshape(-1)])
    flat = _group_argmin(key, score, 2 * ctx.n_bins, xp)
    if flat.shape[0] == 0:
        return None, None

    # winner ids: (global row * 2 + block) * h + column
    in0 = flat < n0
    f1 = flat - n0
    h1 = h - cb
    wid = xp.where(in0, ((r0 + flat // h) * 2) * h + flat % h,
                   ((r0 + f1 // h1) * 2 + 1) * h + cb + f1 % h1)
    return None, (key[flat], score[flat], wid)


def _in_box(
    qx: Any, qy: Any, fr: _LegFrame, box: tuple[float, float, float, float]
) -> Any:
    """Candidates (leg frame) whose world position lies inside the coverage box."""
    wx, wy = fr.to_world(qx, qy)
    return (wx >= box[0]) & (wx <= box[1]) & (wy >= box[2]) & (wy <= box[3])


def _segment_distance(X: Any, Y: Any, g: TargetGeometry, xp: ModuleType) -> Any:
    """Distance from points to the target segment [m]."""
    ax, ay = g.a
    ex, ey = g.b[0] - ax, g.b[1] - ay
    ll = ex * ex + ey * ey
    r = xp.clip(((X - ax) * ex + (Y - ay) * ey) / ll, 0.0, 1.0)
    dx = X - (ax + r * ex)
    dy = Y - (ay + r * ey)
    return xp.sqrt(dx * dx + dy * dy)


def _heading_deg(ux: float, uy: float) -> float:
    return math.degrees(math.atan2(ux, uy)) % 360.0


# --------------------------------------------------------------------------------------
# backtracking


def _backtrack(
    layers: list[_Layer], arr: _Arrival, frame: _LegFrame, wind: WindField, polar: Polar,
    world_start: tuple[NDArray, NDArray], current: CurrentField | None = None,
) -> Track:
    """Polyline of the chosen route: step starts, penalty stops, exact arrival (world frame).

    The vertices at the start point get its world coordinates ``world_start[k][root]``
    exactly (not through the leg frame and back), so a leg starts bit-for-bit where
    the previous one ended.  In a ``current`` the headings and speeds are through the
    water and the track gets SOG/COG (velocity through the water plus the current).
    """
    # moves, newest first: (t_start, t_end, index in its source layer, heading, bsp, delay, side)
    moves = [(arr.t_start, arr.t, arr.parent, arr.heading, arr.bsp, arr.delay, arr.side)]
    idx = arr.parent
    for k in range(len(layers) - 1, 0, -1):
        lay = layers[k]
        pidx = int(lay.parent[idx])
        moves.append((layers[k - 1].t, lay.t, pidx, float(lay.heading[idx]),
                      float(lay.bsp[idx]), float(lay.delay[idx]), int(lay.side[idx])))
        idx = pidx
    moves.reverse()
    root_side = int(layers[0].side[idx])

    # a stopped boat (penalty) shows the heading it will sail next
    hd_next = [m[3] for m in moves]
    for i in range(len(moves) - 2, -1, -1):
        if moves[i][5] >= moves[i][1] - moves[i][0]:  # stopped for the whole step
            hd_next[i] = hd_next[i + 1]

    rows: list[tuple[float, float, float, float, float, int]] = []
    for m, (ts, te, pidx, _, b, dl, sd) in enumerate(moves):
        src = layers[m]
        px, py = float(src.x[pidx]), float(src.y[pidx])
        hd = hd_next[m]
        if m == 0 and root_side != 0 and sd != root_side:
            # forced start side, turned at once: show the old side with the mirrored heading
            rows.append((ts, px, py, float("nan"), 0.0, root_side))
        rows.append((ts, px, py, hd, 0.0 if dl > 0 else b, sd))
        if dl > 0 and ts + dl < te:
            rows.append((ts + dl, px, py, hd, b, sd))
    rows.append((arr.t, arr.x, arr.y, moves[-1][3], moves[-1][4], moves[-1][6]))

    a = np.array(rows)
    wx, wy = frame.to_world(a[:, 1], a[:, 2])
    at_start = (a[:, 1] == float(layers[0].x[idx])) & (a[:, 2] == float(layers[0].y[idx]))
    wx[at_start] = float(world_start[0][idx])
    wy[at_start] = float(world_start[1][idx])
    heading = np.mod(a[:, 3] + frame.offset_deg, 360.0)
    if np.isnan(heading[0]):
        u, v = wind.sample(a[0, 0], wx[0], wy[0])
        twd = math.degrees(math.atan2(-float(u), -float(v)))
        heading[0] = (2.0 * twd - heading[1]) % 360.0
    track = build_track(
        a[:, 0], wx, wy, wind, polar, heading_deg=heading, bsp_ms=a[:, 4],
        side=a[:, 5].astype(np.int8),
    )
    if current is None:
        return track
    cu, cv = current.sample(track.t, track.x, track.y)
    hr = np.radians(track.heading_deg)
    sog, cog = current_rate_set(track.bsp_ms * np.sin(hr) + cu, track.bsp_ms * np.cos(hr) + cv)
    return dataclasses.replace(track, sog_ms=sog, cog_deg=cog)


def _timeout_error(
    label: str, s: RoutingSettings, elapsed: float, dist_min: float,
    calm_since: float | None, t: float,
) -> RoutingError:
    msg = (
        f"leg {label}: no route reached the target within {elapsed:.0f} s of race time "
        f"(max_leg_time_s = {s.max_leg_time_s:g} s); the closest point of the front was "
        f"{dist_min:.0f} m from it."
    )
    if calm_since is not None:
        msg += (
            f"\n  The boat speed was zero on the whole front for the last {t - calm_since:.0f} s: "
            "the wind is calm there (or below the polar's lowest wind speed)."
            "\n  Try: a wind field with wind over the course at this time, a later start, "
            "or a polar that covers light air."
        )
    else:
        msg += (
            "\n  Try: check that the target can be reached (rounding side, wind coverage), "
            "or raise routing.max_leg_time_s."
        )
    return RoutingError(msg)


_ROUTER: Router = route_isochrone  # mypy checks the shared router signature
