"""Golden-section refinement of the deadline solver's steering angle (Wang et al. 2024's
second stage): between the neighbours of the best of the fixed controls, per node."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.polar import Polar
from sailroute.numerics import golden_max, golden_steps
from sailroute.strategy.deadline_grid import SURE, ZERO_CLIP, DeadlineGrid, _node_coords
from sailroute.strategy.deadline_rows import _feet_stencil

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

    def __init__(
        self, grid: DeadlineGrid, polar: Polar, tws_ms: float, a: float, sigma: float, tau: float
    ) -> None:
        self.grid, self.a, self.sigma, self.tau = grid, a, sigma, tau
        self.cubic = grid.interpolation == "cubic"
        self.u_tab, self.f_tab = _fine_speed_table(polar, tws_ms)
        self.du = math.pi / (grid.n_controls - 1)
        self.n_iter = golden_steps(2 * self.du, GOLDEN_TOL_RAD)

    def _value(self, x: NDArray, q: NDArray, i: NDArray, j: NDArray, u: NDArray) -> NDArray:
        f = np.interp(u, self.u_tab, self.f_tab)
        cols, wts = _feet_stencil(
            self.grid, q, i, j, u, f, self.a, self.sigma, self.tau, "fail", self.cubic
        )
        return np.einsum("mk,mk->m", wts, x[cols])

    def refine(
        self, x: NDArray, n0: int, n1: int, best: NDArray, wk: NDArray
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
        off = np.clip(np.rint((u_star - ub) / self.du * OFFSET_STEPS), -OFFSET_STEPS, OFFSET_STEPS)
        u_q = np.clip(ub + off * self.du / OFFSET_STEPS, 0.0, math.pi)
        v_q = self._value(x, q, i, j, u_q).astype(wk.dtype)
        better = v_q > wk[todo]
        wk = wk.copy()
        wk[todo[better]] = v_q[better]
        offset[todo[better]] = off[better].astype(np.int8)
        return wk, offset
