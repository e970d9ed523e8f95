"""Write synthetic files in genuine WRF ``wrfout`` layout (for tests and examples).

The wind is given as functions of time and position, evaluated where WRF
stores it: ``U10``/``V10`` at mass points, ``U`` on the west-east faces and
``V`` on the south-north faces (Arakawa C grid), all rotated to grid-relative
components with the grid's ``COSALPHA``/``SINALPHA``.  Heights are encoded in
``PH``/``PHB`` (geopotential of the full levels) and ``HGT``.  The grid is a
Lambert conformal projection on WRF's sphere (R = 6 370 000 m).

A file written here goes through the real reader (:func:`sailroute.wind.wrf.open_wrf`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from pyproj import Transformer

from sailroute.wind.height import G_WRF
from sailroute.wind.rotation import cone_factor, earth_to_grid, rotation_from_cone

WRF_EARTH_RADIUS_M = 6_370_000.0

WindFunc = Callable[[float, NDArray, NDArray], tuple[NDArray, NDArray]]
"""``f(t, lat, lon) -> (u_east, v_north)`` [m s⁻¹] at the 10 m level."""
LevelWindFunc = Callable[[float, NDArray, NDArray, float], tuple[NDArray, NDArray]]
"""``f(t, lat, lon, z) -> (u_east, v_north)`` [m s⁻¹] at height ``z`` [m]."""


@dataclass(frozen=True)
class LambertGrid:
    """A WRF Lambert-conformal mass grid centred on a point.

    Parameters
    ----------
    center_lat, center_lon : float
        Centre of the grid [°] (the middle cell centre when ``nx``/``ny`` are odd).
    nx, ny : int
        Mass points west-east and south-north.
    dx_m : float
        Grid spacing (``DX = DY``) [m].
    truelat1, truelat2, stand_lon : float
        Projection parameters [°].
    """

    center_lat: float
    center_lon: float
    nx: int
    ny: int
    dx_m: float
    truelat1: float
    truelat2: float
    stand_lon: float

    def _transformer(self) -> tuple[Transformer, Transformer]:
        proj = (
            f"+proj=lcc +lat_1={self.truelat1} +lat_2={self.truelat2} "
            f"+lat_0={self.center_lat} +lon_0={self.stand_lon} "
            f"+a={WRF_EARTH_RADIUS_M} +b={WRF_EARTH_RADIUS_M} +units=m +no_defs"
        )
        fwd = Transformer.from_crs(
            "+proj=longlat +a=6370000 +b=6370000 +no_defs", proj, always_xy=True
        )
        inv = Transformer.from_crs(
            proj, "+proj=longlat +a=6370000 +b=6370000 +no_defs", always_xy=True
        )
        return fwd, inv

    def latlon(self, i: NDArray | float, j: NDArray | float) -> tuple[NDArray, NDArray]:
        """Coordinates [°] of fractional mass-grid indices (faces at ``i ± 0.5``)."""
        fwd, inv = self._transformer()
        xc, yc = fwd.transform(self.center_lon, self.center_lat)
        px = xc + (np.asarray(i, dtype=float) - (self.nx - 1) / 2.0) * self.dx_m
        py = yc + (np.asarray(j, dtype=float) - (self.ny - 1) / 2.0) * self.dx_m
        lon, lat = inv.transform(px, py)
        return np.asarray(lat, dtype=float), np.asarray(lon, dtype=float)

    @property
    def cone(self) -> float:
        """Cone factor of the projection."""
        return cone_factor(1, self.truelat1, self.truelat2)

    def alpha(self, lat: NDArray, lon: NDArray) -> tuple[NDArray, NDArray]:
        """``COSALPHA``/``SINALPHA`` at the given points."""
        return rotation_from_cone(lat, lon, self.cone, self.stand_lon)

    def mass_latlon(self) -> tuple[NDArray, NDArray]:
        """``XLAT``/``XLONG`` of the mass points, shape (ny, nx)."""
        jj, ii = np.mgrid[0 : self.ny, 0 : self.nx]
        return self.latlon(ii, jj)


def full_levels_from_mass(z_mass: Sequence[float]) -> NDArray[np.float64]:
    """Full-level heights [m] (starting at 0) whose midpoints are ``z_mass``."""
    zw = [0.0]
    for z in z_mass:
        zw.append(2.0 * float(z) - zw[-1])
    out = np.asarray(zw)
    if np.any(np.diff(out) <= 0):
        raise ValueError(f"mass levels {list(z_mass)} do not give increasing full levels")
    return out


def write_wrfout(
    path: str | Path,
    grid: LambertGrid,
    times: Sequence[float],
    wind10: WindFunc,
    *,
    level_heights_m: Sequence[float] | None = None,
    wind_at: LevelWindFunc | None = None,
    title: str = "SYNTHETIC wrfout written by sailroute (not model output, not a forecast)",
    write_alpha: bool = True,
    extra_attrs: dict[str, object] | None = None,
    land: NDArray[np.bool_] | None = None,
) -> Path:
    """Write a small wrfout-layout NetCDF file.

    Parameters
    ----------
    path : str or Path
        Output file (overwritten).
    grid : LambertGrid
        The mass grid.
    times : sequence of float
        Slice times [epoch s], strictly increasing, written as UTC ``Times``.
    wind10 : callable
        ``f(t, lat, lon) -> (u_east, v_north)`` at 10 m [m s⁻¹].
    level_heights_m : sequence of float, optional
        Mass-level heights above the sea [m] of model levels to write (``U``, ``V``,
        ``PH``, ``PHB``); requires ``wind_at``.
    wind_at : callable, optional
        ``f(t, lat, lon, z) -> (u_east, v_north)`` [m s⁻¹].
    title : str
        Global ``TITLE`` attribute.
    write_alpha : bool
        Write ``COSALPHA``/``SINALPHA`` (False tests the cone-factor fallback).
    extra_attrs : dict, optional
        More global attributes.
    land : ndarray of bool, shape (ny, nx), optional
        Land cells: written as WRF's ``LANDMASK`` (1 land, 0 water) and ``XLAND`` (1
        land, 2 water) at every time.

    Returns
    -------
    Path
    """
    import netCDF4

    path = Path(path)
    t = np.asarray(times, dtype=float)
    nt, ny, nx = t.size, grid.ny, grid.nx
    lat, lon = grid.mass_latlon()
    ca, sa = grid.alpha(lat, lon)
    ju, iu = np.mgrid[0:ny, 0 : nx + 1]
    lat_u, lon_u = grid.latlon(iu - 0.5, ju)
    ca_u, sa_u = grid.alpha(lat_u, lon_u)
    jv, iv = np.mgrid[0 : ny + 1, 0:nx]
    lat_v, lon_v = grid.latlon(iv, jv - 0.5)
    ca_v, sa_v = grid.alpha(lat_v, lon_v)
    strings = [datetime.fromtimestamp(x, tz=UTC).strftime("%Y-%m-%d_%H:%M:%S") for x in t]

    with netCDF4.Dataset(str(path), "w", format="NETCDF4") as ds:
        ds.createDimension("Time", None)
        ds.createDimension("DateStrLen", 19)
        ds.createDimension("west_east", nx)
        ds.createDimension("south_north", ny)
        ds.createDimension("west_east_stag", nx + 1)
        ds.createDimension("south_north_stag", ny + 1)
        attrs: dict[str, object] = {
            "TITLE": title,
            "START_DATE": strings[0],
            "SIMULATION_START_DATE": strings[0],
            "WEST-EAST_GRID_DIMENSION": np.int32(nx + 1),
            "SOUTH-NORTH_GRID_DIMENSION": np.int32(ny + 1),
            "DX": np.float32(grid.dx_m),
            "DY": np.float32(grid.dx_m),
            "GRIDTYPE": "C",
            "CEN_LAT": np.float32(grid.center_lat),
            "CEN_LON": np.float32(grid.center_lon),
            "TRUELAT1": np.float32(grid.truelat1),
            "TRUELAT2": np.float32(grid.truelat2),
            "MOAD_CEN_LAT": np.float32(grid.center_lat),
            "STAND_LON": np.float32(grid.stand_lon),
            "POLE_LAT": np.float32(90.0),
            "POLE_LON": np.float32(0.0),
            "MAP_PROJ": np.int32(1),
            "MAP_PROJ_CHAR": "Lambert Conformal",
        }
        attrs.update(extra_attrs or {})
        ds.setncatts(attrs)

        def var(
            name: str, dims: tuple[str, ...], desc: str, units: str, stagger: str = ""
        ) -> netCDF4.Variable:
            v = ds.createVariable(name, "f4", dims, zlib=True, complevel=4)
            v.FieldType = np.int32(104)
            v.MemoryOrder = "XYZ" if len(dims) == 4 else "XY "
            v.description = desc
            v.units = units
            v.stagger = stagger
            return v

        tv = ds.createVariable("Times", "S1", ("Time", "DateStrLen"))
        tv[:] = np.array([list(s) for s in strings], dtype="S1")
        d3 = ("Time", "south_north", "west_east")
        var("XLAT", d3, "LATITUDE, SOUTH IS NEGATIVE", "degree_north")[:] = np.broadcast_to(
            lat, (nt, ny, nx)
        )
        var("XLONG", d3, "LONGITUDE, WEST IS NEGATIVE", "degree_east")[:] = np.broadcast_to(
            lon, (nt, ny, nx)
        )
        xt = ds.createVariable("XTIME", "f4", ("Time",))
        xt.units = f"minutes since {strings[0].replace('_', ' ')}"
        xt[:] = (t - t[0]) / 60.0
        if write_alpha:
            var("COSALPHA", d3, "Local cosine of map rotation", "")[:] = np.broadcast_to(
                ca, (nt, ny, nx)
            )
            var("SINALPHA", d3, "Local sine of map rotation", "")[:] = np.broadcast_to(
                sa, (nt, ny, nx)
            )
        var("HGT", d3, "Terrain Height", "m")[:] = np.zeros((nt, ny, nx))
        if land is not None:
            mask = np.broadcast_to(np.asarray(land, dtype=bool), (nt, ny, nx))
            var("LANDMASK", d3, "LAND MASK (1 FOR LAND, 0 FOR WATER)", "")[:] = mask
            var("XLAND", d3, "LAND MASK (1 FOR LAND, 2 FOR WATER)", "")[:] = np.where(mask, 1, 2)
        u10 = np.empty((nt, ny, nx))
        v10 = np.empty((nt, ny, nx))
        for k, tk in enumerate(t):
            ue, ve = wind10(float(tk), lat, lon)
            u10[k], v10[k] = earth_to_grid(ue, ve, ca, sa)
        var("U10", d3, "U at 10 M", "m s-1")[:] = u10
        var("V10", d3, "V at 10 M", "m s-1")[:] = v10
        if level_heights_m is not None:
            if wind_at is None:
                raise ValueError("level_heights_m needs wind_at")
            nz = len(level_heights_m)
            ds.createDimension("bottom_top", nz)
            ds.createDimension("bottom_top_stag", nz + 1)
            zw = full_levels_from_mass(level_heights_m)
            ph_full = G_WRF * zw[None, :, None, None] * np.ones((nt, 1, ny, nx))
            var(
                "PHB",
                ("Time", "bottom_top_stag", "south_north", "west_east"),
                "base-state geopotential",
                "m2 s-2",
                "Z",
            )[:] = 0.9 * ph_full
            var(
                "PH",
                ("Time", "bottom_top_stag", "south_north", "west_east"),
                "perturbation geopotential",
                "m2 s-2",
                "Z",
            )[:] = 0.1 * ph_full
            U = np.empty((nt, nz, ny, nx + 1))
            V = np.empty((nt, nz, ny + 1, nx))
            for k, tk in enumerate(t):
                for m, z in enumerate(level_heights_m):
                    ue, ve = wind_at(float(tk), lat_u, lon_u, float(z))
                    U[k, m] = earth_to_grid(ue, ve, ca_u, sa_u)[0]
                    ue, ve = wind_at(float(tk), lat_v, lon_v, float(z))
                    V[k, m] = earth_to_grid(ue, ve, ca_v, sa_v)[1]
            var(
                "U",
                ("Time", "bottom_top", "south_north", "west_east_stag"),
                "x-wind component",
                "m s-1",
                "X",
            )[:] = U
            var(
                "V",
                ("Time", "bottom_top", "south_north_stag", "west_east"),
                "y-wind component",
                "m s-1",
                "Y",
            )[:] = V
    return path
