"""Station inputs people have: long records with gaps, raw NDBC text in course
files, split date/time columns, pandas DataFrames, dropped-row counts."""

from __future__ import annotations

from datetime import datetime

import numpy as np
import pytest

from sailroute.errors import InputError, WindDataError
from sailroute.geo import LocalFrame
from sailroute.units import KNOT
from sailroute.wind.build import wind_from_spec, wind_notes
from sailroute.wind.ndbc import is_ndbc_text, read_ndbc
from sailroute.wind.stations import StationData, StationWind, read_stations
from tests.conftest import SHARED_REAL, WIND_DATA, requires_shared

GRAYS_REEF = (31.400, -80.866)
FRAME = LocalFrame(*GRAYS_REEF)
NDBC_TXT = WIND_DATA / "ndbc_41008_excerpt.cwind.txt"
NDBC_CSV = WIND_DATA / "ndbc_41008_excerpt.csv"
WHERE = "x.yaml: scenarios.buoy.wind"


def epoch(text: str) -> float:
    return datetime.fromisoformat(text.replace("Z", "+00:00")).timestamp()


def gappy(t_gap_start: float, gap_s: float) -> StationData:
    """One station every 10 min for a day, with one gap."""
    t = epoch("2018-06-26T00:00Z") + 600.0 * np.arange(145)
    t = np.where(t > t_gap_start, t + gap_s, t)
    n = t.size
    return StationData(
        np.full(n, "B"),
        t,
        np.full(n, GRAYS_REEF[0]),
        np.full(n, GRAYS_REEF[1]),
        np.full(n, 5.0),
        np.full(n, 90.0),
        np.full(n, 4.0),
        np.full(n, np.nan),
    )


# --------------------------------------------------------------------------- gaps
def test_gap_check_only_inside_the_race_window() -> None:
    d = gappy(epoch("2018-06-26T10:50Z"), 13 * 3600.0)
    with pytest.raises(
        WindDataError,
        match=r"station 'B' has no record from "
        r"2018-06-26T10:50:00.000Z to 2018-06-27T00:00",
    ):
        StationWind(d, FRAME)
    later = (epoch("2018-06-27T02:00Z"), epoch("2018-06-27T03:30Z"))
    w = StationWind(d, FRAME, time_window=later)
    assert w.coverage.t0 == epoch("2018-06-27T00:00Z")  # the gap-free stretch, not the gap
    assert w.coverage.source_span == (d.t[0], d.t[-1])
    across = (epoch("2018-06-26T10:00Z"), epoch("2018-06-27T01:00Z"))
    with pytest.raises(
        WindDataError,
        match=r"2018-06-26T10:50:00.000Z to 2018-06-27T00:00:00"
        r".000Z inside the race window",
    ):
        StationWind(d, FRAME, time_window=across)
    # a short race inside the gap: still bridged from record to record, so refused
    inside = (epoch("2018-06-26T15:00Z"), epoch("2018-06-26T15:20Z"))
    with pytest.raises(WindDataError, match="inside the race window"):
        StationWind(d, FRAME, time_window=inside)


# --------------------------------------------------------------------------- split columns
def test_split_date_time_columns(station_csv) -> None:
    rows = [
        [2018, 6, 17, 16, 0, 2.9, 317],
        [2018, 6, 17, 16, 10, "MM", 315],
        [2018, 6, 17, 16, 20, 3.0, 314],
    ]
    p = station_csv(rows, header=("year", "month", "day", "hour", "minute", "wspd_kn", "wdir"))
    with pytest.raises(
        InputError,
        match=r"times from the columns year/month/day/hour/minute "
        r"carry no UTC offset; declare it with `timezone: 'Z'`",
    ):
        read_stations(p, position=GRAYS_REEF)
    d = read_stations(p, position=GRAYS_REEF, timezone="+02:00")
    assert d.t.tolist() == [epoch("2018-06-17T14:00Z"), epoch("2018-06-17T14:20Z")]
    assert d.n_missing == 1 and d.speed_ms[0] == pytest.approx(2.9 * KNOT)
    # NDBC's own header, blank separated: MM is the month, mm the minute, and UTC
    q = station_csv(
        [["2018", "07", "17", "02", "10", "318", "2.1"]],
        header=("#YY", "MM", "DD", "hh", "mm", "WDIR", "WSPD"),
        name="n.txt",
        sep="  ",
    )
    e = read_stations(q, position=GRAYS_REEF, speed_unit="m/s")
    assert e.t.tolist() == [epoch("2018-07-17T02:10Z")] and e.direction_deg[0] == 318
    r = station_csv(
        [[2018, 7, 17, 2, 5.0, 90]],
        header=("yyyy", "mm", "dd", "hh", "wspd_ms", "wd"),
        name="amb.csv",
    )
    with pytest.raises(InputError, match=r"column 'mm' could be the month or the minute"):
        read_stations(r, position=GRAYS_REEF, timezone="Z")
    f = read_stations(r, position=GRAYS_REEF, timezone="Z", columns={"month": "mm"})
    assert f.t.tolist() == [epoch("2018-07-17T02:00Z")]


