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
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterator
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path

from sailroute.errors import InputError
from sailroute.live.nmeaout import sentence
from sailroute.nmea import lat_field, lon_field

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


def _num(row: dict[str, str], key: str) -> float | None:
    text = (row.get(key) or "").strip()
    if not text:
        return None
    v = float(text)
    return v if math.isfinite(v) else None


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


def read_trieste(path: Path, utc_offset_s: float = 3600.0) -> list[Row]:
    """Rows of the Trieste coach-boat CSV (see the module docstring)."""
    tz = timezone(timedelta(seconds=utc_offset_s))
    out = []
    with open(path, newline="", encoding="utf-8") as fh:
        for n, r in enumerate(csv.DictReader(fh), 2):
            try:
                t = datetime.fromisoformat(r["datetime_local"]).replace(tzinfo=tz).timestamp()
                lat, lon = _num(r, "lat"), _num(r, "lon")
                if lat is None or lon is None:
                    continue
                out.append(
                    Row(
                        t,
                        lat,
                        lon,
                        _num(r, "sog_kn"),
                        _num(r, "cog_deg"),
                        _num(r, "hdg_deg"),
                        _num(r, "bs_kn"),
                        _num(r, "aws_kn"),
                        _num(r, "awa_deg"),
                        _num(r, "tws_kn"),
                        _num(r, "twd_deg"),
                    )
                )
            except (KeyError, ValueError) as exc:
                raise InputError(
                    f"{path}:{n}: not a row of the Trieste coach-boat CSV "
                    f"({exc}); expected the columns datetime_local, bs_kn, "
                    "awa_deg, aws_kn, hdg_deg, tws_kn, twd_deg, sog_kn, "
                    "cog_deg, lat, lon"
                ) from None
    return out


def read_tallinn(path: Path) -> list[Row]:
    """Rows of the Tallinn race log CSV (see the module docstring); apparent wind only."""
    out = []
    with open(path, newline="", encoding="utf-8") as fh:
        for n, r in enumerate(csv.DictReader(fh), 2):
            try:
                t = datetime.fromisoformat(r["time"]).timestamp()
                lat, lon = _num(r, "lat"), _num(r, "lng")
                if lat is None or lon is None:
                    continue
                awa, tack = _num(r, "awa"), _num(r, "tack")
                signed = None if awa is None or tack is None else awa * (1 if tack >= 0 else -1)
                out.append(
                    Row(
                        t,
                        lat,
                        lon,
                        _num(r, "sog"),
                        _num(r, "cog"),
                        _num(r, "hdg"),
                        None,
                        _num(r, "aws"),
                        signed,
                    )
                )
            except (KeyError, ValueError) as exc:
                raise InputError(
                    f"{path}:{n}: not a row of the Tallinn race log ({exc}); "
                    "expected the columns time, lat, lng, sog, cog, hdg, awa, "
                    "aws, tack"
                ) from None
    return out


def convert_log(
    path: Path,
    fmt: str,
    out: Path,
    *,
    utc_offset_s: float = 3600.0,
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
        The ``.nmea`` file to write.
    utc_offset_s : float
        The logger's clock offset from UTC [s] (``trieste`` only).
    t0, t1 : float, optional
        Keep rows with ``t0 <= t <= t1`` [epoch s].

    Raises
    ------
    InputError
        Unknown format, unreadable file, a row that does not parse, no rows in the span.
    """
    if fmt not in FORMATS:
        raise InputError(f"--format {fmt}: unknown; give one of {', '.join(FORMATS)}")
    if not path.is_file():
        raise InputError(f"{path}: no such file; give the log to convert")
    rows = read_trieste(path, utc_offset_s) if fmt == "trieste" else read_tallinn(path)
    rows = [r for r in rows if (t0 is None or r.t >= t0) and (t1 is None or r.t <= t1)]
    if not rows:
        raise InputError(f"{path}: no rows in the time span asked for; widen --from/--to")
    with open(out, "w", encoding="ascii", newline="\r\n") as fh:
        for r in rows:
            for line in nmea_lines(r):
                fh.write(line + "\n")
    return len(rows)
