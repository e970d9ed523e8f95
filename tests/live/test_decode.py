"""NMEA 0183 and Signal K decoding, the converters, and the apparent-to-true wind, on the
real Trieste and Tallinn logs."""

from __future__ import annotations

import csv
import json
import math
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

from sailroute.live.ais import report_time
from sailroute.live.convert import convert_log, read_tallinn
from sailroute.live.decode import KN, NmeaDecoder, SignalKDecoder
from sailroute.live.livewind import apparent_to_true
from sailroute.live.nmeaout import sentence
from tests.conftest import SHARED_REAL, TESTS_DATA, requires_shared
from tests.live.feed import ais_sentence

LIVE = TESTS_DATA / "live"
TRIESTE_CSV = SHARED_REAL / "wind" / "anemomind-coach-trieste" / "coach_wind_1hz.csv"
TALLINN_CSV = SHARED_REAL / "races" / "tallinn-wednesday-races-2023" / "kolmak_2023_09_27.csv"


def test_rmc_and_wind_sentences() -> None:
    d = NmeaDecoder()
    r = d.feed("$GPRMC,094430.00,A,4533.1074,N,01338.5333,E,4.20,37.0,150218,,,A*55")
    assert r is not None and r.timed
    assert r.t == datetime.fromisoformat("2018-02-15T09:44:30+00:00").timestamp()
    assert r.lat == pytest.approx(45 + 33.1074 / 60) and r.lon == pytest.approx(13 + 38.5333 / 60)
    assert r.sog_ms == pytest.approx(4.2 * KN) and r.cog_deg == 37.0
    a = d.feed(sentence("IIMWV,300.0,R,7.24,N,A").strip())
    assert a is not None and a.awa_deg == -60.0 and a.aws_ms == pytest.approx(7.24 * KN)
    assert a.t == r.t  # the clock of the last RMC
    w = d.feed(sentence("IIMWD,76.0,T,,M,3.63,N,1.87,M").strip())
    assert w is not None and (w.twd_deg, w.tws_ms) == (76.0, 1.87)
    h = d.feed(sentence("HCHDG,100.0,,,3.0,W").strip())
    assert h is not None and h.hdg_deg == 97.0  # magnetic + variation (west is minus)


def test_bad_input_is_counted_not_raised() -> None:
    d = NmeaDecoder()
    assert d.feed(sentence("IIMWV,30.0,R,7.0,N,A").strip()) is None  # before any clock
    assert d.feed("$GPRMC,094430.00,A,4533.1074,N,01338.5333,E,4.20,37.0,150218,,,A*56") is None
    assert d.feed("$GPRMC,094430.00,A,4533.1074,N,01338.5333,E,4.20,37.0,150218,,,A*55")
    assert d.feed("$IIMWV,abc,R") is None  # no checksum
    assert d.feed("not nmea at all") is None
    assert d.feed(sentence("GPRMC,094430.00,V,,,,,,,150218,,,N").strip()) is None  # void fix
    assert d.counts.by_kind == {
        "untimed": 1,
        "bad_checksum": 1,
        "RMC": 1,
        "no_checksum": 1,
        "malformed": 1,
        "ignored": 1,
    }
    assert d.counts.bad == 3


def test_signalk_delta() -> None:
    d = SignalKDecoder()
    assert d.feed(json.dumps({"name": "signalk-server", "self": "vessels.urn:x"})) == []
    delta = {
        "context": "vessels.urn:x",
        "updates": [
            {
                "timestamp": "2018-02-15T09:44:30.000Z",
                "values": [
                    {"path": "navigation.position", "value": {"latitude": 45.5, "longitude": 13.6}},
                    {"path": "navigation.courseOverGroundTrue", "value": math.radians(370.0)},
                    {"path": "environment.wind.angleApparent", "value": -math.pi / 3},
                    {"path": "environment.wind.speedApparent", "value": 3.5},
                ],
            }
        ],
    }
    (r,) = d.feed(json.dumps(delta))
    assert r.t == datetime.fromisoformat("2018-02-15T09:44:30+00:00").timestamp()
    assert (r.lat, r.lon, r.aws_ms) == (45.5, 13.6, 3.5)
    assert r.cog_deg == pytest.approx(10.0) and r.awa_deg == pytest.approx(-60.0)
    # another vessel's delta (an AIS target the server heard) is that vessel's reading
    other = {**delta, "context": "vessels.urn:mrn:imo:mmsi:211000001"}
    (o,) = d.feed(json.dumps(other))
    assert o.vessel == "urn:mrn:imo:mmsi:211000001" and (o.lat, o.lon) == (45.5, 13.6)
    assert r.vessel == ""  # the own vessel's (the hello named it)
    aton = {**delta, "context": "atons.urn:mrn:imo:mmsi:992000001"}
    assert d.feed(json.dumps(aton)) == [] and d.feed("{not json") == []
    assert d.counts.by_kind == {"delta": 2, "ignored": 1, "malformed": 1}


