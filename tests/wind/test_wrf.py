"""WRF reader/decoder/field: real-file known answers, rotation signs, height, sampling, errors."""

from __future__ import annotations

import dataclasses
import math
import shutil
from pathlib import Path

import netCDF4
import numpy as np
import pytest
from conftest import T0, constant_wind, power_profile

from sailroute.errors import InputError, OutOfCoverageError, WindDataError
from sailroute.geo import LocalFrame
from sailroute.timeutil import iso
from sailroute.units import wind_components, wind_speed_direction
from sailroute.wind.base import WindField
from sailroute.wind.rotation import earth_to_local
from sailroute.wind.wrf import (
    crop_window,
    decode_wrf,
    open_wrf,
    read_wrf,
    read_wrf_header,
)
from tests.conftest import SHARED_REAL, WIND_DATA, requires_shared

CI = WIND_DATA / "wrfpython_ci_crop.nc"
CI_REF = WIND_DATA / "wrfpython_ci_result_crop.nc"
SALEM = WIND_DATA / "salem_lambert_crop.nc"


# --------------------------------------------------------------------------- real files
def test_ci_times_and_xy_to_ll_known_answer() -> None:
    h = read_wrf_header(CI)
    assert [iso(t) for t in h.times] == [
        "2005-08-28T12:00:00.000Z",
        "2005-08-28T15:00:00.000Z",
        "2005-08-28T18:00:00.000Z",
        "2005-08-28T21:00:00.000Z",
    ]
    # wrf-python xy_to_ll(x=10, y=10) = (22.63660539, -90.75394145); XLAT is float32
    # (7 digits), so 2e-5 deg (~2 m) is the achievable agreement.
    with netCDF4.Dataset(CI_REF) as ref:
        ll = ref["ll"][:]
    assert ll[0] == pytest.approx(22.63660539, abs=1e-8)
    assert h.lat[10, 10] == pytest.approx(ll[0], abs=2e-5)
    assert h.lon[10, 10] == pytest.approx(ll[1], abs=2e-5)


def test_ci_ll_to_xy_known_answer() -> None:
    """wrf-python ll_to_xy(22.0, -90.0) = (18, 2), unrounded (18.38, 2.35)."""
    frame = LocalFrame(24.0, -90.0)
    field = open_wrf(CI, frame)
    i, j = field.grid_indices(*frame.to_xy(22.0, -90.0))
    # The README gives the unrounded indices to 2 decimals; our map fits XLAT/XLONG to
    # <0.01 cells, so 0.01 cells is the tolerance.
    assert float(i) == pytest.approx(18.38, abs=0.01)
    assert float(j) == pytest.approx(2.35, abs=0.01)
    with netCDF4.Dataset(CI_REF) as ref:
        assert [round(float(i)), round(float(j))] == ref["xy"][:].tolist()


def test_ci_mercator_earth_relative_equals_u10_v10() -> None:
    """Mercator (MAP_PROJ 3) has no grid rotation: uvmet10 = U10/V10 (wrf-python CI)."""
    frame = LocalFrame(23.5, -91.0)
    raw = read_wrf(CI)
    dec = decode_wrf(raw, frame)
    assert dec.rotation == "none"
    with netCDF4.Dataset(CI_REF) as ref:
        uvmet10 = ref["uvmet10"][:]
    np.testing.assert_array_equal(dec.u_earth[0], uvmet10[0])
    np.testing.assert_array_equal(dec.v_earth[0], uvmet10[1])
    np.testing.assert_array_equal(dec.u_earth, raw.u10)


def test_salem_file_rotation_equals_cone_fallback() -> None:
    """Real Lambert file: rotating with its COSALPHA/SINALPHA or with the cone factor agrees."""
    frame = LocalFrame(30.0, 87.0)
    raw = read_wrf(SALEM)
    with_file = decode_wrf(raw, frame)
    with_cone = decode_wrf(dataclasses.replace(raw, cosalpha=None, sinalpha=None), frame)
    assert (with_file.rotation, with_cone.rotation) == ("cosalpha", "cone")
    # |sin alpha| error <= 1e-4 (see test_rotation) times |U| <= 6 m/s -> 1e-3 m/s.
    np.testing.assert_allclose(with_cone.u_earth, with_file.u_earth, atol=1e-3)
    np.testing.assert_allclose(with_cone.v_earth, with_file.v_earth, atol=1e-3)
    # ...and the rotation is not trivially the identity here.
    assert np.max(np.abs(with_file.u_earth - raw.u10)) > 0.01


