"""Gridded wind on latitude/longitude coordinates: CF NetCDF, xarray datasets, GRIB.

What regridded WRF (CDO/NCO), ERA5, ICON, AROME and most national forecasts
deliver: winds on a grid whose cells carry latitude and longitude (1-D axes of a
regular grid or 2-D arrays of a curvilinear one), as **earth-relative** east/north
components or as speed and direction.

1. :func:`read_cf_header` finds, without reading wind arrays,

   * the wind variables: by CF ``standard_name`` (``eastward_wind``/``northward_wind``,
     or ``wind_speed``/``wind_from_direction``), else by common names (``u10``/``v10``,
     ``U10``/``V10``, ``uas``/``vas``, ``10u``/``10v``, ``u``/``v``, ...), else as the
     ``variables`` mapping names them;
   * latitude/longitude: ``standard_name`` ``latitude``/``longitude``, units
     ``degrees_north``/``degrees_east`` or the usual names;
   * times: a CF time coordinate (``units: "hours since ..."``, standard calendars),
     a decoded ``datetime64`` coordinate, a scalar time, a global attribute
     (``valid_time``, ``ref_time``, ...) or the ``time`` argument;
   * the data height: ``time``-independent ``height`` coordinate or attribute, a
     name such as ``u10``/``u100``, or the ``data_height_m`` argument.

2. :func:`open_netcdf` orients the grid (rows south to north, columns west to east,
   longitudes unwrapped around the course, so 0..360 grids and descending latitudes
   work), crops it to the course box plus a margin and the race window, reads the
   window, applies the height correction, rotates the winds into the local frame
   and returns a :class:`~sailroute.wind.grid.GridWind`.  NaN cells (land in a
   sea-only product) are kept as holes: sampling there raises an error naming
   the place.

3. :func:`open_grib` reads GRIB 1/2 through cfgrib (optional extra ``grib``) and
   passes the dataset to :func:`open_netcdf`.

An :class:`xarray.Dataset` (optional extra ``xarray``) is accepted wherever a path is.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.errors import InputError, WindDataError
from sailroute.geo import LocalFrame, wrap_lon
from sailroute.timeutil import iso, parse_time
from sailroute.units import speed_factor, wind_components
from sailroute.wind._xr import (
    SOURCE_ATTR,
    damaged_as_wind_error,
    open_dataset,
    require_xarray,
)
from sailroute.wind.grid import GridWind
from sailroute.wind.height import (
    DEFAULT_EXPONENT,
    DEFAULT_ROUGHNESS_M,
    log_law_factor,
    power_law_factor,
)
from sailroute.wind.rotation import earth_to_local

STANDARD_UV = (("eastward_wind", "northward_wind"),)
"""CF standard names of earth-relative wind components."""

STANDARD_SD = (("wind_speed", "wind_from_direction"), ("wind_speed", "wind_to_direction"))
"""CF standard names of wind speed and direction."""

NAMES_UV = (
    ("u10", "v10"),
    ("U10", "V10"),
    ("u10m", "v10m"),
    ("U10M", "V10M"),
    ("uas", "vas"),
    ("10u", "10v"),
    ("UGRD_10maboveground", "VGRD_10maboveground"),
    ("ugrd10m", "vgrd10m"),
    ("u_10m", "v_10m"),
    ("u100", "v100"),
    ("u", "v"),
    ("U", "V"),
)
"""Variable names tried, in order, when no standard_name says which are the winds."""

NAMES_SD = (
    ("wind_speed", "wind_direction"),
    ("ws10", "wd10"),
    ("si10", "wdir10"),
    ("wspd", "wdir"),
    ("wind_speed_10m", "wind_direction_10m"),
)
"""Speed/direction variable names tried after :data:`NAMES_UV`."""

LAT_NAMES = ("lat", "latitude", "nav_lat", "lats", "XLAT", "LAT", "Latitude", "gridlat_0")
LON_NAMES = ("lon", "longitude", "nav_lon", "lons", "XLONG", "LON", "Longitude", "gridlon_0")
TIME_NAMES = ("valid_time", "time", "Time", "times", "t")
TIME_ATTRS = ("valid_time", "time", "ref_time", "forecast_time", "reference_time", "date")
"""Global attributes read as the time of a file without a time coordinate."""

HEIGHT_NAMES = (
    "height",
    "heightAboveGround",
    "height_above_ground",
    "height_above_ground1",
    "z",
    "level",
)

DIRECTION_UNITS = frozenset(
    {
        "degree",
        "degrees",
        "deg",
        "degrees_true",
        "degree_true",
        "°",
        "degrees true",
        "degT",
        "degree_north",
        "degrees_north",
    }
)
_SPEED_UNIT_ALIASES = {
    "m s-1": "m/s",
    "m s**-1": "m/s",
    "m.s-1": "m/s",
    "ms-1": "m/s",
    "m s^-1": "m/s",
    "m sec-1": "m/s",
    "meter second-1": "m/s",
    "meters/second": "m/s",
    "metre second-1": "m/s",
    "m s{-1}": "m/s",
    "knot": "kn",
    "km h-1": "km/h",
    "km/hr": "km/h",
}
DATA_KEYS = ("u", "v", "speed", "direction", "lat", "lon", "time")
"""Keys of the ``variables`` mapping."""


# ----------------------------------------------------------------------------- open
def _open_source(source: Any) -> tuple[Any, str]:
    """A netCDF4-like dataset and its label, for a path or an xarray Dataset."""
    return open_dataset(source, "NetCDF", "a NetCDF file with wind on latitude/longitude")


def is_wrfout(source: Any) -> bool:
    """True when ``source`` (path or dataset) has the variables of a WRF wrfout file."""
    from sailroute.wind.wrf import REQUIRED_VARIABLES

    ds, _ = _open_source(source)
    with ds:
        return all(v in ds.variables for v in REQUIRED_VARIABLES)


# ----------------------------------------------------------------------------- header
@dataclass(frozen=True)
class CFHeader:
    """What :func:`read_cf_header` learns about a lat/lon wind source.

    Attributes
    ----------
    label : str
        File name (or ``"xarray.Dataset"``) for messages.
    kind : {"uv", "sd"}
        East/north components, or speed and direction.
    names : (str, str)
        The two wind variables (u, v or speed, direction).
    how : str
        How they were found (``"standard_name"``, ``"name"``, ``"variables"``).
    dims : tuple of str
        Dimensions of the wind variables.
    time_dim, row_dim, col_dim : str or None
        Which of ``dims`` is time, and the two grid dimensions (rows: the one along
        which latitude changes most).
    times : ndarray (nt,)
        Epoch seconds [s], strictly increasing.
    time_source : str
        Where the times came from.
    lat, lon : ndarray (nrow, ncol)
        Cell centres [°] in file order (1-D axes expanded).
    regular : bool
        Coordinates were 1-D axes.
    speed_factor : float
        Multiplies stored speeds to m s⁻¹.
    units : str
        The speed units as stored (for ``info``).
    to_direction : bool
        Direction is where the wind blows *to* (``wind_to_direction``).
    data_height_m : float or None
        Height the winds refer to [m], when known.
    height_source : str
        Where it came from.
    fixed : mapping of str to int
        Index used for each size-1 extra dimension.
    """

    label: str
    kind: str
    names: tuple[str, str]
    how: str
    dims: tuple[str, ...]
    time_dim: str | None
    row_dim: str
    col_dim: str
    times: NDArray[np.float64]
    time_source: str
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    regular: bool
    speed_factor: float
    units: str
    to_direction: bool
    data_height_m: float | None
    height_source: str
    fixed: Mapping[str, int] = field(default_factory=dict)

    @property
    def shape(self) -> tuple[int, int, int]:
        """``(nt, nrow, ncol)`` in file order."""
        return (self.times.size, *self.lat.shape)


MAX_WIND_MS = 500.0
"""Strongest wind a gridded file may hold [m/s]: far above any measured gust (about
113 m/s), so that larger values are fill values the file does not declare (-999, 9999,
1e20) or infinities; synthetic test fields may exceed the physical range below it."""


def _attr(var: Any, key: str, default: Any = None) -> Any:
    try:
        return var.getncattr(key) if key in var.ncattrs() else default
    except AttributeError:
        return default


def _std(var: Any) -> str:
    return str(_attr(var, "standard_name", "") or "").strip()


def _find_winds(
    ds: Any, variables: Mapping[str, str] | None, label: str
) -> tuple[str, tuple[str, str], str, bool]:
    """``(kind, names, how, to_direction)`` of the wind variables: ``"uv"`` or ``"sd"``,
    found through ``variables``, a CF ``standard_name`` or a conventional name."""
    names = list(ds.variables)
    found = _given_winds(ds, variables, label) if variables else None
    if found is None:
        found = _standard_winds(ds, names)
    if found is not None:
        return found
    by_std = {_std(ds.variables[n]) for n in names}
    hint = (
        " The file has grid-relative x_wind/y_wind: rotate them to eastward/northward "
        "first (or name them with `variables:` if the grid axes point east and north)."
        if "x_wind" in by_std or "grid_eastward_wind" in by_std
        else ""
    )
    raise WindDataError(
        f"{label}: no wind variables found; expected CF standard_name eastward_wind and "
        "northward_wind (or wind_speed and wind_from_direction), or variables named u10/v10, "
        f"U10/V10, uas/vas, u/v, ... (found: {', '.join(names) or 'none'}). Name them with "
        f"`variables: {{u: NAME, v: NAME}}` (or `{{speed: NAME, direction: NAME}}`).{hint}"
    )


def _given_winds(
    ds: Any, variables: Mapping[str, str], label: str
) -> tuple[str, tuple[str, str], str, bool] | None:
    """The wind variables that ``variables`` names (None when it names none of u, v,
    speed, direction); unknown keys, absent variables and half pairs are errors."""
    unknown = [k for k in variables if k not in DATA_KEYS]
    if unknown:
        raise InputError(
            f"{label}: variables: unknown key(s) {', '.join(unknown)}; "
            f"expected some of {', '.join(DATA_KEYS)}"
        )
    missing = [f"{k}: {v!r}" for k, v in variables.items() if v not in ds.variables]
    if missing:
        raise InputError(
            f"{label}: variables: {', '.join(missing)} not in the file "
            f"(variables: {', '.join(ds.variables)})"
        )
    if "u" in variables or "v" in variables:
        if not ("u" in variables and "v" in variables):
            raise InputError(f"{label}: variables: give both u and v (or speed and direction)")
        return "uv", (variables["u"], variables["v"]), "variables", False
    if "speed" in variables and "direction" in variables:
        to_dir = _std(ds.variables[variables["direction"]]) == "wind_to_direction"
        return "sd", (variables["speed"], variables["direction"]), "variables", to_dir
    if any(k in variables for k in ("speed", "direction")):
        raise InputError(f"{label}: variables: give both speed and direction (or u and v)")
    return None


def _standard_winds(ds: Any, names: list[str]) -> tuple[str, tuple[str, str], str, bool] | None:
    """The first wind pair by CF ``standard_name`` (:data:`STANDARD_UV`, then
    :data:`STANDARD_SD`), else by name (:data:`NAMES_UV`, :data:`NAMES_SD`; at least 2-D)."""
    by_std: dict[str, str] = {}
    for n in names:
        s = _std(ds.variables[n])
        if s and s not in by_std:
            by_std[s] = n
    for a, b in STANDARD_UV:
        if a in by_std and b in by_std:
            return "uv", (by_std[a], by_std[b]), "standard_name", False
    for a, b in STANDARD_SD:
        if a in by_std and b in by_std:
            return "sd", (by_std[a], by_std[b]), "standard_name", b == "wind_to_direction"
    for kind, pairs in (("uv", NAMES_UV), ("sd", NAMES_SD)):
        for a, b in pairs:
            if a in ds.variables and b in ds.variables and ds.variables[a].ndim >= 2:
                return kind, (a, b), "name", False
    return None


def _is_lat(ds: Any, n: str) -> bool:
    v = ds.variables[n]
    return (
        _std(v) == "latitude"
        or str(_attr(v, "units", "")).strip()
        in ("degrees_north", "degree_north", "degree_N", "degrees_N")
        or n in LAT_NAMES
    )


def _is_lon(ds: Any, n: str) -> bool:
    v = ds.variables[n]
    return (
        _std(v) == "longitude"
        or str(_attr(v, "units", "")).strip()
        in ("degrees_east", "degree_east", "degree_E", "degrees_E")
        or n in LON_NAMES
    )


def _find_coord(
    ds: Any,
    wind_dims: tuple[str, ...],
    wind_var: Any,
    test: Any,
    given: str | None,
    what: str,
    label: str,
) -> str:
    if given is not None:
        return given
    # CF order of preference: the wind's `coordinates` attribute, coordinate variables
    # (name == dimension), then any variable whose dimensions are among the wind's.
    listed = str(_attr(wind_var, "coordinates", "") or "").split()
    cands = (
        [n for n in listed if n in ds.variables]
        + [n for n in ds.variables if n in wind_dims]
        + list(ds.variables)
    )
    for n in cands:
        v = ds.variables[n]
        if v.ndim in (1, 2, 3) and set(v.dimensions) <= set(wind_dims) and test(ds, n):
            if v.ndim == 3 and v.dimensions[0] not in wind_dims[:1]:
                continue
            return n
    raise WindDataError(
        f"{label}: no {what} coordinate for the wind variables (dimensions "
        f"{', '.join(wind_dims)}); expected a variable with standard_name {what} (or units "
        f"degrees_{'north' if what == 'latitude' else 'east'}, or named "
        f"{'lat/latitude' if what == 'latitude' else 'lon/longitude'}) on those dimensions. "
        f"Name it with `variables: {{{what[:3]}: NAME}}`."
    )


def _read_all(var: Any) -> NDArray[np.float64]:
    a = var[()] if var.ndim == 0 else var[:]
    if np.ma.isMaskedArray(a) or isinstance(a, np.ma.MaskedArray):
        return np.ma.filled(np.ma.asarray(a, dtype=float), np.nan)
    return np.asarray(a, dtype=float)


def _coords_2d(
    ds: Any, latn: str, lonn: str, dims: tuple[str, ...], label: str
) -> tuple[NDArray, NDArray, str, str, bool]:
    lv, ov = ds.variables[latn], ds.variables[lonn]
    lat = _read_all(lv if lv.ndim < 3 else _First(lv))
    lon = _read_all(ov if ov.ndim < 3 else _First(ov))
    ldims = lv.dimensions[-2:] if lv.ndim >= 2 else lv.dimensions
    odims = ov.dimensions[-2:] if ov.ndim >= 2 else ov.dimensions
    if lat.ndim == 1 and lon.ndim == 1:
        if ldims[0] == odims[0]:
            raise WindDataError(
                f"{label}: {latn} and {lonn} are 1-D on the same dimension "
                f"{ldims[0]!r} (a list of points, not a grid); expected a grid"
            )
        row_dim, col_dim = ldims[0], odims[0]
        lat2, lon2 = np.meshgrid(lat, lon, indexing="ij")
        regular = True
    elif lat.ndim == 2 and lon.shape == lat.shape and tuple(ldims) == tuple(odims):
        d0, d1 = ldims
        # rows: the dimension along which latitude changes most
        dl0 = np.nanmedian(np.abs(np.diff(lat, axis=0))) if lat.shape[0] > 1 else 0.0
        dl1 = np.nanmedian(np.abs(np.diff(lat, axis=1))) if lat.shape[1] > 1 else 0.0
        if dl0 >= dl1:
            row_dim, col_dim, lat2, lon2 = d0, d1, lat, lon
        else:
            row_dim, col_dim, lat2, lon2 = d1, d0, lat.T, lon.T
        regular = False
    else:
        raise WindDataError(
            f"{label}: {latn} {lat.shape} {tuple(ldims)} and {lonn} {lon.shape} "
            f"{tuple(odims)} are neither two 1-D axes nor two 2-D arrays on the "
            "same dimensions"
        )
    missing = [d for d in (row_dim, col_dim) if d not in dims]
    if missing:
        raise WindDataError(
            f"{label}: the wind variables (dimensions {', '.join(dims)}) do not "
            f"have the coordinate dimension(s) {', '.join(missing)}"
        )
    if not (np.all(np.isfinite(lat2)) and np.all(np.isfinite(lon2))):
        raise WindDataError(
            f"{label}: {latn}/{lonn} contain missing or NaN values; expected "
            "a complete coordinate grid"
        )
    if np.any(np.abs(lat2) > 90.0):
        raise WindDataError(
            f"{label}: {latn} has values outside [-90, 90] degrees "
            f"(max |lat| {float(np.max(np.abs(lat2))):g})"
        )
    if np.any(lon2 < -180.0) or np.any(lon2 > 360.0):
        raise WindDataError(
            f"{label}: {lonn} has values outside [-180, 360] degrees "
            f"({float(np.min(lon2)):g} .. {float(np.max(lon2)):g})"
        )
    return lat2, lon2, row_dim, col_dim, regular


class _First:
    """The first time of a 3-D (time, row, col) coordinate variable, read lazily."""

    def __init__(self, var: Any) -> None:
        self._var = var
        self.ndim = 2

    def __getitem__(self, index: Any) -> Any:
        return self._var[0]


def _epoch_from_values(vals: NDArray, var: Any, name: str, label: str) -> NDArray[np.float64]:
    a = np.asarray(vals)
    if a.dtype.kind == "M":
        return a.astype("datetime64[ns]").astype("int64").astype(float) / 1e9
    units = str(_attr(var, "units", "") or "")
    if "since" not in units:
        raise WindDataError(
            f"{label}: time variable {name} has units {units!r}; expected CF "
            "time units such as 'hours since 2014-10-07 00:00:00'"
        )
    calendar = str(_attr(var, "calendar", "standard") or "standard").lower()
    if calendar not in ("standard", "gregorian", "proleptic_gregorian", "julian"):
        raise WindDataError(
            f"{label}: time variable {name} uses calendar {calendar!r}; only "
            "real-world calendars (standard, gregorian, proleptic_gregorian) "
            "can be matched with a race time"
        )
    import cftime

    try:
        values: NDArray[np.float64] = np.ma.filled(np.ma.asarray(a, dtype=float), np.nan).ravel()
    except (ValueError, TypeError) as exc:
        raise WindDataError(
            f"{label}: cannot decode time variable {name} ({units!r}): {exc}"
        ) from None
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise WindDataError(
            f"{label}: time variable {name} has {bad.size} missing or "
            f"non-finite value(s) (the first at index {int(bad[0])}); every "
            "time step needs its time"
        )
    try:
        dts = cftime.num2date(
            values, units, calendar, only_use_cftime_datetimes=False, only_use_python_datetimes=True
        )
    except (ValueError, TypeError, OverflowError) as exc:
        raise WindDataError(
            f"{label}: cannot decode time variable {name} ({units!r}): {exc}"
        ) from None
    return np.array(
        [(d if d.tzinfo else d.replace(tzinfo=UTC)).timestamp() for d in np.atleast_1d(dts)],
        dtype=float,
    )


def _size(dim: Any) -> int:
    """Length of a dimension: an int (xarray) or a netCDF4 ``Dimension``."""
    return dim if isinstance(dim, int) else len(dim)


def _is_time(ds: Any, n: str) -> bool:
    v = ds.variables[n]
    return (
        (getattr(v, "dtype", None) is not None and np.dtype(v.dtype).kind == "M")
        or ("since" in str(_attr(v, "units", "") or ""))
        or _std(v) == "time"
        or (str(_attr(v, "axis", "")).upper() == "T")
    )


def _find_times(
    ds: Any,
    dims: tuple[str, ...],
    grid_dims: tuple[str, str],
    given: str | None,
    time: str | float | None,
    label: str,
) -> tuple[str | None, NDArray[np.float64], str]:
    """``(time dimension or None, epoch seconds [s], source)`` of the wind variables: the
    ``given`` variable, a time coordinate on one of their dimensions, the ``time``
    argument, a scalar time variable, or a global attribute (UTC)."""
    extra = [d for d in dims if d not in grid_dims]
    if given is not None:
        return _given_time(ds, given, extra, label)
    found = _dimension_time(ds, extra, label)
    if found is not None:
        return found
    _refuse_extra_dims(ds, extra, label)
    if time is not None:
        if isinstance(time, int | float) and not isinstance(time, bool):
            return None, np.array([float(time)]), "argument"
        return None, np.array([parse_time(str(time), f"{label}: time").timestamp()]), "argument"
    found = _scalar_time(ds, label)
    if found is not None:
        return found
    raise WindDataError(
        f"{label}: no time found: the wind variables have no time dimension and there is no "
        f"time variable or global attribute ({', '.join(TIME_ATTRS)}); give the time the "
        "field is valid at with `time: '2014-10-07T12:00:00Z'`"
    )


def _given_time(
    ds: Any, given: str, extra: list[str], label: str
) -> tuple[str | None, NDArray[np.float64], str]:
    """The time variable named by ``variables: {time: ...}``: 1-D on one of the wind's
    ``extra`` dimensions, or a scalar."""
    v = ds.variables[given]
    if v.ndim == 1 and v.dimensions[0] in extra:
        return v.dimensions[0], _epoch_from_values(v[:], v, given, label), f"variable {given}"
    if v.ndim == 0:
        return None, _epoch_from_values(np.atleast_1d(v[()]), v, given, label), f"variable {given}"
    raise WindDataError(
        f"{label}: time variable {given} has dimensions {v.dimensions}; "
        f"expected one of the wind's dimensions ({', '.join(extra)}) or none"
    )


def _dimension_time(
    ds: Any, extra: list[str], label: str
) -> tuple[str | None, NDArray[np.float64], str] | None:
    """A time dimension among ``extra``: its coordinate variable, or a time-like 1-D
    variable on it (not a duration); None if there is none."""
    for d in extra:
        cands = ([d] if d in ds.variables else []) + [n for n in TIME_NAMES if n in ds.variables]
        cands += [n for n in ds.variables if n not in cands]
        for n in cands:
            v = ds.variables[n]
            if (
                v.ndim == 1
                and v.dimensions[0] == d
                and _is_time(ds, n)
                and (np.dtype(v.dtype).kind != "m")
            ):
                return d, _epoch_from_values(v[:], v, n, label), f"variable {n}"
    return None


def _refuse_extra_dims(ds: Any, extra: list[str], label: str) -> None:
    """An error when a dimension other than the grid's, of size > 1, is not a time."""
    sizes = {d: _size(ds.dimensions.get(d, 1)) for d in extra} if hasattr(ds, "dimensions") else {}
    big = [d for d, n in sizes.items() if n > 1]
    if big:
        raise WindDataError(
            f"{label}: dimension {big[0]!r} (size {sizes[big[0]]}) of the wind "
            "variables is not a time with CF units; expected a time coordinate such as "
            "time(time) with units 'hours since ...'. Select one level/member first, or "
            "name the time variable with `variables: {time: NAME}`."
        )


