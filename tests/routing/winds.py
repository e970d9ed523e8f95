"""Synthetic winds shared by the routing tests."""

from __future__ import annotations

import numpy as np

from sailroute.wind.grid import GridWind

T0 = 1_524_567_600.0  # 2018-04-24T11:00Z


def gridded_wind(clamp: bool, t0: float = T0) -> GridWind:
    """A wind that veers across the course and in time (500 m cells, 10-min slices over
    two hours from ``t0``), 3.6-5.4 m/s from about north."""
    xs = np.arange(-3000.0, 3001.0, 500.0)
    X, Y = np.meshgrid(xs, xs)
    times = t0 + np.arange(0.0, 7200.0 + 1.0, 600.0)
    T = times[:, None, None] - t0
    twd = 12.0 * np.sin(X / 1500.0) + 8.0 * np.sin(2 * np.pi * T / 1800.0)
    tws = 4.5 * (1.0 + 0.2 * np.cos(Y / 1200.0 + X / 2500.0)) + 0.0 * T
    rad = np.radians(twd)
    return GridWind(times, X, Y, -tws * np.sin(rad), -tws * np.cos(rad), clamp=clamp)
