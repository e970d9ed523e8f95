"""The declared routing interfaces: the ``Router`` signature, settings validated in one
place, and the one tack encoding (names outside, ±1 in arrays)."""

from __future__ import annotations

import inspect
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.routing import griddp, isochrone, multispline
from sailroute.routing.api import ROUTERS, get_router
from sailroute.routing.types import (
    SIDE_NAMES,
    RoutingSettings,
    Start,
    Target,
    check_settings,
    settings_problems,
    side_name,
    side_sign,
)
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


# --- RoutingSettings: one validation ----------------------------------------------------


BAD = [
    ("router", "dijkstra", "router must be one of 'isochrone', 'griddp', 'spline', got 'dijkstra'"),
    ("dt_s", 0.0, "dt_s must be a number > 0, got 0.0"),
    ("heading_step_deg", 60.0, "heading_step_deg must be <= 45, got 60.0"),
    (
        "heading_step_deg",
        0.01,
        "heading_step_deg must be in [0.1, 45] (default 2; finer steps "
        "only slow the router), got 0.01",
    ),
    (
        "dt_s",
        0.1,
        "dt_s must be >= 0.5 s (default 10; finer steps hardly change the route "
        "and make it slow), got 0.1",
    ),
    ("min_dt_s", -1.0, "min_dt_s must be a number > 0, got -1.0"),
    ("prune_sector_deg", float("nan"), "prune_sector_deg must be a number > 0, got nan"),
    ("max_leg_time_s", "1h", "max_leg_time_s must be a number > 0, got '1h'"),
    ("start_line_spacing_m", 0, "start_line_spacing_m must be a number > 0, got 0"),
    ("zone_m", True, "zone_m must be a number > 0, got True"),
    ("tack_penalty_s", -1.0, "tack_penalty_s must be a number >= 0, got -1.0"),
    ("gybe_penalty_s", float("inf"), "gybe_penalty_s must be a number >= 0, got inf"),
    ("max_front_points", 2, "max_front_points must be an integer in [8, 100000], got 2"),
    ("heading_fan", "wide", "heading_fan must be 'hull' or 'full', got 'wide'"),
    ("initial_side", "left", "initial_side must be 'port', 'starboard' or None, got 'left'"),
    ("dp_rows", 2, "dp_rows must be an integer in [3, 200], got 2"),
    ("dp_cols", 1, "dp_cols must be an integer in [2, 1024], got 1"),
    ("dp_refinements", 1.5, "dp_refinements must be an integer in [0, 20], got 1.5"),
    ("dp_samples", 0, "dp_samples must be an integer in [1, 64], got 0"),
    ("dp_shrink", 0.0, "dp_shrink must be in (0, 1], got 0.0"),
    ("dp_half_width_m", -5.0, "dp_half_width_m must be > 0 m or None (automatic), got -5.0"),
    ("spline_cols", 1, "spline_cols must be an integer >= 2, got 1"),
    ("spline_slopes", 0, "spline_slopes must be an integer >= 1, got 0"),
    ("spline_refinements", -1, "spline_refinements must be an integer >= 0, got -1"),
    ("spline_carry_speed", "yes", "spline_carry_speed must be true or false, got 'yes'"),
    ("spline_start_from_rest", 1, "spline_start_from_rest must be true or false, got 1"),
]


def test_default_settings_are_valid() -> None:
    assert settings_problems(RoutingSettings()) == []
    check_settings(
        RoutingSettings(router="spline", initial_side="port", dp_half_width_m=400.0), "x"
    )


def test_every_field_is_checked() -> None:
    checked = {f for f, _, _ in BAD}
    assert checked == set(RoutingSettings.__dataclass_fields__)


@pytest.mark.parametrize(("field", "value", "line"), BAD, ids=[b[0] for b in BAD])
def test_each_bad_field_is_refused_with_its_message(field: str, value: object, line: str) -> None:
    s = replace(RoutingSettings(), **{field: value})
    assert settings_problems(s) == [line]
    with pytest.raises(InputError) as err:
        check_settings(s, "start -> 1")
    assert str(err.value) == f"leg start -> 1: invalid routing settings:\n  - {line}"


@pytest.mark.parametrize(
    ("field", "value"),
    [("dp_cols", 1), ("tack_penalty_s", -1.0), ("spline_slopes", 0), ("heading_fan", "wide")],
)
def test_every_router_refuses_bad_settings_with_the_same_message(field: str, value: object) -> None:
    # before: each router checked only "its" fields, with its own wording
    messages = set()
    for name in ROUTERS:
        s = replace(RoutingSettings(router=name), **{field: value})  # type: ignore[arg-type]
        with pytest.raises(InputError) as err:
            get_router(name)(*LEG, T0, UniformWind(4.0, 0.0), small_polar(), s)
        messages.add(str(err.value))
    assert len(messages) == 1
    assert messages.pop().startswith(f"leg start -> 1: invalid routing settings:\n  - {field}")


def test_several_bad_fields_are_listed_together() -> None:
    s = RoutingSettings(dt_s=-1.0, dp_cols=1)
    assert settings_problems(s) == [
        "dt_s must be a number > 0, got -1.0",
        "dp_cols must be an integer in [2, 1024], got 1",
    ]


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
    s = RoutingSettings(router=router, dp_rows=5, dp_cols=9, dp_refinements=0, initial_side=side)
    res = get_router(router)(*LEG, T0, UniformWind(6.0, 0.0), small_polar(), s)
    assert side_name(int(res.track.side[0])) == side
