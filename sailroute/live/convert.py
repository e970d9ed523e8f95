"""Instrument logs to NMEA 0183 replay files (``sailroute live-convert``).

:func:`nmea_lines` writes one second of instrument output as a typical instrument
network sends it: ``RMC`` (time, position, SOG, COG), ``HDT`` (heading), ``VHW``
(heading and speed through the water), ``MWV`` reference ``R`` (apparent wind) and
``MWD`` (true wind), each only when the log has the quantity.  Two readers give the
rows of the real logs the project uses (``tests/data/live/README.md``):

* ``trieste``: the Anemomind coach-boat log of 2018-02-15, Gulf of Trieste, CSV
  conversion (``coach_wind_1hz.csv``: ``datetime_local`` on the logger's clock,
  ``bs_kn``, ``awa_deg`` (0-360 clockwise from the bow), ``aws_kn``, ``hdg_deg``,
  ``tws_kn``, ``twd_deg``, ``sog_kn``, ``cog_deg``, ``lat``, ``lon``), with the logger's
  UTC offset (CET, +01:00, by default);
* ``tallinn``: the Tallinn Bay race log of 2023-09-27 (``kolmak_2023_09_27.csv``:
  ``time`` in UTC, ``lat``, ``lng``, ``sog``, ``cog``, ``hdg``, ``awa`` (0-180),
  ``aws``, ``tack`` (+1 starboard, −1 port)); only the apparent wind is written, so
  that a replay exercises the apparent-to-true conversion.

Both are read line by line (:mod:`sailroute.textin`): a binary file, a line whose
quotes do not pair up, a value that is not a number or out of :data:`LIMITS` (a
latitude of 91 would be written into ``RMC`` as it is) or a time outside the years
:mod:`sailroute.timeutil` accepts is an error naming the file and line.  A time written
with its own UTC offset keeps it.  The replay file is written whole or not at all, and
never over the log (:func:`sailroute.outdir.replacing`).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path

from sailroute.errors import InputError
from sailroute.live.nmeaout import sentence
from sailroute.nmea import lat_field, lon_field
from sailroute.outdir import check_out_file, replacing
from sailroute.textin import csv_rows, excerpt, looks_binary, text_lines
from sailroute.timeutil import check_time, iso_datetime, offset_text

FORMATS = ("trieste", "tallinn")


@dataclass(frozen=True)
class Row:
    """One second of a log, knots and degrees as instruments give them; None: not logged."""

    t: float
    lat: float
    lon: float
    sog_kn: float | None = None
    cog_deg: float | None = None
    hdg_deg: float | None = None
    stw_kn: float | None = None
    aws_kn: float | None = None
    awa_deg: float | None = None
    tws_kn: float | None = None
    twd_deg: float | None = None


LIMITS: dict[str, tuple[float, float]] = {
    "lat": (-90.0, 90.0),
    "lon": (-180.0, 180.0),
    "speed": (0.0, 100.0),
    "angle": (-360.0, 360.0),
    "tack": (-1.0, 1.0),
}
"""What a log's value may be: degrees of latitude and longitude, a speed [kn], an
angle [deg], the Tallinn log's tack (+1 starboard, -1 port)."""


