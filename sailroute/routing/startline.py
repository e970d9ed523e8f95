"""Start line numbers and the approach to the line: pure functions of geometry, wind and boat.

Conventions (``docs/nomenclature.md``, "Start line"):

* the wind is sampled at the line's midpoint; TWD is the direction it comes from;
* looking upwind, the end on the right is the **starboard end** (where a committee boat
  usually lies), the one on the left the **port end**;
* the **bias** ``b`` is the angle between the line and the line square to the wind
  (perpendicular to TWD), positive when the starboard end lies upwind of the port end:
  with ``β`` the compass bearing from the port end to the starboard end,
  ``b = wrap180(TWD + 90° − β)``;
* the **favoured end** is the end lying upwind (starboard end for ``b > 0``, port end for
  ``b < 0``); none when ``|b|`` is below :data:`SQUARE_TOL_DEG`;
* the **gain** at the favoured end is how much further upwind it lies, measured along the
  wind: ``gain_m = L |sin b|`` for a line of length ``L``, and in time
  ``gain_s = gain_m / VMG_up``, the boat's best upwind VMG in the wind at the gun.

The approach (:func:`line_approach`) is a straight course from a point to the line at the
boat's steady speed in the wind at that point and time (a short pre-start distance: the
wind is taken as constant along it).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.boat.model import BoatModel
from sailroute.errors import InputError, OutOfCoverageError
from sailroute.numerics import sorted_distinct
from sailroute.routing.types import Side
from sailroute.timeutil import iso
from sailroute.units import bearing_deg, heading_unit, signed_twa, wind_speed_direction, wrap180
from sailroute.wind.base import WindField

XY = tuple[float, float]

SQUARE_TOL_DEG = 0.5
"""A line whose bias is smaller than this [°] is square: no end is favoured (wind
directions are seldom known better than this)."""

BIAS_WINDOW_S = 300.0
"""The bias range is taken over this time before the gun [s] (the five-minute sequence)."""

BIAS_STEP_S = 10.0
"""Time step of the bias range [s]."""

HEADING_STEP_DEG = 0.5
"""Heading step of the search for the fastest straight approach [°]."""

EndName = Literal["a", "b"]


def line_bias_deg(a_xy: XY, b_xy: XY, twd_deg: ArrayLike) -> tuple[NDArray[np.float64], bool]:
    """Bias of the line ``a``-``b`` in wind from ``twd_deg``, and which end is starboard.

    Parameters
    ----------
    a_xy, b_xy : tuple of float
        The two ends [m].
    twd_deg : array_like
        Wind direction (from) [°]; any shape.

    Returns
    -------
    bias_deg : ndarray
        ``wrap180(TWD + 90° − β)`` [°] in ``(−180, 180]`` with ``β`` the bearing from the
        port end to the starboard end; positive: the starboard end lies upwind.
    b_is_starboard : bool
        True when ``b`` is the starboard end (the right one looking upwind) in the wind
        of the first element of ``twd_deg``.
    """
    twd = np.asarray(twd_deg, dtype=float)
    dx, dy = b_xy[0] - a_xy[0], b_xy[1] - a_xy[1]
    beta_ab = float(bearing_deg(dx, dy))
    # b is right of a looking upwind when a -> b points within 180° clockwise of TWD
    ref = float(twd.flat[0]) if twd.size else 0.0
    b_is_starboard = bool(wrap180(beta_ab - ref) > 0.0)
    beta = beta_ab if b_is_starboard else beta_ab + 180.0
    bias = wrap180(twd + 90.0 - beta)
    return np.asarray(bias, dtype=float), b_is_starboard


@dataclass(frozen=True)
class StartLineNumbers:
    """The start line in the wind at the gun.

    Attributes
    ----------
    a_name, b_name : str
        Names of the two ends, in the order of the course file.
    a_xy, b_xy : tuple of float
        Their positions [m].
    t_gun : float
        The start signal [epoch s].
    length_m : float
        Line length ``L`` [m].
    tws_ms, twd_deg : float
        Wind at the line's midpoint at the gun [m s⁻¹, ° from].
    bias_deg : float
        Bias at the gun [°]; positive: the starboard end lies upwind (module docstring).
    starboard_end : str
        Name of the end on the right looking upwind (``a_name`` or ``b_name``).
    port_end : str
        Name of the other end.
    favoured_end : str or None
        Name of the end lying upwind; None for a square line (``|bias| <``
        :data:`SQUARE_TOL_DEG`).
    gain_m : float
        ``L |sin b|``: how much further upwind the favoured end lies [m] (0 when square).
    vmg_ms : float
        Best upwind VMG of the boat in the wind at the gun [m s⁻¹].
    gain_s : float
        ``gain_m / vmg_ms`` [s] (inf in a calm).
    bias_min_deg, bias_max_deg : float
        Range of the bias over :data:`BIAS_WINDOW_S` before the gun (the part the wind
        covers) [°]; both equal ``bias_deg`` in a steady wind.
    window_s : float
        Length of the window the range was taken over [s].
    """

    a_name: str
    b_name: str
    a_xy: XY
    b_xy: XY
    t_gun: float
    length_m: float
    tws_ms: float
    twd_deg: float
    bias_deg: float
    starboard_end: str
    port_end: str
    favoured_end: str | None
    gain_m: float
    vmg_ms: float
    gain_s: float
    bias_min_deg: float
    bias_max_deg: float
    window_s: float

    @property
    def favoured_xy(self) -> XY | None:
        """Position of the favoured end [m], None for a square line."""
        if self.favoured_end is None:
            return None
        return self.a_xy if self.favoured_end == self.a_name else self.b_xy

    @property
    def favoured_side(self) -> Side | None:
        """``"starboard"`` or ``"port"``: which end is favoured (None when square)."""
        if self.favoured_end is None:
            return None
        return "starboard" if self.favoured_end == self.starboard_end else "port"


def _wind_at(wind: WindField, t: ArrayLike, xy: XY) -> tuple[NDArray, NDArray]:
    """Speed [m s⁻¹] and direction [° from] of ``wind`` at ``xy`` at times ``t``."""
    t = np.asarray(t, dtype=float)
    u, v = wind.sample(t, np.full(t.shape, xy[0]), np.full(t.shape, xy[1]))
    return wind_speed_direction(u, v)


def start_line_numbers(
    a_xy: XY,
    b_xy: XY,
    wind: WindField,
    boat: BoatModel,
    t_gun: float,
    *,
    names: tuple[str, str] = ("a", "b"),
    window_s: float = BIAS_WINDOW_S,
    step_s: float = BIAS_STEP_S,
) -> StartLineNumbers:
    """Length, bias, favoured end and its gain for the line ``a``-``b`` at the gun.

    Parameters
    ----------
    a_xy, b_xy : tuple of float
        The line's ends [m].
    wind : WindField
        Wind field; sampled at the line's midpoint.
    boat : BoatModel
        Gives the best upwind VMG angle and speed.
    t_gun : float
        Start signal [epoch s].
    names : tuple of str
        Names of the ends ``a`` and ``b`` (mark names).
    window_s, step_s : float
        Window before the gun over which the bias range is taken, and its step [s]; the
        window is cut to the wind's time coverage.

    Returns
    -------
    StartLineNumbers

    Raises
    ------
    InputError
        Both ends at the same place.
    OutOfCoverageError
        The wind does not cover the line's midpoint at the gun.
    """
    mid = (0.5 * (a_xy[0] + b_xy[0]), 0.5 * (a_xy[1] + b_xy[1]))
    tws, twd = (float(v) for v in _wind_at(wind, t_gun, mid))
    length = float(np.hypot(b_xy[0] - a_xy[0], b_xy[1] - a_xy[1]))
    if not length > 0:
        raise InputError(
            f"start line {names[0]} - {names[1]}: both ends are at the same "
            "place; a line needs two distinct marks"
        )
    bias_arr, b_star = line_bias_deg(a_xy, b_xy, twd)
    bias = float(bias_arr)
    starboard, port = (names[1], names[0]) if b_star else (names[0], names[1])
    favoured = None if abs(bias) < SQUARE_TOL_DEG else (starboard if bias > 0 else port)
    gain_m = 0.0 if favoured is None else length * abs(float(np.sin(np.radians(bias))))
    twa_up, _ = boat.vmg_angles_deg(tws)
    vmg = float(boat.steady_speed(tws, twa_up)) * float(np.cos(np.radians(twa_up)))
    gain_s = gain_m / vmg if vmg > 0 else (0.0 if gain_m == 0 else float("inf"))
    t0 = max(t_gun - window_s, float(wind.coverage.t0))
    times = sorted_distinct(np.append(np.arange(t_gun, t0 - 1e-9, -step_s), t0))
    try:
        _, twds = _wind_at(wind, times, mid)
    except OutOfCoverageError:  # a field that covers the gun but not the minutes before
        twds, t0 = np.array([twd]), float(t_gun)
    window = line_bias_deg(a_xy, b_xy, np.append(twd, twds))[0]  # ends named at the gun
    # the bias relative to the gun's, so a range across ±180° stays contiguous
    rel = wrap180(window - bias)
    return StartLineNumbers(
        names[0],
        names[1],
        (float(a_xy[0]), float(a_xy[1])),
        (float(b_xy[0]), float(b_xy[1])),
        float(t_gun),
        length,
        tws,
        twd,
        bias,
        starboard,
        port,
        favoured,
        gain_m,
        vmg,
        gain_s,
        bias + float(rel.min()),
        bias + float(rel.max()),
        float(t_gun - t0),
    )


# --- the approach to the line --------------------------------------------------------


def ray_segment_distance(
    p_xy: XY, heading_deg: ArrayLike, a_xy: XY, b_xy: XY
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Where rays from ``p_xy`` along ``heading_deg`` meet the segment ``a``-``b``.

    Parameters
    ----------
    p_xy : tuple of float
        Ray origin [m].
    heading_deg : array_like
        Compass headings [°].
    a_xy, b_xy : tuple of float
        Segment ends [m].

    Returns
    -------
    distance_m : ndarray
        Distance along each ray to the segment [m]; inf where the ray misses it (or
        runs parallel to it).
    fraction : ndarray
        Where each ray meets the segment, 0 at ``a`` and 1 at ``b``; NaN on a miss.
    """
    ex, ey = heading_unit(heading_deg)
    sx, sy = b_xy[0] - a_xy[0], b_xy[1] - a_xy[1]
    qx, qy = a_xy[0] - p_xy[0], a_xy[1] - p_xy[1]
    den = ex * sy - ey * sx  # cross(e, s)
    with np.errstate(divide="ignore", invalid="ignore"):
        dist = (qx * sy - qy * sx) / den  # cross(q, s) / cross(e, s)
        frac = (qx * ey - qy * ex) / den  # cross(q, e) / cross(e, s)
    tol = 1e-9
    hit = (np.abs(den) > 1e-12) & (dist >= -tol) & (frac >= -tol) & (frac <= 1.0 + tol)
    return (
        np.where(hit, np.maximum(dist, 0.0), np.inf),
        np.where(hit, np.clip(frac, 0.0, 1.0), np.nan),
    )


