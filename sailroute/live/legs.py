"""Which leg the sailor's boat is on, fix by fix: the rounding rule of ``analyze``.

:class:`LegTracker` is :func:`sailroute.analysis.segment.segment_track` made incremental:
each new fix of the boat makes one straight move from the previous fix, tested against
the crossing geometry of the leg being sailed, built by the same public functions
(:func:`~sailroute.analysis.segment.start_search_geometry`,
:func:`~sailroute.analysis.segment.detection_geometry`,
:func:`~sailroute.routing.geometry.segment_crossing`).  A mark is rounded when the move
crosses the mark's rounding ray forwards, a gate or a line when it crosses it from the
side of the leg's start, and the crossing time is interpolated between the two fixes;
the next leg's geometry is then built from the crossing point, as ``analyze`` builds it
from the previous leg's end.  A boat rounding a mark far from the coach boat therefore
advances the leg when ``analyze`` of its track would end the leg, not when someone comes
within some metres of a mark.

The start: before the gun nothing advances; the first move after the gun that crosses
the start line (or its extension, as ``analyze`` searches it) from the pre-start side
starts the race, and a boat already on the
course side at the gun (over early, or a tracker that began after the start) is
started from where it is.  ``analyze`` also times a boat over early that came back
from its restart; here the restart only moves the start point, which tilts the first
mark's rounding ray by a degree or so.

The coach can set the leg by hand (:meth:`LegTracker.set_leg`, from the page or
``--leg``): the tracker goes on from the start of that leg.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sailroute.analysis.segment import (
    DETECT_M,
    LINE_MARGIN_M,
    Crossing,
    detection_geometry,
    start_search_geometry,
)
from sailroute.course.geometry import leg_endpoints
from sailroute.course.model import Course
from sailroute.routing.geometry import TargetGeometry, segment_crossing, start_centre

XY = tuple[float, float]


@dataclass(frozen=True)
class LegChange:
    """The leg changed.

    Attributes
    ----------
    leg : int
        The leg now sailed (0-based; ``n_legs``: finished).
    crossing : Crossing
        Where and when the previous leg ended (for a start: the start).
    how : {"start", "rounding", "set"}
        Detected start, detected end of a leg, or set by the coach.
    """

    leg: int
    crossing: Crossing
    how: str


class LegTracker:
    """The leg being sailed by one boat, advanced fix by fix (module docstring).

    Not thread-safe: the owner calls it under its lock.

    Parameters
    ----------
    course : Course
        The course (its ``start_time`` is the gun).
    leg : int
        The leg being sailed now (0-based); above 0 the race has started.
    detect_m, line_margin_m : float
        As :func:`~sailroute.analysis.segment.segment_track`.
    """

    def __init__(
        self,
        course: Course,
        leg: int = 0,
        *,
        detect_m: float = DETECT_M,
        line_margin_m: float = LINE_MARGIN_M,
    ) -> None:
        self.course = course
        self.detect_m, self.line_margin_m = detect_m, line_margin_m
        self._start_line = start_search_geometry(course, detect_m)
        self._prev: tuple[float, float, float] | None = None
        self.leg = 0
        self.started = False
        self._from: XY = start_centre(leg_endpoints(course, 0)[0])
        self._geom: TargetGeometry | None = None
        self.set_leg(leg)

    def set_leg(self, leg: int, from_xy: XY | None = None) -> None:
        """Sail ``leg`` (0-based) from ``from_xy`` [m] (default: the leg's start centre)."""
        self.leg = max(0, min(int(leg), self.course.n_legs))
        if self.leg > 0:
            self.started = True
        if self.leg < self.course.n_legs:
            self._from = (
                from_xy
                if from_xy is not None
                else start_centre(leg_endpoints(self.course, self.leg)[0])
            )
            self._geom = detection_geometry(
                self.course, self.leg, self._from, self.detect_m, self.line_margin_m
            )
        else:
            self._geom = None

    @property
    def finished(self) -> bool:
        """The boat crossed the finish."""
        return self.leg >= self.course.n_legs

    def update(self, t: float, x: float, y: float) -> list[LegChange]:
        """Take the boat's next fix (time order; an older one is ignored); the leg changes
        it reveals, in order."""
        prev, self._prev = self._prev, (t, x, y)
        if prev is None:
            if not self.started and t >= self.course.start_epoch and self._course_side(x, y):
                return [self._start(Crossing(t, x, y), "start")]
            return []
        if t <= prev[0]:
            self._prev = prev
            return []
        out: list[LegChange] = []
        t0, x0, y0 = prev
        if not self.started:
            gun = self.course.start_epoch
            if t < gun:
                return []
            if t0 < gun:  # the move spans the gun: where was the boat then?
                f = (gun - t0) / (t - t0)
                t0, x0, y0 = gun, x0 + f * (x - x0), y0 + f * (y - y0)
                if self._course_side(x0, y0):  # over at the gun: started from there
                    out.append(self._start(Crossing(t0, x0, y0), "start"))
            if not self.started:
                hit = self._cross(self._start_line, (t0, x0, y0), (t, x, y))
                if hit is None:
                    return []
                out.append(self._start(hit, "start"))
                t0, x0, y0 = hit.t, hit.x, hit.y
        while self._geom is not None:
            hit = self._cross(self._geom, (t0, x0, y0), (t, x, y))
            if hit is None:
                break
            self.set_leg(self.leg + 1, (hit.x, hit.y))
            out.append(LegChange(self.leg, hit, "rounding"))
            # the rest of the move may end the next leg too (a line just after a mark)
            t0, x0, y0 = hit.t + 1e-6, hit.x, hit.y
        return out

    def _start(self, c: Crossing, how: str) -> LegChange:
        self.started = True
        self.set_leg(0, (c.x, c.y))
        return LegChange(0, c, how)

    def _course_side(self, x: float, y: float) -> bool:
        g = self._start_line
        return (x - g.a[0]) * g.normal[0] + (y - g.a[1]) * g.normal[1] > 0

    @staticmethod
    def _cross(
        geom: TargetGeometry, p: tuple[float, float, float], q: tuple[float, float, float]
    ) -> Crossing | None:
        """Where the move ``p`` -> ``q`` (``(t, x, y)``) crosses ``geom`` forwards."""
        hit, s, _ = segment_crossing(
            np.array([p[1]]), np.array([p[2]]), np.array([q[1]]), np.array([q[2]]), geom
        )
        if not hit[0]:
            return None
        f = float(s[0])
        return Crossing(
            p[0] + f * (q[0] - p[0]), p[1] + f * (q[1] - p[1]), p[2] + f * (q[2] - p[2])
        )
