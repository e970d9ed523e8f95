"""Compiled kernels of the deadline solver (optional: ``pip install 'sailroute[fast]'``).

Two loops of :mod:`sailroute.strategy.deadline` written out for `numba`_, each the
same arithmetic in the same order as the NumPy code it replaces, so that the policy is
the same bit for bit (``tests/strategy/test_strategy_deadline.py`` compares both):

- :func:`steer_stencil_bilinear` fills the steering operator (bilinear feet) that
  ``deadline._feet_stencil`` computes with array temporaries: one pass, no temporaries,
  the cosines and sines of ``θ + s_q u`` taken from tables NumPy computed.  It stores one
  column per foot, not four: the four points of a bilinear foot are ``c, c + 1, c + S,
  c + S + 1`` in a copy of the slice padded to ``S = n_θ + 1`` columns per ring (the
  periodic column repeated, :func:`pad_slice`), which cuts the operator's memory and
  traffic from 64 to 40 bytes a row.
- :func:`slice_update` is one budget slice over a range of nodes: the row products of the
  steering operator (bilinear: padded form; cubic: the CSR rows), the max over the
  controls, the switch update, the clip to ``[0, 1]`` and the "more budget never hurts"
  keep, fused into one loop over the nodes (the NumPy path makes a sparse mat-vec, an
  ``argmax``, a ``take_along_axis`` and five ``where`` passes over each block).

Without numba, :data:`AVAILABLE` is False and the solver runs its NumPy path.

.. _numba: https://numba.pydata.org
"""

from __future__ import annotations

import math
from typing import Any

try:  # optional extra
    import numba

    AVAILABLE = True
    """True when numba is installed and the compiled kernels can be used."""
except ImportError:  # pragma: no cover - exercised where numba is not installed
    AVAILABLE = False


def _jit(fn: Any) -> Any:
    # cache=True writes the compiled code next to the module (__pycache__), or, where that
    # folder is read-only, in numba's user-wide cache directory (NUMBA_CACHE_DIR).
    return numba.njit(cache=True, nogil=True)(fn) if AVAILABLE else fn


@_jit
def padded_offset(nt: int) -> int:
    """Index of node 0 in the padded slice: the two ghosts and room for a ghost foot's
    four reads (``0, 1, S, S + 1``) come first."""
    return nt + 3


