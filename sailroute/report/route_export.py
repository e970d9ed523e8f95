"""The planned route for chart plotters and navigation software: waypoints, KML, NMEA 0183.

:func:`route_points` lists the route's waypoints in sailing order: the start point,
each tack and gybe, and the end of every leg (the mark rounded, the gate or line
crossed).  Three writers use them:

* ``route.gpx``'s ``<rte>`` (:func:`sailroute.report.files.write_gpx`);
* ``route.kml`` (:func:`write_kml`): the marks, the sailed route as a line, and the
  waypoints (manoeuvres with their time);
* ``route.nmea`` (:func:`write_nmea`): NMEA 0183 ``WPL`` (waypoint location) sentences,
  one per waypoint, then ``RTE`` (route) sentences listing them in order.

NMEA 0183 conventions followed (IEC 61162-1): talker ``GP``; each sentence at most 82
characters from ``$`` to the line end, with its ``*hh`` checksum (the XOR of the
characters between ``$`` and ``*``, two upper-case hex digits) and CR LF; latitude as
``ddmm.mmmm,N|S`` and longitude ``dddmm.mmmm,E|W`` (4 decimals of a minute: 0.2 m);
waypoint identifiers of at most 6 characters from ``A-Z 0-9`` (:func:`nmea_ids`: the
point's number in the route, then its name in upper case, cut); a route too
long for one ``RTE`` sentence is split over several (field 1 the count, field 2 the
sentence number, field 3 ``c``: a complete route, field 4 the route number ``1``).
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


def _placemark(
    folder: ET.Element,
    name: str,
    description: str,
    coords: str,
    when: str | None = None,
    geometry: str = "Point",
) -> ET.Element:
    pm = _kml(folder, "Placemark")
    _kml(pm, "name", name)
    _kml(pm, "description", description)
    if when is not None:
        _kml(_kml(pm, "TimeStamp"), "when", when)
    geo = _kml(pm, geometry)
    if geometry == "LineString":
        _kml(geo, "tessellate", "1")
    _kml(geo, "coordinates", coords)
    return pm


def write_kml(path: str | Path, plan: Plan) -> Path:
    """Write ``route.kml`` (KML 2.2): marks, the route line and the waypoints.

    Three folders: ``marks`` (a Point per mark), ``route`` (one LineString through
    every track point of every leg), ``waypoints`` (a Point per :func:`route_points`
    entry, with its kind, leg and time in the description and a ``TimeStamp``).
    Coordinates are KML's ``lon,lat`` with 8 decimals.

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
    marks = _kml(doc, "Folder")
    _kml(marks, "name", "marks")
    for m in c.marks.values():
        _placemark(marks, m.name, "mark", f"{m.lon:.8f},{m.lat:.8f}")
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
    )
    wps = _kml(doc, "Folder")
    _kml(wps, "name", "waypoints")
    for p in route_points(plan):
        _placemark(
            wps,
            p.name,
            f"{p.kind}, leg {p.leg}, {iso(p.t)}",
            f"{p.lon:.8f},{p.lat:.8f}",
            when=iso(p.t),
        )
    tree = ET.ElementTree(root)
    ET.indent(tree, space=" ")
    out = Path(path)
    tree.write(out, encoding="utf-8", xml_declaration=True)
    return out


# ----------------------------------------------------------------------------- NMEA 0183
def nmea_ids(names: Sequence[str]) -> tuple[str, ...]:
    """Waypoint identifiers for NMEA 0183: unique, at most 6 characters.

    Each identifier is the waypoint's number in the route (from 0, two digits; three
    from the 101st point) followed by its name in upper case with only ``A-Z`` and
    ``0-9`` kept, cut to 6 characters: ``00STAR``, ``01M1``, ``02T1``, ``03LG1L``.  The
    number makes a mark rounded twice (two places on the route) two waypoints.

    Parameters
    ----------
    names : sequence of str
        The waypoint names, in route order.

    Returns
    -------
    tuple of str
    """
    width = max(2, len(str(len(names) - 1)))
    return tuple(
        f"{k:0{width}d}{re.sub(r'[^A-Z0-9]', '', n.upper())}"[:NMEA_ID_LEN]
        for k, n in enumerate(names)
    )


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
    ids = nmea_ids([p.name for p in points])
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
