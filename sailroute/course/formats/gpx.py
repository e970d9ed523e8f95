"""Read a course from GPX 1.0/1.1: waypoints (``<wpt>``) or a route (``<rte>``).

With a route, its points (``<rtept>``) in order are the leg sequence; waypoints of the
file are marks too (a waypoint and a route point of one name are one mark).  Without a
route, the waypoints in file order are the sequence.  Each point's ``<name>`` names the
mark and its ``<type>`` says what it is: ``mark`` (default), ``start``, ``finish``,
``gate`` (see :mod:`sailroute.course.formats.model`), or ``port`` / ``starboard`` for a
mark rounded on that side.
"""

from __future__ import annotations

from pathlib import Path

from sailroute.course.formats.model import (
    ImportedCourse,
    Waypoint,
    from_waypoints,
    parse_rounding,
    parse_type,
)
from sailroute.course.formats.xmlnodes import Node, parse_xml
from sailroute.errors import InputError

__all__ = ["read_gpx_course"]


def _point(node: Node, src: Path, k: int) -> Waypoint:
    where = f"{src}: line {node.line}"
    try:
        lat, lon = float(node.attrs["lat"]), float(node.attrs["lon"])
    except (KeyError, ValueError):
        raise InputError(
            f"{where}: <{node.tag} lat={node.attrs.get('lat')!r} "
            f"lon={node.attrs.get('lon')!r}>: expected decimal degrees"
        ) from None
    if not (-90.0 <= lat <= 90.0 and -180.0 <= lon <= 360.0):
        raise InputError(
            f"{where}: <{node.tag}> at lat {lat}, lon {lon}; expected lat in "
            "[-90, 90] and lon in [-180, 360] degrees"
        )
    name = node.child_text("name") or f"{node.tag}{k + 1}"
    text = node.child_text("type")
    kind, rounding = "mark", None
    if text.strip().lower() in ("port", "starboard", "stbd", "p", "s"):
        rounding = parse_rounding(text, where)
    else:
        kind = parse_type(text, where)
    return Waypoint(
        name,
        lat,
        lon,
        kind,  # type: ignore[arg-type]
        rounding,
        where,
        line=node.line,
        typed=bool(text.strip()),
    )


def read_gpx_course(path: str | Path) -> ImportedCourse:
    """Read a course from a GPX file.

    Parameters
    ----------
    path : str or Path
        The GPX file.

    Returns
    -------
    ImportedCourse

    Raises
    ------
    InputError
        Not GPX, no waypoints and no route points, a point without valid lat/lon, an
        unknown ``<type>``, or a course that cannot be assembled.
    """
    src = Path(path)
    root = parse_xml(src, "a GPX file")
    if root.tag != "gpx":
        raise InputError(f"{src}: line {root.line}: root element <{root.tag}>; expected <gpx>")
    wpts = [_point(n, src, k) for k, n in enumerate(root.findall("wpt"))]
    routes = root.findall("rte")
    if len(routes) > 1:
        raise InputError(
            f"{src}: line {routes[1].line}: a second <rte>; expected one route "
            "(the course), or none"
        )
    rpts = [_point(n, src, k) for k, n in enumerate(routes[0].findall("rtept"))] if routes else []
    if not wpts and not rpts:
        raise InputError(
            f"{src}: line {root.line}: no waypoints (<wpt>) and no route points "
            "(<rte><rtept>); expected the marks as waypoints or a route"
        )
    meta = root.find("metadata")
    name = (
        (routes[0].child_text("name") if routes else "")
        or (meta.child_text("name") if meta is not None else "")
        or src.stem
    )
    how = "<type> in a GPX file"
    if rpts:
        return from_waypoints(rpts, name=name, src=str(src), extra_marks=wpts, how_to_type=how)
    return from_waypoints(wpts, name=name, src=str(src), how_to_type=how)
