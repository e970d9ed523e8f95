"""What each board and turn says about TWD (step 3 of :mod:`sailroute.analysis.infer_wind`).

Every board (one boat's steady points between two turns) and every turn is one of:

* **upwind board** (``UP``): sailed close-hauled, ``|TWA| = α_k`` (the boat's tacking
  half-angle) with a scatter ``sd_up_k``; only a board that begins or ends with a tack
  of the same boat (a beat is sailed in tacks; a close reach is not);
* **downwind board** (``DOWN``): of a boat that gybes through a clear angle,
  ``|TWA| = 180° − γ_k`` (``γ_k`` its angle off dead downwind), next to a gybe;
* **run** (``RUN``): within ``RUN_BOX_DEG`` of dead downwind: the wind lies in a box
  of that half-width about the course + 180° (a run steers for the mark: its course
  says little more);
* **free** (``FREE``): anything else (a reach, a leg sailed on one board, a board the
  estimate cannot place): only a bound, the boat sails no higher than close-hauled,
  ``|TWA| >= α_k − FREE_MARGIN_DEG``;
* **tack / gybe**: the direction the bow passed through half-way round points into the
  wind (a tack) or away from it (a gybe), with an sd ``TURN_SD_DEG``.

A board's class is decided from the current estimate of TWD and its uncertainty, and
from the turns at its ends; its likelihood on the direction grid is a Gaussian in |TWA|
(up, down, turns) or a soft box (run, free) above a floor ``EPS`` (an outlier costs at
most ``-log EPS``), each board-bin's log likelihood tempered by its share of
``MODEL_CORR_S`` (how long a boat's angle errors last: 30 s of a board count once).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import NDArray
from scipy.special import ndtr

from sailroute.analysis.infer_courses import CORR_S, _Boards, _Points, _Turns
from sailroute.analysis.infer_fit import BIN_S, GRID_DEG, grid_deg
from sailroute.units import wrap180

UP, DOWN, RUN, FREE, TACK, GYBE = 0, 1, 2, 3, 4, 5
"""Observation classes."""

CLASS_NAMES: Final = ("upwind board", "downwind board", "run", "free", "tack", "gybe")

EPS: Final = 0.02
"""Floor of every likelihood (its peak is 1): one board that fits no direction costs at
most ``-log EPS`` ≈ 3.9 in the log likelihood, however far off it is."""

MODEL_CORR_S: Final = 30.0
"""A board's angle errors last this long [s]: each board-bin's log likelihood is
weighted by its seconds of steady points over this (at most 1)."""

BAND_UP_DEG: Final = 12.0
"""A tack-bounded board is upwind when its |TWA| lies within this of ``α_k`` plus twice
the estimate's sd [°]."""

BAND_DOWN_DEG: Final = 15.0
"""The same for a gybe-bounded board and ``180° − γ_k`` [°]."""

BAND_MAX_DEG: Final = 30.0
"""The bands never widen beyond this [°]."""

RUN_BOX_DEG: Final = 30.0
"""A run: the wind within this of the course + 180° [°] (a run steers for the mark, up to
~20° by the lee or broad)."""

FREE_MARGIN_DEG: Final = 8.0
"""A free board sails no higher than ``α_k`` minus this [°]."""

EDGE_SD_DEG: Final = 3.0
"""Softness of the edges of the run and free boxes [°]."""

TURN_SD_DEG: Final = 6.0
"""Sd of the bow's half-way direction about the wind (or its reciprocal) [°]: shifts
during the turn and boards sailed at different angles."""

TURN_MID_DEG: Final = 40.0
"""A turn is a tack when the bow's half-way direction lies within this of the estimated
TWD, a gybe when within this of TWD + 180° [°]."""

TURN_BAND_DEG: Final = 25.0
"""A tack turns through twice the boat's tacking half-angle, a gybe through twice its
angle off dead downwind, within this [°]."""

TACK_DEG: Final = (50.0, 135.0)
"""Range of turn angles of a tack [°] (SailGP's F50s tack through 80-130° over the
ground)."""

GYBE_DEG: Final = (30.0, 110.0)
"""Range of turn angles of a gybe [°] (a wider turn through dead downwind is a rounding
from a reach to a broad reach; SailGP's F50s gybe through 55-100°)."""

