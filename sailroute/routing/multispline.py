"""Adaptive multi-spline refinement (Dębski 2016b): C¹ routes from a layered DP.

Rows of nodes as in the grid DP (``routing/griddp.py``), but every node also
carries ``n_ts`` tangent slopes and an edge is the cubic Hermite curve that
joins ``(r, c, s)`` to ``(r + 1, c', s')`` with those end slopes.  In the leg's
along/across coordinates ``(X, Y)`` an edge is

.. math::  X(t) = X_0 + t\\,\\Delta X,\\qquad
           Y(t) = h_{00} Y_0 + h_{10} \\Delta X\\, m_0 + h_{01} Y_1 + h_{11} \\Delta X\\, m_1,

``t ∈ [0, 1]``, ``ΔX = X_1 − X_0``, slopes ``m = dY/dX``.  The DP state is
``(row, node, slope)``: the route is C¹, so the heading is continuous at the
nodes.  After each pass the grid is re-centred on the best curve: node ranges
and slope ranges shrink geometrically (``k_y = k_α = 1/3``), the reference
slope of a row is the central difference of the best curve's nodes, and the
first pass spans slopes ``±π/5`` around the leg axis.

:func:`fit_multispline` is the generic core (any additive edge cost, e.g. the
function-fitting test problem of the paper); :func:`route_spline` routes a leg
with it, costing each edge by sailing ``m`` chords of the curve (wind at the
time the boat is there, as in the grid DP).  Multi-splines cannot tack (a C¹
curve turning through the wind crosses the no-go zone), so the router is meant
for legs whose best route is one smooth curve; use the grid DP otherwise.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.backend import to_numpy
from sailroute.boat.dynamic import DynamicBoat, chain_time
from sailroute.boat.model import BoatModel
from sailroute.errors import InputError, RoutingError
from sailroute.numerics import hermite, hermite_basis
from sailroute.routing._dp_grid import (
    ChainWind,
    GridBoat,
    LegFrame,
    PathLimits,
    Row,
    default_half_width,
    make_grid,
    penalty_of,
    sample_chains,
    sample_wind,
)
from sailroute.routing.api import Router
from sailroute.routing.geometry import leg_label, target_barrier
from sailroute.routing.settings import RoutingSettings, check_settings
from sailroute.routing.track import build_track, make_leg_result
from sailroute.routing.types import LegResult, Start, Target
from sailroute.wind.base import WindField

if TYPE_CHECKING:
    from sailroute.routing.obstacles import Obstacles
    from sailroute.wind.current import CurrentField

K_Y = 1.0 / 3.0
"""Shrink factor of the node ranges per refinement (paper value)."""
K_ALPHA = 1.0 / 3.0
"""Shrink factor of the slope-angle ranges per refinement (paper value)."""
SLOPE_HALF0 = math.pi / 5.0
"""Initial half range of the slope angles [rad] (paper value)."""
CHORDS = 8
"""Chords per edge used to sail a spline edge in :func:`route_spline`."""
_MAX_SLOPE_ANGLE = math.radians(85.0)


# --------------------------------------------------------------------------------------
# Hermite edges


def hermite_y(y0: Any, m0: Any, y1: Any, m1: Any, dx: Any, t: Any) -> Any:
    """Across coordinate of Hermite edges at parameters ``t`` (broadcast).

    :func:`sailroute.numerics.hermite` in the edge's terms: ends ``y0, y1`` [m],
    slopes ``m0, m1 = dY/dX`` [-], along span ``dx`` [m].
    """
    return hermite(y0, y1, m0, m1, t, dx)


@dataclass(frozen=True, eq=False)
class Edges:
    """All edges between two rows, broadcast to shape ``(C0, S0, C1, S1)``.

    Attributes
    ----------
    x0, y0, m0 : ndarray, shape (C0, 1, 1, 1) / (C0, 1, 1, 1) / (1, S0, 1, 1)
        Start node along/across coordinates and slope ``dY/dX``.
    x1, y1, m1 : ndarray, shape (1, 1, C1, 1) / ... / (1, 1, 1, S1)
        End node.
    acc : ndarray, shape (C0, S0, 1, 1)
        Accumulated cost of the start states (elapsed time for routing).
    carry : ndarray, shape (C0, S0, 1, 1), or None
        State carried along the best path into the start states (the boat
        speed for routing with ``settings.spline.carry_speed``); None on the first row
        or when the edge cost carries nothing.
    """

    x0: NDArray
    y0: NDArray
    m0: NDArray
    x1: NDArray
    y1: NDArray
    m1: NDArray
    acc: NDArray
    carry: NDArray | None = None

    @property
    def shape(self) -> tuple[int, ...]:
        """Broadcast shape ``(C0, S0, C1, S1)``."""
        return np.broadcast_shapes(self.x0.shape, self.m0.shape, self.x1.shape, self.m1.shape)

    def points(self, t: NDArray) -> tuple[NDArray, NDArray]:
        """Along/across coordinates at parameters ``t``: shape ``(C0, S0, C1, S1, len(t))``."""
        t = np.asarray(t, float)
        dx = (self.x1 - self.x0)[..., None]
        x = self.x0[..., None] + t * dx
        y = hermite_y(
            self.y0[..., None], self.m0[..., None], self.y1[..., None], self.m1[..., None], dx, t
        )
        x, y = np.broadcast_arrays(x, y)
        return x, y


EdgeCost = Callable[[int, Edges], "NDArray | tuple[NDArray, NDArray]"]
"""``edge_cost(r, edges) -> cost`` of shape ``edges.shape`` (``inf``: forbidden).

