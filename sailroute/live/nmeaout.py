"""NMEA 0183 out to a chart plotter: the route as ``WPL``/``RTE``, steering as ``RMB``/``APB``.

After each re-plan :func:`route_sentences` gives one ``WPL`` per turning point ahead
(tacks, gybes, marks) and the ``RTE`` sentences listing them, always under the route id
:data:`ROUTE_ID`: a plotter updates that one route in place, and its route list does not
fill up with one route per re-plan.  Waypoint identifiers are ASCII letters, digits and
``-`` (a mark named ``Bóia`` is ``BIA``), so any mark name goes out.  Every position
update of the sailor's boat :func:`steer_sentences` gives ``RMB`` and ``APB`` to the
next turning point.  :class:`NmeaServer` sends them to every TCP client connected to
its port; it only sends, and reads nothing from its clients.
"""

from __future__ import annotations

import errno
import math
import socket
import threading
from collections.abc import Sequence

from sailroute.nmea import frame, lat_field, lon_field, rte_bodies
from sailroute.units import wrap180

NM: float = 1852.0
"""One nautical mile [m]."""
_TALKER = "SR"  # a "proprietary-looking" talker would confuse plotters; SR = sailroute
ROUTE_ID: str = "sailroute"
"""The route id of every ``RTE`` sent: one route, updated in place."""
PORT_TRIES: int = 20
"""A busy NMEA port is replaced by the next free one of this many (:func:`open_nmea_server`)."""


def sentence(body: str) -> str:
    """``$<body>*<checksum>`` with CR LF (:func:`sailroute.nmea.frame`)."""
    return frame(body) + "\r\n"


def _name(name: str) -> str:
    """A waypoint id a plotter accepts: ASCII letters, digits, ``-``, at most 8 characters."""
    out = "".join(c for c in name.upper() if (c.isascii() and c.isalnum()) or c == "-")
    return out[:8] or "WPT"


def route_sentences(waypoints: Sequence[tuple[str, float, float]]) -> list[str]:
    """``WPL`` per waypoint and the ``RTE`` sentences of the route :data:`ROUTE_ID`.

    Parameters
    ----------
    waypoints : sequence of (str, float, float)
        ``(name, lat [°], lon [°])`` in sailing order.
    """
    out = []
    ids = [_name(n) for n, _, _ in waypoints]
    for wid, (_, la, lo) in zip(ids, waypoints, strict=True):
        out.append(
            sentence(f"{_TALKER}WPL,{','.join(lat_field(la))},{','.join(lon_field(lo))},{wid}")
        )
    out += [sentence(body) for body in rte_bodies(_TALKER, ROUTE_ID, ids)]
    return out


def _bearing_range(lat: float, lon: float, lat2: float, lon2: float) -> tuple[float, float]:
    """Great-circle initial bearing [°] and distance [m] (spherical; good at course scale)."""
    p1, p2 = math.radians(lat), math.radians(lat2)
    dl = math.radians(lon2 - lon)
    y = math.sin(dl) * math.cos(p2)
    x = math.cos(p1) * math.sin(p2) - math.sin(p1) * math.cos(p2) * math.cos(dl)
    h = math.sin((p2 - p1) / 2) ** 2 + math.cos(p1) * math.cos(p2) * math.sin(dl / 2) ** 2
    return math.degrees(math.atan2(y, x)) % 360.0, 2 * 6371008.8 * math.asin(math.sqrt(h))


