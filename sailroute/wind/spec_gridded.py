"""Wind specs of model and gridded data: ``uniform``, ``wrf``, ``netcdf`` and ``grib``.

Each type's frozen dataclass (checked values in SI units), its parser (every check that
needs no file content) and its builder (reads the file, makes the field); registered in
:data:`sailroute.wind.specs.WIND_KINDS`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from sailroute.checks import Checker, show
from sailroute.errors import InputError
from sailroute.units import KNOT
from sailroute.wind.base import WindField
from sailroute.wind.height import DEFAULT_EXPONENT, DEFAULT_EXPONENT_RANGE, DEFAULT_ROUGHNESS_M
from sailroute.wind.spec_base import (
    BuildContext,
    Pairs,
    _dict,
    _epoch,
    _pairs,
    _speed_unit,
    _wrapped,
)
from sailroute.wind.uniform import UniformWind

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
    from sailroute.wind.wrf import open_wrf

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
    from sailroute.wind.wrf import open_wrf

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
