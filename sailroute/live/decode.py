"""Instrument readings from NMEA 0183 sentences and Signal K deltas.

Both decoders turn their input into :class:`Reading` objects: one per sentence or
Signal K value, with the data time and only the quantities that input carries, in SI
units (m s⁻¹, degrees true), and the vessel it is about (``""``: the own instruments;
another boat: its Signal K context without ``vessels.``, or ``urn:mrn:imo:mmsi:<MMSI>``
for an AIS report, the same key).  Bad input never raises: a sentence with a wrong or
missing checksum (a talker without checksums is read only with ``require_checksum``
off), a malformed sentence (a position off the globe, a date past the calendar among
them) and a delta that is not JSON are counted in :class:`Counts` and skipped, so that
one noisy instrument does not take the feed down; a Signal K value that is not a finite
number, or a position off the globe, is left out of its reading.  What the numbers say
(a speed of 5e29 m s⁻¹, a date in another year) is checked afterwards, against the
feed's own history, by :mod:`sailroute.live.gates`.

NMEA 0183 sentences read (with pynmea2): ``RMC`` (time, date, position, SOG, COG),
``GGA``/``GLL`` (position), ``VTG`` (COG, SOG), ``HDT``/``HDG`` (heading, true;
``HDG`` with its variation), ``VHW`` (heading and speed through the water), ``MWV``
(wind angle and speed; ``R``: apparent, ``T``: true, both from the bow), ``MWD``
(true wind direction and speed), and AIS ``!AIVDM``/``!AIVDO`` position reports of other
boats (:mod:`sailroute.live.ais`).  A sentence without a time of its own takes the time
of the last ``RMC``/``GGA``/``GLL``/``ZDA`` (instruments send them every second); an AIS
report the time of the second of the minute it gives (:func:`~sailroute.live.ais.report_time`).

Signal K paths read: ``navigation.position``, ``navigation.courseOverGroundTrue``,
``navigation.speedOverGround``, ``navigation.headingTrue``,
``navigation.speedThroughWater``, ``environment.wind.directionTrue``,
``environment.wind.speedTrue`` (or ``speedOverGround``), ``angleTrueWater`` or
``angleTrueGround`` (with the heading), ``environment.wind.angleApparent``,
``environment.wind.speedApparent`` (Signal K is in SI units and radians already).  An
angle and its speed are used together when they come in one update (as a server that
reads NMEA 0183 sends them).  Deltas of other vessels (AIS targets, trackers) are read
with their context as the vessel.
"""

from __future__ import annotations

import json
import math
from collections import Counter
from dataclasses import dataclass, field
from datetime import UTC, date, datetime, time
from typing import Any

import pynmea2

from sailroute.live.ais import AisError, is_ais, parse_ais, report_time
from sailroute.units import wrap180, wrap360

KN: float = 1852.0 / 3600.0
"""One knot [m s⁻¹]."""


@dataclass(frozen=True)
class Reading:
    """What one sentence or delta value says; None where it says nothing.

    Attributes
    ----------
    t : float
        Data time [epoch s] (the instruments' GPS clock).
    lat, lon : float or None
        Position [°].
    sog_ms, cog_deg : float or None
        Speed [m s⁻¹] and course [° true] over the ground.
    hdg_deg : float or None
        Heading [° true].
    stw_ms : float or None
        Speed through the water [m s⁻¹].
    tws_ms, twd_deg : float or None
        True wind speed [m s⁻¹] and the direction it comes from [° true].
    twa_deg : float or None
        True wind angle from the bow [°, + starboard] (``MWV`` reference ``T``).
    aws_ms, awa_deg : float or None
        Apparent wind speed [m s⁻¹] and angle from the bow [°, + starboard].
    timed : bool
        The input carried its own time (``RMC``, ``GGA``, a Signal K timestamp).
    vessel : str
        Whose reading it is: ``""`` for the own instruments, else the other vessel's key
        (module docstring).
    """

    t: float
    lat: float | None = None
    lon: float | None = None
    sog_ms: float | None = None
    cog_deg: float | None = None
    hdg_deg: float | None = None
    stw_ms: float | None = None
    tws_ms: float | None = None
    twd_deg: float | None = None
    twa_deg: float | None = None
    aws_ms: float | None = None
    awa_deg: float | None = None
    timed: bool = False
    vessel: str = ""

    def as_dict(self) -> dict[str, float]:
        """The quantities given (for the JSON-lines log), rounded to what they resolve."""
        out: dict[str, float] = {"t": round(self.t, 3)}
        for name in ("lat", "lon"):
            v = getattr(self, name)
            if v is not None:
                out[name] = round(v, 7)
        for name in (
            "sog_ms",
            "cog_deg",
            "hdg_deg",
            "stw_ms",
            "tws_ms",
            "twd_deg",
            "twa_deg",
            "aws_ms",
            "awa_deg",
        ):
            v = getattr(self, name)
            if v is not None:
                out[name] = round(v, 3)
        return out


