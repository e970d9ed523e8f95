"""The race area (``boundary``, ``obstacles``) in the plan's outputs: ``plan.json``'s
``area``, the polygons on ``route.png`` and in ``report.html``'s figure.

The plans are built without a router (straight legs round the obstacle, timed from the
polar, as in ``conftest.py``); one ``sailroute plan`` run checks the written files.
"""

from __future__ import annotations

import dataclasses
import json
import math
from xml.etree import ElementTree as ET

import numpy as np
import pytest

from sailroute.course.geometry import feature_centre
from sailroute.course.load import load_course
from sailroute.geo import LocalFrame
from sailroute.planning.result import make_plan
from sailroute.report.area import AREA_REACH, OBSTACLE_FILL, area_to_dict, fit_area
from sailroute.report.files import plan_to_dict
from sailroute.report.html import plan_report
from sailroute.report.page import course_area
from sailroute.report.page_figure import figure
from sailroute.report.plots import plot_plan
from sailroute.routing.obstacles import RaceArea
from sailroute.routing.track import make_leg_result
from sailroute.wind.uniform import UniformWind
from tests.conftest import SHARED_REAL, requires_shared
from tests.report.conftest import timed_track

FRAME = LocalFrame(45.0, 13.0)
BREAKWATER_XY = [(-250.0, 600.0), (350.0, 600.0), (350.0, 750.0), (-250.0, 750.0)]
BOUNDARY_XY = [(-600.0, -200.0), (600.0, -200.0), (600.0, 1800.0), (-600.0, 1800.0)]
WIND = UniformWind(6.0, 270.0)  # from the west: the leg north is a reach


def _breakwater_latlon() -> list[tuple[float, float]]:
    lat, lon = FRAME.to_latlon(*np.array(BREAKWATER_XY).T)
    return [(float(a), float(b)) for a, b in zip(lat, lon, strict=True)]


def course_text(boundary: str | None = None) -> str:
    ll = ", ".join(f"{{lat: {a!r}, lon: {b!r}}}" for a, b in _breakwater_latlon())
    bxy = ", ".join(f"{{x: {x:g}, y: {y:g}}}" for x, y in BOUNDARY_XY)
    return f"""
name: harbour race
start_time: "2024-05-01T12:00:00+02:00"
origin: {{lat: 45.0, lon: 13.0}}
marks:
  pin: {{x: -50, y: 0}}
  boat: {{x: 50, y: 0}}
  top: {{x: 0, y: 1500}}
lines:
  start: [pin, boat]
legs:
  - {{to: top, rounding: port}}
boat: {{builtin: ilca7}}
scenarios:
  reach: {{type: uniform, tws_ms: 6, twd_deg: 270}}
boundary:
  points: [{boundary or bxy}]
  clearance_m: 20
obstacles:
  - name: breakwater
    points: [{ll}]
    clearance_m: 10
"""


@pytest.fixture
def course(tmp_path):
    p = tmp_path / "harbour.yaml"
    p.write_text(course_text(), encoding="utf-8")
    return load_course(p)


def round_the_breakwater(course):
    """The leg as straight pieces west of the breakwater (outside its 10 m clearance)."""
    pts = [(0.0, 0.0), (-280.0, 580.0), (-280.0, 770.0), (0.0, 1500.0)]
    return [make_leg_result(timed_track(pts, course.start_epoch, WIND), "test")]


@pytest.fixture
def plan(course):
    return make_plan(course, "reach", round_the_breakwater(course), WIND)


# ------------------------------------------------------------------------- plan.json
def test_plan_json_rings_round_trip_to_the_course_polygons(plan):
    doc = json.loads(json.dumps(plan_to_dict(plan)))
    area = doc["area"]
    assert list(doc).index("area") == list(doc).index("start_line") + 1
    assert area["wind_land_is_obstacle"] is False
    (ob,) = area["obstacles"]
    assert (ob["name"], ob["clearance_m"]) == ("breakwater", 10.0)
    # the obstacle was given in lat/lon: the same degrees come back
    for p, (lat, lon) in zip(ob["points"], _breakwater_latlon(), strict=True):
        assert abs(p["lat"] - lat) <= 1e-7 and abs(p["lon"] - lon) <= 1e-7
        assert set(p) == {"x", "y", "lat", "lon"}
    got = [(p["x"], p["y"]) for p in ob["points"]]
    np.testing.assert_allclose(got, BREAKWATER_XY, atol=1e-3, rtol=0)
    # the boundary was given in x/y: the same metres, and the frame's degrees
    b = area["boundary"]
    assert (b["name"], b["clearance_m"]) == ("boundary", 20.0)
    assert [(p["x"], p["y"]) for p in b["points"]] == BOUNDARY_XY
    lat, lon = FRAME.to_latlon(*np.array(BOUNDARY_XY).T)
    np.testing.assert_allclose([p["lat"] for p in b["points"]], lat, atol=1e-7, rtol=0)
    np.testing.assert_allclose([p["lon"] for p in b["points"]], lon, atol=1e-7, rtol=0)


