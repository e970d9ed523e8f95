"""Station CSV reader, resampling, NDBC reader and the StationWind field."""

from __future__ import annotations

import csv
from collections import Counter
from datetime import datetime

import numpy as np
import pytest

from sailroute.errors import InputError, OutOfCoverageError, WindDataError
from sailroute.geo import LocalFrame
from sailroute.units import KNOT, circular_mean_deg, wind_components, wind_speed_direction
from sailroute.wind.base import WindField
from sailroute.wind.ndbc import read_ndbc
from sailroute.wind.stations import (
    StationData,
    StationWind,
    read_stations,
    resample_stations,
)
from tests.conftest import WIND_DATA

COACH = WIND_DATA / "coach_wind_1hz_excerpt.csv"
NDBC_CSV = WIND_DATA / "ndbc_41008_excerpt.csv"
NDBC_TXT = WIND_DATA / "ndbc_41008_excerpt.cwind.txt"
GRAYS_REEF = (31.400, -80.866)  # NDBC 41008 position
T = "2018-04-24T12:{:02d}:00+02:00"
T_EPOCH = datetime.fromisoformat("2018-04-24T10:00:00+00:00").timestamp()


def rows(*specs):
    return [[T.format(m), s, lat, lon, spd, d] for m, s, lat, lon, spd, d in specs]


# --------------------------------------------------------------------------- reading
def test_canonical_csv_units_times_and_ids(station_csv) -> None:
    p = station_csv(
        rows(
            (0, "A", 43.0, 6.0, 10, 90), (1, "A", 43.0, 6.0, 12, 95), (0, "B", 43.01, 6.01, 8, 359)
        )
    )
    d = read_stations(p, speed_unit="kn")
    assert d.stations == ("A", "B")
    assert d.station.tolist() == ["A", "A", "B"]  # grouped by station, time order kept
    np.testing.assert_allclose(d.speed_ms, np.array([10, 12, 8]) * KNOT, rtol=1e-15)
    np.testing.assert_array_equal(d.t, T_EPOCH + np.array([0, 60, 0]))  # 12:00+02 = 10:00Z
    assert d.n_missing == 0 and d.n_raw == 3
    assert np.all(np.isnan(d.height_m)) and np.all(np.isnan(d.gust_ms))


def test_aliases_timezone_and_unit_from_header() -> None:
    d = read_stations(COACH, timezone="+01:00", station="coach", resample_s=60)
    assert d.stations == ("coach",)
    raw = read_stations(COACH, timezone="+01:00", resample_s=1)  # 1 s bins ~ raw samples
    # tws_kn -> knots: first logged row 4.03 kn at 10:34:58 CET = 09:34:58Z
    assert raw.t[0] == datetime.fromisoformat("2018-02-15T09:34:58+00:00").timestamp() + 0.5
    assert raw.speed_ms[0] == pytest.approx(4.03 * KNOT, rel=1e-12)
    assert raw.stations == ("coach_wind_1hz_excerpt",)  # default id: file stem
    assert len(d) == 15  # 10:35..10:49; the partial first/last minutes are dropped


def test_explicit_column_mapping_and_position(station_csv) -> None:
    p = station_csv(
        [["2018-04-24T10:00:00Z", "3.0", "200"], ["2018-04-24T10:10:00Z", "4.0", "210"]],
        header=("when", "vel", "from_deg"),
    )
    d = read_stations(
        p,
        columns={"time": "when", "speed": "vel", "direction": "from_deg"},
        speed_unit="m/s",
        position=(43.0, 6.0),
        station="buoy",
        height_m=3.5,
    )
    assert d.stations == ("buoy",)
    np.testing.assert_array_equal(d.lat, [43.0, 43.0])
    np.testing.assert_array_equal(d.height_m, [3.5, 3.5])
    np.testing.assert_array_equal(d.direction_deg, [200.0, 210.0])
    with pytest.raises(InputError, match=r"columns.speed: column 'velocity' is not in the header"):
        read_stations(p, columns={"time": "when", "speed": "velocity"}, speed_unit="m/s")


def test_speed_unit_must_be_known_and_consistent(station_csv) -> None:
    p = station_csv(rows((0, "A", 43.0, 6.0, 10, 90)))
    with pytest.raises(InputError, match="unit of column 'speed' is not known; declare it"):
        read_stations(p)
    q = station_csv(
        [[T.format(0), "A", 43, 6, 10, 90]],
        name="kn.csv",
        header=("time", "station", "lat", "lon", "tws_kn", "twd_deg"),
    )
    with pytest.raises(InputError, match="speed_unit 'm/s' contradicts the column name 'tws_kn'"):
        read_stations(q, speed_unit="m/s")
    with pytest.raises(InputError, match="unknown speed unit 'knts'"):
        read_stations(p, speed_unit="knts")