def steer_sentences(
    lat: float,
    lon: float,
    sog_ms: float,
    cog_deg: float,
    origin: tuple[str, float, float],
    dest: tuple[str, float, float],
    arrived: bool = False,
) -> list[str]:
    """``RMB`` and ``APB`` from the boat to the next waypoint ``dest``.

    Parameters
    ----------
    lat, lon : float
        The boat [°].
    sog_ms, cog_deg : float
        Its speed [m s⁻¹] and course [°] over the ground (for the closing speed).
    origin, dest : (str, float, float)
        ``(name, lat, lon)`` of the previous and the next waypoint.
    arrived : bool
        Within the arrival circle.
    """
    brg, rng = _bearing_range(lat, lon, dest[1], dest[2])
    brg_od, _ = _bearing_range(origin[1], origin[2], dest[1], dest[2])
    b_ob, r_ob = _bearing_range(origin[1], origin[2], lat, lon)
    xte = r_ob * math.sin(math.radians(b_ob - brg_od)) / NM  # + right of the track
    steer = "L" if xte > 0 else "R"
    vmc = sog_ms * math.cos(math.radians(float(wrap180(cog_deg - brg)))) * 3600.0 / NM
    a = "A" if arrived else "V"
    o, d = _name(origin[0]), _name(dest[0])
    la, lo = lat_field(dest[1]), lon_field(dest[2])
    rmb = (
        f"{_TALKER}RMB,A,{min(abs(xte), 9.99):.2f},{steer},{o},{d},{la[0]},{la[1]},"
        f"{lo[0]},{lo[1]},{min(rng / NM, 999.9):.3f},{brg:.1f},{vmc:.1f},{a},A"
    )
    apb = (
        f"{_TALKER}APB,A,A,{min(abs(xte), 9.99):.2f},{steer},N,{a},V,{brg_od:.1f},T,{d},"
        f"{brg:.1f},T,{brg:.1f},T,A"
    )
    return [sentence(rmb), sentence(apb)]


def open_nmea_server(port: int, host: str = "127.0.0.1") -> tuple[NmeaServer, str]:
    """An :class:`NmeaServer` on ``port``, or, when that port is busy, on the next free one
    of :data:`PORT_TRIES` (a Signal K server on the same laptop serves NMEA on 10110).

    Returns
    -------
    server : NmeaServer
    note : str
        Empty, or what was busy and which port was taken instead.

    Raises
    ------
    OSError
        No free port among them (or another error than a busy port).
    """
    err: OSError | None = None
    for p in range(port, min(port + PORT_TRIES, 65536)) if port else [0]:
        try:
            server = NmeaServer(p, host)
        except OSError as exc:
            if exc.errno not in (errno.EADDRINUSE, errno.EACCES):
                raise
            err = exc
            continue
        note = "" if p == port else f"NMEA port {port} is busy: using {server.port}"
        return server, note
    assert err is not None
    raise err


class NmeaServer:
    """Send NMEA sentences to every client of a TCP port on 127.0.0.1 (or ``host``).

    Parameters
    ----------
    port : int
        TCP port; 0 picks a free one (:attr:`port` tells which).
    host : str
        Address to listen on.
    """

    def __init__(self, port: int, host: str = "127.0.0.1") -> None:
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        self._sock = socket.create_server((host, port), family=family, reuse_port=False)
        self._sock.settimeout(0.5)
        self.port: int = self._sock.getsockname()[1]
        self._clients: list[socket.socket] = []
        self._lock = threading.Lock()
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._accept, name="nmea-out", daemon=True)
        self._thread.start()

    def _accept(self) -> None:
        while not self._done.is_set():
            try:
                conn, _ = self._sock.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            conn.settimeout(1.0)
            with self._lock:
                self._clients.append(conn)

    @property
    def n_clients(self) -> int:
        """Clients connected now."""
        with self._lock:
            return len(self._clients)

    def send(self, sentences: Sequence[str]) -> None:
        """Send to every client; a client that does not take them is dropped."""
        data = "".join(sentences).encode("ascii", "replace")
        with self._lock:
            keep = []
            for c in self._clients:
                try:
                    c.sendall(data)
                    keep.append(c)
                except OSError:
                    c.close()
            self._clients = keep

    def close(self) -> None:
        """Close the port and every client."""
        self._done.set()
        self._sock.close()
        self._thread.join(timeout=2.0)
        with self._lock:
            for c in self._clients:
                c.close()
            self._clients = []
