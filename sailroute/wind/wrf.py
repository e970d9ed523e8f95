"""WRF ``wrfout`` NetCDF files as wind fields: read -> decode -> field.

1. :func:`read_wrf_header` reads ``Times``, ``XLAT``/``XLONG``, the global
   attributes and which variables exist (cheap).
2. :func:`crop_window` chooses the cells and slices that cover the course box
   plus a margin and the race time window (pure).
3. :func:`read_wrf` reads the raw arrays of that window (:class:`WrfRaw`):
   ``U10``/``V10``, ``COSALPHA``/``SINALPHA`` and, for a height correction
   from model levels, the two lowest ``U``/``V`` levels, ``PH``/``PHB``, ``HGT``.
4. :func:`decode_wrf` turns them into earth-relative, then local-frame winds at
   the requested height (:class:`WrfDecoded`): times as UTC epoch seconds,
   destaggering (thesis eqs 3.5/3.6), rotation with ``COSALPHA``/``SINALPHA``
   (or the projection's cone factor), height correction (power law with a
   per-point exponent fitted from two levels, or log law).
5. :func:`open_wrf` runs the chain and returns a :class:`~sailroute.wind.grid.GridWind`.

No projection is rebuilt from ``MAP_PROJ``: cell centres are placed in the local
frame from ``XLAT``/``XLONG`` with pyproj (no UTM zones, so no zone seam).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.errors import InputError, OutOfCoverageError, WindDataError
from sailroute.geo import LocalFrame
from sailroute.timeutil import iso
from sailroute.wind._xr import damaged_as_wind_error, is_xarray_dataset, open_dataset
from sailroute.wind.base import Coverage
from sailroute.wind.grid import GridWind
from sailroute.wind.height import (
    DEFAULT_EXPONENT,
    DEFAULT_EXPONENT_RANGE,
    DEFAULT_ROUGHNESS_M,
    MIN_FIT_SPEED_MS,
    destagger,
    fit_power_exponent,
    log_law_factor,
    mass_level_heights,
    power_law_factor,
)
from sailroute.wind.rotation import cone_factor, earth_to_local, grid_to_earth, rotation_from_cone

REQUIRED_VARIABLES = ("Times", "XLAT", "XLONG", "U10", "V10")
"""Variables without which a file is not a usable wrfout file."""

MODEL_LEVEL_VARIABLES = ("U", "V", "PH", "PHB", "HGT")
"""Variables needed for a height correction from the lowest model levels."""

PROJECTION_ATTRIBUTES = (
    "MAP_PROJ",
    "TRUELAT1",
    "TRUELAT2",
    "STAND_LON",
    "DX",
    "DY",
    "POLE_LAT",
    "POLE_LON",
    "CEN_LAT",
    "CEN_LON",
    "TITLE",
)

SPEED_UNITS_MS = frozenset(
    {
        "m s-1",
        "m/s",
        "m s**-1",
        "ms-1",
        "m.s-1",
        "m s^-1",
        "m sec-1",
        "meter second-1",
        "meters/second",
        "m s{-1}",
    }
)

U10_HEIGHT_M = 10.0
"""Height of WRF's diagnostic ``U10``/``V10`` [m]."""

N_MODEL_LEVELS = 2
"""Lowest model levels used for the shear-exponent fit (thesis: ~7.5 m and ~25 m)."""


# ----------------------------------------------------------------------------- header
@dataclass(frozen=True)
class WrfHeader:
    """What :func:`read_wrf_header` learns about a file without reading wind arrays.

    Attributes
    ----------
    path : str
        The file.
    times : ndarray, shape (nt,)
        Slice times [epoch s] (UTC), strictly increasing.
    lat, lon : ndarray, shape (ny, nx)
        Mass-point coordinates [°] (first time of 3-D ``XLAT``/``XLONG``).
    attrs : mapping
        Projection-related global attributes that are present.
    variables : frozenset of str
        Variable names in the file.
    """

    path: str
    times: NDArray[np.float64]
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    attrs: Mapping[str, Any]
    variables: frozenset[str]

    @property
    def shape(self) -> tuple[int, int, int]:
        """``(nt, ny, nx)``."""
        return (self.times.size, *self.lat.shape)


def _open(path: str | Path | Any) -> Any:
    return open_dataset(path, "WRF", "a WRF wrfout NetCDF file")[0]


