"""The chart under the maps: a course's ``chart`` file, the wind's land mask, GSHHG, and
what the page says it lacks.

The course ``tests/data/course/giens-shore.yaml`` lies off the east shore of the Giens
tombolo; its chart is ``data/hyeres-coast.geojson`` (GSHHG's land, cut by
``data/make_hyeres_coast.py``), and its second scenario reads the synthetic WRF file whose
``LANDMASK`` is that coast on the file's 1 km grid (``data/make_synthetic_wrf.py``).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import shapely

from sailroute.course.chart import read_chart
from sailroute.course.load import load_course
from sailroute.errors import InputError
from sailroute.report.chart import Chart, LandLayer, chart_for, fit_chart, in_view
from sailroute.wind.landmask import land_mask, wrf_land_mask
from tests.conftest import ROOT, requires_shared

GIENS = ROOT / "tests" / "data" / "course" / "giens-shore.yaml"
COAST = ROOT / "data" / "hyeres-coast.geojson"
WRF = ROOT / "data" / "hyeres-2018-04-24-synthetic-wrfout.nc"


@pytest.fixture(scope="module")
def giens():
    return load_course(GIENS)


def test_chart_file_is_read_at_load(giens):
    assert giens.chart is not None and giens.chart.name == "hyeres-coast.geojson"
    doc = json.loads(COAST.read_text(encoding="utf-8"))
    assert len(giens.chart.land) == len(doc["features"]) > 3  # mainland, Giens, islands
    # the tombolo's east shore runs north-south at about 6.1487 E, 800 m west of mark 1
    land = shapely.union_all([shapely.Polygon(r) for r in giens.chart.land])
    assert land.contains(shapely.Point(6.1470, 43.0600))
    assert not land.contains(shapely.Point(6.1500, 43.0600))
    for m in giens.marks.values():  # every mark is on the water
        assert not land.contains(shapely.Point(m.lon, m.lat))


def test_chart_file_kml_lines_and_errors(tmp_path):
    kml = tmp_path / "c.kml"
    kml.write_text(
        '<kml xmlns="http://www.opengis.net/kml/2.2"><Document><Placemark><Polygon>'
        "<outerBoundaryIs><LinearRing><coordinates>6,43 6.01,43 6.01,43.01 6,43"
        "</coordinates></LinearRing></outerBoundaryIs></Polygon></Placemark><Placemark>"
        "<LineString><coordinates>6,43.02,0 6.02,43.02,0</coordinates></LineString>"
        "</Placemark></Document></kml>",
        encoding="utf-8",
    )
    c = read_chart(kml)
    assert len(c.land) == 1 and c.land[0].shape == (4, 2) and len(c.lines) == 1
    np.testing.assert_allclose(c.lines[0], [[6.0, 43.02], [6.02, 43.02]])
    with pytest.raises(ValueError, match="shapefiles are not read; convert it to GeoJSON"):
        read_chart(tmp_path / "coast.shp")
    empty = tmp_path / "e.geojson"
    empty.write_text('{"type": "FeatureCollection", "features": []}', encoding="utf-8")
    with pytest.raises(ValueError, match="no land polygon or shoreline"):
        read_chart(empty)
    swapped = tmp_path / "s.geojson"
    swapped.write_text('{"type": "LineString", "coordinates": [[43, 600], [43, 601]]}')
    with pytest.raises(ValueError, match="not longitude/latitude degrees"):
        read_chart(swapped)


def test_a_missing_chart_file_is_a_course_error(tmp_path):
    text = GIENS.read_text(encoding="utf-8").replace(
        "chart: ../../../data/hyeres-coast.geojson", "chart: nowhere.geojson"
    )
    text = text.replace("../../../data/", str(ROOT / "data") + "/")
    path = tmp_path / "c.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=r"c\.yaml:\d+: chart: file not found: .*nowhere"):
        load_course(path)


def test_the_shore_of_the_chart_file_is_taken_into_the_map(giens):
    marks = [(m.x, m.y) for m in giens.marks.values()]
    box = (
        min(x for x, _ in marks),
        max(x for x, _ in marks),
        min(y for _, y in marks),
        max(y for _, y in marks),
    )
    x0, x1, y0, y1 = fit_chart(giens, box)
    span = max(box[1] - box[0], box[3] - box[2])
    # the gate is 150 m off the beach: the map reaches 15 % of the span past the shore
    shore_x = float(giens.frame.to_xy(43.06, 6.1487)[0])
    assert x0 == pytest.approx(shore_x - 0.15 * span, abs=25.0)
    assert (x1, y0 <= box[2], y1 >= box[3]) == (box[1], True, True)
    far = (box[0] + 5000, box[1] + 5000, box[2], box[3])  # 5 km out to sea
    assert fit_chart(giens, far) == far


def test_chart_layers_prefer_the_file_and_name_what_is_missing(giens):
    from sailroute.course.specs import build_wind

    extent = (-600.0, 500.0, -600.0, 400.0)
    ch = chart_for(giens, [build_wind(giens, "wrf")], extent)
    names = [layer.name for layer in ch.layers]
    assert names[0] == "land: hyeres-coast.geojson" and ch.layers[0].shown
    wrf = next(layer for layer in ch.layers if "LANDMASK" in layer.name)
    assert not wrf.shown and "(1.0 km cells)" in wrf.name
    assert in_view(ch.layers[0], extent)
    assert "a chart file" not in ch.note() and "a land mask" not in ch.note()
    plain = chart_for(load_course(ROOT / "courses" / "windward-leeward-template.yaml"), [], extent)
    assert "a chart file (course key chart" in plain.note()
    assert "a land mask in the wind data" in plain.note()
    assert Chart().note().startswith("Chart: no land drawn")


def test_wrf_land_mask_draws_the_land_cells_without_a_chart_file():
    """The synthetic file's LANDMASK, as 1 km cells: their area is the count of land cells
    in the clipped box (each cell one DX by DY, the grid's map factor near 1)."""
    from sailroute.geo import LocalFrame

    frame = LocalFrame(43.069067, 6.198550)
    mask = wrf_land_mask(WRF, frame)
    assert mask is not None and mask.land.shape == (25, 25)
    assert mask.spacing_m == pytest.approx(1000.0, rel=0.01)
    assert int(mask.land.sum()) == 257
    from sailroute.report.chart import _cells

    area = _cells(mask).area
    assert area == pytest.approx(257 * 1000.0**2, rel=0.02)


def test_a_grid_with_nan_cells_gives_them_as_land():
    from sailroute.wind.grid import GridWind

    x, y = np.meshgrid(np.arange(4) * 500.0, np.arange(3) * 500.0)
    u = np.ones((2, 3, 4))
    u[:, 0, :2] = np.nan
    g = GridWind([0.0, 3600.0], x, y, u, u.copy(), allow_nan=True)
    m = land_mask(g)
    assert m is not None and m.land.sum() == 2 and m.land[0, :2].all()
    assert land_mask(GridWind([0.0, 1.0], x, y, np.ones((2, 3, 4)), np.ones((2, 3, 4)))) is None


@requires_shared
def test_a_real_wrf_files_land_mask():
    """salem's WRF sample (Tibetan Plateau): LANDMASK 1 on 79 of its 80 cells (one lake)."""
    from sailroute.geo import LocalFrame

    path = ROOT.parent / "shared" / "data" / "real" / "wrf" / "salem" / "wrf_d01_allvars_cropped.nc"
    m = wrf_land_mask(path, LocalFrame(30.0, 87.0))
    assert m is not None and m.land.shape == (8, 10) and int(m.land.sum()) == 79
    assert m.spacing_m == pytest.approx(30000.0, rel=0.02)


def test_html_and_png_draw_the_layers(giens):
    """The page's land trace and route.png's land patches are the shown layer's rings."""
    from sailroute.report.chart import draw_chart
    from sailroute.report.page_figure import land_traces

    ring = np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 0.0]])
    ch = Chart((LandLayer("land: a", (ring,)), LandLayer("land: b", (ring,), shown=False)))
    traces = land_traces(ch, giens.frame)
    assert [t["name"] for t in traces] == ["land: a", "land: b"]
    assert traces[0]["fill"] == "toself" and "visible" not in traces[0]
    assert traces[1]["visible"] == "legendonly"
    lat, lon = giens.frame.to_latlon(100.0, 80.0)
    assert (traces[0]["x"][2], traces[0]["y"][2]) == pytest.approx(
        (float(lon), float(lat)), abs=1e-6
    )
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    draw_chart(ax, ch, (-50.0, 150.0, -50.0, 150.0))
    (pc,) = [c for c in ax.collections if c.get_gid() == "land:0"]
    np.testing.assert_allclose(pc.get_paths()[0].vertices[:4], ring)
    assert pc.get_label() == "land: a"
    ax2 = Figure().add_subplot()
    draw_chart(ax2, ch, (500.0, 600.0, 500.0, 600.0))  # out of view: no legend entry
    assert ax2.collections[0].get_label().startswith("_")


