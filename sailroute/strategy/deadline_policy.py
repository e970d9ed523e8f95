"""What the deadline solvers return: the stored slices (:class:`SliceBands`), the
risk-aware policy (:class:`DeadlinePolicy`) and the risk-neutral one
(:class:`RiskNeutralPolicy`), with their look-ups by node and budget."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sailroute.strategy._deadline_jit import STEER_MASK, SWITCH_BIT
from sailroute.strategy.deadline_grid import DeadlineGrid, _nearest_node, _node_coords
from sailroute.strategy.deadline_refine import OFFSET_STEPS
from sailroute.strategy.shiftmodel import DriftDiffusionShift


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

    def locate(
        self, grid: DeadlineGrid, k: NDArray | int, node: NDArray | int
    ) -> tuple[NDArray[np.int64], NDArray[np.int8]]:
        """Flat index of ``(k, node)`` (broadcast), and where it is not stored: ``-1``
        inside the mark (``w = 1``), ``-2`` beyond reach (``w = 0``), else 0."""
        k, node = np.broadcast_arrays(
            np.asarray(k, dtype=np.int64), np.asarray(node, dtype=np.int64)
        )
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

    def gather(
        self, table: NDArray, grid: DeadlineGrid, k: NDArray | int, node: NDArray | int
    ) -> NDArray:
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

    def decide(
        self, k: NDArray | int, node: NDArray | int
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
