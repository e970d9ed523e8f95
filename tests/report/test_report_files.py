"""plan.json, track.csv, route.gpx and comparison files: schema keys, values, round trips."""

from __future__ import annotations

import csv
import json
from datetime import datetime
from xml.etree import ElementTree as ET

import numpy as np
import pytest

from sailroute.planning.result import compare
from sailroute.report.files import (
    GPX_NS,
    SCHEMA_VERSION,
    SR_NS,
    TRACK_COLUMNS,
    write_comparison,
    write_gpx,
    write_plan_json,
    write_plan_outputs,
    write_track_csv,
)
from sailroute.timeutil import iso, parse_time, to_epoch

NS = {"g": GPX_NS, "sr": SR_NS}


def test_plan_json(tmp_path, plan):
    doc = json.loads(write_plan_json(tmp_path / "plan.json", plan).read_text())
    assert doc["schema_version"] == SCHEMA_VERSION
    for key in (
        "course",
        "scenario",
        "router",
        "start_time",
        "end_time",
        "total_time_s",
        "total_distance_m",
        "total_tacks",
        "total_gybes",
        "origin",
        "legs",
        "references",
    ):
        assert key in doc, key
    assert (doc["course"], doc["scenario"], doc["router"]) == ("report test", "north", "test")
    assert doc["start_time"] == "2024-05-01T10:00:00.000Z"
    assert doc["total_time_s"] == pytest.approx(plan.total_time_s, abs=1e-3)
    assert (doc["total_tacks"], doc["total_gybes"]) == (1, 1)
    assert len(doc["legs"]) == 3
    for k, (leg, pl) in enumerate(zip(doc["legs"], plan.legs, strict=True)):
        r = pl.result
        assert leg["index"] == k + 1
        assert (leg["from"], leg["to"]) == (pl.spec.from_name, pl.spec.to_name)
        assert leg["time_s"] == pytest.approx(r.time_s, abs=1e-3)
        assert (leg["tacks"], leg["gybes"]) == (r.n_tacks, r.n_gybes)
        assert leg["distance_m"] == pytest.approx(r.distance_m, abs=0.01)
        # times: ISO UTC with Z, and end - start = time_s
        t0, t1 = to_epoch(parse_time(leg["start_time"])), to_epoch(parse_time(leg["end_time"]))
        assert leg["start_time"].endswith("Z")
        assert t1 - t0 == pytest.approx(r.time_s, abs=2e-3)  # ms precision on each end
        lat, lon = plan.course.frame.to_latlon(*r.start_xy)
        assert leg["start_point"]["lat"] == pytest.approx(float(lat), abs=1e-7)
        assert leg["start_point"]["lon"] == pytest.approx(float(lon), abs=1e-7)
        assert leg["end_point"]["x"] == pytest.approx(r.end_xy[0], abs=1e-3)
        assert leg["reference"]["winner"] == [700.0, 300.0, 100.0][k]
        assert leg["reference_error_pct"]["winner"] == pytest.approx(
            100 * (r.time_s - [700.0, 300.0, 100.0][k]) / [700.0, 300.0, 100.0][k], abs=1e-3
        )
        assert len(leg["manoeuvres"]) == r.n_tacks + r.n_gybes
    assert [leg["mode"] for leg in doc["legs"]] == ["upwind", "downwind", "reach"]
    assert doc["legs"][0]["start_line_fraction"] == pytest.approx(0.25)
    assert doc["references"]["winner"]["total_time_s"] == 1100.0
    assert doc["references"]["model"]["legs_s"] == [650.0, 320.0, 110.0]


def test_track_csv(tmp_path, plan):
    path = write_track_csv(tmp_path / "track.csv", plan)
    with path.open() as fh:
        rows = list(csv.DictReader(fh))
    with path.open() as fh:
        assert tuple(next(csv.reader(fh))) == TRACK_COLUMNS
    assert len(rows) == sum(len(leg.result.track) for leg in plan.legs)
    assert [r["leg"] for r in rows] == [
        str(k + 1) for k, leg in enumerate(plan.legs) for _ in range(len(leg.result.track))
    ]
    t_race = np.array([float(r["t_race_s"]) for r in rows])
    assert t_race[0] == 0.0 and np.all(np.diff(t_race) >= 0)
    assert t_race[-1] == pytest.approx(plan.total_time_s, abs=1e-3)
    ev = [r["event"] for r in rows]
    assert ev.count("tack") == 1 and ev.count("gybe") == 1
    # lat/lon and x/y of each row agree through the frame (to 1e-8 deg written)
    x = np.array([float(r["x_m"]) for r in rows])
    y = np.array([float(r["y_m"]) for r in rows])
    lat, lon = plan.course.frame.to_latlon(x, y)
    np.testing.assert_allclose([float(r["lat"]) for r in rows], lat, atol=1e-7)
    np.testing.assert_allclose([float(r["lon"]) for r in rows], lon, atol=1e-7)
    assert float(rows[0]["bsp_kn"]) == pytest.approx(float(rows[0]["bsp_ms"]) / 0.514444, 1e-3)
    assert {r["tack"] for r in rows} == {"port", "starboard"}


