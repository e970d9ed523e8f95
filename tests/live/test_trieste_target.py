"""A replay of the shipped Trieste coach-boat log with a sailor's boat in it as an AIS
target: the leg follows the target's roundings as ``analyze`` finds them on its track."""

from __future__ import annotations

import csv
import json
import math
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

from sailroute.commands.analyze import run_analyze_command
from sailroute.commands.live import run_live_command
from sailroute.course.load import build_specs
from sailroute.live.convert import Row, nmea_lines
from sailroute.live.engine import LiveSettings
from sailroute.timeutil import iso
from tests.conftest import ROOT
from tests.live.feed import TRIESTE, ais_sentence, sailed_track, trieste

COACH_LOG = ROOT / "data" / "trieste-coach-2018-02-15.csv"
MMSI = 247000123
EVERY_S = 3  # a tracker's report interval [s]


def coach_rows() -> list[Row]:
    """The coach boat's 1 Hz log as instrument rows: position and the true wind."""
    with open(COACH_LOG, newline="") as fh:
        return [
            Row(
                datetime.fromisoformat(r["time"]).timestamp(),
                float(r["lat"]),
                float(r["lon"]),
                tws_kn=float(r["speed"]),
                twd_deg=float(r["direction"]),
            )
            for r in csv.DictReader(fh)
        ]


def replay_with_target(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Write the coach log with the sailor's boat's AIS reports (class B, every
    :data:`EVERY_S` s, right after the coach's fix of that second); the target's track."""
    course = trieste()
    boat, winds = build_specs(course, ["measured"])
    polar = boat.routing_polar()
    assert polar is not None
    t, x, y = sailed_track(course, winds["measured"], polar, step_s=EVERY_S)
    lat, lon = course.frame.to_latlon(x, y)
    dx, dy = np.gradient(x, t), np.gradient(y, t)
    sog = np.hypot(dx, dy) / (1852 / 3600)
    cog = np.degrees(np.arctan2(dx, dy)) % 360.0
    rows = coach_rows()
    k = 0
    out = []
    for r in rows:
        out.extend(nmea_lines(r))
        while k < t.size and t[k] <= r.t:
            out.append(ais_sentence(MMSI, lat[k], lon[k], sog[k], cog[k], None, int(t[k]) % 60))
            k += 1
    assert k == t.size  # the whole race is inside the log
    path.write_text("\r\n".join(out) + "\r\n", encoding="ascii")
    return t, lat, lon


@pytest.mark.slow
def test_the_leg_follows_the_ais_targets_roundings(tmp_path: Path) -> None:
    """The coach boat never comes within 300 m of a mark; the sailor's boat, an AIS
    target, sails the course round it.  Routed from the target, the leg advances at each
    of its roundings within 5 s (in fact to the millisecond: the same geometry) of
    ``analyze`` on the track live received, and every re-plan starts at the target."""
    replay = tmp_path / "trieste-with-target.nmea"
    t, lat, lon = replay_with_target(replay)
    log = tmp_path / "live.jsonl"
    res = run_live_command(
        trieste(),
        source=str(replay),
        scenario="measured",
        boat=str(MMSI),
        speed=200,
        every_s=120,
        port=None,
        nmea_port=None,
        log=log,
        worker=False,
        settings=LiveSettings(side=False),
    )
    recs = [json.loads(line) for line in log.read_text().splitlines()]
    legs = [r for r in recs if r["kind"] == "leg"]
    assert [(r["how"], r["leg"]) for r in legs] == [
        ("start", 0),
        ("rounding", 1),
        ("rounding", 2),
        ("rounding", 3),
        ("rounding", 4),
    ]
    got = [r for r in recs if r["kind"] == "boat"]
    assert len(got) == t.size
    # analyze, on the track live received (AIS positions to 1/10 000 minute)
    track = tmp_path / "target.csv"
    track.write_text(
        "time,lat,lon\n" + "".join(f"{iso(r['t'])},{r['lat']:.7f},{r['lon']:.7f}\n" for r in got),
        encoding="utf-8",
    )
    ana = run_analyze_command(TRIESTE, [track], out_dir=tmp_path / "analysis", plots=False)
    (a,) = ana.data
    want = [a.segmentation.start.crossing.t, *(leg.t_end for leg in a.legs)]
    live = [r["t"] for r in legs]
    assert np.max(np.abs(np.subtract(live, want))) < 5.0
    assert np.max(np.abs(np.subtract(live, want))) < 0.01
    # the re-plans route the target: each starts within 15 m of it (dead-reckoned ahead
    # of its last report, at most 3 s old), never at the coach boat
    # (on the real wind about one shift a minute: urgent re-plans often stop the one before)
    plans = [r for r in recs if r["kind"] == "plan"]
    assert len(plans) >= 4 and len({p["leg"] for p in plans}) >= 2
    frame = trieste().frame
    x, y = frame.to_xy(lat, lon)
    for p in plans:
        px, py = frame.to_xy(*p["route"][0])
        # the target's last report at the plan's data time (a report stamped up to a second
        # ahead of the coach boat's clock counts: the first plan can come before t[0])
        near = max(int(np.searchsorted(t, p["t"], side="right")) - 1, 0)
        assert math.hypot(float(px - x[near]), float(py - y[near])) < 15.0
        assert p["leg"] == sum(1 for r in legs[1:] if r["t"] <= p["t"])
    assert "sailor's boat (urn:mrn:imo:mmsi:247000123) on leg 4 of 4 (finished)" in res.report