It may instead return ``(cost, carry)``: ``carry`` (broadcast to ``edges.shape``)
is the state at the end of each edge; the DP keeps it for the best predecessor of
every state and passes it back as ``Edges.carry`` on the next row.
"""


@dataclass(frozen=True)
class SplinePass:
    """Diagnostics of one multi-spline DP pass.

    Attributes
    ----------
    cost : float
        Best total cost on this pass's grid.
    node_scale : float
        Node range relative to the first pass (``k_y^k``).
    slope_half_deg : float
        Half range of the slope angles [°].
    edges : int
        Edges costed.
    wall_s : float
        Wall time [s].
    """

    cost: float
    node_scale: float
    slope_half_deg: float
    edges: int
    wall_s: float


@dataclass(frozen=True, eq=False)
class SplineFit:
    """Best multi-spline over all passes.

    Attributes
    ----------
    along, across : ndarray, shape (R,)
        Node coordinates of the best curve [frame units].
    slopes : ndarray, shape (R,)
        Its slopes ``dY/dX`` at the nodes.
    params : ndarray, shape (R,)
        Row parameters of its nodes (see :class:`~sailroute.routing._dp_grid.Row`).
    cost : float
        Its total cost.
    passes : tuple of SplinePass
        One entry per pass; ``cost`` is non-increasing (the incumbent stays
        representable in every refined grid).
    """

    along: NDArray[np.float64]
    across: NDArray[np.float64]
    slopes: NDArray[np.float64]
    params: NDArray[np.float64]
    cost: float
    passes: tuple[SplinePass, ...]

    def curve(self, n_per_edge: int = 32) -> tuple[NDArray, NDArray]:
        """The curve sampled ``n_per_edge`` times per edge (along, across)."""
        t = np.linspace(0.0, 1.0, n_per_edge + 1)[:-1]
        xs, ys = [], []
        for r in range(self.along.size - 1):
            dx = self.along[r + 1] - self.along[r]
            xs.append(self.along[r] + t * dx)
            ys.append(
                hermite_y(
                    self.across[r], self.slopes[r], self.across[r + 1], self.slopes[r + 1], dx, t
                )
            )
        xs.append(self.along[-1:])
        ys.append(self.across[-1:])
        return np.concatenate(xs), np.concatenate(ys)


# --------------------------------------------------------------------------------------
# generic core


def multispline_pass(
    frame: LegFrame,
    rows: Sequence[Row],
    params: Sequence[NDArray],
    slopes: Sequence[NDArray],
    edge_cost: EdgeCost,
    xp: ModuleType = np,
    progress: Callable[[float], None] | None = None,
) -> tuple[list[tuple[int, int]] | None, float, int]:
    """One DP pass over states ``(row, node, slope)``.

    Returns the best path as ``(node, slope)`` per row (None if every path is
    infeasible), its cost and the number of edges costed.
    """
    xy = [frame.coords(*row.points(frame, p)) for row, p in zip(rows, params, strict=True)]
    n_rows = len(rows)
    A = np.zeros((xy[0][0].size, slopes[0].size))
    carry: NDArray | None = None
    bps = []
    edges = 0
    for r in range(n_rows - 1):
        (xa, ya), (xb, yb) = xy[r], xy[r + 1]
        e = Edges(
            xa[:, None, None, None],
            ya[:, None, None, None],
            slopes[r][None, :, None, None],
            xb[None, None, :, None],
            yb[None, None, :, None],
            slopes[r + 1][None, None, None, :],
            A[:, :, None, None],
            None if carry is None else carry[:, :, None, None],
        )
        out = edge_cost(r, e)
        cost, c_out = out if isinstance(out, tuple) else (out, None)
        cost = np.broadcast_to(np.asarray(cost, float), e.shape)
        edges += int(np.prod(e.shape))
        c0, s0, c1, s1 = e.shape
        tot = xp.asarray((A[:, :, None, None] + cost).reshape(c0 * s0, c1 * s1))
        arg = xp.argmin(tot, axis=0)
        A = to_numpy(xp.take_along_axis(tot, arg[None], axis=0)[0]).reshape(c1, s1)
        arg_np = to_numpy(arg)
        bps.append(arg_np.reshape(c1, s1))
        if c_out is not None:
            flat = np.broadcast_to(np.asarray(c_out, float), e.shape).reshape(c0 * s0, c1 * s1)
            carry = flat[arg_np, np.arange(c1 * s1)].reshape(c1, s1)
        if progress is not None:
            progress((r + 1) / (n_rows - 1))
    i_best = int(np.argmin(A))
    best = float(A.reshape(-1)[i_best])
    if not math.isfinite(best):
        return None, math.inf, edges
    c, s = divmod(i_best, A.shape[1])
    path = [(c, s)]
    for r in range(n_rows - 2, -1, -1):
        c, s = divmod(int(bps[r][c, s]), slopes[r].size)
        path.append((c, s))
    return path[::-1], best, edges


def _slope_set(ref: float, half: float, n: int, keep: float | None) -> NDArray:
    """``n`` slopes at angles ``atan(ref) ± half``; ``keep`` replaces the nearest one."""
    a0 = math.atan(ref)
    ang = np.clip(
        a0 + np.linspace(-half, half, n) if n > 1 else np.array([a0]),
        -_MAX_SLOPE_ANGLE,
        _MAX_SLOPE_ANGLE,
    )
    m = np.tan(ang)
    if keep is not None:
        m[int(np.argmin(np.abs(ang - math.atan(keep))))] = keep
    return m


def _reference_slopes(x: NDArray, y: NDArray) -> NDArray:
    """Slopes ``dY/dX`` of a node sequence by central differences (one-sided at the ends)."""
    if x.size < 2:
        return np.zeros_like(x)
    return np.gradient(y, x) if np.all(np.diff(x) > 0) else np.zeros_like(x)


def fit_multispline(
    edge_cost: EdgeCost,
    frame: LegFrame,
    rows: Sequence[Row],
    *,
    n_cols: int,
    n_slopes: int,
    n_refine: int,
    half_width: float,
    slope_half: float = SLOPE_HALF0,
    k_y: float = K_Y,
    k_alpha: float = K_ALPHA,
    centre: float = 0.0,
    xp: ModuleType = np,
    progress: Callable[[float], None] | None = None,
) -> SplineFit:
    """Adaptive multi-spline refinement with an arbitrary additive edge cost.

    Parameters
    ----------
    edge_cost : callable
        ``edge_cost(r, edges) -> cost`` for all edges from row ``r`` to ``r + 1``
        (:class:`Edges`); may depend on ``edges.acc`` (the cost so far) as long
        as arriving earlier never costs more.
    frame : LegFrame
        Maps along/across coordinates to the plane.
    rows : sequence of Row
        Node rows; free rows are parametrised by their across offset.
    n_cols : int
        Nodes per free or line row.
    n_slopes : int
        Slopes per node (``n_ts``; the paper uses 5-9).
    n_refine : int
        Refinements after the first pass.
    half_width : float
        Half range of the free rows' offsets in the first pass.
    slope_half : float
        Half range of the slope angles in the first pass [rad].
    k_y, k_alpha : float
        Shrink factors of the node and slope ranges per refinement.
    centre : float
        Centre of the free rows' offsets in the first pass.
    xp : module
        Array module of the DP minimisation.
    progress : callable, optional
        Called with the fraction done.

    Returns
    -------
    SplineFit
        The best curve over all passes.

    Notes
    -----
    A refined grid puts node ``n_cols // 2`` on the incumbent's node and
    replaces the slope nearest the incumbent's slope by it, so the incumbent
    stays representable and the cost never increases from pass to pass.
    """
    if n_cols < 2 or n_slopes < 1 or n_refine < 0:
        raise InputError(
            f"multi-spline: need n_cols >= 2, n_slopes >= 1, n_refine >= 0; got "
            f"{n_cols}, {n_slopes}, {n_refine}"
        )
    n_pass = n_refine + 1
    params = [
        row.initial(n_cols, half_width) + (centre if row.kind == "free" else 0.0) for row in rows
    ]
    slopes = [_slope_set(0.0, slope_half, n_slopes, None) for _ in rows]
    best: SplineFit | None = None
    passes = []
    for k in range(n_pass):
        tic = _time.perf_counter()
        if k > 0:
            assert best is not None
            scale = k_y**k
            params = [
                row.refined(n_cols, c, scale, half_width)
                for row, c in zip(rows, best.params, strict=True)
            ]
            ref = _reference_slopes(best.along, best.across)
            half = slope_half * k_alpha**k
            slopes = [
                _slope_set(float(ref[r]), half, n_slopes, float(best.slopes[r]))
                for r in range(len(rows))
            ]

        def prog(f: float, k: int = k) -> None:
            if progress is not None:
                progress((k + f) / n_pass)

        path, cost, n_edges = multispline_pass(frame, rows, params, slopes, edge_cost, xp, prog)
        passes.append(
            SplinePass(
                cost,
                k_y**k,
                math.degrees(slope_half * k_alpha**k),
                n_edges,
                _time.perf_counter() - tic,
            )
        )
        if path is None:
            continue
        if best is None or cost < best.cost:
            p = np.array([params[r][c] for r, (c, _) in enumerate(path)])
            xs, ys = [], []
            for r, (c, _) in enumerate(path):
                px, py = rows[r].points(frame, params[r][c : c + 1])
                a, b = frame.coords(px, py)
                xs.append(float(a[0]))
                ys.append(float(b[0]))
            m = np.array([slopes[r][s] for r, (_, s) in enumerate(path)])
            best = SplineFit(np.array(xs), np.array(ys), m, p, cost, ())
    if best is None:
        return SplineFit(
            np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0), math.inf, tuple(passes)
        )
    return SplineFit(best.along, best.across, best.slopes, best.params, best.cost, tuple(passes))


# --------------------------------------------------------------------------------------
# the function-fitting test problem of the paper


def fitting_target(theta: ArrayLike) -> NDArray[np.float64]:
    """``r_t(θ) = (1 + 2θ(1 + θ)) / (1 + 4θ²) · θ(π − θ)``, the paper's test function."""
    th = np.asarray(theta, dtype=float)
    return (1.0 + 2.0 * th * (1.0 + th)) / (1.0 + 4.0 * th * th) * th * (np.pi - th)


