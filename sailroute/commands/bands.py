"""``plan --ensemble N`` / ``compare-scenarios --ensemble N``: leg-time bands of scenarios.

The members are drawn and routed by :mod:`sailroute.bands.route` (as one front per leg,
:func:`~sailroute.bands.route.route_together`); this module parses the command's
choices, picks the router and writes the files (:mod:`sailroute.report.bands`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from sailroute.bands.route import band_summary, spec_for
from sailroute.commands.plan import default_out_dir
from sailroute.commands.result import CommandResult
from sailroute.course.load import build_specs, load_course
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, write_output_set
from sailroute.planning.route import (
    DEFAULT_RUN,
    RunOptions,
    check_boat_and_winds,
    settings_for,
)

__all__ = ["run_bands_command"]


def run_bands_command(
    course: Course | str | Path,
    *,
    scenarios: Sequence[str] | None = None,
    members: int | None = None,
    out_dir: str | Path | None = None,
    plots: bool = True,
    options: RunOptions = DEFAULT_RUN,
    what: str = "bands",
) -> CommandResult:
    """Leg-time bands of one or more scenarios: what ``plan``/``compare-scenarios --ensemble N`` do.

    Parameters
    ----------
    course : Course, str or Path
        The course or its file.
    scenarios : sequence of str, optional
        Scenarios (default: the first one); an ensemble scenario (``members:``) is
        refused: its members are already a spread.
    members : int, optional
        Members of the main ensemble (``--ensemble N``); default the course's
        ``uncertainty.members`` (20 without the section).
    options : RunOptions, optional
        Router, backend and progress display, as ``sailroute plan``; the scheduler may
        only be None or ``"serial"``: the members are routed here, together.
    out_dir : str or Path, optional
        Default ``out/<course>/<scenario>-bands`` (one scenario) or
        ``out/<course>/<what>-bands``.
    plots : bool
        Also write ``bands.png``.
    what : str
        Name of the default folder for several scenarios (``comparison``).

    Returns
    -------
    CommandResult
        ``report``: one table per scenario; ``files``: ``bands_json``, ``bands_csv``,
        ``bands_png``; ``data``: the tuple of :class:`BandSummary`.
    """
    from sailroute.report.bands import bands_page, bands_table, write_bands

    router, backend, progress = options.router, options.backend, options.progress
    scheduler = options.scheduler

    if members is not None and members < 3:
        raise InputError(f"--ensemble {members}: a band needs at least 3 members; give N >= 3")
    if scheduler not in (None, "serial"):
        raise InputError(
            f"--scheduler {scheduler}: --ensemble routes its members here, as one "
            "front per leg; leave out --scheduler (or use serial)"
        )
    course = course if isinstance(course, Course) else load_course(course)
    names = list(scenarios) if scenarios else [course.scenario_names[0]]
    for n in names:
        if n in course.ensembles:
            raise InputError(
                f"{course.where('scenarios.' + n)}: {n!r} is an ensemble of "
                f"{len(course.ensembles[n])} members; --ensemble draws its own members "
                f"around one scenario: give one of {', '.join(repr(s) for s in course.scenarios if s not in course.ensembles[n])} "  # noqa: E501
                "or route the ensemble without --ensemble"
            )
    folder = f"{names[0]}-bands" if len(names) == 1 else f"{what}-bands"
    out = check_out_dir(
        Path(out_dir) if out_dir is not None else default_out_dir(course, folder, router)
    )
    spec, notes = spec_for(course, members)
    settings = settings_for(course, router, backend)
    boat, winds = build_specs(course, names)
    warn = check_boat_and_winds(course, boat, winds)
    if progress is not None:
        for line in warn.values():
            progress.warn(line)
    summaries = tuple(
        band_summary(
            course,
            n,
            spec,
            wind=winds[n],
            boat=boat,
            settings=settings,
            backend=backend,
            progress=progress,
            notes=notes,
        )
        for n in names
    )

    def write(d: Path) -> dict[str, Path]:
        files = write_bands(d, summaries, course_name=course.name, plot=plots)
        if plots:
            from sailroute.report.page_render import PLOTLY_FILE, write_report

            files["html"] = write_report(
                d / "report.html",
                bands_page(course, summaries, winds, router=settings.router, boat=boat),
            )
            files["plotly_js"] = d / PLOTLY_FILE
        return files

    files = write_output_set(out, write)
    return CommandResult(
        "\n\n".join(bands_table(b) for b in summaries),
        files,
        summaries,
        notes=tuple(warn.values()),
        main=("bands_json",),
    )
