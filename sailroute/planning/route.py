"""Route a whole course in one wind scenario, or in several.

A loaded
:class:`~sailroute.course.model.Course` gives the boat and the scenario's wind
(``course/load.py``), each leg is routed with
:func:`~sailroute.routing.api.route_leg` starting where and when the previous leg
ended, and the results become a :class:`~sailroute.planning.result.Plan`.  Nothing
here reads files except through those factories, and nothing prints: progress
goes to an optional :class:`~sailroute.progress.Progress`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from sailroute.backend import get_xp
from sailroute.boat.model import BoatModel
from sailroute.boat.polar import Polar
from sailroute.boat.sanity import check_wind_range, peak_wind, require_speed
from sailroute.course.geometry import course_bbox, leg_endpoints, race_time_window, target_of
from sailroute.course.load import build_current, build_specs
from sailroute.course.model import Course
from sailroute.errors import InputError, format_problems
from sailroute.parallel import SERIAL, check_scheduler, map_tasks
from sailroute.planning.result import Comparison, Plan, compare, make_plan
from sailroute.progress import Progress
from sailroute.routing.api import check_current_router, get_router, route_leg
from sailroute.routing.geometry import chain_leg
from sailroute.routing.obstacles import RaceArea, land_filled, obstacles_for
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import LegResult, RouterName, Start
from sailroute.wind.base import WindField
from sailroute.wind.build import wind_notes
from sailroute.wind.current import CurrentField


@dataclass(frozen=True)
class RunOptions:
    """How to run a plan: which router, on which array backend, where to report, where to run.

    Attributes
    ----------
    router : str, optional
        ``"isochrone"``, ``"griddp"`` or ``"spline"``; overrides the course's
        ``routing.router``.  None: the course's own.
    backend : {"numpy", "cupy", "auto"}
        Array backend of the router kernels.
    progress : Progress, optional
        Per-leg progress display (serial runs only).
    scheduler : str, optional
        None or ``"serial"``: scenarios one after the other here; ``"processes"``: a local
        Dask cluster; ``"tcp://HOST:PORT"``: an existing Dask scheduler
        (``docs/scale-out.md``).  The results are identical.
    """

    router: str | None = None
    backend: str = "numpy"
    progress: Progress | None = None
    scheduler: str | None = None


DEFAULT_RUN = RunOptions()
"""The course's router, NumPy, no progress display, serial."""


@dataclass(frozen=True, eq=False)
class PlannedCourse:
    """A :class:`Plan` with the wind field it was routed in (for plots).

    Attributes
    ----------
    plan : Plan
        The routed course.
    wind : WindField
        The scenario's wind field.
    notes : tuple of str
        Warnings about the run (e.g. wind above the polar's range, allowed by
        ``boat.allow_extrapolation``); also sent to the progress display.
    """

    plan: Plan
    wind: WindField
    notes: tuple[str, ...] = ()


def settings_for(
    course: Course, router: str | None = None, backend: str = "numpy"
) -> RoutingSettings:
    """The course's routing settings, with the router replaced if ``router`` is given.

    Raises
    ------
    InputError
        Unknown router or backend name (checked here, before any work is done).
    """
    settings = (
        course.routing
        if router is None
        else dataclasses.replace(course.routing, router=cast(RouterName, router))
    )  # the name is checked just below
    get_router(settings.router)
    get_xp(backend)
    return settings