def l2_edge_cost(target: Callable[[NDArray], NDArray], n_gauss: int = 8) -> EdgeCost:
    """Edge cost ``∫ (Y(X) − target(X))² dX`` by Gauss-Legendre quadrature (fixed-X rows).

    When every edge of a row spans the same ``X`` interval (rows at fixed
    ``X``, as in :func:`fit_function`) the cost separates: with
    ``Y = P(y0, m0) + Q(y1, m1)`` at the quadrature nodes,
    ``Σ w (P + Q − target)² = Σ w (P − target)² + Σ w Q² + 2 Σ w (P − target) Q``,
    so the row's ``(C0 S0) × (C1 S1)`` costs are two vectors and one matrix
    product instead of a quadrature per edge (equal to rounding: about 1e-16
    of the terms, 1e-10 relative to a converged edge's cost).
    """
    g, w = np.polynomial.legendre.leggauss(n_gauss)
    t = 0.5 * (g + 1.0)
    h00, h10, h01, h11 = hermite_basis(t)

    def cost(r: int, e: Edges) -> NDArray:
        x0, x1 = np.asarray(e.x0, float), np.asarray(e.x1, float)
        if x0.size and np.all(x0 == x0.flat[0]) and np.all(x1 == x1.flat[0]):
            c0, s0, c1, s1 = e.shape
            xa = float(x0.flat[0])
            dx = float(x1.flat[0]) - xa
            ref = target(xa + t * dx)
            y0 = np.broadcast_to(e.y0, (c0, 1, 1, 1)).reshape(c0, 1, 1)
            m0 = np.broadcast_to(e.m0, (1, s0, 1, 1)).reshape(1, s0, 1)
            y1 = np.broadcast_to(e.y1, (1, 1, c1, 1)).reshape(c1, 1, 1)
            m1 = np.broadcast_to(e.m1, (1, 1, 1, s1)).reshape(1, s1, 1)
            p = (h00 * y0 + h10 * dx * m0 - ref).reshape(c0 * s0, -1)
            q = (h01 * y1 + h11 * dx * m1).reshape(c1 * s1, -1)
            tot = (p * w) @ q.T
            tot *= 2.0
            tot += ((p * p) @ w)[:, None]
            tot += ((q * q) @ w)[None, :]
            np.maximum(tot, 0.0, out=tot)
            tot *= 0.5 * dx
            return tot.reshape(c0, s0, c1, s1)
        x, y = e.points(t)
        dxs = np.broadcast_to(e.x1 - e.x0, e.shape)
        return 0.5 * dxs * np.sum(w * (y - target(x)) ** 2, axis=-1)

    return cost


