"""The planned route for chart plotters and navigation software: waypoints, KML, NMEA 0183.

:func:`route_points` lists the route's waypoints in sailing order: the start point,
each tack and gybe, and the end of every leg (the mark rounded, the gate or line
crossed).  Three writers use them:

* ``route.gpx``'s ``<rte>`` (:func:`sailroute.report.files.write_gpx`);
* ``route.kml`` (:func:`write_kml`): the marks, the sailed route as a line, and the
  waypoints (manoeuvres with their time), each drawn in its own style (:data:`KML_STYLES`:
  orange marks, a red route line, red triangles for tacks, blue squares for gybes);
* ``route.nmea`` (:func:`write_nmea`): NMEA 0183 ``WPL`` (waypoint location) sentences,
  one per waypoint, then ``RTE`` (route) sentences listing them in order.

NMEA 0183 conventions followed (IEC 61162-1): talker ``GP``; each sentence at most 82
characters from ``$`` to the line end, with its ``*hh`` checksum (the XOR of the
characters between ``$`` and ``*``, two upper-case hex digits) and CR LF; latitude as
``ddmm.mmmm,N|S`` and longitude ``dddmm.mmmm,E|W`` (4 decimals of a minute: 0.2 m);
waypoint identifiers of at most 6 characters from ``A-Z 0-9`` that say what the point is
on a plotter's small screen (:func:`nmea_ids`: ``START``, ``M1``, ``G4``, ``FIN``,
``T03``, ``J01``); a route too long for one ``RTE`` sentence is split over several (field
1 the count, field 2 the sentence number, field 3 ``c``: a complete route, field 4 the
route number ``1``).  The waypoints keep their full names in ``route.gpx`` and
``route.kml``.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal
from xml.etree import ElementTree as ET

from sailroute._version import __version__
from sailroute.nmea import frame, lat_field, lon_field, rte_bodies
from sailroute.planning.result import Plan
from sailroute.textin import clean_text
from sailroute.timeutil import iso

__all__ = [
    "KML_NS",
    "RoutePoint",
    "nmea_ids",
    "nmea_sentences",
    "route_points",
    "write_kml",
    "write_nmea",
]

KML_NS = "http://www.opengis.net/kml/2.2"
NMEA_ID_LEN = 6
TALKER = "GP"

_ICONS = "http://maps.google.com/mapfiles/kml/shapes/"
KML_STYLES: dict[str, dict[str, str]] = {
    "mark": {"icon": "placemark_circle.png", "colour": "#ff8c00", "scale": "1.1"},
    "leg-end": {"icon": "flag.png", "colour": "#222222", "scale": "0.9"},
    "tack": {"icon": "triangle.png", "colour": "#dc143c", "scale": "0.8"},
    "gybe": {"icon": "square.png", "colour": "#4169e1", "scale": "0.7"},
    "route": {"colour": "#d62728", "width": "3"},
}
"""The styles of ``route.kml`` (ids of its ``<Style>`` elements): an icon of Google
Earth's standard set, its colour (``#rrggbb``, written as KML's ``aabbggrr``) and size for
the points; the colour and width [px] of the route line."""

PointKind = Literal["start", "mark", "gate", "line", "tack", "gybe"]


@dataclass(frozen=True)
class RoutePoint:
    """One waypoint of the planned route.

    Attributes
    ----------
    name : str
        The mark, gate or line name for a leg's start or end; ``T1``, ``T2``, ... for
        tacks and ``G1``, ... for gybes (numbered along the whole route).
    kind : {"start", "mark", "gate", "line", "tack", "gybe"}
        What happens there (``start``: where the first leg starts).
    lat, lon : float
        Position [deg].
    t : float
        Time [epoch s].
    leg : int
        The leg it belongs to (1-based; a leg's end belongs to that leg).
    """

    name: str
    kind: PointKind
    lat: float
    lon: float
    t: float
    leg: int


def route_points(plan: Plan) -> tuple[RoutePoint, ...]:
    """The route's waypoints in sailing order.

    Parameters
    ----------
    plan : Plan
        The routed course.

    Returns
    -------
    tuple of RoutePoint
        The first leg's start point, then for each leg its tacks and gybes in time
        order and its end point (at the leg's arrival, named after its target).
    """
    c = plan.course
    out: list[RoutePoint] = []
    if not plan.legs:
        return ()
    first = plan.legs[0]
    lat, lon = c.frame.to_latlon(*first.result.start_xy)
    out.append(
        RoutePoint(first.spec.from_name, "start", float(lat), float(lon), first.result.t_start, 1)
    )
    count = {"tack": 0, "gybe": 0}
    for pl in plan.legs:
        leg = pl.spec.index + 1
        for m in sorted(pl.result.manoeuvres, key=lambda m: m.t):
            count[m.kind] += 1
            lat, lon = c.frame.to_latlon(m.x, m.y)
            out.append(
                RoutePoint(
                    f"{m.kind[0].upper()}{count[m.kind]}", m.kind, float(lat), float(lon), m.t, leg
                )
            )
        lat, lon = c.frame.to_latlon(*pl.result.end_xy)
        out.append(
            RoutePoint(pl.spec.to_name, pl.spec.kind, float(lat), float(lon), pl.result.t_end, leg)
        )
    return tuple(out)


# ----------------------------------------------------------------------------- KML
def _kml(parent: ET.Element, tag: str, text: str | None = None) -> ET.Element:
    el = ET.SubElement(parent, f"{{{KML_NS}}}{tag}")
    if text is not None:
        el.text = clean_text(text)
    return el


def _kml_colour(hex_colour: str) -> str:
    """``#rrggbb`` as KML's opaque ``ffbbggrr``."""
    r, g, b = hex_colour[1:3], hex_colour[3:5], hex_colour[5:7]
    return f"ff{b}{g}{r}"


def _styles(doc: ET.Element) -> None:
    """The :data:`KML_STYLES` as ``<Style id=...>`` elements of the document."""
    for sid, st in KML_STYLES.items():
        style = _kml(doc, "Style")
        style.set("id", sid)
        if "icon" in st:
            icon = _kml(style, "IconStyle")
            _kml(icon, "color", _kml_colour(st["colour"]))
            _kml(icon, "scale", st["scale"])
            _kml(_kml(icon, "Icon"), "href", _ICONS + st["icon"])
            _kml(_kml(style, "LabelStyle"), "scale", "0.8")
        else:
            line = _kml(style, "LineStyle")
            _kml(line, "color", _kml_colour(st["colour"]))
            _kml(line, "width", st["width"])


def _placemark(
    folder: ET.Element,
    name: str,
    description: str,
    coords: str,
    when: str | None = None,
    geometry: str = "Point",
    style: str = "",
) -> ET.Element:
    pm = _kml(folder, "Placemark")
    _kml(pm, "name", name)
    _kml(pm, "description", description)
    if style:
        _kml(pm, "styleUrl", f"#{style}")
    if when is not None:
        _kml(_kml(pm, "TimeStamp"), "when", when)
    geo = _kml(pm, geometry)
    if geometry == "LineString":
        _kml(geo, "tessellate", "1")
    _kml(geo, "coordinates", coords)
    return pm


def write_kml(path: str | Path, plan: Plan) -> Path:
    """Write ``route.kml`` (KML 2.2): marks, the route line and the waypoints.

    The document's styles (:data:`KML_STYLES`), then three folders: ``marks`` (a Point
    per mark, style ``mark``), ``route`` (one LineString through every track point of
    every leg, style ``route``), ``waypoints`` (a Point per :func:`route_points` entry,
    named as in ``route.gpx``, with its kind, leg, time and plotter identifier
    (:func:`nmea_ids`) in the description and a ``TimeStamp``; style ``tack``, ``gybe``
    or ``leg-end``).  Coordinates are KML's ``lon,lat`` with 8 decimals.

    Returns
    -------
    Path
    """
    ET.register_namespace("", KML_NS)
    c = plan.course
    root = ET.Element(f"{{{KML_NS}}}kml")
    doc = _kml(root, "Document")
    _kml(doc, "name", f"{c.name} ({plan.scenario})")
    _kml(
        doc,
        "description",
        f"sailroute {__version__}: route planned with the "
        f"{plan.router or 'default'} router, start {iso(plan.t_start)}",
    )
    _styles(doc)
    marks = _kml(doc, "Folder")
    _kml(marks, "name", "marks")
    for m in c.marks.values():
        _placemark(marks, m.name, "mark", f"{m.lon:.8f},{m.lat:.8f}", style="mark")
    route = _kml(doc, "Folder")
    _kml(route, "name", "route")
    coords: list[str] = []
    for pl in plan.legs:
        tr = pl.result.track
        lat, lon = c.frame.to_latlon(tr.x, tr.y)
        coords += [f"{b:.8f},{a:.8f}" for a, b in zip(lat, lon, strict=True)]
    _placemark(
        route,
        f"{c.name} ({plan.scenario})",
        f"{len(plan.legs)} legs, {plan.total_time_s:.0f} s",
        " ".join(coords),
        geometry="LineString",
        style="route",
    )
    wps = _kml(doc, "Folder")
    _kml(wps, "name", "waypoints")
    points = route_points(plan)
    ids = nmea_ids([p.name for p in points], [p.kind for p in points])
    for p, ident in zip(points, ids, strict=True):
        _placemark(
            wps,
            p.name,
            f"{p.kind}, leg {p.leg}, {iso(p.t)}, plotter id {ident}",
            f"{p.lon:.8f},{p.lat:.8f}",
            when=iso(p.t),
            style=p.kind if p.kind in ("tack", "gybe") else "leg-end",
        )
    tree = ET.ElementTree(root)
    ET.indent(tree, space=" ")
    out = Path(path)
    tree.write(out, encoding="utf-8", xml_declaration=True)
    return out


# ----------------------------------------------------------------------------- NMEA 0183
def _token(name: str) -> str:
    """``name`` in upper case with only ``A-Z`` and ``0-9`` kept."""
    return re.sub(r"[^A-Z0-9]", "", name.upper())


def _plotter_id(name: str, kind: str) -> str:
    """What a waypoint is, in at most :data:`NMEA_ID_LEN` characters (before making it
    unique): ``START``, the mark's name (``M`` before a name that starts with a digit:
    ``M1``), ``G<gate>``, ``FIN`` or ``L<line>``, ``T<nn>`` for the n-th tack, ``J<nn>``
    for the n-th gybe (jibe: ``G`` names gates)."""
    token = _token(name)
    if kind in ("tack", "gybe"):
        number = re.search(r"\d+", name)
        n = int(number.group()) if number else 0
        return f"{'T' if kind == 'tack' else 'J'}{n:02d}"[:NMEA_ID_LEN]
    if kind == "start":
        return "START"
    if kind == "mark":
        return (f"M{token}" if not token or token[0].isdigit() else token)[:NMEA_ID_LEN]
    if kind == "gate":
        return f"G{token.removeprefix('GATE') or token}"[:NMEA_ID_LEN]
    if kind == "line":
        return "FIN" if token.startswith("FIN") else f"L{token}"[:NMEA_ID_LEN]
    return token[:NMEA_ID_LEN] or "WP"


def nmea_ids(names: Sequence[str], kinds: Sequence[str] | None = None) -> tuple[str, ...]:
    """Waypoint identifiers for NMEA 0183 that read on a plotter: unique, at most 6
    characters of ``A-Z 0-9``.

    With ``kinds`` (:data:`PointKind` of each point) an identifier says what the point
    is: ``START`` (where the first leg starts), ``M1`` (mark ``1`` rounded; a mark whose
    name starts with a letter keeps it: ``B1``, ``TOP``), ``G4`` (gate
    ``gate4`` or ``4`` passed), ``FIN`` (the finish line), ``L<name>`` (another line),
    ``T03`` (the third tack), ``J01`` (the first gybe); without, the name in upper case.
    A mark rounded again gets ``R`` and its passage number (``M1R2``); an identifier still
    taken is cut and numbered until it is free.

    Parameters
    ----------
    names : sequence of str
        The waypoint names (:attr:`RoutePoint.name`), in route order.
    kinds : sequence of str, optional
        What each point is (:attr:`RoutePoint.kind`).

    Returns
    -------
    tuple of str
    """
    kinds = kinds if kinds is not None else [""] * len(names)
    taken: set[str] = set()
    seen: dict[str, int] = {}
    out = []
    for name, kind in zip(names, kinds, strict=True):
        base = _plotter_id(name, kind)
        seen[base] = seen.get(base, 0) + 1
        ident = base if seen[base] == 1 else _numbered(base, "R", seen[base])
        k = seen[base]
        while ident in taken:
            k += 1
            ident = _numbered(base, "", k)
        taken.add(ident)
        out.append(ident)
    return tuple(out)


def _numbered(base: str, sep: str, n: int) -> str:
    """``base`` cut so that ``sep`` and ``n`` fit in :data:`NMEA_ID_LEN` characters."""
    tail = f"{sep}{n}"
    return base[: NMEA_ID_LEN - len(tail)] + tail


def nmea_sentences(points: Sequence[RoutePoint], route_id: str = "1") -> list[str]:
    """The ``WPL`` and ``RTE`` sentences of a route (without line ends).

    Parameters
    ----------
    points : sequence of RoutePoint
        The route's waypoints in order (:func:`route_points`).
    route_id : str
        The route's identifier (``RTE`` field 4).

    Returns
    -------
    list of str
        One ``$GPWPL`` per waypoint, then the ``$GPRTE`` sentences, each at most
        :data:`sailroute.nmea.NMEA_MAX_LEN` characters with its line end.
    """
    ids = nmea_ids([p.name for p in points], [p.kind for p in points])
    out = [
        frame(f"{TALKER}WPL,{','.join(lat_field(p.lat))},{','.join(lon_field(p.lon))},{i}")
        for p, i in zip(points, ids, strict=True)
    ]
    return out + [frame(body) for body in rte_bodies(TALKER, route_id, ids)]


def write_nmea(path: str | Path, plan: Plan) -> Path:
    """Write ``route.nmea``: the route's :func:`nmea_sentences`, one per line, CR LF.

    Returns
    -------
    Path
    """
    out = Path(path)
    with out.open("w", encoding="ascii", newline="") as fh:
        for s in nmea_sentences(route_points(plan)):
            fh.write(s + "\r\n")
    return out
