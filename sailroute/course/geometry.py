"""Course geometry: leg endpoints for the routers, bearings, wind mode, bounding box.

Conventions (``docs/nomenclature.md``): the leg bearing is the compass bearing
θ = atan2(dx, dy) from the leg start to its target (thesis eq. 4.63); the wind
mode of a leg uses Ω = |wrap180(θ − TWD)| with TWD taken at the leg's start point
and start time (eq. 4.64): upwind Ω ≤ 45°, reach 45° < Ω < 135°, downwind Ω ≥ 135°.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.course.model import Course, Gate, Line, Mark
from sailroute.routing.types import Start, Target
from sailroute.units import bearing_deg, wind_speed_direction, wrap180
from sailroute.wind.base import WindField

WindMode = Literal["upwind", "reach", "downwind"]

UPWIND_MAX_DEG = 45.0
"""Ω at or below this is an upwind leg [°]."""
DOWNWIND_MIN_DEG = 135.0
"""Ω at or above this is a downwind leg [°]."""

XY = tuple[float, float]


def feature_centre(feature: Mark | Line | Gate) -> XY:
    """Mark position, or midpoint of a line/gate [m]."""
    if isinstance(feature, Mark):
        return feature.xy
    return feature.midpoint


def target_of(course: Course, i: int) -> Target:
    """The routing target of leg ``i``.

    Parameters
    ----------
    course : Course
        A validated course.
    i : int
        Leg index, 0-based.

    Returns
    -------
    Target
        ``kind="mark"`` with the mark position and rounding side, or
        ``kind="gate"``/``"line"`` with both ends.
    """
    leg = course.legs[i]
    feat = course.feature(leg.to_name)
    if isinstance(feat, Mark):
        return Target("mark", feat.xy, None, leg.rounding, name=leg.to_name)
    kind: Literal["gate", "line"] = "gate" if isinstance(feat, Gate) else "line"
    return Target(kind, feat.a.xy, feat.b.xy, None, name=leg.to_name)


def start_of(course: Course, i: int, previous_end_xy: XY | None = None) -> Start:
    """Where leg ``i`` starts.

    Parameters
    ----------
    course : Course
        A validated course.
    i : int
        Leg index, 0-based.
    previous_end_xy : tuple of float, optional
        Arrival point of leg ``i - 1`` [m] (``LegResult.end_xy``).  Ignored for the
        first leg.  If omitted for a later leg, the nominal point is used: the
        previous mark, or the midpoint of the previous gate/line.

    Returns
    -------
    Start
        First leg: the whole line (``Start(a, b)``) if it starts from a line, else
        the mark position.  Later legs: a point.
    """
    leg = course.legs[i]
    if i == 0:
        feat = course.feature(leg.from_name)
        if isinstance(feat, Mark):
            return Start(feat.xy, None, name=leg.from_name)
        return Start(feat.a.xy, feat.b.xy, name=leg.from_name)
    if previous_end_xy is None:
        previous_end_xy = feature_centre(course.feature(leg.from_name))
    return Start((float(previous_end_xy[0]), float(previous_end_xy[1])), None, name=leg.from_name)


def leg_endpoints(
    course: Course, i: int, previous_end_xy: XY | None = None
) -> tuple[Start, Target]:
    """``(start_of(course, i, previous_end_xy), target_of(course, i))``."""
    return start_of(course, i, previous_end_xy), target_of(course, i)


def xy_bearing_deg(from_xy: XY, to_xy: XY) -> float:
    """Compass bearing θ = atan2(dx, dy) from ``from_xy`` to ``to_xy`` [°, in [0, 360)]."""
    return float(bearing_deg(to_xy[0] - from_xy[0], to_xy[1] - from_xy[1]))


def omega_deg(bearing: ArrayLike, twd: ArrayLike) -> NDArray[np.float64]:
    """Ω = |wrap180(θ − TWD)| [°] in [0, 180]: 0 is dead upwind, 180 dead downwind."""
    return np.abs(wrap180(np.asarray(bearing, float) - np.asarray(twd, float)))


def wind_mode(bearing: float, twd: float) -> WindMode:
    """Wind mode of a leg with bearing ``bearing`` [°] in wind from ``twd`` [°].

    Upwind if Ω ≤ 45°, downwind if Ω ≥ 135°, otherwise reach (thesis eq. 4.64).
    """
    om = float(omega_deg(bearing, twd))
    if om <= UPWIND_MAX_DEG:
        return "upwind"
    if om >= DOWNWIND_MIN_DEG:
        return "downwind"
    return "reach"


def leg_wind_mode(wind: WindField, t: float, from_xy: XY, to_xy: XY) -> WindMode:
    """Wind mode of the leg ``from_xy`` → ``to_xy`` with the wind at ``from_xy`` at time ``t``.

    Parameters
    ----------
    wind : WindField
        Wind field.
    t : float
        Leg start time [epoch s].
    from_xy, to_xy : tuple of float
        Leg start point and target centre [m].
    """
    u, v = wind.sample(t, from_xy[0], from_xy[1])
    _, twd = wind_speed_direction(u, v)
    return wind_mode(xy_bearing_deg(from_xy, to_xy), float(twd))


@dataclass(frozen=True)
class NominalLeg:
    """Straight-line geometry of a leg between nominal points.

    Attributes
    ----------
    index : int
        Leg index.
    from_name, to_name : str
        Names as in :class:`~sailroute.course.model.LegSpec`.
    from_xy, to_xy : tuple of float
        Start point (start-line midpoint, or the previous mark/gate/line centre)
        and target centre [m].
    distance_m : float
        Straight-line length [m].
    bearing_deg : float
        Compass bearing [°].
    """

    index: int
    from_name: str
    to_name: str
    from_xy: XY
    to_xy: XY
    distance_m: float
    bearing_deg: float


def nominal_legs(course: Course) -> tuple[NominalLeg, ...]:
    """Straight-line legs between line midpoints and mark positions (as thesis Fig. 5.6b)."""
    out = []
    for leg in course.legs:
        a = feature_centre(course.feature(leg.from_name))
        b = feature_centre(course.feature(leg.to_name))
        out.append(
            NominalLeg(
                leg.index,
                leg.from_name,
                leg.to_name,
                a,
                b,
                float(math.hypot(b[0] - a[0], b[1] - a[1])),
                xy_bearing_deg(a, b),
            )
        )
    return tuple(out)


def nominal_wind_modes(course: Course, twd_deg: float) -> tuple[WindMode, ...]:
    """Wind mode of each nominal leg in a uniform wind from ``twd_deg`` [°]."""
    return tuple(wind_mode(leg.bearing_deg, twd_deg) for leg in nominal_legs(course))


def course_bbox(course: Course, margin_m: float = 0.0) -> tuple[float, float, float, float]:
    """Bounding box of all marks ``(xmin, xmax, ymin, ymax)`` [m], grown by ``margin_m``.

    The order matches :class:`~sailroute.wind.base.Coverage` and the ``crop_bbox``
    argument of ``wind_from_spec``.
    """
    x = np.array([m.x for m in course.marks.values()])
    y = np.array([m.y for m in course.marks.values()])
    return (
        float(x.min()) - margin_m,
        float(x.max()) + margin_m,
        float(y.min()) - margin_m,
        float(y.max()) + margin_m,
    )


FAR_FROM_COURSE_M: Final = 20_000.0
"""A boat position farther than this from the course area [m] (:func:`course_gap_m`) is
refused by ``sailroute start`` and not re-planned from by ``sailroute live``: another
place, swapped latitude and longitude, or a wrong fix."""


def course_gap_m(course: Course, xy: tuple[float, float]) -> float:
    """Distance [m] from ``xy`` (course frame) to the marks' bounding box
    (:func:`course_bbox`); 0 inside it, NaN for a non-finite position."""
    xmin, xmax, ymin, ymax = course_bbox(course)
    x, y = xy
    if not (math.isfinite(x) and math.isfinite(y)):
        return math.nan
    return math.hypot(max(xmin - x, 0.0, x - xmax), max(ymin - y, 0.0, y - ymax))


def thesis_time_window(
    start_epoch: float,
    *,
    race_duration_s: float = 3600.0,
    before_s: float = 7200.0,
    after_s: float = 10800.0,
    round_s: float = 3600.0,
) -> tuple[float, float]:
    """Time window of wind data needed for a race (thesis eqs. 4.65–4.67).

    ``[floor(start) − before, ceil(start) + after + race_duration]`` with floor/ceil
    to multiples of ``round_s`` (whole hours by default, in UTC).

    Parameters
    ----------
    start_epoch : float
        Start time [epoch s].
    race_duration_s, before_s, after_s, round_s : float
        Expected race duration, lower and upper tolerance and rounding step [s].

    Returns
    -------
    tuple of float
        ``(t0, t1)`` [epoch s].
    """
    lo = math.floor(start_epoch / round_s) * round_s - before_s
    hi = math.ceil(start_epoch / round_s) * round_s + after_s + race_duration_s
    return float(lo), float(hi)


def race_time_window(course: Course) -> tuple[float, float]:
    """``(start, start + time_limit)`` [epoch s]: the time span the wind must cover."""
    t0 = course.start_epoch
    return t0, t0 + course.time_limit_s
