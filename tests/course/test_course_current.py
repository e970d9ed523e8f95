"""A scenario's `current:` end to end: course file -> plan -> plan.json / track.csv."""

from __future__ import annotations

import pytest

from sailroute.errors import InputError

COURSE = """
name: Current test
start_time: "2024-06-01T14:00:00+02:00"
template:
  type: windward-leeward
  centre: {lat: 43.069067, lon: 6.198550}
  twd_deg: 270
  leg_length_m: 600
  laps: 1
  gate_width_m: 50
  start_line_length_m: 100
  finish: leeward
boat: {builtin: ilca7}
routing: {router: ROUTER}
scenarios:
  still: {type: uniform, tws_kn: 12, twd_deg: 270}
  zero:
    wind: {type: uniform, tws_kn: 12, twd_deg: 270}
    current: {type: uniform, speed_kn: 0, set_deg: 0}
  tide:
    wind: {type: uniform, tws_kn: 12, twd_deg: 270}
    current: {type: diamonds, high_water: "2024-06-01T12:00:00Z",
              table: [[-6, 90, 0.5], [0, 0, 1.5], [6, 270, 0.5]]}
"""


def course_file(tmp_path, router="isochrone"):
    p = tmp_path / "c.yaml"
    p.write_text(COURSE.replace("ROUTER", router), encoding="utf-8")
    return p


def test_plan_with_current_end_to_end(tmp_path):
    import csv

    from sailroute.course.load import load_course
    from sailroute.planning.route import plan_course
    from sailroute.report.files import plan_to_dict, write_track_csv

    course = load_course(course_file(tmp_path))
    still = plan_course(course, "still").plan
    zero = plan_course(course, "zero").plan
    tide = plan_course(course, "tide").plan
    for a, b in zip(still.legs, zero.legs, strict=True):
        assert abs(a.result.time_s - b.result.time_s) <= 1e-9
    assert tide.total_time_s != pytest.approx(still.total_time_s, rel=1e-3)
    doc = plan_to_dict(tide)
    assert doc["current"]["type"] == "diamonds" and plan_to_dict(still)["current"] is None
    assert all(leg["mean_sog_kn"] > 0 and leg["mean_stw_kn"] > 0 for leg in doc["legs"])
    write_track_csv(tmp_path / "t.csv", tide)
    rows = list(csv.DictReader((tmp_path / "t.csv").open(encoding="utf-8")))
    assert {"sog_ms", "sog_kn", "cog_deg", "bsp_ms", "heading_deg"} <= set(rows[0])
    assert any(abs(float(r["sog_ms"]) - float(r["bsp_ms"])) > 0.1 for r in rows)
    write_track_csv(tmp_path / "s.csv", still)
    rows = list(csv.DictReader((tmp_path / "s.csv").open(encoding="utf-8")))
    assert all(r["sog_ms"] == r["bsp_ms"] and r["cog_deg"] == r["heading_deg"] for r in rows)


def test_plan_with_current_and_griddp_is_refused(tmp_path):
    from sailroute.course.load import load_course
    from sailroute.planning.route import plan_course

    course = load_course(course_file(tmp_path, "griddp"))
    with pytest.raises(InputError, match=r"set routing\.router: isochrone"):
        plan_course(course, "tide")


def test_course_current_spec_error_names_file_and_key(tmp_path):
    from sailroute.course.load import load_course
    from sailroute.planning.route import plan_course

    p = course_file(tmp_path)
    p.write_text(p.read_text().replace("speed_kn: 0,", "speed_kn: -1,"), encoding="utf-8")
    with pytest.raises(InputError) as exc:
        plan_course(load_course(p), "zero")
    assert "c.yaml" in str(exc.value) and "scenarios.zero.current" in str(exc.value)
    assert "speed_kn" in str(exc.value)
