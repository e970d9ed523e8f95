"""Wind and current specs: parsed once into frozen dataclasses, built into fields from them.

A course file's ``scenarios.<name>.wind`` (or an ensemble's ``members``) and
``scenarios.<name>.current`` are YAML mappings.  Each spec type has three things,
held together in one registry (:data:`WIND_KINDS`, :data:`CURRENT_KINDS`):

* its **dataclass** (:class:`UniformWindSpec`, :class:`WrfWindSpec`, ...): the checked
  values in SI units inside (m s⁻¹, degrees, seconds, epoch seconds, resolved
  :class:`~pathlib.Path`\\ s), and ``where``, the key path its messages start with;
* its **parser**: every check that needs no file content (required and unknown keys,
  types, ranges, units, paths resolved and "file not found"), each problem recorded
  by a :class:`~sailroute.checks.Checker` at its own key's line;
* its **builder**: reads the files and makes the field from the dataclass alone.

:func:`parse_wind_spec` / :func:`parse_current_spec` parse a mapping (raising every
problem at once); :func:`check_wind_spec` / :func:`check_current_spec` record the
problems in a course file's checker instead (the course loader parses every scenario
when it loads).  :func:`sailroute.wind.build.build_wind_field` builds a field from a
spec; :func:`sailroute.wind.build.wind_from_spec` does both.  Spec keys are documented
in ``docs/course-format.md`` and ``docs/design/wind.md``.

A new spec type goes here: its dataclass, its parser and its builder, and one entry
of the registry that pairs them (``WIND_TYPES`` follows from it).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from sailroute.checks import Checker, Problems, real_number, resolve_path, show
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.timeutil import parse_time, to_epoch
from sailroute.units import KNOT, SPEED_UNITS
from sailroute.wind.base import WindField
from sailroute.wind.blended import BlendedWind
from sailroute.wind.current import (
    CurrentField,
    DiamondCurrent,
    UniformCurrent,
    open_netcdf_current,
)
from sailroute.wind.height import DEFAULT_EXPONENT, DEFAULT_EXPONENT_RANGE, DEFAULT_ROUGHNESS_M
from sailroute.wind.measured import (
    DEFAULT_MAX_GAP_S,
    DEFAULT_METHOD,
    DEFAULT_RESAMPLE_S,
    DEFAULT_SMOOTH_S,
    FLEET_METHODS,
    fleet_wind,
    sensor_from_track,
)
from sailroute.wind.ndbc import is_ndbc_text, read_ndbc
from sailroute.wind.stations import (
    CANONICAL_COLUMNS,
    DEFAULT_MISSING,
    TIME_PARTS,
    StationData,
    StationWind,
    parse_offset,
    read_stations,
    resample_stations,
)
from sailroute.wind.uniform import UniformWind
from sailroute.wind.wrf import open_wrf

__all__ = [
    "CURRENT_KINDS",
    "CURRENT_TYPES",
    "MEASURED_MARGIN_S",
    "WIND_KINDS",
    "WIND_TYPES",
    "BlendedWindSpec",
    "BuildContext",
    "CurrentSpec",
    "DiamondCurrentSpec",
    "GribWindSpec",
    "MeasuredWindSpec",
    "NetcdfCurrentSpec",
    "NetcdfWindSpec",
    "SpecKind",
    "StationReadSpec",
    "StationsWindSpec",
    "UniformCurrentSpec",
    "UniformWindSpec",
    "WindSpec",
    "WrfWindSpec",
    "check_current_spec",
    "check_wind_spec",
    "parse_current_spec",
    "parse_wind_spec",
]

BBox = tuple[float, float, float, float]
"""Local-frame box ``(xmin, xmax, ymin, ymax)`` [m] (same order as :class:`Coverage`)."""

Pairs = tuple[tuple[str, Any], ...]
"""A small mapping kept as ``((key, value), ...)`` in file order (hashable, picklable)."""

MEASURED_MARGIN_S = 600.0
"""Records within this of the race window [s] are used by ``type: measured``."""


@dataclass(frozen=True)
class BuildContext:
    """Where a field is built: the course's frame, box and race time.

    Attributes
    ----------
    frame : LocalFrame
        The course's local frame; gridded and station data are mapped into it.
    crop_bbox : tuple of float or None
        Course box ``(xmin, xmax, ymin, ymax)`` [m]; gridded data are cropped to it.
    time_window : tuple of float or None
        Race window ``(t0, t1)`` [epoch s]; slices and records outside it are not read.
    """

    frame: LocalFrame
    crop_bbox: BBox | None = None
    time_window: tuple[float, float] | None = None


def _pairs(d: Mapping[Any, Any] | None) -> Pairs | None:
    return None if d is None else tuple((str(k), v) for k, v in d.items())


def _dict(p: Pairs | None) -> dict[str, Any] | None:
    return None if p is None else dict(p)


def _speed_unit(chk: Checker, spec: Mapping[str, Any]) -> str | None:
    """``speed_unit`` (as written) if it is a known unit; a problem and None if not."""
    unit = chk.string(spec, "speed_unit", None)
    if unit is not None and unit.strip().lower() not in SPEED_UNITS:
        chk.add("speed_unit", f"expected one of 'm/s', 'kn', 'km/h', 'mph'; got {show(unit)}")
        return None
    return unit


def _epoch(chk: Checker, spec: Mapping[str, Any], key: str) -> float | None:
    """``spec[key]`` as an ISO 8601 time [epoch s]; the parser's message recorded if not."""
    try:
        return to_epoch(parse_time(spec[key], where=chk.where(key)))
    except InputError as exc:
        chk.p.extend([str(exc)])
        return None


def _wrapped(where: str, build: Callable[[], Any]) -> Any:
    """``build()``, its :class:`InputError` prefixed with ``where`` (the spec's key path)."""
    try:
        return build()
    except InputError as exc:
        raise type(exc)(f"{where}: {exc}") from None


# ============================================================================ wind: uniform
_UNIFORM_KEYS = ("type", "tws_kn", "tws_ms", "twd_deg", "table", "interpolation", "clamp")


@dataclass(frozen=True, kw_only=True)
class UniformWindSpec:
    """``type: uniform``: one wind everywhere, steady or from a time table.

    Attributes
    ----------
    tws_ms, twd_deg : float or None
        The steady wind [m s⁻¹, degrees from]; None when ``table`` is given.
    table : tuple of (float, float, float) or None
        Rows ``(time [epoch s], tws [m s⁻¹], twd [deg])``, times increasing.
    interpolation : {"linear", "previous"}
        Between the table's rows.
    clamp : bool
        Hold the first/last row outside the table's times.
    where : str
        Message prefix of the spec (``"file:line: scenarios.a.wind"``).
    """

    type: ClassVar[str] = "uniform"
    tws_ms: float | None = None
    twd_deg: float | None = None
    table: tuple[tuple[float, float, float], ...] | None = None
    interpolation: str = "linear"
    clamp: bool = False
    where: str = ""