def fit_function(
    target: Callable[[NDArray], NDArray] = fitting_target,
    *,
    x_end: float = math.pi,
    n_rows: int = 10,
    n_cols: int = 25,
    n_slopes: int = 7,
    n_refine: int = 4,
    lo: float = -0.5,
    hi: float = 3.0,
) -> SplineFit:
    """Fit ``y(x)`` on ``[0, x_end]`` with ``y(0) = y(x_end) = 0`` by multi-spline refinement.

    The paper's test problem: the DP minimises the squared L2 distance to
    ``target`` (default :func:`fitting_target`); ``SplineFit.cost`` is that
    squared distance.  Interior node values start in ``[lo, hi]``.
    """
    frame = LegFrame(0.0, 0.0, 1.0, 0.0, x_end)
    xs = np.linspace(0.0, x_end, n_rows)
    rows = [Row("point", a=(0.0, 0.0))]
    rows += [Row("free", along=float(x)) for x in xs[1:-1]]
    rows += [Row("point", a=(x_end, 0.0))]
    return fit_multispline(
        l2_edge_cost(target),
        frame,
        rows,
        n_cols=n_cols,
        n_slopes=n_slopes,
        n_refine=n_refine,
        half_width=0.5 * (hi - lo),
        centre=0.5 * (hi + lo),
    )


# --------------------------------------------------------------------------------------
# routing


