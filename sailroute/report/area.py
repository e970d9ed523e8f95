"""The race area (``boundary``, ``obstacles``) in the plan's outputs: JSON and drawings.

Pure writers of a course's :class:`~sailroute.routing.obstacles.RaceArea`: the ``area``
object of ``plan.json``, the polygons on ``route.png`` (matplotlib; those of ``report.html`` are
:func:`sailroute.report.page_figure.area_traces`), and the rule by which the maps' extent takes
them in (:func:`fit_area`).  Formats: ``docs/output-format.md``.

Drawing conventions: the boundary is a dark red line, each obstacle a light sand-coloured
fill with a darker outline; where a polygon has a clearance, the line the routes keep to
(the obstacle grown, the boundary shrunk by ``clearance_m``) is dashed in the same colour.
All of it lies under the routes.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.geo import LocalFrame
from sailroute.routing.obstacles import QUAD_SEGS, AreaPolygon, RaceArea

__all__ = [
    "AREA_REACH",
    "BOUNDARY_COLOUR",
    "OBSTACLE_EDGE",
    "OBSTACLE_FILL",
    "area_polygons",
    "area_to_dict",
    "draw_area",
    "fit_area",
    "kept_ring",
]

BOUNDARY_COLOUR = "#a50f15"
"""Colour of the race-area boundary on both maps."""
OBSTACLE_FILL = "#e8d9b5"
"""Fill of the obstacles on both maps (light sand)."""
OBSTACLE_EDGE = "#8c6d31"
"""Outline of the obstacles and of their clearance on both maps."""
AREA_REACH = 0.5
"""How far the maps' extent reaches out to take in the race area, as a fraction of the
course's span (the larger side of the box round the marks and routes): a polygon within
that of the course is shown whole; a larger one (a boundary kilometres round a small
course) is cut at it."""


def _num(x: float, nd: int) -> float | None:
    """Round for JSON; non-finite values become null."""
    return round(float(x), nd) if math.isfinite(float(x)) else None


def kept_ring(
    p: AreaPolygon, *, boundary: bool = False
) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """The closed line the routes keep to [m]: the obstacle grown or (``boundary``) the
    boundary shrunk by its clearance (the outer ring of the largest part); None without a
    clearance."""
    import shapely

    if p.clearance_m <= 0:
        return None
    grow = -p.clearance_m if boundary else p.clearance_m
    g = shapely.buffer(p.polygon(), grow, quad_segs=QUAD_SEGS)
    parts = [q for q in shapely.get_parts(g) if not q.is_empty]
    if not parts:
        return None
    big = max(parts, key=lambda q: q.area)
    xy = shapely.get_coordinates(shapely.get_exterior_ring(big))
    return xy[:, 0], xy[:, 1]


def area_polygons(area: RaceArea) -> list[AreaPolygon]:
    """The boundary (when there is one), then the obstacles in order."""
    return [*([area.boundary] if area.boundary is not None else []), *area.obstacles]


# --- plan.json --------------------------------------------------------------------------


def _polygon_dict(p: AreaPolygon, frame: LocalFrame) -> dict[str, Any]:
    lat, lon = frame.to_latlon(np.asarray(p.x), np.asarray(p.y))
    return {
        "name": p.name,
        "clearance_m": _num(p.clearance_m, 3),
        "points": [
            {"x": _num(x, 3), "y": _num(y, 3), "lat": _num(a, 7), "lon": _num(o, 7)}
            for x, y, a, o in zip(p.x, p.y, np.atleast_1d(lat), np.atleast_1d(lon), strict=True)
        ],
    }


def area_to_dict(area: RaceArea, frame: LocalFrame) -> dict[str, Any] | None:
    """The ``area`` object of ``plan.json``; None when the course has neither a
    boundary nor obstacles (``plan.json`` then has no ``area`` key).

    Returns
    -------
    dict or None
        ``boundary`` (a polygon or null), ``obstacles`` (a list of polygons, in the
        course file's order) and ``wind_land_is_obstacle``; a polygon is ``name``,
        ``clearance_m`` [m] and ``points``, its ring ``{x, y, lat, lon}`` [m, °] in order,
        the first point not repeated.
    """
    if area.boundary is None and not area.obstacles:
        return None
    return {
        "boundary": None if area.boundary is None else _polygon_dict(area.boundary, frame),
        "obstacles": [_polygon_dict(p, frame) for p in area.obstacles],
        "wind_land_is_obstacle": area.wind_land_is_obstacle,
    }


# --- extent ------------------------------------------------------------------------------


def fit_area(
    area: RaceArea, box: tuple[float, float, float, float], reach: float = AREA_REACH
) -> tuple[float, float, float, float]:
    """``box`` = ``(x0, x1, y0, y1)`` [m] (the marks and routes) grown to take in the
    race area's polygons (obstacles with their clearance), but by at most ``reach``
    times the box's larger side (at least 100 m) on each side: an obstacle near the
    course is shown whole, a boundary far round it does not shrink the course to a dot.
    """
    polys = area_polygons(area)
    if not polys:
        return box
    x0, x1, y0, y1 = box
    span = max(x1 - x0, y1 - y0, 100.0)
    xs = [x0, x1]
    ys = [y0, y1]
    for p in polys:
        xs += [min(p.x), max(p.x)]
        ys += [min(p.y), max(p.y)]
        ring = kept_ring(p) if p is not area.boundary else None  # a boundary shrinks
        if ring is not None:
            xs += [float(ring[0].min()), float(ring[0].max())]
            ys += [float(ring[1].min()), float(ring[1].max())]
    lim = reach * span
    return (
        max(min(xs), x0 - lim),
        min(max(xs), x1 + lim),
        max(min(ys), y0 - lim),
        min(max(ys), y1 + lim),
    )


# --- route.png ---------------------------------------------------------------------------


def draw_area(ax: Any, area: RaceArea) -> None:
    """The boundary (line) and obstacles (filled) on a matplotlib map, under the routes.

    Artists carry gids ``boundary``, ``boundary-clearance``, ``obstacle:<name>`` (a
    ``Polygon`` patch) and ``obstacle-clearance:<name>``; the first obstacle and the
    boundary have a legend label, and one grey dashed entry stands for the clearances.
    """
    from matplotlib.patches import Polygon

    clear_label = True
    for k, p in enumerate(area.obstacles):
        patch = Polygon(
            np.column_stack([p.x, p.y]),
            closed=True,
            facecolor=OBSTACLE_FILL,
            edgecolor=OBSTACLE_EDGE,
            lw=0.8,
            zorder=1.5,
            label="obstacles" if k == 0 else None,
        )
        patch.set_gid(f"obstacle:{p.name}")
        ax.add_patch(patch)
    for p in area_polygons(area):
        outer = p is area.boundary
        ring = kept_ring(p, boundary=outer)
        if ring is None:
            continue
        gid = "boundary-clearance" if outer else f"obstacle-clearance:{p.name}"
        ax.plot(
            *ring,
            linestyle=(0, (3, 2)),
            color=BOUNDARY_COLOUR if outer else OBSTACLE_EDGE,
            lw=0.8,
            zorder=1.6,
            gid=gid,
        )
        if clear_label:  # one legend entry, in neutral grey (the lines take their polygon's)
            ax.plot([], [], linestyle=(0, (3, 2)), color="0.4", lw=0.8, label="clearance kept")
            clear_label = False
    b = area.boundary
    if b is not None:
        ax.plot(
            [*b.x, b.x[0]],
            [*b.y, b.y[0]],
            "-",
            color=BOUNDARY_COLOUR,
            lw=1.4,
            zorder=1.7,
            gid="boundary",
            label="race-area boundary",
        )