def test_naive_time_needs_timezone(station_csv) -> None:
    p = station_csv([["2018-02-15T10:00:00", "A", 45.5, 13.6, 5, 60]])
    with pytest.raises(
        InputError,
        match=r"line 2, column 'time': time '2018-02-15T10:00:00' has "
        r"no UTC offset.*timezone: '\+01:00'",
    ):
        read_stations(p, speed_unit="kn")
    d = read_stations(p, speed_unit="kn", timezone="+01:00")
    assert d.t[0] == datetime.fromisoformat("2018-02-15T09:00:00+00:00").timestamp()
    with pytest.raises(InputError, match="not a UTC offset"):
        read_stations(p, speed_unit="kn", timezone="Europe/Rome")


def test_missing_markers_counted_and_dropped(station_csv) -> None:
    p = station_csv(
        rows(
            (0, "A", 43, 6, 10, 90),
            (1, "A", 43, 6, "", 90),
            (2, "A", 43, 6, "MM", 90),
            (3, "A", 43, 6, 11, "999"),
            (4, "A", 43, 6, "nan", 91),
            (5, "A", 43, 6, 12, 92),
        )
    )
    d = read_stations(p, speed_unit="kn", missing=("", "MM", "999", "nan"))
    assert len(d) == 2 and d.n_raw == 6 and d.n_missing == 4
    assert dict(d.missing_by_column) == {"speed": 3, "direction": 1}
    with pytest.raises(WindDataError, match=r"line 5, column 'direction': value 999 is out"):
        read_stations(p, speed_unit="kn", missing=("", "MM", "nan"))


def test_bad_rows_are_named(station_csv) -> None:
    back = station_csv(rows((1, "A", 43, 6, 10, 90), (0, "A", 43, 6, 10, 90)), name="b.csv")
    with pytest.raises(WindDataError, match=r"line 3: .* goes back in time from line 2.*Sort"):
        read_stations(back, speed_unit="kn")
    word = station_csv(rows((0, "A", 43, 6, "ten", 90)), name="w.csv")
    with pytest.raises(WindDataError, match=r"line 2, column 'speed': cannot read 'ten'"):
        read_stations(word, speed_unit="kn")
    short = station_csv([[T.format(0), "A", 43, 6, 10]], name="s.csv")
    with pytest.raises(WindDataError, match="line 2: 5 fields but the header has 6"):
        read_stations(short, speed_unit="kn")
    badtime = station_csv(
        [*rows((0, "A", 43, 6, 10, 90)), ["yesterday", "A", 43, 6, 1, 2]], name="t.csv"
    )
    with pytest.raises(WindDataError, match="line 3, column 'time': cannot read 'yesterday'"):
        read_stations(badtime, speed_unit="kn")


def test_empty_header_only_and_ambiguous(tmp_path, station_csv) -> None:
    e = tmp_path / "e.csv"
    e.write_text("")
    with pytest.raises(WindDataError, match="the file is empty"):
        read_stations(e)
    h = station_csv([], name="h.csv")
    with pytest.raises(WindDataError, match="header but no data rows"):
        read_stations(h, speed_unit="kn")
    amb = station_csv([], name="a.csv", header=("time", "lat", "lon", "tws", "wspd", "twd"))
    with pytest.raises(InputError, match=r"tws, wspd could all be the 'speed' column"):
        read_stations(amb)
    nolat = station_csv([], name="n.csv", header=("time", "speed", "direction"))
    with pytest.raises(InputError, match=r"no column for lat, lon.*position"):
        read_stations(nolat, speed_unit="kn")


def test_repeated_timestamps_need_resampling() -> None:
    with pytest.raises(WindDataError, match=r"line 22: .* repeats the time of line 21.*resample_s"):
        read_stations(COACH, timezone="+01:00")
    assert len(read_stations(COACH, timezone="+01:00", resample_s=10)) > 80


# --------------------------------------------------------------------------- resampling
def _data(t, speed, direction, station="S", lat=43.0, lon=6.0, gust=None):
    n = len(t)
    return StationData(
        np.full(n, station),
        np.asarray(t, float),
        np.full(n, lat),
        np.full(n, lon),
        np.asarray(speed, float),
        np.asarray(direction, float),
        np.full(n, np.nan),
        np.full(n, np.nan) if gust is None else np.asarray(gust, float),
    )


