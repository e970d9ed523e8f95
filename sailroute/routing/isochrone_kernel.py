"""Isochrone kernel: one step of the isochrone leg router and its candidate kernel.

One step of :func:`~sailroute.routing.isochrone.route_isochrone` (the driver, which
keeps the setup, the layers and the backtracking) goes from a front to the next:
:func:`_step` prepares the inputs (:func:`~sailroute.routing.isochrone_inputs._prepare`:
wind, aim points, exact columns, time to go), expands and scores the candidates chunk by
chunk (:func:`_expand`), tests the arrival (:func:`_arrival`) and keeps the best
candidate per sector and side (:func:`_survivors`).  This module holds the step and the
candidate kernel: velocities, manoeuvre timing (a penalty as time debt), end points,
barrier and obstacle blocking, arrival, scores and the winner per sector.  The rest of
the kernel, each module importing only those above it:

* :mod:`sailroute.routing.isochrone_records`: the leg frame, the front records and the
  records of one step;
* :mod:`sailroute.routing.isochrone_polar`: the polar tables
  (:func:`~sailroute.routing.isochrone_polar.polar_tables`) and the lookups in them;
* :mod:`sailroute.routing.isochrone_togo`: the estimated time to go that ranks the
  candidates, and the aim points;
* :mod:`sailroute.routing.isochrone_inputs`: the inputs of one step.

Glossary of the kernel (symbols of ``docs/design/routing.md`` → names in the code; leg
frame, SI units, angles in degrees; the records named here are in
:mod:`~sailroute.routing.isochrone_records`, except :class:`_Timing`):

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
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np

from sailroute.backend import to_numpy
from sailroute.boat.polar import Polar
from sailroute.errors import RoutingError
from sailroute.routing import isochrone_fast as fast
from sailroute.routing.geometry import barrier_blocks, segment_crossing
from sailroute.routing.isochrone_inputs import _prepare
from sailroute.routing.isochrone_polar import _DeviceTables, _grid_speeds
from sailroute.routing.isochrone_records import (
    _CHUNK_ELEMENTS,
    _Arrival,
    _Context,
    _Layer,
    _LegFrame,
    _StepInputs,
)
from sailroute.routing.obstacles import Obstacles, constraint_label
from sailroute.routing.settings import RoutingSettings
from sailroute.wind.base import WindField

# --------------------------------------------------------------------------------------
# candidate blocks and chunks

_KEEP, _SWITCH = 0, 1
"""Candidate blocks of a point: ``_KEEP`` sails on its side, ``_SWITCH`` changes side
(tack or gybe).  A candidate's id is ``(row * 2 + block) * n_columns + column``."""

