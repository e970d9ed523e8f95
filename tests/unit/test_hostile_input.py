"""Hostile and broken input files end in a one-line message and exit 2, and never reach an output.

Each case was an internal error, a hang or a malformed output file before the readers
were hardened: recursive and exponential YAML aliases, deep nesting (YAML and polar
JSON), lone surrogates and control characters in names, marks at absurd coordinates,
unquoted timestamps that do not exist, CSV lines with a stray quote, a file of another
kind given as a station CSV (its content must not be printed), markup in names drawn by
report.html, and a 1 x 1 NetCDF wind grid.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import time
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.boat.io import read_polar
from sailroute.cli import app
from sailroute.course.load import course_from_mapping, load_course
from sailroute.errors import InputError
from sailroute.planning.result import make_plan
from sailroute.report.files import write_gpx, write_track_csv
from sailroute.report.html import plan_report
from sailroute.report.page_figure import figure
from sailroute.routing.track import make_leg_result
from sailroute.textin import CleanCsvWriter, clean_text, csv_rows, excerpt, looks_like_header
from sailroute.track.read import read_track
from sailroute.wind.stations import read_stations
from sailroute.wind.uniform import UniformWind
from sailroute.yamlfile import MAX_DEPTH, MAX_NODES, read_yaml
from tests.conftest import TESTS_DATA
from tests.report.conftest import COURSE, timed_track

MINIMAL = (TESTS_DATA / "course" / "minimal.yaml").read_text()
N_MINIMAL = MINIMAL.count("\n")  # the line an appended key starts on is N_MINIMAL + 1
runner = CliRunner()


def plan_error(tmp_path: Path, text: str, name: str = "course.yaml", **files: str) -> str:
    """Run ``sailroute plan`` on a course text (and side files); assert exit 2, a single
    line on stderr, no traceback and no output folder; return the message."""
    course = tmp_path / name
    course.write_text(text, encoding="utf-8", errors="surrogatepass")
    for fname, content in files.items():
        (tmp_path / fname).write_text(content)
    out = tmp_path / "out"
    res = runner.invoke(app, ["plan", str(course), "-q", "--no-plots", "--out", str(out)])
    assert res.exit_code == 2, res.output
    assert res.stderr.startswith("error: ") and res.stderr.count("\n") == 1, res.stderr
    assert "Traceback" not in res.output and "internal error" not in res.output
    assert not out.exists()
    return res.stderr.removeprefix("error: ").rstrip("\n")


def billion_laughs(levels: int = 9) -> str:
    text = 'l0: &l0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]\n'
    for k in range(1, levels):
        text += f"l{k}: &l{k} [" + ", ".join([f"*l{k - 1}"] * 9) + "]\n"
    return text


# ------------------------------------------------------------------ YAML structure (1, 2, 3)
def test_recursive_alias_is_refused_with_its_line(tmp_path):
    msg = plan_error(tmp_path, MINIMAL + "x: &r [*r]\n")
    assert msg == (
        f"{tmp_path / 'course.yaml'}:{N_MINIMAL + 1}:8: the alias *r is inside the "
        "node &r it refers to (a value that contains itself); refer to a finished node"
    )


@pytest.mark.parametrize(
    "nested",
    [
        "{a: " * 2000 + "1" + "}" * 2000,
        "[" * 5000 + "]" * 5000,
        "\n".join("  " * k + "a:" for k in range(200)) + " 1",
    ],
)
def test_deep_nesting_is_refused(tmp_path, nested):
    msg = plan_error(tmp_path, MINIMAL + "x:\n  " + nested.replace("\n", "\n  ") + "\n")
    assert (
        f"nested more than {MAX_DEPTH} levels deep; a course or boat file needs a few levels" in msg
    )


def test_nesting_through_aliases_counts(tmp_path):
    # 10 anchors of depth 6 chained: 60 levels once expanded, although no line is deep
    text = "a0: &a0 [[[[[1]]]]]\n" + "".join(
        f"a{k}: &a{k} [[[[[*a{k - 1}]]]]]\n" for k in range(1, 10)
    )
    msg = plan_error(tmp_path, MINIMAL + text)
    assert "levels deep through the alias *a" in msg


def test_billion_laughs_is_refused_at_once(tmp_path):
    t0 = time.perf_counter()
    msg = plan_error(tmp_path, MINIMAL + billion_laughs())
    assert time.perf_counter() - t0 < 5.0  # was a hang (9**9 values)
    assert f"more than {MAX_NODES} values once the alias *l" in msg
    assert "a course or boat file has at most a few thousand" in msg


def test_ordinary_anchors_still_work(tmp_path):
    text = MINIMAL.replace("scenarios:\n  north: {type: uniform, tws_kn: 10, twd_deg: 0}\n", "") + (
        "scenarios:\n"
        "  north: &wind {type: uniform, tws_kn: 10, twd_deg: 0}\n"
        "  again: *wind\n"
        "  west: {type: uniform, tws_kn: &tws 10, twd_deg: 270}\n"
        "  east: {type: uniform, tws_kn: *tws, twd_deg: 90}\n"
    )
    p = tmp_path / "course.yaml"
    p.write_text(text)
    course = load_course(p)
    assert set(course.scenarios) == {"north", "again", "west", "east"}
    # a file of some 29 000 values once its aliases are expanded reads (4**7 / 3 + keys)
    doc = tmp_path / "wide.yaml"
    doc.write_text(
        "l0: &l0 [1, 2, 3, 4]\n"
        + "".join(
            f"l{k}: &l{k} [*l{k - 1}, *l{k - 1}, *l{k - 1}, *l{k - 1}]\n" for k in range(1, 7)
        )
    )
    assert np.asarray(read_yaml(doc).data["l6"]).size == 4**7


def test_polar_json_nested_100000_deep(tmp_path):
    for text in ("[" * 100_000 + "]" * 100_000, '{"a":' * 100_000 + "1" + "}" * 100_000):
        p = tmp_path / "deep.json"
        p.write_text(text)
        with pytest.raises(
            InputError,
            match=r"deep.json: not a polar: its JSON nests lists or "
            r"objects too deeply to read \(a polar file has 3 levels\)$",
        ):
            read_polar(p)
    msg = plan_error(tmp_path, MINIMAL + "boat: {polar: deep.json}\n")
    assert msg.endswith(
        "deep.json: not a polar: its JSON nests lists or objects too deeply "
        "to read (a polar file has 3 levels)"
    )


# ------------------------------------------------------------------ text in YAML (4, 11)
@pytest.mark.parametrize(
    ("escape", "what"),
    [
        ("\\ud800", "U+D800 (a lone surrogate)"),
        ("\\0", "U+0000 (a control character)"),
        ("\\x1b", "U+001B (a control character)"),
        ("\\uffff", "U+FFFF (a non-character)"),
    ],
)
def test_bad_characters_in_names_are_refused(tmp_path, escape, what):
    msg = plan_error(tmp_path, MINIMAL.replace("name: minimal", f'name: "a{escape}b"'))
    assert msg.startswith(f"{tmp_path / 'course.yaml'}:1:7: the text ")
    assert msg.endswith(
        f" holds {what}, which no output file can carry; remove it (or the escape that writes it)"
    )
    msg = plan_error(
        tmp_path,
        MINIMAL.replace("  top:", f'  "t{escape}p":').replace("{to: top}", f'{{to: "t{escape}p"}}'),
    )
    assert f"holds {what}" in msg


def test_tab_and_line_breaks_in_text_are_fine(tmp_path):
    p = tmp_path / "course.yaml"
    p.write_text(MINIMAL + 'description: "line 1\\n\\tline 2\\r\\n"\n')
    assert load_course(p).description == "line 1\n\tline 2\r\n"


# ------------------------------------------------------------------ coordinates (5)
def test_mark_at_1e20_is_refused_with_its_key(tmp_path):
    text = "origin: {lat: 45, lon: 13}\n" + MINIMAL.replace(
        "top: {lat: 45.0090, lon: 13.0010}", "top: {x: 1e20, y: 0}"
    )
    msg = plan_error(tmp_path, text)
    assert msg == (
        f"{tmp_path / 'course.yaml'}:7: marks.top.x: expected metres east of the "
        "origin, in [-100000, 100000]; got 1e+20"
    )


def test_marks_far_apart_in_degrees_are_refused(tmp_path):
    text = MINIMAL.replace("top: {lat: 45.0090", "top: {lat: 48.0090")
    p = tmp_path / "course.yaml"
    p.write_text(text)
    with pytest.raises(InputError) as exc:
        load_course(p)
    assert (
        "marks.top: mark 'top' (48.009000, 13.001000) lies 223 km from the course's "
        "centre (46.003000, 13.001000, the mean of the marks' lat/lon); expected every "
        "mark within 100 km of it"
    ) in str(exc.value)


def test_template_lengths_are_bounded(tmp_path):
    text = (
        "name: t\nstart_time: 2024-05-01T10:00:00Z\ntemplate: {type: windward-leeward, "
        "twd_deg: 0, leg_length_m: 1e300, centre: {lat: 45, lon: 13}}\n"
        "scenarios:\n  north: {type: uniform, tws_kn: 10, twd_deg: 0}\n"
    )
    msg = plan_error(tmp_path, text)
    assert msg.endswith(
        ":3: template.leg_length_m: expected at most 100000 m (a buoy course "
        "spans a few km); got 1e+300"
    )


# ------------------------------------------------------------------ timestamps (7)
@pytest.mark.parametrize("stamp", ["2024-02-30T10:00:00Z", "2024-05-01T10:00:60Z", "2024-02-30"])
def test_unquoted_impossible_time_gets_the_quoted_message(tmp_path, stamp):
    bare = plan_error(tmp_path, MINIMAL.replace("2024-05-01T10:00:00Z", stamp))
    quoted = plan_error(tmp_path, MINIMAL.replace("2024-05-01T10:00:00Z", f'"{stamp}"'))
    assert bare == quoted
    assert bare.endswith(
        f":2: start_time: cannot read {stamp!r} as an ISO 8601 time; "
        "expected e.g. '2018-04-24T12:10:00+02:00'"
    )


# ------------------------------------------------------------------ CSV quoting (8)
STATIONS_HEAD = "time,station,lat,lon,speed_kn,direction\n"
ROW = "2024-05-01T10:{m:02d}:00Z,A,45.004,13.001,8.0,0\n"


def station_course(tmp_path: Path, csv_text: str) -> str:
    (tmp_path / "st.csv").write_text(csv_text)
    return MINIMAL.replace(
        "north: {type: uniform, tws_kn: 10, twd_deg: 0}", "st: {type: stations, path: st.csv}"
    )


def test_station_csv_with_a_stray_quote(tmp_path):
    text = STATIONS_HEAD + ROW.format(m=0) + '2024-05-01T10:01:00Z,A,45.004,13.001,4.10,"61\n'
    msg = plan_error(tmp_path, station_course(tmp_path, text + ROW.format(m=2)))
    assert msg.endswith(
        "st.csv, line 3: cannot split the line into fields (unexpected end of "
        'data); check its quotes: a field that starts with " must end with " '
        "before the next ','"
    )


def test_large_station_csv_with_a_stray_quote(tmp_path):
    # was "_csv.Error: field larger than field limit": the quote swallowed the file
    text = (
        STATIONS_HEAD
        + '2024-05-01T09:59:00Z,A,45.004,13.001,4.10,"61\n'
        + "".join(ROW.format(m=m % 60) for m in range(20_000))
    )
    msg = plan_error(tmp_path, station_course(tmp_path, text))
    assert msg.endswith(
        "st.csv, line 2: cannot split the line into fields (unexpected end of "
        'data); check its quotes: a field that starts with " must end with " '
        "before the next ','"
    )


def test_track_and_polar_csv_with_a_stray_quote(tmp_path):
    track = tmp_path / "t.csv"
    track.write_text(
        'time,lat,lon\n2024-05-01T10:00:00Z,45.0,13.0\n2024-05-01T10:00:01Z,45.0,"13.0001\n' * 2000
    )
    with pytest.raises(InputError, match=r"t.csv, line 3: cannot split the line into fields"):
        read_track(track)
    polar = tmp_path / "p.csv"
    polar.write_text('tws_kn,twa_deg,speed_kn\n6,40,"3.1\n' + "6,50,3.3\n" * 30_000)
    with pytest.raises(InputError, match=r"p.csv, line 2: cannot split the line into fields"):
        read_polar(polar)


def test_quoted_fields_still_read():
    rows = csv_rows([(1, 'a,"b,c",d'), (2, '"x ""y""",2,3')], ",", "f.csv")
    assert rows == [["a", "b,c", "d"], ['x "y"', "2", "3"]]


