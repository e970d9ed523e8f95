"""What a course importer reads: marks, lines, gates, the leg sequence and the areas.

Every reader (:mod:`~sailroute.course.formats.gpx`, ``csvfile``, ``kml``, ``racexml``)
returns an :class:`ImportedCourse`; :mod:`~sailroute.course.formats.write` turns it into
a course file.  The point-list formats (GPX, CSV, KML points) describe the course as a
list of :class:`Waypoint` s in sailing order, assembled by :func:`from_waypoints`:

* ``mark`` (the default): a mark, rounded to ``rounding`` (port when not given);
* ``start`` / ``finish``: two consecutive points of this type are the line of that name;
* ``gate``: two consecutive points of this type are a gate, named ``"<a>-<b>"``.

The first item of the list is where the first leg starts (the start line, or a mark).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import datetime
from typing import Literal

import numpy as np
import shapely

from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.routing.rings import ring_problem
from sailroute.routing.types import Side

__all__ = [
    "POINT_TYPES",
    "ImportedCourse",
    "Ring",
    "Waypoint",
    "classify_rings",
    "from_waypoints",
    "parse_rounding",
    "parse_type",
]

LatLon = tuple[float, float]
PointType = Literal["mark", "start", "finish", "gate"]
POINT_TYPES: tuple[PointType, ...] = ("mark", "start", "finish", "gate")
"""The values of a point's type (CSV ``type`` column, GPX ``<type>``, KML ``type`` data)."""
SAME_PLACE_M = 1.0
"""Two points of one name must lie within this distance [m] to be one mark."""


@dataclass(frozen=True)
class Waypoint:
    """One point of a point-list course file.

    Attributes
    ----------
    name : str
        Mark name.
    lat, lon : float
        Position [deg].
    kind : {"mark", "start", "finish", "gate"}
        What the point is (see the module's description).
    rounding : {"port", "starboard"} or None
        Side a mark is left on (None: port).
    where : str
        ``"file: line N"`` for messages.
    line_name : str
        For an end of a line or gate: its name (default: the type for a start or
        finish line, ``"<a>-<b>"`` for a gate).
    """

    name: str
    lat: float
    lon: float
    kind: PointType = "mark"
    rounding: Side | None = None
    where: str = ""
    line_name: str = ""


@dataclass(frozen=True)
class Ring:
    """A polygon read from a file, before it is classed as boundary or obstacle.

    Attributes
    ----------
    name : str
        Its name in the file.
    points : tuple of (float, float)
        Vertices ``(lat, lon)`` [deg], not repeating the first.
    where : str
        ``"file: line N"`` for messages.
    """

    name: str
    points: tuple[LatLon, ...]
    where: str


@dataclass(frozen=True)
class ImportedCourse:
    """A course read from a GPX, CSV, KML or race XML file.

    Attributes
    ----------
    name : str
        Course name.
    marks : tuple of (str, float, float)
        ``(name, lat, lon)`` [deg] of every mark, in file order.
    lines, gates : tuple of (str, str, str)
        ``(name, mark a, mark b)``.
    start_from : str
        The line or mark the first leg starts from.
    legs : tuple of (str, str or None)
        ``(to, rounding)`` of each leg in sailing order (rounding None for a gate or line).
    start_time : datetime or None
        The start signal when the file gives it.
    boundary : tuple of (float, float) or None
        The race area's ring ``(lat, lon)`` [deg].
    obstacles : tuple of (str, tuple of (float, float))
        Areas to stay out of: name and ring.
    notes : tuple of str
        What the import decided that the user should know (areas left out, ...).
    """

    name: str
    marks: tuple[tuple[str, float, float], ...]
    lines: tuple[tuple[str, str, str], ...]
    gates: tuple[tuple[str, str, str], ...]
    start_from: str
    legs: tuple[tuple[str, Side | None], ...]
    start_time: datetime | None = None
    boundary: tuple[LatLon, ...] | None = None
    obstacles: tuple[tuple[str, tuple[LatLon, ...]], ...] = ()
    notes: tuple[str, ...] = ()

    @property
    def frame(self) -> LocalFrame:
        """A local frame at the mean of the marks (for distances and polygon tests)."""
        lat = float(np.mean([m[1] for m in self.marks]))
        lon = float(np.mean([m[2] for m in self.marks]))
        return LocalFrame(lat, lon)


