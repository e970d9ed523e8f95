"""Compiled kernels of the deadline solver (optional: ``pip install 'sailroute[fast]'``).

The loops of :mod:`sailroute.strategy.deadline` written out for `numba`_, each the
same arithmetic in the same order as the NumPy code it replaces, so that the policy is
the same bit for bit (``tests/strategy/test_strategy_deadline.py`` compares both):

- bilinear (the default): :func:`ring_slice` is one budget slice.  Nothing is stored per
  row: a foot's ring offset and fraction depend only on the tack, control and angle, its
  angular offset on those and the ring (``deadline_rows._RingRows``), so along a ring the rows
  fall into runs (:func:`fill_runs`, built once per solve) that read contiguous memory;
  :func:`run_values` does a run's rows for one control, and numba vectorises it.
  :func:`pad_rings` copies the slice into the padded form the runs read.
- bicubic: :func:`slice_update` does the CSR rows of a node range.
- both: :func:`finish_nodes` is the switch update, the clip to ``[0, 1]`` and the "more
  budget never hurts" keep (the NumPy path makes five ``where`` passes over each block).

Without numba, :data:`AVAILABLE` is False and the solver runs its NumPy path.

.. _numba: https://numba.pydata.org
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from sailroute.jit import AVAILABLE as AVAILABLE  # re-exported: numba is installed
from sailroute.jit import inline as _inline
from sailroute.jit import jit as _jit

SWITCH_BIT = 128
"""Bit of an action (``deadline.DeadlinePolicy.action``) set where switching tack is
optimal."""
STEER_MASK = 127
"""Bits of an action holding the steering control index."""


@_jit
def count_runs(
    g: Any,
    b: Any,
    inv_r: Any,
    ca: Any,
    cs: Any,
    fr_in: float,
    nr: int,
    nt: int,
    ring0: int,
    ptr: Any,
) -> None:
    """Number of runs of every ``(q, i, n)`` (see :func:`fill_runs`), as offsets ``ptr``."""
    _runs(g, b, inv_r, ca, cs, fr_in, nr, nt, ring0, ptr, False, ptr, ptr, ptr, ptr, ptr, ptr)


@_jit
def fill_runs(
    g: Any,
    b: Any,
    inv_r: Any,
    ca: Any,
    cs: Any,
    fr_in: float,
    nr: int,
    nt: int,
    ring0: int,
    ptr: Any,
    j0: Any,
    j1: Any,
    kind: Any,
    di: Any,
    op: Any,
    om: Any,
) -> None:
    """The runs of the ring-relative bilinear rows (``deadline_rows._RingRows``).

    Along ``j`` (fixed tack ``q``, ring ``i >= ring0``, control ``n``) a row is one of: a
    foot inside the mark (``kind`` 1, value 1), beyond ``r_max`` (2, value 0), or two feet
    on rings ``i + di`` and ``i + di + 1`` at angle columns ``j + op`` and ``j + om`` (+ 1)
    (``kind`` 0).  A run is a range ``j0 .. j1 - 1`` over which these do not change, so its
    rows read contiguous memory and the slice loop over it vectorises.  ``op``/``om`` are
    ``floor(x ± c_σ)`` with ``x = b inv_r + c_a`` in the value dtype, as :func:`run_values`
    and the NumPy rows compute them.
    """
    _runs(g, b, inv_r, ca, cs, fr_in, nr, nt, ring0, ptr, True, j0, j1, kind, di, op, om)


@_jit
def _runs(
    g: Any,
    b: Any,
    inv_r: Any,
    ca: Any,
    cs: Any,
    fr_in: float,
    nr: int,
    nt: int,
    ring0: int,
    ptr: Any,
    fill: bool,
    j0: Any,
    j1: Any,
    kind: Any,
    di: Any,
    op: Any,
    om: Any,
) -> None:
    n_u = g.shape[1]
    m = 0
    for q in range(2):
        for i in range(nr + 1):
            ir = inv_r[i]
            for n in range(n_u):
                ptr[(q * (nr + 1) + i) * n_u + n] = m
                if i < ring0:
                    continue
                k0, d0, p0, m0 = -1, 0, 0, 0
                for j in range(nt):
                    fr = i + g[q, n, j]
                    k = 1 if fr <= fr_in else (2 if fr > nr else 0)
                    d = p = mm = 0
                    if k == 0:
                        d = math.floor(g[q, n, j])
                        x = b[q, n, j] * ir + ca
                        p = math.floor(x + cs)
                        mm = math.floor(x - cs)
                    if j == 0 or k != k0 or d != d0 or p != p0 or mm != m0:
                        if fill:
                            if j > 0:
                                j1[m - 1] = j
                            j0[m] = j
                            kind[m] = k
                            di[m] = d
                            op[m] = p
                            om[m] = mm
                        m += 1
                        k0, d0, p0, m0 = k, d, p, mm
                if fill:
                    j1[m - 1] = nt
    ptr[2 * (nr + 1) * n_u] = m


@_jit
def pad_rings(prev: Any, nr: int, nt: int, pad: int, ring_lo: int, ring_hi: int, out: Any) -> None:
    """Copy rings ``ring_lo - 1 .. ring_hi`` of ``prev`` into the padded slice of
    ``deadline_rows._RingRows`` (``pad`` periodic columns on each side of every ring)."""
    stride = nt + 2 * pad
    for q in range(2):
        for i in range(max(ring_lo - 1, 0), min(ring_hi + 1, nr + 1)):
            src = (q * (nr + 1) + i) * nt
            dst = (q * (nr + 2) + i) * stride
            for c in range(nt):
                out[dst + pad + c] = prev[src + c]
            for c in range(pad):  # the wings (pad may exceed nt on coarse grids)
                out[dst + c] = prev[src + (c - pad) % nt]
                out[dst + pad + nt + c] = prev[src + c % nt]


LANES = 16
"""Rows per vector chunk: a run is done over whole chunks, the rows outside it masked (a
scalar remainder per run cost more; the tables and scratch have ``LANES`` spare columns)."""


@_inline
def run_values(
    j_lo: int,
    j_hi: int,
    b: Any,
    h0: Any,
    h1: Any,
    ir: Any,
    ca: Any,
    cs: Any,
    fop: Any,
    fom: Any,
    xpad: Any,
    ring: int,
    stride: int,
    n: Any,
    best_val: Any,
    best_n: Any,
) -> None:
    """Rows ``j_lo .. j_hi - 1`` of one run (``kind`` 0) of control ``n``; keeps the best
    so far per node.  A row is the weighted sum of ``deadline_rows._RingRows`` in the order of
    its CSR entries (the NumPy path's mat-vec adds them in that order).

    The loop runs over whole chunks of :data:`LANES` rows with the rows outside the run
    masked, and its indices are unsigned (>= 0 by construction), so numba drops the
    negative-index wrap and LLVM vectorises it without a scalar remainder.
    """
    one = xpad.dtype.type(1.0)
    u1 = np.uint64(1)
    a_ = np.uint64(ring + int(fop))  # ring i + di, the + foot
    b_ = a_ + np.uint64(stride)  # the next ring
    c_ = np.uint64(ring + int(fom))  # the - foot
    d_ = c_ + np.uint64(stride)
    lo = np.uint64(j_lo)
    hi = np.uint64(j_hi)
    start = np.uint64(j_lo - j_lo % LANES)
    stop = np.uint64(j_hi + (-j_hi) % LANES)
    for jj in range(start, stop):
        j = np.uint64(jj)
        x = b[j] * ir + ca
        tp = (x + cs) - fop
        tm = (x - cs) - fom
        w0 = h0[j]
        w1 = h1[j]
        s = xpad.dtype.type(0.0)
        s += (w0 * (one - tp)) * xpad[a_ + j]
        s += (w0 * tp) * xpad[a_ + j + u1]
        s += (w1 * (one - tp)) * xpad[b_ + j]
        s += (w1 * tp) * xpad[b_ + j + u1]
        s += (w0 * (one - tm)) * xpad[c_ + j]
        s += (w0 * tm) * xpad[c_ + j + u1]
        s += (w1 * (one - tm)) * xpad[d_ + j]
        s += (w1 * tm) * xpad[d_ + j + u1]
        old = best_val[j]
        better = (s > old) & (j >= lo) & (j < hi)
        best_val[j] = s if better else old
        best_n[j] = n if better else best_n[j]


@_jit
def unsure_arc(prev: Any, base: int, nt: int, sure: Any) -> tuple[int, int]:
    """``(start, length)`` of the shortest arc of ``j`` (periodic) holding every node of
    the ring at ``prev[base:base + nt]`` with ``w < sure``: the complement of the longest
    run of sure nodes.  ``(0, nt)`` when none is sure, length 0 when all are."""
    best_len, best_end = 0, 0
    run = 0
    for jj in range(2 * nt):  # twice round: a sure run may wrap past j = 0
        if prev[base + jj % nt] >= sure:
            run += 1
            if run > best_len:
                best_len, best_end = run, jj + 1
        else:
            run = 0
    if best_len >= nt:
        return 0, 0
    return best_end % nt, nt - best_len


@_jit
def ring_slice(
    ptr: Any,
    j0: Any,
    j1: Any,
    kind: Any,
    di: Any,
    op: Any,
    om: Any,
    b: Any,
    h0: Any,
    h1: Any,
    inv_r: Any,
    ca: Any,
    cs: Any,
    nr: int,
    nt: int,
    pad: int,
    xpad: Any,
    prev: Any,
    sw_data: Any,
    sw_indices: Any,
    prev_c: Any,
    use_switch: bool,
    ring_lo: int,
    ring_hi: int,
    switch_eps: Any,
    zero_clip: Any,
    sure: Any,
    prev_action: Any,
    w_out: Any,
    action_out: Any,
    best_val: Any,
    best_n: Any,
) -> None:
    """One budget slice of the bilinear solve for rings ``ring_lo .. ring_hi - 1``.

    Per ring and tack: the best control of every node over the runs of
    :func:`fill_runs` (controls in order, the first of equal maxima kept), then
    :func:`finish_nodes` (switch, clip, keep).  ``xpad`` holds ``prev`` padded by
    :func:`pad_rings`; ``best_val``, ``best_n`` are scratch of ``nt`` entries.
    """
    n_u = b.shape[1]
    stride = nt + 2 * pad
    first = prev.dtype.type(-1.0)  # below any row value: control 0 always sets the best
    one = prev.dtype.type(1.0)
    zero = prev.dtype.type(0.0)
    per_tack = (nr + 1) * nt
    for q in range(2):
        for i in range(ring_lo, ring_hi):
            ir = inv_r[i]
            for j in range(nt):
                best_val[j] = first
            # the nodes not yet sure: at most two ranges of j (a sure node keeps its value)
            a, length = unsure_arc(prev, q * per_tack + i * nt, nt, sure)
            spans = ((a, min(a + length, nt)), (0, max(a + length - nt, 0)))
            for n in range(n_u):
                nn = np.int8(n)
                t = (q * (nr + 1) + i) * n_u + n
                b_qn, h0_qn, h1_qn = b[q, n], h0[q, n], h1[q, n]
                for r in range(ptr[t], ptr[t + 1]):
                    for lo_, hi_ in spans:
                        r0, r1 = max(j0[r], lo_), min(j1[r], hi_)
                        if r0 >= r1:
                            continue
                        if kind[r] != 0:  # a ghost foot: the mark (1) or beyond r_max (0)
                            g = one if kind[r] == 1 else zero
                            for j in range(r0, r1):
                                if g > best_val[j]:
                                    best_val[j] = g
                                    best_n[j] = nn
                            continue
                        ring = (q * (nr + 2) + i + di[r]) * stride + pad
                        run_values(
                            r0,
                            r1,
                            b_qn,
                            h0_qn,
                            h1_qn,
                            ir,
                            ca,
                            cs,
                            prev.dtype.type(op[r]),
                            prev.dtype.type(om[r]),
                            xpad,
                            ring,
                            stride,
                            nn,
                            best_val,
                            best_n,
                        )
            finish_nodes(
                q * per_tack + i * nt,
                best_val[:nt],
                best_n[:nt],
                prev,
                sw_data,
                sw_indices,
                prev_c,
                use_switch,
                switch_eps,
                zero_clip,
                sure,
                prev_action,
                w_out,
                action_out,
            )


@_jit
def finish_nodes(
    p0: int,
    best_val: Any,
    best_n: Any,
    prev: Any,
    sw_data: Any,
    sw_indices: Any,
    prev_c: Any,
    use_switch: bool,
    switch_eps: Any,
    zero_clip: Any,
    sure: Any,
    prev_action: Any,
    w_out: Any,
    action_out: Any,
) -> None:
    """Nodes ``p0 .. p0 + len(best_val) - 1`` given their best steering value and
    control: the switch update, the clip to ``[0, 1]`` and the "more budget never hurts"
    keep (a node already sure keeps its value and action).  The action is the control
    index with :data:`SWITCH_BIT` set for a switch.  One call per
    ring or block: numba passes each array as a struct of its fields, which per node
    costs more than the work (and inlining it per node made the slice 1.9x slower)."""
    zero = prev.dtype.type(0.0)
    one = prev.dtype.type(1.0)
    for j in range(best_val.shape[0]):
        p = p0 + j
        pv = prev[p]
        if pv >= sure:
            w_out[p] = pv
            action_out[p] = prev_action[p]
            continue
        wk = best_val[j]
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
            action_out[p] = prev_action[p]
        else:
            w_out[p] = wk
            action_out[p] = np.uint8(best_n[j]) | (np.uint8(SWITCH_BIT) if sw else np.uint8(0))


@_inline
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
    cols: Any,
    vals: Any,
    n_u: int,
    per_row: int,
    prev: Any,
    sw_data: Any,
    sw_indices: Any,
    prev_c: Any,
    use_switch: bool,
    node_lo: int,
    node_hi: int,
    switch_eps: Any,
    zero_clip: Any,
    sure: Any,
    prev_action: Any,
    w_out: Any,
    action_out: Any,
) -> None:
    """One budget slice for nodes ``node_lo .. node_hi - 1`` with CSR steering rows
    (bicubic; see ``solve_deadline``).

    Parameters
    ----------
    cols, vals : ndarray
        The node-major CSR ``indices`` (uint32: numba then skips the negative-index
        wrap, 1.4x) and ``data`` of the steering operator, ``n_u`` rows of ``per_row``
        entries per node.
    n_u, per_row : int
        Controls per node; entries per row.
    prev : ndarray, shape (n_nodes + 2,)
        ``w`` of the previous slice with the two ghosts.
    sw_data, sw_indices : ndarray
        Switch operator entries (6 per node).
    prev_c : ndarray, shape (n_nodes + 2,)
        ``w`` of the slice ``C/Δs`` back (read only when ``use_switch``).
    switch_eps, zero_clip, sure : scalar of ``prev``'s dtype
        The solver's constants, in the value dtype (NumPy compares float32 arrays with
        Python floats in float32).
    prev_action : ndarray of uint8, shape (n_nodes,)
        Action of the previous slice (control index, bit 7 a switch).
    w_out, action_out : ndarray, shape (n_nodes + 2,), (n_nodes,)
        This slice's value and action (written for the node range only).
    """
    best_val = np.empty(node_hi - node_lo, dtype=prev.dtype)
    best_n = np.zeros(node_hi - node_lo, dtype=np.int8)
    for p in range(node_lo, node_hi):
        if prev[p] < sure:  # a sure node keeps its value: skip its rows
            best_val[p - node_lo], best_n[p - node_lo] = _best_csr(
                p, vals, cols, n_u, per_row, prev
            )
    finish_nodes(
        node_lo,
        best_val,
        best_n,
        prev,
        sw_data,
        sw_indices,
        prev_c,
        use_switch,
        switch_eps,
        zero_clip,
        sure,
        prev_action,
        w_out,
        action_out,
    )
