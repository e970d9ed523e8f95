"""Routing settings: the common fields and one class per router, each validating its own
fields, one validation for every router, and the flat names of course files."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest

from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.routing.api import ROUTERS, get_router
from sailroute.routing.settings import (
    COMMON_FIELDS,
    FLAT_NAMES,
    GROUPS,
    MAX_DP_SEGMENT_SAMPLES,
    GridDPSettings,
    IsochroneSettings,
    RoutingSettings,
    SplineSettings,
    check_settings,
    flat_name,
    routing_settings,
    settings_problems,
)
from sailroute.routing.types import Start, Target
from sailroute.wind.uniform import UniformWind

T0 = 1_524_567_600.0
LEG = (Start((0.0, 0.0), name="start"), Target("mark", (0.0, 300.0), rounding="port", name="1"))


def small_polar() -> Polar:
    twa = np.array([0, 40, 60, 90, 120, 150, 180.0])
    g = np.array([0, 0.7, 0.85, 0.97, 0.97, 0.8, 0.6])
    tws = np.array([2, 4, 6, 8.0])
    return Polar.from_arrays(twa, tws, np.outer(g, 0.5 * tws), name="small")


def with_field(s: RoutingSettings, path: str, value: object) -> RoutingSettings:
    """``s`` with the field at ``path`` (``"zone_m"``, ``"griddp.cols"``) set, unchecked."""
    group, _, attr = path.partition(".")
    if not attr:
        return dataclasses.replace(s, **{group: value})
    return dataclasses.replace(
        s, **{group: dataclasses.replace(getattr(s, group), **{attr: value})}
    )


def all_paths() -> set[str]:
    return set(COMMON_FIELDS) | {
        f"{g}.{f.name}" for g, cls in GROUPS.items() for f in dataclasses.fields(cls)
    }


# --- the classes and the registry --------------------------------------------------------


def test_defaults_are_the_former_flat_defaults() -> None:
    s = RoutingSettings()
    assert (s.router, s.tack_penalty_s, s.gybe_penalty_s, s.initial_side) == (
        "isochrone",
        5.0,
        3.0,
        None,
    )
    assert (s.zone_m, s.start_line_spacing_m, s.max_leg_time_s) == (13.0, 5.0, 10800.0)
    assert s.isochrone == IsochroneSettings(10.0, 2.0, 1.0, 1.0, 2000, "hull")
    assert s.griddp == GridDPSettings(13, 64, 2, None, 0.5, 4)
    assert s.spline == SplineSettings(13, None, 25, 7, 3, False, False)


def test_the_registry_declares_each_routers_settings_class() -> None:
    assert {n: e.settings_type for n, e in ROUTERS.items()} == {
        "isochrone": IsochroneSettings,
        "griddp": GridDPSettings,
        "spline": SplineSettings,
    }
    for name, entry in ROUTERS.items():
        # the RoutingSettings field named as the router holds that class
        assert type(getattr(RoutingSettings(), name)) is entry.settings_type
    assert dict(GROUPS) == {n: e.settings_type for n, e in ROUTERS.items()}


def test_settings_are_frozen_and_hashable() -> None:
    s = RoutingSettings()
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.griddp.cols = 3  # type: ignore[misc]
    assert hash(s) == hash(RoutingSettings())
    assert routing_settings(dp_cols=9) != s


# --- the flat names ---------------------------------------------------------------------


def test_flat_names_sort_into_the_groups() -> None:
    s = routing_settings(
        router="griddp",
        zone_m=20.0,
        dt_s=5.0,
        heading_fan="full",
        dp_cols=33,
        dp_shrink=0.25,
        spline_slopes=3,
        spline_carry_speed=True,
    )
    assert (s.router, s.zone_m) == ("griddp", 20.0)
    assert s.isochrone == IsochroneSettings(dt_s=5.0, heading_fan="full")
    assert s.griddp == GridDPSettings(cols=33, shrink=0.25)
    assert s.spline == SplineSettings(slopes=3, carry_speed=True)


def test_dp_rows_and_half_width_set_both_grid_routers() -> None:
    # the grid-DP and spline routers shared these flat fields; a course keeps both in step
    s = routing_settings(dp_rows=7, dp_half_width_m=150.0)
    assert (s.griddp.rows, s.griddp.half_width_m) == (7, 150.0)
    assert (s.spline.rows, s.spline.half_width_m) == (7, 150.0)
    assert FLAT_NAMES["dp_rows"] == ("griddp.rows", "spline.rows")


def test_every_field_of_a_router_has_one_flat_name_and_back() -> None:
    paths = {p for ps in FLAT_NAMES.values() for p in ps}
    assert paths == all_paths() - set(COMMON_FIELDS)
    for flat, ps in FLAT_NAMES.items():
        assert {flat_name(p) for p in ps} == {flat}
    assert flat_name("zone_m") == "zone_m"
    assert len(FLAT_NAMES) == 18  # the former single class's, and isochrone.engine


def test_routing_settings_changes_a_base_and_takes_whole_groups() -> None:
    base = RoutingSettings(router="spline", spline=SplineSettings(cols=11))
    s = routing_settings(base, spline_slopes=5, griddp=GridDPSettings(cols=9), dp_samples=2)
    assert s.router == "spline"
    assert (s.spline.cols, s.spline.slopes) == (11, 5)
    assert s.griddp == GridDPSettings(cols=9, samples=2)  # the group first, then the name
    assert routing_settings() == RoutingSettings()


def test_routing_settings_refuses_an_unknown_name() -> None:
    with pytest.raises(InputError) as err:
        routing_settings(dp_col=3)
    msg = str(err.value)
    assert msg.startswith("routing setting 'dp_col': unknown name; did you mean 'dp_cols'? ")
    assert "valid names: router, tack_penalty_s," in msg and "\n" not in msg


# --- one validation, each class its own fields -------------------------------------------


BAD = [
    ("router", "dijkstra", "router must be one of 'isochrone', 'griddp', 'spline', got 'dijkstra'"),
    ("isochrone.dt_s", 0.0, "isochrone.dt_s must be a number > 0, got 0.0"),
    ("isochrone.heading_step_deg", 60.0, "isochrone.heading_step_deg must be <= 45, got 60.0"),
    (
        "isochrone.heading_step_deg",
        0.01,
        "isochrone.heading_step_deg must be in [0.1, 45] (default 2; finer steps "
        "only slow the router), got 0.01",
    ),
    (
        "isochrone.dt_s",
        0.1,
        "isochrone.dt_s must be >= 0.5 s (default 10; finer steps hardly change the route "
        "and make it slow), got 0.1",
    ),
    ("isochrone.min_dt_s", -1.0, "isochrone.min_dt_s must be a number > 0, got -1.0"),
    (
        "isochrone.min_dt_s",
        0.001,
        "isochrone.min_dt_s must be >= 0.01 s (default 1), got 0.001",
    ),
    (
        "isochrone.prune_sector_deg",
        float("nan"),
        "isochrone.prune_sector_deg must be a number > 0, got nan",
    ),
    ("max_leg_time_s", "1h", "max_leg_time_s must be a number > 0, got '1h'"),
    ("start_line_spacing_m", 0, "start_line_spacing_m must be a number > 0, got 0"),
    ("zone_m", True, "zone_m must be a number > 0, got True"),
    ("tack_penalty_s", -1.0, "tack_penalty_s must be a number >= 0, got -1.0"),
    ("gybe_penalty_s", float("inf"), "gybe_penalty_s must be a number >= 0, got inf"),
    (
        "isochrone.max_front_points",
        2,
        "isochrone.max_front_points must be an integer in [8, 100000], got 2",
    ),
    ("isochrone.heading_fan", "wide", "isochrone.heading_fan must be 'hull' or 'full', got 'wide'"),
    (
        "isochrone.engine",
        "jit",
        "isochrone.engine must be one of 'auto', 'numpy', 'numba' (the same routes; 'auto': "
        "compiled where numba is installed and the work pays for its start-up), got 'jit'",
    ),
    ("initial_side", "left", "initial_side must be 'port', 'starboard' or None, got 'left'"),
    ("griddp.rows", 2, "griddp.rows must be an integer in [3, 200], got 2"),
    ("griddp.cols", 1, "griddp.cols must be an integer in [2, 1024], got 1"),
    ("griddp.refinements", 1.5, "griddp.refinements must be an integer in [0, 20], got 1.5"),
    ("griddp.samples", 0, "griddp.samples must be an integer in [1, 64], got 0"),
    ("griddp.shrink", 0.0, "griddp.shrink must be in (0, 1], got 0.0"),
    (
        "griddp.half_width_m",
        -5.0,
        "griddp.half_width_m must be > 0 m or None (automatic), got -5.0",
    ),
    ("spline.rows", 201, "spline.rows must be an integer in [3, 200], got 201"),
    (
        "spline.half_width_m",
        float("nan"),
        "spline.half_width_m must be > 0 m or None (automatic), got nan",
    ),
    ("spline.cols", 1, "spline.cols must be an integer >= 2, got 1"),
    ("spline.slopes", 0, "spline.slopes must be an integer >= 1, got 0"),
    ("spline.refinements", -1, "spline.refinements must be an integer >= 0, got -1"),
    ("spline.carry_speed", "yes", "spline.carry_speed must be true or false, got 'yes'"),
    ("spline.start_from_rest", 1, "spline.start_from_rest must be true or false, got 1"),
]


def test_default_settings_are_valid() -> None:
    assert settings_problems(RoutingSettings()) == []
    for cls in GROUPS.values():
        assert cls().problems() == []
    check_settings(
        routing_settings(router="spline", initial_side="port", dp_half_width_m=400.0), "x"
    )


def test_every_field_is_checked() -> None:
    assert {f for f, _, _ in BAD} == all_paths()


@pytest.mark.parametrize(("path", "value", "line"), BAD, ids=[f"{b[0]}={b[1]!r}" for b in BAD])
def test_each_bad_field_is_refused_with_its_message(path: str, value: object, line: str) -> None:
    s = with_field(RoutingSettings(), path, value)
    assert settings_problems(s) == [line]
    assert s.problems() == [line]
    with pytest.raises(InputError) as err:
        check_settings(s, "start -> 1")
    assert str(err.value) == f"leg start -> 1: invalid routing settings:\n  - {line}"


@pytest.mark.parametrize(
    ("path", "value", "line"),
    [b for b in BAD if "." in b[0]],
    ids=[f"{b[0]}={b[1]!r}" for b in BAD if "." in b[0]],
)
def test_each_router_class_checks_its_own_fields(path: str, value: object, line: str) -> None:
    group, _, attr = path.partition(".")
    cls = ROUTERS[group].settings_type
    bad: Any = cls(**{attr: value})
    assert bad.problems() == [line]
    # named as the caller says (the course loader names the key the file used)
    assert bad.problems(lambda p: p.upper()) == [line.replace(path, path.upper(), 1)]


def test_a_group_of_the_wrong_class_is_refused() -> None:
    s = dataclasses.replace(RoutingSettings(), griddp=SplineSettings())  # type: ignore[arg-type]
    assert settings_problems(s) == [
        "griddp must be a GridDPSettings, got SplineSettings(rows=13, half_width_m=None, "
        "cols=25, slopes=7, refinements=3, carry_speed=False, start_from_rest=False)"
    ]


@pytest.mark.parametrize(
    ("flat", "value", "path"),
    [
        ("dp_cols", 1, "griddp.cols"),
        ("tack_penalty_s", -1.0, "tack_penalty_s"),
        ("spline_slopes", 0, "spline.slopes"),
        ("heading_fan", "wide", "isochrone.heading_fan"),
    ],
)
def test_every_router_refuses_bad_settings_with_the_same_message(
    flat: str, value: object, path: str
) -> None:
    # every router checks every field (a course may switch router), in the same words
    messages = set()
    for name in ROUTERS:
        s = routing_settings(RoutingSettings(router=name), **{flat: value})  # type: ignore[arg-type]
        with pytest.raises(InputError) as err:
            get_router(name)(*LEG, T0, UniformWind(4.0, 0.0), small_polar(), s)
        messages.add(str(err.value))
    assert len(messages) == 1
    assert messages.pop().startswith(f"leg start -> 1: invalid routing settings:\n  - {path} ")


def test_several_bad_fields_are_listed_together() -> None:
    s = routing_settings(dt_s=-1.0, dp_cols=1, zone_m=0.0)
    assert settings_problems(s) == [
        "zone_m must be a number > 0, got 0.0",
        "isochrone.dt_s must be a number > 0, got -1.0",
        "griddp.cols must be an integer in [2, 1024], got 1",
    ]


def test_a_shared_flat_field_is_named_once() -> None:
    # dp_rows sets both routers' rows; named flat (as a course file does) it is one line
    s = routing_settings(dp_rows=2)
    assert settings_problems(s) == [
        "griddp.rows must be an integer in [3, 200], got 2",
        "spline.rows must be an integer in [3, 200], got 2",
    ]
    assert settings_problems(s, flat_name) == ["dp_rows must be an integer in [3, 200], got 2"]


def test_the_work_estimate_is_each_grid_routers_own() -> None:
    g = GridDPSettings(cols=1024, rows=200, samples=64, refinements=20)
    (line,) = g.problems()
    assert line.startswith(
        "griddp.cols = 1024 with griddp.rows = 200, griddp.samples = 64 and "
        "griddp.refinements = 20 needs about 2.8e+11 wind samples per leg"
    )
    assert f"more than {MAX_DP_SEGMENT_SAMPLES:.0e} (minutes of work)" in line
    (line,) = SplineSettings(cols=1000, slopes=1000).problems()
    assert line.startswith("spline.cols = 1000 with spline.slopes = 1000 needs 1.0e+12 edges")
    assert line.endswith(
        "lower spline.cols, spline.slopes or spline.refinements (defaults 25, 7, 3)"
    )
    # one router's heavy mesh does not hide the other's fields
    s = RoutingSettings(griddp=g, spline=SplineSettings(cols=1))
    assert settings_problems(s)[1:] == ["spline.cols must be an integer >= 2, got 1"]