def parse_type(text: str, where: str) -> PointType:
    """A point type from its text (case-insensitive; empty: ``mark``)."""
    t = text.strip().lower() or "mark"
    if t not in POINT_TYPES:
        raise InputError(
            f"{where}: type {text!r}; expected one of {', '.join(POINT_TYPES)} "
            "(or leave it empty for a mark)"
        )
    return t


def parse_rounding(text: str, where: str) -> Side | None:
    """A rounding side from its text: ``port``/``p``, ``starboard``/``stbd``/``s``; empty: None."""
    t = text.strip().lower()
    if not t:
        return None
    if t in ("port", "p"):
        return "port"
    if t in ("starboard", "stbd", "s"):
        return "starboard"
    raise InputError(f"{where}: rounding {text!r}; expected port or starboard (or empty)")


def _add_mark(marks: dict[str, tuple[float, float, str]], p: Waypoint, frame: LocalFrame) -> None:
    """Record mark ``p``; a name seen before must be the same place."""
    if p.name in marks:
        lat, lon, first = marks[p.name]
        x, y = frame.to_xy([lat, p.lat], [lon, p.lon])
        d = float(math.hypot(x[1] - x[0], y[1] - y[0]))
        if d > SAME_PLACE_M:
            raise InputError(
                f"{p.where}: mark {p.name!r} is {d:.1f} m from the point of the "
                f"same name at {first}; expected one place per name (rename one)"
            )
        return
    marks[p.name] = (p.lat, p.lon, p.where)


def from_waypoints(
    points: Sequence[Waypoint],
    *,
    name: str,
    src: str,
    rings: Sequence[Ring] = (),
    start_time: datetime | None = None,
    extra_marks: Sequence[Waypoint] = (),
) -> ImportedCourse:
    """Assemble a course from a list of points in sailing order.

    Parameters
    ----------
    points : sequence of Waypoint
        The points, in sailing order (see the module's description).
    name : str
        Course name.
    src : str
        The file, for messages.
    rings : sequence of Ring
        Polygons of the file (boundary and obstacles, see :func:`classify_rings`).
    start_time : datetime, optional
        Start signal, when the file gives it.
    extra_marks : sequence of Waypoint
        Marks that are not in the sequence (a GPX file's waypoints beside its route); a
        name also in ``points`` must be the same place.

    Returns
    -------
    ImportedCourse

    Raises
    ------
    InputError
        Fewer than two items, a start/finish/gate point without its partner, a name
        used for two places, or a bad polygon.
    """
    if not points:
        raise InputError(f"{src}: no points; expected the marks in sailing order")
    frame = LocalFrame(
        float(np.mean([p.lat for p in points])), float(np.mean([p.lon for p in points]))
    )
    marks: dict[str, tuple[float, float, str]] = {}
    lines: dict[str, tuple[str, str]] = {}
    gates: dict[str, tuple[str, str]] = {}
    seq: list[tuple[str, Side | None]] = []
    k = 0
    while k < len(points):
        p = points[k]
        _add_mark(marks, p, frame)
        if p.kind == "mark":
            seq.append((p.name, p.rounding or "port"))
            k += 1
            continue
        q = points[k + 1] if k + 1 < len(points) else None
        if q is None or q.kind != p.kind:
            raise InputError(
                f"{p.where}: point {p.name!r} of type {p.kind} stands alone; "
                f"expected two consecutive points of type {p.kind} (its two ends)"
            )
        if q.name == p.name:
            raise InputError(
                f"{q.where}: both ends of the {p.kind} are called {p.name!r}; "
                "expected two different marks"
            )
        _add_mark(marks, q, frame)
        if p.kind == "gate":
            gname = p.line_name or f"{p.name}-{q.name}"
            gates[gname] = (p.name, q.name)
            seq.append((gname, None))
        else:
            lname = p.line_name or p.kind
            lines[lname] = (p.name, q.name)
            seq.append((lname, None))
        k += 2
    for p in extra_marks:
        _add_mark(marks, p, frame)
    if len(seq) < 2:
        raise InputError(
            f"{src}: one item ({seq[0][0]!r}); expected at least two in sailing "
            "order: where the first leg starts and the mark it sails to"
        )
    for n in marks:
        if n in lines or n in gates:
            raise InputError(
                f"{src}: {n!r} names a mark and a line or gate; expected "
                "different names (rename the mark)"
            )
    course = ImportedCourse(
        name=name,
        marks=tuple((n, lat, lon) for n, (lat, lon, _) in marks.items()),
        lines=tuple((n, a, b) for n, (a, b) in lines.items()),
        gates=tuple((n, a, b) for n, (a, b) in gates.items()),
        start_from=seq[0][0],
        legs=tuple(seq[1:]),
        start_time=start_time,
    )
    return classify_rings(course, rings)


