"""NMEA 0183 sentences as text: the checksum, the frame, latitude and longitude fields, and
a route's ``RTE`` sentences within the 82-character limit.

Shared by the route file of ``plan`` (:mod:`sailroute.report.route_export`) and the
plotter output of ``live`` (:mod:`sailroute.live.nmeaout`), which choose their own talker,
waypoint identifiers and line ends.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import reduce
from typing import Final

__all__ = ["NMEA_MAX_LEN", "checksum", "frame", "lat_field", "lon_field", "rte_bodies"]

NMEA_MAX_LEN: Final = 82
"""Most characters of a sentence, ``$`` to the line end (IEC 61162-1)."""


def checksum(body: str) -> str:
    """The checksum of a sentence body (the text between ``$`` and ``*``): the XOR of its
    bytes, two hex digits."""
    return f"{reduce(lambda a, ch: a ^ ord(ch), body, 0):02X}"


def frame(body: str) -> str:
    """``$<body>*<checksum>``, without a line end."""
    return f"${body}*{checksum(body)}"


def _degrees_minutes(value: float, width: int) -> str:
    a = abs(value)
    d = int(a)
    m = round((a - d) * 60.0, 4)
    if m >= 60.0:  # 59.99996' prints as the next whole degree, not as 60.0000'
        d, m = d + 1, 0.0
    return f"{d:0{width}d}{m:07.4f}"


def lat_field(lat: float) -> tuple[str, str]:
    """Latitude [°] as the fields ``ddmm.mmmm`` and ``N``/``S`` (0.2 m resolution)."""
    return _degrees_minutes(lat, 2), "N" if lat >= 0 else "S"


def lon_field(lon: float) -> tuple[str, str]:
    """Longitude [°] as the fields ``dddmm.mmmm`` and ``E``/``W``."""
    return _degrees_minutes(lon, 3), "E" if lon >= 0 else "W"


def rte_bodies(talker: str, route_id: str, ids: Sequence[str]) -> list[str]:
    """The bodies of a route's ``RTE`` sentences (complete route, ``c``): the waypoint
    identifiers in order, split so that each framed sentence with its CR LF stays within
    :data:`NMEA_MAX_LEN` (the header's counts are taken at two digits each)."""
    room = NMEA_MAX_LEN - len("$") - len("*hh") - len("\r\n")
    head = len(f"{talker}RTE,99,99,c,{route_id}")
    groups: list[list[str]] = [[]]
    for i in ids:
        if groups[-1] and head + sum(len(x) + 1 for x in groups[-1]) + len(i) + 1 > room:
            groups.append([])
        groups[-1].append(i)
    n = len(groups)
    return [f"{talker}RTE,{n},{k + 1},c,{route_id},{','.join(g)}" for k, g in enumerate(groups)]
