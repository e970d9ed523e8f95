"""Read sailed tracks: GPX 1.0/1.1 and CSV logs (GPS watches, phones, instrument systems).

:func:`read_track` is the one entry point; the format is chosen from the file's
content (``<`` starts XML, otherwise CSV).

GPX
    Every ``<trkpt>`` of every ``<trk>`` and ``<trkseg>``, in any namespace (GPX 1.0
    or 1.1); each needs ``lat``, ``lon`` and a ``<time>``.  Extensions (Garmin heart
    rate, temperature) are ignored.
CSV
    ``,``, ``;`` or tab separated; lines starting with ``#`` are skipped.  Columns
    are found from their headers (:data:`TRACK_ALIASES`, case-insensitive, after
    removing a unit suffix such as ``_kn``, ``_km_h``, ``_deg``, ``_unk`` and a
    trailing ``_1``) or named with ``columns={"time": ..., "lat": ..., "sog": ...}``.

**Speed units.**  A speed column whose header carries a unit (``sog_kn``,
``BOAT_SPEED_km_h_1``, ``speed_kmh``) is read in that unit; unsuffixed speed
columns (``sog``, ``tws``) take ``speed_unit``, and without it the read fails
asking for one: a wrong guess would scale every speed silently (the rule of the
station reader, ``sailroute.wind.stations``).  A ``speed_unit`` that contradicts a
header suffix is an error.

**Times.**  ISO 8601 with an offset or ``Z``; ``YYYY-MM-DD HH:MM:SS:mmm`` (phone
loggers) is read as ``.mmm``.  Naive times need ``time_zone`` (an offset such as
``"-07:00"``, ``"UTC"``, or an IANA name such as ``"Europe/Madrid"``), unless the
time column's header says UTC (``time_utc``, ``datetime_utc``).  Plain numbers are
epoch seconds (or milliseconds when above 1e11).

**Cleaning** (reported in ``Track.notes``): rows without a time or position are
dropped, points are sorted by time, repeated timestamps keep their first point,
and gaps longer than ``max(30 s, 10 × the median interval)`` are noted.  A track
with fewer than two points left is an error.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from datetime import UTC, tzinfo
from pathlib import Path
from types import MappingProxyType
from typing import Any, Final
from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

import numpy as np
from numpy.typing import NDArray

from sailroute.checks import real_number
from sailroute.errors import InputError
from sailroute.geo import wrap_lon
from sailroute.tabular import (
    DEFAULT_MISSING,
    column_speed_unit,
    map_columns,
    parse_offset,
    unit_from_header,
)
from sailroute.textin import (
    clean_text,
    csv_rows,
    excerpt,
    looks_binary,
    looks_like_header,
    quote_header,
)
from sailroute.timeutil import iso, iso_datetime
from sailroute.track.model import Track
from sailroute.units import speed_factor, wrap180, wrap360

TRACK_ALIASES: Final[dict[str, tuple[str, ...]]] = {
    "time": (
        "time",
        "datetime",
        "timestamp",
        "date_time",
        "time_utc",
        "datetime_utc",
        "utc",
        "gps_time",
        "time_iso",
    ),
    "lat": ("lat", "latitude", "latitude_gps", "lat_gps", "gps_lat"),
    "lon": ("lon", "lng", "long", "longitude", "longitude_gps", "lon_gps", "gps_lon"),
    "sog": ("sog", "gps_sog", "speed", "speed_over_ground", "gps_speed"),
    "cog": ("cog", "gps_cog", "course", "course_over_ground", "loc_orientation"),
    "hdg": ("hdg", "heading", "heading_true", "hdg_true"),
    "bsp": ("bsp", "boat_speed", "boatspeed", "stw", "speed_through_water"),
    "tws": ("tws", "tws_sgp", "true_wind_speed"),
    "twa": ("twa", "twa_sgp", "true_wind_angle"),
    "twd": ("twd", "twd_sgp", "true_wind_direction"),
    "aws": ("aws", "aws_sgp", "apparent_wind_speed"),
    "awa": ("awa", "awa_sgp", "apparent_wind_angle"),
}
"""Canonical track column -> accepted header stems (lower case, unit suffix removed)."""

SPEED_COLUMNS: Final = ("sog", "bsp", "tws", "aws")
ANGLE_COLUMNS: Final = ("cog", "hdg", "twa", "twd", "awa")
_SIGNED: Final = ("twa", "awa")

_STRIP: Final = re.compile(r"(_\d+)?$")
_UNIT_PART: Final = re.compile(r"_(km_h|kmh|kph|kn|kt|kts|knots|m_s|ms|mps|mph|deg|degrees|unk)$")
_PHONE_MS: Final = re.compile(r"^(.*\d{2}:\d{2}:\d{2}):(\d{1,3})$")

GAP_MIN_S: Final = 30.0
"""A jump in time longer than ``max(GAP_MIN_S, 10 × median interval)`` is reported [s]."""


def header_stem(column: str) -> str:
    """Lower-case header without a trailing ``_<digits>`` and unit suffix.

    ``"TWS_SGP_km_h_1"`` -> ``"tws_sgp"``, ``"LATITUDE_GPS_unk"`` -> ``"latitude_gps"``.
    """
    c = _STRIP.sub("", column.strip().lower())
    return _UNIT_PART.sub("", c)


def header_unit(column: str) -> str | None:
    """Speed unit of a header suffix (``BOAT_SPEED_km_h_1`` -> ``"km/h"``), or None."""
    return unit_from_header(_STRIP.sub("", column.strip().lower()))


def read_track(
    path: str | Path,
    *,
    columns: Mapping[str, str] | None = None,
    speed_unit: str | None = None,
    time_zone: str | None = None,
    name: str | None = None,
) -> Track:
    """Read a GPX or CSV track.

    Parameters
    ----------
    path : str or Path
        GPX (1.0/1.1) or CSV file.
    columns : mapping, optional
        CSV only: ``canonical -> file column`` for headers the aliases do not know
        (canonical names: ``time``, ``lat``, ``lon``, ``sog``, ``cog``, ``hdg``,
        ``bsp``, ``tws``, ``twa``, ``twd``, ``aws``, ``awa``).
    speed_unit : str, optional
        Unit of unsuffixed speed columns: ``m/s``, ``kn``, ``km/h`` or ``mph``.
    time_zone : str, optional
        Zone of naive timestamps: a UTC offset (``"+02:00"``, ``"UTC"``) or an IANA
        name (``"America/Los_Angeles"``).
    name : str, optional
        Track name (default: the GPX track name, else the file stem).

    Returns
    -------
    Track
        Cleaned track (see the module notes).

    Raises
    ------
    InputError
        Missing or empty file, XML errors (line and column), points without time,
        unknown/ambiguous/missing columns, undeclared speed unit, unreadable values
        (naming line and column), naive times without ``time_zone``, positions out of
        range, fewer than two usable points.
    """
    p = Path(path)
    src = str(p)
    if not p.is_file():
        raise InputError(f"{src}: track file not found; check the path")
    text = p.read_text(encoding="utf-8-sig", errors="replace")
    if looks_binary(text):
        raise InputError(
            f"{src}: not a text file (binary content); expected a GPX or CSV "
            "track with time, lat, lon"
        )
    if not text.strip():
        raise InputError(f"{src}: the track file is empty; expected GPX or CSV with time, lat, lon")
    tz = _zone(time_zone, src) if time_zone is not None else None
    if text.lstrip().startswith("{"):  # the JSON-lines log of `sailroute live`
        t, lat, lon, lines, channels = read_live_log(text, src)
        default_name = p.stem
    elif text.lstrip().startswith("<"):
        if columns:
            raise InputError(f"{src}: `columns` applies to CSV tracks only; this is GPX")
        t, lat, lon, lines, gpx_name, channels = _read_gpx(text, src, tz)
        default_name = gpx_name or p.stem
    else:
        t, lat, lon, lines, channels = _read_csv(text, src, columns, speed_unit, tz)
        default_name = p.stem
    return clean_track(
        t, lat, lon, lines, channels, src, clean_text(name if name is not None else default_name)
    )


# ------------------------------------------------------------------------------ live log
LIVE_LOG_MAX_AGE_S: Final = 5.0
"""A channel of a ``sailroute live`` log is given at a fix from its last sample at most this
old [s] (the instruments' sentences arrive one by one, between the position fixes)."""
_LIVE_CHANNELS: Final = {
    "sog_ms": "sog_ms",
    "cog_deg": "cog_deg",
    "hdg_deg": "hdg_deg",
    "stw_ms": "bsp_ms",
    "tws_ms": "tws_ms",
    "twd_deg": "twd_deg",
    "twa_deg": "twa_deg",
    "aws_ms": "aws_ms",
    "awa_deg": "awa_deg",
}


def read_live_log(
    text: str, src: str
) -> tuple[NDArray, NDArray, NDArray, NDArray, dict[str, NDArray]]:
    """The track in a ``sailroute live`` JSON-lines log (``--log``): its input samples.

    Each position fix (an ``"input"`` record with ``lat`` and ``lon``) is a track point;
    each measured channel (SOG, COG, heading, speed through the water, true and apparent
    wind) takes at that fix the channel's last sample at most
    :data:`LIVE_LOG_MAX_AGE_S` old, else NaN.  The other records (re-plans, link
    changes, errors) are skipped.

    Returns
    -------
    t, lat, lon : ndarray
        Epoch seconds and degrees of the fixes, in the log's order.
    lines : ndarray of int
        1-based line of each fix.
    channels : dict of str to ndarray
        :data:`sailroute.track.model.CHANNELS` names (``stw_ms`` as ``bsp_ms``).

    Raises
    ------
    InputError
        A line that is not a JSON object, a sample without a time, or no position fix.
    """
    import json

    samples: list[tuple[int, dict[str, Any]]] = []
    for k, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
        except (ValueError, RecursionError):  # RecursionError: nested thousands deep
            raise InputError(
                f"{src}: line {k}: not a JSON object; a `sailroute live` log has one "
                "JSON object per line"
            ) from None
        if not isinstance(rec, dict):
            raise InputError(f"{src}: line {k}: expected a JSON object; got {excerpt(line)!r}")
        if rec.get("kind") != "input":
            continue
        t = rec.get("t")
        if not real_number(t):
            raise InputError(f"{src}: line {k}: an input sample needs a time `t` [epoch s]")
        samples.append((k, rec))
    fixes = [(k, r) for k, r in samples if real_number(r.get("lat")) and real_number(r.get("lon"))]
    if not fixes:
        raise InputError(
            f"{src}: no position fix in this `sailroute live` log ({len(samples)} input "
            "samples); a track needs samples with lat and lon"
        )
    t = np.array([float(r["t"]) for _, r in fixes])
    channels: dict[str, NDArray] = {}
    for key, name in _LIVE_CHANNELS.items():
        have = [(float(r["t"]), float(r[key])) for _, r in samples if real_number(r.get(key))]
        if not have:
            continue
        ts, vs = (np.array(c) for c in zip(*sorted(have, key=lambda p: p[0]), strict=True))
        last = np.searchsorted(ts, t, side="right") - 1
        ok = (last >= 0) & (t - ts[np.maximum(last, 0)] <= LIVE_LOG_MAX_AGE_S)
        channels[name] = np.where(ok, vs[np.maximum(last, 0)], np.nan)
    lat = np.array([float(r["lat"]) for _, r in fixes])
    lon = np.array([float(r["lon"]) for _, r in fixes])
    return t, lat, lon, np.array([k for k, _ in fixes]), channels


# ------------------------------------------------------------------------------ times
def _zone(text: str, src: str) -> tzinfo:
    try:
        return parse_offset(text, f"{src}: time_zone")
    except InputError:
        pass
    try:
        return ZoneInfo(text.strip())
    except (ZoneInfoNotFoundError, ValueError):
        raise InputError(
            f"{src}: time_zone {text!r} is neither a UTC offset ('+02:00', 'UTC') nor a "
            "known IANA zone name ('Europe/Madrid'); give one of those"
        ) from None


def parse_epoch(cell: str, tz: tzinfo | None, where: str, utc_column: bool = False) -> float:
    """Epoch seconds of one timestamp cell (see the module notes for the formats)."""
    s = cell.strip()
    try:
        v = float(s)
    except ValueError:
        pass
    else:
        if not math.isfinite(v):
            raise InputError(f"{where}: {excerpt(cell)!r} is not a time")
        return v / 1000.0 if abs(v) > 1e11 else v
    m = _PHONE_MS.match(s)
    if m:
        s = f"{m.group(1)}.{m.group(2).ljust(3, '0')}"
    try:
        dt = iso_datetime(s)
    except ValueError:
        raise InputError(
            f"{where}: cannot read {excerpt(cell)!r} as a time; expected ISO 8601 with an offset "
            "(2025-06-21T11:18:29Z), or epoch seconds"
        ) from None
    if dt.tzinfo is None:
        if tz is None and not utc_column:
            raise InputError(
                f"{where}: time {cell!r} has no UTC offset; give the logger's zone with "
                "time_zone (--time-zone), e.g. 'UTC', '+02:00' or 'Europe/Madrid'"
            )
        dt = dt.replace(tzinfo=tz if tz is not None else UTC)
    return dt.timestamp()


# ------------------------------------------------------------------------------ GPX
def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1].rsplit(":", 1)[-1]