def check_boat_and_winds(
    course: Course, boat: Polar, winds: Mapping[str, WindField]
) -> dict[str, str]:
    """Polar sanity for every built scenario, before any routing (``docs/usage.md``).

    The boat must have some speed, and each scenario's wind over the course area
    (marks plus a margin, 25 x 25 points) every 5 min over the race window must stay
    within the polar's TWS columns (:mod:`sailroute.boat.sanity`), unless the
    course's ``boat`` block says ``allow_extrapolation: true``.

    Parameters
    ----------
    course : Course
        The course (area, race time window, ``boat.allow_extrapolation``).
    boat : Polar
        The built boat.
    winds : mapping of str to WindField
        Scenario name -> built wind.

    Returns
    -------
    dict of str to str
        Scenario name -> warning, for scenarios whose wind exceeds the polar
        where extrapolation is allowed.

    Raises
    ------
    InputError
        The boat has no speed, or the wind exceeds the polar in some scenarios
        (all of them listed) and extrapolation is not allowed.
    """
    boat_where = course.boat_where or (str(course.source) if course.source else "<course>")
    require_speed(boat, f"{boat_where}: boat")
    allow = course.boat_spec.get("allow_extrapolation", False) is True
    bbox, window = course_bbox(course), race_time_window(course)
    notes: dict[str, str] = {}
    problems: list[str] = []
    for name, wind in winds.items():
        sc = course.scenarios[name]
        where = sc.where or course.where(f"scenarios.{name}")
        try:
            note = check_wind_range(
                boat, peak_wind(wind, bbox, window), allow_extrapolation=allow, where=where
            )
        except InputError as exc:
            problems.append(str(exc))
            continue
        if note is not None:
            notes[name] = note
    if len(problems) == 1:
        raise InputError(problems[0])
    if problems:
        raise InputError(
            format_problems(
                f"{course.source or '<course>'}: the wind exceeds the polar in {len(problems)} "
                "scenarios",
                problems,
            )
        )
    return notes


def _warn(progress: Progress | None, notes: Mapping[str, str]) -> None:
    if progress is not None:
        for note in notes.values():
            progress.warn(note)


def default_scenario(course: Course) -> str:
    """The first scenario of the course file (the one ``plan`` routes by default; an
    ensemble's own name if the first one is an ensemble)."""
    return course.scenario_names[0]


def scenario_members(course: Course, names: Sequence[str]) -> list[str]:
    """``names`` with each ensemble replaced by its members (order kept, no repeats)."""
    ens = course.ensembles
    out: list[str] = []
    for n in names:
        out.extend(ens.get(n, (n,)))
    return list(dict.fromkeys(out))


def route_course(
    course: Course,
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
    *,
    backend: str = "numpy",
    progress: Progress | None = None,
    current: object | None = None,
    from_leg: int = 0,
    under_way: tuple[tuple[float, float], float] | None = None,
) -> list[LegResult]:
    """Route every leg in order, each starting where and when the previous one ended.

    Parameters
    ----------
    course : Course
        The course (its first leg may start anywhere on a line; the router picks
        the best point).
    wind : WindField
        Wind field covering the course and the race time.
    boat : BoatModel
        Boat performance (a :class:`~sailroute.boat.polar.Polar` or, for the grid
        routers, a :class:`~sailroute.boat.dynamic.DynamicBoat`).
    settings : RoutingSettings
        Router choice and numerical settings.
    backend : {"numpy", "cupy", "auto"}
        Array backend of the router kernels.
    progress : Progress, optional
        Receives per-leg start/update/end calls.
    current : CurrentField, optional
        Surface current (isochrone router only); None: still water.
    from_leg : int
        First leg to route (0-based); the legs before it are left out of the result.
    under_way : ((float, float), float), optional
        A boat under way: its position ``(x, y)`` [m] and time [epoch s], where and when
        leg ``from_leg`` starts (instead of that leg's start feature at the start time).

    Returns
    -------
    list of LegResult
        One per leg routed; ``results[i].t_start == results[i - 1].t_end`` and
        ``results[i].start_xy == results[i - 1].end_xy``.  A leg to a mark ends once
        the mark is rounded on its side, and the next leg may not cross back.  Every
        leg stays inside the course's boundary and round its obstacles
        (:func:`~sailroute.routing.obstacles.obstacles_for`).
    """
    results: list[LegResult] = []
    obstacles = obstacles_for(course.area, wind)
    wind = land_filled(course.area, wind)  # the NaN (land) cells, now obstacles, filled
    for i in range(from_leg, course.n_legs):
        spec = course.legs[i]
        previous = results[-1] if results else None
        # chain_leg starts the leg at the previous arrival; a mark is rounded on its side:
        # the leg ends past the rounding (towards the next target) and the next leg may not
        # cross back (routing/geometry.py)
        following = target_of(course, i + 1) if i + 1 < course.n_legs else None
        ends = leg_endpoints(course, i)
        t0 = previous.t_end if previous is not None else course.start_epoch
        if previous is None and under_way is not None:
            ends = (Start(under_way[0], None, name="boat"), ends[1])
            t0 = under_way[1]
        start, target = chain_leg(*ends, previous, following)
        if progress is not None:
            progress.start_leg(i, spec.label)
        res = route_leg(
            start,
            target,
            t0,
            wind,
            boat,
            settings,
            backend=backend,
            progress=progress.update if progress is not None else None,
            current=current,
            obstacles=obstacles,
        )
        if progress is not None:
            progress.end_leg(res.time_s, f"{res.n_tacks} tacks, {res.n_gybes} gybes")
        results.append(res)
    return results


