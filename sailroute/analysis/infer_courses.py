"""Steady courses of GPS tracks and the wind axis they imply (steps 1 and 2 of
:mod:`sailroute.analysis.infer_wind`): the points sailed on a board, away from manoeuvres,
roundings and gaps, the boards they make and the turns between them, with the courses
before and after each (:func:`_steady_points`); the direction about which the courses'
histogram is most symmetric (:func:`wind_axis_deg`, :func:`axis_near_prior`); the boards'
half-separation (:func:`half_separation_deg`)."""

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

BOARD_END_S: Final = 20.0
"""A turn's courses before and after are the mean courses of this much of the boards on
either side [s]."""

ROUNDING_S: Final = 12.0
"""A turn whose peak lies within the distance a boat sails in this time [s] of a mark (at
``REF_SPEED_MS``, or the boat's speed when faster) is a rounding, not a tack or a gybe."""

REF_SPEED_MS: Final = 5.0
"""The time windows above are those of a boat of this median speed or slower [m s⁻¹];
a faster boat's are shorter in proportion (:func:`_time_scale`)."""

MIN_TIME_SCALE: Final = 0.3
"""The windows never shrink below this share of their length [-]."""

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
    """Steady points of all boats (one row per point, in time order)."""

    t: NDArray[np.float64]
    cog: NDArray[np.float64]
    sog: NDArray[np.float64]
    boat: NDArray[np.int64]
    weight: NDArray[np.float64]  # 1 / correlation inflation: sampling interval / CORR_S
    board: NDArray[np.int64]  # index into _Boards


@dataclass(frozen=True)
class _Turns:
    """Turns of all boats (tacks, gybes, roundings, course changes), one row each.

    ``mid`` is the direction the bow passed through half-way round (the course before
    plus half the signed turn): a tack's points into the wind, a gybe's away from it.
    """

    t: NDArray[np.float64]
    boat: NDArray[np.int64]
    c_in: NDArray[np.float64]  # course over TURN_WINDOW_S before the turn [°]
    c_out: NDArray[np.float64]  # and after it [°]
    mid: NDArray[np.float64]  # [°]
    angle: NDArray[np.float64]  # |turn| [°]
    x: NDArray[np.float64]  # where [m]
    y: NDArray[np.float64]
    near_m: NDArray[np.float64]  # distance the boat sails in ROUNDING_S [m]
    paired: NDArray[np.bool_]  # steady boards on both sides (a tack or gybe must have)


@dataclass(frozen=True)
class _Boards:
    """Boards: one boat's steady points between two turns (or a gap, or a slow stretch)."""

    boat: NDArray[np.int64]
    t_start: NDArray[np.float64]
    t_end: NDArray[np.float64]
    turn_before: NDArray[np.int64]  # index into _Turns of the turn that began it, or -1
    turn_after: NDArray[np.int64]  # of the turn that ended it, or -1


def _runs(flag: NDArray) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """First and last index of each run of True in ``flag``."""
    f = np.concatenate([[False], flag.astype(bool), [False]])
    d = np.diff(f.astype(np.int8))
    return np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1