@dataclass
class Counts:
    """What a decoder has seen (mutable; read it under the owner's lock).

    Attributes
    ----------
    by_kind : Counter
        ``"RMC"``, ``"MWV"``, ``"AIS"``, ... for sentences used; ``"bad_checksum"``,
        ``"no_checksum"``, ``"malformed"``, ``"untimed"`` (no clock yet), ``"ignored"`` (a
        sentence type not read, or flagged void by the instrument), ``"empty"`` (a wind
        sentence without values).
    """

    by_kind: Counter[str] = field(default_factory=Counter)

    @property
    def bad(self) -> int:
        """Sentences or deltas skipped as broken (bad or missing checksum, malformed)."""
        return sum(self.by_kind[k] for k in BROKEN)


BROKEN: tuple[str, ...] = ("bad_checksum", "no_checksum", "malformed")
"""The :class:`Counts` kinds of input skipped as broken."""
NOT_USED: tuple[str, ...] = (*BROKEN, "untimed", "ignored", "empty")
"""The :class:`Counts` kinds of input not used (the others count what was used)."""


def _f(value: Any) -> float | None:
    """``float(value)``, or None for an empty field.

    Raises
    ------
    ValueError
        A field that is not a number (the sentence is counted as malformed).
    """
    if value is None or value == "":
        return None
    out = float(value)
    if not math.isfinite(out):
        raise ValueError(f"{value!r} is not a finite number")
    return out


def _position(lat: Any, lon: Any) -> tuple[float, float]:
    """A fix's latitude and longitude [°].

    Raises
    ------
    ValueError
        Not finite, or off the globe (|lat| > 90, |lon| > 180): the sentence is counted
        as malformed.
    """
    la, lo = float(lat), float(lon)
    if not (-90.0 <= la <= 90.0 and -180.0 <= lo <= 180.0):
        raise ValueError(f"position {la}, {lo} is off the globe")
    return la, lo


def _epoch(d: date, tm: time) -> float:
    tz = tm.tzinfo or UTC
    return datetime.combine(d, tm.replace(tzinfo=None)).replace(tzinfo=tz).timestamp()


