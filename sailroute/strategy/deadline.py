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
from numpy.typing import NDArray

from sailroute.backend import get_xp, to_numpy
from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.strategy import _deadline_jit as _jit
from sailroute.strategy._deadline_jit import SWITCH_BIT
from sailroute.strategy._deadline_xp import DeviceRows
from sailroute.strategy.deadline_grid import (
    BLOCK_NODES,
    GH3_OFFSETS,
    GH3_WEIGHTS,
    INTERPOLATIONS,
    REFINEMENTS,
    RN_OUTSIDE_S,
    RN_UNREACHED_S,
    SURE,
    SWITCH_EPS,
    ZERO_CLIP,
    DeadlineGrid,
    _controls_speed,
    _model_rates,
)
from sailroute.strategy.deadline_policy import DeadlinePolicy, RiskNeutralPolicy, SliceBands
from sailroute.strategy.deadline_refine import OFFSET_STEPS, _SteerRefiner
from sailroute.strategy.deadline_rows import (
    _RingRows,
    _RowOperator,
    _steer_operator,
    _switch_operator,
)
from sailroute.strategy.deadline_simulate import (
    DeadlineSimulation,
    simulate_deadline,
    simulate_deadline_chunk,
    start_budget,
)
from sailroute.strategy.shiftmodel import DriftDiffusionShift

