"""``report.html``: one self-contained interactive page that works offline.

The page holds the course and the routes on a latitude/longitude map (a plain sea-coloured
background: no chart, no coastline, no web tiles), the scenario's wind as arrows, a time
slider over the race that moves the wind and a marker for the boat's position, hover text
at every track point (local time and UTC, TWS, TWA, speed, VMG) and the leg table.  A
comparison puts every scenario's route on the same map; clicking a legend entry hides or
shows it.

The drawing is `plotly.js <https://plotly.com/javascript/>`_, inlined into the file (about
4.8 MB; no CDN, no network).  The figure is built here as plain JSON (traces, layout,
animation frames) without plotly's Python figure classes, so that writing a report costs
tens of milliseconds and nothing of plotly is imported unless a report is written
(:func:`plotly_js`).  Everything but :func:`write_report` is pure: data in, dict or
string out, and the same input gives the same bytes (fixed element ids, rounded numbers,
no timestamps).

Four builders make a :class:`Report`: :func:`plan_report` (``sailroute plan``),
:func:`comparison_report` (``compare-scenarios`` and ``plan`` on an ensemble),
:func:`analysis_report` (``sailroute analyze``, one track) and :func:`fleet_report`
(``sailroute analyze`` with several tracks); :func:`render_html` turns it into the page.
The figure's JSON sits in ``<script type="application/json" id="sailroute-figure">``,
so tests and other tools can read exactly what is drawn (:func:`read_figure`).

Conventions: times are the course's local time (``Course.utc_offset_s``, the offset its
``start_time`` is written with) and UTC; speeds in knots, angles in degrees.  VMG is the
velocity made good as in ``sailroute analyze``: against the wind on an upwind leg, with it
on a downwind leg, towards the target's centre on a reach.
"""

from __future__ import annotations

import html
import json
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sailroute import __version__
from sailroute.analysis.windsource import ABOVE_POLAR_PCT
from sailroute.course.geometry import feature_centre
from sailroute.course.model import Course
from sailroute.errors import OutOfCoverageError
from sailroute.planning.result import Comparison, Plan, percent_error
from sailroute.report.plots import SPEED_SPAN_KN, repeat_index_of_ends, speed_limits
from sailroute.report.tables import format_duration, start_point_text
from sailroute.textin import clean_text
from sailroute.timeutil import iso, offset_text
from sailroute.units import KNOT, wind_speed_direction, wrap180, wrap360
from sailroute.wind.base import WindField

if TYPE_CHECKING:  # pragma: no cover
    from sailroute.analysis.result import TrackAnalysis
    from sailroute.routing.types import LegResult

DIV_ID = "sailroute-map"
"""Id of the plot ``div`` (fixed: the same input gives the same file)."""
FIGURE_ID = "sailroute-figure"
"""Id of the ``<script type="application/json">`` holding the figure."""
N_STEPS = 25
"""Positions of the time slider over the race (the wind is sampled at each)."""
WIND_GRID = 12
"""Wind arrows per side of the course area."""
MAX_WIND_LAYERS = 8
"""Most scenarios whose wind is drawn in a comparison (the frames grow with each)."""
SEA = "#dcebf5"
BOAT_COLOUR = "#e41a1c"
"""The boat marker of a single route (a comparison's boats take their route's colour)."""
"""Map background colour (plain water)."""
ROUTE_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
                 "#e377c2", "#17becf", "#bcbd22", "#7f7f7f")
"""Route colours in scenario order (plotly's default palette)."""
WIND_COLOUR = "#41607d"

REPEAT_SHIFT = 0.015
"""Sideways shift of a leg over the same water as an earlier one, per repeat, as a share
of the longest leg (start to end): about 20-30 m on a dinghy course, 8-12 px at the
page's first zoom (``route.png`` shifts such legs by 4 pt)."""
"""Colour of the wind arrows (a comparison's layers take their scenario's route colour)."""
ARROW_FILL = 0.85
"""Length of the strongest wind's arrow as a share of the grid spacing."""
MAX_ROUTE_POINTS = 4000
"""A sailed track is drawn with at most this many points (every k-th fix, each leg's first
and last kept): a 3-hour 10 Hz log would otherwise make a page of 100 MB that no browser
draws; the hover text is at the drawn points."""
FLEET_STEPS = 60
"""Slider positions of a fleet's replay."""


