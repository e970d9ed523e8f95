"""The gun, the start line and the finish line, from where a fleet goes and stops.

* **Departure** (:func:`infer_gun`): before the start a fleet waits behind the line, so
  the median boat's distance to the first mark stays about level, and when the fleet
  goes it falls at the speed the fleet makes towards the mark.  The departure is the
  knee of that median distance: the break of the continuous two-piece line fitted to it
  by least squares (a first fit over the whole window, then over ``±PRE_FIT_S`` about the
  knee until it stays put).  A place the fleet does not leave for (the median distance
  falls slower than ``DEPART_SHARE`` of the fleet's speed after the knee, or changes at
  more than half that rate before it) is not the first mark.
* **Start line and gun** (:func:`start_line`): the line is square to the way the fleet
  goes at the departure (towards the first mark), or along the fleet's line-up then when
  that is clearly elongated (``ELONGATION`` or more, within 30° of square).  Lines of
  that direction from ``LINE_BEHIND_M`` behind the rearmost boat to ``SCAN_AHEAD_S`` of
  sailing ahead of the foremost, every ``SCAN_STEP_M``, are each crossed by every boat
  (its last crossing before it rounds the first mark).  The fleet crosses the start line
  together: among the lines whose crossings spread (interquartile range, its running
  median over the speed-up's width below) within ``TOGETHER_S`` or ``TOGETHER_SHARE`` of
  the tightest, the start line is the one where the fleet speeds up most (its median
  speed across the lines, ``±CROSS_SPEED_S`` about each crossing, ``JUMP_S`` of sailing
  after minus before): boats hold back or reach along below the line and sail at full
  speed from the gun.  Its ends are the outermost
  crossings, ``LINE_END_M`` beyond; the committee boat is the right-hand end looking
  towards the first mark, the pin the left.  The gun is the fleet's early crossing (the
  ``CROSS_QUANTILE`` of the crossings, the first with fewer than ten boats); its standard
  error combines a bootstrap over the boats, the sampling interval, the time to sail
  across the speed-up and half the spread of the guns of the lines where the fleet speeds
  up by ``RIVAL_SHARE`` of the most or more (the boats' approach to the line may be one).
* **Finish line** (:func:`finish_line`): a boat stops racing when it finishes; its race
  ends where it starts to sail slower than ``PACE_SHARE`` of its pace (the
  ``PACE_QUANTILE`` of its speeds over ``SPEED_WINDOW_S``) to the end of its track, for
  ``FINISH_SLOW_S`` or more; a track that ends at speed ends its race.  The finish points
  (where each boat slowed) further than ``FINISH_SPREAD_MAX`` median absolute deviations
  from the median along the last leg are left out (a boat that retired, a log that stops
  mid-leg); when the rest lie more than ``FINISH_DEPTH_S`` of sailing deep there is no
  line (the tracks end wherever: no finish in them).  The line is square to the last leg
  (or along the finish points when they are clearly elongated), at the line within
  ``FINISH_SCAN_S`` of sailing before the first stop where the fleet's speed across it
  drops most (by ``FINISH_DROP`` or more; else just before the first stop), and reaches
  from the outermost crossing of the boats kept to the other, ``LINE_END_M`` beyond.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.turns import BoatPath

__all__ = [
    "BOOTSTRAP",
    "CROSS_QUANTILE",
    "CROSS_SHARE",
    "CROSS_SPEED_S",
    "DEPART_SHARE",
    "ELONGATION",
    "FINISH_DEPTH_S",
    "FINISH_DROP",
    "FINISH_SCAN_S",
    "FINISH_SLOW_S",
    "FINISH_SPREAD_MAX",
    "GUN_EDGE_S",
    "JUMP_S",
    "LINE_BEHIND_M",
    "LINE_END_M",
    "PACE_QUANTILE",
    "PACE_SHARE",
    "PRE_FIT_S",
    "RIVAL_SHARE",
    "SCAN_AHEAD_S",
    "SCAN_STEP_M",
    "SLOW_NOISE",
    "SPEED_WINDOW_S",
    "TOGETHER_S",
    "TOGETHER_SHARE",
    "GunEstimate",
    "LineEstimate",
    "finish_line",
    "hinge_knee",
    "infer_gun",
    "race_ends",
    "start_line",
]

DEPART_SHARE: Final = 0.3
"""At the gun the fleet's median distance to the first mark falls faster than this
share of its typical speed."""

GUN_EDGE_S: Final = 20.0
"""The knee is searched this far inside the fitted window [s]."""

PRE_FIT_S: Final = 90.0
"""The gun's later fits span this either side of the knee [s]."""