class _Row:
    """One line of a log: its cells by column name, read and checked one by one."""

    def __init__(self, cells: dict[str, str], where: str, what: str, columns: str) -> None:
        self.cells, self.where, self.what, self.columns = cells, where, what, columns

    def error(self, why: str) -> InputError:
        return InputError(
            f"{self.where}: not a row of the {self.what} ({why}); expected the columns "
            f"{self.columns}"
        )

    def num(self, key: str, kind: str) -> float | None:
        """The number in column ``key`` within :data:`LIMITS` ``[kind]``; None if empty or NaN."""
        text = (self.cells.get(key) or "").strip()
        if not text:
            return None
        try:
            v = float(text)
        except ValueError:
            raise self.error(f"{key} {excerpt(text)!r} is not a number") from None
        if math.isnan(v):
            return None
        lo, hi = LIMITS[kind]
        if not lo <= v <= hi:
            raise self.error(f"{key} {excerpt(text)!r} is outside [{lo:g}, {hi:g}]")
        return v

    def time(self, key: str, offset_s: float | None, default_s: float) -> float:
        """Epoch seconds of column ``key``: a time with its own UTC offset keeps it (an
        ``offset_s`` given that differs is an error), one without takes ``offset_s`` or
        else ``default_s``."""
        text = self.cells.get(key)
        if text is None:
            raise self.error(f"no `{key}`")
        try:
            dt = iso_datetime(text)
        except ValueError:
            raise self.error(f"{key} {excerpt(text)!r} is not an ISO 8601 time") from None
        own = dt.utcoffset()
        if own is None:
            zone = default_s if offset_s is None else offset_s
            dt = dt.replace(tzinfo=timezone(timedelta(seconds=zone)))
        elif offset_s is not None and own.total_seconds() != offset_s:
            raise InputError(
                f"{self.where}: the time {excerpt(text)!r} carries its own UTC offset "
                f"({offset_text(own.total_seconds())}), not --utc-offset's "
                f"{offset_text(offset_s)}; leave --utc-offset out (a time with an offset "
                "keeps it) or correct the file"
            )
        return check_time(dt, self.where).timestamp()


def _rows(path: Path, what: str, columns: str) -> Iterator[_Row]:
    """The rows of a log CSV (header first), each line split on its own."""
    try:
        text = path.read_text(encoding="utf-8-sig", errors="replace")
    except OSError as exc:
        raise InputError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    if looks_binary(text):
        raise InputError(f"{path}: a binary file; expected the {what} (CSV: {columns})")
    numbered = [(k + 1, ln) for k, ln in enumerate(text_lines(text)) if ln.strip()]
    if not numbered:
        raise InputError(f"{path}: an empty file; expected the {what} (CSV: {columns})")
    rows = csv_rows(numbered, ",", str(path))
    header = [h.strip() for h in rows[0]]
    for (n, _), cells in zip(numbered[1:], rows[1:], strict=True):
        yield _Row(dict(zip(header, cells, strict=False)), f"{path}:{n}", what, columns)


def nmea_lines(row: Row, talker: str = "II") -> Iterator[str]:
    """The sentences of one log row, without line ends."""
    dt = datetime.fromtimestamp(row.t, UTC)
    hms = f"{dt:%H%M%S}.{dt.microsecond // 10000:02d}"
    la, lo = lat_field(row.lat), lon_field(row.lon)
    sog = "" if row.sog_kn is None else f"{row.sog_kn:.2f}"
    cog = "" if row.cog_deg is None else f"{row.cog_deg % 360:.1f}"
    yield sentence(
        f"GPRMC,{hms},A,{la[0]},{la[1]},{lo[0]},{lo[1]},{sog},{cog},{dt:%d%m%y},,,A"
    ).rstrip()
    if row.hdg_deg is not None:
        yield sentence(f"{talker}HDT,{row.hdg_deg % 360:.1f},T").rstrip()
        if row.stw_kn is not None:
            yield sentence(
                f"{talker}VHW,{row.hdg_deg % 360:.1f},T,,M,{row.stw_kn:.2f},N,"
                f"{row.stw_kn * 1.852:.2f},K"
            ).rstrip()
    if row.aws_kn is not None and row.awa_deg is not None:
        yield sentence(f"{talker}MWV,{row.awa_deg % 360:.1f},R,{row.aws_kn:.2f},N,A").rstrip()
    if row.tws_kn is not None and row.twd_deg is not None:
        yield sentence(
            f"{talker}MWD,{row.twd_deg % 360:.1f},T,,M,{row.tws_kn:.2f},N,"
            f"{row.tws_kn * 1852 / 3600:.2f},M"
        ).rstrip()


TRIESTE_COLUMNS = (
    "datetime_local, bs_kn, awa_deg, aws_kn, hdg_deg, tws_kn, twd_deg, sog_kn, cog_deg, lat, lon"
)
TALLINN_COLUMNS = "time, lat, lng, sog, cog, hdg, awa, aws, tack"


