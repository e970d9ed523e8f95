"""``sailroute start`` and the start line / layline outputs of ``sailroute plan``.

A small windward-leeward course in a uniform 5 m/s north wind, its start line turned
5° so that the east (starboard) end lies upwind: bias +5°, favoured end "boat", gain
L sin 5°.  Closed forms use the course's own boat (the built-in ILCA 7 polar).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.course.load import build_boat, load_course
from sailroute.report.page_render import read_figure
from sailroute.units import bearing_deg, wrap180

TWS, BIAS, HALF = 5.0, 5.0, 150.0
END_Y = HALF * math.tan(math.radians(BIAS))


def course_mapping(first_from: str = "start") -> dict:
    return {
        "name": "start line test",
        "start_time": "2024-05-01T12:00:00Z",
        "origin": {"lat": 45.0, "lon": 13.0},
        "marks": {
            "pin": {"x": -HALF, "y": -END_Y},
            "boat": {"x": HALF, "y": END_Y},
            "top": {"x": 0.0, "y": 700.0},
            "bottom": {"x": 0.0, "y": 100.0},
        },
        "lines": {"start": ["pin", "boat"]},
        "legs": [
            {"from": first_from, "to": "top", "rounding": "port"},
            {"to": "bottom", "rounding": "port"},
        ],
        "scenarios": {"steady": {"wind": {"type": "uniform", "tws_ms": TWS, "twd_deg": 0.0}}},
    }


@pytest.fixture(scope="module")
def course_file(tmp_path_factory) -> str:
    p = tmp_path_factory.mktemp("course") / "startline.yaml"
    p.write_text(yaml.safe_dump(course_mapping()), encoding="utf-8")
    return str(p)


@pytest.fixture(scope="module")
def planned(course_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("plan")
    res = CliRunner().invoke(app, ["plan", course_file, "-q", "--out", str(out)])
    assert res.exit_code == 0, res.output
    return res.output, out


def test_plan_json_start_line(course_file, planned):
    _, out = planned
    sl = json.loads((out / "plan.json").read_text())["start_line"]
    length = 2.0 * HALF / math.cos(math.radians(BIAS))
    assert sl["length_m"] == pytest.approx(length, abs=0.01)
    assert sl["bias_deg"] == pytest.approx(BIAS, abs=0.01)
    assert sl["starboard_end"] == "boat" and sl["favoured_end"] == "boat"
    assert sl["favoured_side"] == "starboard"
    assert sl["gain_m"] == pytest.approx(length * math.sin(math.radians(BIAS)), abs=0.01)
    _, vmg = build_boat(load_course(course_file)).vmg_upwind(TWS)
    assert sl["gain_s"] == pytest.approx(sl["gain_m"] / float(vmg), abs=0.02)
    assert sl["bias_min_deg"] == sl["bias_max_deg"] == sl["bias_deg"]  # steady wind
    assert sl["favoured_point"]["x"] == pytest.approx(HALF)


def test_plan_json_laylines(course_file, planned):
    """Leg 1 (a beat) has tack laylines to "top" at 180° ∓ TWA*; leg 2 (a run) gybe
    laylines to "bottom" at ∓ TWA*_down; each about the leg's length."""
    _, out = planned
    legs = json.loads((out / "plan.json").read_text())["legs"]
    up, down = build_boat(load_course(course_file)).vmg_angles_deg(TWS)
    for leg, kind, twa, mark in (
        (legs[0], "tack", up, (0.0, 700.0)),
        (legs[1], "gybe", down, (0.0, 100.0)),
    ):
        lls = leg["laylines"]
        assert [(ll["kind"], ll["tack"]) for ll in lls] == [(kind, "starboard"), (kind, "port")]
        for ll, sign in zip(lls, (1.0, -1.0), strict=True):
            x = np.array([p["x"] for p in ll["points"]])
            y = np.array([p["y"] for p in ll["points"]])
            assert (x[0], y[0]) == pytest.approx(mark)
            back = bearing_deg(x[1:] - mark[0], y[1:] - mark[1])
            assert np.abs(wrap180(back - (180.0 - sign * twa))).max() < 0.1
            assert {"lat", "lon"} <= set(ll["points"][0])
        assert 400.0 < lls[0]["length_m"] < 900.0


def test_plan_table_report_and_map(planned):
    output, out = planned
    assert "start line" in output
    assert "bias                      +5.0° (starboard end boat favoured)" in output
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "Start line" in page and "+5.0° (starboard end boat favoured)" in page
    fig = read_figure(page)
    names = [t.get("name") for t in fig["data"]]
    assert "favoured end" in names and names.count("laylines") == 4
    star = next(t for t in fig["data"] if t.get("name") == "favoured end")
    assert star["x"][0] > 13.0  # the east end


