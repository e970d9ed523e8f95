"""Inputs of one isochrone step: wind, aim points, exact columns, time to go, manoeuvres.

:func:`_prepare` turns a front into the :class:`~sailroute.routing.isochrone_records._StepInputs`
of the candidate kernel: the step length (:func:`_step_length`), the wind and current of
each move and along the way to the target in one ``sample`` call (:func:`_sample_step`,
:func:`_wind_state`), the grid columns tried (:func:`_fan`; per member
:func:`_group_fans`), the exact columns (:func:`_exact_columns`; in a current the crab
angle, :func:`_crab`), the time to go of both sides
(:mod:`~sailroute.routing.isochrone_togo`), the manoeuvre bookkeeping
(:func:`_manoeuvre_state`) and the points a move can take to the target, a barrier or
out of the coverage box (:func:`_within_reach`, :func:`_box_holds`).

Used by the step function (:func:`~sailroute.routing.isochrone_kernel._step`) and by
:mod:`sailroute.routing.batch`, which prepares the members' fronts together; the driver
(:mod:`sailroute.routing.isochrone`) takes :data:`NEAR_TARGET_STEPS` and
:data:`PATH_SAMPLES` from here.
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np

from sailroute.backend import to_numpy
from sailroute.boat.polar import Polar
from sailroute.numerics import clip
from sailroute.routing.geometry import BARRIER_LENGTH_M, TargetGeometry, aim_points
from sailroute.routing.isochrone_polar import PointPolars, _DeviceTables, node_rows
from sailroute.routing.isochrone_records import (
    Groups,
    _Context,
    _Current,
    _ExactColumns,
    _Layer,
    _LegFrame,
    _ManoeuvreState,
    _PointWind,
    _StepInputs,
    _TimeToGo,
)
from sailroute.routing.isochrone_togo import _fastest_aim, _time_to_go, _time_to_go_current
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import Barrier
from sailroute.wind.base import WindField

NEAR_TARGET_STEPS = 3.0
"""The step shrinks to (estimated time to go) / this, once that is below three steps."""

PATH_SAMPLES = 4
"""Wind samples along the line to the target that enter the time-to-go estimate."""

_ROOT_SPEED_MS = 2.0  # progress speed assumed for the sampling horizon at the leg start

_CALM_MS = 1e-9

_CRAB_ITERATIONS = 8
"""Fixed-point iterations of the crab angle of the direct column in a current."""


# --------------------------------------------------------------------------------------
# step length, wind and current of the step


def _step_length(s: RoutingSettings, tau_hint: float) -> float:
    """``dt_s``, shortened to ``max(min_dt_s, tau_hint / NEAR_TARGET_STEPS)`` [s] once the
    estimated time to go ``tau_hint`` [s] is below ``NEAR_TARGET_STEPS`` steps."""
    dt = float(s.isochrone.dt_s)
    if tau_hint < NEAR_TARGET_STEPS * dt and s.isochrone.min_dt_s < dt:
        dt = max(float(s.isochrone.min_dt_s), tau_hint / NEAR_TARGET_STEPS)
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
    dt: float | Any,
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


def _wind_state(
    u: Any, v: Any, dev: _DeviceTables, fr: _LegFrame, xp: ModuleType, polar: Any = None
) -> _PointWind:
    """The wind ``(u, v)`` [m s⁻¹] (world frame, towards; shape (n,)) for the kernel;
    ``polar``: each point's polar in stacked tables (:func:`node_rows`), or None."""
    tws = xp.sqrt(u * u + v * v)
    windy = tws > _CALM_MS
    inv = 1.0 / xp.where(windy, tws, 1.0)
    up_x, up_y = fr.vec_to_leg(xp.where(windy, -u * inv, 0.0), xp.where(windy, -v * inv, 1.0))
    nodes = dev.tws_ms
    row = node_rows(tws, dev, polar, xp)
    weight = clip((tws - nodes[row]) / (nodes[row + 1] - nodes[row]), 0.0, 1.0, xp=xp)
    up_deg = dev.up_deg[row] + weight * (dev.up_deg[row + 1] - dev.up_deg[row])
    down_deg = dev.down_deg[row] + weight * (dev.down_deg[row + 1] - dev.down_deg[row])
    return _PointWind(tws, up_x, up_y, row, weight, up_deg, down_deg)


# --------------------------------------------------------------------------------------
# the grid columns tried


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


# --------------------------------------------------------------------------------------
# exact columns and manoeuvres


