"""Wind inferred from GPS tracks without instruments: TWD(t), and TWS(t) with a polar.

A boat racing upwind sails close to its best-VMG angle on each board, so its course over
ground is the wind direction minus (starboard) or plus (port) its tacking half-angle α;
downwind the same holds with the gybing half-angle.  One or more boats' tracks thus hold
the wind direction and its shifts over time.  The method (``docs/analysis.md``, "Wind
inferred from tracks"):

1. **Steady points.**  The course at each point is that of the displacement over
   ``COG_WINDOW_S`` centred on it.  A point is kept where the boat is faster than
   ``min_speed_ms``, its courses over the ``TURN_WINDOW_S`` before and after it differ by
   less than ``TURN_DEG`` (no manoeuvre), no turning or slow point lies within ``PAD_S``
   (the acceleration after a tack or gybe), no turn of more than ``ROUNDING_DEG`` (a mark
   rounding) within ``ROUNDING_PAD_S``, and no gap in the log nearby.
2. **The wind axis** from the pooled histogram of steady courses: the direction about
   which the histogram is most symmetric (pairs of courses 2 x 15° to 2 x 60° apart: the two
   upwind boards, the two downwind boards).  The up/down ambiguity is resolved with
   ``prior_twd_deg`` (the axis end within 90° of it), or, without a prior, by the boards'
   separation (tacking half-angles exceed the downwind boards' angle off dead downwind)
   and, where that is not clear, by speeds (the upwind boards are sailed slower).
3. **A joint fit.**  Each steady point on an upwind board is one observation of TWD:
   ``course + α_k`` on starboard and ``course − α_k`` on port, with α_k an unknown per
   boat.  TWD(t) is piecewise linear (knots every ``KNOT_S``) with a weak curvature
   penalty that bridges gaps; the fit is a robust (Huber) weighted least squares,
   re-classified and re-fitted ``N_ITER`` times.  Points that fit neither board (reaches)
   are rejected.  The tack jumps of one boat (the bisector of the courses before and
   after), the two boards' courses in the same window (their half-difference is α) and
   the course changes along a board all enter that fit; several boats pool into the one
   TWD(t).  The downwind boards are then added with α held: ``course + 180° ∓ γ_k``
   (``γ_k = 180° − gybing half-angle``, fitted), or, for a boat whose downwind courses
   spread less than ``RUN_GAMMA_DEG`` about dead downwind, ``course + 180°`` at
   ``RUN_WEIGHT`` of its weight (a run: the boat steers for the mark).
4. **The output grid**: TWD at each grid time is a local-linear kernel regression
   (tricube kernel of half-width ``window_s / 2``) of the points' own TWD observations;
   its standard error combines the scatter of those observations (each 1 Hz point counts
   for ``1 / CORR_S`` of an independent one: course errors are correlated over several
   seconds), per boat and board a model error that does not average down
   (``UP_MODEL_SD``, ``RUN_MODEL_SD``, ``DOWN_MODEL_SD``) and the fitted half-angle's
   uncertainty, and an estimate of the smoothing bias (from the fitted curvature).
5. **TWS** (only with a polar): each steady point's speed over ground, at its TWA from the
   inferred TWD, is the polar's speed at one TWS; those TWS are smoothed like TWD.  This
   is the wind in which the polar sails the observed speeds: right only for a boat that
   sails to its polar.

Assumptions: boats sail close to constant angles on each board (their best VMG); no
current (COG = heading, no leeway); a symmetric polar (same angle on both boards); the
wind uniform over the area the boats sail.  A shift between two tacks of the same board
is seen only through the course changes on that board.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import solveh_banded

from sailroute.boat.model import BoatModel
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.timeutil import iso
from sailroute.track.kinematics import track_xy
from sailroute.track.model import Track
from sailroute.units import KNOT, bearing_deg, circular_mean_deg, wind_components, wrap180, wrap360
from sailroute.wind.base import Coverage, prepare_points

MIN_SPEED_MS: Final = 1.0
"""Points slower than this [m s⁻¹] are rejected (no steady course)."""
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
KNOT_S: Final = 20.0
"""Knot spacing of the piecewise-linear TWD(t) of the joint fit [s]."""
CORR_S: Final = 10.0
"""Correlation time of the course errors [s]: a 1 Hz point counts for 1/10 of an
independent observation in the standard errors."""
LAMBDA_SCALE: Final = 0.125
"""The curvature penalty of the joint fit lets TWD(t) bend on a time scale of about
``LAMBDA_SCALE * window_s`` (the equivalent kernel of a second-difference penalty spans
``(lambda / rho) ** 0.25`` knots, rho the data weight per knot)."""
N_ITER: Final = 4
"""Classify-and-fit passes of the joint fit."""
STEP_S: Final = 30.0
"""Default output grid step [s]."""
WINDOW_S: Final = 90.0
"""Default full width of the output smoothing kernel [s]."""
UP_HALF_DEG: Final = (15.0, 65.0)
"""First-pass range of upwind |TWA| [°] (tacking half-angles)."""
DOWN_OFF_DEG: Final = 50.0
"""First pass: downwind boards lie within this of dead downwind [°]."""
BAND_DEG: Final = 20.0
"""Later passes: a point is on a board when its |TWA| is within this of the boat's fitted
half-angle [°]; anything else is a reach and is rejected."""
AXIS_TIE: Final = 0.1
"""Two wind axes whose symmetry scores lie within this fraction of each other are a tie
that ``prior_twd_deg`` breaks (:func:`axis_near_prior`) [-]."""
ALPHA_PRIOR_DEG: Final = (42.0, 10.0)
"""Prior of a tacking half-angle without a polar: mean and sd [°] (keeps a boat that
sails one board only solvable; the data dominate otherwise)."""
GAMMA_PRIOR_DEG: Final = (10.0, 5.0)
"""Prior of the downwind angle off dead downwind (180° − gybing half-angle) [°]."""
UP_MODEL_SD: Final = 3.0
"""How far from one constant angle a boat sails on an upwind board [°]: the VMG optimum is
flat, so a few degrees higher or lower cost little (sailroute's own routes sail 40-50° in
an oscillating wind).  Correlated along a board: it does not average down
with the number of points."""
RUN_MODEL_SD: Final = 8.0
"""The same for a boat that runs (``RUN_GAMMA_DEG``) [°]: near
dead downwind the polar is flat and the boat steers towards the mark, up to 10° by the lee
or on a broad reach without a gybe."""
DOWN_MODEL_SD: Final = 3.0
"""The same for downwind boards of a boat that gybes through a clear angle [°]."""
RUN_WEIGHT: Final = 0.1
"""Runs count for this share of their variance weight [-]: they give the direction where
no boat is on a board, but do not pull a beat's estimate towards the rhumb line (their
error is a bias towards the mark, not noise)."""
RUN_GAMMA_DEG: Final = 12.0
"""A boat whose downwind courses spread less than this either side of dead downwind runs
[°] (:func:`half_separation_deg`)."""
SEPARATION_MARGIN_DEG: Final = 10.0
"""Without a prior, the wind axis end about which the boards are this much further apart
[°] is upwind; with a smaller difference the slower boards decide."""
MAX_SPAN_S: Final = 6 * 3600.0
"""Longest time span inferred in one call [s] (one race, or one evening's races)."""
MAX_APART_M: Final = 20_000.0
"""Tracks whose mean positions lie further apart than this [m] are refused."""
MIN_BOARD_POINTS: Final = 20
"""Steady points needed on each upwind board (all boats together)."""
MIN_OBS_S: Final = 20.0
"""A grid time needs at least this many seconds of observations in its window."""
MAX_SD_DEG: Final = 15.0
"""A grid time whose direction has a larger standard error gets none (NaN) [°]."""


@dataclass(frozen=True, eq=False)
class InferredWind:
    """Wind inferred from tracks, on a regular time grid.

    Attributes
    ----------
    t : ndarray
        Grid times [UTC epoch s].
    twd_deg : ndarray
        True wind direction, from [° compass, in ``[0, 360)``]; NaN where no steady
        point lies within the window.
    twd_sd_deg : ndarray
        Standard error of ``twd_deg`` [°]; NaN where ``twd_deg`` is.
    tws_ms : ndarray
        True wind speed [m s⁻¹]; NaN where unknown (always without a polar).
    tws_sd_ms : ndarray
        Standard error of ``tws_ms`` [m s⁻¹]; NaN where ``tws_ms`` is.
    n_obs : ndarray of int
        Steady 1 Hz points (all boats) within the smoothing window of each grid time.
    method : str
        One line: what was used (boats, points, evidence, how up/down was decided).
    notes : tuple of str
        Per-boat half-angles, the up/down decision, checks and warnings.
    half_angles_deg : mapping of str to (float, float)
        Per boat: fitted tacking half-angle α and gybing half-angle 180° − γ [°].
    """

    t: NDArray[np.float64]
    twd_deg: NDArray[np.float64]
    twd_sd_deg: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    tws_sd_ms: NDArray[np.float64]
    n_obs: NDArray[np.int64]
    method: str
    notes: tuple[str, ...] = ()
    half_angles_deg: Mapping[str, tuple[float, float]] = field(
        default_factory=lambda: MappingProxyType({}))

    def __post_init__(self) -> None:
        n = np.shape(self.t)
        bad = [k for k in ("twd_deg", "twd_sd_deg", "tws_ms", "tws_sd_ms", "n_obs")
               if np.shape(getattr(self, k)) != n]
        if len(n) != 1 or bad:
            raise InputError(f"InferredWind: {', '.join(bad) or 't'} must be 1-D arrays of the "
                             f"length of t ({n}); build it with infer_wind")
        if not isinstance(self.half_angles_deg, MappingProxyType):
            raise TypeError(
                "InferredWind.half_angles_deg must be a read-only mapping "
                f"(types.MappingProxyType), got {type(self.half_angles_deg).__name__}; "
                "pass MappingProxyType(dict(half_angles))")

    def field(self, frame: LocalFrame | None = None, tws_ms: float | None = None,
              *, clamp: bool = False) -> InferredWindField:
        """The inferred wind as a :class:`~sailroute.wind.base.WindField`.

        Uniform in space; TWD and TWS linear in time between the grid times with a
        direction (NaN grid times are skipped).  Covers the first to the last grid time
        with a direction.

        Parameters
        ----------
        frame : LocalFrame, optional
            The local frame the tracks were projected in (named in coverage messages).
        tws_ms : float, optional
            TWS [m s⁻¹] used where TWS was not inferred (always needed without a polar).
        clamp : bool
            Hold the first/last value outside the span instead of raising.

        Raises
        ------
        InputError
            No grid time has a direction, or TWS is missing somewhere and no ``tws_ms``
            was given.
        """
        ok = np.isfinite(self.twd_deg)
        if not ok.any():
            raise InputError("inferred wind: no grid time has a direction; nothing to sample")
        s = self.tws_ms[ok]
        if np.isnan(s).any():
            if tws_ms is None or not np.isfinite(tws_ms) or tws_ms < 0:
                raise InputError(
                    f"inferred wind: TWS is unknown at {int(np.isnan(s).sum())} of {s.size} "
                    "grid times (it is inferred only with a polar); pass a fallback "
                    "tws_ms=... (m/s, >= 0)")
            s = np.where(np.isnan(s), float(tws_ms), s)
        d = _unwrap_deg(self.twd_deg[ok])
        return InferredWindField(self.t[ok].copy(), d, s, frame, clamp)


@dataclass(frozen=True, eq=False)
class InferredWindField:
    """Uniform wind with TWD and TWS linear in time (:meth:`InferredWind.field`).

    Parameters
    ----------
    times : ndarray
        Increasing epoch times [s].
    twd_unwrapped_deg : ndarray
        TWD [°] at ``times``, unwrapped (no jumps of 360°).
    tws_ms : ndarray
        TWS [m s⁻¹] at ``times``.
    frame : LocalFrame or None
        For coverage messages.
    clamp : bool
        Hold the edge values outside the time span instead of raising.
    """

    times: NDArray[np.float64]
    twd_unwrapped_deg: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    frame: LocalFrame | None = None
    clamp: bool = False

    @property
    def coverage(self) -> Coverage:
        """All space; the inferred time span."""
        inf = float("inf")
        return Coverage(float(self.times[0]), float(self.times[-1]), -inf, inf, -inf, inf,
                        frame=self.frame)

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s] and ``x, y`` [m] (broadcast)."""
        t, x, y = prepare_points(self.coverage, t, x, y, clamp=self.clamp,
                                 name="inferred wind")
        d = np.interp(t, self.times, self.twd_unwrapped_deg)
        s = np.interp(t, self.times, self.tws_ms)
        u, v = wind_components(s, d)
        return np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)


# ----------------------------------------------------------------------------- internals


def _unwrap_deg(a: NDArray) -> NDArray[np.float64]:
    return np.degrees(np.unwrap(np.radians(np.asarray(a, float))))


def _window_course(t: NDArray, x: NDArray, y: NDArray, half: float, turn: float
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


def _steady_points(tracks: Sequence[Track], frame: LocalFrame, t0: float, t1: float,
                   min_speed_ms: float) -> tuple[_Points, list[str]]:
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
        ok = (~_near_any(t, (turn > TURN_DEG) | slow, PAD_S)
              & ~_near_any(t, turn > ROUNDING_DEG, ROUNDING_PAD_S)
              & ~_near_any(t, big_gap, COG_WINDOW_S) & (t >= t0) & (t <= t1))
        n_ok = int(ok.sum())
        notes.append(f"{tr.name or k}: {n_ok} of {int(((t >= t0) & (t <= t1)).sum())} points "
                     "steady (not turning, slow or near a gap)")
        ts.append(t[ok])
        cs.append(cog[ok])
        ss.append(sog[ok])
        bs.append(np.full(n_ok, k, dtype=np.int64))
        ws.append(np.full(n_ok, min(1.0, dt / CORR_S)))
    if not ts:
        return _Points(*(np.zeros(0),) * 3, np.zeros(0, np.int64), np.zeros(0)), notes
    t_all = np.concatenate(ts)
    o = np.argsort(t_all, kind="stable")  # time order across boats
    return _Points(t_all[o], np.concatenate(cs)[o], np.concatenate(ss)[o],
                   np.concatenate(bs)[o], np.concatenate(ws)[o]), notes


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


def axis_near_prior(cog_deg: NDArray, prior_twd_deg: float, weights: NDArray | None = None,
                    tie: float = AXIS_TIE) -> float:
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
    h = np.bincount(np.floor(wrap360(cog_deg)).astype(int) % 360, weights=weights,
                    minlength=360).astype(float)
    k = np.arange(-10, 11)
    g = np.exp(-0.5 * (k / 3.0) ** 2)
    return np.asarray(np.sum([np.roll(h, s) * w for s, w in zip(k, g, strict=True)], axis=0),
                      dtype=float)


def half_separation_deg(cog_deg: NDArray, end_deg: float,
                        weights: NDArray | None = None) -> float:
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


# ---------------------------------------------------------------------------- the fit


@dataclass(frozen=True)
class _Fit:
    knots: NDArray[np.float64]
    twd: NDArray[np.float64]        # unwrapped TWD at the knots [°]
    alpha: NDArray[np.float64]      # per boat [°]
    gamma: NDArray[np.float64]      # per boat [°]
    alpha_sd: NDArray[np.float64]
    gamma_sd: NDArray[np.float64]
    up: NDArray[np.bool_]           # per point: on an upwind board
    used: NDArray[np.bool_]         # per point: on a board (up or down)
    boat: NDArray[np.int64]         # per point: boat index
    side: NDArray[np.float64]       # per point: +1 starboard, -1 port
    obs: NDArray[np.float64]        # per point: its own TWD observation (unwrapped) [°]
    w: NDArray[np.float64]          # per point: fit weight (1/sd^2 x robust x correlation)
    msd: NDArray[np.float64]        # per point: model sd (UP/RUN/DOWN_MODEL_SD) [°]
    sigma: tuple[float, float]      # residual sd upwind, downwind [°]


def _basis(t: NDArray, knots: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Linear-interpolation basis: left knot index and the two weights."""
    j = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, knots.size - 2)
    f = np.clip((t - knots[j]) / (knots[j + 1] - knots[j]), 0.0, 1.0)
    return j, 1.0 - f, f


