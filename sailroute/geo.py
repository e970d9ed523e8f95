"""The local metric frame: metres east (x) and north (y) of an origin.

A race course is a few km across, so an azimuthal-equidistant projection
centred on the course is accurate to far below GPS error and has no UTM-zone
seams (the thesis's WRF domain straddled zones 31 and 32).  All routing happens
in this frame; lat/lon appear only at the edges (files, GPX output).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pyproj import Transformer

from sailroute.errors import InputError
from sailroute.units import wrap360

WGS84_LONLAT = "+proj=longlat +datum=WGS84 +no_defs"
"""Longitude and latitude [°] on WGS-84: EPSG:4326 with its axes in x, y order, given as a
PROJ string, which PROJ builds without a look-up in its database (``Transformer.from_crs``
from ``"EPSG:4326"`` took 15 ms of CPU at every start of a command, against about 1 ms)."""


@lru_cache(maxsize=32)
def _transformers(lat0: float, lon0: float) -> tuple[Transformer, Transformer]:
    """WGS-84 longitude/latitude [°] to the frame [m] and back: the same PROJ pipelines as
    from EPSG:4326 with ``always_xy`` (same bits, ``tests/unit/test_units_geo_time.py``)."""
    proj = f"+proj=aeqd +lat_0={lat0!r} +lon_0={lon0!r} +datum=WGS84 +units=m +no_defs"
    fwd = Transformer.from_crs(WGS84_LONLAT, proj, always_xy=True)
    inv = Transformer.from_crs(proj, WGS84_LONLAT, always_xy=True)
    return fwd, inv


def wrap_lon(lon_deg: ArrayLike) -> NDArray[np.float64] | float:
    """Longitude [°] wrapped to ``[-180, 180)`` (GPX's range); 288.67 -> -71.33."""
    w = wrap360(np.asarray(lon_deg, dtype=float) + 180.0) - 180.0
    return float(w) if w.ndim == 0 else w


@dataclass(frozen=True)
class LocalFrame:
    """Azimuthal-equidistant local frame on WGS-84.

    Parameters
    ----------
    lat0, lon0 : float
        Origin [° north, ° east].  ``x`` is metres east and ``y`` metres north of it.
    """

    lat0: float
    lon0: float

    def __post_init__(self) -> None:
        if not (-90.0 <= self.lat0 <= 90.0) or not (-180.0 <= self.lon0 <= 360.0):
            raise InputError(
                f"origin lat={self.lat0}, lon={self.lon0} is not a valid position; "
                "expected lat in [-90, 90] and lon in [-180, 360] degrees"
            )

    def to_xy(self, lat: ArrayLike, lon: ArrayLike) -> tuple[NDArray, NDArray]:
        """Project geographic coordinates [°] to local ``(x, y)`` [m]."""
        fwd, _ = _transformers(float(self.lat0), float(self.lon0))
        x, y = fwd.transform(np.asarray(lon, dtype=float), np.asarray(lat, dtype=float))
        return np.asarray(x, dtype=float), np.asarray(y, dtype=float)

    def to_latlon(self, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Inverse of :meth:`to_xy`: local ``(x, y)`` [m] to ``(lat, lon)`` [°]."""
        _, inv = _transformers(float(self.lat0), float(self.lon0))
        lon, lat = inv.transform(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        return np.asarray(lat, dtype=float), np.asarray(wrap_lon(lon), dtype=float)

    def grid_north_deg(self, lat: ArrayLike, lon: ArrayLike) -> NDArray[np.float64]:
        """Angle [°] from local +y to true north at the given points (meridian convergence).

        A wind vector given in true east/north components must be rotated by this
        angle to be expressed in the local frame.  It is below 0.05° within
        5 km of the origin at mid latitudes, but exact handling keeps larger
        WRF crops honest.
        """
        lat = np.asarray(lat, dtype=float)
        lon = np.asarray(lon, dtype=float)
        d = 1e-4
        x0, y0 = self.to_xy(lat, lon)
        x1, y1 = self.to_xy(lat + d, lon)
        return np.degrees(np.arctan2(x1 - x0, y1 - y0))
