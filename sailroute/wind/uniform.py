"""Spatially uniform wind, constant or varying in time from a small table."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError
from sailroute.units import wind_components
from sailroute.wind.base import Coverage, prepare_points


@dataclass(frozen=True, eq=False)
class UniformWind:
    """Wind that is the same everywhere.

    Parameters
    ----------
    tws_ms : float or sequence of float
        True wind speed [m s⁻¹]; a sequence gives a time table (with ``times``).
    twd_deg : float or sequence of float
        Direction the wind comes from [°]; same length as ``tws_ms``.
    times : sequence of float, optional
        Epoch seconds of the table rows, strictly increasing.  Without it the
        wind is constant for all time.
    interpolation : {"linear", "previous"}
        Between table rows: linear in the ``(u, v)`` components, or hold the
        previous row (a wind that *switches* at the row times).
    clamp : bool
        Outside the table's time span hold the first/last row instead of
        raising :class:`~sailroute.errors.OutOfCoverageError`.
    """

    tws_ms: float | Sequence[float]
    twd_deg: float | Sequence[float]
    times: Sequence[float] | None = None
    interpolation: str = "linear"
    clamp: bool = False

    def __post_init__(self) -> None:
        self._table  # noqa: B018  (built now: building it checks the inputs)

    @cached_property
    def _table(self) -> tuple[NDArray, NDArray, NDArray]:
        """Row times [epoch s] (``[-inf]`` if constant) and components ``(t, u, v)``
        [m s⁻¹]."""
        s = np.atleast_1d(np.asarray(self.tws_ms, dtype=float))
        d = np.atleast_1d(np.asarray(self.twd_deg, dtype=float))
        if s.shape != d.shape:
            raise InputError(
                f"uniform wind: {s.size} speeds but {d.size} directions; give one of each per row"
            )
        if np.any(~np.isfinite(s)) or np.any(s < 0) or np.any(~np.isfinite(d)):
            raise InputError("uniform wind: speeds must be finite and >= 0, directions finite")
        if self.times is None:
            if s.size != 1:
                raise InputError("uniform wind: a table of several rows needs `times`")
            t = np.array([-np.inf])
        else:
            t = np.asarray(self.times, dtype=float)
            if t.shape != s.shape:
                raise InputError(f"uniform wind: {t.size} times for {s.size} rows")
            if np.any(np.diff(t) <= 0):
                raise InputError("uniform wind: table times must increase strictly")
        if self.interpolation not in ("linear", "previous"):
            raise InputError(
                f"uniform wind: interpolation {self.interpolation!r}; "
                "expected 'linear' or 'previous'"
            )
        u, v = wind_components(s, d)
        return t, u, v

    @property
    def coverage(self) -> Coverage:
        """Unbounded in space; the table's time span (unbounded if constant)."""
        inf = float("inf")
        if self.times is None:
            return Coverage.everywhere()
        t = self._table[0]
        return Coverage(float(t[0]), float(t[-1]), -inf, inf, -inf, inf)

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s], position ``x, y`` [m] (broadcast)."""
        t, x, y = prepare_points(self.coverage, t, x, y, clamp=self.clamp, name="uniform wind")
        tt, u, v = self._table
        if tt.size == 1:
            return np.full(t.shape, u[0]), np.full(t.shape, v[0])
        if self.interpolation == "previous":
            k = np.clip(np.searchsorted(tt, t, side="right") - 1, 0, tt.size - 1)
            return u[k], v[k]
        return np.interp(t, tt, u), np.interp(t, tt, v)
