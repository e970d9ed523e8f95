"""``sailroute analyze``: read the tracks, analyse each against the optimal route, write.

The analysis is :mod:`sailroute.analysis.debrief`; the files, tables and pages are
:mod:`sailroute.report.analysis`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from sailroute.analysis.debrief import (
    REFERENCES,
    analysis_winds,
    analyze_track,
    fleet_ranking,
    fleet_reference,
    parse_boat_leg_times,
)
from sailroute.analysis.result import TrackAnalysis
from sailroute.analysis.segment import DETECT_M
from sailroute.commands.result import CommandResult
from sailroute.course.load import build_specs, load_course
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, write_output_set
from sailroute.planning.route import default_scenario, settings_for
from sailroute.progress import Progress
from sailroute.report.analysis import (
    analysis_table,
    fleet_notes,
    fleet_table,
    write_analysis,
    write_fleet,
)
from sailroute.track.read import read_track

__all__ = ["PAGES", "run_analyze_command"]

PAGES = ("fleet", "boat")
"""``--pages``: the fleet's page only (default), or each boat's page and charts too."""


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
) -> CommandResult:
    """Everything ``sailroute analyze`` does, minus printing.

    ``out_dir`` is checked first; every track is read and analysed before anything is
    written, and the files are written as a set
    (:func:`sailroute.outdir.write_output_set`), so a bad input or an interrupted run
    leaves the folder as it was.  One track: ``analysis.json``, ``analysis.csv``,
    ``points.csv``, ``legs.png``, ``loss.png`` in ``out_dir`` (default
    ``out/<course>/analysis-<track stem>``), and ``report.html`` with ``plotly.min.js``.
    Several: ``fleet.csv``, ``fleet.json``, the fleet's ``report.html`` and
    ``plotly.min.js`` (default folder ``out/<course>/analysis-fleet``), and per boat its
    ``analysis.json``, ``analysis.csv`` and ``points.csv`` in ``out_dir/<track stem>/``;
    with ``pages="boat"`` also each boat's ``report.html``, ``legs.png`` and ``loss.png``
    there (they load the one ``plotly.min.js`` of ``out_dir``).  ``plots=False`` writes
    no page and no chart.

    ``wind`` chooses the wind each leg is judged in (:func:`analysis_winds`);
    ``reference="fleet"`` judges every boat against the course's polar scaled to what
    the fleet sails (:func:`sailroute.analysis.fleetpolar.fleet_polar`): the boats are
    analysed twice.
    """
    course = course if isinstance(course, Course) else load_course(course)
    if not tracks:
        raise InputError("analyze: give at least one track file")
    if pages not in PAGES:
        raise InputError(f"--pages: expected one of {', '.join(PAGES)}; got {pages!r}")
    if reference not in REFERENCES:
        raise InputError(f"--reference: expected one of {', '.join(REFERENCES)}; got {reference!r}")
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
    read = [
        read_track(p, columns=columns, speed_unit=speed_unit, time_zone=time_zone, name=s)
        for p, s in zip(tracks, stems, strict=True)
    ]
    settings_for(course, router)
    boat, winds = build_specs(course, [name])
    polar = boat.routing_polar()
    if reference == "fleet" and polar is None:
        raise InputError(
            "--reference fleet scales a polar; the course's boat has none (a "
            "dynamic boat model): use --reference course"
        )
    sources, notes = analysis_winds(course, read, name, winds[name], boat, wind)

    def analyse_all(judged_by: Any, label: str) -> list[TrackAnalysis]:
        out_a = []
        for tr in read:
            if progress is not None:
                progress.set_prefix(f"{tr.name}: ")
            a = analyze_track(
                course,
                tr,
                name,
                leg_times=times[tr.name],
                router=router,
                detect_m=detect_m,
                built=(judged_by, winds[name]),
                winds=sources[tr.name],
                progress=progress,
                missing="error" if len(read) == 1 else "unknown",
                gate_end=gate_end,
            )
            out_a.append(replace(a, reference=label))
        return out_a

    analyses = analyse_all(boat, f"course polar {getattr(boat, 'name', '')}".strip())
    if reference == "fleet":
        fp = fleet_reference(analyses, polar)
        notes.append(fp.describe())
        analyses = analyse_all(fp.polar, fp.describe())
    if len(analyses) == 1:
        files = write_output_set(out, lambda d: write_analysis(d, analyses[0], plots=plots))
        return CommandResult(
            "\n\n".join([analysis_table(analyses[0]), _notes_text(notes)]),
            files,
            data=tuple(analyses),
            notes=tuple(notes),
            main=("analysis_json",),
        )
    rows = fleet_ranking(analyses)
    # the page draws the fleet-wide wind: the first boat's first candidate not its own log
    shared = next((s for s in sources[read[0].name] if s.kind != "measured"), None)
    fleet_wind_layer = (shared.label, shared.field) if shared is not None else None

    def write(d: Path) -> dict[str, Path]:
        files: dict[str, Path] = {}
        boat_pages = plots and pages == "boat"
        for s, a in zip(stems, analyses, strict=True):
            for kind, p in write_analysis(d / s, a, plots=boat_pages, scripts=d).items():
                files[f"{s}/{kind}"] = p
        files.update(
            write_fleet(d, analyses, rows, plots=plots, notes=notes, wind=fleet_wind_layer)
        )
        return files

    report = "\n\n".join(
        [
            *(analysis_table(a) for a in analyses),
            fleet_table(rows, fleet_notes(analyses)),
            _notes_text(notes),
        ]
    )
    return CommandResult(
        report,
        write_output_set(out, write),
        data=tuple(analyses),
        notes=tuple(notes),
        main=("fleet_json",),
    )


def _notes_text(notes: Sequence[str]) -> str:
    """The run's wind and reference notes, one per line."""
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