def _speed(chk: Checker, spec: Mapping[str, Any], required: bool) -> float | None:
    has_kn, has_ms = "tws_kn" in spec, "tws_ms" in spec
    if has_kn and has_ms:
        chk.add("tws_kn", "give either tws_kn or tws_ms, not both")
        return None
    if has_kn:
        v = chk.number(spec, "tws_kn", lo=0.0)
        return None if v is None else v * KNOT
    if has_ms:
        return chk.number(spec, "tws_ms", lo=0.0)
    if required:
        chk.add("tws_kn", "missing required key; give the wind speed as tws_kn or tws_ms")
    return None


def _parse_uniform(spec: Mapping[str, Any], chk: Checker, base_dir: Path) -> UniformWindSpec | None:
    n0 = len(chk.p)
    chk.keys(spec, _UNIFORM_KEYS)
    clamp = chk.boolean(spec, "clamp", False)
    interpolation = chk.choice(spec, "interpolation", ["linear", "previous"], "linear")
    table = spec.get("table")
    if table is None:
        tws = _speed(chk, spec, required=True)
        twd = chk.number(spec, "twd_deg", lo=0.0, hi=360.0)
        return UniformWindSpec(tws_ms=tws, twd_deg=twd, clamp=clamp, where=chk.where())
    for key in ("tws_kn", "tws_ms", "twd_deg"):
        if key in spec:
            chk.add(key, "not allowed together with `table`; put speeds and directions in the rows")
    if not isinstance(table, list) or not table:
        chk.add(
            "table",
            f"expected a non-empty list of rows {{time, tws_kn, twd_deg}}; got {show(table)}",
        )
        return None
    rows: list[tuple[float, float, float]] = []
    tchk = chk.child("table")
    for k, row in enumerate(table):
        rchk = tchk.child(k)
        if not isinstance(row, Mapping):
            rchk.add("time", f"expected a mapping {{time, tws_kn, twd_deg}}; got {show(row)}")
            continue
        rchk.keys(row, ("time", "tws_kn", "tws_ms", "twd_deg"), ("time",))
        t = _epoch(rchk, row, "time") if "time" in row else None
        s = _speed(rchk, row, required=True)
        d = rchk.number(row, "twd_deg", lo=0.0, hi=360.0)
        if t is not None and s is not None and d is not None:
            rows.append((t, s, d))
    if len(chk.p) == n0:
        for k in range(1, len(rows)):
            if rows[k][0] <= rows[k - 1][0]:
                tchk.child(k).add("time", "table times must increase strictly from row to row")
    return UniformWindSpec(
        table=tuple(rows), interpolation=interpolation, clamp=clamp, where=chk.where()
    )


def _build_uniform(spec: UniformWindSpec, ctx: BuildContext) -> WindField:
    if spec.table is None:
        assert spec.tws_ms is not None and spec.twd_deg is not None  # checked by the parser
        return UniformWind(spec.tws_ms, spec.twd_deg, clamp=spec.clamp)
    times, speeds, dirs = (list(c) for c in zip(*spec.table, strict=True))
    return UniformWind(
        speeds, dirs, times=times, interpolation=spec.interpolation, clamp=spec.clamp
    )


# ============================================================================ wind: wrf
_WRF_KEYS = (
    "type",
    "path",
    "height_m",
    "time_step_min",
    "interpolation",
    "levels",
    "shear",
    "fallback_exponent",
    "exponent_range",
    "roughness_m",
    "margin_m",
    "clamp",
)


@dataclass(frozen=True, kw_only=True)
class WrfWindSpec:
    """``type: wrf``: a WRF ``wrfout`` file (:func:`~sailroute.wind.wrf.open_wrf`).

    Attributes
    ----------
    path : Path
        The file, resolved against the course file's folder.
    height_m : float or None
        Wind wanted at this height [m] (None: the file's own 10 m wind).
    time_step_s : float or None
        Resample the file's times to this step [s] (``time_step_min`` × 60).
    interpolation, levels, shear : str
        As the keys of the same names.
    fallback_exponent : float
        Power-law exponent where the file gives no profile.
    exponent_range : tuple of float
        ``(min, max)`` of a fitted exponent.
    roughness_m : float
        Surface roughness of the log profile [m].
    margin_m : float or None
        Crop margin around the course [m].
    clamp : bool
        Hold the edge values outside the data.
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "wrf"
    path: Path
    height_m: float | None = None
    time_step_s: float | None = None
    interpolation: str = "linear"
    levels: str = "auto"
    shear: str = "power"
    fallback_exponent: float = DEFAULT_EXPONENT
    exponent_range: tuple[float, float] = DEFAULT_EXPONENT_RANGE
    roughness_m: float = DEFAULT_ROUGHNESS_M
    margin_m: float | None = None
    clamp: bool = False
    where: str = ""


def _pair(value: Any, ok: Callable[[float, float], bool]) -> tuple[float, float] | None:
    """``[a, b]`` (two numbers with ``ok(a, b)``) as a tuple of floats, else None."""
    if (
        not isinstance(value, list | tuple)
        or len(value) != 2
        or not all(isinstance(a, int | float) and not isinstance(a, bool) for a in value)
        or not ok(value[0], value[1])
    ):
        return None
    return (float(value[0]), float(value[1]))


def _minutes_to_s(v: float | None) -> float | None:
    return None if v is None else v * 60.0


def _parse_wrf(spec: Mapping[str, Any], chk: Checker, base_dir: Path) -> WrfWindSpec | None:
    """Check a ``type: wrf`` spec (also the ``wrf`` part of ``type: blended``)."""
    chk.keys(spec, _WRF_KEYS, ("path",))
    path = chk.file(spec, "path", base_dir)
    height_m = chk.number(spec, "height_m", None, lo=0.0, lo_open=True)
    step = chk.number(spec, "time_step_min", None, lo=0.0, lo_open=True)
    interpolation = chk.choice(spec, "interpolation", ["linear", "nearest"], "linear")
    levels = chk.choice(spec, "levels", ["auto", "u10", "model"], "auto")
    shear = chk.choice(spec, "shear", ["power", "log"], "power")
    fallback = chk.number(spec, "fallback_exponent", DEFAULT_EXPONENT, lo=-1.0, hi=1.0)
    roughness = chk.number(spec, "roughness_m", DEFAULT_ROUGHNESS_M, lo=0.0, lo_open=True)
    margin_m = chk.number(spec, "margin_m", None, lo=0.0)
    clamp = chk.boolean(spec, "clamp", False)
    er: tuple[float, float] | None = DEFAULT_EXPONENT_RANGE
    if "exponent_range" in spec:
        er = _pair(spec["exponent_range"], lambda a, b: a < b)
        if er is None:
            chk.add(
                "exponent_range",
                f"expected [min, max] with min < max, e.g. [0.0, 0.6]; "
                f"got {spec['exponent_range']!r}",
            )
    if levels == "model" and "height_m" not in spec:
        chk.add(
            "levels",
            "'model' levels are only used for a height correction; set height_m "
            "(e.g. 2.68 for a Laser's centre of effort) or use levels: auto",
        )
    if path is None:  # (reported)
        return None
    return WrfWindSpec(
        path=path,
        height_m=height_m,
        time_step_s=_minutes_to_s(step),
        interpolation=interpolation,
        levels=levels,
        shear=shear,
        fallback_exponent=fallback,
        exponent_range=er or DEFAULT_EXPONENT_RANGE,
        roughness_m=roughness,
        margin_m=margin_m,
        clamp=clamp,
        where=chk.where(),
    )


def _s_to_minutes(v: float | None) -> float | None:
    return None if v is None else v / 60.0


def _build_wrf(spec: WrfWindSpec, ctx: BuildContext) -> WindField:
    return _wrapped(
        spec.where,
        lambda: open_wrf(
            spec.path,
            ctx.frame,
            bbox=ctx.crop_bbox,
            time_window=ctx.time_window,
            height_m=spec.height_m,
            time_step_min=_s_to_minutes(spec.time_step_s),
            interpolation=spec.interpolation,
            levels=spec.levels,
            shear=spec.shear,
            fallback_exponent=spec.fallback_exponent,
            exponent_range=spec.exponent_range,
            roughness_m=spec.roughness_m,
            margin_m=spec.margin_m,
            clamp=spec.clamp,
        ),
    )


# ============================================================================ wind: netcdf, grib
_GRID_KEYS = (
    "type",
    "path",
    "variables",
    "time",
    "data_height_m",
    "speed_unit",
    "height_m",
    "shear",
    "exponent",
    "roughness_m",
    "time_step_min",
    "interpolation",
    "steady",
    "margin_m",
    "clamp",
    "select",
)
_CF_ONLY = ("variables", "time", "data_height_m", "speed_unit", "steady", "select")


@dataclass(frozen=True, kw_only=True)
class NetcdfWindSpec:
    """``type: netcdf``: wind on latitude/longitude (CF NetCDF), or a ``wrfout`` file.

    Attributes
    ----------
    path : Path
        The file, resolved against the course file's folder.
    variables : tuple of (str, str) or None
        Data key (``u``, ``v``, ``speed``, ``direction``, ...) -> variable name.
    time : float or None
        The time of a file without a time axis [epoch s].
    data_height_m, height_m : float or None
        Height of the data and height wanted [m].
    speed_unit : str or None
        Unit of the file's speeds, as written (``kn``, ``m/s``, ...).
    shear : {"power", "log"}
        Height profile.
    exponent, roughness_m : float
        Power-law exponent; roughness of the log profile [m].
    time_step_s : float or None
        Resample to this step [s] (``time_step_min`` × 60).
    interpolation : {"linear", "nearest"}
        In time.
    steady : bool
        Use a file of one time for the whole race.
    margin_m : float or None
        Crop margin around the course [m].
    clamp : bool
        Hold the edge values outside the data.
    select : tuple of (str, int) or None
        Dimension name -> index (an ensemble member, a level).
    cf_keys : tuple of str
        The latitude/longitude-only keys the spec gives (refused for a ``wrfout`` file,
        which is known only once the file is opened).
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "netcdf"
    path: Path
    variables: Pairs | None = None
    time: float | None = None
    data_height_m: float | None = None
    speed_unit: str | None = None
    height_m: float | None = None
    shear: str = "power"
    exponent: float = DEFAULT_EXPONENT
    roughness_m: float = DEFAULT_ROUGHNESS_M
    time_step_s: float | None = None
    interpolation: str = "linear"
    steady: bool = False
    margin_m: float | None = None
    clamp: bool = False
    select: tuple[tuple[str, int], ...] | None = None
    cf_keys: tuple[str, ...] = ()
    where: str = ""

    def options(self) -> dict[str, Any]:
        """Keyword arguments of :func:`~sailroute.wind.cf.open_netcdf` (bar path, frame)."""
        return {
            "variables": _dict(self.variables),
            "time": self.time,
            "data_height_m": self.data_height_m,
            "speed_unit": self.speed_unit,
            "height_m": self.height_m,
            "shear": self.shear,
            "exponent": self.exponent,
            "roughness_m": self.roughness_m,
            "time_step_min": _s_to_minutes(self.time_step_s),
            "interpolation": self.interpolation,
            "steady": self.steady,
            "margin_m": self.margin_m,
            "clamp": self.clamp,
            "select": _dict(self.select),
        }