ELONGATION: Final = 3.0
"""A line-up whose spread along its main axis is this many times its spread across is
taken as the line's direction."""

CROSS_QUANTILE: Final = 0.1
"""The gun is this quantile of the start crossings (the fleet's first boats cross right
after it; the first 10 % may be over early)."""

LINE_BEHIND_M: Final = 50.0
"""The start line is searched from this far behind the rearmost boat at the departure [m]."""

SCAN_AHEAD_S: Final = 60.0
"""... to this much sailing ahead of the foremost [s]."""

SCAN_STEP_M: Final = 2.0
"""Step of that search [m]."""

BOOTSTRAP: Final = 200
"""Bootstrap draws of the gun's standard error."""

TOGETHER_S: Final = 1.0
"""Start line levels whose crossings spread less than this more than the tightest
(interquartile range, the full range with fewer than four boats) are the fleet crossing
together [s] ..."""

TOGETHER_SHARE: Final = 0.25
"""... or less than this share more."""

RIVAL_SHARE: Final = 0.5
"""Start lines where the fleet speeds up by this share of the most or more are rivals:
half the spread of their early crossings is the gun's doubt."""

CROSS_SPEED_S: Final = 3.0
"""A boat's speed across a line is measured over this either side of its crossing [s]."""

JUMP_S: Final = 2.0
"""The fleet's speed-up at the line is measured over this much sailing either side of a
level [s at the fleet's typical speed]."""

CROSS_SHARE: Final = 0.8
"""A start line is crossed by this share of the fleet or more."""

LINE_END_M: Final = 10.0
"""A line extends this far beyond the outermost crossing at each end [m]."""

SPEED_WINDOW_S: Final = 20.0
"""Speeds that decide the finish are over this window [s]."""

PACE_QUANTILE: Final = 75.0
"""A boat's pace is this percentile of its speeds after the gun."""

PACE_SHARE: Final = 0.6
"""A boat below this share of its pace is not racing."""

FINISH_SLOW_S: Final = 20.0
"""A boat slow for this long to the end of its track has finished [s]."""

SLOW_NOISE: Final = 0.1
"""... slow: all but this share of its fixes there (speed noise on a slow track)."""

FINISH_SPREAD_MAX: Final = 4.0
"""Finish points more than this many (scaled) median absolute deviations from the
median along the last leg are left out of the line."""

FINISH_SCAN_S: Final = 30.0
"""The finish line is searched over this much sailing before the first stop [s]."""

FINISH_DROP: Final = 0.15
"""... where the fleet's speed across it drops by this share or more (else at the first
stop)."""

FINISH_DEPTH_S: Final = 15.0
"""Finish points spread deeper than this much sailing at the fleet's speed (median
absolute deviation along the last leg) give no line [s]."""


@dataclass(frozen=True)
class GunEstimate:
    """The start signal.

    Attributes
    ----------
    t : float
        The gun [epoch s].
    sd_s : float
        Its standard error [s] (0 for a given gun).
    source : {"given", "inferred"}
        ``--start-time`` (or the course's), or the fleet's departure.
    boats_spread_s : float
        Scaled median absolute deviation of the boats' own departures [s] (NaN: given).
    n_boats : int
        Boats whose departure was fitted.
    """

    t: float
    sd_s: float
    source: str
    boats_spread_s: float = math.nan
    n_boats: int = 0


