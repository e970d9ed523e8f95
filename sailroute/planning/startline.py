"""The start line and the laylines of a course: the routing layer's functions applied to a
:class:`~sailroute.course.model.Course` and its routed legs.

The maths is :mod:`sailroute.routing.startline` and :mod:`sailroute.routing.laylines`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from sailroute.boat.model import BoatModel
from sailroute.course.model import Course, Gate, Line, Mark
from sailroute.errors import InputError
from sailroute.routing.laylines import (
    N_STEPS,
    Layline,
    LaylineKind,
    leg_layline_kind,
    trace_many,
)
from sailroute.routing.startline import StartLineNumbers, start_line_numbers
from sailroute.routing.types import LegResult
from sailroute.wind.base import WindField

__all__ = ["course_laylines", "course_start_line_numbers", "require_start_line", "start_line_of"]


def course_laylines(
    course: Course,
    legs: Sequence[tuple[str | None, LegResult]],
    wind: WindField,
    boat: BoatModel,
    *,
    n_steps: int = N_STEPS,
) -> tuple[tuple[Layline, ...], ...]:
    """Laylines of every leg of a routed course.

    Parameters
    ----------
    course : Course
        The course.
    legs : sequence of (str or None, LegResult)
        Each leg's wind mode (``"upwind"``, ``"reach"``, ``"downwind"`` or None) and its
        routed result, in order.
    wind : WindField
        The wind the course was routed in.
    boat : BoatModel
        The boat it was routed with.
    n_steps : int
        Integration steps per layline.

    Returns
    -------
    tuple of tuple of Layline
        One tuple per leg: tack laylines to the mark (or each gate mark) of an upwind
        leg, gybe laylines for a downwind leg, none for a reach or a leg to a line.
        Each is about as long as the leg (its start point to its target).
    """
    specs: list[tuple[str, tuple[float, float], float, float]] = []
    kinds: list[LaylineKind] = []
    counts: list[int] = []
    for spec, (mode, res) in zip(course.legs, legs, strict=True):
        kind = leg_layline_kind(mode)
        feat = course.feature(spec.to_name)
        ends = [feat] if isinstance(feat, Mark) else [feat.a, feat.b]
        cx = float(np.mean([m.x for m in ends]))
        cy = float(np.mean([m.y for m in ends]))
        length = math.hypot(cx - res.start_xy[0], cy - res.start_xy[1])
        if kind is None or spec.kind == "line" or length <= 0:
            counts.append(0)
            continue
        specs += [(m.name, m.xy, float(res.t_end), length) for m in ends]
        kinds += [kind] * len(ends)
        counts.append(2 * len(ends))
    lines = trace_many(specs, kinds, wind, boat, n_steps) if specs else ()
    bounds = np.cumsum([0, *counts])
    return tuple(tuple(lines[bounds[i] : bounds[i + 1]]) for i in range(len(counts)))


def start_line_of(course: Course) -> Line | None:
    """The line the first leg starts from, or None when it starts at a mark."""
    if not course.legs:
        return None
    feat = course.feature(course.legs[0].from_name)
    return feat if isinstance(feat, Line) and not isinstance(feat, Gate) else None


def require_start_line(course: Course) -> Line:
    """The course's start line.

    Raises
    ------
    InputError
        The first leg starts at a mark (or a gate), not a line.
    """
    line = start_line_of(course)
    if line is None:
        first = course.legs[0].from_name if course.legs else "?"
        raise InputError(
            f"{course.where('legs[0].from')}: the first leg starts from {first!r}, which is "
            "not a line; the start numbers need a start line: add one under `lines` "
            "(e.g. start: [pin, committee]) and start the first leg from it"
        )
    return line


def course_start_line_numbers(
    course: Course, wind: WindField, boat: BoatModel
) -> StartLineNumbers | None:
    """:func:`start_line_numbers` of the course's start line at its start time; None when
    the first leg starts at a mark."""
    line = start_line_of(course)
    if line is None:
        return None
    return start_line_numbers(
        line.a.xy, line.b.xy, wind, boat, course.start_epoch, names=(line.a.name, line.b.name)
    )
