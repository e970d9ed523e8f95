"""Boat performance: polars, the Laser/ILCA VPP and the dynamic segment model.

* :class:`~sailroute.boat.polar.Polar`: speed(TWS, TWA) lookups and VMG optima;
* :mod:`sailroute.boat.io`: ``.pol`` / CSV / JSON / ORC JSON readers and writers;
* :mod:`sailroute.boat.build`: built-in ILCA polars and the course ``boat:`` factory;
* :mod:`sailroute.boat.laser` and :mod:`sailroute.boat.vpp`: the Laser VPP.
"""

from sailroute.boat.build import boat_from_spec, builtin_polar
from sailroute.boat.io import read_polar, write_pol, write_polar_csv, write_polar_json
from sailroute.boat.laser import LaserParams
from sailroute.boat.polar import Polar

__all__ = [
    "LaserParams",
    "Polar",
    "boat_from_spec",
    "builtin_polar",
    "read_polar",
    "write_pol",
    "write_polar_csv",
    "write_polar_json",
]