@dataclass(frozen=True)
class LineEstimate:
    """A start or finish line found from the fleet.

    Attributes
    ----------
    pin, committee : (float, float)
        The left and right ends looking the way the boats cross [m].
    times : tuple of float
        Each boat's crossing [epoch s] (NaN: none found), in the order of the paths.
    depth_m : float
        Scaled median absolute deviation of the boats' positions across the line, at the
        gun (start) or where they finished (finish) [m]: how sharply the fleet marks it.
    n_boats : int
        Boats that crossed it.
    """

    pin: tuple[float, float]
    committee: tuple[float, float]
    times: tuple[float, ...]
    depth_m: float
    n_boats: int

    @property
    def length_m(self) -> float:
        """Distance between the ends [m]."""
        return math.hypot(self.committee[0] - self.pin[0], self.committee[1] - self.pin[1])


def _mad(v: NDArray) -> float:
    """Scaled median absolute deviation (the sd of a normal sample)."""
    return 1.4826 * float(np.median(np.abs(v - np.median(v)))) if v.size else math.nan


def hinge_knee(t: NDArray, r: NDArray, lo: float, hi: float) -> tuple[float, float, float]:
    """The break ``T`` in ``[lo, hi]`` of the continuous two-piece line fitted to ``r(t)``.

    Parameters
    ----------
    t, r : ndarray
        Times [s] and values (finite).
    lo, hi : float
        Range of the break [s].

    Returns
    -------
    (float, float, float)
        The break minimising the squared residuals, and the slopes before and after it
        [unit of r per s] (NaN: fewer than 4 points or an empty range).
    """
    nan = (math.nan, math.nan, math.nan)
    if t.size < 4 or not hi > lo:
        return nan
    cands = t[(t >= lo) & (t <= hi)]
    best, out = math.inf, nan
    for tk in cands:
        a = np.column_stack([np.ones_like(t), np.minimum(t - tk, 0.0), np.maximum(t - tk, 0.0)])
        coef, *_ = np.linalg.lstsq(a, r, rcond=None)
        sse = float(np.sum((a @ coef - r) ** 2))
        if sse < best:
            best, out = sse, (float(tk), float(coef[1]), float(coef[2]))
    return out


def _knee(
    t: NDArray, r: NDArray, t_hi: float, first: float | None = None
) -> tuple[float, float, float]:
    """:func:`hinge_knee` over the window (or from ``first``), then over ``±PRE_FIT_S``
    about the knee until it stays put (3 times at most)."""
    ok = np.isfinite(r)
    t, r = t[ok], r[ok]
    if t.size < 4:
        return math.nan, math.nan, math.nan
    fit = (
        hinge_knee(t, r, t[0] + GUN_EDGE_S, t_hi - GUN_EDGE_S)
        if first is None
        else (first, math.nan, math.nan)
    )
    for _ in range(3):
        k = fit[0]
        if not math.isfinite(k):
            return fit
        m = (t >= k - PRE_FIT_S) & (t <= k + PRE_FIT_S)
        fit2 = hinge_knee(t[m], r[m], k - PRE_FIT_S + GUN_EDGE_S, k + PRE_FIT_S - GUN_EDGE_S)
        if not math.isfinite(fit2[0]):
            return fit
        fit = fit2
        if abs(fit2[0] - k) < 1.0:
            break
    return fit


