"""Wind specs of measured data: ``stations``, ``blended`` (a WRF field corrected by
stations) and ``measured`` (the boats' own logs).

Each type's frozen dataclass (checked values in SI units), its parser (every check that
needs no file content) and its builder (reads the files, makes the field); registered in
:data:`sailroute.wind.specs.WIND_KINDS`.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from sailroute.checks import Checker, resolve_path, show
from sailroute.errors import InputError
from sailroute.tabular import CANONICAL_COLUMNS, DEFAULT_MISSING, TIME_PARTS, parse_offset
from sailroute.wind.base import WindField
from sailroute.wind.height import DEFAULT_EXPONENT, DEFAULT_ROUGHNESS_M
from sailroute.wind.measured import (
    DEFAULT_MAX_GAP_S,
    DEFAULT_METHOD,
    DEFAULT_RESAMPLE_S,
    DEFAULT_SMOOTH_S,
    FLEET_METHODS,
)
from sailroute.wind.spec_base import BuildContext, Pairs, _dict, _pairs, _speed_unit, _wrapped
from sailroute.wind.spec_gridded import WrfWindSpec, _build_wrf, _pair, _parse_wrf

if TYPE_CHECKING:
    from sailroute.wind.stationread import StationData

# The readers (stations, NDBC, blended, the boats' logs) are imported by the builders
# that use them: the parsers run for every scenario of a course that loads.

MEASURED_MARGIN_S = 600.0
"""Records within this of the race window [s] are used by ``type: measured``."""


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
    from sailroute.wind.ndbc import is_ndbc_text
    from sailroute.wind.stationread import read_stations

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
    from sailroute.wind.ndbc import read_ndbc
    from sailroute.wind.stationread import resample_stations

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
    from sailroute.wind.stations import StationWind

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
    from sailroute.wind.blended import BlendedWind

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
    from sailroute.wind.measured import fleet_wind, sensor_from_track

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