class NmeaDecoder:
    """Decode NMEA 0183 sentences, one line at a time, keeping the data clock.

    Parameters
    ----------
    require_checksum : bool
        Refuse a sentence without ``*hh`` (counted ``no_checksum``).  Off only for a
        talker known to send none: without a checksum a bit flipped on the wire gives a
        wrong number that nothing can tell from a right one.

    Attributes
    ----------
    counts : Counts
        Sentences used and skipped.
    """

    def __init__(self, require_checksum: bool = True) -> None:
        self.counts = Counts()
        self.require_checksum = require_checksum
        self._date: date | None = None
        self._t: float | None = None
        self._variation: float = 0.0

    def set_clock(self, t: float) -> None:
        """Take ``t`` [epoch s] as the data clock and its date (the caller refused the
        time the last sentence set: a sentence from another clock must not date the next
        ones)."""
        self._t = t
        self._date = datetime.fromtimestamp(t, UTC).date()

    @property
    def clock(self) -> float | None:
        """The last data time seen [epoch s], or None before the first timed sentence."""
        return self._t

    def _timed(self, tm: time | None) -> float | None:
        """Epoch time of a time-of-day on the last date seen (rolls over midnight)."""
        if tm is None or self._date is None:
            return None
        t = _epoch(self._date, tm)
        if self._t is not None and t < self._t - 43200:  # past midnight since the last RMC
            t += 86400.0
        return t

    def feed(self, line: str) -> Reading | None:
        """Decode one line; None when it says nothing usable (the reason is counted).

        Parameters
        ----------
        line : str
            One sentence, ``$`` or ``!`` first, checksum optional, line end optional.

        Returns
        -------
        Reading or None
        """
        text = line.strip()
        if not text:
            return None
        if is_ais(text):
            return self._ais(text)
        if text[0] != "$":
            self.counts.by_kind["malformed"] += 1
            return None
        if self.require_checksum and "*" not in text:
            self.counts.by_kind["no_checksum"] += 1
            return None
        try:
            msg = pynmea2.parse(text)
        except pynmea2.ChecksumError:
            self.counts.by_kind["bad_checksum"] += 1
            return None
        except (pynmea2.ParseError, ValueError, TypeError, AttributeError, OverflowError):
            self.counts.by_kind["malformed"] += 1
            return None
        try:
            reading = self._reading(msg)
        except (ValueError, TypeError, AttributeError, IndexError, OverflowError):
            # OverflowError: a year or a number past what a date or float holds
            self.counts.by_kind["malformed"] += 1
            return None
        if reading is None:
            return None
        self.counts.by_kind[msg.sentence_type] += 1
        return reading

    def _ais(self, text: str) -> Reading | None:
        """An AIS position report of another vessel, at the time of its second."""
        try:
            pos = parse_ais(text, require_checksum=self.require_checksum)
        except AisError as exc:
            kind = {"bad checksum": "bad_checksum", "no checksum": "no_checksum"}
            self.counts.by_kind[kind.get(str(exc), "malformed")] += 1
            return None
        if pos is None:
            self.counts.by_kind["ignored"] += 1
            return None
        if self._t is None:
            self.counts.by_kind["untimed"] += 1
            return None
        self.counts.by_kind["AIS"] += 1
        return Reading(
            report_time(self._t, pos.second),
            lat=pos.lat,
            lon=pos.lon,
            sog_ms=pos.sog_ms,
            cog_deg=pos.cog_deg,
            hdg_deg=pos.hdg_deg,
            vessel=pos.vessel,
        )

    def _reading(self, msg: Any) -> Reading | None:
        kind = msg.sentence_type
        timed = {"RMC": self._rmc, "GGA": self._fix, "GLL": self._fix, "ZDA": self._zda}
        if kind in timed:
            return timed[kind](msg)
        if self._t is None:
            self.counts.by_kind["untimed"] += 1
            return None
        untimed = {
            "VTG": self._vtg,
            "HDT": self._hdt,
            "HDG": self._hdg,
            "VHW": self._vhw,
            "MWV": self._mwv,
            "MWD": self._mwd,
        }
        if kind in untimed:
            return untimed[kind](msg, self._t)
        self.counts.by_kind["ignored"] += 1
        return None

    def _rmc(self, msg: Any) -> Reading | None:
        """Position, SOG, COG and the date; sets the clock and the magnetic variation."""
        if msg.status != "A" or msg.datestamp is None or msg.timestamp is None:
            self.counts.by_kind["ignored"] += 1
            return None
        lat, lon = _position(msg.latitude, msg.longitude)
        self._date = msg.datestamp
        self._t = _epoch(msg.datestamp, msg.timestamp)
        var = _f(msg.mag_variation)
        if var is not None:
            self._variation = -var if msg.mag_var_dir == "W" else var
        sog = _f(msg.spd_over_grnd)
        return Reading(
            self._t,
            lat=lat,
            lon=lon,
            sog_ms=None if sog is None else sog * KN,
            cog_deg=_f(msg.true_course),
            timed=True,
        )

    def _fix(self, msg: Any) -> Reading | None:
        """GGA or GLL: a position at a time of day (dated by the last RMC or ZDA)."""
        if msg.sentence_type == "GGA" and str(msg.gps_qual) in ("", "0"):
            self.counts.by_kind["ignored"] += 1
            return None
        t = self._timed(msg.timestamp)
        if t is None:
            self.counts.by_kind["untimed"] += 1
            return None
        lat, lon = _position(msg.latitude, msg.longitude)
        self._t = t
        return Reading(t, lat=lat, lon=lon, timed=True)

    def _zda(self, msg: Any) -> Reading | None:
        """The date and time only: a reading with a time and nothing else (the clock's
        gate checks it like a fix's time)."""
        if msg.datestamp is None or msg.timestamp is None:
            self.counts.by_kind["empty"] += 1
            return None
        self._date = msg.datestamp
        self._t = _epoch(msg.datestamp, msg.timestamp)
        return Reading(self._t, timed=True)

    @staticmethod
    def _vtg(msg: Any, t: float) -> Reading | None:
        sog = _f(msg.spd_over_grnd_kts)
        return Reading(t, cog_deg=_f(msg.true_track), sog_ms=None if sog is None else sog * KN)

    @staticmethod
    def _hdt(msg: Any, t: float) -> Reading | None:
        return Reading(t, hdg_deg=_f(msg.heading))

    def _hdg(self, msg: Any, t: float) -> Reading | None:
        """Magnetic heading corrected by deviation and variation (the RMC's when absent)."""
        h = _f(msg.heading)
        if h is None:
            return None
        var = _f(msg.variation)
        v = self._variation if var is None else (-var if msg.var_dir == "W" else var)
        dev = _f(msg.deviation) or 0.0
        dev = -dev if msg.dev_dir == "W" else dev
        return Reading(t, hdg_deg=float(wrap360(h + dev + v)))

    @staticmethod
    def _vhw(msg: Any, t: float) -> Reading | None:
        stw = _f(msg.water_speed_knots)
        return Reading(t, hdg_deg=_f(msg.heading_true), stw_ms=None if stw is None else stw * KN)

    def _mwv(self, msg: Any, t: float) -> Reading | None:
        """Wind angle and speed, apparent (reference R) or true."""
        if len(msg.data) < 5:  # angle, reference, speed, unit, status
            raise ValueError("MWV needs 5 fields")
        if msg.status != "A":
            self.counts.by_kind["ignored"] += 1
            return None
        angle, speed = _f(msg.wind_angle), _f(msg.wind_speed)
        if angle is None or speed is None:
            self.counts.by_kind["empty"] += 1
            return None
        unit = {"N": KN, "M": 1.0, "K": 1 / 3.6}.get(str(msg.wind_speed_units))
        if unit is None:
            self.counts.by_kind["malformed"] += 1
            return None
        a = float(wrap180(angle))
        if msg.reference == "R":
            return Reading(t, aws_ms=speed * unit, awa_deg=a)
        return Reading(t, tws_ms=speed * unit, twa_deg=a)

    @staticmethod
    def _mwd(msg: Any, t: float) -> Reading | None:
        d = _f(msg.direction_true)
        ms, kn = _f(msg.wind_speed_meters), _f(msg.wind_speed_knots)
        s = ms if ms is not None else (None if kn is None else kn * KN)
        if d is None or s is None:
            return None
        return Reading(t, tws_ms=s, twd_deg=float(wrap360(d)))


