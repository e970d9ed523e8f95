"""Synthetic polars shared by the routing tests (independent of the boat package's data)."""

from __future__ import annotations

import numpy as np

from sailroute.boat.polar import Polar


def laser_like_polar() -> Polar:
    """Smooth Laser-like table: speed = f(TWS) g(TWA), no-go below ~30°, best VMG
    near 43° upwind and near 150° downwind (running dead downwind is clearly slower,
    so a run is sailed with gybes).  TWS columns 1-12 m s⁻¹, speeds [m s⁻¹]."""
    twa = np.array([0, 30, 40, 45, 50, 60, 75, 90, 105, 120, 135, 150, 165, 180.0])
    g = np.array([0, 0.45, 0.68, 0.74, 0.79, 0.85, 0.92, 0.97, 1.0, 0.97, 0.9, 0.82, 0.66, 0.55])
    tws = np.array([1, 2, 3, 4, 5, 6, 7, 8, 10, 12.0])
    return Polar.from_arrays(
        twa, tws, np.outer(g, 3.4 * (1 - np.exp(-tws / 3.5))), name="laser-like"
    )
