"""The live loop: read the instruments, gate every reading, follow the wind and the
sailor's boat, re-plan, publish.

Threads share one :class:`LiveEngine`:

* one source thread per feed (:mod:`sailroute.live.sources`): the coach boat's
  instruments (``--source``), and optionally the sailor's boat's own feed
  (``--boat-source``).  Every message is decoded into readings, each reading passes the
  gate (:mod:`sailroute.live.gates`) and updates the state under a lock (microseconds per
  message, so a 1 Hz feed, or a replay hundreds of times faster, never falls behind).
  A message that raises anything is counted (``error``) and the thread goes on: no single
  message ends a source;
* the planner thread wakes on every reading and starts a re-plan of the remaining course
  (:class:`~sailroute.live.planner.PlanCore`) from the sailor's boat in the measured
  wind, in a thread of its own, when one is due: ``first``; ``shift`` (the wind estimator
  found a change point, :mod:`sailroute.live.windest`); ``rounding`` (the sailor's boat
  ended a leg, :mod:`sailroute.live.legs`); ``coach`` (the coach set the boat, its
  position or the leg on the page); ``interval`` (``every_s`` of data time since the
  last re-plan).  An interval re-plan waits for the one under way; the others start at
  once next to it (two at a time), and a re-plan that finishes after a newer one is
  dropped, not shown;
* the page server and the NMEA server answer their clients from the latest state.

The data clock is the feed's own: the newest accepted timed reading (an ``RMC``, ``GGA``,
``GLL`` or ``ZDA``, a Signal K timestamp).  The coach boat's readings without a time of
their own are placed at it; the sailor's boat's reports keep their own times.  The data go
*stale* when the instruments have said nothing for ``stale_s`` of wall time or lost
their connection; the page says so and no re-plan starts.

Every reading of the own instruments, every fix of the sailor's boat, every reading held
out and every re-plan is one line of the JSON-lines log (``kind``: ``"input"``,
``"boat"``, ``"reject"``, ``"leg"``, ``"plan"``, ``"link"``, ``"error"``, ``"end"``),
flushed each second and at the end.
"""

from __future__ import annotations

import json
import math
import threading
import time
import traceback
from collections import Counter, deque
from collections.abc import Mapping
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, replace
from pathlib import Path
from typing import IO, Any

import numpy as np

from sailroute.boat.model import BoatModel
from sailroute.course.geometry import FAR_FROM_COURSE_M, course_gap_m, feature_centre
from sailroute.course.model import Course
from sailroute.errors import InputError, SailrouteError
from sailroute.live.boat import BOAT_SOURCE, SELF, Fix, Sailor, VesselTable, Where, vessel_key
from sailroute.live.decode import NOT_USED, NmeaDecoder, Reading, SignalKDecoder
from sailroute.live.gates import GateLimits, ReadingGate
from sailroute.live.legs import LegChange, LegTracker
from sailroute.live.livewind import DEFAULT_FADE_S, apparent_to_true
from sailroute.live.nmeaout import NmeaServer, open_nmea_server, route_sentences, steer_sentences
from sailroute.live.planner import (
    MEASURED_ONLY,
    PlanCore,
    Planner,
    PlanRequest,
    Superseded,
    ThreadPlanner,
)
from sailroute.live.replan import DEFAULT_REACH_M, LivePlan, upwind_or_downwind_laylines
from sailroute.live.sources import TOO_LONG, Source
from sailroute.live.web import PageServer, loopback
from sailroute.live.windest import DEFAULT_WINDOW_S, Change, WindEstimator
from sailroute.routing.settings import RoutingSettings
from sailroute.units import KNOT
from sailroute.wind.base import WindField

TRUE_WIND_HOLD_S: float = 10.0
"""While a true-wind sentence came in the last this many seconds [s], apparent wind is
not converted (the instrument's own true wind is preferred: it has its calibration)."""
IN_FLIGHT: int = 2
"""Re-plans computed at once at most (an interval re-plan only when none is)."""
ERROR_LOG_S: float = 10.0
"""A message that raised is logged at most once per this many wall seconds (all are
counted)."""
PRIORITY = ("first", "coach", "rounding", "shift")
"""Re-plan reasons that start next to one under way, most urgent first."""