def source_name(path: Any) -> str:
    """File name of a path, or ``"xarray.Dataset"`` for a dataset (for messages)."""
    return "xarray.Dataset" if is_xarray_dataset(path) else str(path)


def parse_wrf_times(chars: NDArray, *, path: str = "WRF file") -> NDArray[np.float64]:
    """Decode WRF ``Times`` (char array ``YYYY-MM-DD_HH:MM:SS``, UTC) to epoch seconds.

    Parameters
    ----------
    chars : ndarray, shape (nt, 19)
        Bytes as stored in the file (or an array of strings).
    path : str
        File name for error messages.

    Returns
    -------
    ndarray, shape (nt,)
        Epoch seconds [s], checked to be strictly increasing.

    Raises
    ------
    WindDataError
        Unreadable strings or times that do not increase.
    """
    a = np.asarray(chars)
    if a.ndim == 2:
        strings = [
            b"".join(row.tolist()).decode("ascii", "replace")
            if a.dtype.kind == "S"
            else "".join(row.tolist())
            for row in a
        ]
    else:
        strings = [
            s.decode("ascii", "replace") if isinstance(s, bytes) else str(s) for s in a.ravel()
        ]
    out = np.empty(len(strings))
    for k, s in enumerate(strings):
        s = s.strip().strip("\x00")
        try:
            dt = datetime.strptime(s, "%Y-%m-%d_%H:%M:%S").replace(tzinfo=UTC)
        except ValueError:
            raise WindDataError(
                f"{path}: Times[{k}] = {s!r} is not a WRF time; expected "
                "'YYYY-MM-DD_HH:MM:SS' (UTC)"
            ) from None
        out[k] = dt.timestamp()
    if out.size == 0:
        raise WindDataError(f"{path}: Times is empty; the file holds no time slices")
    bad = np.nonzero(np.diff(out) <= 0)[0]
    if bad.size:
        k = int(bad[0])
        raise WindDataError(
            f"{path}: Times must increase strictly, but Times[{k}] = {strings[k].strip()} "
            f"and Times[{k + 1}] = {strings[k + 1].strip()}; remove duplicated or "
            "out-of-order slices (e.g. when files were concatenated)"
        )
    return out


@damaged_as_wind_error
def read_wrf_header(path: str | Path) -> WrfHeader:
    """Read times, coordinates and attributes of a wrfout file.

    Parameters
    ----------
    path : str, Path or xarray.Dataset
        The NetCDF file, or the same data opened with xarray.

    Returns
    -------
    WrfHeader

    Raises
    ------
    WindDataError
        Not NetCDF, not a wrfout file (names the missing variables and what was
        found), unreadable times, NaN coordinates.
    """
    name = source_name(path)
    with _open(path) as ds:
        names = frozenset(ds.variables)
        missing = [v for v in REQUIRED_VARIABLES if v not in names]
        if missing:
            found = ", ".join(sorted(names)[:15]) + (" ..." if len(names) > 15 else "")
            raise WindDataError(
                f"{name}: not a WRF wrfout file: missing variable(s) {', '.join(missing)} "
                f"(found: {found or 'none'}); expected {', '.join(REQUIRED_VARIABLES)} as "
                "written by WRF. For winds on latitude/longitude (regridded WRF, ERA5, ICON, "
                "CF NetCDF) use `type: netcdf` (Python: sailroute.wind.open_netcdf)."
            )
        times = parse_wrf_times(ds.variables["Times"][:], path=name)
        lat = _coords(ds, "XLAT", name)
        lon = _coords(ds, "XLONG", name)
        if lat.shape != lon.shape:
            raise WindDataError(f"{name}: XLAT {lat.shape} and XLONG {lon.shape} differ in shape")
        attrs = {k: ds.getncattr(k) for k in PROJECTION_ATTRIBUTES if k in ds.ncattrs()}
    return WrfHeader(name, times, lat, lon, attrs, names)


def _coords(ds: Any, var: str, name: str) -> NDArray[np.float64]:
    v = ds.variables[var]
    if v.ndim == 3:
        a = v[0]
    elif v.ndim == 2:
        a = v[:]
    else:
        raise WindDataError(
            f"{name}: {var} has dimensions {v.dimensions}; expected (Time, south_north, "
            "west_east) or (south_north, west_east)"
        )
    a = np.ma.filled(np.ma.asarray(a, dtype=float), np.nan)
    if not np.all(np.isfinite(a)):
        raise WindDataError(
            f"{name}: {var} contains missing or NaN values; expected a complete coordinate grid"
        )
    return a


