"""Course import, ``live-convert``, ``live``, ``analyze``, ``plan --ensemble``, ``start`` and
``vpp`` under hostile or careless input.

Each case was an internal error (exit 1, "this is a bug"), unbounded memory, a silent
wrong result, a file written where it must not be, or a message naming the wrong file,
before these surfaces were hardened.  Every refusal here is checked the same way
(:func:`refused`): exit 2, one ``error:`` line on stderr naming the input, no traceback,
and no file created, changed or removed anywhere in the test's folder.
"""

from __future__ import annotations

import json
import os
import re
import time
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute import outdir
from sailroute.bands.members import MAX_ENSEMBLE_BYTES, draw_members
from sailroute.cli import app
from sailroute.course.formats import read_course_source
from sailroute.course.load import course_from_mapping, load_course
from sailroute.course.uncertainty import UncertaintySpec
from sailroute.errors import InputError
from sailroute.live.decode import NmeaDecoder, SignalKDecoder
from sailroute.nmea import frame
from sailroute.routing.rings import _pairs_hit, ring_crossing, ring_problem
from sailroute.timeutil import FIRST_YEAR, LAST_YEAR, parse_local_time, parse_time
from sailroute.yamlfile import parse_yaml
from tests.conftest import TESTS_DATA
from tests.course.test_area_errors import RACE as RACE_WITH_LIMITS

runner = CliRunner()
MINIMAL = (TESTS_DATA / "course" / "minimal.yaml").read_text()
TALLINN_NMEA = TESTS_DATA / "live" / "tallinn-2023-09-27.nmea"
WIND = ["--wind-twd", "0", "--wind-tws", "10"]
T0 = "2024-05-01T10:00:00Z"
LATE = "9999-12-31T23:59:59-12:00"
EARLY = "0001-01-01T00:00:00+13:00"
RACE = RACE_WITH_LIMITS.replace("LIMITS", "")  # start 2024-05-01T12:00:00+02:00
RACE_START = "2024-05-01T12:00:00+02:00"
MARKS_CSV = "name,lat,lon,type\npin,45.0,13.0,mark\ntop,45.009,13.001,\n"
LOG_HEADER = (
    "datetime_local,ts_s,bs_kn,awa_deg,aws_kn,hdg_deg,twa_deg,tws_kn,twd_deg,sog_kn,cog_deg,"
    "lat,lon\n"
)
LOG_ROW = "2018-02-15T10:34:58,2614,0.15,144,3.91,280,145,4.03,65,0.03,273,45.5509283,13.6418850\n"


def snapshot(folder: Path) -> dict[str, bytes | str]:
    """Every file (its bytes) and symbolic link (its target) under ``folder``."""
    out: dict[str, bytes | str] = {}
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder).as_posix()
        if p.is_symlink():
            out[rel] = "-> " + os.readlink(p)
        elif p.is_file():
            out[rel] = p.read_bytes()
        else:
            out[rel] = "folder"
    return out


def refused(folder: Path, args: list[str], code: int = 2) -> str:
    """Run the command; assert exit ``code``, one ``error:`` line on stderr, no traceback
    and nothing written under ``folder``; return the message."""
    before = snapshot(folder)
    res = runner.invoke(app, args)
    assert res.exit_code == code, res.output
    assert res.stderr.startswith("error: ") and res.stderr.count("\n") == 1, res.stderr
    assert "Traceback" not in res.output and "internal error" not in res.output
    assert snapshot(folder) == before
    return res.stderr.removeprefix("error: ").rstrip("\n")


def files(folder: Path, **contents: str | bytes) -> Path:
    for name, text in contents.items():
        p = folder / name
        p.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(text, bytes):
            p.write_bytes(text)
        else:
            p.write_text(text, encoding="utf-8")
    return folder


def import_args(src: Path, out: Path, *extra: str) -> list[str]:
    return ["course", "import", str(src), "-o", str(out), *WIND, *extra]


# ------------------------------------------------------------------ times out of the calendar
@pytest.mark.parametrize("stamp", [LATE, EARLY])
def test_the_time_parser_refuses_times_near_the_calendar_ends(stamp):
    for parse in (parse_time, parse_local_time):
        with pytest.raises(InputError) as exc:
            parse(stamp, where="--x")
        assert str(exc.value) == (
            f"--x: time {stamp} is outside the years {FIRST_YEAR}-{LAST_YEAR} (UTC); check the date"
        )
    assert parse_time(f"{FIRST_YEAR}-01-01T00:00:00Z").year == FIRST_YEAR
    assert parse_time(f"{LAST_YEAR}-12-31T13:00:00-10:00").year == LAST_YEAR