def route_course_batch(
    course: Course,
    winds: Sequence[WindField],
    boat: BoatModel | Sequence[BoatModel],
    settings: RoutingSettings,
    *,
    progress: Progress | None = None,
    current: CurrentField | None = None,
) -> list[list[LegResult]]:
    """Route every leg of ``course`` for every member wind, leg by leg as one front.

    The batched counterpart of :func:`route_course` (isochrone router, NumPy, open
    water): each member's leg starts where and when its previous leg ended.

    Parameters
    ----------
    course : Course
        The course.
    winds : sequence of WindField
        One wind per member.
    boat : BoatModel or sequence of BoatModel
        The boat, or one per member.
    settings : RoutingSettings
        Isochrone settings.
    progress : Progress, optional
        Counts the members (routed together); per leg: ``start_leg``, ``update`` (share
        of the leg done, members arrived) and ``end_leg`` (the members' median leg time).
    current : CurrentField, optional
        Surface current of every member; None: still water.

    Returns
    -------
    list of list of LegResult
        Per member, its legs in order.
    """
    from sailroute.routing.batch import route_leg_batch  # not loaded by a single plan

    results: list[list[LegResult]] = [[] for _ in winds]
    if progress is not None:
        progress.start_count(len(winds), "member", together=True)
    for i, spec in enumerate(course.legs):
        following = target_of(course, i + 1) if i + 1 < course.n_legs else None
        ends = leg_endpoints(course, i)
        target = chain_leg(*ends, None, following)[1]
        starts = [chain_leg(*ends, legs[-1] if legs else None, following)[0] for legs in results]
        t0s = [legs[-1].t_end if legs else course.start_epoch for legs in results]
        if progress is not None:
            progress.start_leg(i, spec.label)
        done = route_leg_batch(
            starts,
            target,
            t0s,
            winds,
            boat,
            settings,
            progress=progress.update if progress is not None else None,
            current=current,
        )
        if progress is not None:
            progress.end_leg(
                float(np.median([r.time_s for r in done])), f"median of {len(done)} members"
            )
        for legs, res in zip(results, done, strict=True):
            legs.append(res)
    return results


def plan_course(
    course: Course,
    scenario: str | None = None,
    options: RunOptions = DEFAULT_RUN,
) -> PlannedCourse:
    """Route ``course`` in one of its wind scenarios.

    Parameters
    ----------
    course : Course
        A loaded course (:func:`sailroute.course.load.load_course`).
    scenario : str, optional
        Scenario name; default the first one in the file.
    options : RunOptions, optional
        Router, backend and progress display (the scheduler is not used: one scenario).

    Returns
    -------
    PlannedCourse

    Raises
    ------
    InputError
        Unknown scenario or router, bad boat or wind spec (all problems listed),
        wind above the polar's highest TWS (:func:`check_boat_and_winds`).
    OutOfCoverageError
        The wind data do not cover the course area or the race time.
    RoutingError
        A leg cannot be routed (the message names it).
    """
    name = default_scenario(course) if scenario is None else scenario
    if name in course.ensembles:
        raise InputError(
            f"{course.where('scenarios.' + name)}: {name!r} is an ensemble of "
            f"{len(course.ensembles[name])} members; route them all with "
            "`sailroute plan --scenario NAME` (run_plan_command) or compare_scenarios, or "
            f"one member by its name ({course.ensembles[name][0]!r}, ...)"
        )
    settings = settings_for(course, options.router, options.backend)
    boat, winds = build_specs(course, [name])
    notes = check_boat_and_winds(course, boat, winds)
    _warn(options.progress, notes)
    run = _routed(course, name, winds[name], boat, settings, options)
    return dataclasses.replace(run, notes=tuple(notes.values()))


def _routed(
    course: Course,
    name: str,
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
    options: RunOptions,
) -> PlannedCourse:
    """Route the course in one built scenario and assemble its :class:`Plan`."""
    progress = options.progress
    if progress is not None:
        for line in wind_notes(wind):
            progress.note(line)
    current = build_current(course, name)
    if current is not None:
        check_current_router(settings.router)
    results = route_course(
        course, wind, boat, settings, backend=options.backend, progress=progress, current=current
    )
    return PlannedCourse(_plan_of(course, name, results, wind, boat, settings), wind)


