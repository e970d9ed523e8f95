"""Route and comparison charts (matplotlib object-oriented API, no ``pyplot``).

matplotlib is imported inside the functions so that ``plan --no-plots`` never
pays for it, and no global figure state or GUI backend is touched: each function
returns a :class:`matplotlib.figure.Figure` that the caller saves.

Artists carry a ``gid`` so tests and callers can find them: ``leg:<n>`` (one
``LineCollection`` per leg, coloured by boat speed), ``tacks``/``gybes`` (marker
lines, one point per manoeuvre), ``marks``, ``line:<name>``, ``gate:<name>``,
``wind`` (quiver), ``wind-field`` (speed background, only for non-uniform wind),
``legno:<n>`` (the leg number, on the track), ``wind-leg:<n>`` (the wind where and when
the boat passes the leg's number; drawn only when the wind differs between legs),
``route:<scenario>`` and ``bars:<scenario>`` in comparison charts; the race area's
``boundary``, ``obstacle:<name>`` and their dashed clearances
(:func:`sailroute.report.area.draw_area`).

Map conventions (``route.png``): x/y metres of the course's local frame with latitude
and longitude on the top and right axes; the boat-speed colour scale spans the 2nd-98th
percentile of the moving speeds (penalty stops do not pull it to 0) and at least 2 kn (a
few hundredths of a knot of noise do not look like a change); a leg sailed again over
the same water as an earlier one (the same marks, e.g. the second run of a
windward-leeward) is drawn shifted sideways by a few pixels so both stay visible; times
are the course's local time with its UTC offset.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sailroute.course.model import Course
from sailroute.errors import OutOfCoverageError
from sailroute.planning.result import Comparison, Plan
from sailroute.report.area import draw_area, fit_area
from sailroute.routing.laylines import Layline
from sailroute.routing.startline import StartLineNumbers
from sailroute.routing.types import LegResult
from sailroute.timeutil import iso, offset_text
from sailroute.units import KNOT, circular_mean_deg, wind_speed_direction
from sailroute.wind.base import WindField

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

WIND_GRID = 15
"""Wind arrows per side of the plotted area."""


def _extent(course: Course, legs: Sequence[LegResult], pad: float = 0.08) -> tuple[float, ...]:
    """``(x0, x1, y0, y1)`` [m]: the marks and legs, and the race area within reach of
    them (:func:`sailroute.report.area.fit_area`), padded by ``pad`` of the larger side."""
    xs = [m.x for m in course.marks.values()]
    ys = [m.y for m in course.marks.values()]
    for r in legs:
        xs += [float(r.track.x.min()), float(r.track.x.max())]
        ys += [float(r.track.y.min()), float(r.track.y.max())]
    from sailroute.report.chart import fit_chart

    x0, x1, y0, y1 = fit_chart(course, fit_area(course.area, (min(xs), max(xs), min(ys), max(ys))))
    span = max(x1 - x0, y1 - y0, 100.0)
    return x0 - pad * span, x1 + pad * span, y0 - pad * span, y1 + pad * span


def _map_frame(ax: Axes, extent: Sequence[float]) -> None:
    """Plan view of ``extent`` = ``(x0, x1, y0, y1)`` [m]: equal aspect, axis labels, grid."""
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x, east [m]")
    ax.set_ylabel("y, north [m]")
    ax.grid(True, lw=0.3, alpha=0.5)


def draw_course(ax: Axes, course: Course) -> None:
    """Draw marks, start/finish lines (solid) and gates (dotted) on ``ax``; the marks'
    names are placed by :func:`sailroute.report.mapdraw.finish_map` (:func:`course_labels`)."""
    mx = [m.x for m in course.marks.values()]
    my = [m.y for m in course.marks.values()]
    ax.plot(
        mx,
        my,
        "o",
        color="darkorange",
        mec="black",
        ms=7,
        zorder=5,
        gid="marks",
        label="marks",
        linestyle="none",
    )
    for ln in course.lines.values():
        ax.plot(
            [ln.a.x, ln.b.x],
            [ln.a.y, ln.b.y],
            "-",
            color="black",
            lw=1.5,
            zorder=4,
            gid=f"line:{ln.name}",
        )
    for g in course.gates.values():
        ax.plot(
            [g.a.x, g.b.x],
            [g.a.y, g.b.y],
            ":",
            color="black",
            lw=1.2,
            zorder=4,
            gid=f"gate:{g.name}",
        )


def course_labels(course: Course) -> dict[str, Any]:
    """The keyword arguments of :func:`~sailroute.report.mapdraw.finish_map` for a
    course: its marks and its lines and gates (which names keep off)."""
    return {
        "marks": [(m.name, m.x, m.y) for m in course.marks.values()],
        "lines": [
            np.array([[ln.a.x, ln.a.y], [ln.b.x, ln.b.y]])
            for ln in (*course.lines.values(), *course.gates.values())
        ],
    }


def _draw_wind(
    ax: Axes,
    fig: Figure,
    wind: WindField,
    t: float,
    extent: tuple[float, ...],
    utc_offset_s: float = 0.0,
) -> str | None:
    """Quiver (and speed background if the field varies) at time ``t``; returns a label."""
    x0, x1, y0, y1 = extent
    c = wind.coverage
    gx0, gx1 = max(x0, c.xmin), min(x1, c.xmax)
    gy0, gy1 = max(y0, c.ymin), min(y1, c.ymax)
    if gx0 >= gx1 or gy0 >= gy1 or not (c.t0 <= t <= c.t1):
        return None
    gx, gy = np.meshgrid(np.linspace(gx0, gx1, WIND_GRID), np.linspace(gy0, gy1, WIND_GRID))
    try:
        u, v = wind.sample(t, gx, gy)
    except OutOfCoverageError:
        return None
    spd, twd = wind_speed_direction(u, v)
    if float(np.ptp(spd)) > 1e-6 or float(np.ptp(np.cos(np.radians(twd)))) > 1e-6:
        lo, hi = speed_limits(np.ravel(spd) / KNOT)  # >= 2 kn wide: noise stays pale
        mesh = ax.imshow(
            spd / KNOT,
            extent=(gx0, gx1, gy0, gy1),
            origin="lower",
            cmap="Blues",
            alpha=0.35,
            interpolation="bilinear",
            zorder=0,
            aspect="auto",
            vmin=lo,
            vmax=hi,
        )
        mesh.set_gid("wind-field")
        fig.colorbar(mesh, ax=ax, shrink=0.8, pad=0.1, fraction=0.03, label="wind speed [kn]")
    q = ax.quiver(gx, gy, u, v, color="0.35", alpha=0.7, zorder=1, angles="xy", pivot="middle")
    q.set_gid("wind")
    mean_dir = circular_mean_deg(twd, weights=spd) if float(spd.sum()) > 0 else 0.0
    return (
        f"grey arrows: wind at {local_time(t, utc_offset_s)}, "
        f"{float(spd.mean()) / KNOT:.1f} kn from {mean_dir:.0f}°"
    )


SPEED_SPAN_KN = 2.0
"""Smallest span of a boat-speed colour scale [kn] (noise does not look like a change)."""
OFFSET_PT = 4.0
"""Sideways shift of a leg that repeats an earlier one [points]."""


def speed_limits(
    values: NDArray, span: float = SPEED_SPAN_KN, decimals: int | None = None
) -> tuple[float, float]:
    """Colour-scale limits [kn] of boat speeds ``values`` [kn].

    The 2nd-98th percentile of the finite speeds above 0.05 kn (moving), widened about its
    middle to at least ``span`` [kn] (so that noise does not look like a change) and kept
    >= 0; ``(0, span)`` when nothing moves.  ``decimals``: round both limits (the web
    page writes them so).
    """
    v = np.asarray(values, float)
    v = v[np.isfinite(v) & (v > 0.05)]
    if v.size == 0:
        return 0.0, span
    lo, hi = (float(x) for x in np.percentile(v, [2.0, 98.0]))
    if hi - lo < span:
        lo = max(0.5 * (lo + hi - span), 0.0)
        hi = lo + span
    if decimals is None:
        return lo, hi
    return round(lo, decimals), round(hi, decimals)


def repeat_index(legs: Sequence[LegResult], tol_m: float = 30.0) -> list[int]:
    """For each leg, how many earlier legs started and ended at the same places (within
    ``tol_m``): 0 for a first passage, 1 for the second over the same water, ..."""
    return repeat_index_of_ends([(r.start_xy, r.end_xy) for r in legs], tol_m)


def repeat_index_of_ends(
    ends: Sequence[tuple[tuple[float, float], tuple[float, float]]], tol_m: float = 30.0
) -> list[int]:
    """:func:`repeat_index` of legs given as ``(start_xy, end_xy)`` pairs [m]."""
    out = []
    for k, (a, b) in enumerate(ends):
        same = sum(
            1
            for qa, qb in ends[:k]
            if np.hypot(*np.subtract(qa, a)) < tol_m and np.hypot(*np.subtract(qb, b)) < tol_m
        )
        out.append(same)
    return out


def local_time(t: float, utc_offset_s: float) -> str:
    """``HH:MM`` in the course's local time and its offset, e.g. ``12:10 (UTC+02:00)``."""
    return f"{iso(t + utc_offset_s)[11:16]} ({offset_text(utc_offset_s)})"


