"""The smoother of :mod:`sailroute.analysis.infer_wind`: TWD(t) as a hidden random walk on
a grid of directions, observed through the boats' boards and turns (step 4).

TWD is discretised on the circle (``GRID_DEG``) and in time (bins of ``BIN_S``).  Between
bins it moves as a random walk (variance ``q`` per second, chosen by the marginal
likelihood among ``Q_GRID``); in each bin the boards sailed there multiply in their
likelihoods (:func:`sailroute.analysis.infer_obs.log_likelihoods`).  The forward-backward recursion
(:func:`smooth`) gives each bin's posterior distribution of TWD: its circular mean is the
estimate and its spread the standard error.  Where the boards say nothing the random
walk spreads the posterior, so the standard error grows with the time since the last
informative board, on both sides of a gap.  Also the local-linear kernel regression
used for TWS (:func:`_local_linear`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray
from scipy import fft as sfft

from sailroute.units import wrap180

GRID_DEG: Final = 1.0
"""Resolution of the direction grid [°] (a board's course is rounded to it: an error of
0.3° sd, well below a board's own)."""

BIN_S: Final = 10.0
"""Time step of the random walk and of the binned observations [s]."""

Q_GRID: Final = (1.0, 3.0)
"""Candidate variances of the random walk [°² s⁻¹]; the one of the larger marginal
likelihood is used.  The least, 1.0, lets TWD wander 10° in 100 s (a wind that swings
±10° every 6 min; the SailGP boats' logged TWD changes 5-6.5° RMS in 30-60 s, Auckland
2025), so that a wind the tracks do not see shifting (a fleet on one board at a constant
heading, a reach, a run) is not held steadier than that: the standard error grows by
this rate on both sides of such a stretch."""

START_SD_DEG: Final = 45.0
"""Sd of the direction at the first bin about the starting guess [°]: enough to leave
the boards free, not so much that the other end of the wind axis comes in."""


@dataclass(frozen=True)
class Posterior:
    """The smoother's result, per time bin.

    Attributes
    ----------
    mean_deg : ndarray
        Circular mean of the posterior [°, in ``[0, 360)``].
    sd_deg : ndarray
        Its standard deviation about the mean [°].
    q : float
        The random walk's variance rate used [°² s⁻¹].
    """

    mean_deg: NDArray[np.float64]
    sd_deg: NDArray[np.float64]
    q: float


def grid_deg() -> NDArray[np.float64]:
    """The direction grid [°]: cell centres ``0, GRID_DEG, ...``."""
    return np.arange(0.0, 360.0, GRID_DEG)


def _kernel(var_deg2: float) -> NDArray[np.complex128]:
    """Real FFT of the wrapped Gaussian step of variance ``var_deg2`` on the grid."""
    g = grid_deg()
    d = np.minimum(g, 360.0 - g)
    k = np.exp(-0.5 * d * d / max(var_deg2, 1e-12))
    return np.asarray(sfft.rfft(k / k.sum()), dtype=complex)


def _step(a: NDArray, kf: NDArray) -> NDArray[np.float64]:
    """One random-walk step of the distributions in the rows of ``a`` (circular
    convolution), clipped at 0 against round-off."""
    return np.maximum(sfft.irfft(sfft.rfft(a, axis=-1) * kf, n=a.shape[-1], axis=-1), 0.0)


def _forward(
    lik: NDArray, prior: NDArray, kfs: NDArray
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Filtered distributions (bins x candidates x grid) and the log normaliser of each
    step (bins x candidates), for several kernels at once."""
    nb, G = lik.shape
    nq = kfs.shape[0]
    out = np.empty((nb, nq, G))
    logc = np.empty((nb, nq))
    a = np.broadcast_to(prior, (nq, G))
    for b in range(nb):
        if b:
            a = _step(a, kfs)
        a = a * lik[b]
        c = a.sum(-1)
        c = np.where(c > 0, c, 1e-300)
        a = a / c[:, None]
        out[b], logc[b] = a, np.log(c)
    return out, logc


def _prior(start_deg: float) -> NDArray[np.float64]:
    g = grid_deg()
    prior = np.exp(-0.5 * (wrap180(g - start_deg) / START_SD_DEG) ** 2)
    return np.asarray(prior / prior.sum(), dtype=float)


def log_marginal(ll: NDArray, start_deg: float) -> NDArray[np.float64]:
    """Log marginal likelihood of the bins' log likelihoods ``ll`` for each candidate
    random-walk rate of ``Q_GRID``."""
    top = ll.max(axis=1, keepdims=True)
    kfs = np.stack([_kernel(c * BIN_S) for c in Q_GRID])
    _, logc = _forward(np.exp(ll - top), _prior(start_deg), kfs)
    return np.asarray(logc.sum(0) + float(top.sum()), dtype=float)


def smooth(ll: NDArray, start_deg: float, q: float) -> Posterior:
    """Posterior of TWD in each bin from the bins' log likelihoods on the grid.

    Parameters
    ----------
    ll : ndarray, shape (bins, grid)
        Log likelihood of each grid direction in each bin (0 where nothing is observed).
    start_deg : float
        Starting guess of the first bin's direction [°] (sd ``START_SD_DEG``).
    q : float
        Random-walk variance rate [°² s⁻¹].

    Returns
    -------
    Posterior
    """
    top = ll.max(axis=1, keepdims=True)
    lik = np.exp(ll - top)
    kf = _kernel(q * BIN_S)
    fwd, _ = _forward(lik, _prior(start_deg), kf[None, :])
    a = fwd[:, 0]
    post = np.empty_like(a)
    beta = np.ones(a.shape[1])
    for b in range(a.shape[0] - 1, -1, -1):
        p = a[b] * beta
        post[b] = p / max(p.sum(), 1e-300)
        beta = _step(lik[b] * beta, kf)
        beta /= max(beta.max(), 1e-300)
    mean, sd = circular_stats(post)
    return Posterior(mean, sd, float(q))


def circular_stats(p: NDArray) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Circular mean [°] and the sd about it [°] of distributions on the grid (rows)."""
    g = grid_deg()
    r = np.radians(g)
    mean = np.degrees(np.arctan2(p @ np.sin(r), p @ np.cos(r))) % 360.0
    d = wrap180(g[None, :] - mean[:, None])
    sd = np.sqrt(np.sum(p * d * d, axis=1) / np.maximum(p.sum(1), 1e-300))
    return mean, sd


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
