"""Write an :class:`~sailroute.course.formats.model.ImportedCourse` as a course file (YAML).

The text follows ``docs/course-format.md``: ``marks`` in degrees, ``lines``, ``gates``,
``legs`` (the first with ``from:``), one uniform wind scenario, and the ``boundary`` and
``obstacles`` areas.  Names are written double-quoted (a name such as ``1`` or ``no``
stays text, and a line break inside one is an escape, not a new line), the ``boat``
section as JSON (every key quoted); coordinates with 9 decimals (0.1 mm).  Comments at
the top say where the course came from and what the user has to add; the source's file
name in them has every character that could end the comment replaced, so no text of the
imported file can add a key to the course file.
"""

from __future__ import annotations

import json
import unicodedata
from collections.abc import Mapping, Sequence
from datetime import datetime
from typing import Any

from sailroute.course.formats.model import ImportedCourse, LatLon
from sailroute.textin import excerpt

__all__ = ["course_yaml"]


def _yaml_json(text: str) -> str:
    """JSON text as YAML reads it: U+2028 and U+2029, which JSON writes as they are but
    YAML takes for line breaks, escaped."""
    return text.replace("\u2028", "\\u2028").replace("\u2029", "\\u2029")


def _q(text: str) -> str:
    """A YAML double-quoted scalar (JSON's string syntax is valid YAML)."""
    return _yaml_json(json.dumps(text, ensure_ascii=False))


def _one_line(text: str) -> str:
    """``text`` with every line break (and other control character) as a space."""
    return "".join(" " if unicodedata.category(c)[0] in "CZ" and c != " " else c for c in text)


def _deg(v: float) -> str:
    """Decimal degrees with 9 decimals, trailing zeros dropped (no exponent)."""
    s = f"{v:.9f}".rstrip("0")
    return s + "0" if s.endswith(".") else s


def _point(p: LatLon) -> str:
    return f"{{lat: {_deg(p[0])}, lon: {_deg(p[1])}}}"


def _ring(points: tuple[LatLon, ...], indent: str) -> list[str]:
    return [f"{indent}- {_point(p)}" for p in points]


def _flow(value: Mapping[str, Any]) -> str:
    """A small mapping in YAML flow style: as JSON, every key and text quoted."""
    return _yaml_json(json.dumps(value, ensure_ascii=False, allow_nan=False))


def course_yaml(
    course: ImportedCourse,
    *,
    source: str,
    fmt: str,
    twd_deg: float,
    tws_kn: float,
    start_time: datetime,
    boat: Mapping[str, Any] | None = None,
    header: Sequence[str] | None = None,
    mark_notes: Mapping[str, str] | None = None,
) -> str:
    """The course file text of an imported course.

    Parameters
    ----------
    course : ImportedCourse
        What the importer read.
    source, fmt : str
        The input file and its format, named in the header comment.
    twd_deg, tws_kn : float
        The uniform wind scenario ``uniform`` [deg from, kn].
    start_time : datetime
        Start signal (timezone-aware), written with its UTC offset.
    boat : mapping, optional
        The ``boat`` section; None writes none, and the header comment says that
        ``sailroute plan`` then uses the default ILCA 7 polar.
    header : sequence of str, optional
        The first comment lines (default: where the course was imported from).
    mark_notes : mapping of str to str, optional
        A comment after the line of each mark named.

    Line breaks in ``header`` and ``mark_notes`` are written as spaces: a comment never
    spills into a key.

    Returns
    -------
    str
        YAML text, ending in a newline.
    """
    notes = mark_notes or {}
    lines = (
        header
        if header is not None
        else [f"Imported by `sailroute course import` from {excerpt(source, 200)} ({fmt})."]
    )
    out = [f"# {_one_line(h)}" for h in lines]
    if boat is None:
        out += [
            "# NO BOAT GIVEN (--boat): add a `boat:` section for the boat you race, e.g.",
            "#   boat: {polar: my-boat.pol}   or   boat: {builtin: ilca6}",
            "# until then `sailroute plan` routes the default ILCA 7 polar.",
        ]
    out += [
        f"# Wind: one uniform scenario ({tws_kn:g} kn from {twd_deg:g} deg); add or replace",
        "# scenarios (docs/course-format.md, `scenarios`).",
    ]
    if course.boundary is not None or course.obstacles:
        out.append("# boundary/obstacles: read into the course; the routers do not use them yet.")
    out += [f"name: {_q(course.name)}", f"start_time: {_q(start_time.isoformat())}", "marks:"]
    out += [
        f"  {_q(n)}: {_point((lat, lon))}" + (f"  # {_one_line(notes[n])}" if n in notes else "")
        for n, lat, lon in course.marks
    ]
    if course.lines:
        out.append("lines:")
        out += [f"  {_q(n)}: [{_q(a)}, {_q(b)}]" for n, a, b in course.lines]
    if course.gates:
        out.append("gates:")
        out += [f"  {_q(n)}: [{_q(a)}, {_q(b)}]" for n, a, b in course.gates]
    out.append("legs:")
    for k, (to, rounding) in enumerate(course.legs):
        items = [f"from: {_q(course.start_from)}"] if k == 0 else []
        items.append(f"to: {_q(to)}")
        if rounding is not None:
            items.append(f"rounding: {rounding}")
        out.append(f"  - {{{', '.join(items)}}}")
    if boat is not None:
        out.append(f"boat: {_flow(boat)}")
    out += ["scenarios:", f"  uniform: {{type: uniform, tws_kn: {tws_kn!r}, twd_deg: {twd_deg!r}}}"]
    if course.boundary is not None:
        out += ["boundary:", "  points:", *_ring(course.boundary, "    ")]
    if course.obstacles:
        out.append("obstacles:")
        for name, ring in course.obstacles:
            out += [f"  - name: {_q(name)}", "    points:", *_ring(ring, "      ")]
    return "\n".join(out) + "\n"