def _boat_turns(
    t: NDArray, turn: NDArray, before: NDArray, after: NDArray, gap: NDArray, join_s: float
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    """Turns of one boat: the index of each turn's peak and the courses before/after it.

    A turn is a run of points whose courses over ``TURN_WINDOW_S`` before and after differ
    by more than ``TURN_DEG``, not broken by a gap; runs less than ``join_s`` apart are
    one turn (GPS noise breaks a tack into pieces); its courses are those of the windows
    before its first and after its last point.
    """
    a, b = _runs((turn > TURN_DEG) & ~gap)
    if a.size == 0:
        return np.zeros(0, np.int64), np.zeros(0), np.zeros(0)
    split = np.concatenate([[True], (t[a[1:]] - t[b[:-1]] > join_s) | gap[a[1:]]])
    first = np.flatnonzero(split)
    last = np.concatenate([first[1:], [a.size]]) - 1
    a, b = a[first], b[last]
    peak = np.array([i + int(np.argmax(turn[i : j + 1])) for i, j in zip(a, b, strict=True)])
    return peak.astype(np.int64), before[a], after[b]


@dataclass(frozen=True)
class _BoatPart:
    """One boat's steady points, boards and turns (indices local to the boat)."""

    idx: NDArray[np.int64]  # steady points: indices into the boat's samples
    board: NDArray[np.int64]  # per steady point: its board
    first: NDArray[np.int64]  # per board: sample index of its first and last point
    last: NDArray[np.int64]
    turn_before: NDArray[np.int64]  # per board: its turn, or -1
    turn_after: NDArray[np.int64]
    peak: NDArray[np.int64]  # per turn: sample index of its peak
    c_in: NDArray[np.float64]  # per turn: courses before and after [°]
    c_out: NDArray[np.float64]
    paired: NDArray[np.bool_]  # per turn: steady boards on both sides


def _boat_part(
    t: NDArray,
    cog: NDArray,
    ok: NDArray,
    peak: NDArray,
    c_in: NDArray,
    c_out: NDArray,
    scale: float,
) -> _BoatPart:
    """Boards (runs of steady points with no rejected point between) and the turns that
    begin and end them.  A turn's courses are those of ``BOARD_END_S`` of the boards on
    either side where they come within ``TURN_WINDOW_S`` of it (the windows about the
    turn hold part of the turn itself)."""
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        z = np.zeros(0, np.int64)
        return _BoatPart(idx, z, z, z, z, z, peak, c_in, c_out, np.zeros(peak.size, bool))
    new = np.concatenate([[True], np.diff(idx) > 1])
    board = np.cumsum(new) - 1
    first, last = idx[new], idx[np.concatenate([new[1:], [True]])]
    prev_end = np.concatenate([[-1], last[:-1]])
    next_start = np.concatenate([first[1:], [t.size]])
    nt = peak.size
    j_b = np.searchsorted(peak, first, side="left") - 1
    j_a = np.searchsorted(peak, last, side="right")
    has_b = (j_b >= 0) & (peak[np.clip(j_b, 0, max(nt - 1, 0))] > prev_end) if nt else j_b < -1
    has_a = (j_a < nt) & (peak[np.clip(j_a, 0, max(nt - 1, 0))] < next_start) if nt else j_a < -1
    tb, ta = np.where(has_b, j_b, -1), np.where(has_a, j_a, -1)
    c_in, c_out = c_in.copy(), c_out.copy()
    n_in, n_out = np.zeros(nt, bool), np.zeros(nt, bool)
    r = np.radians(cog)
    for j in range(first.size):
        pts = idx[board == j]
        if ta[j] >= 0 and t[peak[ta[j]]] - t[last[j]] <= 2.0 * TURN_WINDOW_S * scale:
            sel = pts[t[pts] >= t[last[j]] - BOARD_END_S * scale]
            c_in[ta[j]] = np.degrees(np.arctan2(np.sin(r[sel]).sum(), np.cos(r[sel]).sum()))
            n_in[ta[j]] = True
        if tb[j] >= 0 and t[first[j]] - t[peak[tb[j]]] <= 2.0 * TURN_WINDOW_S * scale:
            sel = pts[t[pts] <= t[first[j]] + BOARD_END_S * scale]
            c_out[tb[j]] = np.degrees(np.arctan2(np.sin(r[sel]).sum(), np.cos(r[sel]).sum()))
            n_out[tb[j]] = True
    return _BoatPart(idx, board, first, last, tb, ta, peak, c_in, c_out, n_in & n_out)


def _time_scale(t: NDArray, x: NDArray, y: NDArray, dt: float) -> float:
    """Factor on the time windows for one boat [-]: 1 up to ``REF_SPEED_MS`` of median
    speed, shorter for faster boats (their boards and manoeuvres are shorter; the windows
    span about the same distance), down to ``MIN_TIME_SCALE`` and never under three
    sampling intervals of ``TURN_WINDOW_S``."""
    k = max(1, round(COG_WINDOW_S / max(dt, 1e-9)))  # over ~10 s: GPS noise averages out
    d = np.hypot(x[k:] - x[:-k], y[k:] - y[:-k])
    tt = t[k:] - t[:-k]
    ok = tt > 0
    v = float(np.median(d[ok] / tt[ok])) if ok.any() else 0.0
    sc = float(np.clip(REF_SPEED_MS / max(v, 1e-9), MIN_TIME_SCALE, 1.0))
    return max(sc, min(1.0, 3.0 * dt / TURN_WINDOW_S))


def _steady_points(
    tracks: Sequence[Track],
    frame: LocalFrame,
    t0: float,
    t1: float,
    min_speed_ms: float,
    xy: Sequence[tuple[NDArray, NDArray]] | None = None,
) -> tuple[_Points, _Boards, _Turns, list[str]]:
    """Steady points, their boards and the turns between them, for all boats (``xy``: the
    tracks' positions in ``frame`` when already known)."""
    pts: list[tuple[NDArray, ...]] = []
    brd: list[tuple[NDArray, ...]] = []
    trn: list[tuple[NDArray, ...]] = []
    notes: list[str] = []
    n_boards = n_turns = 0
    pad = COG_WINDOW_S + TURN_WINDOW_S
    for k, tr in enumerate(tracks):
        m = (tr.t_s >= t0 - pad) & (tr.t_s <= t1 + pad)
        t = np.asarray(tr.t_s[m], float)
        if t.size < 3:
            notes.append(f"{tr.name or k}: no points in the window")
            continue
        x, y = track_xy(tr, frame) if xy is None else xy[k]
        x, y = x[m], y[m]
        dt = float(np.median(np.diff(t)))
        sc = _time_scale(t, x, y, dt)
        cog, sog, before, after = _window_course(
            t, x, y, 0.5 * COG_WINDOW_S * sc, TURN_WINDOW_S * sc
        )
        turn = np.abs(wrap180(after - before))
        slow = sog < min_speed_ms
        big_gap = np.concatenate([[False], np.diff(t) > max(MAX_GAP_S, 2.5 * dt)])
        inside = (t >= t0) & (t <= t1)
        ok = (
            ~_near_any(t, (turn > TURN_DEG) | slow, PAD_S * sc)
            & ~_near_any(t, turn > ROUNDING_DEG, ROUNDING_PAD_S * sc)
            & ~_near_any(t, big_gap, COG_WINDOW_S * sc)
            & inside
        )
        peak, c_in, c_out = _boat_turns(
            t, turn, before, after, _near_any(t, big_gap, TURN_WINDOW_S * sc), PAD_S * sc
        )
        bp = _boat_part(t, cog, ok, peak, c_in, c_out, sc)
        n_ok = bp.idx.size
        notes.append(
            f"{tr.name or k}: {n_ok} of {int(inside.sum())} points "
            "steady (not turning, slow or near a gap)"
        )
        w = np.full(n_ok, min(1.0, dt / CORR_S))
        i = bp.idx
        pts.append((t[i], cog[i], sog[i], np.full(n_ok, k, np.int64), w, bp.board + n_boards))
        brd.append(
            (
                np.full(bp.first.size, k, np.int64),
                t[bp.first],
                t[bp.last],
                np.where(bp.turn_before >= 0, bp.turn_before + n_turns, -1),
                np.where(bp.turn_after >= 0, bp.turn_after + n_turns, -1),
            )
        )
        sgn = wrap180(bp.c_out - bp.c_in)
        trn.append(
            (
                t[peak],
                np.full(peak.size, k, np.int64),
                bp.c_in,
                bp.c_out,
                wrap360(bp.c_in + 0.5 * sgn),
                np.abs(sgn),
                x[peak],
                y[peak],
                np.full(peak.size, ROUNDING_S * REF_SPEED_MS / sc),
                bp.paired,
            )
        )
        n_boards += bp.first.size
        n_turns += peak.size
    return (*_gather(pts, brd, trn), notes)


def _gather(
    pts: list[tuple[NDArray, ...]], brd: list[tuple[NDArray, ...]], trn: list[tuple[NDArray, ...]]
) -> tuple[_Points, _Boards, _Turns]:
    """All boats' parts as one set of arrays (points in time order)."""
    if not pts:
        z, zi = np.zeros(0), np.zeros(0, np.int64)
        return (
            _Points(z, z, z, zi, z, zi),
            _Boards(zi, z, z, zi, zi),
            _Turns(z, zi, z, z, z, z, z, z, z, np.zeros(0, bool)),
        )
    cols = [np.concatenate(c) for c in zip(*pts, strict=True)]
    o = np.argsort(cols[0], kind="stable")  # time order across boats
    return (
        _Points(*(c[o] for c in cols)),
        _Boards(*(np.concatenate(c) for c in zip(*brd, strict=True))),
        _Turns(*(np.concatenate(c) for c in zip(*trn, strict=True))),
    )


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
