"""Instrument feeds for the live tests: synthetic NMEA 0183 seconds and a TCP feed server."""

from __future__ import annotations

import math
import socket
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.polar import Polar
from sailroute.course.load import load_course
from sailroute.course.model import Course
from sailroute.live.convert import Row, nmea_lines
from sailroute.nmea import checksum
from sailroute.routing.settings import routing_settings
from sailroute.wind.base import WindField
from tests import fleetgen
from tests.conftest import COURSES

TRIESTE = COURSES / "trieste-coach-wl.yaml"


def trieste(coarse: bool = True) -> Course:
    """The Trieste windward-leeward course (start 2018-02-15 09:45 UTC).

    ``coarse``: routed with 10-s steps and 4° headings (about four times faster than the
    file's 5 s and 2°), so that the tests' re-plans keep up with a fast replay on a busy
    machine.
    """
    course = load_course(TRIESTE)
    if not coarse:
        return course
    return replace(
        course, routing=routing_settings(course.routing, dt_s=10.0, heading_step_deg=4.0)
    )


def approach(
    course: Course,
    seconds: int,
    *,
    speed_ms: float = 2.0,
    twd: Callable[[float], float] = lambda s: 65.0,
    tws_kn: float = 5.0,
    start_back_m: float = 150.0,
    t0: float | None = None,
    to: str = "1",
) -> list[Row]:
    """A boat motoring straight at mark ``to`` from ``start_back_m`` behind the start line.

    ``twd(s)`` is the true wind direction ``s`` seconds in; one row per second.
    """
    mx, my = course.marks[to].xy
    line = course.lines["start"]
    sx, sy = line.midpoint
    d = math.hypot(mx - sx, my - sy)
    ux, uy = (mx - sx) / d, (my - sy) / d
    x0, y0 = sx - ux * start_back_m, sy - uy * start_back_m
    cog = math.degrees(math.atan2(ux, uy)) % 360.0
    t0 = course.start_epoch if t0 is None else t0
    rows = []
    for s in range(seconds):
        go = min(speed_ms * s, math.hypot(mx - x0, my - y0))
        lat, lon = course.frame.to_latlon(x0 + ux * go, y0 + uy * go)
        rows.append(
            Row(
                t0 + s,
                float(lat),
                float(lon),
                speed_ms / 0.514444,
                cog,
                cog,
                speed_ms / 0.514444,
                None,
                None,
                tws_kn,
                twd(s) % 360.0,
            )
        )
    return rows


def _field(value: int, n: int) -> str:
    return format(value & ((1 << n) - 1), f"0{n}b")


def ais_sentence(
    mmsi: int,
    lat: float,
    lon: float,
    sog_kn: float | None = None,
    cog_deg: float | None = None,
    hdg_deg: float | None = None,
    second: int | None = None,
) -> str:
    """An AIS class B position report (message 18) as ``!AIVDM``, encoded by ITU-R M.1371
    (the inverse of :func:`sailroute.live.ais.parse_ais`, written separately for tests)."""
    bits = "".join(
        [
            _field(18, 6),
            _field(0, 2),
            _field(mmsi, 30),
            _field(0, 8),
            _field(1023 if sog_kn is None else round(sog_kn * 10), 10),
            "1",
            _field(round(lon * 600_000), 28),
            _field(round(lat * 600_000), 27),
            _field(3600 if cog_deg is None else round(cog_deg * 10) % 3600, 12),
            _field(511 if hdg_deg is None else round(hdg_deg) % 360, 9),
            _field(60 if second is None else second, 6),
            "0" * 29,
        ]
    )
    payload = "".join(
        chr(v + 48 if v < 40 else v + 56)
        for v in (int(bits[i : i + 6], 2) for i in range(0, 168, 6))
    )
    body = f"AIVDM,1,1,,B,{payload},0"
    return f"!{body}*{checksum(body)}"


@dataclass(frozen=True)
class _OneSkill:
    """A wind as :func:`tests.fleetgen.route_plans` takes it: every boat of skill 1."""

    wind: WindField

    def dilated(self, gun: float, skill: float) -> WindField:
        return self.wind


