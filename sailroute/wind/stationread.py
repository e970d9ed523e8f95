"""Station records (:class:`StationData`): read from a CSV or a DataFrame, checked, resampled.

:func:`read_stations` reads the cells of the columns that :mod:`sailroute.tabular`
found, missing markers counted and their rows dropped, values in SI units and checked
(ranges, times increasing per station); :func:`resample_stations` averages 1-20 Hz logs into
fixed intervals.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.errors import InputError, WindDataError
from sailroute.tabular import (
    DEFAULT_MISSING,
    parse_offset,
    speed_units,
    split_fields,
    station_columns,
    table_lines,
)
from sailroute.textin import clean_text, excerpt, looks_binary
from sailroute.timeutil import iso, iso_datetime
from sailroute.units import speed_factor, wind_components, wind_speed_direction


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


_ARRAY_FIELDS: Final = (
    "station",
    "t",
    "lat",
    "lon",
    "speed_ms",
    "direction_deg",
    "height_m",
    "gust_ms",
)


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
        raise WindDataError(
            f"{p}: not a text file (binary content); expected a station CSV "
            "with a header row such as time,station,lat,lon,speed,direction"
        )
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
    lines = table_lines(text)
    if not lines:
        raise WindDataError(
            f"{name}: the file is empty; expected a header row (e.g. "
            "time,station,lat,lon,speed,direction) followed by data rows"
        )
    rows, delim = split_fields(lines, name)
    header, body = rows[0], rows[1:]
    linenos = [k for k, _ in lines[1:]]
    cmap, parts, timezone = station_columns(
        header,
        columns,
        position=position is not None,
        timezone=timezone,
        name=name,
        lineno=lines[0][0],
    )
    if not body:
        raise WindDataError(f"{name}: the file has a header but no data rows")
    unit, gust_unit = speed_units(header, cmap, speed_unit, name)
    tz = parse_offset(timezone, f"{name}: timezone") if timezone is not None else None
    miss = {m.strip() for m in missing}

    n = len(body)
    cols = _column_cells(
        body, linenos, {**cmap, **{f"_{q}": k for q, k in parts.items()}}, len(header), delim, name
    )
    values, missing_by = _column_values(cols, header, cmap, linenos, miss, name)
    if parts:
        t, missing_by["time"] = _part_times(
            {q: cols[f"_{q}"] for q in parts},
            {q: header[k].strip() for q, k in parts.items()},
            linenos,
            miss,
            tz,
            name,
        )
    else:
        t, missing_by["time"] = _times(cols["time"], linenos, miss, tz, name, header[cmap["time"]])
    st, st_missing = _station_ids(
        cols.get("station"),
        miss,
        missing_by,
        n,
        station if station is not None else Path(name).stem,
    )
    if position is not None and "lat" not in values:
        values["lat"] = np.full(n, float(position[0]))
        values["lon"] = np.full(n, float(position[1]))

    lat, lon = values["lat"], values["lon"]
    spd = values["speed"] * speed_factor(unit)
    dirn = values["direction"]
    h = (
        values["height_m"]
        if "height_m" in values
        else np.full(n, np.nan if height_m is None else float(height_m))
    )
    gust = values["gust"] * speed_factor(gust_unit) if "gust" in values else np.full(n, np.nan)
    _check_ranges(name, linenos, header, cmap, (spd, dirn, lat, lon))

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
        station=ids,
        t=t[keep],
        lat=lat[keep],
        lon=lon[keep],
        speed_ms=spd[keep],
        direction_deg=np.mod(dirn[keep], 360.0),
        height_m=h[keep],
        gust_ms=gust[keep],
        source=name,
        n_raw=n,
        n_missing=int(bad.sum()),
        missing_by_column={k: v for k, v in missing_by.items() if v},
    )
    data = _sorted_checked(
        data, np.asarray(linenos)[keep], name, allow_repeats=resample_s is not None
    )
    if resample_s is not None:
        data = resample_stations(data, resample_s, min_fill=min_fill)
    return data


def _column_cells(
    body: list[list[str]],
    linenos: list[int],
    every: Mapping[str, int],
    ncol: int,
    delim: str,
    name: str,
) -> dict[str, list[str]]:
    """The stripped cells of the columns ``every`` (``key -> index``) of the data rows;
    a row without the header's ``ncol`` fields is an error naming its line."""
    cols: dict[str, list[str]] = {c: [] for c in every}
    for r, lineno in zip(body, linenos, strict=True):
        if len(r) != ncol:
            raise WindDataError(
                f"{name}, line {lineno}: {len(r)} fields but the header has {ncol}; check "
                f"the separator ({delim!r}) and quoting"
            )
        for c, k in every.items():
            cols[c].append(r[k].strip())
    return cols


def _column_values(
    cols: Mapping[str, list[str]],
    header: Sequence[str],
    cmap: Mapping[str, int],
    linenos: list[int],
    miss: set[str],
    name: str,
) -> tuple[dict[str, NDArray], dict[str, int]]:
    """The numeric columns present (lat, lon, speed, direction, height_m, gust) and their
    missing cells per column."""
    missing_by: dict[str, int] = {}
    values: dict[str, NDArray] = {}
    for c in ("lat", "lon", "speed", "direction", "height_m", "gust"):
        if c in cols:
            values[c], missing_by[c] = _numbers(cols[c], c, header[cmap[c]], linenos, miss, name)
    return values, missing_by


