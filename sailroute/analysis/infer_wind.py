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

from sailroute.analysis.infer_courses import (
    AXIS_TIE,
    COG_WINDOW_S,
    CORR_S,
    MAX_GAP_S,
    PAD_S,
    ROUNDING_DEG,
    ROUNDING_PAD_S,
    TURN_DEG,
    TURN_WINDOW_S,
    _Points,
    _steady_points,
    axis_near_prior,
    half_separation_deg,
    wind_axis_deg,
)
from sailroute.analysis.infer_fit import (
    BAND_DEG,
    DOWN_MODEL_SD,
    DOWN_OFF_DEG,
    GAMMA_PRIOR_DEG,
    LAMBDA_SCALE,
    N_ITER,
    RUN_GAMMA_DEG,
    RUN_MODEL_SD,
    RUN_WEIGHT,
    UP_HALF_DEG,
    UP_MODEL_SD,
    _group_var,
    _joint_fit,
    _local_linear,
)
from sailroute.boat.model import BoatModel
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.timeutil import iso
from sailroute.track.kinematics import track_xy
from sailroute.track.model import Track
from sailroute.units import KNOT, circular_mean_deg, wind_components, wrap180, wrap360
from sailroute.wind.base import Coverage, prepare_points

__all__ = [
    "ALPHA_PRIOR_DEG",
    "AXIS_TIE",
    "BAND_DEG",
    "COG_WINDOW_S",
    "CORR_S",
    "DOWN_MODEL_SD",
    "DOWN_OFF_DEG",
    "GAMMA_PRIOR_DEG",
    "KNOT_S",
    "LAMBDA_SCALE",
    "MAX_APART_M",
    "MAX_GAP_S",
    "MAX_SD_DEG",
    "MAX_SPAN_S",
    "MIN_BOARD_POINTS",
    "MIN_OBS_S",
    "MIN_SPEED_MS",
    "N_ITER",
    "PAD_S",
    "ROUNDING_DEG",
    "ROUNDING_PAD_S",
    "RUN_GAMMA_DEG",
    "RUN_MODEL_SD",
    "RUN_WEIGHT",
    "SEPARATION_MARGIN_DEG",
    "STEP_S",
    "TURN_DEG",
    "TURN_WINDOW_S",
    "UP_HALF_DEG",
    "UP_MODEL_SD",
    "WINDOW_S",
    "InferredWind",
    "InferredWindField",
    "axis_near_prior",
    "half_separation_deg",
    "infer_wind",
    "summary",
    "wind_axis_deg",
]

MIN_SPEED_MS: Final = 1.0
"""Points slower than this [m s⁻¹] are rejected (no steady course)."""

KNOT_S: Final = 20.0
"""Knot spacing of the piecewise-linear TWD(t) of the joint fit [s]."""

STEP_S: Final = 30.0
"""Default output grid step [s]."""

WINDOW_S: Final = 90.0
"""Default full width of the output smoothing kernel [s]."""

