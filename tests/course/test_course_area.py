"""The race-area keys (`boundary`, `obstacles`, `wind_land_is_obstacle`): loading, their
errors, and plans that stay inside the boundary and round the obstacles."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from sailroute.course.load import load_course
from sailroute.errors import InputError
from sailroute.routing.obstacles import obstacles_for
from tests.conftest import SHARED_REAL, requires_shared

COURSE = """
name: harbour race
start_time: "2024-05-01T12:00:00+02:00"
origin: {lat: 45.0, lon: 13.0}
marks:
  pin: {x: -50, y: 0}
  boat: {x: 50, y: 0}
  top: {x: 0, y: 1500}
lines:
  start: [pin, boat]
legs:
  - {to: top, rounding: port}
boat: {builtin: ilca7}
routing: {router: ROUTER}
scenarios:
  reach: {type: uniform, tws_kn: 12, twd_deg: 270}
AREA
"""

AREA = """
boundary:
  points: [{x: -600, y: -200}, {x: 600, y: -200}, {x: 600, y: 1800}, {x: -600, y: 1800}]
  clearance_m: 20
obstacles:
  - name: breakwater
    points: [{x: -250, y: 600}, {x: 350, y: 600}, {x: 350, y: 750}, {x: -250, y: 750}]
    clearance_m: 10