UP_MODEL_SD: Final = 3.0
"""Least sd of a boat's upwind boards about ``α_k`` [°]: the VMG optimum is flat, so a
boat sails a few degrees higher or lower at little cost."""

DOWN_MODEL_SD: Final = 4.0
"""Least sd of a gybing boat's downwind boards about ``180° − γ_k`` [°]."""

RUN_GAMMA_DEG: Final = 12.0
"""A boat that sails within this of dead downwind for a quarter of its downwind time
runs [°]."""

ALPHA_PRIOR_DEG: Final = (42.0, 10.0)
"""Prior of a tacking half-angle without a polar: mean and sd [°]."""

GAMMA_PRIOR_DEG: Final = (25.0, 10.0)
"""Prior of a gybing boat's angle off dead downwind without a polar: mean and sd [°]."""

NO_GO_FRACTION: Final = 0.6
"""The no-go zone of :func:`no_go_share`: this fraction of a boat's tacking half-angle
either side of the wind [-]."""

NO_GO_SPEED: Final = 0.6
"""Only a boat this fast (a share of its median speed) in the no-go zone counts [-]."""

NO_GO_SHARE: Final = 0.03
"""A boat that spends more than this share of its steady time in the no-go zone is not
racing in this wind and is left out [-] (:func:`left_out`; the SailGP F50s: at most
0.3 %; a coach boat driven at random: 3.5-31 %)."""

COMMON_SD_DEG: Final = (4.5, 4.5)
"""Sd of an error all boats share on upwind and on downwind boards [°]: it does not
average down with the number of boats.  A fleet that pinches into a tack at a header and
holds its heading as the wind lifts reads as a wind that shifts less than it does, and
no course tells the difference: sailroute's own routes sail 34-39° into a tack and
40-50° on the board, and in a wind that swings ±10° every 6 min the boards show ±3-5°."""


@dataclass(frozen=True)
class BoatAngles:
    """Each boat's angles and how well it holds them [°] (index: boat).

    ``gamma`` is 0 for a boat that runs (``runner``); ``sd_up``, ``sd_down`` and ``sd_turn``
    are the scatter of its upwind boards, downwind boards and turns about the estimate:
    a boat that fits badly counts for less.  ``use`` is False for a boat left out
    (:func:`no_go_share`).
    """

    alpha: NDArray[np.float64]
    alpha_sd: NDArray[np.float64]
    gamma: NDArray[np.float64]
    gamma_sd: NDArray[np.float64]
    runner: NDArray[np.bool_]
    sd_up: NDArray[np.float64]
    sd_down: NDArray[np.float64]
    sd_turn: NDArray[np.float64]
    use: NDArray[np.bool_]


@dataclass(frozen=True)
class Obs:
    """One row per board and time bin: the board's steady points in that bin."""

    bin: NDArray[np.int64]
    board: NDArray[np.int64]
    boat: NDArray[np.int64]
    t: NDArray[np.float64]  # mean time [epoch s]
    cog: NDArray[np.float64]  # circular mean course [°]
    sog: NDArray[np.float64]  # mean speed [m s⁻¹]
    seconds: NDArray[np.float64]  # seconds of independent course (n points x interval)


