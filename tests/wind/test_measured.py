"""Measured wind from boat logs: true-wind formula, sensors, one boat's field, the fleet field."""

from __future__ import annotations

import csv
from pathlib import Path
from types import MappingProxyType

import numpy as np
import pytest

from sailroute.errors import InputError, OutOfCoverageError
from sailroute.geo import LocalFrame
from sailroute.track.model import Track
from sailroute.track.read import read_track
from sailroute.units import KNOT, wind_components, wind_speed_direction, wrap180
from sailroute.wind.measured import (
    MeasuredSeries,
    boat_wind,
    sensor_from_track,
    smooth_vector,
    true_wind,
)
from tests.conftest import SHARED_REAL, requires_shared

T0 = 1737256000.0  # 2025-01-19T03:06:40Z
FRAME = LocalFrame(-36.83, 174.76)
TALLINN = SHARED_REAL / "races" / "tallinn-wednesday-races-2023" / "kolmak_2023_09_27.csv"


# ------------------------------------------------------------------------------ formula
def test_true_wind_hand_example() -> None:
    # Heading north at 5 m/s, 10 m/s apparent from 30 deg to starboard.
    # Air relative to the boat moves towards 210 deg: A = (-5, -8.6603); boat B = (0, 5);
    # W = A + B = (-5, -3.6603): |W| = sqrt(38.397) = 6.1966 m/s, from atan2(5, 3.6603) = 53.79 deg.
    tws, twd = true_wind(10.0, 30.0, 5.0, 0.0)
    assert float(tws) == pytest.approx(6.1966, abs=1e-4)
    assert float(twd) == pytest.approx(53.794, abs=1e-3)
    # the same on port: mirror image
    tws, twd = true_wind(10.0, -30.0, 5.0, 0.0)
    assert (float(tws), float(twd)) == pytest.approx((6.1966, 360 - 53.794), abs=1e-3)
    # dead downwind at 5 m/s with 5 m/s apparent from astern: 10 m/s from the south
    tws, twd = true_wind(5.0, 180.0, 5.0, 0.0)
    assert (float(tws), float(twd)) == pytest.approx((10.0, 180.0), abs=1e-9)
    # heading differs from the course (leeway 5 deg): awa is measured from the bow
    tws, twd = true_wind(10.0, 25.0, 5.0, 0.0, heading_deg=5.0)
    assert (float(tws), float(twd)) == pytest.approx((6.1966, 53.794), abs=1e-3)


@requires_shared
def test_true_wind_reproduces_tallinn_log() -> None:
    # The log's author computed tws/twd from aws, unsigned awa with a tack column, SOG and COG.
    with TALLINN.open() as f:
        rows = list(csv.DictReader(f))

    def col(k: str) -> np.ndarray:
        return np.array([float(r[k]) if r[k] else np.nan for r in rows])

    tws, twd = true_wind(col("aws") * KNOT, col("awa") * col("tack"), col("sog") * KNOT,
                         col("cog"))
    ok = np.isfinite(col("tws"))
    assert ok.sum() > 900
    assert np.median(np.abs(tws[ok] / KNOT - col("tws")[ok])) < 0.05
    assert np.median(np.abs(wrap180(twd[ok] - col("twd")[ok]))) < 0.5
    assert np.max(np.abs(tws[ok] / KNOT - col("tws")[ok])) < 1e-6


# ------------------------------------------------------------------------------ sensors
def _track(t, channels, name="B1", source="b1.csv", xy=None) -> Track:
    n = t.size
    x, y = (np.linspace(0, 3000, n), np.zeros(n)) if xy is None else xy
    lat, lon = FRAME.to_latlon(x, y)
    return Track(t, lat, lon, name, source, MappingProxyType(channels))