@_jit
def steer_stencil_bilinear(
    cos_tab: Any, sin_tab: Any, speeds: Any, nr: int, nt: int, dr: float, dtheta: float,
    target_radius: float, r_max: float, tau: float, a: float, sigma_sqrt_tau: float,
    cols: Any, vals: Any,
) -> None:
    """Bilinear steering stencil of every node (``outer="fail"``), padded form.

    Parameters
    ----------
    cos_tab, sin_tab : ndarray, shape (2, nt, n_u)
        ``cos`` and ``sin`` of ``θ_j + s_q u_n`` (tack ``q``, angle ``j``, control ``n``).
    speeds : ndarray, shape (n_u,)
        Boat speed of each control [m s⁻¹].
    nr, nt : int
        Intervals in ``r``; nodes in ``θ``.
    dr, dtheta : float
        Grid spacings [m], [rad].
    target_radius, r_max : float
        Mark radius and outer radius [m].
    tau, a : float
        Steering time step [s] and wind drift [rad s⁻¹].
    sigma_sqrt_tau : float
        ``σ √τ`` [rad], the Gauss–Hermite foot offset.
    cols : ndarray of uint32, shape (n_nodes, n_u, 2)
        Output: per foot, the padded index ``c`` of its first point (ghost feet: 0 inside
        the mark, 1 beyond ``r_max``).
    vals : ndarray, shape (n_nodes, n_u, 8)
        Output: weights of ``c, c + 1, c + S, c + S + 1`` for each foot (float32 or
        float64), ``½`` of the bilinear weights; a ghost foot ``(½, 0, 0, 0)``.
    """
    n_u = speeds.shape[0]
    per_tack = (nr + 1) * nt
    stride = nt + 1
    off = padded_offset(nt)
    for p in range(2 * per_tack):
        q = p // per_tack
        i = (p % per_tack) // nt
        j = p % nt
        r = i * dr
        th = j * dtheta
        inv_r = 1.0 / r if r > 0 else 0.0
        for n in range(n_u):
            rf = r - tau * speeds[n] * cos_tab[q, j, n]
            dth = tau * (speeds[n] * inv_r * sin_tab[q, j, n] + a)
            inside = rf <= target_radius
            if inside or rf > r_max:
                ghost = 0 if inside else 1
                cols[p, n, 0] = ghost
                cols[p, n, 1] = ghost
                for e in range(8):
                    vals[p, n, e] = 0.0
                vals[p, n, 0] = 0.5
                vals[p, n, 4] = 0.5
                continue
            fr = min(max(rf / dr, 0.0), float(nr))
            i0 = min(math.floor(fr), nr - 1)
            t_r = fr - i0
            w_r0 = 1 - t_r
            ring = off + (q * (nr + 1) + i0) * stride
            for f in range(2):
                pm = 1.0 if f == 0 else -1.0
                ft = (th + dth + pm * sigma_sqrt_tau) / dtheta
                j0f = math.floor(ft)
                t_t = ft - j0f
                w_t0 = 1 - t_t
                cols[p, n, f] = ring + int(j0f) % nt
                e = 4 * f
                vals[p, n, e] = 0.5 * (w_r0 * w_t0)
                vals[p, n, e + 1] = 0.5 * (w_r0 * t_t)
                vals[p, n, e + 2] = 0.5 * (t_r * w_t0)
                vals[p, n, e + 3] = 0.5 * (t_r * t_t)