@dataclass(frozen=True, eq=False)
class Route:
    """One line on the map: a routed course, a sailed track or the optimal legs.

    All arrays have the same length; a row of NaN ends one piece of line and starts the
    next (the optimal legs of an analysis start where the boat was, not where the
    previous optimal leg ended).

    Attributes
    ----------
    name : str
        Legend text.
    t : ndarray
        [epoch s].
    x, y : ndarray
        Course frame [m].
    lat, lon : ndarray
        [°].
    leg : ndarray of int
        1-based leg number of each point.
    tws_kn, twa_deg, speed_kn, vmg_kn : ndarray
        True wind speed [kn], signed TWA [°] (+ starboard tack), speed [kn] (through the
        water for routes, over the ground for sailed tracks) and VMG [kn].
    modes : tuple of str
        Wind mode of each leg (``upwind``/``reach``/``downwind``), by leg number − 1.
    manoeuvres : tuple of (str, float, float, float)
        ``(kind, t, lat, lon)`` of every tack and gybe.
    speed_name : str
        What ``speed_kn`` is, for the hover text.
    dash : str
        Line style (plotly ``dash``).
    boat : bool
        Draw a marker at the boat's position at the slider's time.
    lat_shift, lon_shift : ndarray or None
        Added to ``lat``/``lon`` where the line is drawn [°]: a leg over the same water
        as an earlier one is drawn beside it (:data:`REPEAT_SHIFT`); the hover gives the
        true position.
    """

    name: str
    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    leg: NDArray[np.int64]
    tws_kn: NDArray[np.float64]
    twa_deg: NDArray[np.float64]
    speed_kn: NDArray[np.float64]
    vmg_kn: NDArray[np.float64]
    modes: tuple[str, ...]
    manoeuvres: tuple[tuple[str, float, float, float], ...] = ()
    speed_name: str = "boat speed"
    dash: str = "solid"
    boat: bool = True
    lat_shift: NDArray[np.float64] | None = None
    lon_shift: NDArray[np.float64] | None = None

    def drawn(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``(lat, lon)`` where the line is drawn [°]."""
        if self.lat_shift is None or self.lon_shift is None:
            return self.lat, self.lon
        return self.lat + self.lat_shift, self.lon + self.lon_shift


@dataclass(frozen=True, eq=False)
class WindLayer:
    """A wind field sampled on a grid at the slider's times.

    Attributes
    ----------
    name : str
        Scenario name.
    x, y : ndarray, shape (n,)
        Grid points in the course frame [m].
    lat, lon : ndarray, shape (n,)
        The same points [°].
    spacing_m : float
        Smaller grid step [m] (sets the arrows' length).
    tws_kn, twd_deg : ndarray, shape (n_times, n)
        Speed [kn] and FROM-direction [°]; one row when the wind does not change in
        time (then it is drawn once and the slider leaves it alone); NaN where the
        field has no data at that time.
    """

    name: str
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    spacing_m: float
    tws_kn: NDArray[np.float64]
    twd_deg: NDArray[np.float64]

    @property
    def steady(self) -> bool:
        """True when one row holds the wind of the whole race."""
        return self.tws_kn.shape[0] == 1

    @property
    def uniform(self) -> bool:
        """True when the wind is the same everywhere and all race (to 0.01 kn and 0.1°)."""
        ok = np.isfinite(self.tws_kn)
        if not ok.all():
            return False
        d = wrap180(self.twd_deg - self.twd_deg.flat[0])
        return bool(np.ptp(self.tws_kn) < 0.01 and np.abs(d).max() < 0.1)


@dataclass(frozen=True)
class Table:
    """A table of the page (cells are plain text, escaped when rendered).

    Attributes
    ----------
    caption : str
    headers : tuple of str
    rows, footer : tuple of tuple of str
    collapsed : bool
        Rendered inside a closed ``<details>`` (per-scenario tables of a comparison).
    """

    caption: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    footer: tuple[tuple[str, ...], ...] = ()
    collapsed: bool = False


@dataclass(frozen=True, eq=False)
class Report:
    """Everything the page shows.

    Attributes
    ----------
    title : str
    summary : tuple of str
        Lines under the title.
    course : Course
        Marks, lines and gates; ``utc_offset_s`` for the times.
    routes : tuple of Route
    winds : tuple of WindLayer
        The first is shown, the others start hidden (legend entries).
    times : ndarray
        Slider positions [epoch s].
    tables : tuple of Table
    notes : tuple of str
        Lines under the map.
    colour_by_speed : bool
        Colour the (single) route's points by speed.
    leg_numbers : bool
        Put the leg numbers on the first route.
    legend_beside : bool
        Legend in a column right of the map (many entries) instead of a row above it.
    overlays : tuple of dict
        More plotly traces drawn over the course (laylines, the favoured start end).
    """

    title: str
    summary: tuple[str, ...]
    course: Course
    routes: tuple[Route, ...]
    winds: tuple[WindLayer, ...]
    times: NDArray[np.float64]
    tables: tuple[Table, ...] = ()
    notes: tuple[str, ...] = ()
    colour_by_speed: bool = False
    leg_numbers: bool = True
    legend_beside: bool = False
    overlays: tuple[dict[str, Any], ...] = ()


# ---------------------------------------------------------------------------------------------
# times


def clock(t: float, utc_offset_s: float = 0.0) -> str:
    """``HH:MM:SS`` of epoch seconds ``t`` in the zone ``utc_offset_s`` [s] from UTC."""
    return iso(float(t) + utc_offset_s)[11:19]


def clocks(t: NDArray, utc_offset_s: float = 0.0) -> list[str]:
    """:func:`clock` of every element of ``t`` (``""`` where ``t`` is not finite)."""
    us = np.round((np.asarray(t, dtype=float) + utc_offset_s) * 1e6)
    ok = np.isfinite(us)
    text = np.datetime_as_string(np.where(ok, us, 0.0).astype(np.int64).astype("datetime64[us]"),
                                 unit="s")
    return [str(s)[11:19] if good else "" for s, good in zip(text, ok.tolist(), strict=True)]


def time_label(t: float, utc_offset_s: float) -> str:
    """``12:10:00 local (UTC+02:00) · 10:10:00 UTC``: a time for the page."""
    return f"{clock(t, utc_offset_s)} local ({offset_text(utc_offset_s)}) · {clock(t)} UTC"


# ---------------------------------------------------------------------------------------------
# routes


def leg_vmg(mode: str, speed: NDArray, twa_deg: NDArray, sog: NDArray, cog_deg: NDArray,
            x: NDArray, y: NDArray, centre: tuple[float, float]) -> NDArray[np.float64]:
    """Velocity made good [same unit as the speeds], as ``sailroute analyze`` defines it.

    Upwind: ``speed·cos(TWA)`` (towards the wind); downwind: ``−speed·cos(TWA)``; on a
    reach: the velocity over the ground towards the target's ``centre`` [m].
    """
    if mode == "upwind":
        return speed * np.cos(np.radians(twa_deg))
    if mode == "downwind":
        return -speed * np.cos(np.radians(twa_deg))
    ux, uy = centre[0] - x, centre[1] - y
    vx, vy = sog * np.sin(np.radians(cog_deg)), sog * np.cos(np.radians(cog_deg))
    return (vx * ux + vy * uy) / np.maximum(np.hypot(ux, uy), 1e-9)


def _leg_columns(course: Course, k: int, r: LegResult, mode: str) -> dict[str, NDArray]:
    """Per-point arrays of one routed leg (``k`` 0-based)."""
    tr = r.track
    centre = feature_centre(course.feature(course.legs[k].to_name))
    vmg = leg_vmg(mode, tr.bsp_ms, tr.twa_deg, tr.ground_speed_ms, tr.ground_course_deg,
                  tr.x, tr.y, centre)
    return {"t": tr.t, "x": tr.x, "y": tr.y, "leg": np.full(tr.t.size, k + 1),
            "tws": tr.tws_ms / KNOT, "twa": tr.twa_deg, "speed": tr.bsp_ms / KNOT,
            "vmg": vmg / KNOT}


def _repeat_shifts(parts: Sequence[Mapping[str, NDArray]]) -> list[tuple[float, float]]:
    """Sideways shift ``(dx, dy)`` [m] of each leg: 0 for a first passage, then
    :data:`REPEAT_SHIFT` of the longest leg per earlier leg over the same water, to the
    right of the direction of travel (as on ``route.png``)."""
    ends = []
    for p in parts:
        ok = np.isfinite(p["x"]) & np.isfinite(p["y"])
        xs, ys = np.asarray(p["x"])[ok], np.asarray(p["y"])[ok]
        ends.append(((float(xs[0]), float(ys[0])), (float(xs[-1]), float(ys[-1])))
                    if xs.size else ((math.nan, math.nan), (math.nan, math.nan)))
    chords = [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in ends]
    step = REPEAT_SHIFT * max((c for c in chords if math.isfinite(c)), default=0.0)
    out = []
    for (a, b), c, rep in zip(ends, chords, repeat_index_of_ends(ends), strict=True):
        if rep == 0 or not c > 0:
            out.append((0.0, 0.0))
            continue
        out.append((step * rep * (b[1] - a[1]) / c, -step * rep * (b[0] - a[0]) / c))
    return out


def _route(name: str, course: Course, parts: Sequence[Mapping[str, NDArray]],
           modes: Sequence[str], manoeuvres: Sequence[tuple[str, float, float, float]],
           *, gaps: bool = False, side_by_side: bool = False, **kw: Any) -> Route:
    """Join per-leg columns into a :class:`Route` (a NaN row between legs with ``gaps``;
    legs over the same water drawn beside each other with ``side_by_side``)."""
    cols: dict[str, list[NDArray]] = {k: [] for k in ("t", "x", "y", "leg", "tws", "twa",
                                                      "speed", "vmg")}
    for i, p in enumerate(parts):
        if gaps and i:
            for k in cols:
                cols[k].append(np.array([0 if k == "leg" else np.nan]))
        for k in cols:
            cols[k].append(np.asarray(p[k]))
    c = {k: np.concatenate(v) if v else np.zeros(0) for k, v in cols.items()}
    lat, lon = course.frame.to_latlon(c["x"], c["y"])
    lat, lon = np.asarray(lat, float), np.asarray(lon, float)
    shifts = _repeat_shifts(parts) if side_by_side and parts else []
    if any(sh != (0.0, 0.0) for sh in shifts):
        sx = np.zeros_like(c["x"])
        sy = np.zeros_like(c["y"])
        for i, (dx, dy) in enumerate(shifts):
            sx[c["leg"] == i + 1] = dx
            sy[c["leg"] == i + 1] = dy
        dlat, dlon = course.frame.to_latlon(c["x"] + sx, c["y"] + sy)
        kw = {**kw, "lat_shift": np.asarray(dlat, float) - lat,
              "lon_shift": np.asarray(dlon, float) - lon}
    man = []
    for kind, t, x, y in manoeuvres:
        # drawn on its leg's line: the leg whose time span holds it
        j = next((i for i, p in enumerate(parts) if p["t"][0] <= t <= p["t"][-1]), None)
        dx, dy = shifts[j] if shifts and j is not None else (0.0, 0.0)
        mlat, mlon = course.frame.to_latlon(x + dx, y + dy)
        man.append((kind, float(t), float(mlat), float(mlon)))
    return Route(name, c["t"].astype(float), c["x"], c["y"], lat, lon,
                 c["leg"].astype(np.int64), c["tws"], c["twa"], c["speed"], c["vmg"],
                 tuple(modes), tuple(man), **kw)


def route_from_plan(plan: Plan, name: str | None = None) -> Route:
    """The :class:`Route` of a routed course (boat speed through the water)."""
    modes = [pl.mode or "reach" for pl in plan.legs]
    parts = [_leg_columns(plan.course, pl.spec.index, pl.result, modes[k])
             for k, pl in enumerate(plan.legs)]
    man = [(m.kind, m.t, m.x, m.y) for pl in plan.legs for m in pl.result.manoeuvres]
    return _route(name or plan.scenario, plan.course, parts, modes, man, side_by_side=True)


def decimated(r: Route, max_points: int = MAX_ROUTE_POINTS) -> Route:
    """``r`` with at most about ``max_points`` points: every k-th one, plus the first and
    last of each leg (so leg changes stay where they are)."""
    n = r.t.size
    if n <= max_points:
        return r
    step = math.ceil(n / max_points)
    change = np.flatnonzero(np.diff(r.leg) != 0)
    keep = np.unique(np.concatenate([np.arange(0, n, step), change, change + 1, [n - 1]]))
    cut = {f: getattr(r, f)[keep] for f in ("t", "x", "y", "lat", "lon", "leg", "tws_kn",
                                             "twa_deg", "speed_kn", "vmg_kn")}
    if r.lat_shift is not None and r.lon_shift is not None:
        cut["lat_shift"], cut["lon_shift"] = r.lat_shift[keep], r.lon_shift[keep]
    return replace(r, **cut)


def routes_from_analysis(a: TrackAnalysis) -> tuple[Route, Route]:
    """The sailed track (speed over the ground; at most :data:`MAX_ROUTE_POINTS` points)
    and the optimal legs from its leg starts (legs of unknown start left out)."""
    p, course = a.points, a.course
    modes = [leg.mode for leg in a.legs]
    sailed_parts = [{"t": p.t, "x": p.x, "y": p.y, "leg": p.leg, "tws": p.tws_ms / KNOT,
                     "twa": p.twa_deg, "speed": p.sog_ms / KNOT, "vmg": p.vmg_ms / KNOT}]
    man = []
    for m in (m for leg in a.legs for m in leg.manoeuvres):
        man.append((m.kind, m.t, float(np.interp(m.t, p.t, p.x)),
                    float(np.interp(m.t, p.t, p.y))))
    sailed = decimated(_route(f"sailed: {a.track.name}", course, sailed_parts, modes, man,
                              speed_name="SOG"))
    opt_parts = [_leg_columns(course, leg.index, leg.optimal, leg.mode) for leg in a.legs
                 if leg.optimal is not None]
    opt_man = [(m.kind, m.t, m.x, m.y) for leg in a.legs if leg.optimal is not None
               for m in leg.optimal.manoeuvres]
    optimal = _route("optimal from the boat's leg starts", course, opt_parts, modes,
                     opt_man, gaps=True, dash="dash", boat=False)
    return sailed, optimal


# ---------------------------------------------------------------------------------------------
# wind


def course_area(course: Course, routes: Sequence[Route], pad: float = 0.08
                ) -> tuple[float, float, float, float]:
    """``(x0, x1, y0, y1)`` [m]: the marks and routes, padded by ``pad`` of the larger side."""
    xs = [m.x for m in course.marks.values()]
    ys = [m.y for m in course.marks.values()]
    for r in routes:
        if np.isfinite(r.x).any():
            xs += [float(np.nanmin(r.x)), float(np.nanmax(r.x))]
            ys += [float(np.nanmin(r.y)), float(np.nanmax(r.y))]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    span = max(x1 - x0, y1 - y0, 100.0)
    return x0 - pad * span, x1 + pad * span, y0 - pad * span, y1 + pad * span


def wind_layer(name: str, wind: WindField, course: Course,
               area: tuple[float, float, float, float], times: NDArray,
               grid: int = WIND_GRID) -> WindLayer | None:
    """Sample ``wind`` at the centres of ``grid × grid`` cells over ``area`` (clipped to the
    field's coverage) at each of ``times`` [epoch s].

    Returns
    -------
    WindLayer or None
        None when the field covers none of the area.  Times outside the field's
        coverage give NaN rows (no arrows); a field that is the same at every time
        keeps one row.
    """
    c = wind.coverage
    x0, x1 = max(area[0], c.xmin), min(area[1], c.xmax)
    y0, y1 = max(area[2], c.ymin), min(area[3], c.ymax)
    if not (x0 < x1 and y0 < y1):
        return None
    # cell centres: the arrows stay inside the area
    xs = x0 + (np.arange(grid) + 0.5) * (x1 - x0) / grid
    ys = y0 + (np.arange(grid) + 0.5) * (y1 - y0) / grid
    gx, gy = (a.ravel() for a in np.meshgrid(xs, ys))
    spd = np.full((len(times), gx.size), np.nan)
    twd = np.full((len(times), gx.size), np.nan)
    for k, t in enumerate(times):
        if not (c.t0 <= t <= c.t1):
            continue
        try:
            u, v = wind.sample(float(t), gx, gy)
        except OutOfCoverageError:
            continue
        spd[k], twd[k] = wind_speed_direction(u, v)
    if not np.isfinite(spd).any():
        return None
    if np.allclose(spd, spd[:1], atol=1e-9, equal_nan=True) and \
            np.allclose(twd, twd[:1], atol=1e-9, equal_nan=True):
        spd, twd = spd[:1], twd[:1]
    lat, lon = course.frame.to_latlon(gx, gy)
    spacing = min(x1 - x0, y1 - y0) / grid
    return WindLayer(name, gx, gy, np.asarray(lat, float), np.asarray(lon, float), spacing,
                     spd / KNOT, twd)


def slider_times(routes: Sequence[Route], n: int = N_STEPS) -> NDArray[np.float64]:
    """``n`` equally spaced times [epoch s] from the first start to the last arrival of the
    routes that carry a boat marker (all routes if none does)."""
    rs = [r for r in routes if r.boat] or list(routes)
    t = np.concatenate([r.t for r in rs]) if rs else np.zeros(0)
    t = t[np.isfinite(t)]
    if t.size == 0:
        return np.zeros(1)
    t0, t1 = float(t.min()), float(t.max())
    return np.array([t0]) if t1 <= t0 else np.linspace(t0, t1, n)


# ---------------------------------------------------------------------------------------------
# builders


def _plan_table(plan: Plan, caption: str, collapsed: bool = False) -> Table:
    """The leg table of a plan: times in local time, durations, distances, references."""
    off = plan.course.utc_offset_s
    refs = list(plan.references.items())
    headers = ["leg", "from → to", "mode", "start", "arrival", "time", "distance m",
               "tacks", "gybes", "mean boat speed kn", "start point"]
    for name, _ in refs:
        headers += [name, f"vs {name}"]
    rows = []
    for k, pl in enumerate(plan.legs):
        r = pl.result
        dt = np.diff(r.track.t)
        stw = float(np.sum(r.track.bsp_ms[:-1] * dt) / r.time_s) / KNOT if r.time_s > 0 \
            else float("nan")
        row = [str(pl.spec.index + 1), pl.spec.label.replace("->", "→"), pl.mode or "-",
               clock(r.t_start, off), clock(r.t_end, off), format_duration(r.time_s),
               f"{r.distance_m:.0f}", str(r.n_tacks), str(r.n_gybes), f"{stw:.2f}",
               start_point_text(pl)]
        for _, times in refs:
            row += [format_duration(times[k]), f"{percent_error(r.time_s, times[k]):+.1f}%"]
        rows.append(tuple(row))
    total = ["", "total", "", clock(plan.t_start, off), clock(plan.t_end, off),
             format_duration(plan.total_time_s),
             f"{sum(pl.result.distance_m for pl in plan.legs):.0f}",
             str(sum(pl.result.n_tacks for pl in plan.legs)),
             str(sum(pl.result.n_gybes for pl in plan.legs)), "", ""]
    for _, times in refs:
        total += [format_duration(sum(times)),
                  f"{percent_error(plan.total_time_s, sum(times)):+.1f}%"]
    return Table(caption, tuple(headers), tuple(rows), (tuple(total),), collapsed)


def _times_note(course: Course) -> str:
    return (f"Times: local time of the course ({offset_text(course.utc_offset_s)}, the offset "
            "its start_time is written with) and UTC.")


def _wind_note(layers: Sequence[WindLayer]) -> str:
    if not layers:
        return "No wind drawn: the wind data do not cover the course area."
    steady = all(w.steady for w in layers)
    return (f"Wind: arrows point where the air goes, their length in proportion to the "
            f"speed (hover over an arrowhead for its speed and direction); the field sampled on "
            f"{WIND_GRID} × {WIND_GRID} points over the course area"
            + (", the same all race." if steady else
               f" at each of the slider's {N_STEPS} times."))


HELP = ("Drag the time slider (or press ▶) to move the boat and the wind; click a legend "
        "entry to hide or show it; hover over a route for its time, wind and speed; scroll "
        "to zoom, drag to pan, double-click to reset the view. Background: plain water "
        "(no chart or coastline); positions WGS-84.")


def plan_report(plan: Plan, wind: WindField | None = None) -> Report:
    """The page of ``sailroute plan``: one route, coloured by boat speed, its leg table."""
    c, off = plan.course, plan.course.utc_offset_s
    route = route_from_plan(plan, f"route: {plan.scenario}")
    times = slider_times([route])
    layers = _layers({plan.scenario: wind} if wind is not None else {}, c, [route], times)
    summary = (
        f"Scenario {plan.scenario} · router {plan.router or '-'} · "
        f"start {time_label(plan.t_start, off)} on {iso(plan.t_start + off)[:10]}",
        f"Race time {format_duration(plan.total_time_s)} ({plan.total_time_s:.0f} s), "
        f"{sum(pl.result.distance_m for pl in plan.legs):.0f} m sailed, "
        f"{sum(pl.result.n_tacks for pl in plan.legs)} tacks, "
        f"{sum(pl.result.n_gybes for pl in plan.legs)} gybes; arrival "
        f"{time_label(plan.t_end, off)}",
    )
    # the start line numbers, laylines and favoured end (report/startline.py)
    from sailroute.report.startline import plotly_traces
    from sailroute.report.tables import start_line_rows

    start = () if plan.start_line is None else (
        Table("Start line", ("", "at the gun"), tuple(start_line_rows(plan.start_line))),)
    return Report(f"{c.name} — {plan.scenario}", summary, c, (route,), tuple(layers), times,
                  (_plan_table(plan, "Legs"), *start),
                  (HELP, _times_note(c), _wind_note(layers)), colour_by_speed=True,
                  overlays=tuple(plotly_traces(plan.start_line, plan.laylines, c.frame)))


def _layers(winds: Mapping[str, WindField], course: Course, routes: Sequence[Route],
            times: NDArray) -> list[WindLayer]:
    area = course_area(course, routes)
    out = []
    for name, w in list(winds.items())[:MAX_WIND_LAYERS]:
        layer = wind_layer(name, w, course, area, times)
        if layer is not None:
            out.append(layer)
    return out


def comparison_report(cmp: Comparison, plans: Sequence[Plan],
                      winds: Mapping[str, WindField] | None = None) -> Report:
    """The page of ``compare-scenarios``: every scenario's route (legend toggles them),
    each scenario's wind (the first shown), the legs × scenarios times and each
    scenario's leg table (folded)."""
    course = plans[0].course
    off = course.utc_offset_s
    routes = tuple(route_from_plan(p) for p in plans)
    times = slider_times(routes)
    layers = _layers(dict(winds or {}), course, routes, times)
    refs = list(cmp.references)
    rows = []
    for k, label in enumerate(cmp.leg_labels):
        rows.append((f"{k + 1}", label.replace("->", "→"),
                     *(format_duration(cmp.times[i, k]) for i in range(len(cmp.scenarios))),
                     *(format_duration(cmp.references[r][k]) for r in refs)))
    footer = (("", "total", *(format_duration(t) for t in cmp.totals),
               *(format_duration(float(cmp.references[r].sum())) for r in refs)),)
    tables = [Table("Leg times by scenario", ("leg", "from → to", *cmp.scenarios, *refs),
                    tuple(rows), footer)]
    tables += [_plan_table(p, f"Legs: {p.scenario}", collapsed=True) for p in plans]
    best = int(np.argmin(cmp.totals))
    summary = (
        f"{len(plans)} scenarios, start {time_label(plans[0].t_start, off)} on "
        f"{iso(plans[0].t_start + off)[:10]}",
        "Race times: " + ", ".join(f"{s} {format_duration(t)}"
                                   for s, t in zip(cmp.scenarios, cmp.totals, strict=True))
        + f"; fastest {cmp.scenarios[best]}",
    )
    notes = [HELP, _times_note(course), _wind_note(layers)]
    if winds and len(winds) > len(layers):
        notes.append(f"The wind of {len(winds) - len(layers)} scenarios is not drawn (at most "
                     f"{MAX_WIND_LAYERS} are; or their data miss the course area).")
    return Report(f"{cmp.course_name} — scenario comparison", summary, course, routes,
                  tuple(layers), times, tuple(tables), tuple(notes), leg_numbers=False,
                  legend_beside=True)


def analysis_report(a: TrackAnalysis) -> Report:
    """The page of ``sailroute analyze``: the sailed track, the optimal legs from the
    boat's own leg starts (dashed) and the leg table with the time lost."""
    course, off = a.course, a.course.utc_offset_s
    sailed, optimal = routes_from_analysis(a)
    times = slider_times([sailed])
    layers = _layers({_wind_name(a): a.wind}, course, [sailed, optimal], times)
    rows = []
    for leg in a.legs:
        if not leg.known:
            rows.append((str(leg.index + 1), leg.label.replace("->", "→"), leg.mode,
                         clock(leg.t_start, off) if np.isfinite(leg.t_start) else "unknown",
                         "unknown", format_duration(leg.optimal_time_s), "-", "-", "-", "-",
                         "-", "-", leg.note, leg.wind_source))
            continue
        rows.append((str(leg.index + 1), leg.label.replace("->", "→"), leg.mode,
                     clock(leg.t_start, off), format_duration(leg.sailed_time_s),
                     format_duration(leg.optimal_time_s), f"{leg.loss_s:+.1f}",
                     f"{leg.split.manoeuvres:+.1f}", f"{leg.split.speed:+.1f}",
                     f"{leg.split.route:+.1f}",
                     f"{leg.sailed_tacks}/{leg.sailed_gybes} : "
                     f"{leg.optimal_tacks}/{leg.optimal_gybes}",
                     _polar_pct(leg), f"{leg.side_sailed} / {leg.side_optimal}",
                     leg.wind_source))
    tot = [sum(getattr(leg.split, k) for leg in a.known_legs) for k in ("manoeuvres", "speed",
                                                                         "route")]
    footer = (("", "total" if a.complete else f"{len(a.known_legs)} legs of known time", "",
               "", format_duration(a.sailed_time_s),
               format_duration(a.optimal_time_s), f"{a.loss_s:+.1f}",
               *(f"{v:+.1f}" for v in tot), "", "", "", ""),)
    table = Table("Legs: sailed against optimal from the same point and time",
                  ("leg", "from → to", "mode", "start", "sailed", "optimal", "lost s",
                   "manoeuvres s", "speed s", "route s", "tacks/gybes sailed : optimal",
                   "polar %", "side sailed / optimal", "wind"), tuple(rows), footer)
    t0 = a.legs[0].t_start if a.legs else course.start_epoch
    summary = (f"Track {a.track.name} · scenario {a.scenario} · router {a.router} · start "
               f"{time_label(t0, off)} on {iso(t0 + off)[:10]}",
               f"Sailed {format_duration(a.sailed_time_s)}, optimal "
               f"{format_duration(a.optimal_time_s)}, lost {a.loss_s:+.1f} s")
    return Report(f"{course.name} — {a.track.name}", summary, course, (sailed, optimal),
                  tuple(layers), times, (table,),
                  (HELP, *_judged_notes([a]), *a.notes, _times_note(course),
                   _wind_note(layers)))


def _wind_name(a: TrackAnalysis) -> str:
    """Name of the wind drawn for an analysis: its first leg's source."""
    return a.legs[0].wind_label if a.legs and a.legs[0].wind_label else a.scenario


def _polar_pct(leg: Any) -> str:
    """A leg's mean polar %, marked ``*`` above the polar."""
    if not math.isfinite(leg.mean_polar_pct):
        return "-"
    return f"{leg.mean_polar_pct:.0f}" + (" *" if leg.above_polar else "")


def _judged_notes(analyses: Sequence[TrackAnalysis]) -> list[str]:
    """What the boats are judged against and in which wind, and the above-polar warning."""
    out = []
    refs = dict.fromkeys(a.reference for a in analyses if a.reference)
    out += [f"Judged against the {r}." if r.startswith("course") else f"Judged against a {r}."
            for r in refs]
    winds = dict.fromkeys(f"{leg.wind_source} ({leg.wind_label})" for a in analyses
                          for leg in a.legs if leg.wind_label)
    if winds:
        out.append("Wind of the legs: " + "; ".join(winds) + ".")
    above = [f"{a.track.name} leg {leg.index + 1}" for a in analyses for leg in a.legs
             if leg.above_polar]
    if above:
        out.append(f"* Sailed above {ABOVE_POLAR_PCT:.0f} % of the polar ({', '.join(above)}): "
                   "the polar stands in for another class, or the wind is wrong (too light); "
                   "those losses are not a debrief (analyze --reference fleet judges the boats "
                   "against what the fleet sails).")
    return out


def _leader(analyses: Sequence[TrackAnalysis]) -> int:
    """Index of the boat ahead at the last leg end whose time is known for some boat."""
    for i in reversed(range(min(len(a.legs) for a in analyses))):
        ends = np.array([a.legs[i].t_end for a in analyses])
        if np.isfinite(ends).any():
            return int(np.nanargmin(ends))
    return 0


def _signed(v: float, nd: int = 1) -> str:
    return f"{v:+.{nd}f}" if math.isfinite(v) else "-"


def fleet_report(analyses: Sequence[TrackAnalysis], rows: Sequence[Mapping[str, Any]],
                 notes: Sequence[str] = (), wind: tuple[str, WindField] | None = None
                 ) -> Report:
    """The page of ``sailroute analyze`` with several tracks.

    Every boat's sailed track on one map with one time slider (a marker per boat), the
    optimal legs from the *leader's* leg starts (the boat ahead at the last leg end of
    known time; each boat's own optimal legs are on its own page), the wind (``wind``),
    and three tables: the leg ranking (``rows`` of
    :func:`sailroute.analysis.debrief.fleet_ranking`), the start (time late, distance to the line,
    side and speed at the gun, over early, line offset) and the loss split per boat and
    leg.  ``notes`` (fleet-wide) and each boat's own notes go under the map.  ``wind``
    (name, field) is the wind drawn; default the first boat's first leg's.
    """
    course, off = analyses[0].course, analyses[0].course.utc_offset_s
    sailed = [replace(routes_from_analysis(a)[0], name=a.track.name) for a in analyses]
    lead = _leader(analyses)
    opt = replace(routes_from_analysis(analyses[lead])[1],
                  name=f"optimal from {analyses[lead].track.name}'s leg starts")
    routes = (*sailed, opt)
    times = slider_times(sailed, FLEET_STEPS)
    name, field = wind if wind is not None else (_wind_name(analyses[0]), analyses[0].wind)
    layers = _layers({name: field}, course, routes, times)
    names = [a.track.name for a in analyses]
    by = {(r["leg"], r["boat"]): r for r in rows}
    rank_rows = []
    for i, spec in enumerate(course.legs):
        cells = []
        for b in names:
            row = by.get((i + 1, b))
            if row is None or row["leg_rank"] is None:
                cells.append("unknown")
            else:
                pos = f", pos {row['position']}" if row["position"] is not None else ""
                cells.append(f"{format_duration(row['leg_time_s'])} ({row['leg_rank']}{pos}) "
                             f"{_signed(row['loss_s'])} s")
        rank_rows.append((str(i + 1), spec.label.replace("->", "→"), *cells))
    ranking = Table("Leg ranking: leg time (rank, position at the leg's end) and time lost "
                    "against the optimal leg", ("leg", "from → to", *names),
                    tuple(rank_rows))
    start_rows = []
    for a in analyses:
        st = a.segmentation.start
        start_rows.append((
            a.track.name, clock(st.crossing.t, off), f"{st.late_s:+.1f}",
            f"{st.distance_at_gun_m:.0f} ({st.side_at_gun})",
            f"{st.speed_at_gun_ms / KNOT:.1f}" if math.isfinite(st.speed_at_gun_ms) else "-",
            (f"{st.ocs_s:.0f} s" + (", returned" if st.ocs_returned else "")
             if st.ocs_s is not None else ("returned" if st.ocs_returned else "no")),
            f"{st.line_offset_m:.0f}", "; ".join(st.notes)))
    start = Table("Start", ("boat", "start (local)", "late s", "to the line at the gun m",
                            "speed at the gun kn", "over early", "line offset m", "notes"),
                  tuple(start_rows))
    split_rows = []
    for a in analyses:
        for leg in a.legs:
            split_rows.append((a.track.name, str(leg.index + 1), leg.label.replace("->", "→"),
                               _signed(leg.loss_s), _signed(leg.split.manoeuvres),
                               _signed(leg.split.speed), _signed(leg.split.route),
                               _polar_pct(leg), leg.wind_source, leg.note))
    split = Table("Time lost per boat and leg, split into manoeuvres, speed and route",
                  ("boat", "leg", "from → to", "lost s", "manoeuvres s", "speed s", "route s",
                   "polar %", "wind", "note"), tuple(split_rows),
                  collapsed=len(split_rows) > 40)
    t0 = course.start_epoch
    summary = (
        f"{len(analyses)} boats · scenario {analyses[0].scenario} · router "
        f"{analyses[0].router} · gun {time_label(t0, off)} on {iso(t0 + off)[:10]}",
        "Sailed (legs of known time): " + ", ".join(
            f"{a.track.name} {format_duration(a.sailed_time_s)}"
            + ("" if a.complete else f" ({len(a.known_legs)} of {len(a.legs)} legs)")
            for a in analyses))
    page_notes = [HELP, *_judged_notes(analyses), *notes,
                  *(f"{a.track.name}: {n}" for a in analyses for n in a.notes),
                  "The dashed line is the optimal route of each leg from the leader's own leg "
                  "start point and time.", _times_note(course), _wind_note(layers)]
    return Report(f"{course.name} — fleet of {len(analyses)}", summary, course, routes,
                  tuple(layers), times, (ranking, start, split), tuple(page_notes),
                  leg_numbers=False, legend_beside=True)


# ---------------------------------------------------------------------------------------------
# figure


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
    cols = zip(r.leg.tolist(), modes, clocks(r.t, off), clocks(r.t), _r(r.tws_kn, 2),
               _r(np.abs(r.twa_deg), 1),
               np.where(r.twa_deg >= 0, "stbd", "port").tolist(), _r(r.speed_kn, 3),
               _r(r.vmg_kn, 3), _r(r.lat, 6), _r(r.lon, 6), strict=True)
    ok = np.isfinite(r.t).tolist()
    return [list(row) if good else None for row, good in zip(cols, ok, strict=True)]


def _hover(r: Route, off: float) -> str:
    return ("<b>%{fullData.name}</b> · leg %{customdata[0]} (%{customdata[1]})<br>"
            f"%{{customdata[2]}} local ({offset_text(off)}) · %{{customdata[3]}} UTC<br>"
            "TWS %{customdata[4]:.1f} kn · TWA %{customdata[5]:.0f}° %{customdata[6]}<br>"
            f"{r.speed_name} %{{customdata[7]:.2f}} kn · VMG %{{customdata[8]:.2f}} kn"
            "<br>%{customdata[9]:.5f}° N %{customdata[10]:.5f}° E<extra></extra>")


def boat_at(r: Route, times: NDArray) -> NDArray[np.int64]:
    """Index of the last point of ``r`` at or before each of ``times`` (the first point
    before the start, the last after the arrival); ``r.t`` must be non-decreasing (a
    route with a boat has no gaps)."""
    k = np.searchsorted(r.t, np.asarray(times, dtype=float), side="right") - 1
    return np.clip(k, 0, r.t.size - 1)


def _boat_states(r: Route, times: NDArray, off: float, custom: Sequence[Any]
                 ) -> list[dict[str, Any]]:
    """Boat marker of ``r`` at each of ``times``: the position interpolated in time, the
    hover data of the point before with the time itself."""
    drawn_lat, drawn_lon = r.drawn()
    lat = _r(np.interp(times, r.t, drawn_lat), 7)
    lon = _r(np.interp(times, r.t, drawn_lon), 7)
    true_lat = _r(np.interp(times, r.t, r.lat), 6)
    true_lon = _r(np.interp(times, r.t, r.lon), 6)
    out = []
    for k, (i, local, utc) in enumerate(zip(boat_at(r, times).tolist(), clocks(times, off),
                                            clocks(times), strict=True)):
        row = list(custom[i] or [])
        if row:
            row[2], row[3] = local, utc
            row[9], row[10] = true_lat[k], true_lon[k]
        out.append({"x": [lon[k]], "y": [lat[k]], "customdata": [row]})
    return out


def wind_arrows(w: WindLayer, course: Course, m_per_kn: float
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
        heads = {"x": _r(tip_lon[k], 6), "y": _r(tip_lat[k], 6),
                 "marker": {"angle": _r(angle[k], 1)},
                 "customdata": [[a, b] for a, b in zip(_r(spd[k], 1), _r(twd[k], 0),
                                                       strict=True)]}
        out.append((shafts, heads))
    return out


def label_positions(course: Course) -> list[str]:
    """plotly ``textposition`` of each mark's name: away from its line/gate partner, or from
    the course's centre for a single mark (as on ``route.png``), so the two names of a
    short line do not overlap."""
    from sailroute.report.plots import _label_directions

    out = []
    for dx, dy in _label_directions(course).values():
        v = "top" if dy > 0.3 else ("bottom" if dy < -0.3 else "middle")
        h = "right" if dx > 0.3 else ("left" if dx < -0.3 else "center")
        out.append(f"{v} {h}" if (v, h) != ("middle", "center") else "top right")
    return out


def _course_traces(course: Course) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    first = True
    for ln, dash in [*((ln, "solid") for ln in course.lines.values()),
                     *((g, "dot") for g in course.gates.values())]:
        out.append({"type": "scatter", "mode": "lines", "name": "lines and gates",
                    "legendgroup": "course", "showlegend": first,
                    "x": _r([ln.a.lon, ln.b.lon], 7), "y": _r([ln.a.lat, ln.b.lat], 7),
                    "line": {"color": "black", "width": 2, "dash": dash},
                    "hovertemplate": f"{_label(ln.name)}<extra></extra>"})
        first = False
    marks = list(course.marks.values())
    out.append({"type": "scatter", "mode": "markers+text", "name": "marks",
                "legendgroup": "course",
                "x": _r([m.lon for m in marks], 7), "y": _r([m.lat for m in marks], 7),
                "text": [_label(m.name) for m in marks],
                "textposition": label_positions(course),
                "textfont": {"size": 12, "color": "#222"},
                "marker": {"color": "darkorange", "size": 11,
                           "line": {"color": "black", "width": 1}},
                "hovertemplate": "mark %{text}<br>%{y:.6f}° N %{x:.6f}° E<extra></extra>"})
    return out


def _leg_number_trace(r: Route, group: str) -> dict[str, Any]:
    """The leg numbers along ``r``, spread between 30 % and 70 % of each leg (golden-ratio
    steps, as on ``route.png``) so legs over the same water do not hide each other's."""
    xs, ys, text = [], [], []
    lat, lon = r.drawn()
    for k in range(len(r.modes)):
        idx = np.flatnonzero(r.leg == k + 1)
        if idx.size == 0:
            continue
        i = idx[min(int((0.3 + 0.4 * ((k * 0.6180339887) % 1.0)) * idx.size), idx.size - 1)]
        xs.append(lon[i])
        ys.append(lat[i])
        text.append(str(k + 1))
    return {"type": "scatter", "mode": "markers+text", "name": "leg numbers",
            "legendgroup": group, "showlegend": False, "x": _r(xs, 7), "y": _r(ys, 7),
            "text": text, "textfont": {"size": 10, "color": "#222"},
            "marker": {"color": "white", "size": 17, "line": {"color": "#555", "width": 1}},
            "hovertemplate": "leg %{text}<extra></extra>"}


def figure(report: Report) -> dict[str, Any]:
    """The plotly figure of the page: ``{"data", "layout", "frames", "config"}``.

    Trace order: wind layers, course (lines and gates, marks), the overlays, then per
    route its line, tacks, gybes (and leg numbers on the first route) and the boat
    marker.  Frame ``k`` (named ``str(k)``) moves every boat marker and every
    time-varying wind layer to ``report.times[k]``; the slider's steps animate to them.
    """
    course, off = report.course, report.course.utc_offset_s
    data: list[dict[str, Any]] = []
    moving: list[tuple[int, list[dict[str, Any]]]] = []  # (trace, its state per frame)

    top = max((float(np.nanmax(w.tws_kn)) for w in report.winds
               if np.isfinite(w.tws_kn).any()), default=0.0)
    m_per_kn = ARROW_FILL * min(w.spacing_m for w in report.winds) / top if top > 0 else 0.0
    route_names = [r.name for r in report.routes]
    for i, w in enumerate(report.winds):
        colour = _colour(route_names.index(w.name)) \
            if len(report.winds) > 1 and w.name in route_names else WIND_COLOUR
        name = "wind" if len(report.winds) == 1 else f"wind: {w.name}"
        if w.uniform:
            name += f" {w.tws_kn.flat[0]:.1f} kn from {w.twd_deg.flat[0]:.0f}°"
        rows = wind_arrows(w, course, m_per_kn)
        shafts, heads = rows[0]
        group = f"wind{i}"
        common = {"type": "scatter", "legendgroup": group, "name": _label(name),
                  **({} if i == 0 else {"visible": "legendonly"})}
        data.append({**common, "mode": "lines", **shafts, "hoverinfo": "skip",
                     "line": {"color": colour, "width": 1.3}, "opacity": 0.75})
        data.append({**common, "mode": "markers", "showlegend": False, **heads,
                     "marker": {"symbol": "arrow", "size": 9, "color": colour,
                                "angle": heads["marker"]["angle"], "line": {"width": 0}},
                     "opacity": 0.75,
                     "hovertemplate": "wind %{customdata[0]:.1f} kn from "
                                      f"%{{customdata[1]:.0f}}°<extra>{_label(w.name)}"
                                      "</extra>"})
        if not w.steady:
            moving.append((len(data) - 2, [sh for sh, _ in rows]))
            moving.append((len(data) - 1, [hd for _, hd in rows]))

    data += _course_traces(course)
    data += list(report.overlays)

    single = report.colour_by_speed and len(report.routes) == 1
    slo, shi = speed_limits(np.concatenate([r.speed_kn for r in report.routes]), decimals=2) \
        if report.routes else (0.0, SPEED_SPAN_KN)
    for i, r in enumerate(report.routes):
        group = f"route{i}"
        colour = "#333333" if single else _colour(i)
        custom = _customdata(r, off)
        drawn_lat, drawn_lon = r.drawn()
        tr = {"type": "scatter", "mode": "lines+markers" if single else "lines",
              "name": _label(r.name), "legendgroup": group,
              "x": _r(drawn_lon, 7), "y": _r(drawn_lat, 7),
              "line": {"color": colour, "width": 2.5, "dash": r.dash},
              "customdata": custom, "hovertemplate": _hover(r, off)}
        if single:
            tr["marker"] = {"color": _r(r.speed_kn, 3), "colorscale": "Viridis",
                            "cmin": slo, "cmax": shi, "size": 5,
                            "colorbar": {"title": {"text": "boat speed [kn]"}, "x": 1.02,
                                         "y": 1.0, "yanchor": "top", "len": 0.45,
                                         "thickness": 14}}
        data.append(tr)
        for kind, symbol, mc in (("tack", "triangle-up", "crimson"),
                                 ("gybe", "square", "royalblue")):
            pts = [m for m in r.manoeuvres if m[0] == kind]
            data.append({"type": "scatter", "mode": "markers", "name": f"{kind}s",
                         "legendgroup": group, "showlegend": False,
                         "x": _r([m[3] for m in pts], 7), "y": _r([m[2] for m in pts], 7),
                         "text": [f"{kind} {clock(m[1], off)} local · {clock(m[1])} UTC"
                                  for m in pts],
                         "marker": {"symbol": symbol, "color": mc, "size": 10,
                                    "line": {"color": "white", "width": 1}},
                         "hovertemplate": f"%{{text}}<extra>{_label(r.name)}</extra>"})
        if i == 0 and report.leg_numbers:
            data.append(_leg_number_trace(r, group))
        if r.boat:
            states = _boat_states(r, report.times, off, custom)
            st = states[0]
            data.append({"type": "scatter", "mode": "markers",
                         "name": _label(f"boat: {r.name}"),
                         "legendgroup": group, "showlegend": False, **st,
                         "marker": {"symbol": "circle", "size": 15,
                                    "color": BOAT_COLOUR if single else colour,
                                    "line": {"color": "white", "width": 2.5}},
                         "hovertemplate": "boat · " + _hover(r, off)})
            moving.append((len(data) - 1, states))

    frames = []
    if len(report.times) > 1 and moving:
        for k in range(len(report.times)):
            frames.append({"name": str(k), "data": [states[k] for _, states in moving],
                           "traces": [i for i, _ in moving]})
    return {"data": data, "layout": _layout(report, frames), "frames": frames,
            "config": {"responsive": True, "displaylogo": False, "scrollZoom": True}}


def _layout(report: Report, frames: Sequence[Any]) -> dict[str, Any]:
    course, off = report.course, report.course.utc_offset_s
    lat0 = course.frame.lat0
    x0, x1, y0, y1 = course_area(course, report.routes)
    lats, lons = course.frame.to_latlon(np.array([x0, x1, x0, x1]), np.array([y0, y0, y1, y1]))
    layout: dict[str, Any] = {
        "xaxis": {"title": {"text": "longitude [° E]"}, "tickformat": ".3f",
                  "range": _r([np.min(lons), np.max(lons)], 6), "gridcolor": "white",
                  "zeroline": False, "constrain": "domain"},
        "yaxis": {"title": {"text": "latitude [° N]"}, "tickformat": ".3f",
                  "range": _r([np.min(lats), np.max(lats)], 6), "gridcolor": "white",
                  "zeroline": False, "scaleanchor": "x",
                  "scaleratio": round(1.0 / math.cos(math.radians(lat0)), 6)},
        "plot_bgcolor": SEA, "paper_bgcolor": "white", "hovermode": "closest",
        "dragmode": "pan", "margin": {"l": 70, "r": 30, "t": 40, "b": 40},
        "legend": ({"orientation": "v", "x": 1.02, "y": 1.0, "yanchor": "top"}
                   if report.legend_beside else
                   {"orientation": "h", "x": 0.0, "y": 1.02, "yanchor": "bottom"}),
        "font": {"family": "Helvetica, Arial, sans-serif", "size": 12},
        "uirevision": "sailroute",
    }
    if frames:
        step_args = {"mode": "immediate", "frame": {"duration": 0, "redraw": True},
                     "transition": {"duration": 0}}
        t0 = float(report.times[0])
        layout["sliders"] = [{
            "active": 0, "pad": {"t": 50, "b": 10, "l": 110}, "x": 0.0, "len": 1.0,
            "currentvalue": {"prefix": "time: ", "font": {"size": 13, "color": "#222"}},
            "font": {"color": "rgba(0,0,0,0)", "size": 1},
            "steps": [{"label": f"{time_label(t, off)} · race +{format_duration(t - t0)}",
                       "method": "animate", "args": [[str(k)], step_args]}
                      for k, t in enumerate(report.times)],
        }]
        layout["updatemenus"] = [{
            "type": "buttons", "direction": "left", "x": 0.0, "y": 0.0, "xanchor": "left",
            "yanchor": "top", "pad": {"t": 60, "r": 10}, "showactive": False,
            "buttons": [
                {"label": "▶", "method": "animate",
                 "args": [None, {"mode": "immediate", "fromcurrent": True,
                                 "frame": {"duration": 400, "redraw": True},
                                 "transition": {"duration": 0}}]},
                {"label": "❚❚", "method": "animate",
                 "args": [[None], {"mode": "immediate", "frame": {"duration": 0,
                                                                   "redraw": False}}]},
            ]}]
        layout["margin"]["b"] = 100
    return layout


# ---------------------------------------------------------------------------------------------
# page


_CSS = """
body { font-family: Helvetica, Arial, sans-serif; margin: 16px 24px; color: #222; }
h1 { font-size: 20px; margin: 0 0 6px 0; }
h2 { font-size: 16px; margin: 18px 0 6px 0; }
p.summary { margin: 2px 0; }
#sailroute-map { width: 100%; }
p.note { font-size: 12px; color: #555; margin: 2px 0; }
div.table { overflow-x: auto; }
table { border-collapse: collapse; font-size: 13px; margin: 4px 0 12px 0; }
th, td { border: 1px solid #ccc; padding: 3px 7px; text-align: right; white-space: nowrap; }
th { background: #eef3f7; }
td.l, th.l { text-align: left; }
tfoot td { font-weight: bold; background: #f7f7f7; }
#sailroute-error { color: #b00; font-weight: bold; }
footer { font-size: 11px; color: #777; margin-top: 16px; }
"""

# Draws the figure; ``#step=K`` in the address opens the slider at step K.  The body gets
# data-map="drawn" once everything is done (the browser test reads it); an error is shown
# on the page instead of failing silently.
_JS = """
(function () {
  var box = document.getElementById('sailroute-error');
  function fail(e) { box.textContent = 'The map could not be drawn: ' + e;
                     document.body.setAttribute('data-map', 'failed'); }
  try {
    var fig = JSON.parse(document.getElementById('%(fig)s').textContent);
    var gd = document.getElementById('%(div)s');
    Plotly.newPlot(gd, fig.data, fig.layout, fig.config).then(function () {
      return fig.frames.length ? Plotly.addFrames(gd, fig.frames) : null;
    }).then(function () {
      var m = /step=(\\d+)/.exec(window.location.hash);
      if (m && fig.frames.length) {
        var k = Math.min(parseInt(m[1], 10), fig.frames.length - 1);
        return Plotly.animate(gd, [String(k)], {mode: 'immediate', transition: {duration: 0},
                                                 frame: {duration: 0, redraw: true}})
          .then(function () { return Plotly.relayout(gd, {'sliders[0].active': k}); });
      }
      return null;
    }).then(function () { document.body.setAttribute('data-map', 'drawn'); }, fail);
  } catch (e) { fail(e); }
})();
"""


def _h(text: str) -> str:
    """User text for the page's HTML: escaped, control characters replaced."""
    return html.escape(clean_text(text))


def _label(text: str) -> str:
    """User text (a name) for plotly: trace names, hover text and mark labels.

    Plotly draws these as its own small markup (``<b>``, ``<a href>``, ``<br>``, entities)
    and reads ``%{...}`` in a hover template as a placeholder: ``&``, ``<`` and ``>``
    become entities, ``%`` becomes ``&#37;``, control characters U+FFFD.  (``&quot;``
    is not among the entities plotly knows, so quotes stay as they are.)
    """
    return html.escape(clean_text(text), quote=False).replace("%", "&#37;")


def _json_for_script(obj: Any) -> str:
    """JSON safe inside a ``<script>`` element (no ``<``, ``>`` or ``&`` characters)."""
    text = json.dumps(obj, ensure_ascii=False, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


_LEFT = ' class="l"'
_TEXT_COLUMNS = ("from → to", "mode", "start point", "tacks/gybes sailed : optimal",
                 "side sailed / optimal", "boat", "note", "notes")
"""Table columns aligned left (text); the others are numbers, aligned right."""


def _table_html(t: Table) -> str:
    left = {i for i, h in enumerate(t.headers) if h in _TEXT_COLUMNS}

    def cells(row: Sequence[str], tag: str) -> str:
        return "".join(f"<{tag}{_LEFT if i in left else ''}>{_h(c)}</{tag}>"
                       for i, c in enumerate(row))

    body = "\n".join(f"<tr>{cells(r, 'td')}</tr>" for r in t.rows)
    foot = "\n".join(f"<tr>{cells(r, 'td')}</tr>" for r in t.footer)
    table = (f"<table>\n<thead><tr>{cells(t.headers, 'th')}</tr></thead>\n<tbody>\n{body}\n"
             f"</tbody>\n" + (f"<tfoot>\n{foot}\n</tfoot>\n" if foot else "") + "</table>")
    table = f'<div class="table">\n{table}\n</div>'
    if t.collapsed:
        return f"<details><summary>{_h(t.caption)}</summary>\n{table}\n</details>"
    return f"<h2>{_h(t.caption)}</h2>\n{table}"


def map_height(report: Report) -> int:
    """Height of the plot [px]: the course area's shape on a plot about 1000 px wide, plus
    the legend and slider, within 480 .. 1100 px."""
    x0, x1, y0, y1 = course_area(report.course, report.routes)
    return int(np.clip(round(950 * (y1 - y0) / (x1 - x0)) + 230, 480, 1100))


def render_html(report: Report, plotly_source: str) -> str:
    """The whole page as a string.

    Parameters
    ----------
    report : Report
        What to show.
    plotly_source : str
        The plotly.js bundle, inlined as is (:func:`plotly_js`); tests may pass a stub.

    Returns
    -------
    str
        A complete HTML document that needs no network.
    """
    fig = figure(report)
    notes = "\n".join(f'<p class="note">{_h(n)}</p>' for n in report.notes)
    summary = "\n".join(f'<p class="summary">{_h(s)}</p>' for s in report.summary)
    tables = "\n".join(_table_html(t) for t in report.tables)
    js = _JS % {"fig": FIGURE_ID, "div": DIV_ID}
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="generator" content="sailroute {_h(__version__)}">
<title>{_h(report.title)}</title>
<style>{_CSS}</style>
<script>{plotly_source}</script>
</head>
<body>
<h1>{_h(report.title)}</h1>
{summary}
<div id="sailroute-error"></div>
<div id="{DIV_ID}" style="height: {map_height(report)}px"></div>
{notes}
{tables}
<footer>Written by sailroute {_h(__version__)}; drawing: plotly.js (MIT licence),
inlined.</footer>
<script type="application/json" id="{FIGURE_ID}">{_json_for_script(fig)}</script>
<script>{js}</script>
</body>
</html>
"""


def read_figure(page: str) -> dict[str, Any]:
    """The figure JSON embedded in a page written by :func:`render_html`."""
    m = re.search(rf'<script type="application/json" id="{FIGURE_ID}">(.*?)</script>', page,
                  flags=re.S)
    if m is None:
        raise ValueError(f"no <script id={FIGURE_ID!r}> in the page")
    return json.loads(m.group(1))


def plotly_js() -> str:
    """The plotly.js bundle shipped with the ``plotly`` Python package (imported here only)."""
    from plotly.offline import get_plotlyjs

    return get_plotlyjs()


def write_report(path: str | Path, report: Report) -> Path:
    """Write ``report`` as a self-contained HTML page to ``path``; returns the path."""
    p = Path(path)
    p.write_text(render_html(report, plotly_js()), encoding="utf-8")
    return p


__all__ = ["Report", "Route", "Table", "WindLayer", "analysis_report", "comparison_report",
           "figure", "plan_report", "plotly_js", "read_figure", "render_html", "write_report"]