# ----------------------------------------------------------------------------- window
@dataclass(frozen=True)
class WrfWindow:
    """Index window to read: rows ``j0:j1``, columns ``i0:i1``, slices ``k0:k1`` (end excluded)."""

    j0: int
    j1: int
    i0: int
    i1: int
    k0: int
    k1: int


def crop_window(
    header: WrfHeader,
    frame: LocalFrame,
    *,
    bbox: tuple[float, float, float, float] | None = None,
    margin_m: float | None = None,
    time_window: tuple[float, float] | None = None,
    time_pad_s: float = 0.0,
) -> WrfWindow:
    """Cells and slices that cover ``bbox`` plus ``margin_m`` and ``time_window``.

    Parameters
    ----------
    header : WrfHeader
        From :func:`read_wrf_header`.
    frame : LocalFrame
        The course's local frame.
    bbox : tuple of float, optional
        ``(xmin, xmax, ymin, ymax)`` [m] in ``frame``; ``None`` keeps the whole grid.
    margin_m : float, optional
        Added on every side of ``bbox`` [m]; default three grid spacings.
    time_window : tuple of float, optional
        ``(t0, t1)`` [epoch s]; keeps the slices from the last one at or before
        ``t0 - time_pad_s`` to the first at or after ``t1``.
    time_pad_s : float
        Extra time kept before ``t0`` [s] (frozen sampling needs the block start).

    Returns
    -------
    WrfWindow
        One more ring of cells than strictly needed is kept, clipped to the grid.

    Raises
    ------
    WindDataError
        If the grid has fewer than 2 points along either axis.
    OutOfCoverageError
        If no cell centre lies within the box plus margin.
    """
    nt, ny, nx = header.shape
    if ny < 2 or nx < 2:
        raise WindDataError(
            f"{header.path}: the wind grid has {ny} x {nx} points (rows x columns); a gridded "
            "wind field needs at least 2 x 2 to interpolate between them"
            + (
                "; for one point (a station, a buoy) use `type: stations`, for a steady wind "
                "`type: uniform`"
                if ny * nx == 1
                else ""
            )
        )
    j0, j1, i0, i1 = 0, ny, 0, nx
    if bbox is not None:
        dx = float(header.attrs.get("DX", 0.0)) or _spacing(header, frame)
        m = 3.0 * dx if margin_m is None else float(margin_m)
        x, y = frame.to_xy(header.lat, header.lon)
        xmin, xmax, ymin, ymax = bbox
        inside = (x >= xmin - m) & (x <= xmax + m) & (y >= ymin - m) & (y <= ymax + m)
        if not inside.any():
            course = Coverage(0.0, 0.0, xmin, xmax, ymin, ymax, frame=frame).latlon_box()
            assert course is not None
            lon = np.asarray(header.lon, dtype=float)
            raise OutOfCoverageError(
                f"{header.path}: the grid does not contain the course.\n"
                f"  course box: lat {course[0]:.4f} .. {course[1]:.4f}, lon {course[2]:.4f} .. "
                f"{course[3]:.4f} (x {xmin:.0f} .. {xmax:.0f} m, y {ymin:.0f} .. {ymax:.0f} m, "
                f"plus margin {m:.0f} m)\n"
                f"  grid:       lat {float(np.min(header.lat)):.4f} .. "
                f"{float(np.max(header.lat)):.4f}, lon {float(lon.min()):.4f} .. "
                f"{float(lon.max()):.4f}; time {iso(header.times[0])} .. "
                f"{iso(header.times[-1])}\n"
                "  Check the course origin/marks and that the file is for this venue."
            )
        rows = np.nonzero(inside.any(axis=1))[0]
        cols = np.nonzero(inside.any(axis=0))[0]
        j0, j1 = max(int(rows[0]) - 1, 0), min(int(rows[-1]) + 2, ny)
        i0, i1 = max(int(cols[0]) - 1, 0), min(int(cols[-1]) + 2, nx)
        if j1 - j0 < 2:
            j0, j1 = max(0, min(j0, ny - 2)), max(0, min(j0, ny - 2)) + 2
        if i1 - i0 < 2:
            i0, i1 = max(0, min(i0, nx - 2)), max(0, min(i0, nx - 2)) + 2
    k0, k1 = 0, nt
    if time_window is not None:
        t = header.times
        t0, t1 = time_window
        k0 = max(int(np.searchsorted(t, t0 - time_pad_s, side="right")) - 1, 0)
        k1 = min(int(np.searchsorted(t, t1, side="left")) + 1, nt)
        if k1 <= k0:
            k0, k1 = (nt - 1, nt) if t0 > t[-1] else (0, 1)
    return WrfWindow(j0, j1, i0, i1, k0, k1)


