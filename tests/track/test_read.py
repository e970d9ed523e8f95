"""The track reader: GPX 1.0/1.1, CSV logs, units, time zones, cleaning, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.track import Track, read_track, sog_cog
from sailroute.units import KNOT
from tests.conftest import SHARED_REAL, requires_shared

GPX11 = """<?xml version="1.0" encoding="UTF-8"?>
<gpx version="1.1" creator="test" xmlns="http://www.topografix.com/GPX/1/1"
  xmlns:ns3="http://www.garmin.com/xmlschemas/TrackPointExtension/v1">
  <trk><name>boat A</name>
    <trkseg>
      <trkpt lat="39.40" lon="-0.32"><ele>-500</ele><time>2025-06-21T11:00:00Z</time>
        <extensions><ns3:TrackPointExtension><ns3:hr>138</ns3:hr></ns3:TrackPointExtension>
        </extensions></trkpt>
      <trkpt lat="39.4001" lon="-0.32"><time>2025-06-21T11:00:02Z</time></trkpt>
    </trkseg>
    <trkseg>
      <trkpt lat="39.4002" lon="-0.32"><time>2025-06-21T11:00:01Z</time></trkpt>
      <trkpt lat="39.4002" lon="-0.32"><time>2025-06-21T11:00:02Z</time></trkpt>
      <trkpt lat="39.4010" lon="-0.32"><time>2025-06-21T13:00:03+02:00</time></trkpt>
    </trkseg>
  </trk>
  <trk><trkseg>
      <trkpt lat="39.4020" lon="359.68"><time>2025-06-21T11:02:00Z</time></trkpt>
  </trkseg></trk>
