"""``sailroute live`` and ``sailroute live-convert``: re-plan the rest of a race from the
instruments, and turn instrument logs into NMEA 0183 replay files."""

from __future__ import annotations

import contextlib
import dataclasses
import signal
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from sailroute.commands.result import CommandResult
from sailroute.course.load import build_specs, load_course
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.live.boat import vessel_key
from sailroute.live.convert import convert_log
from sailroute.live.engine import LiveEngine, LiveSettings
from sailroute.live.planner import ProcessPlanner
from sailroute.live.sources import NmeaFileSource, Source, parse_source
from sailroute.live.web import loopback
from sailroute.outdir import check_out_file
from sailroute.planning.route import default_scenario, settings_for
from sailroute.tabular import parse_offset
from sailroute.timeutil import iso, parse_time, to_epoch

__all__ = ["live_report", "run_live_command", "run_live_convert_command", "start_live"]


def _paths(value: Any) -> Iterator[Path]:
    """Every :class:`~pathlib.Path` in a (nested) spec: dataclasses, mappings, sequences."""
    if isinstance(value, Path):
        yield value
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            yield from _paths(getattr(value, f.name))
    elif isinstance(value, dict):
        for v in value.values():
            yield from _paths(v)
    elif isinstance(value, list | tuple):
        for v in value:
            yield from _paths(v)


def course_inputs(course: Course) -> list[Path]:
    """The files a course reads: the course file, its polar, its wind and current files."""
    out = [course.source] if course.source is not None else []
    polar = course.boat_spec.get("polar")
    if isinstance(polar, str):
        out.append(course.base_dir / polar)
    for spec in course.scenarios.values():
        out.extend(_paths(spec.wind))
        out.extend(_paths(spec.current))
    return out


def _file_of(src: Source | None) -> list[Path]:
    return [src.path] if isinstance(src, NmeaFileSource) else []


def start_live(
    course: Course | str | Path,
    *,
    source: str,
    scenario: str | None = None,
    every_s: float = 10.0,
    speed: float = 1.0,
    port: int | None = 8080,
    nmea_port: int | None = 10110,
    log: str | Path | None = None,
    router: str | None = None,
    leg: int = 1,
    settings: LiveSettings | None = None,
    worker: bool = True,
    boat: str | None = None,
    boat_source: str | None = None,
    host: str | None = None,
) -> LiveEngine:
    """Load the course and its forecast, open the ports and start the live threads.

    Parameters are those of :func:`run_live_command`; ``leg`` is 1-based.  The caller
    ends the engine with :meth:`~sailroute.live.engine.LiveEngine.close`.

    Raises
    ------
    InputError
        A bad course, scenario, source, leg number, interval, a port out of 0..65535 or
        in use, a log that is one of the inputs.
    """
    for option, value in (("--port", port), ("--nmea-port", nmea_port)):
        if value is not None and not 0 <= value <= 65535:
            raise InputError(
                f"{option} {value}: expected a TCP port in 0..65535 (0: any free port)"
            )
    loaded = course if isinstance(course, Course) else load_course(course)
    name = default_scenario(loaded) if scenario is None else scenario
    if name in loaded.ensembles:
        raise InputError(
            f"--scenario {name}: an ensemble; give one member "
            f"({', '.join(loaded.ensembles[name])}) as the forecast"
        )
    if not every_s > 0:
        raise InputError(f"--every {every_s:g}: must be > 0 seconds between re-plans")
    if not 1 <= leg <= loaded.n_legs:
        raise InputError(f"--leg {leg}: the course has legs 1..{loaded.n_legs}")
    src = parse_source(source, speed)
    second = None if boat_source is None else parse_source(boat_source, speed)
    if boat_source is not None and boat is None:
        boat = "boat-source"
    if log is not None:
        inputs = [*course_inputs(loaded), *_file_of(src), *_file_of(second)]
        check_out_file(log, inputs, option="--log")
    routing = settings_for(loaded, router)
    model, winds = build_specs(loaded, [name])
    live = dataclasses.replace(settings or LiveSettings(), every_s=every_s)
    planner = ProcessPlanner(loaded, name, router) if worker else None
    return LiveEngine(
        loaded,
        winds[name],
        model,
        routing,
        src,
        live,
        port=port,
        nmea_port=nmea_port,
        log=None if log is None else Path(log),
        leg=leg - 1,
        planner=planner,
        sailor=None if boat is None else vessel_key(boat),
        boat_source=second,
        host=host or "127.0.0.1",
    ).start()