def _fixes(
    path: Path,
    what: str,
    columns: str,
    keys: tuple[str, str, str],
    offset_s: float | None,
    default_s: float,
) -> Iterator[tuple[_Row, float, float, float]]:
    """``(row, t, lat, lon)`` of every row of a log that has a position (the others are
    skipped); ``keys`` name the time, latitude and longitude columns."""
    for r in _rows(path, what, columns):
        t = r.time(keys[0], offset_s, default_s)
        lat, lon = r.num(keys[1], "lat"), r.num(keys[2], "lon")
        if lat is not None and lon is not None:
            yield r, t, lat, lon


def read_trieste(path: Path, utc_offset_s: float | None = None) -> list[Row]:
    """Rows of the Trieste coach-boat CSV (see the module docstring).

    ``utc_offset_s`` [s] is the logger's clock for times written without an offset
    (default +01:00); a time written with one keeps it, and an ``utc_offset_s`` that
    differs from it is an error.
    """
    keys = ("datetime_local", "lat", "lon")
    return [
        Row(
            t,
            lat,
            lon,
            r.num("sog_kn", "speed"),
            r.num("cog_deg", "angle"),
            r.num("hdg_deg", "angle"),
            r.num("bs_kn", "speed"),
            r.num("aws_kn", "speed"),
            r.num("awa_deg", "angle"),
            r.num("tws_kn", "speed"),
            r.num("twd_deg", "angle"),
        )
        for r, t, lat, lon in _fixes(
            path, "Trieste coach-boat CSV", TRIESTE_COLUMNS, keys, utc_offset_s, 3600.0
        )
    ]


def read_tallinn(path: Path) -> list[Row]:
    """Rows of the Tallinn race log CSV (see the module docstring); apparent wind only.
    Its times are UTC (a time written with an offset keeps it)."""
    out = []
    keys = ("time", "lat", "lng")
    for r, t, lat, lon in _fixes(path, "Tallinn race log", TALLINN_COLUMNS, keys, None, 0.0):
        awa, tack = r.num("awa", "angle"), r.num("tack", "tack")
        signed = None if awa is None or tack is None else awa * (1 if tack >= 0 else -1)
        sog, cog, hdg = r.num("sog", "speed"), r.num("cog", "angle"), r.num("hdg", "angle")
        out.append(Row(t, lat, lon, sog, cog, hdg, None, r.num("aws", "speed"), signed))
    return out


def convert_log(
    path: Path,
    fmt: str,
    out: Path,
    *,
    utc_offset_s: float | None = None,
    t0: float | None = None,
    t1: float | None = None,
) -> int:
    """Write the NMEA 0183 replay file of a log; returns the number of rows written.

    Parameters
    ----------
    path : Path
        The log.
    fmt : {"trieste", "tallinn"}
        Its format.
    out : Path
        The ``.nmea`` file to write: written whole or not at all, never over the log.
    utc_offset_s : float, optional
        The logger's clock offset from UTC [s] for times written without one
        (``trieste`` only; default +01:00).
    t0, t1 : float, optional
        Keep rows with ``t0 <= t <= t1`` [epoch s].

    Raises
    ------
    InputError
        Unknown format, unreadable or binary file, a row that does not parse or holds a
        value out of range (naming its line), no rows in the span, or an output that is
        a folder, in a missing folder, or the log itself.
    """
    if fmt not in FORMATS:
        raise InputError(f"--format {fmt}: unknown; give one of {', '.join(FORMATS)}")
    if not path.is_file():
        raise InputError(f"{path}: no such file; give the log to convert")
    if utc_offset_s is not None and fmt != "trieste":
        raise InputError(
            f"--utc-offset: the {fmt} log's times are UTC (or carry their offset); "
            "leave --utc-offset out"
        )
    check_out_file(out, [path])
    rows = read_trieste(path, utc_offset_s) if fmt == "trieste" else read_tallinn(path)
    rows = [r for r in rows if (t0 is None or r.t >= t0) and (t1 is None or r.t <= t1)]
    if not rows:
        raise InputError(f"{path}: no rows in the time span asked for; widen --from/--to")
    with replacing(out, newline="\r\n") as fh:
        for r in rows:
            for line in nmea_lines(r):
                fh.write(line + "\n")
    return len(rows)
