"""Surface current in the isochrone router: closed forms in uniform wind and current.

With uniform wind and a uniform current the wind relative to the water is uniform, so
the water frame is a still-water problem whose target drifts by ``-C``: a reach is the
vector solution (heading ``h`` with ``S(TWA(h))·u(h) + C`` along the leg), a beat two
boards at the VMG angles through the water, each plus ``C`` over the ground.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.routing.api import route_leg
from sailroute.routing.isochrone import route_isochrone
from sailroute.routing.settings import RoutingSettings, routing_settings
from sailroute.routing.types import Start, Target
from sailroute.units import KNOT
from sailroute.wind.build import current_from_spec
from sailroute.wind.current import DiamondCurrent, RelativeWind, UniformCurrent
from sailroute.wind.uniform import UniformWind
from tests.routing.polars import laser_like_polar

POLAR = laser_like_polar()
TWS = 4.37
T0 = 1_524_567_600.0
SET = RoutingSettings()


def mark(length, rounding="port"):
    return Target("mark", (0.0, length), rounding=rounding, name="1")


def water_wind(wind, current):
    u, v = (float(a) for a in RelativeWind(wind, current).sample(T0, 0.0, 0.0))
    return math.hypot(u, v), math.degrees(math.atan2(-u, -v))


def vector_time(wind, current, x, y):
    """Straight to (x, y): heading h with the ground velocity S(TWA(h)) u(h) + C along
    (x, y) (bisection on the crab angle), t = distance / ground speed."""
    tws, twd = water_wind(wind, current)
    cu, cv = (float(a) for a in current.sample(T0, 0.0, 0.0))
    b = math.atan2(x, y)
    ex, ey = math.sin(b), math.cos(b)

    def ground(h):
        s = float(POLAR.speed(tws, twd - h))
        gx, gy = s * math.sin(math.radians(h)) + cu, s * math.cos(math.radians(h)) + cv
        return gx * ey - gy * ex, gx * ex + gy * ey  # across, along

    lo, hi = math.degrees(b) - 60.0, math.degrees(b) + 60.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ground(lo)[0] * ground(mid)[0] > 0 else (lo, mid)
    return math.hypot(x, y) / ground(0.5 * (lo + hi))[1]


def reach_bounds(wind, current, L):
    """The leg ends on the mark's 13 m rounding segment (pointing east): lower bound the
    best straight line to any of its points, upper bound to a point 1 m inside its ends
    (where the router aims), 0.1 m scans."""
    r = np.linspace(0.0, SET.zone_m, 131)
    t = np.array([vector_time(wind, current, ri, L) for ri in r])
    inner = (r >= 1.0 - 1e-9) & (r <= SET.zone_m - 1.0 + 1e-9)
    return float(t.min()), float(t[inner].min())


@pytest.mark.parametrize(
    ("twd", "rate", "set_deg"), [(90.0, 0.5, 200.0), (90.0, 0.8, 90.0), (270.0, 0.6, 0.0)]
)
def test_reach_in_uniform_current_is_the_vector_solution(twd, rate, set_deg):
    L = 800.0
    wind, cur = UniformWind(TWS, twd), UniformCurrent(rate, set_deg)
    r = route_isochrone(Start((0.0, 0.0)), mark(L), T0, wind, POLAR, SET, current=cur)
    lower, upper = reach_bounds(wind, cur, L)
    assert lower * (1 - 1e-9) <= r.time_s <= upper * (1 + 1e-3)  # measured: <= 7e-5 above
    assert (r.n_tacks, r.n_gybes) == (0, 0)
    # over the ground the boat goes straight; through the water it crabs into the current
    tr = r.track
    cu, cv = (float(a) for a in cur.sample(T0, 0.0, 0.0))
    hr = np.radians(tr.heading_deg)
    assert np.allclose(tr.sog_ms * np.sin(np.radians(tr.cog_deg)), tr.bsp_ms * np.sin(hr) + cu)
    assert np.allclose(tr.sog_ms * np.cos(np.radians(tr.cog_deg)), tr.bsp_ms * np.cos(hr) + cv)


def laylines_time(wind, current, target, pen):
    """One tack, both boards at the VMG angles through the water: a g1 + pen C + b g2 =
    target (the boat drifts during the penalty), t = a + pen + b."""
    tws, twd = water_wind(wind, current)
    a_up, vmg = (float(v) for v in POLAR.vmg_upwind(tws))
    s = vmg / math.cos(math.radians(a_up))
    c = np.array([float(a) for a in current.sample(T0, 0.0, 0.0)])
    g = [
        s
        * np.array([math.sin(math.radians(twd + k * a_up)), math.cos(math.radians(twd + k * a_up))])
        + c
        for k in (-1, 1)
    ]
    a, b = np.linalg.solve(np.stack(g, axis=1), np.asarray(target) - pen * c)
    assert a > 0 and b > 0
    return a + b + pen


@pytest.mark.parametrize(("rate", "set_deg"), [(0.6, 90.0), (0.6, 270.0), (0.4, 135.0)])
def test_beat_in_uniform_current_is_the_layline_solution(rate, set_deg):
    L = 1000.0
    st = routing_settings(SET, dt_s=5.0)
    wind, cur = UniformWind(TWS, 0.0), UniformCurrent(rate, set_deg)
    r = route_isochrone(Start((0.0, 0.0)), mark(L), T0, wind, POLAR, st, current=cur)
    # the leg ends on the mark's 13 m rounding segment (pointing east); the closed form
    # is linear along it, so its best point is an end
    expected = min(laylines_time(wind, cur, (x, L), st.tack_penalty_s) for x in (0.0, st.zone_m))
    assert r.time_s == pytest.approx(expected, rel=1e-3)  # measured: 1.0e-4 .. 2.4e-4
    assert (r.n_tacks, r.n_gybes) == (1, 0)


@pytest.mark.parametrize("twd", [0.0, 90.0, 200.0])
def test_zero_current_changes_nothing(twd):
    wind = UniformWind(TWS, twd)
    a = route_isochrone(Start((0.0, 0.0)), mark(700.0), T0, wind, POLAR, SET)
    b = route_isochrone(
        Start((0.0, 0.0)), mark(700.0), T0, wind, POLAR, SET, current=UniformCurrent(0.0, 0.0)
    )
    assert abs(a.time_s - b.time_s) <= 1e-9
    assert a.track.sog_ms is None and a.track.cog_deg is None
    assert np.array_equal(a.track.ground_speed_ms, a.track.bsp_ms)
    assert np.allclose(b.track.sog_ms, b.track.bsp_ms)


def test_route_leg_without_current_is_the_old_call():
    wind = UniformWind(TWS, 45.0)
    a = route_isochrone(Start((0.0, 0.0)), mark(600.0), T0, wind, POLAR, SET)
    b = route_leg(Start((0.0, 0.0)), mark(600.0), T0, wind, POLAR, SET)
    assert a.time_s == b.time_s
    assert np.array_equal(a.track.x, b.track.x)


def test_diamonds_interpolate_the_vector_at_known_hours():
    hw = T0
    d = DiamondCurrent(hw, [-1.0, 0.0, 1.0], [90.0, 90.0, 270.0], [1.0, 2.0, 2.0])
    u, v = d.sample(hw + np.array([-3600.0, -1800.0, 0.0, 1800.0, 3600.0]), 0.0, 0.0)
    # east 1 -> east 2 -> west 2: halfway vectors 1.5 east, then slack (0) at HW+30 min
    assert np.allclose(u, [1.0, 1.5, 2.0, 0.0, -2.0], atol=1e-12)
    assert np.allclose(v, 0.0, atol=1e-12)


FRAME = LocalFrame(43.0, 6.2)


def spec(s, **kw):
    return current_from_spec(
        s, frame=FRAME, base_dir=Path("."), where="c.yaml:3: scenarios.spring.current", **kw
    )


def test_current_spec_builds_each_kind():
    u = spec({"type": "uniform", "speed_kn": 2.0, "set_deg": 90})
    assert np.allclose(u.sample(T0, 0.0, 0.0), (2.0 * KNOT, 0.0), atol=1e-12)
    d = spec(
        {
            "type": "diamonds",
            "high_water": "2018-04-24T11:00:00Z",
            "table": [[-6, 250, 0.4], [0, 70, 1.2], [6, 250, 0.5]],
        },
        time_window=(T0, T0 + 3600.0),
    )
    assert float(np.hypot(*d.sample(T0, 0.0, 0.0))) == pytest.approx(1.2 * KNOT)


@pytest.mark.parametrize(
    ("s", "needle"),
    [
        ({"type": "tidal"}, "type: expected one of 'uniform', 'diamonds', 'netcdf'"),
        ({"type": "uniform", "set_deg": 90}, "speed_kn: missing required key"),
        ({"type": "uniform", "speed_kn": -1, "set_deg": 90}, "speed_kn: expected a number >= 0"),
        ({"type": "uniform", "speed_kn": 1, "set_deg": 90, "drift": 2}, "drift: unknown key"),
        (
            {"type": "diamonds", "high_water": "2018-04-24T11:00:00Z", "table": [[0, 70]]},
            "table[0]: expected [hour, set_deg, rate_kn]",
        ),
        (
            {
                "type": "diamonds",
                "high_water": "2018-04-24T11:00:00Z",
                "table": [[1, 70, 1], [0, 80, 1]],
            },
            "table[1]: the hours must increase",
        ),
        ({"type": "diamonds", "table": [[0, 70, 1]]}, "high_water: missing required key"),
        ({"type": "netcdf", "path": "nowhere.nc"}, "path: file not found"),
    ],
)
def test_current_spec_errors_name_the_key(s, needle):
    with pytest.raises(InputError) as exc:
        spec(s)
    assert "c.yaml:3: scenarios.spring.current" in str(exc.value)
    assert needle in str(exc.value)


def test_diamonds_must_cover_the_race():
    with pytest.raises(InputError, match="does not cover"):
        spec(
            {
                "type": "diamonds",
                "high_water": "2018-04-24T11:00:00Z",
                "table": [[-1, 70, 1], [1, 80, 1]],
            },
            time_window=(T0, T0 + 3 * 3600.0),
        )


@pytest.mark.parametrize("router", ["griddp", "spline"])
def test_other_routers_refuse_a_current(router):
    with pytest.raises(InputError, match=r"set routing.router: isochrone"):
        route_leg(
            Start((0.0, 0.0)),
            mark(500.0),
            T0,
            UniformWind(TWS, 90.0),
            POLAR,
            replace(SET, router=router),
            current=UniformCurrent(0.5, 0.0),
        )


def test_gridded_netcdf_current_equals_the_uniform_one_it_holds(tmp_path):
    # a CMEMS-style file (uo/vo, CF standard names, m/s) holding 0.6 m/s towards 200° on
    # a lat/lon grid: bilinear in a uniform field is that field, so the route equals the
    # UniformCurrent route (the grid's rotation into the local frame is < 0.01° here)
    import netCDF4

    frame = LocalFrame(43.0, 7.0)
    lats, lons = np.arange(42.95, 43.06, 0.01), np.arange(6.95, 7.06, 0.01)
    cu, cv = 0.6 * math.sin(math.radians(200.0)), 0.6 * math.cos(math.radians(200.0))
    path = tmp_path / "cur.nc"
    with netCDF4.Dataset(str(path), "w") as ds:
        ds.createDimension("time", 2)
        ds.createDimension("latitude", lats.size)
        ds.createDimension("longitude", lons.size)
        t = ds.createVariable("time", "f8", ("time",))
        t.units, t[:] = "seconds since 1970-01-01 00:00:00", [T0 - 3600.0, T0 + 7200.0]
        la = ds.createVariable("latitude", "f8", ("latitude",))
        la.standard_name, la.units, la[:] = "latitude", "degrees_north", lats
        lo = ds.createVariable("longitude", "f8", ("longitude",))
        lo.standard_name, lo.units, lo[:] = "longitude", "degrees_east", lons
        for name, std, val in (
            ("uo", "eastward_sea_water_velocity", cu),
            ("vo", "northward_sea_water_velocity", cv),
        ):
            v = ds.createVariable(name, "f4", ("time", "latitude", "longitude"))
            v.standard_name, v.units = std, "m s-1"
            v[:] = np.full((2, lats.size, lons.size), val, dtype=np.float32)
    grid = current_from_spec(
        {"type": "netcdf", "path": "cur.nc"},
        frame=frame,
        base_dir=tmp_path,
        where="c.yaml: scenarios.s.current",
    )
    u, v = grid.sample(T0, 100.0, 200.0)
    assert math.hypot(float(u), float(v)) == pytest.approx(0.6, rel=1e-6)
    wind = UniformWind(TWS, 90.0)
    a = route_isochrone(Start((0.0, 0.0)), mark(700.0), T0, wind, POLAR, SET, current=grid)
    b = route_isochrone(
        Start((0.0, 0.0)), mark(700.0), T0, wind, POLAR, SET, current=UniformCurrent(0.6, 200.0)
    )
    assert a.time_s == pytest.approx(b.time_s, rel=1e-4)
