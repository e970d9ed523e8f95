"""Leg routers (isochrones, grid DP, multi-spline) and their shared types."""

from sailroute.routing.types import (
    Barrier,
    LegResult,
    Manoeuvre,
    RoutingSettings,
    Start,
    Target,
    Track,
)

__all__ = ["Barrier", "LegResult", "Manoeuvre", "RoutingSettings", "Start", "Target", "Track"]