def test_sensor_channel_priority_and_source() -> None:
    t = T0 + np.arange(120.0)
    n = t.size
    tws, twd = np.full(n, 8.0), np.full(n, 40.0)
    hdg = np.where(np.arange(n) < 60, 0.0, 90.0)
    s = sensor_from_track(_track(t, {"tws_ms": tws, "twd_deg": twd}), smooth_s=0)
    assert s.source == "tws/twd"
    np.testing.assert_allclose(s.tws_ms, 8.0)
    np.testing.assert_allclose(s.twd_deg, 40.0)
    s = sensor_from_track(_track(t, {"tws_ms": tws, "twa_deg": wrap180(twd - hdg),
                                     "hdg_deg": hdg}), smooth_s=0)
    assert s.source == "tws + twa + hdg"
    np.testing.assert_allclose(s.twd_deg, 40.0, atol=1e-9)
    # apparent wind of a boat sailing at 4 m/s through a true 8 m/s from 40 deg
    uw, vw = wind_components(tws, twd)
    bu, bv = 4.0 * np.sin(np.radians(hdg)), 4.0 * np.cos(np.radians(hdg))
    aws, afrom = wind_speed_direction(uw - bu, vw - bv)
    ch = {"aws_ms": aws, "awa_deg": wrap180(afrom - hdg), "sog_ms": np.full(n, 4.0),
          "cog_deg": hdg, "hdg_deg": hdg}
    s = sensor_from_track(_track(t, ch), smooth_s=0)
    assert s.source.startswith("aws/awa + sog/cog (over the ground")
    np.testing.assert_allclose(s.tws_ms, 8.0, atol=1e-9)
    np.testing.assert_allclose(s.twd_deg, 40.0, atol=1e-9)
    del ch["sog_ms"], ch["cog_deg"]
    ch["bsp_ms"] = np.full(n, 4.0)
    s = sensor_from_track(_track(t, ch), smooth_s=0)
    assert s.source == "aws/awa + bsp/hdg (over the water)"
    np.testing.assert_allclose(s.tws_ms, 8.0, atol=1e-9)


def test_sensor_drops_nan_rows_and_lists_gaps() -> None:
    t = np.concatenate([T0 + np.arange(100.0), T0 + 160.0 + np.arange(100.0)])
    tws = np.full(t.size, 8.0)
    tws[5] = np.nan
    s = sensor_from_track(_track(t, {"tws_ms": tws, "twd_deg": np.full(t.size, 40.0)}))
    assert len(s) == t.size - 1
    assert any("dropped 1 of 200" in n for n in s.notes)
    assert s.gaps == ((T0 + 99.0, T0 + 160.0),)


def test_smoothing_is_a_centred_vector_mean_within_stretches() -> None:
    t = np.concatenate([np.arange(10.0), 100.0 + np.arange(10.0)])
    u = np.concatenate([np.arange(10.0), np.full(10, 50.0)])
    su, sv = smooth_vector(t, u, np.zeros(20), 5.0, 30.0)
    assert su[5] == pytest.approx(5.0)  # mean of 3..7
    assert su[0] == pytest.approx(1.0)  # mean of 0..2 (window cut at the start)
    assert su[9] == pytest.approx(8.0)  # not mixed with the next stretch
    np.testing.assert_allclose(su[10:], 50.0)
    np.testing.assert_allclose(sv, 0.0)


def test_log_without_wind_columns_names_file_and_channels(tmp_path: Path) -> None:
    p = tmp_path / "dinghy.csv"
    p.write_text("time,lat,lon,sog_kn\n2025-01-19T03:00:00Z,-36.83,174.76,5\n"
                 "2025-01-19T03:00:01Z,-36.83,174.7601,5.1\n")
    tr = read_track(p)
    with pytest.raises(InputError, match=r"dinghy\.csv: no usable wind columns \(channels "
                                         r"found: sog_ms\)"):
        sensor_from_track(tr)


# ------------------------------------------------------------------------------ one boat
def test_boat_wind_hole_raises_naming_boat_and_gap() -> None:
    t = np.concatenate([T0 + np.arange(100.0), T0 + 400.0 + np.arange(100.0)])
    tr = _track(t, {"tws_ms": np.full(t.size, 8.0), "twd_deg": np.full(t.size, 40.0)},
                name="NZL", source="data_NZL.csv")
    f = boat_wind(tr, FRAME)
    u, v = f.sample(np.array([T0, T0 + 99.0, T0 + 400.0]), 0.0, 0.0)
    np.testing.assert_allclose(wind_speed_direction(u, v)[0], 8.0)
    with pytest.raises(OutOfCoverageError,
                       match=r"1 of 2 sample points fall in a gap of the log of NZL "
                             r"\(data_NZL\.csv\): no record from 2025-01-19T03:08:19.*"
                             r"\(301 s > max_gap_s 30 s\)"):
        f.sample(np.array([T0 + 50.0, T0 + 250.0]), 0.0, 0.0)
    # a larger limit bridges it
    f = boat_wind(tr, FRAME, max_gap_s=400.0)
    u, _ = f.sample(T0 + 250.0, 0.0, 0.0)
    assert np.isfinite(u)


def test_boat_wind_is_linear_in_time_in_components() -> None:
    t = T0 + np.array([0.0, 10.0])
    s = MeasuredSeries("B", "", t, *FRAME.to_latlon(np.zeros(2), np.zeros(2)),
                       np.array([2.0, 4.0]), np.array([0.0, -6.0]))
    u, v = boat_wind(s, FRAME).sample(T0 + 2.5, 1e4, -1e4)
    assert (float(u), float(v)) == pytest.approx((2.5, -1.5), abs=1e-9)
