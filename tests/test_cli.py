"""End-to-end: ``sailroute plan`` and ``compare-scenarios`` on the shipped courses.

Through typer's CliRunner (in process), plus one subprocess run of the installed
console script.  Asserts the leg structure against the course file, that legs are
chained (each starts when the previous ended), that every file is written and
agrees with the others, and that bad input exits 2 with a message and no traceback.
"""

from __future__ import annotations

import csv
import itertools
import json
import shutil
import subprocess
import sys
from datetime import datetime
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.course.load import load_course
from tests.conftest import COURSES, ROOT

runner = CliRunner()
GPX = "{http://www.topografix.com/GPX/1/1}"


def invoke(*args: str):
    res = runner.invoke(app, list(args))
    assert "Traceback" not in res.output
    return res


def iso(text: str) -> float:
    return datetime.fromisoformat(text.replace("Z", "+00:00")).timestamp()


def check_plan_files(out: Path, course_file: Path) -> dict:
    """Files of one plan agree with the course and with each other; returns plan.json."""
    course = load_course(course_file)
    doc = json.loads((out / "plan.json").read_text())
    legs = doc["legs"]
    assert [(leg["from"], leg["to"]) for leg in legs] == [
        (spec.from_name, spec.to_name) for spec in course.legs
    ]
    assert iso(legs[0]["start_time"]) == pytest.approx(course.start_epoch, abs=1e-3)
    for prev, nxt in itertools.pairwise(legs):
        assert nxt["start_time"] == prev["end_time"]
    for leg in legs:
        assert leg["time_s"] > 0 and leg["distance_m"] > 0
        assert iso(leg["end_time"]) - iso(leg["start_time"]) == pytest.approx(
            leg["time_s"], abs=2e-3
        )
    assert doc["total_time_s"] == pytest.approx(sum(leg["time_s"] for leg in legs), abs=0.01)
    with (out / "track.csv").open() as f:
        rows = list(csv.DictReader(f))
    t = [float(r["t_race_s"]) for r in rows]
    assert all(b >= a for a, b in itertools.pairwise(t))  # time never runs back
    assert t[-1] == pytest.approx(doc["total_time_s"], abs=0.01)
    assert {int(r["leg"]) for r in rows} == set(range(1, len(legs) + 1))
    trk = ET.parse(out / "route.gpx").getroot().find(f"{GPX}trk")
    assert trk is not None and len(trk.findall(f"{GPX}trkseg")) == len(legs)
    return doc


