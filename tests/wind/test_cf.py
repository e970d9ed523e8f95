"""Gridded lat/lon wind (CF NetCDF, xarray datasets): sailroute/wind/cf.py.

The files are written here with netCDF4 following CF 1.8, with winds given by a
formula of latitude and longitude, so every sampled value has a known answer
independent of the reader: the formula at the point, rotated into the local frame.
"""

from __future__ import annotations

from pathlib import Path

import netCDF4
import numpy as np
import pytest

from sailroute.errors import InputError, OutOfCoverageError, WindDataError
from sailroute.geo import LocalFrame
from sailroute.units import KNOT, wind_components
from sailroute.wind.build import check_covers, wind_from_spec, wind_notes
from sailroute.wind.cf import open_grib, open_netcdf, read_cf_header
from sailroute.wind.rotation import earth_to_local
from sailroute.wind.wrf import open_wrf
from tests.conftest import SHARED_REAL, WIND_DATA, requires_shared

T0 = 1412683200.0  # 2014-10-07T12:00:00Z
FRAME = LocalFrame(43.0, 7.0)


def ue_f(lat, lon, k=1.0):
    """True east wind [m/s]: linear in lat/lon, so bilinear interpolation is exact."""
    return k * (5.0 + 10.0 * (lat - 43.0))


def ve_f(lat, lon, k=1.0):
    return k * (-3.0 + 20.0 * (np.mod(lon + 180.0, 360.0) - 180.0 - 7.0))


def expected_local(frame, x, y, k=1.0):
    lat, lon = frame.to_latlon(x, y)
    return earth_to_local(ue_f(lat, lon, k), ve_f(lat, lon, k), frame.grid_north_deg(lat, lon))


def write_cf(
    path: Path,
    *,
    lats=None,
    lons=None,
    times=(0.0, 3600.0, 7200.0),
    factors=None,
    names=("u10", "v10"),
    std=("eastward_wind", "northward_wind"),
    units="m s-1",
    kind="uv",
    land=None,
    height=10.0,
    time_units="seconds since 2014-10-07 12:00:00",
    extra_dim=0,
) -> Path:
    """A CF file with 1-D lat/lon axes (descending latitude by default)."""
    lats = np.arange(43.3, 42.69, -0.05) if lats is None else np.asarray(lats)
    lons = np.arange(6.6, 7.41, 0.05) if lons is None else np.asarray(lons)
    if factors is None:
        factors = np.linspace(1.0, 2.0, len(times)) if times is not None else [1.0]
    with netCDF4.Dataset(path, "w") as ds:
        ds.Conventions = "CF-1.8"
        if times is not None:
            ds.createDimension("time", None)
        ds.createDimension("lat", lats.size)
        ds.createDimension("lon", lons.size)
        dims = ("lat", "lon")
        if times is not None:
            dims = ("time", *dims)
            tv = ds.createVariable("time", "f8", ("time",))
            tv.units, tv.standard_name, tv.calendar = time_units, "time", "standard"
            tv[:] = np.asarray(times)
        if extra_dim:
            ds.createDimension("member", extra_dim)
            dims = ("member", *dims)
        la = ds.createVariable("lat", "f8", ("lat",))
        la.standard_name, la.units = "latitude", "degrees_north"
        la[:] = lats
        lo = ds.createVariable("lon", "f8", ("lon",))
        lo.standard_name, lo.units = "longitude", "degrees_east"
        lo[:] = lons
        if height is not None:
            h = ds.createVariable("height", "f8", ())
            h.standard_name, h.units, h.positive = "height", "m", "up"
            h[()] = height
        LAT, LON = np.meshgrid(lats, lons, indexing="ij")
        nt = len(times) if times is not None else 1
        ks = np.asarray(factors, dtype=float).reshape(-1, 1, 1)[:nt]
        u = ue_f(LAT, LON) * ks
        v = ve_f(LAT, LON) * ks
        if kind == "sd":
            spd = np.hypot(u, v)
            d = np.mod(np.degrees(np.arctan2(-u, -v)), 360.0)
            a, b = spd / (KNOT if units == "knots" else 1.0), d
        else:
            a, b = u, v
        if land is not None:
            a = np.where(land, np.nan, a)
            b = np.where(land, np.nan, b)
        if times is None:
            a, b = a[0], b[0]
        if extra_dim:
            a = np.broadcast_to(a, (extra_dim, *a.shape))
            b = np.broadcast_to(b, (extra_dim, *b.shape))
        for name, s, arr, un in (
            (names[0], std[0], a, units),
            (names[1], std[1], b, "degree" if kind == "sd" else units),
        ):
            var = ds.createVariable(name, "f4", dims, fill_value=np.float32(1e20))
            if s:
                var.standard_name = s
            var.units = un
            if height is not None:
                var.coordinates = "height"
            var[:] = np.ma.masked_invalid(arr)
    return path