_ISO_UTC: Final = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d{1,9})?Z")
"""The common GPX time (UTC, ``Z``): parsed in bulk by numpy."""


def parse_epochs(
    cells: list[str], tz: tzinfo | None, where: Callable[[int], str]
) -> NDArray[np.float64]:
    """Epoch seconds of many timestamp cells: :func:`parse_epoch` of each, with the usual
    ``YYYY-MM-DDTHH:MM:SS[.f]Z`` form parsed by numpy at once (a 10 Hz log of three hours
    in tens of milliseconds).  ``where(k)`` names cell ``k`` in messages."""
    out = np.full(len(cells), np.nan)
    fast = np.array([_ISO_UTC.fullmatch(c) is not None for c in cells], dtype=bool)
    if fast.any():
        arr = np.array(
            [c[:-1] for c, f in zip(cells, fast, strict=True) if f], dtype="datetime64[ns]"
        )
        out[fast] = (arr - np.datetime64(0, "ns")).astype(np.int64) / 1e9
    for k in np.flatnonzero(~fast):
        out[k] = parse_epoch(cells[k], tz, where(int(k)), utc_column=False)
    return out


def _read_gpx(
    text: str, src: str, tz: tzinfo | None
) -> tuple[NDArray, NDArray, NDArray, NDArray, str, dict[str, NDArray]]:
    """Every ``<trkpt>`` with its ``<time>``, by the expat parser's callbacks (no element
    tree: 300 000 points in about a second)."""
    from xml.parsers import expat

    parser = expat.ParserCreate()
    gpx = _GpxPoints(parser, src)
    parser.StartElementHandler = gpx.start
    parser.EndElementHandler = gpx.end
    parser.CharacterDataHandler = gpx.data
    parser.buffer_text = True
    try:
        parser.Parse(text, True)
    except expat.ExpatError as exc:
        raise InputError(
            f"{src}:{exc.lineno}:{exc.offset + 1}: not well-formed XML "
            f"({expat.errors.messages[exc.code]}: line {exc.lineno}, column "
            f"{exc.offset}); is the file a complete GPX export?"
        ) from None
    if not gpx.root:
        raise InputError(f"{src}: no XML element found; expected a GPX file")
    if not gpx.times:
        raise InputError(
            f"{src}: the GPX file has no track points (<trk><trkseg><trkpt>); "
            "export the activity as a track with times"
        )
    lines = gpx.lines
    try:
        lat, lon = np.array(gpx.lat_s, dtype=float), np.array(gpx.lon_s, dtype=float)
    except ValueError:
        k = next(
            i
            for i, (a, b) in enumerate(zip(gpx.lat_s, gpx.lon_s, strict=True))
            if not _is_float(a) or not _is_float(b)
        )
        raise InputError(
            f"{src}: line {lines[k]}: <trkpt lat={gpx.lat_s[k]!r} "
            f"lon={gpx.lon_s[k]!r}>: expected decimal degrees"
        ) from None
    t = parse_epochs(gpx.times, tz, lambda k: f"{src}: line {lines[k]}")
    return t, lat, lon, np.array(lines), gpx.names[0] if gpx.names else "", {}