def live_report(engine: LiveEngine) -> str:
    """The terminal summary of a live run: inputs, what was held out, re-plans, the last
    plan."""
    st = engine.state()
    c = st["counts"]
    held = ", ".join(f"{c.get('gate_' + k, 0)} {k}" for k in ("bounds", "far", "jump", "time"))
    lines = [
        f"source {engine.source.label}: {engine.n_readings} readings, "
        f"{c['used']} messages used, {c.get('bad_checksum', 0)} with a bad checksum, "
        f"{c.get('no_checksum', 0)} without one, {c.get('malformed', 0)} malformed, "
        f"{c.get('too_long', 0)} too long, {engine.n_drops} connection drops",
        f"readings held out: {c['held_out']} ({held})",
        f"re-plans: {engine.n_plans}; the sailor's boat ({engine.sailor.key or 'none chosen'}) "
        f"on leg {min(engine.legs.leg + 1, engine.course.n_legs)} of {engine.course.n_legs}"
        + (" (finished)" if engine.legs.finished else ""),
    ]
    p = engine.plan
    if p is not None:
        lines.append(
            f"last re-plan #{p.number} at {iso(p.t)} ({p.reason}), leg {p.leg + 1}: "
            f"next mark in {p.time_to_mark_s:.0f} s, finish in "
            f"{p.time_to_finish_s:.0f} s, wind {p.wind_tws_ms * 1.9438:.1f} kn "
            f"from {p.wind_twd_deg:.0f}°"
        )
        if p.wind_note:
            lines.append(f"  {p.wind_note}")
        if p.side is not None:
            lines.append(
                f"side that pays: {p.side.side}"
                + ("" if p.side.side == "none" else f" by {p.side.gain_s:.0f} s")
            )
    if engine.error:
        lines.append(f"last routing problem: {engine.error}")
    if engine.waiting:
        lines.append(f"not routed: {engine.waiting}")
    if engine.n_errors:
        lines.append(f"messages that raised (skipped, in the log): {engine.n_errors}")
    return "\n".join(lines)


class _Ended(KeyboardInterrupt):
    """SIGTERM or SIGHUP: end as Ctrl-C ends."""


class _Signals:
    """While open, SIGTERM and SIGHUP raise :class:`_Ended` in the main thread, once;
    after :meth:`closing` (and after the first), they are ignored, so that nothing
    interrupts the close.  Outside the main thread it does nothing."""

    def __init__(self) -> None:
        self._old: dict[int, Any] = {}
        self._raise = True

    def __enter__(self) -> _Signals:
        if threading.current_thread() is threading.main_thread():
            for sg in (signal.SIGTERM, signal.SIGHUP):
                self._old[sg] = signal.signal(sg, self._handler)
        return self

    def _handler(self, signum: int, frame: Any) -> None:
        if self._raise:
            self._raise = False
            raise _Ended(signal.Signals(signum).name)

    def closing(self) -> None:
        """From now on, ignore them."""
        self._raise = False

    def __exit__(self, *exc: object) -> None:
        for sg, h in self._old.items():
            signal.signal(sg, h)