def _spacing(header: WrfHeader, frame: LocalFrame) -> float:
    x, y = frame.to_xy(header.lat, header.lon)
    return float(np.median(np.hypot(np.diff(x, axis=1), np.diff(y, axis=1))))


# ----------------------------------------------------------------------------- raw read
@dataclass(frozen=True)
class WrfRaw:
    """Raw arrays of one window, float64, as stored (grid-relative winds).

    Attributes
    ----------
    header : WrfHeader
        Whole-file header.
    window : WrfWindow
        What was read.
    times : ndarray (nt,)
        Epoch seconds [s] of the window's slices.
    lat, lon : ndarray (ny, nx)
        Cell centres [°].
    u10, v10 : ndarray (nt, ny, nx)
        Grid-relative 10 m wind [m s⁻¹].
    cosalpha, sinalpha : ndarray (ny, nx) or None
        Grid rotation, when present in the file.
    u, v : ndarray or None
        Lowest model levels, staggered: ``(nt, 2, ny, nx + 1)`` and ``(nt, 2, ny + 1, nx)``.
    ph, phb : ndarray (nt, 3, ny, nx) or None
        Geopotential on the lowest full levels [m² s⁻²].
    hgt : ndarray (ny, nx) or None
        Terrain height [m].
    """

    header: WrfHeader
    window: WrfWindow
    times: NDArray[np.float64]
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    u10: NDArray[np.float64]
    v10: NDArray[np.float64]
    cosalpha: NDArray[np.float64] | None = None
    sinalpha: NDArray[np.float64] | None = None
    u: NDArray[np.float64] | None = None
    v: NDArray[np.float64] | None = None
    ph: NDArray[np.float64] | None = None
    phb: NDArray[np.float64] | None = None
    hgt: NDArray[np.float64] | None = None


def read_wrf(
    path: str | Path,
    window: WrfWindow | None = None,
    *,
    model_levels: bool = False,
    header: WrfHeader | None = None,
) -> WrfRaw:
    """Read the raw arrays of a window of a wrfout file.

    Parameters
    ----------
    path : str or Path
        The file.
    window : WrfWindow, optional
        Cells and slices; default everything.
    model_levels : bool
        Also read the two lowest ``U``/``V`` levels, ``PH``/``PHB`` and ``HGT``.
    header : WrfHeader, optional
        Reuse an already read header.

    Returns
    -------
    WrfRaw

    Raises
    ------
    WindDataError
        Missing variables (named), wrong shapes or units, NaN/missing values.
    """
    hdr = header if header is not None else read_wrf_header(path)
    nt, ny, nx = hdr.shape
    w = window if window is not None else WrfWindow(0, ny, 0, nx, 0, nt)
    name = hdr.path
    with _open(path) as ds:
        if model_levels:
            missing = [v for v in MODEL_LEVEL_VARIABLES if v not in ds.variables]
            if missing:
                raise WindDataError(
                    f"{name}: a height correction from model levels needs "
                    f"{', '.join(MODEL_LEVEL_VARIABLES)}, but {', '.join(missing)} "
                    "is/are missing; use `levels: u10` (10 m wind with the fallback exponent)"
                )
        tsl = slice(w.k0, w.k1)
        js, is_ = slice(w.j0, w.j1), slice(w.i0, w.i1)
        u10 = _read(ds, "U10", name, (nt, ny, nx), (tsl, js, is_), speed=True)
        v10 = _read(ds, "V10", name, (nt, ny, nx), (tsl, js, is_), speed=True)
        ca = sa = None
        if "COSALPHA" in ds.variables and "SINALPHA" in ds.variables:
            ca = _read_2d(ds, "COSALPHA", name, (ny, nx), (js, is_))
            sa = _read_2d(ds, "SINALPHA", name, (ny, nx), (js, is_))
        u = v = ph = phb = hgt = None
        if model_levels:
            nz = ds.variables["U"].shape[1] if ds.variables["U"].ndim == 4 else 0
            if nz < N_MODEL_LEVELS:
                raise WindDataError(
                    f"{name}: U needs at least {N_MODEL_LEVELS} vertical levels "
                    f"with dimensions (Time, bottom_top, south_north, "
                    f"west_east_stag); got shape {ds.variables['U'].shape}"
                )
            lev = slice(0, N_MODEL_LEVELS)
            u = _read(
                ds,
                "U",
                name,
                (nt, nz, ny, nx + 1),
                (tsl, lev, js, slice(w.i0, w.i1 + 1)),
                speed=True,
            )
            v = _read(
                ds,
                "V",
                name,
                (nt, nz, ny + 1, nx),
                (tsl, lev, slice(w.j0, w.j1 + 1), is_),
                speed=True,
            )
            levw = slice(0, N_MODEL_LEVELS + 1)
            ph = _read(ds, "PH", name, (nt, nz + 1, ny, nx), (tsl, levw, js, is_))
            phb = _read(ds, "PHB", name, (nt, nz + 1, ny, nx), (tsl, levw, js, is_))
            hgt = _read_2d(ds, "HGT", name, (ny, nx), (js, is_))
    return WrfRaw(
        hdr,
        w,
        hdr.times[w.k0 : w.k1],
        hdr.lat[w.j0 : w.j1, w.i0 : w.i1],
        hdr.lon[w.j0 : w.j1, w.i0 : w.i1],
        u10,
        v10,
        ca,
        sa,
        u,
        v,
        ph,
        phb,
        hgt,
    )


