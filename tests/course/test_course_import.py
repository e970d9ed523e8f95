"""``sailroute course import``: SailGP race XML, and GPX/CSV/KML written from its marks.

The four race XMLs of SailGP Auckland 2025-01-19 are read from ``../shared/data/real``
(licence none stated: not copied into the project).  Their marks, corners, start times and
limits are read here independently with ElementTree and compared with what the importer
wrote and the course loader read back.
"""

from __future__ import annotations

import math
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
import shapely
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.commands.course_import import run_course_import_command
from sailroute.course.formats import read_course_source
from sailroute.course.load import load_course
from sailroute.errors import InputError
from sailroute.planning.route import plan_course
from sailroute.timeutil import parse_time
from tests.conftest import SHARED_REAL, requires_shared

XML_DIR = SHARED_REAL / "races" / "sailgp-auckland-2025" / "Race_XMLs"
F50 = SHARED_REAL / "polars" / "sailgp-f50" / "2502_m8_APW_HSB2_HSRW.kph.csv"
RACES = {  # file -> local start time (README of the data folder)
    "25011905_03-13-55.xml": "2025-01-19T16:08:00+13:00",
    "25011906_03-35-13.xml": "2025-01-19T16:29:00+13:00",
    "25011907_03-56-34.xml": "2025-01-19T16:50:00+13:00",
    "25011908_04-23-32.xml": "2025-01-19T17:14:00+13:00",
}
R05 = XML_DIR / "25011905_03-13-55.xml"
# Start -> M1 -> LG -> WG -> LG -> WG -> LG1 -> Finish (the README's 8 corners)
LEGS = [
    ("start", "M1", "mark", "port"),
    ("M1", "LG1-LG2", "gate", None),
    ("LG1-LG2", "WG1-WG2", "gate", None),
    ("WG1-WG2", "LG1-LG2", "gate", None),
    ("LG1-LG2", "WG1-WG2", "gate", None),
    ("WG1-WG2", "LG1", "mark", "port"),
    ("LG1", "finish", "line", None),
]
WIND = {"wind_twd_deg": 225.0, "wind_tws_kn": 12.0}
runner = CliRunner()


def xml_marks(path: Path) -> dict[str, tuple[float, float]]:
    """Every <Mark>'s position, read with ElementTree."""
    root = ET.parse(path).getroot()
    return {
        m.get("Name"): (float(m.get("TargetLat")), float(m.get("TargetLng")))
        for m in root.iter("Mark")
    }


def xml_limits(path: Path) -> dict[str, int]:
    return {
        cl.get("name"): len(cl.findall("Limit"))
        for cl in ET.parse(path).getroot().iter("CourseLimit")
    }


def distance_m(course, a: tuple[float, float], b: tuple[float, float]) -> float:
    x, y = course.frame.to_xy([a[0], b[0]], [a[1], b[1]])
    return float(math.hypot(x[1] - x[0], y[1] - y[0]))


def legs_of(course) -> list[tuple[str, str, str, str | None]]:
    return [(leg.from_name, leg.to_name, leg.kind, leg.rounding) for leg in course.legs]