def infer_gun(
    paths: Sequence[BoatPath],
    target: tuple[float, float],
    t_lo: float,
    t_hi: float,
    speed_ms: float,
) -> GunEstimate | None:
    """The gun from the fleet's departure towards the first mark (module notes).

    Parameters
    ----------
    paths : sequence of BoatPath
        The fleet.
    target : (float, float)
        The first mark (or the centre of the first gate) [m].
    t_lo, t_hi : float
        The window [epoch s]: from when the fleet is there to the median first rounding
        of the first mark.
    speed_ms : float
        The fleet's typical speed [m s⁻¹].

    Returns
    -------
    GunEstimate or None
        None when the window is too short for a knee, or the fleet does not leave for
        ``target`` there: after the knee the median distance must fall faster than
        ``DEPART_SHARE`` of ``speed_ms``, and before it change at less than half that
        rate (a place the fleet sails away from, or passes on the way, is no first mark).
    """
    if t_hi - t_lo < 2.0 * GUN_EDGE_S + 10.0:
        return None
    tg = np.arange(math.ceil(t_lo), math.floor(t_hi) + 1.0)
    dist = []
    for p in paths:
        x, y = p.at(tg)
        dist.append(np.hypot(x - target[0], y - target[1]))
    d = np.vstack(dist)
    enough = np.isfinite(d).sum(axis=0) * 2 >= len(paths)
    med = np.full(tg.size, np.nan)
    med[enough] = np.nanmedian(d[:, enough], axis=0)
    gun, before, after = _knee(tg, med, t_hi)
    if not (math.isfinite(gun) and after < -DEPART_SHARE * speed_ms and abs(before) < -0.5 * after):
        return None
    own = np.array([_knee(tg, row, t_hi, gun)[0] for row in d if np.isfinite(row).sum() > 10])
    own = own[np.isfinite(own)]
    step = float(np.median([np.median(np.diff(p.t)) for p in paths if p.t.size > 1]))
    if own.size < 3:
        return GunEstimate(gun, max(step, PRE_FIT_S / 4), "inferred", math.nan, int(own.size))
    spread = _mad(own)
    sd = max(step, 1.2533 * spread / math.sqrt(own.size))  # standard error of a median
    return GunEstimate(float(np.median(own)), sd, "inferred", spread, int(own.size))


def _axis(points: NDArray, forward: NDArray) -> NDArray:
    """Unit vector along the line (to the right looking along ``forward``): along the
    points' main axis when they are elongated and nearly square to ``forward``, else
    square to ``forward``."""
    right = np.array([forward[1], -forward[0]])
    if points.shape[0] >= 5:
        c = points - points.mean(axis=0)
        w, v = np.linalg.eigh(c.T @ c)
        main = v[:, 1]
        if w[0] >= 0 and w[1] >= ELONGATION**2 * max(w[0], 1e-9) and abs(main @ forward) < 0.5:
            return np.asarray(main if main @ right > 0 else -main, dtype=float)
    return right


def _unit(v: NDArray) -> NDArray:
    n = float(np.hypot(v[0], v[1]))
    return v / n if n > 0 else np.array([0.0, 1.0])


def _along(p: BoatPath, t: float, centre: NDArray, along: NDArray) -> float:
    """Where along the line the boat is at ``t`` [m from ``centre``] (NaN: no fix then)."""
    if not math.isfinite(t):
        return math.nan
    x, y = p.at(np.array([t]))
    return float((x[0] - centre[0]) * along[0] + (y[0] - centre[1]) * along[1])


def _early(times: NDArray) -> float:
    """The fleet's early crossing: ``CROSS_QUANTILE`` of ``times``, the first of fewer
    than ten."""
    return float(np.quantile(times, CROSS_QUANTILE)) if times.size >= 10 else float(times.min())


def _crossings(
    t: NDArray, s: NDArray, levels: NDArray, *, last: bool = True
) -> NDArray[np.float64]:
    """Time [epoch s] of the last (or first) forward crossing of each level by ``s(t)``
    (NaN: none)."""
    if t.size < 2:
        return np.full(levels.size, np.nan)
    up = (s[None, :-1] < levels[:, None]) & (s[None, 1:] >= levels[:, None])
    has = up.any(axis=1)
    k = up.shape[1] - 1 - np.argmax(up[:, ::-1], axis=1) if last else np.argmax(up, axis=1)
    dt = t[k + 1] - t[k]
    with np.errstate(divide="ignore", invalid="ignore"):
        f = (levels - s[k]) / (s[k + 1] - s[k])
    return np.where(has, t[k] + f * dt, np.nan)


