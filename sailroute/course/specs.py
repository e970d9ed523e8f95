"""Build a course's boat, wind and current from its specs (the factories' entry points).

A :class:`~sailroute.course.model.Course` keeps its boat spec raw and its wind and
current specs parsed (:mod:`sailroute.wind.specs`, checked when the course loads);
these functions hand them to their factories (:mod:`sailroute.boat.build`,
:mod:`sailroute.wind.build`) with the course's folder, local frame, bounding box, race
time window and line map, so that every problem is reported as
``file:line: key.path: ...``.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from sailroute.checks import suggest
from sailroute.course.model import Course
from sailroute.errors import InputError, format_problems

__all__ = ["build_boat", "build_current", "build_specs", "build_wind", "validate_specs"]


def build_boat(course: Course) -> Any:
    """Build the boat :class:`~sailroute.boat.polar.Polar` from ``course.boat_spec``.

    Uses ``sailroute.boat.build.boat_from_spec``; relative paths resolve against the
    course file's folder.
    """
    from sailroute.boat.build import boat_from_spec

    where = course.boat_where or (str(course.source) if course.source else "<course>")
    return boat_from_spec(
        dict(course.boat_spec),
        base_dir=course.base_dir,
        where=where,
        key="boat",
        lines=course.key_lines,
    )


def build_wind(course: Course, scenario: str) -> Any:
    """Build the :class:`~sailroute.wind.base.WindField` of one scenario.

    The field is cropped to the marks' bounding box and must cover the race time
    window ``[start_time, start_time + time_limit_min]`` (see
    :func:`sailroute.course.geometry.race_time_window`).

    Raises
    ------
    InputError
        Unknown scenario name (with the valid ones), or a bad wind spec.
    OutOfCoverageError
        The wind data do not cover the course or the race time.
    """
    from sailroute.course.geometry import course_bbox, race_time_window
    from sailroute.wind.build import build_wind_field

    if scenario not in course.scenarios:
        names = list(course.scenarios)
        raise InputError(
            f"{course.where('scenarios')}: no scenario {scenario!r}; "
            f"{suggest(scenario, names)}scenarios are: {', '.join(names)}"
        )
    return build_wind_field(
        course.scenarios[scenario].wind,
        frame=course.frame,
        crop_bbox=course_bbox(course),
        time_window=race_time_window(course),
    )


def build_current(course: Course, scenario: str) -> Any:
    """Build the surface current of one scenario (:mod:`sailroute.wind.current`), or None.

    Like :func:`build_wind`: relative paths resolve against the course file's folder
    and the current must cover the course box and the race time window.
    """
    from sailroute.course.geometry import course_bbox, race_time_window
    from sailroute.wind.build import build_current_field

    sc = course.scenarios.get(scenario)
    if sc is None or sc.current is None:  # (an unknown name is build_wind's error)
        return None
    return build_current_field(
        sc.current,
        frame=course.frame,
        crop_bbox=course_bbox(course),
        time_window=race_time_window(course),
    )


def build_specs(
    course: Course, scenarios: Iterable[str] | None = None
) -> tuple[Any, dict[str, Any]]:
    """Build the boat and each scenario's wind once, reporting all problems together.

    Parameters
    ----------
    course : Course
        A loaded course.
    scenarios : iterable of str, optional
        Scenario names to build (default: all).

    Returns
    -------
    boat : Polar
        As :func:`build_boat`.
    winds : dict of str to WindField
        Scenario name -> wind field, as :func:`build_wind`.

    Raises
    ------
    InputError
        One error listing every boat/wind spec problem (each with its key path); a
        single problem keeps its own type (e.g. ``OutOfCoverageError``).
    """
    errors: list[InputError] = []
    boat, winds = None, {}
    try:
        boat = build_boat(course)
    except InputError as exc:
        errors.append(exc)
    for name in course.scenarios if scenarios is None else scenarios:
        try:
            winds[name] = build_wind(course, name)
        except InputError as exc:
            errors.append(exc)
        try:  # validated here with the winds; plan.py builds it again to route
            build_current(course, name)
        except InputError as exc:
            errors.append(exc)
    if len(errors) == 1:  # keep its type (e.g. OutOfCoverageError) and message
        raise errors[0]
    problems = [p for exc in errors for p in _flatten(str(exc))]
    if problems:
        raise InputError(
            format_problems(
                f"{course.source or '<course>'}: {len(problems)} problems in boat/wind specs",
                problems,
            )
        )
    return boat, winds


def validate_specs(course: Course, scenarios: Iterable[str] | None = None) -> None:
    """:func:`build_specs`, keeping only its errors (check a course without routing it)."""
    build_specs(course, scenarios)


def _flatten(message: str) -> list[str]:
    """Split a ``format_problems`` message back into its problems (else keep it whole)."""
    lines = message.splitlines()
    if len(lines) > 1 and all(ln.startswith("  - ") for ln in lines[1:]):
        return [ln[4:] for ln in lines[1:]]
    return [message]
