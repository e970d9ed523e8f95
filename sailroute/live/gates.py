"""The gate every decoded reading passes before the live loop uses it.

A checksum proves that a sentence arrived as it was sent, not that what it says is
true: an instrument can send a valid sentence with 80 kn of wind, a GPS a fix dated
2030, a gateway a speed of 5e29 m s⁻¹.  :class:`ReadingGate` holds out, and counts by
kind, every reading that

* **bounds** — says something no boat or wind on a course does: a value that is not a
  finite number, a boat speed (over the ground or through the water) of
  :data:`MAX_BOAT_KN` or more or below 0, a true wind speed above the polar's highest
  plus :data:`TWS_MARGIN_KN` (an apparent one above that plus the boat's top speed);
* **far** — a position more than
  :data:`~sailroute.course.geometry.FAR_FROM_COURSE_M` from the course area (the marks'
  box, the rule of ``sailroute start``);
* **jump** — jumps beyond what the last seconds allow: a position further from the
  vessel's last one than :data:`MAX_BOAT_KN` for the time between them plus
  :data:`JUMP_SLACK_M`; a true wind speed further than ``max(TWS_JUMP_MS, the speed
  itself)`` from the median of the last :data:`TWS_HISTORY` readings.  A jump that
  :data:`CONFIRM` readings in a row agree on is a new state, not a glitch: the next one
  is let through (a GPS that lost its fix and found it again elsewhere, a front);
* **time** — is dated outside :data:`CLOCK_WINDOW_S` of the feed's own clock (the
  newest accepted time): such a time is never adopted as the clock, so one fix from
  another clock cannot freeze the position for the rest of the run.  Only
  :data:`CONFIRM` timed readings in a row that agree with each other and not with the
  clock move it (``clock_reset``: it was the clock that was wrong, for example the
  first fix after a GPS cold start).

Wind direction is not checked for jumps: in light air it swings through tens of
degrees in a second; the shift detector (:mod:`sailroute.live.windest`) tells a
shift from that noise.  The counts and the last message of each kind are on the page
and in the log.
"""

from __future__ import annotations

import math
from collections import Counter, OrderedDict, deque
from collections.abc import Callable
from dataclasses import dataclass, field, fields

import numpy as np

from sailroute.course.geometry import FAR_FROM_COURSE_M
from sailroute.live.decode import Reading
from sailroute.units import KNOT

MAX_BOAT_KN: float = 70.0
"""A boat speed [kn] at or above which a reading is held out (no dinghy, coach boat or
foiler on a buoy course sails it)."""
TWS_MARGIN_KN: float = 10.0
"""Margin above the polar's highest wind speed before a TWS reading is held out [kn]."""
JUMP_SLACK_M: float = 30.0
"""Position error allowed on top of the top speed between two fixes [m] (GPS error and
fixes stamped to the second)."""
TWS_JUMP_MS: float = 5.0
"""Smallest TWS change from the recent median that counts as a jump [m s⁻¹] (10 kn)."""
TWS_HISTORY: int = 10
"""TWS readings the jump test takes its median over."""
CLOCK_WINDOW_S: float = 120.0
"""A timed reading more than this before or after the feed's clock is held out [s]."""
CONFIRM: int = 5
"""Readings in a row that must agree on a jump or a clock before it is believed."""
MAX_VESSELS: int = 256
"""Vessels whose last fix the jump test keeps (the least recently heard go first)."""

_SPEEDS = ("sog_ms", "stw_ms")


@dataclass(frozen=True)
class GateLimits:
    """The bounds of :class:`ReadingGate` (module docstring).

    Attributes
    ----------
    max_tws_ms : float
        Highest true wind speed let through [m s⁻¹].
    max_boat_ms : float
        Boat speeds at or above this are held out [m s⁻¹].
    reach_m : float
        Positions further than this from the course area are held out [m].
    clock_window_s : float
        Timed readings further than this from the feed's clock are held out [s].
    """

    max_tws_ms: float
    max_boat_ms: float = MAX_BOAT_KN * KNOT
    reach_m: float = FAR_FROM_COURSE_M
    clock_window_s: float = CLOCK_WINDOW_S

    @classmethod
    def for_polar(cls, top_tws_ms: float) -> GateLimits:
        """The limits for a boat whose polar ends at ``top_tws_ms`` [m s⁻¹]."""
        return cls(max_tws_ms=top_tws_ms + TWS_MARGIN_KN * KNOT)


