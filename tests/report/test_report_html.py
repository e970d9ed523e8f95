"""``report.html`` builder (``sailroute.report.html``): what the page embeds is the plan.

The page is checked through the figure JSON it embeds (:func:`read_figure`); the 4.8 MB
plotly.js bundle is a file beside the page, not in it; ``test_report_browser.py`` loads
real pages in Chromium.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import re

import numpy as np
import pytest

from sailroute.course.load import course_from_mapping
from sailroute.planning.result import compare, make_plan
from sailroute.report.html import comparison_report, offset_text, plan_report
from sailroute.report.page import (
    ARROW_FILL,
    DIV_ID,
    N_STEPS,
    REPEAT_SHIFT,
    WIND_GRID,
    clock,
    clocks,
    course_area,
    route_from_plan,
    time_label,
    wind_layer,
)
from sailroute.report.page_figure import figure
from sailroute.report.page_render import read_figure, render_html
from sailroute.report.tables import format_duration
from sailroute.routing.track import make_leg_result
from sailroute.units import KNOT
from sailroute.wind.analytic import AnalyticWind
from tests.report.conftest import COURSE, timed_track


def page_of(report) -> tuple[str, dict]:
    page = render_html(report)
    return page, read_figure(page)


def route_trace(fig: dict, name: str) -> dict:
    (tr,) = [
        t
        for t in fig["data"]
        if t.get("name") == name and "customdata" in t and t["mode"].startswith("lines")
    ]
    return tr


def rotating_wind(t0: float, duration_s: float, speed_ms: float = 5.0) -> AnalyticWind:
    """Wind of constant speed whose FROM-direction turns from 0° to 90° over ``duration_s``."""

    def uv(t, x, y):
        frm = np.radians(90.0 * (t - t0) / duration_s) + 0.0 * x + 0.0 * y
        return -speed_ms * np.sin(frm), -speed_ms * np.cos(frm)

    return AnalyticWind(uv, name="rotating")


def test_offsets_and_clocks():
    assert offset_text(7200) == "UTC+02:00"
    assert offset_text(-12600) == "UTC-03:30"
    assert offset_text(0) == "UTC+00:00"
    t = 1714557600.0  # 2024-05-01T10:00:00Z
    assert clock(t) == "10:00:00" and clock(t, 7200) == "12:00:00"
    assert clock(t + 59.9999, -12600) == "06:30:59"  # truncated, as the ISO times in plan.json
    assert time_label(t, 7200) == "12:00:00 local (UTC+02:00) · 10:00:00 UTC"
    rng = np.random.default_rng(3)
    ts = np.concatenate([t + rng.uniform(0, 86400, 2000), [t - 1e-7, t + 0.9999996, np.nan]])
    got = clocks(ts, 7200)
    assert got[:-1] == [clock(x, 7200) for x in ts[:-1]] and got[-1] == ""


def test_plan_page_embeds_the_plan(plan, wind):
    page, fig = page_of(plan_report(plan, wind))
    course = plan.course
    # the route: every track point with its hover data
    rt = route_trace(fig, "route: north")
    tracks = [pl.result.track for pl in plan.legs]
    assert len(rt["x"]) == sum(len(tr) for tr in tracks)
    lat, lon = course.frame.to_latlon(
        np.concatenate([tr.x for tr in tracks]), np.concatenate([tr.y for tr in tracks])
    )
    np.testing.assert_allclose(rt["y"], lat, atol=1e-6, rtol=0)
    np.testing.assert_allclose(rt["x"], lon, atol=1e-6, rtol=0)
    cd = rt["customdata"]
    assert sorted({row[0] for row in cd}) == [1, 2, 3]  # leg numbers
    assert {k: row[1] for row in cd for k in [row[0]]} == {
        k + 1: pl.mode for k, pl in enumerate(plan.legs)
    }  # the wind mode of each leg
    # times: the course's start_time is 12:00:00+02:00
    assert cd[0][2:4] == ["12:00:00", "10:00:00"]
    assert cd[-1][2:4] == [clock(plan.t_end, 7200), clock(plan.t_end)]
    assert "local (UTC+02:00)" in rt["hovertemplate"]
    # TWS, |TWA|, tack, speed, VMG of one point (leg 1 upwind: VMG = bsp cos TWA)
    tr0 = tracks[0]
    assert cd[0][4] == pytest.approx(tr0.tws_ms[0] / KNOT, abs=0.006)
    assert cd[0][5] == pytest.approx(abs(tr0.twa_deg[0]), abs=0.06)
    assert cd[0][6] == ("stbd" if tr0.twa_deg[0] >= 0 else "port")
    assert cd[0][7] == pytest.approx(tr0.bsp_ms[0] / KNOT, abs=6e-4)
    assert cd[0][8] == pytest.approx(
        tr0.bsp_ms[0] * math.cos(math.radians(tr0.twa_deg[0])) / KNOT, abs=6e-4
    )
    # the marks, within 1e-6 degrees
    (marks,) = [t for t in fig["data"] if t.get("name") == "marks"]
    assert marks["text"] == list(course.marks)
    for name, x, y in zip(marks["text"], marks["x"], marks["y"], strict=True):
        assert (y, x) == pytest.approx((course.marks[name].lat, course.marks[name].lon), abs=1e-6)
    # tacks and gybes where the router put them
    man = [m for pl in plan.legs for m in pl.result.manoeuvres]
    (tacks,) = [t for t in fig["data"] if t.get("name") == "tacks"]
    assert len(tacks["x"]) == sum(m.kind == "tack" for m in man) == 1
    # the leg table: one row per leg, the leg times, the references
    for k, pl in enumerate(plan.legs):
        row = f"<td>{format_duration(pl.result.time_s)}</td>"
        assert row in page
        assert f"<td>{clock(pl.result.t_start, 7200)}</td>" in page, k
    assert page.count("<tr>") == 1 + len(plan.legs) + 1  # header, legs, total
    assert "<th>winner</th>" in page and "<th>model</th>" in page
    assert f'id="{DIV_ID}"' in page and '<script src="plotly.min.js"></script>' in page


def test_slider_moves_the_boat_along_the_route(plan, wind):
    report = plan_report(plan, wind)
    fig = figure(report)
    assert len(report.times) == N_STEPS
    assert report.times[0] == plan.t_start and report.times[-1] == pytest.approx(plan.t_end)
    boat_idx = next(i for i, t in enumerate(fig["data"]) if t["name"].startswith("boat:"))
    rt = route_from_plan(plan)
    assert len(fig["frames"]) == N_STEPS
    for k, fr in enumerate(fig["frames"]):
        assert fr["name"] == str(k)
        assert fr["traces"] == [boat_idx]  # uniform wind: only the boat moves
        (st,) = fr["data"]
        ok = np.isfinite(rt.t)
        assert st["y"][0] == pytest.approx(
            np.interp(report.times[k], rt.t[ok], rt.lat[ok]), abs=1e-6
        )
        assert st["x"][0] == pytest.approx(
            np.interp(report.times[k], rt.t[ok], rt.lon[ok]), abs=1e-6
        )
        assert st["customdata"][0][2] == clock(report.times[k], 7200)
    steps = fig["layout"]["sliders"][0]["steps"]
    assert [s["args"][0] for s in steps] == [[str(k)] for k in range(N_STEPS)]
    assert steps[0]["label"].startswith("12:00:00 local (UTC+02:00) · 10:00:00 UTC")
    finish = plan.course.frame.to_latlon(*plan.legs[-1].result.end_xy)
    last = fig["frames"][-1]["data"][0]
    assert (last["y"][0], last["x"][0]) == pytest.approx(tuple(map(float, finish)), abs=1e-6)


def test_uniform_wind_arrows_point_downwind(plan, wind):
    fig = figure(plan_report(plan, wind))  # 5 m/s from the north
    shafts, heads = (t for t in fig["data"] if t.get("legendgroup") == "wind0")
    assert shafts["name"] == f"wind {5 / KNOT:.1f} kn from 0°"
    assert len(heads["x"]) == WIND_GRID**2 and len(shafts["x"]) == 3 * WIND_GRID**2
    assert set(heads["marker"]["angle"]) == {180.0}  # the air goes south
    assert {tuple(c) for c in heads["customdata"]} == {(round(5 / KNOT, 1), 0.0)}
    # each shaft runs north to south, ARROW_FILL of a grid cell long (the only speed)
    frame = plan.course.frame
    lat0, lat1 = shafts["y"][0], shafts["y"][1]
    assert shafts["y"][2] is None and lat0 > lat1
    x0, y0 = frame.to_xy(lat0, shafts["x"][0])
    x1, y1 = frame.to_xy(lat1, shafts["x"][1])
    a = course_area(plan.course, [route_from_plan(plan)])
    cell = min(a[1] - a[0], a[3] - a[2]) / WIND_GRID
    assert math.hypot(float(x1 - x0), float(y1 - y0)) == pytest.approx(ARROW_FILL * cell, rel=1e-3)


def test_time_varying_wind_is_in_the_frames(plan):
    duration = plan.t_end - plan.t_start
    rot = rotating_wind(plan.t_start, duration)
    report = plan_report(plan, rot)
    (layer,) = report.winds
    assert not layer.steady and layer.tws_kn.shape == (N_STEPS, WIND_GRID**2)
    fig = figure(report)
    heads_idx = next(
        i
        for i, t in enumerate(fig["data"])
        if t.get("legendgroup") == "wind0" and t["mode"] == "markers"
    )
    for k in (0, N_STEPS // 2, N_STEPS - 1):
        fr = fig["frames"][k]
        st = fr["data"][fr["traces"].index(heads_idx)]
        frm = 90.0 * (report.times[k] - plan.t_start) / duration
        np.testing.assert_allclose(st["marker"]["angle"], (frm + 180.0) % 360.0, atol=0.051)
    assert fig["data"][heads_idx]["marker"]["angle"][0] == 180.0  # frame 0 drawn first
    assert "at each of the slider's" in " ".join(report.notes)


def test_comparison_page_has_every_scenario(plan, wind):
    other = dataclasses.replace(plan, scenario="veer")
    plans = [plan, other]
    veer = AnalyticWind(lambda t, x, y: (-5.0 + 0 * x, 0.0 * y), name="east")
    page, fig = page_of(comparison_report(compare(plans), plans, {"north": wind, "veer": veer}))
    for i, name in enumerate(("north", "veer")):
        rt = route_trace(fig, name)
        assert rt["legendgroup"] == f"route{i}" and rt.get("visible", True) is True
        boat = next(t for t in fig["data"] if t["name"] == f"boat: {name}")
        assert boat["legendgroup"] == f"route{i}"  # toggled with its route
    shafts = [
        t
        for t in fig["data"]
        if t.get("legendgroup", "").startswith("wind") and t["mode"] == "lines"
    ]
    assert [t["name"] for t in shafts] == [
        "wind: north 9.7 kn from 0°",
        "wind: veer 9.7 kn from 90°",
    ]
    assert "visible" not in shafts[0] and shafts[1]["visible"] == "legendonly"
    # both boats move in every frame
    boats = [i for i, t in enumerate(fig["data"]) if t["name"].startswith("boat:")]
    assert all(fr["traces"] == boats for fr in fig["frames"])
    assert "<th>north</th><th>veer</th>" in page
    assert "<summary>Legs: veer</summary>" in page
    assert fig["layout"]["legend"]["orientation"] == "v"  # many entries: beside the map


def test_page_is_deterministic_and_escapes_text(plan, wind):
    a = render_html(plan_report(plan, wind))
    assert a == render_html(plan_report(plan, wind))
    evil = dataclasses.replace(plan, scenario="x</script><b>")
    page = render_html(plan_report(evil, wind))
    assert "x</script>" not in page
    fig = read_figure(page)  # still parses
    assert route_trace(fig, "route: x&lt;/script&gt;&lt;b&gt;")
    assert "<h1>report test — x&lt;/script&gt;&lt;b&gt;</h1>" in page
    # nothing to fetch but the plotly.js bundle beside the page
    assert re.findall(r"<script src=\"([^\"]*)\"", page) == ["plotly.min.js"]
    assert "<link" not in page and "http" not in page.split("<script type")[0]


def test_figure_is_valid_for_plotly(plan, wind):
    """plotly's own validator accepts every trace, layout key and frame (plotly.js would
    silently ignore a misspelt attribute)."""
    go = pytest.importorskip("plotly.graph_objects")
    rot = rotating_wind(plan.t_start, plan.t_end - plan.t_start)
    other = dataclasses.replace(plan, scenario="veer")
    for report in (
        plan_report(plan, rot),
        comparison_report(compare([plan, other]), [plan, other], {"north": wind, "veer": rot}),
    ):
        fig = figure(report)
        go.Figure(data=fig["data"], layout=fig["layout"], frames=fig["frames"])


def test_wind_layer_clips_to_the_coverage_and_marks_missing_times(plan):
    from sailroute.wind.base import Coverage

    t0 = plan.t_start
    cover = Coverage(t0, t0 + 100.0, -500.0, 500.0, -200.0, 800.0)
    w = AnalyticWind(lambda t, x, y: (0.0 * x, -3.0 + 0.0 * y), cover=cover, name="boxed")
    layer = wind_layer(
        "boxed",
        w,
        plan.course,
        (-1000.0, 1000.0, -1000.0, 1000.0),
        np.array([t0, t0 + 50.0, t0 + 500.0]),
    )
    assert layer is not None and layer.tws_kn.shape == (3, WIND_GRID**2)
    assert layer.x.min() > -500.0 and layer.x.max() < 500.0  # cell centres inside the box
    assert layer.y.min() > -200.0 and layer.y.max() < 800.0
    assert layer.spacing_m == pytest.approx(1000.0 / WIND_GRID)
    np.testing.assert_allclose(layer.tws_kn[:2], 3.0 / KNOT)
    assert np.isnan(layer.tws_kn[2]).all()  # after the data end: no arrows, not an error
    assert not layer.steady and not layer.uniform
    outside = (2000.0, 3000.0, 2000.0, 3000.0)
    assert wind_layer("boxed", w, plan.course, outside, np.array([t0])) is None


def test_legs_over_the_same_water_are_drawn_side_by_side(wind):
    # start -> top -> gate -> top -> gate: leg 4 sails the water of leg 2 (same ends)
    data = copy.deepcopy(COURSE)
    data["legs"] = [{"to": "top"}, {"to": "gate"}, {"to": "top"}, {"to": "gate"}]
    del data["references"], data["scenarios"]["north"]["references"]
    course = course_from_mapping(data)
    legs, t = [], course.start_epoch
    for pts in (
        [(-50, 0), (-550, 500), (0, 1000)],
        [(0, 1000), (200, 600), (10, 200)],
        [(10, 200), (-480, 690), (0, 1000)],
        [(0, 1000), (200, 600), (10, 200)],
    ):
        legs.append(make_leg_result(timed_track(pts, t, wind), "test"))
        t = legs[-1].t_end
    plan = make_plan(course, "north", legs, wind)
    _, fig = page_of(plan_report(plan, wind))
    rt = route_trace(fig, "route: north")
    leg = np.array([row[0] for row in rt["customdata"]])
    x, y = course.frame.to_xy(np.array(rt["y"]), np.array(rt["x"]))  # where it is drawn
    true_x = np.concatenate([r.track.x for r in legs])
    true_y = np.concatenate([r.track.y for r in legs])
    # legs 1-3 are drawn where they were sailed (1e-7° of rounding: about 1 cm)
    first = leg < 4
    np.testing.assert_allclose(x[first], true_x[first], atol=0.02, rtol=0)
    np.testing.assert_allclose(y[first], true_y[first], atol=0.02, rtol=0)
    # leg 4 is shifted to the right of its direction (0, 1000) -> (10, 200) by
    # REPEAT_SHIFT of the longest leg (start -> top, 1001.2 m): (-15.02, -0.19) m
    step = REPEAT_SHIFT * math.hypot(50.0, 1000.0)
    d = math.hypot(10.0, 800.0)
    np.testing.assert_allclose(x[~first] - true_x[~first], step * -800.0 / d, atol=0.02)
    np.testing.assert_allclose(y[~first] - true_y[~first], -step * 10.0 / d, atol=0.02)
    # the hover gives the true position
    lat, lon = course.frame.to_latlon(true_x, true_y)
    np.testing.assert_allclose([row[9] for row in rt["customdata"]], lat, atol=1e-6, rtol=0)
    np.testing.assert_allclose([row[10] for row in rt["customdata"]], lon, atol=1e-6, rtol=0)
    assert "%{customdata[9]:.5f}° N %{customdata[10]:.5f}° E" in rt["hovertemplate"]
    # the gybes of legs 2 and 4 (both at (200, 600)): the second drawn on the shifted line
    (gybes,) = [tr for tr in fig["data"] if tr.get("name") == "gybes"]
    gx, gy = course.frame.to_xy(np.array(gybes["y"]), np.array(gybes["x"]))
    np.testing.assert_allclose(gx, [200.0, 200.0 + step * -800.0 / d], atol=0.02)
    np.testing.assert_allclose(gy, [600.0, 600.0 - step * 10.0 / d], atol=0.02)
