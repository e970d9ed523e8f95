"""Layered-grid dynamic programming router (Dębski 2016), with mesh refinement.

The leg A→B is covered by ``R`` rows of nodes perpendicular to AB: the start
(point or line), ``R − 2`` free rows of ``C`` equidistant nodes across
``[−H, H]``, and the target's crossing segment (gate, finish line, or the
mark's rounding segment on the correct side).  Every node of a row connects
to every node of the next by a straight segment; the DAG is relaxed row by
row, forward in time, so that each segment is costed with the wind at the
time the boat sails it.

Two boat models (see ``docs/design/griddp.md``):

``Polar``
    Steady polar speed on ``settings.griddp.samples`` pieces of each segment (wind at the
    piece midpoint, at the time the boat is there), plus ``tack_penalty_s`` /
    ``gybe_penalty_s`` for every change of side.  DP state: (row, node, side
    of the last piece); ``2 C²`` segment evaluations per row.
``DynamicBoat``
    Dębski's segment dynamics: the entry speed of a segment follows from the
    predecessor's end speed and the turn angle δ (:meth:`DynamicBoat.initial_speed`).
    DP state: segment (row, start node, end node) with its arrival time and
    end speed; ``C³`` relaxations per row, each a table lookup
    (:class:`~sailroute.boat.dynamic.SegmentTable`), done as one array batch.

After each pass the best path is re-evaluated exactly (sequentially, with the
actual departure times) and the next pass re-centres the rows on it with the
band scaled by ``settings.griddp.shrink`` (node ``C // 2`` on the incumbent, so a pass never
gets worse).  The best pass is returned as a :class:`LegResult` built with the
shared track builder.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable
from dataclasses import dataclass, replace
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sailroute.backend import to_numpy
from sailroute.boat.dynamic import DynamicBoat, SegmentTable, chain_time
from sailroute.boat.model import BoatModel
from sailroute.errors import InputError, RoutingError
from sailroute.routing._dp_grid import (
    GridBoat,
    LegGrid,
    PathLimits,
    default_half_width,
    make_grid,
    node_inside,
    penalty_of,
    sample_chains,
)
from sailroute.routing.api import Router
from sailroute.routing.geometry import leg_label, target_barrier
from sailroute.routing.settings import GridDPSettings, RoutingSettings, check_settings
from sailroute.routing.track import build_track, make_leg_result
from sailroute.routing.types import LegResult, Start, Target, side_sign
from sailroute.wind.base import WindField

if TYPE_CHECKING:
    from sailroute.routing.obstacles import Obstacles
    from sailroute.wind.current import CurrentField

_SIDE_VALUE = np.array([-1, 1], dtype=np.int8)  # state index 0 = port, 1 = starboard


def _options(g: GridDPSettings) -> GridDPSettings:
    """``settings.griddp`` (validated by :func:`~sailroute.routing.settings.check_settings`)
    with plain Python numbers (a NumPy integer is a valid count)."""
    hw = g.half_width_m
    return GridDPSettings(
        rows=int(g.rows),
        cols=int(g.cols),
        refinements=int(g.refinements),
        half_width_m=None if hw is None else float(hw),
        shrink=float(g.shrink),
        samples=int(g.samples),
    )


@dataclass(frozen=True)
class GridDPPass:
    """Diagnostics of one DP pass.

    Attributes
    ----------
    band_half_width_m : float
        Half-width of the free rows' node band in this pass [m].
    node_spacing_m : float
        Spacing of the free rows' nodes [m].
    dp_time_s : float
        Leg time found by the DP on this grid [s].
    time_s : float
        Leg time of that path re-evaluated exactly [s].
    segment_evals : int
        Segment costings: ``2 C_r C_{r+1}`` per row for the polar model (both
        departure sides), ``C_{r-1} C_r C_{r+1}`` (the paper's count) for the
        dynamic model.
    wall_s : float
        Wall time of the pass [s].
    """

    band_half_width_m: float
    node_spacing_m: float
    dp_time_s: float
    time_s: float
    segment_evals: int
    wall_s: float


@dataclass(frozen=True, eq=False)
class GridDPSolution:
    """A grid-DP result with its diagnostics.

    Attributes
    ----------
    result : LegResult
        The best route over all passes.
    passes : tuple of GridDPPass
        One entry per pass (first pass, then refinements).
    half_width_m : float
        Half-width of the first pass [m].
    node_xy : ndarray, shape (R, 2)
        The best path's grid nodes [m].
    """

    result: LegResult
    passes: tuple[GridDPPass, ...]
    half_width_m: float
    node_xy: NDArray[np.float64]


# --------------------------------------------------------------------------------------
# public entry points


def route_griddp(
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
    obstacles: Obstacles | None = None,
) -> LegResult:
    """Fastest route of one leg by layered-grid DP with mesh refinement.

    Parameters
    ----------
    start : Start
        Start point, or start line (its nodes are row 0; the best one is
        reported as ``LegResult.start_xy``).
    target : Target
        Mark (ends on its rounding segment), gate or line.
    t0 : float
        Start time [epoch s].
    wind : WindField
        Wind; sampled at the time the boat sails each piece.
    boat : BoatModel
        Boat model (see the module docstring).
    settings : RoutingSettings
        ``settings.griddp`` (:class:`~sailroute.routing.settings.GridDPSettings`), the
        penalties (polar model), ``initial_side`` (polar model) and ``zone_m``.
    progress : callable, optional
        Called with the fraction done, in [0, 1].
    xp : module
        Array module of the relaxation kernels (NumPy; CuPy-compatible).
    current : CurrentField, optional
        Refused (the grid DP routes still water only): an :class:`InputError`.
    obstacles : Obstacles, optional
        Race-area boundary and obstacles: every straight piece between two nodes must
        stay in free water (:class:`~sailroute.routing._dp_grid.PathLimits`), so nodes
        inside an obstacle are never reached; widen ``dp_half_width_m`` for a detour
        longer than the layline band.

    Returns
    -------
    LegResult
        ``router == "griddp"``.

    Raises
    ------
    InputError
        Invalid settings, boat or leg geometry.
    RoutingError
        No feasible path on the grid (all paths leave the wind coverage or
        need the boat to sail where it cannot), or the best one takes longer
        than ``max_leg_time_s``.
    OutOfCoverageError
        The race outlasts the wind's time span (from the track builder).
    """
    if current is not None:
        raise InputError(
            f"leg {leg_label(start, target)}: the griddp router routes still water "
            "only; set routing.router: isochrone to route a current"
        )
    return solve_griddp(
        start, target, t0, wind, boat, settings, progress=progress, xp=xp, obstacles=obstacles
    ).result


def solve_griddp(
    start: Start,
    target: Target,
    t0: float,
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
    *,
    progress: Callable[[float], None] | None = None,
    xp: ModuleType = np,
    obstacles: Obstacles | None = None,
) -> GridDPSolution:
    """Like :func:`route_griddp`, with per-pass diagnostics (:class:`GridDPSolution`)."""
    check_settings(settings, leg_label(start, target))
    t0 = float(t0)
    grid = make_grid(start, target, settings.griddp.rows, settings.zone_m)
    opts = _options(settings.griddp)
    if not math.isfinite(t0):
        raise InputError(f"leg {grid.label}: start time must be finite, got {t0!r}")
    model = GridBoat.of(boat, grid.label)
    half = opts.half_width_m or default_half_width(grid.frame, wind, t0, model)
    n_pass = opts.refinements + 1
    params = [row.initial(opts.cols, half) for row in grid.rows]
    best: _PathEval | None = None
    best_params: list[float] = []
    passes = []
    for k in range(n_pass):
        tic = _time.perf_counter()
        if k > 0:
            scale = opts.shrink**k
            params = [
                row.refined(opts.cols, c, scale, half)
                for row, c in zip(grid.rows, best_params, strict=True)
            ]
        xy = [row.points(grid.frame, p) for row, p in zip(grid.rows, params, strict=True)]

        def rowprog(frac: float, k: int = k) -> None:
            if progress is not None:
                progress((k + frac) / n_pass)

        lim = grid.limits if obstacles is None else replace(grid.limits, obstacles=obstacles)
        if model.dynamic is not None:
            path, dp_time, evals = _dp_dynamic(model.dynamic, wind, xy, t0, opts, lim, xp, rowprog)
        else:
            path, dp_time, evals = _dp_polar(model, wind, xy, t0, opts, settings, lim, xp, rowprog)
        if path is None:
            raise _no_route(grid, half * opts.shrink**k, k)
        ev = evaluate_path(
            model,
            wind,
            np.array([xy[r][0][c] for r, c in enumerate(path)]),
            np.array([xy[r][1][c] for r, c in enumerate(path)]),
            t0,
            opts.samples,
            settings,
            limits=lim,
        )
        if best is None or ev.time_s < best.time_s:
            best = ev
            best_params = [float(params[r][c]) for r, c in enumerate(path)]
        band = half * opts.shrink**k
        passes.append(
            GridDPPass(
                band,
                2 * band / (opts.cols - 1),
                dp_time,
                ev.time_s,
                evals,
                _time.perf_counter() - tic,
            )
        )
    assert best is not None
    if not math.isfinite(best.time_s):
        raise _no_route(grid, half, 0)
    if best.time_s > settings.max_leg_time_s:
        raise RoutingError(
            f"leg {grid.label}: the best grid-DP route takes {best.time_s:.0f} s, more than "
            f"max_leg_time_s = {settings.max_leg_time_s:.0f} s; check the wind (calm?) or "
            "raise max_leg_time_s"
        )
    track = build_track(best.t, best.x, best.y, wind, model.polar, bsp_ms=best.bsp, side=best.side)
    if progress is not None:
        progress(1.0)
    result = make_leg_result(track, "griddp", target_barrier(target, start, settings.zone_m))
    return GridDPSolution(result, tuple(passes), half, np.stack([best.node_x, best.node_y], axis=1))


def _no_route(grid: LegGrid, band: float, k: int) -> RoutingError:
    return RoutingError(
        f"leg {grid.label}: the grid DP found no feasible path (pass {k + 1}, node band "
        f"±{band:.0f} m).  Every path either leaves the wind data, meets calm, needs a "
        "heading the boat cannot sail, or would pass a rounded mark on the wrong side.  "
        "Check that the wind covers the course area and race time, or widen the grid "
        "(dp_half_width_m) / add rows (dp_rows); a leg that must first finish a rounding "
        "of more than 180° needs the isochrone router."
    )


# --------------------------------------------------------------------------------------
# geometry helpers


def _chains(x0: NDArray, y0: NDArray, x1: NDArray, y1: NDArray, n: int) -> tuple[NDArray, NDArray]:
    """Vertices ``(C0, C1, n + 1)`` of straight segments from every node to every node."""
    f = np.linspace(0.0, 1.0, n + 1)
    px = x0[:, None, None] + (x1[None, :, None] - x0[:, None, None]) * f
    py = y0[:, None, None] + (y1[None, :, None] - y0[:, None, None]) * f
    return px, py


def _inside_pairs(
    wind: WindField, x0: NDArray, y0: NDArray, x1: NDArray, y1: NDArray, lim: PathLimits, last: bool
) -> NDArray:
    """Segments (every node of a row to every node of the next) that may be sailed:
    both ends inside the wind coverage, and the rounding limits respected."""
    ok = node_inside(wind, x0, y0)[:, None] & node_inside(wind, x1, y1)[None, :]
    return ok & lim.allowed(x0[:, None], y0[:, None], x1[None, :], y1[None, :], last)


# --------------------------------------------------------------------------------------
# polar model: state (node, side of the last piece)


def _dp_polar(
    model: GridBoat,
    wind: WindField,
    xy: list,
    t0: float,
    opts: GridDPSettings,
    s: RoutingSettings,
    lim: PathLimits,
    xp: ModuleType,
    progress: Callable[[float], None],
) -> tuple[list[int] | None, float, int]:
    n_rows = len(xy)
    c0 = xy[0][0].size
    T = np.full((c0, 2), np.inf)
    first = side_sign(s.initial_side)  # 0: either side
    for si, sv in enumerate(_SIDE_VALUE):
        if first in (0, sv):
            T[:, si] = t0
    T[~node_inside(wind, *xy[0])] = np.inf
    B = np.full((c0, 2), np.nan)  # |TWA| of the last piece (NaN: none yet)
    free_start = s.initial_side is None
    bps = []
    evals = 0
    for r in range(n_rows - 1):
        (x0, y0), (x1, y1) = xy[r], xy[r + 1]
        ca, cb = x0.size, x1.size
        px, py = _chains(x0, y0, x1, y1, opts.samples)
        t_dep = np.where(np.isfinite(T), T, t0)  # (ca, 2)
        cw = sample_chains(wind, px[:, None], py[:, None], t_dep[:, :, None], model)
        evals += 2 * ca * cb
        spd = model.steady_speed(cw.tws, cw.beta)
        with np.errstate(divide="ignore", invalid="ignore"):
            tp = np.where(cw.length > 0, cw.length / spd, 0.0)
        tp = np.where(np.isnan(tp), np.inf, tp)
        ok = (
            np.all(cw.valid, axis=-1)
            & _inside_pairs(wind, x0, y0, x1, y1, lim, r == n_rows - 2)[:, None, :]
        )
        side = cw.side
        ch = side[..., 1:] != side[..., :-1]
        pen_int = np.sum(
            ch
            * penalty_of(cw.beta[..., 1:], cw.beta[..., :-1], s.tack_penalty_s, s.gybe_penalty_s),
            axis=-1,
        )
        first_b = cw.beta[..., 0]
        old_b = np.broadcast_to(B[:, :, None], first_b.shape)
        join_pen = penalty_of(
            first_b, np.where(np.isnan(old_b), first_b, old_b), s.tack_penalty_s, s.gybe_penalty_s
        )
        state_side = _SIDE_VALUE[None, :, None]
        join = np.where(side[..., 0] != state_side, join_pen, 0.0)
        if r == 0 and free_start:
            join = np.zeros_like(join)  # both start states exist: the first side is free
        cost = T[:, :, None] + np.sum(tp, axis=-1) + pen_int + join
        cost = np.where(ok, cost, np.inf)
        last = side[..., -1]
        cost_x = xp.asarray(cost.reshape(ca * 2, cb))
        last_x = xp.asarray(last.reshape(ca * 2, cb))
        T_new = np.empty((cb, 2))
        bp = np.empty((cb, 2), dtype=np.int64)
        B_new = np.empty((cb, 2))
        lb = cw.beta[..., -1].reshape(ca * 2, cb)
        for si, sv in enumerate(_SIDE_VALUE):
            masked = xp.where(last_x == sv, cost_x, xp.inf)
            arg = to_numpy(xp.argmin(masked, axis=0))
            bp[:, si] = arg
            T_new[:, si] = to_numpy(masked)[arg, np.arange(cb)]
            B_new[:, si] = lb[arg, np.arange(cb)]
        bps.append(bp)
        T, B = T_new, B_new
        progress((r + 1) / (n_rows - 1))
    flat = int(np.argmin(T))
    if not np.isfinite(T.reshape(-1)[flat]):
        return None, math.inf, evals
    c, si = divmod(flat, 2)
    path = [c]
    for bp in reversed(bps):
        c, si = divmod(int(bp[c, si]), 2)
        path.append(c)
    return path[::-1], float(T.reshape(-1)[flat] - t0), evals


# --------------------------------------------------------------------------------------
# dynamic model: state = segment (start node, end node), carrying arrival time and speed


def _dp_dynamic(
    boat: DynamicBoat,
    wind: WindField,
    xy: list,
    t0: float,
    opts: GridDPSettings,
    lim: PathLimits,
    xp: ModuleType,
    progress: Callable[[float], None],
) -> tuple[list[int] | None, float, int]:
    model = GridBoat(boat, None, boat)
    tab = boat.table()
    n_rows = len(xy)
    n = opts.samples
    # first row of segments: from rest
    (x0, y0), (x1, y1) = xy[0], xy[1]
    px, py = _chains(x0, y0, x1, y1, n)
    cw = sample_chains(wind, px, py, np.full(x0.size, t0)[:, None], model)
    ok = np.all(cw.valid, axis=-1) & _inside_pairs(wind, x0, y0, x1, y1, lim, n_rows == 2)
    t, v_end = chain_time(
        boat,
        xp.asarray(cw.beta),
        xp.asarray(cw.tws),
        xp.asarray(cw.length),
        xp.ones(cw.beta.shape),
        xp.zeros(cw.beta.shape[:-1]),
        xp,
    )
    T = xp.where(xp.asarray(ok), t0 + t, xp.inf)
    V = v_end
    U = (xp.asarray(cw.ux[..., 0]), xp.asarray(cw.uy[..., 0]))
    evals = x0.size * x1.size
    bps = []
    progress(1.0 / (n_rows - 1))
    for r in range(1, n_rows - 1):
        (x0, y0), (x1, y1) = xy[r], xy[r + 1]
        cs, ce = x0.size, x1.size
        K = T.shape[0]
        t_est = to_numpy(xp.min(T, axis=0))  # earliest arrival at each node of row r
        reach = np.isfinite(t_est)
        px, py = _chains(x0, y0, x1, y1, n)
        cw = sample_chains(wind, px, py, np.where(reach, t_est, t0)[:, None], model)
        ok = (
            np.all(cw.valid, axis=-1)
            & reach[:, None]
            & _inside_pairs(wind, x0, y0, x1, y1, lim, r == n_rows - 2)
        )
        beta, tws, length = (xp.asarray(a) for a in (cw.beta, cw.tws, cw.length))
        b1, vt1, l1 = beta[..., 0], tws[..., 0], length[..., 0]
        ws1 = tab.steady(b1, xp)
        calm1 = vt1 <= 1e-6
        nogo1 = b1 < tab.beta_min
        slow1 = (b1 < tab.beta_lo) & ~nogo1
        vts = xp.where(calm1, 1.0, vt1)
        wss = xp.where(ws1 > 0, ws1, 1.0)
        v_exit1 = ws1 * vt1
        if n > 1:
            t_tail, v_seg = chain_time(
                boat,
                beta[..., 1:],
                tws[..., 1:],
                length[..., 1:],
                xp.ones(beta[..., 1:].shape),
                v_exit1,
                xp,
            )
        else:
            t_tail, v_seg = xp.zeros(b1.shape), v_exit1
        base = l1 / (wss * vts) + t_tail
        base = xp.where(nogo1 | calm1 | ~xp.asarray(ok), xp.inf, base)
        seg_len = xp.sum(length, axis=-1)
        fallback = ((seg_len < tab.sconv_at(b1, xp)) & ~nogo1 & ~slow1) | (
            nogo1 & (l1 < tab.stop_max)
        )
        fallback = fallback & xp.asarray(ok) & ~calm1
        ux1, uy1 = xp.asarray(cw.ux[..., 0]), xp.asarray(cw.uy[..., 0])
        seg = _SegData.build(tab, ux1, uy1, b1, ws1, vt1, vts, base, slow1, fallback, xp)
        T_new, bp, over = _relax(T, V, U, seg, boat, tab, xp)
        evals += K * cs * ce
        # triples the table cannot serve: short segments, entry speeds above the table
        fb_c, fb_e = xp.nonzero(fallback)
        k_list = [xp.repeat(xp.arange(K), fb_c.size), xp.tile(fb_c, K), xp.tile(fb_e, K)]
        if over is not None:
            k_list = [xp.concatenate([a, o]) for a, o in zip(k_list, over, strict=True)]
        k_i, c_i, e_i = k_list
        keep = xp.isfinite(T[k_i, c_i])
        k_i, c_i, e_i = k_i[keep], c_i[keep], e_i[keep]
        V_new = v_seg + xp.zeros(T_new.shape)
        if k_i.size:
            cos_t = xp.ones((k_i.size, n))
            cos_t[:, 0] = U[0][k_i, c_i] * ux1[c_i, e_i] + U[1][k_i, c_i] * uy1[c_i, e_i]
            t_ex, v_ex = chain_time(
                boat, beta[c_i, e_i], tws[c_i, e_i], length[c_i, e_i], cos_t, V[k_i, c_i], xp
            )
            a_ex = T[k_i, c_i] + t_ex
            # sequential merge keeps the lowest k on ties, like argmin
            for q in range(int(k_i.size)):
                ci, ei = int(c_i[q]), int(e_i[q])
                if float(a_ex[q]) < float(T_new[ci, ei]) or (
                    float(a_ex[q]) == float(T_new[ci, ei]) and int(k_i[q]) < int(bp[ci, ei])
                ):
                    T_new[ci, ei] = a_ex[q]
                    bp[ci, ei] = k_i[q]
                    V_new[ci, ei] = v_ex[q]
        T, V, U = T_new, V_new, (ux1, uy1)
        bps.append(to_numpy(bp))
        progress((r + 1) / (n_rows - 1))
    Tn = to_numpy(T)
    flat = int(np.argmin(Tn))
    if not np.isfinite(Tn.reshape(-1)[flat]):
        return None, math.inf, evals
    cs_, ce_ = divmod(flat, Tn.shape[1])
    path = [ce_, cs_]
    for bp in reversed(bps):
        k = int(bp[cs_, ce_])
        cs_, ce_ = k, cs_
        path.append(cs_)
    return path[::-1], float(Tn.reshape(-1)[flat] - t0), evals


@dataclass(frozen=True, eq=False)
class _SegData:
    """Per-segment constants of one row transition of the dynamic DP (shape ``(cs, ce)``)."""

    ux: Any
    uy: Any
    thr: Any  # entry speed at the steady speed [m/s]: accelerating below, decelerating above
    acc: Any  # index per m/s on the accelerating branch
    dec: Any  # index per m/s on the decelerating branch ...
    dec0: Any  # ... and its offset
    row: Any  # first coefficient row of the segment's angle column
    fb: Any  # weight of the next angle column
    base: Any  # time without the transient loss [s] (inf: excluded here)
    coef: Any  # 1 / v_t for the loss [s/m], 0 where the loss is ignored

    @classmethod
    def build(
        cls,
        tab: SegmentTable,
        ux: Any,
        uy: Any,
        b1: Any,
        ws1: Any,
        vt1: Any,
        vts: Any,
        base: Any,
        slow: Any,
        fallback: Any,
        xp: ModuleType,
    ) -> _SegData:
        m = tab.nq - 1
        j0, fb = tab.column(b1, xp)
        thr = ws1 * vt1
        acc = m / xp.where(thr > 0, thr, 1.0)
        dec = m / ((tab.w_max - ws1) * vts)
        dec0 = m - thr * dec
        return cls(
            ux,
            uy,
            thr,
            acc,
            dec,
            dec0,
            j0 * (2 * m),
            fb,
            xp.where(fallback, xp.inf, base),
            xp.where(slow, 0.0, 1.0 / vts),
        )


_CHUNK = 1 << 17  # triples per numpy batch (keeps the temporaries in cache)


def _relax(
    T: Any,
    V: Any,
    U: tuple[Any, Any],
    seg: _SegData,
    boat: DynamicBoat,
    tab: SegmentTable,
    xp: ModuleType,
) -> tuple[Any, Any, tuple[Any, Any, Any] | None]:
    """Best predecessor of every segment: ``min_k T[k, cs] + t(k, cs, ce)``.

    All ``(k, cs, ce)`` triples are evaluated as array batches (the whole row
    at once for GPU modules, chunks of :data:`_CHUNK` triples for NumPy).
    Returns the arrival times, the argmin over ``k`` (lowest ``k`` on ties) and
    the triples whose entry speed exceeds the table (to be simulated).
    """
    K, cs = T.shape
    ce = seg.ux.shape[1]
    xmax = 2.0 * (tab.nq - 1) - 1e-9
    poly = tab.poly(xp)
    nrow = 2 * (tab.nq - 1)
    step = K if xp is not np else max(1, _CHUNK // max(cs * ce, 1))
    best = bp = None
    over_parts = []
    for k0 in range(0, K, step):
        ks = slice(k0, min(K, k0 + step))
        cosd = U[0][ks, :, None] * seg.ux[None] + U[1][ks, :, None] * seg.uy[None]
        c2 = cosd * cosd
        v0 = V[ks, :, None] * xp.where(cosd >= boat.um, 1.0, xp.where(cosd > boat.lm, c2 * c2, 0.0))
        xq = xp.where(v0 <= seg.thr, v0 * seg.acc, v0 * seg.dec + seg.dec0)
        over = xq > xmax
        xq = xp.clip(xq, 0.0, xmax)
        i0 = xq.astype(xp.int64)
        f = xq - i0
        r0 = seg.row + i0
        g0 = _gather_rows(poly, r0, xp)
        g1 = _gather_rows(poly, r0 + nrow, xp)
        g = g0 + seg.fb[..., None] * (g1 - g0)
        loss = g[..., 0] + f * (g[..., 1] + f * (g[..., 2] + f * g[..., 3]))
        arr = T[ks, :, None] + seg.base + loss * seg.coef
        arr = xp.where(over, xp.inf, arr)
        if bool(xp.any(over & xp.isfinite(T[ks, :, None]))):
            ok_, oc, oe = xp.nonzero(over & xp.isfinite(T[ks, :, None]))
            over_parts.append((ok_ + k0, oc, oe))
        mn = xp.min(arr, axis=0)
        am = xp.argmin(arr, axis=0) + k0
        if best is None:
            best, bp = mn, am
        else:
            upd = mn < best
            best = xp.where(upd, mn, best)
            bp = xp.where(upd, am, bp)
    over_idx = None
    if over_parts:
        over_idx = tuple(xp.concatenate([p[i] for p in over_parts]) for i in range(3))
    return best, bp, over_idx


def _gather_rows(table: Any, idx: Any, xp: ModuleType) -> Any:
    """``table[idx]`` for a C-contiguous ``(M, 4)`` table (fast path for NumPy)."""
    if xp is np:
        rows = table.view(np.dtype((np.void, table.strides[0]))).reshape(-1)
        return np.take(rows, idx).view(table.dtype).reshape(*idx.shape, table.shape[1])
    return xp.take(table, idx, axis=0)


# --------------------------------------------------------------------------------------
# exact evaluation of one path


@dataclass(frozen=True, eq=False)
class _PathEval:
    time_s: float
    t: NDArray
    x: NDArray
    y: NDArray
    bsp: NDArray | None
    side: NDArray
    node_x: NDArray
    node_y: NDArray


def evaluate_path(
    model: GridBoat,
    wind: WindField,
    xs: NDArray,
    ys: NDArray,
    t0: float,
    samples: int,
    settings: RoutingSettings,
    *,
    limits: PathLimits | None = None,
) -> _PathEval:
    """Sail a polyline exactly as the DP costs it, segment by segment in time order.

    Returns the leg time and the track vertices: the nodes, the piece
    boundaries, and for the polar model a repeated vertex where a tack or gybe
    penalty stops the boat.  ``side`` is the side of the piece leaving each
    vertex (the last vertex repeats the last piece's).  A path that breaks
    ``limits`` (the leg's :class:`PathLimits`) takes infinitely long.
    """
    n = samples
    f = np.linspace(0.0, 1.0, n + 1)
    t = float(t0)
    out_t, out_x, out_y, out_s, out_v = [], [], [], [], []
    cur_side = side_sign(settings.initial_side)
    cur_beta = math.nan
    v = 0.0
    prev_dir: tuple[float, float] | None = None
    if limits is not None:
        last = np.arange(xs.size - 1) == xs.size - 2
        if not np.all(
            limits.allowed(xs[:-1], ys[:-1], xs[1:], ys[1:], False)
            & (limits.allowed(xs[:-1], ys[:-1], xs[1:], ys[1:], True) | ~last)
        ):
            return _PathEval(math.inf, *(np.zeros(0),) * 3, None, np.zeros(0, np.int8), xs, ys)
    for r in range(xs.size - 1):
        px = xs[r] + (xs[r + 1] - xs[r]) * f
        py = ys[r] + (ys[r + 1] - ys[r]) * f
        cw = sample_chains(wind, px[None], py[None], np.array([t]), model)
        if not (np.all(cw.valid) and np.all(node_inside(wind, px[[0, -1]], py[[0, -1]]))):
            return _PathEval(math.inf, *(np.zeros(0),) * 3, None, np.zeros(0, np.int8), xs, ys)
        side = cw.side[0]
        beta = cw.beta[0]
        if model.dynamic is not None:
            d = (float(cw.ux[0, 0]), float(cw.uy[0, 0]))
            cos0 = 1.0 if prev_dir is None else d[0] * prev_dir[0] + d[1] * prev_dir[1]
            cos_t = np.ones((1, n))
            cos_t[0, 0] = cos0
            _, v_end, tp, v_in = chain_time(
                model.dynamic, cw.beta, cw.tws, cw.length, cos_t, np.array([v]), pieces=True
            )
            for j in range(n):
                out_t.append(t)
                out_x.append(px[j])
                out_y.append(py[j])
                out_s.append(int(side[j]))
                out_v.append(float(v_in[0, j]))
                t += float(tp[0, j])
            v = float(v_end[0])
            prev_dir = d
        else:
            spd = model.steady_speed(cw.tws[0], beta)
            for j in range(n):
                if cur_side != 0 and side[j] != cur_side:
                    old = beta[j] if math.isnan(cur_beta) else cur_beta
                    pen = float(
                        penalty_of(
                            np.array(beta[j]),
                            np.array(old),
                            settings.tack_penalty_s,
                            settings.gybe_penalty_s,
                        )
                    )
                    out_t.append(t)
                    out_x.append(px[j])
                    out_y.append(py[j])
                    out_s.append(int(side[j]))
                    t += pen
                out_t.append(t)
                out_x.append(px[j])
                out_y.append(py[j])
                out_s.append(int(side[j]))
                ell = float(cw.length[0, j])
                if ell > 0:
                    t = t + ell / float(spd[j]) if spd[j] > 0 else math.inf
                cur_side = int(side[j])
                cur_beta = float(beta[j])
        if not math.isfinite(t):
            return _PathEval(math.inf, *(np.zeros(0),) * 3, None, np.zeros(0, np.int8), xs, ys)
    out_t.append(t)
    out_x.append(float(xs[-1]))
    out_y.append(float(ys[-1]))
    out_s.append(out_s[-1] if out_s else 1)
    out_v.append(v)
    bsp = np.array(out_v) if model.dynamic is not None else None
    return _PathEval(
        t - t0,
        np.array(out_t),
        np.array(out_x),
        np.array(out_y),
        bsp,
        np.array(out_s, dtype=np.int8),
        xs,
        ys,
    )


_ROUTER: Router = route_griddp  # mypy checks the shared router signature
