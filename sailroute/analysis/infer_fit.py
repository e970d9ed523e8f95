"""The joint fit of :mod:`sailroute.analysis.infer_wind` (steps 3 and 4): TWD(t) piecewise
linear with a curvature penalty and per-boat half-angles, robust (Huber) weighted least
squares (:func:`_joint_fit`); the local-linear kernel regression of the points' own TWD
observations onto the output grid and its variance (:func:`_local_linear`,
:func:`_group_var`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import solveh_banded

from sailroute.analysis.infer_courses import _Points
from sailroute.units import wrap180

LAMBDA_SCALE: Final = 0.125
"""The curvature penalty of the joint fit lets TWD(t) bend on a time scale of about
``LAMBDA_SCALE * window_s`` (the equivalent kernel of a second-difference penalty spans
``(lambda / rho) ** 0.25`` knots, rho the data weight per knot)."""

N_ITER: Final = 4
"""Classify-and-fit passes of the joint fit."""

UP_HALF_DEG: Final = (15.0, 65.0)
"""First-pass range of upwind |TWA| [°] (tacking half-angles)."""

DOWN_OFF_DEG: Final = 50.0
"""First pass: downwind boards lie within this of dead downwind [°]."""

BAND_DEG: Final = 20.0
"""Later passes: a point is on a board when its |TWA| is within this of the boat's fitted
half-angle [°]; anything else is a reach and is rejected."""

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


@dataclass(frozen=True)
class _Fit:
    knots: NDArray[np.float64]
    twd: NDArray[np.float64]  # unwrapped TWD at the knots [°]
    alpha: NDArray[np.float64]  # per boat [°]
    gamma: NDArray[np.float64]  # per boat [°]
    alpha_sd: NDArray[np.float64]
    gamma_sd: NDArray[np.float64]
    up: NDArray[np.bool_]  # per point: on an upwind board
    used: NDArray[np.bool_]  # per point: on a board (up or down)
    boat: NDArray[np.int64]  # per point: boat index
    side: NDArray[np.float64]  # per point: +1 starboard, -1 port
    obs: NDArray[np.float64]  # per point: its own TWD observation (unwrapped) [°]
    w: NDArray[np.float64]  # per point: fit weight (1/sd^2 x robust x correlation)
    msd: NDArray[np.float64]  # per point: model sd (UP/RUN/DOWN_MODEL_SD) [°]
    sigma: tuple[float, float]  # residual sd upwind, downwind [°]


def _basis(t: NDArray, knots: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Linear-interpolation basis: left knot index and the two weights."""
    j = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, knots.size - 2)
    f = np.clip((t - knots[j]) / (knots[j + 1] - knots[j]), 0.0, 1.0)
    return j, 1.0 - f, f


def _joint_fit(
    p: _Points,
    n_boats: int,
    knots: NDArray,
    twd0: NDArray,
    alpha0: NDArray,
    gamma0: NDArray,
    alpha_prior_sd: float,
    window_s: float,
    *,
    use_down: bool = True,
    alpha_sd_fixed: NDArray | None = None,
    gamma_prior_sd: NDArray | None = None,
) -> _Fit:
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
            dn = (
                (np.abs((180.0 - a) - gamma[p.boat]) <= BAND_DEG + 5.0)
                if it
                else (a >= 180.0 - DOWN_OFF_DEG)
            )
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
        wt = (
            robust
            * p.weight
            * used
            * np.where(run, RUN_WEIGHT, 1.0)
            / (np.where(up, sig_up, sig_dn) ** 2 + msd**2)
        )
        # normal equations by accumulation: 3 non-zeros per row
        idx = np.stack([j, j + 1, col], axis=1)
        val = np.stack([w0, w1, coef], axis=1)
        rows = (idx[:, :, None] * P + idx[:, None, :]).reshape(-1)
        prods = (val[:, :, None] * val[:, None, :] * wt[:, None, None]).reshape(-1)
        N: NDArray[np.float64] = (
            np.bincount(rows, weights=prods, minlength=P * P).reshape(P, P).astype(float)
        )
        b: NDArray[np.float64] = np.bincount(
            idx.reshape(-1), weights=(val * (wt * y)[:, None]).reshape(-1), minlength=P
        ).astype(float)
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
    obs = cur + wrap180(
        np.where(up, p.cog + side * alpha[p.boat], p.cog + 180.0 - side * gamma[p.boat]) - cur
    )
    ia, ig = J + np.arange(K), J + K + np.arange(K)
    # the covariance of a weighted fit with weights 1/sigma^2 is in deg^2 already
    a_out = np.sqrt(par_var[:K]) if alpha_sd_fixed is None else alpha_sd_fixed
    return _Fit(
        knots,
        twd,
        alpha,
        gamma,
        a_out,
        np.sqrt(par_var[K:]),
        up & used,
        used,
        p.boat,
        side,
        obs,
        wt,
        _model_sd(up, gamma[p.boat]),
        (sig_up, sig_dn),
    )


def _solve_bordered(
    N: NDArray, b: NDArray, J: int
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
    return np.where(
        up, UP_MODEL_SD, np.where(np.abs(gamma) < RUN_GAMMA_DEG, RUN_MODEL_SD, DOWN_MODEL_SD)
    )


def _mad(r: NDArray) -> float:
    return float(1.4826 * np.median(np.abs(r - np.median(r))))


def _local_linear(
    tg: NDArray, t: NDArray, v: NDArray, w: NDArray, h: float, infl: NDArray
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
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
        lw = np.where(
            lin[:, None], kern * (s2[:, None] - s1[:, None] * dt) / det[:, None], kern / s0[:, None]
        )
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


def _group_var(
    tg: NDArray, t: NDArray, w: NDArray, h: float, fit: _Fit, m: NDArray
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
    kern = (
        np.where(inside, (1.0 - np.clip(np.abs(t[k] - tg[:, None]) / h, 0, 1) ** 3) ** 3, 0.0)
        * w[k]
    )
    f = kern / np.maximum(kern.sum(1), 1e-300)[:, None]
    for is_up, sds in ((True, fit.alpha_sd), (False, fit.gamma_sd)):
        for b, sd in enumerate(sds):
            sel = (up[k] == is_up) & (boat[k] == b)
            var += ((f * coef[k] * sel).sum(1) * sd) ** 2 + ((f * msd[k] * sel).sum(1)) ** 2
    return var
