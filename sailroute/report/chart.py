"""The chart under the maps: land from the course's chart file, GSHHG or the wind's land mask.

Sources, in the order the maps prefer them (the first one present is shown; the others
are drawn too but start hidden, a click on their legend entry shows them):

1. the course's ``chart`` file (:mod:`sailroute.course.chart`): a coast the user chose;
2. GSHHG's full-resolution land (:mod:`sailroute.report.gshhg`), when the optional extra
   ``coast`` is installed;
3. the land mask of the wind file (:mod:`sailroute.wind.landmask`): WRF's ``LANDMASK``,
   or the NaN cells of a gridded wind, as the grid's cells (about 1 km on a dinghy
   course's WRF run: coarse).

The race area's boundary and obstacles are drawn by :mod:`sailroute.report.area`; OSM
tiles, when the browser is online, by the page's script (:mod:`sailroute.report.page_render`).
Everything is clipped to a box round the course (:data:`CHART_REACH`), so a zoomed-out
page shows the shore near the course without carrying a whole coastline.
:meth:`Chart.note` says what the map shows and what it lacks.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from sailroute.course.model import Course
from sailroute.geo import LocalFrame

__all__ = [
    "CHART_REACH",
    "LAND_EDGE",
    "LAND_FILL",
    "Chart",
    "LandLayer",
    "chart_for",
    "draw_chart",
    "fit_chart",
    "in_view",
]

LAND_FILL = "#eeeadf"
"""Fill of the land on both maps (the light beige of paper charts)."""
LAND_EDGE = "#8a8272"
"""Outline of the land and colour of the shorelines."""
CHART_REACH = 2.0
"""The chart is kept this many times the map's larger side beyond the map (at least
:data:`MIN_REACH_M`) on each side."""
MIN_REACH_M = 3000.0
"""Least reach of the chart beyond the map [m]."""


@dataclass(frozen=True, eq=False)
class LandLayer:
    """One source of land on the map.

    Attributes
    ----------
    name : str
        Legend text (``"land: coast.geojson"``).
    rings : tuple of ndarray, shape (n, 2)
        The outer ring of each land polygon, closed, in the course frame [m].
    lines : tuple of ndarray, shape (n, 2)
        Shorelines (open lines) in the course frame [m].
    shown : bool
        Drawn at first (else hidden until the reader shows it).
    """

    name: str
    rings: tuple[NDArray[np.float64], ...]
    lines: tuple[NDArray[np.float64], ...] = ()
    shown: bool = True


@dataclass(frozen=True, eq=False)
class Chart:
    """The land layers of a map and what it lacks.

    Attributes
    ----------
    layers : tuple of LandLayer
        In the order of preference (the first one shown).
    missing : tuple of str
        The offline sources that are not there, with how to add them.
    """

    layers: tuple[LandLayer, ...] = ()
    missing: tuple[str, ...] = ()

    def note(self, *, tiles: bool = False) -> str:
        """One line for the page: what land is drawn, and what is missing.

        ``tiles``: the page may add OSM tiles when online (its script says whether it did).
        """
        if self.layers:
            parts = [
                layer.name.removeprefix("land: ") + ("" if layer.shown else " (hidden)")
                for layer in self.layers
            ]
            text = "Chart: land from " + "; ".join(parts) + "."
        else:
            text = "Chart: no land drawn (plain water)."
        if self.missing:
            text += " Not available offline: " + "; ".join(self.missing) + "."
        if tiles:
            text += " OSM tiles: only when the browser is online."
        return text


@lru_cache(maxsize=8)
def _chart_land(course: Course) -> Any:
    """The land of the course's chart file in its frame (None without one)."""
    if course.chart is None or not course.chart.land:
        return None
    land = shapely.union_all([shapely.make_valid(shapely.Polygon(r)) for r in course.chart.land])
    return _to_frame(course.frame, land)


