"""Risk-aware tack strategy: maximise the probability of reaching a mark by a deadline.

Wang, Patnaik, Somalwar, Wu & Vladimirsky (2024), in physical units.  The
mark is a disc of radius ``R_D`` at the origin; the wind is uniform with a
fixed speed and a direction that follows a Brownian motion with drift
(:class:`~sailroute.strategy.shiftmodel.DriftDiffusionShift`).  The state is
target-relative: distance ``r`` [m], angle ``θ`` [rad] of the upwind
direction measured counter-clockwise from the boat→mark line, and the tack
``q`` (index 0 = starboard, Wang et al.'s (2024) ``q = 1``; index 1 = port).  Steering
angle ``u ∈ [0, π]`` off the wind; speed ``f(u)`` from the polar; on
starboard the heading is ``u`` counter-clockwise of the wind (the wind is on
the starboard side), on port ``u`` clockwise.  Wang et al. (2024) eq. (4)::

    dr = -f(u) cos(θ + s_q u) dt,    dθ = [f(u)/r sin(θ + s_q u) + a] dt + σ dB,

``s_q = +1`` on starboard, ``-1`` on port.  Wang et al.'s (2024) ``φ`` (and so ``θ``) is
counter-clockwise, while compass directions are clockwise: a veer
(``drift_deg_per_s > 0``) is ``a < 0`` here.  A tack switch freezes the boat for
``C`` seconds (the tack penalty) while the wind keeps moving.

:func:`solve_deadline` marches the budget ``s`` from 0 to ``s_max`` with the
semi-Lagrangian scheme of Wang et al. (2024) (all deadlines at once): steering update
with a two-node Gauss–Hermite rule (feet ``θ ± σ√τ``, bilinear interpolation,
periodic in ``θ``), switch update with the three-node rule (weights 1/6, 2/3,
1/6 at ``θ + aC + {-1, 0, 1} σ √(3C)``, linear interpolation), ``w = 1`` inside
the mark, ``w = 0`` for a foot beyond ``r_max`` (leaving the area fails), early
zero where ``(r - R_D)/f_max > s``, switching only when ``s >= C``, ``C/Δs``
an integer.  Each update is linear in ``w`` with weights that do not depend on
``s``: the bilinear rows are computed from small tables, relative to the node
(:class:`_RingRows`, nothing stored per row; compiled with numba where installed; on a
GPU, ``engine="cupy"``, built once in GPU memory), the bicubic and switch rows are sparse
operators built once.  The policy keeps,
per slice, only the rings that slice computed (:class:`SliceBands`).

:func:`solve_risk_neutral` computes the risk-neutral counterpart (minimum
expected time, Wang et al. (2024) eq. 5) by value iteration with the same operators,
sweeping rings outward in ``r`` (Gauss–Seidel).  :func:`simulate_deadline`
runs seeded Monte Carlo (Euler–Maruyama in Cartesian coordinates) of a
deadline policy with the deadline upgrade and the fallback to the risk-neutral
policy, or of the risk-neutral policy alone.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from sailroute.backend import get_xp, to_numpy
from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.numerics import golden_max, golden_steps
from sailroute.parallel import TaskRunner, map_tasks
from sailroute.strategy import _deadline_jit as _jit
from sailroute.strategy._deadline_jit import STEER_MASK, SWITCH_BIT
from sailroute.strategy._deadline_xp import DeviceRows
from sailroute.strategy.montecarlo import CHUNK_SIZE, chunk_rng
from sailroute.strategy.shiftmodel import DriftDiffusionShift

GH3_OFFSETS = (-1.0, 0.0, 1.0)
"""Three-node Gauss–Hermite nodes in units of ``sqrt(3 v)`` (``v`` the variance)."""
GH3_WEIGHTS = (1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0)
"""Three-node Gauss–Hermite weights (exact for polynomials up to degree 5)."""
SWITCH_EPS = 1e-7
"""A switch must beat the best steering value by this much (ties keep steering)."""
ZERO_CLIP = 1e-13
"""Probabilities below this are set to 0 (as in the authors' code)."""
SURE = 1.0 - 1e-6
"""``w`` at or above this counts as certain success (deadline upgrade)."""
RN_OUTSIDE_S = 1.0e6
"""Risk-neutral cost [s] of leaving the area ``r > r_max`` (counts as failure)."""
RN_UNREACHED_S = 1.0e9
"""Initial risk-neutral value [s] outside the mark."""
INTERPOLATIONS = ("linear", "cubic")
"""Interpolation of the steering feet: bilinear (Wang et al. 2024), or bicubic Lagrange."""
REFINEMENTS = ("none", "golden")
"""Steering-angle refinement after the direct search over the fixed controls."""
BLOCK_NODES = 8192
"""Nodes per sparse mat-vec block (the block's values stay in cache for the max)."""


@dataclass(frozen=True)
class DeadlineGrid:
    """Target-relative grid ``(r, θ, q)`` and budget steps.

    Parameters
    ----------
    r_max_m : float
        Outer radius [m]; leaving it is a failure.
    n_r : int
        Intervals in ``r`` (``Δr = r_max / n_r``).
    n_theta : int
        Intervals in ``θ`` over ``2π`` (periodic).
    target_radius_m : float
        Radius ``R_D`` of the mark disc [m].
    ds_s : float
        Budget step ``Δs`` = steering time step ``τ`` [s]; the tack penalty
        must be a whole number of steps.
    s_max_s : float
        Largest budget (deadline) solved for [s].
    n_controls : int
        Steering angles ``u_n = nπ/(n_controls - 1)`` (Wang et al. (2024): 49, 3.75°).
    interpolation : {"linear", "cubic"}
        Interpolation at the steering feet: bilinear (default; reproduces Wang et al.
        (2024)'s probabilities, ``docs/strategy.md``), or bicubic Lagrange (4 x 4 points,
        4x the memory and time, less numerical diffusion but non-monotone weights that
        bias the risk-aware policies on coarse grids).
    refine_controls : {"none", "golden"}
        ``"golden"``: after the direct search over the ``n_controls`` angles, a
        golden-section search between the best angle's neighbours (tolerance 1e-3 rad,
        polar speed linear in between), per node, as Wang et al. (2024); the refined
        angle is stored as an int8 offset (``DeadlinePolicy.steer_offset``).
    """

    r_max_m: float
    n_r: int
    n_theta: int
    target_radius_m: float
    ds_s: float
    s_max_s: float
    n_controls: int = 49
    interpolation: str = "linear"
    refine_controls: str = "none"

    def __post_init__(self) -> None:
        if not (self.r_max_m > 0 and math.isfinite(self.r_max_m)):
            raise InputError(f"deadline grid: r_max_m = {self.r_max_m} must be finite and > 0")
        if self.n_r < 2 or self.n_theta < 4 or not 2 <= self.n_controls <= 128:
            raise InputError(
                "deadline grid: need n_r >= 2, n_theta >= 4, 2 <= n_controls <= 128")
        if not 0 < self.target_radius_m < self.r_max_m:
            raise InputError(
                f"deadline grid: target radius {self.target_radius_m} m must be in (0, r_max)"
            )
        if not (self.ds_s > 0 and self.s_max_s >= self.ds_s):
            raise InputError("deadline grid: need ds_s > 0 and s_max_s >= ds_s")
        if self.interpolation not in INTERPOLATIONS:
            raise InputError(
                f"deadline grid: interpolation {self.interpolation!r}; expected one of "
                + ", ".join(INTERPOLATIONS)
            )
        if self.refine_controls not in REFINEMENTS:
            raise InputError(
                f"deadline grid: refine_controls {self.refine_controls!r}; expected one of "
                + ", ".join(REFINEMENTS)
            )

    @property
    def dr(self) -> float:
        """Radial spacing [m]."""
        return self.r_max_m / self.n_r

    @property
    def dtheta(self) -> float:
        """Angular spacing [rad]."""
        return 2.0 * math.pi / self.n_theta

    @property
    def n_s(self) -> int:
        """Number of budget steps (slices ``0 .. n_s``)."""
        return math.floor(self.s_max_s / self.ds_s + 1e-9)

    @property
    def n_nodes(self) -> int:
        """Nodes of one budget slice (both tacks)."""
        return 2 * (self.n_r + 1) * self.n_theta

    @property
    def r_m(self) -> NDArray[np.float64]:
        """Radial nodes [m]."""
        return self.dr * np.arange(self.n_r + 1, dtype=np.float64)

    @property
    def theta_rad(self) -> NDArray[np.float64]:
        """Angular nodes [rad]."""
        return self.dtheta * np.arange(self.n_theta, dtype=np.float64)

    @property
    def controls_rad(self) -> NDArray[np.float64]:
        """Steering angles off the wind [rad]."""
        return np.linspace(0.0, math.pi, self.n_controls)

    def penalty_steps(self, tack_penalty_s: float) -> int:
        """``C / Δs`` as an integer (raises if it is not one)."""
        k = tack_penalty_s / self.ds_s
        if abs(k - round(k)) > 1e-9 or round(k) < 1:
            raise InputError(
                f"tack penalty {tack_penalty_s} s is not a whole (>= 1) number of budget steps "
                f"ds_s = {self.ds_s} s; choose ds_s = penalty / n"
            )
        return round(k)


def _flat(grid: DeadlineGrid, q: NDArray, i: NDArray, j: NDArray) -> NDArray[np.int64]:
    return (q * (grid.n_r + 1) + i) * grid.n_theta + j


def _model_rates(model: DriftDiffusionShift) -> tuple[float, float]:
    """Wang et al. (2024) drift ``a`` [rad s⁻¹] (counter-clockwise) and ``σ`` [rad s⁻½]."""
    if not isinstance(model, DriftDiffusionShift):
        raise InputError(
            "the deadline solver needs a drift-diffusion (Brownian) shift model; convert an OU "
            "model with brownian_equivalent(...)"
        )
    return -math.radians(model.drift_deg_per_s), math.radians(model.sigma_deg_per_sqrt_s)


def brownian_equivalent(sigma_deg: float, timescale_s: float, horizon_s: float) -> float:
    """Brownian diffusion [° s⁻½] with the OU shift's variance of change over ``horizon_s``.

    ``Var[θ(t+T) - θ(t)] = 2σ²(1 - exp(-T/l))`` for a stationary OU shift;
    ``s² T`` for a Brownian one.  Equal at ``T = horizon_s`` (e.g. the nominal
    leg time), so the Brownian model neither under- nor over-states how far
    the wind moves over the leg (it overstates it before, understates after).
    """
    if not (horizon_s > 0 and timescale_s > 0 and sigma_deg >= 0):
        raise InputError("brownian_equivalent: need horizon > 0, timescale > 0, sigma >= 0")
    if math.isinf(timescale_s):
        return 0.0
    var = 2.0 * sigma_deg**2 * (1.0 - math.exp(-horizon_s / timescale_s))
    return math.sqrt(var / horizon_s)


def _stencil(frac: NDArray, cubic: bool) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Offsets and weights of linear (2-point) or cubic Lagrange (4-point) interpolation."""
    t = frac[..., None]
    if not cubic:
        return np.array([0, 1]), np.concatenate([1 - t, t], axis=-1)
    w = np.concatenate(
        [
            -t * (t - 1) * (t - 2) / 6.0,
            (t + 1) * (t - 1) * (t - 2) / 2.0,
            -(t + 1) * t * (t - 2) / 2.0,
            (t + 1) * t * (t - 1) / 6.0,
        ],
        axis=-1,
    )
    return np.array([-1, 0, 1, 2]), w


def _node_coords(
    grid: DeadlineGrid, nodes: NDArray[np.int64]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """Tack index, ring and angle index of flat nodes."""
    per_tack = (grid.n_r + 1) * grid.n_theta
    return nodes // per_tack, (nodes % per_tack) // grid.n_theta, nodes % grid.n_theta


def _feet_stencil(
    grid: DeadlineGrid,
    q: NDArray[np.int64],
    i: NDArray[np.int64],
    j: NDArray[np.int64],
    u: float | NDArray,
    speed: float | NDArray,
    a: float,
    sigma: float,
    tau: float,
    outer: str,
    cubic: bool,
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Columns and weights ``(*shape, 2 k²)`` of the two Gauss–Hermite feet of steering ``u``.

    ``q, i, j`` (tack, ring, angle index) broadcast with ``u`` [rad] and ``speed``
    [m s⁻¹] to ``shape``: e.g. one control for all nodes, one per node, or nodes
    ``(m, 1)`` by controls ``(n_u,)``.  Entries ``0 .. k² - 1`` are the ``+σ√τ`` foot.
    Column ``n_nodes`` is the ghost inside the mark (value 1), ``n_nodes + 1`` the one
    beyond ``r_max`` (value 0, with ``outer="fail"``); a ghost foot has weight ½ on it.
    ``cubic``: 4-point Lagrange weights in ``r`` and ``θ`` (linear in ``r`` next to the
    grid's ends).
    """
    nr, nt = grid.n_r, grid.n_theta
    r = i * grid.dr
    th = j * grid.dtheta
    sgn = np.where(q == 0, 1.0, -1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_r = np.where(r > 0, 1.0 / r, 0.0)
    k = 4 if cubic else 2
    ang = th + sgn * u
    rf = r - tau * speed * np.cos(ang)
    dth = tau * (speed * inv_r * np.sin(ang) + a)
    shape = np.broadcast_shapes(np.shape(q), np.shape(u), np.shape(speed))
    rf = np.broadcast_to(rf, shape)
    dth = np.broadcast_to(dth, shape)
    th = np.broadcast_to(th, shape)
    inside = rf <= grid.target_radius_m
    if outer == "fail":
        beyond = rf > grid.r_max_m
    else:
        beyond = np.zeros(shape, dtype=bool)
        rf = np.minimum(rf, grid.r_max_m)
    fr = np.clip(rf / grid.dr, 0.0, nr)
    i0 = np.minimum(np.floor(fr).astype(np.int64), nr - 1)
    off_r, w_r = _stencil(fr - i0, cubic)
    if cubic:
        # next to r = 0 or r_max fall back to linear weights on the inner two points
        edge = (i0 < 1) | (i0 > nr - 2)
        _, w_lin = _stencil(fr - i0, False)
        pad = np.zeros((*shape, 1))
        w_r = np.where(edge[..., None], np.concatenate([pad, w_lin, pad], axis=-1), w_r)
    rows_r = np.clip(i0[..., None] + off_r, 0, nr)  # (*shape, k)
    ghost = inside | beyond
    base = (np.broadcast_to(q, shape)[..., None] * (nr + 1) + rows_r) * nt  # (*shape, k)
    cols = np.empty((*shape, 2, k * k), dtype=np.int64)
    wts = np.empty((*shape, 2, k * k))
    for f, pm in enumerate((1.0, -1.0)):
        ft = (th + dth + pm * sigma * math.sqrt(tau)) / grid.dtheta
        j0f = np.floor(ft)
        off_t, w_t = _stencil(ft - j0f, cubic)
        cols_t = np.mod(j0f.astype(np.int64)[..., None] + off_t, nt)  # (*shape, k)
        cols[..., f, :] = (base[..., :, None] + cols_t[..., None, :]).reshape(*shape, k * k)
        wts[..., f, :] = 0.5 * (w_r[..., :, None] * w_t[..., None, :]).reshape(*shape, k * k)
    cols[ghost] = np.where(inside[ghost], grid.n_nodes, grid.n_nodes + 1)[:, None, None]
    wts[ghost] = 0.0
    wts[ghost, :, 0] = 0.5
    return cols.reshape(*shape, 2 * k * k), wts.reshape(*shape, 2 * k * k)


@dataclass(frozen=True, eq=False)
class _RowOperator:
    """A sparse operator with ``rows_per_node`` rows of ``per_row`` entries for every node.

    Row ``p * rows_per_node + n`` belongs to node ``p`` (node-major: the controls of one
    node are adjacent, so the max over controls is a contiguous reduction).  Stored as the
    CSR ``data`` and ``indices`` arrays; :meth:`apply` multiplies the rows of a range of
    nodes, so a budget slice only pays for the nodes that can change.
    """

    data: NDArray
    indices: NDArray[np.int32]
    rows_per_node: int
    n_cols: int
    block_nodes: int
    indptr: NDArray[np.int32]

    @classmethod
    def build(cls, cols: NDArray, vals: NDArray, n_cols: int,
              block_nodes: int = BLOCK_NODES) -> _RowOperator:
        """From ``cols`` and ``vals`` of shape ``(n_nodes, rows_per_node, per_row)``."""
        _, rows_per_node, per_row = cols.shape
        if n_cols >= 2**31 or per_row * rows_per_node * block_nodes >= 2**31:
            raise InputError("deadline grid too large for 32-bit sparse indices")
        return cls(
            data=vals.reshape(-1),
            indices=cols.reshape(-1),
            rows_per_node=rows_per_node,
            n_cols=n_cols,
            block_nodes=block_nodes,
            indptr=np.arange(0, per_row * rows_per_node * block_nodes + 1, per_row,
                             dtype=np.int32),
        )

    @property
    def per_row(self) -> int:
        """Entries per row."""
        return int(self.indptr[1])

    def apply(self, x: NDArray, node_lo: int, node_hi: int) -> NDArray:
        """Rows of nodes ``node_lo .. node_hi - 1`` (at most ``block_nodes``) times ``x``,
        shape ``(nodes, rows_per_node)``."""
        n_rows = (node_hi - node_lo) * self.rows_per_node
        a = node_lo * self.rows_per_node * self.per_row
        b = a + n_rows * self.per_row
        # An empty matrix given the block's arrays as views: the constructor would copy
        # views of a much larger array (scipy's prune), i.e. the whole block each time.
        mat = sp.csr_matrix((n_rows, self.n_cols), dtype=self.data.dtype)
        mat.indptr = self.indptr[: n_rows + 1]
        mat.indices = self.indices[a:b]
        mat.data = self.data[a:b]
        return (mat @ x).reshape(node_hi - node_lo, self.rows_per_node)

    @property
    def nbytes(self) -> int:
        """Memory of the stored entries [bytes]."""
        return int(self.data.nbytes + self.indices.nbytes)


def _steer_operator(
    grid: DeadlineGrid,
    speeds: NDArray[np.float64],
    a: float,
    sigma: float,
    tau: float,
    outer: str,
    interpolation: str = "linear",
    dtype: type = np.float32,
) -> _RowOperator:
    """Steering operator of every node: row ``p n_u + n`` = half-sum of the two feet of
    node ``p`` under control ``n`` (:func:`_feet_stencil`; columns: the flat slice plus
    the two ghosts)."""
    if interpolation not in INTERPOLATIONS:
        raise InputError(
            f"interpolation {interpolation!r}: expected one of {', '.join(INTERPOLATIONS)}"
        )
    cubic = interpolation == "cubic"
    u = grid.controls_rad
    kk = 16 if cubic else 4
    cols = np.empty((grid.n_nodes, u.size, 2 * kk), dtype=np.int32)
    vals: NDArray[Any] = np.empty((grid.n_nodes, u.size, 2 * kk), dtype=dtype)
    step = max(1, BLOCK_NODES // 4)
    for n0 in range(0, grid.n_nodes, step):
        n1 = min(n0 + step, grid.n_nodes)
        q, i, j = _node_coords(grid, np.arange(n0, n1)[:, None])
        cols[n0:n1], vals[n0:n1] = _feet_stencil(grid, q, i, j, u, speeds, a, sigma, tau,
                                                 outer, cubic)
    return _RowOperator.build(cols, vals, grid.n_nodes + 2)


@dataclass(frozen=True, eq=False)
class _RingRows:
    """The bilinear steering rows written relative to the node (the default operator).

    The feet of node ``(q, i, j)`` under control ``n`` (:func:`_feet_stencil`) lie at ring
    ``i + g`` and angle column ``j + x ± c_σ`` [cells], with ``g = -τ f_n cos(θ_j + s_q
    u_n)/Δr``, ``x = b/r_i + c_a``, ``b = τ f_n sin(θ_j + s_q u_n)/Δθ``, ``c_a = τa/Δθ`` and
    ``c_σ = σ√τ/Δθ``.  ``g``, ``b`` and the radial fraction depend on ``(q, n, j)`` only,
    so the compiled slice stores nothing per row (the CSR form takes 64 bytes a row, 5 GB
    at 801 x 1024), and along a ring the rows fall into runs that read contiguous memory
    (``_deadline_jit.fill_runs``).  A row is the sum, in this order, of

        h₀(1 - t₊) a₀ + h₀ t₊ a₁ + h₁(1 - t₊) b₀ + h₁ t₊ b₁  (the + foot)

    and the same with ``t₋`` (the - foot), ``h₀ = ½(1 - t_r)``, ``h₁ = ½ t_r``, ``a₀, a₁``
    on ring ``i + ⌊g⌋`` at columns ``⌊x ± c_σ⌋``, ``+ 1``, ``b₀, b₁`` on the next ring, ``t±``
    the fractions of ``x ± c_σ``; ``x``, the weights and the sum in the value dtype.  That is
    a CSR row in entry order, so the NumPy path (:meth:`operator`, one SciPy mat-vec per
    block) gives the same bits.  The same bilinear scheme as :func:`_feet_stencil` up to
    rounding (to 1e-12 in float64).
    """

    g: NDArray[np.float64]
    """``(2, n_u, n_θ)``: radial offset of the feet [cells]."""
    b: NDArray
    """``(2, n_u, n_θ + LANES)``: ``τ f sin(θ + s u)/Δθ`` [cells m], value dtype (the
    compiled loop's spare chunk of zeros at the end, as ``h0`` and ``h1``)."""
    di: NDArray[np.int64]
    """``⌊g⌋``."""
    h0: NDArray
    """``½ (1 - t_r)``, ``t_r = g - ⌊g⌋``, value dtype."""
    h1: NDArray
    """``½ t_r``."""
    inv_r: NDArray
    """``(n_r + 1,)``: ``1/r_i`` [m⁻¹] (0 at ``r = 0``), value dtype."""
    ca: Any
    """``c_a`` (value dtype scalar)."""
    cs: Any
    """``c_σ`` (value dtype scalar)."""
    fr_in: float
    """``R_D/Δr``: a foot at or inside this ring position is in the mark."""
    pad: int
    """Periodic columns copied on each side of a ring (more than any foot's offset)."""
    grid: DeadlineGrid
    runs: tuple[NDArray, ...] | None
    """``(ptr, j0, j1, kind, di, op, om)`` of ``_deadline_jit.fill_runs`` (numba only)."""

    @classmethod
    def build(cls, grid: DeadlineGrid, speeds: NDArray[np.float64], a: float, sigma: float,
              tau: float, dtype: type, compiled: bool) -> _RingRows:
        """Tables of ``grid`` (and the runs when ``compiled``)."""
        u = grid.controls_rad
        q = np.arange(2)[:, None, None]
        ang = grid.theta_rad[None, None, :] + np.where(q == 0, 1.0, -1.0) * u[None, :, None]
        step = tau * speeds[None, :, None]
        g = np.ascontiguousarray(-(step * np.cos(ang)) / grid.dr)
        di = np.floor(g).astype(np.int64)
        tr: NDArray[Any] = (g - di).astype(dtype)
        half = dtype(0.5)
        h0, h1 = half * (dtype(1.0) - tr), half * tr
        b: NDArray[Any] = np.ascontiguousarray((step * np.sin(ang) / grid.dtheta).astype(dtype))
        with np.errstate(divide="ignore"):
            inv_r: NDArray[Any] = np.where(grid.r_m > 0, 1.0 / grid.r_m, 0.0).astype(dtype)
        ca, cs = dtype(tau * a / grid.dtheta), dtype(sigma * math.sqrt(tau) / grid.dtheta)
        n_in = int(np.count_nonzero(grid.r_m <= grid.target_radius_m))
        # the largest |x ± c_σ| over the rings outside the mark, + 2 for ⌊⌋ and the +1 column
        pad = math.ceil(float(np.max(np.abs(b))) * float(inv_r[n_in]) + abs(float(ca))
                        + float(cs)) + 2
        fr_in = grid.target_radius_m / grid.dr
        runs = None
        if compiled:
            ptr = np.zeros(2 * (grid.n_r + 1) * u.size + 1, dtype=np.int64)
            _jit.count_runs(g, b, inv_r, ca, cs, fr_in, grid.n_r, grid.n_theta, n_in, ptr)
            m = int(ptr[-1])
            runs = (ptr, np.empty(m, np.int64), np.empty(m, np.int64), np.empty(m, np.int8),
                    np.empty(m, np.int64), np.empty(m, np.int64), np.empty(m, np.int64))
            _jit.fill_runs(g, b, inv_r, ca, cs, fr_in, grid.n_r, grid.n_theta, n_in, *runs)
        return cls(g, _spare(b), di, _spare(h0), _spare(h1), inv_r, ca, cs, fr_in, pad, grid,
                   runs)

    @property
    def stride(self) -> int:
        """Padded ring length."""
        return self.grid.n_theta + 2 * self.pad

    def padded_size(self) -> int:
        """Length of the padded slice (both tacks, plus a ring of zeros beyond ``r_max``,
        plus the compiled loop's spare chunk)."""
        return 2 * (self.grid.n_r + 2) * self.stride + _jit.LANES

    def pad_slice(self, prev: NDArray, ring_lo: int, ring_hi: int, out: NDArray) -> None:
        """Rings ``ring_lo - 1 .. ring_hi`` of ``prev`` into the padded slice ``out``
        (the compiled path's input)."""
        assert self.runs is not None
        _jit.pad_rings(prev, self.grid.n_r, self.grid.n_theta, self.pad, ring_lo, ring_hi, out)

    def operator(self, block_nodes: int = BLOCK_NODES) -> _RowOperator:
        """The rows as a node-major CSR operator (the NumPy path): columns are the flat
        nodes of the slice and its two ghosts, the entries in the order of the sum."""
        cols, vals = self.entries(np, max(1, block_nodes // 8))
        return _RowOperator.build(cols, vals, self.grid.n_nodes + 2, block_nodes)

    def entries(self, xp: ModuleType = np, step: int = BLOCK_NODES // 8
                ) -> tuple[NDArray[np.int32], NDArray]:
        """Columns and weights ``(n_nodes, n_u, 8)`` of every row, computed on the array
        module ``xp`` (the same operations on CuPy, so the same bits), ``step`` nodes at
        a time."""
        nt, nr, nn = self.grid.n_theta, self.grid.n_r, self.grid.n_nodes
        n_u = self.g.shape[1]
        cols = xp.empty((nn, n_u, 8), dtype=np.int32)
        vals = xp.empty((nn, n_u, 8), dtype=self.b.dtype)
        one = self.b.dtype.type(1.0)
        b, h0, h1 = (xp.asarray(t[..., :nt]) for t in (self.b, self.h0, self.h1))
        g, di, inv_r = xp.asarray(self.g), xp.asarray(self.di), xp.asarray(self.inv_r)
        # a foot in the mark or beyond r_max: half on each ghost column (entries 0 and 4)
        ghost_row = xp.asarray([0.5, 0, 0, 0, 0.5, 0, 0, 0], dtype=self.b.dtype)
        n = xp.arange(n_u)[None, :]
        for n0 in range(0, nn, step):
            blk = slice(n0, min(n0 + step, nn))
            q, i, j = _node_coords(self.grid, xp.arange(blk.start, blk.stop)[:, None])
            x = b[q, n, j] * inv_r[i] + self.ca
            fr = i + g[q, n, j]
            ring = q * (nr + 1) + i + di[q, n, j]
            # the next ring's points; a foot on the last ring weighs 0 on "ring n_r + 1":
            # the ghost beyond r_max (value 0) stands in for it
            last = ring % (nr + 1) == nr
            hh0, hh1 = h0[q, n, j], h1[q, n, j]
            for f, xf in enumerate((x + self.cs, x - self.cs)):
                fl = xp.floor(xf)
                t = xf - fl
                c0 = xp.mod(j + fl.astype(np.int64), nt)
                c1 = xp.mod(c0 + 1, nt)
                e = 4 * f
                cols[blk, :, e] = ring * nt + c0
                cols[blk, :, e + 1] = ring * nt + c1
                cols[blk, :, e + 2] = xp.where(last, nn + 1, (ring + 1) * nt + c0)
                cols[blk, :, e + 3] = xp.where(last, nn + 1, (ring + 1) * nt + c1)
                vals[blk, :, e] = hh0 * (one - t)
                vals[blk, :, e + 1] = hh0 * t
                vals[blk, :, e + 2] = hh1 * (one - t)
                vals[blk, :, e + 3] = hh1 * t
            inside, beyond = fr <= self.fr_in, fr > nr
            ghost = inside | beyond
            cols_b, vals_b = cols[blk], vals[blk]
            cols_b[ghost] = xp.where(inside, nn, nn + 1)[ghost][:, None]
            vals_b[ghost] = ghost_row
        return cols, vals


def _spare(table: NDArray) -> NDArray:
    """``table`` with ``_deadline_jit.LANES`` columns of zeros appended (last axis)."""
    out = np.zeros((*table.shape[:-1], table.shape[-1] + _jit.LANES), dtype=table.dtype)
    out[..., : table.shape[-1]] = table
    return out


def _switch_operator(
    grid: DeadlineGrid, a: float, sigma: float, penalty_s: float, dtype: type = np.float32
) -> _RowOperator:
    """Switch operator of every node: three-node Gauss–Hermite average over the other
    tack's ``θ`` after ``C`` (linear interpolation)."""
    nr, nt = grid.n_r, grid.n_theta
    q, i, j = _node_coords(grid, np.arange(grid.n_nodes))
    m = q.size
    base = ((1 - q) * (nr + 1) + i) * nt
    spread = sigma * math.sqrt(3.0 * penalty_s)
    cols = np.empty((m, 1, 3, 2), dtype=np.int32)
    vals: NDArray[Any] = np.empty((m, 1, 3, 2), dtype=dtype)
    for k, (off, wgt) in enumerate(zip(GH3_OFFSETS, GH3_WEIGHTS, strict=True)):
        ft = (j * grid.dtheta + a * penalty_s + off * spread) / grid.dtheta
        j0f = np.floor(ft)
        wt = ft - j0f
        j0 = np.mod(j0f.astype(np.int64), nt)
        cols[:, 0, k, 0] = base + j0
        cols[:, 0, k, 1] = base + np.mod(j0 + 1, nt)
        vals[:, 0, k, 0] = wgt * (1 - wt)
        vals[:, 0, k, 1] = wgt * wt
    return _RowOperator.build(cols.reshape(m, 1, 6), vals.reshape(m, 1, 6), grid.n_nodes + 2)


OFFSET_STEPS = 127
"""``steer_offset`` units: ``Δu / 127`` (0.03° for 49 controls)."""
FINE_SPEED_STEPS = 1440
"""Intervals of the speed table used between the controls (0.125°)."""
GOLDEN_TOL_RAD = 1e-3
"""Golden-section tolerance on the steering angle (Wang et al. 2024's code) [rad]."""


def _fine_speed_table(polar: Polar, tws_ms: float) -> tuple[NDArray, NDArray]:
    u = np.linspace(0.0, math.pi, FINE_SPEED_STEPS + 1)
    return u, np.asarray(polar.speed(tws_ms, np.degrees(u)), dtype=float)


class _SteerRefiner:
    """Golden-section search of the steering angle between the neighbours of the best
    coarse control, per node, vectorised (Wang et al. 2024's second stage).

    The speed between controls is read from a 0.125° table of the polar (linear in
    between); the feet are computed on the fly with the solver's interpolation.  The
    refined angle is kept as ``u_best + offset Δu / 127`` (int8 offset), and used only
    where it beats the best coarse control.
    """

    def __init__(self, grid: DeadlineGrid, polar: Polar, tws_ms: float, a: float,
                 sigma: float, tau: float) -> None:
        self.grid, self.a, self.sigma, self.tau = grid, a, sigma, tau
        self.cubic = grid.interpolation == "cubic"
        self.u_tab, self.f_tab = _fine_speed_table(polar, tws_ms)
        self.du = math.pi / (grid.n_controls - 1)
        self.n_iter = golden_steps(2 * self.du, GOLDEN_TOL_RAD)

    def _value(self, x: NDArray, q: NDArray, i: NDArray, j: NDArray, u: NDArray) -> NDArray:
        f = np.interp(u, self.u_tab, self.f_tab)
        cols, wts = _feet_stencil(self.grid, q, i, j, u, f, self.a, self.sigma, self.tau,
                                  "fail", self.cubic)
        return np.einsum("mk,mk->m", wts, x[cols])

    def refine(self, x: NDArray, n0: int, n1: int, best: NDArray, wk: NDArray
               ) -> tuple[NDArray, NDArray]:
        """Values and int8 offsets after refining nodes ``n0 .. n1 - 1`` (``x``: previous
        slice with ghosts; ``best``, ``wk``: the best coarse control and its value)."""
        offset = np.zeros(n1 - n0, dtype=np.int8)
        todo = np.flatnonzero((wk > ZERO_CLIP) & (wk < SURE))
        if todo.size == 0:
            return wk, offset
        q, i, j = _node_coords(self.grid, n0 + todo)
        ub = best[todo] * self.du
        lo = np.maximum(ub - self.du, 0.0)
        hi = np.minimum(ub + self.du, math.pi)
        u_star = golden_max(lambda u: self._value(x, q, i, j, u), lo, hi, self.n_iter)
        off = np.clip(np.rint((u_star - ub) / self.du * OFFSET_STEPS), -OFFSET_STEPS,
                      OFFSET_STEPS)
        u_q = np.clip(ub + off * self.du / OFFSET_STEPS, 0.0, math.pi)
        v_q = self._value(x, q, i, j, u_q).astype(wk.dtype)
        better = v_q > wk[todo]
        wk = wk.copy()
        wk[todo[better]] = v_q[better]
        offset[todo[better]] = off[better].astype(np.int8)
        return wk, offset


def _controls_speed(grid: DeadlineGrid, polar: Polar, tws_ms: float) -> NDArray[np.float64]:
    f = np.asarray(polar.speed(tws_ms, np.degrees(grid.controls_rad)), dtype=float)
    if not np.max(f) > 0:
        raise InputError(f"polar {polar.name!r} gives no boat speed at TWS {tws_ms} m/s")
    return f


@dataclass(frozen=True, eq=False)
class SliceBands:
    """``w`` and the action of every budget slice, stored for the rings the slice computed.

    Slice ``k`` computes rings ``lo[k] .. hi[k] - 1`` of both tacks (``solve_deadline``):
    rings below ``lo[k]`` are sure and keep the values of the last slice that computed
    them, rings from ``hi[k]`` on are beyond reach at top speed (``w = 0``), rings inside
    the mark have ``w = 1``.  Only the band is stored (Wang et al.'s (2024) Fig. 3 set-up at
    801 x 1024: 44 % of the dense ``(n_s + 1) x n_nodes`` arrays), so memory and the first
    touch of it shrink accordingly.

    Attributes
    ----------
    lo, hi : ndarray of int64, shape (n_s + 1,)
        Computed rings per slice (``lo = hi = n_in`` for slice 0).
    start : ndarray of int64, shape (n_s + 2,)
        Offset of slice ``k``'s band in the flat arrays (tack 0's rings, then tack 1's).
    w : ndarray, shape (start[-1],)
    action : ndarray of uint8, shape (start[-1],)
        Control index (bits 0-6) and switch (bit 7, :data:`SWITCH_BIT`).
    offset : ndarray of int8, shape (start[-1],), or None
        Golden-refined steering offsets (``refine_controls="golden"``).
    n_in : int
        Rings inside the mark.
    last : ndarray of int64, shape (n_r + 1,)
        The last slice whose band holds ring ``i`` (``lo`` never decreases): where a
        ring below ``lo[k]`` is read.
    """

    lo: NDArray[np.int64]
    hi: NDArray[np.int64]
    start: NDArray[np.int64]
    w: NDArray
    action: NDArray[np.uint8]
    offset: NDArray[np.int8] | None
    n_in: int
    last: NDArray[np.int64]

    def locate(self, grid: DeadlineGrid, k: NDArray | int, node: NDArray | int
               ) -> tuple[NDArray[np.int64], NDArray[np.int8]]:
        """Flat index of ``(k, node)`` (broadcast), and where it is not stored: ``-1``
        inside the mark (``w = 1``), ``-2`` beyond reach (``w = 0``), else 0."""
        k, node = np.broadcast_arrays(np.asarray(k, dtype=np.int64),
                                      np.asarray(node, dtype=np.int64))
        q, i, j = _node_coords(grid, node)
        kk = np.where(i >= self.lo[k], k, self.last[i])
        lo_s, hi_s = self.lo[kk], self.hi[kk]
        flat = self.start[kk] + ((q * (hi_s - lo_s)) + (i - lo_s)) * grid.n_theta + j
        where = np.where(i < self.n_in, -1, np.where(i >= self.hi[k], -2, 0)).astype(np.int8)
        return np.where(where == 0, flat, 0), where

    def w_at(self, flat: NDArray[np.int64], where: NDArray[np.int8]) -> NDArray:
        """``w`` at the places :meth:`locate` returned (1 in the mark, 0 beyond reach)."""
        one, zero = self.w.dtype.type(1.0), self.w.dtype.type(0.0)
        return np.where(where == -1, one, np.where(where == -2, zero, self.w[flat]))

    @staticmethod
    def table_at(table: NDArray, flat: NDArray[np.int64], where: NDArray[np.int8]) -> NDArray:
        """``table`` (``action`` or ``offset``) at the places :meth:`locate` returned; 0
        where not stored."""
        return np.where(where == 0, table[flat], 0).astype(table.dtype)

    def value(self, grid: DeadlineGrid, k: NDArray | int, node: NDArray | int) -> NDArray:
        """``w`` of slice(s) ``k`` at ``node``."""
        return self.w_at(*self.locate(grid, k, node))

    def gather(self, table: NDArray, grid: DeadlineGrid, k: NDArray | int,
               node: NDArray | int) -> NDArray:
        """``table`` (``action`` or ``offset``) at ``(k, node)``; 0 where not stored."""
        return self.table_at(table, *self.locate(grid, k, node))


@dataclass(frozen=True, eq=False)
class DeadlinePolicy:
    """Threshold-aware value ``w(r, θ, q, s) = max P(T <= s)`` and policy ``α*``.

    Attributes
    ----------
    grid : DeadlineGrid
    tack_penalty_s : float
    model : DriftDiffusionShift
    speeds_ms : ndarray, shape (n_controls,)
        Boat speed at each steering angle [m s⁻¹].
    bands : SliceBands
        ``w`` and the action per budget slice and node (flat ``(q, i, j)``), stored for
        the rings each slice computed: read with :meth:`value`, :meth:`steering`,
        :meth:`switches`, or as dense arrays :attr:`w`, :attr:`action`, :attr:`steer`,
        :attr:`switch` (new ``(n_s + 1) x n_nodes`` arrays: small grids).
    solve_time_s : float
    fine_speeds : (ndarray, ndarray) or None
        Angles [rad] and polar speeds [m s⁻¹] (0.125° table) for refined angles: with
        ``grid.refine_controls``, the angle is ``u[steer] + offset Δu / 127``.
    """

    grid: DeadlineGrid
    tack_penalty_s: float
    model: DriftDiffusionShift
    speeds_ms: NDArray[np.float64]
    bands: SliceBands
    solve_time_s: float
    fine_speeds: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None

    def value(self, k: NDArray | int, node: NDArray | int) -> NDArray:
        """``w`` of slice(s) ``k`` at ``node`` (broadcast)."""
        return self.bands.value(self.grid, k, node)

    def switches(self, k: NDArray | int, node: NDArray | int) -> NDArray[np.bool_]:
        """Whether switching tack is optimal in slice(s) ``k`` at ``node``."""
        return self.bands.gather(self.bands.action, self.grid, k, node) >= SWITCH_BIT

    def steering(self, k: NDArray | int, node: NDArray | int) -> tuple[NDArray, NDArray]:
        """Steering angle [rad] and boat speed [m s⁻¹] of slice(s) ``k`` at ``node``."""
        return self.decide(k, node)[1:3]

    def decide(self, k: NDArray | int, node: NDArray | int
               ) -> tuple[NDArray, NDArray, NDArray, NDArray[np.bool_]]:
        """``w``, steering angle [rad], boat speed [m s⁻¹] and switch of slice(s) ``k``
        at ``node`` (one look-up, for the Monte Carlo steps)."""
        b = self.bands
        flat, where = b.locate(self.grid, k, node)
        act = b.table_at(b.action, flat, where)
        idx = (act & STEER_MASK).astype(np.int64)
        if b.offset is None or self.fine_speeds is None:
            u, f = self.grid.controls_rad[idx], self.speeds_ms[idx]
        else:
            du = math.pi / (self.grid.n_controls - 1)
            off = b.table_at(b.offset, flat, where)
            u = np.clip(self.grid.controls_rad[idx] + off * (du / OFFSET_STEPS), 0.0, math.pi)
            f = np.interp(u, *self.fine_speeds)
        return b.w_at(flat, where), u, f, act >= SWITCH_BIT

    def _dense(self, read: Callable[[NDArray, NDArray], NDArray]) -> NDArray:
        k = np.arange(self.grid.n_s + 1)[:, None]
        return read(k, np.arange(self.grid.n_nodes)[None, :])

    @property
    def w(self) -> NDArray:
        """``w`` per slice and node, shape ``(n_s + 1, n_nodes)`` (a new array)."""
        return self._dense(self.value)

    @property
    def action(self) -> NDArray[np.uint8]:
        """Control index (bits 0-6) and switch (bit 7) per slice and node (a new array)."""
        return self._dense(lambda k, n: self.bands.gather(self.bands.action, self.grid, k, n))

    @property
    def steer(self) -> NDArray[np.int8]:
        """Best steering control index per slice and node (a new array)."""
        return (self.action & STEER_MASK).astype(np.int8)

    @property
    def switch(self) -> NDArray[np.bool_]:
        """True where switching tack is optimal, per slice and node (a new array)."""
        return self.action >= SWITCH_BIT

    @property
    def steer_offset(self) -> NDArray[np.int8] | None:
        """Golden-refined steering offsets per slice and node (a new array), or None."""
        table = self.bands.offset
        if table is None:
            return None
        return self._dense(lambda k, n: self.bands.gather(table, self.grid, k, n))

    def node(self, r_m: float, theta_rad: float, tack: int) -> int:
        """Flat index of the node nearest to ``(r, θ)`` on ``tack`` (+1/-1)."""
        return _nearest_node(self.grid, r_m, theta_rad, tack)

    def success_curve(self, r_m: float, theta_rad: float, tack: int = 1) -> NDArray[np.float64]:
        """``w`` at the nearest node for every budget slice: ``P(T <= s_k)`` under ``α^{s_k}``."""
        k = np.arange(self.grid.n_s + 1)
        return self.value(k, self.node(r_m, theta_rad, tack)).astype(float)

    @property
    def s_s(self) -> NDArray[np.float64]:
        """Budget of each slice [s]."""
        return self.grid.ds_s * np.arange(self.grid.n_s + 1, dtype=np.float64)


@dataclass(frozen=True, eq=False)
class RiskNeutralPolicy:
    """Minimum expected time ``v(r, θ, q)`` [s] and its stationary policy ``μ*``.

    Attributes
    ----------
    grid, tack_penalty_s, model, speeds_ms : as :class:`DeadlinePolicy`
    value_s : ndarray, shape (n_nodes,)
    steer : ndarray of int8, shape (n_nodes,)
    switch : ndarray of bool, shape (n_nodes,)
    iterations : int
        Outward sweeps until convergence.
    residual_s : float
        Largest change in the last sweep [s].
    solve_time_s : float
    """

    grid: DeadlineGrid
    tack_penalty_s: float
    model: DriftDiffusionShift
    speeds_ms: NDArray[np.float64]
    value_s: NDArray[np.float64]
    steer: NDArray[np.int8]
    switch: NDArray[np.bool_]
    iterations: int
    residual_s: float
    solve_time_s: float

    def expected_time(self, r_m: float, theta_rad: float, tack: int = 1) -> float:
        """``v`` at the nearest node [s]."""
        return float(self.value_s[_nearest_node(self.grid, r_m, theta_rad, tack)])


def _nearest_nodes(
    grid: DeadlineGrid, r: NDArray, theta: NDArray, q: NDArray
) -> NDArray[np.int64]:
    """Nearest node; points outside the mark never map to a node inside it."""
    first = math.floor(grid.target_radius_m / grid.dr + 1e-9) + 1
    i = np.rint(r / grid.dr).astype(np.int64)
    i = np.clip(np.where(r > grid.target_radius_m, np.maximum(i, first), i), 0, grid.n_r)
    j = np.mod(np.rint(theta / grid.dtheta).astype(np.int64), grid.n_theta)
    return _flat(grid, q.astype(np.int64), i, j)


def _nearest_node(grid: DeadlineGrid, r_m: float, theta_rad: float, tack: int) -> int:
    """Flat index of the node nearest to one point ``(r [m], θ [rad])`` on ``tack`` (+1/-1)."""
    return int(_nearest_nodes(grid, np.array([r_m]), np.array([theta_rad]),
                              np.array([0 if tack == 1 else 1]))[0])


def _active_nodes(grid: DeadlineGrid) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    r_nodes = np.tile(np.repeat(grid.r_m, grid.n_theta), 2)
    inside = r_nodes <= grid.target_radius_m
    return np.flatnonzero(~inside), inside


def _rings_all_sure(w_prev: NDArray, grid: DeadlineGrid, lo: int, hi: int) -> int:
    """First ring ``>= lo`` (and ``< hi``) where some node of either tack is not sure."""
    per_tack = (grid.n_r + 1) * grid.n_theta
    nt = grid.n_theta
    sure = w_prev.dtype.type(SURE)  # as NumPy compares (on any array module)
    while lo < hi:
        if (w_prev[lo * nt:(lo + 1) * nt] < sure).any() or (
            w_prev[per_tack + lo * nt:per_tack + (lo + 1) * nt] < sure
        ).any():
            return lo
        lo += 1
    return lo


ENGINES = ("auto", "numpy", "numba", "cupy")


def resolve_engine(engine: str) -> tuple[bool, ModuleType]:
    """Whether ``engine`` (one of :data:`ENGINES`) marches with the numba kernels, and the
    array module of the slices; an :class:`InputError` saying what to install when it
    cannot run here."""
    if engine not in ENGINES:
        raise InputError(f"engine {engine!r}: expected one of {', '.join(ENGINES)}")
    if engine == "numba" and not _jit.AVAILABLE:
        raise InputError("engine 'numba' needs numba: pip install 'sailroute[fast]'")
    if engine == "cupy":
        try:
            return False, get_xp("cupy")
        except InputError:
            raise InputError("engine 'cupy' needs CuPy and an NVIDIA GPU: pip install "
                             "'sailroute[gpu]' on a machine with one, or use engine 'auto' "
                             "(numba where installed, else NumPy)") from None
    return engine == "numba" or (engine == "auto" and _jit.AVAILABLE), np


def _update_block(n0: int, n1: int, vals: NDArray, prev: NDArray, prev_c: NDArray | None,
                  w_out: NDArray, actions: tuple[NDArray, NDArray],
                  offsets: tuple[NDArray, NDArray] | None, refine: _SteerRefiner | None,
                  switch_op: _RowOperator | DeviceRows, consts: tuple[Any, Any, Any],
                  xp: ModuleType = np) -> None:
    """Nodes ``n0 .. n1 - 1`` of a slice from their steering rows ``vals`` (NumPy path,
    or any array module ``xp``; ``_deadline_jit.finish_nodes`` is the compiled twin):
    ``prev`` is the previous slice, ``prev_c`` the slice ``C`` back (None before a switch
    can pay), ``actions`` and ``offsets`` the previous and this slice's arrays, ``consts``
    ``SWITCH_EPS``, ``ZERO_CLIP`` and ``SURE`` in the value dtype."""
    eps, zero_clip, sure = consts
    best = xp.argmax(vals, axis=1)
    wk = xp.take_along_axis(vals, best[:, None], axis=1)[:, 0]
    off = None
    if refine is not None:
        wk, off = refine.refine(prev, n0, n1, best, wk)
    if prev_c is not None:
        ws = switch_op.apply(prev_c, n0, n1)[:, 0]
        sw = ws > wk + eps
        wk = xp.where(sw, ws, wk)
    else:
        sw = xp.zeros(n1 - n0, dtype=bool)
    wk = xp.where(wk < zero_clip, wk.dtype.type(0.0), xp.minimum(wk, wk.dtype.type(1.0)))
    # More budget never hurts: following the policy of budget s - Δs succeeds by s at
    # least as often.  Where that beats this slice (possible with the non-monotone cubic
    # weights), or where success was already sure (deadline upgrade: any action keeping
    # w = 1 ties, the one of the least sure budget is the tightest), keep the previous
    # slice's value and action.
    p = prev[n0:n1]
    keep = (p >= sure) | (p > wk)
    w_out[n0:n1] = xp.where(keep, p, wk)
    a_prev, a_out = actions
    a_out[n0:n1] = xp.where(keep, a_prev[n0:n1],
                            (best | xp.where(sw, SWITCH_BIT, 0)).astype(np.uint8))
    if offsets is not None and off is not None:
        offsets[1][n0:n1] = xp.where(keep, offsets[0][n0:n1], off)


def solve_deadline(
    polar: Polar,
    tws_ms: float,
    model: DriftDiffusionShift,
    grid: DeadlineGrid,
    tack_penalty_s: float,
    progress: Callable[[int, int], None] | None = None,
    dtype: str = "float32",
    engine: str = "auto",
) -> DeadlinePolicy:
    """March ``w`` over the budget slices ``s = 0, Δs, ..., s_max`` (module docstring).

    Parameters
    ----------
    polar : Polar
        Boat polar, read at ``tws_ms`` for each steering angle.
    tws_ms : float
        Wind speed [m s⁻¹].
    model : DriftDiffusionShift
        Wind-direction process (drift positive = veer).
    grid : DeadlineGrid
    tack_penalty_s : float
        Time ``C`` [s] the boat stands still per tack switch; a whole number of
        budget steps.
    progress : callable, optional
        Called as ``progress(k, n_s)`` after each slice (for a CLI progress line).
    dtype : {"float32", "float64"}
        Precision of the operators and of ``w``.  ``float32`` (default) halves the
        memory and the memory traffic; it changes ``w`` by at most a few 1e-6 on the
        paper's set-up (``benchmarks/bench_deadline.py``).
    engine : {"auto", "numpy", "numba", "cupy"}
        ``"numba"``: the compiled kernels of :mod:`sailroute.strategy._deadline_jit`
        (the optional extra ``sailroute[fast]``) march the slices (golden refinement
        runs on the NumPy path); the policy is the same bit for bit as with
        ``"numpy"``.  ``"cupy"``: the NumPy path's operations on the GPU, with the rows
        and the working slices in GPU memory (the extra ``sailroute[gpu]`` and an NVIDIA
        GPU; :mod:`sailroute.strategy._deadline_xp`); the same policy bit for bit, no
        golden refinement.  ``"auto"`` (default): numba where it is installed.

    Returns
    -------
    DeadlinePolicy
        Memory: ``4 + 1`` bytes (``w`` in float32, the action; ``8 + 1`` in float64,
        ``+ 1`` with ``grid.refine_controls``) per node and slice of the rings each
        slice computed (:class:`SliceBands`): at most ``(n_s + 1) n_nodes`` of them.

    Notes
    -----
    A slice only updates the rings that can change: those that the boat can reach from
    within the budget at top speed (farther rings stay 0) and that are not yet sure
    everywhere (``w >= 1 - 1e-6`` keeps its value and action); only those rings are
    stored (:class:`SliceBands`).  Bilinear rows: :class:`_RingRows` (numba: runs along
    each ring, vectorised; NumPy: the same rows as a node-major CSR operator); bicubic:
    node-major CSR rows.  On the NumPy path a block of nodes is one sparse mat-vec and a
    contiguous max over the controls.
    """
    t0 = time.perf_counter()
    if dtype not in ("float32", "float64"):
        raise InputError(f"dtype {dtype!r}: expected 'float32' or 'float64'")
    ftype = np.dtype(dtype).type
    compiled, xp = resolve_engine(engine)
    if xp is not np and grid.refine_controls != "none":
        raise InputError("engine 'cupy' does not refine the steering angle: use "
                         "refine_controls='none', or engine 'numpy' or 'numba'")
    kc = grid.penalty_steps(tack_penalty_s)
    a, sigma = _model_rates(model)
    f = _controls_speed(grid, polar, tws_ms)
    f_max = float(np.max(f))
    refine = (
        _SteerRefiner(grid, polar, tws_ms, a, sigma, grid.ds_s)
        if grid.refine_controls != "none" else None
    )
    jit = compiled and refine is None  # golden refinement runs on the NumPy path
    cubic = grid.interpolation == "cubic"
    rows = None if cubic else _RingRows.build(grid, f, a, sigma, grid.ds_s, ftype, jit)
    if cubic:
        steer_op: _RowOperator | None = _steer_operator(grid, f, a, sigma, grid.ds_s, "fail",
                                                        "cubic", ftype)
    else:  # the compiled slice computes the bilinear rows; NumPy multiplies them
        assert rows is not None
        steer_op = None if jit or xp is not np else rows.operator()
    switch_op = _switch_operator(grid, a, sigma, tack_penalty_s, ftype)
    # the rows the NumPy code multiplies, on the array module (one block per tack band)
    steer_x: _RowOperator | DeviceRows | None = steer_op
    switch_x: _RowOperator | DeviceRows = switch_op
    block = BLOCK_NODES
    if xp is not np:
        if steer_op is not None:
            steer_x = DeviceRows.from_host(steer_op, xp)
        else:
            assert rows is not None
            steer_x = DeviceRows.of(*rows.entries(xp, 1 << 17), xp)
        switch_x = DeviceRows.from_host(switch_op, xp)
        block = grid.n_nodes
    n_s, n_nodes, nt = grid.n_s, grid.n_nodes, grid.n_theta
    per_tack = (grid.n_r + 1) * nt
    n_in = int(np.count_nonzero(grid.r_m <= grid.target_radius_m))  # rings inside the mark
    reach_time = (grid.r_m - grid.target_radius_m) / f_max  # per ring
    # rings reachable at top speed within each budget; rings beyond stay 0
    his = np.searchsorted(reach_time, grid.ds_s * np.arange(n_s + 1), side="right")
    his[0] = n_in
    bound = int(np.sum(his - n_in)) * 2 * nt  # the bands can be no larger (never touched)
    band_w = xp.empty(bound, dtype=ftype)
    band_a = xp.empty(bound, dtype=np.uint8)
    band_o = np.empty(bound, dtype=np.int8) if refine is not None else None
    los, starts = np.full(n_s + 1, n_in), np.zeros(n_s + 2, dtype=np.int64)
    # working slices: w of the last kc + 1 budgets (the switch reads C back), the action of
    # the last two; inside the mark w = 1, ghosts: a foot inside the mark (1), beyond (0)
    ws = xp.zeros((kc + 1, n_nodes + 2), dtype=ftype)
    for q in (0, 1):
        ws[:, q * per_tack:q * per_tack + n_in * nt] = 1.0
    ws[:, n_nodes] = 1.0
    acts = xp.zeros((2, n_nodes), dtype=np.uint8)
    offs = np.zeros((2, n_nodes), dtype=np.int8) if refine is not None else None
    consts = tuple(ftype(c) for c in (SWITCH_EPS, ZERO_CLIP, SURE))  # as NumPy compares
    switch_cols = switch_op.indices.view(np.uint32)  # the kernels' index type
    steer_cols = None if steer_op is None else steer_op.indices.view(np.uint32)
    xpad = np.zeros(rows.padded_size() if rows is not None and jit else 0, dtype=ftype)
    best_val = np.zeros(nt + _jit.LANES, dtype=ftype)  # scratch of the compiled slice
    best_n = np.zeros(nt + _jit.LANES, dtype=np.int8)
    lo = n_in
    for k in range(1, n_s + 1):
        prev, cur = ws[(k - 1) % (kc + 1)], ws[k % (kc + 1)]
        prev_c = ws[max(k - kc, 0) % (kc + 1)]
        a_prev, a_cur = acts[(k - 1) % 2], acts[k % 2]
        hi = int(his[k])
        lo = _rings_all_sure(prev, grid, lo, hi)
        # rings below lo are sure and keep their value and action: bring the reused slots
        # up to date (they hold budget k - kc - 1, resp. k - 2; rings frozen before agree)
        for q in (0, 1):
            base = q * per_tack
            lo_w = int(los[k - kc - 1]) if k > kc else n_in
            cur[base + lo_w * nt:base + lo * nt] = prev[base + lo_w * nt:base + lo * nt]
            lo_a = int(los[k - 2]) if k > 1 else n_in
            a_cur[base + lo_a * nt:base + lo * nt] = a_prev[base + lo_a * nt:base + lo * nt]
            if offs is not None:
                offs[k % 2, base + lo_a * nt:base + lo * nt] = \
                    offs[(k - 1) % 2, base + lo_a * nt:base + lo * nt]
        switch_args = (switch_op.data, switch_cols, prev_c, k >= kc)
        if jit and rows is not None:
            assert rows.runs is not None
            rows.pad_slice(prev, lo, hi, xpad)
            _jit.ring_slice(*rows.runs, rows.b, rows.h0, rows.h1, rows.inv_r, rows.ca,
                            rows.cs, grid.n_r, nt, rows.pad, xpad, prev, *switch_args, lo, hi,
                            *consts, a_prev, cur, a_cur, best_val, best_n)
        elif jit:
            assert steer_op is not None
            for q in (0, 1):
                _jit.slice_update(
                    steer_cols, steer_op.data, f.size, steer_op.per_row, prev, *switch_args,
                    q * per_tack + lo * nt, q * per_tack + hi * nt, *consts, a_prev, cur,
                    a_cur)
        else:
            assert steer_x is not None
            for q in (0, 1):
                for n0 in range(q * per_tack + lo * nt, q * per_tack + hi * nt, block):
                    n1 = min(n0 + block, q * per_tack + hi * nt)
                    vals = steer_x.apply(prev, n0, n1)
                    _update_block(n0, n1, vals, prev, prev_c if k >= kc else None, cur,
                                  (a_prev, a_cur), None if offs is None else
                                  (offs[(k - 1) % 2], offs[k % 2]), refine, switch_x,
                                  consts, xp)
        # store the band of rings lo .. hi - 1 (tack 0, then tack 1)
        los[k] = lo
        size = (hi - lo) * nt
        starts[k + 1] = starts[k] + 2 * size
        for q in (0, 1):
            dst = slice(int(starts[k]) + q * size, int(starts[k]) + (q + 1) * size)
            src = slice(q * per_tack + lo * nt, q * per_tack + hi * nt)
            band_w[dst] = cur[src]
            band_a[dst] = a_cur[src]
            if band_o is not None and offs is not None:
                band_o[dst] = offs[k % 2, src]
        if progress is not None:
            progress(k, n_s)
    used = int(starts[-1])
    last = np.searchsorted(los, np.arange(grid.n_r + 1), side="right") - 1
    bands = SliceBands(los, his.astype(np.int64), starts, to_numpy(band_w[:used]),
                       to_numpy(band_a[:used]),
                       None if band_o is None else band_o[:used], n_in, last)
    return DeadlinePolicy(
        grid=grid,
        tack_penalty_s=float(tack_penalty_s),
        model=model,
        speeds_ms=f,
        bands=bands,
        solve_time_s=time.perf_counter() - t0,
        fine_speeds=(refine.u_tab, refine.f_tab) if refine is not None else None,
    )


def solve_risk_neutral(
    polar: Polar,
    tws_ms: float,
    model: DriftDiffusionShift,
    grid: DeadlineGrid,
    tack_penalty_s: float,
    tol_s: float = 1e-6,
    max_sweeps: int = 2000,
    tau_s: float | None = None,
    progress: Callable[[int, float], None] | None = None,
    ring_iterations: int = 64,
) -> RiskNeutralPolicy:
    """Minimum expected time by value iteration (Wang et al. (2024) eq. 5, risk-neutral).

    ``v = min( min_u [τ + ½ Σ± v(foot±)],  C + 𝒢[v(r, ·, q̃)] )``, ``v = 0`` in
    the mark, ``v = RN_OUTSIDE_S`` beyond ``r_max``.  Rings are updated in
    order of increasing ``r`` with the newest values (Gauss–Seidel), which
    carries information outward from the mark in one sweep; sweeps repeat
    until the largest change is below ``tol_s`` [s].  The step ``τ`` defaults to
    the deadline grid's ``Δs``, so that both policies see the same
    discretisation; a larger ``tau_s`` (e.g. ``1.5 Δr / f_max``, the authors'
    choice per control) converges in fewer sweeps but, with a fixed ``τ``,
    gives a visibly worse policy on coarse grids (Fig. 4a set-up at 100 x 128:
    ``E[T]`` 44.14 instead of 43.90).
    Interpolation is always bilinear here (whatever ``grid.interpolation``
    says): value iteration needs the monotone scheme (non-negative weights) to
    converge, and ``v`` is smooth.  Each ring is repeated (up to
    ``ring_iterations`` times) until it changes by less than ``tol_s``: a ring's nodes
    feed each other through ``θ`` and the switch, and one update moves information
    only a few cells around the ring, so plain sweeps need hundreds of passes (Wang et
    al.'s Fig. 3 set-up at 201 x 256: 204 sweeps, 18 s; with ring iterations: 2 sweeps,
    2.3 s, and a better converged value).

    Raises
    ------
    InputError
        If the iteration has not converged after ``max_sweeps`` sweeps.
    """
    t0 = time.perf_counter()
    a, sigma = _model_rates(model)
    f = _controls_speed(grid, polar, tws_ms)
    _, inside = _active_nodes(grid)
    n_nodes = grid.n_nodes
    tau = grid.ds_s if tau_s is None else float(tau_s)
    if not tau > 0:
        raise InputError(f"risk-neutral time step {tau_s} s must be > 0")
    nt = grid.n_theta
    per_tack = (grid.n_r + 1) * nt
    n_in = int(np.count_nonzero(grid.r_m <= grid.target_radius_m))
    s_op = _steer_operator(grid, f, a, sigma, tau, "fail", "linear")
    c_op = _switch_operator(grid, a, sigma, tack_penalty_s)
    blocks = [
        [(q * per_tack + i * nt + b0, q * per_tack + i * nt + min(b0 + BLOCK_NODES, nt))
         for q in (0, 1) for b0 in range(0, nt, BLOCK_NODES)]
        for i in range(n_in, grid.n_r + 1)
    ]
    # start from a plausible upper estimate (beat to the mark at the worst VMG, two switches)
    # rather than "unreached": far fewer sweeps, the fixed point is the same
    u = grid.controls_rad
    vmg_worst = min(float(np.max(f * np.cos(u))), float(np.max(-f * np.cos(u))))
    r_all = np.tile(np.repeat(grid.r_m, grid.n_theta), 2)
    v = np.full(n_nodes + 2, RN_UNREACHED_S)
    if vmg_worst > 0:
        v[:n_nodes] = (r_all - grid.target_radius_m) / vmg_worst + 2.0 * tack_penalty_s
    v[:n_nodes][inside] = 0.0
    v[n_nodes] = 0.0
    v[n_nodes + 1] = RN_OUTSIDE_S
    steer = np.zeros(n_nodes, dtype=np.int8)
    switch = np.zeros(n_nodes, dtype=np.bool_)
    residual = math.inf
    sweeps = 0
    while residual > tol_s:
        if sweeps >= max_sweeps:
            raise InputError(
                f"risk-neutral value iteration did not converge in {max_sweeps} sweeps "
                f"(last change {residual:.3g} s); use a coarser grid or raise max_sweeps"
            )
        sweeps += 1
        residual = 0.0
        for ring in blocks:
            # both tacks of a ring from the old values, then written (Gauss–Seidel by ring);
            # the ring is repeated while it changes (its nodes feed each other through θ
            # and the switch), which carries information around the ring in one sweep
            for it in range(ring_iterations):
                change = 0.0
                updates = []
                for n0, n1 in ring:
                    vals = tau + s_op.apply(v, n0, n1)
                    best = np.argmin(vals, axis=1)
                    vs = np.take_along_axis(vals, best[:, None], axis=1)[:, 0]
                    vc = tack_penalty_s + c_op.apply(v, n0, n1)[:, 0]
                    sw = vc < vs - SWITCH_EPS
                    new = np.minimum(np.where(sw, vc, vs), RN_UNREACHED_S)
                    change = max(change, float(np.max(np.abs(new - v[n0:n1]))))
                    updates.append((n0, n1, new, best, sw))
                for n0, n1, new, best, sw in updates:
                    v[n0:n1] = new
                    steer[n0:n1] = best
                    switch[n0:n1] = sw
                if it == 0:
                    residual = max(residual, change)
                if change <= tol_s:
                    break
        if progress is not None:
            progress(sweeps, residual)
    return RiskNeutralPolicy(
        grid=grid,
        tack_penalty_s=float(tack_penalty_s),
        model=model,
        speeds_ms=f,
        value_s=v[:n_nodes].copy(),
        steer=steer,
        switch=switch,
        iterations=sweeps,
        residual_s=residual,
        solve_time_s=time.perf_counter() - t0,
    )


@dataclass(frozen=True, eq=False)
class DeadlineSimulation:
    """Monte Carlo runs of a target-relative policy.

    Attributes
    ----------
    leg_time_s : ndarray, shape (n_runs,)
        Arrival time [s]; ``inf`` for runs that left ``r_max`` or passed ``t_max``.
    n_switches : ndarray of int, shape (n_runs,)
        Tack switches.
    fell_back : ndarray of bool, shape (n_runs,)
        Runs that switched to the risk-neutral policy (deadline out of reach).
    deadline_s : float or None
        Budget the risk-aware policy started with (after the upgrade); ``None``
        for the risk-neutral policy.
    tracks_xy_m : ndarray of float32, shape (n_tracks, n_steps, 2)
        Positions of the first runs (NaN after arrival) [m], mark at the origin,
        the initial wind from ``+y``.
    seed : int
    """

    leg_time_s: NDArray[np.float64]
    n_switches: NDArray[np.int64]
    fell_back: NDArray[np.bool_]
    deadline_s: float | None
    tracks_xy_m: NDArray[np.float32]
    seed: int


def start_budget(policy: DeadlinePolicy, r_m: float, theta_rad: float, tack: int,
                 deadline_s: float) -> float:
    """Budget after the deadline upgrade: the least ``s_k <= ŝ`` with ``w = 1`` if any."""
    g = policy.grid
    k_hat = int(min(round(deadline_s / g.ds_s), g.n_s))
    if k_hat < 0:
        raise InputError(f"deadline {deadline_s} s must be >= 0")
    curve = policy.success_curve(r_m, theta_rad, tack)[: k_hat + 1]
    sure = np.flatnonzero(curve >= SURE)
    return float(sure[0] * g.ds_s) if sure.size else float(k_hat * g.ds_s)


def simulate_deadline_chunk(
    rn: RiskNeutralPolicy,
    chunk_index: int,
    seed: int,
    start: tuple[float, float, int],
    ra: DeadlinePolicy | None = None,
    deadline_s: float | None = None,
    dt_s: float | None = None,
    t_max_s: float | None = None,
    n_tracks: int = 0,
    chunk_size: int = CHUNK_SIZE,
    give_up_below: float = 0.0,
) -> DeadlineSimulation:
    """Simulate one chunk of runs (see :func:`simulate_deadline`)."""
    g = rn.grid
    a, sigma = _model_rates(rn.model)
    c = rn.tack_penalty_s
    dt = g.ds_s / 5.0 if dt_s is None else float(dt_s)
    if not dt > 0:
        raise InputError(f"time step {dt_s} s must be > 0")
    r0, th0, tack0 = start
    if tack0 not in (1, -1):
        raise InputError(f"start tack must be +1 or -1, got {tack0}")
    t_max = (g.ds_s * g.n_s * 3.0) if t_max_s is None else float(t_max_s)
    rng = chunk_rng(seed, chunk_index)
    n = int(chunk_size)
    u = rn.grid.controls_rad
    f = rn.speeds_ms
    # wind from +y at the start (φ = 0); β = φ - θ is the bearing of the mark from the boat
    beta0 = -th0
    x = np.full(n, r0 * math.sin(beta0))
    y = np.full(n, -r0 * math.cos(beta0))
    phi = np.zeros(n)
    q = np.full(n, 0 if tack0 == 1 else 1, dtype=np.int64)
    t = np.zeros(n)
    switches = np.zeros(n, dtype=np.int64)
    done = np.zeros(n, dtype=bool)
    result = np.full(n, np.inf)
    s_hat: float | None = None
    if ra is not None and deadline_s is not None:
        s_hat = start_budget(ra, r0, th0, tack0, deadline_s)
    use_ra = s_hat is not None
    s_budget = np.full(n, s_hat if s_hat is not None else 0.0)
    risk_aware = np.full(n, use_ra)
    fell_back = np.zeros(n, dtype=bool)
    last_switch = np.zeros(n, dtype=bool)
    tracks: list[NDArray] = []
    n_tr = min(n_tracks, n)
    while not np.all(done):
        r = np.hypot(x, y)
        theta = np.mod(phi - np.arctan2(x, -y), 2 * math.pi)
        node = _nearest_nodes(g, r, theta, q)
        act_steer = rn.steer[node].astype(np.int64)
        act_u, act_f = u[act_steer], f[act_steer]
        act_switch = rn.switch[node].copy()
        if use_ra:
            assert ra is not None
            k = np.rint(s_budget / g.ds_s).astype(np.int64)
            ok = risk_aware & (k >= 0) & (k <= g.n_s)
            kk = np.clip(k, 0, g.n_s)
            ra_w, ra_u, ra_f, ra_sw = ra.decide(kk, node)
            hopeless = ok & (ra_w <= give_up_below)
            newly = risk_aware & (~ok | hopeless) & ~done
            fell_back |= newly
            risk_aware &= ~newly
            act_u = np.where(risk_aware, ra_u, act_u)
            act_f = np.where(risk_aware, ra_f, act_f)
            act_switch = np.where(risk_aware, ra_sw, act_switch)
        # never two switches in a row (a coarse grid can make the lookups ping-pong)
        act_switch &= ~last_switch & ~done
        z = rng.standard_normal(n)
        # switch: stand still for C while the wind moves
        phi_sw = phi + a * c + sigma * math.sqrt(c) * z
        # steer: Euler–Maruyama step
        heading = phi + np.where(q == 0, 1.0, -1.0) * act_u
        sp_ = act_f
        xn = x - sp_ * np.sin(heading) * dt
        yn = y + sp_ * np.cos(heading) * dt
        phin = phi + a * dt + sigma * math.sqrt(dt) * z
        steering = ~act_switch & ~done
        rn_new = np.hypot(xn, yn)
        arrive = steering & (rn_new <= g.target_radius_m)
        frac = np.clip((r - g.target_radius_m) / np.maximum(r - rn_new, 1e-300), 0.0, 1.0)
        result = np.where(arrive, t + frac * dt, result)
        x = np.where(steering, xn, x)
        y = np.where(steering, yn, y)
        phi = np.where(steering, phin, np.where(act_switch, phi_sw, phi))
        q = np.where(act_switch, 1 - q, q)
        switches += act_switch
        step = np.where(act_switch, c, np.where(steering, dt, 0.0))
        t = t + step
        s_budget = s_budget - step
        last_switch = act_switch
        lost = ~done & ~arrive & (((rn_new > g.r_max_m) & steering) | (t > t_max))
        done |= arrive | lost
        if n_tr:
            tracks.append(np.stack([np.where(done[:n_tr] & ~arrive[:n_tr], np.nan, x[:n_tr]),
                                    np.where(done[:n_tr] & ~arrive[:n_tr], np.nan, y[:n_tr])],
                                   axis=-1).astype(np.float32))
    tr = np.stack(tracks, axis=1) if tracks else np.zeros((0, 0, 2), dtype=np.float32)
    return DeadlineSimulation(
        leg_time_s=result,
        n_switches=switches,
        fell_back=fell_back,
        deadline_s=s_hat,
        tracks_xy_m=tr,
        seed=int(seed),
    )


def simulate_deadline(
    rn: RiskNeutralPolicy,
    n_runs: int,
    seed: int,
    start: tuple[float, float, int],
    ra: DeadlinePolicy | None = None,
    deadline_s: float | None = None,
    dt_s: float | None = None,
    t_max_s: float | None = None,
    n_tracks: int = 0,
    give_up_below: float = 0.0,
    scheduler: str | TaskRunner | None = None,
) -> DeadlineSimulation:
    """Seeded Monte Carlo of the risk-aware policy ``α^ŝ`` (with ``ra`` and ``deadline_s``)
    or of the risk-neutral policy ``μ*`` (without).

    Parameters
    ----------
    rn : RiskNeutralPolicy
        ``μ*``: the policy itself, or the fallback once the deadline is out of
        reach (``w = 0`` at the nearest node, or the budget is spent).
    n_runs : int
    seed : int
        Chunk ``k`` uses the same stream as in :mod:`sailroute.strategy.montecarlo`.
    start : (float, float, int)
        ``(r [m], θ [rad], tack)``: distance to the mark, upwind direction
        counter-clockwise from the boat→mark line, +1 starboard / -1 port.
    ra : DeadlinePolicy, optional
    deadline_s : float, optional
        ``ŝ`` [s]; upgraded to the least budget with ``w = 1`` when the deadline
        is sure to be met.
    dt_s : float, optional
        Euler–Maruyama step [s]; default ``Δs / 5``.
    t_max_s : float, optional
        Runs still sailing then count as failures; default ``3 s_max``.
    n_tracks : int
        Keep the tracks of this many runs (from the first chunk only).
    give_up_below : float
        Fall back to ``μ*`` once ``w`` at the nearest node is at or below this.
    scheduler : str, TaskRunner or None
        Where the chunks of :data:`~sailroute.strategy.montecarlo.CHUNK_SIZE`
        runs go (:func:`sailroute.parallel.map_tasks`); the result does not
        depend on it.
    """
    if n_runs < 1:
        raise InputError(f"number of Monte Carlo runs {n_runs} must be >= 1")
    if (ra is None) != (deadline_s is None):
        raise InputError("give both a deadline policy and a deadline, or neither")
    n_chunks = -(-int(n_runs) // CHUNK_SIZE)
    parts = map_tasks(
        _deadline_chunk_task,
        range(n_chunks),
        shared=(rn, seed, start, ra, deadline_s, dt_s, t_max_s, n_tracks, give_up_below),
        scheduler=scheduler,
    )
    sl = slice(0, n_runs)
    return DeadlineSimulation(
        leg_time_s=np.concatenate([p.leg_time_s for p in parts])[sl],
        n_switches=np.concatenate([p.n_switches for p in parts])[sl],
        fell_back=np.concatenate([p.fell_back for p in parts])[sl],
        deadline_s=parts[0].deadline_s,
        tracks_xy_m=parts[0].tracks_xy_m,
        seed=int(seed),
    )


def _deadline_chunk_task(
    chunk_index: int,
    rn: RiskNeutralPolicy,
    seed: int,
    start: tuple[float, float, int],
    ra: DeadlinePolicy | None,
    deadline_s: float | None,
    dt_s: float | None,
    t_max_s: float | None,
    n_tracks: int,
    give_up_below: float,
) -> DeadlineSimulation:
    """One chunk of :func:`simulate_deadline` (top level, so Dask can pickle it)."""
    return simulate_deadline_chunk(
        rn, chunk_index, seed, start, ra, deadline_s, dt_s, t_max_s,
        n_tracks if chunk_index == 0 else 0, CHUNK_SIZE, give_up_below,
    )
