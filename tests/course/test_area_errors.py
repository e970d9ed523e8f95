"""Bad race-area and import input: one line naming the file and the element, from the
library (:class:`~sailroute.errors.InputError`) and from the command line (exit 2, the
same line after ``error:``, nothing written), never a traceback.

The race XML here is a small one written in the test (a start line, one mark and one
``CourseLimit``) in the layout of the SailGP files (``test_course_import.py`` reads the
real ones).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.commands.course_import import run_course_import_command
from sailroute.course.load import load_course
from sailroute.errors import InputError
from tests.course.test_course_area import AREA, write

runner = CliRunner()
WIND = ["--wind-twd", "225", "--wind-tws", "12"]

LIMIT = """  <CourseLimit name="NAME">
POINTS  </CourseLimit>
"""
# a rock 300 m north-east of the start, clear of every mark; its corners in order
ROCK = [(45.0030, 13.0030), (45.0030, 13.0050), (45.0045, 13.0050), (45.0045, 13.0030)]
RACE = """<?xml version="1.0" encoding="utf-8"?>
<Race>
  <RaceID>7</RaceID>
  <RaceStartTime Start="2024-05-01T12:00:00+02:00" Postpone="False" />
  <Course>
    <CompoundMark CompoundMarkID="1" Name="SL">
      <Mark SeqID="1" Name="SL1" TargetLat="45.0000" TargetLng="13.0000" />
      <Mark SeqID="2" Name="SL2" TargetLat="45.0000" TargetLng="13.0015" />
    </CompoundMark>
    <CompoundMark CompoundMarkID="2" Name="M1">
      <Mark SeqID="1" Name="M1" TargetLat="45.0100" TargetLng="13.0008" />
    </CompoundMark>
  </Course>
  <CompoundMarkSequence>
    <Corner SeqID="1" CompoundMarkID="1" Rounding="SP" ZoneSize="3" />
    <Corner SeqID="2" CompoundMarkID="2" Rounding="Port" ZoneSize="3" />
  </CompoundMarkSequence>
