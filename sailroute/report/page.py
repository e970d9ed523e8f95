"""What ``report.html`` shows: routes, wind layers, tables, times, and their look.

:class:`Report` is the page's content (made by the builders of
:mod:`sailroute.report.html`), :class:`Route` one drawn route with its hover columns,
:class:`WindLayer` a scenario's wind sampled on a grid at the slider's times,
:class:`Table` a table under the map.  The figure is :mod:`sailroute.report.page_figure`,
the HTML :mod:`sailroute.report.page_render`.  Times are the course's local time and UTC;
speeds in knots, angles in degrees.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sailroute.course.geometry import feature_centre
from sailroute.course.model import Course
from sailroute.errors import OutOfCoverageError
from sailroute.planning.result import Plan
from sailroute.report.area import fit_area
from sailroute.report.chart import Chart, fit_chart
from sailroute.report.plots import repeat_index_of_ends
from sailroute.timeutil import iso, offset_text
from sailroute.units import KNOT, wind_speed_direction, wrap180
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
"""Map background colour (plain water)."""
BOAT_COLOUR = "#e41a1c"
"""The boat marker of a single route (a comparison's boats take their route's colour)."""
ROUTE_COLOURS = (
    "#1f77b4",
    "#d62728",
    "#2ca02c",
    "#9467bd",
    "#ff7f0e",
    "#8c564b",
    "#e377c2",
    "#17becf",
    "#bcbd22",
    "#7f7f7f",
)
"""Route colours in scenario order (plotly's default palette)."""
WIND_COLOUR = "#41607d"
"""Colour of the wind arrows (a comparison's layers take their scenario's route colour)."""
REPEAT_SHIFT = 0.015
"""Sideways shift of a leg over the same water as an earlier one, per repeat, as a share
of the longest leg (start to end): about 20-30 m on a dinghy course, 8-12 px at the
page's first zoom (``route.png`` shifts such legs by 4 pt)."""
ARROW_FILL = 0.85
"""Length of the strongest wind's arrow as a share of the grid spacing."""
MAX_ROUTE_POINTS = 4000
"""A sailed track is drawn with at most this many points (every k-th fix, each leg's first
and last kept): a 3-hour 10 Hz log would otherwise make a page of 100 MB that no browser
draws; the hover text is at the drawn points."""
FLEET_POINTS = 40_000
"""Points of all the boats' tracks on a fleet's page together, shared equally by the boats
(each at most :data:`MAX_ROUTE_POINTS`, at least :data:`MIN_BOAT_POINTS`): 60 boats of
45 min at 1 Hz are drawn every 4 s, and the page stays about 6 MB."""
MIN_BOAT_POINTS = 300
"""Fewest points of one boat's track on a fleet's page (a very large fleet)."""
FLEET_STEPS = 60
"""Slider positions of a fleet's replay."""
LEG_COLOURS = ROUTE_COLOURS[:8]
"""Colours of the legs of an analysis (sailed; the optimal legs in a lighter shade)."""


def lighter(colour: str, share: float = 0.55) -> str:
    """``colour`` (``#rrggbb``) mixed with ``share`` of white."""
    rgb = [int(colour[i : i + 2], 16) for i in (1, 3, 5)]
    return "#" + "".join(f"{round(c + share * (255 - c)):02x}" for c in rgb)


GREY = "#a9b4bf"
"""Colour of the boats that are not picked when the reader picks one on a fleet's page."""


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
    colour : str
        Line colour (``#rrggbb``); empty: the page's palette in route order
        (:data:`ROUTE_COLOURS`).
    leg_colours : tuple of str
        A colour per leg (``#rrggbb``, by leg number − 1): the line is drawn leg by leg,
        each in its colour (an analysis: the sailed legs, the optimal ones lighter).
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
    colour: str = ""
    leg_colours: tuple[str, ...] = ()

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
    keys : tuple of tuple of (float or None)
        With ``rows``, one per cell: the number a click on the column's header sorts by
        (a time in seconds for ``4:12.0``); None where the cell is text or unknown.
        Empty: the table is not sortable.  Unknown cells of a numeric column sort last
        both ways.
    boats : tuple of int
        With ``rows``, one per row: the index of the boat (route) the row is about, among
        the routes that carry a boat marker; a click on the row picks that boat
        (:attr:`Report.pick`).  Empty: rows pick nothing.
    swatches : tuple of str
        With ``rows``, one per row: a colour (``#rrggbb``) shown as a dot before the
        first cell (the boat's colour on the map).
    name : str
        ``id`` of the ``<table>`` (letters, digits and ``-``); empty: none.
    """

    caption: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    footer: tuple[tuple[str, ...], ...] = ()
    collapsed: bool = False
    keys: tuple[tuple[float | None, ...], ...] = ()
    boats: tuple[int, ...] = ()
    swatches: tuple[str, ...] = ()
    name: str = ""


@dataclass(frozen=True)
class NoteGroup:
    """One finding shared by several boats, shown once and folded (a ``<details>`` block).

    Attributes
    ----------
    summary : str
        The line shown folded: the finding and how many boats, which.
    items : tuple of str
        The lines shown unfolded (each boat's own wording); empty when the summary says
        it all.
    """

    summary: str
    items: tuple[str, ...] = ()


@dataclass(frozen=True, eq=False)
class Report:
    """Everything the page shows.

    Attributes
    ----------
    title : str
    summary : tuple of str
        Lines under the title.
    banner : tuple of str
        Lines above the summary, set apart: what changes how the whole page reads (the
        course's polar beaten on most legs: the losses are its error).
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
    folded : tuple of NoteGroup
        Findings shared by several boats, under the notes, folded.
    chart : Chart or None
        The land under the map (:func:`sailroute.report.chart.chart_for`); None: none.
    pick : bool
        A fleet: the reader picks a boat (a list above the map, a click on its track or
        on its row, ``#boat=NAME`` in the address) and the others turn grey; tacks and
        gybes are drawn for the picked boat only and the course over the tracks.
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
    folded: tuple[NoteGroup, ...] = ()
    pick: bool = False
    chart: Chart | None = None
    banner: tuple[str, ...] = ()


def clock(t: float, utc_offset_s: float = 0.0) -> str:
    """``HH:MM:SS`` of epoch seconds ``t`` in the zone ``utc_offset_s`` [s] from UTC."""
    return iso(float(t) + utc_offset_s)[11:19]


def clocks(t: NDArray, utc_offset_s: float = 0.0) -> list[str]:
    """:func:`clock` of every element of ``t`` (``""`` where ``t`` is not finite)."""
    us = np.round((np.asarray(t, dtype=float) + utc_offset_s) * 1e6)
    ok = np.isfinite(us)
    text = np.datetime_as_string(
        np.where(ok, us, 0.0).astype(np.int64).astype("datetime64[us]"), unit="s"
    )
    return [str(s)[11:19] if good else "" for s, good in zip(text, ok.tolist(), strict=True)]


def time_label(t: float, utc_offset_s: float) -> str:
    """``12:10:00 local (UTC+02:00) · 10:10:00 UTC``: a time for the page."""
    return f"{clock(t, utc_offset_s)} local ({offset_text(utc_offset_s)}) · {clock(t)} UTC"


def leg_vmg(
    mode: str,
    speed: NDArray,
    twa_deg: NDArray,
    sog: NDArray,
    cog_deg: NDArray,
    x: NDArray,
    y: NDArray,
    centre: tuple[float, float],
) -> NDArray[np.float64]:
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
    vmg = leg_vmg(
        mode, tr.bsp_ms, tr.twa_deg, tr.ground_speed_ms, tr.ground_course_deg, tr.x, tr.y, centre
    )
    return {
        "t": tr.t,
        "x": tr.x,
        "y": tr.y,
        "leg": np.full(tr.t.size, k + 1),
        "tws": tr.tws_ms / KNOT,
        "twa": tr.twa_deg,
        "speed": tr.bsp_ms / KNOT,
        "vmg": vmg / KNOT,
    }


def _repeat_shifts(parts: Sequence[Mapping[str, NDArray]]) -> list[tuple[float, float]]:
    """Sideways shift ``(dx, dy)`` [m] of each leg: 0 for a first passage, then
    :data:`REPEAT_SHIFT` of the longest leg per earlier leg over the same water, to the
    right of the direction of travel (as on ``route.png``)."""
    ends = []
    for p in parts:
        ok = np.isfinite(p["x"]) & np.isfinite(p["y"])
        xs, ys = np.asarray(p["x"])[ok], np.asarray(p["y"])[ok]
        ends.append(
            ((float(xs[0]), float(ys[0])), (float(xs[-1]), float(ys[-1])))
            if xs.size
            else ((math.nan, math.nan), (math.nan, math.nan))
        )
    chords = [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in ends]
    step = REPEAT_SHIFT * max((c for c in chords if math.isfinite(c)), default=0.0)
    out = []
    for (a, b), c, rep in zip(ends, chords, repeat_index_of_ends(ends), strict=True):
        if rep == 0 or not c > 0:
            out.append((0.0, 0.0))
            continue
        out.append((step * rep * (b[1] - a[1]) / c, -step * rep * (b[0] - a[0]) / c))
    return out


def _route(
    name: str,
    course: Course,
    parts: Sequence[Mapping[str, NDArray]],
    modes: Sequence[str],
    manoeuvres: Sequence[tuple[str, float, float, float]],
    *,
    gaps: bool = False,
    side_by_side: bool = False,
    **kw: Any,
) -> Route:
    """Join per-leg columns into a :class:`Route` (a NaN row between legs with ``gaps``;
    legs over the same water drawn beside each other with ``side_by_side``)."""
    cols: dict[str, list[NDArray]] = {
        k: [] for k in ("t", "x", "y", "leg", "tws", "twa", "speed", "vmg")
    }
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
        kw = {
            **kw,
            "lat_shift": np.asarray(dlat, float) - lat,
            "lon_shift": np.asarray(dlon, float) - lon,
        }
    man = []
    for kind, t, x, y in manoeuvres:
        # drawn on its leg's line: the leg whose time span holds it
        j = next((i for i, p in enumerate(parts) if p["t"][0] <= t <= p["t"][-1]), None)
        dx, dy = shifts[j] if shifts and j is not None else (0.0, 0.0)
        mlat, mlon = course.frame.to_latlon(x + dx, y + dy)
        man.append((kind, float(t), float(mlat), float(mlon)))
    return Route(
        name,
        c["t"].astype(float),
        c["x"],
        c["y"],
        lat,
        lon,
        c["leg"].astype(np.int64),
        c["tws"],
        c["twa"],
        c["speed"],
        c["vmg"],
        tuple(modes),
        tuple(man),
        **kw,
    )


def route_from_plan(plan: Plan, name: str | None = None) -> Route:
    """The :class:`Route` of a routed course (boat speed through the water)."""
    modes = [pl.mode or "reach" for pl in plan.legs]
    parts = [
        _leg_columns(plan.course, pl.spec.index, pl.result, modes[k])
        for k, pl in enumerate(plan.legs)
    ]
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
    cut = {
        f: getattr(r, f)[keep]
        for f in ("t", "x", "y", "lat", "lon", "leg", "tws_kn", "twa_deg", "speed_kn", "vmg_kn")
    }
    if r.lat_shift is not None and r.lon_shift is not None:
        cut["lat_shift"], cut["lon_shift"] = r.lat_shift[keep], r.lon_shift[keep]
    return replace(r, **cut)


def routes_from_analysis(a: TrackAnalysis) -> tuple[Route, Route]:
    """The sailed track (speed over the ground; at most :data:`MAX_ROUTE_POINTS` points)
    and the optimal legs from its leg starts (legs of unknown start left out)."""
    return sailed_route(a), optimal_route(a)


def sailed_route(a: TrackAnalysis, max_points: int = MAX_ROUTE_POINTS) -> Route:
    """The sailed track of ``a`` (speed over the ground), at most about ``max_points``
    points (:func:`decimated`), its tacks and gybes."""
    p = a.points
    modes = [leg.mode for leg in a.legs]
    sailed_parts = [
        {
            "t": p.t,
            "x": p.x,
            "y": p.y,
            "leg": p.leg,
            "tws": p.tws_ms / KNOT,
            "twa": p.twa_deg,
            "speed": p.sog_ms / KNOT,
            "vmg": p.vmg_ms / KNOT,
        }
    ]
    man = []
    for m in (m for leg in a.legs for m in leg.manoeuvres):
        man.append((m.kind, m.t, float(np.interp(m.t, p.t, p.x)), float(np.interp(m.t, p.t, p.y))))
    return decimated(
        _route(f"sailed: {a.track.name}", a.course, sailed_parts, modes, man, speed_name="SOG"),
        max_points,
    )


def optimal_route(a: TrackAnalysis) -> Route:
    """The optimal legs of ``a`` from its own leg starts (legs of unknown start left out),
    dashed, without a boat marker."""
    course = a.course
    opt_parts = [
        _leg_columns(course, leg.index, leg.optimal, leg.mode)
        for leg in a.legs
        if leg.optimal is not None
    ]
    opt_man = [
        (m.kind, m.t, m.x, m.y)
        for leg in a.legs
        if leg.optimal is not None
        for m in leg.optimal.manoeuvres
    ]
    return _route(
        "optimal from the boat's leg starts",
        course,
        opt_parts,
        [leg.mode for leg in a.legs],
        opt_man,
        gaps=True,
        dash="dash",
        boat=False,
    )


def course_area(
    course: Course, routes: Sequence[Route], pad: float = 0.08
) -> tuple[float, float, float, float]:
    """``(x0, x1, y0, y1)`` [m]: the marks and routes, and the race area and the chart
    file's shore within reach of them (:func:`sailroute.report.area.fit_area`,
    :func:`sailroute.report.chart.fit_chart`), padded by ``pad`` of the larger side."""
    xs = [m.x for m in course.marks.values()]
    ys = [m.y for m in course.marks.values()]
    for r in routes:
        if np.isfinite(r.x).any():
            xs += [float(np.nanmin(r.x)), float(np.nanmax(r.x))]
            ys += [float(np.nanmin(r.y)), float(np.nanmax(r.y))]
    box = (min(xs), max(xs), min(ys), max(ys))
    x0, x1, y0, y1 = fit_chart(course, fit_area(course.area, box))
    span = max(x1 - x0, y1 - y0, 100.0)
    return x0 - pad * span, x1 + pad * span, y0 - pad * span, y1 + pad * span


def wind_layer(
    name: str,
    wind: WindField,
    course: Course,
    area: tuple[float, float, float, float],
    times: NDArray,
    grid: int = WIND_GRID,
) -> WindLayer | None:
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
    if np.allclose(spd, spd[:1], atol=1e-9, equal_nan=True) and np.allclose(
        twd, twd[:1], atol=1e-9, equal_nan=True
    ):
        spd, twd = spd[:1], twd[:1]
    lat, lon = course.frame.to_latlon(gx, gy)
    spacing = min(x1 - x0, y1 - y0) / grid
    return WindLayer(
        name, gx, gy, np.asarray(lat, float), np.asarray(lon, float), spacing, spd / KNOT, twd
    )


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
