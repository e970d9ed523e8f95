"""What a course importer reads: marks, lines, gates, the leg sequence and the areas.

Every reader (:mod:`~sailroute.course.formats.gpx`, ``csvfile``, ``kml``, ``racexml``)
returns an :class:`ImportedCourse`; :mod:`~sailroute.course.formats.write` turns it into
a course file.  The point-list formats (GPX, CSV, KML points) describe the course as a
list of :class:`Waypoint` s in sailing order, assembled by :func:`from_waypoints`:

* ``mark`` (the default): a mark, rounded to ``rounding`` (port when not given);
* ``start`` / ``finish``: two consecutive points of this type are the line of that name;
* ``gate``: two consecutive points of this type are a gate, named ``"<a>-<b>"``.

The first item of the list is where the first leg starts (the start line, or a mark).
A file in which no point says what it is (no type, no rounding) is refused: every point
would be a mark and the course would have no start line, which is what a plotter's
export of a race course's marks gives, not a course.

Every course remembers the line of the file each of its parts came from
(:attr:`ImportedCourse.key_lines`), so that what the course file's checks find is
reported at the line of the file that was imported.
"""

from __future__ import annotations

import dataclasses
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
from sailroute.textin import bad_char

__all__ = [
    "POINT_TYPES",
    "ImportedCourse",
    "Ring",
    "Waypoint",
    "check_name",
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
    line : int
        1-based line of the point in its file (0: unknown).
    typed : bool
        The file says what the point is (a type or a rounding side); False for a mark
        by default.
    """

    name: str
    lat: float
    lon: float
    kind: PointType = "mark"
    rounding: Side | None = None
    where: str = ""
    line_name: str = ""
    line: int = 0
    typed: bool = True


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
    line : int
        1-based line of the polygon in its file (0: unknown).
    """

    name: str
    points: tuple[LatLon, ...]
    where: str
    line: int = 0


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
    key_lines : tuple of (str, int)
        Key path of the course file to be written (``"marks.M1"``, ``"legs[2]"``,
        ``"boundary"``, ``"obstacles[0]"``) -> 1-based line of the imported file it
        comes from.
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
    key_lines: tuple[tuple[str, int], ...] = ()

    @property
    def frame(self) -> LocalFrame:
        """A local frame at the mean of the marks (for distances and polygon tests)."""
        lat = float(np.mean([m[1] for m in self.marks]))
        lon = float(np.mean([m[2] for m in self.marks]))
        return LocalFrame(lat, lon)


def check_name(name: str, where: str, what: str = "name") -> str:
    """``name`` if a course file and every output can carry it, else an error at ``where``.

    Raises
    ------
    InputError
        A control character, a lone surrogate or U+FFFE/U+FFFF in the name
        (:func:`~sailroute.textin.bad_char`).
    """
    bad = bad_char(name)
    if bad is not None:
        raise InputError(
            f"{where}: the {what} {name!a} holds {bad}, which no output file can carry; remove it"
        )
    return name


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


def _add_mark(
    marks: dict[str, tuple[float, float, str, int]], p: Waypoint, frame: LocalFrame
) -> None:
    """Record mark ``p``; a name seen before must be the same place."""
    check_name(p.name, p.where, "mark name")
    if p.name in marks:
        lat, lon, first, _ = marks[p.name]
        x, y = frame.to_xy([lat, p.lat], [lon, p.lon])
        d = float(math.hypot(x[1] - x[0], y[1] - y[0]))
        if d > SAME_PLACE_M:
            raise InputError(
                f"{p.where}: mark {p.name!r} is {d:.1f} m from the point of the "
                f"same name at {first}; expected one place per name (rename one)"
            )
        return
    marks[p.name] = (p.lat, p.lon, p.where, p.line)


def _untyped(points: Sequence[Waypoint], how_to_type: str) -> InputError:
    """The error for a file in which no point says what it is."""
    p = points[0]
    return InputError(
        f"{p.where}: no point says what it is ({how_to_type}), so every point would be a "
        f"mark and the course would start at the mark {p.name!r}, with no start line; "
        "give the start line's two ends the type start (the finish's finish, a gate's "
        "gate), or the first point the type mark to start the first leg there"
    )


def from_waypoints(
    points: Sequence[Waypoint],
    *,
    name: str,
    src: str,
    rings: Sequence[Ring] = (),
    start_time: datetime | None = None,
    extra_marks: Sequence[Waypoint] = (),
    how_to_type: str = "a type",
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
    how_to_type : str
        How the file gives a point's type, for the message when none does
        (``"<type> in a GPX file"``).

    Returns
    -------
    ImportedCourse

    Raises
    ------
    InputError
        Fewer than two items, no point with a type or rounding, a start/finish/gate
        point without its partner, a name used for two places or holding a control
        character, or a bad polygon.
    """
    if not points:
        raise InputError(f"{src}: no points; expected the marks in sailing order")
    if not any(p.typed for p in points):
        raise _untyped(points, how_to_type)
    frame = LocalFrame(
        float(np.mean([p.lat for p in points])), float(np.mean([p.lon for p in points]))
    )
    marks: dict[str, tuple[float, float, str, int]] = {}
    lines: dict[str, tuple[str, str]] = {}
    gates: dict[str, tuple[str, str]] = {}
    seq: list[tuple[str, Side | None]] = []
    key_lines: dict[str, int] = {}
    k = 0
    while k < len(points):
        p = points[k]
        _add_mark(marks, p, frame)
        key_lines["legs[0].from" if not seq else f"legs[{len(seq) - 1}]"] = p.line
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
            gname = check_name(p.line_name or f"{p.name}-{q.name}", p.where, "gate name")
            gates[gname] = (p.name, q.name)
            key_lines.setdefault(f"gates.{gname}", p.line)
            seq.append((gname, None))
        else:
            lname = check_name(p.line_name or p.kind, p.where, "line name")
            lines[lname] = (p.name, q.name)
            key_lines.setdefault(f"lines.{lname}", p.line)
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
    key_lines.update({f"marks.{n}": line for n, (_, _, _, line) in marks.items()})
    course = ImportedCourse(
        name=check_name(name, src, "course name"),
        marks=tuple((n, lat, lon) for n, (lat, lon, _, _) in marks.items()),
        lines=tuple((n, a, b) for n, (a, b) in lines.items()),
        gates=tuple((n, a, b) for n, (a, b) in gates.items()),
        start_from=seq[0][0],
        legs=tuple(seq[1:]),
        start_time=start_time,
        key_lines=tuple((k, v) for k, v in key_lines.items() if v > 0),
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
    key_lines = dict(course.key_lines)
    taken: set[str] = set()
    for r in rings:
        check_name(r.name, r.where, "polygon name")
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
                key_lines["boundary"] = r.line
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
            key_lines[f"obstacles[{len(obstacles)}]"] = r.line
            obstacles.append((name, r.points))
    return dataclasses.replace(
        course,
        boundary=boundary,
        obstacles=tuple(obstacles),
        notes=tuple(notes),
        key_lines=tuple((k, v) for k, v in key_lines.items() if v > 0),
    )