__all__ = [
    "BLOCK_NODES",
    "ENGINES",
    "GH3_OFFSETS",
    "GH3_WEIGHTS",
    "INTERPOLATIONS",
    "OFFSET_STEPS",
    "REFINEMENTS",
    "RN_OUTSIDE_S",
    "RN_UNREACHED_S",
    "SURE",
    "SWITCH_EPS",
    "ZERO_CLIP",
    "DeadlineGrid",
    "DeadlinePolicy",
    "DeadlineSimulation",
    "RiskNeutralPolicy",
    "SliceBands",
    "brownian_equivalent",
    "resolve_engine",
    "simulate_deadline",
    "simulate_deadline_chunk",
    "solve_deadline",
    "solve_risk_neutral",
    "start_budget",
]


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
        if (w_prev[lo * nt : (lo + 1) * nt] < sure).any() or (
            w_prev[per_tack + lo * nt : per_tack + (lo + 1) * nt] < sure
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
            raise InputError(
                "engine 'cupy' needs CuPy and an NVIDIA GPU: pip install "
                "'sailroute[gpu]' on a machine with one, or use engine 'auto' "
                "(numba where installed, else NumPy)"
            ) from None
    return engine == "numba" or (engine == "auto" and _jit.AVAILABLE), np


def _update_block(
    n0: int,
    n1: int,
    vals: NDArray,
    prev: NDArray,
    prev_c: NDArray | None,
    w_out: NDArray,
    actions: tuple[NDArray, NDArray],
    offsets: tuple[NDArray, NDArray] | None,
    refine: _SteerRefiner | None,
    switch_op: _RowOperator | DeviceRows,
    consts: tuple[Any, Any, Any],
    xp: ModuleType = np,
) -> None:
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
    a_out[n0:n1] = xp.where(
        keep, a_prev[n0:n1], (best | xp.where(sw, SWITCH_BIT, 0)).astype(np.uint8)
    )
    if offsets is not None and off is not None:
        offsets[1][n0:n1] = xp.where(keep, offsets[0][n0:n1], off)


@dataclass(frozen=True, eq=False)
class _SliceOperators:
    """The rows a budget slice multiplies, and how (:func:`solve_deadline`).

    ``rows``: the bilinear rows (None with bicubic interpolation); ``steer_op``: the
    steering rows as a host CSR operator (bicubic, or bilinear on the NumPy path; None
    where the compiled slice computes them); ``steer_x``, ``switch_x``: the rows the NumPy
    code multiplies, on the array module; ``block``: nodes per multiplication; ``jit``:
    whether the numba kernels march the slices.
    """

    rows: _RingRows | None
    steer_op: _RowOperator | None
    switch_op: _RowOperator
    steer_x: _RowOperator | DeviceRows | None
    switch_x: _RowOperator | DeviceRows
    block: int
    jit: bool
    refine: _SteerRefiner | None
    n_controls: int


def _slice_operators(
    grid: DeadlineGrid,
    f: NDArray[np.float64],
    rates: tuple[float, float, float],
    ftype: type,
    jit: bool,
    refine: _SteerRefiner | None,
    xp: ModuleType,
) -> _SliceOperators:
    """Steering and switch rows of ``grid`` for polar speeds ``f`` [m s⁻¹] and ``rates``
    ``(a, σ, C)`` (drift [rad s⁻¹], diffusion [rad s⁻½], tack penalty [s])."""
    a, sigma, penalty = rates
    cubic = grid.interpolation == "cubic"
    rows = None if cubic else _RingRows.build(grid, f, a, sigma, grid.ds_s, ftype, jit)
    if cubic:
        steer_op: _RowOperator | None = _steer_operator(
            grid, f, a, sigma, grid.ds_s, "fail", "cubic", ftype
        )
    else:  # the compiled slice computes the bilinear rows; NumPy multiplies them
        assert rows is not None
        steer_op = None if jit or xp is not np else rows.operator()
    switch_op = _switch_operator(grid, a, sigma, penalty, ftype)
    if xp is np:
        return _SliceOperators(
            rows, steer_op, switch_op, steer_op, switch_op, BLOCK_NODES, jit, refine, f.size
        )
    # on the array module: one block per tack band
    if steer_op is not None:
        steer_x: _RowOperator | DeviceRows = DeviceRows.from_host(steer_op, xp)
    else:
        assert rows is not None
        steer_x = DeviceRows.of(*rows.entries(xp, 1 << 17), xp)
    return _SliceOperators(
        rows,
        steer_op,
        switch_op,
        steer_x,
        DeviceRows.from_host(switch_op, xp),
        grid.n_nodes,
        jit,
        refine,
        f.size,
    )


def _working_slices(
    grid: DeadlineGrid, kc: int, n_in: int, ftype: type, refined: bool, xp: ModuleType
) -> tuple[NDArray, NDArray, NDArray | None]:
    """``w`` of the last ``kc + 1`` budgets (the switch reads ``C`` back), the action (and
    the refined offsets) of the last two: 1 inside the mark and on the ghost in the mark,
    0 elsewhere."""
    per_tack = (grid.n_r + 1) * grid.n_theta
    ws = xp.zeros((kc + 1, grid.n_nodes + 2), dtype=ftype)
    for q in (0, 1):
        ws[:, q * per_tack : q * per_tack + n_in * grid.n_theta] = 1.0
    ws[:, grid.n_nodes] = 1.0
    acts = xp.zeros((2, grid.n_nodes), dtype=np.uint8)
    offs = np.zeros((2, grid.n_nodes), dtype=np.int8) if refined else None
    return ws, acts, offs


def _slice_scratch(ops: _SliceOperators, nt: int, ftype: type) -> tuple[NDArray, ...]:
    """Scratch arrays of the compiled slice: the padded previous slice, the best value and
    control per node of a ring."""
    size = ops.rows.padded_size() if ops.rows is not None and ops.jit else 0
    xpad: NDArray[Any] = np.zeros(size, dtype=ftype)
    return (xpad, np.zeros(nt + _jit.LANES, dtype=ftype), np.zeros(nt + _jit.LANES, dtype=np.int8))


def _carry_sure_rings(
    grid: DeadlineGrid,
    k: int,
    kc: int,
    rings: tuple[int, int, int],
    ws: NDArray,
    acts: NDArray,
    offs: NDArray | None,
) -> None:
    """Rings below ``lo`` are sure and keep their value and action: bring the reused slots
    of slice ``k`` up to date (they hold budget ``k - kc - 1``, resp. ``k - 2``; rings
    frozen before agree).  ``rings``: ``(lo_w, lo_a, lo)``, the first ring those slots
    computed, and the first ring slice ``k`` computes."""
    lo_w, lo_a, lo = rings
    nt, per_tack = grid.n_theta, (grid.n_r + 1) * grid.n_theta
    prev, cur = ws[(k - 1) % (kc + 1)], ws[k % (kc + 1)]
    a_prev, a_cur = acts[(k - 1) % 2], acts[k % 2]
    for q in (0, 1):
        base = q * per_tack
        cur[base + lo_w * nt : base + lo * nt] = prev[base + lo_w * nt : base + lo * nt]
        a_cur[base + lo_a * nt : base + lo * nt] = a_prev[base + lo_a * nt : base + lo * nt]
        if offs is not None:
            offs[k % 2, base + lo_a * nt : base + lo * nt] = offs[
                (k - 1) % 2, base + lo_a * nt : base + lo * nt
            ]


def _march_slice(
    ops: _SliceOperators,
    grid: DeadlineGrid,
    k: int,
    kc: int,
    rings: tuple[int, int],
    ws: NDArray,
    acts: NDArray,
    offs: NDArray | None,
    consts: tuple[Any, ...],
    scratch: tuple[NDArray, ...],
    xp: ModuleType,
) -> None:
    """Rings ``rings = (lo, hi)`` (``lo .. hi - 1``) of budget slice ``k`` from slice
    ``k - 1`` (and ``k - kc`` for the switch), into the working slices."""
    lo, hi = rings
    nt, per_tack = grid.n_theta, (grid.n_r + 1) * grid.n_theta
    prev, cur = ws[(k - 1) % (kc + 1)], ws[k % (kc + 1)]
    prev_c = ws[max(k - kc, 0) % (kc + 1)]
    a_prev, a_cur = acts[(k - 1) % 2], acts[k % 2]
    switch_op, rows = ops.switch_op, ops.rows
    switch_args = (switch_op.data, switch_op.indices.view(np.uint32), prev_c, k >= kc)
    if ops.jit and rows is not None:
        assert rows.runs is not None
        xpad, best_val, best_n = scratch
        rows.pad_slice(prev, lo, hi, xpad)
        _jit.ring_slice(
            *rows.runs,
            rows.b,
            rows.h0,
            rows.h1,
            rows.inv_r,
            rows.ca,
            rows.cs,
            grid.n_r,
            nt,
            rows.pad,
            xpad,
            prev,
            *switch_args,
            lo,
            hi,
            *consts,
            a_prev,
            cur,
            a_cur,
            best_val,
            best_n,
        )
    elif ops.jit:
        steer_op = ops.steer_op
        assert steer_op is not None
        for q in (0, 1):
            _jit.slice_update(
                steer_op.indices.view(np.uint32),
                steer_op.data,
                ops.n_controls,
                steer_op.per_row,
                prev,
                *switch_args,
                q * per_tack + lo * nt,
                q * per_tack + hi * nt,
                *consts,
                a_prev,
                cur,
                a_cur,
            )
    else:
        steer_x = ops.steer_x
        assert steer_x is not None
        for q in (0, 1):
            for n0 in range(q * per_tack + lo * nt, q * per_tack + hi * nt, ops.block):
                n1 = min(n0 + ops.block, q * per_tack + hi * nt)
                vals = steer_x.apply(prev, n0, n1)
                _update_block(
                    n0,
                    n1,
                    vals,
                    prev,
                    prev_c if k >= kc else None,
                    cur,
                    (a_prev, a_cur),
                    None if offs is None else (offs[(k - 1) % 2], offs[k % 2]),
                    ops.refine,
                    ops.switch_x,
                    consts,
                    xp,
                )


def _store_band(
    grid: DeadlineGrid,
    start: int,
    rings: tuple[int, int],
    slices: tuple[NDArray, NDArray, NDArray | None],
    bands: tuple[NDArray, NDArray, NDArray | None],
) -> None:
    """Rings ``lo .. hi - 1`` of both tacks (tack 0, then tack 1) of the slice's ``w``,
    action and offsets into the flat band arrays from ``start``."""
    lo, hi = rings
    nt, per_tack = grid.n_theta, (grid.n_r + 1) * grid.n_theta
    size = (hi - lo) * nt
    cur, a_cur, o_cur = slices
    band_w, band_a, band_o = bands
    for q in (0, 1):
        dst = slice(start + q * size, start + (q + 1) * size)
        src = slice(q * per_tack + lo * nt, q * per_tack + hi * nt)
        band_w[dst] = cur[src]
        band_a[dst] = a_cur[src]
        if band_o is not None and o_cur is not None:
            band_o[dst] = o_cur[src]


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
        raise InputError(
            "engine 'cupy' does not refine the steering angle: use "
            "refine_controls='none', or engine 'numpy' or 'numba'"
        )
    kc = grid.penalty_steps(tack_penalty_s)
    a, sigma = _model_rates(model)
    f = _controls_speed(grid, polar, tws_ms)
    refine = (
        _SteerRefiner(grid, polar, tws_ms, a, sigma, grid.ds_s)
        if grid.refine_controls != "none"
        else None
    )
    # golden refinement runs on the NumPy path
    ops = _slice_operators(
        grid, f, (a, sigma, tack_penalty_s), ftype, compiled and refine is None, refine, xp
    )
    n_s, nt = grid.n_s, grid.n_theta
    n_in = int(np.count_nonzero(grid.r_m <= grid.target_radius_m))  # rings inside the mark
    reach_time = (grid.r_m - grid.target_radius_m) / float(np.max(f))  # per ring
    # rings reachable at top speed within each budget; rings beyond stay 0
    his = np.searchsorted(reach_time, grid.ds_s * np.arange(n_s + 1), side="right")
    his[0] = n_in
    bound = int(np.sum(his - n_in)) * 2 * nt  # the bands can be no larger (never touched)
    band_w = xp.empty(bound, dtype=ftype)
    band_a = xp.empty(bound, dtype=np.uint8)
    band_o = np.empty(bound, dtype=np.int8) if refine is not None else None
    los, starts = np.full(n_s + 1, n_in), np.zeros(n_s + 2, dtype=np.int64)
    ws, acts, offs = _working_slices(grid, kc, n_in, ftype, refine is not None, xp)
    consts = tuple(ftype(c) for c in (SWITCH_EPS, ZERO_CLIP, SURE))  # as NumPy compares
    scratch = _slice_scratch(ops, nt, ftype)
    lo = n_in
    for k in range(1, n_s + 1):
        hi = int(his[k])
        lo = _rings_all_sure(ws[(k - 1) % (kc + 1)], grid, lo, hi)
        _carry_sure_rings(
            grid,
            k,
            kc,
            (int(los[k - kc - 1]) if k > kc else n_in, int(los[k - 2]) if k > 1 else n_in, lo),
            ws,
            acts,
            offs,
        )
        _march_slice(ops, grid, k, kc, (lo, hi), ws, acts, offs, consts, scratch, xp)
        # store the band of rings lo .. hi - 1 (tack 0, then tack 1)
        los[k] = lo
        starts[k + 1] = starts[k] + 2 * (hi - lo) * nt
        _store_band(
            grid,
            int(starts[k]),
            (lo, hi),
            (ws[k % (kc + 1)], acts[k % 2], None if offs is None else offs[k % 2]),
            (band_w, band_a, band_o),
        )
        if progress is not None:
            progress(k, n_s)
    used = int(starts[-1])
    last = np.searchsorted(los, np.arange(grid.n_r + 1), side="right") - 1
    bands = SliceBands(
        los,
        his.astype(np.int64),
        starts,
        to_numpy(band_w[:used]),
        to_numpy(band_a[:used]),
        None if band_o is None else band_o[:used],
        n_in,
        last,
    )
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
        [
            (q * per_tack + i * nt + b0, q * per_tack + i * nt + min(b0 + BLOCK_NODES, nt))
            for q in (0, 1)
            for b0 in range(0, nt, BLOCK_NODES)
        ]
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
