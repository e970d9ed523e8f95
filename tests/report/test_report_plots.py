"""Route and comparison charts: the expected artists exist (no pixel comparison)."""

from __future__ import annotations

import numpy as np
import pytest

from sailroute.planning.result import compare
from sailroute.report.plots import WIND_GRID, plot_comparison, plot_plan, plot_route
from sailroute.units import wind_components
from sailroute.wind.analytic import AnalyticWind


def by_gid(fig, prefix):
    return [a for a in fig.findobj() if (a.get_gid() or "").startswith(prefix)]


def test_plot_route_artists(plan, wind, tmp_path):
    fig = plot_route(plan.course, plan.results, wind)
    legs = by_gid(fig, "leg:")
    assert sorted(a.get_gid() for a in legs) == ["leg:1", "leg:2", "leg:3"]
    for a, pl in zip(sorted(legs, key=lambda a: a.get_gid()), plan.legs, strict=True):
        assert len(a.get_segments()) == len(pl.result.track) - 1
        # coloured by boat speed in knots
        np.testing.assert_allclose(a.get_array(), pl.result.track.bsp_ms[:-1] / 0.514444, rtol=1e-5)
    (tacks,) = by_gid(fig, "tacks")
    (gybes,) = by_gid(fig, "gybes")
    assert len(tacks.get_xdata()) == 1 and len(gybes.get_xdata()) == 1
    m = plan.legs[0].result.manoeuvres[0]
    assert (tacks.get_xdata()[0], tacks.get_ydata()[0]) == (m.x, m.y)
    (marks,) = by_gid(fig, "marks")
    assert len(marks.get_xdata()) == len(plan.course.marks)
    assert len(by_gid(fig, "line:")) == 2 and len(by_gid(fig, "gate:")) == 1
    (q,) = by_gid(fig, "wind")
    assert q.N == WIND_GRID * WIND_GRID
    assert by_gid(fig, "wind-field") == []  # uniform wind: arrows only
    ax = fig.axes[0]
    assert ax.get_aspect() == 1.0
    assert any("boat speed" in a.get_ylabel() for a in fig.axes)
    path = tmp_path / "r.png"
    fig.savefig(path, dpi=40)
    assert path.read_bytes()[:4] == b"\x89PNG"


def test_plot_route_varying_wind_has_background(plan):
    wind = AnalyticWind(lambda t, x, y: wind_components(5.0 + 0.002 * y, 0.0 * x))
    fig = plot_plan(plan, wind)
    assert len(by_gid(fig, "wind-field")) == 1
    assert fig.axes[0].get_aspect() == 1.0  # the background image keeps the map's equal aspect
    assert "north" in fig.axes[0].get_title()


def test_plot_route_without_wind(plan):
    fig = plot_route(plan.course, plan.results)
    assert by_gid(fig, "wind") == []
    assert len(by_gid(fig, "leg:")) == 3


@pytest.mark.parametrize("with_map", [True, False])
def test_plot_comparison(plan, with_map):
    other = plan.__class__(plan.course, "copy", plan.legs, plan.references, plan.router)
    cmp = compare([plan, other])
    fig = plot_comparison(cmp, [plan, other] if with_map else [])
    assert len(by_gid(fig, "bars:north")) == 3 and len(by_gid(fig, "bars:copy")) == 3
    heights = [p.get_height() for p in by_gid(fig, "bars:north")]
    np.testing.assert_allclose(heights, [leg.time_s for leg in plan.legs])
    (ref,) = by_gid(fig, "reference:winner")
    np.testing.assert_allclose(ref.get_ydata(), [700.0, 300.0, 100.0])
    routes = by_gid(fig, "route:")
    assert len(routes) == (2 if with_map else 0)
    assert len(fig.axes) == (2 if with_map else 1)
    # the map as route.png draws it: the marks named, a scale bar and a north arrow
    names = sorted(a.get_text() for a in by_gid(fig, "mark-name:"))
    assert names == (sorted(plan.course.marks) if with_map else [])
    assert bool(by_gid(fig, "scale-bar")) == bool(by_gid(fig, "north-arrow")) == with_map
    if with_map:
        (text,) = [a for a in by_gid(fig, "scale-bar") if hasattr(a, "get_text")]
        assert text.get_text().endswith(" m")


