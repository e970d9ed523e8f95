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
"""

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
