"""The deadline solver's linear updates: steering and switch rows of every node.

Steering (Wang et al. 2024): two Gauss–Hermite feet ``θ ± σ√τ`` per control, bilinear
(:class:`_RingRows`, relative to the node, nothing stored per row) or bicubic Lagrange
(:func:`_steer_operator`, a node-major sparse operator); switch: the three-node rule over
the other tack after the tack penalty (:func:`_switch_operator`).  Columns are the flat
nodes of a budget slice plus two ghosts: inside the mark (value 1), beyond ``r_max``
(value 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from sailroute.errors import InputError
from sailroute.strategy import _deadline_jit as _jit
from sailroute.strategy.deadline_grid import (
    BLOCK_NODES,
    GH3_OFFSETS,
    GH3_WEIGHTS,
    INTERPOLATIONS,
    DeadlineGrid,
    _node_coords,
)


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
    def build(
        cls, cols: NDArray, vals: NDArray, n_cols: int, block_nodes: int = BLOCK_NODES
    ) -> _RowOperator:
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
            indptr=np.arange(0, per_row * rows_per_node * block_nodes + 1, per_row, dtype=np.int32),
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
        cols[n0:n1], vals[n0:n1] = _feet_stencil(
            grid, q, i, j, u, speeds, a, sigma, tau, outer, cubic
        )
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
    def build(
        cls,
        grid: DeadlineGrid,
        speeds: NDArray[np.float64],
        a: float,
        sigma: float,
        tau: float,
        dtype: type,
        compiled: bool,
    ) -> _RingRows:
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
        pad = (
            math.ceil(float(np.max(np.abs(b))) * float(inv_r[n_in]) + abs(float(ca)) + float(cs))
            + 2
        )
        fr_in = grid.target_radius_m / grid.dr
        runs = None
        if compiled:
            ptr = np.zeros(2 * (grid.n_r + 1) * u.size + 1, dtype=np.int64)
            _jit.count_runs(g, b, inv_r, ca, cs, fr_in, grid.n_r, grid.n_theta, n_in, ptr)
            m = int(ptr[-1])
            runs = (
                ptr,
                np.empty(m, np.int64),
                np.empty(m, np.int64),
                np.empty(m, np.int8),
                np.empty(m, np.int64),
                np.empty(m, np.int64),
                np.empty(m, np.int64),
            )
            _jit.fill_runs(g, b, inv_r, ca, cs, fr_in, grid.n_r, grid.n_theta, n_in, *runs)
        return cls(g, _spare(b), di, _spare(h0), _spare(h1), inv_r, ca, cs, fr_in, pad, grid, runs)

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

    def entries(
        self, xp: ModuleType = np, step: int = BLOCK_NODES // 8
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