def _latlon_axes(ax: Axes, course: Course) -> None:
    """Latitude (right) and longitude (top) on secondary axes of the local x/y map."""
    frame = course.frame
    lat0, lon0 = frame.lat0, frame.lon0
    m_lat = 111_132.0  # metres per degree of latitude (WGS-84, mid-latitudes; ±0.5 %)
    m_lon = m_lat * float(np.cos(np.radians(lat0)))
    top = ax.secondary_xaxis(
        "top",
        functions=(
            lambda x: lon0 + np.asarray(x) / m_lon,
            lambda lon: (np.asarray(lon) - lon0) * m_lon,
        ),
    )
    right = ax.secondary_yaxis(
        "right",
        functions=(
            lambda y: lat0 + np.asarray(y) / m_lat,
            lambda lat: (np.asarray(lat) - lat0) * m_lat,
        ),
    )
    top.set_xlabel("longitude [°E]", fontsize=8)
    right.set_ylabel("latitude [°N]", fontsize=8)
    for a in (top, right):
        a.tick_params(labelsize=7)
    top.xaxis.set_major_formatter("{x:.3f}")
    right.yaxis.set_major_formatter("{x:.3f}")


def label_point(r: LegResult, k: int) -> int:
    """Track index where leg ``k``'s number goes: spread along the legs (golden-ratio
    steps between 30 % and 70 % of the track), so that legs over the same water, or
    crossing at their middles, do not put their numbers on top of each other."""
    frac = 0.3 + 0.4 * ((k * 0.6180339887) % 1.0)
    return min(int(frac * r.track.t.size), r.track.t.size - 1)


