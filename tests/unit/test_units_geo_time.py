"""Conventions: direction round trips, quadrants, calm, frame accuracy, time parsing."""

from __future__ import annotations

from datetime import UTC, datetime

import numpy as np
import pytest
from pyproj import Geod

from sailroute.errors import InputError
from sailroute.geo import LocalFrame, wrap_lon
from sailroute.timeutil import iso, iso_datetime, parse_time, to_epoch
from sailroute.units import (
    KNOT,
    bearing_deg,
    signed_twa,
    to_ms,
    wind_components,
    wind_speed_direction,
    wrap180,
    wrap360,
)


@pytest.mark.parametrize(
    ("twd", "u", "v"),
    [(0.0, 0.0, -1.0), (90.0, -1.0, 0.0), (180.0, 0.0, 1.0), (270.0, 1.0, 0.0)],
)
def test_wind_components_quadrants(twd: float, u: float, v: float) -> None:
    uu, vv = wind_components(1.0, twd)
    np.testing.assert_allclose([uu, vv], [u, v], atol=1e-15)


def test_direction_roundtrip_and_north_is_zero() -> None:
    twd = np.linspace(0, 359.9, 3600)
    s = np.full_like(twd, 7.3)
    s2, d2 = wind_speed_direction(*wind_components(s, twd))
    np.testing.assert_allclose(s2, s, rtol=1e-12)
    np.testing.assert_allclose(wrap180(d2 - twd), 0.0, atol=1e-9)
    assert wind_speed_direction(0.0, -3.0)[1] == 0.0  # north wind -> 0, not 360


def test_calm_has_direction_zero() -> None:
    _, d = wind_speed_direction(np.array([0.0, 0.0]), np.array([0.0, 0.0]))
    assert np.all(d == 0.0)


def test_wrap_ranges() -> None:
    a = np.array([-720.0, -180.0, -0.0, 180.0, 359.999, 360.0, 540.0])
    w = wrap360(a)
    assert np.all((w >= 0) & (w < 360))
    w2 = wrap180(a)
    assert np.all((w2 > -180) & (w2 <= 180))
    assert wrap180(-180.0) == 180.0


def test_signed_twa_starboard_positive() -> None:
    # wind from 45 while heading north -> over starboard bow -> positive
    assert signed_twa(45.0, 0.0) == pytest.approx(45.0)
    assert signed_twa(315.0, 0.0) == pytest.approx(-45.0)
    assert bearing_deg(1.0, 0.0) == pytest.approx(90.0)


def test_speed_units() -> None:
    assert to_ms(10.0, "kn") == pytest.approx(5.144444, rel=1e-6)
    assert pytest.approx(0.514444, rel=1e-6) == KNOT
    assert to_ms(36.0, "km/h") == pytest.approx(10.0)
    assert to_ms(1.0, "mph") == pytest.approx(0.44704)
    with pytest.raises(InputError, match="expected one of"):
        to_ms(1.0, "furlongs/fortnight")


def test_local_frame_matches_geodesic_over_5km() -> None:
    frame = LocalFrame(43.069067, 6.198550)  # Hyeres, Echo area centre
    geod = Geod(ellps="WGS84")
    az = np.linspace(0, 350, 36)
    lon, lat, _ = geod.fwd(np.full(36, 6.198550), np.full(36, 43.069067), az, np.full(36, 5000.0))
    x, y = frame.to_xy(lat, lon)
    # distance from origin exact (equidistant), and pairwise distances within 0.1 m
    np.testing.assert_allclose(np.hypot(x, y), 5000.0, atol=1e-6)
    _, _, d_geo = geod.inv(lon[:-1], lat[:-1], lon[1:], lat[1:])
    d_xy = np.hypot(np.diff(x), np.diff(y))
    assert np.max(np.abs(d_geo - d_xy)) < 0.1
    lat2, lon2 = frame.to_latlon(x, y)
    np.testing.assert_allclose(lat2, lat, atol=1e-10)
    np.testing.assert_allclose(lon2, lon, atol=1e-10)


_ORIGINS = [
    (43.064507, 6.229547),
    (45.642375, 13.701999999999998),  # a mean of marks: 17 digits, which PROJ rounds
    (89.9, 0.0),
    (-90.0, 12.0),
    (0.0, 359.9),
    (41.2, 288.67),
    (60.1, -179.99),
    (1e-07, -1e-09),
] + [
    (float(a), float(b))
    for a, b in np.random.default_rng(9).uniform((-90.0, -180.0), (90.0, 360.0), (12, 2))
]


@pytest.mark.parametrize(("lat0", "lon0"), _ORIGINS)
def test_local_frame_is_what_pyproj_computes_from_epsg_4326_to_the_bit(
    lat0: float, lon0: float
) -> None:
    # the frame's source CRS is a PROJ string (no look-up in PROJ's database at every
    # start): plans, GPX and KML keep the same bytes as with EPSG:4326
    from pyproj import Transformer

    proj = f"+proj=aeqd +lat_0={lat0!r} +lon_0={lon0!r} +datum=WGS84 +units=m +no_defs"
    fwd = Transformer.from_crs("EPSG:4326", proj, always_xy=True)
    inv = Transformer.from_crs(proj, "EPSG:4326", always_xy=True)
    rng = np.random.default_rng(5)
    lat = np.clip(lat0 + rng.uniform(-2.0, 2.0, 2000), -90.0, 90.0)
    lon = lon0 + rng.uniform(-3.0, 3.0, 2000)
    x, y = rng.uniform(-6e4, 6e4, 2000), rng.uniform(-6e4, 6e4, 2000)
    frame = LocalFrame(lat0, lon0)
    want_x, want_y = fwd.transform(lon, lat)
    want_lon, want_lat = inv.transform(x, y)
    got_x, got_y = frame.to_xy(lat, lon)
    got_lat, got_lon = frame.to_latlon(x, y)
    assert np.array_equal(got_x, want_x) and np.array_equal(got_y, want_y)
    assert np.array_equal(got_lat, want_lat)
    assert np.array_equal(got_lon, np.asarray(wrap_lon(want_lon)))


def test_parse_time_requires_offset() -> None:
    t = parse_time("2018-04-24T12:10:00+02:00")
    assert t == datetime(2018, 4, 24, 10, 10, tzinfo=UTC)
    assert iso(to_epoch(parse_time("2018-04-24T10:10:00Z"))) == "2018-04-24T10:10:00.000Z"
    with pytest.raises(InputError, match="no UTC offset"):
        parse_time("2018-04-24T12:10:00", where="course.yaml: start_time")
    with pytest.raises(InputError, match="ISO 8601"):
        parse_time("yesterday")


def test_iso_datetime_keeps_the_time_as_written() -> None:
    # the one ISO 8601 parser: Z or z is UTC, an offset is kept, a naive time stays naive
    # (the track and station readers may apply a declared zone to it)
    z = iso_datetime(" 2018-04-24T10:10:00z ")
    assert z == datetime(2018, 4, 24, 10, 10, tzinfo=UTC) and z.utcoffset().total_seconds() == 0
    plus2 = iso_datetime("2018-04-24T12:10:00.5+02:00")
    assert plus2.utcoffset().total_seconds() == 7200.0
    assert plus2.timestamp() == datetime(2018, 4, 24, 10, 10, 0, 500000, tzinfo=UTC).timestamp()
    assert iso_datetime("2018-04-24 12:10").tzinfo is None
    with pytest.raises(ValueError):
        iso_datetime("24/04/2018 12:10")
