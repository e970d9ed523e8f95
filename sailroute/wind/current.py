"""Surface (tidal) current: the :class:`CurrentField` contract, its sources and the
water-relative wind.

Conventions (``docs/nomenclature.md``, "Current"):

* a current field maps arrays of ``(t, x, y)`` [epoch s, m, m] to ``(u, v)``
  [m s⁻¹], the eastward/northward velocity of the **water** over the ground, the
  direction it flows **to** -- the same contract and coverage rules as
  :class:`~sailroute.wind.base.WindField`, so the gridded reader serves both;
* the **set** of a current is the compass direction it flows **towards** (the nautical
  convention; the opposite of a wind direction), its **rate** the speed;
* a boat moves over the ground with its velocity through the water plus the current,
  and it feels the wind relative to the water: ``wind - current``
  (:class:`RelativeWind`).  Its TWA/TWS, polar speed and heading are all taken
  in the water; SOG/COG are over the ground.

Sources: :class:`UniformCurrent` (steady, everywhere), :class:`DiamondCurrent` (a
tidal-diamond table of set/rate by hour relative to high water, spatially uniform)
and gridded NetCDF u/v (:func:`open_netcdf_current`, through the CF reader).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError
from sailroute.wind.base import Coverage, WindField, prepare_points

CURRENT_NAMES = (
    ("uo", "vo"),
    ("eastward_sea_water_velocity", "northward_sea_water_velocity"),
    ("u", "v"),
)
"""Variable (or CF standard) names tried, in order, for a gridded current's u/v."""


def current_components(rate_ms: ArrayLike, set_deg: ArrayLike) -> tuple[NDArray, NDArray]:
    """Current vector ``(u, v)`` [m s⁻¹] from rate and set (direction flowing TO) [°]."""
    r = np.asarray(rate_ms, dtype=float)
    a = np.radians(np.asarray(set_deg, dtype=float))
    return r * np.sin(a), r * np.cos(a)


def current_rate_set(u: ArrayLike, v: ArrayLike) -> tuple[NDArray, NDArray]:
    """Rate [m s⁻¹] and set [°, towards, ``[0, 360)``] of a current vector."""
    u = np.asarray(u, dtype=float)
    v = np.asarray(v, dtype=float)
    return np.hypot(u, v), np.mod(np.degrees(np.arctan2(u, v)), 360.0)