def _leg_wind(
    ax: Axes, wind: WindField, legs: Sequence[LegResult], extent: tuple[float, ...]
) -> str | None:
    """One arrow per leg where its number is (at that point's time); nothing when the wind
    is the same on every leg.  Returns the legend text ("1: 6.3 kn 149°, ...") or None."""
    size = 0.06 * max(extent[1] - extent[0], extent[3] - extent[2])
    samples = []
    for k, r in enumerate(legs):
        i = label_point(r, k)
        t, x, y = float(r.track.t[i]), float(r.track.x[i]), float(r.track.y[i])
        try:
            su, sv = wind.sample(t, x, y)
        except OutOfCoverageError:
            continue
        samples.append((k, x, y, float(su), float(sv)))
    if not samples:
        return None
    uv = np.array([(u, v) for *_, u, v in samples])
    if float(np.ptp(uv[:, 0])) < 0.02 and float(np.ptp(uv[:, 1])) < 0.02:
        return None  # the same wind on every leg: the background arrows say it all
    parts = []
    for k, x, y, u, v in samples:
        spd, twd = (float(a) for a in wind_speed_direction(u, v))
        if spd <= 0:
            continue
        ux, uy = u / spd, v / spd
        ax.annotate(
            "",
            xy=(x + 0.5 * size * ux, y + 0.5 * size * uy),
            xytext=(x - 0.5 * size * ux, y - 0.5 * size * uy),
            arrowprops={"arrowstyle": "-|>", "color": "steelblue", "lw": 1.6},
            zorder=8,
            gid=f"wind-leg:{k + 1}",
        )
        parts.append(f"{k + 1}: {spd / KNOT:.1f} kn {twd:.0f}°")
    rows = [", ".join(parts[i : i + 3]) for i in range(0, len(parts), 3)]
    return "blue arrows, wind at each leg's number:\n" + "\n".join(rows)