# ------------------------------------------------------------------------------ Signal K
_SK_PATHS: dict[str, tuple[str, float]] = {
    "navigation.courseOverGroundTrue": ("cog_deg", math.degrees(1.0)),
    "navigation.speedOverGround": ("sog_ms", 1.0),
    "navigation.headingTrue": ("hdg_deg", math.degrees(1.0)),
    "navigation.speedThroughWater": ("stw_ms", 1.0),
    "environment.wind.directionTrue": ("twd_deg", math.degrees(1.0)),
    "environment.wind.speedTrue": ("tws_ms", 1.0),
    "environment.wind.speedOverGround": ("tws_ms", 1.0),
    "environment.wind.angleTrueGround": ("twa_deg", math.degrees(1.0)),
    "environment.wind.angleTrueWater": ("twa_deg", math.degrees(1.0)),
    "environment.wind.angleApparent": ("awa_deg", math.degrees(1.0)),
    "environment.wind.speedApparent": ("aws_ms", 1.0),
}
_ANGLES = {"cog_deg", "hdg_deg", "twd_deg"}
_SIGNED = {"twa_deg", "awa_deg"}


def _sk_fields(path: Any, value: Any) -> dict[str, Any]:
    """The :class:`Reading` fields of one Signal K path and value (empty when unused)."""
    if path == "navigation.position" and isinstance(value, dict):
        lat, lon = _sk_f(value.get("latitude")), _sk_f(value.get("longitude"))
        if lat is None or lon is None or not (abs(lat) <= 90.0 and abs(lon) <= 180.0):
            return {}
        return {"lat": lat, "lon": lon}
    if not (isinstance(path, str) and path in _SK_PATHS):
        return {}
    v = _sk_f(value)
    if v is None:
        return {}
    name, scale = _SK_PATHS[path]
    v *= scale
    if name in _ANGLES:
        v = float(wrap360(v))
    elif name in _SIGNED:
        v = float(wrap180(v))
    return {name: v}


