"""Where the instrument data come from: a Signal K server, an NMEA 0183 TCP or UDP feed,
or a recorded NMEA file.

Each source runs in its own thread (:meth:`Source.run`) and hands every line or
message to the caller's ``emit`` as it arrives; nothing it calls may block for long.
A network source that loses its connection tells ``link(False)`` (the data go stale),
waits and connects again with a growing back-off (0.5 s doubling to 8 s, reset by a
good connection), until ``done`` is set.  A file source replays its lines at the pace
of their ``RMC``/``GGA`` times divided by ``speed``, and returns at the end; a jump of
the file's clock by more than :data:`JUMP_S` either way (a GPS that dated one fix in
another year) is not waited out.

A line longer than :data:`MAX_LINE` (an NMEA 0183 sentence is at most 82 characters) is
dropped up to its end without being held in memory, and :data:`TOO_LONG` is emitted in
its place (the engine counts it); a Signal K message over :data:`MAX_MESSAGE` bytes
closes the connection, which is then opened again.
"""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, Protocol
from urllib.parse import urlsplit

from sailroute.errors import InputError
from sailroute.live.decode import NmeaDecoder

Emit = Callable[[str], None]
Link = Callable[[bool, str], None]

BACKOFF_S: tuple[float, float] = (0.5, 8.0)
"""First and longest wait before connecting again [s]."""
MAX_LINE: int = 4096
"""Longest line read from an NMEA 0183 source [bytes]."""
MAX_MESSAGE: int = 1 << 20
"""Longest Signal K message read [bytes]."""
TOO_LONG: str = "\x00too long"
"""What a source emits in place of a line longer than :data:`MAX_LINE` (compared by
identity: ``text is TOO_LONG``)."""
JUMP_S: float = 120.0
"""A replay does not wait out a jump of its clock by more than this [s]."""


class Source(Protocol):
    """An instrument feed (see the module docstring)."""

    @property
    def kind(self) -> Literal["nmea", "signalk"]:
        """What ``emit`` receives: NMEA 0183 lines or Signal K delta messages (JSON)."""
        ...

    @property
    def label(self) -> str:
        """The source as the user gave it."""
        ...

    def run(self, emit: Emit, link: Link, done: threading.Event) -> None:
        """Read until ``done`` is set (or a file ends), calling ``emit`` per message."""
        ...


class LineSplitter:
    """Split a byte stream into lines for ``emit``, never holding more than
    :data:`MAX_LINE` bytes of one line (the rest of a longer one is skipped, and
    :data:`TOO_LONG` emitted once for it)."""

    def __init__(self, emit: Emit) -> None:
        self._emit = emit
        self._buf = b""
        self._skipping = False

    def feed(self, chunk: bytes) -> None:
        """Take the next bytes."""
        *lines, rest = chunk.split(b"\n")
        for raw in lines:
            if self._skipping:
                self._skipping = False
            elif len(self._buf) + len(raw) > MAX_LINE:
                self._emit(TOO_LONG)
            else:
                self._emit((self._buf + raw).decode("ascii", "replace"))
            self._buf = b""
        if self._skipping:
            return
        self._buf += rest
        if len(self._buf) > MAX_LINE:
            self._buf, self._skipping = b"", True
            self._emit(TOO_LONG)


def _backoff(wait: float, done: threading.Event) -> float:
    """Wait ``wait`` seconds (unless ``done``), return the next wait."""
    done.wait(wait)
    return min(wait * 2.0, BACKOFF_S[1])


def _netloc(host: str, port: int) -> str:
    """``host:port``, an IPv6 address in brackets."""
    return f"[{host}]:{port}" if ":" in host else f"{host}:{port}"


@dataclass(frozen=True)
class NmeaTcpSource:
    """An NMEA 0183 feed from a TCP server (a multiplexer, an instrument gateway)."""

    host: str
    port: int
    kind: Literal["nmea", "signalk"] = "nmea"

    @property
    def label(self) -> str:
        """``nmea+tcp://host:port``."""
        return f"nmea+tcp://{_netloc(self.host, self.port)}"

    def run(self, emit: Emit, link: Link, done: threading.Event) -> None:
        """Connect, read lines, reconnect with back-off until ``done``."""
        wait = BACKOFF_S[0]
        while not done.is_set():
            try:
                with socket.create_connection((self.host, self.port), timeout=2.0) as sock:
                    sock.settimeout(0.5)
                    link(True, f"connected to {self.label}")
                    wait = BACKOFF_S[0]
                    lines = LineSplitter(emit)
                    while not done.is_set():
                        try:
                            chunk = sock.recv(65536)
                        except TimeoutError:
                            continue
                        if not chunk:
                            break
                        lines.feed(chunk)
                link(False, f"{self.label} closed the connection")
            except OSError as exc:
                link(False, f"{self.label}: {exc.strerror or exc}")
            if not done.is_set():
                wait = _backoff(wait, done)