BOX = (-3000.0, 3000.0, -3000.0, 3000.0)


def probe(n=40, seed=1, box=BOX):
    rng = np.random.default_rng(seed)
    return rng.uniform(box[0], box[1], n), rng.uniform(box[2], box[3], n)


# --------------------------------------------------------------------------- values
def test_regular_grid_descending_lat_values_rotation_and_time(tmp_path) -> None:
    f = open_netcdf(write_cf(tmp_path / "a.nc"), FRAME, bbox=BOX)
    x, y = probe()
    for t, k in ((T0, 1.0), (T0 + 1800.0, 1.25), (T0 + 7200.0, 2.0)):
        u, v = f.sample(t, x, y)
        eu, ev = expected_local(FRAME, x, y, k)
        np.testing.assert_allclose(u, eu, atol=2e-3)
        np.testing.assert_allclose(v, ev, atol=2e-3)
    info = f.info
    assert info["found_by"] == "standard_name" and info["variables"] == ("u10", "v10")
    assert info["data_height_m"] == 10.0 and info["height_source"] == "coordinate height"
    assert info["time_source"] == "variable time"
    assert f.coverage.source_span == (T0, T0 + 7200.0)


def test_longitudes_0_to_360_across_the_seam(tmp_path) -> None:
    # a grid stored 0..359.5, course on the Greenwich meridian: the columns just west
    # of 0 deg are at the far end of the file
    lons = np.arange(0.0, 360.0, 0.5)
    # (half the test field: at the seam it reaches 160 m/s, which the reader refuses)
    p = write_cf(
        tmp_path / "g.nc",
        lats=np.arange(44.0, 42.0, -0.25),
        lons=lons,
        times=(0.0,),
        factors=(0.5,),
    )
    frame = LocalFrame(43.0, 0.0)
    f = open_netcdf(p, frame, bbox=(-20000.0, 20000.0, -20000.0, 20000.0), steady=True)
    assert f.shape[2] < 20  # cropped around the seam, not the whole globe
    x, y = probe(box=(-20000.0, 20000.0, -20000.0, 20000.0))
    lat, lon = frame.to_latlon(x, y)
    assert lon.min() < 0 < lon.max()
    u, v = f.sample(T0 + 1e6, x, y)  # steady: any time
    eu, ev = earth_to_local(
        ue_f(lat, lon, 0.5), ve_f(lat, lon, 0.5), frame.grid_north_deg(lat, lon)
    )
    np.testing.assert_allclose(u, eu, atol=2e-2)  # 0.5 deg cells: index map misfit ~0.01 cell
    np.testing.assert_allclose(v, ev, atol=2e-2)


def test_speed_direction_in_knots_and_explicit_names(tmp_path) -> None:
    p = write_cf(tmp_path / "sd.nc", names=("WS", "WD"), std=("", ""), units="knots", kind="sd")
    with pytest.raises(WindDataError, match=r"no wind variables found.*found: .*WS, WD"):
        read_cf_header(p)
    f = open_netcdf(p, FRAME, bbox=BOX, variables={"speed": "WS", "direction": "WD"})
    x, y = probe()
    u, v = f.sample(T0 + 3600.0, x, y)
    eu, ev = expected_local(FRAME, x, y, 1.5)
    np.testing.assert_allclose(u, eu, atol=2e-3)
    np.testing.assert_allclose(v, ev, atol=2e-3)
    assert f.info["units"] == "knots"