def sailed_track(
    course: Course,
    wind: WindField,
    polar: Polar,
    *,
    step_s: float = 1.0,
    lead_s: float = 90.0,
    tail_s: float = 60.0,
) -> tuple[NDArray, NDArray, NDArray]:
    """A boat sailing ``course`` in ``wind`` as the fleet generator sails its boats
    (:func:`tests.fleetgen.route_plans`: routed leg by leg, 6 m off the marks, with drawn
    roundings), starting 40 % along the start line 5.4 s after the gun (so that no fix
    lies on the line), with ``lead_s`` of approach from below the line and ``tail_s`` on
    past the finish, sampled every ``step_s``.

    Returns
    -------
    t, x, y : ndarray
        Times [epoch s] and positions [m, course frame].
    """
    line = course.lines["start"]
    (ax, ay), (bx, by) = line.a.xy, line.b.xy
    sx, sy = ax + 0.4 * (bx - ax), ay + 0.4 * (by - ay)
    gun = course.start_epoch
    plan = fleetgen._Plan("sailor", gun, gun + 5.4, (sx, sy), 1.0, 0, None)
    routed = fleetgen.route_plans(course, [plan], polar, _OneSkill(wind))["sailor"]  # type: ignore[arg-type]
    t, x, y = (np.array(v) for v in zip(*routed.knots(), strict=True))
    nx, ny = by - ay, -(bx - ax)
    n = math.hypot(nx, ny)
    nx, ny = nx / n, ny / n
    mx, my = course.marks["1"].xy
    if (mx - sx) * nx + (my - sy) * ny < 0:  # the normal towards the course side
        nx, ny = -nx, -ny
    v = fleetgen.LOITER_MS
    hx, hy = x[-1] - x[-2], y[-1] - y[-2]
    h = math.hypot(hx, hy)
    t = np.concatenate([[t[0] - lead_s], t, [t[-1] + tail_s]])
    x = np.concatenate([[x[0] - nx * v * lead_s], x, [x[-1] + hx / h * v * tail_s]])
    y = np.concatenate([[y[0] - ny * v * lead_s], y, [y[-1] + hy / h * v * tail_s]])
    ts = np.arange(math.ceil(t[0]), t[-1], step_s)
    return ts, np.interp(ts, t, x), np.interp(ts, t, y)


def lines_of(rows: Sequence[Row]) -> list[str]:
    """The NMEA sentences of ``rows``, in order."""
    return [line for r in rows for line in nmea_lines(r)]


def write_feed(path: Path, rows: Sequence[Row]) -> Path:
    """Write ``rows`` as a ``.nmea`` file."""
    path.write_text("".join(line + "\r\n" for line in lines_of(rows)), encoding="ascii")
    return path


class FeedServer:
    """A TCP server that sends NMEA lines to each client, paced at ``rate`` seconds per
    second of feed (one ``RMC`` per second of feed).

    Parameters
    ----------
    lines : sequence of str
        The feed.
    rate : float
        Feed seconds per wall second.
    drop_after : int, optional
        Close the first connection after this many ``RMC`` sentences (a dropped link);
        the next connection goes on from there after ``down_s`` of refusing clients.
    down_s : float
        How long the server accepts no connection after the drop [s].
    """

    def __init__(
        self,
        lines: Sequence[str],
        rate: float = 20.0,
        drop_after: int | None = None,
        down_s: float = 1.0,
    ) -> None:
        self.lines = list(lines)
        self.rate = rate
        self.drop_after = drop_after
        self.down_s = down_s
        self._sock = socket.create_server(("127.0.0.1", 0))
        self._sock.settimeout(0.2)
        self.port: int = self._sock.getsockname()[1]
        self.connections = 0
        self.sent = 0
        self.finished = threading.Event()
        self._quit = threading.Event()
        self._pos = 0
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        while not self._quit.is_set() and self._pos < len(self.lines):
            try:
                conn, _ = self._sock.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            self.connections += 1
            dropped = self._send(conn)
            conn.close()
            if dropped:  # refuse clients for a while: the link is down
                self._sock.close()
                time.sleep(self.down_s)
                self._sock = socket.create_server(("127.0.0.1", self.port))
                self._sock.settimeout(0.2)
        self.finished.set()

    def _send(self, conn: socket.socket) -> bool:
        n_rmc = 0
        while self._pos < len(self.lines) and not self._quit.is_set():
            line = self.lines[self._pos]
            if line[3:6] == "RMC":
                n_rmc += 1
                if (
                    self.drop_after is not None
                    and self.connections == 1
                    and n_rmc > self.drop_after
                ):
                    return True
                time.sleep(1.0 / self.rate)
            try:
                conn.sendall((line + "\r\n").encode("ascii"))
            except OSError:
                return False
            self._pos += 1
            self.sent += 1
        return False

    def close(self) -> None:
        """End the server."""
        self._quit.set()
        self._thread.join(timeout=5.0)
        self._sock.close()
