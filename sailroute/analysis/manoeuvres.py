"""Tacks and gybes in a sailed track, from the sign of the true wind angle.

A GPS track has no heading; the course over ground stands in for it (no leeway, no
current), so TWA = wrap180(TWD − COG) with TWD from the scenario's wind.  COG is noisy
at low speed and around head-to-wind, so the side (sign of TWA) is:

1. computed from a COG smoothed as a vector mean over ``smooth_s``;
2. carried forward through points slower than ``min_speed_ms`` (a boat in irons
   has no meaningful course);
3. cleaned of runs shorter than ``hold_s`` (a side must be held that long to count:
   a luff head-to-wind and back is not a tack).

Each remaining change of side is a manoeuvre at the first point on the new side: a
**tack** if the mean |TWA| over ``hold_s`` either side is below 90°, else a **gybe**
(``docs/nomenclature.md``) — provided the boat really turned: the mean course over
``2 hold_s`` after the change differs by at least ``min_turn_deg`` from the mean course
over ``2 hold_s`` before it.  Without that rule a run sailed dead downwind (or a beat
head to wind) in a wind a few degrees off the scenario's counted a gybe (tack) at every
wobble of the course across the wind axis.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from sailroute.units import bearing_deg, signed_twa, wrap180

HOLD_S = 5.0
"""A new side must be held this long to count as a manoeuvre [s]."""
SMOOTH_S = 3.0
"""Window of the vector-mean COG smoothing [s]."""
MIN_SPEED_MS = 0.5
"""Below this speed over ground the side is carried forward [m s⁻¹]."""
MIN_TURN_DEG = 30.0
"""A change of side counts as a manoeuvre only if the course turned this much [°]
(a Laser's gybe in a run turns ≥ 30°; a wobble across dead downwind does not)."""


@dataclass(frozen=True)
class SailedManoeuvre:
    """A tack or gybe found in a track.

    Attributes
    ----------
    kind : {"tack", "gybe"}
    t : float
        Time of the first point on the new side [epoch s].
    index : int
        Index of that point in the track arrays.
    """

    kind: Literal["tack", "gybe"]
    t: float
    index: int


def smooth_cog(
    t: NDArray, vx: NDArray, vy: NDArray, window_s: float = SMOOTH_S
) -> NDArray[np.float64]:
    """COG [°] of the velocity averaged over ``±window_s/2`` around each point."""
    t = np.asarray(t, float)
    if window_s <= 0 or t.size < 3:
        return bearing_deg(vx, vy)
    cx = np.concatenate([[0.0], np.cumsum(vx)])
    cy = np.concatenate([[0.0], np.cumsum(vy)])
    lo = np.searchsorted(t, t - 0.5 * window_s, side="left")
    hi = np.searchsorted(t, t + 0.5 * window_s, side="right")
    return bearing_deg(cx[hi] - cx[lo], cy[hi] - cy[lo])


def sides(
    t: NDArray,
    twa_deg: NDArray,
    sog_ms: NDArray,
    *,
    hold_s: float = HOLD_S,
    min_speed_ms: float = MIN_SPEED_MS,
) -> NDArray[np.int8]:
    """Cleaned side (+1 starboard, −1 port) at each point (see the module notes)."""
    s = np.where(np.asarray(twa_deg) >= 0, 1, -1).astype(np.int8)
    slow = np.asarray(sog_ms) < min_speed_ms
    if slow.all():
        return s
    first = int(np.argmin(slow))
    s[:first] = s[first]
    # a slow point keeps the side of the last point before it that was not slow
    last_fast = np.maximum.accumulate(np.where(slow, 0, np.arange(s.size)))
    s = s[np.maximum(last_fast, first)]
    # drop short runs: merge each run shorter than hold_s into the run before it
    for _ in range(3):
        change = np.flatnonzero(s[1:] != s[:-1]) + 1
        starts = np.concatenate([[0], change])
        ends = np.concatenate([change, [s.size]])
        t_end = np.append(t, t[-1])
        merged = False
        for a, b in zip(starts[1:], ends[1:], strict=True):
            dur = (t_end[b] if b < s.size else t[-1]) - t[a]
            if dur < hold_s and b < s.size:
                s[a:b] = s[a - 1]
                merged = True
        if not merged:
            break
    return s


def _mean_course(cog_deg: NDArray, sel: NDArray | slice) -> float:
    """Vector-mean course [°] of the selected points."""
    r = np.radians(cog_deg[sel])
    return float(np.degrees(np.arctan2(np.sin(r).sum(), np.cos(r).sum())))


def find_sailed_manoeuvres(
    t: NDArray,
    twd_deg: NDArray,
    cog_deg: NDArray,
    sog_ms: NDArray,
    *,
    hold_s: float = HOLD_S,
    min_speed_ms: float = MIN_SPEED_MS,
    min_turn_deg: float = MIN_TURN_DEG,
) -> tuple[tuple[SailedManoeuvre, ...], NDArray[np.float64]]:
    """Tacks and gybes of a track.

    Parameters
    ----------
    t : ndarray
        Times [epoch s].
    twd_deg : ndarray
        True wind direction at each point [°, from].
    cog_deg : ndarray
        (Smoothed) course over ground [°].
    sog_ms : ndarray
        Speed over ground [m s⁻¹].
    hold_s, min_speed_ms, min_turn_deg : float
        See the module notes.

    Returns
    -------
    manoeuvres : tuple of SailedManoeuvre
    twa_deg : ndarray
        Signed TWA from COG [°] at each point.
    """
    twa = signed_twa(twd_deg, cog_deg)
    s = sides(t, twa, sog_ms, hold_s=hold_s, min_speed_ms=min_speed_ms)
    cog = np.asarray(cog_deg, float)
    out = []
    # windows by index (t increases): O(log n) per side change, not a pass over the track
    change = np.flatnonzero(s[1:] != s[:-1]) + 1
    tc = t[change]
    b0 = np.searchsorted(t, tc - 2.0 * hold_s, side="left")
    a1 = np.searchsorted(t, tc + 2.0 * hold_s, side="right")
    n0 = np.searchsorted(t, tc - hold_s, side="left")
    n1 = np.searchsorted(t, tc + hold_s, side="right")
    after0 = np.searchsorted(t, tc, side="right")
    for k, i in enumerate(change.tolist()):
        before = slice(int(b0[k]), i)
        after = slice(int(after0[k]), int(a1[k]))
        if before.stop > before.start and after.stop > after.start:
            turn = abs(float(wrap180(_mean_course(cog, after) - _mean_course(cog, before))))
            if turn < min_turn_deg:
                continue
        near = slice(int(n0[k]), int(n1[k]))
        kind: Literal["tack", "gybe"] = "tack" if np.mean(np.abs(twa[near])) < 90.0 else "gybe"
        out.append(SailedManoeuvre(kind, float(t[i]), int(i)))
    return tuple(out), twa