@dataclass(frozen=True)
class LiveSettings:
    """How the live loop reads and re-plans.

    Attributes
    ----------
    every_s : float
        Re-plan at least this often [s of data time].
    shift_deg, change_ms : float
        Smallest wind direction [°] and speed [m s⁻¹] change that is a shift
        (:class:`~sailroute.live.windest.WindEstimator`; a larger one is needed where the
        wind's own noise is larger).
    fade_s : float
        E-folding time of the measured wind's weight ahead [s]
        (:class:`~sailroute.live.livewind.LiveWind`).
    window_s : float
        Longest averaging window of the measured wind [s].
    stale_s : float
        Data older than this [s of wall time] are stale.
    reach_m : float
        Distance at which a turning point of the route counts as reached by the plotter's
        steering [m].
    side : bool
        Compute the side that pays (two more routed legs per re-plan).
    require_checksum : bool
        Refuse NMEA 0183 sentences without a checksum.
    """

    every_s: float = 10.0
    shift_deg: float = 5.0
    change_ms: float = 0.5144
    fade_s: float = DEFAULT_FADE_S
    window_s: float = DEFAULT_WINDOW_S
    stale_s: float = 5.0
    reach_m: float = DEFAULT_REACH_M
    side: bool = True
    require_checksum: bool = True


class JsonLog:
    """The JSON-lines log: one object per line, flushed at most a second late and at close."""

    def __init__(self, path: Path | None) -> None:
        self._fh: IO[str] | None = None
        if path is not None:
            try:
                self._fh = open(path, "w", encoding="utf-8")  # noqa: SIM115 (closed in close)
            except OSError as exc:
                raise InputError(
                    f"--log {path}: cannot write ({exc.strerror}); give a path "
                    "in a folder that exists and is writable"
                ) from None
        self._lock = threading.Lock()
        self._flushed = time.monotonic()
        self.lines = 0
        self.enabled = path is not None

    def write(self, record: Mapping[str, Any]) -> None:
        """Append one record."""
        if not self.enabled:
            return
        text = json.dumps(record, separators=(",", ":"), ensure_ascii=True)
        with self._lock:
            fh = self._fh
            if fh is None:  # closed meanwhile
                return
            fh.write(text + "\n")
            self.lines += 1
            now = time.monotonic()
            if now - self._flushed > 1.0:
                fh.flush()
                self._flushed = now

    def close(self) -> None:
        """Flush and close."""
        with self._lock:
            if self._fh is not None:
                self._fh.flush()
                self._fh.close()
                self._fh = None


def input_problem(
    course: Course, boat: BoatModel, xy: tuple[float, float], tws_ms: float
) -> str | None:
    """Why a re-plan from this position in this wind would mislead, or None.

    A position more than :data:`~sailroute.course.geometry.FAR_FROM_COURSE_M` from the
    course area (:func:`~sailroute.course.geometry.course_gap_m`), or a measured wind
    above the polar's highest wind speed (its speeds there would be extrapolated), is
    said on the page and in the log instead of routed from.
    """
    d = course_gap_m(course, xy)
    if not d <= FAR_FROM_COURSE_M:  # NaN too
        return (
            f"the position is {d / 1000:.1f} km from the course area (the marks' box): "
            "not re-planned (check the GPS source and the course file)"
        )
    polar = boat.routing_polar()
    if polar is not None and math.isfinite(tws_ms):
        top = float(np.max(polar.tws_ms))
        if tws_ms > top:
            return (
                f"the measured wind, {tws_ms / KNOT:.1f} kn, is above the polar's highest "
                f"wind speed, {top / KNOT:.1f} kn: not re-planned (the boat's speeds there "
                "are unknown; give a polar that covers it)"
            )
    return None


def _top_tws(boat: BoatModel) -> float:
    """The polar's highest wind speed [m s⁻¹] (40 kn for a boat without a polar)."""
    polar = boat.routing_polar()
    return float(np.max(polar.tws_ms)) if polar is not None else 40.0 * KNOT


@dataclass
class _Feed:
    """One source with its decoder and role (``instruments`` or ``boat``)."""

    source: Source
    decoder: NmeaDecoder | SignalKDecoder
    role: str
    linked: bool = False
    wall: float = -math.inf
    note: str = ""
    ended: bool = False