def _sk_f(value: Any) -> float | None:
    """A Signal K number, or None (null, text, NaN, an integer past a float)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    try:
        v = float(value)
    except OverflowError:
        return None
    return v if math.isfinite(v) else None


def _sk_time(text: Any) -> float | None:
    if not isinstance(text, str):
        return None
    try:
        dt = datetime.fromisoformat(text.replace("Z", "+00:00"))
        return (dt if dt.tzinfo else dt.replace(tzinfo=UTC)).timestamp()
    except (ValueError, OverflowError):
        return None


class SignalKDecoder:
    """Decode Signal K delta messages (JSON text).

    A delta is ``{"context": ..., "updates": [{"timestamp": ..., "values": [{"path": ...,
    "value": ...}]}]}``; values at one update's timestamp become one :class:`Reading`,
    ``timed`` when it holds a position (a server stamps the values it got no time for
    with its own clock, which need not be the GPS's).  The
    server's hello message names the own vessel (``self``); a delta of that context, of
    ``vessels.self`` or without a context is the own instruments', a delta of another
    ``vessels.<id>`` context another vessel's (``vessel`` ``<id>``: an AIS target, a
    tracker); other contexts (aids to navigation, aircraft) are ignored.

    Attributes
    ----------
    counts : Counts
        ``"delta"`` for deltas used, ``"malformed"`` for text that is not a delta.
    self_context : str or None
        The own vessel's context (from the hello message); None until it arrives.
    """

    def __init__(self) -> None:
        self.counts = Counts()
        self.self_context: str | None = None

    def feed(self, text: str) -> list[Reading]:
        """Decode one WebSocket message; an empty list when it says nothing usable."""
        try:
            msg = json.loads(text)
        except (ValueError, RecursionError):  # RecursionError: nested thousands deep
            self.counts.by_kind["malformed"] += 1
            return []
        if not isinstance(msg, dict):
            self.counts.by_kind["malformed"] += 1
            return []
        if "updates" not in msg:
            if isinstance(msg.get("self"), str):  # the hello message
                self.self_context = msg["self"]
            return []
        vessel = self._vessel(msg.get("context"))
        if vessel is None:
            self.counts.by_kind["ignored"] += 1
            return []
        updates = msg["updates"]
        if not isinstance(updates, list):
            self.counts.by_kind["malformed"] += 1
            return []
        return [r for r in (self._update(up, vessel) for up in updates) if r is not None]

    def _vessel(self, ctx: Any) -> str | None:
        """``""`` for the own vessel, the id of another one, None for another context."""
        if ctx is None or ctx == "vessels.self" or ctx == self.self_context:
            return ""
        if isinstance(ctx, str) and ctx.startswith("vessels.") and len(ctx) > 8:
            return ctx.removeprefix("vessels.")[:200]
        return None

    def _update(self, up: Any, vessel: str) -> Reading | None:
        """One update of a delta: its values at its time, or None when none is usable."""
        if not isinstance(up, dict) or not isinstance(up.get("values"), list):
            self.counts.by_kind["malformed"] += 1
            return None
        t = _sk_time(up.get("timestamp"))
        if t is None:
            self.counts.by_kind["untimed"] += 1
            return None
        fields: dict[str, Any] = {}
        for item in up["values"]:
            if isinstance(item, dict):
                fields.update(_sk_fields(item.get("path"), item.get("value")))
        if not fields:
            return None
        self.counts.by_kind["delta"] += 1
        # a server stamps what it did not get a time for (a heading, the wind) with its own
        # clock: only a position's time is the data clock (the engine places the rest at it)
        return Reading(t, timed="lat" in fields, vessel=vessel, **fields)