@pytest.mark.slow
def test_a_course_with_a_chart_file_draws_the_shore_in_html_and_png(tmp_path):
    """``sailroute plan`` of the Giens course: report.html has the coast as its first,
    shown land trace, within the map's range; route.png has its land patch in view."""
    import subprocess
    import sys

    from sailroute.report.page_render import read_figure

    proc = subprocess.run(
        [sys.executable, "-m", "sailroute", "plan", str(GIENS), "-o", str(tmp_path), "-q"],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    fig = read_figure((tmp_path / "report.html").read_text(encoding="utf-8"))
    land = [t for t in fig["data"] if t.get("meta") == "land"]
    assert land[0]["name"] == "land: hyeres-coast.geojson" and "visible" not in land[0]
    x0, x1 = fig["layout"]["xaxis"]["range"]
    y0, y1 = fig["layout"]["yaxis"]["range"]
    rings, ring = [], []
    for x, y in zip([*land[0]["x"], None], [*land[0]["y"], None], strict=True):
        if x is None:
            rings.append(shapely.Polygon(ring))
            ring = []
        else:
            ring.append((x, y))
    drawn = shapely.union_all([shapely.make_valid(r) for r in rings])
    view = shapely.box(x0, y0, x1, y1)
    share = drawn.intersection(view).area / view.area
    assert 0.03 < share < 0.5  # a strip of land along the map's west side
    assert "Chart: land from hyeres-coast.geojson" in fig["chart"]["note"]
    from matplotlib.image import imread

    img = imread(tmp_path / "route.png")[..., :3]
    beige = np.all(np.abs(img - np.array([0xEE, 0xEA, 0xDF]) / 255.0) < 0.02, axis=-1)
    assert beige.mean() > 0.03  # the land fills a strip of the map
    assert math.isfinite(float(beige.mean()))