def route_spline(
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
    """Fastest C¹ route of one leg by adaptive multi-spline refinement.

    Parameters
    ----------
    start, target, t0, wind, boat, settings, progress, xp
        As :func:`~sailroute.routing.griddp.route_griddp`; the grid uses
        ``settings.spline`` (:class:`~sailroute.routing.settings.SplineSettings`).
    current, obstacles : optional
        Refused with an :class:`InputError`: the spline router routes still, open
        water only (a smooth curve round an obstacle would need its tangents fitted to
        the obstacle; route such a course with the isochrone or grid-DP router).

    Returns
    -------
    LegResult
        ``router == "spline"``; track vertices every chord (``CHORDS`` per edge).

    Raises
    ------
    InputError
        Invalid settings, or a current or obstacles given.
    RoutingError
        No smooth route is feasible on the grid (typically a leg that needs a
        tack: use the grid DP).
    """
    for given, what in ((current, "a current"), (obstacles, "a race-area boundary or obstacles")):
        if given is not None:
            raise InputError(
                f"leg {leg_label(start, target)}: the spline router cannot honour {what}; "
                "set routing.router: isochrone (or griddp for obstacles)"
            )
    sol = solve_spline(start, target, t0, wind, boat, settings, progress=progress, xp=xp)
    return sol[0]


def solve_spline(
    start: Start,
    target: Target,
    t0: float,
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
    *,
    progress: Callable[[float], None] | None = None,
    xp: ModuleType = np,
) -> tuple[LegResult, SplineFit]:
    """Like :func:`route_spline`, also returning the :class:`SplineFit` diagnostics."""
    check_settings(settings, leg_label(start, target))
    t0 = float(t0)
    grid = make_grid(start, target, settings.spline.rows, settings.zone_m)
    model = GridBoat.of(boat, grid.label)
    half = settings.spline.half_width_m or default_half_width(grid.frame, wind, t0, model)
    cost = _route_cost(grid.frame, wind, model, t0, settings, grid.limits, len(grid.rows))
    fit = fit_multispline(
        cost,
        grid.frame,
        grid.rows,
        n_cols=settings.spline.cols,
        n_slopes=settings.spline.slopes,
        n_refine=settings.spline.refinements,
        half_width=half,
        xp=xp,
        progress=progress,
    )
    if not math.isfinite(fit.cost):
        raise RoutingError(
            f"leg {grid.label}: the multi-spline router found no feasible smooth route "
            f"(node band ±{half:.0f} m).  A C¹ curve cannot tack, and every candidate "
            "left the wind data or crossed a no-go zone; route this leg with the grid DP "
            "(router: griddp), or widen dp_half_width_m."
        )
    if fit.cost > settings.max_leg_time_s:
        raise RoutingError(
            f"leg {grid.label}: the best multi-spline route takes {fit.cost:.0f} s, more than "
            f"max_leg_time_s = {settings.max_leg_time_s:.0f} s; check the wind (calm?) or "
            "raise max_leg_time_s"
        )
    t, x, y, side, bsp = _sail_curve(grid.frame, wind, model, t0, settings, fit, grid.limits)
    track = build_track(t, x, y, wind, model.polar, bsp_ms=bsp, side=side)
    if progress is not None:
        progress(1.0)
    return make_leg_result(track, "spline", target_barrier(target, start, settings.zone_m)), fit


@dataclass(frozen=True, eq=False)
class _EdgeSail:
    time: NDArray  # (...,) edge time [s], penalties included
    tp: NDArray  # (..., CHORDS) chord sailing times [s]
    pen: NDArray  # (..., CHORDS) penalty before each chord [s]
    pen_end: NDArray  # (...,) penalty at the end node [s]
    side: NDArray  # (..., CHORDS)
    v_in: NDArray | None  # (..., CHORDS) dynamic: speed entering each chord
    v_end: NDArray | None = None  # (...,) dynamic: speed at the end node [m/s]


def _tangent_side(
    frame: LegFrame, wind: WindField, t: NDArray, px: NDArray, py: NDArray, m: NDArray
) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray]:
    """Unit tangent ``(hx, hy)`` of slope ``m`` at points, and TWS, signed TWA [rad] there."""
    hx, hy = frame.ex - m * frame.ey, frame.ey + m * frame.ex
    hn = np.hypot(hx, hy)
    hx, hy = hx / hn, hy / hn
    u, v, _ = sample_wind(wind, t, px, py)
    tws = np.hypot(u, v)
    safe = np.where(tws > 0, tws, 1.0)
    fx, fy = -u / safe, -v / safe
    twa = np.arctan2(-(hx * fy - hy * fx), hx * fx + hy * fy)
    return hx, hy, tws, twa, np.where(twa >= 0, 1, -1)


def _chain_limits(
    cw: ChainWind, px: NDArray, py: NDArray, limits: PathLimits | None, last: bool
) -> NDArray:
    """Chains inside the wind data that respect ``limits`` (``last``: ending on the target)."""
    ok = np.all(cw.valid, axis=-1)
    if limits is not None:
        x0, y0, x1, y1 = px[..., :-1], py[..., :-1], px[..., 1:], py[..., 1:]
        ok = ok & np.all(limits.allowed(x0, y0, x1, y1, False), axis=-1)
        if last:
            ok = ok & limits.allowed(x0[..., -1], y0[..., -1], x1[..., -1], y1[..., -1], True)
    return ok


def _turn_cosines(cw: ChainWind, hx: NDArray, hy: NDArray) -> NDArray:
    """Cosine of the turn into each chord; the first from the start tangent ``(hx, hy)``."""
    cos_t = np.ones(cw.beta.shape)
    cos_t[..., 0] = hx * cw.ux[..., 0] + hy * cw.uy[..., 0]
    cos_t[..., 1:] = cw.ux[..., 1:] * cw.ux[..., :-1] + cw.uy[..., 1:] * cw.uy[..., :-1]
    return cos_t


