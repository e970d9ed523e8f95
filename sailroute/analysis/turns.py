"""A track's turns between straight boards, and which of them round a mark.

A boat racing round a course sails straight boards joined by turns.  The boards are the
segments of the track simplified by the Douglas-Peucker algorithm (Douglas and Peucker
1973) to ``eps_m``: the polyline through the fewest fixes that stays within ``eps_m`` of
every fix.  Segments sailed for at least ``MIN_BOARD_S`` faster than ``MIN_SPEED_MS`` are
boards; whatever lies between two consecutive boards (a single vertex, or short segments
of a turn that took a while) is one :class:`Turn`: the course of the board before and
after it, the signed sum of the course changes on the way (− = to the left, the sense of
a rounding that leaves the mark to port) and its apex, the fix furthest along the
direction the boat turned away from.

A turn is a **rounding** (:func:`is_rounding`) when it changes the point of sail, which a
tack or a gybe does not: a tack turns ~80-100° from one close-hauled board to the other and
a gybe from one broad reach to the other, and both keep ``|TWA|``; a windward mark turns a
beat into a run, a leeward mark a run into a beat, a reaching mark a beat or a run into a
reach.  The test needs only the wind axis, not which end the wind comes from: ``|TWA|``
measured from either end changes by the same amount.  A gybe between two reaches (the
gybe mark of a triangle) keeps ``|TWA|`` too; it counts when both boards are reaches and
the turn is wider than any downwind gybe.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.segment import gap_limit_s
from sailroute.geo import LocalFrame
from sailroute.track.kinematics import track_xy
from sailroute.track.model import Track
from sailroute.units import bearing_deg, wrap180

__all__ = [
    "EPS_MIN_M",
    "EPS_S",
    "MAX_TURN_S",
    "MIN_BOARD_S",
    "MIN_SPEED_MS",
    "REACH_BAND_DEG",
    "REACH_GYBE_DEG",
    "ROUNDING_TURN_DEG",
    "SAIL_CHANGE_DEG",
    "BoatPath",
    "Turn",
    "boards",
    "find_turns",
    "is_rounding",
    "sail_change_deg",
    "simplify",
    "typical_speed_ms",
]

EPS_S: Final = 1.0
"""The simplification tolerance is the distance sailed in this time at the fleet's
typical speed [s]: 4 m for a dinghy at 8 kn, 15 m for a foiling catamaran at 30 kn."""

EPS_MIN_M: Final = 5.0
"""Smallest simplification tolerance [m] (GPS noise of a tracker is 2-3 m)."""

MIN_BOARD_S: Final = 6.0
"""A simplified segment sailed at least this long is a board [s]."""

MIN_SPEED_MS: Final = 1.0
"""A board is sailed faster than this [m s⁻¹] (slower: drifting, stopped, capsized)."""

MAX_TURN_S: Final = 90.0
"""Two boards further apart in time than this are not joined by a turn [s]."""

ROUNDING_TURN_DEG: Final = 40.0
"""A rounding turns the boat at least this much [°]."""

SAIL_CHANGE_DEG: Final = 35.0
"""A rounding changes ``|TWA|`` by at least this much [°]; a tack or gybe changes it by
the difference of the boat's angles on its two boards (< 15° in a steady wind, < 25°
across a shift)."""

REACH_BAND_DEG: Final = 30.0
"""A board within this of a beam reach (``|TWA|`` in 60-120°) is a reach [°]."""

REACH_GYBE_DEG: Final = 100.0
"""A turn between two reaches wider than this is a gybe mark [°] (a gybe on a run turns
40-90°)."""


@dataclass(frozen=True, eq=False)
class BoatPath:
    """One boat's track in the local frame, with the gaps it must not be bridged across.

    Attributes
    ----------
    name : str
        The boat (the track's name).
    t : ndarray
        Times [epoch s], increasing.
    x, y : ndarray
        Positions [m].
    gap_s : float
        Longest interval between fixes that is bridged [s]
        (:func:`sailroute.analysis.segment.gap_limit_s`).
    """

    name: str
    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    gap_s: float

    @classmethod
    def of_track(cls, track: Track, frame: LocalFrame) -> BoatPath:
        """The path of ``track`` in ``frame``."""
        x, y = track_xy(track, frame)
        t = np.asarray(track.t_s, float)
        return cls(track.name, t, np.asarray(x, float), np.asarray(y, float), gap_limit_s(t))

    def pieces(self) -> list[slice]:
        """The stretches without a gap longer than ``gap_s``."""
        cut = np.flatnonzero(np.diff(self.t) > self.gap_s) + 1
        edges = [0, *cut.tolist(), self.t.size]
        return [slice(a, b) for a, b in itertools.pairwise(edges) if b > a]

    def at(self, tq: NDArray) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Positions at the times ``tq`` [m]: NaN outside the track and inside its gaps."""
        tq = np.asarray(tq, float)
        x = np.interp(tq, self.t, self.x)
        y = np.interp(tq, self.t, self.y)
        k = np.clip(np.searchsorted(self.t, tq), 1, max(self.t.size - 1, 1))
        bad = (tq < self.t[0]) | (tq > self.t[-1])
        if self.t.size > 1:
            bad |= (self.t[k] - self.t[k - 1]) > self.gap_s
        return np.where(bad, np.nan, x), np.where(bad, np.nan, y)

    def speed(self, window_s: float, *, ahead: bool = False) -> NDArray[np.float64]:
        """Speed over ground over ``±window_s / 2`` about each fix, or over the
        ``window_s`` after it (``ahead``) [m s⁻¹]; NaN where the fixes in the window span
        less than half of it (the ends of the track)."""
        t = self.t
        a, b = (0.0, window_s) if ahead else (-0.5 * window_s, 0.5 * window_s)
        lo = np.searchsorted(t, t + a, side="left")
        hi = np.searchsorted(t, t + b, side="right") - 1
        dt = t[hi] - t[lo]
        d = np.hypot(self.x[hi] - self.x[lo], self.y[hi] - self.y[lo])
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(dt >= 0.5 * window_s, d / np.where(dt > 0, dt, 1.0), np.nan)


@dataclass(frozen=True)
class Turn:
    """One turn of a track between two boards.

    Attributes
    ----------
    t : float
        Time at the apex [epoch s].
    x, y : float
        The apex [m]: the fix furthest along ``u_in − u_out`` (``u`` the unit vectors of
        the courses): the tip of a U-turn, the corner of a square one.
    course_in_deg, course_out_deg : float
        Course of the board before and after [°].
    turn_deg : float
        Signed turn [°]: − to the left (a port rounding), + to the right; a turn of more
        than 180° keeps its sense (a bear-away and gybe round a windward mark).
    duration_s : float
        From the end of the board before to the start of the board after [s] (0 when they
        meet at one fix).
    """

    t: float
    x: float
    y: float
    course_in_deg: float
    course_out_deg: float
    turn_deg: float
    duration_s: float

    @property
    def side(self) -> str:
        """``"port"`` for a turn to the left (the mark inside it is left to port)."""
        return "port" if self.turn_deg < 0 else "starboard"

    @property
    def outward(self) -> tuple[float, float]:
        """Unit vector from the inside of the turn to the apex: along ``u_in − u_out``,
        or square to the course for a turn of about 0° or 360°."""
        a, b = math.radians(self.course_in_deg), math.radians(self.course_out_deg)
        ox, oy = math.sin(a) - math.sin(b), math.cos(a) - math.cos(b)
        n = math.hypot(ox, oy)
        if n < 1e-6:  # out = in: the apex lies square to the course, away from the turn
            s = 1.0 if self.turn_deg < 0 else -1.0
            return s * math.cos(a), -s * math.sin(a)
        return ox / n, oy / n


def typical_speed_ms(t: NDArray, x: NDArray, y: NDArray) -> float:
    """Median speed between consecutive fixes [m s⁻¹] (0 for fewer than two fixes)."""
    if t.size < 2:
        return 0.0
    dt = np.diff(t)
    ok = dt > 0
    return float(np.median(np.hypot(np.diff(x)[ok], np.diff(y)[ok]) / dt[ok])) if ok.any() else 0.0


def simplify(x: NDArray, y: NDArray, eps_m: float) -> NDArray[np.int64]:
    """Indices of the fixes the Douglas-Peucker simplification keeps (first and last
    always).

    Parameters
    ----------
    x, y : ndarray
        The polyline [m].
    eps_m : float
        Largest distance of a dropped fix from the simplified polyline [m].
    """
    n = x.size
    if n <= 2:
        return np.arange(n, dtype=np.int64)
    keep = np.zeros(n, dtype=bool)
    keep[0] = keep[-1] = True
    stack = [(0, n - 1)]
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        dx, dy = x[b] - x[a], y[b] - y[a]
        px, py = x[a + 1 : b] - x[a], y[a + 1 : b] - y[a]
        length = math.hypot(dx, dy)
        d = np.abs(px * dy - py * dx) / length if length > 0 else np.hypot(px, py)
        k = int(np.argmax(d))
        if d[k] > eps_m:
            m = a + 1 + k
            keep[m] = True
            stack.extend(((a, m), (m, b)))
    return np.flatnonzero(keep).astype(np.int64)


def boards(
    t: NDArray, x: NDArray, y: NDArray, eps_m: float
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_]]:
    """The simplified track's vertices, each segment's course [°] and whether it is a board.

    Returns
    -------
    vertices : ndarray of int
        Indices of the kept fixes.
    course_deg : ndarray
        Course of each segment ``vertices[k] → vertices[k + 1]`` [°].
    is_board : ndarray of bool
        The segment lasts ``MIN_BOARD_S`` or more at more than ``MIN_SPEED_MS``.
    """
    v = simplify(x, y, eps_m)
    dx, dy = np.diff(x[v]), np.diff(y[v])
    dt = np.diff(t[v])
    with np.errstate(divide="ignore", invalid="ignore"):
        speed = np.where(dt > 0, np.hypot(dx, dy) / np.where(dt > 0, dt, 1.0), 0.0)
    return v, bearing_deg(dx, dy), (dt >= MIN_BOARD_S) & (speed > MIN_SPEED_MS)


