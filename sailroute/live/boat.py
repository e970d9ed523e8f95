"""Whose race: the sailor's boat among the vessels in the feed, and where it is now.

The coach boat's instruments give the wind; the route is the sailor's.  The sailor's
boat is chosen (``--boat``, or on the page) as

* ``self``: the instruments' own position (the coach is the boat, or sails beside it);
* a vessel in the feed: an AIS target (its MMSI, or ``urn:mrn:imo:mmsi:<MMSI>``), a
  Signal K ``vessels.<id>`` context (the id), or the boat of a second source
  (:data:`BOAT_SOURCE`);
* nobody yet: the page lists the vessels heard (:class:`VesselTable`) and the coach
  picks one, or types or taps a position.

:class:`Sailor` keeps the chosen boat's last fix and, for the page, its recent track.
Its position for a re-plan (:meth:`Sailor.position`) is the newest of the last fix and
the last position set on the page; a fix up to :data:`DEAD_RECKON_S` old is carried
forward along its SOG and COG to the data clock (an AIS class B report comes every
30 s at dinghy speeds); a fix older than :data:`BOAT_STALE_S`, or a position set on the
page more than :data:`MANUAL_HOLD_S` ago, is not routed from.
"""

from __future__ import annotations

from collections import OrderedDict, deque
from dataclasses import dataclass

from sailroute.geo import LocalFrame
from sailroute.live.ais import MMSI_URN
from sailroute.units import heading_unit

SELF: str = "self"
"""The ``--boat`` value for the instruments' own position."""
BOAT_SOURCE: str = "boat-source"
"""The vessel key of the own position of ``--boat-source``, the sailor's boat's feed."""
DEAD_RECKON_S: float = 60.0
"""A fix at most this old is carried forward by its SOG/COG [s of data time]."""
BOAT_STALE_S: float = 120.0
"""A fix older than this is not routed from [s of data time]."""
MANUAL_HOLD_S: float = 600.0
"""A position set on the page is routed from for this long [s of data time]."""
TRACK_STEP_S: float = 2.0
"""Spacing of the track kept for the page [s]."""
TRACK_S: float = 1800.0
"""Length of the track kept for the page [s]."""
MAX_VESSELS: int = 256
"""Vessels :class:`VesselTable` keeps (the least recently heard go first)."""


def vessel_key(text: str) -> str:
    """The vessel key ``--boat`` names: ``self``, an MMSI (nine digits) as
    ``urn:mrn:imo:mmsi:<MMSI>``, a Signal K context without ``vessels.``."""
    text = text.strip()
    if text.isdigit() and len(text) <= 9:
        return f"{MMSI_URN}{int(text):09d}"
    return text.removeprefix("vessels.")


@dataclass(frozen=True)
class Fix:
    """A position report.

    Attributes
    ----------
    t : float
        Time [epoch s].
    lat, lon : float
        Position [°].
    sog_ms, cog_deg, hdg_deg : float or None
        Speed [m s⁻¹] and course over the ground [° true], heading [° true].
    """

    t: float
    lat: float
    lon: float
    sog_ms: float | None = None
    cog_deg: float | None = None
    hdg_deg: float | None = None


@dataclass(frozen=True)
class Where:
    """Where a re-plan starts.

    Attributes
    ----------
    lat, lon : float
        Position [°] (dead-reckoned to the data clock).
    age_s : float
        Age of the fix or position it comes from [s of data time].
    how : {"fix", "dead reckoning", "page"}
        Where it comes from.
    """

    lat: float
    lon: float
    age_s: float
    how: str


class VesselTable:
    """The vessels heard and their last fixes (bounded; not thread-safe)."""

    def __init__(self, size: int = MAX_VESSELS) -> None:
        self.size = size
        self._last: OrderedDict[str, Fix] = OrderedDict()

    def update(self, key: str, fix: Fix) -> None:
        """Record ``key``'s newest fix."""
        old = self._last.get(key)
        if old is not None and fix.t < old.t:
            return
        self._last[key] = fix
        self._last.move_to_end(key)
        while len(self._last) > self.size:
            self._last.popitem(last=False)

    def get(self, key: str) -> Fix | None:
        """The last fix of ``key``, or None."""
        return self._last.get(key)

    def listing(self, clock: float | None) -> list[dict[str, object]]:
        """The vessels, most recently heard first, as the page lists them."""
        out = []
        for key, f in reversed(self._last.items()):
            out.append(
                {
                    "id": key,
                    "label": key.removeprefix(MMSI_URN) if key.startswith(MMSI_URN) else key,
                    "lat": round(f.lat, 6),
                    "lon": round(f.lon, 6),
                    "age_s": None if clock is None else round(clock - f.t, 1),
                }
            )
        return out


class Sailor:
    """The sailor's boat: which vessel it is, its last fix, a position set on the page and
    the recent track (not thread-safe)."""

    def __init__(self, key: str | None) -> None:
        self.key = key
        self.fix: Fix | None = None
        self.manual: tuple[float, float, float] | None = None  # t, lat, lon
        self.track: deque[tuple[float, float, float]] = deque(
            maxlen=int(TRACK_S / TRACK_STEP_S) + 1
        )

    def choose(self, key: str | None) -> None:
        """Follow another vessel (its track starts again)."""
        if key != self.key:
            self.key, self.fix = key, None
            self.track.clear()

    def take(self, fix: Fix) -> bool:
        """The chosen boat's next fix; False for one older than the last."""
        if self.fix is not None and fix.t < self.fix.t:
            return False
        self.fix = fix
        if not self.track or fix.t >= self.track[-1][0] + TRACK_STEP_S:
            self.track.append((fix.t, fix.lat, fix.lon))
        return True

    def set_position(self, t: float, lat: float, lon: float) -> None:
        """A position typed or tapped on the page, at data time ``t``."""
        self.manual = (t, lat, lon)

    def position(self, clock: float, frame: LocalFrame) -> tuple[Where | None, str]:
        """Where to route from at ``clock``, or None and why not (``frame``: the course
        frame, for dead reckoning)."""
        f, m = self.fix, self.manual
        if self.key is None and m is None:
            return None, "no boat chosen: pick the sailor's boat on the page or give --boat"
        if m is not None and (f is None or m[0] >= f.t):
            age = clock - m[0]
            if age <= MANUAL_HOLD_S:
                return Where(m[1], m[2], age, "page"), ""
            return None, (
                f"the position set on the page is {age / 60:.0f} min old: set it again, or "
                "choose a boat with a tracker"
            )
        if f is None:
            return None, f"no fix of {self.key} yet"
        age = clock - f.t
        if age > BOAT_STALE_S:
            return None, f"the last fix of {self.key} is {age:.0f} s old: not routed from"
        if 0.0 < age <= DEAD_RECKON_S and f.sog_ms is not None and f.cog_deg is not None:
            x, y = frame.to_xy(f.lat, f.lon)
            ux, uy = heading_unit(f.cog_deg + frame.grid_north_deg(f.lat, f.lon))
            la, lo = frame.to_latlon(x + f.sog_ms * age * ux, y + f.sog_ms * age * uy)
            return Where(float(la), float(lo), age, "dead reckoning"), ""
        return Where(f.lat, f.lon, max(age, 0.0), "fix"), ""