# --------------------------------------------------------------------------- NDBC in specs
def test_ndbc_text_in_a_course_spec() -> None:
    assert is_ndbc_text(NDBC_TXT) and not is_ndbc_text(NDBC_CSV)
    window = (epoch("2018-06-17T16:30Z"), epoch("2018-06-17T17:30Z"))
    spec = {
        "type": "stations",
        "format": "ndbc",
        "path": NDBC_TXT.name,
        "position": {"lat": GRAYS_REEF[0], "lon": GRAYS_REEF[1]},
        "station": "41008",
        "measurement_height_m": 3.8,
        "height_m": 2.68,
    }
    a = wind_from_spec(
        spec,
        frame=FRAME,
        base_dir=WIND_DATA,
        where=WHERE,
        crop_bbox=(-500.0, 500.0, -500.0, 500.0),
        time_window=window,
    )
    auto = {k: v for k, v in spec.items() if k != "format"}
    b = wind_from_spec(auto, frame=FRAME, base_dir=WIND_DATA, where=WHERE, time_window=window)
    c = wind_from_spec(
        {**auto, "path": NDBC_CSV.name},
        frame=FRAME,
        base_dir=WIND_DATA,
        where=WHERE,
        time_window=window,
    )
    t = np.linspace(*window, 7)
    np.testing.assert_array_equal(a.sample(t, 0.0, 0.0), b.sample(t, 0.0, 0.0))
    np.testing.assert_allclose(a.sample(t, 0.0, 0.0), c.sample(t, 0.0, 0.0), atol=1e-12)
    notes = wind_notes(a)
    assert notes == [
        f"station wind {NDBC_TXT}: 47 rows read, 3 dropped for missing values "
        "(speed 3, direction 3), 44 records used"
    ]
    with pytest.raises(
        InputError,
        match=rf"{WHERE}: ndbc_41008_excerpt.cwind.txt is NDBC text, "
        r"which does not carry the buoy's position",
    ):
        wind_from_spec(
            {"type": "stations", "path": NDBC_TXT.name},
            frame=FRAME,
            base_dir=WIND_DATA,
            where=WHERE,
        )
    with pytest.raises(
        InputError,
        match=rf"{WHERE}.format: expected one of 'auto', 'csv', "
        r"'ndbc'; got 'ndbc-txt' \(did you mean 'ndbc'\?\)",
    ):
        wind_from_spec({**spec, "format": "ndbc-txt"}, frame=FRAME, base_dir=WIND_DATA, where=WHERE)


# --------------------------------------------------------------------------- DataFrame
def test_station_wind_from_a_pandas_dataframe() -> None:
    pd = pytest.importorskip("pandas")
    df = pd.read_csv(NDBC_CSV)
    df["time_utc"] = pd.to_datetime(df["time_utc"], utc=True)
    a = read_stations(df.set_index("time_utc"), position=GRAYS_REEF, station="41008")
    b = read_stations(NDBC_CSV, position=GRAYS_REEF, station="41008")
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.speed_ms, b.speed_ms)
    assert a.n_missing == b.n_missing == 3 and a.source == "DataFrame"
    naive = df.assign(time_utc=df["time_utc"].dt.tz_localize(None))
    with pytest.raises(
        InputError,
        match=r"DataFrame, line 2, column 'time_utc': time "
        r"'2018-06-17 16:00:00' has no UTC offset",
    ):
        read_stations(naive, position=GRAYS_REEF)


# --------------------------------------------------------------------------- real files
NDBC_REAL = SHARED_REAL / "wind"


@requires_shared
def test_whole_41008_record_usable_for_a_race_after_its_gaps() -> None:
    csv_path = NDBC_REAL / "ndbc-41008-cwind" / "41008_cwind_2018.csv"
    txt_path = NDBC_REAL / "ndbc-41008-cwind" / "41008.cwind.txt"
    window = (epoch("2018-07-20T14:00Z"), epoch("2018-07-20T15:30Z"))
    base = {
        "type": "stations",
        "position": {"lat": GRAYS_REEF[0], "lon": GRAYS_REEF[1]},
        "station": "41008",
    }
    with pytest.raises(
        WindDataError,
        match=r"no record from 2018-06-26T10:50:00.000Z to "
        r"2018-06-27T00:00:00.000Z",
    ):
        StationWind(read_stations(csv_path, position=GRAYS_REEF), FRAME)
    a = wind_from_spec(
        {**base, "path": str(csv_path)},
        frame=FRAME,
        base_dir=NDBC_REAL,
        where=WHERE,
        time_window=window,
    )
    b = wind_from_spec(
        {**base, "path": str(txt_path)},
        frame=FRAME,
        base_dir=NDBC_REAL,
        where=WHERE,
        time_window=window,
    )
    assert a.coverage.t0 == epoch("2018-07-20T03:00Z")  # after the gap 01:50..03:00Z that day
    t = np.linspace(*window, 10)
    np.testing.assert_allclose(a.sample(t, 0.0, 0.0), b.sample(t, 0.0, 0.0), atol=1e-12)
    assert "6432 rows read, 3 dropped for missing values" in wind_notes(b)[0]
    std = read_ndbc(NDBC_REAL / "ndbc-41002-stdmet" / "41002.txt", position=(31.76, -74.84))
    assert std.n_raw == 6560 and std.n_missing == 120