def run_live_command(
    course: Course | str | Path,
    *,
    source: str,
    scenario: str | None = None,
    every_s: float = 10.0,
    speed: float = 1.0,
    port: int | None = 8080,
    nmea_port: int | None = 10110,
    log: str | Path | None = None,
    duration_s: float | None = None,
    router: str | None = None,
    leg: int = 1,
    announce: Callable[[str], None] | None = None,
    settings: LiveSettings | None = None,
    worker: bool = True,
    boat: str | None = None,
    boat_source: str | None = None,
    host: str | None = None,
) -> CommandResult:
    """Everything ``sailroute live`` does, minus printing.

    Runs until ``duration_s`` of wall time, the end of a replayed file, Ctrl-C, SIGTERM
    or SIGHUP; every way ends cleanly (threads joined, workers ended, ports closed, the
    log's ``end`` line written).

    Parameters
    ----------
    course : Course, str or Path
        The course being raced.
    source : str
        The coach boat's instruments: ``signalk://HOST:PORT``, ``nmea+tcp://HOST:PORT``,
        ``nmea+udp://:PORT`` or a recorded ``.nmea`` file
        (:func:`sailroute.live.sources.parse_source`).
    scenario : str, optional
        The forecast scenario (default: the course's first).
    every_s : float
        Re-plan at least every this many seconds of data time [s].
    speed : float
        Replay speed of a recorded file (1 = real time).
    port, nmea_port : int or None
        The page's HTTP port and the NMEA-out TCP port (0: any free port; None: not
        served); a busy NMEA port is replaced by the next free one.
    log : str or Path, optional
        The JSON-lines log (never one of the inputs).
    duration_s : float, optional
        Wall time to run [s].
    router : str, optional
        Overrides the course's router.
    leg : int
        The leg being sailed at the start (1-based; later legs follow as the sailor's
        boat rounds).
    announce : callable, optional
        Receives the page's address and the NMEA port once they are open.
    settings : LiveSettings, optional
        Re-plan rules (wind thresholds, fade time, checksums); ``every_s`` replaces its
        interval.
    worker : bool
        Compute the re-plans in worker processes (default), so that routing never slows
        the input reader (:mod:`sailroute.live.planner`); False: in threads of this
        process (no start-up time, for tests and short runs).
    boat : str, optional
        The sailor's boat: ``self``, an MMSI, a Signal K vessel id
        (:mod:`sailroute.live.boat`); None: chosen on the page (or the boat of
        ``boat_source``).
    boat_source : str, optional
        The sailor's boat's own feed (any ``source`` form).
    host : str, optional
        Serve the page and the NMEA port on this address instead of 127.0.0.1; every
        request to the page then needs the token in its address.

    Returns
    -------
    CommandResult
        ``data`` is the last :class:`~sailroute.live.replan.LivePlan` (None if none);
        ``files`` the log.
    """
    engine = start_live(
        course,
        source=source,
        scenario=scenario,
        every_s=every_s,
        speed=speed,
        port=port,
        nmea_port=nmea_port,
        log=log,
        router=router,
        leg=leg,
        settings=settings,
        worker=worker,
        boat=boat,
        boat_source=boat_source,
        host=host,
    )
    with _Signals() as signals:
        try:
            with contextlib.suppress(KeyboardInterrupt):
                if announce is not None:
                    for note in engine.notes:
                        announce(note)
                    if engine.page is not None:
                        announce(f"page: {engine.page.url}")
                    if engine.nmea is not None:
                        where = host if host and not loopback(host) else "127.0.0.1"
                        announce(
                            f"NMEA 0183 out (RMB, APB, WPL, RTE): tcp://{where}:{engine.nmea.port}"
                        )
                engine.wait(duration_s)
        finally:
            signals.closing()
            engine.close()
    files = {"log": Path(log)} if log is not None else {}
    return CommandResult(live_report(engine), files, engine.plan, main=())


def run_live_convert_command(
    log: str | Path,
    *,
    fmt: str,
    out: str | Path,
    utc_offset: str | None = None,
    start: str | None = None,
    end: str | None = None,
) -> CommandResult:
    """Everything ``sailroute live-convert`` does: an instrument log to a ``.nmea`` replay.

    Parameters
    ----------
    log : str or Path
        The log (:mod:`sailroute.live.convert` lists the formats).
    fmt : {"trieste", "tallinn"}
        Its format.
    out : str or Path
        The ``.nmea`` file to write.
    utc_offset : str, optional
        The logger's UTC offset, ``+HH:MM``, for times written without one (``trieste``:
        the logger's local clock; default +01:00).
    start, end : str, optional
        ISO 8601 times with an offset: keep that span only.
    """
    zone = None if utc_offset is None else parse_offset(utc_offset, "--utc-offset").utcoffset(None)
    offset = None if zone is None else zone.total_seconds()
    t0 = None if start is None else to_epoch(parse_time(start, "--from"))
    t1 = None if end is None else to_epoch(parse_time(end, "--to"))
    n = convert_log(Path(log), fmt, Path(out), utc_offset_s=offset, t0=t0, t1=t1)
    return CommandResult(
        f"{n} seconds of {fmt} log written as NMEA 0183",
        {"nmea": Path(out)},
        n,
        main=(),
        labels={"nmea": "replay (NMEA 0183)"},
    )