def _sail_edges(
    frame: LegFrame,
    wind: WindField,
    model: GridBoat,
    t_dep: NDArray,
    x: NDArray,
    y: NDArray,
    m0: NDArray,
    m1: NDArray,
    settings: RoutingSettings,
    limits: PathLimits | None = None,
    last: bool = False,
    v_in: NDArray | None = None,
) -> _EdgeSail:
    """Sail chord chains ``(x, y)`` of shape ``(..., CHORDS + 1)`` from ``t_dep``.

    The tack side at a node is that of the curve's tangent there (the same for
    the edges on both sides, the route being C¹), so a side change is charged
    once: between the start node and the first chord, between chords, or
    between the last chord and the end node.  The dynamic model enters each
    edge at ``v_in`` [m s⁻¹] (default: the steady speed of the start node's
    tangent; no seconds penalty; turns between chords follow the model's turn
    rule).  Chains that break ``limits`` (``last``: the edge ends on the target
    segment) take infinitely long.
    """
    px, py = frame.point(x, y)
    cw = sample_chains(wind, px, py, t_dep, model)
    hx, hy, tws0, twa0, side0 = _tangent_side(frame, wind, t_dep, px[..., 0], py[..., 0], m0)
    ok = _chain_limits(cw, px, py, limits, last)
    lead = cw.side.shape[:-1]
    if model.dynamic is not None:
        boat = model.dynamic
        v_start = tws0 * boat.table().steady(np.abs(twa0)) if v_in is None else v_in
        cos_t = _turn_cosines(cw, hx, hy)
        total, v_end, tp, v_pc = chain_time(
            boat, cw.beta, cw.tws, cw.length, cos_t, np.broadcast_to(v_start, lead), pieces=True
        )
        total = np.where(ok, total, np.inf)
        return _EdgeSail(total, tp, np.zeros(tp.shape), np.zeros(lead), cw.side, v_pc, v_end)
    spd = model.steady_speed(cw.tws, cw.beta)
    with np.errstate(divide="ignore", invalid="ignore"):
        tp = np.where(cw.length > 0, cw.length / spd, 0.0)
    tp = np.where(np.isnan(tp), np.inf, tp)
    side0 = np.broadcast_to(side0, lead)
    beta0 = np.broadcast_to(np.abs(twa0), lead)
    prev_side = np.concatenate([side0[..., None], cw.side[..., :-1]], axis=-1)
    prev_beta = np.concatenate([beta0[..., None], cw.beta[..., :-1]], axis=-1)
    pen = np.where(
        cw.side != prev_side,
        penalty_of(cw.beta, prev_beta, settings.tack_penalty_s, settings.gybe_penalty_s),
        0.0,
    )
    run = np.sum(tp + pen, axis=-1)
    t_arr = t_dep + np.where(np.isfinite(run), run, 0.0)
    _, _, _, twa1, side1 = _tangent_side(frame, wind, t_arr, px[..., -1], py[..., -1], m1)
    pen_end = np.where(
        side1 != cw.side[..., -1],
        penalty_of(
            np.abs(twa1), cw.beta[..., -1], settings.tack_penalty_s, settings.gybe_penalty_s
        ),
        0.0,
    )
    total = np.where(ok, run + pen_end, np.inf)
    return _EdgeSail(total, tp, pen, pen_end, cw.side, None, None)


# --------------------------------------------------------------------------------------
# the dynamic model's row cost: bound, then sail only the edges that can win

PRUNE_REL = 1e-3
"""Relative safety margin of the edge-time lower bound used to skip edges."""
PRUNE_ABS_S = 1e-2
"""Absolute safety margin [s] of that bound."""
PRUNE_PROBE = 2
"""Candidates per end state sailed first, to give every state an upper bound."""


def _predictor_speed(boat: DynamicBoat) -> Callable[[NDArray, NDArray], NDArray]:
    """Steady speed [m s⁻¹] linear in the table's angles (no Newton polish).

    Used only to time the chords for the wind's second sample (relative error
    below 1e-6; none at all in time-independent wind).
    """
    tab = boat.table()
    ws = tab.w_ss

    def speed(tws: NDArray, beta: NDArray) -> NDArray:
        jf = np.clip((beta - tab.beta_lo) / tab.dbeta, 0.0, ws.size - 1.0 - 1e-9)
        j0 = jf.astype(np.intp)
        f = jf - j0
        return np.where(beta < tab.beta_min, 0.0, tws * ((1.0 - f) * ws[j0] + f * ws[j0 + 1]))

    return speed


def _speed_cap(boat: DynamicBoat) -> NDArray[np.float64]:
    """Per table interval, an upper bound of the scaled steady speed ``w_ss`` on it."""
    ws = boat.table().w_ss
    return np.maximum(ws[:-1], ws[1:]) * (1.0 + 1e-4)