def observations(p: _Points, t0: float, n_bins: int) -> Obs:
    """The steady points grouped by board and time bin (bins of ``BIN_S`` from ``t0``)."""
    b = np.clip(((p.t - t0) // BIN_S).astype(np.int64), 0, n_bins - 1)
    key = p.board * n_bins + b
    uk, inv = np.unique(key, return_inverse=True)
    w = p.weight
    sw = np.bincount(inv, w)
    r = np.radians(p.cog)
    s, c = np.bincount(inv, w * np.sin(r)), np.bincount(inv, w * np.cos(r))
    first = np.zeros(uk.size, np.int64)
    first[inv[::-1]] = np.arange(inv.size)[::-1]
    return Obs(
        (uk % n_bins).astype(np.int64),
        (uk // n_bins).astype(np.int64),
        p.boat[first],
        np.bincount(inv, w * p.t) / sw,
        np.degrees(np.arctan2(s, c)) % 360.0,
        np.bincount(inv, w * p.sog) / sw,
        np.asarray(sw * CORR_S, dtype=float),
    )


def turn_kinds(
    turns: _Turns,
    twd_deg: NDArray,
    ang: BoatAngles | None = None,
    at_mark: NDArray | None = None,
) -> NDArray[np.int64]:
    """``TACK``, ``GYBE`` or ``FREE`` (another turn: a rounding, a change of course) for
    each turn, in the wind ``twd_deg`` [°] at its time; a turn ``at_mark`` is a rounding.

    A tack's bow passes within ``TURN_MID_DEG`` of the wind, a gybe's stern; with the
    boats' angles ``ang``, a tack also turns through twice the boat's tacking half-angle
    and a gybe through twice its angle off dead downwind, within ``TURN_BAND_DEG``; a
    runner's gybes (a few degrees by the lee either side, or a course change near dead
    downwind) say nothing.  A rounding that passes the wind (a reach
    to a run with a gybe) turns through another angle: its two courses are not symmetric
    about the wind.
    """
    off = np.abs(wrap180(turns.mid - twd_deg))
    # a tack or a gybe joins two steady boards (a luff, a bear-away or a slow turn does not)
    a = np.where(turns.paired if at_mark is None else turns.paired & ~at_mark, turns.angle, np.nan)
    tack = (off <= TURN_MID_DEG) & (a >= TACK_DEG[0]) & (a <= TACK_DEG[1])
    gybe = (off >= 180.0 - TURN_MID_DEG) & (a >= GYBE_DEG[0]) & (a <= GYBE_DEG[1])
    if ang is not None:
        k = turns.boat
        tack &= np.abs(a - 2.0 * ang.alpha[k]) <= TURN_BAND_DEG
        gybe &= ~ang.runner[k] & (np.abs(a - 2.0 * ang.gamma[k]) <= TURN_BAND_DEG)
    return np.where(tack, TACK, np.where(gybe, GYBE, FREE)).astype(np.int64)


def classify_boards(
    obs: Obs,
    boards: _Boards,
    kinds: NDArray,
    ang: BoatAngles,
    twa_deg: NDArray,
    sd_deg: NDArray,
) -> NDArray[np.int64]:
    """The class of every board (module notes), from the board-bins' TWA ``twa_deg`` and
    the estimate's sd ``sd_deg`` at their times [°]."""
    nbd = boards.boat.size
    w = obs.seconds
    r = np.radians(twa_deg)
    s = np.bincount(obs.board, w * np.sin(r), nbd)
    c = np.bincount(obs.board, w * np.cos(r), nbd)
    a = np.abs(np.degrees(np.arctan2(s, c)))
    sw = np.bincount(obs.board, w, nbd)
    sd = np.bincount(obs.board, w * sd_deg, nbd) / np.maximum(sw, 1e-12)
    k = boards.boat

    def adjacent(kind: int) -> NDArray[np.bool_]:
        out = np.zeros(nbd, bool)
        for j in (boards.turn_before, boards.turn_after):
            out |= (j >= 0) & (kinds[np.maximum(j, 0)] == kind)
        return out

    band_up = np.minimum(BAND_UP_DEG + 2.0 * sd, BAND_MAX_DEG)
    band_dn = np.minimum(BAND_DOWN_DEG + 2.0 * sd, BAND_MAX_DEG)
    up = adjacent(TACK) & (np.abs(a - ang.alpha[k]) <= band_up)
    down = ~up & adjacent(GYBE) & ~ang.runner[k] & (np.abs(180.0 - a - ang.gamma[k]) <= band_dn)
    run = ~up & ~down & (180.0 - a + 2.0 * sd <= RUN_BOX_DEG)
    return np.where(up, UP, np.where(down, DOWN, np.where(run, RUN, FREE))).astype(np.int64)


def _profile(kind: int, centre: float, sd: float) -> NDArray[np.float64]:
    """Log likelihood of each offset of the grid from the course (``θ − course``) for one
    class: a Gaussian in |TWA| about ``centre`` (up: α, down: 180 − γ, tack: 0, gybe:
    180) or a soft box (run: 180 − |TWA| <= ``centre``; free: |TWA| >= ``centre``)."""
    a = np.abs(wrap180(grid_deg()))
    if kind in (UP, DOWN, TACK, GYBE):
        g = np.exp(-0.5 * ((a - centre) / sd) ** 2)
    elif kind == RUN:
        g = ndtr((centre - (180.0 - a)) / EDGE_SD_DEG)
    else:
        g = ndtr((a - centre) / EDGE_SD_DEG)
    return np.asarray(np.log(EPS + (1.0 - EPS) * g), dtype=float)


def log_likelihoods(
    obs: Obs,
    cls: NDArray,
    turns: _Turns,
    kinds: NDArray,
    ang: BoatAngles,
    t0: float,
    n_bins: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Log likelihood of each grid direction in each bin (bins x grid): of the upwind and
    downwind boards, of the runs and free boards (bounds), and of the turns."""
    G = grid_deg().size
    K = ang.alpha.size
    # one profile per boat and class; a row's grid is its profile shifted by its course
    prof3 = np.empty((K, 6, G))
    for k in range(K):
        prof3[k, UP] = _profile(UP, ang.alpha[k], ang.sd_up[k])
        prof3[k, DOWN] = _profile(DOWN, 180.0 - ang.gamma[k], ang.sd_down[k])
        prof3[k, RUN] = _profile(RUN, RUN_BOX_DEG, 1.0)
        prof3[k, FREE] = _profile(FREE, ang.alpha[k] - FREE_MARGIN_DEG, 1.0)
        prof3[k, TACK] = _profile(TACK, 0.0, ang.sd_turn[k])
        prof3[k, GYBE] = _profile(GYBE, 180.0, ang.sd_turn[k])
    prof = prof3.reshape(K * 6, G)
    ti = kinds != FREE
    rows_boat = np.concatenate([obs.boat, turns.boat[ti]])
    rows_cls = np.concatenate([cls, kinds[ti]])
    rows_c = np.concatenate([obs.cog, turns.mid[ti]])
    rows_w = (
        np.concatenate([np.minimum(1.0, obs.seconds / MODEL_CORR_S), np.ones(int(ti.sum()))])
        * ang.use[rows_boat]
    )
    rows_bin = np.concatenate(
        [obs.bin, np.clip(((turns.t[ti] - t0) // BIN_S).astype(np.int64), 0, n_bins - 1)]
    )
    o = np.argsort(rows_bin, kind="stable")
    rows_boat, rows_cls, rows_c, rows_w, rows_bin = (
        rows_boat[o],
        rows_cls[o],
        rows_c[o],
        rows_w[o],
        rows_bin[o],
    )
    pid = rows_boat * 6 + rows_cls
    # row j of a course c is prof[(j - c) mod G]: a window of the profile laid twice
    start = G - np.rint(rows_c / GRID_DEG).astype(np.int64) % G
    win = sliding_window_view(np.concatenate([prof, prof], axis=1).astype(np.float32), G, axis=1)
    chunk = max(1, 2_000_000 // G)
    out = []
    info = (rows_cls == UP) | (rows_cls == DOWN)
    for part in (info, (rows_cls == RUN) | (rows_cls == FREE), rows_cls >= TACK):
        ll = np.zeros((n_bins, G))
        idx = np.flatnonzero(part)
        for s0 in range(0, idx.size, chunk):
            sl = idx[s0 : s0 + chunk]
            rows = win[pid[sl], start[sl]] * rows_w[sl, None].astype(np.float32)
            bins = rows_bin[sl]
            starts = np.flatnonzero(np.concatenate([[True], bins[1:] != bins[:-1]]))
            ll[bins[starts]] += np.add.reduceat(rows, starts, axis=0)
        out.append(ll)
    return out[0], out[1], out[2]


def systematic_var(
    obs: Obs, cls: NDArray, ang: BoatAngles, twa_deg: NDArray, n_bins: int
) -> NDArray[np.float64]:
    """Variance [°²] per bin from errors the smoother treats as known: the fitted angles'
    uncertainty (it cancels between the two boards, adds up on one) and an error all
    boats share (``COMMON_SD_DEG``); the nearest bin's value where a bin has no board
    that observes the wind."""
    m = ((cls == UP) | (cls == DOWN)) & ang.use[obs.boat]
    if not m.any():
        return np.zeros(n_bins)
    up = cls[m] == UP
    k = obs.boat[m]
    side = np.where(twa_deg[m] >= 0.0, 1.0, -1.0)
    sd_obs = np.where(up, ang.sd_up[k], ang.sd_down[k])
    w = np.minimum(1.0, obs.seconds[m] / MODEL_CORR_S) / sd_obs**2
    b = obs.bin[m]
    sw = np.bincount(b, w, n_bins)
    a_sd = np.where(up, ang.alpha_sd[k], ang.gamma_sd[k])
    sys_ = np.bincount(b, w * np.where(up, side, -side) * a_sd, n_bins)
    com = np.bincount(b, w * np.where(up, COMMON_SD_DEG[0], COMMON_SD_DEG[1]), n_bins)
    has = sw > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        var = np.where(has, (sys_ / sw) ** 2 + (com / sw) ** 2, np.nan)
    idx = np.flatnonzero(has)
    i = np.arange(n_bins)
    after = idx[np.clip(np.searchsorted(idx, i), 0, idx.size - 1)]
    before = idx[np.clip(np.searchsorted(idx, i) - 1, 0, idx.size - 1)]
    pick = np.where(np.abs(before - i) < np.abs(after - i), before, after)
    return np.asarray(var[pick], dtype=float)


def no_go_share(
    obs: Obs, twa_deg: NDArray, sd_deg: NDArray, ang: BoatAngles
) -> NDArray[np.float64]:
    """Per boat, the share of its steady time spent where no sailing boat goes: closer to
    the wind than ``NO_GO_FRACTION`` of its tacking half-angle (less twice the estimate's
    sd) at ``NO_GO_SPEED`` of its median speed or more.  A racing boat gets there only
    slowly (luffing before the start: SailGP's F50s at 16-20° and a third of their speed);
    a coach boat, or a boat that races in another wind, often and at speed."""
    K = ang.alpha.size
    med = np.array(
        [np.median(obs.sog[obs.boat == k]) if (obs.boat == k).any() else 0.0 for k in range(K)]
    )
    inside = (np.abs(twa_deg) < NO_GO_FRACTION * ang.alpha[obs.boat] - 2.0 * sd_deg) & (
        obs.sog >= NO_GO_SPEED * med[obs.boat]
    )
    tot = np.bincount(obs.boat, obs.seconds, K)
    return np.asarray(
        np.bincount(obs.boat, obs.seconds * inside, K) / np.maximum(tot, 1e-12), dtype=float
    )


def left_out(share: NDArray, use: NDArray) -> NDArray[np.bool_]:
    """The boats of ``use`` to leave out: whose :func:`no_go_share` exceeds
    ``NO_GO_SHARE`` and three times the median of those used (a wind estimate that is
    wrong puts the whole fleet there); none when that would leave out half of them or
    more."""
    if not use.any():
        return np.zeros(share.size, bool)
    out = use & (share > max(NO_GO_SHARE, 3.0 * float(np.median(share[use]))))
    return out if 2 * int(out.sum()) < int(use.sum()) else np.zeros(share.size, bool)


def _robust_sd(r: NDArray, w: NDArray) -> float:
    """Weighted sd of residuals with those beyond 3 MADs left out [°]."""
    if r.size == 0 or w.sum() <= 0:
        return float("nan")
    mad = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    keep = np.abs(r - np.median(r)) <= 3.0 * max(mad, 1.0)
    return float(np.sqrt(np.sum(w[keep] * r[keep] ** 2) / max(np.sum(w[keep]), 1e-12)))


def _combine(prior: float, prior_sd: float, vals: NDArray, floor_sd: float) -> tuple[float, float]:
    """Median of ``vals`` combined with a prior: the precision-weighted mean and its sd;
    the median's sd from the values' spread (at least ``floor_sd``) over sqrt(n)."""
    if vals.size == 0:
        return prior, prior_sd
    med = float(np.median(vals))
    spread = 1.4826 * float(np.median(np.abs(vals - med))) if vals.size > 2 else floor_sd
    sd = max(spread, floor_sd) / np.sqrt(vals.size)
    wp, wd = 1.0 / prior_sd**2, 1.0 / sd**2
    return (wp * prior + wd * med) / (wp + wd), float(1.0 / np.sqrt(wp + wd))


def _scatter(vals: NDArray, seconds: NDArray, centre: float, floor_sd: float) -> float:
    """How far a boat's boards lie from its angle [°]: the robust sd of their |TWA| (or
    angle off dead downwind) about ``centre``, at least ``floor_sd``; each board-bin
    counts for its share of ``MODEL_CORR_S``.

    The angle itself comes from the turns, not from the boards: while the whole fleet
    sails one board, a board's angle and the wind trade off (a fleet that sails 5°
    lower in every lift reads as a wind that shifts 5° less), and only the turns, where
    the wind is the same on both boards, tell them apart.
    """
    w = np.minimum(1.0, seconds / MODEL_CORR_S)
    if w.sum() < 3.0:
        return floor_sd
    return max(floor_sd, _robust_sd(vals - centre, w))


def _fleet_angle(halves: NDArray, prior: tuple[float, float]) -> tuple[float, float]:
    """The fleet's angle from all its tacks' (or gybes') half-angles and the prior: the
    median with the spread of the boats' angles as its sd (the prior of each boat)."""
    if halves.size < 3:
        return prior
    med = float(np.median(halves))
    spread = max(3.0, 1.4826 * float(np.median(np.abs(halves - med))))
    m, _ = _combine(*prior, halves, spread)
    return m, spread


def boat_angles(
    n_boats: int,
    obs: Obs,
    cls: NDArray,
    twa_deg: NDArray,
    turns: _Turns,
    loose: NDArray,
    twd_turn: NDArray,
    prior_alpha: tuple[float, float],
    prior_gamma: tuple[float, float],
    use: NDArray,
) -> BoatAngles:
    """Each boat's angles and how well its boards hold them.

    The fleet's tacking half-angle is the median of half the angles its tacks turned
    through (``loose``: turns classified by direction alone), combined with the prior (the
    polar's or the default); each boat's is that combined with its own tacks within
    ``TURN_BAND_DEG / 2`` of the fleet's.  The same for the gybes of the boats that gybe;
    a boat whose downwind boards lie within ``RUN_GAMMA_DEG`` of dead downwind runs.  A
    boat's turns scatter about the wind ``twd_turn`` (at least ``TURN_SD_DEG``).
    """
    alpha = np.zeros(n_boats)
    alpha_sd = np.zeros(n_boats)
    gamma = np.zeros(n_boats)
    gamma_sd = np.zeros(n_boats)
    runner = np.zeros(n_boats, bool)
    sd_up = np.full(n_boats, UP_MODEL_SD)
    sd_down = np.full(n_boats, DOWN_MODEL_SD)
    sd_turn = np.full(n_boats, TURN_SD_DEG)
    off_turn = wrap180(turns.mid - twd_turn - np.where(loose == GYBE, 180.0, 0.0))
    half = 0.5 * turns.angle
    a_abs = np.abs(twa_deg)
    for k in range(n_boats):
        # a runner sails within RUN_GAMMA_DEG of dead downwind for a quarter of its
        # downwind time at least (a broad reach to a wing mark is not a gybing board)
        off = 180.0 - a_abs[(obs.boat == k) & (a_abs > 120.0)]
        runner[k] = bool(off.size and float(np.quantile(off, 0.25)) < RUN_GAMMA_DEG)
    fleet = use[turns.boat]
    fa = _fleet_angle(half[fleet & (loose == TACK)], prior_alpha)
    fg = _fleet_angle(half[fleet & (loose == GYBE) & ~runner[turns.boat]], prior_gamma)
    for k in range(n_boats):
        tk = turns.boat == k
        mine = obs.boat == k
        mt = tk & (loose != FREE)
        if mt.sum() >= 3:
            sd_turn[k] = max(TURN_SD_DEG, _robust_sd(off_turn[mt], np.ones(int(mt.sum()))))
        own = half[tk & (loose == TACK)]
        alpha[k], alpha_sd[k] = _combine(*fa, own[np.abs(own - fa[0]) <= 0.5 * TURN_BAND_DEG], 3.0)
        sel = mine & (cls == UP)
        sd_up[k] = _scatter(a_abs[sel], obs.seconds[sel], alpha[k], UP_MODEL_SD)
        if runner[k]:
            continue
        own = half[tk & (loose == GYBE)]
        gamma[k], gamma_sd[k] = _combine(*fg, own[np.abs(own - fg[0]) <= 0.5 * TURN_BAND_DEG], 3.0)
        sel = mine & (cls == DOWN)
        sd_down[k] = _scatter(180.0 - a_abs[sel], obs.seconds[sel], gamma[k], DOWN_MODEL_SD)
    side = np.where(twa_deg >= 0.0, 1.0, -1.0)
    up = (cls == UP) & use[obs.boat]
    alpha, alpha_sd = _in_bin_angles(obs, up, obs.cog, side, sd_up, alpha, alpha_sd)
    dn = (cls == DOWN) & ~runner[obs.boat] & use[obs.boat]
    gamma, gamma_sd = _in_bin_angles(
        obs, dn, obs.cog + 180.0 * side, -side, sd_down, gamma, gamma_sd
    )
    for k in range(n_boats):
        mine = obs.boat == k
        sd_up[k] = _scatter(a_abs[mine & up], obs.seconds[mine & up], alpha[k], UP_MODEL_SD)
        if not runner[k]:
            off = 180.0 - a_abs[mine & dn]
            sd_down[k] = _scatter(off, obs.seconds[mine & dn], gamma[k], DOWN_MODEL_SD)
    return BoatAngles(
        alpha, alpha_sd, gamma, gamma_sd, runner, sd_up, sd_down, sd_turn, use.astype(bool)
    )


def _in_bin_angles(
    obs: Obs,
    sel: NDArray,
    v: NDArray,
    coef: NDArray,
    sd_boat: NDArray,
    prior: NDArray,
    prior_sd: NDArray,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The boats' angles from boards sailed in the same time bin.

    Each selected board-bin says ``TWD = v + coef · angle_k`` (upwind: the course and its
    side; downwind: the course + 180° and minus its side); boats sailing at the same time
    see the same TWD, so their differences hold the angles without the wind: two boats
    on opposite boards their sum, on the same board their difference.  A least-squares
    fit of all such in-bin differences with the turns' angles as the prior (robust: a
    second pass without the board-bins beyond 3 MADs); the prior alone where no two
    boats share a bin.  This is the angle of the boards themselves, which may differ
    from the turns' (a fleet that pinches into a tack and foots out of it).
    """
    K = prior.size
    idx = np.flatnonzero(sel)
    mean, sd = prior.copy(), prior_sd.copy()
    if idx.size < 2:
        return mean, sd
    _, b = np.unique(obs.bin[idx], return_inverse=True)
    nb = int(b.max()) + 1
    k, a = obs.boat[idx], coef[idx]
    w0 = np.minimum(1.0, obs.seconds[idx] / MODEL_CORR_S) / sd_boat[k] ** 2
    # courses relative to one of the bin's own (no wrap inside a bin)
    ref = np.zeros(nb)
    ref[b[::-1]] = v[idx][::-1]
    u = wrap180(v[idx] - ref[b])
    psd = np.maximum(prior_sd, 1e-3)
    keep = np.ones(idx.size, bool)
    for _ in range(2):
        w = w0 * keep
        sw = np.maximum(np.bincount(b, w, nb), 1e-300)
        # normal equations of the fit with each bin's TWD eliminated: sum over bins of
        # diag(w a^2) - g g' / W, g the bin's sum of w a e_k
        G = np.bincount(b * K + k, w * a, nb * K).reshape(nb, K)
        A = np.diag(np.bincount(k, w * a * a, K)) - G.T @ (G / sw[:, None])
        ub = np.bincount(b, w * u, nb) / sw
        rhs = -(np.bincount(k, w * a * u, K) - G.T @ ub)
        cov = np.linalg.inv(A + np.diag(1.0 / psd**2))
        mean = cov @ (rhs + prior / psd**2)
        sd = np.sqrt(np.diag(cov))
        fit = a * mean[k]
        r = (u - ub[b]) + (fit - np.bincount(b, w * fit, nb)[b] / sw[b])
        multi = np.bincount(b, keep.astype(float), nb)[b] >= 2
        mad = 1.4826 * float(np.median(np.abs(r[multi & keep]))) if (multi & keep).any() else 0.0
        keep = np.abs(r) <= 3.0 * max(mad, 1.0)
    return mean, np.maximum(sd, 0.5)


__all__ = [
    "BAND_DOWN_DEG",
    "BAND_UP_DEG",
    "CLASS_NAMES",
    "DOWN",
    "EPS",
    "FREE",
    "GYBE",
    "MODEL_CORR_S",
    "NO_GO_FRACTION",
    "NO_GO_SHARE",
    "NO_GO_SPEED",
    "RUN",
    "RUN_BOX_DEG",
    "TACK",
    "UP",
    "BoatAngles",
    "Obs",
    "boat_angles",
    "classify_boards",
    "left_out",
    "log_likelihoods",
    "no_go_share",
    "observations",
    "systematic_var",
    "turn_kinds",
]
