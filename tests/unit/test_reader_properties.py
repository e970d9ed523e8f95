"""Property tests of the file readers (hypothesis, derandomized: the same examples every run).

* polar files: any valid polar written by our writers (``.pol``, long CSV, JSON; m/s or
  knots) reads back to exactly the floats that were written, times the unit factor;
* station CSV: random valid rows (any UTC offset, rows with a missing speed) read back
  grouped by station with the same instants and values; the missing rows are counted;
* course YAML: marks anywhere in the accepted range (longitudes in [-180, 360]) load with
  their latitude, their longitude wrapped into [-180, 180), and local coordinates that
  keep the distances between marks (also across the antimeridian).
"""

from __future__ import annotations

import tempfile
from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from pyproj import Geod

from sailroute.boat.io import read_polar, write_pol, write_polar_csv, write_polar_json
from sailroute.boat.polar import Polar
from sailroute.course.load import load_course
from sailroute.geo import wrap_lon
from sailroute.units import speed_factor
from sailroute.wind.stations import read_stations

# few examples, the same ones every run: together these tests take about a second
FAST = settings(
    max_examples=50,
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)

WRITERS = {
    "pol": (write_pol, ".pol"),
    "csv": (write_polar_csv, ".csv"),
    "json": (write_polar_json, ".json"),
}


def _increasing(
    draw: st.DrawFn, n: int, first: st.SearchStrategy[float], gap: st.SearchStrategy[float]
) -> np.ndarray:
    steps = draw(st.lists(gap, min_size=n - 1, max_size=n - 1))
    return draw(first) + np.concatenate([[0.0], np.cumsum(steps)])


@st.composite
def polars(draw: st.DrawFn) -> Polar:
    """Polars the readers accept: TWA in [0, 170], TWS up to 25 m/s, speeds up to 30 m/s."""
    n_twa, n_tws = draw(st.integers(2, 7)), draw(st.integers(1, 5))
    twa = _increasing(
        draw, n_twa, st.one_of(st.just(0.0), st.floats(0.01, 15.0)), st.floats(0.01, 25.0)
    )
    tws = _increasing(draw, n_tws, st.floats(0.1, 5.0), st.floats(0.05, 5.0))
    cells = draw(
        st.lists(
            st.floats(0.0, 30.0, allow_subnormal=False),
            min_size=n_twa * n_tws,
            max_size=n_twa * n_tws,
        )
    )
    # the readers refuse a polar without speed: one cell (any) is positive
    cells[draw(st.integers(0, len(cells) - 1))] = draw(st.floats(0.1, 30.0))
    return Polar.from_arrays(twa, tws, np.reshape(cells, (n_twa, n_tws)), name="p")


@FAST
@given(polar=polars(), fmt=st.sampled_from(sorted(WRITERS)), unit=st.sampled_from(["m/s", "kn"]))
def test_written_polar_reads_back_exactly(polar: Polar, fmt: str, unit: str) -> None:
    write, suffix = WRITERS[fmt]
    f = speed_factor(unit)
    with tempfile.TemporaryDirectory() as d:
        path = write(polar, Path(d) / f"boat{suffix}", unit, decimals=None)
        back = read_polar(path, speed_unit=unit if fmt == "pol" else None)
    # the file holds v / f written as the shortest exact text; the reader multiplies by f
    np.testing.assert_array_equal(back.twa_deg, polar.twa_deg)
    np.testing.assert_array_equal(back.tws_ms, polar.tws_ms / f * f)
    np.testing.assert_array_equal(back.speed_ms, polar.speed_ms / f * f)
    if unit == "m/s":
        np.testing.assert_array_equal(back.speed_ms, polar.speed_ms)
    assert back.name == ("p" if fmt == "json" else "boat")  # JSON keeps its name field


UTC_OFFSETS_MIN = st.integers(-14 * 4, 14 * 4).map(lambda q: 15 * q)


@st.composite
def station_rows(draw: st.DrawFn) -> list[dict]:
    """Rows of up to 3 stations at distinct whole-second times, some with a missing speed."""
    times = draw(
        st.lists(st.integers(1_500_000_000, 1_900_000_000), min_size=1, max_size=12, unique=True)
    )
    rows = [
        {
            "t": t,
            "offset_min": draw(UTC_OFFSETS_MIN),
            "station": draw(st.sampled_from(["A", "B", "S-3"])),
            "lat": draw(st.floats(-90.0, 90.0)),
            "lon": draw(st.floats(-180.0, 360.0)),
            "speed": draw(st.floats(0.0, 60.0)),
            "direction": draw(st.floats(0.0, 360.0)),
            "missing": draw(st.booleans()),
        }
        for t in sorted(times)
    ]
    assume(not all(r["missing"] for r in rows))
    return rows