def edge_time_bound(
    boat: DynamicBoat, cw: ChainWind, v_in: NDArray, cap: NDArray | None = None
) -> NDArray:
    """Lower bound [s] of the time to sail chord chains entered at ``v_in`` [m s⁻¹].

    Driving, the boat approaches the steady speed ``w_ss v_t`` from either side;
    coasting (no-drive zone) or turning it slows down.  So it enters chord ``j``
    no faster than ``V_j = max(v_in, max_{i<j} w_ss,i v_t,i)`` and sails it no
    faster than ``max(V_j, w_ss,j v_t,j)``; where it drives, the chord takes
    at least its steady time plus the (negative) transient loss
    ``Λ(β_j, V_j / v_t,j)`` of a boat entering at ``V_j``, since a transient
    entered faster than steady saves at most its whole loss; and where it
    coasts (``β < c2/c1``) the drag alone gives ``dv/ds ≤ −k v``, so a chord of
    length ``ℓ`` takes at least ``(e^{kℓ} − 1) / (k V_j)``.  The bound per chord
    is the largest of these; shape ``cw.beta.shape[:-1]``.
    """
    tab = boat.table()
    cap = _speed_cap(boat) if cap is None else cap
    jf = np.clip((cw.beta - tab.beta_lo) / tab.dbeta, 0.0, cap.size - 1.0)
    vss = cap[jf.astype(np.intp)] * cw.tws  # upper bound of the steady speed [m/s]
    v_enter = np.empty_like(vss)
    v_enter[..., 0] = v_in
    if vss.shape[-1] > 1:
        v_enter[..., 1:] = np.maximum(
            np.maximum.accumulate(vss[..., :-1], axis=-1), np.asarray(v_in, float)[..., None]
        )
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(cw.length > 0, cw.length / np.maximum(v_enter, vss), 0.0)
        drive = (cw.beta >= tab.beta_lo) & (cw.length > 0) & (cw.tws > 0)
        fast = drive & (v_enter > vss)
        steady = np.where(drive, cw.length / vss, 0.0)
        t_drive = steady
        if np.any(fast):
            i = np.nonzero(fast)
            u = cw.tws[i]
            w0 = v_enter[i] / u
            ok = w0 <= tab.w_max
            b = cw.beta[i]
            jb = np.clip((b - tab.beta_lo) / tab.dbeta, 0.0, tab.w_ss.size - 1.0 - 1e-9)
            j0 = jb.astype(np.intp)
            ws = (1.0 - (jb - j0)) * tab.w_ss[j0] + (jb - j0) * tab.w_ss[j0 + 1]
            lam = np.where(ok, tab.loss_at(b, w0, ws), -np.inf)
            t_drive = steady.copy()
            t_drive[i] = steady[i] + np.minimum(lam, 0.0) / u
        t = np.where(drive, np.maximum(t, t_drive), t)
        # coasting through the no-drive zone: dv/ds <= -k v, so v <= V e^{-k s}
        coast = (cw.beta < tab.beta_min) & (cw.length > 0)
        if np.any(coast):
            i = np.nonzero(coast)
            t[i] = np.maximum(t[i], np.expm1(boat.k * cw.length[i]) / (boat.k * v_enter[i]))
    return np.sum(t, axis=-1)


def _dynamic_row(
    frame: LegFrame,
    wind: WindField,
    model: GridBoat,
    e: Edges,
    px: NDArray,
    py: NDArray,
    t_start: NDArray,
    v_start: NDArray | None,
    limits: PathLimits | None,
    last: bool,
    cap: NDArray,
) -> tuple[NDArray, NDArray]:
    """Edge times [s] and end speeds [m s⁻¹] of one row of the dynamic model.

    ``px, py``: chord vertices, shape ``(N, CHORDS + 1)`` with ``N = M0 M1`` edges
    ordered (start state, end state); ``t_start``, ``v_start``: departure time and
    entry speed per start state (``v_start`` None: steady speed of the tangent).
    Edges are sailed only where ``acc + bound`` does not exceed an upper bound of
    their end state's best arrival (from :data:`PRUNE_PROBE` sailed candidates),
    so the row's minima, and the DP, are those of sailing every edge; the other
    edges get ``inf``.
    """
    boat = model.dynamic
    assert boat is not None
    c0, s0, c1, s1 = e.shape
    m0n, m1n = c0 * s0, c1 * s1
    n = m0n * m1n
    t_dep = np.repeat(t_start.reshape(-1), m1n)
    cw = sample_chains(wind, px, py, t_dep, model, _predictor_speed(boat))
    ok = _chain_limits(cw, px, py, limits, last)
    sx, sy = frame.point(
        np.broadcast_to(e.x0[:, :, 0, 0], (c0, s0)), np.broadcast_to(e.y0[:, :, 0, 0], (c0, s0))
    )
    hx, hy, tws0, twa0, _ = _tangent_side(
        frame, wind, t_start, sx, sy, np.broadcast_to(e.m0[:, :, 0, 0], (c0, s0))
    )
    if v_start is None:
        v_start = tws0 * boat.table().steady(np.abs(twa0))
    v_e = np.repeat(np.broadcast_to(v_start, (c0, s0)).reshape(-1), m1n)
    cos_t = _turn_cosines(cw, np.repeat(hx.reshape(-1), m1n), np.repeat(hy.reshape(-1), m1n))
    acc = np.repeat(np.broadcast_to(e.acc[:, :, 0, 0], (c0, s0)).reshape(-1), m1n)
    bound = edge_time_bound(boat, cw, v_e, cap)
    lo = np.where(ok, acc + (bound * (1.0 - PRUNE_REL) - PRUNE_ABS_S), np.inf)
    cost = np.full(n, np.inf)
    v_end = np.zeros(n)

    def sail(idx: NDArray) -> None:
        if idx.size:
            t, v = chain_time(boat, cw.beta[idx], cw.tws[idx], cw.length[idx], cos_t[idx], v_e[idx])
            cost[idx] = t
            v_end[idx] = v

    end = np.arange(n) % m1n
    k = min(PRUNE_PROBE, m0n)
    lo2 = lo.reshape(m0n, m1n)
    probe = np.argpartition(lo2, k - 1, axis=0)[:k] if k < m0n else np.arange(m0n)[:, None]
    first = np.unique((probe * m1n + np.arange(m1n)).reshape(-1))
    first = first[ok[first]]
    sail(first)
    ub = np.full(m1n, np.inf)
    np.minimum.at(ub, end[first], acc[first] + cost[first])
    todo = ok & (lo <= ub[end])
    todo[first] = False
    sail(np.flatnonzero(todo))
    return cost.reshape(e.shape), v_end.reshape(e.shape)