def plot_route(
    course: Course,
    legs: Sequence[LegResult],
    wind: WindField | None = None,
    t: float | None = None,
    *,
    title: str | None = None,
    utc_offset_s: float = 0.0,
    start_line: StartLineNumbers | None = None,
    laylines: Sequence[Sequence[Layline]] = (),
) -> Figure:
    """Map of a routed course.

    Parameters
    ----------
    course : Course
        Marks, lines and gates to draw, and the race area (boundary and obstacles,
        under the routes; the map's extent takes them in as
        :func:`sailroute.report.area.fit_area` says), over the chart
        (:func:`sailroute.report.chart.chart_for`: the course's chart file, GSHHG or the
        wind's land mask).
    legs : sequence of LegResult
        The routed legs; each is one ``LineCollection`` coloured by boat speed [kn].
    wind : WindField, optional
        Drawn at time ``t`` over the plotted area as arrows (direction the air
        moves), plus a speed background if the field is not uniform.
    t : float, optional
        Time of the wind drawing [epoch s]; default the first leg's start.
    title : str, optional
        Axes title.
    utc_offset_s : float
        The course's local offset from UTC [s], for the times shown.
    start_line : StartLineNumbers, optional
        Its favoured end is starred.
    laylines : sequence of sequence of Layline
        Per leg, its laylines (dashed grey).

    Returns
    -------
    matplotlib.figure.Figure
        The map, with the scale bar, north arrow and the names and symbols placed so that
        they overlap nothing (:func:`sailroute.report.mapdraw.finish_map`); the legend
        under the map.
    """
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    from matplotlib.transforms import offset_copy

    from sailroute.report.chart import chart_for, draw_chart
    from sailroute.report.mapdraw import MapItem, finish_map
    from sailroute.report.startline import draw_laylines

    extent = _extent(course, legs)
    aspect = (extent[3] - extent[2]) / (extent[1] - extent[0])
    # the map axes is about 7 in wide once the margins and colour bar are taken; the
    # legend goes under it
    map_h = float(np.clip(7.0 * aspect, 3.0, 9.4))
    height = map_h + 1.6 + LEGEND_IN
    fig = Figure(figsize=(10.0, height))
    # a fixed layout in inches (constrained layout cost 0.2-0.45 s of a 1.8 s plan):
    # room for the metre ticks (left, bottom) and the legend under them, the title and
    # longitude axis (top), and the latitude axis and colour bar (right)
    fig.subplots_adjust(
        left=0.75 / 10.0,
        right=1.0 - 1.2 / 10.0,
        bottom=(0.55 + LEGEND_IN) / height,
        top=1.0 - 0.85 / height,
    )
    ax = fig.add_subplot()
    if t is None:
        t = legs[0].t_start if legs else course.start_epoch
    wind_label = _draw_wind(ax, fig, wind, t, extent, utc_offset_s) if wind is not None else None
    chart = chart_for(course, [wind], extent)
    draw_chart(ax, chart, extent)
    draw_area(ax, course.area)
    draw_course(ax, course)
    draw_laylines(ax, laylines)
    bsp_all = np.concatenate([r.track.bsp_ms for r in legs]) / KNOT if legs else np.zeros(1)
    norm = Normalize(*speed_limits(bsp_all))
    lc = None
    repeats = repeat_index(legs)
    items: list[MapItem] = []
    shifts: list[tuple[float, float]] = []
    for k, r in enumerate(legs):
        pts = np.column_stack([r.track.x, r.track.y])
        segs = np.stack([pts[:-1], pts[1:]], axis=1)
        # an (n, 2, 2) array is the segment list matplotlib documents; its stubs want a Sequence
        lc = LineCollection(
            segs,  # type: ignore[arg-type]
            cmap="viridis",
            norm=norm,
            linewidths=2.2,
            zorder=3,
        )
        lc.set_array(r.track.bsp_ms[:-1] / KNOT)
        lc.set_gid(f"leg:{k + 1}")
        shifts.append((0.0, 0.0))
        if repeats[k]:  # the same water as an earlier leg: shift it sideways on screen
            dx, dy = np.subtract(r.end_xy, r.start_xy)
            n = float(np.hypot(dx, dy)) or 1.0
            off = OFFSET_PT * repeats[k]
            shifts[-1] = (off * dy / n, -off * dx / n)
            lc.set_transform(
                offset_copy(ax.transData, fig=fig, x=off * dy / n, y=-off * dx / n, units="points")
            )
        ax.add_collection(lc)
        i = label_point(r, k)
        items.append(MapItem("legno", float(r.track.x[i]), float(r.track.y[i]), str(k + 1)))
    legs_wind = _leg_wind(ax, wind, legs, extent) if wind is not None else None
    if legs_wind:
        wind_label = f"{wind_label}\n{legs_wind}" if wind_label else legs_wind
    if lc is not None:
        # beside the map's latitude axis (a wind speed bar moves out beyond it)
        fig.colorbar(lc, ax=ax, label="boat speed [kn]", shrink=0.8, pad=0.09, fraction=0.04)
    items += [MapItem(m.kind, m.x, m.y) for r in legs for m in r.manoeuvres]
    if start_line is not None and start_line.favoured_xy is not None:
        fx, fy = start_line.favoured_xy
        items.append(MapItem("favoured", fx, fy, f"favoured +{start_line.gain_m:.0f} m"))
    _map_frame(ax, extent)
    _latlon_axes(ax, course)
    ax.set_title(title or course.name, fontsize=10)
    finish_map(
        fig,
        ax,
        routes=[np.column_stack([r.track.x, r.track.y]) for r in legs],
        items=items,
        shifts_pt=shifts,
        **course_labels(course),
    )
    legend_under(ax, wind_label)
    return fig


