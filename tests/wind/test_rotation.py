"""Rotation of wind vectors: grid -> earth (WRF) and earth -> local frame."""

from __future__ import annotations

import math

import netCDF4
import numpy as np
import pytest

from sailroute.errors import WindDataError
from sailroute.geo import LocalFrame
from sailroute.units import wind_components, wind_speed_direction
from sailroute.wind.rotation import (
    cone_factor,
    earth_to_grid,
    earth_to_local,
    grid_to_earth,
    rotate_clockwise,
    rotation_from_cone,
)
from tests.conftest import WIND_DATA

SALEM = WIND_DATA / "salem_lambert_crop.nc"


def test_rotate_clockwise_quarter_turns() -> None:
    # A vector pointing north turned clockwise by 90 deg points east (exact in float).
    u, v = rotate_clockwise(0.0, 1.0, 90.0)
    assert u == pytest.approx(1.0, abs=1e-15) and v == pytest.approx(0.0, abs=1e-15)
    u, v = rotate_clockwise(1.0, 0.0, 90.0)  # east -> south
    assert u == pytest.approx(0.0, abs=1e-15) and v == pytest.approx(-1.0, abs=1e-15)


def test_grid_to_earth_matches_wrf_python_formula_and_inverts() -> None:
    # wrf-python uvmet: u_e = u cos a - v sin a, v_e = v cos a + u sin a.
    rng = np.random.default_rng(1)
    u, v = rng.normal(size=(2, 50))
    a = rng.uniform(-0.5, 0.5, 50)
    ue, ve = grid_to_earth(u, v, np.cos(a), np.sin(a))
    np.testing.assert_allclose(ue, u * np.cos(a) - v * np.sin(a), rtol=0, atol=1e-15)
    np.testing.assert_allclose(ve, v * np.cos(a) + u * np.sin(a), rtol=0, atol=1e-15)
    ub, vb = earth_to_grid(ue, ve, np.cos(a), np.sin(a))
    np.testing.assert_allclose(ub, u, atol=1e-14)
    np.testing.assert_allclose(vb, v, atol=1e-14)


def test_cone_factor_known_values() -> None:
    # Lambert 30/60: n = ln(cos30/cos60) / ln(tan(30)/tan(15)) = 0.715566... (textbook value).
    expected = math.log(math.cos(math.radians(30)) / math.cos(math.radians(60))) / math.log(
        math.tan(math.radians(30)) / math.tan(math.radians(15))
    )
    assert cone_factor(1, 30.0, 60.0) == pytest.approx(expected, rel=1e-12)
    assert cone_factor(1, 30.0, 60.0) == pytest.approx(0.7155668, abs=1e-7)
    assert cone_factor(1, 45.0, 45.0) == pytest.approx(math.sin(math.radians(45.0)))
    assert cone_factor(2, 60.0, 60.0) == 1.0
    assert cone_factor(3) == 0.0
    with pytest.raises(WindDataError, match="MAP_PROJ = 4"):
        cone_factor(4)


def test_cone_rotation_reproduces_salem_cosalpha_sinalpha() -> None:
    """Known answer: real WRF 3.3.1 COSALPHA/SINALPHA (Lambert 30/35, STAND_LON 87)."""
    with netCDF4.Dataset(SALEM) as ds:
        lat, lon = ds["XLAT"][:], ds["XLONG"][:]
        ca_file, sa_file = ds["COSALPHA"][:], ds["SINALPHA"][:]
        cone = cone_factor(int(ds.MAP_PROJ), float(ds.TRUELAT1), float(ds.TRUELAT2))
        ca, sa = rotation_from_cone(lat, lon, cone, float(ds.STAND_LON))
    # WRF stores them in float32 and computes them slightly differently: 1e-4 covers both,
    # while |SINALPHA| reaches 0.013 here, so a sign error would fail by 100x the tolerance.
    assert np.max(np.abs(sa_file)) > 0.01
    np.testing.assert_allclose(ca, ca_file, atol=1e-4)
    np.testing.assert_allclose(sa, sa_file, atol=1e-4)


def test_salem_grid_y_axis_bearing_equals_minus_alpha() -> None:
    """Geometric check independent of any formula: the +j grid direction measured from
    XLAT/XLONG has compass bearing -alpha, so a pure grid-v wind must come out along it."""
    with netCDF4.Dataset(SALEM) as ds:
        lat, lon = np.asarray(ds["XLAT"][:], float), np.asarray(ds["XLONG"][:], float)
        ca, sa = np.asarray(ds["COSALPHA"][:], float), np.asarray(ds["SINALPHA"][:], float)
    # Bearing of the step from cell (j, i) to (j + 1, i) on a sphere-like grid:
    dlat = lat[1:] - lat[:-1]
    dlon = (lon[1:] - lon[:-1]) * np.cos(np.radians(0.5 * (lat[1:] + lat[:-1])))
    bearing = np.degrees(np.arctan2(dlon, dlat))
    ue, ve = grid_to_earth(0.0, 1.0, 0.5 * (ca[1:] + ca[:-1]), 0.5 * (sa[1:] + sa[:-1]))
    wind_bearing = np.degrees(np.arctan2(ue, ve))
    # 30 km cells: the finite-difference bearing is good to ~0.02 deg; alpha spans +-0.75 deg.
    np.testing.assert_allclose(wind_bearing, bearing, atol=0.05)
    assert np.ptp(bearing) > 1.0


def test_earth_to_local_follows_meridian_convergence() -> None:
    frame = LocalFrame(43.0, 6.0)
    lat, lon = 43.1, 6.5  # ~40 km east: local +y deviates from true north measurably
    gn = frame.grid_north_deg(lat, lon)
    assert abs(gn) > 0.2
    # A north wind (blowing south) at that point, expressed in local components,
    # must point along the local direction of true south.
    u, v = wind_components(6.0, 0.0)
    ul, vl = earth_to_local(u, v, gn)
    x0, y0 = frame.to_xy(lat, lon)
    x1, y1 = frame.to_xy(lat - 1e-3, lon)
    south_bearing = np.degrees(np.arctan2(x1 - x0, y1 - y0)) % 360
    assert np.degrees(np.arctan2(ul, vl)) % 360 == pytest.approx(south_bearing, abs=1e-3)
    assert wind_speed_direction(ul, vl)[0] == pytest.approx(6.0, rel=1e-12)
