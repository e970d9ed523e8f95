"""Leg routers (isochrones, grid DP, multi-spline) and their shared types."""

from sailroute.routing.types import (
    LegResult,
    Manoeuvre,
    RoutingSettings,
    Start,
    Target,
    Track,
)

__all__ = ["LegResult", "Manoeuvre", "RoutingSettings", "Start", "Target", "Track"]
