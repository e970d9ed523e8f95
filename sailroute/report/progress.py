"""A tiny progress reporter for the CLI (stderr, plain text, no dependency).

The library never prints; the CLI creates a :class:`Progress` and passes it (or
its :meth:`Progress.update` method) to the routing loop.  On a terminal, updates
overwrite one line with ``\\r``; otherwise (pipes, CI logs) only the start and end
of each leg are written, one line each.
"""

from __future__ import annotations

import sys
import time
from typing import TextIO


class Progress:
    """Progress of a multi-leg routing run.

    Parameters
    ----------
    n_legs : int
        Number of legs.
    stream : text stream, optional
        Where to write (default ``sys.stderr``).
    enabled : bool
        False makes every method a no-op (``--quiet``).
    min_interval_s : float
        Minimum wall time between two in-place updates [s].
    live : bool, optional
        Overwrite a line with ``\\r`` updates; default: only if ``stream`` is a TTY.
    """

    def __init__(
        self,
        n_legs: int,
        stream: TextIO | None = None,
        *,
        enabled: bool = True,
        min_interval_s: float = 0.2,
        live: bool | None = None,
    ) -> None:
        self.n_legs = n_legs
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.min_interval_s = min_interval_s
        isatty = getattr(self.stream, "isatty", None)
        self.live = bool(isatty and isatty()) if live is None else live
        self._leg = 0
        self._label = ""
        self._t_leg = 0.0
        self._t_last = -1e9
        self._width = 0
        self.prefix = ""

    def set_prefix(self, text: str) -> None:
        """Put ``text`` (e.g. ``"wrf10: "``) before every line, for multi-scenario runs."""
        self.prefix = text

    def _write(self, text: str, *, end: str) -> None:
        text = self.prefix + text
        if self.live and end == "":
            pad = max(self._width - len(text), 0)
            self.stream.write("\r" + text + " " * pad)
            self._width = len(text)
        else:
            if self.live and self._width:
                self.stream.write("\r" + " " * self._width + "\r")
                self._width = 0
            self.stream.write(text + end)
        self.stream.flush()

    def warn(self, text: str) -> None:
        """Print ``warning: <text>`` on its own line, even when disabled (``--quiet``).

        Warnings change what a result means (e.g. wind above the polar's range),
        so quiet mode does not hide them.
        """
        saved, self.prefix = self.prefix, ""
        try:
            self._write(f"warning: {text}", end="\n")
        finally:
            self.prefix = saved

    def note(self, text: str) -> None:
        """Write one line of information (e.g. how the wind data were read)."""
        if not self.enabled:
            return
        self._write(text, end="\n")

    def start_leg(self, index: int, label: str) -> None:
        """Announce leg ``index`` (0-based) with a label like ``"start -> 1"``."""
        if not self.enabled:
            return
        self._leg, self._label = index, label
        self._t_leg = time.perf_counter()
        self._t_last = -1e9
        msg = f"leg {index + 1}/{self.n_legs} {label}: routing..."
        self._write(msg, end="" if self.live else "\n")

    def update(self, fraction: float | None = None, note: str = "") -> None:
        """Progress within the current leg: ``fraction`` in [0, 1] and/or a short note.

        Suitable as a router ``progress`` callback; throttled to ``min_interval_s``.
        """
        if not self.enabled or not self.live:
            return
        now = time.perf_counter()
        if now - self._t_last < self.min_interval_s:
            return
        self._t_last = now
        parts = [f"leg {self._leg + 1}/{self.n_legs} {self._label}:"]
        if fraction is not None:
            parts.append(f"{100.0 * min(max(fraction, 0.0), 1.0):3.0f}%")
        if note:
            parts.append(note)
        parts.append(f"({now - self._t_leg:.1f} s)")
        self._write(" ".join(parts), end="")

    __call__ = update

    def end_leg(self, leg_time_s: float, summary: str = "") -> None:
        """Report the finished leg: its sailed time [s] and an optional summary."""
        if not self.enabled:
            return
        wall = time.perf_counter() - self._t_leg
        extra = f", {summary}" if summary else ""
        self._write(
            f"leg {self._leg + 1}/{self.n_legs} {self._label}: {leg_time_s:.1f} s{extra} "
            f"(computed in {wall:.1f} s)",
            end="\n",
        )
