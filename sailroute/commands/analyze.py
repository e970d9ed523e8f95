"""``sailroute analyze``: read the tracks, analyse each against the optimal route, write.

The analysis is :mod:`sailroute.analysis.debrief`; a fleet is first triaged
(:mod:`sailroute.analysis.triage`: which boats can be debriefed, the fleet's start) and
debriefed as a :class:`~sailroute.analysis.fleet.FleetAnalysis`; the files, tables and pages
are :mod:`sailroute.report.analysis`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from sailroute.analysis.debrief import (
    REFERENCES,
    analysis_winds,
    analyze_fleet,
    analyze_track,
    fleet_reference,
    parse_boat_leg_times,
    prepare_fleet,
)
from sailroute.analysis.fleet import FleetAnalysis
from sailroute.analysis.fleetlearn import beaten_note, learned_reference
from sailroute.analysis.gains import fleet_gains
from sailroute.analysis.result import TrackAnalysis
from sailroute.analysis.segment import DETECT_M, StartClock
from sailroute.analysis.triage import BoatEntry, Triage, class_notes, triage_fleet
from sailroute.boat.polar import Polar
from sailroute.commands.result import CommandResult
from sailroute.course.load import build_specs, load_course
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, write_output_set
from sailroute.planning.route import default_scenario, settings_for
from sailroute.progress import Progress
from sailroute.report.analysis import (
    analysis_table,
    fleet_table,
    gains_table,
    results_table,
    write_analysis,
    write_fleet,
)
from sailroute.timeutil import iso
from sailroute.track.model import Track
from sailroute.track.read import read_track

__all__ = ["PAGES", "TABLES_MAX", "run_analyze_command"]

PAGES = ("fleet", "boat")
"""``--pages``: the fleet's page only (default), or each boat's page and charts too."""

TABLES_MAX = 10
"""A fleet of up to this many debriefed boats gets each boat's table and the per-leg
ranking in the terminal report; a larger one the results table only (every boat's tables
are in its folder)."""


def run_analyze_command(
    course: Course | str | Path,
    tracks: Sequence[str | Path],
    *,
    scenario: str | None = None,
    router: str | None = None,
    out_dir: str | Path | None = None,
    leg_times: str | Sequence[str] | None = None,
    columns: Mapping[str, str] | None = None,
    speed_unit: str | None = None,
    time_zone: str | None = None,
    detect_m: float = DETECT_M,
    plots: bool = True,
    progress: Progress | None = None,
    gate_end: str = "line",
    wind: str = "auto",
    reference: str = "course",
    pages: str = "fleet",
    gun: str | float | None = None,
) -> CommandResult:
    """Everything ``sailroute analyze`` does, minus printing.

    ``out_dir`` is checked first; every track is read and analysed before anything is
    written, and the files are written as a set
    (:func:`sailroute.outdir.write_output_set`), so a bad input or an interrupted run
    leaves the folder as it was.  One track: ``analysis.json``, ``analysis.csv``,
    ``points.csv``, ``legs.png``, ``loss.png`` in ``out_dir`` (default
    ``out/<course>/analysis-<track stem>``), and ``report.html`` with ``plotly.min.js``; a
    track that cannot be analysed is an error.  Several: ``fleet.csv``, ``fleet.json``,
    the fleet's ``report.html`` and ``plotly.min.js`` (default folder
    ``out/<course>/analysis-fleet``), and per debriefed boat its ``analysis.json``,
    ``analysis.csv`` and ``points.csv`` in ``out_dir/<track stem>/``; with
    ``pages="boat"`` also each boat's ``report.html``, ``legs.png`` and ``loss.png``
    there (they load the one ``plotly.min.js`` of ``out_dir``).  ``plots=False`` writes
    no page and no chart.  A boat that cannot be debriefed
    (:func:`sailroute.analysis.triage.triage_fleet`) is left out with a note, and the run
    fails only when no boat can be debriefed.

    ``wind`` chooses the wind each leg is judged in (:func:`analysis_winds`);
    ``reference="fleet"`` judges every boat against the course's polar scaled to what the
    fleet sails (:func:`sailroute.analysis.fleetpolar.fleet_polar`), ``reference="learned"``
    against the polar learned from the analysed fleet itself
    (:func:`sailroute.analysis.fleetlearn.learned_reference`): the boats are analysed twice.
    Judged against the course's polar, a fleet that beats it by more than 10 % on most legs
    gets a first line saying so (:func:`~sailroute.analysis.fleetlearn.beaten_note`).
    ``gun`` (an ISO time with offset, or epoch seconds) replaces the course's gun
    (``restart_time``, else ``start_time``): the restart after a general recall. ``data`` of
    the result is the :class:`~sailroute.analysis.fleet.FleetAnalysis` (a sequence of the
    boats' analyses) for a fleet, a one-analysis tuple for one track.
    """
    course = course if isinstance(course, Course) else load_course(course)
    if not tracks:
        raise InputError("analyze: give at least one track file")
    if pages not in PAGES:
        raise InputError(f"--pages: expected one of {', '.join(PAGES)}; got {pages!r}")
    if reference not in REFERENCES:
        raise InputError(f"--reference: expected one of {', '.join(REFERENCES)}; got {reference!r}")
    gun_t = _gun(gun, course)
    name = default_scenario(course) if scenario is None else scenario
    stems = _unique_stems(tracks)
    times = parse_boat_leg_times(leg_times, stems, course.n_legs)
    stem = Path(course.source).stem if course.source else "course"
    default = (
        Path("out")
        / stem
        / (f"analysis-{Path(tracks[0]).stem}" if len(tracks) == 1 else "analysis-fleet")
    )
    out = check_out_dir(Path(out_dir) if out_dir is not None else default)
    read_kw: dict[str, Any] = {
        "columns": columns,
        "speed_unit": speed_unit,
        "time_zone": time_zone,
    }
    one = len(tracks) == 1
    read: list[tuple[str, str, Track | Exception]] = []
    for p, s in zip(tracks, stems, strict=True):
        try:
            read.append((s, str(p), read_track(p, name=s, **read_kw)))
        except InputError as exc:
            if one:
                raise
            read.append((s, str(p), exc))
    tri = triage_fleet(
        course,
        read,
        gun_t=gun_t,
        leg_times=times,
        detect_m=detect_m,
        gate_end=gate_end,
        fleet_start=not one,
    )
    debriefed = tri.analysed
    if one:
        got = read[0][2]
        assert isinstance(got, Track)  # one unreadable track raised above
        # one boat: its own errors, word for word (never starts, a leg never completed)
        debriefed = (
            BoatEntry(stems[0], str(tracks[0]), tri.entries[0].track or got, tri.entries[0].status),
        )
    elif not debriefed:
        raise InputError(
            f"analyze: no boat of the {len(tracks)} tracks can be analysed: "
            + " | ".join(class_notes(tri.entries))
        )
    settings_for(course, router)
    boat, winds = build_specs(course, [name])
    polar = boat.routing_polar()
    if reference != "course" and polar is None:
        raise InputError(
            f"--reference {reference} scales a polar; the course's boat has none (a "
            "dynamic boat model): use --reference course"
        )
    boat_tracks = [e.track for e in debriefed if e.track is not None]
    # the tracks as the fleet's triage projected them, where it did
    projected = [e.xy for e in debriefed if e.track is not None and e.xy is not None]
    sources, notes = analysis_winds(
        course,
        boat_tracks,
        name,
        winds[name],
        boat,
        wind,
        gun_t=tri.start.track_gun_t,
        race_end_t=tri.race_end_t,
        xy=projected if not one and len(projected) == len(boat_tracks) else None,
    )

    def analyse_all(judged_by: Any, label: str) -> list[TrackAnalysis]:
        if one:  # its own segmentation and errors, its legs routed one by one
            e = debriefed[0]
            assert e.track is not None
            a = analyze_track(
                course,
                e.track,
                name,
                leg_times=times[e.name],
                router=router,
                detect_m=detect_m,
                built=(judged_by, winds[name]),
                winds=sources[e.name],
                progress=progress,
                missing="error",
                gate_end=gate_end,
                clock=StartClock.plain(tri.start.track_gun_t),
            )
            return [replace(a, reference=label)]
        # a fleet: triaged and segmented, its legs routed together
        prepared = prepare_fleet(
            course, debriefed, name, (judged_by, winds[name]), sources, router=router
        )
        return [replace(a, reference=label) for a in analyze_fleet(prepared, progress)]

    analyses = analyse_all(boat, f"course polar {getattr(boat, 'name', '')}".strip())
    analyses, beaten = _rejudge(reference, analyses, analyse_all, notes, boat, polar, course, name)
    banner = () if beaten is None else (beaten,)
    if one:
        res = _one_boat(out, analyses[0], tri, notes, plots, banner)
    else:
        fleet = FleetAnalysis(course, tri, tuple(analyses), tuple(notes))
        res = _fleet(out, fleet, sources, plots, pages, polar, banner)
    return res if beaten is None else replace(res, report=f"note: {beaten}\n\n{res.report}")


def _rejudge(
    reference: str,
    analyses: list[TrackAnalysis],
    analyse_all: Callable[[Any, str], list[TrackAnalysis]],
    notes: list[str],
    boat: Any,
    polar: Any,
    course: Course,
    scenario: str,
) -> tuple[list[TrackAnalysis], str | None]:
    """The analyses against ``reference`` (``analyses`` are against the course's boat), the
    reference's line added to ``notes``; and the line saying the course's polar is beaten
    on most legs (:func:`~sailroute.analysis.fleetlearn.beaten_note`, put first in
    ``notes``; None: not beaten, or another reference asked for)."""
    if reference == "course":
        beaten = beaten_note(analyses, getattr(boat, "name", ""))
        if beaten is not None:
            notes.insert(0, beaten)
        return analyses, beaten
    if reference == "fleet":
        ref: Any = fleet_reference(analyses, polar)
    else:
        ref = learned_reference(course, [a.track for a in analyses], scenario, polar)
    notes.append(ref.describe())
    return analyse_all(ref.polar, ref.describe()), None


def _one_boat(
    out: Path,
    a: TrackAnalysis,
    tri: Triage,
    notes: list[str],
    plots: bool,
    banner: Sequence[str] = (),
) -> CommandResult:
    """The result of one track: its files, its table and the run's notes (``banner`` at
    the top of its page)."""
    all_notes = [*tri.notes(), *notes]
    files = write_output_set(out, lambda d: write_analysis(d, a, plots=plots, banner=banner))
    return CommandResult(
        "\n\n".join([analysis_table(a), _notes_text(all_notes)]),
        files,
        data=(a,),
        notes=tuple(all_notes),
        main=("analysis_json",),
    )


def _fleet(
    out: Path,
    fleet: FleetAnalysis,
    sources: Mapping[str, Sequence[Any]],
    plots: bool,
    pages: str,
    polar: Polar | None,
    banner: Sequence[str] = (),
) -> CommandResult:
    """The result of a fleet: its gains (with a ``polar``: :mod:`sailroute.analysis.gains`),
    every debriefed boat's files, the fleet's, the tables (``banner`` at the top of the
    fleet's page and of each boat's)."""
    if polar is not None:
        fleet = replace(fleet, gains=fleet_gains(fleet.course, fleet, polar.speed))
    rows = fleet.rows()
    # the page draws the fleet-wide wind: the first boat's first candidate not its own log
    first = fleet.analyses[0].track.name
    shared = next((s for s in sources[first] if s.kind != "measured"), None)
    fleet_wind_layer = (shared.label, shared.field) if shared is not None else None

    def write(d: Path) -> dict[str, Path]:
        files: dict[str, Path] = {}
        boat_pages = plots and pages == "boat"
        for a in fleet.analyses:
            s = a.track.name
            boat_files = write_analysis(d / s, a, plots=boat_pages, scripts=d, banner=banner)
            for kind, p in boat_files.items():
                files[f"{s}/{kind}"] = p
        files.update(
            write_fleet(
                d,
                fleet.analyses,
                rows,
                plots=plots,
                notes=fleet.notes,
                wind=fleet_wind_layer,
                fleet=fleet,
                banner=banner,
            )
        )
        return files

    few = len(fleet.analyses) <= TABLES_MAX
    n = len(fleet)
    parts = [analysis_table(a, legend=k == n - 1) for k, a in enumerate(fleet)] if few else []
    parts.append(results_table(fleet))
    if fleet.gains is not None:
        parts.append(gains_table(fleet, per_leg=few))
    if few:
        parts.append(fleet_table(rows))
    else:
        parts.append(
            f"({len(fleet.analyses)} boats debriefed: each boat's table is in its folder, "
            "<boat>/analysis.csv)"
        )
    parts.append(_notes_text(fleet.all_notes()))
    return CommandResult(
        "\n\n".join(parts),
        write_output_set(out, write),
        data=fleet,
        notes=fleet.all_notes(),
        main=("fleet_json",),
    )


def _gun(gun: str | float | None, course: Course) -> float | None:
    """``--gun``: an ISO time with offset (or epoch seconds) of the gun [epoch s]."""
    if gun is None:
        return None
    if isinstance(gun, int | float):
        return float(gun)
    from sailroute.timeutil import parse_time, to_epoch

    t = to_epoch(parse_time(gun, "--gun"))
    if not course.start_epoch - 6 * 3600.0 <= t <= course.start_epoch + 6 * 3600.0:
        raise InputError(
            f"--gun {gun}: expected the gun of this race, within 6 h of the course's "
            f"start_time {iso(course.start_epoch)}; check the date and the UTC offset"
        )
    return t


def _notes_text(notes: Sequence[str]) -> str:
    """The run's notes, one per line."""
    return "\n".join(f"note: {n}" for n in notes)


def _unique_stems(paths: Sequence[str | Path]) -> list[str]:
    out: list[str] = []
    for p in paths:
        s = Path(p).stem
        k = 2
        base = s
        while s in out:
            s = f"{base}-{k}"
            k += 1
        out.append(s)
    return out
