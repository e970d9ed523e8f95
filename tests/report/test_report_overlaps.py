"""No label overlaps another, a mark, the boat or the route, on every shipped course.

The pages of the shipped courses (``courses/*.yaml``) are written by the commands as a
user runs them (``plan``, ``plan --ensemble``, ``compare-scenarios``, ``analyze`` of the
shipped Snipe track), opened in headless Chromium at 1280 and 1920 px (a screenshot of
each is kept), and the boxes of what was drawn are read from the rendered page's DOM and
SVG (``overlaps.js``: the annotations' text boxes, the symbol points, the legend, the scale
bar; the marks' and the boat's points; the route lines' vertices through their screen
matrices).  ``route.png`` of each course is measured from matplotlib's artist extents.
The measure is the test's own: two boxes overlap when they share more than 0.5 px both
ways; a box meets the route when a route segment passes through it (tack and gybe
symbols and leg numbers lie on their route by design and are exempt from that one).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import ROOT
from tests.report.test_report_browser import CHROMIUM, REQUIRED

COURSES = sorted((ROOT / "courses").glob("*.yaml"))
TOL = 0.5
WIDTHS = (1280, 1920)

pytestmark = pytest.mark.slow


def _crosses(box, seg) -> bool:
    """Whether the segment ``(x0, y0, x1, y1)`` passes through the box (Liang-Barsky)."""
    x0, y0, x1, y1 = seg
    dx, dy = x1 - x0, y1 - y0
    t0, t1 = 0.0, 1.0
    for p, q in (
        (-dx, x0 - box[0]),
        (dx, box[2] - x0),
        (-dy, y0 - box[1]),
        (dy, box[3] - y0),
    ):
        if p == 0:
            if q < 0:
                return False
            continue
        t = q / p
        if p < 0:
            t0 = max(t0, t)
        else:
            t1 = min(t1, t)
        if t0 > t1:
            return False
    return True


def overlaps(items, fixed, routes) -> list[str]:
    """Every pair of items that overlap, every item over a fixed box, every item (not
    allowed on the route) that a route segment passes through."""
    out = []
    shrunk = [(n, (x0 + TOL, y0 + TOL, x1 - TOL, y1 - TOL), r) for n, x0, y0, x1, y1, r in items]
    for i, (a, ba, _) in enumerate(shrunk):
        for b, bb, _ in shrunk[i + 1 :]:
            if min(ba[2], bb[2]) > max(ba[0], bb[0]) and min(ba[3], bb[3]) > max(ba[1], bb[1]):
                out.append(f"{a} overlaps {b}")
        for b, *fb in fixed:
            if min(ba[2], fb[2]) > max(ba[0], fb[0]) and min(ba[3], fb[3]) > max(ba[1], fb[1]):
                out.append(f"{a} covers {b}")
    segs = np.asarray(routes, float).reshape(-1, 4)
    for a, ba, on_route in shrunk:
        if on_route:
            continue
        near = segs[
            (np.maximum(segs[:, 0], segs[:, 2]) >= ba[0])
            & (np.minimum(segs[:, 0], segs[:, 2]) <= ba[2])
            & (np.maximum(segs[:, 1], segs[:, 3]) >= ba[1])
            & (np.minimum(segs[:, 1], segs[:, 3]) <= ba[3])
        ]
        if any(_crosses(ba, s) for s in near):
            out.append(f"{a} is on the route")
    return out


def test_the_overlap_measure_sees_what_it_must():
    items = [
        ("a", 0, 0, 10, 10, False),
        ("b", 8, 8, 20, 20, False),  # a 2 px corner: an overlap
        ("c", 30, 0, 40, 10, False),
        ("d", 40.2, 0, 50, 10, False),  # touching within 0.5 px: none
        ("e", 60, 0, 70, 10, True),
    ]
    fixed = [("mark", 35, 5, 37, 7)]
    routes = [(55, 5, 75, 5), (0, 30, 100, 30)]
    assert overlaps(items, fixed, routes) == ["a overlaps b", "c covers mark"]
    assert overlaps([("f", 50, 0, 58, 10, False)], [], routes) == ["f is on the route"]


def _run(*args: str) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "sailroute", *args, "-q"], capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr[-3000:]


@pytest.fixture(scope="module")
def pages(tmp_path_factory) -> dict[str, Path]:
    """The report.html of every page kind of the shipped courses, written by the CLI."""
    out = tmp_path_factory.mktemp("pages")
    found = {}
    for c in COURSES:
        _run("plan", str(c), "-o", str(out / c.stem / "plan"))
        found[f"{c.stem} plan"] = out / c.stem / "plan" / "report.html"
        text = c.read_text(encoding="utf-8")
        if text.count("type: uniform") + text.count("type: wrf") + text.count("type: stations") > 1:
            _run("compare-scenarios", str(c), "-o", str(out / c.stem / "cmp"))
            found[f"{c.stem} compare-scenarios"] = out / c.stem / "cmp" / "report.html"
    wl = ROOT / "courses" / "windward-leeward-template.yaml"
    _run("plan", str(wl), "--ensemble", "3", "-o", str(out / "bands"))
    found["windward-leeward-template bands"] = out / "bands" / "report.html"
    snipe = ROOT / "courses" / "snipe-valencia-p01.yaml"
    gpx = ROOT / "data" / "snipe-valencia-2025-06-21-ESP30782-P01.gpx"
    _run("analyze", str(snipe), str(gpx), "-o", str(out / "analyze"))
    found["snipe-valencia-p01 analyze"] = out / "analyze" / "report.html"
    return found


@pytest.mark.browser
@pytest.mark.skipif(CHROMIUM is None and not REQUIRED, reason="no Chromium installed")
def test_no_label_overlaps_on_the_shipped_pages(pages, tmp_path):
    from tests.report.cdp import browser, page_errors

    # Hyeres's page stays small beside the shared drawing library
    hyeres = pages["hyeres-r1 plan"]
    assert hyeres.stat().st_size < 1_000_000
    assert (hyeres.parent / "plotly.min.js").stat().st_size > 3_000_000

    script = (Path(__file__).parent / "overlaps.js").read_text(encoding="utf-8")
    found = {}
    for width in WIDTHS:
        with browser(CHROMIUM, width, 1100) as tab:
            for name, page in pages.items():
                tab.open(page.as_uri())
                tab.wait_for("document.body.hasAttribute('data-placed')")
                assert tab.evaluate("document.body.getAttribute('data-map')") == "drawn", name
                tab.screenshot(tmp_path / f"{name.replace(' ', '-')}-{width}.png")
                boxes = json.loads(tab.evaluate(script))
                assert boxes["routes"], f"{name}: no route measured"
                assert len(boxes["items"]) > len(boxes["fixed"]) > 0, name
                found[f"{name} at {width} px"] = overlaps(**boxes)
            assert page_errors(tab.console) == []
    assert {k: v for k, v in found.items() if v} == {}
    assert len(found) == 2 * len(pages) >= 2 * (len(COURSES) + 4)


def _png_boxes(fig, ax_index: int = 0):
    """items, fixed, routes of a map figure (route.png, or the map of comparison.png at
    ``ax_index``), from its artists' extents [px]."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    r = fig.canvas.get_renderer()
    ax = fig.axes[ax_index]
    k = fig.dpi / 72.0
    items, fixed, routes = [], [], []
    for a in fig.findobj():
        gid = a.get_gid() or ""
        if gid.startswith(("mark-name:", "legno:", "favoured-label")):
            patch = a.get_bbox_patch()
            e = (patch or a).get_window_extent(r)
            items.append((gid, e.x0, e.y0, e.x1, e.y1, gid.startswith("legno:")))
        elif gid in ("tacks", "gybes", "favoured-end", "marks"):
            half = 0.5 * a.get_markersize() * k
            for i, p in enumerate(ax.transData.transform(np.column_stack(a.get_data()))):
                box = (p[0] - half, p[1] - half, p[0] + half, p[1] + half)
                if gid == "marks":
                    fixed.append((f"mark:{i}", *box))
                else:
                    items.append((f"{gid}:{i}", *box, gid != "favoured-end"))
        elif gid.startswith("leg:"):
            for s in a.get_segments():
                q = a.get_transform().transform(s)
                routes.append((*q[0], *q[1]))
        elif gid.startswith("route:"):  # comparison.png: a scenario's route, one line
            q = a.get_transform().transform(np.column_stack(a.get_data()))
            routes.extend((*q[i], *q[i + 1]) for i in range(len(q) - 1))
    furniture = [
        a.get_window_extent(r) for a in fig.findobj() if a.get_gid() in ("scale-bar", "north-arrow")
    ]
    items.append(
        (
            "scale bar and north arrow",
            min(e.x0 for e in furniture),
            min(e.y0 for e in furniture),
            max(e.x1 for e in furniture),
            max(e.y1 for e in furniture),
            False,
        )
    )
    e = ax.get_legend().get_window_extent(r)
    items.append(("legend", e.x0, e.y0, e.x1, e.y1, False))
    return items, fixed, routes