def fit_chart(
    course: Course, box: tuple[float, float, float, float], reach: float = 0.5
) -> tuple[float, float, float, float]:
    """``box`` = ``(x0, x1, y0, y1)`` [m] grown to show the shore of the course's chart
    file when it lies within ``reach`` times the box's larger side (as the race area's
    polygons are taken in: :func:`sailroute.report.area.fit_area`): the box reaches past
    the nearest land by 15 % of that side, no farther."""
    land = _chart_land(course)
    if land is None:
        return box
    x0, x1, y0, y1 = box
    span = max(x1 - x0, y1 - y0, 100.0)
    gap = float(shapely.distance(shapely.box(x0, y0, x1, y1), land))
    if gap > reach * span:
        return box
    grow = gap + 0.15 * span
    near = shapely.clip_by_rect(land, x0 - grow, y0 - grow, x1 + grow, y1 + grow)
    if near.is_empty:
        return box
    bx0, by0, bx1, by1 = near.bounds
    return min(x0, bx0), max(x1, bx1), min(y0, by0), max(y1, by1)


def _clip_box(extent: Sequence[float]) -> tuple[float, float, float, float]:
    x0, x1, y0, y1 = extent
    reach = max(CHART_REACH * max(x1 - x0, y1 - y0), MIN_REACH_M)
    return x0 - reach, x1 + reach, y0 - reach, y1 + reach


def _layer(
    name: str, geom: Any, box: tuple[float, float, float, float], shown: bool
) -> LandLayer | None:
    """The polygons and lines of ``geom`` (course frame) inside ``box``, simplified to a
    2000th of the map; None when nothing is left."""
    x0, x1, y0, y1 = box
    g = shapely.clip_by_rect(geom, x0, y0, x1, y1)
    tol = max((x1 - x0) / 2000.0 / (2 * CHART_REACH + 1), 1.0)
    g = shapely.simplify(g, tol)
    rings, lines = [], []
    for part in shapely.get_parts(g):
        if part.is_empty:
            continue
        if isinstance(part, shapely.Polygon):
            rings.append(shapely.get_coordinates(part.exterior))
        elif isinstance(part, shapely.LineString):
            lines.append(shapely.get_coordinates(part))
        elif isinstance(part, shapely.MultiLineString | shapely.MultiPolygon):
            sub = _layer(name, part, box, shown)
            if sub is not None:
                rings += sub.rings
                lines += sub.lines
    if not rings and not lines:
        return None
    return LandLayer(name, tuple(rings), tuple(lines), shown)


def _to_frame(frame: LocalFrame, geom: Any) -> Any:
    """A lon/lat geometry in the course frame."""

    def xy(coords: NDArray[np.float64]) -> NDArray[np.float64]:
        x, y = frame.to_xy(coords[:, 1], coords[:, 0])
        return np.column_stack([np.asarray(x, float), np.asarray(y, float)])

    return shapely.transform(geom, xy)


def _cells(mask: Any) -> Any:
    """The land cells of a :class:`~sailroute.wind.landmask.LandMask` as one geometry:
    each cell the quadrilateral half-way to its neighbours."""
    x, y, land = mask.x, mask.y, mask.land
    gx = np.gradient(x, axis=1), np.gradient(y, axis=1)  # one cell east
    gy = np.gradient(x, axis=0), np.gradient(y, axis=0)  # one cell north
    j, i = np.nonzero(land)
    if j.size == 0:
        return shapely.Polygon()
    cx, cy = x[j, i], y[j, i]
    ex, ey = 0.5 * gx[0][j, i], 0.5 * gx[1][j, i]
    nx, ny = 0.5 * gy[0][j, i], 0.5 * gy[1][j, i]
    quads = [
        shapely.Polygon(
            [
                (a - e - n, b - f - m),
                (a + e - n, b + f - m),
                (a + e + n, b + f + m),
                (a - e + n, b - f + m),
            ]
        )
        for a, b, e, f, n, m in zip(cx, cy, ex, ey, nx, ny, strict=True)
    ]
    # neighbours' quads meet within rounding: close the seams
    return shapely.union_all(quads).buffer(0.5).buffer(-0.5)


@lru_cache(maxsize=8)
def _gshhg(box: tuple[float, float, float, float]) -> Any:
    from sailroute.report.gshhg import gshhg_land

    return gshhg_land(box)