@dataclass(frozen=True, kw_only=True)
class GribWindSpec(NetcdfWindSpec):
    """``type: grib``: wind on latitude/longitude from GRIB (the ``grib`` extra).

    The attributes of :class:`NetcdfWindSpec`, and ``filter`` (cfgrib's
    ``filter_by_keys``, as pairs).
    """

    type: ClassVar[str] = "grib"
    filter: Pairs | None = None


def _select(chk: Checker, spec: Mapping[str, Any]) -> tuple[tuple[str, int], ...] | None:
    sel = chk.mapping(spec, "select", None)
    if sel is None:
        return None
    bad = {k: v for k, v in sel.items() if not isinstance(v, int) or isinstance(v, bool) or v < 0}
    if bad:
        chk.add(
            "select",
            "expected a mapping of dimension name to an index >= 0, e.g. "
            f"{{number: 3}}; got {dict(sel)!r}",
        )
        return None
    return tuple((str(k), int(v)) for k, v in sel.items())


def _variables(chk: Checker, spec: Mapping[str, Any]) -> Pairs | None:
    var = chk.mapping(spec, "variables", None)
    if var is None:
        return None
    from sailroute.wind.cf import DATA_KEYS

    vchk = chk.child("variables")
    vchk.keys(var, DATA_KEYS)
    for k, v in var.items():
        if k in DATA_KEYS and (not isinstance(v, str) or not v.strip()):
            vchk.add(str(k), f"expected a variable name; got {show(v)}")
    if not (
        {"u", "v"} <= set(var)
        or {"speed", "direction"} <= set(var)
        or not set(var) & {"u", "v", "speed", "direction"}
    ):
        chk.add(
            "variables", "give both u and v, or both speed and direction, e.g. {u: u10, v: v10}"
        )
    return _pairs(var)


def _grid_fields(
    spec: Mapping[str, Any], chk: Checker, base_dir: Path, extra: tuple[str, ...] = ()
) -> dict[str, Any]:
    """The fields of a ``type: netcdf`` / ``type: grib`` spec, problems to ``chk``."""
    chk.keys(spec, (*_GRID_KEYS, *extra))  # a missing path is reported by chk.file
    fields: dict[str, Any] = {
        "path": chk.file(spec, "path", base_dir),
        "height_m": chk.number(spec, "height_m", None, lo=0.0, lo_open=True),
        "data_height_m": chk.number(spec, "data_height_m", None, lo=0.0, lo_open=True),
        "shear": chk.choice(spec, "shear", ["power", "log"], "power"),
        "exponent": chk.number(spec, "exponent", DEFAULT_EXPONENT, lo=-1.0, hi=1.0),
        "roughness_m": chk.number(spec, "roughness_m", DEFAULT_ROUGHNESS_M, lo=0.0, lo_open=True),
        "time_step_s": _minutes_to_s(chk.number(spec, "time_step_min", None, lo=0.0, lo_open=True)),
        "interpolation": chk.choice(spec, "interpolation", ["linear", "nearest"], "linear"),
        "steady": chk.boolean(spec, "steady", False),
        "margin_m": chk.number(spec, "margin_m", None, lo=0.0),
        "clamp": chk.boolean(spec, "clamp", False),
    }
    fields["select"] = _select(chk, spec)
    fields["speed_unit"] = _speed_unit(chk, spec)
    fields["variables"] = _variables(chk, spec)
    fields["time"] = _epoch(chk, spec, "time") if "time" in spec else None
    fields["cf_keys"] = tuple(k for k in _CF_ONLY if k in spec)
    fields["where"] = chk.where()
    return fields