_EXACT_OF_BLOCK = ([0, 1, 2], [0, 1, 3])
"""The :class:`_ExactColumns` a block tries: VMG up, VMG down, its own direct column."""


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
    jit: bool = False,
) -> _Arrival | tuple[_Layer, bool, float, float]:
    """One isochrone step from the front ``f``; ``jit``: on the compiled path
    (:mod:`~sailroute.routing.isochrone_fast`, the same results).

    Returns the arrival if a candidate crosses the target during the step, else the
    new front, whether any point moved, the front's least estimated time to go [s] and
    its least distance to the target [m].
    """
    prepared = fast.prepare(f, wind, polar, dev, ctx, s, tau_hint) if jit else None
    if prepared is None:
        prepared = _prepare(f, wind, polar, dev, ctx, s, tau_hint, xp)
    pre, tau_min, dist_min = prepared
    arrival, best, who = _candidates(pre, dev, ctx, xp, jit)
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
    n_columns = pre.n_columns
    column = wid % n_columns
    block = (wid // n_columns) % 2
    row = wid // (2 * n_columns)
    if jit:
        layer, moved = fast.survivors(pre, row, block, column, best[won], dev)
    else:
        layer, moved = _survivors(pre, row, block, column, best[won], dev, xp)
    return layer, bool(xp.any(moved)), tau_min, dist_min


def _candidates(
    pre: _StepInputs, dev: _DeviceTables, ctx: _Context, xp: ModuleType, jit: bool
) -> tuple[_Arrival | None, Any, Any]:
    """Every candidate move of a step: the earliest arrival, or else the best candidate
    per key (sector and side, per member) with its score [s] and id (see :data:`_KEEP`),
    infinite and 0 where a key has none.

    ``jit``: the compiled kernel scores the candidates of a step without obstacles
    (:func:`~sailroute.routing.isochrone_fast.candidates`, the same results)."""
    if jit and ctx.obstacles is None:
        done = fast.candidates(pre, dev, ctx)
        if done is not None:
            return (None if done[0] is None else _arrival_of(pre, done[0])), done[1], done[2]
    n, n_columns = pre.n, pre.n_columns
    chunk = n if xp is not np else max(1, _CHUNK_ELEMENTS // (n_columns + 3))
    n_keys = 2 * ctx.n_bins * pre.n_groups
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
    return arrival, best, who


def _arrival_of(pre: _StepInputs, rec: Any) -> _Arrival:
    """The arrival the compiled kernel found, as :func:`_arrival` builds it from ``rec``
    (:func:`~sailroute.routing.isochrone_jit.candidates`: time into the step, row,
    block, column, fraction of the move, start, end, velocity, speed, delay, side)."""
    t_hit, row, ds, x0, y0, end_x, end_y = (float(rec[i]) for i in (1, 2, 5, 6, 7, 8, 9))
    heading = (
        _heading_deg(end_x - x0, end_y - y0)
        if pre.current_x is None  # through the water:
        else _heading_deg(float(rec[10]), float(rec[11]))
    )
    return _Arrival(
        parent=int(row),
        t_start=pre.t,
        t=pre.t + t_hit,
        x=x0 + ds * (end_x - x0),
        y=y0 + ds * (end_y - y0),
        heading=heading,
        bsp=float(rec[12]),
        delay=float(rec[13]),
        side=int(rec[14]),
    )


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
    dt = pre.dt_of(row)
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
    dt = c.dt_rows
    delay = xp.minimum(owed, dt)
    return _Timing(delay, dt - delay, owed - delay)


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
    dt = c.dt if isinstance(c.dt, float) else c.dt[sub, None]
    delay = xp.minimum(owed, dt)
    return _Timing(delay, dt - delay, owed - delay)


def _drifted(c: _StepInputs, qx: Any, qy: Any) -> tuple[Any, Any]:
    """End points moved by the current over the whole step, stopped or not."""
    if c.current_x is None:
        return qx, qy
    dt = c.dt_rows
    return qx + dt * c.current_x[:, None], qy + dt * c.current_y[:, None]


def _keep_ends(
    c: _StepInputs, keep: _Block, pending: Any, pending_timing: _Timing | None
) -> tuple[Any, Any]:
    """End points [m] of the moves of block ``_KEEP``: a whole step, except for the
    pending rows (``pending``, with their ``pending_timing``), which may still owe time."""
    qx = c.x[:, None] + c.dt_rows * keep.vx
    qy = c.y[:, None] + c.dt_rows * keep.vy
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
    separately).  The points themselves are tested for free water only in the leg's
    start layer (:attr:`_StepInputs.starts_free`): every later point ends a move found free."""
    px, py = to_numpy(c.x), to_numpy(c.y)
    reach = None if c.reach_m is None else to_numpy(c.reach_m)
    if c.starts_free and reach is not None and obstacles.fan_clear(px, py, reach, frame.to_world):
        return blocked  # the whole front is far from the race area's edges
    qx = np.concatenate([to_numpy(q[0]) for q in ends], axis=1)  # both blocks in one call
    qy = np.concatenate([to_numpy(q[1]) for q in ends], axis=1)
    bad = ~obstacles.moves_free(
        px, py, qx, qy, frame.to_world, starts_free=c.starts_free, reach=reach
    )
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
    what = constraint_label(name)
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
    score = c.keep.tau_s[:, None] - c.dt_rows * keep.rate
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


def _heading_deg(ux: float, uy: float) -> float:
    return math.degrees(math.atan2(ux, uy)) % 360.0