class LiveEngine:
    """Read the feeds, re-plan the rest of ``course`` for the sailor's boat, serve the page
    and the NMEA port.

    Parameters
    ----------
    course : Course
        The course being raced.
    forecast : WindField
        The scenario's wind (the forecast the measured wind fades into).
    boat : BoatModel
        The boat.
    routing : RoutingSettings
        Router settings.
    source : Source
        The coach boat's instrument feed.
    settings : LiveSettings
        Re-plan rules.
    port, nmea_port : int or None
        Page and NMEA-out TCP ports (0: a free one; None: none).  A busy NMEA port is
        replaced by the next free one (:attr:`notes` says so).
    log : Path, optional
        JSON-lines log.
    leg : int
        The leg being sailed at the start (0-based).
    planner : Planner, optional
        Where re-plans are computed; default: in the calling threads
        (:class:`~sailroute.live.planner.ThreadPlanner`).  The engine closes it.
    sailor : str, optional
        The sailor's boat (:mod:`sailroute.live.boat`): ``"self"``, a vessel key, or None
        (chosen on the page).
    boat_source : Source, optional
        The sailor's boat's own feed (its own position is vessel
        :data:`~sailroute.live.boat.BOAT_SOURCE`).
    host : str
        Address the page and the NMEA port listen on.
    token : str, optional
        Required in the page's address (``?token=``) for every request; None: only for
        the page's changes (the page carries it).
    """

    def __init__(
        self,
        course: Course,
        forecast: WindField,
        boat: BoatModel,
        routing: RoutingSettings,
        source: Source,
        settings: LiveSettings = LiveSettings(),
        *,
        port: int | None = 0,
        nmea_port: int | None = 0,
        log: Path | None = None,
        leg: int = 0,
        planner: Planner | None = None,
        sailor: str | None = SELF,
        boat_source: Source | None = None,
        host: str = "127.0.0.1",
        token: str | None = None,
    ) -> None:
        self.course, self.forecast, self.boat, self.routing = course, forecast, boat, routing
        self.planner: Planner = planner or ThreadPlanner(PlanCore(course, forecast, boat, routing))
        self.source, self.settings = source, settings
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self.done = threading.Event()
        self._feeds = [_Feed(source, self._decoder(source), "instruments")]
        if boat_source is not None:
            self._feeds.append(_Feed(boat_source, self._decoder(boat_source), "boat"))
        frame = course.frame

        def to_xy(lat: float, lon: float) -> tuple[float, float]:
            x, y = frame.to_xy(lat, lon)
            return float(x), float(y)

        self._gate = ReadingGate(
            GateLimits.for_polar(_top_tws(boat)),
            to_xy,
            lambda x, y: course_gap_m(course, (x, y)),
        )
        self._wind = WindEstimator(settings.window_s, settings.shift_deg, settings.change_ms)
        self._own: Fix | None = None
        self._sog: float | None = None
        self._cog: float | None = None
        self._hdg: float | None = None
        self._true_t = -math.inf
        self.vessels = VesselTable()
        self.sailor = Sailor(None if sailor is None else vessel_key(sailor))
        self.legs = LegTracker(course, leg)
        self._pending: set[str] = {"first"}
        self._shift: Change | None = None
        self._in_flight = 0
        self._requested = 0
        self._last_request_t = -math.inf
        self.plan: LivePlan | None = None
        self._waypoint = 0
        self.error = ""
        self.error_t: float | None = None
        self.waiting = ""
        self.n_readings = 0
        self.n_plans = 0
        self.n_links = 0
        self.n_drops = 0
        self.n_errors = 0
        self._errors_logged = -math.inf
        self.problems: Counter[str] = Counter()
        # (number, wall time, data clock) of the last plans published (the benchmark's)
        self.published: deque[tuple[int, float, float | None]] = deque(maxlen=1000)
        self.notes: list[str] = []
        self.log = JsonLog(log)
        self._threads: list[threading.Thread] = []
        self._plan_threads: set[threading.Thread] = set()
        self.source_ended = threading.Event()
        self.page: PageServer | None = None
        self.nmea: NmeaServer | None = None
        try:
            if port is not None:
                self.page = PageServer(
                    self.state, port, host, token, self.command, token_for_all=not loopback(host)
                )
        except OSError as exc:
            self.planner.close()
            raise InputError(
                f"--port {port}: cannot serve the page ({exc.strerror}); pick a free port"
            ) from None
        try:
            if nmea_port is not None:
                self.nmea, note = open_nmea_server(nmea_port, host)
                if note:
                    self.notes.append(note)
        except OSError as exc:
            self._close_servers()
            self.planner.close()
            raise InputError(
                f"--nmea-port {nmea_port}: cannot listen ({exc.strerror}); pick a free port"
            ) from None

    def _decoder(self, source: Source) -> NmeaDecoder | SignalKDecoder:
        if source.kind == "signalk":
            return SignalKDecoder()
        return NmeaDecoder(require_checksum=self.settings.require_checksum)

    # ------------------------------------------------------------------------- input
    def _link(self, feed: _Feed, up: bool, note: str) -> None:
        with self._lock:
            if feed.linked and not up:
                self.n_drops += 1
            feed.linked, feed.note = up, note
            self.n_links += up
        self.log.write(
            {"kind": "link", "source": feed.role, "up": up, "note": note, "wall": time.time()}
        )

    def feed(self, text: str, which: int = 0) -> None:
        """Decode one message of feed ``which`` and update the state (source thread).

        Never raises: a message that makes anything raise is counted as ``error`` and
        logged (at most once per :data:`ERROR_LOG_S`).
        """
        try:
            self._feed(text, self._feeds[which])
        except Exception as exc:  # no single message may end a source
            with self._lock:
                self.n_errors += 1
                self.problems["error"] += 1
                due = time.monotonic() - self._errors_logged > ERROR_LOG_S
                if due:
                    self._errors_logged = time.monotonic()
            if due:
                self.log.write(
                    {
                        "kind": "error",
                        "message": f"a message of {self._feeds[which].source.label} raised "
                        f"{type(exc).__name__}: {str(exc)[:200]} (skipped; "
                        f"{self.n_errors} so far)",
                        "where": traceback.format_exc(limit=3)[-600:],
                    }
                )

    def _feed(self, text: str, feed: _Feed) -> None:
        records: list[dict[str, Any]] = []
        steer = None
        with self._lock:
            feed.wall = time.monotonic()
            if text is TOO_LONG:
                self.problems["too_long"] += 1
                return
            out = feed.decoder.feed(text)
            batch = [] if out is None else (out if isinstance(out, list) else [out])
            moved = False
            for r in batch:
                moved |= self._take(r, feed, records)
            if moved:
                steer = self._steer()
        for rec in records:
            self.log.write(rec)
        if steer and self.nmea is not None:
            self.nmea.send(steer)
        if records:
            self._wake.set()

    def _take(self, r: Reading, feed: _Feed, records: list[dict[str, Any]]) -> bool:
        """Gate one reading and merge it into the state (lock held); True when the
        sailor's boat moved."""
        if feed.role == "boat" and not r.vessel:
            r = replace(r, vessel=BOAT_SOURCE)
        if r.vessel:  # another boat: its position and motion only, at its own time
            r = replace(
                r, tws_ms=None, twd_deg=None, twa_deg=None, aws_ms=None, awa_deg=None, stw_ms=None
            )
        elif not r.timed:
            clock = self._gate.clock
            if clock is None:
                self.problems["untimed"] += 1
                return False
            r = replace(r, t=clock)
        why = self._gate.check(r)
        if why:
            records.append({"kind": "reject", "why": why, **_whose(r), **r.as_dict()})
            if isinstance(feed.decoder, NmeaDecoder) and self._gate.clock is not None:
                feed.decoder.set_clock(self._gate.clock)  # not dated by the refused time
            return False
        if r.vessel:
            return self._other(r, records)
        return self._mine(r, records)

    def _mine(self, r: Reading, records: list[dict[str, Any]]) -> bool:
        """A reading of the coach boat's own instruments."""
        quantities = {k: v for k, v in r.as_dict().items() if k != "t"}
        if not quantities:
            return False  # a time only (ZDA)
        self.n_readings += 1
        self._sog = r.sog_ms if r.sog_ms is not None else self._sog
        self._cog = r.cog_deg if r.cog_deg is not None else self._cog
        self._hdg = r.hdg_deg if r.hdg_deg is not None else self._hdg
        tws = twd = None
        if r.tws_ms is not None and r.twd_deg is not None:
            tws, twd = r.tws_ms, r.twd_deg
            self._true_t = r.t
        elif r.tws_ms is not None and r.twa_deg is not None and self._hdg is not None:
            tws, twd = r.tws_ms, (self._hdg + r.twa_deg) % 360.0
            self._true_t = r.t
        elif (
            r.aws_ms is not None
            and r.awa_deg is not None
            and self._sog is not None
            and self._cog is not None
            and r.t - self._true_t > TRUE_WIND_HOLD_S
        ):
            tws, twd = apparent_to_true(r.aws_ms, r.awa_deg, self._sog, self._cog, self._hdg)
            r = replace(r, tws_ms=tws, twd_deg=twd)
        if tws is not None and twd is not None:
            change = self._wind.add(r.t, tws, twd)
            if change is not None:
                self._shift = change
                self._pending.add("shift")
                records.append(
                    {
                        "kind": "shift",
                        "t": round(change.t, 3),
                        "what": change.kind,
                        "before": [round(change.before[0], 3), round(change.before[1], 1)],
                        "after": [round(change.after[0], 3), round(change.after[1], 1)],
                    }
                )
        records.append({"kind": "input", **r.as_dict()})
        moved = False
        if r.lat is not None and r.lon is not None:
            fix = Fix(r.t, r.lat, r.lon, self._sog, self._cog, self._hdg)
            if self._own is None or fix.t >= self._own.t:
                self._own = fix
            if self.sailor.key == SELF:
                moved = self._sailor_fix(fix, records)
        return moved

    def _other(self, r: Reading, records: list[dict[str, Any]]) -> bool:
        """A reading of another vessel: its fix in the table, and the sailor's boat's."""
        if r.lat is None or r.lon is None:
            return False
        fix = Fix(r.t, r.lat, r.lon, r.sog_ms, r.cog_deg, r.hdg_deg)
        self.vessels.update(r.vessel, fix)
        if r.vessel != self.sailor.key:
            return False
        records.append({"kind": "boat", **_whose(r), **r.as_dict()})
        return self._sailor_fix(fix, records)

    def _sailor_fix(self, fix: Fix, records: list[dict[str, Any]]) -> bool:
        """The sailor's boat's next fix: its track, and the leg it is on (lock held)."""
        if not self.sailor.take(fix):
            return False
        x, y = self.course.frame.to_xy(fix.lat, fix.lon)
        for change in self.legs.update(fix.t, float(x), float(y)):
            self._leg_changed(change, records)
        return True

    def _leg_changed(self, change: LegChange, records: list[dict[str, Any]]) -> None:
        c = change.crossing
        records.append(
            {
                "kind": "leg",
                "leg": change.leg,
                "how": change.how,
                "t": None if not math.isfinite(c.t) else round(c.t, 3),
                "boat": self.sailor.key,
            }
        )
        if change.how != "start":
            self._pending.add("rounding" if change.how == "rounding" else "coach")

    def _steer(self) -> list[str] | None:
        """``RMB``/``APB`` from the sailor's boat to the next waypoint of the plan (lock
        held)."""
        plan, f = self.plan, self.sailor.fix
        if plan is None or f is None or not plan.waypoints:
            return None
        wps = plan.waypoints
        frame = self.course.frame
        x, y = frame.to_xy(f.lat, f.lon)
        while self._waypoint < len(wps) - 1:
            wx, wy = frame.to_xy(wps[self._waypoint][1], wps[self._waypoint][2])
            if math.hypot(float(x - wx), float(y - wy)) > self.settings.reach_m:
                break
            self._waypoint += 1
        dest = wps[self._waypoint]
        origin = wps[self._waypoint - 1] if self._waypoint > 0 else ("BOAT", f.lat, f.lon)
        return steer_sentences(f.lat, f.lon, f.sog_ms or 0.0, f.cog_deg or 0.0, origin, dest)

    # ------------------------------------------------------------------------- the page
    def command(self, name: str, args: Mapping[str, Any]) -> str:
        """What the coach changed on the page: ``boat`` (``{"boat": key or "self"}``),
        ``position`` (``{"lat", "lon"}``), ``leg`` (``{"leg": 1-based}``).

        Returns
        -------
        str
            What was done (said on the page).

        Raises
        ------
        InputError
            A value that is not one of these.
        """
        with self._lock:
            clock = self._gate.clock
            if name == "boat":
                key = args.get("boat")
                if not isinstance(key, str) or not key.strip() or len(key) > 200:
                    raise InputError("boat: give 'self' or a vessel's id")
                key = vessel_key(key)
                self.sailor.choose(key)
                if key == SELF and self._own is not None:
                    self.sailor.take(self._own)
                else:
                    last = self.vessels.get(key)
                    if last is not None:
                        self.sailor.take(last)
                done = f"routing {key}"
            elif name == "position":
                lat, lon = args.get("lat"), args.get("lon")
                if not all(isinstance(v, int | float) and math.isfinite(v) for v in (lat, lon)):
                    raise InputError("position: give lat and lon in degrees")
                assert isinstance(lat, int | float) and isinstance(lon, int | float)
                xy = self.course.frame.to_xy(float(lat), float(lon))
                gap = course_gap_m(self.course, (float(xy[0]), float(xy[1])))
                if not abs(lat) <= 90 or not abs(lon) <= 180 or not gap <= FAR_FROM_COURSE_M:
                    raise InputError(
                        f"position {lat}, {lon}: not within {FAR_FROM_COURSE_M / 1000:.0f} km "
                        "of the course area"
                    )
                if clock is None:
                    raise InputError("position: no data clock yet (no fix from the feed)")
                self.sailor.set_position(clock, float(lat), float(lon))
                done = f"routing from {lat:.5f}, {lon:.5f}"
            elif name == "leg":
                leg = args.get("leg")
                n = self.course.n_legs
                if not isinstance(leg, int) or not 1 <= leg <= n:
                    raise InputError(f"leg: give a leg number 1..{n}")
                self.legs.set_leg(leg - 1)
                done = f"leg {leg} of {n}"
                self.log.write({"kind": "leg", "leg": leg - 1, "how": "set", "t": clock})
            else:
                raise InputError(f"{name}: not a command of the page (boat, position, leg)")
            self._pending.add("coach")
        self.log.write({"kind": "coach", "command": name, "done": done, "t": clock})
        self._wake.set()
        return done

    # ------------------------------------------------------------------------- state
    def stale(self) -> bool:
        """No data for ``stale_s`` of wall time, or the instruments are disconnected."""
        with self._lock:
            return self._stale()

    def _stale(self) -> bool:
        feed = self._feeds[0]
        return (not feed.linked and not feed.ended) or (
            time.monotonic() - feed.wall > self.settings.stale_s
        )

    def counts(self) -> dict[str, int]:
        """Messages used and skipped, readings held out, by kind (lock held)."""
        c: Counter[str] = Counter()
        for f in self._feeds:
            c.update(f.decoder.counts.by_kind)
        used = sum(v for k, v in c.items() if k not in NOT_USED)
        bad = sum(f.decoder.counts.bad for f in self._feeds)
        return {
            "used": used,
            "bad": bad,
            "held_out": sum(v for k, v in self._gate.counts.items() if k in _HELD),
            **dict(c),
            **{f"gate_{k}": v for k, v in self._gate.counts.items()},
            **dict(self.problems),
        }

    def state(self) -> dict[str, Any]:
        """What ``/state.json`` serves."""
        with self._lock:
            clock = self._gate.clock
            est = self._wind.estimate()
            spread = self._wind.spread()
            where, why = (
                self.sailor.position(clock, self.course.frame) if clock is not None else (None, "")
            )
            leg = self.legs.leg
            frame = self.course.frame
            tg = None
            lls: list[dict[str, Any]] = []
            if leg < self.course.n_legs:
                c = feature_centre(self.course.feature(self.course.legs[leg].to_name))
                la, lo = frame.to_latlon(*c)
                tg = [float(la), float(lo)]
                if est is not None:
                    bxy = None
                    if where is not None:
                        bx, by = frame.to_xy(where.lat, where.lon)
                        bxy = (float(bx), float(by))
                    for ll in upwind_or_downwind_laylines(self.course, leg, self.boat, est, bxy):
                        lls.append(
                            {
                                "tack": ll.tack,
                                "bearing_deg": round(ll.bearing_deg, 1),
                                "distance_m": _finite(ll.distance_m, 1),
                                "time_s": _finite(ll.time_s, 1),
                            }
                        )
            marks = []
            for name, m in self.course.marks.items():
                la, lo = frame.to_latlon(*m.xy)
                marks.append([name, round(float(la), 7), round(float(lo), 7)])
            lines = []
            for name, ln in (*self.course.lines.items(), *self.course.gates.items()):
                (la, la2), (lo, lo2) = frame.to_latlon(
                    np.array([ln.a.xy[0], ln.b.xy[0]]), np.array([ln.a.xy[1], ln.b.xy[1]])
                )
                lines.append([name, *(round(float(v), 7) for v in (la, lo, la2, lo2))])
            plan = self.plan
            f = self.sailor.fix
            return {
                "t": clock,
                "source": self.source.label,
                "stale": self._stale(),
                "link": self._feeds[0].note,
                "leg": leg,
                "n_legs": self.course.n_legs,
                "leg_labels": [lg.label for lg in self.course.legs],
                "boat": {
                    "id": self.sailor.key,
                    "where": None
                    if where is None
                    else {
                        "lat": where.lat,
                        "lon": where.lon,
                        "age_s": round(where.age_s, 1),
                        "how": where.how,
                    },
                    "sog_ms": None if f is None else f.sog_ms,
                    "cog_deg": None if f is None else f.cog_deg,
                    "hdg_deg": None if f is None else f.hdg_deg,
                    "track": [[round(a, 7), round(b, 7)] for _, a, b in self.sailor.track],
                    "why_not": why,
                },
                "position": None
                if self._own is None
                else {
                    "t": self._own.t,
                    "lat": self._own.lat,
                    "lon": self._own.lon,
                    "sog_ms": self._sog,
                    "cog_deg": self._cog,
                    "hdg_deg": self._hdg,
                },
                "vessels": self.vessels.listing(clock)[:30],
                "wind": None
                if est is None
                else {
                    "tws_ms": est[0],
                    "twd_deg": est[1],
                    "spread_deg": round(spread[0], 1),
                    "since": self._wind.since,
                },
                "wind_trend": [
                    [round(a, 1), round(b, 3), round(c, 1), round(d, 1)]
                    for a, b, c, d in self._wind.trend()
                ],
                "shift": None
                if self._wind.last_change is None
                else {
                    "t": self._wind.last_change.t,
                    "shift_deg": round(self._wind.last_change.shift_deg, 1),
                    "kind": self._wind.last_change.kind,
                },
                "laylines": lls,
                "plan": None if plan is None else plan.as_dict(),
                "plan_age_s": None if plan is None or clock is None else round(clock - plan.t, 1),
                "measured_only": plan is not None and bool(plan.wind_note),
                "next_mark": tg,
                "marks": marks,
                "lines": lines,
                "error": self.error,
                "error_t": self.error_t,
                "waiting": self.waiting,
                "counts": self.counts(),
                "held_out": dict(self._gate.last),
                "notes": list(self.notes),
            }

    # ------------------------------------------------------------------------- planning
    def _due(self) -> tuple[str, PlanRequest] | None:
        """The re-plan to start now, if one is due (lock held)."""
        clock = self._gate.clock
        if clock is None or self._stale() or self.done.is_set():
            return None
        est = self._wind.estimate()
        if est is None:
            self.waiting = "no wind reading yet"
            return None
        if self.legs.finished:
            self.waiting = "the boat has finished"
            return None
        where, why = self.sailor.position(clock, self.course.frame)
        if where is None:
            self.waiting = why
            return None
        self.waiting = ""
        reason = next((r for r in PRIORITY if r in self._pending), None)
        if reason == "first" and (self.plan is not None or self._in_flight):
            self._pending.discard("first")
            reason = next((r for r in PRIORITY if r in self._pending), None)
        if reason is not None:
            if self._in_flight >= IN_FLIGHT:
                return None
        elif self._in_flight == 0 and clock - self._last_request_t >= self.settings.every_s:
            reason = "interval"
        else:
            return None
        self._pending.clear()
        x, y = self.course.frame.to_xy(where.lat, where.lon)
        self._requested += 1
        self._in_flight += 1
        self._last_request_t = clock
        urgent = reason != "interval"
        if urgent:  # whatever is being computed is out of date: stop it
            self.planner.supersede(self._requested)
        return reason, PlanRequest(
            self._requested,
            reason,
            clock,
            float(x),
            float(y),
            self.legs.leg,
            est[0],
            est[1],
            self.settings.fade_s,
            coarse=urgent,
        )

    def replan(self, req: PlanRequest) -> LivePlan | None:
        """Compute ``req``, publish it unless a newer re-plan is already out, add its side
        that pays, log it; the plan, or None (refused, failed or superseded)."""
        try:
            return self._replan(req)
        finally:
            with self._lock:
                self._in_flight -= 1
            self._wake.set()

    def _replan(self, req: PlanRequest) -> LivePlan | None:
        problem = input_problem(self.course, self.boat, (req.x, req.y), req.tws_ms)
        if problem is not None:  # said on the page and in the log; no re-plan on it
            self._failed(req, problem)
            return None
        w0 = time.perf_counter()
        try:
            plan, first = self.planner.route(req)
        except Superseded:
            self.log.write({"kind": "superseded", "number": req.number, "t": req.t})
            return None
        except (SailrouteError, BrokenProcessPool) as exc:
            self._failed(req, str(exc))
            return None
        with self._lock:
            if self.plan is not None and self.plan.number > plan.number:
                superseded = True
            else:
                superseded = False
                self.plan, self._waypoint = plan, 0
                self.error, self.error_t = "", None
                self.n_plans += 1
                self.published.append((plan.number, time.monotonic(), self._gate.clock))
        if superseded:
            self.log.write({"kind": "superseded", "number": plan.number, "t": plan.t})
            return None
        if self.nmea is not None:
            self.nmea.send(route_sentences(plan.waypoints))
        if self.settings.side and not self._newer(plan.number):
            try:
                side = self.planner.side(req, first, bool(plan.wind_note))
            except Superseded:
                pass  # a newer re-plan is on its way
            except (SailrouteError, BrokenProcessPool) as exc:
                self.log.write({"kind": "error", "t": req.t, "message": f"side: {exc}"})
            else:
                plan = replace(plan, side=side, compute_s=time.perf_counter() - w0)
                with self._lock:
                    if self.plan is not None and self.plan.number == plan.number:
                        self.plan = plan
        self.log.write({"kind": "plan", **plan.as_dict()})
        return plan

    def _newer(self, number: int) -> bool:
        with self._lock:
            return self._requested > number

    def _failed(self, req: PlanRequest, message: str) -> None:
        with self._lock:
            self.error = message
            if self.error_t is None:
                self.error_t = req.t
        self.log.write({"kind": "error", "t": req.t, "message": message})

    def _plan_loop(self) -> None:
        while not self.done.is_set():
            self._wake.wait(0.25)
            self._wake.clear()
            while True:
                with self._lock:
                    due = self._due()
                if due is None or self.done.is_set():
                    break
                th = threading.Thread(
                    target=self._plan_thread, args=(due[1],), name="live-replan", daemon=True
                )
                with self._lock:
                    self._plan_threads.add(th)
                th.start()

    def _plan_thread(self, req: PlanRequest) -> None:
        try:
            self.replan(req)
        finally:
            with self._lock:
                self._plan_threads.discard(threading.current_thread())

    def _source_loop(self, which: int) -> None:
        feed = self._feeds[which]

        def emit(text: str) -> None:
            self.feed(text, which)

        def link(up: bool, note: str) -> None:
            self._link(feed, up, note)

        wait = 0.5
        try:
            while not self.done.is_set():
                try:
                    feed.source.run(emit, link, self.done)
                    break
                except SailrouteError as exc:
                    with self._lock:
                        self.error = str(exc)
                    self.log.write({"kind": "error", "message": str(exc)})
                    break
                except Exception as exc:  # a source must not end on a bug
                    self.log.write(
                        {
                            "kind": "error",
                            "message": f"{feed.source.label}: {type(exc).__name__}: {exc}",
                        }
                    )
                    with self._lock:
                        self.problems["source_error"] += 1
                        feed.linked = False
                    if self.done.wait(wait):
                        break
                    wait = min(wait * 2.0, 8.0)
        finally:
            with self._lock:
                feed.ended = True
            if which == 0:
                self.source_ended.set()
            self._wake.set()

    # ------------------------------------------------------------------------- life
    def start(self) -> LiveEngine:
        """Start the source and planner threads; returns self."""
        targets: list[tuple[str, Any, tuple[Any, ...]]] = [
            (f"live-source-{k}", self._source_loop, (k,)) for k in range(len(self._feeds))
        ]
        targets.append(("live-plan", self._plan_loop, ()))
        for name, target, args in targets:
            th = threading.Thread(target=target, args=args, name=name, daemon=True)
            th.start()
            self._threads.append(th)
        return self

    def _idle(self) -> bool:
        with self._lock:
            return self._in_flight == 0

    def wait(self, duration_s: float | None = None) -> None:
        """Block until ``duration_s`` of wall time passed, or the instruments' file ended
        and its last re-plan is done (None: until :meth:`close` from another thread)."""
        end = math.inf if duration_s is None else time.monotonic() + duration_s
        while not self.done.is_set() and time.monotonic() < end:
            if self.source_ended.wait(min(0.2, max(end - time.monotonic(), 0.0))):
                while not self._idle() and time.monotonic() < end:  # the re-plans under way
                    time.sleep(0.05)
                with self._lock:
                    due = self._due()
                if due is not None:
                    self.replan(due[1])
                return

    def _close_servers(self) -> None:
        if self.page is not None:
            self.page.close()

    def close(self) -> None:
        """End every thread and worker, close the ports, write the ``end`` line and close
        the log."""
        self.done.set()
        self._wake.set()
        self.planner.supersede(2**62)  # the re-plans under way stop at their next step
        for th in self._threads:
            th.join(timeout=30.0)
        with self._lock:
            planning = list(self._plan_threads)
        for th in planning:
            th.join(timeout=60.0)
        self._close_servers()
        self.planner.close()
        if self.nmea is not None:
            self.nmea.close()
        with self._lock:
            counts = self.counts()
        self.log.write(
            {
                "kind": "end",
                "readings": self.n_readings,
                "plans": self.n_plans,
                "drops": self.n_drops,
                "counts": counts,
                "leg": self.legs.leg,
                "wall": time.time(),
            }
        )
        self.log.close()


_HELD = ("bounds", "far", "jump", "time")


def _whose(r: Reading) -> dict[str, str]:
    """``{"vessel": key}`` for another vessel's reading, else nothing (the log's records)."""
    return {"vessel": r.vessel} if r.vessel else {}


def _finite(v: float, digits: int) -> float | None:
    return round(v, digits) if math.isfinite(v) else None


__all__ = ["MEASURED_ONLY", "JsonLog", "LiveEngine", "LiveSettings", "Where", "input_problem"]
