"""Measured wind from stations (fixed anemometers, buoys, coach boats): read, resample, field.

* :func:`read_stations` reads a CSV with the canonical columns ``time`` (ISO 8601
  with offset), ``station``, ``lat``, ``lon``, ``speed``, ``direction`` (from,
  °T) and optional ``height_m``, ``gust``; other headers are mapped through
  :data:`COLUMN_ALIASES` or an explicit ``columns`` mapping.  Missing-value
  markers are counted and their rows dropped.
* :func:`resample_stations` averages 1-20 Hz logs into fixed intervals: scalar
  mean speed, vector-mean direction.
* :class:`StationWind` interpolates the stations in space (inverse distance or
  scipy RBF) and linearly in time, inside the stations' box plus ``radius_m``.

A station whose position changes (a coach boat) is one moving station; its
position is interpolated in time like its wind.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime, timedelta, timezone
from functools import cached_property
from pathlib import Path
from typing import Any, Final, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError, OutOfCoverageError, WindDataError, format_problems
from sailroute.geo import LocalFrame
from sailroute.textin import (
    clean_text,
    csv_rows,
    excerpt,
    looks_binary,
    looks_like_header,
    quote_header,
)
from sailroute.timeutil import iso
from sailroute.units import speed_factor, wind_components, wind_speed_direction
from sailroute.wind.base import Coverage, prepare_points
from sailroute.wind.height import (
    DEFAULT_EXPONENT,
    DEFAULT_ROUGHNESS_M,
    log_law_factor,
    power_law_factor,
)
from sailroute.wind.rotation import earth_to_local

CANONICAL_COLUMNS: Final = ("time", "station", "lat", "lon", "speed", "direction", "height_m",
                            "gust")
"""Column names of the canonical station CSV schema."""

REQUIRED_COLUMNS: Final = ("time", "speed", "direction")
"""Always required (``lat``/``lon`` unless ``position`` is given; ``station`` defaults)."""

_SPEED_SUFFIXES: Final = ("_kn", "_kt", "_kts", "_ms", "_m_s", "_mps", "_kmh", "_kph", "_mph")

COLUMN_ALIASES: Final[dict[str, tuple[str, ...]]] = {
    "time": ("time", "time_utc", "datetime", "datetime_utc", "datetime_local", "timestamp",
             "date_time", "utc", "time_iso", "t"),
    "station": ("station", "station_id", "stationid", "id", "name", "sensor"),
    "lat": ("lat", "latitude", "lat_deg"),
    "lon": ("lon", "lng", "long", "longitude", "lon_deg"),
    "speed": ("speed", "tws", "wspd", "wind_speed", "windspeed", "ws",
              *(f"{base}{suffix}" for base in ("speed", "tws", "wspd", "wind_speed")
                for suffix in _SPEED_SUFFIXES)),
    "direction": ("direction", "twd", "twd_deg", "wdir", "wdir_deg", "wdir_deg_true",
                  "wind_direction", "wind_dir", "winddir", "wd", "direction_deg", "dir"),
    "height_m": ("height_m", "height", "z", "z_m", "anemometer_height_m", "sensor_height_m"),
    "gust": ("gust", "gst", "wind_gust", "gust_speed", *(f"gust{x}" for x in _SPEED_SUFFIXES)),
}
"""Built-in header aliases (case-insensitive) for each canonical column."""

DEFAULT_MISSING: Final = ("", "NA", "N/A", "NaN", "nan", "NAN", "null", "NULL", "None", "MM",
                          "-", "--")
"""Cell values read as missing by default (add e.g. ``"999"`` for NDBC codes)."""

_UNIT_SUFFIXES: Final = (("_m_s", "m/s"), ("_ms", "m/s"), ("_mps", "m/s"), ("_kn", "kn"),
                         ("_km_h", "km/h"),
                         ("_kt", "kn"), ("_kts", "kn"), ("_knots", "kn"), ("_kmh", "km/h"),
                         ("_kph", "km/h"), ("_mph", "mph"))


# ------------------------------------------------------------------------------ data
@dataclass(frozen=True)
class StationData:
    """Station records, one per (station, time), SI units, sorted by station then time.

    Attributes
    ----------
    station : ndarray of str
        Station id of each record.
    t : ndarray
        Epoch seconds [s] (UTC).
    lat, lon : ndarray
        Position [°] (varies in time for a moving station).
    speed_ms : ndarray
        Wind speed [m s⁻¹].
    direction_deg : ndarray
        Direction the wind comes from [°], in ``[0, 360)``.
    height_m : ndarray
        Measurement height above the water [m]; NaN when unknown.
    gust_ms : ndarray
        Gust [m s⁻¹]; NaN when absent.
    source : str
        File the records came from.
    n_raw : int
        Data rows in the file (before dropping and resampling).
    n_missing : int
        Rows dropped because a needed value was a missing marker or NaN.
    missing_by_column : mapping of str to int
        Missing cells per canonical column (also counting optional columns).
    """

    station: NDArray[np.str_]
    t: NDArray[np.float64]
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    speed_ms: NDArray[np.float64]
    direction_deg: NDArray[np.float64]
    height_m: NDArray[np.float64]
    gust_ms: NDArray[np.float64]
    source: str = ""
    n_raw: int = 0
    n_missing: int = 0
    missing_by_column: Mapping[str, int] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def stations(self) -> tuple[str, ...]:
        """Station ids in order of first appearance."""
        _, first = np.unique(self.station, return_index=True)
        return tuple(str(s) for s in self.station[np.sort(first)])

    def select(self, station: str) -> StationData:
        """Records of one station."""
        m = self.station == station
        return replace(self, **{k: getattr(self, k)[m] for k in _ARRAY_FIELDS})

    @property
    def u(self) -> NDArray[np.float64]:
        """Eastward wind component [m s⁻¹] (true east)."""
        return wind_components(self.speed_ms, self.direction_deg)[0]

    @property
    def v(self) -> NDArray[np.float64]:
        """Northward wind component [m s⁻¹] (true north)."""
        return wind_components(self.speed_ms, self.direction_deg)[1]


_ARRAY_FIELDS: Final = ("station", "t", "lat", "lon", "speed_ms", "direction_deg", "height_m",
                        "gust_ms")


# ------------------------------------------------------------------------------ reading
def unit_from_header(column: str) -> str | None:
    """Speed unit implied by a header suffix (``tws_kn`` -> ``"kn"``), or None."""
    c = column.strip().lower()
    for suffix, unit in _UNIT_SUFFIXES:
        if c.endswith(suffix):
            return unit
    return None


def parse_offset(text: str, where: str = "timezone") -> timezone:
    """Parse a fixed UTC offset such as ``"+01:00"``, ``"-0530"``, ``"Z"`` or ``"UTC"``."""
    s = text.strip()
    if s.upper() in ("Z", "UTC", "GMT", "+00:00", "00:00"):
        return UTC
    m = re.fullmatch(r"([+-])(\d{1,2}):?(\d{2})?", s)
    if not m:
        raise InputError(
            f"{where}: {text!r} is not a UTC offset; expected e.g. '+01:00', '-05:00' or 'Z' "
            "(named zones are not accepted: give the offset that applied on the day)"
        )
    sign = 1 if m.group(1) == "+" else -1
    delta = timedelta(hours=int(m.group(2)), minutes=int(m.group(3) or 0))
    if delta > timedelta(hours=14):
        raise InputError(f"{where}: offset {text!r} is larger than 14 hours")
    return timezone(sign * delta)


def map_columns(
    header: Sequence[str], columns: Mapping[str, str] | None = None, *, where: str = "CSV",
    aliases: Mapping[str, Sequence[str]] = COLUMN_ALIASES,
) -> dict[str, int]:
    """Map canonical column names to indices of ``header``.

    Parameters
    ----------
    header : sequence of str
        The file's header fields.
    columns : mapping, optional
        Explicit ``canonical -> file column`` mapping; takes precedence over aliases.
    where : str
        File name for messages.
    aliases : mapping of str to sequence of str
        Canonical name -> accepted lower-case headers (default: the station schema,
        :data:`COLUMN_ALIASES`; the track reader passes its own).

    Returns
    -------
    dict
        ``canonical name -> column index`` for every canonical column found.

    Raises
    ------
    InputError
        Unknown canonical names, explicit columns not in the header, or ambiguous
        aliases (two headers for one canonical column).
    """
    norm = [h.strip().lower() for h in header]
    out: dict[str, int] = {}
    problems: list[str] = []
    for canon, col in (columns or {}).items():
        if canon not in aliases:
            problems.append(f"columns.{canon}: unknown canonical column; expected one of "
                            + ", ".join(aliases))
            continue
        if not isinstance(col, str) or col.strip().lower() not in norm:
            problems.append(f"columns.{canon}: column {col!r} is not in the header "
                            f"({quote_header(header)})")
            continue
        out[canon] = norm.index(col.strip().lower())
    for canon, names in aliases.items():
        if canon in out:
            continue
        hits = [k for k, h in enumerate(norm) if h in names and k not in out.values()]
        if len(hits) > 1:
            problems.append(
                f"columns: {', '.join(header[k].strip() for k in hits)} could all be the "
                f"{canon!r} column; choose one with `columns: {{{canon}: <name>}}`"
            )
        elif hits:
            out[canon] = hits[0]
    if problems:
        raise InputError(format_problems(f"{where}: cannot map the CSV columns", problems))
    return out


TIME_PARTS: Final = ("year", "month", "day", "hour", "minute", "second")
"""Split date/time columns that can stand in for ``time`` (``columns`` may map them)."""

_PART_ALIASES: Final[dict[str, tuple[str, ...]]] = {
    "year": ("year", "yyyy", "yy", "#yy", "yr", "#yr"),
    "month": ("month", "mo", "mon", "mth"),
    "day": ("day", "dd", "dy"),
    "hour": ("hour", "hh", "hr"),
    "minute": ("minute", "min", "mn", "mi"),
    "second": ("second", "sec", "ss"),
}
_PART_CASED: Final = {"MM": "month", "mm": "minute"}  # NDBC: '#YY MM DD hh mm'


def time_part_columns(header: Sequence[str], columns: Mapping[str, str] | None = None, *,
                      where: str = "CSV") -> dict[str, int]:
    """Indices of split date/time columns (year, month, day, hour[, minute, second]).

    ``MM`` (upper case) is the month and ``mm`` the minute, as in NDBC's
    ``#YY MM DD hh mm``; other names are matched case-insensitively.  Returns an
    empty dict unless at least year, month, day and hour are found.

    Raises
    ------
    InputError
        A mapped column is not in the header, or ``mm`` could be month or minute.
    """
    stripped = [h.strip() for h in header]
    norm = [h.lower() for h in stripped]
    out: dict[str, int] = {}
    for part, col in (columns or {}).items():
        if part in TIME_PARTS:
            if col.strip().lower() not in norm:
                raise InputError(f"{where}: columns.{part}: column {col!r} is not in the header "
                                 f"({', '.join(stripped)})")
            out[part] = norm.index(col.strip().lower())
    for k, h in enumerate(stripped):
        found = _PART_CASED.get(h)
        if found is None:
            found = next((q for q, names in _PART_ALIASES.items() if h.lower() in names), None)
        if found is not None and found not in out and k not in out.values():
            out[found] = k
    if "minute" in out and "month" not in out and stripped[out["minute"]] == "mm":
        raise InputError(f"{where}: column 'mm' could be the month or the minute; say which "
                         "with `columns: {month: mm}` or `columns: {minute: mm}` (NDBC writes "
                         "the month as MM and the minute as mm)")
    return out if all(q in out for q in TIME_PARTS[:4]) else {}


def _table_text(source: Any) -> tuple[str, str]:
    """``(text, name)`` of a station table: a CSV file, or a pandas DataFrame as CSV."""
    if type(source).__name__ == "DataFrame" and hasattr(source, "to_csv"):
        df = source
        import pandas as pd

        if isinstance(df.index, pd.DatetimeIndex):
            df = df.reset_index(names=df.index.name or "time")
        return df.to_csv(index=False), "DataFrame"
    p = Path(source)
    if not p.is_file():
        raise InputError(f"{p}: station file not found; check the `path`")
    text = p.read_text(encoding="utf-8-sig", errors="replace")
    if looks_binary(text):
        raise WindDataError(f"{p}: not a text file (binary content); expected a station CSV "
                            "with a header row such as time,station,lat,lon,speed,direction")
    return text, str(p)


def read_stations(
    path: str | Path | Any,
    *,
    columns: Mapping[str, str] | None = None,
    speed_unit: str | None = None,
    timezone: str | None = None,
    missing: Sequence[str] = DEFAULT_MISSING,
    station: str | None = None,
    position: tuple[float, float] | None = None,
    height_m: float | None = None,
    resample_s: float | None = None,
    min_fill: float = 0.5,
) -> StationData:
    """Read a station wind CSV.

    Parameters
    ----------
    path : str, Path or pandas.DataFrame
        CSV file (``,``, ``;``, tab or blank separated; lines starting with ``#``
        are skipped), or a DataFrame with the same columns (a ``DatetimeIndex``
        counts as the ``time`` column; line numbers in messages then count the
        header as line 1).
    columns : mapping, optional
        ``canonical -> file column`` for headers that the built-in aliases do not
        know; also ``year``, ``month``, ``day``, ``hour``, ``minute``, ``second``
        for split date/time columns.
    speed_unit : str, optional
        Unit of ``speed`` and ``gust``: ``m/s``, ``kn``, ``km/h`` or ``mph``.  When
        omitted, the speed header's suffix decides (``tws_kn`` -> kn,
        ``wspd_m_s`` -> m/s); a plain ``speed`` header then is an error, because a
        wrong guess would silently scale every speed.
    timezone : str, optional
        UTC offset (``"+01:00"``) applied to timestamps that carry none.  Without it
        a naive timestamp is an error naming the line.  Without a ``time`` column
        the time is built from year/month/day/hour[/minute/second] columns
        (``#YY MM DD hh mm`` as NDBC writes them: UTC), which carry no offset either.
    missing : sequence of str
        Cell values that mean "no data" (compared after stripping blanks).
    station : str, optional
        Station id when the file has no ``station`` column (default: the file stem).
    position : (float, float), optional
        ``(lat, lon)`` [°] of a fixed station when the file has no ``lat``/``lon``.
    height_m : float, optional
        Measurement height [m] when the file has no ``height_m`` column.
    resample_s : float, optional
        Average into bins of this many seconds (see :func:`resample_stations`).
    min_fill : float
        With ``resample_s``: drop bins holding less than this fraction of the
        samples a full bin would hold.

    Returns
    -------
    StationData

    Raises
    ------
    InputError / WindDataError
        Empty file, unknown or ambiguous columns, undeclared unit, unreadable
        numbers or times (naming line and column), naive times without
        ``timezone``, values out of range, times that do not increase per station.
    """
    text, name = _table_text(path)
    p = Path(name)
    all_lines = text.splitlines()
    lines = [(k + 1, ln) for k, ln in enumerate(all_lines)
             if ln.strip() and not ln.lstrip().startswith("#")]
    if all_lines and all_lines[0].startswith(("#YY", "#yy", "#YYYY")):  # NDBC-style header
        lines = [(1, all_lines[0].lstrip("#")), *lines]
    if not lines:
        raise WindDataError(
            f"{name}: the file is empty; expected a header row (e.g. "
            "time,station,lat,lon,speed,direction) followed by data rows"
        )
    delim = max((",", ";", "\t"), key=lines[0][1].count)
    if not lines[0][1].count(delim) and len(lines[0][1].split()) > 1:
        delim = " "  # blank separated (NDBC-like text)
        rows = [ln.split() for _, ln in lines]
    else:
        rows = csv_rows(lines, delim, name)
    header, body = rows[0], rows[1:]
    linenos = [k for k, _ in lines[1:]]
    canon_cols = {k: v for k, v in (columns or {}).items() if k not in TIME_PARTS}
    cmap = map_columns(header, canon_cols, where=name)
    parts: dict[str, int] = {}
    if "time" not in cmap:
        parts = time_part_columns(header, columns, where=name)
        if parts and timezone is None and header[parts["year"]].strip().upper() in ("YY", "#YY"):
            timezone = "Z"  # NDBC's #YY MM DD hh mm columns are UTC
    need = list(REQUIRED_COLUMNS) + ([] if position is not None else ["lat", "lon"])
    absent = [c for c in need if c not in cmap and not (c == "time" and parts)]
    if absent and not looks_like_header(header):
        raise InputError(
            f"{name}: not a station CSV: line {lines[0][0]} is not a header of column names; "
            "expected a header row such as time,station,lat,lon,speed_kn,direction (names and "
            "aliases: docs/course-format.md)")
    if absent:
        raise InputError(
            f"{name}: no column for {', '.join(absent)}; header is "
            f"{quote_header(header)}. Rename the columns to the canonical "
            "names (time, station, lat, lon, speed, direction) or map them with `columns: "
            "{canonical: file_column}`" + (" or give `position: {lat, lon}` for a fixed "
                                           "station" if "lat" in absent else "")
            + (". The time may also come from year, month, day, hour[, minute, second] "
               "columns" if "time" in absent else "")
        )
    if not body:
        raise WindDataError(f"{name}: the file has a header but no data rows")
    column = header[cmap["speed"]]
    unit = column_speed_unit(column, speed_unit, name, unit_from_header(column))
    gust_unit = unit
    if "gust" in cmap and speed_unit is None and unit_from_header(header[cmap["gust"]]):
        gust_unit = unit_from_header(header[cmap["gust"]]) or unit
    tz = parse_offset(timezone, f"{name}: timezone") if timezone is not None else None
    miss = {m.strip() for m in missing}

    ncol = len(header)
    n = len(body)
    every = {**cmap, **{f"_{q}": k for q, k in parts.items()}}
    cols: dict[str, list[str]] = {c: [] for c in every}
    for r, lineno in zip(body, linenos, strict=True):
        if len(r) != ncol:
            raise WindDataError(
                f"{name}, line {lineno}: {len(r)} fields but the header has {ncol}; check "
                f"the separator ({delim!r}) and quoting"
            )
        for c, k in every.items():
            cols[c].append(r[k].strip())

    missing_by: dict[str, int] = {}
    values: dict[str, NDArray] = {}
    for c in ("lat", "lon", "speed", "direction", "height_m", "gust"):
        if c in cols:
            values[c], missing_by[c] = _numbers(cols[c], c, header[cmap[c]], linenos, miss, name)
    if parts:
        t, missing_by["time"] = _part_times({q: cols[f"_{q}"] for q in parts},
                                            {q: header[k].strip() for q, k in parts.items()},
                                            linenos, miss, tz, name)
    else:
        t, missing_by["time"] = _times(cols["time"], linenos, miss, tz, name,
                                       header[cmap["time"]])
    if "station" in cols:
        st = np.array([clean_text(v) for v in cols["station"]], dtype=object)
        st_missing = np.isin(st, list(miss))
        missing_by["station"] = int(st_missing.sum())
    else:
        st = np.full(n, clean_text(station if station is not None else p.stem), dtype=object)
        st_missing = np.zeros(n, dtype=bool)
    if position is not None and "lat" not in values:
        values["lat"] = np.full(n, float(position[0]))
        values["lon"] = np.full(n, float(position[1]))

    lat, lon = values["lat"], values["lon"]
    spd = values["speed"] * speed_factor(unit)
    dirn = values["direction"]
    h = values["height_m"] if "height_m" in values else np.full(
        n, np.nan if height_m is None else float(height_m))
    gust = values["gust"] * speed_factor(gust_unit) if "gust" in values else np.full(n, np.nan)

    _check_range(name, linenos, header[cmap["speed"]], spd, 0.0, np.inf, "speeds must be >= 0")
    _check_range(name, linenos, header[cmap["direction"]], dirn, 0.0, 360.0,
                 "directions must lie in [0, 360] degrees (wind FROM, true)")
    if "lat" in cmap:
        _check_range(name, linenos, header[cmap["lat"]], lat, -90.0, 90.0, "latitude in [-90, 90]")
        _check_range(name, linenos, header[cmap["lon"]], lon, -180.0, 360.0,
                     "longitude in [-180, 360]")

    bad = np.isnan(t) | np.isnan(lat) | np.isnan(lon) | np.isnan(spd) | np.isnan(dirn) | st_missing
    keep = ~bad
    if not keep.any():
        raise WindDataError(
            f"{name}: every one of the {n} rows has a missing value in a needed column "
            f"(missing per column: {_fmt_counts(missing_by)}); check the `missing` markers "
            "and the column mapping"
        )
    ids = np.array([str(s) for s in st[keep]])
    data = StationData(
        station=ids, t=t[keep], lat=lat[keep], lon=lon[keep], speed_ms=spd[keep],
        direction_deg=np.mod(dirn[keep], 360.0), height_m=h[keep], gust_ms=gust[keep],
        source=name, n_raw=n, n_missing=int(bad.sum()),
        missing_by_column={k: v for k, v in missing_by.items() if v},
    )
    data = _sorted_checked(data, np.asarray(linenos)[keep], name,
                           allow_repeats=resample_s is not None)
    if resample_s is not None:
        data = resample_stations(data, resample_s, min_fill=min_fill)
    return data


def column_speed_unit(
    column: str, declared: str | None, where: str, implied: str | None = None
) -> str:
    """Unit of a speed column: the declared ``speed_unit`` or the header's unit suffix.

    Parameters
    ----------
    column : str
        Header of the column, for messages.
    declared : str, optional
        ``speed_unit`` given by the course file or ``--speed-unit``.
    where : str
        File name, for messages.
    implied : str, optional
        Unit the header names (``unit_from_header(column)`` or the caller's own
        reading of it); ``None``: none.

    Raises
    ------
    InputError
        Neither says, the declared unit is unknown, or the two disagree.
    """
    if declared is None:
        if implied is None:
            raise InputError(
                f"{where}: the unit of column {column!r} is not known; declare it with "
                "`speed_unit:` (--speed-unit on the command line; one of 'm/s', 'kn', 'km/h', "
                "'mph') or name the column with a unit suffix such as speed_kn / speed_m_s"
            )
        return implied
    try:
        f_decl = speed_factor(declared)
    except InputError as exc:
        raise InputError(f"{where}: speed_unit: {exc}") from None
    if implied is not None and not np.isclose(f_decl, speed_factor(implied)):
        raise InputError(
            f"{where}: speed_unit {declared!r} contradicts the column name {column!r} "
            f"(which says {implied!r}); fix one of them"
        )
    return declared


def _parse_cells(cells: list[str], miss: set[str], parse: Callable[[int, str], float]
                 ) -> tuple[NDArray, int]:
    """Parse a column cell by cell: ``parse(k, cell)``, or NaN for a missing marker.

    Returns the values and how many are missing (markers, and cells read as NaN).
    """
    out = np.array([np.nan if c in miss else parse(k, c) for k, c in enumerate(cells)],
                   dtype=float)
    return out, int(np.count_nonzero(np.isnan(out)))


def _numbers(cells: list[str], canon: str, column: str, linenos: list[int], miss: set[str],
             name: str) -> tuple[NDArray, int]:
    def number(k: int, c: str) -> float:
        try:
            v = float(c)
        except ValueError:
            raise WindDataError(
                f"{name}, line {linenos[k]}, column {column!r}: cannot read {excerpt(c)!r} as a "
                f"number ({canon}); if it marks missing data, add it to `missing`"
            ) from None
        if np.isinf(v):
            raise WindDataError(
                f"{name}, line {linenos[k]}, column {column!r}: {excerpt(c)!r} is not a finite "
                f"number ({canon}); replace it with a value or a missing marker"
            )
        return v

    return _parse_cells(cells, miss, number)


def _times(cells: list[str], linenos: list[int], miss: set[str], tz: timezone | None, name: str,
           column: str) -> tuple[NDArray, int]:
    def epoch(k: int, c: str) -> float:
        s = c[:-1] + "+00:00" if c.endswith(("Z", "z")) else c
        try:
            dt = datetime.fromisoformat(s)
        except ValueError:
            raise WindDataError(
                f"{name}, line {linenos[k]}, column {column!r}: cannot read {excerpt(c)!r} as an "
                "ISO 8601 time; expected e.g. 2018-02-15T10:34:58+01:00"
            ) from None
        if dt.tzinfo is None:
            if tz is None:
                raise InputError(
                    f"{name}, line {linenos[k]}, column {column!r}: time {c!r} has no UTC "
                    f"offset; add it to the file (e.g. {c}+01:00 or {c}Z) or declare the "
                    "logger's offset with `timezone: '+01:00'`"
                )
            dt = dt.replace(tzinfo=tz)
        return dt.timestamp()

    return _parse_cells(cells, miss, epoch)


def _part_times(cells: Mapping[str, list[str]], headers: Mapping[str, str], linenos: list[int],
                miss: set[str], tz: timezone | None, name: str) -> tuple[NDArray, int]:
    """Epoch seconds from split year/month/day/hour[/minute/second] columns."""
    if tz is None:
        cols = "/".join(headers.values())
        raise InputError(
            f"{name}: times from the columns {cols} carry no UTC offset; declare it with "
            "`timezone: 'Z'` (UTC, as NDBC and most loggers write) or e.g. `timezone: '+01:00'`"
        )
    n = len(next(iter(cells.values())))
    out = np.full(n, np.nan)
    for k in range(n):
        vals = {q: c[k] for q, c in cells.items()}
        if any(v in miss for v in vals.values()):
            continue
        try:
            num = {q: int(float(v)) for q, v in vals.items()}
            year = num["year"]
            if year < 100:  # two-digit years (old NDBC files): 50..99 -> 19xx
                year += 1900 if year >= 50 else 2000
            out[k] = datetime(year, num["month"], num["day"], num["hour"], num.get("minute", 0),
                              num.get("second", 0), tzinfo=tz).timestamp()
        except ValueError:
            shown = excerpt(" ".join(f"{headers[q]}={v}" for q, v in vals.items()))
            raise WindDataError(
                f"{name}, line {linenos[k]}: cannot read the date/time columns ({shown}) as a "
                "date; expected whole numbers (year, month 1-12, day, hour 0-23, ...)"
            ) from None
    return out, int(np.count_nonzero(np.isnan(out)))


def _check_range(name: str, linenos: list[int], column: str, a: NDArray, lo: float, hi: float,
                 what: str) -> None:
    bad = np.nonzero((a < lo) | (a > hi))[0]
    if bad.size:
        k = int(bad[0])
        raise WindDataError(
            f"{name}, line {linenos[k]}, column {column!r}: value {a[k]:g} is out of range "
            f"({what}); {bad.size} row(s) affected"
        )


def _fmt_counts(d: Mapping[str, int]) -> str:
    return ", ".join(f"{k} {v}" for k, v in d.items() if v) or "none"


def _sorted_checked(data: StationData, linenos: NDArray, name: str, *,
                    allow_repeats: bool = False) -> StationData:
    """Group by station (first appearance) and check times increase within each station.

    Repeated timestamps (1 Hz loggers with a 1 s clock jitter) are accepted only
    when the data will be resampled into bins anyway.
    """
    order_ids = {s: k for k, s in enumerate(data.stations)}
    key = np.array([order_ids[s] for s in data.station])
    order = np.argsort(key, kind="stable")
    data = replace(data, **{k: getattr(data, k)[order] for k in _ARRAY_FIELDS})
    linenos = linenos[order]
    key = key[order]
    same = key[1:] == key[:-1]
    dt = np.diff(data.t)
    bad = np.nonzero(same & ((dt < 0) if allow_repeats else (dt <= 0)))[0]
    if bad.size:
        k = int(bad[0])
        repeat = data.t[k + 1] == data.t[k]
        kind = "repeats the time of" if repeat else "goes back in time from"
        fix = ("Remove the duplicated rows, or average them away with `resample_s` (e.g. 10)."
               if repeat else "Sort the file by time.")
        raise WindDataError(
            f"{name}, line {linenos[k + 1]}: time {iso(data.t[k + 1])} of station "
            f"{str(data.station[k + 1])!r} {kind} line {linenos[k]} ({iso(data.t[k])}); times "
            f"must increase within each station. {fix}"
        )
    return data


# ------------------------------------------------------------------------------ resample
def resample_stations(data: StationData, interval_s: float, *, min_fill: float = 0.5
                      ) -> StationData:
    """Average records into fixed intervals per station.

    Bins are aligned to multiples of ``interval_s`` since the epoch (UTC clock),
    and each output record is stamped at its bin's centre.  Speed is the scalar
    mean of the speeds (what an anemometer's mean speed reports); direction is
    that of the mean wind vector (``u``, ``v`` averaged), so a wind swinging
    across north averages to north, not south.  Position and height are means,
    gust is the bin's maximum.  Bins with fewer than ``min_fill`` times the
    samples of a full bin (at the station's median sampling interval) are
    dropped, so a 2-sample bin at the end of a log does not stand for a full minute.

    Parameters
    ----------
    data : StationData
        Raw records.
    interval_s : float
        Bin length [s], > 0.
    min_fill : float
        Minimum filled fraction of a bin, in [0, 1].

    Returns
    -------
    StationData
        Resampled records (``n_raw``/``n_missing`` carried over).
    """
    if not (interval_s > 0):
        raise InputError(f"resample_s must be a positive number of seconds, got {interval_s!r}")
    if len(data) == 0:
        return data
    ids = data.stations
    lookup = {s: k for k, s in enumerate(ids)}
    sidx = np.array([lookup[s] for s in data.station], dtype=np.int64)
    b = np.floor(data.t / interval_s).astype(np.int64)
    key = sidx.astype(np.int64) * (1 << 40) + (b - b.min())
    uniq, first, inv, counts = np.unique(key, return_index=True, return_inverse=True,
                                         return_counts=True)
    u, v = data.u, data.v

    def mean(a: NDArray) -> NDArray:
        return np.bincount(inv, weights=a, minlength=uniq.size) / counts

    expected = np.empty(uniq.size)
    for k in range(len(ids)):
        m = sidx == k
        dt = np.median(np.diff(data.t[m])) if m.sum() > 1 else interval_s
        expected[sidx[first] == k] = max(interval_s / max(dt, 1e-9), 1.0)
    keep = counts >= min_fill * expected
    um, vm = mean(u), mean(v)
    _, dirn = wind_speed_direction(um, vm)
    gust = np.full(uniq.size, -np.inf)
    np.maximum.at(gust, inv, np.where(np.isnan(data.gust_ms), -np.inf, data.gust_ms))
    gust[~np.isfinite(gust)] = np.nan
    out = StationData(
        station=data.station[first], t=(b[first] + 0.5).astype(np.float64) * interval_s,
        lat=mean(data.lat), lon=mean(data.lon), speed_ms=mean(data.speed_ms), direction_deg=dirn,
        height_m=mean(data.height_m), gust_ms=gust, source=data.source, n_raw=data.n_raw,
        n_missing=data.n_missing, missing_by_column=data.missing_by_column,
    )
    return replace(out, **{k: getattr(out, k)[keep] for k in _ARRAY_FIELDS})


def local_records(
    data: StationData,
    frame: LocalFrame,
    height_m: float | None,
    name: str,
    *,
    shear: str = "power",
    exponent: float = DEFAULT_EXPONENT,
    roughness_m: float = DEFAULT_ROUGHNESS_M,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Positions and winds of the records in the local frame, at a target height.

    Parameters
    ----------
    data : StationData
        Station records.
    frame : LocalFrame
        The local frame.
    height_m : float or None
        Target height [m]; each record is scaled from its ``height_m`` with the
        power law (``exponent``) or the log law (``shear="log"``, ``roughness_m``).
        ``None``: as measured.
    name : str
        Label for messages.
    shear : {"power", "log"}
        Height-correction law.
    exponent : float
        Power-law exponent [-].
    roughness_m : float
        Log-law roughness length [m].

    Returns
    -------
    x, y : ndarray
        Record positions [m].
    u, v : ndarray
        Record winds, local-frame components [m s⁻¹].

    Raises
    ------
    InputError
        ``height_m`` is set but a record's measurement height is unknown.
    """
    x, y = frame.to_xy(data.lat, data.lon)
    ue, ve = data.u, data.v
    if height_m is not None:
        if np.any(np.isnan(data.height_m)):
            raise InputError(
                f"{name}: a target height_m is set but the measurement height is unknown "
                f"for {data.source or 'the stations'}; add a height_m column or give the "
                "stations' height (`measurement_height_m`)"
            )
        f = (power_law_factor(data.height_m, height_m, exponent) if shear == "power" else
             log_law_factor(data.height_m, height_m, roughness_m))
        ue, ve = ue * f, ve * f
    u, v = earth_to_local(ue, ve, frame.grid_north_deg(data.lat, data.lon))
    return x, y, u, v


# ------------------------------------------------------------------------------ field
RbfKernel = Literal["thin_plate_spline", "linear", "cubic", "quintic", "multiquadric",
                    "inverse_multiquadric", "inverse_quadratic", "gaussian"]
"""Kernel names of :class:`scipy.interpolate.RBFInterpolator`."""


@dataclass(frozen=True, eq=False)
class _StationState:
    """What a :class:`StationWind` derives from its inputs (built once, when it is made)."""

    series: tuple  # per station: (id, t, x, y, u, v) arrays in the local frame
    cov: Coverage
    moving: bool  # some station moves (coach boat)
    rbf: Any  # RBF interpolator of station weights (method "rbf"), else None
    limit: str = ""  # which station's records limit the common time span ("" if one station)


@dataclass(frozen=True, eq=False)
class StationWind:
    """Wind field interpolated from station records.

    Parameters
    ----------
    data : StationData
        The records (resample high-rate logs first).
    frame : LocalFrame
        The course's local frame.
    method : {"idw", "rbf"}
        Spatial interpolation: inverse-distance weighting (``power``), or a scipy
        :class:`~scipy.interpolate.RBFInterpolator` (``rbf_kernel``; fixed
        stations only).  Both reproduce a station's value at its position and a
        constant wind exactly.
    power : float
        IDW exponent (2: weights ``1/d²``).
    radius_m : float
        Coverage = the stations' bounding box (every recorded position) expanded
        by this [m].  Far from the stations an interpolant is an extrapolation,
        which was the thesis's main failure, so the box is kept tight.
    max_gap_s : float
        A station whose records are further apart than this inside the common
        time span is an error (no silent bridging of outages) [s].
    height_m : float, optional
        Target height [m]; records are scaled from their ``height_m`` with the
        power law (``exponent``) or log law (``shear="log"``).  ``None``: as measured.
    shear : {"power", "log"}
    exponent : float
        Power-law exponent for the height correction [-].
    roughness_m : float
        Log-law roughness length [m].
    rbf_kernel : str
        Kernel for ``method="rbf"`` (see scipy; :data:`RbfKernel`).
    clamp : bool
        Clamp points to the coverage instead of raising.
    name : str
        Label for messages.
    time_window : (float, float), optional
        The race window [epoch s].  Gaps longer than ``max_gap_s`` are then an
        error only inside it: a month-long record with an outage a week before
        the race is usable, and the coverage is the gap-free stretch around the
        window.  ``None``: every gap inside the stations' common span counts.

    Notes
    -----
    Coverage in time is the span during which *every* station reports (the
    intersection), so no station drops out mid-race.  Between records each
    station's ``(u, v)`` (and position) is interpolated linearly in time.
    """

    data: StationData
    frame: LocalFrame
    method: str = "idw"
    power: float = 2.0
    radius_m: float = 2000.0
    max_gap_s: float = 1800.0
    height_m: float | None = None
    shear: str = "power"
    exponent: float = DEFAULT_EXPONENT
    roughness_m: float = DEFAULT_ROUGHNESS_M
    rbf_kernel: RbfKernel = "thin_plate_spline"
    clamp: bool = False
    name: str = "station wind"
    time_window: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        self._state  # noqa: B018  (built now: building it checks the inputs)

    @cached_property
    def _state(self) -> _StationState:
        """Per-station series, coverage and interpolator (checked and built once)."""
        d = self.data
        if len(d) == 0:
            raise WindDataError(f"{self.name}: no station records")
        if self.method not in ("idw", "rbf"):
            raise InputError(f"{self.name}: method {self.method!r}; expected 'idw' or 'rbf'")
        if self.shear not in ("power", "log"):
            raise InputError(f"{self.name}: shear {self.shear!r}; expected 'power' or 'log'")
        if not (self.radius_m >= 0) or not (self.power > 0) or not (self.max_gap_s > 0):
            raise InputError(f"{self.name}: radius_m must be >= 0, power and max_gap_s > 0")
        x, y, ul, vl = local_records(d, self.frame, self.height_m, self.name, shear=self.shear,
                                     exponent=self.exponent, roughness_m=self.roughness_m)
        series = []
        moving = False
        for s in d.stations:
            m = d.station == s
            ts = d.t[m]
            moving |= bool(np.ptp(x[m]) > 1e-6 or np.ptp(y[m]) > 1e-6)
            series.append((s, ts, x[m], y[m], ul[m], vl[m]))
        spans = [_gap_free_span(ts, self.time_window, self.max_gap_s) if
                 self.time_window is not None else (float(ts[0]), float(ts[-1]))
                 for _, ts, *_ in series]
        t0 = max(a for a, _ in spans)
        t1 = min(b for _, b in spans)
        if t0 > t1:
            spans_txt = "; ".join(f"{s[0]}: {iso(a)} .. {iso(b)}"
                                  for s, (a, b) in zip(series, spans, strict=True))
            raise WindDataError(
                f"{self.name}: the stations never report at the same time ({spans_txt}); "
                "use stations with overlapping records"
            )
        lo, hi = (t0, t1) if self.time_window is None else (
            max(t0, self.time_window[0]), min(t1, self.time_window[1]))
        for s, ts, *_ in series:
            if lo > hi:
                break
            if self.time_window is None:
                edges = np.concatenate([[lo], ts[(ts >= lo) & (ts <= hi)], [hi]])
            else:  # the records around the window too: a gap is bridged from record to record
                k0 = max(int(np.searchsorted(ts, lo, side="right")) - 1, 0)
                k1 = int(np.searchsorted(ts, hi, side="left")) + 1
                edges = ts[k0:k1]
            gaps = np.diff(edges)
            if gaps.size and gaps.max() > self.max_gap_s:
                k = int(np.argmax(gaps))
                where = "" if self.time_window is None else " inside the race window"
                raise WindDataError(
                    f"{self.name}: station {s!r} has no record from {iso(edges[k])} to "
                    f"{iso(edges[k + 1])}{where} ({gaps[k] / 60:.0f} min > max_gap_s "
                    f"{self.max_gap_s / 60:.0f} min); the wind there would be a guess. "
                    "Restrict the race window, drop that station, or raise max_gap_s."
                )
        rbf = None
        if self.method == "rbf":
            if moving:
                raise InputError(f"{self.name}: method 'rbf' needs fixed stations; a station "
                                 "moves (coach boat?) -- use method 'idw'")
            from scipy.interpolate import RBFInterpolator

            pts = np.array([[s[2][0], s[3][0]] for s in series])
            # A degree-1 polynomial needs 3 non-collinear stations; with fewer, use the
            # linear kernel with a constant term (still exact at the stations).
            kernel: RbfKernel = self.rbf_kernel if len(series) >= 3 else "linear"
            deg = None if len(series) >= 3 else 0
            try:
                rbf = RBFInterpolator(pts, np.eye(len(series)), kernel=kernel, degree=deg)
            except (ValueError, np.linalg.LinAlgError) as exc:
                raise InputError(f"{self.name}: RBF interpolation failed for these stations "
                                 f"({exc}); use method 'idw'") from None
        cov = Coverage(t0, t1, float(x.min()) - self.radius_m, float(x.max()) + self.radius_m,
                       float(y.min()) - self.radius_m, float(y.max()) + self.radius_m,
                       frame=self.frame, source_span=(float(d.t.min()), float(d.t.max())))
        limit = ""
        if len(series) > 1:
            k0 = max(range(len(spans)), key=lambda k: spans[k][0])
            k1 = min(range(len(spans)), key=lambda k: spans[k][1])
            src = f" of {d.source}" if d.source else ""
            limit = (f"the time span is limited by station {series[k0][0]!r}{src} (first record "
                     f"{iso(spans[k0][0])}) and station {series[k1][0]!r} (last record "
                     f"{iso(spans[k1][1])})")
        return _StationState(tuple(series), cov, moving, rbf, limit)

    @property
    def coverage(self) -> Coverage:
        """Common time span of the stations; their box plus ``radius_m``."""
        return self._state.cov

    def station_values(self, t: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """Per-station ``(x, y, u, v)`` interpolated at times ``t``, each shape ``(n, S)``."""
        cols: list[list[NDArray]] = [[], [], [], []]
        moving = self._state.moving
        for _, ts, xs, ys, us, vs in self._state.series:
            for c, a, moves in zip(cols, (xs, ys, us, vs), (moving, moving, True, True),
                                   strict=True):
                if not moves or a.size == 1:
                    c.append(np.full(t.shape, a[0]))
                else:
                    c.append(np.interp(t, ts, a))
        x, y, u, v = (np.stack(c, axis=-1) for c in cols)
        return x, y, u, v

    @property
    def station_ids(self) -> tuple[str, ...]:
        """Station ids in the order of the weight columns."""
        return tuple(s[0] for s in self._state.series)

    def weights(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> NDArray:
        """Normalised spatial weights ``(n, S)`` of the stations at points ``(t, x, y)``.

        Points are flattened; no coverage check (used by :class:`BlendedWind`-style
        diagnostics).
        """
        t, x, y = (a.ravel() for a in np.broadcast_arrays(
            np.asarray(t, float), np.asarray(x, float), np.asarray(y, float)))
        if self._state.rbf is not None:
            return self._state.rbf(np.column_stack([x, y]))
        sx, sy, _, _ = self.station_values(t)
        return idw_weights(x, y, sx, sy, self.power)

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s] and local ``x, y`` [m] (broadcast).

        Outside the coverage the :class:`~sailroute.errors.OutOfCoverageError` names
        the stations (logs) whose first and last records limit the common time span.
        """
        try:
            t, x, y = prepare_points(self._state.cov, t, x, y, clamp=self.clamp,
                                     name=self.name)
        except OutOfCoverageError as e:
            if not self._state.limit:
                raise
            raise OutOfCoverageError(f"{e}\n  ({self._state.limit})") from None
        shape = t.shape
        t, x, y = t.ravel(), x.ravel(), y.ravel()
        sx, sy, su, sv = self.station_values(t)
        if self._state.rbf is not None:
            w = self._state.rbf(np.column_stack([x, y]))
        elif len(self._state.series) == 1:
            w = np.ones((t.size, 1))
        else:
            w = idw_weights(x, y, sx, sy, self.power)
        u = np.einsum("ns,ns->n", w, su)
        v = np.einsum("ns,ns->n", w, sv)
        return u.reshape(shape), v.reshape(shape)


def _gap_free_span(ts: NDArray, window: tuple[float, float], max_gap_s: float
                   ) -> tuple[float, float]:
    """The stretch of records around ``window`` without a gap longer than ``max_gap_s``.

    Gaps that overlap the window itself are left in (the caller reports them);
    a window outside the records gives the whole record (the coverage check
    then reports it).
    """
    cut = np.nonzero(np.diff(ts) > max_gap_s)[0]
    starts = np.concatenate([[0], cut + 1])
    ends = np.concatenate([cut, [ts.size - 1]])
    w0, w1 = window
    first = int(np.searchsorted(ts[ends], w0, side="left"))  # first stretch ending >= w0
    last = int(np.searchsorted(ts[starts], w1, side="right")) - 1  # last starting <= w1
    if first >= starts.size or last < 0 or first > last:
        return float(ts[0]), float(ts[-1])
    return float(ts[starts[first]]), float(ts[ends[last]])


def idw_weights(x: NDArray, y: NDArray, sx: NDArray, sy: NDArray, power: float = 2.0
                ) -> NDArray[np.float64]:
    """Inverse-distance weights ``(n, S)`` normalised to sum 1 per point.

    Parameters
    ----------
    x, y : ndarray (n,)
        Points [m].
    sx, sy : ndarray (n, S) or (1, S)
        Station positions [m].
    power : float
        Exponent ``p`` in ``w = 1 / d^p``.

    Returns
    -------
    ndarray (n, S)
        A point on a station gets weight 1 for it (to within 1e-12).
    """
    d2 = (x[:, None] - sx) ** 2 + (y[:, None] - sy) ** 2
    d2 = np.maximum(d2, 1e-24)
    w = d2 ** (-0.5 * power) if power != 2.0 else 1.0 / d2
    return w / w.sum(axis=1, keepdims=True)