def find_turns(
    t: NDArray, x: NDArray, y: NDArray, eps_m: float
) -> tuple[list[Turn], NDArray[np.float64], NDArray[np.float64]]:
    """The turns between consecutive boards of one gap-free stretch of track.

    Parameters
    ----------
    t : ndarray
        Times [epoch s], increasing, without gaps the caller would not bridge.
    x, y : ndarray
        Positions [m].
    eps_m : float
        Simplification tolerance [m] (``max(EPS_MIN_M, EPS_S × typical speed)``).

    Returns
    -------
    turns : list of Turn
        In time order.
    board_course_deg, board_s : ndarray
        Course [°] and duration [s] of each board (for the wind axis).
    """
    if t.size < 3:
        return [], np.zeros(0), np.zeros(0)
    v, course, is_board = boards(t, x, y, eps_m)
    idx = np.flatnonzero(is_board)
    seg_len = np.hypot(np.diff(x[v]), np.diff(y[v]))
    out: list[Turn] = []
    for k1, k2 in itertools.pairwise(idx):
        i, j = int(v[k1 + 1]), int(v[k2])  # end of board k1, start of board k2
        if t[j] - t[i] > MAX_TURN_S:
            continue
        # the course changes along the way, over segments long enough to have a course
        between = [int(k1), *(k for k in range(k1 + 1, k2) if seg_len[k] > 0.5 * eps_m), int(k2)]
        total = float(np.sum(wrap180(np.diff(course[between])))) if len(between) > 1 else 0.0
        cin, cout = float(course[k1]), float(course[k2])
        a, b = math.radians(cin), math.radians(cout)
        wx, wy = math.sin(a) - math.sin(b), math.cos(a) - math.cos(b)
        if i == j or math.hypot(wx, wy) < 1e-6:
            k = (i + j) // 2
        else:
            k = i + int(np.argmax(x[i : j + 1] * wx + y[i : j + 1] * wy))
        out.append(
            Turn(float(t[k]), float(x[k]), float(y[k]), cin, cout, total, float(t[j] - t[i]))
        )
    return out, course[idx], np.diff(t[v])[idx]


def sail_change_deg(turn: Turn, axis_deg: float) -> float:
    """How much the turn changes ``|TWA|`` [°], the wind along ``axis_deg`` (either end)."""
    a_in = abs(float(wrap180(axis_deg - turn.course_in_deg)))
    a_out = abs(float(wrap180(axis_deg - turn.course_out_deg)))
    return abs(a_in - a_out)


def is_rounding(turn: Turn, axis_deg: float) -> bool:
    """True when ``turn`` rounds a mark (see the module notes).

    Parameters
    ----------
    turn : Turn
    axis_deg : float
        The wind axis [°] (either end).
    """
    if abs(turn.turn_deg) < ROUNDING_TURN_DEG:
        return False
    if sail_change_deg(turn, axis_deg) >= SAIL_CHANGE_DEG:
        return True
    off_beam = [
        abs(abs(float(wrap180(axis_deg - c))) - 90.0)
        for c in (turn.course_in_deg, turn.course_out_deg)
    ]
    return max(off_beam) <= REACH_BAND_DEG and abs(turn.turn_deg) >= REACH_GYBE_DEG