# ------------------------------------------------------------------ file contents (16)
PASSWD = (
    "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n"
    "secret:x:1000:1000:Secret Person,,,:/home/secret:/bin/bash\n"
)


def test_a_file_of_another_kind_is_not_printed(tmp_path):
    msg = plan_error(tmp_path, station_course(tmp_path, PASSWD))
    assert msg.endswith(
        "st.csv: not a station CSV: line 1 is not a header of column names; "
        "expected a header row such as time,station,lat,lon,speed_kn,direction "
        "(names and aliases: docs/course-format.md)"
    )
    for word in ("root:x", "daemon", "Secret Person", "/bin/bash"):
        assert word not in msg
    track = tmp_path / "passwd"
    track.write_text(PASSWD)
    with pytest.raises(InputError) as exc:
        read_track(track)
    assert "not a track: line 1 is not a header of column names" in str(exc.value)
    assert "root:x" not in str(exc.value) and "Secret" not in str(exc.value)


def test_a_binary_file_is_not_printed(tmp_path):
    blob = tmp_path / "st.csv"
    blob.write_bytes(b"\x7fELF\x02\x01\x01\x00" + bytes(range(256)) * 8)
    with pytest.raises(
        InputError,
        match=r"st.csv: not a text file \(binary content\)$|"
        r"st.csv: not a text file \(binary content\); expected a station CSV",
    ):
        read_stations(blob)
    with pytest.raises(InputError, match=r"not a text file \(binary content\); expected a GPX"):
        read_track(blob)