def _joint_fit(p: _Points, n_boats: int, knots: NDArray, twd0: NDArray,
               alpha0: NDArray, gamma0: NDArray, alpha_prior_sd: float,
               window_s: float, *, use_down: bool = True,
               alpha_sd_fixed: NDArray | None = None,
               gamma_prior_sd: NDArray | None = None) -> _Fit:
    """Fit TWD(t) at the knots and the boats' half-angles (module notes, step 3).

    ``use_down=False`` fits the upwind boards alone; ``alpha_sd_fixed`` holds the tacking
    half-angles at ``alpha0`` (their sd as given) and fits the rest.
    """
    J, K = knots.size, n_boats
    P = J + 2 * K
    j, w0, w1 = _basis(p.t, knots)
    twd = twd0.copy()
    alpha, gamma = alpha0.copy(), gamma0.copy()
    robust = np.ones(p.t.size)
    sig_up, sig_dn = 5.0, 10.0
    par_var: NDArray[np.float64] = np.ones(2 * K)
    # D'D of the second-difference operator D, built band by band (pentadiagonal)
    dtd = np.zeros((J, J))
    r = np.arange(J - 2)
    for a_, ca in enumerate((1.0, -2.0, 1.0)):
        for b_, cb in enumerate((1.0, -2.0, 1.0)):
            np.add.at(dtd, (r + a_, r + b_), ca * cb)
    up = used = np.zeros(p.t.size, bool)
    side = np.ones(p.t.size)
    y = np.zeros(p.t.size)
    coef = np.zeros(p.t.size)
    wt = np.zeros(p.t.size)
    for it in range(N_ITER):
        cur = twd[j] * w0 + twd[j + 1] * w1
        twa = wrap180(cur - p.cog)
        a = np.abs(twa)
        side = np.where(twa >= 0, 1.0, -1.0)
        if it == 0 and alpha_sd_fixed is None:
            up = (a >= UP_HALF_DEG[0]) & (a <= UP_HALF_DEG[1])
            dn = a >= 180.0 - DOWN_OFF_DEG
        else:
            up = np.abs(a - alpha[p.boat]) <= BAND_DEG
            dn = (np.abs((180.0 - a) - gamma[p.boat]) <= BAND_DEG + 5.0) if it else (
                a >= 180.0 - DOWN_OFF_DEG)
        if not use_down:
            dn = np.zeros_like(up)
        used = up | dn
        # observation relative to the current curve: y = dTWD(t) - s alpha (up),
        # y = dTWD(t) + s gamma (down); unknowns: knot increments, alpha, gamma (absolute)
        y = np.where(up, wrap180(p.cog - cur), wrap180(p.cog + 180.0 - cur))
        col = np.where(up, J + p.boat, J + K + p.boat)
        coef = np.where(up, -side, side)
        msd = _model_sd(up, gamma[p.boat])
        run = ~up & (np.abs(gamma[p.boat]) < RUN_GAMMA_DEG)
        wt = (robust * p.weight * used * np.where(run, RUN_WEIGHT, 1.0)
              / (np.where(up, sig_up, sig_dn) ** 2 + msd**2))
        # normal equations by accumulation: 3 non-zeros per row
        idx = np.stack([j, j + 1, col], axis=1)
        val = np.stack([w0, w1, coef], axis=1)
        rows = (idx[:, :, None] * P + idx[:, None, :]).reshape(-1)
        prods = (val[:, :, None] * val[:, None, :] * wt[:, None, None]).reshape(-1)
        N: NDArray[np.float64] = np.bincount(rows, weights=prods,
                                             minlength=P * P).reshape(P, P).astype(float)
        b: NDArray[np.float64] = np.bincount(
            idx.reshape(-1), weights=(val * (wt * y)[:, None]).reshape(-1),
            minlength=P).astype(float)
        # curvature penalty on the increments (bridges gaps; resolution ~ window_s)
        per_knot = np.bincount(j, weights=wt, minlength=J)
        rho = float(np.median(per_knot[per_knot > 0])) if (per_knot > 0).any() else 1.0
        lam = rho * (LAMBDA_SCALE * window_s / (knots[1] - knots[0])) ** 4
        N[:J, :J] += lam * dtd
        N[np.arange(J), np.arange(J)] += 1e-6
        # penalise the curvature of the total curve, not only of the increment
        b[:J] -= lam * (dtd @ twd)
        # priors on the half-angles (absolute values)
        ia, ig = J + np.arange(K), J + K + np.arange(K)
        a_sd = alpha_prior_sd if alpha_sd_fixed is None else 1e-3
        N[ia, ia] += 1.0 / a_sd**2
        g_sd = GAMMA_PRIOR_DEG[1] if gamma_prior_sd is None else gamma_prior_sd
        N[ig, ig] += 1.0 / g_sd**2
        b[ia] += alpha0 / a_sd**2
        b[ig] += gamma0 / g_sd**2
        sol, par_var = _solve_bordered(N, b, J)
        twd = twd + sol[:J]
        alpha, gamma = sol[ia], sol[ig]
        # residuals and robust weights
        fitted = sol[:J][j] * w0 + sol[:J][j + 1] * w1 + coef * sol[col]
        r = y - fitted
        sig_up = _mad(r[up & used]) if (up & used).sum() > 10 else sig_up
        sig_dn = _mad(r[~up & used]) if (~up & used).sum() > 10 else sig_dn
        sig_up, sig_dn = max(sig_up, 0.5), max(sig_dn, 0.5)
        sc = np.where(up, sig_up, sig_dn)
        robust = np.minimum(1.0, 1.5 * sc / np.maximum(np.abs(r), 1e-9))
    cur = twd[j] * w0 + twd[j + 1] * w1
    obs = cur + wrap180(np.where(up, p.cog + side * alpha[p.boat],
                                 p.cog + 180.0 - side * gamma[p.boat]) - cur)
    ia, ig = J + np.arange(K), J + K + np.arange(K)
    # the covariance of a weighted fit with weights 1/sigma^2 is in deg^2 already
    a_out = np.sqrt(par_var[:K]) if alpha_sd_fixed is None else alpha_sd_fixed
    return _Fit(knots, twd, alpha, gamma, a_out,
                np.sqrt(par_var[K:]), up & used, used, p.boat, side, obs, wt,
                _model_sd(up, gamma[p.boat]),
                (sig_up, sig_dn))


