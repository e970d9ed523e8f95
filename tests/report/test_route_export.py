"""route.gpx's route, route.kml and route.nmea, read back by gpxpy, ElementTree and pynmea2."""

from __future__ import annotations

from xml.etree import ElementTree as ET

import gpxpy
import numpy as np
import pynmea2
import pytest

from sailroute.nmea import NMEA_MAX_LEN, checksum
from sailroute.report.files import write_gpx, write_plan_outputs
from sailroute.report.route_export import (
    KML_NS,
    RoutePoint,
    nmea_ids,
    nmea_sentences,
    route_points,
    write_kml,
    write_nmea,
)
from sailroute.timeutil import iso

K = {"k": KML_NS}
MINUTE_M = 1852.0  # one minute of latitude [m]


def _degrees(value: str, hemisphere: str) -> float:
    """NMEA ``(d)ddmm.mmmm`` and N/S/E/W to signed degrees."""
    v = float(value)
    deg = int(v // 100) + (v % 100) / 60.0
    return -deg if hemisphere in "SW" else deg


def test_route_points_are_the_start_the_manoeuvres_and_each_leg_end(plan):
    pts = route_points(plan)
    assert [(p.name, p.kind, p.leg) for p in pts] == [
        ("start", "start", 1),
        ("T1", "tack", 1),
        ("top", "mark", 1),
        ("G1", "gybe", 2),
        ("gate", "gate", 2),
        ("finish", "line", 3),
    ]
    t = [p.t for p in pts]
    assert np.all(np.diff(t) > 0)
    frame = plan.course.frame
    tack = plan.legs[0].result.manoeuvres[0]
    x, y = frame.to_xy(pts[1].lat, pts[1].lon)
    assert (float(x), float(y)) == pytest.approx((tack.x, tack.y), abs=1e-6)
    assert pts[1].t == tack.t
    x, y = frame.to_xy(pts[-1].lat, pts[-1].lon)
    assert (float(x), float(y)) == pytest.approx(plan.legs[-1].result.end_xy, abs=1e-6)
    assert pts[-1].t == pytest.approx(plan.t_end)


def test_gpxpy_reads_the_route_beside_the_track(tmp_path, plan):
    path = write_gpx(tmp_path / "route.gpx", plan)
    gpx = gpxpy.parse(path.read_text(encoding="utf-8"))
    assert len(gpx.routes) == 1 and len(gpx.tracks) == 1
    assert len(gpx.tracks[0].segments) == len(plan.legs)
    pts = route_points(plan)
    rpts = gpx.routes[0].points
    assert [p.name for p in rpts] == [p.name for p in pts]
    assert [p.type for p in rpts] == [p.kind for p in pts]
    np.testing.assert_allclose([p.latitude for p in rpts], [p.lat for p in pts], atol=1e-8)
    np.testing.assert_allclose([p.longitude for p in rpts], [p.lon for p in pts], atol=1e-8)
    np.testing.assert_allclose([p.time.timestamp() for p in rpts], [p.t for p in pts], atol=1e-3)
    assert sorted(w.name for w in gpx.waypoints) == sorted(plan.course.marks)
    # GPX 1.1 order of the root's children: metadata, wpt*, rte*, trk*
    root = ET.parse(path).getroot()
    tags = [c.tag.split("}")[1] for c in root]
    assert tags == ["metadata", *["wpt"] * len(plan.course.marks), "rte", "trk"]
    assert root.tag == "{http://www.topografix.com/GPX/1/1}gpx"


def test_kml_holds_the_marks_the_route_line_and_the_waypoints(tmp_path, plan):
    root = ET.parse(write_kml(tmp_path / "route.kml", plan)).getroot()
    assert root.tag == f"{{{KML_NS}}}kml"
    folders = {f.find("k:name", K).text: f for f in root.findall("k:Document/k:Folder", K)}
    assert list(folders) == ["marks", "route", "waypoints"]
    marks = folders["marks"].findall("k:Placemark", K)
    assert [m.find("k:name", K).text for m in marks] == list(plan.course.marks)
    for pm, mark in zip(marks, plan.course.marks.values(), strict=True):
        lon, lat = map(float, pm.find("k:Point/k:coordinates", K).text.split(","))
        assert (lat, lon) == pytest.approx((mark.lat, mark.lon), abs=1e-8)
    line = folders["route"].find("k:Placemark/k:LineString/k:coordinates", K).text.split()
    assert len(line) == sum(len(pl.result.track) for pl in plan.legs)
    lon0, lat0 = map(float, line[0].split(","))
    x, y = plan.course.frame.to_xy(lat0, lon0)
    assert (float(x), float(y)) == pytest.approx(plan.legs[0].result.start_xy, abs=1e-3)
    wps = folders["waypoints"].findall("k:Placemark", K)
    pts = route_points(plan)
    assert [w.find("k:name", K).text for w in wps] == [p.name for p in pts]
    assert [w.find("k:TimeStamp/k:when", K).text for w in wps] == [iso(p.t) for p in pts]
    assert wps[1].find("k:description", K).text.startswith("tack, leg 1, ")
    assert wps[1].find("k:description", K).text.endswith("plotter id T01")


def test_kml_draws_marks_route_and_manoeuvres_in_their_styles(tmp_path, plan):
    root = ET.parse(write_kml(tmp_path / "route.kml", plan)).getroot()
    styles = {s.get("id"): s for s in root.findall("k:Document/k:Style", K)}
    assert set(styles) == {"mark", "leg-end", "tack", "gybe", "route"}
    # KML colours are aabbggrr: the route's #d62728 is ff2827d6
    assert styles["route"].find("k:LineStyle/k:color", K).text == "ff2827d6"
    assert styles["tack"].find("k:IconStyle/k:Icon/k:href", K).text.endswith("triangle.png")
    assert styles["gybe"].find("k:IconStyle/k:Icon/k:href", K).text.endswith("square.png")
    folders = {f.find("k:name", K).text: f for f in root.findall("k:Document/k:Folder", K)}

    def used(folder):
        return {
            pm.find("k:name", K).text: pm.find("k:styleUrl", K).text
            for pm in folders[folder].findall("k:Placemark", K)
        }

    assert set(used("marks").values()) == {"#mark"}
    assert list(used("route").values()) == ["#route"]
    wps = used("waypoints")
    assert wps["T1"] == "#tack" and wps["G1"] == "#gybe" and wps["finish"] == "#leg-end"


def test_nmea_sentences_parse_and_their_checksums_verify(tmp_path, plan):
    path = write_nmea(tmp_path / "route.nmea", plan)
    raw = path.read_bytes()
    assert raw.endswith(b"\r\n") and b"\n" not in raw.replace(b"\r\n", b"")
    lines = raw.decode("ascii").split("\r\n")[:-1]
    pts = route_points(plan)
    msgs = [pynmea2.parse(s, check=True) for s in lines]  # raises on a bad checksum
    wpl = [m for m in msgs if m.sentence_type == "WPL"]
    rte = [m for m in msgs if m.sentence_type == "RTE"]
    assert len(wpl) == len(pts) and len(rte) == 1
    assert all(len(s) + 2 <= NMEA_MAX_LEN for s in lines)
    for m, p in zip(wpl, pts, strict=True):
        # 4 decimals of a minute: within 0.1 m of latitude
        lat, lon = _degrees(m.lat, m.lat_dir), _degrees(m.lon, m.lon_dir)
        assert abs(lat - p.lat) * 60 * MINUTE_M < 0.1
        assert abs(lon - p.lon) * 60 * MINUTE_M * np.cos(np.radians(p.lat)) < 0.1
        assert len(m.waypoint_id) <= 6
    assert rte[0].waypoint_list == [m.waypoint_id for m in wpl]
    assert (rte[0].num_in_seq, rte[0].sen_num, rte[0].start_type) == ("1", "1", "c")


def test_nmea_checksum_of_a_published_sentence():
    # the RMC example of the NMEA 0183 references (gpsinformation.org, D. DePriest)
    body = "GPRMC,081836,A,3751.65,S,14507.36,E,000.0,360.0,130998,011.3,E"
    assert checksum(body) == "62"


def test_a_long_route_is_split_over_several_rte_sentences():
    pts = [
        RoutePoint(f"mark{k}", "mark", -36.8 - k * 1e-3, 174.7 + k * 1e-3, 1e9 + k, k)
        for k in range(40)
    ]
    lines = nmea_sentences(pts)
    msgs = [pynmea2.parse(s, check=True) for s in lines]
    rte = [m for m in msgs if m.sentence_type == "RTE"]
    assert len(rte) >= 4
    assert all(len(s) + 2 <= NMEA_MAX_LEN for s in lines)
    assert [m.num_in_seq for m in rte] == [str(len(rte))] * len(rte)
    assert [m.sen_num for m in rte] == [str(k + 1) for k in range(len(rte))]
    ids = [i for m in rte for i in m.waypoint_list]
    assert ids == [m.waypoint_id for m in msgs if m.sentence_type == "WPL"]
    assert len(set(ids)) == 40
    # southern and eastern hemispheres: ddmm.mmmm,S and dddmm.mmmm,E
    assert lines[0].startswith("$GPWPL,3648.0000,S,17442.0000,E,MARK0*")


def test_nmea_ids_say_what_the_point_is_in_six_characters():
    # the Hyeres R1 route: start, a tack, mark 1, gate4, mark 1 again, two gybes, 4p, finish
    names = ["start", "T1", "1", "gate4", "1", "G1", "G2", "4p", "finish"]
    kinds = ["start", "tack", "mark", "gate", "mark", "gybe", "gybe", "mark", "line"]
    assert nmea_ids(names, kinds) == (
        "START", "T01", "M1", "G4", "M1R2", "J01", "J02", "M4P", "FIN"
    )  # fmt: skip
    # a gate named by its number, a line that is not the finish, a lettered mark
    assert nmea_ids(["4", "gate", "B1"], ["gate", "line", "mark"]) == ("G4", "LGATE", "B1")


def test_nmea_ids_are_unique_and_short():
    ids = nmea_ids(["start", "M1", "T1", "LG1-LG2", "LG1-LG2", "a\x00b"])
    assert ids == ("START", "M1", "T1", "LG1LG2", "LG1LR2", "AB")
    many = nmea_ids([f"T{k}" for k in range(150)], ["tack"] * 150)
    assert len(set(many)) == 150 and max(map(len, many)) <= 6 and many[120] == "T120"
    # names that collide once cut and cleaned still give distinct identifiers
    same = nmea_ids(["wing mark 1", "wing-mark-1", "WINGMA", "wingma"], ["mark"] * 4)
    assert len(set(same)) == 4 and max(map(len, same)) <= 6


def test_the_plan_files_include_kml_and_nmea(tmp_path, plan):
    out = write_plan_outputs(tmp_path, plan, plot=False)
    assert out["kml"] == tmp_path / "route.kml" and out["nmea"] == tmp_path / "route.nmea"
    assert sum(1 for _ in out["nmea"].open()) == len(route_points(plan)) + 1


def test_control_characters_in_names_leave_kml_well_formed_and_nmea_ascii(tmp_path, plan):
    import dataclasses

    evil = dataclasses.replace(plan, course=dataclasses.replace(plan.course, name="a\x00b\x1b"))
    root = ET.parse(write_kml(tmp_path / "route.kml", evil)).getroot()  # a NUL would not parse
    assert root.find("k:Document/k:name", K).text == "a\ufffdb\ufffd (north)"
    text = write_nmea(tmp_path / "route.nmea", evil).read_bytes()
    assert all(32 <= b < 127 for b in text.replace(b"\r\n", b""))