def _scalar_time(ds: Any, label: str) -> tuple[str | None, NDArray[np.float64], str] | None:
    """A scalar time variable (not a duration), else a global attribute of
    :data:`TIME_ATTRS` read as an ISO 8601 time (UTC unless it says); None if neither."""
    for n in TIME_NAMES + tuple(ds.variables):
        if n in ds.variables and ds.variables[n].ndim == 0 and _is_time(ds, n):
            v = ds.variables[n]
            if np.dtype(v.dtype).kind == "m":
                continue
            return None, _epoch_from_values(np.atleast_1d(v[()]), v, n, label), f"variable {n}"
    attrs = ds.ncattrs()
    for key in TIME_ATTRS:
        if key in attrs:
            text = str(ds.getncattr(key)).strip()
            s = text[:-1] + "+00:00" if text.endswith(("Z", "z")) else text
            try:
                dt = datetime.fromisoformat(s.replace(" UTC", "").replace("_", "T"))
            except ValueError:
                continue
            if dt.tzinfo is None:
                dt = dt.replace(tzinfo=UTC)
            return None, np.array([dt.timestamp()]), f"global attribute {key} (UTC)"
    return None


def _speed_units(var: Any, name: str, label: str, declared: str | None) -> tuple[float, str]:
    units = _attr(var, "units", None)
    if declared is not None:
        return speed_factor(declared), declared
    if units is None or not str(units).strip():
        return 1.0, "none given (read as m/s)"
    u = str(units).strip()
    key = _SPEED_UNIT_ALIASES.get(u, u)
    try:
        return speed_factor(key), u
    except InputError:
        raise WindDataError(
            f"{label}: variable {name} has units {u!r}; expected a speed (m s-1, knots, km/h). "
            "Fix the units attribute or declare the unit with `speed_unit:`"
        ) from None