def test_curvilinear_x_y_order_and_height_correction(tmp_path) -> None:
    # 2-D lat/lon stored (x, y) with x first, like the Ligurian files; a rotated grid
    p = tmp_path / "curv.nc"
    ii, jj = np.meshgrid(np.arange(30), np.arange(25), indexing="ij")  # (x, y)
    lat = 42.8 + 0.012 * jj + 0.002 * ii
    lon = 6.8 + 0.016 * ii - 0.003 * jj
    with netCDF4.Dataset(p, "w") as ds:
        ds.ref_time = "2014-10-07T12:00:00"
        ds.createDimension("x", 30)
        ds.createDimension("y", 25)
        for name, arr in (
            ("lat", lat),
            ("lon", lon),
            ("u10", ue_f(lat, lon)),
            ("v10", ve_f(lat, lon)),
        ):
            v = ds.createVariable(name, "f8", ("x", "y"))
            v[:] = arr
    hdr = read_cf_header(p)
    assert (hdr.row_dim, hdr.col_dim) == ("y", "x")
    assert hdr.times.tolist() == [T0] and "ref_time" in hdr.time_source
    f = open_netcdf(p, FRAME, bbox=BOX, height_m=2.68, steady=True)
    x, y = probe()
    u, v = f.sample(T0, x, y)
    k = (2.68 / 10.0) ** (1.0 / 7.0)
    eu, ev = expected_local(FRAME, x, y, k)
    np.testing.assert_allclose(u, eu, atol=2e-3)
    np.testing.assert_allclose(v, ev, atol=2e-3)
    assert f.info["height_source"] == "variable name u10" and f.info["height_m"] == 2.68


# --------------------------------------------------------------------------- NaN cells
def test_nan_land_cells_are_holes_that_routing_may_not_cross(tmp_path) -> None:
    lats = np.arange(43.3, 42.69, -0.05)
    lons = np.arange(6.6, 7.41, 0.05)
    LAT, LON = np.meshgrid(lats, lons, indexing="ij")
    land = np.broadcast_to((LAT > 43.02) & (LON > 7.02), (3, *LAT.shape))
    f = open_netcdf(write_cf(tmp_path / "land.nc", land=land), FRAME, bbox=BOX)
    assert f.info["nan_cells"] > 0
    assert "without wind: land or masked" in wind_notes(f)[0]
    u, _ = f.sample(T0, -2000.0, -2000.0)  # sea: fine
    assert np.isfinite(u)
    with pytest.raises(OutOfCoverageError) as e:
        f.sample(T0, [-2000.0, 3000.0], [-2000.0, 3000.0])
    msg = str(e.value)
    assert "the data hold no wind (NaN: land or masked cells) at 1 of 2 sample points" in msg
    assert "first at lat 43.02" in msg and "lon 7.03" in msg
    hole_u, _ = f.sample_with_holes(T0, 3000.0, 3000.0)
    assert np.isnan(hole_u)


def test_routing_into_nan_cells_raises(tmp_path) -> None:
    from sailroute.boat.build import boat_from_spec
    from sailroute.routing.api import route_leg
    from sailroute.routing.settings import RoutingSettings
    from sailroute.routing.types import Start, Target

    lats = np.arange(43.3, 42.69, -0.05)
    lons = np.arange(6.6, 7.41, 0.05)
    LAT, _ = np.meshgrid(lats, lons, indexing="ij")
    land = np.broadcast_to(np.abs(LAT - 43.0) < 0.03, (3, *LAT.shape))  # a land bridge
    f = open_netcdf(write_cf(tmp_path / "bridge.nc", land=land), FRAME, bbox=BOX)
    boat = boat_from_spec({"builtin": "ilca7"}, base_dir=tmp_path, where="boat")
    with pytest.raises(OutOfCoverageError, match="the data hold no wind"):
        route_leg(
            Start((0.0, -2500.0)),
            Target("mark", (0.0, 2500.0), rounding="port", name="1"),
            T0,
            f,
            boat,
            RoutingSettings(),
        )