</gpx>
"""

GPX10 = """<?xml version="1.0"?>
<gpx version="1.0" xmlns="http://www.topografix.com/GPX/1/0">
<trk><trkseg>
<trkpt lat="45.0" lon="13.0"><time>2024-05-01T10:00:00Z</time></trkpt>
<trkpt lat="45.001" lon="13.0"><time>2024-05-01T10:00:10Z</time></trkpt>
</trkseg></trk></gpx>
"""


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def test_gpx11_segments_tracks_sorting_duplicates_gaps(tmp_path: Path) -> None:
    tr = read_track(_write(tmp_path, "a.gpx", GPX11))
    assert tr.name == "boat A"
    # 6 points: one repeated time dropped, out-of-order one sorted in
    assert np.all(np.diff(tr.t_s) > 0)
    assert len(tr) == 5
    assert tr.t_s[0] == pytest.approx(1750503600.0)
    assert tr.t_s[2] == tr.t_s[0] + 2  # the first 11:00:02 point is kept
    assert tr.lat_deg[2] == pytest.approx(39.4001)
    assert tr.lon_deg[-1] == pytest.approx(-0.32)  # 359.68 wrapped
    joined = " | ".join(tr.notes)
    assert "sorted 1 out-of-order" in joined
    assert "dropped 1 duplicate" in joined
    assert "gap of 117 s at 2025-06-21T11:00:03Z" in joined


def test_gpx10_and_name_override(tmp_path: Path) -> None:
    tr = read_track(_write(tmp_path, "b.gpx", GPX10), name="X")
    assert tr.name == "X" and len(tr) == 2 and tr.notes == ()


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("", "empty"),
        (
            '<?xml version="1.0"?><gpx version="1.1" xmlns="http://www.topografix.com/GPX/1/1">'
            "<metadata/></gpx>",
            "no track points",
        ),
        (
            '<gpx version="1.1">\n<trk><trkseg>\n<trkpt lat="1" lon="2"></trkpt>\n'
            "</trkseg></trk></gpx>",
            "line 3: <trkpt> has no <time>",
        ),
        (
            '<gpx version="1.1">\n<trk><trkseg>\n<trkpt lat="1" lon="2">\n</trk></gpx>',
            r"e\.gpx:4:\d+: not well-formed XML",
        ),
        # found by the fuzz test: two times in one point gave one time more than points
        (
            '<gpx version="1.1">\n<trk><trkseg>\n<trkpt lat="1" lon="2"><time>2025-06-21T11:18:31Z'
            "</time>\n<time>2025-06-21T11:18:30Z</time></trkpt>\n</trkseg></trk></gpx>",
            "line 4: a <trkpt> with a second <time>",
        ),
    ],
)
def test_bad_gpx(tmp_path: Path, text: str, match: str) -> None:
    with pytest.raises(InputError, match=match):
        read_track(_write(tmp_path, "e.gpx", text))


def test_csv_units_time_zones_and_channels(tmp_path: Path) -> None:
    csv_text = (
        "time;lat;lon;sog_kn;cog;TWA_SGP_deg;BOAT_SPEED_km_h_1\n"
        "2025-01-19 10:00:00;45.0;13.0;10;90;-40;36\n"
        "2025-01-19 10:00:01;45.0;13.0001;;90;-40;36\n"
    )
    p = _write(tmp_path, "c.csv", csv_text)
    with pytest.raises(InputError, match=r"c\.csv, line 2, column 'time'.*no UTC offset"):
        read_track(p)
    tr = read_track(p, time_zone="+01:00")
    assert tr.t_s[0] == pytest.approx(1737280800.0 - 3600.0)  # 10:00+01:00 = 09:00Z
    assert tr.channels["sog_ms"][0] == pytest.approx(10 * KNOT)
    assert np.isnan(tr.channels["sog_ms"][1])
    assert tr.channels["bsp_ms"][0] == pytest.approx(10.0)
    assert tr.channels["twa_deg"][0] == pytest.approx(-40.0)
    assert read_track(p, time_zone="Europe/Rome").t_s[0] == pytest.approx(tr.t_s[0])


def test_csv_unsuffixed_speed_needs_a_unit(tmp_path: Path) -> None:
    p = _write(
        tmp_path,
        "d.csv",
        "time,lat,lng,sog\n2023-09-27 14:31:56+00:00,59.4,24.8,5\n"
        "2023-09-27 14:31:57+00:00,59.4,24.8001,6\n",
    )
    with pytest.raises(InputError, match=r"unit of column 'sog' is not known.*speed_unit"):
        read_track(p)
    assert read_track(p, speed_unit="kn").channels["sog_ms"][1] == pytest.approx(6 * KNOT)
    with pytest.raises(InputError, match="unknown speed unit"):
        read_track(p, speed_unit="furlong")


def test_csv_phone_time_format_epoch_and_column_mapping(tmp_path: Path) -> None:
    p = _write(
        tmp_path,
        "e.csv",
        "when,y,x\n2015-07-28 17:29:21:798,47.6,-122.28\n2015-07-28 17:29:22:799,47.6001,-122.28\n",
    )
    with pytest.raises(InputError, match="no column for time, lat, lon"):
        read_track(p)
    tr = read_track(p, columns={"time": "when", "lat": "y", "lon": "x"}, time_zone="-07:00")
    assert tr.t_s[0] == pytest.approx(1438129761.798)
    q = _write(
        tmp_path,
        "f.csv",
        "timestamp,lat,lon\n1438129761798,47.6,-122.28\n1438129762.5,47.6001,-122.28\n",
    )
    assert read_track(q).t_s.tolist() == pytest.approx([1438129761.798, 1438129762.5])


def test_csv_errors_name_line_and_column(tmp_path: Path) -> None:
    p = _write(
        tmp_path, "g.csv", "time,lat,lon\n2024-01-01T00:00:00Z,45,13\n2024-01-01T00:00:01Z,abc,13\n"
    )
    with pytest.raises(InputError, match=r"g\.csv, line 3, column 'lat': cannot read 'abc'"):
        read_track(p)
    q = _write(
        tmp_path, "h.csv", "time,lat,lon\n2024-01-01T00:00:00Z,95,13\n2024-01-01T00:00:01Z,45,13\n"
    )
    with pytest.raises(InputError, match=r"line 2: latitude 95 is out of range"):
        read_track(q)
    r = _write(tmp_path, "i.csv", "time,lat,lon\n2024-01-01T00:00:00Z,45,13\n")
    with pytest.raises(InputError, match="only 1 usable point"):
        read_track(r)
    with pytest.raises(InputError, match="not found"):
        read_track(tmp_path / "nope.gpx")


def test_sog_cog_from_positions() -> None:
    frame = LocalFrame(45.0, 13.0)
    t = np.arange(0.0, 60.0, 1.0)
    t[10:] += 0.4  # uneven sampling
    x, y = 3.0 * t, -4.0 * t  # 5 m/s towards 143.13°
    la, lo = frame.to_latlon(x, y)
    sog, cog = sog_cog(Track(t, la, lo), frame)
    assert sog == pytest.approx(np.full(t.size, 5.0), abs=1e-4)
    assert cog == pytest.approx(np.full(t.size, np.degrees(np.arctan2(3, -4))), abs=1e-3)


@requires_shared
def test_real_tracks_read() -> None:
    races = SHARED_REAL / "races"
    snipe = read_track(races / "snipe-valencia-2025" / "2025-06-21-ESP30782-P01.gpx")
    assert len(snipe) == 1981 and snipe.notes == ()
    assert snipe.t_s[0] == pytest.approx(1750504709.0)  # 11:18:29Z
    tallinn = races / "tallinn-wednesday-races-2023" / "kolmak_2023_09_27.csv"
    with pytest.raises(InputError, match="speed_unit"):
        read_track(tallinn)
    tl = read_track(tallinn, speed_unit="kn")
    assert len(tl) == 942 and {"sog_ms", "tws_ms", "twd_deg", "hdg_deg"} <= set(tl.channels)
    j24 = read_track(
        races / "j24-lake-washington-2015" / "Sensor_record_20150728_211517_AndroSensor.csv",
        time_zone="-07:00",
    )
    assert j24.t_s[0] == pytest.approx(1438129763.799)  # 17:29:23.799 PDT, 3rd row
    assert "dropped 2 row(s)" in j24.notes[0]
    gp = read_track(races / "sailgp-auckland-2025" / "Boat_logs" / "data_AUS.csv", time_zone="UTC")
    assert np.nanmedian(gp.channels["tws_ms"]) == pytest.approx(36.0 / 3.6, rel=0.2)