def _data_height(ds: Any, var: Any, name: str, dims: tuple[str, ...]) -> tuple[float | None, str]:
    h = _attr(var, "height", None)
    if h is not None:
        m = re.match(r"\s*([0-9.]+)\s*(m|meters?|metres?)?\s*$", str(h))
        if m:
            return float(m.group(1)), f"attribute {name}:height"
    listed = str(_attr(var, "coordinates", "") or "").split()
    for n in listed + list(HEIGHT_NAMES):
        if n in ds.variables and n not in (name,):
            v = ds.variables[n]
            size = int(np.prod(v.shape)) if v.ndim else 1
            std = _std(v)
            if (
                size == 1
                and (std == "height" or n in HEIGHT_NAMES)
                and (n in listed or n in dims or v.ndim == 0 or std == "height")
            ):
                units = str(_attr(v, "units", "") or "").strip()
                if units in ("m", "meters", "metre", "metres", "meter"):
                    val = float(_read_all(v).ravel()[0])
                    if val > 0:
                        return val, f"coordinate {n}"
    m = re.fullmatch(r"[A-Za-z_]*?(\d+)m?|(\d+)[uv]", name, flags=re.IGNORECASE)
    if m:
        return float(m.group(1) or m.group(2)), f"variable name {name}"
    long_name = str(_attr(var, "long_name", "") or "")
    m = re.search(r"(\d+)\s*(m|metre|meter)\b", long_name)
    if m:
        return float(m.group(1)), f"long_name of {name}"
    return None, "unknown"