@pytest.mark.parametrize("stamp", [LATE, EARLY])
def test_every_command_that_reads_a_time_refuses_them(tmp_path, stamp):
    files(tmp_path, **{"c.yaml": MINIMAL, "m.csv": MARKS_CSV, "log.csv": LOG_HEADER + LOG_ROW})
    years = f"outside the years {FIRST_YEAR}-{LAST_YEAR} (UTC)"
    c = str(tmp_path / "c.yaml")
    msg = refused(tmp_path, ["start", c, "--time", stamp, "--xy", "0,-100", "-o", f"{c}.o"])
    assert msg.startswith(f"--time: time {stamp} is {years}")
    bad = files(tmp_path / "bad", **{"c.yaml": MINIMAL.replace("2024-05-01T10:00:00Z", stamp)})
    msg = refused(tmp_path, ["plan", str(bad / "c.yaml"), "-q", "--no-plots", "-o", f"{c}.o"])
    assert msg.startswith(f"{bad / 'c.yaml'}:2: start_time: time {stamp} is {years}")
    msg = refused(
        tmp_path,
        import_args(tmp_path / "m.csv", tmp_path / "i.yaml", "--start-time", stamp),
    )
    assert msg.startswith(f"--start-time: time {stamp} is {years}")
    xml = files(tmp_path / "x", **{"r.xml": RACE.replace(RACE_START, stamp)})
    msg = refused(tmp_path, import_args(xml / "r.xml", tmp_path / "i.yaml"))
    assert msg.startswith(f"{xml / 'r.xml'}: line 4: RaceStartTime Start: time {stamp} is {years}")
    args = ["analyze", c, str(tmp_path / "t.gpx"), "-q", "-o", f"{c}.o"]
    msg = refused(tmp_path, [*args, "--leg-times", f"{stamp},-,-"])
    assert msg.startswith(f"--leg-times: time {stamp} is {years}")
    log = str(tmp_path / "log.csv")
    for option in ("--from", "--to"):
        args = ["live-convert", log, "--format", "trieste", "-o", f"{log}.nmea", option, stamp]
        assert refused(tmp_path, args).startswith(f"{option}: time {stamp} is {years}")
    row = LOG_ROW.replace("2018-02-15T10:34:58", stamp)
    files(tmp_path, **{"late.csv": LOG_HEADER + row})
    args = ["live-convert", str(tmp_path / "late.csv"), "--format", "trieste", "-o", f"{log}.n"]
    assert refused(tmp_path, args).startswith(f"{tmp_path / 'late.csv'}:2: time {stamp} is {years}")


# ------------------------------------------------------------------ course import: XML
def test_kml_nested_1100_folders_deep(tmp_path):
    kml = (
        "<kml><Document>"
        + "<Folder>" * 1100
        + "<Placemark><name>a</name><Point><coordinates>13,45</coordinates></Point></Placemark>"
        + "</Folder>" * 1100
        + "</Document></kml>"
    )
    files(tmp_path, **{"c.kml": kml})
    msg = refused(
        tmp_path, import_args(tmp_path / "c.kml", tmp_path / "c.yaml", "--start-time", T0)
    )
    assert msg == (
        f"{tmp_path / 'c.kml'}: line 1: elements nested more than 100 levels deep; "
        "expected a KML file (a course needs a few levels)"
    )


@pytest.mark.parametrize(
    ("tag", "line", "within"),
    [("Corner", 16, "<CompoundMarkSequence>"), ("Mark", 8, "CompoundMark '1'")],
)
def test_race_xml_with_two_elements_of_one_seqid(tmp_path, tag, line, within):
    files(tmp_path, **{"r.xml": RACE.replace(f'<{tag} SeqID="2"', f'<{tag} SeqID="1"')})
    msg = refused(tmp_path, import_args(tmp_path / "r.xml", tmp_path / "c.yaml"))
    assert msg == (
        f"{tmp_path / 'r.xml'}: line {line}: <{tag}> SeqID=1 again (also at line {line - 1}) "
        f"in {within}; expected each SeqID once (they give the order)"
    )


def test_race_xml_without_compound_marks(tmp_path):
    text = re.sub(r"<Course>.*</Course>", "<Course></Course>", RACE, flags=re.S)
    files(tmp_path, **{"r.xml": text})
    msg = refused(tmp_path, import_args(tmp_path / "r.xml", tmp_path / "c.yaml"))
    assert msg == (
        f"{tmp_path / 'r.xml'}: line 5: <Course> holds no <CompoundMark>; expected the "
        "course's marks, each in a <CompoundMark>"
    )


