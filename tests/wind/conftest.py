"""Fixtures for the wind tests: a tiny genuine-layout wrfout writer and station CSVs."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pytest

from sailroute.geo import LocalFrame
from sailroute.units import wind_components
from sailroute.wind.synthetic_wrf import LambertGrid, write_wrfout

T0 = 1524556800.0  # 2018-04-24T08:00:00Z
CENTER = (45.0, 10.0)
# A Lambert grid whose standard longitude lies 20 degrees west of the domain:
# the grid is rotated by alpha = -cone * 20 deg = -14.31 deg (cone 0.7156 for 30/60),
# large enough that a sign error in the rotation shows at once.
TRUELATS = (30.0, 60.0)
STAND_LON = -10.0


def constant_wind(tws: float, twd: float) -> Callable:
    """``wind10(t, lat, lon)`` for a constant earth-relative wind."""
    u, v = wind_components(tws, twd)

    def f(t: float, lat: np.ndarray, lon: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.full(lat.shape, float(u)), np.full(lat.shape, float(v))

    return f


def power_profile(tws10: float, twd: float, alpha: float) -> Callable:
    """``wind_at(t, lat, lon, z)``: constant direction, speed ``tws10 (z/10)^alpha``."""
    u, v = wind_components(tws10, twd)

    def f(t: float, lat: np.ndarray, lon: np.ndarray, z: float) -> tuple[np.ndarray, np.ndarray]:
        k = (z / 10.0) ** alpha
        return np.full(lat.shape, float(u) * k), np.full(lat.shape, float(v) * k)

    return f


@pytest.fixture
def frame() -> LocalFrame:
    """Local frame at the centre of the tiny WRF grid."""
    return LocalFrame(*CENTER)


@pytest.fixture
def tiny_wrf(tmp_path: Path) -> Callable[..., Path]:
    """Factory writing a small real NetCDF file in wrfout layout.

    Defaults: 7 x 6 cells of 1000 m, Lambert (30/60, STAND_LON -10) centred at
    45 N 10 E, 4 slices 10 min apart from 2018-04-24T08:00Z, constant 5 m/s from
    150 deg at 10 m, two model levels at 7.5 m and 25 m with a 0.15 power law.
    """

    def make(
        name: str = "tiny_wrfout.nc",
        *,
        wind10: Callable | None = None,
        wind_at: Callable | None = None,
        level_heights_m: Sequence[float] | None = (7.5, 25.0),
        times: Sequence[float] | None = None,
        nx: int = 7,
        ny: int = 6,
        dx_m: float = 1000.0,
        write_alpha: bool = True,
        center: tuple[float, float] = CENTER,
        stand_lon: float = STAND_LON,
    ) -> Path:
        grid = LambertGrid(center[0], center[1], nx, ny, dx_m, *TRUELATS, stand_lon)
        t = T0 + 600.0 * np.arange(4) if times is None else np.asarray(times, float)
        w10 = wind10 or constant_wind(5.0, 150.0)
        wat = wind_at or power_profile(5.0, 150.0, 0.15)
        return write_wrfout(
            tmp_path / name,
            grid,
            t,
            w10,
            level_heights_m=level_heights_m,
            wind_at=wat if level_heights_m is not None else None,
            write_alpha=write_alpha,
        )

    return make


@pytest.fixture
def station_csv(tmp_path: Path) -> Callable[..., Path]:
    """Factory writing a station CSV from a header and rows (lists of cells)."""

    def make(
        rows: Sequence[Sequence[object]],
        header: Sequence[str] = ("time", "station", "lat", "lon", "speed", "direction"),
        name: str = "st.csv",
        sep: str = ",",
    ) -> Path:
        p = tmp_path / name
        lines = [sep.join(header)] + [sep.join(str(c) for c in r) for r in rows]
        p.write_text("\n".join(lines) + "\n")
        return p

    return make