def _check_times(
    times: NDArray[np.float64],
    time_dim: str | None,
    dims: tuple[str, ...],
    shape: tuple[int, ...],
    label: str,
) -> None:
    """One finite time per slice of ``time_dim`` (if any), strictly increasing."""
    if time_dim is not None and times.size != dict(zip(dims, shape, strict=True))[time_dim]:
        raise WindDataError(
            f"{label}: the time coordinate has {times.size} values but "
            f"dimension {time_dim!r} has {shape[dims.index(time_dim)]}"
        )
    if not np.all(np.isfinite(times)):
        raise WindDataError(f"{label}: the time coordinate has missing values")
    bad = np.nonzero(np.diff(times) <= 0)[0]
    if bad.size:
        k = int(bad[0])
        raise WindDataError(
            f"{label}: times must increase strictly, but time[{k}] = {iso(times[k])} and "
            f"time[{k + 1}] = {iso(times[k + 1])}; remove duplicated or out-of-order slices"
        )


def _fixed_indices(
    dims: tuple[str, ...],
    shape: tuple[int, ...],
    field_dims: tuple[str, str, str | None],
    select: Mapping[str, int] | None,
    label: str,
) -> dict[str, int]:
    """Index taken along each dimension other than the grid's and the time's
    (``field_dims``): the one ``select`` names, else 0 for a dimension of size 1."""
    fixed: dict[str, int] = {}
    chosen = dict(select or {})
    unknown = sorted(set(chosen) - set(dims))
    if unknown:
        raise InputError(
            f"{label}: select names {', '.join(map(repr, unknown))}, which "
            f"the wind variables do not have (dimensions: {', '.join(dims)})"
        )
    for d, n in zip(dims, shape, strict=True):
        if d in field_dims:
            if d in chosen:
                raise InputError(
                    f"{label}: select {d!r}: that is a time or grid "
                    "dimension; select only members or levels"
                )
            continue
        if d in chosen:
            k = chosen[d]
            if not 0 <= k < n:
                raise InputError(
                    f"{label}: select {d}: {k} is out of range; that "
                    f"dimension has indices 0 .. {n - 1}"
                )
            fixed[d] = int(k)
            continue
        if n != 1:
            raise WindDataError(
                f"{label}: the wind variables have an extra dimension {d!r} of size {n} "
                "(levels or ensemble members); pick one with `select: {"
                f"{d}: 0}}` in the wind spec (an ensemble scenario's `members: {{dim: "
                f"{d}, ...}}` takes them all), or with xarray `ds.isel({{{d!r}: 0}})`"
            )
        fixed[d] = 0
    return fixed