def _check_units(var: Any, vname: str, name: str) -> None:
    units = getattr(var, "units", None)
    if units is None:
        return
    if str(units).strip() not in SPEED_UNITS_MS:
        raise WindDataError(
            f"{name}: variable {vname} has units {units!r}; expected metres per second "
            "('m s-1' as WRF writes it). Convert the file to m/s or fix the units attribute."
        )


def _read(
    ds: Any,
    vname: str,
    name: str,
    shape: tuple[int, ...],
    index: tuple[slice, ...],
    *,
    speed: bool = False,
) -> NDArray[np.float64]:
    var = ds.variables[vname]
    if tuple(var.shape) != tuple(shape):
        raise WindDataError(
            f"{name}: {vname} has shape {var.shape} {var.dimensions}; expected {shape} "
            "to match Times and XLAT/XLONG"
        )
    if speed:
        _check_units(var, vname, name)
    a: NDArray[np.float64] = np.ma.filled(np.ma.asarray(var[index], dtype=float), np.nan)
    _check_finite(a, vname, name, index)
    return a


def _read_2d(
    ds: Any, vname: str, name: str, shape: tuple[int, int], index: tuple[slice, slice]
) -> NDArray[np.float64]:
    var = ds.variables[vname]
    if tuple(var.shape[-2:]) != shape or var.ndim not in (2, 3):
        raise WindDataError(
            f"{name}: {vname} has shape {var.shape}; expected {shape} or "
            f"(Time, {shape[0]}, {shape[1]})"
        )
    a = var[(0, *index)] if var.ndim == 3 else var[index]
    a = np.ma.filled(np.ma.asarray(a, dtype=float), np.nan)
    _check_finite(a, vname, name, index)
    return a


def _check_finite(a: NDArray, vname: str, name: str, index: tuple[slice, ...]) -> None:
    bad = ~np.isfinite(a)
    if bad.any():
        first = np.argwhere(bad)[0]
        pos = ", ".join(str(int(f) + (s.start or 0)) for f, s in zip(first, index, strict=False))
        raise WindDataError(
            f"{name}: {vname} has {int(bad.sum())} missing or NaN values in the region read "
            f"(first at index [{pos}]); wind fields must be complete over the course. "
            "Crop the course away from masked cells or fill the gaps."
        )


