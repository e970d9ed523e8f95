"""``sailroute plan`` and ``sailroute compare-scenarios``: route, then write the files.

The routing is :mod:`sailroute.planning.route`; the files and pages are
:mod:`sailroute.report`.  Nothing here prints: :mod:`sailroute.cli` prints the
:class:`~sailroute.commands.result.CommandResult`.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from sailroute.commands.result import CommandResult
from sailroute.course.load import load_course
from sailroute.course.model import Course
from sailroute.outdir import check_out_dir, path_part_problem, safe_part, write_output_set
from sailroute.planning.route import (
    DEFAULT_RUN,
    RunOptions,
    default_scenario,
    plan_course,
    route_scenarios,
)
from sailroute.report import png_worker

__all__ = ["default_out_dir", "run_compare_command", "run_plan_command"]


def _loaded(course: Course | str | Path) -> Course:
    """``course`` itself, or the course loaded from that path."""
    return course if isinstance(course, Course) else load_course(course)


def default_out_dir(course: Course, what: str, router: str | None = None) -> Path:
    """``out/<course file stem>/<what>``: where results go without ``--out``.

    A ``router`` other than the course's own (``routing.router``) is added to the last
    part, ``out/<stem>/<what>-<router>``, so that ``plan --router griddp`` does not
    replace the folder of the default router's run.  ``what`` (a scenario name given on
    the command line) must be one safe path part (:func:`sailroute.outdir.safe_part`).
    """
    stem = Path(course.source).stem if course.source else "course"
    if path_part_problem(stem) is not None:
        stem = "course"
    safe_part(what, "scenario")
    if router is not None and router != course.routing.router:
        what = f"{what}-{router}"
    return Path("out") / stem / what


def run_plan_command(
    course: Course | str | Path,
    *,
    scenario: str | None = None,
    out_dir: str | Path | None = None,
    plots: bool = True,
    options: RunOptions = DEFAULT_RUN,
) -> CommandResult:
    """Everything ``sailroute plan`` does, minus printing.

    Writes ``plan.json``, ``track.csv``, ``route.gpx``, ``route.png`` and ``report.html``
    (the last two unless ``plots`` is False) into ``out_dir`` (default
    ``out/<course>/<scenario>``; checked before routing, written as a set:
    :func:`sailroute.outdir.write_output_set`).  For an ensemble scenario it routes every
    member and writes ``ensemble.json`` and ``ensemble.csv`` (the spread of leg times, the
    side of the course), ``report.html`` with every member's route (unless ``plots`` is
    False) plus each
    member's plan files in ``out_dir/<member>/``.
    """
    from sailroute.report.files import write_plan_outputs
    from sailroute.report.tables import plan_table

    course = _loaded(course)
    name = default_scenario(course) if scenario is None else scenario
    out = check_out_dir(
        Path(out_dir) if out_dir is not None else default_out_dir(course, name, options.router)
    )
    if name in course.ensembles:
        return _run_ensemble(course, name, out_dir=out, options=options, plots=plots)
    with png_worker.start(plots) as png:  # loads matplotlib on another core meanwhile
        run = plan_course(course, scenario, options)

        def write(d: Path) -> dict[str, Path]:
            if plots:  # the child draws while the other files are written here
                png.submit(run.plan, run.wind, d / "route.png", png_worker.DPI)
            files = dict(write_plan_outputs(d, run.plan, wind=run.wind, plot=False))
            if plots:
                from sailroute.report.html import plan_report
                from sailroute.report.page_render import PLOTLY_FILE, write_report

                html = write_report(d / "report.html", plan_report(run.plan, run.wind))
                files["png"] = png.result()
                files["html"] = html
                files["plotly_js"] = d / PLOTLY_FILE
            return files

        files = write_output_set(out, write)
    return CommandResult(
        plan_table(run.plan), files, data=run.plan, notes=run.notes, main=("plan",)
    )


def _run_ensemble(
    course: Course,
    name: str,
    *,
    out_dir: str | Path | None,
    options: RunOptions,
    plots: bool = True,
) -> CommandResult:
    """``sailroute plan`` on an ensemble scenario: every member, then the spread."""
    from sailroute.report.ensemble import ensemble_table, summarize_ensemble, write_ensemble
    from sailroute.report.files import write_plan_outputs

    cmp, plans, winds = route_scenarios(course, [name], options, batch=True)
    summary = summarize_ensemble(name, plans, winds)
    out = Path(out_dir) if out_dir is not None else default_out_dir(course, name, options.router)

    def write(d: Path) -> dict[str, Path]:
        files: dict[str, Path] = dict(write_ensemble(d, summary))
        if plots:
            from sailroute.report.html import comparison_report
            from sailroute.report.page_render import PLOTLY_FILE, write_report

            files["html"] = write_report(d / "report.html", comparison_report(cmp, plans, winds))
            files["plotly_js"] = d / PLOTLY_FILE
        for p in plans:
            sub = d / safe_part(p.scenario, "scenario")
            for kind, path in write_plan_outputs(sub, p, plot=False).items():
                files[f"{p.scenario}/{kind}"] = path
        return files

    return CommandResult(
        ensemble_table(summary),
        write_output_set(out, write),
        data=tuple(plans),
        main=("ensemble_json",),
    )


def run_compare_command(
    course: Course | str | Path,
    *,
    scenarios: Sequence[str] | None = None,
    out_dir: str | Path | None = None,
    plots: bool = True,
    options: RunOptions = DEFAULT_RUN,
) -> CommandResult:
    """Everything ``sailroute compare-scenarios`` does, minus printing.

    Writes ``comparison.json``, ``comparison.csv``, ``comparison.png`` and ``report.html``
    (the last two unless ``plots`` is False) into ``out_dir`` (default
    ``out/<course>/comparison``), and
    each scenario's ``plan.json``, ``track.csv`` and ``route.gpx`` into
    ``out_dir/<scenario>/``; for each ensemble whose members were all routed, its
    spread in ``out_dir/<ensemble>/ensemble.json`` and ``ensemble.csv``.
    """
    from sailroute.report.ensemble import ensemble_table, summarize_ensemble, write_ensemble
    from sailroute.report.files import write_comparison, write_plan_outputs
    from sailroute.report.tables import comparison_table

    course = _loaded(course)
    out = check_out_dir(
        Path(out_dir)
        if out_dir is not None
        else default_out_dir(course, "comparison", options.router)
    )
    cmp, plans, winds = route_scenarios(course, scenarios, options)
    report = [comparison_table(cmp)]
    by_name = {p.scenario: p for p in plans}
    summaries = [
        summarize_ensemble(ens, [by_name[m] for m in members], winds)
        for ens, members in course.ensembles.items()
        if all(m in by_name for m in members)
    ]
    report += [ensemble_table(summary) for summary in summaries]

    def write(d: Path) -> dict[str, Path]:
        js, cs = write_comparison(d, cmp)
        files: dict[str, Path] = {"comparison_json": js, "comparison_csv": cs}
        if plots:
            from sailroute.report.html import comparison_report
            from sailroute.report.page_render import PLOTLY_FILE, write_report
            from sailroute.report.plots import plot_comparison

            plot_comparison(cmp, plans).savefig(d / "comparison.png", dpi=150)
            files["comparison_png"] = d / "comparison.png"
            files["html"] = write_report(d / "report.html", comparison_report(cmp, plans, winds))
            files["plotly_js"] = d / PLOTLY_FILE
        for p in plans:
            sub = d / safe_part(p.scenario, "scenario")
            for kind, path in write_plan_outputs(sub, p, plot=False).items():
                files[f"{p.scenario}/{kind}"] = path
        for summary in summaries:
            sub = d / safe_part(summary.name, "scenario")
            for kind, path in write_ensemble(sub, summary).items():
                files[f"{summary.name}/{kind}"] = path
        return files

    return CommandResult(
        "\n\n".join(report),
        write_output_set(out, write),
        data=(cmp, tuple(plans)),
        main=("comparison_json",),
    )