def test_no_area_key_without_an_area(plan):
    bare = dataclasses.replace(plan, course=dataclasses.replace(plan.course, area=RaceArea()))
    doc = plan_to_dict(bare)
    assert "area" not in doc
    with_area = plan_to_dict(plan)
    del with_area["area"]
    assert json.dumps(doc) == json.dumps(with_area)  # nothing else changes
    # the land rule alone draws and writes nothing either
    land = RaceArea(wind_land_is_obstacle=True)
    assert area_to_dict(land, FRAME) is None
    assert fit_area(land, (0.0, 1.0, 0.0, 1.0)) == (0.0, 1.0, 0.0, 1.0)


# ------------------------------------------------------------------------- route.png
def _by_gid(fig):
    ax = fig.axes[0]
    return ax, {a.get_gid(): a for a in (*ax.patches, *ax.lines, *ax.collections) if a.get_gid()}


def test_png_draws_the_polygons_under_the_route(plan):
    fig = plot_plan(plan, WIND)
    ax, arts = _by_gid(fig)
    patch = arts["obstacle:breakwater"]
    np.testing.assert_allclose(patch.get_xy()[:4], BREAKWATER_XY, atol=1e-6)
    bx, by = arts["boundary"].get_data()
    assert list(zip(bx, by, strict=True)) == [*BOUNDARY_XY, BOUNDARY_XY[0]]
    # the dashed clearances: the obstacle grown by 10 m, the boundary shrunk by 20 m
    cx, cy = arts["obstacle-clearance:breakwater"].get_data()
    assert (min(cx), max(cx), min(cy), max(cy)) == pytest.approx((-260, 360, 590, 760), abs=1e-6)
    sx, sy = arts["boundary-clearance"].get_data()
    assert (min(sx), max(sx), min(sy), max(sy)) == pytest.approx((-580, 580, -180, 1780), abs=1e-6)
    assert arts["obstacle-clearance:breakwater"].get_linestyle() == "--"
    assert patch.get_zorder() < arts["leg:1"].get_zorder()
    assert arts["boundary"].get_zorder() < arts["leg:1"].get_zorder()
    labels = ax.get_legend_handles_labels()[1]
    assert {"obstacles", "race-area boundary", "clearance kept"} <= set(labels)
    assert labels.count("clearance kept") == 1
    # the boundary lies within half the course's span of it: shown whole
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    assert x0 < -600 and x1 > 600 and y0 < -200 and y1 > 1800
    # pixels of the obstacle's fill colour inside it, the sea's outside it
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colors import to_rgb

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    img = np.asarray(canvas.buffer_rgba())[..., :3].astype(float) / 255.0
    h = img.shape[0]

    def pixel(x, y):
        px, py = ax.transData.transform((x, y))
        return img[round(h - py), round(px)]

    fill = np.array(to_rgb(OBSTACLE_FILL))
    for x, y in [(50, 675), (300, 620), (-200, 730)]:
        assert np.abs(pixel(x, y) - fill).max() < 0.08, (x, y)
    assert np.abs(pixel(450, 675) - fill).max() > 0.08


def test_a_far_boundary_does_not_zoom_the_map_out(tmp_path):
    """A 20 km square round a 1.5 km course: the map reaches out half the course's span
    (750 m) beyond the marks and route, no further."""
    far = ", ".join(
        f"{{x: {x}, y: {y}}}" for x, y in [(-1e4, -1e4), (1e4, -1e4), (1e4, 1e4), (-1e4, 1e4)]
    )
    p = tmp_path / "far.yaml"
    p.write_text(course_text(far), encoding="utf-8")
    course = load_course(p)
    plan = make_plan(course, "reach", round_the_breakwater(course), WIND)
    ax = plot_plan(plan, WIND).axes[0]
    span = 1500.0  # marks and route: x -280..50, y 0..1500
    pad = 0.08 * (1.0 + 2 * AREA_REACH) * span
    assert ax.get_ylim() == pytest.approx((-AREA_REACH * span - pad, 1500 + 750 + pad))
    assert fit_area(course.area, (-280.0, 50.0, 0.0, 1500.0)) == (-1030.0, 800.0, -750.0, 2250.0)
    # the HTML map takes the same extent
    assert course_area(course, ()) == pytest.approx(
        (-50 - 750 - pad, 50 + 750 + pad, -750 - pad, 2250 + pad)
    )


# ------------------------------------------------------------------------ report.html
def _traces(fig, name):
    return [t for t in fig["data"] if t.get("name") == name]