"""


def write(tmp_path, area=AREA, router="isochrone", name="c.yaml"):
    p = tmp_path / name
    p.write_text(COURSE.replace("ROUTER", router).replace("AREA", area), encoding="utf-8")
    return p


def test_area_is_parsed_into_the_local_frame(tmp_path):
    course = load_course(write(tmp_path))
    a = course.area
    assert a.boundary is not None and a.boundary.clearance_m == 20.0
    assert a.boundary.x == (-600.0, 600.0, 600.0, -600.0)
    (ob,) = a.obstacles
    assert (ob.name, ob.clearance_m, ob.y[2]) == ("breakwater", 10.0, 750.0)
    assert not a.wind_land_is_obstacle
    assert load_course(write(tmp_path, area="")).area.is_empty


def test_lat_lon_points_and_files_give_the_same_polygon(tmp_path):
    course = load_course(write(tmp_path))
    ob = course.area.obstacles[0]
    lat, lon = course.frame.to_latlon(np.array(ob.x), np.array(ob.y))
    ring = [[float(b), float(a)] for a, b in zip(lat, lon, strict=True)]
    (tmp_path / "bw.geojson").write_text(
        json.dumps(
            {
                "type": "Feature",
                "properties": {},
                "geometry": {"type": "Polygon", "coordinates": [ring + ring[:1]]},
            }
        )
    )
    kml = ET.Element("kml")
    coords = ET.SubElement(
        ET.SubElement(
            ET.SubElement(ET.SubElement(kml, "Polygon"), "outerBoundaryIs"), "LinearRing"
        ),
        "coordinates",
    )
    coords.text = " ".join(f"{x},{y},0" for x, y in ring + ring[:1])
    (tmp_path / "bw.kml").write_bytes(ET.tostring(kml))
    points = ", ".join(f"{{lat: {a!r}, lon: {b!r}}}" for b, a in ring)
    for spec in ("file: bw.geojson", "file: bw.kml", f"points: [{points}]"):
        area = AREA.replace(
            "points: [{x: -250, y: 600}, {x: 350, y: 600}, {x: 350, y: 750}, {x: -250, y: 750}]",
            spec,
        )
        got = load_course(write(tmp_path, area)).area.obstacles[0]
        assert np.allclose(got.x, ob.x, atol=1e-6) and np.allclose(got.y, ob.y, atol=1e-6)


@pytest.mark.parametrize(
    ("area", "message"),
    [
        (
            AREA.replace(
                "{x: 350, y: 750}, {x: -250, y: 750}", "{x: -250, y: 750}, {x: 350, y: 750}"
            ),
            r"c.yaml:\d+: obstacles\[0\]: expected a simple polygon; its edge from point \d to \d "
            r"crosses the edge",
        ),
        (
            AREA.replace(", {x: 350, y: 750}, {x: -250, y: 750}", ""),
            r"obstacles\[0\]: expected a ring of at least 3 points; got 2",
        ),
        (
            AREA.replace("y: 600}, {x: 350, y: 600}", "y: -20}, {x: 350, y: -20}"),
            r"obstacles\[0\]: mark 'pin' \(-50, 0 m\) lies inside obstacle 'breakwater' with its "
            r"clearance_m = 10 m; move the mark",
        ),
        (
            AREA.replace(
                "{x: 600, y: 1800}, {x: -600, y: 1800}", "{x: 600, y: 1490}, {x: -600, y: 1490}"
            ),
            r"c.yaml:\d+: boundary: the boundary shrunk by its clearance_m = 20 m does not contain "
            r"every mark: 'top' \(0, 1500 m\) lie outside",
        ),
        (
            "boundary: {file: missing.geojson}",
            r"boundary.file: cannot read .*missing.geojson.*; expected a GeoJSON",
        ),
        (
            "obstacles: [{name: x, points: [], file: a.kml}]",
            r"obstacles\[0\]: give either `points`",
        ),
        ("wind_land_is_obstacle: 1", r"wind_land_is_obstacle: expected true or false"),
    ],
)
def test_bad_area_is_a_one_line_error_naming_file_and_key(tmp_path, area, message):
    with pytest.raises(InputError, match=message) as err:
        load_course(write(tmp_path, area))
    assert "Traceback" not in str(err.value)


def test_plan_stays_inside_the_boundary_and_round_the_obstacle(tmp_path):
    from sailroute.planning.route import plan_course
    from sailroute.wind.uniform import UniformWind

    course = load_course(write(tmp_path))
    obs = obstacles_for(course.area)
    assert obs is not None
    open_water = load_course(write(tmp_path, area="", name="open.yaml"))
    for router in ("isochrone", "griddp"):
        plan = plan_course(load_course(write(tmp_path, router=router)), "reach").plan
        free = plan_course(open_water, "reach").plan
        for leg in plan.legs:
            x, y = leg.result.track.x, leg.result.track.y
            assert np.all(obs.segments_free(x[:-1], y[:-1], x[1:], y[1:])), router
        # the detour round the 600 m breakwater costs time
        assert plan.total_time_s > free.total_time_s * 1.02, router
    assert UniformWind  # the scenario's wind type


def test_spline_router_refuses_an_area(tmp_path):
    from sailroute.planning.route import plan_course

    with pytest.raises(
        InputError,
        match="'spline': a race-area boundary or obstacles are "
        "honoured by the isochrone and griddp routers only",
    ):
        plan_course(load_course(write(tmp_path, router="spline")), "reach")


@pytest.mark.parametrize(
    ("area", "router", "code", "message"),
    [
        (
            AREA.replace("y: 600}, {x: 350, y: 600}", "y: -20}, {x: 350, y: -20}"),
            "isochrone",
            2,
            "mark 'pin' (-50, 0 m) lies inside obstacle 'breakwater'",
        ),
        (AREA, "spline", 2, "honoured by the isochrone and griddp routers only"),
        (
            AREA.replace(
                "{x: -250, y: 600}, {x: 350, y: 600}, {x: 350, y: 750}, {x: -250, y: 750}",
                "{x: -700, y: 600}, {x: 700, y: 600}, {x: 700, y: 750}, {x: -700, y: 750}",
            ),
            "isochrone",
            3,
            "no route round obstacle 'breakwater'",
        ),
    ],
)
def test_cli_exit_codes_and_nothing_written(tmp_path, area, router, code, message):
    from typer.testing import CliRunner

    from sailroute.cli import app

    out = tmp_path / "out"
    res = CliRunner().invoke(
        app, ["plan", str(write(tmp_path, area, router)), "-o", str(out), "-q", "--no-plots"]
    )
    assert res.exit_code == code, res.output
    assert message in " ".join(res.output.split())
    assert "Traceback" not in res.output
    assert not out.exists() or not any(out.iterdir())


def test_land_cells_of_a_gridded_wind_become_an_obstacle(tmp_path):
    """An island of NaN cells across the direct route: without `wind_land_is_obstacle`
    the route samples the hole and fails; with it, it goes round in wind everywhere."""
    from sailroute.course.load import build_boat
    from sailroute.errors import OutOfCoverageError, RoutingError
    from sailroute.planning.route import route_course
    from sailroute.wind.grid import GridWind

    y, x = np.mgrid[-300:2001:50.0, -800:801:50.0]
    u = np.full((1, *x.shape), 6.0)  # from the west, 6 m/s
    island = (np.abs(x) <= 150) & (np.abs(y - 800) <= 100)
    u[0, island] = np.nan
    wind = GridWind([0.0], x, y, u, np.zeros_like(u), allow_nan=True, steady=True)
    plain = load_course(write(tmp_path, area=""))
    with pytest.raises((OutOfCoverageError, RoutingError), match=r"NaN|no wind"):
        route_course(plain, wind, build_boat(plain), plain.routing)
    course = load_course(write(tmp_path, area="wind_land_is_obstacle: true", name="land.yaml"))
    assert course.area.wind_land_is_obstacle
    obs = obstacles_for(course.area, wind)
    assert obs is not None and obs.names == ("land",)
    (leg,) = route_course(course, wind, build_boat(course), course.routing)
    tr = leg.track
    assert np.all(np.isfinite(tr.tws_ms))
    assert np.all(obs.segments_free(tr.x[:-1], tr.y[:-1], tr.x[1:], tr.y[1:]))
    assert np.max(np.abs(tr.x)) > 150.0  # round the island, not through it


# ---------------------------------------------------------------------- real: SailGP
RACE = SHARED_REAL / "races" / "sailgp-auckland-2025"


def course_limits(xml) -> dict[str, list[tuple[str, str]]]:
    """``CourseLimit`` name -> its points ``(lat, lon)`` as written in the race XML."""
    root = ET.parse(xml).getroot()
    return {
        cl.get("name", ""): [(p.get("Lat", ""), p.get("Lon", "")) for p in cl.iterfind("Limit")]
        for cl in root.iterfind("CourseLimit")
    }


@requires_shared
def test_sailgp_auckland_race_stays_in_its_course_limits(tmp_path):
    """Race 25011905 planned with the F50 polar inside the race XML's `Exclusion Zone`
    ring (the water the race keeps spectators out of) and round its `AY` and `BYOB` zones,
    all three from the XML's CourseLimit polygons.  The XML's `Boundary` cannot be the
    course's `boundary`: the start marks SL1 and SL2 lie 8 m and 10 m outside it (the
    boats start from outside the racing area), which the loader refuses, as it must for a
    route that has to start inside."""
    import shapely

    from sailroute.planning.route import plan_course
    from tests.analysis.test_sailgp_fleet import XML, course_from_xml

    limits = course_limits(XML)
    path = course_from_xml(XML, 20.0, 65.0, tmp_path / "race.yaml")

    def ring(name):
        return "[" + ", ".join(f"{{lat: {a}, lon: {b}}}" for a, b in limits[name]) + "]"

    text = path.read_text(encoding="utf-8")
    bad = text + f"boundary: {{points: {ring('Boundary')}}}\n"
    path.write_text(bad, encoding="utf-8")
    with pytest.raises(
        InputError,
        match=r"boundary: the boundary does not contain every "
        r"mark: 'SL1' \(\d+, -\d+ m\), 'SL2' .* lie outside",
    ):
        load_course(path)
    area = (
        f"boundary: {{points: {ring('Exclusion Zone')}, clearance_m: 10}}\n"
        f"obstacles:\n  - {{name: AY, points: {ring('AY')}, clearance_m: 10}}\n"
        f"  - {{name: BYOB, points: {ring('BYOB')}, clearance_m: 10}}\n"
    )
    path.write_text(text + area, encoding="utf-8")
    course = load_course(path)
    assert len(course.legs) == 7 and len(course.area.obstacles) == 2
    obs = obstacles_for(course.area)
    assert obs is not None
    plan = plan_course(course, "race-mean").plan
    shapes = {}
    for name in ("Exclusion Zone", "AY", "BYOB"):
        lat, lon = np.array(limits[name], dtype=float).T
        shapes[name] = shapely.polygons(np.column_stack(course.frame.to_xy(lat, lon)))
    for leg in plan.legs:
        x, y = leg.result.track.x, leg.result.track.y
        assert np.all(obs.segments_free(x[:-1], y[:-1], x[1:], y[1:]))
        assert np.all(shapely.contains_xy(shapes["Exclusion Zone"], x, y))
        for zone in ("AY", "BYOB"):
            assert not np.any(shapely.intersects_xy(shapes[zone], x, y)), zone
    assert 300.0 < plan.total_time_s < 1500.0  # an F50 race of 7 legs: minutes