class _GpxPoints:
    """The expat callbacks of :func:`_read_gpx`: the position cells, line and ``<time>``
    text of each ``<trkpt>``, and the names of the ``<trk>`` elements."""

    def __init__(self, parser: Any, src: str) -> None:
        self.parser, self.src = parser, src
        self.times: list[str] = []
        self.lat_s: list[str] = []
        self.lon_s: list[str] = []
        self.lines: list[int] = []
        self.names: list[str] = []
        self.stack: list[str] = []
        self.text_buf: list[str] = []
        self.root = self.pt = self.has_time = False
        self.local: dict[str, str] = {}

    def start(self, name: str, attrs: dict[str, str]) -> None:
        """An element opens: the root must be ``<gpx>``; a ``<trkpt>`` starts a point."""
        tag = self.local.get(name) or self.local.setdefault(name, _local(name))
        if not self.root:
            self.root = True
            if tag != "gpx":
                raise InputError(
                    f"{self.src}: line {self.parser.CurrentLineNumber}: root "
                    f"element <{tag}>; expected <gpx> (a GPX 1.0/1.1 file)"
                )
        self.stack.append(tag)
        if tag == "trkpt":
            self.pt, self.has_time = True, False
            self.lat_s.append(attrs.get("lat", ""))
            self.lon_s.append(attrs.get("lon", ""))
            self.lines.append(self.parser.CurrentLineNumber)
        elif tag in ("time", "name"):
            self.text_buf.clear()

    def end(self, name: str) -> None:
        """An element closes: a point's one ``<time>``, a track's ``<name>``, a point that
        must have had a time."""
        tag = self.stack.pop()
        parent = self.stack[-1] if self.stack else None
        if tag == "time" and self.pt and parent == "trkpt":
            if self.has_time:
                raise InputError(
                    f"{self.src}: line {self.parser.CurrentLineNumber}: a "
                    "<trkpt> with a second <time> (GPX gives each point one); "
                    "is the file damaged?"
                )
            self.times.append("".join(self.text_buf).strip())
            self.has_time = True
        elif tag == "name" and parent == "trk":
            self.names.append("".join(self.text_buf).strip())
        elif tag == "trkpt" and self.pt:
            self.pt = False
            if not self.has_time or not self.times[-1]:
                raise InputError(
                    f"{self.src}: line {self.lines[-1]}: <trkpt> has no <time>; "
                    "a track for analysis needs a time on every point"
                )

    def data(self, chunk: str) -> None:
        """Text inside a ``<time>`` or ``<name>``."""
        if self.stack and self.stack[-1] in ("time", "name"):
            self.text_buf.append(chunk)


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