LIMITS</Race>
"""


def race_xml(path: Path, ring=ROCK, *, buoy: bool = False) -> Path:
    """The race XML with ``ring`` [(lat, lon)] as the CourseLimit ``Rock``; ``buoy``: a
    ``<Buoy>`` element (unknown) in the compound mark M1."""
    pts = "".join(
        f'    <Limit SeqID="{k + 1}" Lat="{a:.7f}" Lon="{b:.7f}" />\n'
        for k, (a, b) in enumerate(ring)
    )
    text = RACE.replace("LIMITS", LIMIT.replace("NAME", "Rock").replace("POINTS", pts))
    if buoy:
        m1 = '<CompoundMark CompoundMarkID="2" Name="M1">\n'
        text = text.replace(m1, m1 + '      <Buoy Name="M1" />\n', 1)
    path.write_text(text, encoding="utf-8")
    return path


def line_of(path: Path, needle: str) -> int:
    return next(k + 1 for k, ln in enumerate(path.read_text().splitlines()) if needle in ln)


def one_line(msg: str, *parts: str) -> None:
    assert "\n" not in msg.strip(), msg
    assert "Traceback" not in msg
    for p in parts:
        assert p in msg, msg


def cli_fails(args: list[str], *parts: str) -> None:
    res = runner.invoke(app, args)
    assert res.exit_code == 2, res.output
    assert res.output.startswith("error: "), res.output
    one_line(res.output, *parts)


def test_the_synthetic_race_xml_imports(tmp_path):
    """The XML the error cases below break: it imports, with the rock as an obstacle."""
    out = tmp_path / "race.yaml"
    run_course_import_command(
        race_xml(tmp_path / "race.xml"), out=out, wind_twd_deg=225.0, wind_tws_kn=12.0
    )
    course = load_course(out)
    assert [o.name for o in course.area.obstacles] == ["Rock"]
    assert [leg.to_name for leg in course.legs] == ["M1"]


# --------------------------------------------------------------------- race XML import
def _xml_cases(tmp_path: Path) -> list[tuple[Path, tuple[str, ...]]]:
    crossed = [ROCK[0], ROCK[2], ROCK[1], ROCK[3]]  # a bow tie
    bad = race_xml(tmp_path / "crossed.xml", crossed)
    cases = [
        (
            bad,
            (f"{bad}: line {line_of(bad, 'CourseLimit name')}: polygon 'Rock'", "crosses the edge"),
        )
    ]
    buoy = race_xml(tmp_path / "buoy.xml", buoy=True)
    cases.append(
        (
            buoy,
            (
                f"{buoy}: line {line_of(buoy, '<Buoy')}: <Buoy> in CompoundMark '2'",
                "expected <Mark",
            ),
        )
    )
    # the rock moved over M1: refused at its line in the XML, nothing written
    over = [(a + 0.0062, b - 0.0035) for a, b in ROCK]  # 45.0092..45.0107 N
    inside = race_xml(tmp_path / "inside.xml", over)
    where = f"{inside}: line {line_of(inside, 'CourseLimit name')}: polygon 'Rock'"
    cases.append((inside, (where, "holds the mark 'M1'; expected an area to stay out of")))
    empty = tmp_path / "empty.gpx"
    empty.write_text(
        '<?xml version="1.0"?>\n<gpx version="1.1" creator="x" '
        'xmlns="http://www.topografix.com/GPX/1/1">\n<trk/></gpx>\n'
    )
    cases.append((empty, (str(empty), "line 2", "no waypoints (<wpt>)")))
    return cases


CASES = [
    "self-intersecting polygon",
    "unknown element",
    "mark inside an obstacle",
    "GPX without waypoints",
]


@pytest.mark.parametrize("k", range(len(CASES)), ids=CASES)
def test_import_errors_library_and_cli(tmp_path, k):
    src, parts = _xml_cases(tmp_path)[k]
    out = tmp_path / "c.yaml"
    start = ["--start-time", "2024-05-01T12:00:00+02:00"] if src.suffix == ".gpx" else []
    with pytest.raises(InputError) as exc:
        run_course_import_command(
            src,
            out=out,
            wind_twd_deg=225.0,
            wind_tws_kn=12.0,
            start_time=start[1] if start else None,
        )
    one_line(str(exc.value), *parts)
    assert not out.exists()
    cli_fails(["course", "import", str(src), "-o", str(out), *WIND, *start], *parts)
    assert not out.exists()


# ------------------------------------------------------------------ course file: plan
PLAN_CASES = {
    "self-intersecting polygon": (
        AREA.replace("{x: 350, y: 750}, {x: -250, y: 750}", "{x: -250, y: 750}, {x: 350, y: 750}"),
        (
            "c.yaml:",
            "obstacles[0]: expected a simple polygon; its edge from point",
            "crosses the edge",
        ),
    ),
    "boundary does not contain the course": (
        AREA.replace(
            "{x: 600, y: 1800}, {x: -600, y: 1800}", "{x: 600, y: 1490}, {x: -600, y: 1490}"
        ),
        (
            "c.yaml:",
            "boundary: the boundary shrunk by its clearance_m = 20 m does not contain every mark",
            "'top' (0, 1500 m)",
        ),
    ),
    "mark inside an obstacle": (
        AREA.replace(
            "{x: -250, y: 600}, {x: 350, y: 600}, {x: 350, y: 750}, {x: -250, y: 750}",
            "{x: -70, y: -20}, {x: -30, y: -20}, {x: -30, y: 20}, {x: -70, y: 20}",
        ),
        ("c.yaml:", "obstacles[0]: mark 'pin' (-50, 0 m) lies inside obstacle 'breakwater'"),
    ),
}


@pytest.mark.parametrize("case", list(PLAN_CASES))
def test_course_file_area_errors_library_and_cli(tmp_path, case):
    area, parts = PLAN_CASES[case]
    path = write(tmp_path, area)
    with pytest.raises(InputError) as exc:
        load_course(path)
    one_line(str(exc.value), str(path), *parts)
    out = tmp_path / "out"
    cli_fails(["plan", str(path), "-o", str(out), "-q", "--no-plots"], str(path), *parts)
    assert not out.exists() or not any(out.iterdir())
