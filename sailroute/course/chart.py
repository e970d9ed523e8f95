"""The ``chart`` key of a course file: a coastline or land file drawn under the maps.

``chart: coast.geojson`` (relative to the course file) names a GeoJSON or KML file of
land polygons (``Polygon``, ``MultiPolygon``; KML ``Polygon``) and shorelines
(``LineString``, ``MultiLineString``; KML ``LineString``), in longitude/latitude degrees
(WGS-84), anywhere in its features, folders or geometry collections.  The maps of
``report.html`` and ``route.png`` draw it as land under the course
(:mod:`sailroute.report.chart`); routing does not use it (give land the routes must avoid
as ``obstacles``).  Shapefiles are not read: GDAL's ``ogr2ogr -f GeoJSON out.geojson
in.shp`` or QGIS's "Save Features As" turns one into GeoJSON.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.checks import Checker, show

__all__ = ["CHART_SUFFIXES", "ChartFile", "check_chart", "read_chart"]

CHART_SUFFIXES = (".geojson", ".json", ".kml")
"""File name endings of a chart file."""


@dataclass(frozen=True, eq=False)
class ChartFile:
    """A course's chart: land polygons and shorelines in longitude/latitude.

    Attributes
    ----------
    path : Path
        The file.
    land : tuple of ndarray, shape (n, 2)
        The outer ring of each land polygon, ``(lon, lat)`` [°] per row.
    lines : tuple of ndarray, shape (n, 2)
        Each shoreline, ``(lon, lat)`` [°] per row.
    """

    path: Path
    land: tuple[NDArray[np.float64], ...]
    lines: tuple[NDArray[np.float64], ...]

    @property
    def name(self) -> str:
        """The file's name, for legends and notes."""
        return self.path.name


def _lonlat(coords: Any, where: str) -> NDArray[np.float64]:
    """``[[lon, lat(, alt)], ...]`` as an ``(n, 2)`` array, checked to be degrees."""
    try:
        a = np.array([[float(p[0]), float(p[1])] for p in coords], dtype=float)
    except (TypeError, ValueError, IndexError):
        raise ValueError(f"{where}: expected [[lon, lat], ...] coordinates") from None
    if a.size == 0:
        return a.reshape(0, 2)
    if not (np.isfinite(a).all() and np.abs(a[:, 1]).max() <= 90 and np.abs(a[:, 0]).max() <= 360):
        raise ValueError(f"{where}: coordinates are not longitude/latitude degrees")
    return a


def _geojson(doc: Any) -> Iterator[tuple[str, NDArray[np.float64]]]:
    """``("land" | "line", ring or line)`` of every geometry of a GeoJSON document."""
    if not isinstance(doc, Mapping):
        return
    kind, coords = doc.get("type"), doc.get("coordinates")
    if kind == "FeatureCollection":
        for f in doc.get("features") or []:
            yield from _geojson(f)
    elif kind == "Feature":
        yield from _geojson(doc.get("geometry"))
    elif kind == "GeometryCollection":
        for g in doc.get("geometries") or []:
            yield from _geojson(g)
    elif kind == "Polygon" and coords:
        yield "land", _lonlat(coords[0], "a Polygon")
    elif kind == "MultiPolygon" and coords:
        for poly in coords:
            if poly:
                yield "land", _lonlat(poly[0], "a MultiPolygon")
    elif kind == "LineString" and coords:
        yield "line", _lonlat(coords, "a LineString")
    elif kind == "MultiLineString" and coords:
        for line in coords:
            yield "line", _lonlat(line, "a MultiLineString")


def _kml(root: ET.Element) -> Iterator[tuple[str, NDArray[np.float64]]]:
    """``("land" | "line", ...)`` of every KML Polygon's outer ring and LineString."""

    def tag(el: ET.Element) -> str:
        return el.tag.rsplit("}", 1)[-1]

    def coords(el: ET.Element, what: str) -> NDArray[np.float64]:
        text = " ".join(c.text or "" for c in el.iter() if tag(c) == "coordinates")
        return _lonlat([t.split(",") for t in text.split()], what)

    for el in root.iter():
        if tag(el) == "outerBoundaryIs":
            yield "land", coords(el, "a KML Polygon")
        elif tag(el) == "LineString":
            yield "line", coords(el, "a KML LineString")


def read_chart(path: str | Path) -> ChartFile:
    """Read a chart file (GeoJSON or KML).

    Raises
    ------
    ValueError
        With a one-line reason: unreadable, a shapefile, not GeoJSON/KML, bad
        coordinates, or no polygon or line in it.
    """
    p = Path(path)
    if p.suffix.lower() in (".shp", ".shx", ".dbf"):
        raise ValueError(
            f"{p.name}: shapefiles are not read; convert it to GeoJSON (ogr2ogr -f GeoJSON "
            f"{p.stem}.geojson {p.name}, or QGIS: Save Features As, GeoJSON)"
        )
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"cannot read {p}: {exc.__class__.__name__}: {exc}") from None
    if p.suffix.lower() == ".kml" or text.lstrip().startswith("<"):
        try:
            parts = list(_kml(ET.fromstring(text)))
        except ET.ParseError as exc:
            raise ValueError(f"{p.name} is not KML (XML error: {exc})") from None
    else:
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as exc:
            raise ValueError(f"{p.name} is not GeoJSON (line {exc.lineno}: {exc.msg})") from None
        parts = list(_geojson(doc))
    land = tuple(a for kind, a in parts if kind == "land" and len(a) >= 3)
    lines = tuple(a for kind, a in parts if kind == "line" and len(a) >= 2)
    if not land and not lines:
        raise ValueError(
            f"{p.name}: no land polygon or shoreline in it; expected GeoJSON (Multi)Polygon "
            "or (Multi)LineString geometries, or KML Polygons or LineStrings"
        )
    return ChartFile(p, land, lines)


def check_chart(c: Checker, data: Mapping[str, Any]) -> ChartFile | None:
    """The course file's ``chart`` (None when absent or after recording a problem)."""
    if data.get("chart") is None:
        return None
    raw = data["chart"]
    if not isinstance(raw, str) or Path(raw).suffix.lower() not in (*CHART_SUFFIXES, ".shp"):
        c.add(
            "chart",
            f"expected the path of a GeoJSON (.geojson) or KML (.kml) file of the coast or "
            f"land; got {show(raw)}",
        )
        return None
    full = c.file(data, "chart", Path(c.p.file).parent)
    if full is None:
        return None
    try:
        return read_chart(full)
    except ValueError as exc:
        c.add("chart", str(exc))
        return None
