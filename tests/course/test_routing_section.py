"""The ``routing:`` section of a course file: flat keys (every shipped course) and one
section per router give the same settings; unknown, doubled and mistyped keys are one
line each, with the file's line."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from sailroute.course.load import course_from_mapping, load_course
from sailroute.routing.settings import (
    FLAT_NAMES,
    GridDPSettings,
    IsochroneSettings,
    RoutingSettings,
    SplineSettings,
)
from tests.conftest import COURSES
from tests.course.test_course_load import BASE, problems, write

N_BASE = BASE.count("\n")  # the line of "routing:"

FLAT = """\
routing:
  router: spline
  tack_penalty_s: 7
  zone_m: 20
  dt_s: 5
  heading_step_deg: 1
  min_dt_s: 0.5
  prune_sector_deg: 2
  max_front_points: 500
  heading_fan: full
  dp_rows: 9
  dp_cols: 17
  dp_refinements: 1
  dp_half_width_m: 300
  dp_shrink: 0.25
  dp_samples: 2
  spline_cols: 11
  spline_slopes: 5
  spline_refinements: 1
  spline_carry_speed: true
  spline_start_from_rest: true
"""

NESTED = """\
routing:
  router: spline
  tack_penalty_s: 7
  zone_m: 20
  isochrone:
    dt_s: 5
    heading_step_deg: 1
    min_dt_s: 0.5
    prune_sector_deg: 2
    max_front_points: 500
    heading_fan: full
  griddp: {rows: 9, cols: 17, refinements: 1, half_width_m: 300, shrink: 0.25, samples: 2}
  spline:
    rows: 9
    half_width_m: 300
    cols: 11
    slopes: 5
    refinements: 1
    carry_speed: true
    start_from_rest: true