def test_plan_near_land_cells_routes_and_checks_the_polar_over_the_sea(tmp_path) -> None:
    # land in the north-east corner of the course area's margin: the polar-range check
    # samples the area with holes (it once stopped here with the NaN error), the legs
    # stay on the sea and route
    from sailroute.course.load import course_from_mapping
    from sailroute.planning.route import plan_course

    lats = np.arange(43.3, 42.69, -0.05)
    lons = np.arange(6.6, 7.41, 0.05)
    LAT, LON = np.meshgrid(lats, lons, indexing="ij")
    land = np.broadcast_to((LAT > 43.012) & (LON > 7.015), (3, *LAT.shape))
    write_cf(tmp_path / "coast.nc", land=land)
    course = course_from_mapping(
        {
            "name": "coast",
            "start_time": "2014-10-07T12:00:00Z",
            "time_limit_min": 60,
            "origin": {"lat": 43.0, "lon": 7.0},
            "marks": {"a": {"x": -300.0, "y": -1800.0}, "b": {"x": -300.0, "y": -200.0}},
            "legs": [{"from": "a", "to": "b"}],
            "scenarios": {"cf": {"wind": {"type": "netcdf", "path": "coast.nc"}}},
        },
        source=tmp_path / "coast.yaml",
    )
    run = plan_course(course)
    assert run.plan.total_time_s > 0 and run.notes == ()


# --------------------------------------------------------------------------- time, coverage
def test_single_time_needs_steady_and_coverage_message_names_lat_lon(tmp_path) -> None:
    p = write_cf(tmp_path / "one.nc", times=(0.0,))
    f = open_netcdf(p, FRAME, bbox=BOX)
    with pytest.raises(OutOfCoverageError) as e:
        check_covers(f, BOX, (T0, T0 + 3600.0), name="x.yaml: forecast")
    msg = str(e.value)
    assert "covered: time 2014-10-07T12:00:00.000Z .. 2014-10-07T12:00:00.000Z" in msg
    assert "(lat 42.9" in msg and "°N" in msg and "°E" in msg
    assert "set `steady: true`" in msg
    g = open_netcdf(p, FRAME, bbox=BOX, steady=True)
    check_covers(g, BOX, (T0, T0 + 3600.0))
    u, v = g.sample(T0 + 3600.0, 0.0, 0.0)
    np.testing.assert_allclose([u, v], expected_local(FRAME, 0.0, 0.0), atol=2e-3)


def test_cropped_window_message_names_the_files_whole_span(tiny_wrf, frame) -> None:
    # the race starts after the file's last slice: only that slice is read, and the
    # message must still say what the file holds (not "covered 14:00Z..14:00Z")
    path = tiny_wrf("late.nc")
    t_last = 1524556800.0 + 1800.0
    f = open_wrf(path, frame, time_window=(t_last + 3600.0, t_last + 7200.0))
    with pytest.raises(OutOfCoverageError) as e:
        check_covers(f, (-100.0, 100.0, -100.0, 100.0), (t_last + 3600.0, t_last + 7200.0))
    msg = str(e.value)
    assert "covered: time 2018-04-24T08:30:00.000Z .. 2018-04-24T08:30:00.000Z" in msg
    assert "the source holds 2018-04-24T08:00:00.000Z .. 2018-04-24T08:30:00.000Z" in msg
    assert "lat 44.9" in msg and "lon 9.9" in msg


