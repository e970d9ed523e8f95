"""Wind inferred from GPS tracks without instruments: TWD(t) with an honest uncertainty,
and TWS(t) from a source the caller chooses.

A boat racing upwind sails close to its best-VMG angle on each board, so its course over
ground is the wind direction minus (starboard) or plus (port) its tacking half-angle α; a
boat that gybes downwind does the same about the downwind direction; a tack turns the bow
through the wind and a gybe away from it.  Reaches and runs steer for a mark: they bound
the wind more than they tell it.  The method (``docs/analysis.md``, "Wind inferred from
tracks"):

1. **Steady points, boards and turns** (:mod:`~sailroute.analysis.infer_courses`): the
   course of each point over ``COG_WINDOW_S``; points away from manoeuvres, roundings,
   slow stretches and gaps; a board is one boat's run of steady points between two turns,
   and each turn has the courses before and after it.
2. **The wind axis** from the pooled histogram of steady courses: the direction about
   which it is most symmetric.  Which end is upwind: the one nearer ``prior_twd_deg``,
   or without a prior the end about which the boards lie further apart (tacking
   half-angles exceed the downwind boards' angle off dead downwind) and, where that is
   not clear, the slower boards.
3. **Observations** (:mod:`~sailroute.analysis.infer_obs`): each board is an upwind board
   (next to a tack of its boat, at ``α_k``), a downwind board (next to a gybe, at
   ``180° − γ_k``), a run (a box about the course + 180°) or free (a reach, or a board
   the estimate cannot place: only ``|TWA| >= α_k − 8°``); each tack and gybe observes the
   wind through the direction its bow passed half-way round.  The boats' angles come
   from their own tacks and gybes (half the angle turned through), the fleet's, or the
   polar; each boat's scatter about them weights its boards (a boat that holds its
   angles badly counts less), and every likelihood has a floor (an outlier boat cannot
   pull the estimate further than its floor allows).
4. **The smoother** (:mod:`~sailroute.analysis.infer_fit`): TWD on a grid of directions
   follows a random walk between bins of 10 s (its rate chosen by the marginal
   likelihood); the forward-backward recursion gives each bin's posterior.  Its mean is
   the estimate; its spread, plus the fitted angles' uncertainty and an error all boats
   share, the standard error.  Where no board tells the wind the posterior spreads, so
   the standard error grows with the time since the last informative board.  Classes
   and angles are re-fitted ``N_ITER`` times.
5. **TWS** from an explicit source (:class:`~sailroute.analysis.infer_tws.TwsSource`): a
   series (scenario, measured, station) or the polar inverted at the observed speeds.

Assumptions: boats sail close to one angle on each upwind board and on each gybing
downwind board; no current (COG = heading, no leeway); the same angle on both tacks; the
wind uniform over the area the boats sail.
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
    _Boards,
    _Points,
    _steady_points,
    _Turns,
    axis_near_prior,
    half_separation_deg,
    wind_axis_deg,
)
from sailroute.analysis.infer_fit import (
    BIN_S,
    Q_GRID,
    Posterior,
    _local_linear,
    log_marginal,
    smooth,
)
from sailroute.analysis.infer_obs import (
    ALPHA_PRIOR_DEG,
    CLASS_NAMES,
    DOWN,
    DOWN_MODEL_SD,
    FREE,
    GAMMA_PRIOR_DEG,
    GYBE,
    RUN,
    TACK,
    TURN_SD_DEG,
    UP,
    UP_MODEL_SD,
    BoatAngles,
    Obs,
    boat_angles,
    classify_boards,
    left_out,
    log_likelihoods,
    no_go_share,
    observations,
    systematic_var,
    turn_kinds,
)
from sailroute.analysis.infer_tws import TwsSource, invert_polar
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
    "COG_WINDOW_S",
    "CORR_S",
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
    "STEP_S",
    "TURN_DEG",
    "TURN_WINDOW_S",
    "WINDOW_S",
    "InferredWind",
    "InferredWindField",
    "TwsSource",
    "axis_near_prior",
    "half_separation_deg",
    "infer_wind",
    "summary",
    "wind_axis_deg",
]

MIN_SPEED_MS: Final = 1.0
"""Points slower than this [m s⁻¹] are rejected (no steady course)."""

STEP_S: Final = 30.0
"""Default output grid step [s]."""

WINDOW_S: Final = 90.0
"""Default full width of the kernel that smooths TWS and counts ``n_obs`` [s]."""

N_ITER: Final = 4
"""Classify-and-smooth passes."""

SEPARATION_MARGIN_DEG: Final = 10.0
"""Without a prior, the wind axis end about which the boards are this much further apart
[°] is upwind; with a smaller difference the slower boards decide."""

MAX_SPAN_S: Final = 6 * 3600.0
"""Longest time span inferred in one call [s] (one race, or one evening's races)."""

MAX_APART_M: Final = 20_000.0
"""Tracks whose mean positions lie further apart than this [m] are refused."""

MIN_BOARD_POINTS: Final = 20
"""Steady points needed on each side (starboard, port) of the boards that observe the
wind (upwind and gybing downwind boards, all boats together)."""

MIN_OBS_S: Final = 20.0
"""TWS at a grid time needs at least this many seconds of observations in its window."""

POLAR_TWA_SD_DEG: Final = 15.0
"""TWS from the polar uses the steady points whose TWA is known to this standard error
[°]."""

MAX_SD_DEG: Final = 25.0
"""A grid time whose direction has a larger standard error gets none (NaN) [°]: its
posterior spreads over most of a quadrant, the tracks do not tell the wind there."""


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
        Per boat: fitted tacking half-angle α and gybing half-angle 180° − γ [°] (180°
        for a boat that runs).
    tws_source : str
        Where ``tws_ms`` comes from (:data:`~sailroute.analysis.infer_tws.TWS_KINDS`).
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
    tws_source: str = "none"

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

    def sd_at(self, t: float) -> float:
        """Standard error of the direction at ``t`` [°]: linear between the grid times; the
        nearest edge's outside; infinite where no grid time nearby has a direction."""
        ok = np.isfinite(self.twd_sd_deg)
        if not ok.any():
            return float("inf")
        i = int(np.clip(np.searchsorted(self.t, t), 1, max(self.t.size - 1, 1)))
        near = self.twd_sd_deg[max(i - 1, 0) : i + 1]
        if not np.isfinite(near).all():
            return float("inf")
        return float(np.interp(t, self.t[ok], self.twd_sd_deg[ok]))

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


def _same_place(
    trs: Sequence[Track], xy: Sequence[tuple[NDArray, NDArray]], t0: float, t1: float
) -> tuple[list[int], list[str]]:
    """The tracks sailed in one place, and a note for each left out.

    A track whose mean position over the span lies more than ``MAX_APART_M`` from the
    fleet's median is left out when most tracks lie together (a boat of another race:
    one wind does not fit both); with no such majority the tracks are refused.
    """
    centres = []
    for i, (tr, (x, y)) in enumerate(zip(trs, xy, strict=True)):
        m = (tr.t_s >= t0) & (tr.t_s <= t1)
        if m.any():
            centres.append((i, float(np.mean(x[m])), float(np.mean(y[m]))))
    if not centres:
        return [], []
    c = np.array([(x, y) for _, x, y in centres])
    med = np.median(c, axis=0)
    far = np.hypot(*(c - med).T) > MAX_APART_M
    if 2 * int(far.sum()) >= far.size:  # no majority: judge the pairs of all tracks
        far[:] = False
    kept = [centres[j] for j in np.flatnonzero(~far)]
    for (a, xa, ya), (b, xb, yb) in itertools.combinations(kept, 2):
        d = float(np.hypot(xb - xa, yb - ya))
        if d > MAX_APART_M:
            raise InputError(
                f"infer_wind: {trs[a].name or f'track {a + 1}'!r} and "
                f"{trs[b].name or f'track {b + 1}'!r} sailed {d / 1000:.1f} km apart in the "
                f"time span (more than {MAX_APART_M / 1000:.0f} km): one wind does not fit "
                "boats of different places; infer each race on its own tracks"
            )
    names = [trs[i].name or f"track {i + 1}" for i, _, _ in centres]
    notes = [
        f"{n}: left out: sailed {np.hypot(*(c[j] - med)) / 1000:.1f} km from the fleet "
        f"(more than {MAX_APART_M / 1000:.0f} km: another race?)"
        for j, n in enumerate(names)
        if far[j]
    ]
    return [i for j, (i, _, _) in enumerate(centres) if not far[j]], notes


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


def _start_guess(p: _Points, prior_twd_deg: float | None) -> tuple[float, str, list[str]]:
    """The upwind end of the tracks' wind axis [°], how it was decided, and notes."""
    notes: list[str] = []
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
    return float(twd_axis), how, notes


def _angle_priors(
    boat: BoatModel | None, p: _Points
) -> tuple[tuple[float, float], tuple[float, float]]:
    """Priors of the tacking half-angle and of a gybing boat's angle off dead downwind
    [°]: the polar's best-VMG angles at a TWS guessed from the median speed, or the
    defaults."""
    if boat is None:
        return ALPHA_PRIOR_DEG, GAMMA_PRIOR_DEG
    up, down = boat.vmg_angles_deg(float(np.clip(np.median(p.sog) * 1.6, 2.0, 12.0)))
    return (float(up), ALPHA_PRIOR_DEG[1]), (float(180.0 - down), GAMMA_PRIOR_DEG[1])


@dataclass(frozen=True)
class _Pass:
    """The last classify-and-smooth pass."""

    obs: Obs
    post: Posterior
    board_cls: NDArray[np.int64]  # per board
    cls: NDArray[np.int64]  # per board-bin observation
    kinds: NDArray[np.int64]  # per turn
    ang: BoatAngles
    twa: NDArray[np.float64]  # per board-bin, at the posterior mean [°]
    sd: NDArray[np.float64]  # per bin: posterior and systematic [°]
    turn_boat: NDArray[np.int64]  # per turn
    no_go: NDArray[np.float64]  # per boat: share of its time in the no-go zone


@dataclass(frozen=True)
class _Fleet:
    """What the passes work on: the steady points, boards and turns of all boats."""

    p: _Points
    boards: _Boards
    turns: _Turns
    n_boats: int
    t0: float  # start of the first bin [epoch s]
    n_bins: int
    priors: tuple[tuple[float, float], tuple[float, float]]  # α and γ [°]: mean, sd
    at_mark: NDArray[np.bool_]  # per turn: near a mark (a rounding)


def _passes(f: _Fleet, prior_twd_deg: float | None) -> tuple[_Pass, float, str, list[str]]:
    """Classify, fit the boats' angles and smooth, ``N_ITER`` times (module notes); the
    passes start again without the boats the first pass finds not racing in this wind
    (:func:`~sailroute.analysis.infer_obs.left_out`).  Also the upwind end of the wind
    axis, how it was decided, and notes."""
    use = np.ones(f.n_boats, bool)
    for _ in range(3):
        mine = use[f.p.boat]
        kept = _Points(
            *(getattr(f.p, k)[mine] for k in ("t", "cog", "sog", "boat", "weight", "board"))
        )
        start, how, notes = _start_guess(kept, prior_twd_deg)
        res, again = _pass_loop(f, start, use)
        if not again.any():
            break
        use = use & ~again
    return res, start, how, notes


def _pass_loop(f: _Fleet, start: float, use: NDArray[np.bool_]) -> tuple[_Pass, NDArray[np.bool_]]:
    """The passes with the boats ``use``; stops after the first when it finds more boats
    to leave out (returned)."""
    p, boards, turns, n_boats, t0, n_bins = f.p, f.boards, f.turns, f.n_boats, f.t0, f.n_bins
    priors, at_mark = f.priors, f.at_mark
    obs = observations(p, t0, n_bins)
    tb = t0 + (np.arange(n_bins) + 0.5) * BIN_S
    un = np.full(n_bins, start)
    sd = np.full(n_bins, 10.0)
    ang = BoatAngles(
        np.full(n_boats, priors[0][0]),
        np.full(n_boats, priors[0][1]),
        np.full(n_boats, priors[1][0]),
        np.full(n_boats, priors[1][1]),
        np.zeros(n_boats, bool),
        np.full(n_boats, UP_MODEL_SD),
        np.full(n_boats, DOWN_MODEL_SD),
        np.full(n_boats, TURN_SD_DEG),
        use.copy(),
    )
    res: _Pass | None = None
    q = Q_GRID[0]
    for it in range(N_ITER):
        twa = wrap180(np.interp(obs.t, tb, un) - obs.cog)
        sd_obs = np.interp(obs.t, tb, sd)
        twd_turn = np.interp(turns.t, tb, un)
        loose = turn_kinds(turns, twd_turn, None, at_mark)
        bcls = classify_boards(obs, boards, loose, ang, twa, sd_obs)
        ang = boat_angles(
            n_boats, obs, bcls[obs.board], twa, turns, loose, twd_turn, *priors, ang.use
        )
        kinds = turn_kinds(turns, twd_turn, ang, at_mark)
        bcls = classify_boards(obs, boards, kinds, ang, twa, sd_obs)
        cls = bcls[obs.board]
        ll_boards, ll_bounds, ll_turns = log_likelihoods(obs, cls, turns, kinds, ang, t0, n_bins)
        ll = ll_boards + ll_bounds + ll_turns
        if it < 2:  # the rate settles with the classes of the first passes
            q = max(
                Q_GRID[int(np.argmax(log_marginal(ll, start)))],
                Q_GRID[int(np.argmax(log_marginal(ll_turns, start)))],
            )
        post = smooth(ll, start, q)
        un = np.degrees(np.unwrap(np.radians(post.mean_deg)))
        twa = wrap180(np.interp(obs.t, tb, un) - obs.cog)
        sd = np.sqrt(post.sd_deg**2 + systematic_var(obs, cls, ang, twa, n_bins))
        if it == 0:
            # which boats sail where no racing boat goes, in the wind the beats, gybes and
            # turns tell (the bounds of a boat that is not racing would move that wind)
            info = smooth(ll_boards + ll_turns, start, q)
            un_i = np.degrees(np.unwrap(np.radians(info.mean_deg)))
            share = no_go_share(
                obs,
                wrap180(np.interp(obs.t, tb, un_i) - obs.cog),
                np.interp(obs.t, tb, info.sd_deg),
                ang,
            )
            out = use & left_out(share, use)
        res = _Pass(obs, post, bcls, cls, kinds, ang, twa, sd, turns.boat, share)
        if out.any():
            return res, out
    assert res is not None
    return res, np.zeros(n_boats, bool)


def _at_marks(turns: _Turns, marks: Sequence[tuple[float, float]]) -> NDArray[np.bool_]:
    """True for the turns whose peak lies within ``turns.near_m`` of a mark."""
    near = np.zeros(turns.t.size, bool)
    for mx, my in marks:
        near |= np.hypot(turns.x - float(mx), turns.y - float(my)) <= turns.near_m
    return near


def _check_boards(p: _Points, res: _Pass, start: float, how: str) -> None:
    """Refuse a span whose observing boards lie on one side only, or that has downwind
    boards but no upwind ones (the prior on the wrong end of the axis)."""
    cls = res.board_cls[p.board]
    i = np.searchsorted(res.obs.t, p.t).clip(0, res.obs.t.size - 1)
    side = res.twa[i] >= 0.0
    n = {(c, s): int(((cls == c) & (side == s)).sum()) for c in (UP, DOWN) for s in (True, False)}
    n_up = n[UP, True] + n[UP, False]
    n_dn = n[DOWN, True] + n[DOWN, False] + int((cls == RUN).sum())
    if n_up < MIN_BOARD_POINTS and n[DOWN, True] + n[DOWN, False] >= 60:
        raise InputError(
            f"infer_wind: no upwind boards with the wind from {wrap360(start):.0f}° "
            f"({how}), but {n_dn} points on downwind boards: the wind more likely comes from "
            f"the other end of the axis, {wrap360(start + 180.0):.0f}°; check "
            "prior_twd_deg"
        )
    if (
        min(n[UP, True], n[UP, False]) < MIN_BOARD_POINTS
        and min(n[DOWN, True], n[DOWN, False]) < MIN_BOARD_POINTS
    ):
        raise InputError(
            f"infer_wind: {n[UP, True]} starboard and {n[UP, False]} port upwind points, "
            f"{n[DOWN, True]} and {n[DOWN, False]} on gybing downwind boards (need "
            f"{MIN_BOARD_POINTS} on each board of a beat or of a gybing run): the wind "
            "cannot be told from one course; give a span with at least one beat sailed on "
            "both tacks"
        )


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
    tws: TwsSource | None = None,
    marks: Sequence[tuple[float, float]] = (),
    xy: Sequence[tuple[NDArray, NDArray]] | None = None,
) -> InferredWind:
    """Estimate TWD(t) with its uncertainty, and TWS(t) from a chosen source, from boats'
    GPS tracks.

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
        The boats' polar: the prior of the boats' angles (its best-VMG angles at a TWS
        guessed from the median speed), and TWS by inverting it when ``tws`` is not
        given.  Without it the angles come from the fleet's own tacks and gybes.
    t0, t1 : float, optional
        Time span [epoch s] of the grid; default the tracks' span (at most
        ``MAX_SPAN_S``).
    step_s : float
        Grid step [s].
    window_s : float
        Full width [s] of the kernel that smooths TWS and counts ``n_obs``.
    min_speed_ms : float
        Points slower than this are rejected [m s⁻¹].
    tws : TwsSource, optional
        Where TWS comes from (:class:`~sailroute.analysis.infer_tws.TwsSource`): a series
        (scenario, measured, station), the polar inverted, or none.  Default: the polar
        of ``boat`` when given, else none.
    marks : sequence of (float, float)
        The course's marks (gate and line ends too) in ``frame`` [m]: a turn near one is
        a rounding, not a tack or a gybe (a rounding from a reach to a broad reach turns
        the stern through the wind as a gybe does, with courses that are not symmetric
        about it).
    xy : sequence of (x, y) arrays, optional
        Each track's fixes already in ``frame`` [m], in the order of ``tracks`` (a
        caller that projected them; default: projected here).

    Returns
    -------
    InferredWind

    Raises
    ------
    InputError
        No tracks, bad parameters, an empty or too long time span, tracks sailed more
        than ``MAX_APART_M`` apart with no majority of them together, too few steady
        points, boards on one side only or no upwind boards (the message says how many).
    """
    trs = _check_inputs(tracks, step_s, window_s, prior_twd_deg, min_speed_ms)
    if tws is None:
        tws = TwsSource.polar(boat) if boat is not None else TwsSource.none()
    if not isinstance(tws, TwsSource):
        raise InputError(
            f"infer_wind: tws must be a TwsSource, got {type(tws).__name__}; build one with "
            "TwsSource.from_series, TwsSource.from_field, TwsSource.polar or TwsSource.none"
        )
    have = [tr for tr in trs if len(tr)]
    ta = min(float(tr.t_s[0]) for tr in have) if have else 0.0
    tb = max(float(tr.t_s[-1]) for tr in have) if have else 0.0
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
    if xy is None or len(xy) != len(trs):
        xy = [track_xy(tr, frame) for tr in trs]
    keep, far_notes = _same_place(trs, xy, t0, t1)
    trs, xy = [trs[i] for i in keep], [xy[i] for i in keep]
    names = [tr.name or f"track {i + 1}" for i, tr in enumerate(trs)]
    p, boards, turns, notes = _steady_points(trs, frame, t0, t1, min_speed_ms, xy)
    notes = far_notes + notes
    if p.t.size < 60:
        raise InputError(
            f"infer_wind: only {p.t.size} steady points (faster than {min_speed_ms} m/s, "
            f"not turning) in {iso(t0)} .. {iso(t1)}; need at least 60: give longer tracks "
            "or the race's time span"
        )
    K = len(trs)
    n_bins = int(np.ceil((t1 - t0) / BIN_S)) + 1
    priors = _angle_priors(boat, p)
    at_mark = _at_marks(turns, marks)
    res, start, how, axis_notes = _passes(
        _Fleet(p, boards, turns, K, t0, n_bins, priors, at_mark), prior_twd_deg
    )
    notes.extend(axis_notes)
    _check_boards(p, res, start, how)
    # the output grid
    tg = np.arange(t0, t1 + 1e-6, step_s)
    tbin = t0 + (np.arange(n_bins) + 0.5) * BIN_S
    un = np.degrees(np.unwrap(np.radians(res.post.mean_deg)))
    sd_all = np.interp(tg, tbin, res.sd)
    bad = ~(sd_all <= MAX_SD_DEG)
    twd = np.where(bad, np.nan, wrap360(np.interp(tg, tbin, un)))
    sd = np.where(bad, np.nan, sd_all)
    h = 0.5 * window_s
    n = np.searchsorted(p.t, tg + h, side="right") - np.searchsorted(p.t, tg - h, side="left")
    tws_ms, tws_sd, tws_note = _tws(tws, tg, p, res, tbin, un, h, bad)
    notes.append(tws_note)
    notes.extend(_boat_notes(names, p, res, boat is not None))
    used = res.ang.use[res.obs.boat]
    sec = np.bincount(res.cls[used], res.obs.seconds[used], 4)
    turned = res.ang.use[res.turn_boat]
    n_out = int((~res.ang.use).sum())
    method = (
        f"inferred from {K - n_out} track(s)"
        + (f" ({n_out} left out)" if n_out else "")
        + ": "
        + ", ".join(f"{sec[c]:.0f} s on {CLASS_NAMES[c]}s" for c in (UP, DOWN, RUN, FREE))
        + f"; {int((turned & (res.kinds == TACK)).sum())} tacks, "
        f"{int((turned & (res.kinds == GYBE)).sum())} "
        f"gybes; random walk {res.post.q:g} °²/s; TWS from {tws.kind}"
        + (f" ({tws.label})" if tws.label and tws.label != tws.kind else "")
    )
    half = {names[k]: (float(res.ang.alpha[k]), float(180.0 - res.ang.gamma[k])) for k in range(K)}
    return InferredWind(
        tg,
        twd,
        sd,
        tws_ms,
        tws_sd,
        n.astype(np.int64),
        method,
        tuple(notes),
        MappingProxyType(half),
        tws.kind,
    )


