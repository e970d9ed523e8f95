"""Polar sanity through the CLI: bad polars and wind above the polar exit 2 with a message
(never a traceback); ``allow_extrapolation`` warns once; the shipped courses pass the check."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.course.load import build_specs, load_course
from sailroute.planning.route import check_boat_and_winds
from tests.conftest import COURSES, TESTS_DATA

runner = CliRunner()

COURSE = """\
name: polar sanity
start_time: "2024-06-01T14:00:00+02:00"
template:
  type: windward-leeward
  centre: {{lat: 43.07, lon: 6.2}}
  twd_deg: 270
  leg_length_m: 400
  laps: 1
  gate_width_m: 40
  start_line_length_m: 80
  finish: leeward
boat: {boat}
scenarios:
  s: {{type: uniform, tws_kn: {tws_kn}, twd_deg: 270}}
"""
POL = "TWA\\TWS\t6\t12\t20\n45\t4\t5.5\t6\n90\t5\t6.5\t7.5\n150\t4.5\t6\t8\n"


def course_file(tmp_path: Path, boat: str = "{builtin: ilca7}", tws_kn: float = 10) -> Path:
    path = tmp_path / "c.yaml"
    path.write_text(COURSE.format(boat=boat, tws_kn=tws_kn))
    return path


def plan(tmp_path: Path, course: Path):
    res = runner.invoke(
        app, ["plan", str(course), "--no-plots", "-q", "--out", str(tmp_path / "out")]
    )
    assert "Traceback" not in res.output
    return res


def orc_file(tmp_path: Path, old: str, new: str) -> str:
    raw = json.dumps(json.loads((TESTS_DATA / "boat" / "ITA_ITA455J70.json").read_text()))
    assert old in raw
    (tmp_path / "orc.json").write_text(raw.replace(old, new, 1))
    return "orc.json"


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        (
            "tiny.pol",
            POL.replace("\n45\t", "\n1e-320\t"),
            "tiny.pol:2: cell 1: TWA 0.0 and 1e-320 deg are closer than 1e-06 deg",
        ),
        (
            "fast.pol",
            POL.replace("\t6.5\t", "\t1e300\t"),
            "fast.pol:3: cell 3: boat speed 1e+300 kn",
        ),
        ("zero.pol", "TWA\\TWS\t6\t12\n45\t0\t0\n90\t0\t0\n", "zero.pol: this polar has no speed"),
        (
            "f50.kph.csv",
            "TWA/TWS,18,36\n60,30,60\n120,40,80\n",
            "speed_unit='kn' says the boat speed unit is 'kn' but the file name 'f50.kph.csv' says "
            "'km/h'",
        ),
    ],
)
def test_bad_polar_file_exits_2_with_the_file_and_line(tmp_path, name, text, message):
    (tmp_path / name).write_text(text)
    unit = ", speed_unit: kn" if name.endswith(".kph.csv") else ""
    res = plan(tmp_path, course_file(tmp_path, f"{{polar: {name}{unit}}}"))
    assert res.exit_code == 2, res.output
    assert message in res.output


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            '"beat_angle": [43.6',
            '"beat_angle": [1e400',
            "orc.json: vpp.beat_angle[0]: expected an angle in (0, 90) deg; got inf",
        ),
        (
            '"beat_angle": [43.6',
            '"beat_angle": [Infinity',
            "orc.json: vpp.beat_angle[0]: expected an angle in (0, 90) deg; got inf",
        ),
        (
            '"angles": [52',
            '"angles": [-Infinity',
            "orc.json: vpp.angles[0]: expected an angle in [0, 180] deg; got -inf",
        ),
    ],
)
def test_orc_non_finite_values_exit_2(tmp_path, old, new, message):
    name = orc_file(tmp_path, old, new)
    res = plan(tmp_path, course_file(tmp_path, f"{{polar: {name}}}"))
    assert res.exit_code == 2, res.output
    assert message in res.output


def test_wind_above_the_polar_exits_2_and_allow_extrapolation_warns_once(tmp_path):
    res = plan(tmp_path, course_file(tmp_path, tws_kn=35))
    assert res.exit_code == 2
    assert "c.yaml:14: scenarios.s: the wind reaches 18.0 m/s (35.0 kn)" in res.output
    assert "allow_extrapolation: true" in res.output
    assert not (tmp_path / "out").exists()
    res = plan(
        tmp_path, course_file(tmp_path, "{builtin: ilca7, allow_extrapolation: true}", tws_kn=35)
    )
    assert res.exit_code == 0, res.output
    assert res.output.count("warning:") == 1  # printed once, even with -q
    assert "35.0 kn" in res.output and (tmp_path / "out" / "plan.json").is_file()


@pytest.mark.cli
def test_denormal_twa_through_the_console_script_has_no_traceback(tmp_path):
    exe = shutil.which("sailroute", path=str(Path(sys.executable).parent))
    assert exe is not None
    (tmp_path / "tiny.pol").write_text(POL.replace("\n45\t", "\n1e-320\t"))
    course = course_file(tmp_path, "{polar: tiny.pol}")
    proc = subprocess.run(
        [exe, "plan", str(course), "--no-plots", "-q"], cwd=tmp_path, capture_output=True, text=True
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert "closer than 1e-06 deg" in proc.stderr


@pytest.mark.parametrize("course", sorted(COURSES.glob("*.yaml")), ids=lambda p: p.stem)
def test_shipped_courses_pass_the_check_in_every_scenario(course):
    c = load_course(course)
    boat, winds = build_specs(c)
    assert check_boat_and_winds(c, boat, winds) == {}