@FAST
@given(rows=station_rows(), unit=st.sampled_from(["ms", "kn"]))
def test_station_csv_rows_read_back(rows: list[dict], unit: str) -> None:
    lines = [f"time,station,lat,lon,speed_{unit},direction"]
    for r in rows:
        tz = timezone(timedelta(minutes=r["offset_min"]))
        stamp = datetime.fromtimestamp(r["t"], tz).isoformat()
        speed = "NA" if r["missing"] else repr(r["speed"])
        lines.append(f"{stamp},{r['station']},{r['lat']!r},{r['lon']!r},{speed},{r['direction']!r}")
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "stations.csv"
        path.write_text("\n".join(lines) + "\n")
        data = read_stations(path)
    kept = [r for r in rows if not r["missing"]]
    first = list(dict.fromkeys(r["station"] for r in kept))
    kept.sort(key=lambda r: first.index(r["station"]))  # stable: times stay increasing
    assert data.n_raw == len(rows)
    assert data.n_missing == len(rows) - len(kept)
    assert data.stations == tuple(first)
    assert list(data.station) == [r["station"] for r in kept]
    np.testing.assert_array_equal(data.t, [float(r["t"]) for r in kept])
    np.testing.assert_array_equal(data.lat, [r["lat"] for r in kept])
    np.testing.assert_array_equal(data.lon, [r["lon"] for r in kept])
    np.testing.assert_array_equal(
        data.speed_ms, np.array([r["speed"] for r in kept]) * speed_factor(unit)
    )
    np.testing.assert_array_equal(data.direction_deg, np.mod([r["direction"] for r in kept], 360.0))


COURSE = """\
name: property
start_time: 2024-05-01T10:00:00Z
marks:
  pin: {{lat: {lat0!r}, lon: {lon0!r}}}
  boat: {{lat: {lat0!r}, lon: {lon1!r}}}
  top: {{lat: {lat2!r}, lon: {lon2!r}}}
lines:
  start: [pin, boat]
legs:
  - {{to: top}}
  - {{to: start}}
scenarios:
  north: {{type: uniform, tws_kn: 10, twd_deg: 0}}
"""

WGS84 = Geod(ellps="WGS84")


@FAST
@given(
    lat0=st.floats(-80.0, 80.0),
    lon0=st.floats(-180.0, 359.98),
    d_boat=st.floats(0.001, 0.01),
    d_top=st.tuples(st.floats(0.001, 0.01), st.floats(-0.01, 0.01)),
)
@example(lat0=45.0, lon0=179.9995, d_boat=0.002, d_top=(0.009, 0.001))  # across 180
@example(lat0=-17.8, lon0=-180.0, d_boat=0.003, d_top=(0.01, -0.002))  # -180 itself
def test_course_marks_wrap_and_keep_distances(
    lat0: float, lon0: float, d_boat: float, d_top: tuple[float, float]
) -> None:
    given_ll = {
        "pin": (lat0, lon0),
        "boat": (lat0, lon0 + d_boat),
        "top": (lat0 + d_top[0], lon0 + d_top[1]),
    }
    assume(given_ll["top"][1] >= -180.0)
    text = COURSE.format(
        lat0=lat0,
        lon0=lon0,
        lon1=given_ll["boat"][1],
        lat2=given_ll["top"][0],
        lon2=given_ll["top"][1],
    )
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "course.yaml"
        path.write_text(text)
        course = load_course(path)
    for name, (lat, lon) in given_ll.items():
        m = course.marks[name]
        assert m.lat == lat
        assert -180.0 <= m.lon < 180.0
        assert m.lon == wrap_lon(lon)
        # the same meridian: a multiple of 360 apart (to rounding)
        assert abs((m.lon - lon) / 360.0 - round((m.lon - lon) / 360.0)) < 1e-12
        # the local frame is centred on the course, and maps back to the mark
        assert np.hypot(m.x, m.y) < 2000.0
        back_lat, back_lon = course.frame.to_latlon(m.x, m.y)
        assert abs(float(back_lat) - m.lat) < 1e-9
        assert abs(float(wrap_lon(float(back_lon) - m.lon))) < 1e-9
    # distances in the local frame are the geodesic ones (to 1 mm)
    names = list(given_ll)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            ma, mb = course.marks[a], course.marks[b]
            _, _, dist = WGS84.inv(ma.lon, ma.lat, mb.lon, mb.lat)
            assert abs(np.hypot(mb.x - ma.x, mb.y - ma.y) - dist) < 1e-3
