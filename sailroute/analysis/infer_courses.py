"""Steady courses of GPS tracks and the wind axis they imply (steps 1 and 2 of
:mod:`sailroute.analysis.infer_wind`): the points sailed on a board, away from manoeuvres,
roundings and gaps (:func:`_steady_points`); the direction about which their histogram is
most symmetric (:func:`wind_axis_deg`, :func:`axis_near_prior`); the boards' half-separation
(:func:`half_separation_deg`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from sailroute.geo import LocalFrame
from sailroute.track.kinematics import track_xy
from sailroute.track.model import Track
from sailroute.units import bearing_deg, wrap180, wrap360

COG_WINDOW_S: Final = 10.0
"""The course at a point is that of the displacement over this window centred on it [s]."""

TURN_WINDOW_S: Final = 20.0
"""The courses over this window before and after a point tell whether it turns [s]."""

TURN_DEG: Final = 20.0
"""A point whose courses over the ``TURN_WINDOW_S`` before and after differ by more than
this [°] is turning (a manoeuvre)."""

PAD_S: Final = 10.0
"""Points within this of a turning or slow point are rejected too [s]."""

ROUNDING_DEG: Final = 110.0
"""A turn of more than this [°] between the ``TURN_WINDOW_S`` before and after a point is a
mark rounding (a tack turns 80-100°)."""

ROUNDING_PAD_S: Final = 30.0
"""Points within this of a mark rounding are rejected [s]: boats reach in to a mark from
above the layline, luff or bear away round it, and settle on the new leg after it."""

MAX_GAP_S: Final = 5.0
"""A course window that holds a gap in the log longer than this [s] (or 2.5 sampling
intervals, for logs slower than 0.5 Hz) is not used."""

CORR_S: Final = 10.0
"""Correlation time of the course errors [s]: a 1 Hz point counts for 1/10 of an
independent observation in the standard errors."""

AXIS_TIE: Final = 0.1
"""Two wind axes whose symmetry scores lie within this fraction of each other are a tie
that ``prior_twd_deg`` breaks (:func:`axis_near_prior`) [-]."""


def _window_course(
    t: NDArray, x: NDArray, y: NDArray, half: float, turn: float
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Course and speed of the displacement over ``[t - half, t + half]``, and the courses
    over ``[t - turn, t]`` and ``[t, t + turn]`` [°, m s⁻¹, °, °]."""
    xa, ya = np.interp(t - half, t, x), np.interp(t - half, t, y)
    xb, yb = np.interp(t + half, t, x), np.interp(t + half, t, y)
    span = np.minimum(t + half, t[-1]) - np.maximum(t - half, t[0])
    dx, dy = xb - xa, yb - ya
    with np.errstate(invalid="ignore", divide="ignore"):
        sog = np.where(span > 0, np.hypot(dx, dy) / np.where(span > 0, span, 1.0), 0.0)
    xp, yp = np.interp(t - turn, t, x), np.interp(t - turn, t, y)
    xn, yn = np.interp(t + turn, t, x), np.interp(t + turn, t, y)
    return bearing_deg(dx, dy), sog, bearing_deg(x - xp, y - yp), bearing_deg(xn - x, yn - y)


def _near_any(t: NDArray, flag: NDArray, pad: float) -> NDArray[np.bool_]:
    """True where a flagged point lies within ``pad`` seconds."""
    c = np.concatenate([[0], np.cumsum(flag.astype(np.int64))])
    lo = np.searchsorted(t, t - pad, side="left")
    hi = np.searchsorted(t, t + pad, side="right")
    return (c[hi] - c[lo]) > 0


@dataclass(frozen=True)
class _Points:
    """Steady points of all boats (one row per point)."""

    t: NDArray[np.float64]
    cog: NDArray[np.float64]
    sog: NDArray[np.float64]
    boat: NDArray[np.int64]
    weight: NDArray[np.float64]  # 1 / correlation inflation: sampling interval / CORR_S


def _steady_points(
    tracks: Sequence[Track], frame: LocalFrame, t0: float, t1: float, min_speed_ms: float
) -> tuple[_Points, list[str]]:
    ts, cs, ss, bs, ws, notes = [], [], [], [], [], []
    for k, tr in enumerate(tracks):
        m = (tr.t_s >= t0 - COG_WINDOW_S) & (tr.t_s <= t1 + COG_WINDOW_S)
        t = np.asarray(tr.t_s[m], float)
        if t.size < 3:
            notes.append(f"{tr.name or k}: no points in the window")
            continue
        x, y = track_xy(tr.between(t[0], t[-1]), frame)
        half = 0.5 * COG_WINDOW_S
        cog, sog, before, after = _window_course(t, x, y, half, TURN_WINDOW_S)
        turn = np.abs(wrap180(after - before))
        slow = sog < min_speed_ms
        dt = float(np.median(np.diff(t)))
        big_gap = np.concatenate([[False], np.diff(t) > max(MAX_GAP_S, 2.5 * dt)])
        ok = (
            ~_near_any(t, (turn > TURN_DEG) | slow, PAD_S)
            & ~_near_any(t, turn > ROUNDING_DEG, ROUNDING_PAD_S)
            & ~_near_any(t, big_gap, COG_WINDOW_S)
            & (t >= t0)
            & (t <= t1)
        )
        n_ok = int(ok.sum())
        notes.append(
            f"{tr.name or k}: {n_ok} of {int(((t >= t0) & (t <= t1)).sum())} points "
            "steady (not turning, slow or near a gap)"
        )
        ts.append(t[ok])
        cs.append(cog[ok])
        ss.append(sog[ok])
        bs.append(np.full(n_ok, k, dtype=np.int64))
        ws.append(np.full(n_ok, min(1.0, dt / CORR_S)))
    if not ts:
        return _Points(*(np.zeros(0),) * 3, np.zeros(0, np.int64), np.zeros(0)), notes
    t_all = np.concatenate(ts)
    o = np.argsort(t_all, kind="stable")  # time order across boats
    return _Points(
        t_all[o],
        np.concatenate(cs)[o],
        np.concatenate(ss)[o],
        np.concatenate(bs)[o],
        np.concatenate(ws)[o],
    ), notes