def distance_to_segment(p_xy: XY, a_xy: XY, b_xy: XY) -> tuple[float, float]:
    """Shortest distance from ``p_xy`` to the segment ``a``-``b`` [m] and the nearest
    point's fraction along it (0 at ``a``, 1 at ``b``)."""
    sx, sy = b_xy[0] - a_xy[0], b_xy[1] - a_xy[1]
    den = sx * sx + sy * sy
    f = 0.0 if den == 0 else ((p_xy[0] - a_xy[0]) * sx + (p_xy[1] - a_xy[1]) * sy) / den
    f = min(max(f, 0.0), 1.0)
    cx, cy = a_xy[0] + f * sx, a_xy[1] + f * sy
    return float(np.hypot(p_xy[0] - cx, p_xy[1] - cy)), float(f)


@dataclass(frozen=True)
class Approach:
    """One straight course from a point to the start line.

    Attributes
    ----------
    label : str
        What it is: ``"close-hauled"``, ``"to <end>"`` or ``"fastest"``.
    tack : {"port", "starboard"}
        Tack sailed (the side the wind comes over).
    heading_deg : float
        Compass heading [°].
    twa_deg : float
        True wind angle, unsigned [°].
    speed_ms : float
        Boat speed [m s⁻¹].
    distance_m : float
        Path length to the line [m]; inf when this heading misses the line.
    time_s : float
        ``distance_m / speed_ms`` [s]; inf when it misses or the boat has no speed.
    fraction : float
        Where it reaches the line, 0 at end ``a`` and 1 at end ``b``; NaN on a miss.
    point_xy : tuple of float
        Where it reaches the line [m] (NaN on a miss).
    """

    label: str
    tack: Side
    heading_deg: float
    twa_deg: float
    speed_ms: float
    distance_m: float
    time_s: float
    fraction: float
    point_xy: XY

    @property
    def reaches(self) -> bool:
        """True when this heading reaches the line in finite time."""
        return bool(np.isfinite(self.time_s))