@_jit
def pad_slice(prev: Any, nt: int, out: Any) -> None:
    """Copy a slice ``prev`` (``n_nodes`` values and the two ghosts) into the padded form
    read by the bilinear rows: ghosts at 0 and 1, ring ``R`` at ``off + R S .. + nt``
    followed by its column 0 again (periodic ``θ``)."""
    n_nodes = prev.shape[0] - 2
    stride = nt + 1
    off = padded_offset(nt)
    out[0] = prev[n_nodes]
    out[1] = prev[n_nodes + 1]
    for ring in range(n_nodes // nt):
        src = ring * nt
        dst = off + ring * stride
        for j in range(nt):
            out[dst + j] = prev[src + j]
        out[dst + nt] = prev[src]


@_jit
def _row_bilinear(c0: int, c1: int, v: int, vals: Any, xpad: Any, stride: int) -> Any:
    """One bilinear row: foot +, then foot - (the CSR row's order of the sums)."""
    s = xpad.dtype.type(0.0)
    s += vals[v] * xpad[c0]
    s += vals[v + 1] * xpad[c0 + 1]
    s += vals[v + 2] * xpad[c0 + stride]
    s += vals[v + 3] * xpad[c0 + stride + 1]
    s += vals[v + 4] * xpad[c1]
    s += vals[v + 5] * xpad[c1 + 1]
    s += vals[v + 6] * xpad[c1 + stride]
    s += vals[v + 7] * xpad[c1 + stride + 1]
    return s


@_jit
def _best_bilinear(p: int, cols: Any, vals: Any, n_u: int, xpad: Any, stride: int) -> Any:
    """Best control (the first of equal maxima) and its value at node ``p`` (padded
    bilinear rows).  (Skipping controls whose eight points all lie below the best value
    so far reads fewer weights but costs more than it saves: 1.25x slower, measured.)"""
    wk = xpad.dtype.type(0.0)
    best = 0
    for n in range(n_u):
        c = (p * n_u + n) * 2
        s = _row_bilinear(cols[c], cols[c + 1], (p * n_u + n) * 8, vals, xpad, stride)
        if n == 0 or s > wk:
            wk = s
            best = n
    return wk, best


@_jit
def _best_csr(p: int, data: Any, indices: Any, n_u: int, per_row: int, prev: Any) -> Any:
    """Best control and its value at node ``p`` (CSR rows, e.g. bicubic)."""
    wk = prev.dtype.type(0.0)
    best = 0
    b = p * n_u * per_row
    for n in range(n_u):
        s = prev.dtype.type(0.0)
        for e in range(per_row):
            s += data[b + e] * prev[indices[b + e]]
        b += per_row
        if n == 0 or s > wk:
            wk = s
            best = n
    return wk, best


@_jit
def slice_update(
    bilinear: bool, cols: Any, vals: Any, n_u: int, per_row: int, stride: int, prev: Any,
    xpad: Any,
    sw_data: Any, sw_indices: Any, prev_c: Any, use_switch: bool,
    node_lo: int, node_hi: int, switch_eps: Any, zero_clip: Any, sure: Any,
    prev_steer: Any, prev_switch: Any, w_out: Any, steer_out: Any, switch_out: Any,
) -> None:
    """One budget slice for nodes ``node_lo .. node_hi - 1`` (see ``solve_deadline``).

    Parameters
    ----------
    bilinear : bool
        ``cols, vals`` are the padded bilinear rows of :func:`steer_stencil_bilinear`
        (read from ``xpad``), else the node-major CSR ``indices, data`` of the steering
        operator (``n_u`` rows of ``per_row`` entries per node; read from ``prev``).
    cols, vals : ndarray
        The steering operator, flattened; column indices as uint32 (numba then skips
        the negative-index wrap: 1.4x).
    n_u, per_row : int
        Controls per node; entries per CSR row (cubic).
    stride : int
        The padded ring length ``S = n_θ + 1`` (bilinear).
    prev : ndarray, shape (n_nodes + 2,)
        ``w`` of the previous slice with the two ghosts.
    xpad : ndarray
        ``prev`` padded by :func:`pad_slice` (bilinear only).
    sw_data, sw_indices : ndarray
        Switch operator entries (6 per node).
    prev_c : ndarray, shape (n_nodes + 2,)
        ``w`` of the slice ``C/Δs`` back (read only when ``use_switch``).
    switch_eps, zero_clip, sure : scalar of ``prev``'s dtype
        The solver's constants, in the value dtype (NumPy compares float32 arrays with
        Python floats in float32).
    prev_steer, prev_switch : ndarray, shape (n_nodes,)
        Action of the previous slice.
    w_out, steer_out, switch_out : ndarray, shape (n_nodes + 2,), (n_nodes,), (n_nodes,)
        This slice's value and action (written for the node range only).
    """
    zero = prev.dtype.type(0.0)
    one = prev.dtype.type(1.0)
    for p in range(node_lo, node_hi):
        pv = prev[p]
        if pv >= sure:  # kept whatever this slice gives: skip the row products
            w_out[p] = pv
            steer_out[p] = prev_steer[p]
            switch_out[p] = prev_switch[p]
            continue
        if bilinear:
            wk, best = _best_bilinear(p, cols, vals, n_u, xpad, stride)
        else:
            wk, best = _best_csr(p, vals, cols, n_u, per_row, prev)
        sw = False
        if use_switch:
            ws = zero
            b = p * 6
            for e in range(6):
                ws += sw_data[b + e] * prev_c[sw_indices[b + e]]
            if ws > wk + switch_eps:
                sw = True
                wk = ws
        if wk < zero_clip:
            wk = zero
        elif wk > one:
            wk = one
        if pv > wk:
            w_out[p] = pv
            steer_out[p] = prev_steer[p]
            switch_out[p] = prev_switch[p]
        else:
            w_out[p] = wk
            steer_out[p] = best
            switch_out[p] = sw
