"""Check the race-area keys of a course file (``boundary``, ``obstacles``, the land rule).

Part of the check step of :func:`sailroute.course.load.load_course`
(``docs/course-format.md``).  A polygon is a list of ``points`` (each ``{lat, lon}`` or
``{x, y}`` metres like the marks; a ring, the first point not repeated) or a ``file``
(a GeoJSON Polygon, Feature or FeatureCollection with one polygon, or a KML Polygon;
the path relative to the course file).  Every polygon is converted to the course's
local frame and checked: at least 3 points, edges that do not cross, every mark out of
each obstacle grown by its clearance and inside the boundary shrunk by its own.  The
result is a :class:`~sailroute.routing.obstacles.RaceArea`.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from sailroute.checks import Checker, join_path, show
from sailroute.geo import LocalFrame
from sailroute.routing.obstacles import QUAD_SEGS, AreaPolygon, RaceArea, polygon_problem

__all__ = ["AREA_KEYS", "check_area", "read_polygon_file"]

AREA_KEYS = ("boundary", "obstacles", "wind_land_is_obstacle")
"""Top-level keys of the race area."""
POLYGON_KEYS = ("points", "file", "clearance_m")
OBSTACLE_KEYS = ("name", *POLYGON_KEYS)

Position = tuple[str, tuple[float, float]]
PositionReader = Callable[[Checker, Any, str, str], Position | None]
"""The course checker's point reader: ``(checker, value, path, what)`` ->
``("ll", (lat, lon))`` or ``("xy", (x, y))``, or None after recording a problem."""


def read_polygon_file(path: Path) -> list[tuple[float, float]]:
    """The outer ring of the one polygon in a GeoJSON or KML file, as ``(lon, lat)``.

    Raises
    ------
    ValueError
        With a one-line reason (unreadable, not JSON/KML, no polygon, several).
    """
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"cannot read {path}: {exc.__class__.__name__}: {exc}") from None
    if path.suffix.lower() == ".kml" or text.lstrip().startswith("<"):
        return _kml_ring(text, path)
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path} is not GeoJSON (line {exc.lineno}: {exc.msg})") from None
    rings = _geojson_rings(doc)
    if len(rings) != 1:
        raise ValueError(f"{path}: expected exactly one Polygon; found {len(rings)}")
    return rings[0]


def _geojson_rings(doc: Any) -> list[list[tuple[float, float]]]:
    if not isinstance(doc, Mapping):
        return []
    kind = doc.get("type")
    if kind == "FeatureCollection":
        return [r for f in doc.get("features") or [] for r in _geojson_rings(f)]
    if kind == "Feature":
        return _geojson_rings(doc.get("geometry"))
    if kind == "Polygon":
        coords = doc.get("coordinates") or []
        try:
            return [[(float(p[0]), float(p[1])) for p in coords[0]]] if coords else []
        except (TypeError, ValueError, IndexError):
            raise ValueError("a Polygon's coordinates must be [[lon, lat], ...] rings") from None
    return []


def _kml_ring(text: str, path: Path) -> list[tuple[float, float]]:
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ValueError(f"{path} is not KML (XML error: {exc})") from None
    rings = [el for el in root.iter() if el.tag.rsplit("}", 1)[-1] == "outerBoundaryIs"]
    if len(rings) != 1:
        raise ValueError(f"{path}: expected exactly one KML Polygon; found {len(rings)}")
    coords = [el.text or "" for el in rings[0].iter() if el.tag.rsplit("}", 1)[-1] == "coordinates"]
    out = []
    for token in " ".join(coords).split():
        parts = token.split(",")
        try:
            out.append((float(parts[0]), float(parts[1])))
        except (ValueError, IndexError):
            raise ValueError(
                f"{path}: bad KML coordinate {token!r}; expected lon,lat[,alt]"
            ) from None
    return out


def _open_ring(pts: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The ring without its closing point (a file's first point repeated last)."""
    return pts[:-1] if len(pts) > 1 and pts[0] == pts[-1] else pts


