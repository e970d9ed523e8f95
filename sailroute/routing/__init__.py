"""Leg routers (isochrones, grid DP, multi-spline) and their shared types."""

from sailroute.routing.types import (
    Barrier,
    LegResult,
    Manoeuvre,
    RouteTrack,
    RoutingSettings,
    Start,
    Target,
)

__all__ = ["Barrier", "LegResult", "Manoeuvre", "RouteTrack", "RoutingSettings", "Start", "Target"]