def wind_axis_deg(cog_deg: NDArray, weights: NDArray | None = None) -> tuple[float, float]:
    """The direction about which a set of courses is most symmetric.

    Parameters
    ----------
    cog_deg : ndarray
        Courses [°] of steady points.
    weights : ndarray, optional
        Weight of each course.

    Returns
    -------
    axis_deg : float
        The axis [°, in ``[0, 180)``]: the wind comes from ``axis`` or ``axis + 180``.
    strength : float
        Contrast of the symmetry score, ``1 - mean / max`` over all axes, in [0, 1]: 0 for
        courses with no preferred axis.

    Notes
    -----
    The courses are binned in 1° bins and smoothed (Gaussian, 3°); the score of a
    direction θ is ``sum_d H(θ + d) H(θ − d)`` over half-separations ``d`` of 15° to 60°
    (two boards), added for θ and θ + 180° (upwind and downwind boards).
    """
    axis = _axis_scores(cog_deg, weights)
    i = int(np.argmax(axis))
    strength = 1.0 - float(np.mean(axis)) / float(axis[i]) if axis[i] > 0 else 0.0
    return float(i + 0.5) % 180.0, strength


def _axis_scores(cog_deg: NDArray, weights: NDArray | None = None) -> NDArray[np.float64]:
    """Symmetry score of each axis ``i + 0.5`` [°], ``i`` in 0..179 (:func:`wind_axis_deg`)."""
    h = _course_histogram(cog_deg, weights)
    th = np.arange(360)[:, None] + 0.5
    d = np.arange(15, 61)[None, :]
    s = np.sum(h[(th + d).astype(int) % 360] * h[(th - d).astype(int) % 360], axis=1)
    return np.asarray(s[:180] + s[180:], dtype=float)


def axis_near_prior(
    cog_deg: NDArray, prior_twd_deg: float, weights: NDArray | None = None, tie: float = AXIS_TIE
) -> float:
    """The wind axis [°, in ``[0, 180)``] when the courses leave several nearly tied.

    Among the local maxima of the symmetry score within ``tie`` of the best (a club
    course's reaches make a second axis), the one closest to ``prior_twd_deg`` (either
    end); the best alone when none ties with it.
    """
    sc = _axis_scores(cog_deg, weights)
    best = float(sc.max())
    if best <= 0.0:
        return float(np.argmax(sc) + 0.5) % 180.0
    peak = (sc >= np.roll(sc, 1)) & (sc >= np.roll(sc, -1)) & (sc >= (1.0 - tie) * best)
    axes = np.nonzero(peak)[0] + 0.5
    off = np.abs(wrap180(axes - prior_twd_deg))
    off = np.minimum(off, 180.0 - off)
    return float(axes[int(np.argmin(off))]) % 180.0


def _course_histogram(cog_deg: NDArray, weights: NDArray | None = None) -> NDArray[np.float64]:
    """Courses in 1° bins (bin i holds [i, i + 1)), smoothed with a 3° Gaussian."""
    h = np.bincount(
        np.floor(wrap360(cog_deg)).astype(int) % 360, weights=weights, minlength=360
    ).astype(float)
    k = np.arange(-10, 11)
    g = np.exp(-0.5 * (k / 3.0) ** 2)
    return np.asarray(
        np.sum([np.roll(h, s) * w for s, w in zip(k, g, strict=True)], axis=0), dtype=float
    )


def half_separation_deg(cog_deg: NDArray, end_deg: float, weights: NDArray | None = None) -> float:
    """Mean half-separation [°] of the courses symmetric about the direction ``end_deg``.

    The score-weighted mean of ``d`` in 0..70° of ``sum H(end + d) H(end − d)``: about the
    upwind end of the wind axis it is the tacking half-angle (35-55°), about the downwind
    end the angle of the downwind boards off dead downwind (0° for a boat that runs, 20-35°
    for one that gybes through a clear angle).
    """
    h = _course_histogram(cog_deg, weights)
    d = np.arange(0, 71)
    e = float(end_deg) % 360.0
    i = np.floor(e).astype(int)
    # bins i + d and i - d are symmetric about i + 0.5; the end lies within half a bin
    s = h[(i + d) % 360] * h[(i - d) % 360]
    return float(np.sum(d * s) / np.sum(s)) if np.sum(s) > 0 else float("nan")
