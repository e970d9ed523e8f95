"""Read a course from a race XML (SailGP, America's Cup race-management ``<Race>`` file).

The file's parts, as the SailGP race-management system writes them:

* ``<RaceStartTime Start="2025-01-19T16:08:00+13:00">``: the start signal;
* ``<Course>``: ``<CompoundMark>`` s, each holding one ``<Mark>`` (a mark) or two (a gate,
  or the start or finish line), with ``Name``, ``TargetLat`` and ``TargetLng``;
* ``<CompoundMarkSequence>``: ``<Corner>`` s in ``SeqID`` order, each naming a compound
  mark and its ``Rounding``: ``Port`` / ``Stbd`` (``Starboard``) for a mark, ``SP`` /
  ``PS`` (pass between: the first mark to starboard and the second to port, or the other
  way) for a gate or line.  The first corner is the start line and the last the finish
  when they have two marks;
* ``<CourseLimit name=...>``: polygons of ``<Limit Lat Lon>`` in ``SeqID`` order; the one
  named ``Boundary`` is the race area, the others obstacles
  (:func:`~sailroute.course.formats.model.classify_rings`).

A gate is named ``"<mark 1>-<mark 2>"`` (``LG1-LG2``), the lines ``start`` and ``finish``.
"""

from __future__ import annotations

import math
from datetime import datetime
from pathlib import Path

from sailroute.course.formats.model import ImportedCourse, Ring, classify_rings
from sailroute.course.formats.xmlnodes import Node, parse_xml
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.routing.types import Side
from sailroute.timeutil import parse_time

__all__ = ["read_race_xml"]

MARK_SIDES: dict[str, Side] = {"port": "port", "stbd": "starboard", "starboard": "starboard"}
PASS_BETWEEN = ("sp", "ps")


def _float(node: Node, key: str, lo: float, hi: float, src: Path) -> float:
    text = node.attrs.get(key)
    try:
        v = float(text if text is not None else "")
    except ValueError:
        raise InputError(
            f"{src}: line {node.line}: <{node.tag}> {key}={text!r}; expected decimal degrees"
        ) from None
    if not (math.isfinite(v) and lo <= v <= hi):
        raise InputError(
            f"{src}: line {node.line}: <{node.tag}> {key}={text!r}; expected a "
            f"number in [{lo:g}, {hi:g}]"
        )
    return v


def _seq(node: Node, src: Path) -> int:
    try:
        return int(node.attrs["SeqID"])
    except (KeyError, ValueError):
        raise InputError(
            f"{src}: line {node.line}: <{node.tag}> SeqID="
            f"{node.attrs.get('SeqID')!r}; expected a whole number"
        ) from None


def _compound_marks(course: Node, src: Path) -> dict[str, list[tuple[str, float, float, int]]]:
    """CompoundMarkID -> its marks ``(name, lat, lon, line)`` in SeqID order."""
    out: dict[str, list[tuple[str, float, float, int]]] = {}
    for cm in course.children:
        if cm.tag != "CompoundMark":
            raise InputError(
                f"{src}: line {cm.line}: <{cm.tag}> in <Course>; expected "
                "<CompoundMark> elements only"
            )
        cid = cm.attrs.get("CompoundMarkID", "")
        if not cid:
            raise InputError(f"{src}: line {cm.line}: <CompoundMark> without CompoundMarkID")
        if cid in out:
            raise InputError(
                f"{src}: line {cm.line}: CompoundMarkID {cid!r} used twice; "
                "expected each compound mark once"
            )
        marks = []
        for m in cm.children:
            if m.tag != "Mark":
                raise InputError(
                    f"{src}: line {m.line}: <{m.tag}> in CompoundMark {cid!r}; "
                    "expected <Mark Name TargetLat TargetLng> elements only"
                )
            name = m.attrs.get("Name", "").strip()
            if not name:
                raise InputError(f"{src}: line {m.line}: <Mark> without a Name")
            lat = _float(m, "TargetLat", -90.0, 90.0, src)
            lon = _float(m, "TargetLng", -180.0, 360.0, src)
            marks.append((_seq(m, src), name, lat, lon, m.line))
        if len(marks) not in (1, 2):
            raise InputError(
                f"{src}: line {cm.line}: CompoundMark {cid!r} holds {len(marks)} "
                "marks; expected 1 (a mark) or 2 (a gate or line)"
            )
        out[cid] = [(n, la, lo, ln) for _, n, la, lo, ln in sorted(marks)]
    return out


def _rings(root: Node, src: Path) -> list[Ring]:
    rings = []
    for lim in root.findall("CourseLimit"):
        pts = sorted(
            (_seq(p, src), _float(p, "Lat", -90.0, 90.0, src), _float(p, "Lon", -180.0, 360.0, src))
            for p in lim.findall("Limit")
        )
        ring = [(la, lo) for _, la, lo in pts]
        if len(ring) > 1 and ring[0] == ring[-1]:
            ring = ring[:-1]
        rings.append(
            Ring(
                lim.attrs.get("name", "") or f"limit{lim.line}",
                tuple(ring),
                f"{src}: line {lim.line}",
            )
        )
    return rings