# ----------------------------------------------------------------------------- decode
@dataclass(frozen=True)
class WrfDecoded:
    """Decoded WRF wind in the local frame.

    Attributes
    ----------
    times : ndarray (nt,)
        Epoch seconds [s] (UTC).
    lat, lon, x, y : ndarray (ny, nx)
        Cell centres [°] and their local coordinates [m].
    u, v : ndarray (nt, ny, nx)
        Wind at ``height_m`` in local-frame components [m s⁻¹].
    height_m : float
        Height the winds refer to [m] (10 when uncorrected).
    levels : str
        ``"u10"`` or ``"model"``: which WRF winds were used.
    exponent : ndarray (nt, ny, nx) or None
        Power-law exponent applied per point (None for no correction or the log law).
    fallback_fraction : float
        Share of points where the fitted exponent was unusable and the fallback was used.
    rotation : str
        ``"cosalpha"`` (from the file) or ``"cone"`` (from MAP_PROJ) or ``"none"``.
    u_earth, v_earth : ndarray (nt, ny, nx)
        The same wind in true east/north components [m s⁻¹] (before the
        local-frame rotation).
    """

    times: NDArray[np.float64]
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    u: NDArray[np.float64]
    v: NDArray[np.float64]
    height_m: float
    levels: str
    exponent: NDArray[np.float64] | None
    fallback_fraction: float
    rotation: str
    u_earth: NDArray[np.float64]
    v_earth: NDArray[np.float64]


def wrf_rotation(raw: WrfRaw) -> tuple[NDArray, NDArray, str]:
    """``(cosalpha, sinalpha, source)`` for the window: from the file, else from the cone factor.

    Raises
    ------
    WindDataError
        Neither COSALPHA/SINALPHA nor the projection attributes are present.
    """
    if raw.cosalpha is not None and raw.sinalpha is not None:
        return raw.cosalpha, raw.sinalpha, "cosalpha"
    a = raw.header.attrs
    if "MAP_PROJ" not in a:
        raise WindDataError(
            f"{raw.header.path}: cannot rotate grid-relative winds to earth-relative: neither "
            "COSALPHA/SINALPHA nor the MAP_PROJ attribute is present. Add them (as WRF writes "
            "them) or convert the winds to earth-relative first."
        )
    proj = int(a["MAP_PROJ"])
    if proj == 6 and (
        float(a.get("POLE_LAT", 90.0)) != 90.0 or float(a.get("POLE_LON", 0.0)) != 0.0
    ):
        raise WindDataError(
            f"{raw.header.path}: rotated-pole lat-lon grid (MAP_PROJ 6, POLE_LAT "
            f"{a.get('POLE_LAT')}) without COSALPHA/SINALPHA; the rotation is unknown"
        )
    if proj in (1, 2):
        need = ["TRUELAT1", "STAND_LON"] + (["TRUELAT2"] if proj == 1 else [])
        miss = [k for k in need if k not in a]
        if miss:
            raise WindDataError(
                f"{raw.header.path}: MAP_PROJ {proj} needs global attribute(s) "
                f"{', '.join(miss)} to rotate the winds"
            )
    cone = cone_factor(proj, float(a.get("TRUELAT1", 0.0)), float(a.get("TRUELAT2", 0.0)))
    if cone == 0.0:
        one = np.ones_like(raw.lat)
        return one, np.zeros_like(raw.lat), "none"
    ca, sa = rotation_from_cone(raw.lat, raw.lon, cone, float(a["STAND_LON"]))
    return ca, sa, "cone"