def _plan_of(
    course: Course,
    name: str,
    results: Sequence[LegResult],
    wind: WindField,
    boat: BoatModel,
    settings: RoutingSettings,
) -> Plan:
    """The :class:`Plan` of routed legs, with the start line's numbers and the laylines
    (:mod:`sailroute.planning.startline`)."""
    from sailroute.planning.startline import course_laylines, course_start_line_numbers

    plan = make_plan(course, name, list(results), wind, router=settings.router)
    return dataclasses.replace(
        plan,
        start_line=course_start_line_numbers(course, wind, boat),
        laylines=course_laylines(course, [(pl.mode, pl.result) for pl in plan.legs], wind, boat),
    )


def _scenario_done(progress: Progress | None, names: Sequence[str]) -> Any:
    """A line per scenario as it comes back from a worker (``scenario 2 of 5 done
    (wrf10): ...``), or None without a progress display."""
    if progress is None:
        return None
    progress.start_count(len(names), "scenario")
    done = [0]

    def report(k: int, plan: Plan) -> None:
        done[0] += 1
        progress.item_done(done[0], f"{names[k]}, {plan.total_time_s:.1f} s")

    return report


def _plan_task(task: tuple[Course, str, str | None, str]) -> Plan:
    """One scenario of :func:`compare_scenarios` (top level, so Dask can pickle it)."""
    course, name, router, backend = task
    return plan_course(course, name, RunOptions(router=router, backend=backend)).plan


def compare_scenarios(
    course: Course,
    scenarios: Sequence[str] | None = None,
    options: RunOptions = DEFAULT_RUN,
) -> tuple[Comparison, list[Plan]]:
    """Route ``course`` in several scenarios and put the leg times side by side.

    Parameters
    ----------
    course : Course
        A loaded course.
    scenarios : sequence of str, optional
        Scenario names, in the order to report them; default all, in file order.
    options : RunOptions, optional
        Router, backend, progress display (serial runs only; a distributed run reports
        nothing until all scenarios are back) and scheduler.

    Returns
    -------
    comparison : Comparison
        Leg times (scenarios × legs) with the references.
    plans : list of Plan
        One per scenario, in the same order.
    """
    cmp, plans, _ = route_scenarios(course, scenarios, options)
    return cmp, plans


def route_scenarios(
    course: Course,
    scenarios: Sequence[str] | None = None,
    options: RunOptions = DEFAULT_RUN,
    *,
    batch: bool = False,
) -> tuple[Comparison, list[Plan], dict[str, WindField]]:
    """:func:`compare_scenarios`, plus the scenarios' built winds (for ``report.html``);
    ``batch``: route the scenarios together (:func:`~sailroute.routing.batch.batchable`)."""
    router, backend, progress = options.router, options.backend, options.progress
    names = list(course.scenarios) if not scenarios else scenario_members(course, scenarios)
    settings = settings_for(course, router, backend)
    where = check_scheduler(options.scheduler)  # a bad name fails before any work
    # every problem of every scenario in one error, up front
    boat, winds = build_specs(course, names)
    _warn(progress, check_boat_and_winds(course, boat, winds))
    open_water = course.area == RaceArea()  # the batch routes without a race area
    from sailroute.routing.batch import batchable  # not loaded by a single plan

    if (
        where == SERIAL
        and batch
        and open_water
        and batchable(settings, backend, [build_current(course, n) for n in names])
    ):
        # the members as one front per leg (routing/batch.py)
        results = route_course_batch(
            course, [winds[n] for n in names], boat, settings, progress=progress
        )
        plans = [
            _plan_of(course, n, r, winds[n], boat, settings)
            for n, r in zip(names, results, strict=True)
        ]
    elif where == SERIAL:
        plans = []
        for n in names:
            if progress is not None:
                progress.set_prefix(f"{n}: ")
            plans.append(_routed(course, n, winds[n], boat, settings, options).plan)
    else:
        # workers build their own scenario (a wind field is not worth shipping)
        plans = map_tasks(
            _plan_task,
            [(course, n, router, backend) for n in names],
            scheduler=where,
            on_done=_scenario_done(progress, names),
        )
    return compare(plans), plans, winds