@dataclass(frozen=True)
class LineApproach:
    """How a boat at a point gets to the start line, and the time it has to burn.

    Attributes
    ----------
    p_xy : tuple of float
        The boat's position [m].
    t : float
        The time it is there [epoch s].
    t_gun : float
        The start signal [epoch s].
    tws_ms, twd_deg : float
        Wind at the boat [m s⁻¹, ° from].
    distance_m : float
        Shortest distance to the line [m].
    course_side : bool
        True when the boat is on the course side of the line (upwind of it: over early).
    close_hauled : tuple of Approach
        Starboard then port tack at the best upwind VMG angle (each may miss the line).
    to_ends : tuple of Approach
        Straight to end ``a`` then end ``b``, on whichever tack that heading is.
    tacks : tuple of Approach
        The fastest straight approach on starboard, then on port.
    fastest : Approach
        The fastest of all straight approaches.
    wind_note : str
        Where the wind was taken elsewhere than at the boat (outside the wind's coverage:
        the nearest covered place and time); empty otherwise.
    """

    p_xy: XY
    t: float
    t_gun: float
    tws_ms: float
    twd_deg: float
    distance_m: float
    course_side: bool
    close_hauled: tuple[Approach, ...]
    to_ends: tuple[Approach, ...]
    tacks: tuple[Approach, ...]
    fastest: Approach
    wind_note: str = ""

    @property
    def time_to_gun_s(self) -> float:
        """Time from ``t`` to the gun [s]."""
        return self.t_gun - self.t

    @property
    def time_to_burn_s(self) -> float:
        """``time_to_gun_s`` minus the fastest time to the line [s]."""
        return self.time_to_gun_s - self.fastest.time_s