def decode_wrf(
    raw: WrfRaw,
    frame: LocalFrame,
    *,
    height_m: float | None = None,
    levels: str = "auto",
    shear: str = "power",
    fallback_exponent: float = DEFAULT_EXPONENT,
    exponent_range: tuple[float, float] = DEFAULT_EXPONENT_RANGE,
    roughness_m: float = DEFAULT_ROUGHNESS_M,
    min_fit_speed_ms: float = MIN_FIT_SPEED_MS,
) -> WrfDecoded:
    """Earth-relative, height-corrected, local-frame winds from raw WRF arrays.

    Parameters
    ----------
    raw : WrfRaw
        From :func:`read_wrf` (with ``model_levels=True`` for ``levels="model"``).
    frame : LocalFrame
        Target frame.
    height_m : float, optional
        Height the wind is wanted at [m] (Laser centre of effort: 2.68).  ``None``:
        no correction, the 10 m wind.
    levels : {"auto", "u10", "model"}
        ``model``: fit a power-law exponent per point from the two lowest model
        levels and scale the lowest level's wind to ``height_m``; where the fit is
        unusable use ``U10/V10`` with ``fallback_exponent``.  ``u10``: scale
        ``U10/V10`` with ``fallback_exponent`` (or the log law).  ``auto``: ``model``
        when the arrays were read, else ``u10``.
    shear : {"power", "log"}
        Profile law.  ``log`` uses the fixed ``roughness_m`` and the lowest model
        level (``model``) or 10 m (``u10``) as reference.
    fallback_exponent : float
        Power-law exponent where no fit is used or usable [-] (default 1/7).
    exponent_range : (float, float)
        Accepted fitted exponents [-] (default 0 .. 0.6).
    roughness_m : float
        Log-law roughness length [m].
    min_fit_speed_ms : float
        Minimum speed at both levels for a usable fit [m s⁻¹].

    Returns
    -------
    WrfDecoded
    """
    if levels not in ("auto", "u10", "model"):
        raise InputError(f"levels {levels!r}; expected 'auto', 'u10' or 'model'")
    if shear not in ("power", "log"):
        raise InputError(f"shear {shear!r}; expected 'power' or 'log'")
    have_model = raw.u is not None
    use = ("model" if have_model else "u10") if levels == "auto" else levels
    if use == "model" and not have_model:
        raise InputError("levels 'model' needs the model-level arrays: read_wrf(model_levels=True)")
    ca, sa, how = wrf_rotation(raw)
    ue, ve = grid_to_earth(raw.u10, raw.v10, ca, sa)
    exponent = None
    fallback_fraction = 0.0
    z_out = U10_HEIGHT_M
    if height_m is not None:
        z_out = float(height_m)
        if use == "u10":
            f = (
                power_law_factor(U10_HEIGHT_M, z_out, fallback_exponent)
                if shear == "power"
                else log_law_factor(U10_HEIGHT_M, z_out, roughness_m)
            )
            ue, ve = ue * f, ve * f
            if shear == "power":
                exponent = np.full(ue.shape, float(fallback_exponent))
                fallback_fraction = 1.0
        else:
            ue, ve, exponent, fallback_fraction = _from_model_levels(
                raw,
                ca,
                sa,
                ue,
                ve,
                z_out,
                shear,
                fallback_exponent,
                exponent_range,
                roughness_m,
                min_fit_speed_ms,
            )
    x, y = frame.to_xy(raw.lat, raw.lon)
    gn = frame.grid_north_deg(raw.lat, raw.lon)
    ul, vl = earth_to_local(ue, ve, gn)
    return WrfDecoded(
        raw.times,
        raw.lat,
        raw.lon,
        x,
        y,
        ul,
        vl,
        z_out,
        use,
        exponent,
        fallback_fraction,
        how,
        ue,
        ve,
    )


def _from_model_levels(
    raw: WrfRaw,
    ca: NDArray,
    sa: NDArray,
    ue10: NDArray,
    ve10: NDArray,
    z_out: float,
    shear: str,
    fallback: float,
    exponent_range: tuple[float, float],
    roughness_m: float,
    min_speed: float,
) -> tuple[NDArray, NDArray, NDArray | None, float]:
    name = raw.header.path
    if raw.u is None or raw.v is None or raw.ph is None or raw.phb is None or raw.hgt is None:
        raise InputError("levels 'model' needs the model-level arrays: read_wrf(model_levels=True)")
    um = destagger(raw.u, axis=-1)  # (nt, 2, ny, nx)
    vm = destagger(raw.v, axis=-2)
    z = mass_level_heights(raw.ph, raw.phb, raw.hgt)  # (nt, 2, ny, nx)
    z1, z2 = z[:, 0], z[:, 1]
    if np.any(z1 <= 0) or np.any(z2 <= z1):
        raise WindDataError(
            f"{name}: model-level heights from PH/PHB/HGT are not increasing above ground "
            f"(lowest level {float(np.min(z1)):.2f} m, second {float(np.min(z2)):.2f} m); "
            "check PH, PHB and HGT"
        )
    ue1, ve1 = grid_to_earth(um[:, 0], vm[:, 0], ca, sa)
    s1 = np.hypot(um[:, 0], vm[:, 0])
    s2 = np.hypot(um[:, 1], vm[:, 1])
    if shear == "log":
        f = log_law_factor(z1, z_out, roughness_m)
        return ue1 * f, ve1 * f, None, 0.0
    alpha, usable = fit_power_exponent(
        s1, z1, s2, z2, exponent_range=exponent_range, min_speed_ms=min_speed
    )
    f_fit = power_law_factor(z1, z_out, np.where(usable, alpha, 0.0))
    f_fb = power_law_factor(U10_HEIGHT_M, z_out, fallback)
    ue = np.where(usable, ue1 * f_fit, ue10 * f_fb)
    ve = np.where(usable, ve1 * f_fit, ve10 * f_fb)
    exponent = np.where(usable, alpha, fallback)
    return ue, ve, exponent, float(1.0 - usable.mean())