LEGEND_IN = 1.1
"""Height under the map kept for its legend [in]."""


def legend_under(ax: Axes, title: str | None = None) -> None:
    """The map's legend under it (it covers nothing of the map), in columns."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return
    ax.apply_aspect()
    height_in = ax.get_position().height * float(ax.get_figure(root=True).get_figheight())  # type: ignore[union-attr]
    ax.legend(
        handles,
        labels,
        loc="upper left",
        bbox_to_anchor=(0.0, -0.42 / max(height_in, 0.5)),
        ncol=min(4, len(handles)),
        fontsize=8,
        title=title,
        title_fontsize=8,
        frameon=False,
        alignment="left",
    )


def plot_plan(plan: Plan, wind: WindField | None = None) -> Figure:
    """:func:`plot_route` of a :class:`Plan` with a title giving scenario and total time,
    its laylines (dashed grey) and the favoured end of the start line (green star)."""
    from sailroute.report.tables import format_duration

    off = plan.course.utc_offset_s
    title = (
        f"{plan.course.name} - {plan.scenario}: {format_duration(plan.total_time_s)} "
        f"({plan.total_time_s:.0f} s), start {local_time(plan.t_start, off)}"
    )
    return plot_route(
        plan.course,
        plan.results,
        wind,
        plan.t_start,
        title=title,
        utc_offset_s=off,
        start_line=plan.start_line,
        laylines=plan.laylines,
    )


def plot_comparison(cmp: Comparison, plans: Sequence[Plan] = ()) -> Figure:
    """Leg-time bars per scenario (references as black ticks) and routes overlaid on one map.

    Parameters
    ----------
    cmp : Comparison
        Leg times and references.
    plans : sequence of Plan, optional
        The routed plans, in the order of ``cmp.scenarios``; without them only
        the bar chart is drawn.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    from sailroute.report.chart import chart_for, draw_chart
    from sailroute.report.mapdraw import finish_map

    with_map = bool(plans)
    fig = Figure(figsize=(15.0 if with_map else 9.0, 6.5), layout="constrained")
    axes: list[Any] = list(fig.subplots(1, 2 if with_map else 1, squeeze=False)[0])
    ax = axes[0]
    ns, nl = cmp.times.shape
    width = 0.8 / max(ns, 1)
    x = np.arange(nl)
    colours = [f"C{i % 10}" for i in range(ns)]
    for i, s in enumerate(cmp.scenarios):
        bars = ax.bar(
            x - 0.4 + width * (i + 0.5),
            cmp.times[i],
            width,
            color=colours[i],
            label=f"{s} ({cmp.totals[i]:.0f} s)",
        )
        for patch in bars.patches:
            patch.set_gid(f"bars:{s}")
    styles = [("_", 24, "black"), ("o", 8, "none"), ("D", 7, "none"), ("s", 7, "none")]
    for j, (r, vals) in enumerate(cmp.references.items()):
        mk, ms, mfc = styles[j % len(styles)]
        ax.plot(
            x,
            vals,
            mk,
            color="black",
            mfc=mfc,
            ms=ms,
            mew=2,
            linestyle="none",
            label=f"{r} ({vals.sum():.0f} s)",
            gid=f"reference:{r}",
            zorder=4,
        )
    ax.set_xticks(x, [f"{k + 1}\n{lab}" for k, lab in enumerate(cmp.leg_labels)], fontsize=8)
    ax.set_ylabel("leg time [s]")
    ax.set_title(f"{cmp.course_name}: leg times by scenario", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, axis="y", lw=0.3, alpha=0.5)
    if with_map:
        mx = axes[1]
        course = plans[0].course
        draw_area(mx, course.area)
        draw_course(mx, course)
        xs_of, ys_of = [], []
        for i, p in enumerate(plans):
            xs = np.concatenate([r.track.x for r in p.results])
            ys = np.concatenate([r.track.y for r in p.results])
            xs_of.append(xs)
            ys_of.append(ys)
            mx.plot(
                xs,
                ys,
                "-",
                color=colours[i % len(colours)],
                lw=1.6,
                gid=f"route:{p.scenario}",
                label=p.scenario,
            )
        extent = _extent(course, [r for p in plans for r in p.results])
        draw_chart(mx, chart_for(course, [], extent), extent)
        _map_frame(mx, extent)
        mx.legend(fontsize=8, loc="upper left")
        mx.set_title("routes", fontsize=10)
        # names, scale bar and north arrow are placed on the final layout: run the
        # constrained layout once, then keep it
        engine = fig.get_layout_engine()
        if engine is not None:
            engine.execute(fig)
        fig.set_layout_engine("none")
        finish_map(
            fig,
            mx,
            routes=[np.column_stack([xs_of[i], ys_of[i]]) for i in range(len(plans))],
            **course_labels(course),
        )
    return fig