def _tws(
    src: TwsSource,
    tg: NDArray,
    p: _Points,
    res: _Pass,
    tbin: NDArray,
    un: NDArray,
    h: float,
    bad: NDArray,
) -> tuple[NDArray[np.float64], NDArray[np.float64], str]:
    """TWS and its sd on the grid from the chosen source, and a note."""
    nan = np.full(tg.size, np.nan)
    if src.kind == "none":
        return nan, nan.copy(), "TWS not inferred (no source chosen)"
    if src.kind != "polar":
        s, sd = src.at(tg)
        return s, sd, f"TWS from the {src.kind} ({src.label})"
    boat = src.boat
    assert boat is not None
    twa = wrap180(np.interp(p.t, tbin, un) - p.cog)
    used = np.interp(p.t, tbin, res.sd) <= POLAR_TWA_SD_DEG  # the TWA is known
    s_pt = invert_polar(boat, twa, p.sog)
    ok = used & np.isfinite(s_pt)
    if ok.sum() < 30:
        return nan, nan.copy(), "TWS not inferred: too few points within the polar's speed range"
    e2, v2, _, _ = _local_linear(tg, p.t[ok], s_pt[ok], p.weight[ok], h, 1.0 / p.weight[ok])
    sec2 = _seconds_in_window(tg, p.t[ok], h, p.weight[ok])
    good = np.isfinite(e2) & (sec2 >= MIN_OBS_S) & ~bad
    tws = np.where(good, np.maximum(e2, 0.0), np.nan)
    tws_sd = np.where(good, np.sqrt(v2), np.nan)
    s_med = float(np.nanmedian(tws)) if np.isfinite(tws).any() else float("nan")
    up_pol = boat.vmg_angles_deg(s_med)[0] if np.isfinite(s_med) else float("nan")
    return (
        tws,
        tws_sd,
        f"TWS from the polar {getattr(boat, 'name', '')!r}: the wind in which it sails the "
        f"observed speeds (median {s_med / KNOT:.1f} kn); check: its best-VMG upwind angle "
        f"there is {up_pol:.1f}°, the boats' tacking half-angles "
        + ", ".join(f"{a:.1f}°" for a in res.ang.alpha),
    )