@damaged_as_wind_error
def read_cf_header(
    source: Any,
    *,
    variables: Mapping[str, str] | None = None,
    time: str | float | None = None,
    data_height_m: float | None = None,
    speed_unit: str | None = None,
    select: Mapping[str, int] | None = None,
) -> CFHeader:
    """Find the winds, coordinates, times and data height of a lat/lon wind source.

    Parameters
    ----------
    source : str, Path or xarray.Dataset
        NetCDF file or dataset.
    variables : mapping, optional
        Explicit names: ``u``/``v`` or ``speed``/``direction``, and optionally
        ``lat``, ``lon``, ``time``.
    time : str or float, optional
        Valid time of a source without one (ISO 8601 with offset, or epoch s).
    data_height_m : float, optional
        Height of the winds [m] when the source does not say.
    speed_unit : str, optional
        Speed unit overriding the ``units`` attribute.
    select : mapping of str to int, optional
        Index to take along each extra dimension (an ensemble member or a level),
        e.g. ``{"number": 3}``; extra dimensions of size 1 need none.

    Returns
    -------
    CFHeader

    Raises
    ------
    InputError / WindDataError
        Missing winds, coordinates or time (each message says what was expected,
        what the file holds and which spec key names it), bad units.
    """
    ds, label = _open_source(source)
    with ds:
        kind, names, how, to_dir = _find_winds(ds, variables, label)
        va, vb = ds.variables[names[0]], ds.variables[names[1]]
        if tuple(va.dimensions) != tuple(vb.dimensions) or tuple(va.shape) != tuple(vb.shape):
            raise WindDataError(
                f"{label}: {names[0]} {va.dimensions} and {names[1]} "
                f"{vb.dimensions} must have the same dimensions and shape"
            )
        dims = tuple(va.dimensions)
        vmap = dict(variables or {})
        latn = _find_coord(ds, dims, va, _is_lat, vmap.get("lat"), "latitude", label)
        lonn = _find_coord(ds, dims, va, _is_lon, vmap.get("lon"), "longitude", label)
        lat, lon, row_dim, col_dim, regular = _coords_2d(ds, latn, lonn, dims, label)
        time_dim, times, tsrc = _find_times(
            ds, dims, (row_dim, col_dim), vmap.get("time"), time, label
        )
        _check_times(times, time_dim, dims, tuple(va.shape), label)
        fixed = _fixed_indices(dims, tuple(va.shape), (row_dim, col_dim, time_dim), select, label)
        if str(_attr(va, "GRIB_uvRelativeToGrid", 0)) == "1":
            raise WindDataError(
                f"{label}: {names[0]}/{names[1]} are relative to the GRIB grid's axes "
                "(uvRelativeToGrid = 1), not to true east/north; rotate them to earth-relative "
                "first (e.g. with the grid's rotation angles) and pass the dataset"
            )
        factor, units = _speed_units(va, names[0], label, speed_unit)
        if kind == "sd":
            du = str(_attr(vb, "units", "degree") or "degree").strip()
            if du not in DIRECTION_UNITS:
                raise WindDataError(
                    f"{label}: direction variable {names[1]} has units {du!r}; "
                    "expected degrees (clockwise from true north)"
                )
        h: float | None
        if data_height_m is not None:
            h, hsrc = float(data_height_m), "argument"
        else:
            h, hsrc = _data_height(ds, va, names[0], dims)
    return CFHeader(
        label,
        kind,
        names,
        how,
        dims,
        time_dim,
        row_dim,
        col_dim,
        times,
        tsrc,
        lat,
        lon,
        regular,
        factor,
        units,
        to_dir,
        h,
        hsrc,
        fixed,
    )