def test_time_window_reads_only_the_bracketing_slices(tmp_path) -> None:
    times = np.arange(0.0, 24 * 3600.0 + 1, 3600.0)
    p = write_cf(tmp_path / "day.nc", times=times, factors=1.0 + times / 86400.0)
    f = open_netcdf(p, FRAME, bbox=BOX, time_window=(T0 + 5 * 3600 + 600, T0 + 6 * 3600))
    assert f.shape[0] == 2 and f.info["window"]["times"] == (5, 7)
    u, _ = f.sample(T0 + 5.5 * 3600, 0.0, 0.0)
    assert float(u) == pytest.approx(
        float(expected_local(FRAME, 0.0, 0.0, 1.0 + 5.5 / 24)[0]), abs=2e-3
    )


# --------------------------------------------------------------------------- errors
def test_errors_teach(tmp_path) -> None:
    p = write_cf(tmp_path / "nt.nc", times=None)
    with pytest.raises(
        WindDataError,
        match=r"no time found.*give the time the field is valid "
        r"at with `time: '2014-10-07T12:00:00Z'`",
    ):
        read_cf_header(p)
    assert read_cf_header(p, time="2014-10-07T14:00:00+02:00").times.tolist() == [T0]
    p = write_cf(tmp_path / "nh.nc", height=None, names=("eu", "ev"))
    with pytest.raises(InputError, match=r"needs the height of the winds.*set `data_height_m`"):
        open_netcdf(p, FRAME, bbox=BOX, height_m=2.68)
    assert (
        open_netcdf(p, FRAME, bbox=BOX, height_m=2.68, data_height_m=10.0).info["height_source"]
        == "argument"
    )
    p = write_cf(tmp_path / "ens.nc", extra_dim=3)
    with pytest.raises(
        WindDataError,
        match=r"extra dimension 'member' of size 3 .*"
        r"`ds.isel\(\{'member': 0\}\)`",
    ):
        read_cf_header(p)
    p = write_cf(tmp_path / "k.nc", units="furlongs per fortnight")
    with pytest.raises(WindDataError, match=r"units 'furlongs per fortnight'; expected a speed"):
        read_cf_header(p)
    with pytest.raises(
        OutOfCoverageError,
        match=r"the grid does not contain the course.\n"
        r"  course box: lat 44\.9",
    ):
        open_netcdf(write_cf(tmp_path / "far.nc"), LocalFrame(45.0, 7.0), bbox=BOX)


def test_course_spec_netcdf(tmp_path, tiny_wrf, frame) -> None:
    p = write_cf(tmp_path / "spec.nc", names=("UU", "VV"), std=("", ""))
    where = "x.yaml: scenarios.cf.wind"
    spec = {
        "type": "netcdf",
        "path": p.name,
        "variables": {"u": "UU", "v": "VV"},
        "height_m": 2.68,
        "time_step_min": 30,
    }
    f = wind_from_spec(
        spec,
        frame=FRAME,
        base_dir=tmp_path,
        where=where,
        crop_bbox=BOX,
        time_window=(T0, T0 + 3600.0),
    )
    u, _ = f.sample(T0 + 1700.0, 0.0, 0.0)  # frozen at the 12:00 block
    assert float(u) == pytest.approx(
        float(expected_local(FRAME, 0.0, 0.0, (2.68 / 10) ** (1 / 7))[0]), abs=2e-3
    )
    with pytest.raises(InputError) as e:
        wind_from_spec(
            {
                "type": "netcdf",
                "path": p.name,
                "variables": {"u": "UU", "w": 3},
                "steady": "yes",
                "tme": "x",
            },
            frame=FRAME,
            base_dir=tmp_path,
            where=where,
        )
    msg = str(e.value)
    assert f"{where}.variables.w: unknown key" in msg
    assert f"{where}.steady: expected true or false; got 'yes'" in msg
    assert f"{where}.tme: unknown key; did you mean 'time'?" in msg
    assert f"{where}.variables: give both u and v" in msg
    # a wrfout file named as netcdf is detected and read as WRF
    w = tiny_wrf("auto.nc")
    a = wind_from_spec(
        {"type": "netcdf", "path": str(w), "height_m": 2.68},
        frame=frame,
        base_dir=tmp_path,
        where=where,
    )
    b = wind_from_spec(
        {"type": "wrf", "path": str(w), "height_m": 2.68},
        frame=frame,
        base_dir=tmp_path,
        where=where,
    )
    np.testing.assert_array_equal(
        a.sample(1524556800.0, 10.0, 20.0), b.sample(1524556800.0, 10.0, 20.0)
    )
    with pytest.raises(InputError, match=r"not a WRF wrfout file.*use `type: netcdf`"):
        wind_from_spec({"type": "wrf", "path": str(p)}, frame=FRAME, base_dir=tmp_path, where=where)


