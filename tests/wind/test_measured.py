"""Measured wind from boat logs: true-wind formula, sensors, one boat's field, the fleet field."""

from __future__ import annotations

import csv
from datetime import UTC, datetime
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
    FLEET_METHODS,
    MeasuredSeries,
    boat_wind,
    estimate_biases,
    fleet_wind,
    hull_fraction,
    leave_one_out,
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

    tws, twd = true_wind(col("aws") * KNOT, col("awa") * col("tack"), col("sog") * KNOT, col("cog"))
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
    s = sensor_from_track(
        _track(t, {"tws_ms": tws, "twa_deg": wrap180(twd - hdg), "hdg_deg": hdg}), smooth_s=0
    )
    assert s.source == "tws + twa + hdg"
    np.testing.assert_allclose(s.twd_deg, 40.0, atol=1e-9)
    # apparent wind of a boat sailing at 4 m/s through a true 8 m/s from 40 deg
    uw, vw = wind_components(tws, twd)
    bu, bv = 4.0 * np.sin(np.radians(hdg)), 4.0 * np.cos(np.radians(hdg))
    aws, afrom = wind_speed_direction(uw - bu, vw - bv)
    ch = {
        "aws_ms": aws,
        "awa_deg": wrap180(afrom - hdg),
        "sog_ms": np.full(n, 4.0),
        "cog_deg": hdg,
        "hdg_deg": hdg,
    }
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
    p.write_text(
        "time,lat,lon,sog_kn\n2025-01-19T03:00:00Z,-36.83,174.76,5\n"
        "2025-01-19T03:00:01Z,-36.83,174.7601,5.1\n"
    )
    tr = read_track(p)
    with pytest.raises(
        InputError,
        match=r"dinghy\.csv: no usable wind columns \(channels "
        r"found: sog_ms\)",
    ):
        sensor_from_track(tr)


# ------------------------------------------------------------------------------ one boat
def test_boat_wind_hole_raises_naming_boat_and_gap() -> None:
    t = np.concatenate([T0 + np.arange(100.0), T0 + 400.0 + np.arange(100.0)])
    tr = _track(
        t,
        {"tws_ms": np.full(t.size, 8.0), "twd_deg": np.full(t.size, 40.0)},
        name="NZL",
        source="data_NZL.csv",
    )
    f = boat_wind(tr, FRAME)
    u, v = f.sample(np.array([T0, T0 + 99.0, T0 + 400.0]), 0.0, 0.0)
    np.testing.assert_allclose(wind_speed_direction(u, v)[0], 8.0)
    with pytest.raises(
        OutOfCoverageError,
        match=r"1 of 2 sample points fall in a gap of the log of NZL "
        r"\(data_NZL\.csv\): no record from 2025-01-19T03:08:19.*"
        r"\(301 s > max_gap_s 30 s\)",
    ):
        f.sample(np.array([T0 + 50.0, T0 + 250.0]), 0.0, 0.0)
    # a larger limit bridges it
    f = boat_wind(tr, FRAME, max_gap_s=400.0)
    u, _ = f.sample(T0 + 250.0, 0.0, 0.0)
    assert np.isfinite(u)


def test_boat_wind_is_linear_in_time_in_components() -> None:
    t = T0 + np.array([0.0, 10.0])
    s = MeasuredSeries(
        "B",
        "",
        t,
        *FRAME.to_latlon(np.zeros(2), np.zeros(2)),
        np.array([2.0, 4.0]),
        np.array([0.0, -6.0]),
    )
    u, v = boat_wind(s, FRAME).sample(T0 + 2.5, 1e4, -1e4)
    assert (float(u), float(v)) == pytest.approx((2.5, -1.5), abs=1e-9)