def test_gpx(tmp_path, plan):
    root = ET.parse(write_gpx(tmp_path / "route.gpx", plan)).getroot()
    assert root.tag == f"{{{GPX_NS}}}gpx" and root.get("version") == "1.1"
    wpts = root.findall("g:wpt", NS)
    assert sorted(w.find("g:name", NS).text for w in wpts) == sorted(plan.course.marks)
    rtepts = root.findall("g:rte/g:rtept", NS)
    # the start, each leg's end and, between, the plan's one tack (leg 1) and one gybe (leg 2)
    assert [p.find("g:name", NS).text for p in rtepts] == [
        "start",
        "T1",
        "top",
        "G1",
        "gate",
        "finish",
    ]
    assert [p.find("g:type", NS).text for p in rtepts] == [
        "start",
        "tack",
        "mark",
        "gybe",
        "gate",
        "line",
    ]
    # GPX 1.1 rteptType order: time before name before type
    assert [c.tag.split("}")[1] for c in rtepts[0]] == ["time", "name", "type"]
    segs = root.findall("g:trk/g:trkseg", NS)
    assert len(segs) == len(plan.legs)
    frame = plan.course.frame
    for seg, pl in zip(segs, plan.legs, strict=True):
        tr = pl.result.track
        pts = seg.findall("g:trkpt", NS)
        assert len(pts) == len(tr)
        lat = np.array([float(p.get("lat")) for p in pts])
        lon = np.array([float(p.get("lon")) for p in pts])
        # lat/lon round trip to the local frame within 1e-6 deg (written with 8 decimals)
        elat, elon = frame.to_latlon(tr.x, tr.y)
        np.testing.assert_allclose(lat, elat, atol=1e-6)
        np.testing.assert_allclose(lon, elon, atol=1e-6)
        x, y = frame.to_xy(lat, lon)
        np.testing.assert_allclose(x, tr.x, atol=0.01)
        np.testing.assert_allclose(y, tr.y, atol=0.01)
        times = [p.find("g:time", NS).text for p in pts]
        assert times == [iso(t) for t in tr.t]
        assert datetime.fromisoformat(times[0].replace("Z", "+00:00")).tzinfo is not None
        bsp = [float(p.find("g:extensions/sr:bsp_ms", NS).text) for p in pts]
        np.testing.assert_allclose(bsp, tr.bsp_ms, atol=1e-3)


def test_comparison_files(tmp_path, plan):
    other = plan.__class__(
        plan.course, "copy", plan.legs, {"winner": (700.0, 300.0, 100.0)}, plan.router
    )
    cmp = compare([plan, other])
    jp, cp = write_comparison(tmp_path / "out", cmp)
    doc = json.loads(jp.read_text())
    assert doc["error_convention"] == "(model - reference) / reference * 100"
    assert doc["scenarios"] == ["north", "copy"]
    assert len(doc["legs"]) == 3
    leg1 = doc["legs"][0]
    t1 = plan.legs[0].time_s
    assert leg1["time_s"]["north"] == pytest.approx(t1, abs=1e-3)
    assert leg1["error_pct"]["winner"]["copy"] == pytest.approx(100 * (t1 - 700) / 700, abs=1e-3)
    assert doc["totals"]["reference_s"]["winner"] == 1100.0
    assert set(doc["scenario_references"]) == {"north"}  # "model" belongs to north only
    with cp.open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 3 * 2 + 2  # legs x scenarios + one total per scenario
    assert list(rows[0]) == ["leg", "label", "scenario", "time_s", "winner_s", "winner_error_pct"]
    assert rows[-1]["leg"] == "total"
    assert float(rows[-1]["time_s"]) == pytest.approx(plan.total_time_s, abs=1e-3)


def test_write_plan_outputs(tmp_path, plan, wind):
    out = write_plan_outputs(tmp_path / "new" / "dir", plan, wind=wind, dpi=40)
    assert set(out) == {"plan", "track", "gpx", "kml", "nmea", "png"}
    assert out["png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    out = write_plan_outputs(tmp_path / "np", plan, plot=False)
    assert "png" not in out and not (tmp_path / "np" / "route.png").exists()
