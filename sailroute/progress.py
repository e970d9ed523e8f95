"""Progress reporters for the CLI (stderr).

The library never prints; the CLI creates one with :func:`make_progress` and passes
it (or its :meth:`Progress.update` method) to the routing loop.  On a terminal it is
a :class:`RichProgress`: a rich progress bar for the leg being routed, and one line
per finished leg above it.  Otherwise (pipes, CI logs, tests) it is a plain
:class:`Progress`: only the start and end of each leg, one line each.  Both print
the same lines for finished legs, notes and warnings, and are context managers
(leaving the block removes the bar and restores the cursor).

A run over many things (the members of an ensemble, the scenarios of a comparison,
the boats of a fleet) counts them: :meth:`Progress.start_count`, then
:meth:`Progress.start_item` before each and :meth:`Progress.item_done` after each
(``boat 12 of 57 done (GBR 1234): 1 min 3 s elapsed, about 4 min left``); members
routed together (:mod:`sailroute.routing.batch`) are counted with ``together=True``
and the legs' notes say how many have arrived.  The time left is the elapsed time
scaled by the share of the run still to do.
"""

from __future__ import annotations

import sys
import time
from types import TracebackType
from typing import Any, TextIO


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
        self._count: tuple[int, str, bool] | None = None  # (total, noun, together)
        self._item = 0  # things done before the one under way
        self._t_run = time.perf_counter()

    def __enter__(self) -> Progress:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    def close(self) -> None:
        """End the display (nothing to do for plain text)."""

    def set_prefix(self, text: str) -> None:
        """Put ``text`` (e.g. ``"wrf10: "``) before every line, for multi-scenario runs."""
        self.prefix = text

    # --- counting the things of a run ----------------------------------------------

    def start_count(self, total: int, noun: str, *, together: bool = False) -> None:
        """Count ``total`` things (``noun``: ``"member"``, ``"scenario"``, ``"boat"``)
        from now: the run's clock starts, and the lines and the bar show the elapsed
        time and the time left.  ``together``: they are routed together, one leg at a
        time (the batched ensemble), so the legs, not the things, measure the run."""
        self._count = (max(int(total), 1), noun, together)
        self._item = 0
        self._t_run = time.perf_counter()

    def start_item(self, index: int, name: str = "") -> None:
        """Thing ``index`` (0-based) of the count begins: its lines start with its name
        and ``"<noun> k of N"`` (e.g. ``"m37 (member 38 of 100): "``)."""
        self._item = index
        if self._count is None:
            return
        total, noun, _ = self._count
        what = f"{noun} {index + 1} of {total}"
        self.prefix = f"{name} ({what}): " if name else f"{what}: "

    def item_done(self, done: int, name: str = "") -> None:
        """``done`` of the counted things are finished (``name``: the last one): one line
        ``"<noun> k of N done (name): 12 s elapsed, about 40 s left"``.  Generic: a loop
        over things calls it after each (after :meth:`start_count`)."""
        if self._count is None:
            self.start_count(done, "item")
        assert self._count is not None
        total, noun, _ = self._count
        self._item = done
        if not self.enabled:
            return
        saved, self.prefix = self.prefix, ""
        label = f" ({name})" if name else ""
        try:
            self._write(f"{noun} {done} of {total} done{label}: {self.clock()}", end="\n")
        finally:
            self.prefix = saved

    def fraction(self, leg_fraction: float = 0.0) -> float:
        """The share of the run done [0-1]: the things done, then the legs done of the
        one under way and ``leg_fraction`` of its current leg."""
        legs = (self._leg + min(max(leg_fraction, 0.0), 1.0)) / max(self.n_legs, 1)
        if self._count is None:
            return legs
        total, _, together = self._count
        return legs if together else (self._item + legs) / total

    def clock(self, fraction: float | None = None) -> str:
        """``"12 s elapsed, about 40 s left"``: the run's time so far and the time left
        at this pace, given the share done (default: the things done of the count)."""
        elapsed = time.perf_counter() - self._t_run
        if fraction is None:
            fraction = self._item / self._count[0] if self._count is not None else 0.0
        out = f"{duration(elapsed)} elapsed"
        if 0.0 < fraction < 1.0:
            out += f", about {duration(elapsed * (1.0 - fraction) / fraction)} left"
        return out

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
        if self._count is not None:
            parts.append(f"- {self.clock(self.fraction(fraction or 0.0))}")
        self._write(" ".join(parts), end="")

    __call__ = update

    def end_leg(self, leg_time_s: float, summary: str = "") -> None:
        """Report the finished leg: its sailed time [s] and an optional summary."""
        if not self.enabled:
            return
        wall = time.perf_counter() - self._t_leg
        extra = f", {summary}" if summary else ""
        run = "" if self._count is None else f"; {self.clock(self.fraction(1.0))}"
        self._write(
            f"leg {self._leg + 1}/{self.n_legs} {self._label}: {leg_time_s:.1f} s{extra} "
            f"(computed in {wall:.1f} s{run})",
            end="\n",
        )