def test_a_csv_header_is_quoted_short_and_clean(tmp_path):
    p = tmp_path / "st.csv"
    p.write_text(
        "time,station,lat,lon,spd,dir" + ",x" * 200 + "\n"
        "2024-05-01T10:00:00Z,A,45,13,8,0" + ",1" * 200 + "\n"
    )
    with pytest.raises(InputError) as exc:
        read_stations(p)
    msg = str(exc.value)
    assert "; header is time, station, lat, lon, spd, dir, x, x, " in msg
    quoted = msg.split("; header is ")[1].split(". Rename")[0]
    assert len(quoted) == 120 and quoted.endswith("...")


def test_excerpt_and_header_test():
    assert excerpt("a\x00b\tc\ufffd" + "x" * 100, 10) == "a?b?c?x..."
    assert looks_like_header(["time", "lat", "lon", "speed_kn"])
    assert looks_like_header(["Wind Speed (m/s)", "TWD [°]"])
    assert not looks_like_header(["root:x:0:0:root:/root:/bin/bash"])
    assert not looks_like_header(["a sentence, with a comma; and more: text"] * 2)


# ------------------------------------------------------------------ writers (11, 17)
def evil_plan(name: str, scenario: str):
    """The report tests' routed course, with ``name`` and ``scenario`` as given (the API
    path: no YAML reader between the strings and the writers)."""
    course = dataclasses.replace(course_from_mapping(COURSE), name=name)
    wind = UniformWind(5.0, 0.0)
    t0 = course.start_epoch
    r1 = make_leg_result(timed_track([(-50, 0), (-550, 500), (0, 1000)], t0, wind), "test")
    r2 = make_leg_result(timed_track([(0, 1000), (200, 600), (10, 200)], r1.t_end, wind), "t")
    r3 = make_leg_result(timed_track([(10, 200), (320, 100)], r2.t_end, wind), "test")
    return make_plan(course, scenario, [r1, r2, r3], wind), wind


