"""Route and comparison charts (matplotlib object-oriented API, no ``pyplot``).

matplotlib is imported inside the functions so that ``plan --no-plots`` never
pays for it, and no global figure state or GUI backend is touched: each function
returns a :class:`matplotlib.figure.Figure` that the caller saves.

Artists carry a ``gid`` so tests and callers can find them: ``leg:<n>`` (one
``LineCollection`` per leg, coloured by boat speed), ``tacks``/``gybes`` (marker
lines, one point per manoeuvre), ``marks``, ``line:<name>``, ``gate:<name>``,
``wind`` (quiver), ``wind-field`` (speed background, only for non-uniform wind),
``route:<scenario>`` and ``bars:<scenario>`` in comparison charts.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from sailroute.course.model import Course
from sailroute.errors import OutOfCoverageError
from sailroute.report.plan import Comparison, Plan
from sailroute.routing.types import LegResult
from sailroute.timeutil import iso
from sailroute.units import KNOT, circular_mean_deg, wind_speed_direction
from sailroute.wind.base import WindField

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

WIND_GRID = 15
"""Wind arrows per side of the plotted area."""


def _extent(course: Course, legs: Sequence[LegResult], pad: float = 0.08) -> tuple[float, ...]:
    xs = [m.x for m in course.marks.values()]
    ys = [m.y for m in course.marks.values()]
    for r in legs:
        xs += [float(r.track.x.min()), float(r.track.x.max())]
        ys += [float(r.track.y.min()), float(r.track.y.max())]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
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


def _label_directions(course: Course) -> dict[str, tuple[float, float]]:
    """Unit offset direction of each mark's label: away from its line/gate partner, or
    away from the course centroid for single marks."""
    cx = float(np.mean([m.x for m in course.marks.values()]))
    cy = float(np.mean([m.y for m in course.marks.values()]))
    out = {name: (m.x - cx, m.y - cy) for name, m in course.marks.items()}
    for ln in (*course.lines.values(), *course.gates.values()):
        out[ln.a.name] = (ln.a.x - ln.b.x, ln.a.y - ln.b.y)
        out[ln.b.name] = (ln.b.x - ln.a.x, ln.b.y - ln.a.y)
    for k, (dx, dy) in out.items():
        n = float(np.hypot(dx, dy))
        out[k] = (dx / n, dy / n) if n > 0 else (0.7071, 0.7071)
    return out


def draw_course(ax: Axes, course: Course) -> None:
    """Draw marks (with names), start/finish lines (solid) and gates (dotted) on ``ax``."""
    mx = [m.x for m in course.marks.values()]
    my = [m.y for m in course.marks.values()]
    ax.plot(mx, my, "o", color="darkorange", mec="black", ms=7, zorder=5, gid="marks",
            label="marks", linestyle="none")
    dirs = _label_directions(course)
    for m in course.marks.values():
        dx, dy = dirs[m.name]
        ha = "left" if dx > 0.3 else ("right" if dx < -0.3 else "center")
        va = "bottom" if dy > 0.3 else ("top" if dy < -0.3 else "center")
        ax.annotate(m.name, (m.x, m.y), xytext=(9 * dx, 9 * dy), textcoords="offset points",
                    fontsize=8, zorder=6, ha=ha, va=va)
    for ln in course.lines.values():
        ax.plot([ln.a.x, ln.b.x], [ln.a.y, ln.b.y], "-", color="black", lw=1.5, zorder=4,
                gid=f"line:{ln.name}")
    for g in course.gates.values():
        ax.plot([g.a.x, g.b.x], [g.a.y, g.b.y], ":", color="black", lw=1.2, zorder=4,
                gid=f"gate:{g.name}")


def _draw_wind(ax: Axes, fig: Figure, wind: WindField, t: float,
               extent: tuple[float, ...]) -> str | None:
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
        mesh = ax.imshow(spd / KNOT, extent=(gx0, gx1, gy0, gy1), origin="lower",
                         cmap="Blues", alpha=0.35, interpolation="bilinear", zorder=0,
                         aspect="auto")
        mesh.set_gid("wind-field")
        fig.colorbar(mesh, ax=ax, orientation="horizontal", fraction=0.04, pad=0.08,
                     label="wind speed [kn]")
    q = ax.quiver(gx, gy, u, v, color="0.35", alpha=0.7, zorder=1, angles="xy", pivot="middle")
    q.set_gid("wind")
    mean_dir = circular_mean_deg(twd, weights=spd) if float(spd.sum()) > 0 else 0.0
    return (f"wind at {iso(t)[11:16]} UTC: {float(spd.mean()) / KNOT:.1f} kn "
            f"from {mean_dir:.0f}°")


def plot_route(
    course: Course,
    legs: Sequence[LegResult],
    wind: WindField | None = None,
    t: float | None = None,
    *,
    title: str | None = None,
) -> Figure:
    """Map of a routed course.

    Parameters
    ----------
    course : Course
        Marks, lines and gates to draw.
    legs : sequence of LegResult
        The routed legs; each is one ``LineCollection`` coloured by boat speed [kn].
    wind : WindField, optional
        Drawn at time ``t`` over the plotted area as arrows (direction the air
        moves), plus a speed background if the field is not uniform.
    t : float, optional
        Time of the wind drawing [epoch s]; default the first leg's start.
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    extent = _extent(course, legs)
    aspect = (extent[3] - extent[2]) / (extent[1] - extent[0])
    fig = Figure(figsize=(10.0, float(np.clip(8.0 * aspect + 2.0, 4.5, 11.0))),
                 layout="constrained")
    ax = fig.add_subplot()
    if t is None:
        t = legs[0].t_start if legs else course.start_epoch
    wind_label = _draw_wind(ax, fig, wind, t, extent) if wind is not None else None
    draw_course(ax, course)
    bsp_all = np.concatenate([r.track.bsp_ms for r in legs]) / KNOT if legs else np.zeros(1)
    norm = Normalize(vmin=float(bsp_all.min()), vmax=max(float(bsp_all.max()),
                                                          float(bsp_all.min()) + 1e-3))
    lc = None
    for k, r in enumerate(legs):
        pts = np.column_stack([r.track.x, r.track.y])
        segs = np.stack([pts[:-1], pts[1:]], axis=1)
        lc = LineCollection(segs, cmap="viridis", norm=norm, linewidths=2.2, zorder=3)
        lc.set_array(r.track.bsp_ms[:-1] / KNOT)
        lc.set_gid(f"leg:{k + 1}")
        ax.add_collection(lc)
    if lc is not None:
        fig.colorbar(lc, ax=ax, label="boat speed [kn]", shrink=0.8)
    tacks = [(m.x, m.y) for r in legs for m in r.manoeuvres if m.kind == "tack"]
    gybes = [(m.x, m.y) for r in legs for m in r.manoeuvres if m.kind == "gybe"]
    ax.plot([p[0] for p in tacks], [p[1] for p in tacks], "^", color="crimson", ms=6,
            linestyle="none", zorder=7, gid="tacks", label=f"tacks ({len(tacks)})")
    ax.plot([p[0] for p in gybes], [p[1] for p in gybes], "s", color="royalblue", ms=5,
            linestyle="none", zorder=7, gid="gybes", label=f"gybes ({len(gybes)})")
    _map_frame(ax, extent)
    ax.legend(loc="best", fontsize=8, title=wind_label, title_fontsize=8)
    ax.set_title(title or course.name, fontsize=10)
    return fig


