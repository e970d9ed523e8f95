"""Thin wrappers that make the functional core convenient from Python.

The package namespace (``import sailroute``, see ``docs/api.md``) re-exports the
existing functions and result types; the three functions here exist only where the
existing signatures are shaped for course files or the CLI:

* :func:`open_wind` -- a wind source from a spec, given a course instead of a
  frame, a base folder, a bounding box and a time window;
* :func:`plan_with_wind` -- route a course in a wind field built in Python (not
  one of the course file's scenarios);
* :func:`vpp` -- the Laser/ILCA VPP polar of a class name, a boat file or
  parameters, without writing files (``sailroute vpp`` writes them).

Nothing here prints or writes files.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from sailroute.boat.polar import Polar
from sailroute.course.model import Course
from sailroute.errors import InputError
from sailroute.planning.route import PlannedCourse
from sailroute.progress import Progress
from sailroute.wind.base import WindField


def open_wind(
    course: Course,
    spec: Mapping[str, Any] | None = None,
    /,
    *,
    base_dir: str | Path | None = None,
    **keys: Any,
) -> WindField:
    """Open a wind source for a course, from a course-file wind spec.

    The spec is the same mapping a scenario's ``wind:`` holds in a course file
    (``docs/course-format.md``), given as a mapping, as keyword arguments, or both
    (keywords win).  The course supplies the local frame, the area the data must
    cover (its marks) and the race time window
    (:func:`sailroute.course.geometry.race_time_window`).

    Parameters
    ----------
    course : Course
        A loaded course (:func:`sailroute.load_course`).
    spec : mapping, optional
        Wind spec, e.g. ``{"type": "wrf", "path": "wrfout.nc", "height_m": 2.68}``;
        ``type`` is one of ``uniform``, ``wrf``, ``netcdf``, ``grib``, ``stations``,
        ``blended``.  Paths may be strings or :class:`pathlib.Path`.
    base_dir : str or Path, optional
        Folder that relative ``path`` values resolve against; default the current
        working directory (a course file's own specs resolve against the course
        file's folder instead).
    **keys
        Spec keys, e.g. ``type="uniform", tws_kn=10, twd_deg=108``.

    Returns
    -------
    WindField
        ``UniformWind``, ``GridWind``, ``StationWind`` or ``BlendedWind``, with
        ``sample(t, x, y) -> (u, v)`` [m s⁻¹] in the course's frame.

    Raises
    ------
    InputError
        No ``type``, unknown type, unknown/missing/invalid keys (all listed at
        once), unreadable files.
    WindDataError
        Malformed data files.
    OutOfCoverageError
        The data do not cover the course's marks or its race time window (unless
        the spec sets ``clamp: true``).

    Examples
    --------
    >>> import sailroute
    >>> course = sailroute.load_course("courses/hyeres-r1.yaml")
    >>> wind = sailroute.open_wind(course, type="uniform", tws_kn=10, twd_deg=108)
    >>> u, v = wind.sample(course.start_epoch, 0.0, 0.0)
    """
    from sailroute.course.geometry import course_bbox, race_time_window
    from sailroute.wind.build import wind_from_spec

    merged = _plain({**(dict(spec) if spec is not None else {}), **keys})
    if not merged:
        raise InputError(
            "open_wind: give a wind spec, e.g. open_wind(course, type='uniform', "
            "tws_kn=10, twd_deg=108) (keys as in docs/course-format.md, 'wind:')"
        )
    kind = merged.get("type", "?")
    return wind_from_spec(
        merged,
        frame=course.frame,
        base_dir=Path.cwd() if base_dir is None else Path(base_dir),
        where=f"open_wind({kind})",
        crop_bbox=course_bbox(course),
        time_window=race_time_window(course),
    )


def _plain(value: Any) -> Any:
    """``value`` with every path (``os.PathLike``) made a string, in nested specs too."""
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return type(value)(_plain(v) for v in value)
    return value


def plan_with_wind(
    course: Course,
    wind: WindField,
    *,
    boat: Polar | None = None,
    name: str = "custom",
    router: str | None = None,
    backend: str = "numpy",
    current: Any = None,
    progress: Progress | None = None,
) -> PlannedCourse:
    """Route a course in a wind field built in Python, leg by leg.

    :func:`sailroute.plan_course` routes one of the course file's scenarios; this
    routes ``wind`` (from :func:`open_wind`, ``open_wrf``, ``StationWind``, an
    ``AnalyticWind``...) with the same checks: the boat must have speed and the
    wind must stay within the polar's TWS columns over the course area and race
    time (unless the course's ``boat`` block allows extrapolation).

    Parameters
    ----------
    course : Course
        A loaded course.
    wind : WindField
        Wind in the course's frame, covering its area and race time.
    boat : Polar, optional
        Boat; default the course's ``boat`` (:func:`sailroute.course.load.build_boat`).
    name : str
        Scenario name given to the plan (a course scenario of that name adds its
        references).
    router : str, optional
        ``"isochrone"``, ``"griddp"`` or ``"spline"``; overrides the course's
        ``routing.router``.
    backend : {"numpy", "cupy", "auto"}
        Array backend of the router kernels.
    current : CurrentField, optional
        Surface current (isochrone router only); None: still water.
    progress : Progress, optional
        Per-leg progress display.

    Returns
    -------
    PlannedCourse
        ``plan`` (legs chained: ``plan.total_time_s`` is the sum of the leg times),
        ``wind`` and ``notes`` (a warning when the wind exceeds the polar and the
        course allows it).

    Raises
    ------
    InputError
        Unknown router or backend, a boat without speed, wind above the polar.
    OutOfCoverageError
        The wind does not cover a leg.
    RoutingError
        A leg cannot be routed (the message names it).
    """
    from sailroute.boat.sanity import check_wind_range, peak_wind, require_speed
    from sailroute.course.geometry import course_bbox, race_time_window
    from sailroute.course.load import build_boat
    from sailroute.planning.result import make_plan
    from sailroute.planning.route import route_course, settings_for
    from sailroute.routing.api import check_current_router

    settings = settings_for(course, router, backend)
    if current is not None:
        check_current_router(settings.router)
    polar = build_boat(course) if boat is None else boat
    where = f"plan_with_wind({name})"
    require_speed(polar, f"{where}: boat")
    allow = course.boat_spec.get("allow_extrapolation", False) is True
    note = check_wind_range(
        polar,
        peak_wind(wind, course_bbox(course), race_time_window(course)),
        allow_extrapolation=allow,
        where=where,
    )
    if note is not None and progress is not None:
        progress.warn(note)
    results = route_course(
        course, wind, polar, settings, backend=backend, progress=progress, current=current
    )
    plan = make_plan(course, name, results, wind, router=settings.router)
    return PlannedCourse(plan, wind, () if note is None else (note,))


def vpp(
    boat: str | Path | Mapping[str, Any] | Any = "ilca7",
    *,
    crew_mass_kg: float | None = None,
    tws_ms: Sequence[float] | None = None,
    twa_deg: Sequence[float] | None = None,
    kinetics: str | Mapping[str, Any] | Any = "steady",
    interpolation: str = "pchip",
) -> Polar:
    """Polar of a Laser/ILCA from the velocity prediction program (``docs/vpp.md``).

    Parameters
    ----------
    boat : str, Path, mapping or LaserParams
        ``"ilca7"``, ``"ilca6"`` or ``"ilca4"`` (the class's shipped parameters);
        a boat YAML file (``class``, ``crew_mass_kg``, parameter overrides); a
        mapping with the same keys; or :class:`~sailroute.boat.laser.LaserParams`.
    crew_mass_kg : float, optional
        Sailor mass [kg], overriding the boat's.
    tws_ms : sequence of float, optional
        Increasing TWS columns [m s⁻¹] (wind at the sail's centre of effort);
        default the built-in polars' 1-28 kn.
    twa_deg : sequence of float, optional
        Increasing TWA rows in [0, 180] [°]; default 0-180 every 2.5°.
    kinetics : {"steady", "race"} or mapping or Kinetics
        ``steady``: the steady force balance alone (default, as ``sailroute vpp``);
        ``race``: plus wave riding and pumping, the model of the built-in
        ``ilca7`` polar; a mapping overrides race-model parameters.
    interpolation : {"pchip", "linear"}
        Interpolation of the returned polar.

    Returns
    -------
    Polar
        ``speed_ms[i, j]`` at ``twa_deg[i]``, ``tws_ms[j]`` (cached: the same
        arguments return the same object).

    Raises
    ------
    InputError
        Unknown class, unreadable boat file, a parameter or sailor mass out of
        range, a bad kinetics value or grid.
    """
    import numpy as np

    from sailroute.boat.boatfile import load_boat_file
    from sailroute.boat.build import vpp_polar
    from sailroute.boat.kinetics import Kinetics, kinetics_from_spec
    from sailroute.boat.laser import CLASSES, CREW_MASS_RANGE_KG, LaserParams, params_from_mapping
    from sailroute.errors import format_problems

    if isinstance(boat, LaserParams):
        params = boat
    elif isinstance(boat, Mapping):
        params = params_from_mapping(boat, where="vpp(boat)")
    elif isinstance(boat, str) and boat.lower() in CLASSES:
        params = CLASSES[boat.lower()]
    elif isinstance(boat, str | Path):
        params = load_boat_file(boat)[0]
    else:
        raise InputError(
            f"vpp: boat must be a class name ({', '.join(map(repr, CLASSES))}), "
            f"a boat YAML path, a mapping or LaserParams; got {boat!r}"
        )
    if crew_mass_kg is not None:
        lo, hi = CREW_MASS_RANGE_KG
        if not lo <= crew_mass_kg <= hi:
            raise InputError(
                f"vpp: crew_mass_kg = {crew_mass_kg}: expected a sailor mass in {lo:g}-{hi:g} kg"
            )
        params = dataclasses.replace(params, crew_mass_kg=float(crew_mass_kg))
    if isinstance(kinetics, Kinetics):
        kin = kinetics
    else:
        kin, problems = kinetics_from_spec(kinetics, key="vpp: kinetics")
        if problems:
            raise InputError(
                problems[0] if len(problems) == 1 else format_problems("vpp: kinetics", problems)
            )

    def grid(values: Sequence[float] | None) -> tuple[float, ...] | None:
        return None if values is None else tuple(float(v) for v in np.asarray(values).ravel())

    return vpp_polar(params, grid(tws_ms), grid(twa_deg), interpolation, kin)


__all__ = ["open_wind", "plan_with_wind", "vpp"]