def _parse_netcdf(spec: Mapping[str, Any], chk: Checker, base_dir: Path) -> NetcdfWindSpec | None:
    fields = _grid_fields(spec, chk, base_dir)
    return None if fields["path"] is None else NetcdfWindSpec(**fields)


def _parse_grib(spec: Mapping[str, Any], chk: Checker, base_dir: Path) -> GribWindSpec | None:
    fields = _grid_fields(spec, chk, base_dir, extra=("filter",))
    filt = _pairs(chk.mapping(spec, "filter", None))
    return None if fields["path"] is None else GribWindSpec(**fields, filter=filt)


def _open_netcdf(spec: NetcdfWindSpec, ctx: BuildContext) -> WindField:
    from sailroute.wind.cf import is_wrfout, open_netcdf

    opts = spec.options()
    if is_wrfout(spec.path):
        if spec.cf_keys:
            raise InputError(
                f"{spec.path.name} is a WRF wrfout file; {', '.join(spec.cf_keys)} only "
                "apply to latitude/longitude files (use the `type: wrf` keys)"
            )
        for k in _CF_ONLY:
            opts.pop(k)
        opts["fallback_exponent"] = opts.pop("exponent")
        return open_wrf(
            spec.path, ctx.frame, bbox=ctx.crop_bbox, time_window=ctx.time_window, **opts
        )
    return open_netcdf(
        spec.path, ctx.frame, bbox=ctx.crop_bbox, time_window=ctx.time_window, **opts
    )


def _build_netcdf(spec: NetcdfWindSpec, ctx: BuildContext) -> WindField:
    return _wrapped(spec.where, lambda: _open_netcdf(spec, ctx))


def _build_grib(spec: GribWindSpec, ctx: BuildContext) -> WindField:
    from sailroute.wind.cf import open_grib

    return _wrapped(
        spec.where,
        lambda: open_grib(
            spec.path,
            ctx.frame,
            filter_by_keys=_dict(spec.filter),
            bbox=ctx.crop_bbox,
            time_window=ctx.time_window,
            **spec.options(),
        ),
    )


# ============================================================================ wind: stations
_READ_KEYS = (
    "path",
    "format",
    "speed_unit",
    "columns",
    "timezone",
    "resample_s",
    "station",
    "position",
    "measurement_height_m",
    "missing",
)
_STATION_FIELD_KEYS = (
    "method",
    "power",
    "radius_m",
    "max_gap_s",
    "height_m",
    "shear",
    "exponent",
    "roughness_m",
    "clamp",
)


@dataclass(frozen=True, kw_only=True)
class StationReadSpec:
    """How to read a station file (the ``stations`` keys that :func:`read_stations` takes).

    Attributes
    ----------
    path : Path
        The file, resolved against the course file's folder.
    format : {"auto", "csv", "ndbc"}
        File format (``auto``: NDBC text is recognised, else CSV).
    speed_unit : str or None
        Unit of the file's speeds, as written.
    columns : tuple of (str, str) or None
        Canonical column -> the file's column.
    timezone : str or None
        UTC offset of times written without one (``+02:00``).
    resample_s : float or None
        Resample the records to this step [s].
    station : str or None
        The station id of a single-station file.
    position : tuple of float or None
        ``(lat, lon)`` [deg] of a file that does not give it.
    height_m : float or None
        Measurement height [m] (``measurement_height_m``).
    missing : tuple of str or None
        Markers of a missing value (the defaults and the spec's).
    where : str
        Message prefix of the part of the spec these keys are in.
    """

    path: Path
    format: str = "auto"
    speed_unit: str | None = None
    columns: Pairs | None = None
    timezone: str | None = None
    resample_s: float | None = None
    station: str | None = None
    position: tuple[float, float] | None = None
    height_m: float | None = None
    missing: tuple[str, ...] | None = None
    where: str = ""