def test_salem_model_level_height_correction_is_sane() -> None:
    frame = LocalFrame(30.0, 87.0)
    f = open_wrf(SALEM, frame, height_m=2.68)
    assert f.info["levels"] == "model"
    assert 0.0 <= f.info["fallback_fraction"] < 0.5
    g = open_wrf(SALEM, frame)
    t = f.coverage.t0
    s_low = np.hypot(*f.sample(t, 0.0, 0.0))
    s_10 = np.hypot(*g.sample(t, 0.0, 0.0))
    assert s_low < s_10  # exponents are clipped to [0, 0.6], so 2.68 m is never windier


@pytest.mark.parametrize(
    "name",
    [
        "ligurian_sea_2014-10-07T12-00-00_area_strong_wind_conv.nc",
        "ligurian_sea_2014-10-07T12-00-00_area_domain.nc",
    ],
)
@requires_shared
def test_ligurian_file_is_rejected_naming_missing_variables(name: str) -> None:
    """Post-processed WRF (lon/lat/u10/v10, no Times): not wrfout, rejected cleanly.

    The file has no licence, so it is read in place and never copied.
    """
    path = SHARED_REAL / "wrf" / "ligurian-sea" / name
    with pytest.raises(WindDataError) as e:
        open_wrf(path, LocalFrame(42.5, 7.5))
    msg = str(e.value)
    assert "not a WRF wrfout file" in msg
    assert "Times, XLAT, XLONG, U10, V10" in msg  # all five are missing (u10 is lower case)
    assert "u10" in msg  # and it says what it found


# --------------------------------------------------------------------------- tiny files
def test_tiny_rotation_sign(tiny_wrf, frame) -> None:
    """The file stores grid-relative winds rotated by ~14 deg; decoding must undo it."""
    path = tiny_wrf(wind10=constant_wind(5.0, 150.0))
    raw = read_wrf(path)
    _, twd_grid = wind_speed_direction(raw.u10, raw.v10)
    # alpha = -cone * (10 - (-10)) = -14.31 deg: the grid's +y points 14.3 deg east of
    # north, so a wind from 150 deg true comes from 150 - 14.3 deg in grid terms.
    assert np.all(np.abs(twd_grid - (150.0 - 14.31)) < 0.3)
    dec = decode_wrf(raw, frame)
    s, d = wind_speed_direction(dec.u_earth, dec.v_earth)
    np.testing.assert_allclose(s, 5.0, atol=1e-5)  # float32 storage
    np.testing.assert_allclose(d, 150.0, atol=1e-4)


def test_tiny_cone_fallback_equals_file_alpha(tiny_wrf, frame) -> None:
    a = decode_wrf(read_wrf(tiny_wrf("a.nc")), frame)
    b = decode_wrf(read_wrf(tiny_wrf("b.nc", write_alpha=False)), frame)
    assert (a.rotation, b.rotation) == ("cosalpha", "cone")
    np.testing.assert_allclose(b.u_earth, a.u_earth, atol=1e-5)
    np.testing.assert_allclose(b.v_earth, a.v_earth, atol=1e-5)


def test_field_protocol_and_local_direction(tiny_wrf, frame) -> None:
    f = open_wrf(tiny_wrf(), frame)
    assert isinstance(f, WindField)
    u, v = f.sample(T0, 0.0, 0.0)
    s, d = wind_speed_direction(u, v)
    # At the frame origin local north = true north (grid_north_deg = 0).
    assert float(s) == pytest.approx(5.0, abs=1e-5)
    assert float(d) == pytest.approx(150.0, abs=1e-4)