def classify_rings(course: ImportedCourse, rings: Sequence[Ring]) -> ImportedCourse:
    """Class a file's polygons as the boundary or obstacles; check each is a simple ring.

    A ring whose name contains ``boundary`` (any case) is the boundary (one at most);
    one that holds every mark is an outer limit around the race area (a spectator
    exclusion line, say) and is left out with a note, since an obstacle there would
    leave no water to sail in; every other ring is an obstacle.

    Raises
    ------
    InputError
        A self-intersecting ring, fewer than 3 points, two boundaries, or an obstacle
        that holds a mark (the course file would refuse it), naming the file and line of
        the ring.
    """
    frame = course.frame
    mx, my = frame.to_xy([m[1] for m in course.marks], [m[2] for m in course.marks])
    boundary: tuple[LatLon, ...] | None = None
    boundary_where = ""
    obstacles: list[tuple[str, tuple[LatLon, ...]]] = []
    notes = list(course.notes)
    taken: set[str] = set()
    for r in rings:
        x, y = frame.to_xy([p[0] for p in r.points], [p[1] for p in r.points])
        xy = np.column_stack([x, y])
        problem = ring_problem(xy)
        if problem is not None:
            raise InputError(f"{r.where}: polygon {r.name!r}: {problem}")
        inside = shapely.contains_xy(shapely.Polygon(xy), mx, my)
        if "boundary" in r.name.lower():
            if boundary is not None:
                raise InputError(
                    f"{r.where}: a second boundary {r.name!r} (the first is at "
                    f"{boundary_where}); expected one (rename the other)"
                )
            outside = [m[0] for m, ok in zip(course.marks, inside, strict=True) if not ok]
            if outside:  # a course file's boundary holds every mark (course-format.md)
                notes.append(
                    f"the boundary {r.name!r} ({r.where}) leaves the marks "
                    f"{', '.join(outside)} outside: left out (routes are not kept "
                    "inside it); add a `boundary:` that holds every mark to use one"
                )
            else:
                boundary, boundary_where = r.points, r.where
        elif inside.all():
            notes.append(
                f"polygon {r.name!r} ({r.where}) holds every mark: an outer limit "
                "around the race area, not an area to stay out of; left out"
            )
        else:
            if inside.any():  # the course file would refuse it: say so at the source
                held = [repr(m[0]) for m, ok in zip(course.marks, inside, strict=True) if ok]
                raise InputError(
                    f"{r.where}: polygon {r.name!r} holds the mark{'s' * (len(held) > 1)} "
                    f"{', '.join(held)}; expected an area to stay out of, clear of every "
                    "mark (check the polygon's points and the marks' positions)"
                )
            name, n = r.name, 1
            while name in taken:  # obstacle names are unique in a course file
                n += 1
                name = f"{r.name}-{n}"
            taken.add(name)
            obstacles.append((name, r.points))
    return ImportedCourse(
        course.name,
        course.marks,
        course.lines,
        course.gates,
        course.start_from,
        course.legs,
        course.start_time,
        boundary,
        tuple(obstacles),
        tuple(notes),
    )
