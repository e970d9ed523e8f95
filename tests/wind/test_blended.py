"""Model wind corrected by stations: speed ratio and direction offset spread by distance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import T0, constant_wind

from sailroute.errors import InputError, WindDataError
from sailroute.geo import LocalFrame
from sailroute.units import wind_speed_direction
from sailroute.wind.blended import BlendedWind, window_mean
from sailroute.wind.stations import StationData
from sailroute.wind.uniform import UniformWind
from sailroute.wind.wrf import open_wrf

FRAME = LocalFrame(45.0, 10.0)
BASE = UniformWind(5.0, 150.0)


def obs(xy, speeds, dirs, times=None, height=np.nan) -> StationData:
    """One record per (station, time); directions given in the local frame."""
    times = T0 + 300.0 * np.arange(7) if times is None else np.asarray(times, float)
    ids, tt, la, lo, s, d = [], [], [], [], [], []
    for k, (x, y) in enumerate(xy):
        lat, lon = FRAME.to_latlon(x, y)
        gn = float(FRAME.grid_north_deg(lat, lon))
        sp = np.broadcast_to(np.asarray(speeds[k], float), times.shape)
        di = np.broadcast_to(np.asarray(dirs[k], float), times.shape)
        ids += [f"S{k}"] * times.size
        tt += list(times)
        la += [float(lat)] * times.size
        lo += [float(lon)] * times.size
        s += list(sp)
        d += list((di - gn) % 360.0)
    n = len(tt)
    return StationData(
        np.array(ids),
        np.array(tt),
        np.array(la),
        np.array(lo),
        np.array(s),
        np.array(d),
        np.full(n, height),
        np.full(n, np.nan),
    )


def speed_dir(f, t, x, y):
    s, d = wind_speed_direction(*f.sample(t, x, y))
    return float(s), float(d)


def test_full_correction_at_station_and_decay_with_distance() -> None:
    b = BlendedWind(BASE, obs([(0.0, 0.0)], [6.0], [160.0]), FRAME, length_scale_m=1000.0)
    s, d = speed_dir(b, T0 + 900.0, 0.0, 0.0)
    assert s == pytest.approx(6.0, rel=1e-9) and d == pytest.approx(160.0, abs=1e-6)
    # At one length scale the Gaussian weight is exp(-1/2): ln-ratio and offset scale by it.
    g = math.exp(-0.5)
    s, d = speed_dir(b, T0 + 900.0, 1000.0, 0.0)
    assert s == pytest.approx(5.0 * 1.2**g, rel=1e-6)  # frame rotation ~1e-4 deg: rel 1e-6
    assert d == pytest.approx(150.0 + 10.0 * g, abs=1e-3)
    s, d = speed_dir(b, T0 + 900.0, 8000.0, 0.0)  # 8 L away: weight exp(-32) ~ 1e-14
    assert s == pytest.approx(5.0, rel=1e-9) and d == pytest.approx(150.0, abs=1e-6)


def test_nearby_stations_are_averaged_not_added() -> None:
    b = BlendedWind(
        BASE,
        obs([(-100.0, 0.0), (100.0, 0.0)], [6.0, 6.0], [160.0, 160.0]),
        FRAME,
        length_scale_m=1000.0,
    )
    s, d = speed_dir(b, T0 + 900.0, 0.0, 0.0)  # sum of weights ~2: normalised, not doubled
    assert s == pytest.approx(6.0, rel=1e-6) and d == pytest.approx(160.0, abs=1e-3)


def test_time_smoothing_and_taper() -> None:
    speeds = [np.array([5.5, 6.5, 5.5, 6.5, 5.5, 6.5, 5.5])]
    b = BlendedWind(BASE, obs([(0.0, 0.0)], speeds, [150.0]), FRAME, time_scale_s=900.0)
    lr = b.corrections[0].log_ratio
    # Centred 900 s window at 300 s spacing = 3 records (2 at the ends).
    expect = np.log(np.array(speeds[0]) / 5.0)
    np.testing.assert_allclose(lr[1:-1], (expect[:-2] + expect[1:-1] + expect[2:]) / 3, atol=1e-12)
    assert lr[0] == pytest.approx((expect[0] + expect[1]) / 2, abs=1e-12)
    # 450 s after the last record the weight has tapered to 1/2.
    t_end = T0 + 1800.0
    s_end = speed_dir(b, t_end, 0.0, 0.0)[0]
    s_half = speed_dir(b, t_end + 450.0, 0.0, 0.0)[0]
    assert math.log(s_half / 5.0) == pytest.approx(0.5 * math.log(s_end / 5.0), abs=1e-9)
    assert speed_dir(b, t_end + 901.0, 0.0, 0.0)[0] == pytest.approx(5.0, rel=1e-12)


def test_window_mean_ignores_invalid() -> None:
    t = np.arange(5.0)
    out = window_mean(
        t, np.array([1.0, 100.0, 3.0, 5.0, 7.0]), np.array([True, False, True, True, True]), 2.0
    )
    np.testing.assert_allclose(out, [1.0, 2.0, 4.0, 5.0, 6.0])


def test_calm_and_extreme_observations_are_guarded() -> None:
    calm = BlendedWind(BASE, obs([(0.0, 0.0)], [0.3], [40.0]), FRAME)
    assert calm.corrections == ()  # below min_speed_ms: no information, no correction
    assert speed_dir(calm, T0, 0.0, 0.0) == pytest.approx((5.0, 150.0), abs=1e-9)
    wild = BlendedWind(BASE, obs([(0.0, 0.0)], [25.0], [300.0]), FRAME)
    s, d = speed_dir(wild, T0, 0.0, 0.0)
    assert s == pytest.approx(10.0, rel=1e-9)  # ratio clipped to 2
    assert d == pytest.approx(210.0, abs=1e-6)  # offset 300 - 150 = +150 clipped to +60


def test_with_wrf_base_and_height(tiny_wrf, frame) -> None:
    wrf = open_wrf(tiny_wrf(wind10=constant_wind(5.0, 150.0)), frame, height_m=2.68, levels="u10")
    s_wrf = 5.0 * 0.268 ** (1 / 7)
    # Observed 6 m/s at 7.5 m -> at 2.68 m with 1/7: 6 (2.68/7.5)^(1/7)
    b = BlendedWind(wrf, obs([(0.0, 0.0)], [6.0], [150.0], height=7.5), frame, height_m=2.68)
    s, _d = speed_dir(b, T0 + 600.0, 0.0, 0.0)
    assert s == pytest.approx(6.0 * (2.68 / 7.5) ** (1 / 7), rel=1e-5)  # float32 WRF file
    assert s != pytest.approx(s_wrf, rel=1e-2)
    assert b.coverage == wrf.coverage
    with pytest.raises(InputError, match="measurement height is unknown"):
        BlendedWind(wrf, obs([(0.0, 0.0)], [6.0], [150.0]), frame, height_m=2.68)
    far = obs([(50e3, 0.0)], [6.0], [150.0])
    with pytest.raises(WindDataError, match=r"no station record .* lies inside the model"):
        BlendedWind(wrf, far, frame)