def test_race_start_time_in_lower_case_z_is_utc(tmp_path):
    files(tmp_path, **{"r.xml": RACE.replace(RACE_START, "2024-05-01T10:00:00z")})
    res = runner.invoke(app, import_args(tmp_path / "r.xml", tmp_path / "c.yaml"))
    assert res.exit_code == 0, res.output
    course = load_course(tmp_path / "c.yaml")
    assert course.start_time == parse_time("2024-05-01T10:00:00Z") and course.utc_offset_s == 0


@pytest.mark.parametrize(
    ("encoding", "why"),
    [("rot13", "'rot13' is not a text encoding"), ("UTF-7", "multi-byte encodings")],
)
def test_xml_declaring_an_encoding_expat_cannot_read(tmp_path, encoding, why):
    files(tmp_path, **{"r.xml": RACE.replace('encoding="utf-8"', f'encoding="{encoding}"')})
    msg = refused(tmp_path, import_args(tmp_path / "r.xml", tmp_path / "c.yaml"))
    assert msg.startswith(
        f"{tmp_path / 'r.xml'}: line 1: cannot read the encoding {encoding!r} the XML "
        "declaration names ("
    )
    assert why in msg and msg.endswith("in UTF-8 (save it as UTF-8)")


# ------------------------------------------------------------------ course import: --boat
def test_boat_mapping_nested_5000_deep(tmp_path):
    files(tmp_path, **{"r.xml": RACE})
    boat = "{a: " * 5000 + "1" + "}" * 5000
    msg = refused(tmp_path, import_args(tmp_path / "r.xml", tmp_path / "c.yaml", "--boat", boat))
    assert msg.startswith("--boat '{a: {a: {a:") and len(msg) < 300
    assert "not a YAML mapping (at 1:" in msg and "nested more than 50 levels deep" in msg


@pytest.mark.parametrize(
    ("boat", "message"),
    [
        (
            '{builtin: ilca7, "x\\nboat": {builtin: ilca6}}',
            "the key 'x\\nboat' is not a name; expected keys such as polar, builtin",
        ),
        ("{1: ilca7}", "the key 1 is not a name"),
        ("{builtin: 2024-05-01}", "holds a date, time or binary value"),
        ("{builtin: .nan}", "holds NaN or inf"),
    ],
)
def test_boat_mapping_keys_and_values_cannot_write_yaml(tmp_path, boat, message):
    files(tmp_path, **{"r.xml": RACE})
    msg = refused(tmp_path, import_args(tmp_path / "r.xml", tmp_path / "c.yaml", "--boat", boat))
    assert message in msg


def test_boat_mapping_is_written_with_every_key_quoted(tmp_path):
    files(tmp_path, **{"r.xml": RACE})
    boat = '{builtin: ilca6, interpolation: "linear\\u2028boat: x"}'
    res = runner.invoke(app, import_args(tmp_path / "r.xml", tmp_path / "c.yaml", "--boat", boat))
    assert res.exit_code == 2, res.output  # the boat checks refuse the interpolation...
    assert "--boat: interpolation: expected one of" in res.stderr
    boat = "{builtin: ilca6, interpolation: linear}"
    res = runner.invoke(app, import_args(tmp_path / "r.xml", tmp_path / "c.yaml", "--boat", boat))
    assert res.exit_code == 0, res.output
    text = (tmp_path / "c.yaml").read_text()
    assert '\nboat: {"builtin": "ilca6", "interpolation": "linear"}\n' in text
    assert dict(load_course(tmp_path / "c.yaml").boat_spec) == {
        "builtin": "ilca6",
        "interpolation": "linear",
    }


# ------------------------------------------------------------------ course import: names
def test_a_newline_in_the_imported_file_name_adds_no_key(tmp_path):
    name = "x\nboat: {builtin: ilca6}\ny\u2028z: 1\n#.csv"
    src = tmp_path / name
    src.write_text(MARKS_CSV)
    res = runner.invoke(app, import_args(src, tmp_path / "c.yaml", "--start-time", T0))
    assert res.exit_code == 0, res.output
    text = (tmp_path / "c.yaml").read_text()
    assert text.splitlines()[0] == (
        "# Imported by `sailroute course import` from x?boat: {builtin: ilca6}?y?z: 1?#.csv (csv)."
    )
    doc = parse_yaml(text, "c.yaml").data
    assert set(doc) == {"name", "start_time", "marks", "legs", "scenarios"}  # no boat
    assert doc["name"] == src.stem


