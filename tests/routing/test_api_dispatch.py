"""``route_leg`` dispatches on ``settings.router`` and reports missing routers clearly."""

from __future__ import annotations

import sys
import types
from dataclasses import replace

import numpy as np
import pytest

from sailroute.boat.polar import Polar
from sailroute.errors import InputError, RoutingError
from sailroute.routing import api
from sailroute.routing.api import get_router, route_leg
from sailroute.routing.isochrone import route_isochrone
from sailroute.routing.settings import GridDPSettings, RoutingSettings, SplineSettings
from sailroute.routing.types import Start, Target
from sailroute.wind.uniform import UniformWind

T0 = 1_524_567_600.0


def small_polar() -> Polar:
    twa = np.array([0, 40, 60, 90, 120, 150, 180.0])
    g = np.array([0, 0.7, 0.85, 0.97, 0.97, 0.8, 0.6])
    tws = np.array([2, 4, 6, 8.0])
    return Polar.from_arrays(twa, tws, np.outer(g, 0.5 * tws), name="small")


LEG = (Start((0.0, 0.0), name="start"), Target("mark", (0.0, 300.0), rounding="port", name="1"))


def test_isochrone_dispatch_is_the_isochrone_router():
    polar, wind, st = small_polar(), UniformWind(4.0, 0.0), RoutingSettings()
    a = route_leg(*LEG, T0, wind, polar, st)
    b = route_isochrone(*LEG, T0, wind, polar, st)
    assert a.router == "isochrone"
    assert a.time_s == b.time_s
    assert np.array_equal(a.track.x, b.track.x)


def test_progress_is_passed_through():
    seen: list[float] = []
    route_leg(
        *LEG, T0, UniformWind(4.0, 90.0), small_polar(), RoutingSettings(), progress=seen.append
    )
    assert seen and seen[-1] == 1.0


def test_unknown_router_is_an_input_error_listing_the_choices():
    st = replace(RoutingSettings(), router="dijkstra")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"'dijkstra'.*'isochrone', 'griddp', 'spline'"):
        route_leg(*LEG, T0, UniformWind(4.0, 0.0), small_polar(), st)


def test_missing_router_module_is_a_routing_error(monkeypatch):
    monkeypatch.setitem(
        api.ROUTERS,
        "griddp",
        api.RouterEntry("sailroute.routing._no_such_module", "f", GridDPSettings),
    )
    with pytest.raises(RoutingError, match=r"'griddp' is not available.*_no_such_module"):
        get_router("griddp")


def test_module_without_the_function_is_a_routing_error(monkeypatch):
    mod = types.ModuleType("sailroute_fake_router")
    monkeypatch.setitem(sys.modules, "sailroute_fake_router", mod)
    monkeypatch.setitem(
        api.ROUTERS,
        "spline",
        api.RouterEntry("sailroute_fake_router", "route_spline", SplineSettings),
    )
    with pytest.raises(RoutingError, match="has no function route_spline"):
        get_router("spline")


def test_other_routers_are_called_lazily_with_the_shared_signature(monkeypatch):
    calls = []
    mod = types.ModuleType("sailroute_fake_griddp")

    def route_griddp(start, target, t0, wind, polar, settings, *, progress=None):
        calls.append((start, target, t0, settings.router, progress))
        raise RoutingError("no feasible path on the grid")

    mod.route_griddp = route_griddp  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "sailroute_fake_griddp", mod)
    monkeypatch.setitem(
        api.ROUTERS,
        "griddp",
        api.RouterEntry("sailroute_fake_griddp", "route_griddp", GridDPSettings),
    )
    st = replace(RoutingSettings(), router="griddp")
    # a router's RoutingError without the leg gets the leg label prepended
    with pytest.raises(RoutingError, match=r"^leg start -> 1 \(griddp router\): no feasible"):
        route_leg(*LEG, T0, UniformWind(4.0, 0.0), small_polar(), st)
    assert calls == [(LEG[0], LEG[1], T0, "griddp", None)]


def test_routing_errors_that_name_the_leg_pass_unchanged():
    st = replace(RoutingSettings(), max_leg_time_s=60.0)
    with pytest.raises(RoutingError) as err:
        route_leg(*LEG, T0, UniformWind(0.0, 0.0), small_polar(), st)
    assert str(err.value).startswith("leg start -> 1: no route reached the target")
