"""The WindField contract, checked on every implementation built to represent one constant wind.

Each source is built so that the wind is constant *in the local frame*: 5 m/s blowing
from local bearing 150 deg.  (A wind constant in true east/north components would turn
by the meridian convergence across the area, ~0.01 deg per km east here.)
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from conftest import T0

from sailroute.analysis.infer_wind import InferredWind
from sailroute.errors import OutOfCoverageError
from sailroute.geo import LocalFrame
from sailroute.units import wind_components
from sailroute.wind.analytic import AnalyticWind
from sailroute.wind.base import Coverage, WindField
from sailroute.wind.blended import BlendedWind
from sailroute.wind.cf import open_netcdf
from sailroute.wind.measured import MeasuredSeries, boat_wind, fleet_wind
from sailroute.wind.rotation import rotate_clockwise
from sailroute.wind.stations import StationData, StationWind
from sailroute.wind.uniform import UniformWind
from sailroute.wind.wrf import open_wrf

TWS, TWD = 5.0, 150.0
U0, V0 = (float(a) for a in wind_components(TWS, TWD))


def local_constant_wind(frame: LocalFrame) -> Callable:
    """``wind10`` whose local-frame components are (U0, V0) everywhere."""

    def f(t, lat, lon):
        return rotate_clockwise(
            np.full(lat.shape, U0), np.full(lat.shape, V0), -frame.grid_north_deg(lat, lon)
        )

    return f


def local_constant_profile(frame: LocalFrame) -> Callable:
    w10 = local_constant_wind(frame)

    def f(t, lat, lon, z):  # power law 0.12, reproduced exactly at 10 m by U10/V10
        u, v = w10(t, lat, lon)
        k = (z / 10.0) ** 0.12
        return u * k, v * k

    return f


def stations_constant(
    frame: LocalFrame, xy=((-1500.0, -1000.0), (1200.0, -800.0), (0.0, 1500.0))
) -> StationData:
    """Stations reading the local constant wind every 5 min from T0 to T0 + 30 min."""
    t = T0 + 300.0 * np.arange(7)
    ids, tt, la, lo, d = [], [], [], [], []
    for k, (x, y) in enumerate(xy):
        lat, lon = frame.to_latlon(x, y)
        twd_true = (TWD - float(frame.grid_north_deg(lat, lon))) % 360.0
        ids += [f"S{k}"] * t.size
        tt += list(t)
        la += [float(lat)] * t.size
        lo += [float(lon)] * t.size
        d += [twd_true] * t.size
    n = len(tt)
    return StationData(
        np.array(ids),
        np.array(tt),
        np.array(la),
        np.array(lo),
        np.full(n, TWS),
        np.array(d),
        np.full(n, 10.0),
        np.full(n, np.nan),
    )


def build(kind: str, tiny_wrf, frame: LocalFrame, clamp: bool) -> WindField:
    if kind == "uniform":
        return UniformWind(TWS, TWD, clamp=clamp)
    if kind == "uniform-table":
        return UniformWind([TWS, TWS], [TWD, TWD], times=[T0, T0 + 1800.0], clamp=clamp)
    if kind == "inferred":  # wind inferred from tracks, 30 s grid over 30 min
        t = T0 + 30.0 * np.arange(61)
        n = t.size
        return InferredWind(
            t,
            np.full(n, TWD),
            np.full(n, 1.0),
            np.full(n, np.nan),
            np.full(n, np.nan),
            np.full(n, 50),
            "contract",
        ).field(frame, tws_ms=TWS, clamp=clamp)
    if kind == "analytic":
        cover = Coverage(T0, T0 + 1800.0, -2000.0, 2000.0, -1500.0, 1500.0)
        return AnalyticWind(lambda t, x, y: (U0, V0), cover, clamp=clamp)
    path = tiny_wrf(
        "contract.nc", wind10=local_constant_wind(frame), wind_at=local_constant_profile(frame)
    )
    if kind == "wrf-linear":
        return open_wrf(path, frame, clamp=clamp)
    if kind == "wrf-nearest":
        return open_wrf(path, frame, interpolation="nearest", clamp=clamp)
    if kind == "wrf-frozen-10min":
        return open_wrf(path, frame, time_step_min=10, clamp=clamp)
    if kind == "wrf-2.68m":  # scaled from the model levels: constant speed again
        return open_wrf(path, frame, height_m=10.0, levels="model", clamp=clamp)
    if kind == "netcdf-cf":
        return open_netcdf(cf_constant(tiny_wrf, frame), frame, clamp=clamp)
    if kind == "stations-idw":
        return StationWind(stations_constant(frame), frame, clamp=clamp)
    if kind == "stations-rbf":
        return StationWind(stations_constant(frame), frame, method="rbf", clamp=clamp)
    if kind == "boat-measured":
        return boat_wind(boat_constant(frame), frame, clamp=clamp)
    if kind == "fleet-measured":
        return fleet_wind([boat_constant(frame, k) for k in range(3)], frame, clamp=clamp).field
    if kind == "blended":
        return BlendedWind(open_wrf(path, frame), stations_constant(frame), frame, clamp=clamp)
    raise AssertionError(kind)


def boat_constant(frame: LocalFrame, k: int = 0) -> MeasuredSeries:
    """Boat k sailing east at 5 m/s for 30 min, reading the local constant wind at 1 Hz."""
    t = T0 + np.arange(1801.0)
    lat, lon = frame.to_latlon(-4500.0 + 5.0 * np.arange(1801.0), np.full(1801, 300.0 * k))
    u, v = wind_components(TWS, (TWD - frame.grid_north_deg(lat, lon)) % 360.0)
    return MeasuredSeries(f"B{k}", f"b{k}.csv", t, lat, lon, u, v, "tws/twd")


def cf_constant(tiny_wrf, frame: LocalFrame):
    """A CF lat/lon file (descending latitudes) holding the local constant wind."""
    import netCDF4

    path = tiny_wrf("contract.nc").with_name("contract_cf.nc")
    lat = np.linspace(45.03, 44.97, 7)
    lon = np.linspace(9.96, 10.04, 9)
    LAT, LON = np.meshgrid(lat, lon, indexing="ij")
    ue, ve = local_constant_wind(frame)(T0, LAT, LON)
    with netCDF4.Dataset(path, "w") as ds:
        for name, n in (("time", 4), ("latitude", lat.size), ("longitude", lon.size)):
            ds.createDimension(name, n)
        tv = ds.createVariable("time", "f8", ("time",))
        tv.units = "minutes since 2018-04-24 08:00:00"
        tv[:] = [0.0, 10.0, 20.0, 30.0]
        for name, vals, units in (
            ("latitude", lat, "degrees_north"),
            ("longitude", lon, "degrees_east"),
        ):
            v = ds.createVariable(name, "f8", (name,))
            v.units = units
            v[:] = vals
        for name, std, vals in (("u10", "eastward_wind", ue), ("v10", "northward_wind", ve)):
            v = ds.createVariable(name, "f4", ("time", "latitude", "longitude"))
            v.standard_name, v.units = std, "m s-1"
            v[:] = np.broadcast_to(vals, (4, *vals.shape))
    return path


KINDS = [
    "uniform",
    "uniform-table",
    "inferred",
    "analytic",
    "wrf-linear",
    "wrf-nearest",
    "wrf-frozen-10min",
    "wrf-2.68m",
    "netcdf-cf",
    "stations-idw",
    "stations-rbf",
    "blended",
    "boat-measured",
    "fleet-measured",
]
# Exact for the analytic sources; float32 storage in WRF files limits those to ~1e-6 m/s.
TOL = {
    "uniform": 1e-12,
    "uniform-table": 1e-12,
    "inferred": 1e-12,
    "analytic": 1e-12,
    "stations-idw": 1e-12,
    "stations-rbf": 1e-9,
    "boat-measured": 1e-12,
    "fleet-measured": 1e-12,
}


@pytest.fixture(params=KINDS)
def field_and_tol(request, tiny_wrf, frame):
    return (
        build(request.param, tiny_wrf, frame, clamp=False),
        build(request.param, tiny_wrf, frame, clamp=True),
        TOL.get(request.param, 2e-5),
    )


def _inside(c, n=5):
    """n points inside the coverage (finite stand-ins for unbounded axes)."""

    def span(lo, hi, d):
        lo = lo if np.isfinite(lo) else d[0]
        hi = hi if np.isfinite(hi) else d[1]
        return np.linspace(lo, hi, n)

    return (
        span(c.t0, c.t1, (T0, T0 + 1800.0)),
        span(c.xmin, c.xmax, (-1e4, 1e4)),
        span(c.ymin, c.ymax, (-1e4, 1e4)),
    )


def test_protocol_and_values(field_and_tol) -> None:
    f, fc, tol = field_and_tol
    assert isinstance(f, WindField) and isinstance(fc, WindField)
    # the clamp flag is part of the contract: routers read it, they never probe for it
    assert (f.clamp, fc.clamp) == (False, True)
    t, x, y = _inside(f.coverage)
    u, v = f.sample(t, x, y)
    assert u.dtype == np.float64 and v.dtype == np.float64
    np.testing.assert_allclose(u, U0, atol=tol)
    np.testing.assert_allclose(v, V0, atol=tol)


def test_broadcasting_shapes(field_and_tol) -> None:
    f, _, tol = field_and_tol
    t, x, y = _inside(f.coverage)
    u, v = f.sample(t[2], x[1:4].reshape(3, 1), y[:4].reshape(1, 4))
    assert u.shape == v.shape == (3, 4)
    np.testing.assert_allclose(u, U0, atol=tol)
    u, v = f.sample(t[1], x[1], y[1])
    assert np.shape(u) == np.shape(v) == ()
    u, v = f.sample(np.array([]), np.array([]), np.array([]))
    assert u.shape == v.shape == (0,)


def test_inputs_untouched_and_deterministic(field_and_tol) -> None:
    f, _, _ = field_and_tol
    t, x, y = _inside(f.coverage)
    keep = (t.copy(), x.copy(), y.copy())
    a = f.sample(t, x, y)
    b = f.sample(t, x, y)
    for p, q in zip((t, x, y), keep, strict=True):
        np.testing.assert_array_equal(p, q)
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])


def test_edges_are_inside(field_and_tol) -> None:
    f, _, tol = field_and_tol
    c = f.coverage
    t, x, y = _inside(c)
    corners_t = np.array([t[0], t[-1], t[0], t[-1]])
    corners_x = np.array([x[0], x[-1], x[-1], x[0]])
    corners_y = np.array([y[0], y[-1], y[0], y[-1]])
    u, v = f.sample(corners_t, corners_x, corners_y)
    np.testing.assert_allclose(u, U0, atol=tol)
    np.testing.assert_allclose(v, V0, atol=tol)


def test_outside_raises_and_clamp_holds_edge(field_and_tol) -> None:
    f, fc, tol = field_and_tol
    c = f.coverage
    t, x, y = _inside(c, 3)
    probes = []
    if np.isfinite(c.t1):
        probes.append((c.t1 + 60.0, x[1], y[1]))
    if np.isfinite(c.xmax):
        probes += [(t[1], c.xmax + 10.0, y[1]), (t[1], x[1], c.ymin - 10.0)]
    for p in probes:
        with pytest.raises(OutOfCoverageError) as e:
            f.sample(*p)
        assert "requested" in str(e.value) and "covered" in str(e.value)
        u, v = fc.sample(*p)
        np.testing.assert_allclose([u, v], [U0, V0], atol=tol)
    # NaN is never "clamped" to an edge: both modes refuse it (no NaN winds out)
    for g in (f, fc):
        with pytest.raises(OutOfCoverageError, match="1 of 3 sample points contain NaN"):
            g.sample(t[1], np.array([x[1], np.nan, x[1]]), y[1])
        with pytest.raises(OutOfCoverageError, match="NaN"):
            g.sample(np.nan, x[1], y[1])
    if not probes:  # unbounded (constant uniform wind): anything goes
        u, _ = f.sample(1e12, 1e9, -1e9)
        assert float(u) == pytest.approx(U0, abs=tol)
