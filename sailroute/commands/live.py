"""``sailroute live`` and ``sailroute live-convert``: re-plan the rest of a race from the
instruments, and turn instrument logs into NMEA 0183 replay files."""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from pathlib import Path

from sailroute.commands.result import CommandResult
from sailroute.course.load import build_specs, load_course
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.live.convert import convert_log
from sailroute.live.engine import LiveEngine, LiveSettings
from sailroute.live.planner import ProcessPlanner
from sailroute.live.sources import parse_source
from sailroute.planning.route import default_scenario, settings_for
from sailroute.tabular import parse_offset
from sailroute.timeutil import iso, parse_time, to_epoch

__all__ = ["live_report", "run_live_command", "run_live_convert_command", "start_live"]


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
) -> LiveEngine:
    """Load the course and its forecast, open the ports and start the live threads.

    Parameters are those of :func:`run_live_command`; ``leg`` is 1-based.  The caller
    ends the engine with :meth:`~sailroute.live.engine.LiveEngine.close`.

    Raises
    ------
    InputError
        A bad course, scenario, source, leg number, interval, a port out of 0..65535 or
        in use.
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
    routing = settings_for(loaded, router)
    boat, winds = build_specs(loaded, [name])
    base = settings or LiveSettings()
    live = LiveSettings(
        every_s,
        base.shift_deg,
        base.change_ms,
        base.fade_s,
        base.window_s,
        base.stale_s,
        base.reach_m,
        base.side,
    )
    planner = ProcessPlanner(loaded, name, router) if worker else None
    return LiveEngine(
        loaded,
        winds[name],
        boat,
        routing,
        src,
        live,
        port=port,
        nmea_port=nmea_port,
        log=None if log is None else Path(log),
        leg=leg - 1,
        planner=planner,
    ).start()


def live_report(engine: LiveEngine) -> str:
    """The terminal summary of a live run: inputs, re-plans, the last plan."""
    st = engine.state()
    c = st["counts"]
    lines = [
        f"source {engine.source.label}: {engine.n_readings} readings, "
        f"{c['used']} messages used, {c.get('bad_checksum', 0)} with a bad checksum, "
        f"{c.get('malformed', 0)} malformed, {engine.n_drops} connection drops",
        f"re-plans: {engine.n_plans}",
    ]
    p = engine.plan
    if p is not None:
        lines.append(
            f"last re-plan #{p.number} at {iso(p.t)} ({p.reason}), leg {p.leg + 1}: "
            f"next mark in {p.time_to_mark_s:.0f} s, finish in "
            f"{p.time_to_finish_s:.0f} s, wind {p.wind_tws_ms * 1.9438:.1f} kn "
            f"from {p.wind_twd_deg:.0f}°"
        )
        if p.side is not None:
            lines.append(
                f"side that pays: {p.side.side}"
                + ("" if p.side.side == "none" else f" by {p.side.gain_s:.0f} s")
            )
    if engine.error:
        lines.append(f"last routing problem: {engine.error}")
    return "\n".join(lines)


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
) -> CommandResult:
    """Everything ``sailroute live`` does, minus printing.

    Runs until ``duration_s`` of wall time, the end of a replayed file, or Ctrl-C; every
    way ends cleanly (threads joined, ports closed, log flushed).

    Parameters
    ----------
    course : Course, str or Path
        The course being raced.
    source : str
        ``signalk://HOST:PORT``, ``nmea+tcp://HOST:PORT``, ``nmea+udp://:PORT`` or a
        recorded ``.nmea`` file (:func:`sailroute.live.sources.parse_source`).
    scenario : str, optional
        The forecast scenario (default: the course's first).
    every_s : float
        Re-plan at least every this many seconds of data time [s].
    speed : float
        Replay speed of a recorded file (1 = real time).
    port, nmea_port : int or None
        The page's HTTP port and the NMEA-out TCP port on 127.0.0.1 (0: any free port;
        None: not served).
    log : str or Path, optional
        The JSON-lines log.
    duration_s : float, optional
        Wall time to run [s].
    router : str, optional
        Overrides the course's router.
    leg : int
        The leg being sailed at the start (1-based; later legs follow as marks are
        reached).
    announce : callable, optional
        Receives the page URL and the NMEA port once they are open.
    settings : LiveSettings, optional
        Re-plan rules (wind thresholds, fade time); ``every_s`` replaces its interval.
    worker : bool
        Compute the re-plans in a worker process (default), so that routing never slows
        the input reader (:mod:`sailroute.live.planner`); False: in a thread of this
        process (no start-up time, for tests and short runs).

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
    )
    try:
        if announce is not None:
            if engine.page is not None:
                announce(f"page: http://127.0.0.1:{engine.page.port}/")
            if engine.nmea is not None:
                announce(f"NMEA 0183 out (RMB, APB, WPL, RTE): tcp://127.0.0.1:{engine.nmea.port}")
        with contextlib.suppress(KeyboardInterrupt):
            engine.wait(duration_s)
    finally:
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
