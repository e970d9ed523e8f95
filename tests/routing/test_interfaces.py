"""The declared routing interfaces: the ``Router`` signature and the one tack encoding
(names outside, ±1 in arrays); the settings are tested in ``test_settings.py``."""

from __future__ import annotations

import inspect
from typing import Any

import numpy as np
import pytest

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.routing import griddp, isochrone, multispline
from sailroute.routing.api import ROUTERS, get_router
from sailroute.routing.settings import (
    RoutingSettings,
    routing_settings,
)
from sailroute.routing.types import SIDE_NAMES, Start, Target, side_name, side_sign
from sailroute.wind.uniform import UniformWind

T0 = 1_524_567_600.0
LEG = (Start((0.0, 0.0), name="start"), Target("mark", (0.0, 300.0), rounding="port", name="1"))


def small_polar() -> Polar:
    twa = np.array([0, 40, 60, 90, 120, 150, 180.0])
    g = np.array([0, 0.7, 0.85, 0.97, 0.97, 0.8, 0.6])
    tws = np.array([2, 4, 6, 8.0])
    return Polar.from_arrays(twa, tws, np.outer(g, 0.5 * tws), name="small")


# --- Router -------------------------------------------------------------------------


@pytest.mark.parametrize("name", list(ROUTERS))
def test_every_router_has_the_router_call_shape(name: str) -> None:
    func = get_router(name)
    module = {"isochrone": isochrone, "griddp": griddp, "spline": multispline}[name]
    assert module._ROUTER is func  # the assignment mypy checks against `Router`
    sig = inspect.signature(func)
    params = list(sig.parameters.values())
    # six positional arguments, in the Router order, then keyword-only options
    assert [p.kind for p in params[:6]] == [inspect.Parameter.POSITIONAL_OR_KEYWORD] * 6
    assert [p.name for p in params[:6]] == ["start", "target", "t0", "wind", "boat", "settings"]
    assert sig.parameters["progress"].kind is inspect.Parameter.KEYWORD_ONLY
    assert sig.parameters["progress"].default is None
    assert sig.parameters["xp"].default is np
    sig.bind(
        *LEG, T0, UniformWind(4.0, 0.0), small_polar(), RoutingSettings(), progress=None, xp=np
    )
    assert sig.return_annotation == "LegResult"


# --- tack / side encoding ----------------------------------------------------------------


def test_side_converters_round_trip() -> None:
    assert SIDE_NAMES == ("port", "starboard")
    assert [side_sign(n) for n in SIDE_NAMES] == [-1, 1]
    assert side_sign(None) == 0
    for name in SIDE_NAMES:
        assert side_name(side_sign(name)) == name
    for sign in (-1, 1, np.int8(-1), np.int8(1)):
        assert side_sign(side_name(sign)) == sign


@pytest.mark.parametrize("bad", ["left", "Port", "stbd", "", 1])
def test_side_sign_rejects_other_names(bad: object) -> None:
    with pytest.raises(InputError, match=r"expected 'port' or 'starboard'") as err:
        side_sign(bad)  # type: ignore[arg-type]
    assert str(err.value) == f"side {bad!r}: expected 'port' or 'starboard'"


@pytest.mark.parametrize("bad", [0, 0.0, float("nan")])
def test_side_name_has_no_name_for_no_side(bad: float) -> None:
    with pytest.raises(ValueError, match="has no name"):
        side_name(bad)


@pytest.mark.parametrize("router", ["isochrone", "griddp"])
@pytest.mark.parametrize("side", SIDE_NAMES)
def test_initial_side_name_starts_the_track_on_that_sign(router: Any, side: Any) -> None:
    # a beat: the route starts on the tack the settings name (side_sign in the arrays)
    s = routing_settings(router=router, dp_rows=5, dp_cols=9, dp_refinements=0, initial_side=side)
    res = get_router(router)(*LEG, T0, UniformWind(6.0, 0.0), small_polar(), s)
    assert side_name(int(res.track.side[0])) == side