@requires_shared
@pytest.mark.parametrize("name", sorted(RACES))
def test_race_xml_marks_sequence_start_and_limits(tmp_path, name):
    src = XML_DIR / name
    res = run_course_import_command(src, out=tmp_path / "c.yaml", **WIND)
    course = load_course(tmp_path / "c.yaml")
    marks = xml_marks(src)
    assert set(course.marks) == set(marks)
    for n, ll in marks.items():
        m = course.marks[n]
        assert distance_m(course, (m.lat, m.lon), ll) < 0.1, n
    assert legs_of(course) == LEGS
    assert course.lines["start"].a.name == "SL1" and course.lines["finish"].b.name == "FL2"
    assert (course.gates["LG1-LG2"].a.name, course.gates["WG1-WG2"].b.name) == ("LG1", "WG2")
    assert course.start_time == parse_time(RACES[name])
    assert course.utc_offset_s == 13 * 3600.0
    limits = xml_limits(src)
    assert limits == {"Boundary": 12, "Exclusion Zone": 18, "AY": 6, "BYOB": 10}
    # a Boundary that leaves marks outside (the start marks of the first three races) is
    # left out, and said so; one that holds every mark is the course's boundary
    ring = shapely.Polygon([(lon, lat) for lat, lon in xml_rings(src)["Boundary"]])
    holds = all(shapely.contains_xy(ring, lon, lat) for lat, lon in marks.values())
    if holds:
        assert course.area.boundary is not None and len(course.area.boundary.x) == 12
    else:
        assert course.area.boundary is None
        assert any("'Boundary'" in n and "outside: left out" in n for n in res.notes)
    assert holds == (name == "25011908_04-23-32.xml")
    assert [(o.name, len(o.x)) for o in course.area.obstacles] == [("AY", 6), ("BYOB", 10)]
    # the exclusion line encloses the whole race area: left out, and said so
    assert any("'Exclusion Zone'" in n and "holds every mark" in n for n in res.notes)
    assert any("no boat given" in n for n in res.notes)
    text = (tmp_path / "c.yaml").read_text()
    assert "NO BOAT GIVEN" in text.splitlines()[1] and "\nboat:" not in text


@requires_shared
def test_imported_race_plans_with_the_f50_polar(tmp_path):
    boat = f"{{polar: {F50}, speed_unit: km/h, wind_unit: km/h}}"
    run_course_import_command(R05, out=tmp_path / "r05.yaml", boat=boat, **WIND)
    course = load_course(tmp_path / "r05.yaml")
    assert course.boat_spec["polar"] == str(F50)
    run = plan_course(course)
    assert [pl.spec.to_name for pl in run.plan.legs] == [leg[1] for leg in LEGS]
    # an F50 in 12 kn sails the 7 legs (about 7.6 km) well under the 90 min limit
    assert 0 < run.plan.total_time_s < 1800
    assert all(pl.result.time_s > 0 for pl in run.plan.legs)


# ------------------------------------------------------------------ GPX / CSV / KML
SEQUENCE = [
    ("SL1", "start"),
    ("SL2", "start"),
    ("M1", "port"),
    ("LG1", "gate"),
    ("LG2", "gate"),
    ("WG1", "gate"),
    ("WG2", "gate"),
    ("LG1", "gate"),
    ("LG2", "gate"),
    ("WG1", "gate"),
    ("WG2", "gate"),
    ("LG1", "port"),
    ("FL1", "finish"),
    ("FL2", "finish"),
]
"""Race 25011905 as a list of points in sailing order, with their types."""
T0 = "2025-01-19T16:08:00+13:00"


def write_gpx(path: Path, marks: dict[str, tuple[float, float]], *, route: bool) -> Path:
    pts = "".join(
        f'<{tag} lat="{marks[n][0]}" lon="{marks[n][1]}"><name>{n}</name><type>{t}</type></{tag}>\n'
        for n, t in SEQUENCE
        for tag in (["rtept"] if route else ["wpt"])
    )
    body = f"<rte><name>race 05</name>\n{pts}</rte>" if route else pts
    path.write_text(
        '<?xml version="1.0"?>\n<gpx version="1.1" creator="test" '
        f'xmlns="http://www.topografix.com/GPX/1/1">\n{body}\n</gpx>\n'
    )
    return path


def write_csv(path: Path, marks: dict[str, tuple[float, float]]) -> Path:
    rows = ["Name,LAT,Lon,Type,Rounding"]
    for n, t in SEQUENCE:
        kind, side = ("mark", t) if t == "port" else (t, "")
        rows.append(f"{n},{marks[n][0]},{marks[n][1]},{kind},{side}")
    path.write_text("\n".join(rows) + "\n")
    return path


