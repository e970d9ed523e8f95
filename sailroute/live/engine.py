"""The live loop: read the instruments, keep the measured wind, re-plan, publish.

Three kinds of thread share one :class:`LiveEngine`:

* the source thread (:mod:`sailroute.live.sources`) decodes every message into
  readings and updates the boat's state under a lock (microseconds per message, so a
  1 Hz feed, or a replay hundreds of times faster, never falls behind);
* the planner thread wakes on every reading, and re-plans the remaining course
  (:func:`sailroute.live.replan.route_remaining`) when ``every_s`` of data time have
  passed since the last re-plan or the measured wind has changed by the threshold
  since (:func:`sailroute.live.livewind.wind_changed`); the routing runs outside the
  lock;
* the page server and the NMEA server answer their clients from the latest state.

The data clock is the time of the newest position fix (``RMC``, ``GGA``, ``GLL`` or a
Signal K ``navigation.position`` with its timestamp); every other reading is placed at
that time, because an instrument gateway stamps what it did not get a time for with its
own clock.  The data go *stale* when the source has said nothing for ``stale_s`` of
wall time or has lost its connection; the page says so and no re-plan starts.

Every reading and every re-plan is one line of the JSON-lines log (``kind``:
``"input"``, ``"plan"``, ``"link"``, ``"error"``, ``"end"``), flushed each second and at
the end.
"""

from __future__ import annotations

import json
import math
import threading
import time
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
from sailroute.live.decode import NmeaDecoder, Reading, SignalKDecoder
from sailroute.live.livewind import DEFAULT_FADE_S, RollingWind, apparent_to_true, wind_changed
from sailroute.live.nmeaout import NmeaServer, route_sentences, steer_sentences
from sailroute.live.planner import PlanCore, Planner, PlanRequest, ThreadPlanner
from sailroute.live.replan import DEFAULT_REACH_M, LivePlan, current_leg
from sailroute.live.sources import Source
from sailroute.live.web import PageServer
from sailroute.routing.settings import RoutingSettings
from sailroute.units import KNOT
from sailroute.wind.base import WindField

TRUE_WIND_HOLD_S: float = 10.0
"""While a true-wind sentence came in the last this many seconds [s], apparent wind is
not converted (the instrument's own true wind is preferred: it has its calibration)."""


@dataclass(frozen=True)
class LiveSettings:
    """How the live loop re-plans.

    Attributes
    ----------
    every_s : float
        Re-plan at least this often [s of data time].
    shift_deg, change_ms : float
        Re-plan at once when the measured wind direction changes by ``shift_deg`` [°] or
        its speed by ``change_ms`` [m s⁻¹] since the last re-plan.
    fade_s : float
        E-folding time of the measured wind's weight ahead [s]
        (:class:`~sailroute.live.livewind.LiveWind`).
    window_s : float
        Averaging window of the measured wind [s].
    stale_s : float
        Data older than this [s of wall time] are stale.
    reach_m : float
        Distance at which a leg's mark, gate or line counts as reached [m].
    side : bool
        Compute the side that pays (two more routed legs per re-plan).
    """

    every_s: float = 10.0
    shift_deg: float = 5.0
    change_ms: float = 0.5144
    fade_s: float = DEFAULT_FADE_S
    window_s: float = 60.0
    stale_s: float = 5.0
    reach_m: float = DEFAULT_REACH_M
    side: bool = True


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

    def write(self, record: Mapping[str, Any]) -> None:
        """Append one record."""
        if self._fh is None:
            return
        text = json.dumps(record, separators=(",", ":"))
        with self._lock:
            self._fh.write(text + "\n")
            self.lines += 1
            now = time.monotonic()
            if now - self._flushed > 1.0:
                self._fh.flush()
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