def test_gpx_and_csv_writers_carry_no_control_characters(tmp_path):
    plan, _ = evil_plan("a\x00b\x1bc", "s\x07")
    gpx = write_gpx(tmp_path / "route.gpx", plan)
    root = ET.parse(gpx).getroot()  # well-formed XML (a NUL made it fail)
    names = [e.text for e in root.iter("{http://www.topografix.com/GPX/1/1}name")]
    assert "a\ufffdb\ufffdc - s\ufffd" in names
    text = write_track_csv(tmp_path / "track.csv", plan).read_text()
    assert not any(c in text for c in "\x00\x07\x1b")
    buf = io.StringIO()
    CleanCsvWriter(buf).writerow(["x\x00y", 1.5, "\ud800"])
    assert buf.getvalue() == "x\ufffdy,1.5,\ufffd\r\n"
    assert list(csv.reader(io.StringIO(buf.getvalue()))) == [["x\ufffdy", "1.5", "\ufffd"]]


def test_report_escapes_every_name_plotly_draws():
    plan, wind = evil_plan("<i>c</i>", "<b>s%{x}</b>")
    fig = figure(plan_report(plan, wind))
    for trace in fig["data"]:
        for key in ("name", "hovertemplate"):
            value = trace.get(key, "")
            # markup of plotly's own (<b>, <br>, <extra>) is in the templates; the names
            # inside are escaped, and % of a name cannot start a placeholder
            assert "<b>s" not in value and "s%{x}" not in value, (key, value)
        for label in trace.get("text", []) if isinstance(trace.get("text"), list) else []:
            assert "<" not in label
    boat = [t for t in fig["data"] if t["name"].startswith("boat: ")]
    assert boat and boat[0]["name"] == "boat: route: &lt;b&gt;s&#37;{x}&lt;/b&gt;"
    assert json.dumps(fig)  # plain JSON


