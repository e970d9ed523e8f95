"""Leg routers (isochrones, grid DP, multi-spline) and their shared types."""

from sailroute.routing.settings import (
    GridDPSettings,
    IsochroneSettings,
    RoutingSettings,
    SplineSettings,
    routing_settings,
)
from sailroute.routing.types import Barrier, LegResult, Manoeuvre, RouteTrack, Start, Target

__all__ = [
    "Barrier",
    "GridDPSettings",
    "IsochroneSettings",
    "LegResult",
    "Manoeuvre",
    "RouteTrack",
    "RoutingSettings",
    "SplineSettings",
    "Start",
    "Target",
    "routing_settings",
]