def _polygon(
    c: Checker,
    raw: Any,
    path: str,
    name: str,
    frame: LocalFrame,
    has_origin: bool,
    base: Path,
    position: PositionReader,
) -> AreaPolygon | None:
    """One polygon spec (``points`` or ``file``, ``clearance_m``) in the course frame."""
    keys = OBSTACLE_KEYS if path.startswith("obstacles") else POLYGON_KEYS
    if not c.at(path).is_mapping(
        raw,
        "a mapping with `points` (a list of {lat, lon} or "
        "{x, y}) or `file` (GeoJSON or KML), and `clearance_m`",
    ):
        return None
    c.at(path).keys(raw, keys)
    clearance = c.at(path).number(raw, "clearance_m", 0.0, lo=0.0)
    if ("points" in raw) == ("file" in raw):
        c.p.add(
            path,
            "give either `points` (a list of {lat, lon} or {x, y}) or `file` "
            "(a GeoJSON or KML polygon), one of them",
        )
        return None
    xy: list[tuple[float, float]] = []
    if "file" in raw:
        fpath = join_path(path, "file")
        if not isinstance(raw["file"], str) or not raw["file"].strip():
            c.p.add(fpath, f"expected a path to a GeoJSON or KML file; got {show(raw['file'])}")
            return None
        try:
            lonlat = _open_ring(read_polygon_file(base / raw["file"]))
        except ValueError as exc:
            c.p.add(
                fpath,
                f"{exc}; expected a GeoJSON Polygon/Feature or a KML Polygon in lon/lat degrees",
            )
            return None
        if lonlat:
            lon, lat = np.array(lonlat).T
            px, py = frame.to_xy(lat, lon)
            xy = list(
                zip(np.asarray(px, float).tolist(), np.asarray(py, float).tolist(), strict=True)
            )
    else:
        ppath = join_path(path, "points")
        pts = raw["points"]
        if not isinstance(pts, list):
            c.p.add(ppath, f"expected a list of {{lat, lon}} or {{x, y}}; got {show(pts)}")
            return None
        bad = False
        for i, p in enumerate(pts):
            pos = position(c, p, join_path(ppath, i), f"point {i + 1} of {name!r}")
            if pos is None:
                bad = True
            elif pos[0] == "ll":
                x, y = frame.to_xy(*pos[1])
                xy.append((float(x), float(y)))
            elif not has_origin:
                c.p.add(
                    join_path(ppath, i),
                    "points in {x, y} metres need `origin: {lat, "
                    "lon}` at the top level of the course file (the point x = y = 0)",
                )
                bad = True
            else:
                xy.append(pos[1])
        if bad:
            return None
        xy = _open_ring(xy)
    if clearance is None:
        return None
    xs, ys = tuple(p[0] for p in xy), tuple(p[1] for p in xy)
    problem = polygon_problem(xs, ys, clearance, boundary=path == "boundary")
    if problem is not None:
        c.p.add(path, problem)
        return None
    return AreaPolygon(name, xs, ys, clearance, path)


def check_area(
    c: Checker,
    data: Mapping[str, Any],
    frame: LocalFrame | None,
    marks: Mapping[str, tuple[float, float]],
    position: PositionReader,
) -> RaceArea:
    """The race area of a course file (an empty one when it names none).

    Parameters
    ----------
    c : Checker
        The course file's checker (problems recorded, not raised).
    data : mapping
        The course file's top level.
    frame : LocalFrame or None
        The course frame (None after an earlier problem: nothing is converted).
    marks : mapping of str to tuple of float
        Mark name -> ``(x, y)`` [m], to check against the polygons.
    position : callable
        The course checker's point reader (``{lat, lon}`` or ``{x, y}``).

    Returns
    -------
    RaceArea
    """
    land = c.boolean(data, "wind_land_is_obstacle", False)
    if frame is None or not any(k in data for k in ("boundary", "obstacles")):
        return RaceArea(wind_land_is_obstacle=land)
    base = Path(c.p.file).parent
    has_origin = "origin" in data
    boundary = None
    if "boundary" in data:
        boundary = _polygon(
            c, data["boundary"], "boundary", "boundary", frame, has_origin, base, position
        )
    obstacles: list[AreaPolygon] = []
    raw = data.get("obstacles", [])
    if not isinstance(raw, list):
        c.p.add(
            "obstacles",
            f"expected a list of {{name, points or file, clearance_m}}; got {show(raw)}",
        )
        raw = []
    seen: set[str] = set()
    for i, item in enumerate(raw):
        path = join_path("obstacles", i)
        name = str(item.get("name", f"obstacle {i + 1}")) if isinstance(item, Mapping) else ""
        if name in seen:
            c.p.add(
                join_path(path, "name"),
                f"obstacle name {name!r} is used twice; give each obstacle its own name",
            )
        seen.add(name)
        ob = _polygon(c, item, path, name, frame, has_origin, base, position)
        if ob is not None:
            obstacles.append(ob)
    _marks_clear(c, boundary, obstacles, marks)
    return RaceArea(boundary, tuple(obstacles), land)


def _marks_clear(
    c: Checker,
    boundary: AreaPolygon | None,
    obstacles: list[AreaPolygon],
    marks: Mapping[str, tuple[float, float]],
) -> None:
    """A problem for each mark inside a grown obstacle or outside the shrunk boundary."""
    import shapely

    if not marks:
        return
    names = list(marks)
    mx = np.array([marks[k][0] for k in names])
    my = np.array([marks[k][1] for k in names])
    for ob in obstacles:
        g = ob.polygon()
        if ob.clearance_m > 0:
            g = shapely.buffer(g, ob.clearance_m, quad_segs=QUAD_SEGS)
        for k in np.flatnonzero(shapely.intersects_xy(g, mx, my)):
            kept = f" with its clearance_m = {ob.clearance_m:g} m" if ob.clearance_m else ""
            c.p.add(
                ob.where,
                f"mark {names[k]!r} ({mx[k]:.0f}, {my[k]:.0f} m) lies inside "
                f"obstacle {ob.name!r}{kept}; move the mark or the obstacle's points"
                + (", or lower clearance_m" if ob.clearance_m else ""),
            )
    if boundary is not None:
        g = boundary.polygon()
        if boundary.clearance_m > 0:
            g = shapely.buffer(g, -boundary.clearance_m, quad_segs=QUAD_SEGS)
        out = np.flatnonzero(~shapely.contains_xy(g, mx, my))
        if out.size:
            listed = ", ".join(f"{names[k]!r} ({mx[k]:.0f}, {my[k]:.0f} m)" for k in out)
            kept = (
                f" shrunk by its clearance_m = {boundary.clearance_m:g} m"
                if boundary.clearance_m
                else ""
            )
            c.p.add(
                "boundary",
                f"the boundary{kept} does not contain every mark: {listed} "
                "lie outside; the boundary must enclose the whole course (check its "
                "points, their order and the marks)",
            )