# ----------------------------------------------------------------------------- window
def _orient(header: CFHeader, frame: LocalFrame) -> tuple[NDArray, NDArray]:
    """File row and column indices ordered south to north and west to east."""
    lat, lon = header.lat, header.lon
    rel = np.asarray(wrap_lon(lon - frame.lon0), dtype=float)
    if header.regular:
        rows = np.argsort(lat[:, 0], kind="stable")
        cols = np.argsort(rel[0, :], kind="stable")
        return rows, cols
    nr, nc = lat.shape
    rows = np.arange(nr)
    cols = np.arange(nc)
    if nr > 1 and np.median(np.diff(lat, axis=0)) < 0:
        rows = rows[::-1]
    if nc > 1 and np.median(np.diff(rel, axis=1)) < 0:
        cols = cols[::-1]
    return rows, cols


def _index(idx: NDArray) -> slice | NDArray:
    """A slice for contiguous increasing indices (fast in netCDF4), else the array."""
    if idx.size and np.all(np.diff(idx) == 1):
        return slice(int(idx[0]), int(idx[-1]) + 1)
    return idx


def dimension_sizes(path: str | Path) -> dict[str, int]:
    """The dimensions of a NetCDF file and their sizes (the header only; no data read).

    Raises
    ------
    OSError
        The file cannot be read as NetCDF.
    """
    import netCDF4

    with netCDF4.Dataset(str(path), "r") as ds:
        return {k: len(v) for k, v in ds.dimensions.items()}