def plot_plan(plan: Plan, wind: WindField | None = None) -> Figure:
    """:func:`plot_route` of a :class:`Plan` with a title giving scenario and total time."""
    from sailroute.report.tables import format_duration

    title = (f"{plan.course.name} - {plan.scenario}: {format_duration(plan.total_time_s)} "
             f"({plan.total_time_s:.0f} s), start {iso(plan.t_start)[:16]}Z")
    return plot_route(plan.course, plan.results, wind, plan.t_start, title=title)


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

    with_map = bool(plans)
    fig = Figure(figsize=(15.0 if with_map else 9.0, 6.5), layout="constrained")
    axes: list[Any] = list(fig.subplots(1, 2 if with_map else 1, squeeze=False)[0])
    ax = axes[0]
    ns, nl = cmp.times.shape
    width = 0.8 / max(ns, 1)
    x = np.arange(nl)
    colours = [f"C{i % 10}" for i in range(ns)]
    for i, s in enumerate(cmp.scenarios):
        bars = ax.bar(x - 0.4 + width * (i + 0.5), cmp.times[i], width, color=colours[i],
                      label=f"{s} ({cmp.totals[i]:.0f} s)")
        for patch in bars.patches:
            patch.set_gid(f"bars:{s}")
    styles = [("_", 24, "black"), ("o", 8, "none"), ("D", 7, "none"), ("s", 7, "none")]
    for j, (r, vals) in enumerate(cmp.references.items()):
        mk, ms, mfc = styles[j % len(styles)]
        ax.plot(x, vals, mk, color="black", mfc=mfc, ms=ms, mew=2, linestyle="none",
                label=f"{r} ({vals.sum():.0f} s)", gid=f"reference:{r}", zorder=4)
    ax.set_xticks(x, [f"{k + 1}\n{lab}" for k, lab in enumerate(cmp.leg_labels)], fontsize=8)
    ax.set_ylabel("leg time [s]")
    ax.set_title(f"{cmp.course_name}: leg times by scenario", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, axis="y", lw=0.3, alpha=0.5)
    if with_map:
        mx = axes[1]
        course = plans[0].course
        draw_course(mx, course)
        for i, p in enumerate(plans):
            xs = np.concatenate([r.track.x for r in p.results])
            ys = np.concatenate([r.track.y for r in p.results])
            mx.plot(xs, ys, "-", color=colours[i % len(colours)], lw=1.6, gid=f"route:{p.scenario}",
                    label=p.scenario)
        _map_frame(mx, _extent(course, [r for p in plans for r in p.results]))
        mx.legend(fontsize=8)
        mx.set_title("routes", fontsize=10)
    return fig
