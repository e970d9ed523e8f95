"""The shape of a delimited table: header aliases, separators, units, UTC offsets.

What a station CSV or a track log looks like before its cells are read
(:mod:`sailroute.wind.stationread`, :mod:`sailroute.track.read`):
which header is which canonical column (:func:`map_columns`, :data:`COLUMN_ALIASES`), split
date/time columns (:func:`time_part_columns`), the separator (:func:`split_fields`), the
speed unit from the declared ``speed_unit`` or a header suffix (:func:`column_speed_unit`),
and a fixed UTC offset (:func:`parse_offset`).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from datetime import UTC, timedelta, timezone
from typing import Final

import numpy as np

from sailroute.errors import InputError, format_problems
from sailroute.textin import csv_rows, looks_like_header, quote_header
from sailroute.units import speed_factor

CANONICAL_COLUMNS: Final = (
    "time",
    "station",
    "lat",
    "lon",
    "speed",
    "direction",
    "height_m",
    "gust",
)
"""Column names of the canonical station CSV schema."""

REQUIRED_COLUMNS: Final = ("time", "speed", "direction")
"""Always required (``lat``/``lon`` unless ``position`` is given; ``station`` defaults)."""

_SPEED_SUFFIXES: Final = ("_kn", "_kt", "_kts", "_ms", "_m_s", "_mps", "_kmh", "_kph", "_mph")

COLUMN_ALIASES: Final[dict[str, tuple[str, ...]]] = {
    "time": (
        "time",
        "time_utc",
        "datetime",
        "datetime_utc",
        "datetime_local",
        "timestamp",
        "date_time",
        "utc",
        "time_iso",
        "t",
    ),
    "station": ("station", "station_id", "stationid", "id", "name", "sensor"),
    "lat": ("lat", "latitude", "lat_deg"),
    "lon": ("lon", "lng", "long", "longitude", "lon_deg"),
    "speed": (
        "speed",
        "tws",
        "wspd",
        "wind_speed",
        "windspeed",
        "ws",
        *(
            f"{base}{suffix}"
            for base in ("speed", "tws", "wspd", "wind_speed")
            for suffix in _SPEED_SUFFIXES
        ),
    ),
    "direction": (
        "direction",
        "twd",
        "twd_deg",
        "wdir",
        "wdir_deg",
        "wdir_deg_true",
        "wind_direction",
        "wind_dir",
        "winddir",
        "wd",
        "direction_deg",
        "dir",
    ),
    "height_m": ("height_m", "height", "z", "z_m", "anemometer_height_m", "sensor_height_m"),
    "gust": ("gust", "gst", "wind_gust", "gust_speed", *(f"gust{x}" for x in _SPEED_SUFFIXES)),
}
"""Built-in header aliases (case-insensitive) for each canonical column."""

DEFAULT_MISSING: Final = (
    "",
    "NA",
    "N/A",
    "NaN",
    "nan",
    "NAN",
    "null",
    "NULL",
    "None",
    "MM",
    "-",
    "--",
)
"""Cell values read as missing by default (add e.g. ``"999"`` for NDBC codes)."""

_UNIT_SUFFIXES: Final = (
    ("_m_s", "m/s"),
    ("_ms", "m/s"),
    ("_mps", "m/s"),
    ("_kn", "kn"),
    ("_km_h", "km/h"),
    ("_kt", "kn"),
    ("_kts", "kn"),
    ("_knots", "kn"),
    ("_kmh", "km/h"),
    ("_kph", "km/h"),
    ("_mph", "mph"),
)


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
    header: Sequence[str],
    columns: Mapping[str, str] | None = None,
    *,
    where: str = "CSV",
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
            problems.append(
                f"columns.{canon}: unknown canonical column; expected one of " + ", ".join(aliases)
            )
            continue
        if not isinstance(col, str) or col.strip().lower() not in norm:
            problems.append(
                f"columns.{canon}: column {col!r} is not in the header ({quote_header(header)})"
            )
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


def time_part_columns(
    header: Sequence[str], columns: Mapping[str, str] | None = None, *, where: str = "CSV"
) -> dict[str, int]:
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
                raise InputError(
                    f"{where}: columns.{part}: column {col!r} is not in the header "
                    f"({', '.join(stripped)})"
                )
            out[part] = norm.index(col.strip().lower())
    for k, h in enumerate(stripped):
        found = _PART_CASED.get(h)
        if found is None:
            found = next((q for q, names in _PART_ALIASES.items() if h.lower() in names), None)
        if found is not None and found not in out and k not in out.values():
            out[found] = k
    if "minute" in out and "month" not in out and stripped[out["minute"]] == "mm":
        raise InputError(
            f"{where}: column 'mm' could be the month or the minute; say which "
            "with `columns: {month: mm}` or `columns: {minute: mm}` (NDBC writes "
            "the month as MM and the minute as mm)"
        )
    return out if all(q in out for q in TIME_PARTS[:4]) else {}


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


def table_lines(text: str) -> list[tuple[int, str]]:
    """``(line number, line)`` of the header and data lines of a station table.

    Blank lines and lines starting with ``#`` are skipped, except an NDBC-style
    ``#YY MM DD hh mm`` header (its ``#`` removed).
    """
    all_lines = text.splitlines()
    lines = [
        (k + 1, ln)
        for k, ln in enumerate(all_lines)
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if all_lines and all_lines[0].startswith(("#YY", "#yy", "#YYYY")):  # NDBC-style header
        lines = [(1, all_lines[0].lstrip("#")), *lines]
    return lines


def split_fields(lines: list[tuple[int, str]], name: str) -> tuple[list[list[str]], str]:
    """Fields of every line and the separator: the most frequent of ``,``, ``;`` and tab
    in the header, else blanks (NDBC-like text) when the header has several words."""
    delim = max((",", ";", "\t"), key=lines[0][1].count)
    if not lines[0][1].count(delim) and len(lines[0][1].split()) > 1:
        return [ln.split() for _, ln in lines], " "  # blank separated (NDBC-like text)
    return csv_rows(lines, delim, name), delim


def station_columns(
    header: Sequence[str],
    columns: Mapping[str, str] | None,
    *,
    position: bool,
    timezone: str | None,
    name: str,
    lineno: int,
) -> tuple[dict[str, int], dict[str, int], str | None]:
    """Canonical columns, split date/time columns and the UTC offset of a station header.

    Parameters
    ----------
    header : sequence of str
        The header's fields (on line ``lineno``).
    columns : mapping, optional
        ``canonical -> file column`` (and ``year`` .. ``second`` for split times).
    position : bool
        A fixed position is given (``lat``/``lon`` are then not needed).
    timezone : str, optional
        The declared UTC offset; ``"Z"`` when omitted and the times come from NDBC's
        ``#YY MM DD hh mm`` columns (UTC).
    name : str
        File name, for messages.
    lineno : int
        Line of the header, for messages.

    Returns
    -------
    (dict, dict, str or None)
        ``canonical -> index`` (:func:`map_columns`), ``part -> index``
        (:func:`time_part_columns`; empty with a ``time`` column), and the offset.

    Raises
    ------
    InputError
        The first line is not a header, or a needed column is absent.
    """
    canon_cols = {k: v for k, v in (columns or {}).items() if k not in TIME_PARTS}
    cmap = map_columns(header, canon_cols, where=name)
    parts: dict[str, int] = {}
    if "time" not in cmap:
        parts = time_part_columns(header, columns, where=name)
        if parts and timezone is None and header[parts["year"]].strip().upper() in ("YY", "#YY"):
            timezone = "Z"  # NDBC's #YY MM DD hh mm columns are UTC
    need = list(REQUIRED_COLUMNS) + ([] if position else ["lat", "lon"])
    absent = [c for c in need if c not in cmap and not (c == "time" and parts)]
    if absent and not looks_like_header(header):
        raise InputError(
            f"{name}: not a station CSV: line {lineno} is not a header of column names; "
            "expected a header row such as time,station,lat,lon,speed_kn,direction (names and "
            "aliases: docs/course-format.md)"
        )
    if absent:
        raise InputError(
            f"{name}: no column for {', '.join(absent)}; header is "
            f"{quote_header(header)}. Rename the columns to the canonical "
            "names (time, station, lat, lon, speed, direction) or map them with `columns: "
            "{canonical: file_column}`"
            + (" or give `position: {lat, lon}` for a fixed station" if "lat" in absent else "")
            + (
                ". The time may also come from year, month, day, hour[, minute, second] columns"
                if "time" in absent
                else ""
            )
        )
    return cmap, parts, timezone


def speed_units(
    header: Sequence[str], cmap: Mapping[str, int], declared: str | None, name: str
) -> tuple[str, str]:
    """Units of the ``speed`` and ``gust`` columns (:func:`column_speed_unit`); the gust
    column's own unit suffix counts when no ``speed_unit`` is declared."""
    column = header[cmap["speed"]]
    unit = column_speed_unit(column, declared, name, unit_from_header(column))
    gust_unit = unit
    if "gust" in cmap and declared is None and unit_from_header(header[cmap["gust"]]):
        gust_unit = unit_from_header(header[cmap["gust"]]) or unit
    return unit, gust_unit