@damaged_as_wind_error
def open_netcdf(
    source: Any,
    frame: LocalFrame,
    *,
    bbox: tuple[float, float, float, float] | None = None,
    margin_m: float | None = None,
    time_window: tuple[float, float] | None = None,
    variables: Mapping[str, str] | None = None,
    time: str | float | None = None,
    data_height_m: float | None = None,
    speed_unit: str | None = None,
    height_m: float | None = None,
    shear: str = "power",
    exponent: float = DEFAULT_EXPONENT,
    roughness_m: float = DEFAULT_ROUGHNESS_M,
    time_step_min: float | None = None,
    interpolation: str = "linear",
    steady: bool = False,
    clamp: bool = False,
    label: str | None = None,
    select: Mapping[str, int] | None = None,
) -> GridWind:
    """Open gridded lat/lon wind (CF NetCDF file or xarray Dataset) as a wind field.

    Parameters
    ----------
    source : str, Path or xarray.Dataset
        The data.  Winds are taken as **earth-relative** (true east/north, or
        direction from true north), as CF ``eastward_wind`` says.
    frame : LocalFrame
        The course's local frame.
    bbox : tuple of float, optional
        Course box ``(xmin, xmax, ymin, ymax)`` [m]; the grid is cropped to it plus
        ``margin_m`` (default three grid spacings).
    margin_m : float, optional
        Crop margin [m].
    time_window : tuple of float, optional
        ``(t0, t1)`` [epoch s]; only the slices bracketing it are read.
    variables, time, data_height_m, speed_unit, select
        See :func:`read_cf_header`.
    height_m : float, optional
        Height the wind is wanted at [m] (Laser centre of effort: 2.68); the data
        are scaled from their height with the power law (``exponent``) or the log
        law (``shear="log"``, ``roughness_m``).  ``None``: as stored.
    shear : {"power", "log"}
    exponent : float
        Power-law exponent [-] (default 1/7).
    roughness_m : float
        Log-law roughness length [m].
    time_step_min : float, optional
        Freeze the wind per block of this many minutes.
    interpolation : {"linear", "nearest"}
        Spatial interpolation.
    steady : bool
        A source with a single time: use it at all times.
    clamp : bool
        Clamp sample points to the coverage instead of raising.
    label : str, optional
        Name in messages (default ``"NetCDF wind <file>"``).

    Returns
    -------
    GridWind
        With ``frame`` set and ``info`` holding ``path``, ``variables``, ``found_by``,
        ``time_source``, ``units``, ``data_height_m``, ``height_source``,
        ``height_m``, ``window`` (file index ranges), ``nan_cells``, ``map_degree``.

    Raises
    ------
    InputError / WindDataError
        See :func:`read_cf_header`; a height correction without a known data height.
    OutOfCoverageError
        No cell lies within the course box plus margin.
    """
    from sailroute.wind.wrf import WrfHeader, crop_window

    if shear not in ("power", "log"):
        raise InputError(f"shear {shear!r}; expected 'power' or 'log'")
    hdr = read_cf_header(
        source,
        variables=variables,
        time=time,
        data_height_m=data_height_m,
        speed_unit=speed_unit,
        select=select,
    )
    name = hdr.label
    if height_m is not None and hdr.data_height_m is None:
        raise InputError(
            f"{name}: a height correction to height_m {height_m:g} m needs the height of the "
            f"winds, which the file does not give ({hdr.names[0]} has no height coordinate or "
            "attribute); set `data_height_m` (10 for 10 m winds)"
        )
    rows, cols = _orient(hdr, frame)
    lat_o = hdr.lat[np.ix_(rows, cols)]
    lon_o = hdr.lon[np.ix_(rows, cols)]
    oriented = WrfHeader(name, hdr.times, lat_o, lon_o, {}, frozenset())
    step_s = None if time_step_min is None else float(time_step_min) * 60.0
    w = crop_window(
        oriented,
        frame,
        bbox=bbox,
        margin_m=margin_m,
        time_window=time_window,
        time_pad_s=step_s or 0.0,
    )
    r_file, c_file = rows[w.j0 : w.j1], cols[w.i0 : w.i1]
    r_sorted, c_sorted = np.sort(r_file), np.sort(c_file)
    ds, _ = _open_source(source)
    arrays = []
    with ds:
        for vname in hdr.names:
            var = ds.variables[vname]
            index: list[Any] = []
            for d in hdr.dims:
                if d == hdr.time_dim:
                    index.append(slice(w.k0, w.k1))
                elif d == hdr.row_dim:
                    index.append(_index(r_sorted))
                elif d == hdr.col_dim:
                    index.append(_index(c_sorted))
                else:
                    k = hdr.fixed.get(d, 0)
                    index.append(slice(k, k + 1))
            a = var[tuple(index)]
            a = np.ma.filled(np.ma.asarray(a, dtype=float), np.nan)
            order = [
                hdr.dims.index(d) for d in (hdr.time_dim, hdr.row_dim, hdr.col_dim) if d is not None
            ]
            order += [k for k in range(a.ndim) if k not in order]
            shape = (w.k1 - w.k0 if hdr.time_dim is not None else 1, r_file.size, c_file.size)
            if a.size != shape[0] * shape[1] * shape[2]:  # a damaged or unusual header
                raise WindDataError(
                    f"{name}: {vname} holds {a.size} values where its dimensions "
                    f"{tuple(hdr.dims)} give {shape[0]} x {shape[1]} x {shape[2]}; the file's "
                    "header does not describe its data (a damaged file?)"
                )
            a = np.transpose(a, order).reshape(shape)
            # back from sorted file order to south-north / west-east order
            a = a[:, np.searchsorted(r_sorted, r_file)][:, :, np.searchsorted(c_sorted, c_file)]
            arrays.append(a)
    if hdr.kind == "uv":
        ue, ve = arrays[0] * hdr.speed_factor, arrays[1] * hdr.speed_factor
    else:
        spd = arrays[0] * hdr.speed_factor
        dirn = arrays[1] + (180.0 if hdr.to_direction else 0.0)
        ue, ve = wind_components(spd, np.mod(dirn, 360.0))
    both = np.isnan(ue) | np.isnan(ve)
    if hdr.kind == "sd":
        neg = np.nanmin(arrays[0]) if np.any(~both) else 0.0
        if neg < 0:
            raise WindDataError(f"{name}: {hdr.names[0]} has negative speeds (min {neg:g})")
    ue[both] = np.nan
    ve[both] = np.nan
    with np.errstate(invalid="ignore"):
        fast = np.nanmax(np.hypot(ue, ve)) if np.any(~both) else 0.0
    if not fast <= MAX_WIND_MS:  # also inf
        raise WindDataError(
            f"{name}: {' and '.join(hdr.names)} give a wind of {fast:g} m/s; expected at most "
            f"{MAX_WIND_MS:g} m/s (check speed_unit; a value that marks missing data needs "
            "the variable's _FillValue or missing_value attribute)"
        )
    if both.all():
        raise WindDataError(
            f"{name}: every cell in the window around the course has no wind "
            "(NaN: land or masked); check the course position and the file"
        )
    z_out = hdr.data_height_m
    if height_m is not None:
        z_in = hdr.data_height_m
        assert z_in is not None  # a height correction without the data's height is refused above
        z_out = float(height_m)
        f = (
            power_law_factor(z_in, z_out, exponent)
            if shear == "power"
            else log_law_factor(z_in, z_out, roughness_m)
        )
        ue, ve = ue * f, ve * f
    lat_w = lat_o[w.j0 : w.j1, w.i0 : w.i1]
    lon_w = lon_o[w.j0 : w.j1, w.i0 : w.i1]
    x, y = frame.to_xy(lat_w, lon_w)
    ul, vl = earth_to_local(ue, ve, frame.grid_north_deg(lat_w, lon_w))
    times = hdr.times[w.k0 : w.k1]
    span = (float(hdr.times[0]), float(hdr.times[-1]))
    nan_cells = int(both[0].sum()) if both.ndim == 3 else 0
    info: dict[str, Any] = {
        "path": name,
        "format": "cf",
        "variables": hdr.names,
        "found_by": hdr.how,
        "time_source": hdr.time_source,
        "units": hdr.units,
        "data_height_m": hdr.data_height_m,
        "height_source": hdr.height_source,
        "height_m": z_out,
        "window": {
            "rows": (int(r_sorted[0]), int(r_sorted[-1]) + 1),
            "cols": (int(c_sorted[0]), int(c_sorted[-1]) + 1),
            "times": (w.k0, w.k1),
        },
        "cells": int(both[0].size),
        "nan_cells": nan_cells,
        "times": f"{iso(times[0])} .. {iso(times[-1])} ({times.size} of {hdr.times.size} slices)",
        "map_degree": None,  # filled in below, from the field's index map
        "map_residual_cells": None,
    }
    field = GridWind(
        times,
        x,
        y,
        ul,
        vl,
        interpolation=interpolation,
        time_step_s=step_s,
        clamp=clamp,
        name=label or f"gridded wind {_short(name)}",
        info=info,
        frame=frame,
        source_span=span,
        allow_nan=True,
        steady=steady,
    )
    info.update(
        map_degree=field.index_map.degree, map_residual_cells=field.index_map.residual_cells
    )
    return field