def _approaches(
    label: str | list[str],
    p_xy: XY,
    headings: NDArray,
    twd: float,
    tws: float,
    boat: BoatModel,
    a_xy: XY,
    b_xy: XY,
) -> list[Approach]:
    """Straight approaches along ``headings`` (vectorised), one :class:`Approach` each."""
    dist, frac = ray_segment_distance(p_xy, headings, a_xy, b_xy)
    stwa = signed_twa(twd, headings)
    twa = np.abs(stwa)
    speed = np.asarray(boat.steady_speed(tws, twa), dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        time = np.where(np.isfinite(dist) & (speed > 0), dist / speed, np.inf)
    time = np.where(dist == 0.0, 0.0, time)
    labels = [label] * headings.size if isinstance(label, str) else label
    sx, sy = b_xy[0] - a_xy[0], b_xy[1] - a_xy[1]
    out = []
    for k in range(headings.size):
        f = float(frac[k])
        tack: Side = "starboard" if stwa[k] >= 0 else "port"
        out.append(
            Approach(
                labels[k],
                tack,
                float(headings[k] % 360.0),
                float(twa[k]),
                float(speed[k]),
                float(dist[k]),
                float(time[k]),
                f,
                (a_xy[0] + f * sx, a_xy[1] + f * sy),
            )
        )
    return out


def line_approach(
    p_xy: XY,
    t: float,
    a_xy: XY,
    b_xy: XY,
    wind: WindField,
    boat: BoatModel,
    t_gun: float,
    *,
    names: tuple[str, str] = ("a", "b"),
    heading_step_deg: float = HEADING_STEP_DEG,
) -> LineApproach:
    """Distance and time from ``p_xy`` to the line ``a``-``b``, on each tack, and time to burn.

    Every approach is a straight course at the boat's steady speed in the wind at
    ``p_xy`` at time ``t``: close-hauled on each tack (the best upwind VMG angle), straight
    to each end, and the fastest straight course (headings every ``heading_step_deg``
    plus the exact ones to the ends and close-hauled).  A boat already on the line has
    time 0.

    Parameters
    ----------
    p_xy : tuple of float
        The boat [m].
    t : float
        Time it is there [epoch s].
    a_xy, b_xy : tuple of float
        The line's ends [m].
    wind : WindField
        Sampled at ``p_xy`` and ``t``.
    boat : BoatModel
        Steady speeds and the best upwind VMG angle.
    t_gun : float
        The start signal [epoch s].
    names : tuple of str
        Names of the ends (for the labels ``"to <end>"``).
    heading_step_deg : float
        Heading step of the search [°].

    Returns
    -------
    LineApproach
    """
    tws, twd, note = wind_near(wind, t, p_xy)
    dist, _ = distance_to_segment(p_xy, a_xy, b_xy)
    # the course side is upwind of the line: beyond it seen from the pre-start area
    mid = (0.5 * (a_xy[0] + b_xy[0]), 0.5 * (a_xy[1] + b_xy[1]))
    ux, uy = heading_unit(twd)
    sx, sy = b_xy[0] - a_xy[0], b_xy[1] - a_xy[1]
    nx, ny = -sy, sx  # a normal of the line, turned to point upwind
    if nx * ux + ny * uy < 0:
        nx, ny = -nx, -ny
    course_side = bool((p_xy[0] - mid[0]) * nx + (p_xy[1] - mid[1]) * ny > 1e-9 and dist > 0)
    twa_up, _ = boat.vmg_angles_deg(tws)
    close = _approaches(
        ["close-hauled", "close-hauled"],
        p_xy,
        np.array([twd - twa_up, twd + twa_up]),
        twd,
        tws,
        boat,
        a_xy,
        b_xy,
    )
    end_headings = np.array(
        [float(bearing_deg(e[0] - p_xy[0], e[1] - p_xy[1])) for e in (a_xy, b_xy)]
    )
    ends = _approaches(
        [f"to {names[0]}", f"to {names[1]}"], p_xy, end_headings, twd, tws, boat, a_xy, b_xy
    )
    for k, e in enumerate((a_xy, b_xy)):  # straight at an end: exactly its distance
        d = float(np.hypot(e[0] - p_xy[0], e[1] - p_xy[1]))
        sp = ends[k].speed_ms
        ends[k] = Approach(
            ends[k].label,
            ends[k].tack,
            ends[k].heading_deg,
            ends[k].twa_deg,
            sp,
            d,
            d / sp if sp > 0 else (0.0 if d == 0 else float("inf")),
            float(k),
            e,
        )
    grid = np.arange(0.0, 360.0, heading_step_deg)
    scan = _approaches("fastest", p_xy, grid, twd, tws, boat, a_xy, b_xy)
    candidates = [*close, *ends, *scan]
    tacks = []
    for side in ("starboard", "port"):
        on = [c for c in candidates if c.tack == side]
        best = min(on, key=lambda c: c.time_s)
        tacks.append(
            Approach(
                "fastest",
                best.tack,
                best.heading_deg,
                best.twa_deg,
                best.speed_ms,
                best.distance_m,
                best.time_s,
                best.fraction,
                best.point_xy,
            )
        )
    fastest = min(tacks, key=lambda c: c.time_s)
    return LineApproach(
        (float(p_xy[0]), float(p_xy[1])),
        float(t),
        float(t_gun),
        tws,
        twd,
        dist,
        course_side,
        tuple(close),
        tuple(ends),
        tuple(tacks),
        fastest,
        note,
    )


def wind_near(wind: WindField, t: float, xy: XY) -> tuple[float, float, str]:
    """Wind speed [m s⁻¹] and direction [° from] at ``xy`` and ``t``, or at the nearest
    covered place and time, with a note saying so (empty when inside the coverage)."""
    cov = wind.coverage
    tc = min(max(float(t), cov.t0), cov.t1)
    xc = min(max(float(xy[0]), cov.xmin), cov.xmax)
    yc = min(max(float(xy[1]), cov.ymin), cov.ymax)
    notes = []
    if tc != t:
        notes.append(
            f"the wind data cover {iso(cov.t0)} .. {iso(cov.t1)}; the wind at {iso(tc)} is used"
        )
    if (xc, yc) != (float(xy[0]), float(xy[1])):
        gap = float(np.hypot(xc - xy[0], yc - xy[1]))
        notes.append(
            f"the position is {gap:.0f} m outside the wind data's area; the wind at "
            "its nearest edge is used"
        )
    tws, twd = wind_speed_direction(*wind.sample(tc, xc, yc))
    return float(tws), float(twd), "; ".join(notes)


# --- a course's start line -------------------------------------------------------------