@runtime_checkable
class CurrentField(Protocol):
    """Protocol of all current sources: water velocity ``(u, v)`` [m s⁻¹], towards."""

    @property
    def coverage(self) -> Coverage:
        """Time span and bounding box where :meth:`sample` is defined."""
        ...

    def sample(
        self, t: ArrayLike, x: ArrayLike, y: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Current ``(u, v)`` [m s⁻¹] at epoch ``t`` [s] and local ``x, y`` [m]."""
        ...


@dataclass(frozen=True, eq=False)
class UniformCurrent:
    """A steady current, the same everywhere.

    Parameters
    ----------
    speed_ms : float
        Rate [m s⁻¹], >= 0.
    set_deg : float
        Set: the compass direction the water flows **towards** [°].
    """

    speed_ms: float
    set_deg: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.speed_ms) and self.speed_ms >= 0 and np.isfinite(self.set_deg)):
            raise InputError(
                f"uniform current: the rate must be finite and >= 0 and the set "
                f"finite; got {self.speed_ms!r} m/s towards {self.set_deg!r}°"
            )

    @cached_property
    def _uv(self) -> tuple[float, float]:
        """Velocity components ``(u, v)`` [m s⁻¹] (east, north)."""
        u, v = current_components(self.speed_ms, self.set_deg)
        return float(u), float(v)

    @property
    def coverage(self) -> Coverage:
        """Everywhere, always."""
        return Coverage.everywhere()

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Current ``(u, v)`` [m s⁻¹] (broadcast shape of the inputs)."""
        t, x, y = prepare_points(self.coverage, t, x, y, clamp=False, name="uniform current")
        u, v = self._uv
        return np.full(t.shape, u), np.full(t.shape, v)


@dataclass(frozen=True, eq=False)
class DiamondCurrent:
    """A tidal diamond: set and rate by hour relative to high water, spatially uniform.

    Between the table's hours the current **vector** is interpolated linearly (so a
    turning stream passes through slack rather than swinging at full rate).

    Parameters
    ----------
    high_water : float
        Time of the reference high water [epoch s].
    hours : sequence of float
        Hours relative to high water (negative before), strictly increasing,
        e.g. ``-6 .. +6``.
    set_deg : sequence of float
        Set (towards) [°] per row.
    rate_ms : sequence of float
        Rate [m s⁻¹] per row (>= 0).
    clamp : bool
        Outside the table hold the first/last row instead of raising
        :class:`~sailroute.errors.OutOfCoverageError`.
    """

    high_water: float
    hours: Sequence[float]
    set_deg: Sequence[float]
    rate_ms: Sequence[float]
    clamp: bool = False

    def __post_init__(self) -> None:
        self._table  # noqa: B018  (built now: building it checks the rows)

    @cached_property
    def _table(self) -> tuple[NDArray, NDArray, NDArray]:
        """Row times [epoch s] and velocity components ``(t, u, v)`` [m s⁻¹]."""
        h = np.asarray(self.hours, dtype=float)
        s = np.asarray(self.set_deg, dtype=float)
        r = np.asarray(self.rate_ms, dtype=float)
        if not (h.ndim == 1 and h.shape == s.shape == r.shape and h.size >= 1):
            raise InputError(
                "tidal diamond: give one hour, set and rate per row "
                f"(got {h.size} hours, {s.size} sets, {r.size} rates)"
            )
        if not (
            np.all(np.isfinite(h))
            and np.all(np.isfinite(s))
            and np.all(np.isfinite(r))
            and np.all(r >= 0)
        ):
            raise InputError("tidal diamond: hours, sets and rates must be finite, rates >= 0")
        if np.any(np.diff(h) <= 0):
            raise InputError("tidal diamond: the hours must increase strictly from row to row")
        u, v = current_components(r, s)
        return float(self.high_water) + 3600.0 * h, u, v

    @property
    def coverage(self) -> Coverage:
        """Everywhere; from the first to the last row's time."""
        inf = float("inf")
        t = self._table[0]
        return Coverage(float(t[0]), float(t[-1]), -inf, inf, -inf, inf)

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Current ``(u, v)`` [m s⁻¹], linear in time between rows."""
        t, x, y = prepare_points(
            self.coverage, t, x, y, clamp=self.clamp, name="tidal-diamond current"
        )
        tt, u, v = self._table
        if tt.size == 1:
            return np.full(t.shape, u[0]), np.full(t.shape, v[0])
        return np.interp(t, tt, u), np.interp(t, tt, v)


@dataclass(frozen=True, eq=False)
class RelativeWind:
    """The wind a boat feels in a current: ``wind - current`` (a :class:`WindField`).

    Parameters
    ----------
    wind : WindField
        True wind over the ground.
    current : CurrentField
        Water velocity over the ground (towards).

    Its coverage is the intersection of the two; ``clamp`` is the wind's.
    """

    wind: WindField
    current: CurrentField

    @property
    def clamp(self) -> bool:
        """Whether the wind clamps at its edges (the router then ignores the box)."""
        return bool(self.wind.clamp)

    @property
    def coverage(self) -> Coverage:
        """Where both the wind and the current are defined."""
        a, b = self.wind.coverage, self.current.coverage
        return Coverage(
            max(a.t0, b.t0),
            min(a.t1, b.t1),
            max(a.xmin, b.xmin),
            min(a.xmax, b.xmax),
            max(a.ymin, b.ymin),
            min(a.ymax, b.ymax),
            frame=a.frame if a.frame is not None else b.frame,
        )

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Water-relative wind ``(u, v)`` [m s⁻¹]."""
        u, v = self.wind.sample(t, x, y)
        cu, cv = self.current.sample(t, x, y)
        return np.asarray(u, dtype=float) - cu, np.asarray(v, dtype=float) - cv


def _current_variables(path: Path) -> dict[str, str] | None:
    """The u/v variable names of a gridded current file (:data:`CURRENT_NAMES`), or None."""
    import netCDF4

    with netCDF4.Dataset(path) as ds:
        names = set(ds.variables)
        std = {getattr(v, "standard_name", None): k for k, v in ds.variables.items()}
    for a, b in CURRENT_NAMES:
        if a in names and b in names:
            return {"u": a, "v": b}
        if a in std and b in std:
            return {"u": std[a], "v": std[b]}
    return None


def open_netcdf_current(
    path: str | Path,
    frame: Any,
    *,
    variables: Mapping[str, str] | None = None,
    speed_unit: str | None = None,
    select: Mapping[str, int] | None = None,
    interpolation: str = "linear",
    steady: bool = False,
    clamp: bool = False,
    bbox: tuple[float, float, float, float] | None = None,
    time_window: tuple[float, float] | None = None,
) -> WindField:
    """Open a gridded lat/lon surface current (CF NetCDF, e.g. CMEMS ``uo``/``vo``).

    Read by the CF wind reader (:func:`sailroute.wind.cf.open_netcdf`): the water
    velocity's u/v are towards-components just like a wind's, so the grid, the
    rotation into the local frame and the coverage rules are the wind's.  No height
    correction.  Without ``variables`` the names in :data:`CURRENT_NAMES` are tried
    (variable names, then CF standard names).

    Raises
    ------
    InputError
        No u/v current variables found (the message lists what was tried).
    """
    from sailroute.wind.cf import open_netcdf

    p = Path(path)
    var = dict(variables) if variables else _current_variables(p)
    if var is None:
        tried = ", ".join(f"{a}/{b}" for a, b in CURRENT_NAMES)
        raise InputError(
            f"{p.name}: no surface-current variables found (tried {tried}, as "
            "names and CF standard names); name them with `variables: {u: ..., "
            "v: ...}`"
        )
    return open_netcdf(
        p,
        frame,
        bbox=bbox,
        time_window=time_window,
        variables=var,
        speed_unit=speed_unit,
        select=select,
        interpolation=interpolation,
        steady=steady,
        clamp=clamp,
        label=f"NetCDF current {p.name}",
    )