@pytest.mark.parametrize("course", COURSES, ids=lambda p: p.stem)
def test_no_label_overlaps_on_comparison_png(course):
    """comparison.png's map: the routes of the course's first two scenarios (its only one
    where it has one), the marks named, a scale bar and a north arrow."""
    from sailroute.course.load import load_course
    from sailroute.planning.result import compare
    from sailroute.planning.route import plan_course
    from sailroute.report.plots import plot_comparison

    c = load_course(course)
    runs = [plan_course(c, s) for s in list(c.scenarios)[:2]]
    fig = plot_comparison(compare([r.plan for r in runs]), [r.plan for r in runs])
    items, fixed, routes = _png_boxes(fig, ax_index=1)
    names = [n for n, *_ in items if n.startswith("mark-name:")]
    assert len(names) == len(c.marks) and fixed and routes
    assert overlaps(items, fixed, routes) == []


@pytest.mark.parametrize("course", COURSES, ids=lambda p: p.stem)
def test_no_label_overlaps_on_route_png(course):
    from sailroute.course.load import load_course
    from sailroute.planning.route import plan_course
    from sailroute.report.plots import plot_plan

    run = plan_course(load_course(course))
    items, fixed, routes = _png_boxes(plot_plan(run.plan, run.wind))
    assert routes and fixed and len(items) > len(run.plan.course.marks)
    assert overlaps(items, fixed, routes) == []