def test_names_with_line_breaks_round_trip_and_control_characters_are_refused(tmp_path):
    csv = 'name,lat,lon,type\n"a\u2028b",45.0,13.0,mark\n"c\u2029d",45.009,13.001,\n'
    files(tmp_path, **{"m.csv": csv})
    res = runner.invoke(
        app, import_args(tmp_path / "m.csv", tmp_path / "c.yaml", "--start-time", T0)
    )
    assert res.exit_code == 0, res.output
    course = load_course(tmp_path / "c.yaml")
    assert set(course.marks) == {"a\u2028b", "c\u2029d"}  # one row each, names intact
    assert [(leg.from_name, leg.to_name) for leg in course.legs] == [("a\u2028b", "c\u2029d")]
    files(tmp_path / "g", **{"c.csv": MARKS_CSV.replace("top", "to\x01p")})
    msg = refused(
        tmp_path, import_args(tmp_path / "g" / "c.csv", tmp_path / "g.yaml", "--start-time", T0)
    )
    assert msg == (
        f"{tmp_path / 'g' / 'c.csv'}, line 3: the mark name 'to\\x01p' holds U+0001 (a "
        "control character), which no output file can carry; remove it"
    )


# ------------------------------------------------------------------ course import: drafts
def test_a_symlink_at_the_old_draft_name_is_never_written_through(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("not sailroute's")
    files(tmp_path, **{"m.csv": MARKS_CSV, "bad.csv": MARKS_CSV.replace("top", "pin")})
    (tmp_path / ".c.yaml.sailroute-tmp").symlink_to(victim)
    for src, code in (("bad.csv", 2), ("m.csv", 0)):
        res = runner.invoke(
            app, import_args(tmp_path / src, tmp_path / "c.yaml", "--start-time", T0)
        )
        assert res.exit_code == code, res.output
        assert victim.read_text() == "not sailroute's"
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        ".c.yaml.sailroute-tmp",
        "bad.csv",
        "c.yaml",
        "m.csv",
        "victim.txt",
    ]
    assert (tmp_path / ".c.yaml.sailroute-tmp").is_symlink()


def test_the_draft_is_created_exclusively_and_not_through_a_link(tmp_path, monkeypatch):
    victim = tmp_path / "victim.txt"
    victim.write_text("not sailroute's")
    monkeypatch.setattr(outdir.secrets, "token_hex", lambda n: "guessed")
    draft = tmp_path / ".out.txt.guessed.sailroute-tmp"
    draft.symlink_to(victim)
    with (
        pytest.raises(
            InputError, match=r"-o .*out.txt: cannot create a file in .* \(File exists\)"
        ),
        outdir.replacing(tmp_path / "out.txt") as fh,
    ):
        fh.write("x")
    assert victim.read_text() == "not sailroute's" and not (tmp_path / "out.txt").exists()
    draft.unlink()
    with pytest.raises(RuntimeError), outdir.replacing(tmp_path / "out.txt") as fh:
        fh.write("half")
        raise RuntimeError
    assert sorted(p.name for p in tmp_path.iterdir()) == ["victim.txt"]  # no draft left


def test_errors_found_after_composing_name_the_source_and_its_line(tmp_path):
    files(tmp_path, **{"same.csv": "name,lat,lon,type\na,45,13,mark\na,45,13,\nb,45.01,13,\n"})
    msg = refused(
        tmp_path, import_args(tmp_path / "same.csv", tmp_path / "c.yaml", "--start-time", T0)
    )
    assert msg == (
        f"{tmp_path / 'same.csv'}:3: legs[0].to: 'a' is where the leg starts; a leg must "
        "go to a different mark, gate or line"
    )
    files(tmp_path, **{"m.csv": MARKS_CSV})
    msg = refused(
        tmp_path,
        import_args(
            tmp_path / "m.csv", tmp_path / "c.yaml", "--start-time", T0, "--boat", "ilca99"
        ),
    )
    assert msg.startswith("--boat: builtin: expected one of 'ilca4'")
    assert msg.endswith("got 'ilca99' (did you mean 'ilca7'?)")


