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

import itertools
import math
from pathlib import Path

from sailroute.course.formats.model import ImportedCourse, Ring, check_name, classify_rings
from sailroute.course.formats.xmlnodes import Node, parse_xml
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.routing.types import Side
from sailroute.timeutil import parse_local_time

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


def _in_seq_order(nodes: list[Node], src: Path, what: str) -> list[Node]:
    """``nodes`` sorted by their ``SeqID``; two of one SeqID are an error (which comes first?)."""
    keyed = sorted(((_seq(n, src), n) for n in nodes), key=lambda sn: sn[0])
    for (a, na), (b, nb) in itertools.pairwise(keyed):
        if a == b:
            raise InputError(
                f"{src}: line {nb.line}: <{nb.tag}> SeqID={b} again (also at line "
                f"{na.line}) in {what}; expected each SeqID once (they give the order)"
            )
    return [n for _, n in keyed]


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
        for m in _in_seq_order(cm.children, src, f"CompoundMark {cid!r}"):
            name = check_name(m.attrs.get("Name", "").strip(), f"{src}: line {m.line}", "Name")
            if not name:
                raise InputError(f"{src}: line {m.line}: <Mark> without a Name")
            lat = _float(m, "TargetLat", -90.0, 90.0, src)
            lon = _float(m, "TargetLng", -180.0, 360.0, src)
            marks.append((name, lat, lon, m.line))
        if len(marks) not in (1, 2):
            raise InputError(
                f"{src}: line {cm.line}: CompoundMark {cid!r} holds {len(marks)} "
                "marks; expected 1 (a mark) or 2 (a gate or line)"
            )
        out[cid] = marks
    if not out:
        raise InputError(
            f"{src}: line {course.line}: <Course> holds no <CompoundMark>; expected the "
            "course's marks, each in a <CompoundMark>"
        )
    return out


def _rings(root: Node, src: Path) -> list[Ring]:
    rings = []
    for lim in root.findall("CourseLimit"):
        name = lim.attrs.get("name", "")
        ring = [
            (_float(p, "Lat", -90.0, 90.0, src), _float(p, "Lon", -180.0, 360.0, src))
            for p in _in_seq_order(lim.findall("Limit"), src, f"CourseLimit {name!r}")
        ]
        if len(ring) > 1 and ring[0] == ring[-1]:
            ring = ring[:-1]
        rings.append(
            Ring(
                name or f"limit{lim.line}",
                tuple(ring),
                f"{src}: line {lim.line}",
                lim.line,
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
    corners = _in_seq_order(sequence.findall("Corner"), src, "<CompoundMarkSequence>")
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
    key_lines: dict[str, int] = {}
    for k, corner in enumerate(corners):
        key_lines["legs[0].from" if k == 0 else f"legs[{k - 1}]"] = corner.line
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
            key_lines.setdefault(f"lines.{lname}", corner.line)
            seq.append((lname, None))
        else:
            gname = f"{pair[0]}-{pair[1]}"
            gates[gname] = pair
            key_lines.setdefault(f"gates.{gname}", corner.line)
            seq.append((gname, None))
    rst = root.find("RaceStartTime")
    start = None
    if rst is not None and rst.attrs.get("Start"):
        text = rst.attrs["Start"]
        start = parse_local_time(text, where=f"{src}: line {rst.line}: RaceStartTime Start")
        key_lines["start_time"] = rst.line
    race_id = check_name(root.child_text("RaceID"), f"{src}: line {root.line}", "RaceID")
    key_lines.update({f"marks.{n}": line for n, (_, _, line) in marks.items()})
    imported = ImportedCourse(
        name=f"race {race_id}" if race_id else src.stem,
        marks=tuple((n, la, lo) for n, (la, lo, _) in marks.items()),
        lines=tuple((n, a, b) for n, (a, b) in lines.items()),
        gates=tuple((n, a, b) for n, (a, b) in gates.items()),
        start_from=seq[0][0],
        legs=tuple(seq[1:]),
        start_time=start,
        key_lines=tuple(key_lines.items()),
    )
    return classify_rings(imported, _rings(root, src))