# --- route.png conventions --------------------------------------------------------------------
from sailroute.report.plots import OFFSET_PT, local_time, repeat_index, speed_limits  # noqa: E402


def test_speed_scale_ignores_stops_and_is_at_least_2_kn_wide():
    bsp = np.r_[np.zeros(50), np.full(200, 6.28), np.full(10, 6.3)]  # stops + 0.02 kn noise
    lo, hi = speed_limits(bsp)
    assert lo > 5.0 and hi - lo == pytest.approx(2.0)
    assert lo <= 6.28 <= hi
    wide = np.linspace(3.0, 9.0, 101)
    lo, hi = speed_limits(wide)
    assert lo == pytest.approx(np.percentile(wide, 2)) and hi == pytest.approx(
        np.percentile(wide, 98)
    )


def test_speed_scale_skips_non_finite_speeds_and_rounds_for_the_web_page():
    # one scale for route.png and report.html: NaN and inf speeds do not count; the page
    # writes the limits to 2 decimals
    bsp = np.r_[np.linspace(3.0, 9.0, 101), np.nan, np.inf, -np.inf]
    assert speed_limits(bsp) == speed_limits(np.linspace(3.0, 9.0, 101))
    lo, hi = speed_limits(bsp, decimals=2)
    assert (lo, hi) == (
        round(np.percentile(np.linspace(3.0, 9.0, 101), 2), 2),
        round(np.percentile(np.linspace(3.0, 9.0, 101), 98), 2),
    )
    assert speed_limits(np.zeros(5)) == (0.0, 2.0)
    assert speed_limits(np.full(3, np.nan), span=3.0) == (0.0, 3.0)


def test_local_time_names_the_offset(plan):
    assert plan.course.utc_offset_s == 7200.0  # "2024-05-01T12:00:00+02:00"
    assert local_time(plan.t_start, plan.course.utc_offset_s) == "12:00 (UTC+02:00)"
    assert local_time(0.0, -4.5 * 3600) == "19:30 (UTC-04:30)"
    fig = plot_plan(plan)
    assert "start 12:00 (UTC+02:00)" in fig.axes[0].get_title()


def test_leg_numbers_lat_lon_axes_and_repeated_legs_offset(plan, wind):
    fig = plot_route(plan.course, plan.results, wind)
    nums = by_gid(fig, "legno:")
    assert sorted(a.get_text() for a in nums) == ["1", "2", "3"]
    labels = " ".join(a.get_xlabel() + a.get_ylabel() for a in fig.axes[0].child_axes)
    assert "longitude" in labels and "latitude" in labels
    # uniform wind: no per-leg wind arrows
    assert by_gid(fig, "wind-leg:") == []
    # the same leg twice: the second copy is drawn OFFSET_PT points to the side
    legs = [*plan.results, plan.results[1]]
    assert repeat_index(legs) == [0, 0, 0, 1]
    fig2 = plot_route(plan.course, legs)
    ax = fig2.axes[0]
    first, again = (
        next(a for a in by_gid(fig2, "leg:") if a.get_gid() == g) for g in ("leg:2", "leg:4")
    )
    fig2.canvas.draw()
    p1 = first.get_transform().transform(first.get_segments()[0][0])
    p2 = again.get_transform().transform(again.get_segments()[0][0])
    shift_pt = float(np.hypot(*(p2 - p1))) * 72.0 / fig2.dpi
    assert shift_pt == pytest.approx(OFFSET_PT, rel=1e-6)
    assert first.get_transform() == ax.transData


def test_varying_wind_draws_one_arrow_per_leg(plan):
    wind = AnalyticWind(lambda t, x, y: wind_components(5.0 + 0.002 * y, 0.0 * x))
    fig = plot_plan(plan, wind)
    assert sorted(a.get_gid() for a in by_gid(fig, "wind-leg:")) == [
        "wind-leg:1",
        "wind-leg:2",
        "wind-leg:3",
    ]
    title = fig.axes[0].get_legend().get_title().get_text()
    assert "wind at each leg's number" in title and "1: " in title