# ----------------------------------------------------------------------------- field
@damaged_as_wind_error
def open_wrf(
    path: str | Path,
    frame: LocalFrame,
    *,
    bbox: tuple[float, float, float, float] | None = None,
    margin_m: float | None = None,
    time_window: tuple[float, float] | None = None,
    height_m: float | None = None,
    levels: str = "auto",
    shear: str = "power",
    fallback_exponent: float = DEFAULT_EXPONENT,
    exponent_range: tuple[float, float] = DEFAULT_EXPONENT_RANGE,
    roughness_m: float = DEFAULT_ROUGHNESS_M,
    time_step_min: float | None = None,
    interpolation: str = "linear",
    clamp: bool = False,
) -> GridWind:
    """Open a wrfout file as a wind field in ``frame``.

    Parameters
    ----------
    path : str, Path or xarray.Dataset
        The wrfout NetCDF file (or the same data opened with xarray).
    frame : LocalFrame
        The course's local frame.
    bbox : tuple of float, optional
        Course box ``(xmin, xmax, ymin, ymax)`` [m]; the grid is cropped to it plus
        ``margin_m`` (default three grid spacings).  ``None`` keeps the whole grid.
    margin_m : float, optional
        Crop margin [m].
    time_window : tuple of float, optional
        ``(t0, t1)`` [epoch s]; only the slices bracketing it are read.
    height_m : float, optional
        Height the wind is wanted at [m] (Laser centre of effort: 2.68); ``None``:
        the 10 m wind, uncorrected.  Height correction: :func:`decode_wrf`.
    levels : {"auto", "u10", "model"}
        ``auto``: the model levels when ``height_m`` is set and the file has them,
        else ``U10/V10`` (see :func:`decode_wrf`).
    shear : {"power", "log"}
        Profile law of the height correction.
    fallback_exponent : float
        Power-law exponent where no fit is used or usable [-] (default 1/7).
    exponent_range : (float, float)
        Accepted fitted exponents [-] (default 0 .. 0.6).
    roughness_m : float
        Log-law roughness length [m].
    time_step_min : float, optional
        Freeze the wind per block of this many minutes (thesis: 60, 30, 10).
    interpolation : {"linear", "nearest"}
        Spatial interpolation (thesis: nearest).
    clamp : bool
        Clamp sample points to the coverage instead of raising.

    Returns
    -------
    GridWind
        ``info`` holds ``path``, ``levels``, ``height_m``, ``rotation``,
        ``fallback_fraction``, ``window`` and ``map_degree``/``map_residual_cells``.
    """
    header = read_wrf_header(path)
    step_s = None if time_step_min is None else float(time_step_min) * 60.0
    window = crop_window(
        header,
        frame,
        bbox=bbox,
        margin_m=margin_m,
        time_window=time_window,
        time_pad_s=step_s or 0.0,
    )
    want_model = height_m is not None and (
        levels == "model"
        or (levels == "auto" and all(v in header.variables for v in MODEL_LEVEL_VARIABLES))
    )
    raw = read_wrf(path, window, model_levels=want_model, header=header)
    dec = decode_wrf(
        raw,
        frame,
        height_m=height_m,
        levels=levels if want_model else "u10",
        shear=shear,
        fallback_exponent=fallback_exponent,
        exponent_range=exponent_range,
        roughness_m=roughness_m,
    )
    label = f"WRF wind {Path(header.path).name}"
    info: dict[str, Any] = {
        "path": header.path,
        "levels": dec.levels,
        "height_m": dec.height_m,
        "rotation": dec.rotation,
        "fallback_fraction": dec.fallback_fraction,
        "window": window,
        "times": f"{iso(dec.times[0])} .. {iso(dec.times[-1])} ({dec.times.size} slices)",
        "map_degree": None,  # filled in below, from the field's index map
        "map_residual_cells": None,
        "exponent_mean": None if dec.exponent is None else float(np.mean(dec.exponent)),
    }
    field = GridWind(
        dec.times,
        dec.x,
        dec.y,
        dec.u,
        dec.v,
        interpolation=interpolation,
        time_step_s=step_s,
        clamp=clamp,
        name=label,
        info=info,
        frame=frame,
        source_span=(float(header.times[0]), float(header.times[-1])),
    )
    info.update(
        map_degree=field.index_map.degree, map_residual_cells=field.index_map.residual_cells
    )
    return field