def test_names_read_from_files_are_cleaned(tmp_path):
    p = tmp_path / "st.csv"
    p.write_text(STATIONS_HEAD + "2024-05-01T10:00:00Z,A\x01B,45,13,8,0\n")
    assert read_stations(p).stations == ("A\ufffdB",)
    assert clean_text("ok\tok\n") == "ok\tok\n"


# ------------------------------------------------------------------ NetCDF 1 x 1 (24)
def write_grid(path: Path, ny: int, nx: int) -> None:
    import netCDF4

    with netCDF4.Dataset(path, "w") as ds:
        ds.createDimension("time", 3)
        ds.createDimension("latitude", ny)
        ds.createDimension("longitude", nx)
        for name, dim, units, values in (
            ("time", "time", "hours since 2024-05-01 09:00:00", [0.0, 1.0, 2.0]),
            ("latitude", "latitude", "degrees_north", 45.004 + 0.01 * np.arange(ny)),
            ("longitude", "longitude", "degrees_east", 13.001 + 0.01 * np.arange(nx)),
        ):
            v = ds.createVariable(name, "f8", (dim,))
            v.units, v.standard_name = units, name
            v[:] = values
        for name, std, value in (("u10", "eastward_wind", 0.0), ("v10", "northward_wind", -5.0)):
            v = ds.createVariable(name, "f4", ("time", "latitude", "longitude"))
            v.units, v.standard_name = "m s-1", std
            v[:] = value


@pytest.mark.filterwarnings("error")  # numpy's "Mean of empty slice" was printed
@pytest.mark.parametrize(("ny", "nx"), [(1, 1), (1, 4)])
def test_one_point_grid_is_refused_before_any_arithmetic(tmp_path, ny, nx):
    write_grid(tmp_path / "g.nc", ny, nx)
    text = MINIMAL.replace(
        "north: {type: uniform, tws_kn: 10, twd_deg: 0}", "grid: {type: netcdf, path: g.nc}"
    )
    msg = plan_error(tmp_path, text)
    assert (
        f"g.nc: the wind grid has {ny} x {nx} points (rows x columns); a gridded wind "
        "field needs at least 2 x 2 to interpolate between them" in msg
    )
    assert "nan" not in msg


