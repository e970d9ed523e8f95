"""Wind fields defined by formulas: for tests, benchmarks and teaching examples."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.wind.base import Coverage, prepare_points

UVFunc = Callable[[NDArray, NDArray, NDArray], tuple[NDArray, NDArray]]


@dataclass(frozen=True, eq=False)
class AnalyticWind:
    """A wind field given by a vectorised function ``f(t, x, y) -> (u, v)``.

    Parameters
    ----------
    func : callable
        Takes broadcast float arrays ``t`` [epoch s], ``x``, ``y`` [m] and returns
        ``(u, v)`` [m s⁻¹] of the same shape.
    cover : Coverage
        Where the formula is meant to be used (default: everywhere).
    clamp : bool
        Clamp points to ``cover`` instead of raising outside it.
    name : str
        Label for messages.
    """

    func: UVFunc
    cover: Coverage = field(default_factory=Coverage.everywhere)
    clamp: bool = False
    name: str = "analytic wind"

    @property
    def coverage(self) -> Coverage:
        """The declared coverage."""
        return self.cover

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s] and ``x, y`` [m]."""
        t, x, y = prepare_points(self.cover, t, x, y, clamp=self.clamp, name=self.name)
        u, v = self.func(t, x, y)
        return (
            np.broadcast_to(np.asarray(u, dtype=float), t.shape).copy(),
            np.broadcast_to(np.asarray(v, dtype=float), t.shape).copy(),
        )


def debski_test_wind(
    v0: float = -20.0, length_m: float = 500.0, half_width_m: float = 400.0
) -> AnalyticWind:
    """Spatially varying test wind of Dębski (2016b).

    ``v_t(x, y) = v0 [(cos(x/L) + y/H) x̂ + (x/L - sin(y/L)) ŷ]`` with the paper's
    ``v0 = -20, L = 500, H = 400``; the leg runs from A = (0, 0) to B = (L, 0).
    The returned vector is the air velocity ``(u, v)`` [m s⁻¹] (with v0 < 0 the
    wind blows mostly towards -x, i.e. the leg A→B is upwind).

    Parameters
    ----------
    v0 : float
        Scale [m s⁻¹].
    length_m, half_width_m : float
        ``L`` and ``H`` [m].

    Returns
    -------
    AnalyticWind
        Time-independent field, covering x in [-L/2, 3L/2], y in [-H, H].
    """
    L, H = float(length_m), float(half_width_m)

    def f(t: NDArray, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
        return v0 * (np.cos(x / L) + y / H), v0 * (x / L - np.sin(y / L))

    inf = float("inf")
    cover = Coverage(-inf, inf, -0.5 * L, 1.5 * L, -H, H)
    return AnalyticWind(f, cover, name="Debski test wind")