# ------------------------------------------------------------------------------ fleet
def _analytic_boats(biased=(1.1, 8.0, 15.0), n_s=1200):
    """Three boats sailing loops through an oscillating wind; boat B2 biased."""
    t = T0 + np.arange(float(n_s))
    out = []
    for k, (f, dd, dt) in enumerate([(1.0, 0.0, 0.0), (1.0, 0.0, 0.0), biased]):
        x = 800 * np.sin(2 * np.pi * t / 300 + k) + 200 * k
        y = 600 * np.cos(2 * np.pi * t / 420 + k) - 100 * k
        tt = t - dt  # its clock is dt ahead: the wind of time t - dt is stamped t
        d = 60 + 10 * np.sin(2 * np.pi * (tt - T0) / 360) + 0.0003 * x
        s = 10 + 1.5 * np.sin(2 * np.pi * (tt - T0) / 240 + 1) + 0.0001 * y
        u, v = wind_components(s * f, d + dd)
        lat, lon = FRAME.to_latlon(x, y)
        out.append(MeasuredSeries(f"B{k}", f"b{k}.csv", t, lat, lon, u, v, "tws/twd"))
    return out


def test_bias_recovery_on_synthetic_sensors() -> None:
    b = estimate_biases(_analytic_boats())
    assert [x.boat for x in b] == ["B0", "B1", "B2"]
    assert b[2].speed_factor == pytest.approx(1.1, rel=0.02)
    assert b[2].direction_offset_deg == pytest.approx(8.0, abs=1.0)
    assert b[2].time_offset_s == pytest.approx(15.0, abs=2.0)
    for ok in b[:2]:  # the consensus is the median boat: the biased one does not drag them
        assert ok.speed_factor == pytest.approx(1.0, rel=0.01)
        assert abs(ok.direction_offset_deg) < 0.5 and abs(ok.time_offset_s) < 1.0
    assert all(x.n_samples > 2000 and x.clock_samples == x.n_samples for x in b)
    # a clock offset beyond the search peaks at its edge: not identified, not corrected
    short = estimate_biases(_analytic_boats(), max_lag_s=8.0)
    assert short[2].clock_samples < short[2].n_samples
    assert all(x.time_offset_s == 0.0 for x in short if x.clock_samples == 0)
    assert short[2].time_offset_s == 0.0 and "time not identified" in short[2].describe()
    fw = fleet_wind(_analytic_boats(), FRAME)
    assert fw.biases == b
    assert any(n.startswith("bias B2: speed x1.09") for n in fw.notes)


@pytest.mark.parametrize("method", FLEET_METHODS)
def test_fleet_reproduces_a_uniform_wind(method: str) -> None:
    boats = _analytic_boats()
    uni = []
    for s in boats:
        lat, lon = s.lat, s.lon
        tw = (150.0 - FRAME.grid_north_deg(lat, lon)) % 360  # constant in the local frame
        uni.append(MeasuredSeries(s.boat, s.file, s.t, lat, lon, *wind_components(7.0, tw)))
    rng = np.random.default_rng(3)
    pts = (
        rng.uniform(T0 + 30, T0 + 1100, 500),
        rng.uniform(-700, 700, 500),
        rng.uniform(-500, 500, 500),
    )
    u0, v0 = wind_components(7.0, 150.0)
    u, v = fleet_wind(uni, FRAME, method=method, estimate_bias=False).field.sample(*pts)
    np.testing.assert_allclose(u, u0, atol=1e-9)
    np.testing.assert_allclose(v, v0, atol=1e-9)
    # a steady wind has no bias to find (in true directions the boats differ by the
    # meridian convergence across 1.6 km, 0.006 deg)
    fw = fleet_wind(uni, FRAME, method=method)
    assert all(
        b.speed_factor == pytest.approx(1.0, abs=1e-9)
        and b.time_offset_s == 0.0
        and abs(b.direction_offset_deg) < 0.01
        for b in fw.biases
    )
    u, v = fw.field.sample(*pts)
    np.testing.assert_allclose(u, u0, atol=1e-3)