def chart_for(course: Course, winds: Sequence[Any], extent: Sequence[float]) -> Chart:
    """The land to draw round ``extent`` = ``(x0, x1, y0, y1)`` [m] (the map).

    Parameters
    ----------
    course : Course
        Its ``chart`` file and frame.
    winds : sequence of WindField
        The winds on the page: the first with a land mask gives it.
    extent : sequence of float
        The map's box in the course frame [m].

    Returns
    -------
    Chart
    """
    from sailroute.report.gshhg import GSHHG_NAME, gshhg_files
    from sailroute.wind.landmask import land_mask

    frame = course.frame
    box = _clip_box(extent)
    found: list[tuple[str, Any]] = []
    missing = []
    if course.chart is not None:
        land = [shapely.Polygon(r) for r in course.chart.land]
        lines = [shapely.LineString(r) for r in course.chart.lines]
        geom = shapely.GeometryCollection(
            [shapely.make_valid(shapely.union_all(land)), *lines] if land else lines
        )
        found.append((f"land: {course.chart.name}", _to_frame(frame, geom)))
    else:
        missing.append("a chart file (course key chart: coast.geojson or .kml)")
    if gshhg_files() is not None:
        lat, lon = frame.to_latlon(np.array([box[0], box[1]]), np.array([box[2], box[3]]))
        g = _gshhg(
            (
                round(float(lon[0]), 4),
                round(float(lon[1]), 4),
                round(float(lat[0]), 4),
                round(float(lat[1]), 4),
            )
        )
        if g is not None and not g.is_empty:
            found.append((f"land: {GSHHG_NAME}", _to_frame(frame, g)))
    else:
        missing.append("a world coastline (pip install 'sailroute[coast]': GSHHG)")
    mask = next((m for m in (land_mask(w) for w in winds if w is not None) if m), None)
    if mask is not None and mask.land.any():
        found.append((f"land: {mask.source}", _cells(mask)))
    elif mask is None:
        missing.append("a land mask in the wind data")
    layers: list[LandLayer] = []
    for name, geom in found:
        layer = _layer(name, geom, box, shown=not layers)
        if layer is not None:
            layers.append(layer)
    return Chart(tuple(layers), tuple(missing))


def in_view(layer: LandLayer, extent: Sequence[float]) -> bool:
    """Whether some of ``layer`` lies inside ``extent`` = ``(x0, x1, y0, y1)`` [m]."""
    x0, x1, y0, y1 = extent
    view = shapely.box(x0, y0, x1, y1)
    parts: list[shapely.Geometry] = [shapely.Polygon(r) for r in layer.rings if len(r) >= 4]
    parts += [shapely.LineString(r) for r in layer.lines]
    return any(shapely.intersects(view, shapely.make_valid(p)) for p in parts)


def draw_chart(ax: Any, chart: Chart, extent: Sequence[float]) -> None:
    """The shown land layers on a matplotlib map of ``extent`` = ``(x0, x1, y0, y1)``
    (course frame, metres), under everything else; gids ``land:<k>`` (polygons) and
    ``shore:<k>`` (lines), ``k`` the layer's index; a legend entry only for land in view."""
    from matplotlib.collections import LineCollection, PolyCollection

    for k, layer in enumerate(chart.layers):
        if not layer.shown:
            continue
        label = layer.name if in_view(layer, extent) else None
        if layer.rings:
            pc = PolyCollection(
                [np.asarray(r) for r in layer.rings],
                facecolors=LAND_FILL,
                edgecolors=LAND_EDGE,
                linewidths=0.7,
                zorder=0.5,
                label=label,
            )
            pc.set_gid(f"land:{k}")
            ax.add_collection(pc, autolim=False)
        if layer.lines:
            lc = LineCollection(
                [np.asarray(r) for r in layer.lines],
                colors=LAND_EDGE,
                linewidths=1.0,
                zorder=0.6,
                label=None if layer.rings else label,
            )
            lc.set_gid(f"shore:{k}")
            ax.add_collection(lc, autolim=False)
