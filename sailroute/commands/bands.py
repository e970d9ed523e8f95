"""``plan --ensemble N`` / ``compare-scenarios --ensemble N``: leg-time bands of scenarios.

The members come from :mod:`sailroute.bands.members` (the course's ``uncertainty``
section, or :data:`~sailroute.course.uncertainty.DEFAULT_UNCERTAINTY`);
:func:`route_members` routes a list of members one by one with the course's router
(any function with its signature can route them instead, e.g. a batched router); the
bands, the one-at-a-time breakdown and the side verdicts are
:class:`~sailroute.bands.summary.BandSummary`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sailroute.bands.members import (
    NOMINAL,
    Member,
    draw_members,
    member_boat,
    member_wind,
    one_at_a_time,
    resolve_shifts,
)
from sailroute.bands.summary import BandSummary
from sailroute.commands.plan import default_out_dir
from sailroute.commands.result import CommandResult
from sailroute.course.load import build_current, build_specs, load_course
from sailroute.course.model import Course
from sailroute.course.uncertainty import DEFAULT_UNCERTAINTY, UncertaintySpec
from sailroute.errors import InputError
from sailroute.outdir import check_out_dir, write_output_set
from sailroute.planning.route import (
    DEFAULT_RUN,
    RunOptions,
    check_boat_and_winds,
    route_course,
    settings_for,
)
from sailroute.progress import Progress
from sailroute.report.ensemble import honest_side
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import LegResult
from sailroute.wind.base import WindField

__all__ = ["RouteMembers", "band_summary", "route_members", "run_bands_command", "spec_for"]

RouteMembers = Callable[..., list[list[LegResult]]]
"""``route(course, scenario, members, *, wind, boat, settings, backend, progress)``:
leg results of each member, in order."""


def spec_for(course: Course, n: int | None = None) -> tuple[UncertaintySpec, tuple[str, ...]]:
    """The course's uncertainty (or the defaults), with ``n`` members if given, shifts fitted.

    Returns
    -------
    spec : UncertaintySpec
    notes : tuple of str
        Says when the defaults were used.
    """
    notes: tuple[str, ...] = ()
    spec = course.uncertainty
    if spec is None:
        spec = DEFAULT_UNCERTAINTY
        notes = (
            "the course has no `uncertainty:` section: default uncertainties (TWS 1 kn, "
            "TWD 5° 1 sigma, shifts ±5° every 6 min; docs/course-format.md)",
        )
    if n is not None:
        spec = spec.with_members(n)
    return resolve_shifts(spec), notes


def route_members(
    course: Course,
    scenario: str,
    members: Sequence[Member],
    *,
    wind: WindField,
    boat: Any,
    settings: RoutingSettings,
    backend: str = "numpy",
    progress: Progress | None = None,
) -> list[list[LegResult]]:
    """Route the course once per member, one after the other.

    Parameters
    ----------
    course : Course
        The course.
    scenario : str
        The scenario (its current, if any, is used for every member).
    members : sequence of Member
        The members (:func:`sailroute.bands.members.draw_members`).
    wind : WindField
        The scenario's built wind.
    boat : Polar
        The course's built boat.
    settings : RoutingSettings
        Router and its settings.
    backend : str
        Array backend of the router kernels.
    progress : Progress, optional
        Per-leg progress, prefixed with the member's name.

    Returns
    -------
    list of list of LegResult
        Per member, its legs.
    """
    current = build_current(course, scenario)
    where = course.boat_where or str(course.source or "<course>")
    out = []
    for m in members:
        if progress is not None:
            progress.set_prefix(f"{scenario} {m.name}: ")
        w = member_wind(wind, m, course.start_epoch)
        b = member_boat(course.boat_spec, boat, m, base_dir=course.base_dir, where=where)
        out.append(
            route_course(
                course, w, b, settings, backend=backend, progress=progress, current=current
            )
        )
    return out


def _times(results: Sequence[Sequence[LegResult]]) -> np.ndarray:
    return np.array([[r.time_s for r in legs] for legs in results], dtype=float)


def band_summary(
    course: Course,
    scenario: str,
    spec: UncertaintySpec,
    *,
    wind: WindField,
    boat: Any,
    settings: RoutingSettings,
    backend: str = "numpy",
    progress: Progress | None = None,
    route: RouteMembers = route_members,
    notes: Sequence[str] = (),
    oat: bool = True,
) -> BandSummary:
    """Route a scenario's members (main ensemble, nominal, one-at-a-time) and summarize.

    Parameters
    ----------
    course, scenario, wind, boat, settings, backend, progress
        As :func:`route_members`.
    spec : UncertaintySpec
        The uncertainty (shifts resolved: :func:`spec_for`).
    route : callable
        Routes a member list (default :func:`route_members`).
    notes : sequence of str
        Carried into the summary.
    oat : bool
        Also route the one-at-a-time members (the breakdown by source).

    Returns
    -------
    BandSummary
    """
    main = draw_members(spec, course.time_limit_s)
    oat_members = one_at_a_time(spec, course.time_limit_s) if oat else {}
    flat = [NOMINAL, *main, *(m for ms in oat_members.values() for m in ms)]
    # a one-at-a-time member equal to the nominal one (a source's median) is not routed twice
    key = {m.name: dataclasses.replace(m, name="") for m in flat}
    unique: dict[Member, Member] = {}
    for m in flat:
        unique.setdefault(key[m.name], m)
    todo = list(unique.values())
    results = route(
        course,
        scenario,
        todo,
        wind=wind,
        boat=boat,
        settings=settings,
        backend=backend,
        progress=progress,
    )
    by_key = {key[m.name]: r for m, r in zip(todo, results, strict=True)}
    res_of = {m.name: by_key[key[m.name]] for m in flat}
    where = course.boat_where or str(course.source or "<course>")
    sides = []
    for m in main:
        w = member_wind(wind, m, course.start_epoch)
        b = member_boat(course.boat_spec, boat, m, base_dir=course.base_dir, where=where)
        sides.append(
            tuple(
                honest_side(
                    r,
                    w,
                    b,
                    tack_penalty_s=settings.tack_penalty_s,
                    gybe_penalty_s=settings.gybe_penalty_s,
                    margin_s=spec.side_margin_s,
                    margin_pct=spec.side_margin_pct,
                )
                for r in res_of[m.name]
            )
        )
    return BandSummary(
        scenario=scenario,
        leg_labels=tuple(leg.label for leg in course.legs),
        members=tuple(m.name for m in main),
        times_s=_times([res_of[m.name] for m in main]),
        nominal_s=_times([res_of[NOMINAL.name]])[0],
        oat_s={s: _times([res_of[m.name] for m in ms]) for s, ms in oat_members.items()},
        sides=tuple(sides),
        references=course.references_for(scenario),
        uncertainty=spec,
        notes=tuple(notes),
        nominal_legs=tuple(res_of[NOMINAL.name]),
    )


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
        only be None or ``"serial"``: the members are routed here, one after the other.
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
    from sailroute.report.page_render import write_report

    router, backend, progress = options.router, options.backend, options.progress
    scheduler = options.scheduler

    if members is not None and members < 3:
        raise InputError(f"--ensemble {members}: a band needs at least 3 members; give N >= 3")
    if scheduler not in (None, "serial"):
        raise InputError(
            f"--scheduler {scheduler}: --ensemble routes its members here, one "
            "after the other; leave out --scheduler (or use serial)"
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
            files["html"] = write_report(
                d / "report.html", bands_page(course, summaries, winds, router=settings.router)
            )
        return files

    files = write_output_set(out, write)
    return CommandResult(
        "\n\n".join(bands_table(b) for b in summaries),
        files,
        summaries,
        notes=tuple(warn.values()),
        main=("bands_json",),
    )