def test_hull_fraction_on_a_known_triangle() -> None:
    t = T0 + np.arange(0.0, 601.0, 10.0)
    sens = []
    for k, (x, y) in enumerate([(0.0, 0.0), (1000.0, 0.0), (0.0, 1000.0)]):
        lat, lon = FRAME.to_latlon(np.full(t.size, x), np.full(t.size, y))
        sens.append(MeasuredSeries(f"B{k}", "", t, lat, lon, np.ones(t.size), np.ones(t.size)))
    px = np.array([100.0, 300.0, 900.0, -10.0, 200.0])
    py = np.array([100.0, 300.0, 900.0, 50.0, 200.0])
    pt = np.array([T0 + 100, T0 + 300, T0 + 300, T0 + 500, T0 + 700])  # last: after the logs
    assert hull_fraction(sens, FRAME, pt, px, py) == pytest.approx(2 / 5)
    fw = fleet_wind(sens, FRAME, method="mean", estimate_bias=False)
    assert fw.coverage_report(pt, px, py) == pytest.approx(0.4)
    assert fw.extrapolation_note(pt, px, py, "the course").startswith(
        "fleet wind: 60 % of the course (5 points) lie outside the sensors' hull"
    )


def test_fleet_names_the_log_that_limits_the_span_and_refuses_common_holes() -> None:
    boats = _analytic_boats((1.0, 0.0, 0.0))
    short = boats[2].between(T0 + 100, T0 + 900)
    fw = fleet_wind([boats[0], boats[1], short], FRAME, estimate_bias=False)
    assert "limited by the log of B2 (b2.csv) (starts" in fw.notes[-1]
    with pytest.raises(
        OutOfCoverageError,
        match=r"(?s)requested.*the time span is limited by "
        r"the log of B2 \(b2\.csv\)",
    ):
        fw.field.sample(T0 + 50, 0.0, 0.0)
    cut = [b.between(T0, T0 + 400) for b in boats]
    later = [b.between(T0 + 500, T0 + 1199) for b in boats]
    holed = [
        MeasuredSeries(
            a.boat,
            a.file,
            np.concatenate([a.t, b.t]),
            np.concatenate([a.lat, b.lat]),
            np.concatenate([a.lon, b.lon]),
            np.concatenate([a.u, b.u]),
            np.concatenate([a.v, b.v]),
            gaps=((T0 + 400, T0 + 500),),
        )
        for a, b in zip(cut, later, strict=True)
    ]
    fw = fleet_wind(holed, FRAME, estimate_bias=False, method="mean")
    with pytest.raises(
        OutOfCoverageError,
        match=r"every log has a gap .* B0 \(b0\.csv\) "
        r"2025-01-19T03:13:20",
    ):
        fw.field.sample(T0 + 450, 0.0, 0.0)
    u, _ = fw.field.sample(T0 + 399, 0.0, 0.0)
    assert np.isfinite(u)


def test_fleet_bad_input() -> None:
    boats = _analytic_boats()
    with pytest.raises(InputError, match="method 'kriging'; expected one of mean, idw"):
        fleet_wind(boats, FRAME, method="kriging")
    apart = [boats[0].between(T0, T0 + 100), boats[1].between(T0 + 500, T0 + 600)]
    with pytest.raises(InputError, match="the logs never overlap in time"):
        fleet_wind(apart, FRAME, estimate_bias=False)


# ------------------------------------------------------------------------------ SailGP
SAILGP = SHARED_REAL / "races" / "sailgp-auckland-2025" / "Boat_logs"


def _race(boat: str, race: int) -> Track:
    t0 = t1 = None
    with (SAILGP / f"data_{boat}.csv").open() as f:
        for row in csv.DictReader(f):
            if row["TRK_RACE_NUM_unk"].strip() and int(float(row["TRK_RACE_NUM_unk"])) == race:
                t = datetime.fromisoformat(row["DATETIME"]).replace(tzinfo=UTC).timestamp()
                t0 = t if t0 is None else min(t0, t)
                t1 = t if t1 is None else max(t1, t)
    assert t0 is not None and t1 is not None
    tr = read_track(SAILGP / f"data_{boat}.csv", time_zone="UTC", name=boat)
    return tr.between(t0, t1)