# ------------------------------------------------------------------------------ CSV
def _read_csv(
    text: str,
    src: str,
    columns: Mapping[str, str] | None,
    speed_unit: str | None,
    tz: tzinfo | None,
) -> tuple[NDArray, NDArray, NDArray, NDArray, dict[str, NDArray]]:
    lines = [
        (k + 1, ln)
        for k, ln in enumerate(text.splitlines())
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not lines:
        raise InputError(
            f"{src}: the track file holds only comments; expected GPX or CSV with time, lat, lon"
        )
    delim = max((",", ";", "\t"), key=lines[0][1].count)
    rows = csv_rows(lines, delim, src)
    header, body = rows[0], rows[1:]
    linenos = [k for k, _ in lines[1:]]
    stems = [header_stem(h) for h in header]
    explicit: dict[str, str] = {}
    low = [h.strip().lower() for h in header]
    for canon, col in (columns or {}).items():
        if isinstance(col, str) and col.strip().lower() in low:
            explicit[canon] = stems[low.index(col.strip().lower())]
        else:
            explicit[canon] = col  # map_columns reports it
    cmap = map_columns(stems, explicit, where=src, aliases=TRACK_ALIASES)
    absent = [c for c in ("time", "lat", "lon") if c not in cmap]
    if absent and not looks_like_header(header):
        raise InputError(
            f"{src}: not a track: line {lines[0][0]} is not a header of column names; expected "
            "GPX, or CSV with a header row such as time,lat,lon,sog_kn (names and aliases: "
            "docs/usage.md, 'sailroute analyze')"
        )
    if absent:
        raise InputError(
            f"{src}: no column for {', '.join(absent)}; header is "
            f"{quote_header(header)}. Name the columns time, lat, lon (see "
            "docs/usage.md, 'sailroute analyze') or map them with --column CANON=NAME"
        )
    if not body:
        raise InputError(f"{src}: the file has a header but no data rows")
    units: dict[str, str] = {
        c: column_speed_unit(header[cmap[c]], speed_unit, src, header_unit(header[cmap[c]]))
        for c in SPEED_COLUMNS
        if c in cmap
    }
    ncol = len(header)
    for r, lineno in zip(body, linenos, strict=True):
        if len(r) != ncol:
            raise InputError(
                f"{src}, line {lineno}: {len(r)} fields but the header has {ncol}; "
                f"check the separator ({delim!r}) and quoting"
            )
    miss = set(DEFAULT_MISSING)
    tcol = header[cmap["time"]]
    utc_col = "utc" in tcol.strip().lower()
    t = np.array(
        [
            np.nan
            if r[cmap["time"]].strip() in miss
            else parse_epoch(r[cmap["time"]], tz, f"{src}, line {ln}, column {tcol!r}", utc_col)
            for r, ln in zip(body, linenos, strict=True)
        ]
    )
    vals = {
        c: _numbers(body, linenos, cmap[c], header[cmap[c]], miss, src) for c in cmap if c != "time"
    }
    lat, lon = vals.pop("lat"), vals.pop("lon")
    channels: dict[str, NDArray] = {}
    for c, v in vals.items():
        if c in SPEED_COLUMNS:
            channels[f"{c}_ms"] = v * speed_factor(units[c])
        elif c in _SIGNED:
            channels[f"{c}_deg"] = wrap180(v)
        else:
            channels[f"{c}_deg"] = wrap360(v)
    return t, lat, lon, np.array(linenos), channels


def _numbers(
    body: list[list[str]], linenos: list[int], k: int, column: str, miss: set[str], src: str
) -> NDArray:
    out = np.empty(len(body))
    for i, r in enumerate(body):
        c = r[k].strip()
        if c in miss:
            out[i] = np.nan
            continue
        try:
            out[i] = float(c)
        except ValueError:
            raise InputError(
                f"{src}, line {linenos[i]}, column {column!r}: cannot read "
                f"{excerpt(c)!r} as a number"
            ) from None
        if math.isinf(out[i]):
            raise InputError(
                f"{src}, line {linenos[i]}, column {column!r}: {excerpt(c)!r} is "
                "not a finite number; replace it with a value or a missing marker"
            )
    return out


# ------------------------------------------------------------------------------ cleaning
def clean_track(
    t: NDArray,
    lat: NDArray,
    lon: NDArray,
    lines: NDArray,
    channels: Mapping[str, NDArray],
    src: str,
    name: str,
) -> Track:
    """Drop unusable rows, sort, remove repeated times, note gaps; build the :class:`Track`.

    Parameters
    ----------
    t, lat, lon : ndarray
        Raw times [epoch s] and positions [°] (NaN = missing).
    lines : ndarray of int
        File line of each point (for messages).
    channels : mapping
        Measured channels, same length.
    src, name : str
        File and track name.

    Returns
    -------
    Track

    Raises
    ------
    InputError
        A latitude/longitude out of range (naming the line), or fewer than two
        usable points.
    """
    notes: list[str] = []
    n0 = t.size
    for a, lo, hi, what in ((lat, -90.0, 90.0, "latitude"), (lon, -180.0, 360.0, "longitude")):
        bad = np.nonzero((a < lo) | (a > hi))[0]
        if bad.size:
            k = int(bad[0])
            raise InputError(
                f"{src}, line {int(lines[k])}: {what} {a[k]:g} is out of range "
                f"[{lo:g}, {hi:g}] ({bad.size} point(s))"
            )
    ok = np.isfinite(t) & np.isfinite(lat) & np.isfinite(lon) & ~((lat == 0) & (lon == 0))
    if (~ok).any():
        notes.append(f"dropped {int((~ok).sum())} row(s) without a time or position")
    idx = np.nonzero(ok)[0]
    back = int(np.count_nonzero(np.diff(t[idx]) < 0))
    order = idx[np.argsort(t[idx], kind="stable")]
    if back:
        notes.append(f"sorted {back} out-of-order point(s)")
    ts = t[order]
    keep = np.concatenate([[True], np.diff(ts) > 0]) if ts.size else np.zeros(0, bool)
    if (~keep).any():
        notes.append(f"dropped {int((~keep).sum())} duplicate timestamp(s)")
    order = order[keep]
    if order.size < 2:
        raise InputError(
            f"{src}: only {order.size} usable point(s) of {n0} (a point needs a time, lat and "
            "lon); a track needs at least two"
        )
    ts = t[order]
    dt = np.diff(ts)
    limit = max(GAP_MIN_S, 10.0 * float(np.median(dt)))
    gaps = np.nonzero(dt > limit)[0]
    for k in gaps[:5]:
        notes.append(f"gap of {dt[k]:.0f} s at {iso(ts[k])[:-5]}Z")
    if gaps.size > 5:
        notes.append(f"... and {gaps.size - 5} more gap(s) longer than {limit:.0f} s")
    lon_w = np.asarray(wrap_lon(lon[order]), dtype=float)
    return Track(
        ts,
        lat[order].astype(float),
        lon_w,
        name,
        src,
        MappingProxyType({k: np.asarray(v, float)[order] for k, v in channels.items()}),
        tuple(notes),
    )