@dataclass
class _Held:
    """Readings held out in a row, to tell a glitch from a new state."""

    values: deque[tuple[float, ...]] = field(default_factory=lambda: deque(maxlen=CONFIRM))

    def agree(self, value: tuple[float, ...], close: Callable[[tuple, tuple], bool]) -> bool:
        """Add ``value``; True once :data:`CONFIRM` in a row agree pairwise in order."""
        if self.values and not close(self.values[-1], value):
            self.values.clear()
        self.values.append(value)
        return len(self.values) >= CONFIRM


@dataclass
class _VesselState:
    fix: tuple[float, float, float] | None = None  # t, x, y
    held: _Held = field(default_factory=_Held)


class ReadingGate:
    """Hold out readings that bounds, distance, jumps or their time rule out.

    Not thread-safe: the owner calls it under its lock.

    Parameters
    ----------
    limits : GateLimits
        The bounds.
    to_xy : callable
        ``(lat, lon) -> (x, y)`` [m] in the course frame.
    gap_m : callable
        ``(x, y) -> distance [m]`` from the course area
        (:func:`~sailroute.course.geometry.course_gap_m`).

    Attributes
    ----------
    counts : Counter
        Readings held out, by kind (``bounds``, ``far``, ``jump``, ``time``), and
        ``clock_reset``.
    last : dict
        The last message of each kind (what the page shows).
    clock : float or None
        The feed's clock [epoch s]: the newest accepted time.
    """

    def __init__(
        self,
        limits: GateLimits,
        to_xy: Callable[[float, float], tuple[float, float]],
        gap_m: Callable[[float, float], float],
    ) -> None:
        self.limits = limits
        self._to_xy, self._gap_m = to_xy, gap_m
        self.counts: Counter[str] = Counter()
        self.last: dict[str, str] = {}
        self.clock: float | None = None
        self._clock_held = _Held()
        self._vessels: OrderedDict[str, _VesselState] = OrderedDict()
        self._tws: deque[float] = deque(maxlen=TWS_HISTORY)
        self._tws_held = _Held()

    def _out(self, kind: str, message: str) -> None:
        self.counts[kind] += 1
        self.last[kind] = message

    def _vessel(self, key: str) -> _VesselState:
        st = self._vessels.get(key)
        if st is None:
            st = self._vessels[key] = _VesselState()
            if len(self._vessels) > MAX_VESSELS:
                self._vessels.popitem(last=False)
        else:
            self._vessels.move_to_end(key)
        return st

    def check(self, r: Reading) -> str:
        """``""`` when ``r`` passes, else the kind it is held out as (and counted).

        A timed reading is checked against the clock's window; one of the own
        instruments (``vessel`` empty) dated inside it moves the clock.  A reading that
        passes updates the vessel's last fix and the TWS history.
        """
        why = self._bounds(r) or self._time(r)
        if why:
            return why
        if r.timed and not r.vessel:  # a time in the window is the feed's clock
            self.clock = r.t if self.clock is None else max(self.clock, r.t)
            self._clock_held.values.clear()
        xy: tuple[float, float] | None = None
        st: _VesselState | None = None
        if r.lat is not None and r.lon is not None:
            xy = self._to_xy(r.lat, r.lon)
            gap = self._gap_m(*xy)
            if not gap <= self.limits.reach_m:
                self._out(
                    "far",
                    f"a position {gap / 1000:.1f} km from the course area "
                    f"({r.lat:.4f}, {r.lon:.4f}): check the GPS and the course file",
                )
                return "far"
            st = self._vessel(r.vessel)
            if self._jumped(st, r.t, xy):
                return "jump"
        if r.tws_ms is not None and self._tws_jumped(r.tws_ms):
            return "jump"
        if st is not None and xy is not None:
            st.fix = (r.t, xy[0], xy[1])
            st.held.values.clear()
        if r.tws_ms is not None:
            self._tws.append(r.tws_ms)
            self._tws_held.values.clear()
        return ""

    def _bounds(self, r: Reading) -> str:
        for f in fields(r):
            v = getattr(r, f.name)
            if isinstance(v, float) and not math.isfinite(v):
                self._out("bounds", f"{f.name} is not a finite number")
                return "bounds"
        lim = self.limits
        for name in _SPEEDS:
            v = getattr(r, name)
            if v is not None and not 0.0 <= v < lim.max_boat_ms:
                self._out(
                    "bounds",
                    f"a boat speed of {v / KNOT:.3g} kn ({name}; at most "
                    f"{lim.max_boat_ms / KNOT:.0f} kn)",
                )
                return "bounds"
        for name, top in (("tws_ms", lim.max_tws_ms), ("aws_ms", lim.max_tws_ms + lim.max_boat_ms)):
            v = getattr(r, name)
            if v is not None and not 0.0 <= v <= top:
                self._out(
                    "bounds",
                    f"a wind speed of {v / KNOT:.3g} kn ({name}; at most {top / KNOT:.0f} kn, "
                    "the polar's highest plus a margin)",
                )
                return "bounds"
        return ""

    def _time(self, r: Reading) -> str:
        """Hold out a time outside the window round the clock (module docstring)."""
        if not r.timed or self.clock is None:
            return ""
        w = self.limits.clock_window_s
        if abs(r.t - self.clock) <= w:
            return ""
        if not r.vessel and self._clock_held.agree((r.t,), lambda a, b: abs(b[0] - a[0]) <= w):
            self.counts["clock_reset"] += 1
            self.last["clock_reset"] = (
                f"the clock moved by {r.t - self.clock:+.0f} s: {CONFIRM} fixes in a row "
                "agreed on the new time"
            )
            self.clock = r.t
            self._vessels.clear()  # every last fix is from the old clock
            return ""
        self._out(
            "time",
            f"a reading dated {r.t - self.clock:+.0f} s from the feed's clock "
            f"(more than {w:.0f} s): another clock",
        )
        return "time"

    def _jumped(self, st: _VesselState, t: float, xy: tuple[float, float]) -> bool:
        if st.fix is None:
            return False
        t0, x0, y0 = st.fix
        d = math.hypot(xy[0] - x0, xy[1] - y0)
        vmax = self.limits.max_boat_ms

        def close(a: tuple, b: tuple) -> bool:
            return (
                math.hypot(b[1] - a[1], b[2] - a[2])
                <= vmax * max(abs(b[0] - a[0]), 1.0) + JUMP_SLACK_M
            )

        if d <= vmax * max(abs(t - t0), 1.0) + JUMP_SLACK_M:
            return False
        if st.held.agree((t, xy[0], xy[1]), close):
            self.counts["jump_accepted"] += 1
            return False
        self._out("jump", f"a position {d:.0f} m from the last one {t - t0:.0f} s before")
        return True

    def _tws_jumped(self, tws: float) -> bool:
        if len(self._tws) < 3:
            return False
        med = float(np.median(self._tws))
        if abs(tws - med) <= max(TWS_JUMP_MS, med):
            return False

        def close(a: tuple, b: tuple) -> bool:
            return abs(b[0] - a[0]) <= max(TWS_JUMP_MS, a[0])

        if self._tws_held.agree((tws,), close):
            self._tws.clear()
            self.counts["jump_accepted"] += 1
            return False
        self._out(
            "jump", f"a wind speed of {tws / KNOT:.1f} kn against {med / KNOT:.1f} kn just before"
        )
        return True

    def report(self) -> dict[str, int]:
        """The counts (for the page and the log)."""
        return dict(self.counts)