def test_html_figure_has_a_trace_per_polygon(plan):
    fig = figure(plan_report(plan, WIND))
    (bt,) = _traces(fig, "race-area boundary")
    lat, lon = FRAME.to_latlon(*np.array([*BOUNDARY_XY, BOUNDARY_XY[0]]).T)
    np.testing.assert_allclose(bt["y"], lat, atol=1e-7, rtol=0)
    np.testing.assert_allclose(bt["x"], lon, atol=1e-7, rtol=0)
    assert "clearance 20 m" in bt["hovertemplate"]
    (ot,) = _traces(fig, "obstacle: breakwater")
    ring = [*_breakwater_latlon(), _breakwater_latlon()[0]]
    np.testing.assert_allclose(ot["y"], [a for a, _ in ring], atol=1e-7, rtol=0)
    np.testing.assert_allclose(ot["x"], [b for _, b in ring], atol=1e-7, rtol=0)
    assert ot["fill"] == "toself" and "obstacle breakwater" in ot["hovertemplate"]
    clear = _traces(fig, "clearance kept")
    assert len(clear) == 2 and [t.get("showlegend") for t in clear] == [True, False]
    # under the marks and the route
    names = [t.get("name") for t in fig["data"]]
    assert names.index("obstacle: breakwater") < names.index("marks")
    assert names.index("race-area boundary") < names.index("route: reach")
    # the map's range takes in the boundary
    lo, hi = fig["layout"]["xaxis"]["range"]
    assert lo < min(bt["x"]) and hi > max(bt["x"])


def test_html_area_traces_are_valid_for_plotly(plan):
    go = pytest.importorskip("plotly.graph_objects")
    fig = figure(plan_report(plan, WIND))
    go.Figure(data=[t for t in fig["data"] if t.get("legendgroup") == "area"])


def test_cli_plan_writes_the_area(tmp_path):
    from typer.testing import CliRunner

    from sailroute.cli import app

    src = tmp_path / "harbour.yaml"
    src.write_text(course_text(), encoding="utf-8")
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["plan", str(src), "-o", str(out), "-q", "--no-plots"])
    assert res.exit_code == 0, res.output
    doc = json.loads((out / "plan.json").read_text(encoding="utf-8"))
    course = load_course(src)
    assert doc["area"] == json.loads(json.dumps(area_to_dict(course.area, course.frame)))


# ---------------------------------------------------------------- real: SailGP race XML
RACE_XML = SHARED_REAL / "races" / "sailgp-auckland-2025" / "Race_XMLs" / "25011908_04-23-32.xml"


@requires_shared
def test_imported_race_xml_area_in_every_output(tmp_path):
    """Race 25011908 imported with ``course import``: its ``Boundary`` (which holds every
    mark of this race) and the ``AY`` and ``BYOB`` zones, read here with ElementTree, come
    back in plan.json to 1e-7° and as one trace each in report.html."""
    from sailroute.commands.course_import import run_course_import_command

    run_course_import_command(
        RACE_XML, out=tmp_path / "r08.yaml", wind_twd_deg=225.0, wind_tws_kn=12.0
    )
    course = load_course(tmp_path / "r08.yaml")
    limits = {
        cl.get("name"): [(float(p.get("Lat")), float(p.get("Lon"))) for p in cl.iter("Limit")]
        for cl in ET.parse(RACE_XML).getroot().iter("CourseLimit")
    }
    wind = UniformWind(12.0 * 0.514444, 225.0)
    legs = []
    t = course.start_epoch
    for spec in course.legs:  # straight legs between the features' centres
        a = feature_centre(course.feature(spec.from_name))
        b = feature_centre(course.feature(spec.to_name))
        legs.append(make_leg_result(timed_track([a, b], t, wind), "test"))
        t = legs[-1].t_end
    plan = make_plan(course, "uniform", legs, wind)
    area = json.loads(json.dumps(plan_to_dict(plan)))["area"]
    got = {"Boundary": area["boundary"], **{o["name"]: o for o in area["obstacles"]}}
    assert set(got) == {"Boundary", "AY", "BYOB"}
    for name, poly in got.items():
        ring = limits[name]
        if ring[0] == ring[-1]:
            ring = ring[:-1]
        assert len(poly["points"]) == len(ring), name
        for p, (lat, lon) in zip(poly["points"], ring, strict=True):
            assert abs(p["lat"] - lat) <= 1e-7 and abs(p["lon"] - lon) <= 1e-7, name
    fig = figure(plan_report(plan, wind))
    assert len(_traces(fig, "race-area boundary")) == 1
    for name in ("AY", "BYOB"):
        (tr,) = _traces(fig, f"obstacle: {name}")
        assert len(tr["x"]) == len(got[name]["points"]) + 1
    ax, arts = _by_gid(plot_plan(plan, wind))
    assert {"boundary", "obstacle:AY", "obstacle:BYOB"} <= set(arts)
    assert math.isfinite(ax.get_xlim()[0])