def test_the_output_may_not_be_an_input(tmp_path):
    files(
        tmp_path, **{"m.yaml": MARKS_CSV, "p.yaml": "TWA\\TWS\t6\t10\n45\t3.5\t4.5\n90\t4.5\t5.5\n"}
    )
    (tmp_path / "link.yaml").symlink_to(tmp_path / "m.yaml")
    for out in ("m.yaml", "link.yaml"):  # the input itself, and a link to it
        args = import_args(tmp_path / "m.yaml", tmp_path / out, "--format", "csv")
        msg = refused(tmp_path, [*args, "--start-time", T0])
        assert msg.startswith(f"-o {tmp_path / out}: the same file as the input")
    files(tmp_path, **{"c.csv": MARKS_CSV})
    msg = refused(
        tmp_path,
        import_args(
            tmp_path / "c.csv",
            tmp_path / "p.yaml",
            "--start-time",
            T0,
            "--boat",
            "{polar: p.yaml}",
        ),
    )
    assert msg.startswith(f"-o {tmp_path / 'p.yaml'}: the same file as the input")


# ------------------------------------------------------------------ course import: GPX types
def test_a_gpx_without_types_is_refused(tmp_path):
    pts = "".join(
        f'<wpt lat="{45 + k * 0.003}" lon="13.0"><name>{n}</name></wpt>\n'
        for k, n in enumerate(["SL1", "SL2", "M1", "LG1", "LG2", "WG1", "FL1"])
    )
    files(tmp_path, **{"c.gpx": f'<?xml version="1.0"?>\n<gpx version="1.1">\n{pts}</gpx>\n'})
    msg = refused(
        tmp_path, import_args(tmp_path / "c.gpx", tmp_path / "c.yaml", "--start-time", T0)
    )
    assert msg == (
        f"{tmp_path / 'c.gpx'}: line 3: no point says what it is (<type> in a GPX file), so "
        "every point would be a mark and the course would start at the mark 'SL1', with no "
        "start line; give the start line's two ends the type start (the finish's finish, "
        "a gate's gate), or the first point the type mark to start the first leg there"
    )
    typed = pts.replace("<name>SL1</name>", "<name>SL1</name><type>mark</type>", 1)
    files(tmp_path, **{"t.gpx": f'<gpx version="1.1">\n{typed}</gpx>\n'})
    res = runner.invoke(
        app, import_args(tmp_path / "t.gpx", tmp_path / "t.yaml", "--start-time", T0)
    )
    assert res.exit_code == 0, res.output
    assert load_course(tmp_path / "t.yaml").n_legs == 6


# ------------------------------------------------------------------ polygons: memory
def _circle(n: int, radius_m: float = 3000.0) -> np.ndarray:
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([radius_m * np.cos(a), radius_m * np.sin(a)])


def test_the_ring_test_is_bounded_in_memory():
    ring = _circle(20_000)
    tracemalloc.start()
    try:
        assert ring_problem(ring) is None
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 64 * 2**20  # the test of every pair took 1.5-7 GB
    bowtie = _circle(2000)
    bowtie[[500, 1500]] = bowtie[[1500, 500]]
    assert ring_crossing(bowtie) == _every_pair(bowtie) == (499, 1500)


def _every_pair(p: np.ndarray) -> tuple[int, int] | None:
    """The first crossing by testing every pair of non-adjacent edges at once."""
    n = p.shape[0]
    i, j = np.triu_indices(n, k=2)
    keep = ~((i == 0) & (j == n - 1))
    hit = np.flatnonzero(_pairs_hit(p, np.roll(p, -1, axis=0), i[keep], j[keep]))
    return None if hit.size == 0 else (int(i[keep][hit[0]]), int(j[keep][hit[0]]))


def test_the_ring_test_finds_the_first_crossing_of_every_pair():
    """Against the test of every pair at once, on small random rings (integer ones have
    touching and collinear edges)."""
    rng = np.random.default_rng(7)
    n_hits = 0
    for k in range(3000):
        n = int(rng.integers(4, 12))
        p = rng.integers(0, 5, (n, 2)).astype(float) if k % 2 else rng.normal(size=(n, 2))
        if np.any(np.all(p == np.roll(p, -1, axis=0), axis=1)):
            continue  # ring_problem refuses a repeated point before
        every = _every_pair(p)
        assert ring_crossing(p) == every, p
        n_hits += every is not None
    assert 500 < n_hits < 2900  # both outcomes are tested


