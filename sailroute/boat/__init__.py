"""Boat performance: polars, the Laser/ILCA VPP and the dynamic segment model."""

from sailroute.boat.polar import Polar

__all__ = ["Polar"]