def read_race_xml(path: str | Path) -> ImportedCourse:
    """Read a course from a SailGP / America's Cup race XML file.

    Parameters
    ----------
    path : str or Path
        The ``<Race>`` XML file.

    Returns
    -------
    ImportedCourse
        Marks, the start and finish lines, gates, legs with rounding sides, the start
        time and the course limits.

    Raises
    ------
    InputError
        Not a ``<Race>`` file, an unknown element in ``<Course>`` or a CompoundMark, a
        corner naming no compound mark, a rounding that does not fit its compound mark,
        one mark name at two places, or a bad limit polygon (each naming the line).
    """
    src = Path(path)
    root = parse_xml(src, "a race XML file (<Race>)")
    if root.tag != "Race":
        raise InputError(
            f"{src}: line {root.line}: root element <{root.tag}>; expected "
            "<Race> (a SailGP / America's Cup race XML)"
        )
    course = root.find("Course")
    sequence = root.find("CompoundMarkSequence")
    if course is None or sequence is None:
        raise InputError(
            f"{src}: line {root.line}: <Race> without <Course> and "
            "<CompoundMarkSequence>; expected both"
        )
    cms = _compound_marks(course, src)
    corners = sorted((_seq(c, src), c) for c in sequence.findall("Corner"))
    if len(corners) < 2:
        raise InputError(
            f"{src}: line {sequence.line}: {len(corners)} corner(s); expected "
            "at least 2 (the start and one mark)"
        )
    marks: dict[str, tuple[float, float, int]] = {}
    all_ll = [(la, lo) for ms in cms.values() for _, la, lo, _ in ms]
    frame = LocalFrame(
        sum(p[0] for p in all_ll) / len(all_ll), sum(p[1] for p in all_ll) / len(all_ll)
    )
    lines: dict[str, tuple[str, str]] = {}
    gates: dict[str, tuple[str, str]] = {}
    seq: list[tuple[str, Side | None]] = []
    for k, (_, corner) in enumerate(corners):
        cid = corner.attrs.get("CompoundMarkID", "")
        if cid not in cms:
            raise InputError(
                f"{src}: line {corner.line}: Corner CompoundMarkID={cid!r}; "
                f"expected one of {', '.join(cms)}"
            )
        ms = cms[cid]
        for name, lat, lon, line in ms:
            if name in marks:
                x, y = frame.to_xy([marks[name][0], lat], [marks[name][1], lon])
                d = float(math.hypot(x[1] - x[0], y[1] - y[0]))
                if d > 1.0:
                    raise InputError(
                        f"{src}: line {line}: mark {name!r} is {d:.1f} m from "
                        f"the mark of that name at line {marks[name][2]}; "
                        "expected one place per name"
                    )
            else:
                marks[name] = (lat, lon, line)
        rounding = corner.attrs.get("Rounding", "").strip().lower()
        if len(ms) == 1:
            if rounding not in MARK_SIDES:
                raise InputError(
                    f"{src}: line {corner.line}: Rounding="
                    f"{corner.attrs.get('Rounding')!r} at the single mark "
                    f"{ms[0][0]!r}; expected Port or Stbd"
                )
            seq.append((ms[0][0], MARK_SIDES[rounding]))
            continue
        if rounding not in PASS_BETWEEN:
            raise InputError(
                f"{src}: line {corner.line}: Rounding="
                f"{corner.attrs.get('Rounding')!r} at the two marks "
                f"{ms[0][0]!r}, {ms[1][0]!r}; expected SP or PS (pass between)"
            )
        pair = (ms[0][0], ms[1][0])
        if k == 0 or k == len(corners) - 1:
            lname = "start" if k == 0 else "finish"
            lines[lname] = pair
            seq.append((lname, None))
        else:
            gname = f"{pair[0]}-{pair[1]}"
            gates[gname] = pair
            seq.append((gname, None))
    rst = root.find("RaceStartTime")
    start = None
    if rst is not None and rst.attrs.get("Start"):
        text = rst.attrs["Start"]
        parse_time(text, where=f"{src}: line {rst.line}: RaceStartTime Start")  # the checks
        start = datetime.fromisoformat(text.replace("Z", "+00:00"))  # keeps the local offset
    race_id = root.child_text("RaceID")
    imported = ImportedCourse(
        name=f"race {race_id}" if race_id else src.stem,
        marks=tuple((n, la, lo) for n, (la, lo, _) in marks.items()),
        lines=tuple((n, a, b) for n, (a, b) in lines.items()),
        gates=tuple((n, a, b) for n, (a, b) in gates.items()),
        start_from=seq[0][0],
        legs=tuple(seq[1:]),
        start_time=start,
    )
    return classify_rings(imported, _rings(root, src))