@requires_shared
def test_sailgp_default_beats_the_sensor_mean_leaving_one_boat_out() -> None:
    tracks = [_race(b, 25011905) for b in ("NZL", "AUS", "GBR")]
    sens = [sensor_from_track(t) for t in tracks]
    assert sens[0].source == "tws/twd" and sens[0].gaps == ()
    raw = [sensor_from_track(t, smooth_s=0.0) for t in tracks]
    rows = leave_one_out(
        sens,
        FRAME,
        {
            "default": {},
            "mean": {"method": "mean", "resample_s": 0.0, "estimate_bias": False},
        },
        targets=raw,
    )
    pooled = {r.label: r for r in rows if r.boat == "pooled"}
    d, m = pooled["default"], pooled["mean"]
    assert d.n == m.n > 1800
    # measured (benchmarks/bench_fleet_wind.py --smoke): 1.526 kn / 3.61 deg vs 1.877 kn / 3.96 deg
    assert d.speed_rms_kn == pytest.approx(1.526, abs=0.03)
    assert d.dir_mae_deg == pytest.approx(3.61, abs=0.1)
    assert m.speed_rms_kn == pytest.approx(1.877, abs=0.03)
    assert m.dir_mae_deg == pytest.approx(3.96, abs=0.1)
    assert d.speed_rms_kn < m.speed_rms_kn - 0.25 and d.dir_mae_deg < m.dir_mae_deg - 0.2


# ------------------------------------------------------------------------------ course spec
def _write_log(path: Path, boat_y: float, twd: float) -> None:
    lines = ["time,lat,lon,tws_kn,twd"]
    for k in range(0, 900, 2):
        lat, lon = FRAME.to_latlon(-900.0 + 2.0 * k, boat_y)
        t = datetime.fromtimestamp(T0 + k, UTC).isoformat()
        lines.append(f"{t},{float(lat):.7f},{float(lon):.7f},12.0,{twd}")
    path.write_text("\n".join(lines) + "\n")


def test_course_wind_type_measured(tmp_path: Path) -> None:
    from sailroute.wind.build import wind_from_spec

    for k in range(3):
        _write_log(tmp_path / f"boat{k}.csv", 300.0 * k, 200.0)
    spec = {"type": "measured", "tracks": [f"boat{k}.csv" for k in range(3)], "method": "mean"}
    f = wind_from_spec(
        spec,
        frame=FRAME,
        base_dir=tmp_path,
        where="c.yaml: scenarios.m",
        time_window=(T0 + 100, T0 + 800),
    )
    s, d = wind_speed_direction(*f.sample(T0 + 400.0, 0.0, 300.0))
    assert float(s) == pytest.approx(12.0 * KNOT, rel=1e-9)
    assert float(d) == pytest.approx(
        200.0 + float(FRAME.grid_north_deg(*FRAME.to_latlon(0.0, 300.0))), abs=0.01
    )
    with pytest.raises(InputError, match=r"c\.yaml: scenarios\.m\.tracks\[1\]: file not found"):
        wind_from_spec(
            {"type": "measured", "tracks": ["boat0.csv", "nope.csv"]},
            frame=FRAME,
            base_dir=tmp_path,
            where="c.yaml: scenarios.m",
        )
    with pytest.raises(InputError, match=r"scenarios\.m\.method: expected one of 'mean'"):
        wind_from_spec(
            {"type": "measured", "tracks": ["boat0.csv"], "method": "krige"},
            frame=FRAME,
            base_dir=tmp_path,
            where="c.yaml: scenarios.m",
        )
    with pytest.raises(
        InputError,
        match=r"scenarios\.m\.tracks\[0\]: boat0\.csv has no wind "
        r"records within 600 s of the race window",
    ):
        wind_from_spec(
            {"type": "measured", "tracks": ["boat0.csv"]},
            frame=FRAME,
            base_dir=tmp_path,
            where="c.yaml: scenarios.m",
            time_window=(T0 + 1e5, T0 + 2e5),
        )
