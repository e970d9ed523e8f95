"""Build a :class:`~sailroute.wind.base.WindField` from a wind spec (a YAML mapping).

The course loader calls :func:`wind_from_spec` once per scenario.  Spec keys are
documented in ``docs/design/wind.md`` ("Wind spec keys").  Every problem in a
spec is collected and reported in one :class:`~sailroute.errors.InputError`,
each line prefixed with its key path.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from sailroute.checks import Checker, Problems, real_number, resolve_path, show
from sailroute.errors import InputError, OutOfCoverageError
from sailroute.geo import LocalFrame
from sailroute.timeutil import parse_time, to_epoch
from sailroute.units import KNOT, SPEED_UNITS
from sailroute.wind.base import Coverage, WindField
from sailroute.wind.blended import BlendedWind
from sailroute.wind.current import (
    CurrentField,
    DiamondCurrent,
    UniformCurrent,
    open_netcdf_current,
)
from sailroute.wind.height import DEFAULT_EXPONENT, DEFAULT_EXPONENT_RANGE, DEFAULT_ROUGHNESS_M
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

BBox = tuple[float, float, float, float]
"""Local-frame box ``(xmin, xmax, ymin, ymax)`` [m] (same order as :class:`Coverage`)."""


def wind_from_spec(
    spec: Mapping[str, Any],
    *,
    frame: LocalFrame,
    base_dir: Path,
    where: str,
    crop_bbox: BBox | None = None,
    time_window: tuple[float, float] | None = None,
    lines: Mapping[str, int] | None = None,
) -> WindField:
    """Build a wind field from a spec mapping.

    Parameters
    ----------
    spec : mapping
        The wind spec, e.g. ``{"type": "uniform", "tws_kn": 10, "twd_deg": 108}``;
        ``type`` is one of ``uniform``, ``wrf``, ``netcdf`` (CF lat/lon, or wrfout
        detected), ``grib``, ``stations``, ``blended``, ``measured`` (boat logs).
    frame : LocalFrame
        The course's local frame; gridded and station data are mapped into it.
    base_dir : Path
        Directory that relative ``path`` values are resolved against (the course file's).
    where : str
        Prefix for error messages, e.g. ``"courses/x.yaml: scenarios.wrf10[0]"``.
    crop_bbox : tuple of float, optional
        Course bounding box ``(xmin, xmax, ymin, ymax)`` [m] in ``frame`` (marks, no
        margin).  WRF data are cropped to it plus ``margin_m``; a source that does
        not cover it raises :class:`~sailroute.errors.OutOfCoverageError` now
        (unless the spec sets ``clamp: true``).
    time_window : tuple of float, optional
        Race time window ``(t0, t1)`` [epoch s].  WRF slices outside it are not
        read; a source that does not cover it raises now (unless ``clamp``).
    lines : mapping of str to int, optional
        1-based line of each key path of the file ``where`` names (the course
        file's line map, :attr:`~sailroute.course.model.Course.key_lines`): each
        problem is then reported at its own key's line.

    Returns
    -------
    WindField

    Raises
    ------
    InputError
        Unknown type, unknown/missing/invalid keys (all listed at once), unreadable files.
    WindDataError
        Malformed data files.
    OutOfCoverageError
        The data do not cover ``crop_bbox``/``time_window`` and ``clamp`` is false.
    """
    probs = Problems.below(where, lines, what="wind spec")
    chk = Checker(probs, probs.root)
    if not isinstance(spec, Mapping):
        raise InputError(f"{where}: expected a wind spec mapping (type: ...); got {show(spec)}")
    kind = chk.choice(spec, "type", list(_BUILDERS))
    if kind is None:
        chk.p.raise_if_any()
    if crop_bbox is not None and not (
        crop_bbox[0] <= crop_bbox[1] and crop_bbox[2] <= crop_bbox[3]
    ):
        raise InputError(
            f"{where}: crop_bbox must be (xmin, xmax, ymin, ymax) in metres; got {tuple(crop_bbox)}"
        )
    if time_window is not None and not time_window[0] <= time_window[1]:
        raise InputError(
            f"{where}: time_window must be (t0, t1) with t0 <= t1; got {tuple(time_window)}"
        )
    ctx = _Context(frame, Path(base_dir), crop_bbox, time_window)
    field = _BUILDERS[kind](spec, chk, ctx)
    if not spec.get("clamp", False):
        check_covers(field, crop_bbox, time_window, name=f"{where}: {kind} wind", frame=frame)
    return field


def check_covers(
    field: WindField | CurrentField,
    bbox: BBox | None,
    time_window: tuple[float, float] | None,
    *,
    name: str = "wind field",
    frame: LocalFrame | None = None,
) -> None:
    """Raise :class:`OutOfCoverageError` unless ``field`` covers ``bbox`` and ``time_window``.

    Parameters
    ----------
    field : WindField
        The field to check.
    bbox : tuple of float or None
        ``(xmin, xmax, ymin, ymax)`` [m] that must lie inside the field's box.
    time_window : tuple of float or None
        ``(t0, t1)`` [epoch s] that must lie inside the field's time span.
    name : str
        Label for the message.
    frame : LocalFrame, optional
        Adds latitude/longitude to the message (the field's own frame is used
        when its coverage has one).
    """
    c = field.coverage
    t0, t1 = time_window if time_window is not None else (c.t0, c.t1)
    x0, x1, y0, y1 = bbox if bbox is not None else (c.xmin, c.xmax, c.ymin, c.ymax)
    if (
        t0 >= c.t0
        and t1 <= c.t1
        and x0 >= c.xmin
        and x1 <= c.xmax
        and y0 >= c.ymin
        and (y1 <= c.ymax)
    ):
        return
    frame = frame if frame is not None else c.frame
    need = Coverage(t0, t1, x0, x1, y0, y1, frame=frame)
    if c.frame is None and frame is not None:
        c = Coverage(
            c.t0, c.t1, c.xmin, c.xmax, c.ymin, c.ymax, frame=frame, source_span=c.source_span
        )
    span = c.source_span or (c.t0, c.t1)
    single = span[0] == span[1] and not (t0 >= c.t0 and t1 <= c.t1)
    raise OutOfCoverageError(
        f"{name} does not cover the course and race time.\n"
        f"  needed:  {need.describe()}\n"
        f"  covered: {c.describe()}\n"
        + (
            "  The source holds a single time: to use it as a steady wind for the whole race, "
            "set `steady: true`.\n"
            if single
            else ""
        )
        + "  Use wind data that covers the course (the thesis's main failure was extrapolating "
        "outside the data), or opt in to clamping at the edges with `clamp: true`."
    )


def wind_notes(field: WindField) -> list[str]:
    """One-line summaries of how a wind source was read, for the progress display.

    Gridded fields: the slices read, the cells and how many hold no wind (NaN);
    station fields: the rows read and how many were dropped for missing values.
    Other fields: none.
    """
    name = getattr(field, "name", type(field).__name__)
    info = getattr(field, "info", None)
    data = getattr(field, "data", None)
    if isinstance(info, Mapping) and "times" in info:
        text = f"{name}: {info['times']}"
        if "cells" in info:
            text += f", {info['cells']} cells"
            if info.get("nan_cells"):
                text += f" ({info['nan_cells']} without wind: land or masked)"
        if info.get("height_m") is not None:
            text += f", wind at {info['height_m']:g} m"
        return [text]
    if isinstance(data, StationData):
        text = f"{name}: {data.n_raw} rows read"
        if data.n_missing:
            per = ", ".join(
                f"{k} {v}"
                for k, v in data.missing_by_column.items()
                if k not in ("gust", "height_m")
            )  # optional: no row dropped
            text += f", {data.n_missing} dropped for missing values ({per})"
        return [text + f", {len(data)} records used"]
    return []


class _Context:
    def __init__(
        self,
        frame: LocalFrame,
        base_dir: Path,
        crop_bbox: BBox | None,
        time_window: tuple[float, float] | None,
        where: str = "",
    ) -> None:
        self.frame = frame
        self.base_dir = base_dir
        self.crop_bbox = crop_bbox
        self.time_window = time_window
        self.where = where  # message prefix of the spec (file, line, key path)


# ---------------------------------------------------------------------------- uniform
_UNIFORM_KEYS = ("type", "tws_kn", "tws_ms", "twd_deg", "table", "interpolation", "clamp")


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


def _build_uniform(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> WindField:
    chk.keys(spec, _UNIFORM_KEYS)
    clamp = chk.boolean(spec, "clamp", False)
    interpolation = chk.choice(spec, "interpolation", ["linear", "previous"], "linear")
    table = spec.get("table")
    if table is None:
        tws = _speed(chk, spec, required=True)
        twd = chk.number(spec, "twd_deg", lo=0.0, hi=360.0)
        chk.p.raise_if_any()
        assert tws is not None  # required: reported above when missing or invalid
        return UniformWind(tws, twd, clamp=clamp)
    for key in ("tws_kn", "tws_ms", "twd_deg"):
        if key in spec:
            chk.add(key, "not allowed together with `table`; put speeds and directions in the rows")
    if not isinstance(table, list) or not table:
        chk.add(
            "table",
            f"expected a non-empty list of rows {{time, tws_kn, twd_deg}}; got {show(table)}",
        )
        chk.p.raise_if_any()
    times: list[float] = []
    speeds: list[float] = []
    dirs: list[float] = []
    tchk = chk.child("table")
    for k, row in enumerate(table):
        rchk = tchk.child(k)
        if not isinstance(row, Mapping):
            rchk.add("time", f"expected a mapping {{time, tws_kn, twd_deg}}; got {show(row)}")
            continue
        rchk.keys(row, ("time", "tws_kn", "tws_ms", "twd_deg"), ("time",))
        t = None
        if "time" in row:
            try:
                t = to_epoch(parse_time(row["time"], where=rchk.where("time")))
            except InputError as exc:
                rchk.p.extend([str(exc)])
        s = _speed(rchk, row, required=True)
        d = rchk.number(row, "twd_deg", lo=0.0, hi=360.0)
        if t is not None and s is not None and d is not None:
            times.append(t)
            speeds.append(s)
            dirs.append(d)
    if not chk.p:
        for k in range(1, len(times)):
            if times[k] <= times[k - 1]:
                tchk.child(k).add("time", "table times must increase strictly from row to row")
    chk.p.raise_if_any()
    return UniformWind(speeds, dirs, times=times, interpolation=interpolation, clamp=clamp)


# ---------------------------------------------------------------------------- wrf
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


def _path(chk: Checker, spec: Mapping[str, Any], ctx: _Context) -> Path | None:
    return chk.file(spec, "path", ctx.base_dir)


def _wrf_options(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> dict[str, Any]:
    """Validate a ``type: wrf`` spec into keyword arguments of :func:`open_wrf`."""
    chk.keys(spec, _WRF_KEYS, ("path",))
    opts: dict[str, Any] = {
        "path": _path(chk, spec, ctx),
        "height_m": chk.number(spec, "height_m", None, lo=0.0, lo_open=True),
        "time_step_min": chk.number(spec, "time_step_min", None, lo=0.0, lo_open=True),
        "interpolation": chk.choice(spec, "interpolation", ["linear", "nearest"], "linear"),
        "levels": chk.choice(spec, "levels", ["auto", "u10", "model"], "auto"),
        "shear": chk.choice(spec, "shear", ["power", "log"], "power"),
        "fallback_exponent": chk.number(
            spec, "fallback_exponent", DEFAULT_EXPONENT, lo=-1.0, hi=1.0
        ),
        "roughness_m": chk.number(spec, "roughness_m", DEFAULT_ROUGHNESS_M, lo=0.0, lo_open=True),
        "margin_m": chk.number(spec, "margin_m", None, lo=0.0),
        "clamp": chk.boolean(spec, "clamp", False),
        "exponent_range": DEFAULT_EXPONENT_RANGE,
    }
    if "exponent_range" in spec:
        er = spec["exponent_range"]
        if (
            not isinstance(er, list | tuple)
            or len(er) != 2
            or not all(isinstance(a, int | float) and not isinstance(a, bool) for a in er)
            or not er[0] < er[1]
        ):
            chk.add(
                "exponent_range", f"expected [min, max] with min < max, e.g. [0.0, 0.6]; got {er!r}"
            )
        else:
            opts["exponent_range"] = (float(er[0]), float(er[1]))
    if opts["levels"] == "model" and "height_m" not in spec:
        chk.add(
            "levels",
            "'model' levels are only used for a height correction; set height_m "
            "(e.g. 2.68 for a Laser's centre of effort) or use levels: auto",
        )
    return opts


def _open_wrf_checked(opts: dict[str, Any], where: str, ctx: _Context) -> WindField:
    try:
        return open_wrf(
            opts.pop("path"), ctx.frame, bbox=ctx.crop_bbox, time_window=ctx.time_window, **opts
        )
    except InputError as exc:
        raise type(exc)(f"{where}: {exc}") from None


def _build_wrf(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> WindField:
    opts = _wrf_options(spec, chk, ctx)
    chk.p.raise_if_any()
    return _open_wrf_checked(opts, chk.where(), ctx)


# ---------------------------------------------------------------------------- netcdf / grib
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


def _grid_options(
    spec: Mapping[str, Any], chk: Checker, ctx: _Context, extra: tuple[str, ...] = ()
) -> dict[str, Any]:
    """Validate a ``type: netcdf`` / ``type: grib`` spec into :func:`open_netcdf` keywords."""
    chk.keys(spec, (*_GRID_KEYS, *extra))  # a missing path is reported by _path
    opts: dict[str, Any] = {
        "path": _path(chk, spec, ctx),
        "height_m": chk.number(spec, "height_m", None, lo=0.0, lo_open=True),
        "data_height_m": chk.number(spec, "data_height_m", None, lo=0.0, lo_open=True),
        "shear": chk.choice(spec, "shear", ["power", "log"], "power"),
        "exponent": chk.number(spec, "exponent", DEFAULT_EXPONENT, lo=-1.0, hi=1.0),
        "roughness_m": chk.number(spec, "roughness_m", DEFAULT_ROUGHNESS_M, lo=0.0, lo_open=True),
        "time_step_min": chk.number(spec, "time_step_min", None, lo=0.0, lo_open=True),
        "interpolation": chk.choice(spec, "interpolation", ["linear", "nearest"], "linear"),
        "steady": chk.boolean(spec, "steady", False),
        "margin_m": chk.number(spec, "margin_m", None, lo=0.0),
        "clamp": chk.boolean(spec, "clamp", False),
        "speed_unit": None,
        "variables": None,
        "time": None,
        "select": None,
    }
    sel = chk.mapping(spec, "select", None)
    if sel is not None:
        bad = {
            k: v for k, v in sel.items() if not isinstance(v, int) or isinstance(v, bool) or v < 0
        }
        if bad:
            chk.add(
                "select",
                "expected a mapping of dimension name to an index >= 0, e.g. "
                f"{{number: 3}}; got {dict(sel)!r}",
            )
        else:
            opts["select"] = {str(k): int(v) for k, v in sel.items()}
    unit = chk.string(spec, "speed_unit", None)
    if unit is not None and unit.strip().lower() not in SPEED_UNITS:
        chk.add("speed_unit", f"expected one of 'm/s', 'kn', 'km/h', 'mph'; got {show(unit)}")
    else:
        opts["speed_unit"] = unit
    var = chk.mapping(spec, "variables", None)
    if var is not None:
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
        opts["variables"] = dict(var)
    if "time" in spec:
        try:
            opts["time"] = to_epoch(parse_time(spec["time"], where=chk.where("time")))
        except InputError as exc:
            chk.p.extend([str(exc)])
    return opts


def _build_netcdf(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> WindField:
    from sailroute.wind.cf import is_wrfout, open_netcdf

    opts = _grid_options(spec, chk, ctx)
    chk.p.raise_if_any()
    path = opts.pop("path")
    try:
        if is_wrfout(path):
            used = [k for k in _CF_ONLY if k in spec]
            if used:
                raise InputError(
                    f"{path.name} is a WRF wrfout file; {', '.join(used)} only "
                    "apply to latitude/longitude files (use the `type: wrf` keys)"
                )
            for k in _CF_ONLY:
                opts.pop(k)
            opts["fallback_exponent"] = opts.pop("exponent")
            return open_wrf(
                path, ctx.frame, bbox=ctx.crop_bbox, time_window=ctx.time_window, **opts
            )
        return open_netcdf(path, ctx.frame, bbox=ctx.crop_bbox, time_window=ctx.time_window, **opts)
    except InputError as exc:
        raise type(exc)(f"{chk.where()}: {exc}") from None


def _build_grib(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> WindField:
    from sailroute.wind.cf import open_grib

    opts = _grid_options(spec, chk, ctx, extra=("filter",))
    filt = chk.mapping(spec, "filter", None)
    chk.p.raise_if_any()
    path = opts.pop("path")
    try:
        return open_grib(
            path,
            ctx.frame,
            filter_by_keys=filt,
            bbox=ctx.crop_bbox,
            time_window=ctx.time_window,
            **opts,
        )
    except InputError as exc:
        raise type(exc)(f"{chk.where()}: {exc}") from None


# ---------------------------------------------------------------------------- stations
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


def _read_options(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> dict[str, Any]:
    """Validate the station-file keys into keyword arguments of :func:`read_stations`."""
    opts: dict[str, Any] = {
        "path": _path(chk, spec, ctx),
        "format": chk.choice(spec, "format", ["auto", "csv", "ndbc"], "auto"),
    }
    unit = chk.string(spec, "speed_unit", None)
    if unit is not None and unit.strip().lower() not in SPEED_UNITS:
        chk.add("speed_unit", f"expected one of 'm/s', 'kn', 'km/h', 'mph'; got {show(unit)}")
        unit = None
    opts["speed_unit"] = unit
    cols = chk.mapping(spec, "columns", None)
    if cols is not None:
        for k, v in cols.items():
            if k not in CANONICAL_COLUMNS and k not in TIME_PARTS:
                chk.child("columns").add(
                    str(k),
                    "unknown canonical column; expected one of "
                    + ", ".join((*CANONICAL_COLUMNS, *TIME_PARTS)),
                )
            elif not isinstance(v, str):
                chk.child("columns").add(str(k), f"expected a column name; got {show(v)}")
    opts["columns"] = cols
    tz = chk.string(spec, "timezone", None)
    if tz is not None:
        try:
            parse_offset(tz)
        except InputError as exc:
            chk.add("timezone", str(exc).split(": ", 1)[-1])
            tz = None
    opts["timezone"] = tz
    opts["resample_s"] = chk.number(spec, "resample_s", None, lo=0.0, lo_open=True)
    st = spec.get("station")
    if st is not None and not isinstance(st, str | int):
        chk.add("station", f"expected a station id; got {show(st)}")
    opts["station"] = None if st is None else str(st)
    pos = chk.mapping(spec, "position", None)
    if pos is not None:
        pchk = chk.child("position")
        pchk.keys(pos, ("lat", "lon"), ("lat", "lon"))
        la = pchk.number(pos, "lat", lo=-90.0, hi=90.0) if "lat" in pos else None
        lo = pchk.number(pos, "lon", lo=-180.0, hi=360.0) if "lon" in pos else None
        opts["position"] = None if la is None or lo is None else (la, lo)
    opts["height_m"] = chk.number(spec, "measurement_height_m", None, lo=0.0, lo_open=True)
    miss = spec.get("missing")
    if miss is not None:
        if not isinstance(miss, list) or not all(isinstance(m, str | int | float) for m in miss):
            chk.add(
                "missing", f"expected a list of markers such as ['', 'MM', '999'], got {miss!r}"
            )
        else:
            opts["missing"] = tuple(DEFAULT_MISSING) + tuple(str(m) for m in miss)
    return opts


def _read_checked(opts: dict[str, Any], where: str) -> StationData:
    opts = dict(opts)
    path, fmt = opts.pop("path"), opts.pop("format", "auto")
    try:
        if fmt == "ndbc" or (fmt == "auto" and is_ndbc_text(path)):
            return _read_ndbc_checked(path, opts, where)
        return read_stations(path, **opts)
    except InputError as exc:
        raise type(exc)(f"{where}: {exc}") from None


def _read_ndbc_checked(path: Path, opts: dict[str, Any], where: str) -> StationData:
    """NDBC realtime text: only position, station, height and resample_s apply."""
    if opts.get("position") is None:
        raise InputError(
            f"{path.name} is NDBC text, which does not carry the buoy's position; "
            "add `position: {lat: ..., lon: ...}` (from the station's NDBC page, "
            "e.g. 41008: {lat: 31.400, lon: -80.866})"
        )
    bad = [k for k in ("columns", "speed_unit", "timezone") if opts.get(k) is not None]
    if bad:
        raise InputError(
            f"{', '.join(bad)}: not used for NDBC text (its columns, m/s and UTC "
            "are fixed by the format); remove them"
        )
    data = read_ndbc(
        path, position=opts["position"], station=opts.get("station"), height_m=opts.get("height_m")
    )
    if opts.get("resample_s") is not None:
        data = resample_stations(data, opts["resample_s"])
    return data


def _build_stations(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> WindField:
    chk.keys(spec, ("type", *_READ_KEYS, *_STATION_FIELD_KEYS), ("path",))
    ropts = _read_options(spec, chk, ctx)
    fopts = {
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
    chk.p.raise_if_any()
    data = _read_checked(ropts, chk.where())
    try:
        return StationWind(
            data,
            ctx.frame,
            name=f"station wind {data.source}",
            time_window=ctx.time_window,
            **fopts,
        )
    except InputError as exc:
        raise type(exc)(f"{chk.where()}: {exc}") from None


# ---------------------------------------------------------------------------- blended
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


def _build_blended(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> WindField:
    chk.keys(spec, _BLEND_KEYS, ("wrf", "stations"))
    wspec = chk.mapping(spec, "wrf")
    sspec = chk.mapping(spec, "stations")
    wopts: dict[str, Any] = {}
    ropts: dict[str, Any] = {}
    if wspec is not None:
        wchk = chk.child("wrf")
        if wspec.get("type", "wrf") != "wrf":
            wchk.add("type", f"expected 'wrf' (or leave it out); got {show(wspec.get('type'))}")
        wopts = _wrf_options(
            {k: v for k, v in wspec.items() if k != "type"} | {"type": "wrf"}, wchk, ctx
        )
    if sspec is not None:
        schk = chk.child("stations")
        schk.keys(sspec, ("type", *_READ_KEYS), ("path",))
        ropts = _read_options(sspec, schk, ctx)
    bopts: dict[str, Any] = {
        "length_scale_m": chk.number(spec, "length_scale_m", 2000.0, lo=0.0, lo_open=True),
        "time_scale_s": chk.number(spec, "time_scale_s", 600.0, lo=0.0),
        "min_speed_ms": chk.number(spec, "min_speed_ms", 1.0, lo=0.0),
        "max_offset_deg": chk.number(spec, "max_offset_deg", 60.0, lo=0.0, hi=180.0),
        "clamp": chk.boolean(spec, "clamp", False),
    }
    if "ratio_range" in spec:
        rr = spec["ratio_range"]
        if (
            not isinstance(rr, list | tuple)
            or len(rr) != 2
            or not all(isinstance(a, int | float) and not isinstance(a, bool) for a in rr)
            or not 0 < rr[0] <= 1 <= rr[1]
        ):
            chk.add(
                "ratio_range",
                f"expected [min, max] with 0 < min <= 1 <= max, e.g. [0.5, 2.0]; got {rr!r}",
            )
        else:
            bopts["ratio_range"] = (float(rr[0]), float(rr[1]))
    chk.p.raise_if_any()
    base = _open_wrf_checked(dict(wopts), chk.where("wrf"), ctx)
    data = _read_checked(ropts, chk.where("stations"))
    try:
        return BlendedWind(
            base,
            data,
            ctx.frame,
            height_m=wopts.get("height_m"),
            exponent=wopts.get("fallback_exponent", DEFAULT_EXPONENT),
            name=f"blended wind ({Path(str(wopts['path'])).name} + {Path(data.source).name})",
            **bopts,
        )
    except InputError as exc:
        raise type(exc)(f"{chk.where()}: {exc}") from None


# ---------------------------------------------------------------------------- measured
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
MEASURED_MARGIN_S = 600.0
"""Records within this of the race window [s] are used by ``type: measured``."""


def _build_measured(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> WindField:
    """``type: measured``: the fleet's measured wind from boat logs (``fleet_wind(...).field``)."""
    from sailroute.track.read import read_track  # track reads through wind.stations: late
    from sailroute.wind.measured import (
        DEFAULT_MAX_GAP_S,
        DEFAULT_METHOD,
        DEFAULT_RESAMPLE_S,
        DEFAULT_SMOOTH_S,
        FLEET_METHODS,
        fleet_wind,
        sensor_from_track,
    )

    chk.keys(spec, _MEASURED_KEYS, ("tracks",))
    raw = spec.get("tracks")
    paths: list[Path] = []
    if raw is not None:
        if not isinstance(raw, list) or not raw or not all(isinstance(p, str) for p in raw):
            chk.add("tracks", f"expected a non-empty list of log paths; got {show(raw)}")
        else:
            tchk = chk.child("tracks")
            for k, p in enumerate(raw):
                tchk.file(raw, k, ctx.base_dir, value=p)
                paths.append(resolve_path(ctx.base_dir, p))
    unit = chk.string(spec, "speed_unit", None)
    if unit is not None and unit.strip().lower() not in SPEED_UNITS:
        chk.add("speed_unit", f"expected one of 'm/s', 'kn', 'km/h', 'mph'; got {show(unit)}")
    tz = chk.string(spec, "time_zone", None)
    method = chk.choice(spec, "method", list(FLEET_METHODS), DEFAULT_METHOD)
    bias = chk.boolean(spec, "estimate_bias", True)
    resample_s = chk.number(spec, "resample_s", DEFAULT_RESAMPLE_S, lo=0.0)
    smooth_s = chk.number(spec, "smooth_s", DEFAULT_SMOOTH_S, lo=0.0)
    max_gap_s = chk.number(spec, "max_gap_s", DEFAULT_MAX_GAP_S, lo=0.0, lo_open=True)
    radius_m = chk.number(spec, "radius_m", 2000.0, lo=0.0)
    clamp = chk.boolean(spec, "clamp", False)
    chk.p.raise_if_any()
    series = []
    for k, p in enumerate(paths):
        where = chk.where(f"tracks[{k}]")
        try:
            s = sensor_from_track(
                read_track(p, speed_unit=unit, time_zone=tz), smooth_s=smooth_s, max_gap_s=max_gap_s
            )
        except InputError as exc:
            raise type(exc)(f"{where}: {exc}") from None
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
    try:
        fw = fleet_wind(
            series,
            ctx.frame,
            method=method,
            estimate_bias=bias,
            resample_s=resample_s,
            radius_m=radius_m,
            clamp=clamp,
            options={"name": "measured wind (" + ", ".join(s.boat for s in series) + ")"},
        )
    except InputError as exc:
        raise type(exc)(f"{chk.where()}: {exc}") from None
    return fw.field


_BUILDERS: dict[str, Callable[[Mapping[str, Any], Checker, _Context], WindField]] = {
    "uniform": _build_uniform,
    "wrf": _build_wrf,
    "netcdf": _build_netcdf,
    "grib": _build_grib,
    "stations": _build_stations,
    "blended": _build_blended,
    "measured": _build_measured,
}

WIND_TYPES: tuple[str, ...] = tuple(_BUILDERS)
"""Values of a wind spec's ``type``."""


# ---------------------------------------------------------------------------- currents
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


def current_from_spec(
    spec: Mapping[str, Any],
    *,
    frame: LocalFrame,
    base_dir: Path,
    where: str,
    crop_bbox: BBox | None = None,
    time_window: tuple[float, float] | None = None,
    lines: Mapping[str, int] | None = None,
) -> CurrentField:
    """Build a current field from a scenario's ``current:`` mapping.

    Parameters
    ----------
    spec : mapping
        ``{type: uniform, speed_kn | speed_ms, set_deg}``,
        ``{type: diamonds, high_water, table: [[hour, set_deg, rate_kn], ...]}`` or
        ``{type: netcdf, path, variables, ...}`` (``docs/course-format.md``); the types
        are the keys of :data:`CURRENT_BUILDERS`.
    frame : LocalFrame
        The course's local frame.
    base_dir : Path
        Folder that a relative ``path`` resolves against.
    where : str
        Key-path prefix of messages, e.g. ``"courses/x.yaml:12: scenarios.spring.current"``.
    crop_bbox, time_window : optional
        Course box [m] and race window [epoch s] that the current must cover
        (unless ``clamp: true``), as for a wind spec.
    lines : mapping of str to int, optional
        1-based line of each key path of the file (the course's line map): each
        problem is reported at its own key's line.

    Raises
    ------
    InputError
        Every problem of the spec at once, each with its key path.
    OutOfCoverageError
        The current does not cover the course or the race time.
    """
    probs = Problems.below(where, lines, what="current spec")
    chk = Checker(probs, probs.root)
    if not isinstance(spec, Mapping):
        raise InputError(
            f"{where}: expected a current spec mapping, e.g. {{type: uniform, "
            f"speed_kn: 1.5, set_deg: 90}}; got {show(spec)}"
        )
    kind = chk.choice(spec, "type", list(CURRENT_BUILDERS))
    chk.p.raise_if_any()
    assert kind is not None  # an unknown or missing type was raised just above
    field = CURRENT_BUILDERS[kind](
        spec, chk, _Context(frame, Path(base_dir), crop_bbox, time_window, where)
    )
    if not spec.get("clamp", False):
        check_covers(field, crop_bbox, time_window, name=f"{where}: {kind} current", frame=frame)
    return field


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


def _build_uniform_current(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> CurrentField:
    """``type: uniform``: one rate and set everywhere, all the time."""
    chk.keys(spec, _CURRENT_UNIFORM_KEYS, ("set_deg",))
    rate = _current_rate(chk, spec)
    set_deg = chk.number(spec, "set_deg", lo=0.0, hi=360.0) if "set_deg" in spec else None
    chk.p.raise_if_any()
    assert set_deg is not None and rate is not None  # required: reported above when missing
    return UniformCurrent(rate, set_deg)


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


def _build_diamond_current(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> CurrentField:
    """``type: diamonds``: a tidal-diamond table of set and rate by hour from high water."""
    chk.keys(spec, _CURRENT_DIAMOND_KEYS, ("high_water", "table"))
    unit = chk.choice(spec, "rate_unit", ["kn", "m/s"], "kn")
    scale = KNOT if unit == "kn" else 1.0
    clamp = chk.boolean(spec, "clamp", False)
    hw = None
    if "high_water" in spec:
        try:
            hw = to_epoch(parse_time(spec["high_water"], where=chk.where("high_water")))
        except InputError as exc:
            chk.p.extend([str(exc)])
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
    chk.p.raise_if_any()
    h, s, r = (list(c) for c in zip(*rows, strict=True))
    assert hw is not None  # required key: reported above when missing or unreadable
    return DiamondCurrent(hw, h, s, r, clamp=clamp)


def _build_netcdf_current(spec: Mapping[str, Any], chk: Checker, ctx: _Context) -> CurrentField:
    """``type: netcdf``: a gridded current (u, v) from a NetCDF file."""
    chk.keys(spec, _CURRENT_NETCDF_KEYS, ("path",))
    path = _path(chk, spec, ctx)
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
    opts = {
        "interpolation": chk.choice(spec, "interpolation", ["linear", "nearest"], "linear"),
        "steady": chk.boolean(spec, "steady", False),
        "clamp": chk.boolean(spec, "clamp", False),
    }
    chk.p.raise_if_any()
    assert path is not None  # required key: reported above when missing
    try:
        return open_netcdf_current(
            path,
            ctx.frame,
            variables=var,
            speed_unit=unit,
            select=sel,
            bbox=ctx.crop_bbox,
            time_window=ctx.time_window,
            **opts,
        )
    except InputError as exc:
        raise type(exc)(f"{ctx.where}: {exc}") from None


CURRENT_BUILDERS: dict[str, Callable[[Mapping[str, Any], Checker, _Context], CurrentField]] = {
    "uniform": _build_uniform_current,
    "diamonds": _build_diamond_current,
    "netcdf": _build_netcdf_current,
}
"""Current spec ``type`` -> builder (the types ``current:`` accepts)."""