def _station_ids(
    cells: list[str] | None, miss: set[str], missing_by: dict[str, int], n: int, default: str
) -> tuple[NDArray, NDArray[np.bool_]]:
    """Station id of each row and where it is missing (counted into ``missing_by``); the
    ``default`` id for every row without a ``station`` column."""
    if cells is None:
        return np.full(n, clean_text(default), dtype=object), np.zeros(n, dtype=bool)
    st = np.array([clean_text(v) for v in cells], dtype=object)
    st_missing = np.isin(st, list(miss))
    missing_by["station"] = int(st_missing.sum())
    return st, st_missing


def _check_ranges(
    name: str,
    linenos: list[int],
    header: Sequence[str],
    cmap: Mapping[str, int],
    values: tuple[NDArray, NDArray, NDArray, NDArray],
) -> None:
    """Speed [m s⁻¹] >= 0, direction in [0, 360] and, from the file, lat and lon [°]."""
    spd, dirn, lat, lon = values
    _check_range(name, linenos, header[cmap["speed"]], spd, 0.0, np.inf, "speeds must be >= 0")
    _check_range(
        name,
        linenos,
        header[cmap["direction"]],
        dirn,
        0.0,
        360.0,
        "directions must lie in [0, 360] degrees (wind FROM, true)",
    )
    if "lat" in cmap:
        _check_range(name, linenos, header[cmap["lat"]], lat, -90.0, 90.0, "latitude in [-90, 90]")
        _check_range(
            name, linenos, header[cmap["lon"]], lon, -180.0, 360.0, "longitude in [-180, 360]"
        )


def _parse_cells(
    cells: list[str], miss: set[str], parse: Callable[[int, str], float]
) -> tuple[NDArray, int]:
    """Parse a column cell by cell: ``parse(k, cell)``, or NaN for a missing marker.

    Returns the values and how many are missing (markers, and cells read as NaN).
    """
    out = np.array([np.nan if c in miss else parse(k, c) for k, c in enumerate(cells)], dtype=float)
    return out, int(np.count_nonzero(np.isnan(out)))


def _numbers(
    cells: list[str], canon: str, column: str, linenos: list[int], miss: set[str], name: str
) -> tuple[NDArray, int]:
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


def _times(
    cells: list[str],
    linenos: list[int],
    miss: set[str],
    tz: timezone | None,
    name: str,
    column: str,
) -> tuple[NDArray, int]:
    def epoch(k: int, c: str) -> float:
        try:
            dt = iso_datetime(c)
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


def _part_times(
    cells: Mapping[str, list[str]],
    headers: Mapping[str, str],
    linenos: list[int],
    miss: set[str],
    tz: timezone | None,
    name: str,
) -> tuple[NDArray, int]:
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
            out[k] = datetime(
                year,
                num["month"],
                num["day"],
                num["hour"],
                num.get("minute", 0),
                num.get("second", 0),
                tzinfo=tz,
            ).timestamp()
        except ValueError:
            shown = excerpt(" ".join(f"{headers[q]}={v}" for q, v in vals.items()))
            raise WindDataError(
                f"{name}, line {linenos[k]}: cannot read the date/time columns ({shown}) as a "
                "date; expected whole numbers (year, month 1-12, day, hour 0-23, ...)"
            ) from None
    return out, int(np.count_nonzero(np.isnan(out)))


def _check_range(
    name: str, linenos: list[int], column: str, a: NDArray, lo: float, hi: float, what: str
) -> None:
    bad = np.nonzero((a < lo) | (a > hi))[0]
    if bad.size:
        k = int(bad[0])
        raise WindDataError(
            f"{name}, line {linenos[k]}, column {column!r}: value {a[k]:g} is out of range "
            f"({what}); {bad.size} row(s) affected"
        )


def _fmt_counts(d: Mapping[str, int]) -> str:
    return ", ".join(f"{k} {v}" for k, v in d.items() if v) or "none"


def _sorted_checked(
    data: StationData, linenos: NDArray, name: str, *, allow_repeats: bool = False
) -> StationData:
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
        fix = (
            "Remove the duplicated rows, or average them away with `resample_s` (e.g. 10)."
            if repeat
            else "Sort the file by time."
        )
        raise WindDataError(
            f"{name}, line {linenos[k + 1]}: time {iso(data.t[k + 1])} of station "
            f"{str(data.station[k + 1])!r} {kind} line {linenos[k]} ({iso(data.t[k])}); times "
            f"must increase within each station. {fix}"
        )
    return data


def resample_stations(
    data: StationData, interval_s: float, *, min_fill: float = 0.5
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
    uniq, first, inv, counts = np.unique(
        key, return_index=True, return_inverse=True, return_counts=True
    )
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
        station=data.station[first],
        t=(b[first] + 0.5).astype(np.float64) * interval_s,
        lat=mean(data.lat),
        lon=mean(data.lon),
        speed_ms=mean(data.speed_ms),
        direction_deg=dirn,
        height_m=mean(data.height_m),
        gust_ms=gust,
        source=data.source,
        n_raw=data.n_raw,
        n_missing=data.n_missing,
        missing_by_column=data.missing_by_column,
    )
    return replace(out, **{k: getattr(out, k)[keep] for k in _ARRAY_FIELDS})
