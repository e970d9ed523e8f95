"""Read a course from KML (Google Earth, OpenCPN): placemarks in document order.

* a ``Point`` placemark is a mark, named by its ``<name>``; an ``<ExtendedData>`` entry
  ``type`` (``mark``, ``start``, ``finish``, ``gate``) or ``rounding``
  (``port``/``starboard``) says what it is, as the CSV columns do
  (:mod:`sailroute.course.formats.model`);
* a ``LineString`` of two points is a line (a gate with ``type: gate``) named by the
  placemark, its ends the marks ``<name>_1`` and ``<name>_2``; a line named ``start`` or
  ``finish`` (any case), else the first item, is the start line;
* a ``Polygon`` (its outer ring) is the boundary when its name holds ``boundary``, else
  an obstacle (:func:`~sailroute.course.formats.model.classify_rings`).

The placemarks' order is the leg sequence.  Coordinates are KML's ``lon,lat[,alt]``.
"""

from __future__ import annotations

from pathlib import Path

from sailroute.course.formats.model import (
    ImportedCourse,
    LatLon,
    Ring,
    Waypoint,
    from_waypoints,
    parse_rounding,
    parse_type,
)
from sailroute.course.formats.xmlnodes import Node, parse_xml
from sailroute.errors import InputError

__all__ = ["read_kml_course"]

GEOMETRIES = ("Point", "LineString", "Polygon")


def _coords(node: Node, where: str) -> list[LatLon]:
    """``(lat, lon)`` of a ``<coordinates>`` element's ``lon,lat[,alt]`` tuples."""
    out: list[LatLon] = []
    for tup in node.text.split():
        parts = tup.split(",")
        try:
            lon, lat = float(parts[0]), float(parts[1])
        except (IndexError, ValueError):
            raise InputError(
                f"{where}: coordinates {tup!r}; expected lon,lat[,alt] in decimal degrees"
            ) from None
        if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 360.0):
            raise InputError(
                f"{where}: coordinates {tup!r}; expected lat in [-90, 90] and "
                "lon in [-180, 360] degrees (KML writes lon first)"
            )
        out.append((lat, lon))
    return out


def _data(pm: Node) -> dict[str, str]:
    """``<ExtendedData><Data name=..><value>`` entries, names in lower case."""
    ext = pm.find("ExtendedData")
    if ext is None:
        return {}
    return {d.attrs.get("name", "").lower(): d.child_text("value") for d in ext.findall("Data")}


def _geometry(pm: Node, where: str) -> Node:
    geo = [c for c in pm.children if c.tag in GEOMETRIES or c.tag == "MultiGeometry"]
    if not geo:
        raise InputError(
            f"{where}: placemark {pm.child_text('name')!r} has no Point, "
            "LineString or Polygon; expected one"
        )
    if geo[0].tag == "MultiGeometry":
        raise InputError(
            f"{src_of(where)}: line {geo[0].line}: <MultiGeometry>; expected "
            "a Point, LineString or Polygon per placemark (split it)"
        )
    return geo[0]


def src_of(where: str) -> str:
    """The file part of a ``"file: line N"`` location."""
    return where.rsplit(": line ", 1)[0]


def read_kml_course(path: str | Path) -> ImportedCourse:
    """Read a course from a KML file.

    Parameters
    ----------
    path : str or Path
        The KML file.

    Returns
    -------
    ImportedCourse

    Raises
    ------
    InputError
        Not KML, no placemarks, bad coordinates, a LineString not of two points, a
        bad polygon, or a course that cannot be assembled (each naming the line).
    """
    src = Path(path)
    root = parse_xml(src, "a KML file")
    if root.tag != "kml":
        raise InputError(f"{src}: line {root.line}: root element <{root.tag}>; expected <kml>")
    placemarks = list(root.iter("Placemark"))
    if not placemarks:
        raise InputError(f"{src}: no <Placemark>; expected the marks as Point placemarks")
    points: list[Waypoint] = []
    rings: list[Ring] = []
    n_items = 0
    lines = [pm for pm in placemarks if _geometry(pm, f"{src}: line {pm.line}").tag == "LineString"]
    for pm in placemarks:
        where = f"{src}: line {pm.line}"
        geo = _geometry(pm, where)
        name = pm.child_text("name") or f"placemark{pm.line}"
        coords_node = next(geo.iter("coordinates"), None)
        if coords_node is None:
            raise InputError(f"{src}: line {geo.line}: <{geo.tag}> without <coordinates>")
        coords = _coords(coords_node, f"{src}: line {coords_node.line}")
        data = _data(pm)
        if geo.tag == "Point":
            if len(coords) != 1:
                raise InputError(
                    f"{src}: line {coords_node.line}: a Point with {len(coords)} "
                    "coordinates; expected one lon,lat"
                )
            kind = parse_type(data.get("type", ""), where)
            rounding = parse_rounding(data.get("rounding", ""), where)
            typed = bool(data.get("type", "").strip() or data.get("rounding", "").strip())
            points.append(
                Waypoint(
                    name,
                    coords[0][0],
                    coords[0][1],
                    kind,
                    rounding,
                    where,
                    line=pm.line,
                    typed=typed,
                )
            )
            n_items += 1
        elif geo.tag == "LineString":
            if len(coords) != 2:
                raise InputError(
                    f"{src}: line {coords_node.line}: LineString {name!r} of "
                    f"{len(coords)} points; expected 2 (a line's two ends)"
                )
            kind = parse_type(data.get("type", ""), where)
            if kind == "mark":
                low = name.lower()
                kind = (
                    "start"
                    if "start" in low
                    else "finish"
                    if "finish" in low
                    else "start"
                    if n_items == 0 and pm is lines[0]
                    else "finish"
                )
            line_name = name if kind == "gate" else (kind if name.lower() == kind else name)
            for k, (lat, lon) in enumerate(coords):
                points.append(
                    Waypoint(f"{name}_{k + 1}", lat, lon, kind, None, where, line_name, pm.line)
                )
            n_items += 1
        else:
            outer = geo.find("outerBoundaryIs")
            ring_node = next(outer.iter("coordinates"), None) if outer is not None else None
            if ring_node is None:
                raise InputError(
                    f"{src}: line {geo.line}: Polygon {name!r} without "
                    "<outerBoundaryIs><LinearRing><coordinates>"
                )
            ring = _coords(ring_node, f"{src}: line {ring_node.line}")
            if len(ring) > 1 and ring[0] == ring[-1]:
                ring = ring[:-1]  # KML closes its rings; a course ring does not
            rings.append(Ring(name, tuple(ring), f"{src}: line {pm.line}", pm.line))
    doc = root.find("Document")
    title = (doc.child_text("name") if doc is not None else "") or src.stem
    return from_waypoints(
        points,
        name=title,
        src=str(src),
        rings=rings,
        how_to_type="a `type` or `rounding` ExtendedData entry, or a LineString, in a KML file",
    )