def test_checksums_are_required_unless_told() -> None:
    """An MWD without a checksum is refused and counted (a flipped bit in it would go
    unseen); a decoder told to accept such a talker reads it."""
    d = NmeaDecoder()
    assert d.feed("$GPRMC,094430.00,A,4533.1074,N,01338.5333,E,4.20,37.0,150218,,,A*55")
    assert d.feed("$IIMWD,76.0,T,,M,3.63,N,1.87,M") is None
    assert d.counts.by_kind["no_checksum"] == 1 and d.counts.bad == 1
    lax = NmeaDecoder(require_checksum=False)
    lax.feed("$GPRMC,094430.00,A,4533.1074,N,01338.5333,E,4.20,37.0,150218,,,A*55")
    w = lax.feed("$IIMWD,76.0,T,,M,3.63,N,1.87,M")
    assert w is not None and w.tws_ms == 1.87


def test_a_date_past_the_calendar_is_malformed() -> None:
    """A ZDA of the year 9999999999 (it raised OverflowError out of the decoder, which
    ended the source thread) and a 401-digit field are counted as malformed."""
    d = NmeaDecoder()
    assert d.feed(sentence("GPZDA,094430.00,15,02,9999999999,,").strip()) is None
    assert d.feed(sentence("GPZDA," + "9" * 401 + ",15,02,2018,,").strip()) is None
    assert d.counts.by_kind["malformed"] == 2
    z = d.feed(sentence("GPZDA,094430.00,15,02,2018,,").strip())
    assert z is not None and z.timed and z.t == d.clock == 1518687870.0


def test_ais_position_reports() -> None:
    """The class A report of gpsd's AIVDM documentation decodes to its published fields;
    a class B report encoded here round-trips to 1/10 000 minute; the report's time is
    the second it gives, in the minute before the receiver's clock."""
    d = NmeaDecoder()
    assert d.feed(ais_sentence(211000001, 45.5, 13.6, 4.0, 90.0, 88, 10)) is None  # no clock
    d.feed("$GPRMC,094430.00,A,4533.1074,N,01338.5333,E,4.20,37.0,150218,,,A*55")
    a = d.feed("!AIVDM,1,1,,A,13u?etPv2;0n:dDPwUM1U1Cb069D,0*24")
    assert a is not None and a.vessel == "urn:mrn:imo:mmsi:265547250"
    assert (a.lat, a.lon) == pytest.approx((57.6603533, 11.8329767), abs=1e-7)
    assert a.sog_ms == pytest.approx(13.9 * KN) and (a.cog_deg, a.hdg_deg) == (40.4, 41.0)
    assert a.t == d.clock - 30 + 53 - 60  # clock 09:44:30, reported at second 53: 09:43:53
    b = d.feed(ais_sentence(211000001, 45.5661234, 13.6712345, 4.3, 123.4, 120, 28))
    assert b is not None and b.t == d.clock - 2 and b.vessel == "urn:mrn:imo:mmsi:211000001"
    assert b.lat == pytest.approx(45.5661234, abs=1 / 600_000) and b.cog_deg == 123.4
    assert b.lon == pytest.approx(13.6712345, abs=1 / 600_000) and b.hdg_deg == 120.0
    assert report_time(1000.0, None) == 1000.0 and report_time(1019.0, 21) == 981.0
    assert report_time(965.0, 30) == 930.0 and report_time(965.0, 6) == 966.0  # 1 s early
    bad = ais_sentence(211000001, 45.5, 13.6)
    assert d.feed(bad[:-2] + ("00" if bad[-2:] != "00" else "01")) is None
    assert d.feed(bad.split("*")[0]) is None  # no checksum
    assert (
        d.feed(sentence("AIVDM,2,1,3,B,55P5TL01VIaAL@7WKO@mBplU@<PDhh,0").replace("$", "!")) is None
    )
    assert d.counts.by_kind["bad_checksum"] == 1 and d.counts.by_kind["no_checksum"] == 1
    assert d.counts.by_kind["AIS"] == 2 and d.counts.by_kind["ignored"] == 1


