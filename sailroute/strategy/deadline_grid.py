"""The deadline solver's grid: target-relative nodes ``(r, θ, q)``, budget steps, constants.

The state space of Wang, Patnaik, Somalwar, Wu & Vladimirsky (2024) in physical units
(:mod:`sailroute.strategy.deadline`): rings ``r_i = i Δr`` out to ``r_max``, angles
``θ_j = j Δθ`` (periodic), both tacks; a flat node index ``(q (n_r + 1) + i) n_θ + j``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
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
            raise InputError("deadline grid: need n_r >= 2, n_theta >= 4, 2 <= n_controls <= 128")
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


def _node_coords(
    grid: DeadlineGrid, nodes: NDArray[np.int64]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """Tack index, ring and angle index of flat nodes."""
    per_tack = (grid.n_r + 1) * grid.n_theta
    return nodes // per_tack, (nodes % per_tack) // grid.n_theta, nodes % grid.n_theta


def _nearest_nodes(grid: DeadlineGrid, r: NDArray, theta: NDArray, q: NDArray) -> NDArray[np.int64]:
    """Nearest node; points outside the mark never map to a node inside it."""
    first = math.floor(grid.target_radius_m / grid.dr + 1e-9) + 1
    i = np.rint(r / grid.dr).astype(np.int64)
    i = np.clip(np.where(r > grid.target_radius_m, np.maximum(i, first), i), 0, grid.n_r)
    j = np.mod(np.rint(theta / grid.dtheta).astype(np.int64), grid.n_theta)
    return _flat(grid, q.astype(np.int64), i, j)


def _nearest_node(grid: DeadlineGrid, r_m: float, theta_rad: float, tack: int) -> int:
    """Flat index of the node nearest to one point ``(r [m], θ [rad])`` on ``tack`` (+1/-1)."""
    return int(
        _nearest_nodes(
            grid, np.array([r_m]), np.array([theta_rad]), np.array([0 if tack == 1 else 1])
        )[0]
    )


def _controls_speed(grid: DeadlineGrid, polar: Polar, tws_ms: float) -> NDArray[np.float64]:
    f = np.asarray(polar.speed(tws_ms, np.degrees(grid.controls_rad)), dtype=float)
    if not np.max(f) > 0:
        raise InputError(f"polar {polar.name!r} gives no boat speed at TWS {tws_ms} m/s")
    return f