def test_a_kml_polygon_of_20000_points_imports_in_bounded_memory(tmp_path):
    lat = 45.005 + 0.05 * np.sin(np.linspace(0, 2 * np.pi, 20_000, endpoint=False))
    lon = 13.001 + 0.07 * np.cos(np.linspace(0, 2 * np.pi, 20_000, endpoint=False))
    coords = " ".join(f"{b:.7f},{a:.7f}" for a, b in zip(lat, lon, strict=True))
    files(
        tmp_path,
        **{
            "c.kml": "<kml><Document>"
            '<Placemark><name>a</name><ExtendedData><Data name="type"><value>mark</value>'
            "</Data></ExtendedData><Point><coordinates>13.0,45.0</coordinates></Point></Placemark>"
            "<Placemark><name>b</name><Point><coordinates>13.002,45.009</coordinates></Point>"
            "</Placemark><Placemark><name>boundary</name><Polygon><outerBoundaryIs><LinearRing>"
            f"<coordinates>{coords}</coordinates></LinearRing></outerBoundaryIs></Polygon>"
            "</Placemark></Document></kml>"
        },
    )
    tracemalloc.start()
    try:
        ic, _ = read_course_source(tmp_path / "c.kml")
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert ic.boundary is not None and len(ic.boundary) == 20_000
    assert peak < 256 * 2**20


@pytest.mark.slow  # some 15 s under tracemalloc: the checks read the points one by one
def test_a_course_boundary_of_15000_points_loads_in_bounded_memory():
    data = parse_yaml(MINIMAL, "minimal.yaml").data
    a = np.linspace(0.0, 2 * np.pi, 15_000, endpoint=False)
    data["boundary"] = {
        "points": [{"lat": 45.0045 + 0.03 * np.sin(k), "lon": 13.001 + 0.04 * np.cos(k)} for k in a]
    }
    tracemalloc.start()
    try:
        course = course_from_mapping(data)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert course.area.boundary is not None and len(course.area.boundary.x) == 15_000
    assert peak < 256 * 2**20  # the test of every pair took gigabytes


# ------------------------------------------------------------------ live-convert
def _convert(log: Path, out: Path, *extra: str, fmt: str = "trieste") -> list[str]:
    return ["live-convert", str(log), "--format", fmt, "-o", str(out), *extra]


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (bytes(range(256)) * 20, "{log}: a binary file; expected the Trieste coach-boat CSV"),
        (
            LOG_HEADER + "2018-02-15T10:34:58," + "1" * 200_000 + "\n",
            "{log}, line 2: a line of 200020 characters, with a field longer than 131072",
        ),
        (
            LOG_HEADER + LOG_ROW.replace("45.5509283", "91"),
            "{log}:2: not a row of the Trieste coach-boat CSV (lat '91' is outside [-90, 90])",
        ),
        (
            LOG_HEADER + LOG_ROW.replace("13.6418850", "1e300"),
            "{log}:2: not a row of the Trieste coach-boat CSV (lon '1e300' is outside [-180, 180])",
        ),
        (
            LOG_HEADER + LOG_ROW.replace(",4.03,", ",1e300,"),
            "{log}:2: not a row of the Trieste coach-boat CSV (tws_kn '1e300' is outside",
        ),
    ],
)
def test_live_convert_refuses_what_it_cannot_write(tmp_path, content, message):
    files(tmp_path, **{"log.csv": content})
    log = tmp_path / "log.csv"
    msg = refused(tmp_path, _convert(log, tmp_path / "x.nmea"))
    assert msg.startswith(message.format(log=log)), msg


@pytest.mark.parametrize(
    ("offset", "message"),
    [
        ("+24:00", "--utc-offset: offset '+24:00' is larger than 14 hours"),
        ("1h", "--utc-offset: '1h' is not a UTC offset; expected e.g. '+01:00'"),
    ],
)
def test_live_convert_utc_offset_out_of_range(tmp_path, offset, message):
    files(tmp_path, **{"log.csv": LOG_HEADER + LOG_ROW})
    msg = refused(
        tmp_path, _convert(tmp_path / "log.csv", tmp_path / "x.nmea", "--utc-offset", offset)
    )
    assert msg.startswith(message)


def test_live_convert_output_checks(tmp_path):
    files(tmp_path, **{"log.csv": LOG_HEADER + LOG_ROW, "sub/keep.txt": "x"})
    log = tmp_path / "log.csv"
    msg = refused(tmp_path, _convert(log, tmp_path / "sub"))
    assert msg == f"-o {tmp_path / 'sub'}: a folder; expected the name of the file to write"
    msg = refused(tmp_path, _convert(log, tmp_path / "no" / "x.nmea"))
    assert msg == (
        f"-o {tmp_path / 'no' / 'x.nmea'}: the folder {tmp_path / 'no'} does not exist; "
        "create it first or choose another"
    )
    msg = refused(tmp_path, _convert(log, log))
    assert msg == (
        f"-o {log}: the same file as the input {log}; writing it would replace the input; "
        "choose another name"
    )