@dataclass(frozen=True, kw_only=True)
class StationsWindSpec:
    """``type: stations``: measured wind interpolated between stations (:class:`StationWind`).

    Attributes
    ----------
    read : StationReadSpec
        The station file and how to read it.
    method : {"idw", "rbf"}
        Interpolation between stations.
    power : float
        Inverse-distance power.
    radius_m : float
        Smoothing radius [m].
    max_gap_s : float
        Longest gap between a station's records bridged in time [s].
    height_m : float or None
        Height wanted [m].
    shear : {"power", "log"}
        Height profile.
    exponent, roughness_m : float
        Power-law exponent; roughness of the log profile [m].
    clamp : bool
        Hold the edge values outside the data.
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "stations"
    read: StationReadSpec
    method: str = "idw"
    power: float = 2.0
    radius_m: float = 2000.0
    max_gap_s: float = 1800.0
    height_m: float | None = None
    shear: str = "power"
    exponent: float = DEFAULT_EXPONENT
    roughness_m: float = DEFAULT_ROUGHNESS_M
    clamp: bool = False
    where: str = ""


def _columns(chk: Checker, spec: Mapping[str, Any]) -> Pairs | None:
    cols = chk.mapping(spec, "columns", None)
    if cols is None:
        return None
    for k, v in cols.items():
        if k not in CANONICAL_COLUMNS and k not in TIME_PARTS:
            chk.child("columns").add(
                str(k),
                "unknown canonical column; expected one of "
                + ", ".join((*CANONICAL_COLUMNS, *TIME_PARTS)),
            )
        elif not isinstance(v, str):
            chk.child("columns").add(str(k), f"expected a column name; got {show(v)}")
    return _pairs(cols)


def _timezone(chk: Checker, spec: Mapping[str, Any]) -> str | None:
    tz = chk.string(spec, "timezone", None)
    if tz is not None:
        try:
            parse_offset(tz)
        except InputError as exc:
            chk.add("timezone", str(exc).split(": ", 1)[-1])
            return None
    return tz


def _position(chk: Checker, spec: Mapping[str, Any]) -> tuple[float, float] | None:
    pos = chk.mapping(spec, "position", None)
    if pos is None:
        return None
    pchk = chk.child("position")
    pchk.keys(pos, ("lat", "lon"), ("lat", "lon"))
    la = pchk.number(pos, "lat", lo=-90.0, hi=90.0) if "lat" in pos else None
    lo = pchk.number(pos, "lon", lo=-180.0, hi=360.0) if "lon" in pos else None
    return None if la is None or lo is None else (la, lo)


def _missing(chk: Checker, spec: Mapping[str, Any]) -> tuple[str, ...] | None:
    miss = spec.get("missing")
    if miss is None:
        return None
    if not isinstance(miss, list) or not all(isinstance(m, str | int | float) for m in miss):
        chk.add("missing", f"expected a list of markers such as ['', 'MM', '999'], got {miss!r}")
        return None
    return tuple(DEFAULT_MISSING) + tuple(str(m) for m in miss)


def _parse_read(spec: Mapping[str, Any], chk: Checker, base_dir: Path) -> StationReadSpec | None:
    """The station-file keys of a ``stations`` spec (or of a blend's ``stations`` part)."""
    path = chk.file(spec, "path", base_dir)
    fmt = chk.choice(spec, "format", ["auto", "csv", "ndbc"], "auto")
    unit = _speed_unit(chk, spec)
    columns = _columns(chk, spec)
    tz = _timezone(chk, spec)
    resample_s = chk.number(spec, "resample_s", None, lo=0.0, lo_open=True)
    st = spec.get("station")
    if st is not None and not isinstance(st, str | int):
        chk.add("station", f"expected a station id; got {show(st)}")
    position = _position(chk, spec)
    height_m = chk.number(spec, "measurement_height_m", None, lo=0.0, lo_open=True)
    missing = _missing(chk, spec)
    if path is None:  # (reported)
        return None
    return StationReadSpec(
        path=path,
        format=fmt,
        speed_unit=unit,
        columns=columns,
        timezone=tz,
        resample_s=resample_s,
        station=None if st is None else str(st),
        position=position,
        height_m=height_m,
        missing=missing,
        where=chk.where(),
    )


def _parse_stations(
    spec: Mapping[str, Any], chk: Checker, base_dir: Path
) -> StationsWindSpec | None:
    chk.keys(spec, ("type", *_READ_KEYS, *_STATION_FIELD_KEYS), ("path",))
    read = _parse_read(spec, chk, base_dir)
    fields = {
        "method": chk.choice(spec, "method", ["idw", "rbf"], "idw"),
        "power": chk.number(spec, "power", 2.0, lo=0.0, lo_open=True),
        "radius_m": chk.number(spec, "radius_m", 2000.0, lo=0.0),
        "max_gap_s": chk.number(spec, "max_gap_s", 1800.0, lo=0.0, lo_open=True),
        "height_m": chk.number(spec, "height_m", None, lo=0.0, lo_open=True),
        "shear": chk.choice(spec, "shear", ["power", "log"], "power"),
        "exponent": chk.number(spec, "exponent", DEFAULT_EXPONENT, lo=-1.0, hi=1.0),
        "roughness_m": chk.number(spec, "roughness_m", DEFAULT_ROUGHNESS_M, lo=0.0, lo_open=True),
        "clamp": chk.boolean(spec, "clamp", False),
    }
    if read is None:  # (reported)
        return None
    return StationsWindSpec(read=read, **fields, where=chk.where())


def _read_station_data(spec: StationReadSpec) -> StationData:
    """The records of a station file, its :class:`InputError` prefixed with ``spec.where``."""

    def read() -> StationData:
        if spec.format == "ndbc" or (spec.format == "auto" and is_ndbc_text(spec.path)):
            return _read_ndbc_checked(spec)
        opts: dict[str, Any] = {
            "speed_unit": spec.speed_unit,
            "columns": _dict(spec.columns),
            "timezone": spec.timezone,
            "resample_s": spec.resample_s,
            "station": spec.station,
            "height_m": spec.height_m,
        }
        if spec.position is not None:
            opts["position"] = spec.position
        if spec.missing is not None:
            opts["missing"] = spec.missing
        return read_stations(spec.path, **opts)

    return _wrapped(spec.where, read)


def _read_ndbc_checked(spec: StationReadSpec) -> StationData:
    """NDBC realtime text: only position, station, height and resample_s apply."""
    if spec.position is None:
        raise InputError(
            f"{spec.path.name} is NDBC text, which does not carry the buoy's position; "
            "add `position: {lat: ..., lon: ...}` (from the station's NDBC page, "
            "e.g. 41008: {lat: 31.400, lon: -80.866})"
        )
    given = {"columns": spec.columns, "speed_unit": spec.speed_unit, "timezone": spec.timezone}
    bad = [k for k, v in given.items() if v is not None]
    if bad:
        raise InputError(
            f"{', '.join(bad)}: not used for NDBC text (its columns, m/s and UTC "
            "are fixed by the format); remove them"
        )
    data = read_ndbc(
        spec.path, position=spec.position, station=spec.station, height_m=spec.height_m
    )
    if spec.resample_s is not None:
        data = resample_stations(data, spec.resample_s)
    return data


def _build_stations(spec: StationsWindSpec, ctx: BuildContext) -> WindField:
    data = _read_station_data(spec.read)
    return _wrapped(
        spec.where,
        lambda: StationWind(
            data,
            ctx.frame,
            name=f"station wind {data.source}",
            time_window=ctx.time_window,
            method=spec.method,
            power=spec.power,
            radius_m=spec.radius_m,
            max_gap_s=spec.max_gap_s,
            height_m=spec.height_m,
            shear=spec.shear,
            exponent=spec.exponent,
            roughness_m=spec.roughness_m,
            clamp=spec.clamp,
        ),
    )


# ============================================================================ wind: blended
_BLEND_KEYS = (
    "type",
    "wrf",
    "stations",
    "length_scale_m",
    "time_scale_s",
    "min_speed_ms",
    "ratio_range",
    "max_offset_deg",
    "clamp",
)
DEFAULT_RATIO_RANGE: tuple[float, float] | None = None
"""``ratio_range`` when the spec has none (None: :class:`BlendedWind`'s own default)."""


@dataclass(frozen=True, kw_only=True)
class BlendedWindSpec:
    """``type: blended``: a WRF field corrected by stations (:class:`BlendedWind`).

    Attributes
    ----------
    wrf : WrfWindSpec
        The model part (``wrf:``).
    stations : StationReadSpec
        The station file (``stations:``).
    length_scale_m : float
        Spatial scale of the correction [m].
    time_scale_s : float
        Time scale of the correction [s].
    min_speed_ms : float
        Below this speed [m s⁻¹] no speed ratio is taken.
    ratio_range : tuple of float or None
        ``(min, max)`` speed ratio (None: the blend's default).
    max_offset_deg : float
        Largest direction correction [deg].
    clamp : bool
        Hold the edge values outside the data.
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "blended"
    wrf: WrfWindSpec
    stations: StationReadSpec
    length_scale_m: float = 2000.0
    time_scale_s: float = 600.0
    min_speed_ms: float = 1.0
    ratio_range: tuple[float, float] | None = DEFAULT_RATIO_RANGE
    max_offset_deg: float = 60.0
    clamp: bool = False
    where: str = ""


def _parse_blended(spec: Mapping[str, Any], chk: Checker, base_dir: Path) -> BlendedWindSpec | None:
    chk.keys(spec, _BLEND_KEYS, ("wrf", "stations"))
    wspec = chk.mapping(spec, "wrf")
    sspec = chk.mapping(spec, "stations")
    wrf = stations = None
    if wspec is not None:
        wchk = chk.child("wrf")
        if wspec.get("type", "wrf") != "wrf":
            wchk.add("type", f"expected 'wrf' (or leave it out); got {show(wspec.get('type'))}")
        wrf = _parse_wrf(
            {k: v for k, v in wspec.items() if k != "type"} | {"type": "wrf"}, wchk, base_dir
        )
    if sspec is not None:
        schk = chk.child("stations")
        schk.keys(sspec, ("type", *_READ_KEYS), ("path",))
        stations = _parse_read(sspec, schk, base_dir)
    length_scale_m = chk.number(spec, "length_scale_m", 2000.0, lo=0.0, lo_open=True)
    time_scale_s = chk.number(spec, "time_scale_s", 600.0, lo=0.0)
    min_speed_ms = chk.number(spec, "min_speed_ms", 1.0, lo=0.0)
    max_offset_deg = chk.number(spec, "max_offset_deg", 60.0, lo=0.0, hi=180.0)
    clamp = chk.boolean(spec, "clamp", False)
    rr = DEFAULT_RATIO_RANGE
    if "ratio_range" in spec:
        rr = _pair(spec["ratio_range"], lambda a, b: 0 < a <= 1 <= b)
        if rr is None:
            chk.add(
                "ratio_range",
                f"expected [min, max] with 0 < min <= 1 <= max, e.g. [0.5, 2.0]; "
                f"got {spec['ratio_range']!r}",
            )
    if wrf is None or stations is None:  # (reported)
        return None
    return BlendedWindSpec(
        wrf=wrf,
        stations=stations,
        length_scale_m=length_scale_m,
        time_scale_s=time_scale_s,
        min_speed_ms=min_speed_ms,
        ratio_range=rr,
        max_offset_deg=max_offset_deg,
        clamp=clamp,
        where=chk.where(),
    )


def _build_blended(spec: BlendedWindSpec, ctx: BuildContext) -> WindField:
    base = _build_wrf(spec.wrf, ctx)
    data = _read_station_data(spec.stations)
    opts: dict[str, Any] = {
        "length_scale_m": spec.length_scale_m,
        "time_scale_s": spec.time_scale_s,
        "min_speed_ms": spec.min_speed_ms,
        "max_offset_deg": spec.max_offset_deg,
        "clamp": spec.clamp,
    }
    if spec.ratio_range is not None:
        opts["ratio_range"] = spec.ratio_range
    return _wrapped(
        spec.where,
        lambda: BlendedWind(
            base,
            data,
            ctx.frame,
            height_m=spec.wrf.height_m,
            exponent=spec.wrf.fallback_exponent,
            name=f"blended wind ({spec.wrf.path.name} + {Path(data.source).name})",
            **opts,
        ),
    )


# ============================================================================ wind: measured
_MEASURED_KEYS = (
    "type",
    "tracks",
    "speed_unit",
    "time_zone",
    "method",
    "estimate_bias",
    "resample_s",
    "smooth_s",
    "max_gap_s",
    "radius_m",
    "clamp",
)


@dataclass(frozen=True, kw_only=True)
class MeasuredWindSpec:
    """``type: measured``: the fleet's measured wind from boat logs (``fleet_wind(...).field``).

    Attributes
    ----------
    tracks : tuple of Path
        The boat logs, resolved against the course file's folder.
    track_wheres : tuple of str
        Message prefix of each log's entry (``"...wind.tracks[0]"``).
    speed_unit, time_zone : str or None
        As written; passed to the log reader.
    method : str
        How the fleet's measurements make one field.
    estimate_bias : bool
        Estimate and remove each boat's instrument bias.
    resample_s, smooth_s, max_gap_s : float
        Resampling step, smoothing window, longest bridged gap [s].
    radius_m : float
        Spatial radius of the fleet field [m].
    clamp : bool
        Hold the edge values outside the data.
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "measured"
    tracks: tuple[Path, ...]
    track_wheres: tuple[str, ...] = ()
    speed_unit: str | None = None
    time_zone: str | None = None
    method: str = DEFAULT_METHOD
    estimate_bias: bool = True
    resample_s: float = DEFAULT_RESAMPLE_S
    smooth_s: float = DEFAULT_SMOOTH_S
    max_gap_s: float = DEFAULT_MAX_GAP_S
    radius_m: float = 2000.0
    clamp: bool = False
    where: str = ""


def _parse_measured(spec: Mapping[str, Any], chk: Checker, base_dir: Path) -> MeasuredWindSpec:
    chk.keys(spec, _MEASURED_KEYS, ("tracks",))
    raw = spec.get("tracks")
    paths: list[Path] = []
    wheres: list[str] = []
    if raw is not None:
        if not isinstance(raw, list) or not raw or not all(isinstance(p, str) for p in raw):
            chk.add("tracks", f"expected a non-empty list of log paths; got {show(raw)}")
        else:
            tchk = chk.child("tracks")
            for k, p in enumerate(raw):
                tchk.file(raw, k, base_dir, value=p)
                paths.append(resolve_path(base_dir, p))
                wheres.append(chk.where(f"tracks[{k}]"))
    return MeasuredWindSpec(
        tracks=tuple(paths),
        track_wheres=tuple(wheres),
        speed_unit=_speed_unit(chk, spec),
        time_zone=chk.string(spec, "time_zone", None),
        method=chk.choice(spec, "method", list(FLEET_METHODS), DEFAULT_METHOD),
        estimate_bias=chk.boolean(spec, "estimate_bias", True),
        resample_s=chk.number(spec, "resample_s", DEFAULT_RESAMPLE_S, lo=0.0),
        smooth_s=chk.number(spec, "smooth_s", DEFAULT_SMOOTH_S, lo=0.0),
        max_gap_s=chk.number(spec, "max_gap_s", DEFAULT_MAX_GAP_S, lo=0.0, lo_open=True),
        radius_m=chk.number(spec, "radius_m", 2000.0, lo=0.0),
        clamp=chk.boolean(spec, "clamp", False),
        where=chk.where(),
    )


def _build_measured(spec: MeasuredWindSpec, ctx: BuildContext) -> WindField:
    from sailroute.track.read import read_track  # track reads through wind.stations: late

    def sensor(p: Path) -> Any:
        return sensor_from_track(
            read_track(p, speed_unit=spec.speed_unit, time_zone=spec.time_zone),
            smooth_s=spec.smooth_s,
            max_gap_s=spec.max_gap_s,
        )

    series = []
    for p, where in zip(spec.tracks, spec.track_wheres, strict=True):
        s = _wrapped(where, functools.partial(sensor, p))
        if ctx.time_window is not None:
            w0, w1 = ctx.time_window
            cut = s.between(w0 - MEASURED_MARGIN_S, w1 + MEASURED_MARGIN_S)
            if len(cut) < 2:
                raise InputError(
                    f"{where}: {p.name} has no wind records within "
                    f"{MEASURED_MARGIN_S:g} s of the race window; use the logs of "
                    "this race"
                )
            s = cut
        series.append(s)
    fw = _wrapped(
        spec.where,
        lambda: fleet_wind(
            series,
            ctx.frame,
            method=spec.method,
            estimate_bias=spec.estimate_bias,
            resample_s=spec.resample_s,
            radius_m=spec.radius_m,
            clamp=spec.clamp,
            options={"name": "measured wind (" + ", ".join(s.boat for s in series) + ")"},
        ),
    )
    return fw.field


# ============================================================================ currents
_CURRENT_UNIFORM_KEYS = ("type", "speed_kn", "speed_ms", "set_deg")
_CURRENT_DIAMOND_KEYS = ("type", "high_water", "table", "rate_unit", "clamp")
_CURRENT_NETCDF_KEYS = (
    "type",
    "path",
    "variables",
    "speed_unit",
    "select",
    "interpolation",
    "steady",
    "clamp",
)


@dataclass(frozen=True, kw_only=True)
class UniformCurrentSpec:
    """``type: uniform``: one rate and set everywhere, all the time.

    Attributes
    ----------
    rate_ms : float
        Rate [m s⁻¹] (``speed_kn`` converted, or ``speed_ms``).
    set_deg : float
        Set: the direction the water flows towards [deg].
    clamp : bool
        Always False (a uniform current covers everything; not a key).
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "uniform"
    rate_ms: float
    set_deg: float
    clamp: bool = False
    where: str = ""


def _current_rate(chk: Checker, spec: Mapping[str, Any]) -> float | None:
    """The rate of a uniform current [m s⁻¹] from ``speed_kn`` or ``speed_ms``."""
    if "speed_kn" in spec and "speed_ms" in spec:
        chk.add("speed_kn", "give either speed_kn or speed_ms, not both")
        return None
    if "speed_ms" in spec:
        return chk.number(spec, "speed_ms", lo=0.0)
    if "speed_kn" in spec:
        rate = chk.number(spec, "speed_kn", lo=0.0)
        return None if rate is None else rate * KNOT
    chk.add("speed_kn", "missing required key; give the rate as speed_kn or speed_ms")
    return None


def _parse_uniform_current(
    spec: Mapping[str, Any], chk: Checker, base_dir: Path
) -> UniformCurrentSpec | None:
    chk.keys(spec, _CURRENT_UNIFORM_KEYS, ("set_deg",))
    rate = _current_rate(chk, spec)
    set_deg = chk.number(spec, "set_deg", lo=0.0, hi=360.0) if "set_deg" in spec else None
    if rate is None or set_deg is None:  # (reported)
        return None
    return UniformCurrentSpec(rate_ms=rate, set_deg=set_deg, where=chk.where())


def _build_uniform_current(spec: UniformCurrentSpec, ctx: BuildContext) -> CurrentField:
    return UniformCurrent(spec.rate_ms, spec.set_deg)


@dataclass(frozen=True, kw_only=True)
class DiamondCurrentSpec:
    """``type: diamonds``: a tidal-diamond table of set and rate by hour from high water.

    Attributes
    ----------
    high_water : float
        The time of high water [epoch s].
    table : tuple of (float, float, float)
        Rows ``(hour from high water, set [deg], rate [m s⁻¹])``, hours increasing.
    clamp : bool
        Hold the first/last row outside the table's hours.
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "diamonds"
    high_water: float
    table: tuple[tuple[float, float, float], ...]
    clamp: bool = False
    where: str = ""


def _diamond_rows(chk: Checker, table: Any, scale: float) -> list[tuple[float, float, float]]:
    """The rows ``(hour, set_deg, rate_ms)`` of a tidal-diamond table, problems to ``chk``."""
    rows: list[tuple[float, float, float]] = []
    tchk = chk.child("table")
    for k, row in enumerate(table):
        ok = isinstance(row, list | tuple) and len(row) == 3 and all(real_number(a) for a in row)
        if not ok:
            tchk.add(
                k,
                f"expected [hour, set_deg, rate_{'kn' if scale != 1 else 'ms'}]"
                f" (three numbers); got {row!r}",
            )
        elif not (0.0 <= row[1] <= 360.0 and row[2] >= 0):
            tchk.add(k, f"expected a set in [0, 360] and a rate >= 0; got {row!r}")
        elif rows and row[0] <= rows[-1][0]:
            tchk.add(
                k,
                f"the hours must increase strictly from row to row "
                f"({row[0]:g} after {rows[-1][0]:g})",
            )
        else:
            rows.append((float(row[0]), float(row[1]), float(row[2]) * scale))
    return rows


def _parse_diamond_current(
    spec: Mapping[str, Any], chk: Checker, base_dir: Path
) -> DiamondCurrentSpec | None:
    chk.keys(spec, _CURRENT_DIAMOND_KEYS, ("high_water", "table"))
    unit = chk.choice(spec, "rate_unit", ["kn", "m/s"], "kn")
    scale = KNOT if unit == "kn" else 1.0
    clamp = chk.boolean(spec, "clamp", False)
    hw = _epoch(chk, spec, "high_water") if "high_water" in spec else None
    rows: list[tuple[float, float, float]] = []
    table = spec.get("table")
    if "table" in spec and (not isinstance(table, list) or not table):
        chk.add(
            "table",
            "expected a non-empty list of rows [hour, set_deg, rate_kn], "
            f"e.g. [[-6, 250, 0.4], [0, 70, 1.2]]; got {show(table)}",
        )
    elif isinstance(table, list):
        rows = _diamond_rows(chk, table, scale)
    if hw is None:  # (reported)
        return None
    return DiamondCurrentSpec(
        high_water=hw,
        table=tuple(rows),
        clamp=clamp,
        where=chk.where(),
    )


def _build_diamond_current(spec: DiamondCurrentSpec, ctx: BuildContext) -> CurrentField:
    h, s, r = (list(c) for c in zip(*spec.table, strict=True))
    return DiamondCurrent(spec.high_water, h, s, r, clamp=spec.clamp)


@dataclass(frozen=True, kw_only=True)
class NetcdfCurrentSpec:
    """``type: netcdf``: a gridded current (u, v) from a NetCDF file.

    Attributes
    ----------
    path : Path
        The file, resolved against the course file's folder.
    variables : tuple of (str, str) or None
        ``(("u", NAME), ("v", NAME))``: the file's variables (None: found by name).
    speed_unit : str or None
        Unit of the file's speeds, as written.
    select : tuple of (str, int) or None
        Dimension name -> index.
    interpolation : {"linear", "nearest"}
        In time.
    steady : bool
        Use a file of one time for the whole race.
    clamp : bool
        Hold the edge values outside the data.
    where : str
        Message prefix of the spec.
    """

    type: ClassVar[str] = "netcdf"
    path: Path
    variables: Pairs | None = None
    speed_unit: str | None = None
    select: Pairs | None = None
    interpolation: str = "linear"
    steady: bool = False
    clamp: bool = False
    where: str = ""


def _parse_netcdf_current(
    spec: Mapping[str, Any], chk: Checker, base_dir: Path
) -> NetcdfCurrentSpec | None:
    chk.keys(spec, _CURRENT_NETCDF_KEYS, ("path",))
    path = chk.file(spec, "path", base_dir)
    var = chk.mapping(spec, "variables", None)
    if var is not None and not (
        {"u", "v"} == set(var) and all(isinstance(v, str) and v for v in var.values())
    ):
        chk.add(
            "variables", f"expected {{u: NAME, v: NAME}}, e.g. {{u: uo, v: vo}}; got {dict(var)!r}"
        )
    unit = chk.string(spec, "speed_unit", None)
    if unit is not None and unit.strip().lower() not in SPEED_UNITS:
        chk.add("speed_unit", f"expected one of 'm/s', 'kn', 'km/h', 'mph'; got {show(unit)}")
    sel = chk.mapping(spec, "select", None)
    interpolation = chk.choice(spec, "interpolation", ["linear", "nearest"], "linear")
    steady = chk.boolean(spec, "steady", False)
    clamp = chk.boolean(spec, "clamp", False)
    if path is None:  # (reported)
        return None
    return NetcdfCurrentSpec(
        path=path,
        variables=_pairs(var),
        speed_unit=unit,
        select=_pairs(sel),
        interpolation=interpolation,
        steady=steady,
        clamp=clamp,
        where=chk.where(),
    )


def _build_netcdf_current(spec: NetcdfCurrentSpec, ctx: BuildContext) -> CurrentField:
    return _wrapped(
        spec.where,
        lambda: open_netcdf_current(
            spec.path,
            ctx.frame,
            variables=_dict(spec.variables),
            speed_unit=spec.speed_unit,
            select=_dict(spec.select),
            bbox=ctx.crop_bbox,
            time_window=ctx.time_window,
            interpolation=spec.interpolation,
            steady=spec.steady,
            clamp=spec.clamp,
        ),
    )


# ============================================================================ the registry
WindSpec = (
    UniformWindSpec
    | WrfWindSpec
    | NetcdfWindSpec
    | GribWindSpec
    | StationsWindSpec
    | BlendedWindSpec
    | MeasuredWindSpec
)
"""A parsed wind spec: one of the dataclasses of :data:`WIND_KINDS`."""

CurrentSpec = UniformCurrentSpec | DiamondCurrentSpec | NetcdfCurrentSpec
"""A parsed current spec: one of the dataclasses of :data:`CURRENT_KINDS`."""


@dataclass(frozen=True)
class SpecKind:
    """One spec type: its dataclass, its parser and its builder.

    Attributes
    ----------
    spec : type
        The dataclass (its ``type`` class attribute is the YAML ``type``).
    parse : callable
        ``parse(mapping, checker, base_dir) -> spec or None``: every check that needs no
        file content, problems recorded by the checker (None: a required value is
        missing or invalid).
    build : callable
        ``build(spec, BuildContext) -> field``: reads the files, makes the field.
    """

    spec: type
    parse: Callable[[Mapping[str, Any], Checker, Path], Any]
    build: Callable[[Any, BuildContext], Any]


WIND_KINDS: dict[str, SpecKind] = {
    k.spec.type: k  # type: ignore[attr-defined]
    for k in (
        SpecKind(UniformWindSpec, _parse_uniform, _build_uniform),
        SpecKind(WrfWindSpec, _parse_wrf, _build_wrf),
        SpecKind(NetcdfWindSpec, _parse_netcdf, _build_netcdf),
        SpecKind(GribWindSpec, _parse_grib, _build_grib),
        SpecKind(StationsWindSpec, _parse_stations, _build_stations),
        SpecKind(BlendedWindSpec, _parse_blended, _build_blended),
        SpecKind(MeasuredWindSpec, _parse_measured, _build_measured),
    )
}
"""Wind spec ``type`` -> its dataclass, parser and builder: the one registry of wind types."""

CURRENT_KINDS: dict[str, SpecKind] = {
    k.spec.type: k  # type: ignore[attr-defined]
    for k in (
        SpecKind(UniformCurrentSpec, _parse_uniform_current, _build_uniform_current),
        SpecKind(DiamondCurrentSpec, _parse_diamond_current, _build_diamond_current),
        SpecKind(NetcdfCurrentSpec, _parse_netcdf_current, _build_netcdf_current),
    )
}
"""Current spec ``type`` -> its dataclass, parser and builder."""

WIND_TYPES: tuple[str, ...] = tuple(WIND_KINDS)
"""Values of a wind spec's ``type``."""

CURRENT_TYPES: tuple[str, ...] = tuple(CURRENT_KINDS)
"""Values of a current spec's ``type``."""


def _check(
    kinds: Mapping[str, SpecKind], spec: Any, chk: Checker, base_dir: Path, what: str
) -> Any:
    """Parse ``spec`` (at ``chk.path``) with the parser of its ``type``; None after a problem."""
    if not chk.is_mapping(spec, what):
        return None
    n0 = len(chk.p)
    kind = chk.choice(spec, "type", list(kinds))
    if kind is None:
        return None
    out = kinds[kind].parse(spec, chk, Path(base_dir))
    return out if len(chk.p) == n0 else None


def check_wind_spec(spec: Any, chk: Checker, base_dir: Path) -> WindSpec | None:
    """Parse the wind spec at ``chk.path``, its problems recorded by ``chk``.

    Parameters
    ----------
    spec : mapping
        The wind spec as the YAML gives it.
    chk : Checker
        A checker of the spec's own key path (``scenarios.a.wind``); the course loader
        passes its own, so that the spec's problems are listed with the course's.
    base_dir : Path
        Folder that relative paths resolve against (the course file's).

    Returns
    -------
    WindSpec or None
        None when a problem was recorded.
    """
    return _check(WIND_KINDS, spec, chk, base_dir, "a wind spec mapping (type: ...)")


def check_current_spec(spec: Any, chk: Checker, base_dir: Path) -> CurrentSpec | None:
    """Parse the current spec at ``chk.path``, as :func:`check_wind_spec`."""
    return _check(
        CURRENT_KINDS,
        spec,
        chk,
        base_dir,
        "a current spec mapping, e.g. {type: uniform, speed_kn: 1.5, set_deg: 90}",
    )


def parse_wind_spec(
    spec: Any, *, base_dir: Path, where: str = "", lines: Mapping[str, int] | None = None
) -> WindSpec:
    """Parse a wind spec mapping into its dataclass, every problem raised at once.

    Parameters
    ----------
    spec : mapping
        E.g. ``{"type": "uniform", "tws_kn": 10, "twd_deg": 108}``; ``type`` is one of
        :data:`WIND_TYPES`.
    base_dir : Path
        Folder that relative ``path`` values resolve against.
    where : str
        Message prefix, e.g. ``"courses/x.yaml:12: scenarios.a.wind"``.
    lines : mapping of str to int, optional
        1-based line of each key path of the file ``where`` names: each problem is
        then reported at its own key's line.

    Returns
    -------
    WindSpec

    Raises
    ------
    InputError
        Unknown type, unknown/missing/invalid keys, files not found (all listed at once).

    Examples
    --------
    >>> from pathlib import Path
    >>> s = parse_wind_spec({"type": "uniform", "tws_kn": 10, "twd_deg": 108}, base_dir=Path())
    >>> round(s.tws_ms, 4), s.twd_deg
    (5.1444, 108.0)
    """
    probs = Problems.below(where, lines, what="wind spec")
    out = check_wind_spec(spec, Checker(probs, probs.root), base_dir)
    probs.raise_if_any()
    assert out is not None  # None only with a problem, raised just above
    return out


def parse_current_spec(
    spec: Any, *, base_dir: Path, where: str = "", lines: Mapping[str, int] | None = None
) -> CurrentSpec:
    """Parse a current spec mapping into its dataclass, as :func:`parse_wind_spec`.

    ``type`` is one of :data:`CURRENT_TYPES`; e.g. ``{type: uniform, speed_kn: 1.5,
    set_deg: 90}`` or ``{type: diamonds, high_water, table: [[hour, set_deg, rate_kn],
    ...]}`` (``docs/course-format.md``).
    """
    probs = Problems.below(where, lines, what="current spec")
    out = check_current_spec(spec, Checker(probs, probs.root), base_dir)
    probs.raise_if_any()
    assert out is not None  # None only with a problem, raised just above
    return out