class RichProgress(Progress):
    """Progress on a terminal: a rich bar for the current leg (fraction, note, elapsed
    time) and the plain :class:`Progress` lines for finished legs, notes and warnings.

    Parameters
    ----------
    n_legs : int
        Number of legs.
    stream : text stream, optional
        Where to draw (default ``sys.stderr``).
    enabled : bool
        False: no bar and no lines, warnings only (``--quiet``).
    min_interval_s : float
        Minimum wall time between two redraws [s].
    force_terminal : bool, optional
        Draw as on a terminal even if ``stream`` is not one (tests).
    """

    def __init__(
        self,
        n_legs: int,
        stream: TextIO | None = None,
        *,
        enabled: bool = True,
        min_interval_s: float = 0.1,
        force_terminal: bool | None = None,
    ) -> None:
        super().__init__(n_legs, stream, enabled=enabled, min_interval_s=min_interval_s, live=True)
        from rich.console import Console
        from rich.progress import BarColumn, TaskProgressColumn, TextColumn, TimeElapsedColumn
        from rich.progress import Progress as Bar

        self.console = Console(file=self.stream, force_terminal=force_terminal, highlight=False)
        self._bar = Bar(
            TextColumn("{task.description}"),
            BarColumn(),
            TaskProgressColumn(),
            TimeElapsedColumn(),
            TextColumn("{task.fields[note]}"),
            console=self.console,
            transient=True,
            auto_refresh=False,
        )
        self._task: Any = None
        self._running = False

    def _write(self, text: str, *, end: str) -> None:
        style = "yellow" if text.startswith("warning: ") else None
        self.console.print(
            self.prefix + text, end=end, style=style, markup=False, highlight=False, soft_wrap=True
        )

    def start_leg(self, index: int, label: str) -> None:
        """Start the bar of leg ``index`` (0-based)."""
        if not self.enabled:
            return
        self._leg, self._label = index, label
        self._t_leg = time.perf_counter()
        self._t_last = -1e9
        desc = f"{self.prefix}leg {index + 1}/{self.n_legs} {label}"
        if self._task is None:
            self._task = self._bar.add_task(desc, total=1.0, note="")
        else:
            self._bar.reset(self._task, total=1.0, description=desc, note="")
        if not self._running:
            self._bar.start()
            self._running = True
        self._bar.refresh()

    def update(self, fraction: float | None = None, note: str = "") -> None:
        """Move the bar to ``fraction`` in [0, 1] (None: keep) and show ``note``."""
        if not self.enabled or self._task is None:
            return
        now = time.perf_counter()
        if now - self._t_last < self.min_interval_s:
            return
        self._t_last = now
        if self._count is not None:
            clock = self.clock(self.fraction(fraction or 0.0))
            note = f"{note} - {clock}" if note else clock
        kw: dict[str, Any] = {"note": note}
        if fraction is not None:
            kw["completed"] = min(max(float(fraction), 0.0), 1.0)
        self._bar.update(self._task, **kw)
        self._bar.refresh()

    __call__ = update

    def end_leg(self, leg_time_s: float, summary: str = "") -> None:
        """Print the finished leg's line above the bar."""
        if not self.enabled:
            return
        if self._task is not None:
            self._bar.update(self._task, completed=1.0, note="")
        super().end_leg(leg_time_s, summary)

    def close(self) -> None:
        """Remove the bar and show the cursor again."""
        if self._running:
            self._bar.stop()
            self._running = False


def duration(seconds: float) -> str:
    """A duration for people: ``"8.2 s"``, ``"42 s"``, ``"3 min 5 s"``, ``"1 h 02 min"``."""
    if seconds < 10.0:
        return f"{seconds:.1f} s"
    s = round(seconds)
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"


def make_progress(n_legs: int, *, enabled: bool = True, stream: TextIO | None = None) -> Progress:
    """A :class:`RichProgress` if ``stream`` (default stderr) is a terminal, else a
    plain :class:`Progress`; ``enabled=False`` (``--quiet``) prints warnings only."""
    s = stream if stream is not None else sys.stderr
    isatty = getattr(s, "isatty", None)
    if enabled and isatty is not None and isatty():
        return RichProgress(n_legs, s, enabled=enabled)
    return Progress(n_legs, s, enabled=enabled)