def write_kml(
    path: Path, marks: dict[str, tuple[float, float]], rings: dict[str, list[tuple[float, float]]]
) -> Path:
    pms = []
    for n, t in SEQUENCE:
        data = (
            '<Data name="rounding"><value>port</value></Data>'
            if t == "port"
            else f'<Data name="type"><value>{t}</value></Data>'
        )
        pms.append(
            f"<Placemark><name>{n}</name><ExtendedData>{data}</ExtendedData>"
            f"<Point><coordinates>{marks[n][1]},{marks[n][0]},0</coordinates></Point>"
            "</Placemark>"
        )
    for name, ring in rings.items():
        closed = [*ring, ring[0]]  # KML repeats the first point
        coords = " ".join(f"{lon},{lat},0" for lat, lon in closed)
        pms.append(
            f"<Placemark><name>{name}</name><Polygon><outerBoundaryIs><LinearRing>"
            f"<coordinates>{coords}</coordinates></LinearRing></outerBoundaryIs>"
            "</Polygon></Placemark>"
        )
    path.write_text(
        '<?xml version="1.0"?>\n<kml xmlns="http://www.opengis.net/kml/2.2">'
        "<Document><name>race 05</name>\n" + "\n".join(pms) + "\n</Document></kml>\n"
    )
    return path


def xml_rings(path: Path) -> dict[str, list[tuple[float, float]]]:
    return {
        cl.get("name"): [(float(p.get("Lat")), float(p.get("Lon"))) for p in cl.findall("Limit")]
        for cl in ET.parse(path).getroot().iter("CourseLimit")
    }


@requires_shared
@pytest.mark.parametrize("kind", ["gpx-route", "gpx-waypoints", "csv", "kml"])
def test_point_files_give_the_race_xml_course(tmp_path, kind):
    marks = xml_marks(R05)
    rings = xml_rings(R05)
    if kind.startswith("gpx"):
        src = write_gpx(tmp_path / "course.gpx", marks, route=kind == "gpx-route")
    elif kind == "csv":
        src = write_csv(tmp_path / "course.csv", marks)
    else:
        src = write_kml(
            tmp_path / "course.kml", marks, {"Boundary": rings["Boundary"], "AY": rings["AY"]}
        )
    run_course_import_command(src, out=tmp_path / "c.yaml", start_time=T0, boat="ilca7", **WIND)
    course = load_course(tmp_path / "c.yaml")
    assert legs_of(course) == LEGS
    for n, ll in marks.items():
        m = course.marks[n]
        assert distance_m(course, (m.lat, m.lon), ll) < 0.1, n
    assert course.start_time == parse_time(T0)
    assert dict(course.boat_spec) == {"builtin": "ilca7"}
    assert course.area.boundary is None  # the race's Boundary leaves the start marks out
    if kind == "kml":
        assert [(o.name, len(o.x)) for o in course.area.obstacles] == [("AY", 6)]
        ay = course.area.obstacles[0]
        lat, lon = course.frame.to_latlon(np.asarray(ay.x), np.asarray(ay.y))
        np.testing.assert_allclose(np.column_stack([lat, lon]), rings["AY"], atol=1e-9)
    else:
        assert course.area.obstacles == ()


def test_kml_linestring_is_a_line_and_gpx_waypoints_keep_file_order(tmp_path):
    kml = tmp_path / "c.kml"
    kml.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2"><Document>'
        "<Placemark><name>Start</name><LineString><coordinates>13.0,45.0 13.002,45.0"
        "</coordinates></LineString></Placemark>"
        "<Placemark><name>top</name><Point><coordinates>13.001,45.009</coordinates></Point>"
        "</Placemark>"
        "<Placemark><name>Finish</name><LineString><coordinates>13.0,45.0005 13.002,45.0005"
        "</coordinates></LineString></Placemark></Document></kml>"
    )
    ic, fmt = read_course_source(kml)
    assert fmt == "kml"
    assert ic.lines == (("start", "Start_1", "Start_2"), ("finish", "Finish_1", "Finish_2"))
    assert (ic.start_from, ic.legs) == ("start", (("top", "port"), ("finish", None)))
    run_course_import_command(kml, out=tmp_path / "c.yaml", start_time=T0, **WIND)
    course = load_course(tmp_path / "c.yaml")
    assert course.lines["start"].length_m == pytest.approx(157.6, abs=0.5)  # 0.002 deg lon
    assert course.marks["top"].lat == 45.009


