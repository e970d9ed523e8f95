"""Per-leg performance measures and the time-loss decomposition (pure functions).

Notation for one leg: the sailed time ``T_s`` runs from the leg's start crossing to
its end crossing; the optimal time ``T_o`` is the router's time from the same point
and time to the same target, in the same wind; the loss is ``L = T_s − T_o``.  It is
split into three parts that add up to ``L`` exactly:

manoeuvres ``L_m``
    For every sailed tack or gybe, the window ``[t − MAN_BEFORE_S, t + MAN_AFTER_S]``
    (overlapping windows merged, clipped to the leg).  Inside the windows the boat
    took ``W`` seconds and made ``P`` metres of progress along the leg axis (leg start
    to target centre); at the leg's straight-line progress rate ``v̄`` (progress per
    second outside the windows) that progress needs ``P / v̄``.  The sailed
    manoeuvres cost ``W − P / v̄`` (each window at least 0: a turn never gains on
    sailing straight, :func:`window_costs`); the optimal route's own manoeuvres cost its
    penalties (``n_tacks · tack_penalty_s + n_gybes · gybe_penalty_s``), which are
    subtracted: ``L_m`` is the manoeuvre time lost *beyond* what the optimal route
    spends.
speed ``L_v``
    Outside the windows, the time the boat would have saved sailing its own path at
    polar speed: ``Σ dt (1 − r)``, ``r = SOG / polar(TWS, |TWA|)`` (TWA from COG and
    the scenario's wind; ``r`` clipped to ``[0, RATIO_MAX]``, points where the polar
    is below ``POLAR_MIN_MS`` — head to wind — left out).  Negative when the boat beat
    the polar.
route ``L_r``
    The rest, ``L − L_m − L_v``: what sailing the chosen path at polar speed with
    optimal manoeuvring would still lose against the optimal route — the side of
    the course, the angles sailed, extra distance, overstanding.

The cumulative loss along the track compares progress: at a sailed point with
progress fraction ``p`` along the leg axis, ``loss = (t − t_leg_start) − τ_o(p)`` plus
the losses of the earlier legs, with ``τ_o(p)`` the time the optimal route first
reached ``p``.  At the end of a leg it equals the leg's ``L`` exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

MAN_BEFORE_S: Final = 10.0
"""Manoeuvre window before the first point on the new side [s]."""
MAN_AFTER_S: Final = 20.0
"""Manoeuvre window after it [s] (acceleration back to speed)."""
RATIO_MAX: Final = 1.5
"""SOG / polar ratios are clipped to ``[0, RATIO_MAX]`` in the speed loss."""
POLAR_MIN_MS: Final = 0.3
"""Points where the polar speed is below this [m s⁻¹] are left out of speed measures."""
SIDE_FRACTION: Final = 0.05
"""A mean lateral offset within this fraction of the leg length is the "middle"."""


@dataclass(frozen=True)
class LossSplit:
    """The decomposition of one leg's loss (all [s]); ``total = manoeuvres + speed + route``."""

    total: float
    manoeuvres: float
    speed: float
    route: float


def axis_progress(
    x: NDArray, y: NDArray, a: tuple[float, float], b: tuple[float, float]
) -> NDArray[np.float64]:
    """Progress [m] along the axis from ``a`` to ``b`` (projection of ``(x, y) − a``)."""
    ux, uy = b[0] - a[0], b[1] - a[1]
    n = float(np.hypot(ux, uy)) or 1.0
    return ((np.asarray(x) - a[0]) * ux + (np.asarray(y) - a[1]) * uy) / n


def lateral_offset(
    x: NDArray, y: NDArray, a: tuple[float, float], b: tuple[float, float]
) -> NDArray[np.float64]:
    """Signed distance [m] from the axis ``a → b``: + right of it looking from ``a`` to ``b``."""
    ux, uy = b[0] - a[0], b[1] - a[1]
    n = float(np.hypot(ux, uy)) or 1.0
    return ((np.asarray(x) - a[0]) * uy - (np.asarray(y) - a[1]) * ux) / n


def time_mean(t: NDArray, v: NDArray, mask: NDArray | None = None) -> float:
    """Time-weighted mean of ``v`` (each point weighted by half its two intervals)."""
    t = np.asarray(t, float)
    if t.size < 2:
        return float(np.nanmean(v)) if np.size(v) else float("nan")
    w = np.zeros_like(t)
    d = np.diff(t)
    w[:-1] += 0.5 * d
    w[1:] += 0.5 * d
    ok = np.isfinite(v) & (w > 0)
    if mask is not None:
        ok &= mask
    return float(np.sum(w[ok] * v[ok]) / np.sum(w[ok])) if ok.any() else float("nan")


def side_label(mean_lateral_m: float, leg_length_m: float) -> str:
    """``"left"``, ``"right"`` or ``"middle"`` from a mean lateral offset [m]."""
    if not np.isfinite(mean_lateral_m) or abs(mean_lateral_m) <= SIDE_FRACTION * leg_length_m:
        return "middle"
    return "right" if mean_lateral_m > 0 else "left"