def check_report_html(path: Path, doc: dict, course) -> None:
    """report.html agrees with plan.json and track.csv: offline page, the route's points and
    times, the marks, the leg table."""
    from sailroute.report.page import REPEAT_SHIFT, clock
    from sailroute.report.page_render import plotly_js, read_figure
    from sailroute.report.tables import format_duration

    page = path.read_text(encoding="utf-8")
    # plotly.js is one file beside the page, loaded by a relative address (offline)
    assert '<script src="plotly.min.js"></script>' in page and len(page) < 1_000_000
    assert (path.parent / "plotly.min.js").read_text(encoding="utf-8") == plotly_js()
    fig = read_figure(page)
    (route,) = [t for t in fig["data"] if t["name"] == f"route: {doc['scenario']}"]
    with (path.parent / "track.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(route["x"]) == len(rows)
    lat = np.array([float(r["lat"]) for r in rows])
    lon = np.array([float(r["lon"]) for r in rows])
    # the hover's position is the track's; the line is drawn there, except legs over the
    # same water as an earlier one, drawn beside it (within REPEAT_SHIFT of the longest leg)
    assert [c[9] for c in route["customdata"]] == pytest.approx(lat.tolist(), abs=1e-6)
    assert [c[10] for c in route["customdata"]] == pytest.approx(lon.tolist(), abs=1e-6)
    x, y = course.frame.to_xy(np.array(route["y"]), np.array(route["x"]))
    tx, ty = course.frame.to_xy(lat, lon)
    shift = np.hypot(x - tx, y - ty)
    legs = np.array([int(r["leg"]) for r in rows])
    # Hyères: leg 4 (1 -> 4p) sails the water of leg 2 (1 -> gate 4), shifted by
    # REPEAT_SHIFT of the longest leg (start to end); the others are drawn in place
    chord = max(
        float(np.hypot(tx[legs == k][-1] - tx[legs == k][0], ty[legs == k][-1] - ty[legs == k][0]))
        for k in set(legs)
    )
    assert float(np.max(shift[legs != 4])) < 0.05
    np.testing.assert_allclose(shift[legs == 4], REPEAT_SHIFT * chord, atol=0.05)
    assert [c[0] for c in route["customdata"]] == [int(r["leg"]) for r in rows]
    assert [c[3] for c in route["customdata"]] == [r["time"][11:19] for r in rows]  # UTC
    (marks,) = [t for t in fig["data"] if t["name"] == "marks"]
    for name, lon, lat in zip(marks["text"], marks["x"], marks["y"], strict=True):
        assert (lat, lon) == pytest.approx(
            (course.marks[name].lat, course.marks[name].lon), abs=1e-6
        )
    off = course.utc_offset_s
    for leg in doc["legs"]:  # leg table: local start and arrival, the leg time
        assert (
            f'<tr><td>{leg["index"]}</td><td class="l">{leg["from"]} → {leg["to"]}</td>'
            f'<td class="l">{leg["mode"]}</td><td>{clock(iso(leg["start_time"]), off)}'
            f"</td><td>{clock(iso(leg['end_time']), off)}</td>"
            f"<td>{format_duration(leg['time_s'])}</td>"
        ) in page


def test_plan_hyeres_constant_writes_consistent_files(tmp_path):
    out = tmp_path / "plan"
    res = invoke("plan", str(COURSES / "hyeres-r1.yaml"), "--out", str(out))
    assert res.exit_code == 0, res.output
    doc = check_plan_files(out, COURSES / "hyeres-r1.yaml")
    assert doc["scenario"] == "constant" and doc["router"] == "isochrone"
    assert [leg["mode"] for leg in doc["legs"]] == [
        "upwind",
        "downwind",
        "upwind",
        "downwind",
        "reach",
    ]
    assert [leg["tacks"] for leg in doc["legs"]] == [1, 0, 1, 0, 0]
    png = out / "route.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the terminal table: one row per leg and the total, which equals plan.json
    assert "total" in res.output and f"{doc['total_time_s']:.1f}" in res.output
    check_report_html(out / "report.html", doc, load_course(COURSES / "hyeres-r1.yaml"))
    assert f"wrote interactive report (HTML): {out / 'report.html'}" in res.output
    assert "leg 5/5 4p -> finish" in res.output  # progress lines (stderr, mixed in here)


@pytest.mark.parametrize(
    ("course", "scenario", "n_legs"),
    [
        ("trieste-coach-wl.yaml", "measured", 4),
        ("windward-leeward-template.yaml", "veered-10deg", 6),
        ("trapezoid-outer-template.yaml", None, 6),
    ],
)
def test_plan_other_shipped_courses(tmp_path, course, scenario, n_legs):
    args = ["plan", str(COURSES / course), "--out", str(tmp_path), "--no-plots", "--quiet"]
    if scenario:
        args += ["--scenario", scenario]
    res = invoke(*args)
    assert res.exit_code == 0, res.output
    doc = check_plan_files(tmp_path, COURSES / course)
    assert len(doc["legs"]) == n_legs
    assert not (tmp_path / "route.png").exists()
    assert not (tmp_path / "report.html").exists()  # --no-plots: no plot output at all
    assert "routing..." not in res.output


def test_plan_measured_wind_beats_tack_with_the_shifts(tmp_path):
    """Real wind (coach-boat log): the beats are upwind legs and the shifts make them tack."""
    res = invoke(
        "plan", str(COURSES / "trieste-coach-wl.yaml"), "-o", str(tmp_path), "--no-plots", "-q"
    )
    assert res.exit_code == 0, res.output
    legs = json.loads((tmp_path / "plan.json").read_text())["legs"]
    assert [leg["mode"] for leg in legs] == ["upwind", "downwind", "upwind", "downwind"]
    assert all(leg["tacks"] >= 1 for leg in (legs[0], legs[2]))


def test_compare_scenarios_table_files_and_per_scenario_plans(tmp_path):
    course = COURSES / "windward-leeward-template.yaml"
    res = invoke("compare-scenarios", str(course), "--out", str(tmp_path), "-q")
    assert res.exit_code == 0, res.output
    doc = json.loads((tmp_path / "comparison.json").read_text())
    assert doc["scenarios"] == ["steady-12kn", "veered-10deg"]
    for name in doc["scenarios"]:
        plan = check_plan_files(tmp_path / name, course)
        assert [leg["time_s"] for leg in plan["legs"]] == pytest.approx(
            [leg["time_s"][name] for leg in doc["legs"]], abs=1e-3
        )
        assert plan["total_time_s"] == pytest.approx(doc["totals"]["time_s"][name], abs=1e-3)
    beat = doc["legs"][2]["time_s"]
    # a 10 deg veer the committee did not follow makes the beats shorter in time: part of
    # each beat becomes a fetch on the lifted tack
    assert beat["veered-10deg"] < beat["steady-12kn"]
    with (tmp_path / "comparison.csv").open() as f:
        assert len(list(csv.DictReader(f))) == 2 * 6 + 2  # legs x scenarios + totals
    assert (tmp_path / "comparison.png").read_bytes()[:4] == b"\x89PNG"
    from sailroute.report.page_render import read_figure

    fig = read_figure((tmp_path / "report.html").read_text(encoding="utf-8"))
    routes = [
        t
        for t in fig["data"]
        if t.get("legendgroup", "").startswith("route") and t["mode"] == "lines"
    ]
    assert [t["name"] for t in routes] == doc["scenarios"]
    for t, name in zip(routes, doc["scenarios"], strict=True):
        with (tmp_path / name / "track.csv").open() as f:
            assert len(t["x"]) == sum(1 for _ in csv.DictReader(f))


def test_compare_reference_errors_follow_the_stated_convention(tmp_path):
    res = invoke(
        "compare-scenarios",
        str(COURSES / "hyeres-r1.yaml"),
        "-s",
        "constant",
        "-o",
        str(tmp_path),
        "--no-plots",
        "-q",
    )
    assert res.exit_code == 0, res.output
    assert "(model - winner)/winner" in res.output
    with (tmp_path / "comparison.csv").open() as f:
        row = next(r for r in csv.DictReader(f) if r["leg"] == "1")
    model, ref = float(row["time_s"]), float(row["winner_s"])
    assert ref == 984.0
    assert float(row["winner_error_pct"]) == pytest.approx(100 * (model - ref) / ref, abs=2e-3)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["plan", "nope.yaml"], "nope.yaml: course file not found"),
        (
            ["plan", str(COURSES / "windward-leeward-template.yaml"), "-s", "steady"],
            "did you mean 'steady-12kn'? scenarios are: steady-12kn, veered-10deg",
        ),
        (
            ["plan", str(COURSES / "windward-leeward-template.yaml"), "-r", "fast"],
            "Invalid value for '--router' / '-r': 'fast' is not one of 'isochrone', 'griddp', "
            "'spline'",
        ),
        (
            ["compare-scenarios", str(COURSES / "windward-leeward-template.yaml"), "-s", "calm"],
            "no scenario 'calm'",
        ),
        (
            ["plan", str(ROOT / "tests" / "data" / "course" / "many-problems.yaml")],
            "7 problems in the course file",
        ),
    ],
)
def test_bad_input_exits_2_with_a_message(tmp_path, args, message):
    res = invoke(*args, "--out", str(tmp_path / "out"))
    assert res.exit_code == 2
    assert message in res.output
    assert not (tmp_path / "out").exists()