def test_apparent_to_true_analytic() -> None:
    """Close-hauled at 4 m/s with 6 m/s of apparent wind 30° on starboard: the true wind
    follows from the triangle (law of cosines) and comes from the starboard side."""
    tws, twd = apparent_to_true(6.0, 30.0, 4.0, 0.0, 0.0)
    assert tws == pytest.approx(math.sqrt(36 + 16 - 48 * math.cos(math.radians(30))))
    # components: the true wind's angle from the bow is atan2(aws sin awa, aws cos awa - sog)
    assert twd == pytest.approx(math.degrees(math.atan2(3.0, 6 * math.cos(math.radians(30)) - 4)))
    # with a heading 10° off the COG (leeway, current) the angle turns with the bow
    tws2, twd2 = apparent_to_true(6.0, 30.0, 4.0, 0.0, 10.0)
    assert twd2 > twd and tws2 != tws


@requires_shared
def test_tallinn_replay_true_wind_matches_the_source(tmp_path: Path) -> None:
    """The Tallinn replay carries apparent wind only; converted with SOG/COG it gives the
    TWS the log's author computed (which uses SOG: shared README) to 0.01 kn."""
    out = tmp_path / "t.nmea"
    n = convert_log(TALLINN_CSV, "tallinn", out)
    assert n == len(read_tallinn(TALLINN_CSV))
    author = {}
    with open(TALLINN_CSV, newline="") as fh:
        for row in csv.DictReader(fh):
            if row["tws"]:
                author[round(datetime.fromisoformat(row["time"]).timestamp())] = float(row["tws"])
    d = NmeaDecoder()
    sog = cog = None
    diffs = []
    for line in out.read_text().splitlines():
        r = d.feed(line)
        if r is None:
            continue
        sog, cog = (r.sog_ms, r.cog_deg) if r.sog_ms is not None else (sog, cog)
        if r.aws_ms is not None and r.awa_deg is not None and round(r.t) in author:
            tws, _ = apparent_to_true(r.aws_ms, r.awa_deg, sog, cog, None)
            diffs.append(tws / KN - author[round(r.t)])
    assert len(diffs) > 700
    assert np.median(np.abs(diffs)) < 0.01 and np.max(np.abs(diffs)) < 0.05


@requires_shared
def test_trieste_replay_round_trip() -> None:
    """The committed Trieste replay decodes, row by row, to the source CSV's position, TWS
    and TWD (the CSV's local clock is CET, UTC+01:00)."""
    with open(TRIESTE_CSV, newline="") as fh:
        src = [
            (datetime.fromisoformat(row["datetime_local"] + "+01:00").timestamp(), row)
            for row in csv.DictReader(fh)
        ]
    d = NmeaDecoder()
    fixes, winds = [], []
    for line in (LIVE / "trieste-coach-2018-02-15.nmea").read_text().splitlines():
        r = d.feed(line)
        assert r is not None
        if r.lat is not None:
            fixes.append(r)
        if r.twd_deg is not None:
            winds.append(r)
    rows = [row for t, row in src if fixes[0].t <= t <= fixes[-1].t]
    assert len(fixes) == len(winds) == len(rows) == 824 and d.counts.bad == 0
    for f, w, row in zip(fixes, winds, rows, strict=True):
        assert f.lat == pytest.approx(float(row["lat"]), abs=1e-6)
        assert f.lon == pytest.approx(float(row["lon"]), abs=1e-6)
        assert w.twd_deg == float(row["twd_deg"]) % 360
        assert w.tws_ms == pytest.approx(float(row["tws_kn"]) * KN, abs=0.006)
