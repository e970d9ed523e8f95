"""Route the members of a scenario's leg-time bands and summarize them.

The members come from :mod:`sailroute.bands.members` (the course's ``uncertainty``
section, or :data:`~sailroute.course.uncertainty.DEFAULT_UNCERTAINTY`);
:func:`route_together` routes a list of members as one front per leg (the isochrone
router on NumPy in open water: :func:`~sailroute.planning.route.route_course_batch`,
each member with its own wind, shift series and boat, all in the scenario's current),
:func:`route_members` one by one with the course's router (any router, backend or race
area; any function with their signature can route them instead);
:func:`band_summary` routes the main ensemble, the nominal member and the one-at-a-time
members and returns the bands, the breakdown and the side verdicts as a
:class:`~sailroute.bands.summary.BandSummary`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from sailroute.bands.members import (
    NOMINAL,
    Member,
    check_ensemble_size,
    draw_members,
    member_boat,
    member_wind,
    one_at_a_time,
    resolve_shifts,
)
from sailroute.bands.sides import honest_sides
from sailroute.bands.summary import BandSummary, member_track
from sailroute.course.load import build_current
from sailroute.course.model import Course
from sailroute.course.uncertainty import DEFAULT_UNCERTAINTY, PolarSpread, UncertaintySpec
from sailroute.planning.route import route_course, route_course_batch
from sailroute.progress import Progress
from sailroute.routing.batch import batchable
from sailroute.routing.obstacles import RaceArea
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import LegResult
from sailroute.wind.base import WindField

__all__ = [
    "RouteMembers",
    "band_summary",
    "polar_spread",
    "route_members",
    "route_together",
    "spec_for",
]


RouteMembers = Callable[..., list[list[LegResult]]]
"""``route(course, scenario, members, *, wind, boat, settings, backend, progress)``:
leg results of each member, in order."""


def spec_for(course: Course, n: int | None = None) -> tuple[UncertaintySpec, tuple[str, ...]]:
    """The course's uncertainty (or the defaults), with ``n`` members if given, shifts
    fitted, and the course's learned polar as a source (:func:`polar_spread`).

    Returns
    -------
    spec : UncertaintySpec
    notes : tuple of str
        Says when the defaults were used, and when the members draw the polar.
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
    spread = polar_spread(course) if spec.draw_polar else None
    if spread is not None:
        spec = dataclasses.replace(spec, polar=spread)
        notes += (
            f"the boat is a polar learned from a fleet ({spread.file.name}, level "
            f"{spread.level}): each member draws its table from the bootstrap's "
            f"uncertainty (median cell sd {100 * spread.sd_log:.1f} %) and the legs' "
            f"scatter about the race pace ({100 * spread.pace_sd_log:.1f} %); "
            "`uncertainty: {polar: false}` keeps it fixed",
        )
    return resolve_shifts(spec), notes


def polar_spread(course: Course) -> PolarSpread | None:
    """The course's boat as a band source, when it is a polar learned by ``sailroute polar
    fit`` (None otherwise)."""
    from sailroute.boat.build import learned_boat

    found = learned_boat(course.boat_spec, course.base_dir)
    if found is None:
        return None
    from sailroute.boat.learnfile import read_learned

    lp = read_learned(found[0])
    t = lp.level(found[1])
    learned = t.sd_log[lp.status == "learned"]
    return PolarSpread(
        file=found[0],
        level=found[1],
        modes=int(t.modes.shape[0]),
        sd_log=float(np.median(learned)) if learned.size else 0.0,
        pace_sd_log=float(t.pace_sd_log or 0.0),
    )


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
    if progress is not None:
        progress.start_count(len(members), "member")
    out = []
    for k, m in enumerate(members):
        if progress is not None:
            progress.start_item(k, f"{scenario} {m.name}")
        w, b = _member_inputs(course, m, wind, boat)
        out.append(
            route_course(
                course, w, b, settings, backend=backend, progress=progress, current=current
            )
        )
    if progress is not None:
        progress.set_prefix("")
        progress.item_done(len(members), scenario)
    return out


def route_together(
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
    """Route the course for every member at once: one front per leg.

    As :func:`route_members` (the same parameters and results; the first leg's times the
    same bit for bit, the later legs' within the batch's tolerance:
    :mod:`sailroute.routing.batch`), through
    :func:`~sailroute.planning.route.route_course_batch`: each member with its own wind
    (speed, direction, shift series) and boat, all in the scenario's current.  Where the
    batch cannot route the course (another router or array backend, a race area) the
    members are routed one by one (:func:`route_members`).
    """
    current = build_current(course, scenario)
    if not (batchable(settings, backend, [current]) and course.area == RaceArea()):
        return route_members(
            course,
            scenario,
            members,
            wind=wind,
            boat=boat,
            settings=settings,
            backend=backend,
            progress=progress,
        )
    inputs = [_member_inputs(course, m, wind, boat) for m in members]
    if progress is not None:
        progress.set_prefix(f"{scenario}: ")
    out = route_course_batch(
        course,
        [w for w, _ in inputs],
        [b for _, b in inputs],
        settings,
        progress=progress,
        current=current,
    )
    if progress is not None:
        progress.set_prefix("")
    return out


def _member_inputs(course: Course, m: Member, wind: WindField, boat: Any) -> tuple[Any, Any]:
    """A member's wind and boat (:func:`~sailroute.bands.members.member_wind`,
    :func:`~sailroute.bands.members.member_boat`)."""
    where = course.boat_where or str(course.source or "<course>")
    w = member_wind(wind, m, course.start_epoch)
    return w, member_boat(course.boat_spec, boat, m, base_dir=course.base_dir, where=where)


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
    route: RouteMembers = route_together,
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
        Routes a member list (default :func:`route_together`: all of them as one front
        per leg).
    notes : sequence of str
        Carried into the summary.
    oat : bool
        Also route the one-at-a-time members (the breakdown by source).

    Returns
    -------
    BandSummary

    Raises
    ------
    InputError
        More members than fit in memory (:func:`~sailroute.bands.members.check_ensemble_size`).
    """
    check_ensemble_size(spec, spec.members, course.time_limit_s, course.n_legs)
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
    inputs = [_member_inputs(course, m, wind, boat) for m in main]
    sides = honest_sides(
        [res_of[m.name] for m in main],
        [w for w, _ in inputs],
        [b for _, b in inputs],
        tack_penalty_s=settings.tack_penalty_s,
        gybe_penalty_s=settings.gybe_penalty_s,
        margin_s=spec.side_margin_s,
        margin_pct=spec.side_margin_pct,
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
        member_tracks=tuple(member_track(res_of[m.name]) for m in main),
    )