# --------------------------------------------------------------------------- xarray
def test_xarray_dataset_in_and_to_xarray_round_trip(tmp_path, tiny_wrf, frame) -> None:
    xr = pytest.importorskip("xarray")
    p = write_cf(tmp_path / "x.nc")
    with xr.open_dataset(p) as ds:
        a = open_netcdf(ds, FRAME, bbox=BOX)
    b = open_netcdf(p, FRAME, bbox=BOX)
    x, y = probe()
    np.testing.assert_allclose(a.sample(T0 + 900.0, x, y), b.sample(T0 + 900.0, x, y), atol=1e-12)
    assert a.info["path"] == "xarray.Dataset" and a.info["time_source"] == "variable time"
    out = b.to_xarray()
    assert out["eastward_wind"].attrs["standard_name"] == "eastward_wind"
    assert str(out["time"].values[0]) == "2014-10-07T12:00:00.000000000"
    c = open_netcdf(out, FRAME)  # our own output is CF
    inner = (-2000.0, 2000.0, -2000.0, 2000.0)
    x, y = probe(box=inner)
    np.testing.assert_allclose(c.sample(T0 + 900.0, x, y), b.sample(T0 + 900.0, x, y), atol=1e-3)
    # open_wrf takes a dataset too
    w = tiny_wrf("xw.nc")
    with xr.open_dataset(w) as ds:
        d = open_wrf(ds, frame, height_m=2.68)
    e = open_wrf(w, frame, height_m=2.68)
    np.testing.assert_allclose(
        d.sample(1524556800.0, 50.0, 80.0), e.sample(1524556800.0, 50.0, 80.0), atol=1e-12
    )


def test_missing_xarray_is_a_clear_error(monkeypatch) -> None:
    import builtins

    from sailroute.wind.grid import GridWind

    real = builtins.__import__

    def no_xarray(name, *a, **k):
        if name == "xarray":
            raise ImportError("No module named 'xarray'")
        return real(name, *a, **k)

    g = GridWind(
        [T0],
        np.array([[0.0, 1.0], [0.0, 1.0]]),
        np.array([[0.0, 0.0], [1.0, 1.0]]),
        np.zeros((1, 2, 2)),
        np.zeros((1, 2, 2)),
    )
    monkeypatch.setattr(builtins, "__import__", no_xarray)
    with pytest.raises(InputError, match=r"install it with `pip install 'sailroute\[xarray\]'`"):
        g.to_xarray()


# --------------------------------------------------------------------------- real files
LIG = SHARED_REAL / "wrf" / "ligurian-sea"


@requires_shared
def test_ligurian_sea_fields() -> None:
    small = LIG / "ligurian_sea_2014-10-07T12-00-00_area_strong_wind_conv.nc"
    domain = LIG / "ligurian_sea_2014-10-07T12-00-00_area_domain.nc"
    with netCDF4.Dataset(small) as ds:  # a cell of the file, read independently
        lat, lon = ds["lat"][20, 18], ds["lon"][20, 18]
        u10, v10 = float(ds["u10"][20, 18]), float(ds["v10"][20, 18])
    frame = LocalFrame(float(lat), float(lon))
    f = open_netcdf(small, frame, bbox=(-2000.0, 2000.0, -2000.0, 2000.0), steady=True)
    eu, ev = earth_to_local(u10, v10, frame.grid_north_deg(lat, lon))
    np.testing.assert_allclose(f.sample(T0, 0.0, 0.0), (eu, ev), atol=1e-4)
    assert f.info["time_source"] == "global attribute ref_time (UTC)"
    assert wind_components(1.0, 0.0)[1] < 0  # sanity of the convention used above
    # the domain file has NaN land: a course off Nice touches it
    nice = LocalFrame(43.672, 7.279)
    g = open_netcdf(domain, nice, bbox=(-3000.0, 3000.0, -3000.0, 3000.0), steady=True)
    assert g.info["nan_cells"] > 0
    np.testing.assert_array_equal(np.isfinite(g.sample(T0, 0.0, -2000.0)), True)
    with pytest.raises(
        OutOfCoverageError,
        match=r"no wind \(NaN: land or masked cells\).*"
        r"first at lat 43\.6",
    ):
        g.sample(T0, 0.0, np.linspace(-2000.0, 3000.0, 11))