def test_live_convert_keeps_an_offset_the_data_carries(tmp_path):
    row = LOG_ROW.replace("2018-02-15T10:34:58", "2018-02-15T10:34:58+05:00")
    files(tmp_path, **{"log.csv": LOG_HEADER + row})
    log, out = tmp_path / "log.csv", tmp_path / "x.nmea"
    res = runner.invoke(app, _convert(log, out))
    assert res.exit_code == 0, res.output
    assert f"wrote replay (NMEA 0183): {out}" in res.output
    assert out.read_text().startswith("$GPRMC,053458.00,A,")  # 10:34:58+05:00 in UTC
    out.unlink()
    msg = refused(tmp_path, _convert(log, out, "--utc-offset", "+01:00"))
    assert msg == (
        f"{log}:2: the time '2018-02-15T10:34:58+05:00' carries its own UTC offset "
        "(UTC+05:00), not --utc-offset's UTC+01:00; leave --utc-offset out (a time with an "
        "offset keeps it) or correct the file"
    )
    files(tmp_path, **{"naive.csv": LOG_HEADER + LOG_ROW})
    res = runner.invoke(app, _convert(tmp_path / "naive.csv", out, "--utc-offset", "+02:00"))
    assert res.exit_code == 0 and out.read_text().startswith("$GPRMC,083458.00,A,")


# ------------------------------------------------------------------ live
@pytest.mark.parametrize(("option", "value"), [("--port", "70000"), ("--nmea-port", "-1")])
def test_live_ports_out_of_range(tmp_path, option, value):
    files(tmp_path, **{"c.yaml": MINIMAL})
    args = ["live", str(tmp_path / "c.yaml"), "--source", str(TALLINN_NMEA), option, value]
    msg = refused(tmp_path, [*args, "--duration", "1"])
    assert msg == f"{option} {value}: expected a TCP port in 0..65535 (0: any free port)"


def test_decoders_leave_out_positions_off_the_globe_and_numbers_past_a_float():
    nmea = NmeaDecoder()
    assert (
        nmea.feed(frame("GPRMC,094430.00,A,9933.1074,N,01338.5333,E,4.20,37.0,150218,,,A")) is None
    )
    assert nmea.counts.by_kind["malformed"] == 1 and nmea.clock is None  # no clock from it
    ok = nmea.feed(frame("GPRMC,094430.00,A,4533.1074,N,01338.5333,E,4.20,37.0,150218,,,A"))
    assert ok is not None and ok.lat == pytest.approx(45 + 33.1074 / 60)
    sk = SignalKDecoder()
    delta = {
        "updates": [
            {
                "timestamp": "2024-05-01T10:00:01Z",
                "values": [
                    {"path": "navigation.position", "value": {"latitude": 1e20, "longitude": 13}},
                    {"path": "navigation.speedOverGround", "value": 10**400},
                    {"path": "navigation.headingTrue", "value": 0.5},
                ],
            }
        ]
    }
    (r,) = sk.feed(json.dumps(delta))
    assert (r.lat, r.lon, r.sog_ms) == (None, None, None)
    assert r.hdg_deg == pytest.approx(np.degrees(0.5))


def test_signal_k_delta_nested_deep_is_malformed():
    dec = SignalKDecoder()
    assert dec.feed("[" * 100_000 + "]" * 100_000) == []
    assert dec.counts.by_kind["malformed"] == 1


# ------------------------------------------------------------------ analyze
def test_analyze_a_live_log_with_a_deeply_nested_line(tmp_path):
    fix = {"kind": "input", "t": 1714557600.0, "lat": 45.0, "lon": 13.001}
    log = json.dumps(fix) + "\n" + "[" * 100_000 + "]" * 100_000 + "\n"
    files(tmp_path, **{"c.yaml": MINIMAL, "today.jsonl": log})
    msg = refused(
        tmp_path,
        [
            "analyze",
            str(tmp_path / "c.yaml"),
            str(tmp_path / "today.jsonl"),
            "-q",
            "-o",
            str(tmp_path / "o"),
        ],
    )
    assert msg == (
        f"{tmp_path / 'today.jsonl'}: line 2: not a JSON object; a `sailroute live` log has "
        "one JSON object per line"
    )