def _exact_columns(
    wind: _PointWind,
    aim_x: Any,
    aim_y: Any,
    cur: _Current | None,
    polar: Polar | PointPolars,
    xp: ModuleType,
) -> _ExactColumns:
    """VMG up, VMG down and the direct columns to the aim points ``(aim_x, aim_y)`` (unit
    vectors, shape (2, n): own side, other side); boat speeds from :meth:`Polar.speed`.
    In a current the direct heading is the one whose ground track goes to the aim
    (:func:`_crab`)."""
    tws_h = to_numpy(wind.tws_ms)
    if cur is None:
        cos_d = clip(wind.up_y * aim_y + wind.up_x * aim_x, -1.0, 1.0, xp=xp)  # (2, n)
        sin_d = wind.up_x * aim_y - wind.up_y * aim_x
        a_d = xp.degrees(xp.arccos(cos_d))
    else:
        cos_d, sin_d, a_d, v_d = _crab(aim_x, aim_y, cur.move_x, cur.move_y, wind, polar, xp)
    twa = xp.concatenate([wind.up_deg[:, None], wind.down_deg[:, None], a_d.T], axis=1)
    # the points along the last axis (PointPolars); the four columns in one lookup
    if cur is None:
        bsp = xp.asarray(polar.speed(tws_h[None, :], to_numpy(twa.T)).T, dtype=float)
    else:
        v_vmg = xp.asarray(polar.speed(tws_h[None, :], to_numpy(twa[:, :2].T)).T, dtype=float)
        bsp = xp.concatenate([v_vmg, v_d.T], axis=1)
    bsp = xp.ascontiguousarray(bsp)
    rad = xp.radians(twa[:, :2])
    return _ExactColumns(
        twa_deg=twa,
        bsp_ms=bsp,
        cos_twa=xp.concatenate([xp.cos(rad), cos_d.T], axis=1),
        sin_twa=xp.concatenate([xp.sin(rad), xp.abs(sin_d).T], axis=1),
        direct_sin_keep=sin_d[0],
        direct_sin_switch=sin_d[1],
    )


def _crab(
    ex: Any,
    ey: Any,
    cx: Any,
    cy: Any,
    wind: _PointWind,
    polar: Polar | PointPolars,
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


# --------------------------------------------------------------------------------------
# the points within reach of the target, a barrier or the box edge


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
        close = _segment_distance(x, y, _barrier_ray(b), xp) <= step_m + clear + 1e-3
        near_barrier.append(close if bool(xp.any(close)) else None)
    return near, tuple(near_barrier)


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
    ax, ay, ex, ey, ll = _segment_params(g)
    r = clip(((x - ax) * ex + (y - ay) * ey) / ll, 0.0, 1.0, xp=xp)
    dx = x - (ax + r * ex)
    dy = y - (ay + r * ey)
    return xp.sqrt(dx * dx + dy * dy)


def _segment_params(g: TargetGeometry) -> tuple[float, float, float, float, float]:
    """``(ax, ay, ex, ey, ll)`` of :func:`_segment_distance`: the end ``a`` [m], the
    vector ``b - a`` [m] and its squared length [m²]."""
    ax, ay = g.a
    ex, ey = g.b[0] - ax, g.b[1] - ay
    return ax, ay, ex, ey, ex * ex + ey * ey


def _barrier_ray(b: Barrier) -> TargetGeometry:
    """A barrier's ray as a segment :data:`BARRIER_LENGTH_M` long (:func:`_within_reach`)."""
    return TargetGeometry(
        b.mark,
        (b.mark[0] + BARRIER_LENGTH_M * b.ray[0], b.mark[1] + BARRIER_LENGTH_M * b.ray[1]),
        b.normal,
        "ray",
    )


# --------------------------------------------------------------------------------------
# the inputs of the candidate kernel


def _prepare(
    f: _Layer,
    wind: WindField,
    polar: Polar | PointPolars,
    dev: _DeviceTables,
    ctx: _Context,
    s: RoutingSettings,
    tau_hint: float,
    xp: ModuleType,
    groups: Groups | None = None,
    dt: float | Any = None,
) -> tuple[_StepInputs, Any, Any]:
    """Step length, wind, VMG angles, direct bearing and time to go of the front points.

    * The step is ``dt_s``, shortened to ``max(min_dt_s, tau / 3)`` once the estimated
      time to go ``tau`` (from the previous step, ``tau_hint``) is below three steps;
      ``dt`` [s], where given, is the step instead (members routed together: one per
      point, each member's own).
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
    dt = _step_length(s, tau_hint) if dt is None else dt
    aim_x, aim_y = aim_points(x, y, ctx.geom, xp=xp)  # direct bearing to the aim point
    ex, ey, dist = _direction(aim_x - x, aim_y - y, xp)
    u, v, cur = _sample_step(f, dt, aim_x, aim_y, dist, wind, ctx, s, xp)
    point_polar = polar.index if isinstance(polar, PointPolars) else None  # members' boats
    move_wind = _wind_state(u[0], v[0], dev, ctx.frame, xp, point_polar)
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
    mean_wind = _wind_state(xp.mean(u, axis=0), xp.mean(v, axis=0), dev, ctx.frame, xp, point_polar)
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
    reach = top_ms * dt * 1.0001
    near, near_barrier = _within_reach(x, y, reach, ctx, xp, first_clear)
    box_clear = ctx.box is None or _box_holds(x, y, reach, ctx, xp)

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
        starts_free=ctx.obstacles is not None and not bool(xp.any(f.parent < 0)),
        reach_m=reach,
    )
    return pre, tau_min, dist_min