def _boat_notes(
    names: Sequence[str],
    p: _Points,
    res: _Pass,
    polar: bool,
) -> list[str]:
    """One line per boat: its angles, how well it holds them, its boards."""
    out = []
    ang = res.ang
    cls = res.board_cls[p.board]
    for k, name in enumerate(names):
        if not ang.use[k]:
            out.append(
                f"{name}: left out: {100 * res.no_go[k]:.0f} % of its steady time closer to "
                "the wind than any boat sails (not racing in this wind: a coach boat, "
                "another race?)"
            )
            continue
        mine = p.boat == k
        n_up = int((mine & (cls == UP)).sum())
        n_dn = int((mine & np.isin(cls, (DOWN, RUN))).sum())
        n_tk = int(((res.kinds == TACK) & (res.turn_boat == k)).sum())
        down = (
            "runs (a box about dead downwind)"
            if ang.runner[k]
            else f"gybing half-angle {180.0 - ang.gamma[k]:.1f} ± {ang.gamma_sd[k]:.1f}°"
        )
        weak = (
            f" (no tacks of its own: the fleet's{' and the polar' if polar else ''})"
            if n_tk == 0
            else ""
        )
        out.append(
            f"{name}: tacking half-angle {ang.alpha[k]:.1f} ± {ang.alpha_sd[k]:.1f}°{weak} "
            f"from {n_tk} tacks, boards within {ang.sd_up[k]:.1f}°, {down} ({n_up} upwind, "
            f"{n_dn} downwind points)"
        )
    return out


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
        ``twd_mean_deg`` (circular mean, each grid time weighted by ``1 / sd²``: a
        stretch where the tracks hardly tell the wind counts little),
        ``twd_min_deg``/``twd_max_deg`` and ``twd_range_deg`` (of the unwrapped series),
        ``twd_shift_rms_deg`` (RMS of TWD about its mean, weighted alike),
        ``twd_sd_median_deg``, ``tws_mean_ms``/``tws_min_ms``/
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
    w = 1.0 / np.maximum(inferred.twd_sd_deg[ok], 1e-3) ** 2
    mean = circular_mean_deg(d, w)
    dev = wrap180(d - mean)
    s = inferred.tws_ms[ok]
    s = s[np.isfinite(s)]
    return out | {
        "twd_mean_deg": round(mean, 2) % 360.0,
        "twd_min_deg": round(float(wrap360(mean + dev.min())), 2),
        "twd_max_deg": round(float(wrap360(mean + dev.max())), 2),
        "twd_range_deg": round(float(dev.max() - dev.min()), 2),
        "twd_shift_rms_deg": round(float(np.sqrt(np.sum(w * dev**2) / np.sum(w))), 2),
        "twd_sd_median_deg": round(float(np.median(inferred.twd_sd_deg[ok])), 2),
        "tws_mean_ms": round(float(s.mean()), 3) if s.size else None,
        "tws_min_ms": round(float(s.min()), 3) if s.size else None,
        "tws_max_ms": round(float(s.max()), 3) if s.size else None,
        "t_start": iso(float(inferred.t[ok][0])),
        "t_end": iso(float(inferred.t[ok][-1])),
    }