def test_resample_vector_direction_scalar_speed_and_bins() -> None:
    t = 1000.0 * 60 + np.arange(120)  # two full minutes of 1 Hz samples
    d = np.where(np.arange(120) % 2 == 0, 350.0, 10.0)  # swings across north
    s = np.where(np.arange(120) % 2 == 0, 4.0, 6.0)
    g = np.where(np.arange(120) == 7, 9.0, np.nan)
    r = resample_stations(_data(t, s, d, gust=g), 60.0)
    assert len(r) == 2
    np.testing.assert_array_equal(r.t, [60000.0 + 30.0, 60060.0 + 30.0])  # bin centres
    np.testing.assert_allclose(r.speed_ms, [5.0, 5.0])  # scalar mean
    # Vector mean of 4 m/s from 350 and 6 m/s from 10: the speed-weighted mean of the
    # directions, tan(dir) = (6 sin 10 - 4 sin 10) / (10 cos 10) -> 2.0 deg (not 180!).
    expected = np.degrees(np.arctan2(2 * np.sin(np.radians(10)), 10 * np.cos(np.radians(10))))
    np.testing.assert_allclose(r.direction_deg, expected, atol=1e-9)
    assert r.gust_ms[0] == 9.0 and np.isnan(r.gust_ms[1])
    # A bin with less than half its samples is dropped:
    r2 = resample_stations(_data(t[:80], s[:80], d[:80]), 60.0)
    assert len(r2) == 1


def test_coach_resampling_matches_hand_computation() -> None:
    r = read_stations(COACH, timezone="+01:00", resample_s=60)
    with open(COACH, newline="") as f:
        raw = [
            row
            for row in csv.DictReader(f)
            if row["datetime_local"].startswith("2018-02-15T10:40:")
        ]
    spd = np.array([float(x["tws_kn"]) for x in raw]) * KNOT
    u, v = wind_components(spd, [float(x["twd_deg"]) for x in raw])
    k = int(
        np.argmin(np.abs(r.t - datetime.fromisoformat("2018-02-15T09:40:30+00:00").timestamp()))
    )
    assert r.speed_ms[k] == pytest.approx(spd.mean(), rel=1e-12)
    assert r.direction_deg[k] == pytest.approx(
        wind_speed_direction(u.mean(), v.mean())[1], abs=1e-9
    )
    assert r.lat[k] == pytest.approx(np.mean([float(x["lat"]) for x in raw]), abs=1e-12)
    r10 = read_stations(COACH, timezone="+01:00", resample_s=10)
    with open(COACH, newline="") as f:
        stamps = [row["datetime_local"] for row in csv.DictReader(f)]
    per_bin = Counter(s[:18] for s in stamps)  # "YYYY-MM-DDTHH:MM:S" = one 10 s bin
    # Median interval 1 s -> a full bin holds 10 samples; bins with < 5 are dropped.
    assert len(r10) == sum(1 for n in per_bin.values() if n >= 5) == 92


# --------------------------------------------------------------------------- NDBC
def test_ndbc_raw_text_and_csv_agree() -> None:
    a = read_ndbc(NDBC_TXT, position=GRAYS_REEF, station="41008")
    b = read_stations(NDBC_CSV, position=GRAYS_REEF, station="41008")
    assert len(a) == len(b) == 44 and a.n_missing == b.n_missing == 3
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.speed_ms, b.speed_ms)
    np.testing.assert_array_equal(a.direction_deg, b.direction_deg)
    np.testing.assert_array_equal(np.isnan(a.gust_ms), np.isnan(b.gust_ms))


def test_ndbc_circular_mean_across_north() -> None:
    d = read_stations(NDBC_CSV, position=GRAYS_REEF)
    hour = (d.t >= datetime.fromisoformat("2018-06-17T18:10:00+00:00").timestamp()) & (
        d.t <= datetime.fromisoformat("2018-06-17T19:30:00+00:00").timestamp()
    )
    dirs = d.direction_deg[hour]
    assert dirs.min() < 10 and dirs.max() > 350  # the hour straddles north
    assert 100 < np.mean(dirs) < 200  # the naive arithmetic mean points south: the trap
    m = circular_mean_deg(dirs)
    assert m < 10 or m > 355
    r = resample_stations(d.select(d.stations[0]), 3600.0, min_fill=0.5)
    k = int(
        np.argmin(np.abs(r.t - datetime.fromisoformat("2018-06-17T18:30:00+00:00").timestamp()))
    )
    assert r.direction_deg[k] < 15 or r.direction_deg[k] > 345