# ------------------------------------------------------------------ bad input
def assert_one_line(exc: pytest.ExceptionInfo, *parts: str) -> None:
    msg = str(exc.value)
    assert "\n" not in msg, msg
    for p in parts:
        assert p in msg, msg


def test_gpx_without_waypoints(tmp_path):
    src = tmp_path / "empty.gpx"
    src.write_text(
        '<?xml version="1.0"?>\n<gpx version="1.1" creator="x" '
        'xmlns="http://www.topografix.com/GPX/1/1">\n<trk/></gpx>\n'
    )
    with pytest.raises(InputError) as exc:
        run_course_import_command(src, out=tmp_path / "c.yaml", start_time=T0, **WIND)
    assert_one_line(exc, str(src), "line 2", "no waypoints (<wpt>)")
    assert not (tmp_path / "c.yaml").exists()


@requires_shared
def test_unknown_element_in_a_compound_mark(tmp_path):
    text = R05.read_text().replace(
        '<CompoundMark CompoundMarkID="2" Name="M1">',
        '<CompoundMark CompoundMarkID="2" Name="M1">\n      <Buoy Name="M1" />',
        1,
    )
    src = tmp_path / "race.xml"
    src.write_text(text)
    line = next(k + 1 for k, ln in enumerate(text.splitlines()) if "<Buoy" in ln)
    with pytest.raises(InputError) as exc:
        run_course_import_command(src, out=tmp_path / "c.yaml", **WIND)
    assert_one_line(exc, f"{src}: line {line}: <Buoy> in CompoundMark '2'", "expected <Mark")


def test_csv_missing_a_column(tmp_path):
    src = tmp_path / "marks.csv"
    src.write_text("name,lat\nA,45.0\nB,45.01\n")
    with pytest.raises(InputError) as exc:
        run_course_import_command(src, out=tmp_path / "c.yaml", start_time=T0, **WIND)
    assert_one_line(exc, f"{src}, line 1: missing column lon", "expected a header with name")


def test_csv_bad_number_names_its_line(tmp_path):
    src = tmp_path / "marks.csv"
    src.write_text("# marks\nname,lat,lon\nA,45.0,13.0\nB,forty,13.0\n")
    with pytest.raises(InputError) as exc:
        run_course_import_command(src, out=tmp_path / "c.yaml", start_time=T0, **WIND)
    assert_one_line(exc, f"{src}, line 4: lat 'forty'")


@requires_shared
def test_self_intersecting_polygon(tmp_path):
    text = R05.read_text()
    # swap two vertices of the boundary: its ring crosses itself
    a = '<Limit SeqID="2" Lat="-36.8272030" Lon="174.7620790" />'
    b = '<Limit SeqID="3" Lat="-36.8279690" Lon="174.7677170" />'
    text = (
        text.replace(a, "@A@")
        .replace(b, a.replace('"2"', '"3"'))
        .replace("@A@", b.replace('"3"', '"2"'))
    )
    src = tmp_path / "race.xml"
    src.write_text(text)
    line = next(k + 1 for k, ln in enumerate(text.splitlines()) if 'name="Boundary"' in ln)
    with pytest.raises(InputError) as exc:
        run_course_import_command(src, out=tmp_path / "c.yaml", **WIND)
    assert_one_line(exc, f"{src}: line {line}: polygon 'Boundary'", "crosses the edge")


def test_wind_is_required(tmp_path):
    src = tmp_path / "m.csv"
    src.write_text("name,lat,lon,type\nA,45.0,13.0,mark\nB,45.01,13.0,\n")
    with pytest.raises(InputError, match="--wind-twd and --wind-tws are required"):
        run_course_import_command(src, out=tmp_path / "c.yaml", start_time=T0)
    with pytest.raises(InputError, match="gives no start time; give --start-time"):
        run_course_import_command(src, out=tmp_path / "c.yaml", **WIND)