def _scan(
    paths: Sequence[BoatPath],
    windows: Sequence[tuple[float, float]],
    centre: NDArray,
    normal: NDArray,
    levels: NDArray,
    *,
    last: bool,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Each boat's crossing of each level in its window (boats x levels) [epoch s], and
    the fleet's median speed across each level (over ``±CROSS_SPEED_S``) [m s⁻¹]."""
    rows, speeds = [], []
    for p, (lo, hi) in zip(paths, windows, strict=True):
        m = (p.t >= lo) & (p.t <= hi)
        s = (p.x[m] - centre[0]) * normal[0] + (p.y[m] - centre[1]) * normal[1]
        c = _crossings(p.t[m], s, levels, last=last)
        xa, ya = p.at(c - CROSS_SPEED_S)
        xb, yb = p.at(c + CROSS_SPEED_S)
        rows.append(c)
        speeds.append(((xb - xa) * normal[0] + (yb - ya) * normal[1]) / (2.0 * CROSS_SPEED_S))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # levels nobody crosses
        return np.vstack(rows), np.nanmedian(np.vstack(speeds), axis=0)


def _jump(speed: NDArray, at: NDArray, j: int) -> NDArray[np.float64]:
    """Speed ``j`` levels after minus ``j`` levels before each level in ``at``."""
    sp = np.where(np.isfinite(speed), speed, 0.0)
    return np.asarray(sp[np.minimum(at + j, sp.size - 1)] - sp[np.maximum(at - j, 0)], float)


def start_line(
    paths: Sequence[BoatPath],
    ref_t: float,
    target: tuple[float, float],
    first_visits: Sequence[float],
    speed_ms: float,
) -> tuple[LineEstimate, float, float] | None:
    """The start line the fleet crosses together, and when it does (module notes).

    Parameters
    ----------
    paths : sequence of BoatPath
    ref_t : float
        The fleet's departure (:func:`infer_gun`) or the given gun [epoch s].
    target : (float, float)
        The first mark (or first gate's centre) [m].
    first_visits : sequence of float
        Each boat's rounding of it [epoch s] (the caller gives a time for a boat without
        one); a boat's crossing is its last one before that.
    speed_ms : float
        The fleet's typical speed [m s⁻¹].

    Returns
    -------
    (LineEstimate, float, float) or None
        The line, the fleet's early crossing (``CROSS_QUANTILE`` of the crossings, the
        first with fewer than ten boats) [epoch s] and its standard error [s] (a
        bootstrap over the boats, ``BOOTSTRAP`` draws, and the sampling interval); None
        with fewer than two boats at ``ref_t`` or no level the fleet crosses.
    """
    at = np.array([[float(v[0]) for v in p.at(np.array([ref_t]))] for p in paths])
    ok = np.isfinite(at).all(axis=1)
    if ok.sum() < 2:
        return None
    pts = at[ok]
    centre = np.median(pts, axis=0)
    fwd = _unit(np.asarray(target) - centre)
    along = _axis(pts, fwd)
    normal = np.array([-along[1], along[0]])  # forward across the line
    s_ref = (pts - centre) @ normal
    levels = np.arange(
        float(s_ref.min()) - LINE_BEHIND_M,
        float(s_ref.max()) + SCAN_AHEAD_S * speed_ms,
        SCAN_STEP_M,
    )
    cross, speed = _scan(
        paths,
        [(ref_t - PRE_FIT_S, tv) for tv in first_visits],
        centre,
        normal,
        levels,
        last=True,
    )
    n_cross = np.isfinite(cross).sum(axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # levels nobody crosses
        if len(paths) >= 4:
            spread = np.nanpercentile(cross, 75, axis=0) - np.nanpercentile(cross, 25, axis=0)
        else:
            spread = np.nanmax(cross, axis=0) - np.nanmin(cross, axis=0)
    spread = np.where(n_cross >= CROSS_SHARE * len(paths), spread, np.inf)
    if not np.isfinite(spread).any():
        return None
    j = max(1, round(JUMP_S * speed_ms / SCAN_STEP_M))
    # the spread's running median over the jump's width: one line's lucky spread is noise
    pad = np.pad(spread, j, mode="edge")
    spread = np.median(np.lib.stride_tricks.sliding_window_view(pad, 2 * j + 1), axis=1)
    best = float(np.min(spread))
    together = np.flatnonzero(spread <= best + max(TOGETHER_S, TOGETHER_SHARE * best))
    # within those, where the fleet speeds up most: the release at the gun
    score = _jump(speed, together, j)
    k = int(together[int(np.argmax(score))])
    # the speed-ups nearly as strong (the boats' approach to the line may be one): the
    # spread of their guns is the doubt
    rivals = together[score >= RIVAL_SHARE * float(np.max(score))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        rival_t = [_early(cross[:, r][np.isfinite(cross[:, r])]) for r in rivals]
    level = float(levels[k])
    times = cross[:, k]
    ok_t = times[np.isfinite(times)]
    where = [
        w
        for w in (_along(p, tc, centre, along) for p, tc in zip(paths, times, strict=True))
        if math.isfinite(w)
    ]
    if not where:
        return None
    base = centre + level * normal
    lo, hi = min(where) - LINE_END_M, max(where) + LINE_END_M
    pin, com = base + lo * along, base + hi * along
    early = _early(ok_t)
    rng = np.random.default_rng(0)
    boot = [_early(rng.choice(ok_t, ok_t.size)) for _ in range(BOOTSTRAP)]
    step = float(np.median([np.median(np.diff(p.t)) for p in paths if p.t.size > 1]))
    across = j * SCAN_STEP_M / max(float(np.nan_to_num(speed[k])), 0.1)  # the jump's half-width
    ambiguity = 0.5 * (max(rival_t) - min(rival_t))
    sd = math.sqrt(float(np.var(boot)) + step**2 + across**2 + ambiguity**2)
    line = LineEstimate(
        (float(pin[0]), float(pin[1])),
        (float(com[0]), float(com[1])),
        tuple(float(v) for v in times),
        _mad(s_ref - level),
        int(ok_t.size),
    )
    return line, early, sd


def race_ends(paths: Sequence[BoatPath], gun_t: float) -> tuple[list[float], list[float]]:
    """Each boat's end of racing and its pace (module notes).

    Returns
    -------
    ends : list of float
        The first fix from which the boat is slow to the end of its track (all but
        ``SLOW_NOISE`` of the fixes there followed by ``SPEED_WINDOW_S`` below
        ``PACE_SHARE`` of its pace), when that lasts ``FINISH_SLOW_S`` or more, else the
        track's end [epoch s] (NaN: no fix after the gun).
    pace : list of float
        The boat's pace [m s⁻¹] (NaN: no fix after the gun).
    """
    ends, paces = [], []
    for p in paths:
        after = p.t >= gun_t
        if not after.any():
            ends.append(math.nan)
            paces.append(math.nan)
            continue
        v = p.speed(SPEED_WINDOW_S)[after]
        if not np.isfinite(v).any():
            ends.append(float(p.t[-1]))
            paces.append(math.nan)
            continue
        pace = float(np.nanpercentile(v, PACE_QUANTILE))
        with np.errstate(invalid="ignore"):
            fast = after & (p.speed(SPEED_WINDOW_S, ahead=True) >= PACE_SHARE * pace)
        # from the first fix after which at most SLOW_NOISE of the fixes are fast
        share = np.cumsum(fast[::-1])[::-1] / np.arange(fast.size, 0, -1)
        slow = np.flatnonzero(after & (share <= SLOW_NOISE))
        end = float(p.t[-1])
        if slow.size and p.t[-1] - p.t[slow[0]] >= FINISH_SLOW_S + SPEED_WINDOW_S:
            end = float(p.t[slow[0]])
        ends.append(end)
        paces.append(pace)
    return ends, paces


def finish_line(
    paths: Sequence[BoatPath],
    ends: Sequence[float],
    last: tuple[float, float],
    last_visits: Sequence[float],
    speed_ms: float,
) -> LineEstimate | None:
    """The finish line from where the boats stopped racing (module notes).

    Parameters
    ----------
    paths : sequence of BoatPath
    ends : sequence of float
        Each boat's end of racing (:func:`race_ends`) [epoch s].
    last : (float, float)
        The last mark (or gate centre) [m].
    last_visits : sequence of float
        Each boat's rounding of it [epoch s] (NaN: none); only boats that rounded it
        before their end count.
    speed_ms : float
        The fleet's typical speed [m s⁻¹].

    Returns
    -------
    LineEstimate or None
        None with fewer than two finishers or finish points spread too deep.
    """
    pts, rows = [], []
    for k, (p, e, tv) in enumerate(zip(paths, ends, last_visits, strict=True)):
        if not (math.isfinite(e) and math.isfinite(tv) and e > tv):
            continue
        x, y = p.at(np.array([min(e + 0.5 * SPEED_WINDOW_S, float(p.t[-1]))]))
        if math.isfinite(float(x[0])):
            pts.append((float(x[0]), float(y[0])))
            rows.append(k)
    if len(pts) < 2:
        return None
    xy = np.array(pts)
    fwd = _unit(np.median(xy, axis=0) - np.asarray(last))
    s = (xy - np.asarray(last)) @ fwd
    dev = _mad(s)
    keep = np.abs(s - np.median(s)) <= FINISH_SPREAD_MAX * max(dev, 1.0)
    if keep.sum() < 2 or _mad(s[keep]) > FINISH_DEPTH_S * speed_ms:
        return None
    xy, s = xy[keep], s[keep]
    kept = {r for r, k in zip(rows, keep, strict=True) if k}
    along = _axis(xy, fwd)
    normal = np.array([-along[1], along[0]])
    centre = np.median(xy, axis=0)
    # before anyone stops, where the fleet slows most: the line (the first stop without)
    stop = float(np.min((xy - centre) @ normal)) - 1.0
    levels = np.arange(stop - FINISH_SCAN_S * speed_ms, stop + 0.5 * SCAN_STEP_M, SCAN_STEP_M)
    windows = [
        (tv, e + SPEED_WINDOW_S) if k in kept else (math.inf, -math.inf)
        for k, (e, tv) in enumerate(zip(ends, last_visits, strict=True))
    ]
    cross, speed = _scan(paths, windows, centre, normal, levels, last=False)
    ok = np.flatnonzero(np.isfinite(cross).sum(axis=0) >= CROSS_SHARE * len(kept))
    j = max(1, round(JUMP_S * speed_ms / SCAN_STEP_M))
    drop = -_jump(speed, ok, j) if ok.size else np.zeros(0)
    k = int(ok[int(np.argmax(drop))]) if ok.size else levels.size - 1
    if not (drop.size and drop.max() >= FINISH_DROP * float(np.nanmax(speed[ok]))):
        k = levels.size - 1
    level = float(levels[k])
    times = tuple(float(v) for v in cross[:, k])
    w = np.array([_along(p, tc, centre, along) for p, tc in zip(paths, times, strict=True)])
    w = w[np.isfinite(w)]
    if w.size < 2:
        return None
    base = centre + level * normal
    pin = base + (float(w.min()) - LINE_END_M) * along
    com = base + (float(w.max()) + LINE_END_M) * along
    return LineEstimate(
        (float(pin[0]), float(pin[1])),
        (float(com[0]), float(com[1])),
        times,
        _mad(s),
        int(np.isfinite(np.asarray(times)).sum()),
    )
