"""sailroute: open, scriptable race routing for buoy courses.

The package is a functional core (``wind``, ``boat``, ``course``, ``routing``,
``strategy``) with thin orchestration (``plan``, ``analyze``) and a thin CLI
(``cli``).  Conventions (units, angles, time) are in ``docs/nomenclature.md``.

The names below are the curated Python API (``docs/api.md``)::

    import sailroute
    course = sailroute.load_course("courses/hyeres-r1.yaml")
    run = sailroute.plan_course(course, "constant")
    print(run.plan.total_time_s)

They are loaded lazily (PEP 562): ``import sailroute`` itself imports nothing
heavy (no NumPy, SciPy or matplotlib), so the command line starts fast; the first
access to a name imports its module.
"""

from __future__ import annotations

import importlib

from sailroute._version import __version__

# ``typing`` is not imported at run time: ``import sailroute`` (the first thing the
# ``sailroute`` command runs, before its Ctrl-C guard) stays a few statements long.
TYPE_CHECKING = False

# Public name -> module that defines it.  ``__all__`` lists the same names and the
# TYPE_CHECKING block below repeats them as imports, for type checkers, IDEs, linters
# and the API reference (tests/test_api.py checks that the three agree).
_EXPORTS: dict[str, str] = {
    # courses
    "Course": "sailroute.course.model",
    "course_from_mapping": "sailroute.course.load",
    "leg_endpoints": "sailroute.course.geometry",
    "load_course": "sailroute.course.load",
    # planning a course
    "Comparison": "sailroute.planning.result",
    "Plan": "sailroute.planning.result",
    "PlannedCourse": "sailroute.planning.route",
    "PlannedLeg": "sailroute.planning.result",
    "compare_scenarios": "sailroute.planning.route",
    "plan_course": "sailroute.planning.route",
    "plan_with_wind": "sailroute.api",
    "route_course": "sailroute.planning.route",
    "write_plan_outputs": "sailroute.report.files",
    # routing one leg
    "LegResult": "sailroute.routing.types",
    "RoutingSettings": "sailroute.routing.settings",
    "Start": "sailroute.routing.types",
    "Target": "sailroute.routing.types",
    "route_leg": "sailroute.routing.api",
    # wind
    "BlendedWind": "sailroute.wind.blended",
    "GridWind": "sailroute.wind.grid",
    "StationData": "sailroute.wind.stations",
    "StationWind": "sailroute.wind.stations",
    "UniformWind": "sailroute.wind.uniform",
    "WindField": "sailroute.wind.base",
    "open_grib": "sailroute.wind.cf",
    "open_netcdf": "sailroute.wind.cf",
    "open_wind": "sailroute.api",
    "open_wrf": "sailroute.wind.wrf",
    "read_stations": "sailroute.wind.stations",
    "wind_from_spec": "sailroute.wind.build",
    # boat
    "LaserParams": "sailroute.boat.laser",
    "Polar": "sailroute.boat.polar",
    "builtin_polar": "sailroute.boat.build",
    "fit_polar": "sailroute.boat.fit",
    "read_polar": "sailroute.boat.io",
    "vpp": "sailroute.api",
    "write_pol": "sailroute.boat.io",
    # race analysis
    "TrackAnalysis": "sailroute.analysis.debrief",
    "analyze_track": "sailroute.analysis.debrief",
    "fleet_ranking": "sailroute.analysis.debrief",
    "read_track": "sailroute.track.read",
    # tack strategy
    "DriftDiffusionShift": "sailroute.strategy.shiftmodel",
    "OUShift": "sailroute.strategy.shiftmodel",
    "StrategyResult": "sailroute.strategy.study",
    "StrategySettings": "sailroute.strategy.study",
    "run_strategy": "sailroute.strategy.study",
    # errors
    "InputError": "sailroute.errors",
    "OutOfCoverageError": "sailroute.errors",
    "RoutingError": "sailroute.errors",
    "SailrouteError": "sailroute.errors",
    "WindDataError": "sailroute.errors",
}

__all__ = [
    "BlendedWind",
    "Comparison",
    "Course",
    "DriftDiffusionShift",
    "GridWind",
    "InputError",
    "LaserParams",
    "LegResult",
    "OUShift",
    "OutOfCoverageError",
    "Plan",
    "PlannedCourse",
    "PlannedLeg",
    "Polar",
    "RoutingError",
    "RoutingSettings",
    "SailrouteError",
    "Start",
    "StationData",
    "StationWind",
    "StrategyResult",
    "StrategySettings",
    "Target",
    "TrackAnalysis",
    "UniformWind",
    "WindDataError",
    "WindField",
    "__version__",
    "analyze_track",
    "builtin_polar",
    "compare_scenarios",
    "course_from_mapping",
    "fit_polar",
    "fleet_ranking",
    "leg_endpoints",
    "load_course",
    "open_grib",
    "open_netcdf",
    "open_wind",
    "open_wrf",
    "plan_course",
    "plan_with_wind",
    "read_polar",
    "read_stations",
    "read_track",
    "route_course",
    "route_leg",
    "run_strategy",
    "vpp",
    "wind_from_spec",
    "write_plan_outputs",
    "write_pol",
]

if TYPE_CHECKING:  # pragma: no cover - the same names, for static tools
    from sailroute.analysis.debrief import TrackAnalysis, analyze_track, fleet_ranking
    from sailroute.api import open_wind, plan_with_wind, vpp
    from sailroute.boat.build import builtin_polar
    from sailroute.boat.fit import fit_polar
    from sailroute.boat.io import read_polar, write_pol
    from sailroute.boat.laser import LaserParams
    from sailroute.boat.polar import Polar
    from sailroute.course.geometry import leg_endpoints
    from sailroute.course.load import course_from_mapping, load_course
    from sailroute.course.model import Course
    from sailroute.errors import (
        InputError,
        OutOfCoverageError,
        RoutingError,
        SailrouteError,
        WindDataError,
    )
    from sailroute.planning.result import Comparison, Plan, PlannedLeg
    from sailroute.planning.route import PlannedCourse, compare_scenarios, plan_course, route_course
    from sailroute.report.files import write_plan_outputs
    from sailroute.routing.api import route_leg
    from sailroute.routing.settings import RoutingSettings
    from sailroute.routing.types import LegResult, Start, Target
    from sailroute.strategy.shiftmodel import DriftDiffusionShift, OUShift
    from sailroute.strategy.study import StrategyResult, StrategySettings, run_strategy
    from sailroute.track.read import read_track
    from sailroute.wind.base import WindField
    from sailroute.wind.blended import BlendedWind
    from sailroute.wind.build import wind_from_spec
    from sailroute.wind.cf import open_grib, open_netcdf
    from sailroute.wind.grid import GridWind
    from sailroute.wind.stations import StationData, StationWind, read_stations
    from sailroute.wind.uniform import UniformWind
    from sailroute.wind.wrf import open_wrf


if TYPE_CHECKING:
    from typing import Any


def __getattr__(name: str) -> Any:
    """Import the module of a public name on first access (PEP 562) and cache it."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(
            f"module 'sailroute' has no attribute {name!r}; the public names "
            "are listed in sailroute.__all__ (docs/api.md)"
        )
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