def test_start_command_closed_form(course_file, tmp_path):
    """From d below the line's middle, close-hauled on starboard: path d' / cos(TWA*) where
    d' is the distance along the wind to the line, time path / V(TWA*)."""
    boat = build_boat(load_course(course_file))
    up, _ = boat.vmg_angles_deg(TWS)
    d = 120.0
    res = CliRunner().invoke(
        app,
        [
            "start",
            course_file,
            "--xy",
            f"0,{-d}",
            "--time",
            "-100",
            "--out",
            str(tmp_path),
            "--json",
        ],
    )
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    star = doc["close_hauled"]["starboard"]
    # heading 360 - TWA* (north-west), meets the line y = x tan(5°)
    h = math.radians(360.0 - up)
    s = d / (math.cos(h) - math.sin(h) * math.tan(math.radians(BIAS)))
    assert star["distance_m"] == pytest.approx(s, abs=0.01)
    assert star["time_s"] == pytest.approx(s / float(boat.speed(TWS, up)), abs=0.01)
    assert doc["distance_to_line_m"] == pytest.approx(d * math.cos(math.radians(BIAS)), abs=0.01)
    assert doc["time_to_burn_s"] == pytest.approx(100.0 - doc["fastest"]["time_s"], abs=0.01)
    assert (
        doc["fastest"]["time_s"]
        <= min(star["time_s"], doc["close_hauled"]["port"]["time_s"]) + 1e-9
    )
    assert doc["start_line"]["favoured_end"] == "boat"
    assert json.loads((tmp_path / "start.json").read_text()) == doc


def _refused(args: list[str], tmp_path, expected: str) -> None:
    out = tmp_path / "out"
    res = CliRunner().invoke(app, [*args, "--out", str(out)])
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ")
    assert expected in lines[0]
    assert "Traceback" not in res.output
    assert not out.exists()


def test_start_refuses_a_far_position(course_file, tmp_path):
    _refused(
        ["start", course_file, "--at", "45.3,13.0", "--time", "-60"],
        tmp_path,
        "the position is 33 km from the course area",
    )


def test_start_refuses_an_unparsable_time(course_file, tmp_path):
    _refused(
        ["start", course_file, "--xy", "0,-100", "--time", "five to twelve"],
        tmp_path,
        "--time 'five to twelve': expected an ISO 8601 time",
    )


def test_start_refuses_a_bad_position(course_file, tmp_path):
    _refused(
        ["start", course_file, "--at", "45.0", "--time", "-60"],
        tmp_path,
        "--at '45.0': expected two comma-separated numbers",
    )
    _refused(
        ["start", course_file, "--time", "-60"],
        tmp_path,
        "give the boat's position with --at LAT,LON",
    )


def test_start_refuses_a_course_without_a_start_line(tmp_path):
    p = tmp_path / "nostart.yaml"
    p.write_text(yaml.safe_dump(course_mapping(first_from="bottom")), encoding="utf-8")
    _refused(
        ["start", str(p), "--xy", "0,-100", "--time", "-60"],
        tmp_path,
        "the first leg starts from 'bottom', which is not a line",
    )


def test_route_png_draws_laylines_and_the_favoured_end(course_file):
    from sailroute.planning.route import plan_course
    from sailroute.report.plots import plot_plan

    run = plan_course(load_course(course_file))
    ax = plot_plan(run.plan, run.wind).axes[0]
    gids = {a.get_gid() for a in ax.get_lines()}
    assert {
        "layline:1:top:starboard",
        "layline:1:top:port",
        "layline:2:bottom:starboard",
        "layline:2:bottom:port",
        "favoured-end",
    } <= gids
    star = next(a for a in ax.get_lines() if a.get_gid() == "favoured-end")
    at = (star.get_xdata()[0], star.get_ydata()[0])
    if at != pytest.approx((HALF, END_Y)):  # moved off the route's start: a leader to it
        (leaders,) = [c for c in ax.collections if c.get_gid() == "leaders"]
        starts = [tuple(seg[0]) for seg in leaders.get_segments()]
        assert any(s == pytest.approx((HALF, END_Y), abs=0.01) for s in starts)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "laylines" in labels and "favoured start end" in labels
    assert ax.get_legend().get_title().get_text().startswith("grey arrows: wind")


def test_plan_from_a_mark_has_no_start_line():
    from sailroute.course.load import course_from_mapping
    from sailroute.planning.route import plan_course
    from sailroute.report.files import plan_to_dict
    from sailroute.report.tables import plan_table

    plan = plan_course(course_from_mapping(course_mapping(first_from="bottom"))).plan
    assert plan.start_line is None
    assert plan_to_dict(plan)["start_line"] is None
    assert "\nstart line\n" not in plan_table(plan) and "bias" not in plan_table(plan)
    assert [ll.kind for ll in plan.laylines[0]] == ["tack", "tack"]  # bottom -> top: a beat