"""


def routing_of(tmp_path: Path, section: str) -> RoutingSettings:
    return load_course(write(tmp_path, BASE + section)).routing


def test_flat_and_nested_forms_give_equal_settings(tmp_path: Path) -> None:
    flat, nested = routing_of(tmp_path, FLAT), routing_of(tmp_path, NESTED)
    assert flat == nested
    assert flat == RoutingSettings(
        router="spline",
        tack_penalty_s=7.0,
        zone_m=20.0,
        isochrone=IsochroneSettings(5.0, 1.0, 0.5, 2.0, 500, "full"),
        griddp=GridDPSettings(9, 17, 1, 300.0, 0.25, 2),
        spline=SplineSettings(9, 300.0, 11, 5, 1, True, True),
    )


def test_the_forms_mix_and_an_empty_section_keeps_the_defaults(tmp_path: Path) -> None:
    s = routing_of(tmp_path, "routing:\n  dt_s: 5\n  griddp: {cols: 9}\n  spline:\n")
    assert s == RoutingSettings(
        isochrone=IsochroneSettings(dt_s=5.0), griddp=GridDPSettings(cols=9)
    )


@pytest.mark.parametrize("course", ["hyeres-r1.yaml", "trieste-coach-wl.yaml"])
def test_shipped_courses_load_the_same_when_nested(course: str) -> None:
    path = COURSES / course
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    nested: dict[str, dict[str, object]] = {}
    for key in [k for k in data["routing"] if k in FLAT_NAMES]:
        value = data["routing"].pop(key)
        for p in FLAT_NAMES[key]:
            group, _, attr = p.partition(".")
            nested.setdefault(group, {})[attr] = value
    assert nested == {"isochrone": {"dt_s": 5.0, "heading_step_deg": 2.0}}
    data["routing"].update(nested)
    moved = course_from_mapping(data, source=path).routing
    assert moved == load_course(path).routing
    assert moved.isochrone.dt_s == 5.0


@pytest.mark.parametrize(
    ("section", "line", "expected"),
    [
        (
            "griddp: {colz: 3}",
            1,
            "routing.griddp.colz: unknown key for the griddp router; did you mean 'cols'? "
            "valid keys: rows, cols, refinements, half_width_m, shrink, samples",
        ),
        ("isochrones: {dt_s: 5}", 1, "routing.isochrones: unknown key; did you mean 'isochrone'?"),
        ("spline_col: 9", 1, "routing.spline_col: unknown key; did you mean 'spline_cols'?"),
        ("griddp: 5", 1, "routing.griddp: expected a mapping of griddp router settings; got 5"),
        (
            "dp_cols: 9\n  griddp: {cols: 9}",
            2,
            "routing.griddp.cols: given twice (also as routing.dp_cols, line {first}); keep "
            "one: a flat key and a router's section set the same setting",
        ),
        (
            "griddp:\n    cols: 9\n  dp_cols: 9",
            3,
            "routing.dp_cols: given twice (also as routing.griddp.cols, line {second}); keep one",
        ),
        (
            "dp_rows: 9\n  spline: {rows: 5}",
            2,
            "routing.spline.rows: given twice (also as routing.dp_rows, line {first}); keep one",
        ),
        (
            "griddp: {cols: many}",
            1,
            "routing.griddp.cols: expected a whole number >= 0; got 'many'",
        ),
        (
            "isochrone: {dt_s: 0.1}",
            1,
            "routing.isochrone.dt_s: expected a time step >= 0.5 s (default 10; finer steps "
            "hardly change the route and make it slow); got 0.1",
        ),
        (
            "isochrone: {heading_step_deg: 90}",
            1,
            "routing.isochrone.heading_step_deg: expected a number in [0.1, 45]",
        ),
        (
            "spline: {carry_speed: 1}",
            1,
            "routing.spline.carry_speed: expected true or false; got 1",
        ),
        (
            "griddp: {half_width_m: wide}",
            1,
            "routing.griddp.half_width_m: expected a number or null",
        ),
    ],
)
def test_section_problems_are_one_line_with_the_files_line(
    tmp_path: Path, section: str, line: int, expected: str
) -> None:
    path = write(tmp_path, BASE + f"routing:\n  {section}\n")
    msg = problems(path)
    expected = expected.format(first=N_BASE + 2, second=N_BASE + 3)
    assert msg.startswith(f"{path}:{N_BASE + 1 + line}: {expected}")
    assert "\n" not in msg


@pytest.mark.parametrize(
    ("section", "expected"),
    [
        ("griddp: {cols: 1}", "routing.griddp.cols: griddp.cols must be an integer in [2, 1024]"),
        ("dp_cols: 1", "routing.dp_cols: dp_cols must be an integer in [2, 1024], got 1"),
        ("griddp: {shrink: 2}", "routing.griddp.shrink: griddp.shrink must be in (0, 1], got 2.0"),
        ("spline: {slopes: 0}", "routing.spline.slopes: spline.slopes must be an integer >= 1"),
        ("dp_rows: 2", "routing.dp_rows: dp_rows must be an integer in [3, 200], got 2"),
        ("isochrone: {min_dt_s: 0.001}", "routing.isochrone.min_dt_s: isochrone.min_dt_s must be"),
        (
            "spline: {cols: 1000, slopes: 1000}",
            "routing.spline.cols: spline.cols = 1000 with spline.slopes = 1000 needs 1.0e+12 "
            "edges between two rows",
        ),
        (
            "griddp: {cols: 1024, rows: 200, samples: 64, refinements: 20}",
            "routing.griddp.cols: griddp.cols = 1024 with griddp.rows = 200, griddp.samples = "
            "64 and griddp.refinements = 20 needs about 2.8e+11 wind samples",
        ),
    ],
)
def test_router_rules_name_the_key_as_the_file_gives_it(
    tmp_path: Path, section: str, expected: str
) -> None:
    # a flat key keeps its flat name in the routers' messages (the shared dp_rows once)
    path = write(tmp_path, BASE + f"routing:\n  {section}\n")
    msg = problems(path)
    assert msg.startswith(f"{path}:{N_BASE + 2}: {expected}")
    assert "\n" not in msg