class LiveEngine:
    """Read a source, re-plan the rest of ``course``, serve the page and the NMEA port.

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
        The instrument feed.
    settings : LiveSettings
        Re-plan rules.
    port, nmea_port : int or None
        Page and NMEA-out TCP ports on 127.0.0.1 (0: a free one; None: none).
    log : Path, optional
        JSON-lines log.
    leg : int
        The leg being sailed at the start (0-based).
    planner : Planner, optional
        Where re-plans are computed; default: in the planner thread
        (:class:`~sailroute.live.planner.ThreadPlanner`).  The engine closes it.
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
    ) -> None:
        self.course, self.forecast, self.boat, self.routing = course, forecast, boat, routing
        self.planner: Planner = planner or ThreadPlanner(PlanCore(course, forecast, boat, routing))
        self.source, self.settings = source, settings
        self._lock = threading.Lock()
        self._planning = threading.Lock()  # one re-plan at a time
        self._wake = threading.Event()
        self.done = threading.Event()
        self._decoder: NmeaDecoder | SignalKDecoder = (
            SignalKDecoder() if source.kind == "signalk" else NmeaDecoder()
        )
        self._wind = RollingWind(settings.window_s)
        self._pos: tuple[float, float, float] | None = None  # t, lat, lon
        self._sog: float | None = None
        self._cog: float | None = None
        self._hdg: float | None = None
        self._true_t = -math.inf
        self._clock: float | None = None
        self._wall = -math.inf
        self._linked = False
        self._link_note = ""
        self.leg = leg
        self.plan: LivePlan | None = None
        self._plan_wind: tuple[float, float] | None = None
        self._plan_t = -math.inf
        self._waypoint = 0
        self.error = ""
        self.n_readings = 0
        self.n_plans = 0
        self.n_links = 0
        self.n_drops = 0
        self.plan_wall: list[float] = []  # wall time each plan was published (benchmark)
        self.log = JsonLog(log)
        try:
            self.page = PageServer(self.state, port) if port is not None else None
        except OSError as exc:
            self.planner.close()
            raise InputError(
                f"--port {port}: cannot serve the page ({exc.strerror}); pick a free port"
            ) from None
        try:
            self.nmea = NmeaServer(nmea_port) if nmea_port is not None else None
        except OSError as exc:
            self._close_servers()
            self.planner.close()
            raise InputError(
                f"--nmea-port {nmea_port}: cannot listen ({exc.strerror}); pick a free port"
            ) from None
        self._threads: list[threading.Thread] = []
        self.source_ended = threading.Event()

    # ------------------------------------------------------------------------- input
    def _link(self, up: bool, note: str) -> None:
        with self._lock:
            if self._linked and not up:
                self.n_drops += 1
            self._linked, self._link_note = up, note
            self.n_links += up
        self.log.write({"kind": "link", "up": up, "note": note, "wall": time.time()})

    def feed(self, text: str) -> None:
        """Decode one message from the source and update the state (source thread)."""
        with self._lock:
            readings = self._decoder.feed(text)
            if readings is None:
                return
            batch = readings if isinstance(readings, list) else [readings]
            used = [r for r in (self._apply(r) for r in batch) if r is not None]
            self._wall = time.monotonic()
            steer = self._steer() if any(r.lat is not None for r in used) else None
        for r in used:
            self.log.write({"kind": "input", **r.as_dict()})
        if steer and self.nmea is not None:
            self.nmea.send(steer)
        if used:
            self._wake.set()

    def _apply(self, r: Reading) -> Reading | None:
        """Merge one reading into the state (lock held); the reading as placed, or None."""
        if r.lat is not None and r.lon is not None:
            if self._clock is not None and r.t + 3600.0 < self._clock:
                return None  # a fix from another clock (the gateway's): not the GPS
            self._clock = max(self._clock or r.t, r.t)
            self._pos = (r.t, r.lat, r.lon)
        if self._clock is None:
            return None
        r = replace(r, t=self._clock)
        self.n_readings += 1
        self._sog = r.sog_ms if r.sog_ms is not None else self._sog
        self._cog = r.cog_deg if r.cog_deg is not None else self._cog
        self._hdg = r.hdg_deg if r.hdg_deg is not None else self._hdg
        if r.tws_ms is not None and r.twd_deg is not None:
            self._true_t = r.t
            self._wind.add(r.t, r.tws_ms, r.twd_deg)
        elif r.tws_ms is not None and r.twa_deg is not None and self._hdg is not None:
            self._true_t = r.t
            self._wind.add(r.t, r.tws_ms, (self._hdg + r.twa_deg) % 360.0)
        elif (
            r.aws_ms is not None
            and r.awa_deg is not None
            and self._sog is not None
            and self._cog is not None
            and r.t - self._true_t > TRUE_WIND_HOLD_S
        ):
            tws, twd = apparent_to_true(r.aws_ms, r.awa_deg, self._sog, self._cog, self._hdg)
            self._wind.add(r.t, tws, twd)
            r = replace(r, tws_ms=tws, twd_deg=twd)
        return r

    def _steer(self) -> list[str] | None:
        """``RMB``/``APB`` to the next waypoint of the plan (lock held)."""
        plan, pos = self.plan, self._pos
        if plan is None or pos is None or not plan.waypoints:
            return None
        wps = plan.waypoints
        frame = self.course.frame
        x, y = frame.to_xy(pos[1], pos[2])
        while self._waypoint < len(wps) - 1:
            wx, wy = frame.to_xy(wps[self._waypoint][1], wps[self._waypoint][2])
            if math.hypot(float(x - wx), float(y - wy)) > self.settings.reach_m:
                break
            self._waypoint += 1
        dest = wps[self._waypoint]
        origin = wps[self._waypoint - 1] if self._waypoint > 0 else ("BOAT", pos[1], pos[2])
        return steer_sentences(pos[1], pos[2], self._sog or 0.0, self._cog or 0.0, origin, dest)

    # ------------------------------------------------------------------------- state
    def stale(self) -> bool:
        """No data for ``stale_s`` of wall time, or the source is disconnected."""
        with self._lock:
            return self._stale()

    def _stale(self) -> bool:
        return (not self._linked and not self.source_ended.is_set()) or (
            time.monotonic() - self._wall > self.settings.stale_s
        )

    def state(self) -> dict[str, Any]:
        """What ``/state.json`` serves."""
        with self._lock:
            pos = self._pos
            wind = self._wind.mean()
            counts = self._decoder.counts
            tg = None
            if self.leg < self.course.n_legs:
                c = feature_centre(self.course.feature(self.course.legs[self.leg].to_name))
                la, lo = self.course.frame.to_latlon(*c)
                tg = [float(la), float(lo)]
            marks = []
            for name, m in self.course.marks.items():
                la, lo = self.course.frame.to_latlon(*m.xy)
                marks.append([name, round(float(la), 7), round(float(lo), 7)])
            return {
                "t": self._clock,
                "source": self.source.label,
                "stale": self._stale(),
                "link": self._link_note,
                "leg": self.leg,
                "n_legs": self.course.n_legs,
                "position": None
                if pos is None
                else {
                    "t": pos[0],
                    "lat": pos[1],
                    "lon": pos[2],
                    "sog_ms": self._sog,
                    "cog_deg": self._cog,
                    "hdg_deg": self._hdg,
                },
                "wind": None if wind is None else {"tws_ms": wind[0], "twd_deg": wind[1]},
                "wind_trend": [
                    [round(a, 1), round(b, 3), round(c, 1)] for a, b, c in self._wind.trend()
                ],
                "plan": None if self.plan is None else self.plan.as_dict(),
                "next_mark": tg,
                "marks": marks,
                "error": self.error,
                "counts": {
                    "used": sum(
                        v
                        for k, v in counts.by_kind.items()
                        if k not in ("bad_checksum", "malformed", "untimed", "ignored", "empty")
                    ),
                    "bad": counts.bad,
                    **dict(counts.by_kind),
                },
            }

    # ------------------------------------------------------------------------- planning
    def _due(self) -> tuple[str, float, float, float, float, float] | None:
        """``(reason, t, lat, lon, tws, twd)`` when a re-plan is due, else None (lock held)."""
        if self._pos is None or self._clock is None or self._stale():
            return None
        wind = self._wind.mean()
        if wind is None or self.leg >= self.course.n_legs:
            return None
        if self.plan is None:
            reason = "first"
        elif wind_changed(self._plan_wind, wind, self.settings.shift_deg, self.settings.change_ms):
            reason = "wind"
        elif self._clock - self._plan_t >= self.settings.every_s:
            reason = "interval"
        else:
            return None
        return reason, self._clock, self._pos[1], self._pos[2], wind[0], wind[1]

    def replan(
        self, reason: str, t: float, lat: float, lon: float, tws: float, twd: float
    ) -> LivePlan | None:
        """Route the rest of the course from ``lat, lon`` at ``t`` in the measured wind."""
        with self._planning:
            return self._replan(reason, t, lat, lon, tws, twd)

    def _replan(
        self, reason: str, t: float, lat: float, lon: float, tws: float, twd: float
    ) -> LivePlan | None:
        frame = self.course.frame
        x, y = (float(v) for v in frame.to_xy(lat, lon))
        with self._lock:
            self.leg = leg = current_leg(self.course, self.leg, (x, y), self.settings.reach_m)
            self._plan_wind, self._plan_t = (tws, twd), t
        if leg >= self.course.n_legs:
            return None
        problem = input_problem(self.course, self.boat, (x, y), tws)
        if problem is not None:  # said on the page and in the log; no re-plan on it
            with self._lock:
                self.error = problem
            self.log.write({"kind": "error", "t": t, "message": problem})
            return None
        req = PlanRequest(self.n_plans + 1, reason, t, x, y, leg, tws, twd, self.settings.fade_s)
        w0 = time.perf_counter()
        try:
            plan = self.planner.route(req)
        except (SailrouteError, BrokenProcessPool) as exc:
            with self._lock:
                self.error = str(exc)
            self.log.write({"kind": "error", "t": t, "message": str(exc)})
            return None
        self._publish(plan)
        if self.settings.side:
            try:
                side = self.planner.side(plan.number)
            except (SailrouteError, BrokenProcessPool) as exc:
                self.log.write({"kind": "error", "t": t, "message": f"side: {exc}"})
            else:
                plan = replace(plan, side=side, compute_s=time.perf_counter() - w0)
                with self._lock:
                    if self.plan is not None and self.plan.number == plan.number:
                        self.plan = plan
        self.log.write({"kind": "plan", **plan.as_dict()})
        return plan

    def _publish(self, plan: LivePlan) -> None:
        with self._lock:
            self.plan, self.error, self._waypoint = plan, "", 0
            self.n_plans = plan.number
            self.plan_wall.append(time.monotonic())
        if self.nmea is not None:
            self.nmea.send(route_sentences(plan.number, plan.waypoints))

    def _plan_loop(self) -> None:
        while not self.done.is_set():
            self._wake.wait(0.25)
            self._wake.clear()
            with self._lock:
                due = self._due()
            if due is not None and not self.done.is_set():
                self.replan(*due)

    def _source_loop(self) -> None:
        try:
            self.source.run(self.feed, self._link, self.done)
        except SailrouteError as exc:
            with self._lock:
                self.error = str(exc)
            self.log.write({"kind": "error", "message": str(exc)})
        finally:
            self.source_ended.set()

    # ------------------------------------------------------------------------- life
    def start(self) -> LiveEngine:
        """Start the source and planner threads; returns self."""
        for name, target in (("live-source", self._source_loop), ("live-plan", self._plan_loop)):
            th = threading.Thread(target=target, name=name, daemon=True)
            th.start()
            self._threads.append(th)
        return self

    def wait(self, duration_s: float | None = None) -> None:
        """Block until ``duration_s`` of wall time passed, or a file source ended and its
        last re-plan is done (None: until :meth:`close` from another thread)."""
        end = math.inf if duration_s is None else time.monotonic() + duration_s
        while not self.done.is_set() and time.monotonic() < end:
            if self.source_ended.wait(min(0.2, max(end - time.monotonic(), 0.0))):
                with self._planning:  # the re-plan under way first, then the last one
                    with self._lock:
                        due = self._due()
                    if due is not None:
                        self._replan(*due)
                return

    def _close_servers(self) -> None:
        if self.page is not None:
            self.page.close()

    def close(self) -> None:
        """End every thread, close the ports, flush and close the log."""
        self.done.set()
        self._wake.set()
        for th in self._threads:
            th.join(timeout=30.0)
        self._close_servers()
        self.planner.close()
        if getattr(self, "nmea", None) is not None:
            assert self.nmea is not None
            self.nmea.close()
        with self._lock:
            counts = dict(self._decoder.counts.by_kind)
        self.log.write(
            {
                "kind": "end",
                "readings": self.n_readings,
                "plans": self.n_plans,
                "drops": self.n_drops,
                "counts": counts,
            }
        )
        self.log.close()