def _linear_field(
    frame: LocalFrame, a: float = 4.0, bx: float = 1e-3, by: float = -5e-4, bt: float = 1e-3
):
    """u_e = a + bx x + by y + bt (t - T0), v_e = 0: linear in local x, y and t."""

    def f(t: float, lat: np.ndarray, lon: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x, y = frame.to_xy(lat, lon)
        return a + bx * x + by * y + bt * (t - T0), np.zeros(lat.shape)

    def exact(t, x, y):
        return a + bx * x + by * y + bt * (t - T0)

    return f, exact


def _exact_local(frame: LocalFrame, exact, t, x, y):
    """Local-frame components of the earth-relative (exact(t, x, y), 0) wind."""
    t, x, y = np.broadcast_arrays(np.asarray(t, float), np.asarray(x, float), np.asarray(y, float))
    lat, lon = frame.to_latlon(x, y)
    return earth_to_local(exact(t, x, y), 0.0, frame.grid_north_deg(lat, lon))


def test_bilinear_and_linear_time_exact_on_linear_field(tiny_wrf, frame) -> None:
    wind10, exact = _linear_field(frame)
    f = open_wrf(tiny_wrf(wind10=wind10, level_heights_m=None), frame)
    c = f.coverage
    rng = np.random.default_rng(7)
    n = 2000
    t = rng.uniform(c.t0, c.t1, n)
    x = rng.uniform(c.xmin, c.xmax, n)
    y = rng.uniform(c.ymin, c.ymax, n)
    u, v = f.sample(t, x, y)
    ue, ve = _exact_local(frame, exact, t, x, y)
    # Errors: float32 storage of the winds (~5e-7 relative) and of XLAT/XLONG (cell
    # centres off by <= 0.21 m, times a gradient <= 1e-3 m/s per m), the index map's
    # misfit (~1e-4 cells x 1 m/s per cell).  2e-4 m/s bounds them all.
    np.testing.assert_allclose(u, ue, atol=2e-4)
    np.testing.assert_allclose(v, ve, atol=2e-4)
    assert np.ptp(u) > 5.0  # the field really varies (a constant would pass trivially)


def test_nearest_returns_cell_values(tiny_wrf, frame) -> None:
    wind10, exact = _linear_field(frame, bt=0.0)
    f = open_wrf(tiny_wrf(wind10=wind10, level_heights_m=None), frame, interpolation="nearest")
    raw = read_wrf(f.info["path"])
    x, y = frame.to_xy(raw.lat, raw.lon)
    # A point 0.3 cells (300 m) off the centre of cell (j=2, i=3) takes that cell's value.
    u, _ = f.sample(T0, x[2, 3] + 300.0, y[2, 3] - 300.0)
    cell_u = _exact_local(frame, exact, T0, x[2, 3], y[2, 3])[0]
    # float32 XLAT/XLONG/U10 and the local rotation: 1e-4 m/s (see the bilinear test).
    assert float(u) == pytest.approx(float(cell_u), abs=1e-4)
    assert abs(float(u) - exact(T0, x[2, 3] + 300.0, y[2, 3] - 300.0)) > 0.1


def test_frozen_blocks_use_the_block_start_slice(tiny_wrf, frame) -> None:
    def wind10(t, lat, lon):  # speed 5, 6, 7, 8 m/s at 08:00, 08:10, 08:20, 08:30
        u, v = wind_components(5.0 + (t - T0) / 600.0, 270.0)
        return np.full(lat.shape, u), np.full(lat.shape, v)

    path = tiny_wrf(wind10=wind10, level_heights_m=None)
    frozen = open_wrf(path, frame, time_step_min=20)
    linear = open_wrf(path, frame)
    t = T0 + 60.0 * np.array([0, 19, 20, 25, 30])
    s_frozen = np.hypot(*frozen.sample(t, 0.0, 0.0))
    s_linear = np.hypot(*linear.sample(t, 0.0, 0.0))
    # 20-min blocks aligned to the UTC clock: 08:00-08:20 -> slice 08:00 (5 m/s),
    # 08:20-08:40 -> slice 08:20 (7 m/s).
    np.testing.assert_allclose(s_frozen, [5, 5, 7, 7, 7], atol=1e-5)
    np.testing.assert_allclose(s_linear, [5, 6.9, 7, 7.5, 8], atol=1e-5)


def test_height_from_model_levels_recovers_power_law(tiny_wrf, frame) -> None:
    path = tiny_wrf(wind_at=power_profile(5.0, 150.0, 0.15))
    f = open_wrf(path, frame, height_m=2.68)
    assert f.info["levels"] == "model" and f.info["fallback_fraction"] == 0.0
    assert f.info["exponent_mean"] == pytest.approx(0.15, abs=1e-5)
    s, d = wind_speed_direction(*f.sample(T0, 0.0, 0.0))
    assert float(s) == pytest.approx(5.0 * 0.268**0.15, abs=1e-5)
    assert float(d) == pytest.approx(150.0, abs=1e-4)


def test_unusable_fit_falls_back_to_u10_with_fallback_exponent(tiny_wrf, frame) -> None:
    # Exponent 0.8 between the levels is outside [0, 0.6]: use U10 with 1/7 instead.
    path = tiny_wrf(wind_at=power_profile(5.0, 150.0, 0.8))
    f = open_wrf(path, frame, height_m=2.68)
    assert f.info["fallback_fraction"] == 1.0
    s = float(np.hypot(*f.sample(T0, 0.0, 0.0)))
    assert s == pytest.approx(5.0 * 0.268 ** (1 / 7), abs=1e-5)
    wider = open_wrf(path, frame, height_m=2.68, exponent_range=(0.0, 1.0))
    assert float(np.hypot(*wider.sample(T0, 0.0, 0.0))) == pytest.approx(5.0 * 0.268**0.8, abs=1e-5)


def test_u10_levels_and_log_law(tiny_wrf, frame) -> None:
    path = tiny_wrf()
    p = open_wrf(path, frame, height_m=2.68, levels="u10", fallback_exponent=0.1)
    lg = open_wrf(path, frame, height_m=2.68, levels="u10", shear="log", roughness_m=2e-4)
    assert float(np.hypot(*p.sample(T0, 0, 0))) == pytest.approx(5 * 0.268**0.1, abs=1e-5)
    expected = 5 * math.log(2.68 / 2e-4) / math.log(10 / 2e-4)
    assert float(np.hypot(*lg.sample(T0, 0, 0))) == pytest.approx(expected, abs=1e-5)


def test_crop_to_bbox_and_time_window(tiny_wrf, frame) -> None:
    wind10, exact = _linear_field(frame)
    # STAND_LON at the centre: the grid is not rotated there, so its columns are ~1006 m
    # apart in x (Lambert scale factor 0.994 at 45 N for 30/60) and rows ~1003 m in y.
    path = tiny_wrf(wind10=wind10, level_heights_m=None, nx=25, ny=21, stand_lon=10.0)
    h = read_wrf_header(path)
    w = crop_window(
        h,
        frame,
        bbox=(-1000.0, 1500.0, -500.0, 500.0),
        margin_m=1000.0,
        time_window=(T0 + 700.0, T0 + 1100.0),
    )
    # x in [-2000, 2500] m -> columns 11..14 (x = -1006 .. 2013) plus one ring -> 10..15;
    # y in [-1500, 1500] -> rows 9..11 plus one ring -> 8..12; slices 08:10 .. 08:20.
    assert (w.i0, w.i1, w.j0, w.j1) == (10, 16, 8, 13)
    assert (w.k0, w.k1) == (1, 3)
    f = open_wrf(
        path,
        frame,
        bbox=(-1000.0, 1500.0, -500.0, 500.0),
        margin_m=1000.0,
        time_window=(T0 + 700.0, T0 + 1100.0),
    )
    c = f.coverage
    assert c.xmin <= -2000 and c.xmax >= 2500 and c.ymin <= -1500 and c.ymax >= 1500
    assert (c.t0, c.t1) == (T0 + 600.0, T0 + 1200.0)
    u, _ = f.sample(T0 + 900.0, 1200.0, 300.0)
    assert float(u) == pytest.approx(
        float(_exact_local(frame, exact, T0 + 900.0, 1200.0, 300.0)[0]), abs=2e-4
    )


def test_no_utm_seam_across_6_east(tiny_wrf) -> None:
    """A grid straddling 6 deg E (the UTM 31/32 boundary that broke the thesis's per-point
    deg2utm) maps to evenly spaced local cells, and a linear field stays linear across it."""
    frame = LocalFrame(43.07, 6.0)
    wind10, exact = _linear_field(frame)
    path = tiny_wrf(
        "seam.nc", wind10=wind10, level_heights_m=None, center=(43.07, 6.0), stand_lon=6.0, nx=9
    )
    raw = read_wrf(path)
    assert raw.lon.min() < 6.0 < raw.lon.max()
    x, _ = frame.to_xy(raw.lat, raw.lon)
    # Steps are DX on WRF's sphere read as WGS-84 (x 1.0028 at 43 N); uniform to 0.1 m.
    assert np.ptp(np.diff(x, axis=1)) < 0.1
    f = open_wrf(path, frame)
    assert f.index_map.degree == 1 and f.index_map.residual_cells < 1e-3
    xs = np.linspace(-2000.0, 2000.0, 41)  # crosses x = 0, i.e. 6 deg E
    u, _ = f.sample(T0, xs, 0.0)
    np.testing.assert_allclose(u, _exact_local(frame, exact, T0, xs, 0.0)[0], atol=2e-4)


def test_outside_coverage_raises_naming_both_ranges_and_clamp(tiny_wrf, frame) -> None:
    path = tiny_wrf()
    f = open_wrf(path, frame)
    with pytest.raises(OutOfCoverageError) as e:
        f.sample(T0 + 3600.0, 0.0, 0.0)
    msg = str(e.value)
    assert "requested" in msg and "covered" in msg and "clamp" in msg
    assert iso(T0 + 3600.0) in msg and iso(T0 + 1800.0) in msg
    fc = open_wrf(path, frame, clamp=True)
    np.testing.assert_allclose(
        fc.sample(T0 + 3600.0, 1e6, 0.0), fc.sample(T0 + 1800.0, fc.coverage.xmax, 0.0), atol=1e-12
    )


def test_bbox_outside_domain_is_an_error(tiny_wrf, frame) -> None:
    with pytest.raises(OutOfCoverageError, match="does not contain the course"):
        open_wrf(tiny_wrf(), frame, bbox=(50e3, 52e3, 0.0, 1e3))


# --------------------------------------------------------------------------- bad input
def _edit(path: Path, fn) -> Path:
    with netCDF4.Dataset(path, "a") as ds:
        fn(ds)
    return path


def test_missing_variable_named(tiny_wrf, frame) -> None:
    path = _edit(tiny_wrf(), lambda ds: ds.renameVariable("V10", "V10_renamed"))
    with pytest.raises(WindDataError, match=r"not a WRF wrfout file: missing variable\(s\) V10"):
        open_wrf(path, frame)


def test_wrong_units_named(tiny_wrf, frame) -> None:
    path = _edit(tiny_wrf(), lambda ds: setattr(ds["U10"], "units", "knots"))
    with pytest.raises(WindDataError, match="U10 has units 'knots'; expected metres per second"):
        open_wrf(path, frame)


def test_nan_values_named(tiny_wrf, frame) -> None:
    def poke(ds):
        ds["U10"][2, 3, 4] = np.nan

    path = _edit(tiny_wrf(), poke)
    with pytest.raises(WindDataError, match=r"U10 has 1 missing or NaN values .*\[2, 3, 4\]"):
        open_wrf(path, frame)


def test_non_monotonic_times_named(tiny_wrf, frame) -> None:
    def swap(ds):
        t = ds["Times"][:]
        ds["Times"][1], ds["Times"][2] = t[2], t[1]

    path = _edit(tiny_wrf(), swap)
    with pytest.raises(WindDataError, match=r"Times\[1\] = 2018-04-24_08:20:00 and Times\[2\]"):
        read_wrf_header(path)


def test_empty_and_non_netcdf_files(tmp_path, frame) -> None:
    empty = tmp_path / "empty.nc"
    empty.write_bytes(b"")
    with pytest.raises(WindDataError, match="empty"):
        open_wrf(empty, frame)
    text = tmp_path / "text.nc"
    text.write_text("not netcdf\n")
    with pytest.raises(WindDataError, match="cannot be read as NetCDF"):
        open_wrf(text, frame)
    with pytest.raises(InputError, match="not found"):
        open_wrf(tmp_path / "missing.nc", frame)


def test_model_levels_requested_but_absent(tiny_wrf, frame) -> None:
    path = tiny_wrf(level_heights_m=None)
    with pytest.raises(WindDataError, match="levels: u10"):
        open_wrf(path, frame, height_m=2.68, levels="model")
    # auto quietly uses U10 with the fallback exponent
    assert open_wrf(path, frame, height_m=2.68).info["levels"] == "u10"


def test_no_rotation_information(tiny_wrf, frame) -> None:
    path = _edit(tiny_wrf(write_alpha=False), lambda ds: ds.delncattr("MAP_PROJ"))
    with pytest.raises(WindDataError, match="neither COSALPHA/SINALPHA nor the MAP_PROJ"):
        open_wrf(path, frame)


def test_copied_real_file_is_readable_from_elsewhere(tmp_path) -> None:
    # The reader takes any path (no reliance on the file name or folder).
    p = shutil.copy(SALEM, tmp_path / "renamed_output")
    assert read_wrf_header(p).shape == (4, 8, 10)
