"""Wind sources, all behind the :class:`~sailroute.wind.base.WindField` protocol.

* :class:`UniformWind` — constant or time-table wind, the same everywhere;
* :class:`AnalyticWind` — a formula ``f(t, x, y)``;
* :func:`open_wrf` -> :class:`GridWind` — WRF ``wrfout`` NetCDF;
* :func:`open_netcdf` / :func:`open_grib` -> :class:`GridWind` — wind on latitude/longitude
  (CF NetCDF, xarray datasets, GRIB via the ``grib`` extra);
* :func:`read_stations` -> :class:`StationData` -> :class:`StationWind` — measured wind;
* :class:`BlendedWind` — a model field corrected by stations;
* :func:`sensor_from_track`, :func:`boat_wind`, :func:`fleet_wind` — the wind measured
  on board (boat logs as moving sensors; one boat's own wind, or the fleet's field);
* :func:`wind_from_spec` — any of these from a course-file wind spec.

Design notes: ``docs/design/wind.md``.

The names are loaded lazily (PEP 562), as the package namespace's
(``sailroute/__init__.py``): every import of a module of the package
(``sailroute.wind.specs``, ``sailroute.wind.grid``) runs this file first, and a plan needs
the readers of its own scenarios' sources only.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Public name -> module that defines it (or imports it: ``measured`` re-exports its parts).
_EXPORTS: dict[str, str] = {
    "AnalyticWind": "sailroute.wind.analytic",
    "Coverage": "sailroute.wind.base",
    "WindField": "sailroute.wind.base",
    "prepare_points": "sailroute.wind.base",
    "BlendedWind": "sailroute.wind.blended",
    "check_covers": "sailroute.wind.build",
    "wind_from_spec": "sailroute.wind.build",
    "open_grib": "sailroute.wind.cf",
    "open_netcdf": "sailroute.wind.cf",
    "GridWind": "sailroute.wind.grid",
    "BoatBias": "sailroute.wind.measured",
    "BoatWind": "sailroute.wind.measured",
    "FleetField": "sailroute.wind.measured",
    "FleetWind": "sailroute.wind.measured",
    "MeasuredSeries": "sailroute.wind.measured",
    "boat_wind": "sailroute.wind.measured",
    "fleet_wind": "sailroute.wind.measured",
    "sensor_from_track": "sailroute.wind.measured",
    "true_wind": "sailroute.wind.measured",
    "read_ndbc": "sailroute.wind.ndbc",
    "StationData": "sailroute.wind.stations",
    "StationWind": "sailroute.wind.stations",
    "read_stations": "sailroute.wind.stations",
    "resample_stations": "sailroute.wind.stations",
    "UniformWind": "sailroute.wind.uniform",
    "open_wrf": "sailroute.wind.wrf",
}

__all__ = [
    "AnalyticWind",
    "BlendedWind",
    "BoatBias",
    "BoatWind",
    "Coverage",
    "FleetField",
    "FleetWind",
    "GridWind",
    "MeasuredSeries",
    "StationData",
    "StationWind",
    "UniformWind",
    "WindField",
    "boat_wind",
    "check_covers",
    "fleet_wind",
    "open_grib",
    "open_netcdf",
    "open_wrf",
    "prepare_points",
    "read_ndbc",
    "read_stations",
    "resample_stations",
    "sensor_from_track",
    "true_wind",
    "wind_from_spec",
]

if TYPE_CHECKING:  # pragma: no cover - the same names, for static tools
    from sailroute.wind.analytic import AnalyticWind
    from sailroute.wind.base import Coverage, WindField, prepare_points
    from sailroute.wind.blended import BlendedWind
    from sailroute.wind.build import check_covers, wind_from_spec
    from sailroute.wind.cf import open_grib, open_netcdf
    from sailroute.wind.grid import GridWind
    from sailroute.wind.measured import (
        BoatBias,
        BoatWind,
        FleetField,
        FleetWind,
        MeasuredSeries,
        boat_wind,
        fleet_wind,
        sensor_from_track,
        true_wind,
    )
    from sailroute.wind.ndbc import read_ndbc
    from sailroute.wind.stations import StationData, StationWind, read_stations, resample_stations
    from sailroute.wind.uniform import UniformWind
    from sailroute.wind.wrf import open_wrf


def __getattr__(name: str) -> Any:
    """Import the module of a public name on first access (PEP 562) and cache it."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'sailroute.wind' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value