# --------------------------------------------------------------------------- field
def _two_stations(t0: float = 0.0) -> StationData:
    frame = LocalFrame(43.0, 6.0)
    la, lo = frame.to_latlon(np.array([-1000.0, 1000.0]), np.array([0.0, 0.0]))
    t = np.array([t0, t0 + 600.0])
    return StationData(
        np.array(["W", "W", "E", "E"]),
        np.tile(t, 2),
        np.repeat(la, 2),
        np.repeat(lo, 2),
        np.array([4.0, 6.0, 8.0, 8.0]),
        np.array([270.0, 270.0, 270.0, 270.0]),
        np.full(4, 7.5),
        np.full(4, np.nan),
    )


def test_idw_exact_at_stations_average_between_linear_in_time() -> None:
    frame = LocalFrame(43.0, 6.0)
    f = StationWind(_two_stations(), frame)
    assert isinstance(f, WindField)
    # West station at 300 s: its two records 4 and 6 m/s interpolate to 5 m/s.
    # (Speeds are compared: the local frame turns each station's west wind by its
    # meridian convergence, ~1e-4 rad at 1 km, which moves u by ~1e-8 m/s; averaging two
    # vectors turned opposite ways shortens the mean by ~1e-7 m/s, hence 1e-6 there.)
    s, d = wind_speed_direction(*f.sample(300.0, -1000.0, 0.0))
    assert float(s) == pytest.approx(5.0, abs=1e-9)
    assert float(d) == pytest.approx(270.0, abs=0.01)
    s, _ = wind_speed_direction(*f.sample(300.0, 0.0, 0.0))  # equidistant: mean of 5 and 8
    assert float(s) == pytest.approx(6.5, abs=1e-6)
    s, _ = wind_speed_direction(*f.sample(0.0, 500.0, 0.0))  # d_W = 1500 m, d_E = 500 m
    assert float(s) == pytest.approx(
        (4 / 1500**2 + 8 / 500**2) / (1 / 1500**2 + 1 / 500**2), abs=1e-6
    )


def test_rbf_exact_at_stations_and_constant() -> None:
    frame = LocalFrame(43.0, 6.0)
    f = StationWind(_two_stations(), frame, method="rbf")
    assert float(np.hypot(*f.sample(0.0, 1000.0, 0.0))) == pytest.approx(8.0, abs=1e-9)
    assert float(np.hypot(*f.sample(600.0, -1000.0, 0.0))) == pytest.approx(6.0, abs=1e-9)
    assert 6.0 < float(np.hypot(*f.sample(600.0, 0.0, 300.0))) < 8.0


def test_station_coverage_height_and_gaps() -> None:
    frame = LocalFrame(43.0, 6.0)
    f = StationWind(_two_stations(), frame, radius_m=500.0, height_m=2.68)
    c = f.coverage
    assert (c.xmin, c.xmax) == pytest.approx((-1500.0, 1500.0), abs=1e-6)
    assert (c.t0, c.t1) == (0.0, 600.0)
    s = np.hypot(*f.sample(0.0, 1000.0, 0.0))
    assert float(s) == pytest.approx(8.0 * (2.68 / 7.5) ** (1 / 7), abs=1e-9)
    with pytest.raises(OutOfCoverageError, match=r"requested.*\n.*covered"):
        f.sample(0.0, 1600.0, 0.0)
    with pytest.raises(WindDataError, match=r"station 'W' has no record .* max_gap_s"):
        StationWind(_two_stations(), frame, max_gap_s=300.0)
    late = _two_stations()
    late = StationData(
        late.station,
        late.t + np.array([0, 0, 1e4, 1e4]),
        late.lat,
        late.lon,
        late.speed_ms,
        late.direction_deg,
        late.height_m,
        late.gust_ms,
    )
    with pytest.raises(WindDataError, match="never report at the same time"):
        StationWind(late, frame)


def test_coverage_error_names_the_station_that_cuts_the_span() -> None:
    d = _two_stations()
    # station E starts 120 s later than W and ends with it: E limits the start
    d = StationData(
        d.station,
        d.t + np.array([0.0, 0.0, 120.0, 0.0]),
        d.lat,
        d.lon,
        d.speed_ms,
        d.direction_deg,
        d.height_m,
        d.gust_ms,
        source="coach.csv",
    )
    f = StationWind(d, LocalFrame(43.0, 6.0))
    assert f.coverage.t0 == 120.0
    with pytest.raises(
        OutOfCoverageError,
        match=r"(?s)requested.*the time span is limited by "
        r"station 'E' of coach\.csv \(first record "
        r"1970-01-01T00:02:00",
    ):
        f.sample(60.0, 0.0, 0.0)