# ------------------------------------------------------------------ plan --ensemble
@pytest.mark.parametrize("members", ["1000000000", "99999999999999999999999"])
def test_an_ensemble_too_large_is_refused_before_anything_is_drawn(tmp_path, members):
    files(tmp_path, **{"c.yaml": MINIMAL})
    t = time.perf_counter()
    args = ["plan", str(tmp_path / "c.yaml"), "-q", "--no-plots", "-o", str(tmp_path / "o")]
    msg = refused(tmp_path, [*args, "--ensemble", members])
    assert time.perf_counter() - t < 30.0  # was 24 GB and a kill by the kernel
    per = 1024 + 64 * (5400 / 10 + 2) + 2 * 16384  # minimal.yaml: shifts, 90 min, 2 legs
    assert msg == (
        f"{members} members would hold about {int(members) * per / 2**30:.3g} GiB (each its "
        f"shift series and the routes of 2 legs, about {per / 1024:.0f} kiB), more than 1 "
        f"GiB; give at most {int(MAX_ENSEMBLE_BYTES // per)} members (--ensemble N or "
        "uncertainty.members; a band is steady from a few dozen)"
    )


def test_a_wide_relative_speed_spread_has_no_calm_member():
    """``tws_pct: 100``, inside its documented range, drew members with no wind: the
    factor is log-normal, (1 + 1.0) ** z, positive at every z and 1 at the median."""
    spec = UncertaintySpec(tws_rel=1.0, members=50)
    members = draw_members(spec, 3600.0)
    scales = np.array([m.tws_scale for m in members])
    assert scales.min() > 0.05 and np.median(scales) == pytest.approx(1.0, rel=0.1)
    # log-symmetric: a member z sigmas up is the inverse of one z sigmas down
    assert np.log(scales).mean() == pytest.approx(0.0, abs=0.05)
    assert float(np.quantile(scales, 0.8413)) == pytest.approx(2.0, rel=0.15)


@pytest.mark.slow
def test_plan_ensemble_with_a_100_percent_speed_spread_routes(tmp_path):
    files(tmp_path, **{"c.yaml": MINIMAL + "uncertainty: {tws_pct: 100, shifts: null}\n"})
    out = tmp_path / "o"
    res = runner.invoke(
        app,
        ["plan", str(tmp_path / "c.yaml"), "-q", "--no-plots", "-o", str(out), "--ensemble", "3"],
    )
    assert res.exit_code == 0, res.output
    assert (out / "bands.json").is_file()


# ------------------------------------------------------------------ start, vpp, plan -o
def test_start_time_in_seconds_needs_a_sign(tmp_path):
    files(tmp_path, **{"c.yaml": MINIMAL})
    args = ["start", str(tmp_path / "c.yaml"), "--xy", "0,-100", "-o", str(tmp_path / "o")]
    msg = refused(tmp_path, [*args, "--time", "600"])
    assert msg == (
        "--time '600': seconds from the gun need a sign: -600 (600 s before the gun) or "
        "+600 (after it)"
    )
    msg = refused(tmp_path, [*args, "--time", "-1e300"])
    assert msg == "--time '-1e300': expected seconds from the gun within ±86400 (a day), e.g. -90"


def test_start_far_position_prints_a_short_distance(tmp_path):
    files(tmp_path, **{"c.yaml": MINIMAL})
    args = ["start", str(tmp_path / "c.yaml"), "--time", "-60", "-o", str(tmp_path / "o")]
    msg = refused(tmp_path, [*args, "--xy", "1e300,1e300"])
    assert msg.startswith(
        "--xy 1e300,1e300: the position is more than 100 000 km from the course area"
    )
    assert len(msg) < 300


@pytest.mark.parametrize("text", ["", "# nothing set\n", "{}\n"])
def test_vpp_refuses_an_empty_boat_file(tmp_path, text):
    files(tmp_path, **{"b.yaml": text})
    msg = refused(tmp_path, ["vpp", str(tmp_path / "b.yaml"), "-o", str(tmp_path / "o")])
    assert msg.startswith(f"{tmp_path / 'b.yaml'}: the boat file is empty; expected")


def test_plan_out_empty_is_refused(tmp_path, monkeypatch):
    files(tmp_path, **{"c.yaml": MINIMAL, "plan.json": "{}"})
    monkeypatch.chdir(tmp_path)
    msg = refused(tmp_path, ["plan", "c.yaml", "-q", "--no-plots", "-o", ""])
    assert msg == (
        "--out '': an empty folder name; give the output folder (e.g. --out out/run, or "
        "--out . for the working folder)"
    )