# --------------------------------------------------------------------------- GRIB
GRIB = WIND_DATA / "wind_10m_synthetic.grib2"  # made by tests/data/wind/make_grib.py


def test_grib_file_values_and_course_spec() -> None:
    pytest.importorskip("cfgrib")
    f = open_grib(GRIB, FRAME, bbox=BOX)
    assert f.info["format"] == "grib" and f.info["variables"] == ("u10", "v10")
    assert f.info["data_height_m"] == 10.0 and f.info["height_source"] == (
        "coordinate heightAboveGround"
    )
    assert f.coverage.t0 == T0 and f.coverage.t1 == T0 + 3600.0  # valid_time of the 2 steps
    x, y = probe()
    lat, lon = FRAME.to_latlon(x, y)
    gn = FRAME.grid_north_deg(lat, lon)
    for t, step in ((T0, 0.0), (T0 + 1800.0, 0.5), (T0 + 3600.0, 1.0)):
        eu, ev = earth_to_local(ue_f(lat, lon) + step, ve_f(lat, lon) - step, gn)
        u, v = f.sample(t, x, y)
        np.testing.assert_allclose(u, eu, atol=3e-3)  # 16-bit packing: ~3e-4 m/s steps
        np.testing.assert_allclose(v, ev, atol=3e-3)
    g = wind_from_spec(
        {"type": "grib", "path": GRIB.name, "height_m": 2.68},
        frame=FRAME,
        base_dir=WIND_DATA,
        where="x.yaml: scenarios.grib.wind",
        crop_bbox=BOX,
        time_window=(T0, T0 + 3600.0),
    )
    k = (2.68 / 10.0) ** (1.0 / 7.0)
    np.testing.assert_allclose(g.sample(T0, x, y), np.multiply(f.sample(T0, x, y), k), atol=1e-12)


def test_grib_without_cfgrib_says_how_to_install(monkeypatch) -> None:
    import builtins

    real = builtins.__import__

    def no_cfgrib(name, *a, **k):
        if name == "cfgrib":
            raise ImportError("No module named 'cfgrib'")
        return real(name, *a, **k)

    pytest.importorskip("xarray")
    monkeypatch.setattr(builtins, "__import__", no_cfgrib)
    with pytest.raises(
        InputError,
        match=r"reading GRIB needs the optional packages cfgrib and "
        r"eccodes .*`pip install 'sailroute\[grib\]'`",
    ):
        open_grib(GRIB, FRAME)


def test_a_dimension_with_an_empty_name_is_still_the_time_axis() -> None:
    # found by the fuzz test: a damaged header names the time dimension "" (a NUL byte);
    # the reader treated "" as no time axis and failed reshaping 3 x 3 x 3 values as 1 x 3 x 3
    from tests.unit.test_fuzz_inputs import FRAME

    w = open_netcdf(
        Path(__file__).parents[1] / "data" / "wind" / "damaged_dims.nc", FRAME, clamp=True
    )
    assert w.info["times"].endswith("(3 of 3 slices)")
    u, v = w.sample(w.times[1], 0.0, 0.0)
    assert float(u) == pytest.approx(1.0, abs=1e-3) and float(v) == pytest.approx(-5.0, abs=1e-3)