def test_moving_station_coverage_follows_track() -> None:
    d = read_stations(COACH, timezone="+01:00", resample_s=60)
    frame = LocalFrame(45.55, 13.65)
    f = StationWind(d, frame, radius_m=1000.0)
    x, y = frame.to_xy(d.lat, d.lon)
    c = f.coverage
    assert c.xmin == pytest.approx(x.min() - 1000.0) and c.ymax == pytest.approx(y.max() + 1e3)
    # A single moving station gives its own (interpolated) reading everywhere nearby.
    k = 5
    u, v = f.sample(d.t[k], x[k] + 300.0, y[k] - 200.0)
    s, dd = wind_speed_direction(u, v)
    assert float(s) == pytest.approx(d.speed_ms[k], rel=1e-9)
    assert float(dd) == pytest.approx(
        d.direction_deg[k] + frame.grid_north_deg(d.lat[k], d.lon[k]), abs=1e-6
    )
    with pytest.raises(InputError, match="'rbf' needs fixed stations"):
        StationWind(d, frame, method="rbf")


# --------------------------------------------------------------------------- additions
@pytest.mark.parametrize(
    ("header", "declared", "factor"),
    [
        ("speed_kmh", None, 1000.0 / 3600.0),
        ("wind_speed_mph", None, 1609.344 / 3600.0),
        ("speed", "km/h", 1000.0 / 3600.0),
        ("speed", "mph", 1609.344 / 3600.0),
        ("speed", "m/s", 1.0),
        ("tws_kn", None, 1852.0 / 3600.0),
    ],
)
def test_all_four_speed_units(station_csv, header: str, declared, factor: float) -> None:
    p = station_csv(
        rows((0, "A", 43.0, 6.0, 18, 90), (1, "A", 43.0, 6.0, 36, 95)),
        header=("time", "station", "lat", "lon", header, "direction"),
    )
    d = read_stations(p, speed_unit=declared)
    np.testing.assert_allclose(d.speed_ms, np.array([18.0, 36.0]) * factor, rtol=1e-15)


@pytest.mark.parametrize("hz", [1, 10, 20])
def test_resampling_high_rate_logs(hz: int) -> None:
    # 3 minutes at hz: a wind veering steadily from 350 to 10 deg (across north) at 5 m/s,
    # starting 20 s into a UTC minute (1_000_020 s is a minute boundary): bins of 40, 60, 60
    # and 20 s; the last holds a third of a full bin's samples and is dropped (min_fill 0.5).
    n = 180 * hz
    t = 1_000_040.0 + np.arange(n) / hz
    direction = (350.0 + 20.0 * np.arange(n) / n) % 360.0
    r = resample_stations(_data(t, np.full(n, 5.0), direction), 60.0)
    assert len(r) == 3
    np.testing.assert_allclose(r.speed_ms, 5.0, rtol=1e-12)
    starts = np.floor(t / 60.0) * 60.0
    for k, b in enumerate(np.unique(starts)[:3]):
        m = starts == b
        u, v = wind_components(5.0, direction[m])
        assert r.direction_deg[k] == pytest.approx(
            wind_speed_direction(u.mean(), v.mean())[1], abs=1e-9
        )
        assert r.t[k] == b + 30.0
    assert r.direction_deg[1] > 355.0 or r.direction_deg[1] < 5.0  # across north, not south


def test_non_finite_numbers_are_refused(station_csv) -> None:
    p = station_csv(rows((0, "A", 43, 6, 10, 90), (1, "A", 43, 6, "inf", 90)), name="inf.csv")
    with pytest.raises(WindDataError, match=r"line 3, column 'speed': 'inf' is not a finite"):
        read_stations(p, speed_unit="kn")


def test_ndbc_out_of_range_value_is_named(tmp_path) -> None:
    lines = NDBC_TXT.read_text().splitlines()
    f = lines[2].split()
    f[5] = "412"  # WDIR
    bad = tmp_path / "bad.cwind.txt"
    bad.write_text("\n".join([*lines[:2], " ".join(f), *lines[3:]]) + "\n")
    with pytest.raises(WindDataError, match=r"line 3, column WDIR: value '412' is out of range"):
        read_ndbc(bad, position=GRAYS_REEF)