def _short(name: str) -> str:
    return name if name == "xarray.Dataset" else Path(name).name


# ----------------------------------------------------------------------------- GRIB
def open_grib_dataset(path: str | Path, *, filter_by_keys: Mapping[str, Any] | None = None) -> Any:
    """Read a GRIB file into an :class:`xarray.Dataset` with cfgrib (extra ``grib``).

    Parameters
    ----------
    path : str or Path
        GRIB 1 or 2 file.
    filter_by_keys : mapping, optional
        cfgrib message filter, e.g. ``{"typeOfLevel": "heightAboveGround", "level": 10}``
        for files that mix levels.

    Raises
    ------
    InputError
        Missing file, cfgrib/eccodes not installed (with the install command), or
        a file cfgrib cannot turn into one dataset (with the filter to use).
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(
            f"{p}: GRIB file not found; check the `path` (relative to the course file's folder)"
        )
    xr = require_xarray("reading GRIB")
    try:
        import cfgrib  # noqa: F401
    except (ImportError, RuntimeError) as exc:
        raise InputError(
            f"{p}: reading GRIB needs the optional packages cfgrib and eccodes ({exc}); install "
            "them with `pip install 'sailroute[grib]'`"
        ) from None
    kw: dict[str, Any] = {"indexpath": ""}  # no .idx files next to the data
    if filter_by_keys:
        kw["filter_by_keys"] = dict(filter_by_keys)
    try:
        ds = xr.open_dataset(str(p), engine="cfgrib", backend_kwargs=kw)
        ds.load()
    except Exception as exc:
        text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise WindDataError(
            f"{p}: cannot be read as GRIB by cfgrib ({text}). A file that mixes levels or "
            "forecast types needs a filter, e.g. `filter: {typeOfLevel: heightAboveGround, "
            "level: 10}`"
        ) from None
    ds.attrs[SOURCE_ATTR] = str(p)
    return ds


def open_grib(
    path: str | Path,
    frame: LocalFrame,
    *,
    filter_by_keys: Mapping[str, Any] | None = None,
    **kwargs: Any,
) -> GridWind:
    """Open GRIB wind (via cfgrib) as a wind field; keywords as :func:`open_netcdf`."""
    ds = open_grib_dataset(path, filter_by_keys=filter_by_keys)
    kwargs.setdefault("label", f"GRIB wind {Path(path).name}")
    field = open_netcdf(ds, frame, **kwargs)
    return replace(field, info={**field.info, "path": str(path), "format": "grib"})
