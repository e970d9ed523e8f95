"""The plotly figure of ``report.html`` as plain JSON: traces, layout, animation frames.

Built without plotly's Python classes, so writing a page costs tens of milliseconds; pure:
the same :class:`~sailroute.report.page.Report` gives the same dict.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.course.model import Course
from sailroute.geo import LocalFrame
from sailroute.report.area import (
    BOUNDARY_COLOUR,
    OBSTACLE_EDGE,
    OBSTACLE_FILL,
    area_polygons,
    kept_ring,
)
from sailroute.report.chart import LAND_EDGE, LAND_FILL, Chart
from sailroute.report.markup import plotly_label
from sailroute.report.page import (
    ARROW_FILL,
    BOAT_COLOUR,
    GREY,
    ROUTE_COLOURS,
    SEA,
    WIND_COLOUR,
    Report,
    Route,
    WindLayer,
    clock,
    clocks,
    course_area,
    time_label,
)
from sailroute.report.plots import speed_limits
from sailroute.report.tables import format_duration
from sailroute.textin import clean_text
from sailroute.timeutil import offset_text
from sailroute.units import wrap360

__all__ = [
    "area_traces",
    "boat_at",
    "figure",
    "land_traces",
    "mark_annotations",
    "plotly_label",
    "wind_arrows",
]


def _r(a: Any, nd: int) -> Any:
    """Round for JSON; NaN/inf become null; arrays become lists."""
    arr = np.asarray(a, dtype=float)
    if arr.ndim == 0:
        v = float(arr)
        return round(v, nd) if math.isfinite(v) else None
    vals = np.round(arr.ravel(), nd)  # rint(x·10ⁿ)/10ⁿ: the shortest repr is the rounded one
    out = vals.tolist()
    for i in np.flatnonzero(~np.isfinite(vals)):
        out[i] = None
    return out


def _colour(i: int) -> str:
    return ROUTE_COLOURS[i % len(ROUTE_COLOURS)]


def _customdata(r: Route, off: float) -> list[list[Any] | None]:
    """Hover data per point: leg, mode, local time, UTC time, TWS, |TWA|, tack, speed, VMG,
    latitude, longitude (the true position, also where the line is drawn shifted)."""
    modes = [r.modes[k - 1] if 0 < k <= len(r.modes) else "" for k in r.leg.tolist()]
    cols = zip(
        r.leg.tolist(),
        modes,
        clocks(r.t, off),
        clocks(r.t),
        _r(r.tws_kn, 2),
        _r(np.abs(r.twa_deg), 1),
        np.where(r.twa_deg >= 0, "stbd", "port").tolist(),
        _r(r.speed_kn, 3),
        _r(r.vmg_kn, 3),
        _r(r.lat, 6),
        _r(r.lon, 6),
        strict=True,
    )
    ok = np.isfinite(r.t).tolist()
    return [list(row) if good else None for row, good in zip(cols, ok, strict=True)]


def _hover(r: Route, off: float) -> str:
    return (
        "<b>%{fullData.name}</b> · leg %{customdata[0]} (%{customdata[1]})<br>"
        f"%{{customdata[2]}} local ({offset_text(off)}) · %{{customdata[3]}} UTC<br>"
        "TWS %{customdata[4]:.1f} kn · TWA %{customdata[5]:.0f}° %{customdata[6]}<br>"
        f"{r.speed_name} %{{customdata[7]:.2f}} kn · VMG %{{customdata[8]:.2f}} kn"
        "<br>%{customdata[9]:.5f}° N %{customdata[10]:.5f}° E<extra></extra>"
    )


def boat_at(r: Route, times: NDArray) -> NDArray[np.int64]:
    """Index of the last point of ``r`` at or before each of ``times`` (the first point
    before the start, the last after the arrival); ``r.t`` must be non-decreasing (a
    route with a boat has no gaps)."""
    k = np.searchsorted(r.t, np.asarray(times, dtype=float), side="right") - 1
    return np.clip(k, 0, r.t.size - 1)


def _boat_states(
    r: Route, times: NDArray, off: float, custom: Sequence[Any]
) -> list[dict[str, Any]]:
    """Boat marker of ``r`` at each of ``times``: the position interpolated in time, the
    hover data of the point before with the time itself."""
    drawn_lat, drawn_lon = r.drawn()
    lat = _r(np.interp(times, r.t, drawn_lat), 7)
    lon = _r(np.interp(times, r.t, drawn_lon), 7)
    true_lat = _r(np.interp(times, r.t, r.lat), 6)
    true_lon = _r(np.interp(times, r.t, r.lon), 6)
    out = []
    for k, (i, local, utc) in enumerate(
        zip(boat_at(r, times).tolist(), clocks(times, off), clocks(times), strict=True)
    ):
        row = list(custom[i] or [])
        if row:
            row[2], row[3] = local, utc
            row[9], row[10] = true_lat[k], true_lon[k]
        out.append({"x": [lon[k]], "y": [lat[k]], "customdata": [row]})
    return out


def wind_arrows(
    w: WindLayer, course: Course, m_per_kn: float
) -> list[tuple[dict[str, Any], dict[str, Any]]]:
    """Every row of ``w`` as arrows centred on the grid points, ``m_per_kn`` metres long per
    knot.

    Returns
    -------
    list of (dict, dict)
        Per row: the shafts (``x``/``y`` of one line trace, pieces separated by nulls)
        and the heads (arrow markers at the tips, ``marker.angle`` where the air goes,
        clockwise from north; ``customdata`` ``[speed kn, FROM-direction °]`` for the hover).
    """
    spd, twd = w.tws_kn, w.twd_deg
    go = np.radians(twd + 180.0)
    half = 0.5 * m_per_kn * spd
    dx, dy = half * np.sin(go), half * np.cos(go)
    tail_lat, tail_lon = course.frame.to_latlon(w.x - dx, w.y - dy)
    tip_lat, tip_lon = course.frame.to_latlon(w.x + dx, w.y + dy)
    nan = np.full(w.x.size, np.nan)
    angle = np.where(np.isfinite(twd), wrap360(twd + 180.0), np.nan)
    out = []
    for k in range(spd.shape[0]):
        xs = np.column_stack([tail_lon[k], tip_lon[k], nan]).ravel()
        ys = np.column_stack([tail_lat[k], tip_lat[k], nan]).ravel()
        shafts = {"x": _r(xs, 6), "y": _r(ys, 6)}
        heads = {
            "x": _r(tip_lon[k], 6),
            "y": _r(tip_lat[k], 6),
            "marker": {"angle": _r(angle[k], 1)},
            "customdata": [[a, b] for a, b in zip(_r(spd[k], 1), _r(twd[k], 0), strict=True)],
        }
        out.append((shafts, heads))
    return out


def _course_traces(course: Course) -> list[dict[str, Any]]:
    """Lines and gates, and the marks (symbols; their names are annotations placed by the
    page's script: :func:`mark_annotations`)."""
    out: list[dict[str, Any]] = []
    first = True
    for ln, dash in [
        *((ln, "solid") for ln in course.lines.values()),
        *((g, "dot") for g in course.gates.values()),
    ]:
        out.append(
            {
                "type": "scatter",
                "mode": "lines",
                "name": "lines and gates",
                "legendgroup": "course",
                "showlegend": first,
                "x": _r([ln.a.lon, ln.b.lon], 7),
                "y": _r([ln.a.lat, ln.b.lat], 7),
                "line": {"color": "black", "width": 2, "dash": dash},
                "hovertemplate": f"{plotly_label(ln.name)}<extra></extra>",
                "meta": "line",
            }
        )
        first = False
    marks = list(course.marks.values())
    out.append(
        {
            "type": "scatter",
            "mode": "markers",
            "name": "marks",
            "legendgroup": "course",
            "x": _r([m.lon for m in marks], 7),
            "y": _r([m.lat for m in marks], 7),
            "text": [plotly_label(m.name) for m in marks],
            "marker": {
                "color": "darkorange",
                "size": MARK_SIZE,
                "line": {"color": "black", "width": 1},
            },
            "hovertemplate": "mark %{text}<br>%{y:.6f}° N %{x:.6f}° E<extra></extra>",
            "meta": "marks",
        }
    )
    return out


MARK_SIZE = 11
"""Diameter of the mark symbols on the page [px]."""


def _annotation(lon: float, lat: float, text: str, **style: Any) -> dict[str, Any]:
    """A label at a point, moved by the page's script (``ax``/``ay``: its offset [px];
    the arrow, the leader line, shown only when it had to move away)."""
    return {
        "x": _r(lon, 7),
        "y": _r(lat, 7),
        "text": text,
        "showarrow": True,
        "arrowhead": 0,
        "arrowwidth": 0.8,
        "arrowcolor": "rgba(0,0,0,0)",
        "standoff": 0,
        "ax": 0,
        "ay": -14,
        "axref": "pixel",
        "ayref": "pixel",
        "captureevents": False,
        **style,
    }


def mark_annotations(course: Course) -> list[dict[str, Any]]:
    """The marks' names as annotations (``name`` ``mark:<k>``, ``k`` the mark's index)."""
    return [
        _annotation(
            m.lon,
            m.lat,
            plotly_label(m.name),
            name=f"mark:{k}",
            font={"size": 12, "color": "#222"},
            bgcolor="rgba(255,255,255,0.55)",
            borderpad=1,
        )
        for k, m in enumerate(course.marks.values())
    ]


def _joined_lonlat(frame: LocalFrame, parts: Sequence[NDArray]) -> tuple[list[Any], list[Any]]:
    """``(lon, lat)`` lists [°] of lines in the course frame [m], a null between them."""
    xs: list[Any] = []
    ys: list[Any] = []
    for part in parts:
        lat, lon = frame.to_latlon(part[:, 0], part[:, 1])
        xs += [*_r(lon, 6), None]
        ys += [*_r(lat, 6), None]
    return xs[:-1], ys[:-1]


def land_traces(chart: Chart | None, frame: LocalFrame) -> list[dict[str, Any]]:
    """The chart's land layers (:mod:`sailroute.report.chart`) as filled traces in lon/lat
    (``meta`` ``land``), the first shown, the others in the legend only; shorelines as
    lines."""
    out: list[dict[str, Any]] = []
    for layer in chart.layers if chart is not None else ():
        common = {
            "type": "scatter",
            "mode": "lines",
            "name": plotly_label(layer.name),
            "legendgroup": layer.name,
            "hoverinfo": "skip",
            "meta": "land",
            **({} if layer.shown else {"visible": "legendonly"}),
        }
        if layer.rings:
            xs, ys = _joined_lonlat(frame, layer.rings)
            out.append(
                {
                    **common,
                    "x": xs,
                    "y": ys,
                    "fill": "toself",
                    "fillcolor": LAND_FILL,
                    "line": {"color": LAND_EDGE, "width": 1},
                }
            )
        if layer.lines:
            xs, ys = _joined_lonlat(frame, layer.lines)
            out.append(
                {
                    **common,
                    "x": xs,
                    "y": ys,
                    "line": {"color": LAND_EDGE, "width": 1.5},
                    "showlegend": not layer.rings,
                }
            )
    return out


def _closed_lonlat(frame: LocalFrame, x: Any, y: Any) -> tuple[Any, Any]:
    """A ring's ``(lon, lat)`` lists [°], 7 decimals, its first point repeated last."""
    xs, ys = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    lat, lon = frame.to_latlon(np.append(xs, xs[0]), np.append(ys, ys[0]))
    return _r(lon, 7), _r(lat, 7)


def area_traces(course: Course) -> list[dict[str, Any]]:
    """The race area (:mod:`sailroute.report.area`) as plotly traces in lon/lat: one per
    polygon, closed (``race-area boundary``, a line; ``obstacle: <name>``, filled), the
    hover naming it and its clearance; then one dashed trace per polygon with a
    clearance: the line the routes keep to.  Empty without a boundary or obstacles."""
    area, frame = course.area, course.frame
    out: list[dict[str, Any]] = []
    b = area.boundary
    if b is not None:
        lon, lat = _closed_lonlat(frame, b.x, b.y)
        out.append(
            {
                "type": "scatter",
                "mode": "lines",
                "name": "race-area boundary",
                "legendgroup": "area",
                "x": lon,
                "y": lat,
                "line": {"color": BOUNDARY_COLOUR, "width": 2},
                "hovertemplate": f"race-area boundary, clearance {b.clearance_m:g} m"
                "<extra></extra>",
            }
        )
    for p in area.obstacles:
        lon, lat = _closed_lonlat(frame, p.x, p.y)
        name = plotly_label(p.name)
        out.append(
            {
                "type": "scatter",
                "mode": "lines",
                "name": f"obstacle: {name}",
                "legendgroup": "area",
                "x": lon,
                "y": lat,
                "fill": "toself",
                "fillcolor": OBSTACLE_FILL,
                "line": {"color": OBSTACLE_EDGE, "width": 1},
                "hoveron": "fills+points",
                "hovertemplate": f"obstacle {name}, clearance {p.clearance_m:g} m<extra></extra>",
            }
        )
    first = True
    for p in area_polygons(area):
        ring = kept_ring(p, boundary=p is b)
        if ring is None:
            continue
        lon, lat = _closed_lonlat(frame, ring[0][:-1], ring[1][:-1])
        whose = "the boundary" if p is b else f"obstacle {plotly_label(p.name)}"
        out.append(
            {
                "type": "scatter",
                "mode": "lines",
                "name": "clearance kept",
                "legendgroup": "area",
                "showlegend": first,
                "x": lon,
                "y": lat,
                "line": {
                    "color": BOUNDARY_COLOUR if p is b else OBSTACLE_EDGE,
                    "width": 1,
                    "dash": "dash",
                },
                "hovertemplate": f"{p.clearance_m:g} m clearance of {whose}<extra></extra>",
            }
        )
        first = False
    return out


def leg_number_annotations(r: Route) -> list[dict[str, Any]]:
    """The leg numbers along ``r`` as badges (annotations ``legno:<n>``), at 30 % to 70 % of
    each leg (golden-ratio steps, as on ``route.png``) so legs over the same water do not
    hide each other's; the page's script slides one aside when something is there."""
    out = []
    lat, lon = r.drawn()
    for k in range(len(r.modes)):
        idx = np.flatnonzero(r.leg == k + 1)
        if idx.size == 0:
            continue
        i = idx[min(int((0.3 + 0.4 * ((k * 0.6180339887) % 1.0)) * idx.size), idx.size - 1)]
        out.append(
            _annotation(
                float(lon[i]),
                float(lat[i]),
                str(k + 1),
                name=f"legno:{k + 1}",
                ay=0,
                font={"size": 10, "color": "#222"},
                bgcolor="white",
                bordercolor="#555",
                borderwidth=1,
                borderpad=2,
            )
        )
    return out


def _manoeuvre_trace(
    kind: str,
    pts: Sequence[tuple[str, float, float, float]],
    name: str,
    group: str,
    off: float,
    legend: bool = False,
) -> dict[str, Any]:
    """The tacks (``kind="tack"``) or gybes of a route as one marker trace (``legend``: with
    the legend entry that says what the symbol is)."""
    symbol, colour = MANOEUVRE_SYMBOLS[kind]
    return {
        "type": "scatter",
        "mode": "markers",
        "name": f"{kind}s",
        "legendgroup": f"{kind}s" if legend else group,
        "showlegend": legend,
        "x": _r([m[3] for m in pts], 7),
        "y": _r([m[2] for m in pts], 7),
        "text": [f"{kind} {clock(m[1], off)} local · {clock(m[1])} UTC" for m in pts],
        "marker": {
            "symbol": symbol,
            "color": colour,
            "size": MANOEUVRE_SIZE,
            "line": {"color": "white", "width": 1},
        },
        "hovertemplate": f"%{{text}}<extra>{plotly_label(name)}</extra>",
    }


MANOEUVRE_SYMBOLS = {"tack": ("triangle-up", "crimson"), "gybe": ("square", "royalblue")}
MANOEUVRE_SIZE = 10
"""Size of the tack and gybe symbols [px]."""
"""Marker symbol and colour of the tacks and gybes."""


def _route_trace(
    r: Route, colour: str, group: str, custom: Sequence[Any], off: float, width: float
) -> dict[str, Any]:
    drawn_lat, drawn_lon = r.drawn()
    return {
        "type": "scatter",
        "mode": "lines",
        "name": plotly_label(r.name),
        "legendgroup": group,
        "x": _r(drawn_lon, 7),
        "y": _r(drawn_lat, 7),
        "line": {"color": colour, "width": width, "dash": r.dash},
        "customdata": custom,
        "hovertemplate": _hover(r, off),
    }


def _leg_pieces(r: Route, tr: dict[str, Any], custom: Sequence[Any]) -> list[dict[str, Any]]:
    """The route trace ``tr`` of ``r`` cut leg by leg, each in its :attr:`Route.leg_colours`."""
    out = []
    for k, c in enumerate(r.leg_colours):
        idx = np.flatnonzero(r.leg == k + 1)
        if idx.size == 0:
            continue
        out.append(
            {
                **tr,
                "name": f"leg {k + 1} · {tr['name']}",
                "x": [tr["x"][j] for j in idx],
                "y": [tr["y"][j] for j in idx],
                "customdata": [custom[int(j)] for j in idx],
                "line": {**tr["line"], "color": c},
                "showlegend": True,
            }
        )
    return out


def _speed_colours(report: Report) -> dict[str, Any]:
    """Marker colours of a single route by its speed, with the colour bar."""
    (r,) = report.routes
    slo, shi = speed_limits(r.speed_kn, decimals=2)
    return {
        "color": _r(r.speed_kn, 3),
        "colorscale": "Viridis",
        "cmin": slo,
        "cmax": shi,
        "size": 5,
        "colorbar": {
            "title": {"text": "boat speed [kn]"},
            "x": 1.02,
            "y": 1.0,
            "yanchor": "top",
            "len": 0.45,
            "thickness": 14,
        },
    }


def _boat_trace(
    r: Route, states: Sequence[dict[str, Any]], colour: str, group: str, off: float, size: int
) -> dict[str, Any]:
    return {
        "type": "scatter",
        "mode": "markers",
        "name": plotly_label(f"boat: {r.name}"),
        "legendgroup": group,
        "showlegend": False,
        **states[0],
        "marker": {
            "symbol": "circle",
            "size": size,
            "color": colour,
            "line": {"color": "white", "width": 2.5 if size > 10 else 1.0},
        },
        "hovertemplate": "boat · " + _hover(r, off),
    }


def _highlight_traces() -> list[dict[str, Any]]:
    """The picked boat's line, tacks and gybes (filled in by the page's script)."""
    line = {
        "type": "scatter",
        "mode": "lines",
        "name": "picked boat",
        "showlegend": False,
        "x": [],
        "y": [],
        "line": {"color": GREY, "width": 4.5},
        "hoverinfo": "skip",
    }
    out = [line]
    for kind in ("tack", "gybe"):
        out.append({**_manoeuvre_trace(kind, (), "picked boat", "picked", 0.0), "text": []})
    return out


def _pick_entry(r: Route, line: int, marker: int, colour: str, off: float) -> dict[str, Any]:
    """What the page's script needs to highlight one boat."""
    entry: dict[str, Any] = {
        "name": clean_text(r.name),
        "label": plotly_label(r.name),
        "line": line,
        "marker": marker,
        "colour": colour,
    }
    for kind in ("tack", "gybe"):
        tr = _manoeuvre_trace(kind, [m for m in r.manoeuvres if m[0] == kind], r.name, "", off)
        entry[f"{kind}s"] = {"x": tr["x"], "y": tr["y"], "text": tr["text"]}
    return entry


def figure(report: Report) -> dict[str, Any]:
    """The plotly figure of the page: ``{"data", "layout", "frames", "config"}``, plus
    ``"pick"`` on a fleet's page (:attr:`Report.pick`).

    Trace order: wind layers, the race area (:func:`area_traces`), course (lines and
    gates, marks), the overlays, then per
    route its line, tacks, gybes (and leg numbers on the first route) and the boat
    marker.  Frame ``k`` (named ``str(k)``) moves every boat marker and every
    time-varying wind layer to ``report.times[k]``; the slider's steps animate to them.

    On a fleet's page (``report.pick``) the routes have no tack and gybe traces, the
    course comes after the routes (over them), and three traces end the list: the picked
    boat's line, tacks and gybes, empty until the reader picks one.  ``"pick"`` holds
    ``grey`` (:data:`~sailroute.report.page.GREY`), ``highlight`` (those three traces'
    indices) and per boat (route with a marker) ``name``, ``label`` (for plotly),
    ``line`` and ``marker`` (trace indices), ``colour``, ``tacks`` and ``gybes``
    (``x``, ``y``, ``text``).
    """
    course, off = report.course, report.course.utc_offset_s
    data: list[dict[str, Any]] = []
    moving: list[tuple[int, list[dict[str, Any]]]] = []  # (trace, its state per frame)
    data += land_traces(report.chart, course.frame)
    data += _wind_traces(report, moving)
    data += area_traces(course)
    if not report.pick:
        data += _course_traces(course)
    data += list(report.overlays)
    annotations = mark_annotations(course)
    # what the page's script places (page_render): symbols first, then the names
    symbols: list[dict[str, Any]] = []
    badges: list[dict[str, Any]] = []
    routes: list[int] = []

    single = report.colour_by_speed and len(report.routes) == 1
    picks = []
    for i, r in enumerate(report.routes):
        group = f"route{i}"
        colour = "#333333" if single else (r.colour or _colour(i))
        custom = _customdata(r, off)
        tr = _route_trace(r, colour, group, custom, off, 1.6 if report.pick else 2.5)
        if single:
            tr["mode"] = "lines+markers"
            tr["marker"] = _speed_colours(report)
        if r.leg_colours:  # leg by leg, each in its colour; the hover as on the whole line
            for piece in _leg_pieces(r, tr, custom):
                data.append(piece)
                routes.append(len(data) - 1)
            tr = {**tr, "visible": "legendonly", "showlegend": False}
        data.append(tr)
        line = len(data) - 1
        routes.append(line)
        if not report.pick:
            for kind in ("tack", "gybe"):
                pts = [m for m in r.manoeuvres if m[0] == kind]
                legend = not any(t.get("showlegend") and t.get("name") == f"{kind}s" for t in data)
                data.append(
                    _manoeuvre_trace(
                        kind, pts, r.name, f"{kind}s", off, legend=legend and bool(pts)
                    )
                )
                symbols += [
                    {
                        "trace": len(data) - 1,
                        "point": k,
                        "size": MANOEUVRE_SIZE + 2,
                        "gap": 0,
                        "route": True,
                    }
                    for k in range(len(pts))
                ]
        if i == 0 and report.leg_numbers:
            for a in leg_number_annotations(r):
                badges.append({"ann": len(annotations), "gap": 0, "route": True})
                annotations.append(a)
        if r.boat:
            states = _boat_states(r, report.times, off, custom)
            marker_colour = BOAT_COLOUR if single else colour
            data.append(_boat_trace(r, states, marker_colour, group, off, 9 if report.pick else 15))
            moving.append((len(data) - 1, states))
            picks.append(_pick_entry(r, line, len(data) - 1, colour, off))

    out: dict[str, Any] = {}
    if report.pick:
        data += _course_traces(course)
        data += _highlight_traces()
        n = len(data)
        out["pick"] = {"grey": GREY, "highlight": [n - 3, n - 2, n - 1], "boats": picks}
    out["place"] = _place(report, data, annotations, routes, symbols, badges)
    out["chart"] = {
        "note": (report.chart or Chart()).note(),
        "lat0": course.frame.lat0,
    }
    frames = []
    if len(report.times) > 1 and moving:
        for k in range(len(report.times)):
            frames.append(
                {
                    "name": str(k),
                    "data": [states[k] for _, states in moving],
                    "traces": [i for i, _ in moving],
                }
            )
    layout = _layout(report, frames)
    layout["annotations"] = annotations
    return {
        "data": data,
        "layout": layout,
        "frames": frames,
        "config": {"responsive": True, "displaylogo": False, "scrollZoom": True},
        **out,
    }


def _place(
    report: Report,
    data: list[dict[str, Any]],
    annotations: list[dict[str, Any]],
    routes: list[int],
    symbols: list[dict[str, Any]],
    badges: list[dict[str, Any]],
) -> dict[str, Any]:
    """What the page's script places (:mod:`sailroute.report.page_render`), in order: the
    favoured end, the tack and gybe symbols, the leg numbers, the marks' names, the
    favoured end's label; what they keep off (the routes and lines, the marks and the
    boats where the page opens); the trace of the leader lines (appended to ``data``; -1
    on a fleet's page).  Adds the favoured end's label to ``annotations``."""
    favoured = []
    for k, t in enumerate(data):
        if t.get("meta") == "favoured" and t.get("x"):
            favoured.append({"trace": k, "point": 0, "size": 18, "gap": 0, "route": False})
            annotations.append(
                _annotation(
                    t["x"][0],
                    t["y"][0],
                    t["text"][0],
                    name="favoured-label",
                    font={"size": 11, "color": "#1b5e20"},
                )
            )
            favoured.append({"ann": len(annotations) - 1, "gap": 12, "route": False})
    n_marks = len(report.course.marks)
    names = [{"ann": k, "gap": 0.5 * MARK_SIZE + 3, "route": False} for k in range(n_marks)]
    marks = next(k for k, t in enumerate(data) if t.get("meta") == "marks")
    fixed = [{"trace": marks, "size": MARK_SIZE + 2, "first": False}]
    fixed += [  # the boats where the page opens (the boat at the start covers the route)
        {"trace": k, "size": t["marker"]["size"] + 2, "first": True}
        for k, t in enumerate(data)
        if str(t.get("name", "")).startswith("boat: ") and not report.pick
    ]
    lines = [k for k, t in enumerate(data) if t.get("meta") == "line"]
    leaders = -1
    if not report.pick:
        data.append(
            {
                "type": "scatter",
                "mode": "lines",
                "name": "leaders",
                "showlegend": False,
                "x": [],
                "y": [],
                "line": {"color": "#555", "width": 0.8},
                "hoverinfo": "skip",
                "meta": "leaders",
            }
        )
        leaders = len(data) - 1
    return {
        "leaders": leaders,
        "routes": routes,
        "lines": lines,
        "fixed": fixed,
        "items": favoured[:1] + symbols + badges + names + favoured[1:],
    }


def _wind_traces(
    report: Report, moving: list[tuple[int, list[dict[str, Any]]]]
) -> list[dict[str, Any]]:
    """Shafts and heads of every wind layer (the first shown); the time-varying ones are
    added to ``moving`` with their state per frame."""
    course = report.course
    data: list[dict[str, Any]] = []
    top = max(
        (float(np.nanmax(w.tws_kn)) for w in report.winds if np.isfinite(w.tws_kn).any()),
        default=0.0,
    )
    m_per_kn = ARROW_FILL * min(w.spacing_m for w in report.winds) / top if top > 0 else 0.0
    route_names = [r.name for r in report.routes]
    for i, w in enumerate(report.winds):
        colour = (
            _colour(route_names.index(w.name))
            if len(report.winds) > 1 and w.name in route_names
            else WIND_COLOUR
        )
        name = "wind" if len(report.winds) == 1 else f"wind: {w.name}"
        if w.uniform:
            name += f" {w.tws_kn.flat[0]:.1f} kn from {w.twd_deg.flat[0]:.0f}°"
        rows = wind_arrows(w, course, m_per_kn)
        shafts, heads = rows[0]
        group = f"wind{i}"
        common = {
            "type": "scatter",
            "legendgroup": group,
            "name": plotly_label(name),
            **({} if i == 0 else {"visible": "legendonly"}),
        }
        data.append(
            {
                **common,
                "mode": "lines",
                **shafts,
                "hoverinfo": "skip",
                "line": {"color": colour, "width": 1.3},
                "opacity": 0.75,
            }
        )
        data.append(
            {
                **common,
                "mode": "markers",
                "showlegend": False,
                **heads,
                "marker": {
                    "symbol": "arrow",
                    "size": 9,
                    "color": colour,
                    "angle": heads["marker"]["angle"],
                    "line": {"width": 0},
                },
                "opacity": 0.75,
                "hovertemplate": "wind %{customdata[0]:.1f} kn from "
                f"%{{customdata[1]:.0f}}°<extra>{plotly_label(w.name)}"
                "</extra>",
            }
        )
        if not w.steady:
            moving.append((len(data) - 2, [sh for sh, _ in rows]))
            moving.append((len(data) - 1, [hd for _, hd in rows]))
    return data


def _layout(report: Report, frames: Sequence[Any]) -> dict[str, Any]:
    course, off = report.course, report.course.utc_offset_s
    lat0 = course.frame.lat0
    x0, x1, y0, y1 = course_area(course, report.routes)
    lats, lons = course.frame.to_latlon(np.array([x0, x1, x0, x1]), np.array([y0, y0, y1, y1]))
    layout: dict[str, Any] = {
        "xaxis": {
            "title": {"text": "longitude [° E]"},
            "tickformat": ".3f",
            "range": _r([np.min(lons), np.max(lons)], 6),
            "gridcolor": "white",
            "zeroline": False,
            "constrain": "domain",
        },
        "yaxis": {
            "title": {"text": "latitude [° N]"},
            "tickformat": ".3f",
            "range": _r([np.min(lats), np.max(lats)], 6),
            "gridcolor": "white",
            "zeroline": False,
            "scaleanchor": "x",
            "scaleratio": round(1.0 / math.cos(math.radians(lat0)), 6),
        },
        "plot_bgcolor": SEA,
        "paper_bgcolor": "white",
        "hovermode": "closest",
        "dragmode": "pan",
        "margin": {"l": 70, "r": 30, "t": 40, "b": 40},
        "legend": {
            **(
                {"orientation": "v", "x": 1.02, "y": 1.0, "yanchor": "top"}
                if report.legend_beside
                else {"orientation": "h", "x": 0.0, "y": 1.02, "yanchor": "bottom"}
            ),
            "groupclick": "toggleitem",
        },
        "font": {"family": "Helvetica, Arial, sans-serif", "size": 12},
        "uirevision": "sailroute",
        "modebar": {"orientation": "v"},
    }
    if frames:
        step_args = {
            "mode": "immediate",
            "frame": {"duration": 0, "redraw": True},
            "transition": {"duration": 0},
        }
        t0 = float(report.times[0])
        layout["sliders"] = [
            {
                "active": 0,
                "pad": {"t": 50, "b": 10, "l": 110},
                "x": 0.0,
                "len": 1.0,
                "currentvalue": {"prefix": "time: ", "font": {"size": 13, "color": "#222"}},
                "font": {"color": "rgba(0,0,0,0)", "size": 1},
                "steps": [
                    {
                        "label": f"{time_label(t, off)} · race +{format_duration(t - t0)}",
                        "method": "animate",
                        "args": [[str(k)], step_args],
                    }
                    for k, t in enumerate(report.times)
                ],
            }
        ]
        layout["updatemenus"] = [
            {
                "type": "buttons",
                "direction": "left",
                "x": 0.0,
                "y": 0.0,
                "xanchor": "left",
                "yanchor": "top",
                "pad": {"t": 60, "r": 10},
                "showactive": False,
                "buttons": [
                    {
                        "label": "▶",
                        "method": "animate",
                        "args": [
                            None,
                            {
                                "mode": "immediate",
                                "fromcurrent": True,
                                "frame": {"duration": 400, "redraw": True},
                                "transition": {"duration": 0},
                            },
                        ],
                    },
                    {
                        "label": "❚❚",
                        "method": "animate",
                        "args": [
                            [None],
                            {"mode": "immediate", "frame": {"duration": 0, "redraw": False}},
                        ],
                    },
                ],
            }
        ]
        layout["margin"]["b"] = 100
    return layout