def test_course_file_areas_are_checked_at_their_line(tmp_path):
    course = tmp_path / "c.yaml"
    course.write_text(
        'name: x\nstart_time: "2024-05-01T12:00:00Z"\nmarks:\n'
        "  a: {lat: 45.0, lon: 13.0}\n  b: {lat: 45.01, lon: 13.0}\n"
        "legs:\n  - {from: a, to: b}\nscenarios:\n  s: {type: uniform, tws_kn: 10, twd_deg: 0}\n"
        "boundary:\n  points: [{lat: 44.99, lon: 12.99}, {lat: 45.02, lon: 13.01},\n"
        "           {lat: 45.02, lon: 12.99}, {lat: 44.99, lon: 13.01}]\n"
        "obstacles:\n  - {name: rock, points: [{lat: 45.005, lon: 13.001}, "
        "{lat: 45.005, lon: 13.002}], clearance_m: 5}\n"
    )
    with pytest.raises(InputError) as exc:
        load_course(course)
    msg = str(exc.value)
    assert (
        f"{course}:10: boundary: expected a simple polygon; its edge from point 1 "
        "to 2 crosses the edge from point 3 to 4" in msg
    )
    assert f"{course}:14: obstacles[0]: expected a ring of at least 3 points; got 2" in msg


# ------------------------------------------------------------------ command line
def test_cli_writes_the_course_and_reports_it(tmp_path):
    src = tmp_path / "m.csv"
    src.write_text("name,lat,lon,rounding\npin,45.0,13.0,\ntop,45.009,13.001,starboard\n")
    out = tmp_path / "c.yaml"
    res = runner.invoke(
        app,
        [
            "course",
            "import",
            str(src),
            "-o",
            str(out),
            "--wind-twd",
            "0",
            "--wind-tws",
            "10",
            "--start-time",
            T0,
        ],
    )
    assert res.exit_code == 0, res.output
    assert "leg 1: pin -> top [mark] (starboard)" in res.output
    assert f"wrote course (YAML): {out}" in res.output
    assert "note: no boat given (--boat)" in res.output
    assert load_course(out).legs[0].rounding == "starboard"


def test_cli_bad_input_exits_2_and_writes_nothing(tmp_path):
    src = tmp_path / "m.csv"
    src.write_text("name,lat,lon,type\npin,45.0,13.0,mark\ntop,45.009,13.001,\n")
    out = tmp_path / "c.yaml"
    res = runner.invoke(
        app,
        [
            "course",
            "import",
            str(src),
            "-o",
            str(out),
            "--wind-twd",
            "0",
            "--wind-tws",
            "10",
            "--start-time",
            T0,
            "--boat",
            "ilca99",
        ],
    )
    assert res.exit_code == 2
    assert res.output.startswith("error: ") and "ilca99" in res.output
    assert "Traceback" not in res.output
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]


def test_boat_option_forms(tmp_path):
    import os

    from sailroute.commands.course_import import boat_spec_of

    polar = tmp_path / "polars" / "mine.pol"
    polar.parent.mkdir()
    polar.write_text("TWA\\TWS\t6\t10\n45\t3.5\t4.5\n90\t4.5\t5.5\n")
    out = tmp_path / "courses" / "c.yaml"
    assert boat_spec_of(str(polar), out) == {"polar": os.path.join("..", "polars", "mine.pol")}
    assert boat_spec_of("ilca6", out) == {"builtin": "ilca6"}
    assert boat_spec_of("{polar: f.csv, speed_unit: km/h}", out) == {
        "polar": "f.csv",
        "speed_unit": "km/h",
    }
    assert boat_spec_of(None, out) is None
    with pytest.raises(InputError, match="no such polar file"):
        boat_spec_of(str(tmp_path / "missing.pol"), out)
    with pytest.raises(InputError, match=r"--boat '\{1, 2': not a YAML mapping"):
        boat_spec_of("{1, 2", out)