def manoeuvre_mask(t: NDArray, man_t: NDArray) -> NDArray[np.bool_]:
    """True at points inside any manoeuvre window ``[t_k − MAN_BEFORE_S, t_k + MAN_AFTER_S]``."""
    t = np.asarray(t, float)
    m = np.zeros(t.size, dtype=bool)
    for tk in np.asarray(man_t, float):
        m |= (t >= tk - MAN_BEFORE_S) & (t <= tk + MAN_AFTER_S)
    return m


def split_loss(
    t: NDArray,
    progress_m: NDArray,
    ratio: NDArray,
    man_t: NDArray,
    loss_s: float,
    optimal_penalty_s: float,
) -> LossSplit:
    """Decompose one leg's loss (see the module notes).

    Parameters
    ----------
    t : ndarray
        Times of the leg's track points [epoch s], first = leg start, last = leg end.
    progress_m : ndarray
        Progress along the leg axis at those points [m].
    ratio : ndarray
        SOG / polar speed at the points (NaN where the polar is undefined).
    man_t : ndarray
        Times of the sailed manoeuvres in this leg [epoch s].
    loss_s : float
        ``T_s − T_o`` [s].
    optimal_penalty_s : float
        Manoeuvre penalties of the optimal route [s].

    Returns
    -------
    LossSplit
    """
    t = np.asarray(t, float)
    dt = np.diff(t)
    sailed_man, win = manoeuvre_cost(t, progress_m, man_t)
    lm = sailed_man - optimal_penalty_s
    r_mid = 0.5 * (ratio[:-1] + ratio[1:])
    ok = ~win & np.isfinite(r_mid)
    lv = float(np.sum(dt[ok] * (1.0 - np.clip(r_mid[ok], 0.0, RATIO_MAX))))
    return LossSplit(float(loss_s), float(lm), lv, float(loss_s) - float(lm) - lv)


def manoeuvre_cost(
    t: NDArray, progress_m: NDArray, man_t: NDArray
) -> tuple[float, NDArray[np.bool_]]:
    """Time the sailed manoeuvres of one leg cost [s], and which intervals they cover.

    The windows of ``man_t`` (:func:`manoeuvre_mask`; an interval belongs to a window when
    both its ends do), each costing ``W − P / v̄`` (:func:`window_costs`) with ``v̄`` the
    progress rate outside them; 0 when that rate is not positive or there is no window.

    Parameters
    ----------
    t : ndarray
        Times of the leg's points [epoch s].
    progress_m : ndarray
        Progress along the leg axis at those points [m].
    man_t : ndarray
        Times of the manoeuvres [epoch s].

    Returns
    -------
    cost : float
        [s], at least 0.
    win : ndarray of bool
        Per interval (``len(t) − 1``): inside a window.
    """
    t = np.asarray(t, float)
    dt = np.diff(t)
    inman = manoeuvre_mask(t, man_t)
    win = inman[:-1] & inman[1:]
    dprog = np.diff(np.asarray(progress_m, float))
    straight_t = float(np.sum(dt[~win]))
    rate = float(np.sum(dprog[~win]) / straight_t) if straight_t > 0 else 0.0
    if rate <= 0.05 or not win.any():
        return 0.0, win
    return float(np.sum(window_costs(dt, dprog, win, rate))), win


def window_costs(dt: NDArray, dprog: NDArray, win: NDArray, rate: float) -> NDArray[np.float64]:
    """Cost [s] of each manoeuvre window: ``W − P / v̄``, at least 0.

    Parameters
    ----------
    dt, dprog : ndarray
        Duration [s] and axis progress [m] of each track interval.
    win : ndarray of bool
        Intervals inside a manoeuvre window; each run of True is one window.
    rate : float
        Straight-line progress rate ``v̄`` [m s⁻¹], > 0.

    Returns
    -------
    ndarray
        One cost per window.  A window that made more progress than ``v̄`` would
        (negative cost) counts 0: turning through the wind never gains on sailing
        straight, so a negative value only says ``v̄`` was a poor reference there (a
        leg with slow stretches outside its manoeuvres, a boat that tacks at full
        speed); counted, it would book a tactical choice (more tacks than the
        optimum) as a manoeuvre gain.
    """
    w = np.asarray(win, bool)
    if not w.any():
        return np.zeros(0)
    edges = np.diff(np.concatenate([[0], w.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    cdt = np.concatenate([[0.0], np.cumsum(dt)])
    cdp = np.concatenate([[0.0], np.cumsum(dprog)])
    cost = (cdt[ends] - cdt[starts]) - (cdp[ends] - cdp[starts]) / rate
    return np.maximum(cost, 0.0)


def progress_loss(
    t_rel: NDArray, progress_m: NDArray, t_rel_opt: NDArray, progress_opt_m: NDArray
) -> NDArray[np.float64]:
    """Loss [s] at each sailed point against the optimal route, by progress along the axis.

    ``t_rel − τ_o(p)``, with ``τ_o`` the first time the optimal route reached progress
    ``p`` (its progress made monotone); progress beyond the optimal route's last value
    maps to its end time.
    """
    po = np.maximum.accumulate(np.asarray(progress_opt_m, float))
    keep = np.concatenate([[True], np.diff(po) > 1e-9])
    tau = np.interp(np.asarray(progress_m, float), po[keep], np.asarray(t_rel_opt)[keep])
    return np.asarray(t_rel, float) - tau