@dataclass(frozen=True)
class NmeaUdpSource:
    """NMEA 0183 datagrams broadcast on a UDP port (one or more sentences each)."""

    host: str
    port: int
    kind: Literal["nmea", "signalk"] = "nmea"

    @property
    def label(self) -> str:
        """``nmea+udp://host:port``."""
        return f"nmea+udp://{_netloc(self.host, self.port)}"

    def run(self, emit: Emit, link: Link, done: threading.Event) -> None:
        """Listen until ``done``."""
        family = socket.AF_INET6 if ":" in self.host else socket.AF_INET
        with socket.socket(family, socket.SOCK_DGRAM) as sock:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                sock.bind((self.host or "0.0.0.0", self.port))
            except OSError as exc:
                raise InputError(
                    f"--source {self.label}: cannot listen on UDP port {self.port} "
                    f"({exc.strerror or exc}); pick a free port"
                ) from None
            sock.settimeout(0.5)
            link(True, f"listening on {self.label}")
            while not done.is_set():
                try:
                    data = sock.recv(65536)
                except TimeoutError:
                    continue
                for raw in data.split(b"\n"):
                    emit(raw.decode("ascii", "replace") if len(raw) <= MAX_LINE else TOO_LONG)


@dataclass(frozen=True)
class NmeaFileSource:
    """A recorded NMEA 0183 file, replayed at ``speed`` times real time."""

    path: Path
    speed: float = 1.0
    kind: Literal["nmea", "signalk"] = "nmea"

    @property
    def label(self) -> str:
        """The file's path."""
        return str(self.path)

    def run(self, emit: Emit, link: Link, done: threading.Event) -> None:
        """Replay the file, pacing by its sentence times; return at its end."""
        clock = NmeaDecoder(require_checksum=False)  # pacing only
        t0: float | None = None
        last: float | None = None
        w0 = time.monotonic()
        link(True, f"replaying {self.path} at {self.speed:g}x")
        with open(self.path, encoding="ascii", errors="replace", newline="") as fh:
            while not done.is_set():
                line = fh.readline(MAX_LINE + 1)
                if not line:
                    return
                if len(line) > MAX_LINE:
                    while line and not line.endswith("\n"):  # skip the rest of it
                        line = fh.readline(MAX_LINE + 1)
                    emit(TOO_LONG)
                    continue
                head = line[3:6]
                if head in ("RMC", "GGA", "GLL", "ZDA"):
                    clock.feed(line)
                    t = clock.clock
                    if t is not None:
                        if t0 is None:
                            t0, w0 = t, time.monotonic()
                        elif last is not None and abs(t - last) > JUMP_S:
                            t0 += t - last  # a jump of the file's clock: not waited out
                        last = t
                        due = w0 + (t - t0) / self.speed - time.monotonic()
                        if due > 0 and done.wait(due):
                            return
                emit(line.rstrip("\r\n"))


@dataclass(frozen=True)
class SignalKSource:
    """A Signal K server's WebSocket delta stream (``/signalk/v1/stream?subscribe=all``)."""

    url: str
    kind: Literal["nmea", "signalk"] = "signalk"

    @property
    def label(self) -> str:
        """The WebSocket URL."""
        return self.url

    def run(self, emit: Emit, link: Link, done: threading.Event) -> None:
        """Connect, read deltas, reconnect with back-off until ``done``."""
        from websockets.exceptions import WebSocketException
        from websockets.sync.client import connect

        wait = BACKOFF_S[0]
        while not done.is_set():
            try:
                with connect(
                    self.url, open_timeout=3.0, close_timeout=1.0, max_size=MAX_MESSAGE
                ) as ws:
                    link(True, f"connected to {self.url}")
                    wait = BACKOFF_S[0]
                    while not done.is_set():
                        try:
                            msg = ws.recv(timeout=0.5)
                        except TimeoutError:
                            continue
                        emit(msg if isinstance(msg, str) else msg.decode("utf-8", "replace"))
            except (OSError, WebSocketException) as exc:
                link(False, f"{self.url}: {exc}")
            if not done.is_set():
                wait = _backoff(wait, done)


def parse_source(text: str, speed: float = 1.0) -> Source:
    """The :class:`Source` a ``--source`` value names.

    Parameters
    ----------
    text : str
        ``signalk://host:port`` (or ``ws://``/``wss://`` with a path), ``nmea+tcp://host:port``,
        ``nmea+udp://:port`` (or ``nmea+udp://host:port`` to listen on one address), or
        the path of a recorded NMEA 0183 file.
    speed : float
        Replay speed of a file (ignored for network sources).

    Raises
    ------
    InputError
        An unknown scheme, a missing port, a file that does not exist.
    """
    how = (
        "give signalk://HOST:PORT, nmea+tcp://HOST:PORT, nmea+udp://:PORT or the path "
        "of a recorded .nmea file"
    )
    if "://" not in text:
        path = Path(text)
        if not path.is_file():
            raise InputError(f"--source {text}: no such file; {how}")
        if not speed > 0:
            raise InputError(
                f"--speed {speed:g}: must be > 0 (1 = real time, 10 = ten times faster)"
            )
        return NmeaFileSource(path, speed)
    parts = urlsplit(text)
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme in ("ws", "wss"):
        return SignalKSource(text)
    if port is None:
        raise InputError(f"--source {text}: no port number; {how}")
    host = parts.hostname or ""
    if parts.scheme == "signalk":
        query = "?subscribe=all"
        where = _netloc(host or "127.0.0.1", port)
        return SignalKSource(f"ws://{where}/signalk/v1/stream{query}")
    if parts.scheme == "nmea+tcp":
        return NmeaTcpSource(host or "127.0.0.1", port)
    if parts.scheme == "nmea+udp":
        return NmeaUdpSource(host, port)
    raise InputError(f"--source {text}: unknown scheme {parts.scheme!r}; {how}")