def _route_cost(
    frame: LegFrame,
    wind: WindField,
    model: GridBoat,
    t0: float,
    settings: RoutingSettings,
    limits: PathLimits,
    n_rows: int,
) -> EdgeCost:
    t = np.linspace(0.0, 1.0, CHORDS + 1)
    boat = model.dynamic
    carry = bool(settings.spline.carry_speed) and boat is not None
    rest = bool(settings.spline.start_from_rest) and boat is not None
    cap = _speed_cap(boat) if boat is not None else None

    def cost(r: int, e: Edges) -> NDArray | tuple[NDArray, NDArray]:
        x, y = e.points(t)
        last = r == n_rows - 2
        if boat is None:
            t_dep = np.broadcast_to(t0 + e.acc, e.shape)
            m0 = np.broadcast_to(e.m0, e.shape)
            m1 = np.broadcast_to(e.m1, e.shape)
            return _sail_edges(frame, wind, model, t_dep, x, y, m0, m1, settings, limits, last).time
        assert cap is not None
        px, py = frame.point(x.reshape(-1, CHORDS + 1), y.reshape(-1, CHORDS + 1))
        c0, s0 = e.shape[:2]
        t_start = np.broadcast_to(t0 + e.acc[:, :, 0, 0], (c0, s0))
        if r == 0 and rest:
            v_start = np.zeros((c0, s0))
        elif carry and e.carry is not None:
            v_start = np.broadcast_to(e.carry[:, :, 0, 0], (c0, s0))
        else:
            v_start = None
        times, v_end = _dynamic_row(
            frame, wind, model, e, px, py, t_start, v_start, limits, last, cap
        )
        return (times, v_end) if carry else times

    return cost


def _sail_curve(
    frame: LegFrame,
    wind: WindField,
    model: GridBoat,
    t0: float,
    settings: RoutingSettings,
    fit: SplineFit,
    limits: PathLimits | None = None,
) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray | None]:
    """Sail the best curve edge by edge: track vertices at the chord ends."""
    tt = np.linspace(0.0, 1.0, CHORDS + 1)
    t = t0
    dyn = model.dynamic is not None
    carry = bool(settings.spline.carry_speed) and dyn
    rest = bool(settings.spline.start_from_rest) and dyn
    v_prev: float | None = None
    out_t, out_x, out_y, out_s, out_v = [], [], [], [], []
    for r in range(fit.along.size - 1):
        dx = fit.along[r + 1] - fit.along[r]
        X = fit.along[r] + tt * dx
        Y = hermite_y(fit.across[r], fit.slopes[r], fit.across[r + 1], fit.slopes[r + 1], dx, tt)
        v_in = (
            np.zeros(1)
            if r == 0 and rest
            else np.array([v_prev])
            if carry and v_prev is not None
            else None
        )
        es = _sail_edges(
            frame,
            wind,
            model,
            np.array([t]),
            X[None],
            Y[None],
            np.array([fit.slopes[r]]),
            np.array([fit.slopes[r + 1]]),
            settings,
            limits,
            r == fit.along.size - 2,
            v_in,
        )
        if es.v_end is not None:
            v_prev = float(es.v_end[0])
        px, py = frame.point(X, Y)
        for j in range(CHORDS):
            if es.pen[0, j] > 0:
                out_t.append(t)
                out_x.append(float(px[j]))
                out_y.append(float(py[j]))
                out_s.append(int(es.side[0, j]))
                out_v.append(0.0)
                t += float(es.pen[0, j])
            out_t.append(t)
            out_x.append(float(px[j]))
            out_y.append(float(py[j]))
            out_s.append(int(es.side[0, j]))
            out_v.append(float(es.v_in[0, j]) if es.v_in is not None else 0.0)
            t += float(es.tp[0, j])
        if es.pen_end[0] > 0:  # side change at the end node: stop there
            nxt = -int(es.side[0, -1])
            out_t.append(t)
            out_x.append(float(px[-1]))
            out_y.append(float(py[-1]))
            out_s.append(nxt)
            out_v.append(0.0)
            t += float(es.pen_end[0])
    out_t.append(t)
    out_x.append(float(frame.point(fit.along[-1], fit.across[-1])[0]))
    out_y.append(float(frame.point(fit.along[-1], fit.across[-1])[1]))
    out_s.append(out_s[-1])
    out_v.append(out_v[-1])
    bsp = np.array(out_v) if model.dynamic is not None else None
    return (np.array(out_t), np.array(out_x), np.array(out_y), np.array(out_s, dtype=np.int8), bsp)


_ROUTER: Router = route_spline  # mypy checks the shared router signature
