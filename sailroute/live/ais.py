"""AIS position reports from ``!AIVDM``/``!AIVDO`` sentences (ITU-R M.1371).

An AIS sentence carries a 6-bit armoured payload.  The position reports read here are
the single-sentence ones that say where a boat is: message types 1, 2 and 3 (class A),
18 and 19 (class B; 19 is the extended report).  Each gives the vessel's MMSI, its
position (1/10 000 minute), speed over the ground (0.1 kn), course over the ground
(0.1°), true heading (1°) and the UTC second of the minute at which the report was made;
a field at its "not available" value is left out.  Other message types, and reports
split over several sentences, are not positions and are skipped.

A small tracker on a dinghy (a class B transponder, or a tracker that speaks AIS) is how
a coach's instruments see the sailor's boat: :mod:`sailroute.live.decode` turns these
reports into readings of the vessel ``urn:mrn:imo:mmsi:<MMSI>``, the key Signal K gives
the same boat.
"""

from __future__ import annotations

from dataclasses import dataclass

from sailroute.nmea import checksum

MMSI_URN: str = "urn:mrn:imo:mmsi:"
"""Prefix of a vessel key made from an MMSI (as Signal K names vessels)."""

KN: float = 1852.0 / 3600.0
"""One knot [m s⁻¹]."""

POSITION_TYPES: frozenset[int] = frozenset({1, 2, 3, 18, 19})
"""Message types read: class A (1-3) and class B (18, 19) position reports."""


class AisError(ValueError):
    """A sentence that is not a well-formed AIS position report."""


@dataclass(frozen=True)
class AisPosition:
    """One AIS position report.

    Attributes
    ----------
    mmsi : int
        The vessel's MMSI.
    lat, lon : float
        Position [°].
    sog_ms, cog_deg, hdg_deg : float or None
        Speed [m s⁻¹] and course [° true] over the ground, true heading [°]; None when
        the report says "not available".
    second : int or None
        UTC second of the minute the position was taken (0-59), None when not given.
    """

    mmsi: int
    lat: float
    lon: float
    sog_ms: float | None
    cog_deg: float | None
    hdg_deg: float | None
    second: int | None

    @property
    def vessel(self) -> str:
        """The vessel key ``urn:mrn:imo:mmsi:<MMSI>``."""
        return f"{MMSI_URN}{self.mmsi:09d}"


def is_ais(text: str) -> bool:
    """True for an ``!AIVDM``/``!AIVDO`` sentence (any talker)."""
    return len(text) > 6 and text[0] == "!" and text[3:6] in ("VDM", "VDO")


def _bits(payload: str) -> str:
    """The payload's bits as a string of ``0``/``1`` (6 per character)."""
    out = []
    for ch in payload:
        v = ord(ch) - 48
        if v > 40:
            v -= 8
        if not 0 <= v < 64 or 87 < ord(ch) < 96:
            raise AisError(f"{ch!r} is not a 6-bit AIS character")
        out.append(f"{v:06b}")
    return "".join(out)


def _uint(bits: str, start: int, n: int) -> int:
    return int(bits[start : start + n], 2)


def _sint(bits: str, start: int, n: int) -> int:
    v = _uint(bits, start, n)
    return v - (1 << n) if v >= 1 << (n - 1) else v


def parse_ais(text: str, *, require_checksum: bool = True) -> AisPosition | None:
    """The position report in one AIS sentence, or None for another message.

    Parameters
    ----------
    text : str
        ``!AIVDM,1,1,,A,<payload>,<fill>*hh`` (line end stripped).
    require_checksum : bool
        A sentence without ``*hh`` is refused.

    Returns
    -------
    AisPosition or None
        None: a message type that is not a position report, or one sentence of several.

    Raises
    ------
    AisError
        A bad or missing checksum (the message says which), a wrong number of fields,
        a payload too short for its type, a position not available or off the globe.
    """
    body, star, given = text[1:].partition("*")
    if not star:
        if require_checksum:
            raise AisError("no checksum")
    elif given.strip().upper() != checksum(body):
        raise AisError("bad checksum")
    fields = body.split(",")
    if len(fields) != 7:
        raise AisError(f"{len(fields)} fields, expected 7")
    if fields[1] != "1":
        return None  # one of several sentences: not a single-sentence position report
    bits = _bits(fields[5])
    if len(bits) < 6:
        raise AisError("empty payload")
    kind = _uint(bits, 0, 6)
    if kind not in POSITION_TYPES:
        return None
    if kind in (1, 2, 3):
        need, sog_at, lon_at, cog_at, hdg_at, sec_at = 143, 50, 61, 116, 128, 137
    else:
        need, sog_at, lon_at, cog_at, hdg_at, sec_at = 139, 46, 57, 112, 124, 133
    if len(bits) < need:
        raise AisError(f"type {kind} needs {need} bits, the payload has {len(bits)}")
    lon = _sint(bits, lon_at, 28) / 600_000.0
    lat = _sint(bits, lon_at + 28, 27) / 600_000.0
    if not (abs(lat) <= 90.0 and abs(lon) <= 180.0):
        raise AisError(f"position {lat:.4f}, {lon:.4f} not available or off the globe")
    sog = _uint(bits, sog_at, 10)
    cog = _uint(bits, cog_at, 12)
    hdg = _uint(bits, hdg_at, 9)
    sec = _uint(bits, sec_at, 6)
    return AisPosition(
        _uint(bits, 8, 30),
        lat,
        lon,
        None if sog >= 1023 else sog / 10.0 * KN,
        None if cog >= 3600 else cog / 10.0,
        None if hdg >= 360 else float(hdg),
        None if sec >= 60 else sec,
    )


def report_time(clock: float, second: int | None) -> float:
    """The time of a report made at ``second`` of a minute, heard at ``clock`` [epoch s].

    The latest time at or before ``clock`` + 2 s whose second of the minute is
    ``second`` (a report is at most a minute old; 2 s of slack for the receiver's clock
    running a little behind); ``clock`` itself when the second is not given.
    """
    if second is None:
        return clock
    t = (clock // 60.0) * 60.0 + second
    return t - 60.0 if t > clock + 2.0 else t
