"""Where a wind file says there is land: WRF's ``LANDMASK``/``XLAND``, or a grid's NaN cells.

The maps draw it as land when the course names no chart file
(:mod:`sailroute.report.chart`).  A WRF file's mask is read for its whole grid (the wind
itself is read for the course's box only), so that the land round the course shows
when the reader zooms out; a gridded wind from another source (CF NetCDF, a sea-only
product) marks land with NaN winds, and those cells are its land.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.geo import LocalFrame
from sailroute.wind.grid import GridWind
from sailroute.wind.wrf import WrfWindow, _open, read_wrf_header

__all__ = ["LandMask", "land_mask", "wrf_land_mask"]


@dataclass(frozen=True, eq=False)
class LandMask:
    """Land cells of a wind grid.

    Attributes
    ----------
    source : str
        What the mask is, for legends (``"WRF land mask of f.nc (1.0 km cells)"``).
    x, y : ndarray, shape (ny, nx)
        Cell centres in the course frame [m].
    land : ndarray of bool, shape (ny, nx)
        True where the cell is land.
    """

    source: str
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    land: NDArray[np.bool_]

    @property
    def spacing_m(self) -> float:
        """Median distance between neighbouring cell centres along a row [m]."""
        d = np.hypot(np.diff(self.x, axis=1), np.diff(self.y, axis=1))
        return float(np.median(d)) if d.size else 0.0


def wrf_land_mask(path: str | Path, frame: LocalFrame) -> LandMask | None:
    """The ``LANDMASK`` (1 land) or else ``XLAND`` (1 land, 2 water) of a wrfout file at
    its first time, over the whole grid, in ``frame``; None when it has neither."""
    header = read_wrf_header(path)
    ds = _open(path)
    try:
        name = next((v for v in ("LANDMASK", "XLAND") if v in ds.variables), None)
        if name is None:
            return None
        var = ds.variables[name]
        a: NDArray[np.float64] = np.ma.filled(
            np.ma.asarray(var[0] if var.ndim == 3 else var[:], dtype=float), 0.0
        )
    finally:
        ds.close()
    if a.shape != header.lat.shape:
        return None
    land = (a > 0.5) & (a < 1.5) if name == "XLAND" else a > 0.5
    x, y = frame.to_xy(header.lat, header.lon)
    mask = LandMask("", np.asarray(x, float), np.asarray(y, float), np.asarray(land, bool))
    what = f"WRF {name} of {Path(header.path).name} ({mask.spacing_m / 1000:.1f} km cells)"
    return LandMask(what, mask.x, mask.y, mask.land)


def land_mask(wind: Any) -> LandMask | None:
    """The land cells a wind field knows of, or None.

    A :class:`~sailroute.wind.grid.GridWind` read from a WRF file gives the file's mask
    (:func:`wrf_land_mask`); another gridded wind its cells whose wind is NaN at every
    time.  A field that wraps another (``base``: a perturbed or blended wind) gives its
    base's.
    """
    for _ in range(8):  # wrappers round a gridded wind
        if isinstance(wind, GridWind):
            if isinstance(wind.info.get("window"), WrfWindow) and wind.frame is not None:
                return wrf_land_mask(wind.info["path"], wind.frame)
            nan = np.isnan(np.asarray(wind.u, dtype=float)).all(axis=0)
            if not nan.any():
                return None
            x, y = np.asarray(wind.x, float), np.asarray(wind.y, float)
            mask = LandMask("", x, y, nan)
            return LandMask(
                f"land cells (no wind) of {wind.name} ({mask.spacing_m / 1000:.1f} km cells)",
                x,
                y,
                nan,
            )
        wind = getattr(wind, "base", None)
        if wind is None:
            return None
    return None