def _solve_bordered(N: NDArray, b: NDArray, J: int
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Solve the normal equations ``N x = b`` whose knot block ``N[:J, :J]`` is banded
    (pentadiagonal: linear basis plus the second-difference penalty) and bordered by a few
    dense parameter rows, by the Schur complement in O(J); also the variances of the
    parameters (the diagonal of the parameter block of ``N⁻¹``)."""
    A, B, C = N[:J, :J], N[:J, J:], N[J:, J:]
    ab = np.zeros((3, J))
    for u in range(3):  # upper banded storage: ab[2 - u, j] = A[j - u, j]
        ab[2 - u, u:] = np.diagonal(A, u)
    rhs = np.column_stack([b[:J], B])
    try:
        z = solveh_banded(ab, rhs)
        S = C - B.T @ z[:, 1:]
        par = np.linalg.solve(S, b[J:] - B.T @ z[:, 0])
        var = np.diag(np.linalg.inv(S))
    except (np.linalg.LinAlgError, ValueError):
        sol = np.linalg.lstsq(N, b, rcond=None)[0]
        return sol, np.diag(np.linalg.pinv(N))[J:].astype(float)
    x = z[:, 0] - z[:, 1:] @ par
    return np.concatenate([x, par]), np.asarray(var, dtype=float)


def _model_sd(up: NDArray, gamma: NDArray) -> NDArray[np.float64]:
    return np.where(up, UP_MODEL_SD, np.where(np.abs(gamma) < RUN_GAMMA_DEG, RUN_MODEL_SD,
                                              DOWN_MODEL_SD))


def _mad(r: NDArray) -> float:
    return float(1.4826 * np.median(np.abs(r - np.median(r))))


def _local_linear(tg: NDArray, t: NDArray, v: NDArray, w: NDArray, h: float,
                  infl: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Local-linear kernel regression of ``v(t)`` at ``tg`` (tricube, half-width ``h``).

    Parameters
    ----------
    tg : ndarray
        Grid times [s].
    t, v, w : ndarray
        Sorted point times [s], values and weights.
    h : float
        Kernel half-width [s].
    infl : ndarray
        Variance inflation of each point (1 / its share of an independent observation).

    Returns
    -------
    est : ndarray
        The estimate at each grid time (NaN without points); the local mean where the
        window has points on one side only.
    var : ndarray
        Its variance, ``sum l_i² r_i² infl_i`` with ``l`` the equivalent kernel and ``r``
        the residuals about the local fit.
    n : ndarray of int
        Points in the window.
    mu2 : ndarray
        ``sum l_i (t_i − tg)²``, the kernel's second moment (for the smoothing bias).
    """
    G = tg.size
    est = np.full(G, np.nan)
    var = np.full(G, np.nan)
    n = np.zeros(G, np.int64)
    mu2 = np.full(G, np.nan)
    order = np.argsort(t)
    t, v, w, infl = t[order], v[order], w[order], infl[order]
    lo = np.searchsorted(t, tg - h, side="left")
    hi = np.searchsorted(t, tg + h, side="right")
    width = int(np.max(hi - lo)) if G else 0
    if width == 0:
        return est, var, n, mu2
    k = lo[:, None] + np.arange(width)[None, :]
    inside = k < hi[:, None]
    k = np.minimum(k, t.size - 1)
    dt = t[k] - tg[:, None]
    kern = np.where(inside, (1.0 - np.clip(np.abs(dt) / h, 0, 1) ** 3) ** 3, 0.0) * w[k]
    s0 = kern.sum(1)
    s1 = (kern * dt).sum(1)
    s2 = (kern * dt * dt).sum(1)
    det = s0 * s2 - s1 * s1
    # local linear only with data on both sides (a quarter of the window each); else the
    # local mean (an extrapolated slope at the ends of the data is noise)
    both = ((kern * (dt < -0.25 * h)).sum(1) > 0) & ((kern * (dt > 0.25 * h)).sum(1) > 0)
    lin = both & (det > 1e-9 * np.maximum(s0 * s2, 1e-300))
    # equivalent kernel l_i = kern_i (s2 - s1 dt_i) / det (local linear); else local mean
    with np.errstate(invalid="ignore", divide="ignore"):
        lw = np.where(lin[:, None], kern * (s2[:, None] - s1[:, None] * dt) / det[:, None],
                      kern / s0[:, None])
    vv = v[k]
    e = (lw * vv).sum(1)
    r = vv - e[:, None]
    var_ = (lw**2 * r**2 * infl[k] * inside).sum(1)
    n_ = inside.sum(1)
    m2 = (lw * dt * dt).sum(1)
    ok = s0 > 0
    est[ok], var[ok], n[:] = e[ok], var_[ok], n_
    mu2[ok] = m2[ok]
    return est, var, n, mu2


# ---------------------------------------------------------------------------- TWS


def _invert_polar(boat: BoatModel, twa_deg: NDArray, sog_ms: NDArray) -> NDArray[np.float64]:
    """TWS [m s⁻¹] at which the boat's polar sails ``sog_ms`` at ``twa_deg`` (NaN where it
    cannot: faster than the polar's top speed at that angle, or slower than at 0.5 m/s)."""
    grid = np.arange(0.5, 25.01, 0.1)
    ang = np.arange(0.0, 181.0)
    table = np.asarray(boat.steady_speed(grid[None, :], ang[:, None]), float)
    table = np.maximum.accumulate(table, axis=1)  # the rising part of each column
    row = table[np.clip(np.rint(np.abs(twa_deg)).astype(int), 0, 180)]
    c = (row < sog_ms[:, None]).sum(1)
    ok = (c > 0) & (c < grid.size)
    ci = np.clip(c, 1, grid.size - 1)
    s0 = row[np.arange(c.size), ci - 1]
    s1 = row[np.arange(c.size), ci]
    with np.errstate(invalid="ignore", divide="ignore"):
        f = np.where(s1 > s0, (sog_ms - s0) / (s1 - s0), 0.0)
    return np.where(ok, grid[ci - 1] + f * (grid[ci] - grid[ci - 1]), np.nan)


# ---------------------------------------------------------------------------- public API


def _gamma_priors(p: _Points, n_boats: int, twd_axis: float, default: float
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Prior angle off dead downwind [°] per boat, and its sd.

    From each boat's downwind courses: their half-separation about the downwind end of the
    race's wind axis (:func:`half_separation_deg`).  Below ``RUN_GAMMA_DEG`` the boat runs:
    its angle is held at 0 (a run has no boards to tell apart: the sign of a TWA near 180°
    is noise); above, it is the prior mean with sd ``GAMMA_PRIOR_DEG[1]``.  A boat with
    fewer than 30 downwind points gets ``default``.
    """
    a = np.abs(wrap180(p.cog - twd_axis - 180.0))
    mean = np.full(n_boats, float(default))
    sd = np.full(n_boats, GAMMA_PRIOR_DEG[1])
    for k in range(n_boats):
        sel = (p.boat == k) & (a < 50.0)
        if sel.sum() >= 30:
            g = half_separation_deg(p.cog[sel], twd_axis + 180.0, p.weight[sel])
            if np.isfinite(g):
                mean[k], sd[k] = (0.0, 1e-3) if g < RUN_GAMMA_DEG else (g, GAMMA_PRIOR_DEG[1])
    return mean, sd


def _upwind_end(p: _Points, cands: tuple[float, float]) -> tuple[float, str]:
    """Which end of the wind axis is upwind, without a prior: the end about which the
    boards are further apart (tacking half-angles exceed the downwind boards' angle off
    dead downwind by ``SEPARATION_MARGIN_DEG`` or more); where the two differ less, the end
    whose boards are sailed slower."""
    sep = [half_separation_deg(p.cog, c, p.weight) for c in cands]
    if np.all(np.isfinite(sep)) and abs(sep[0] - sep[1]) >= SEPARATION_MARGIN_DEG:
        k = int(np.argmax(sep))
        return cands[k], (f"up/down from the boards' separation (no prior): {sep[k]:.0f}° "
                          f"either side upwind, {sep[1 - k]:.0f}° downwind")
    speeds = []
    for c in cands:
        a = np.abs(wrap180(c - p.cog))
        speeds.append(float(np.median(p.sog[a < 70])) if (a < 70).any() else np.inf)
    k = int(np.argmin(speeds))  # upwind: the slower boards
    return cands[k], (f"up/down from speeds (no prior; boards {sep[0]:.0f}° and {sep[1]:.0f}° "
                      f"either side): upwind boards {speeds[k] / KNOT:.1f} kn, "
                      f"downwind {speeds[1 - k] / KNOT:.1f} kn")


def _check_same_place(trs: Sequence[Track], frame: LocalFrame, t0: float, t1: float) -> None:
    """Refuse tracks whose mean positions over the span lie more than ``MAX_APART_M``
    apart (boats of different races: one wind does not fit both)."""
    centres = []
    for i, tr in enumerate(trs):
        part = tr.between(t0, t1)
        if len(part):
            x, y = track_xy(part, frame)
            centres.append((tr.name or f"track {i + 1}", float(np.mean(x)), float(np.mean(y))))
    for (na, xa, ya), (nb, xb, yb) in itertools.combinations(centres, 2):
        d = float(np.hypot(xb - xa, yb - ya))
        if d > MAX_APART_M:
            raise InputError(
                f"infer_wind: {na!r} and {nb!r} sailed {d / 1000:.1f} km apart in the time "
                f"span (more than {MAX_APART_M / 1000:.0f} km): one wind does not fit boats of "
                "different places; infer each race on its own tracks")


def _check_inputs(tracks: Sequence[Track] | Track, step_s: float, window_s: float,
                  prior: float | None, min_speed_ms: float) -> list[Track]:
    trs = [tracks] if isinstance(tracks, Track) else list(tracks)
    if not trs:
        raise InputError("infer_wind: no tracks given; pass one or more Track objects")
    for i, tr in enumerate(trs):
        if not isinstance(tr, Track):
            raise InputError(f"infer_wind: item {i} is a {type(tr).__name__}, not a Track; "
                             "read tracks with sailroute.track.read_track")
    for name, v, unit in (("step_s", step_s, "s"), ("window_s", window_s, "s"),
                          ("min_speed_ms", min_speed_ms, "m/s")):
        if not (isinstance(v, int | float) and np.isfinite(v) and v > 0):
            raise InputError(f"infer_wind: {name} must be a number > 0 {unit}, got {v!r}")
    if prior is not None and not np.isfinite(prior):
        raise InputError(f"infer_wind: prior_twd_deg must be a finite direction, got {prior!r}")
    return trs


def infer_wind(
    tracks: Sequence[Track] | Track,
    frame: LocalFrame,
    *,
    prior_twd_deg: float | None = None,
    boat: BoatModel | None = None,
    t0: float | None = None,
    t1: float | None = None,
    step_s: float = STEP_S,
    window_s: float = WINDOW_S,
    min_speed_ms: float = MIN_SPEED_MS,
) -> InferredWind:
    """Estimate TWD(t), and TWS(t) with a polar, from boats' GPS tracks.

    Parameters
    ----------
    tracks : Track or sequence of Track
        One or more boats' tracks (positions; instrument channels are not used).
    frame : LocalFrame
        Local metric frame (the course's ``Course.frame``); directions are in its grid.
    prior_twd_deg : float, optional
        A rough TWD [°, from] (the course axis, the sailor's estimate; within ~60°) that
        decides which end of the inferred axis the wind comes from.  Without it the
        upwind end is the one about which the boards lie further apart (or, where that
        is not clear, are sailed slower); ``notes`` says which decided.
    boat : BoatModel, optional
        The boats' polar: gives TWS(t) (the wind in which it sails the observed speeds)
        and the prior half-angles (its best-VMG angles at a TWS guessed from the median
        speed).  Without it TWS stays NaN.
    t0, t1 : float, optional
        Time span [epoch s] of the grid; default the tracks' span (at most
        ``MAX_SPAN_S``).
    step_s : float
        Grid step [s].
    window_s : float
        Full width of the smoothing window [s]: the time resolution of the estimate.
    min_speed_ms : float
        Points slower than this are rejected [m s⁻¹].

    Returns
    -------
    InferredWind

    Raises
    ------
    InputError
        No tracks, bad parameters, an empty or too long time span, tracks sailed more
        than ``MAX_APART_M`` apart, or too few steady points on upwind or downwind boards
        to infer a direction (the message says how many).
    """
    trs = _check_inputs(tracks, step_s, window_s, prior_twd_deg, min_speed_ms)
    ta = min(float(tr.t_s[0]) for tr in trs if len(tr)) if any(len(tr) for tr in trs) else 0.0
    tb = max(float(tr.t_s[-1]) for tr in trs if len(tr)) if any(len(tr) for tr in trs) else 0.0
    t0 = ta if t0 is None else float(t0)
    t1 = tb if t1 is None else float(t1)
    if not t1 > t0:
        raise InputError(f"infer_wind: empty time span {iso(t0)} .. {iso(t1)}; "
                         "give t0 < t1 within the tracks' times")
    if t1 - t0 > MAX_SPAN_S:
        raise InputError(
            f"infer_wind: the time span {iso(t0)} .. {iso(t1)} is {(t1 - t0) / 3600:.1f} h, "
            f"more than {MAX_SPAN_S / 3600:.0f} h (tracks of different days?); infer one race "
            "at a time: give t0 and t1, or the tracks of one race")
    _check_same_place(trs, frame, t0, t1)
    names = [tr.name or f"track {i + 1}" for i, tr in enumerate(trs)]
    p, notes = _steady_points(trs, frame, t0, t1, min_speed_ms)
    if p.t.size < 60:
        raise InputError(
            f"infer_wind: only {p.t.size} steady points (faster than {min_speed_ms} m/s, "
            f"not turning) in {iso(t0)} .. {iso(t1)}; need at least 60: give longer tracks "
            "or the race's time span")
    # 1. the axis and which end is upwind
    axis, strength = wind_axis_deg(p.cog, p.weight)
    if prior_twd_deg is not None:
        tied = axis_near_prior(p.cog, float(prior_twd_deg), p.weight)
        if tied != axis:
            notes.append(f"the tracks' courses are nearly as symmetric about {tied:.0f}° as "
                         f"about {axis:.0f}° (within {100 * AXIS_TIE:.0f} %): the prior "
                         "decides")
            axis = tied
    cands = (axis, axis + 180.0)
    if prior_twd_deg is not None:
        twd_axis = min(cands, key=lambda c: abs(float(wrap180(c - prior_twd_deg))))
        off = float(wrap180(twd_axis - prior_twd_deg))
        prior = float(wrap360(prior_twd_deg))
        how = f"up/down from the prior TWD {prior:.0f}° (tracks' axis {off:+.0f}° off it)"
        if abs(off) > 60.0:
            notes.append(f"the tracks' wind axis lies {off:+.0f}° from the prior "
                         f"{prior:.0f}°: check the prior")
    else:
        twd_axis, how = _upwind_end(p, cands)
    notes.append(f"wind axis {wrap360(twd_axis):.0f}° (symmetry contrast {strength:.2f}); {how}")
    # 2. the joint fit
    K = len(trs)
    knots = np.arange(t0, t1 + KNOT_S, KNOT_S)
    if knots.size < 3:
        knots = np.linspace(t0, t1, 3)
    a0, g0 = ALPHA_PRIOR_DEG[0], GAMMA_PRIOR_DEG[0]
    a_sd = ALPHA_PRIOR_DEG[1]
    if boat is not None:
        a0v, b0v = boat.vmg_angles_deg(float(np.clip(np.median(p.sog) * 1.6, 2.0, 12.0)))
        a0, g0 = float(a0v), float(180.0 - b0v)
    # upwind boards alone give TWD and the tacking half-angles; the downwind boards are
    # then fitted with those held (a running boat steers for the mark within ~10° of dead
    # downwind, which would otherwise pull the half-angles and damp the shifts)
    fit_up = _joint_fit(p, K, knots, np.full(knots.size, float(twd_axis)),
                        np.full(K, a0), np.full(K, g0), a_sd, window_s, use_down=False)
    g0s, g_sd = _gamma_priors(p, K, float(twd_axis), g0)
    fit = _joint_fit(p, K, knots, fit_up.twd, fit_up.alpha, g0s, a_sd, window_s,
                     gamma_prior_sd=g_sd,
                     alpha_sd_fixed=fit_up.alpha_sd)
    n_up, n_dn = int(fit.up.sum()), int((fit.used & ~fit.up).sum())
    n_stbd = int((fit_up.up & (fit_up.side > 0)).sum())
    n_port = int((fit_up.up & (fit_up.side < 0)).sum())
    if n_stbd + n_port < MIN_BOARD_POINTS and n_dn >= 60:
        raise InputError(
            f"infer_wind: no upwind boards with the wind from {wrap360(twd_axis):.0f}° "
            f"({how}), but {n_dn} points on downwind boards: the wind more likely comes from "
            f"the other end of the axis, {wrap360(twd_axis + 180.0):.0f}°; check "
            "prior_twd_deg")
    if n_up + n_dn < 60 or min(n_stbd, n_port) < MIN_BOARD_POINTS:
        raise InputError(
            f"infer_wind: {n_stbd} starboard and {n_port} port upwind points, {n_dn} downwind "
            f"(need {MIN_BOARD_POINTS} on each upwind board): the wind cannot be told from "
            "one course; give a span with at least one beat sailed on both tacks")
    # 3. the output grid
    tg = np.arange(t0, t1 + 1e-6, step_s)
    h = 0.5 * window_s
    m = fit.used
    wgt = fit.w[m]
    # each point counts for p.weight (its sampling interval / CORR_S) of an independent one
    est, var, n, mu2 = _local_linear(tg, p.t[m], fit.obs[m], wgt, h, 1.0 / p.weight[m])
    # half-angle uncertainty: imbalance of boards within the window
    ang_var = _group_var(tg, p.t[m], wgt, h, fit, m)
    # smoothing bias from the fitted curvature
    curv = np.interp(tg, fit.knots[1:-1],
                     np.diff(fit.twd, 2) / (fit.knots[1] - fit.knots[0]) ** 2)
    bias = 0.5 * curv * np.nan_to_num(mu2)
    sd_all = np.sqrt(var + ang_var + bias**2)
    secs = _seconds_in_window(tg, p.t[m], h, p.weight[m])
    bad = ~np.isfinite(est) | (secs < MIN_OBS_S) | ~(sd_all <= MAX_SD_DEG)
    twd = np.where(bad, np.nan, wrap360(est))
    sd = np.where(bad, np.nan, sd_all)
    # 4. TWS from the polar
    tws = np.full(tg.size, np.nan)
    tws_sd = np.full(tg.size, np.nan)
    if boat is not None:
        curve = np.interp(p.t, fit.knots, fit.twd)
        twa = wrap180(curve - p.cog)
        s_pt = _invert_polar(boat, twa, p.sog)
        ok = m & np.isfinite(s_pt)
        if ok.sum() >= 30:
            e2, v2, _, _ = _local_linear(tg, p.t[ok], s_pt[ok], p.weight[ok], h,
                                         1.0 / p.weight[ok])
            sec2 = _seconds_in_window(tg, p.t[ok], h, p.weight[ok])
            good = np.isfinite(e2) & (sec2 >= MIN_OBS_S) & ~bad
            tws = np.where(good, np.maximum(e2, 0.0), np.nan)
            tws_sd = np.where(good, np.sqrt(v2), np.nan)
            s_med = float(np.nanmedian(tws)) if np.isfinite(tws).any() else float("nan")
            up_pol = boat.vmg_angles_deg(s_med)[0] if np.isfinite(s_med) else float("nan")
            notes.append(f"TWS from the polar {getattr(boat, 'name', '')!r}: the wind in which "
                         f"it sails the observed speeds (median {s_med / KNOT:.1f} kn); check: "
                         f"its best-VMG upwind angle there is {up_pol:.1f}°, the boats' "
                         "tacking half-angles " + ", ".join(f"{a:.1f}°" for a in fit.alpha))
        else:
            notes.append("TWS not inferred: too few points within the polar's speed range")
    half = {names[k]: (float(fit.alpha[k]), float(180.0 - fit.gamma[k])) for k in range(K)}
    for k in range(K):
        nk_up = int((fit.up & (p.boat == k)).sum())
        nk_dn = int((fit.used & ~fit.up & (p.boat == k)).sum())
        down = (f"runs (downwind held at 180°, {RUN_WEIGHT:g} weight)"
                if abs(fit.gamma[k]) < RUN_GAMMA_DEG and fit.gamma_sd[k] < 0.01 else
                f"gybing half-angle {180.0 - fit.gamma[k]:.1f} ± {fit.gamma_sd[k]:.1f}°")
        weak = (f" (weakly determined by the track: leans on its prior {a0:.0f}° ± "
                f"{a_sd:.0f}°{', the polar' if boat is not None else ''})"
                if fit.alpha_sd[k] > 0.5 * a_sd else "")
        notes.append(f"{names[k]}: tacking half-angle {fit.alpha[k]:.1f} ± "
                     f"{fit.alpha_sd[k]:.1f}°{weak}, {down} ({nk_up} upwind, {nk_dn} downwind "
                     "points)")
    method = (f"inferred from {K} track(s): {n_up} upwind and {n_dn} downwind board points "
              f"(course ± fitted half-angles), window {window_s:.0f} s, "
              f"course scatter {fit.sigma[0]:.1f}° upwind / {fit.sigma[1]:.1f}° downwind"
              + ("; TWS from the polar" if boat is not None else "; TWS not inferred (no polar)"))
    return InferredWind(tg, twd, sd, tws, tws_sd, n.astype(np.int64), method, tuple(notes),
                        MappingProxyType(half))


def _seconds_in_window(tg: NDArray, t: NDArray, h: float, weight: NDArray
                       ) -> NDArray[np.float64]:
    """Seconds of steady track within ``tg ± h``: each point stands for its sampling
    interval, up to ``CORR_S`` (``weight * CORR_S``); ``t`` sorted."""
    c = np.concatenate([[0.0], np.cumsum(weight * CORR_S)])
    return np.asarray(c[np.searchsorted(t, tg + h, side="right")]
                      - c[np.searchsorted(t, tg - h, side="left")], dtype=float)


def _group_var(tg: NDArray, t: NDArray, w: NDArray, h: float, fit: _Fit, m: NDArray
               ) -> NDArray[np.float64]:
    """Variance [°²] at the grid times from errors shared by a boat's board.

    Two terms per boat and board (upwind, downwind), with ``f_i`` the point's share of the
    kernel weight: the model error (``(sum f_i msd_i)²``: how far a board's angle may sit
    from the fitted constant, the same along the board) and the uncertainty of the fitted
    half-angle (``(sum f_i s_i)² sd²`` with ``s_i`` the board's sign: it cancels where both
    boards are sailed in the window and adds up where only one is).
    """
    up, boat = fit.up[m], fit.boat[m]
    coef = np.where(up, fit.side[m], -fit.side[m])
    msd = fit.msd[m]
    var = np.zeros(tg.size)
    lo = np.searchsorted(t, tg - h, side="left")
    hi = np.searchsorted(t, tg + h, side="right")
    width = int(np.max(hi - lo)) if tg.size else 0
    if width == 0:
        return var
    k = lo[:, None] + np.arange(width)[None, :]
    inside = k < hi[:, None]
    k = np.minimum(k, t.size - 1)
    kern = np.where(inside, (1.0 - np.clip(np.abs(t[k] - tg[:, None]) / h, 0, 1) ** 3) ** 3,
                    0.0) * w[k]
    f = kern / np.maximum(kern.sum(1), 1e-300)[:, None]
    for is_up, sds in ((True, fit.alpha_sd), (False, fit.gamma_sd)):
        for b, sd in enumerate(sds):
            sel = (up[k] == is_up) & (boat[k] == b)
            var += ((f * coef[k] * sel).sum(1) * sd) ** 2 + ((f * msd[k] * sel).sum(1)) ** 2
    return var


def summary(inferred: InferredWind) -> dict[str, Any]:
    """Numbers for reports: mean TWD, its range and shifts, TWS if known.

    Parameters
    ----------
    inferred : InferredWind

    Returns
    -------
    dict
        ``twd_mean_deg`` (circular mean), ``twd_min_deg``/``twd_max_deg`` and
        ``twd_range_deg`` (of the unwrapped series), ``twd_shift_rms_deg`` (RMS of TWD
        about its mean), ``twd_sd_median_deg``, ``tws_mean_ms``/``tws_min_ms``/
        ``tws_max_ms`` (None without TWS), ``t_start``/``t_end`` (ISO UTC of the grid
        times with a direction), ``n_grid`` (of them), ``method``.  None where no grid
        time has a direction.
    """
    ok = np.isfinite(inferred.twd_deg)
    out: dict[str, Any] = {"n_grid": int(ok.sum()), "method": inferred.method}
    if not ok.any():
        return out | {k: None for k in ("twd_mean_deg", "twd_min_deg", "twd_max_deg",
                                          "twd_range_deg", "twd_shift_rms_deg",
                                          "twd_sd_median_deg", "tws_mean_ms", "tws_min_ms",
                                          "tws_max_ms", "t_start", "t_end")}
    d = inferred.twd_deg[ok]
    mean = circular_mean_deg(d)
    dev = wrap180(d - mean)
    s = inferred.tws_ms[ok]
    s = s[np.isfinite(s)]
    return out | {
        "twd_mean_deg": round(mean, 2) % 360.0,
        "twd_min_deg": round(float(wrap360(mean + dev.min())), 2),
        "twd_max_deg": round(float(wrap360(mean + dev.max())), 2),
        "twd_range_deg": round(float(dev.max() - dev.min()), 2),
        "twd_shift_rms_deg": round(float(np.sqrt(np.mean(dev**2))), 2),
        "twd_sd_median_deg": round(float(np.median(inferred.twd_sd_deg[ok])), 2),
        "tws_mean_ms": round(float(s.mean()), 3) if s.size else None,
        "tws_min_ms": round(float(s.min()), 3) if s.size else None,
        "tws_max_ms": round(float(s.max()), 3) if s.size else None,
        "t_start": iso(float(inferred.t[ok][0])),
        "t_end": iso(float(inferred.t[ok][-1])),
    }