@pytest.mark.cli
def test_installed_console_script_runs_the_readme_example(tmp_path):
    exe = shutil.which("sailroute", path=str(Path(sys.executable).parent))
    assert exe is not None, "console script not installed next to this Python"
    version = subprocess.run([exe, "--version"], capture_output=True, text=True, check=True)
    assert version.stdout.startswith("sailroute ")
    mod = subprocess.run(
        [sys.executable, "-m", "sailroute", "--version"], capture_output=True, text=True, check=True
    )
    assert mod.stdout == version.stdout
    proc = subprocess.run(
        [exe, "plan", str(COURSES / "windward-leeward-template.yaml"), "--no-plots"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "out" / "windward-leeward-template" / "steady-12kn"  # the default --out
    check_plan_files(out, COURSES / "windward-leeward-template.yaml")
    bad = subprocess.run(
        [exe, "plan", "missing.yaml"], cwd=tmp_path, capture_output=True, text=True
    )
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert bad.stderr.startswith("error: missing.yaml: course file not found")


def test_out_that_is_a_file_exits_2_with_a_message(tmp_path):
    taken = tmp_path / "taken"
    taken.write_text("not a folder")
    res = invoke(
        "plan",
        str(COURSES / "windward-leeward-template.yaml"),
        "--no-plots",
        "-q",
        "--out",
        str(taken),
    )
    assert res.exit_code == 2
    assert (
        f"--out: cannot create the output folder {str(taken)!r} (a file of that name "
        "exists); choose another folder with --out" in res.output
    )