ALPHA_PRIOR_DEG: Final = (42.0, 10.0)
"""Prior of a tacking half-angle without a polar: mean and sd [°] (keeps a boat that
sails one board only solvable; the data dominate otherwise)."""

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
        default_factory=lambda: MappingProxyType({})
    )

    def __post_init__(self) -> None:
        n = np.shape(self.t)
        bad = [
            k
            for k in ("twd_deg", "twd_sd_deg", "tws_ms", "tws_sd_ms", "n_obs")
            if np.shape(getattr(self, k)) != n
        ]
        if len(n) != 1 or bad:
            raise InputError(
                f"InferredWind: {', '.join(bad) or 't'} must be 1-D arrays of the "
                f"length of t ({n}); build it with infer_wind"
            )
        if not isinstance(self.half_angles_deg, MappingProxyType):
            raise TypeError(
                "InferredWind.half_angles_deg must be a read-only mapping "
                f"(types.MappingProxyType), got {type(self.half_angles_deg).__name__}; "
                "pass MappingProxyType(dict(half_angles))"
            )

    def field(
        self, frame: LocalFrame | None = None, tws_ms: float | None = None, *, clamp: bool = False
    ) -> InferredWindField:
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
                    "tws_ms=... (m/s, >= 0)"
                )
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
        return Coverage(
            float(self.times[0]), float(self.times[-1]), -inf, inf, -inf, inf, frame=self.frame
        )

    def sample(
        self, t: ArrayLike, x: ArrayLike, y: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s] and ``x, y`` [m] (broadcast)."""
        t, x, y = prepare_points(self.coverage, t, x, y, clamp=self.clamp, name="inferred wind")
        d = np.interp(t, self.times, self.twd_unwrapped_deg)
        s = np.interp(t, self.times, self.tws_ms)
        u, v = wind_components(s, d)
        return np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)


def _unwrap_deg(a: NDArray) -> NDArray[np.float64]:
    return np.degrees(np.unwrap(np.radians(np.asarray(a, float))))


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


def _gamma_priors(
    p: _Points, n_boats: int, twd_axis: float, default: float
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
        return cands[k], (
            f"up/down from the boards' separation (no prior): {sep[k]:.0f}° "
            f"either side upwind, {sep[1 - k]:.0f}° downwind"
        )
    speeds = []
    for c in cands:
        a = np.abs(wrap180(c - p.cog))
        speeds.append(float(np.median(p.sog[a < 70])) if (a < 70).any() else np.inf)
    k = int(np.argmin(speeds))  # upwind: the slower boards
    return cands[k], (
        f"up/down from speeds (no prior; boards {sep[0]:.0f}° and {sep[1]:.0f}° "
        f"either side): upwind boards {speeds[k] / KNOT:.1f} kn, "
        f"downwind {speeds[1 - k] / KNOT:.1f} kn"
    )


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
                "different places; infer each race on its own tracks"
            )


def _check_inputs(
    tracks: Sequence[Track] | Track,
    step_s: float,
    window_s: float,
    prior: float | None,
    min_speed_ms: float,
) -> list[Track]:
    trs = [tracks] if isinstance(tracks, Track) else list(tracks)
    if not trs:
        raise InputError("infer_wind: no tracks given; pass one or more Track objects")
    for i, tr in enumerate(trs):
        if not isinstance(tr, Track):
            raise InputError(
                f"infer_wind: item {i} is a {type(tr).__name__}, not a Track; "
                "read tracks with sailroute.track.read_track"
            )
    for name, v, unit in (
        ("step_s", step_s, "s"),
        ("window_s", window_s, "s"),
        ("min_speed_ms", min_speed_ms, "m/s"),
    ):
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
        raise InputError(
            f"infer_wind: empty time span {iso(t0)} .. {iso(t1)}; "
            "give t0 < t1 within the tracks' times"
        )
    if t1 - t0 > MAX_SPAN_S:
        raise InputError(
            f"infer_wind: the time span {iso(t0)} .. {iso(t1)} is {(t1 - t0) / 3600:.1f} h, "
            f"more than {MAX_SPAN_S / 3600:.0f} h (tracks of different days?); infer one race "
            "at a time: give t0 and t1, or the tracks of one race"
        )
    _check_same_place(trs, frame, t0, t1)
    names = [tr.name or f"track {i + 1}" for i, tr in enumerate(trs)]
    p, notes = _steady_points(trs, frame, t0, t1, min_speed_ms)
    if p.t.size < 60:
        raise InputError(
            f"infer_wind: only {p.t.size} steady points (faster than {min_speed_ms} m/s, "
            f"not turning) in {iso(t0)} .. {iso(t1)}; need at least 60: give longer tracks "
            "or the race's time span"
        )
    # 1. the axis and which end is upwind
    axis, strength = wind_axis_deg(p.cog, p.weight)
    if prior_twd_deg is not None:
        tied = axis_near_prior(p.cog, float(prior_twd_deg), p.weight)
        if tied != axis:
            notes.append(
                f"the tracks' courses are nearly as symmetric about {tied:.0f}° as "
                f"about {axis:.0f}° (within {100 * AXIS_TIE:.0f} %): the prior "
                "decides"
            )
            axis = tied
    cands = (axis, axis + 180.0)
    if prior_twd_deg is not None:
        twd_axis = min(cands, key=lambda c: abs(float(wrap180(c - prior_twd_deg))))
        off = float(wrap180(twd_axis - prior_twd_deg))
        prior = float(wrap360(prior_twd_deg))
        how = f"up/down from the prior TWD {prior:.0f}° (tracks' axis {off:+.0f}° off it)"
        if abs(off) > 60.0:
            notes.append(
                f"the tracks' wind axis lies {off:+.0f}° from the prior "
                f"{prior:.0f}°: check the prior"
            )
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
    fit_up = _joint_fit(
        p,
        K,
        knots,
        np.full(knots.size, float(twd_axis)),
        np.full(K, a0),
        np.full(K, g0),
        a_sd,
        window_s,
        use_down=False,
    )
    g0s, g_sd = _gamma_priors(p, K, float(twd_axis), g0)
    fit = _joint_fit(
        p,
        K,
        knots,
        fit_up.twd,
        fit_up.alpha,
        g0s,
        a_sd,
        window_s,
        gamma_prior_sd=g_sd,
        alpha_sd_fixed=fit_up.alpha_sd,
    )
    n_up, n_dn = int(fit.up.sum()), int((fit.used & ~fit.up).sum())
    n_stbd = int((fit_up.up & (fit_up.side > 0)).sum())
    n_port = int((fit_up.up & (fit_up.side < 0)).sum())
    if n_stbd + n_port < MIN_BOARD_POINTS and n_dn >= 60:
        raise InputError(
            f"infer_wind: no upwind boards with the wind from {wrap360(twd_axis):.0f}° "
            f"({how}), but {n_dn} points on downwind boards: the wind more likely comes from "
            f"the other end of the axis, {wrap360(twd_axis + 180.0):.0f}°; check "
            "prior_twd_deg"
        )
    if n_up + n_dn < 60 or min(n_stbd, n_port) < MIN_BOARD_POINTS:
        raise InputError(
            f"infer_wind: {n_stbd} starboard and {n_port} port upwind points, {n_dn} downwind "
            f"(need {MIN_BOARD_POINTS} on each upwind board): the wind cannot be told from "
            "one course; give a span with at least one beat sailed on both tacks"
        )
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
    curv = np.interp(tg, fit.knots[1:-1], np.diff(fit.twd, 2) / (fit.knots[1] - fit.knots[0]) ** 2)
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
            e2, v2, _, _ = _local_linear(tg, p.t[ok], s_pt[ok], p.weight[ok], h, 1.0 / p.weight[ok])
            sec2 = _seconds_in_window(tg, p.t[ok], h, p.weight[ok])
            good = np.isfinite(e2) & (sec2 >= MIN_OBS_S) & ~bad
            tws = np.where(good, np.maximum(e2, 0.0), np.nan)
            tws_sd = np.where(good, np.sqrt(v2), np.nan)
            s_med = float(np.nanmedian(tws)) if np.isfinite(tws).any() else float("nan")
            up_pol = boat.vmg_angles_deg(s_med)[0] if np.isfinite(s_med) else float("nan")
            notes.append(
                f"TWS from the polar {getattr(boat, 'name', '')!r}: the wind in which "
                f"it sails the observed speeds (median {s_med / KNOT:.1f} kn); check: "
                f"its best-VMG upwind angle there is {up_pol:.1f}°, the boats' "
                "tacking half-angles " + ", ".join(f"{a:.1f}°" for a in fit.alpha)
            )
        else:
            notes.append("TWS not inferred: too few points within the polar's speed range")
    half = {names[k]: (float(fit.alpha[k]), float(180.0 - fit.gamma[k])) for k in range(K)}
    for k in range(K):
        nk_up = int((fit.up & (p.boat == k)).sum())
        nk_dn = int((fit.used & ~fit.up & (p.boat == k)).sum())
        down = (
            f"runs (downwind held at 180°, {RUN_WEIGHT:g} weight)"
            if abs(fit.gamma[k]) < RUN_GAMMA_DEG and fit.gamma_sd[k] < 0.01
            else f"gybing half-angle {180.0 - fit.gamma[k]:.1f} ± {fit.gamma_sd[k]:.1f}°"
        )
        weak = (
            f" (weakly determined by the track: leans on its prior {a0:.0f}° ± "
            f"{a_sd:.0f}°{', the polar' if boat is not None else ''})"
            if fit.alpha_sd[k] > 0.5 * a_sd
            else ""
        )
        notes.append(
            f"{names[k]}: tacking half-angle {fit.alpha[k]:.1f} ± "
            f"{fit.alpha_sd[k]:.1f}°{weak}, {down} ({nk_up} upwind, {nk_dn} downwind "
            "points)"
        )
    method = (
        f"inferred from {K} track(s): {n_up} upwind and {n_dn} downwind board points "
        f"(course ± fitted half-angles), window {window_s:.0f} s, "
        f"course scatter {fit.sigma[0]:.1f}° upwind / {fit.sigma[1]:.1f}° downwind"
        + ("; TWS from the polar" if boat is not None else "; TWS not inferred (no polar)")
    )
    return InferredWind(
        tg, twd, sd, tws, tws_sd, n.astype(np.int64), method, tuple(notes), MappingProxyType(half)
    )


def _seconds_in_window(tg: NDArray, t: NDArray, h: float, weight: NDArray) -> NDArray[np.float64]:
    """Seconds of steady track within ``tg ± h``: each point stands for its sampling
    interval, up to ``CORR_S`` (``weight * CORR_S``); ``t`` sorted."""
    c = np.concatenate([[0.0], np.cumsum(weight * CORR_S)])
    return np.asarray(
        c[np.searchsorted(t, tg + h, side="right")] - c[np.searchsorted(t, tg - h, side="left")],
        dtype=float,
    )


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
        return out | {
            k: None
            for k in (
                "twd_mean_deg",
                "twd_min_deg",
                "twd_max_deg",
                "twd_range_deg",
                "twd_shift_rms_deg",
                "twd_sd_median_deg",
                "tws_mean_ms",
                "tws_min_ms",
                "tws_max_ms",
                "t_start",
                "t_end",
            )
        }
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
