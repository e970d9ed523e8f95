"""Course templates: lay a windward-leeward or trapezoid course from the wind and a leg length.

Race committees set courses relative to the wind, so a template takes the
direction the course is set for (``twd_deg``), the windward leg length and the
course centre, and returns mark positions and the leg sequence.  The geometry
(documented with a figure in ``docs/course-format.md``) follows the World Sailing
*Race Management Manual* (2018, §8.3 windward-leeward, §8.12 course naming) and the
ILCA championship sailing instructions (courses ``L``, ``I`` and ``O``):

Unit vectors, with ``û`` pointing upwind (towards where the wind comes from) and
``l̂`` to the left when looking upwind (``l̂ = û`` turned 90° anticlockwise)::

    û = (sin TWD, cos TWD)        l̂ = (−cos TWD, sin TWD)

* mark ``1`` (windward) at ``centre + L/2 û``; leeward gate ``4s``/``4p`` centred at
  ``centre − L/2 û``, its marks ``gate_width/2`` apart on either side, ``4s`` on the
  left and ``4p`` on the right looking upwind, so boats running down leave ``4p`` to
  port and ``4s`` to starboard;
* start line perpendicular to the wind, centred ``start_offset_m`` downwind of the
  leeward gate: ``start_pin`` on the left, ``start_boat`` (committee boat) on the
  right looking upwind;
* windward-leeward finish: ``leeward`` (default) puts a shorter finish line on the
  start line's centre ("the start line, reduced in length, becomes the finish line");
  ``windward`` puts it ``finish_offset_m`` upwind of mark 1 and the last leg is a beat;
* trapezoid: mark ``2`` is reached from ``1`` on a reach to the left (all marks are
  rounded to port); ``reach_angle_deg`` is the interior angle at mark 1 between the
  run 1→4 and the reach 1→2, so the reach is sailed at TWA ``180° − reach_angle_deg``
  (60° gives a broad reach at TWA 120°).  Gate ``3s``/``3p`` lies dead downwind of
  ``2`` at the level of gate 4 (both leeward gates on one line across the wind); the
  finish line is ``finish_reach_m`` to the right of ``3p`` (a beam reach towards the
  inner loop), oriented along the wind.

Sequences (``laps`` = number of beats, as in the course codes ``L2``, ``I2``, ``O2``)::

    windward-leeward, leeward finish   Start-1-(4s/4p-1)×(laps-1)-Finish
    windward-leeward, windward finish  Start-1-(4s/4p-1)×(laps-2)-4s/4p-Finish
    trapezoid inner                    Start-1-(4s/4p-1)×(laps-1)-2-3p-Finish
    trapezoid outer                    Start-1-2-(3s/3p-2)×(laps-1)-3p-Finish
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

from sailroute.errors import InputError

XY = tuple[float, float]


@dataclass(frozen=True)
class LayoutLeg:
    """One leg of a generated layout: target name and rounding side (marks only)."""

    to: str
    rounding: Literal["port", "starboard"] | None = None


@dataclass(frozen=True)
class CourseLayout:
    """Marks, lines, gates and legs of a generated course, in local metres.

    Attributes
    ----------
    marks : dict of str to tuple of float
        Mark name → ``(x, y)`` [m].
    lines, gates : dict of str to tuple of str
        Name → the two mark names.
    start_from : str
        Where the first leg starts (the start line's name).
    legs : tuple of LayoutLeg
        Legs in order.
    """

    marks: dict[str, XY] = field(default_factory=dict)
    lines: dict[str, tuple[str, str]] = field(default_factory=dict)
    gates: dict[str, tuple[str, str]] = field(default_factory=dict)
    start_from: str = "start"
    legs: tuple[LayoutLeg, ...] = ()


def _axes(twd_deg: float) -> tuple[XY, XY]:
    t = math.radians(twd_deg)
    up = (math.sin(t), math.cos(t))
    left = (-up[1], up[0])
    return up, left


def _at(p: XY, *terms: tuple[float, XY]) -> XY:
    x, y = p
    for k, (dx, dy) in terms:
        x += k * dx
        y += k * dy
    return (x, y)


def _pair(
    into: dict[str, tuple[str, str]],
    layout: CourseLayout,
    name: str,
    ends: tuple[str, str],
    centre: XY,
    length_m: float,
    axis: XY,
) -> None:
    """Put marks ``ends`` at ``centre ± length_m / 2 · axis`` and register them as ``name``."""
    layout.marks[ends[0]] = _at(centre, (length_m / 2, axis))
    layout.marks[ends[1]] = _at(centre, (-length_m / 2, axis))
    into[name] = ends


def _check_positive(**values: float) -> None:
    bad = [f"{k} must be > 0, got {v!r}" for k, v in values.items() if not v > 0]
    if bad:
        raise InputError("course template: " + "; ".join(bad))


def _leeward_end(
    layout: CourseLayout,
    centre: XY,
    up: XY,
    left: XY,
    leg_length_m: float,
    gate_width_m: float,
    start_line_length_m: float,
    start_offset_m: float,
) -> None:
    """Add mark 1, gate 4 and the start line (shared by both templates)."""
    m1 = _at(centre, (leg_length_m / 2, up))
    g4 = _at(centre, (-leg_length_m / 2, up))
    layout.marks["1"] = m1
    _pair(layout.gates, layout, "4", ("4s", "4p"), g4, gate_width_m, left)
    st = _at(g4, (-start_offset_m, up))
    _pair(layout.lines, layout, "start", ("start_pin", "start_boat"), st, start_line_length_m, left)


def windward_leeward(
    centre_xy: XY,
    twd_deg: float,
    leg_length_m: float,
    laps: int = 2,
    *,
    gate_width_m: float = 50.0,
    start_line_length_m: float = 150.0,
    start_offset_m: float = 50.0,
    finish: Literal["leeward", "windward"] = "leeward",
    finish_line_length_m: float = 60.0,
    finish_offset_m: float = 50.0,
) -> CourseLayout:
    """Windward-leeward course with a leeward gate (course ``L<laps>``).

    Parameters
    ----------
    centre_xy : tuple of float
        Midpoint between mark 1 and the leeward gate centre [m].
    twd_deg : float
        Wind direction the course is set for [°, from].
    leg_length_m : float
        Distance from the gate centre to mark 1 [m].
    laps : int
        Number of beats (windward legs), ≥ 1 (≥ 2 with a windward finish).
    gate_width_m : float
        Distance between ``4s`` and ``4p`` [m] (about 10 hull lengths).
    start_line_length_m : float
        Start line length [m].
    start_offset_m : float
        Distance of the start line downwind of the gate [m].
    finish : {"leeward", "windward"}
        Finish after the last run on a shortened start line, or after the last
        beat on a line ``finish_offset_m`` upwind of mark 1.
    finish_line_length_m, finish_offset_m : float
        Finish line length and (windward finish) its offset beyond mark 1 [m].

    Returns
    -------
    CourseLayout
    """
    _check_positive(
        leg_length_m=leg_length_m,
        gate_width_m=gate_width_m,
        start_line_length_m=start_line_length_m,
        finish_line_length_m=finish_line_length_m,
    )
    if finish not in ("leeward", "windward"):
        raise InputError(f"course template: finish must be 'leeward' or 'windward', got {finish!r}")
    min_laps = 2 if finish == "windward" else 1
    if int(laps) != laps or laps < min_laps:
        raise InputError(
            f"course template: laps must be an integer >= {min_laps} with a {finish} finish, "
            f"got {laps!r}"
        )
    up, left = _axes(twd_deg)
    layout = CourseLayout()
    _leeward_end(
        layout,
        centre_xy,
        up,
        left,
        leg_length_m,
        gate_width_m,
        start_line_length_m,
        start_offset_m,
    )
    if finish == "leeward":
        fc = _at(centre_xy, (-leg_length_m / 2 - start_offset_m, up))
    else:
        fc = _at(centre_xy, (leg_length_m / 2 + finish_offset_m, up))
    _pair(
        layout.lines,
        layout,
        "finish",
        ("finish_pin", "finish_boat"),
        fc,
        finish_line_length_m,
        left,
    )
    legs = [LayoutLeg("1", "port")]
    n_gate_to_1 = laps - 1 if finish == "leeward" else laps - 2
    for _ in range(n_gate_to_1):
        legs += [LayoutLeg("4"), LayoutLeg("1", "port")]
    if finish == "windward":
        legs.append(LayoutLeg("4"))
    legs.append(LayoutLeg("finish"))
    return CourseLayout(layout.marks, layout.lines, layout.gates, "start", tuple(legs))


def trapezoid(
    centre_xy: XY,
    twd_deg: float,
    leg_length_m: float,
    laps: int = 2,
    *,
    loop: Literal["inner", "outer"] = "outer",
    reach_angle_deg: float = 60.0,
    reach_length_m: float | None = None,
    gate_width_m: float = 50.0,
    start_line_length_m: float = 150.0,
    start_offset_m: float = 50.0,
    finish_line_length_m: float = 60.0,
    finish_reach_m: float | None = None,
) -> CourseLayout:
    """Trapezoid course, inner (``I<laps>``) or outer (``O<laps>``) loop.

    Parameters
    ----------
    centre_xy : tuple of float
        Midpoint between mark 1 and the centre of gate 4 [m].
    twd_deg : float
        Wind direction the course is set for [°, from].
    leg_length_m : float
        Windward leg length, gate 4 to mark 1 [m].
    laps : int
        Number of beats, ≥ 1.
    loop : {"inner", "outer"}
        Inner loop: beats between gate 4 and mark 1, then 1-2-3p-finish.  Outer
        loop: 1-2, then beats between gate 3 and mark 2, then 3p-finish.
    reach_angle_deg : float
        Interior angle at mark 1 between the leg to gate 4 and the reach to mark 2
        [°], in (0, 180); the reach is sailed at TWA ``180 − reach_angle_deg``.
    reach_length_m : float, optional
        Length of the reach 1→2 [m]; default two thirds of ``leg_length_m``.
    gate_width_m, start_line_length_m, start_offset_m, finish_line_length_m : float
        As in :func:`windward_leeward` [m].
    finish_reach_m : float, optional
        Distance from gate 3 centre to the finish line centre, at right angles to
        the wind towards the inner loop [m]; default a quarter of ``leg_length_m``.

    Returns
    -------
    CourseLayout
    """
    reach_length_m = 2.0 * leg_length_m / 3.0 if reach_length_m is None else reach_length_m
    finish_reach_m = leg_length_m / 4.0 if finish_reach_m is None else finish_reach_m
    _check_positive(
        leg_length_m=leg_length_m,
        gate_width_m=gate_width_m,
        reach_length_m=reach_length_m,
        start_line_length_m=start_line_length_m,
        finish_line_length_m=finish_line_length_m,
        finish_reach_m=finish_reach_m,
    )
    if loop not in ("inner", "outer"):
        raise InputError(f"course template: loop must be 'inner' or 'outer', got {loop!r}")
    if not 0.0 < reach_angle_deg < 180.0:
        raise InputError(
            f"course template: reach_angle_deg must be in (0, 180), got {reach_angle_deg!r}"
        )
    if int(laps) != laps or laps < 1:
        raise InputError(f"course template: laps must be an integer >= 1, got {laps!r}")
    up, left = _axes(twd_deg)
    layout = CourseLayout()
    _leeward_end(
        layout,
        centre_xy,
        up,
        left,
        leg_length_m,
        gate_width_m,
        start_line_length_m,
        start_offset_m,
    )
    a = math.radians(reach_angle_deg)
    m1 = layout.marks["1"]
    # reach 1->2: reach_angle from the downwind direction (-up), turned towards the left
    m2 = _at(m1, (-reach_length_m * math.cos(a), up), (reach_length_m * math.sin(a), left))
    layout.marks["2"] = m2
    # gate 3 dead downwind of 2, level with gate 4
    drop = leg_length_m - reach_length_m * math.cos(a)
    if drop <= gate_width_m:
        raise InputError(
            "course template: mark 2 lies too close to the leeward gates "
            f"(run 2->3 would be {drop:.0f} m); use a smaller reach_length_m or reach_angle_deg"
        )
    g3 = _at(m2, (-drop, up))
    _pair(layout.gates, layout, "3", ("3s", "3p"), g3, gate_width_m, left)
    fc = _at(g3, (-finish_reach_m, left))
    _pair(
        layout.lines, layout, "finish", ("finish_pin", "finish_boat"), fc, finish_line_length_m, up
    )
    legs = [LayoutLeg("1", "port")]
    if loop == "inner":
        for _ in range(laps - 1):
            legs += [LayoutLeg("4"), LayoutLeg("1", "port")]
        legs += [LayoutLeg("2", "port"), LayoutLeg("3p", "port"), LayoutLeg("finish")]
    else:
        legs.append(LayoutLeg("2", "port"))
        for _ in range(laps - 1):
            legs += [LayoutLeg("3"), LayoutLeg("2", "port")]
        legs += [LayoutLeg("3p", "port"), LayoutLeg("finish")]
    return CourseLayout(layout.marks, layout.lines, layout.gates, "start", tuple(legs))


TEMPLATES: dict[str, Callable[..., CourseLayout]] = {
    "windward-leeward": windward_leeward,
    "trapezoid": trapezoid,
}
"""Template name (the ``template.type`` key) → builder."""