# ------------------------------------------------------------------ found by the fuzz test
@pytest.mark.parametrize("digits", [400, 5000])
def test_integer_too_long_for_a_float(tmp_path, digits):
    msg = plan_error(tmp_path, MINIMAL.replace("pin: {lat: 45.0000", f"pin: {{lat: {'9' * digits}"))
    assert ":4: marks.pin.lat: expected a latitude in [-90, 90] degrees; got " in msg
    assert len(msg) < 300


def test_template_length_below_a_metre(tmp_path):
    text = (
        "name: t\nstart_time: 2024-05-01T10:00:00Z\ntemplate: {type: windward-leeward, "
        "twd_deg: 0, leg_length_m: 2.2e-313, centre: {lat: 45, lon: 13}}\n"
        "scenarios:\n  north: {type: uniform, tws_kn: 10, twd_deg: 0}\n"
    )
    assert plan_error(tmp_path, text).endswith(
        ":3: template.leg_length_m: expected at least 1 m; got 2.2e-313"
    )


def grid_course(tmp_path: Path, **overrides: object) -> str:
    kw: dict[str, object] = {
        "lat": 45.004 + 0.01 * np.arange(2),
        "lon": 13.001 + 0.01 * np.arange(2),
        "hours": [0.0, 1.0, 2.0],
        "u": np.zeros((3, 2, 2)),
        "v": np.full((3, 2, 2), -5.0),
    }
    kw.update(overrides)
    from tests.unit.test_fuzz_inputs import write_grid as write_cf_grid

    write_cf_grid(
        tmp_path / "g.nc", "NETCDF3_CLASSIC", kw["lat"], kw["lon"], kw["hours"], kw["u"], kw["v"]
    )
    return MINIMAL.replace(
        "north: {type: uniform, tws_kn: 10, twd_deg: 0}",
        "grid: {type: netcdf, path: g.nc, clamp: true}",
    )


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize(
    ("overrides", "expected"),
    [
        (
            {"hours": [0.0, np.nan, 2.0]},
            "time variable time has 1 missing or non-finite value(s) "
            "(the first at index 1); every time step needs its time",
        ),
        (
            {"u": np.full((3, 2, 2), np.inf)},
            "u10 and v10 give a wind of inf m/s; expected at most 500 m/s",
        ),
        (
            {"u": np.full((3, 2, 2), 9999.0)},
            "give a wind of 9999 m/s; expected at most 500 m/s "
            "(check speed_unit; a value that marks missing data "
            "needs the variable's _FillValue",
        ),
        ({"lon": [13.0, 573.0]}, "longitude has values outside [-180, 360] degrees (13 .. 573)"),
    ],
)
def test_grid_numbers_that_cannot_be_wind(tmp_path, overrides, expected):
    assert expected in plan_error(tmp_path, grid_course(tmp_path, **overrides))


def test_damaged_classic_netcdf_header(tmp_path):
    text = grid_course(tmp_path)
    data = bytearray((tmp_path / "g.nc").read_bytes())
    data[8:12] = b"\x00\x00\x00\x0a"  # the dimension list ...
    data[12:16] = b"\x7f\xff\xff\xff"  # ... claims 2**31 - 1 dimensions
    (tmp_path / "g.nc").write_bytes(bytes(data))
    msg = plan_error(tmp_path, text)
    assert (
        "g.nc: damaged NetCDF file: it lists 2147483647 items at offset 16, more than the "
        "file holds; expected a complete classic NetCDF file" in msg
    )


def test_polar_and_track_numbers_past_a_float(tmp_path):
    orc = json.loads((TESTS_DATA / "boat" / "BUL_BUL7888.json").read_text())
    orc["vpp"]["speeds"][0] = int("9" * 400)
    p = tmp_path / "orc.json"
    p.write_text(json.dumps(orc))
    with pytest.raises(InputError, match=r"orc.json: not an ORC certificate polar.*OverflowError"):
        read_polar(p)
    t = tmp_path / "t.csv"
    t.write_text(
        "time,lat,lon,cog\n2024-05-01T10:00:00Z,45,13,1e309\n2024-05-01T10:00:01Z,45,13.0001,10\n"
    )
    with pytest.raises(
        InputError,
        match=r"t.csv, line 2, column 'cog': '1e309' is not a finite "
        r"number; replace it with a value or a missing marker",
    ):
        read_track(t)
