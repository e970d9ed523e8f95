"""Wind-shift models and their discretisation to Markov chains on direction bins.

A *shift* ``θ`` is the deviation [°] of the true wind direction (TWD, the
direction the wind comes FROM) from a reference direction, usually the course
axis of an upwind leg.  Positive ``θ`` is a clockwise shift (a veer), in the
compass sense of ``docs/nomenclature.md``.

Two continuous-time models are offered:

* :class:`OUShift` -- an oscillating, mean-reverting shift (Ornstein–Uhlenbeck):
  ``dθ = -(θ - m)/l dt + σ sqrt(2/l) dW``, stationary sd ``σ``, autocorrelation
  ``exp(-|τ|/l)`` (Shepherd et al.'s AR(1) wind in continuous time);
* :class:`DriftDiffusionShift` -- a persistent/trending shift (Brownian motion
  with drift): ``dθ = a dt + s dW`` (Wang et al. (2024)).

Both have exact Gaussian transition laws over any time step ``Δt``
(:meth:`transition_moments`).  For the stochastic DP the shift is discretised to
a Markov chain on bins of width ``δθ`` (:func:`transition_matrix`) either by
integrating the exact transition density over each bin (``method="integrate"``,
Shepherd et al.'s eq. 13 with the corrected bin limits and the tails lumped into the
edge bins) or from a birth–death generator ``Q`` that matches the drift and the
diffusion of the process locally, ``M(Δt) = expm(Q Δt)`` (``method="generator"``,
time-consistent: ``M(t1) M(t2) = M(t1 + t2)``).  :func:`chain_diagnostics`
measures the chain's stationary sd and autocorrelation against the targets --
the bin-integration method drifts far from them when the one-step sd is much
smaller than ``δθ`` (see ``docs/design/strategy.md``, "discretisation trap").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import expm
from scipy.special import ndtr

from sailroute.errors import InputError

ChainMethod = Literal["generator", "integrate"]
CHAIN_METHODS: tuple[str, ...] = ("generator", "integrate")


@dataclass(frozen=True)
class OUShift:
    """Mean-reverting (Ornstein–Uhlenbeck) wind shift.

    Parameters
    ----------
    sigma_deg : float
        Stationary standard deviation of the shift [°], ``>= 0``.
    timescale_s : float
        e-folding time ``l_t`` of the autocorrelation [s], ``> 0``; ``inf`` gives
        a frozen wind (no change after the start).
    mean_deg : float
        Mean shift the process reverts to [°].
    """

    sigma_deg: float
    timescale_s: float
    mean_deg: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.sigma_deg) and self.sigma_deg >= 0):
            raise InputError(f"OU shift: sigma_deg = {self.sigma_deg} must be finite and >= 0")
        if not (self.timescale_s > 0) or math.isnan(self.timescale_s):
            raise InputError(
                f"OU shift: timescale_s = {self.timescale_s} must be > 0 (inf for a frozen wind)"
            )
        if not math.isfinite(self.mean_deg):
            raise InputError(f"OU shift: mean_deg = {self.mean_deg} must be finite")

    @property
    def kind(self) -> str:
        """Model name used in summaries: ``"ou"``."""
        return "ou"

    def transition_moments(
        self, theta_deg: ArrayLike, dt_s: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Exact mean and sd [°] of ``θ(t + Δt)`` given ``θ(t)``.

        ``R = 1 - exp(-Δt/l)``; mean ``θ + R (m - θ)``;
        variance ``σ² (1 - exp(-2Δt/l))``.
        """
        th = np.asarray(theta_deg, dtype=float)
        dt = np.asarray(dt_s, dtype=float)
        decay = np.exp(-dt / self.timescale_s)
        mean = self.mean_deg + (th - self.mean_deg) * decay
        sd = self.sigma_deg * np.sqrt(np.maximum(1.0 - decay * decay, 0.0))
        return mean, np.broadcast_to(sd, mean.shape).astype(float)

    def drift_diffusion(self, theta_deg: ArrayLike) -> tuple[NDArray[np.float64], float]:
        """Local drift [° s⁻¹] and diffusion coefficient ``D`` [°² s⁻¹] (``dθ = b dt + √D dW``)."""
        th = np.asarray(theta_deg, dtype=float)
        if math.isinf(self.timescale_s):
            return np.zeros_like(th), 0.0
        return -(th - self.mean_deg) / self.timescale_s, 2.0 * self.sigma_deg**2 / self.timescale_s

    def autocorrelation(self, lag_s: ArrayLike) -> NDArray[np.float64]:
        """Autocorrelation ``exp(-|τ|/l)`` at lag ``τ`` [s]."""
        return np.exp(-np.abs(np.asarray(lag_s, dtype=float)) / self.timescale_s)

    def describe(self) -> dict[str, float | str]:
        """Parameters as a JSON-ready dict (units in the keys)."""
        return {
            "kind": "ou",
            "sigma_deg": self.sigma_deg,
            "timescale_s": self.timescale_s,
            "mean_deg": self.mean_deg,
        }


@dataclass(frozen=True)
class DriftDiffusionShift:
    """Persistent wind shift: Brownian motion with constant drift (Wang et al. (2024)).

    Parameters
    ----------
    drift_deg_per_s : float
        Drift ``a`` [° s⁻¹]; positive veers (clockwise).
    sigma_deg_per_sqrt_s : float
        Diffusion ``s`` [° s⁻½], ``>= 0``: ``Var θ(t) = s² t``.
    """

    drift_deg_per_s: float
    sigma_deg_per_sqrt_s: float

    def __post_init__(self) -> None:
        if not math.isfinite(self.drift_deg_per_s):
            raise InputError(f"drift-diffusion shift: drift {self.drift_deg_per_s} must be finite")
        s = self.sigma_deg_per_sqrt_s
        if not (math.isfinite(s) and s >= 0):
            raise InputError(f"drift-diffusion shift: sigma {s} must be finite and >= 0")

    @property
    def kind(self) -> str:
        """Model name used in summaries: ``"drift-diffusion"``."""
        return "drift-diffusion"

    def transition_moments(
        self, theta_deg: ArrayLike, dt_s: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Exact mean ``θ + aΔt`` and sd ``s √Δt`` [°] of ``θ(t + Δt)``."""
        th = np.asarray(theta_deg, dtype=float)
        dt = np.asarray(dt_s, dtype=float)
        mean = th + self.drift_deg_per_s * dt
        sd = self.sigma_deg_per_sqrt_s * np.sqrt(np.maximum(dt, 0.0))
        return mean, np.broadcast_to(sd, mean.shape).astype(float)

    def drift_diffusion(self, theta_deg: ArrayLike) -> tuple[NDArray[np.float64], float]:
        """Local drift [° s⁻¹] and diffusion coefficient ``D = s²`` [°² s⁻¹]."""
        th = np.asarray(theta_deg, dtype=float)
        return np.full_like(th, self.drift_deg_per_s), self.sigma_deg_per_sqrt_s**2

    def describe(self) -> dict[str, float | str]:
        """Parameters as a JSON-ready dict (units in the keys)."""
        return {
            "kind": "drift-diffusion",
            "drift_deg_per_s": self.drift_deg_per_s,
            "sigma_deg_per_sqrt_s": self.sigma_deg_per_sqrt_s,
        }


ShiftModel = OUShift | DriftDiffusionShift


def shift_bins(step_deg: float = 5.0, max_deg: float = 45.0) -> NDArray[np.float64]:
    """Bin centres ``-max, -max + step, ..., max`` [°] of a shift grid.

    Raises
    ------
    InputError
        If ``max_deg`` is not a whole number of steps.
    """
    if not (step_deg > 0 and max_deg >= 0):
        raise InputError(f"shift grid: step {step_deg}° must be > 0 and max {max_deg}° >= 0")
    n = max_deg / step_deg
    if abs(n - round(n)) > 1e-9:
        raise InputError(
            f"shift grid: max {max_deg}° is not a whole number of {step_deg}° steps; "
            "choose e.g. max = 45, step = 5"
        )
    n = round(n)
    return step_deg * np.arange(-n, n + 1, dtype=float)


def _bin_step(bins_deg: NDArray[np.float64]) -> float:
    if bins_deg.ndim != 1 or bins_deg.size < 1:
        raise InputError("shift grid: need a 1-D array of at least one bin centre")
    if bins_deg.size == 1:
        return math.inf
    steps = np.diff(bins_deg)
    if np.any(steps <= 0) or np.ptp(steps) > 1e-9 * steps[0]:
        raise InputError("shift grid: bin centres must be equally spaced and increasing")
    return float(steps[0])


def _integrate_rows(
    model: ShiftModel, bins: NDArray, i_from: NDArray, dt_s: NDArray
) -> NDArray[np.float64]:
    """Bin-integrated exact transition law (Shepherd et al. eq. 13, corrected)."""
    h = _bin_step(bins)
    mean, sd = model.transition_moments(bins[i_from], dt_s)
    # bin j collects θ' in [θ_j - δθ/2, θ_j + δθ/2); the edge bins take the tails
    edges = np.concatenate([[-np.inf], bins[:-1] + h / 2, [np.inf]])
    m = mean[..., None]
    s = sd[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (edges - m) / s
    # s == 0: a point mass at the mean (step function of the edges)
    z = np.where(s > 0, z, np.where(edges > m, np.inf, -np.inf))
    cdf = ndtr(z)
    return np.diff(cdf, axis=-1)


def generator_matrix(model: ShiftModel, bins_deg: ArrayLike) -> NDArray[np.float64]:
    """Birth–death generator ``Q`` [s⁻¹] of the continuous-time chain on the bins.

    Rates to the neighbouring bins match the local drift ``b`` and diffusion
    ``D`` of the process (Kushner–Dupuis): central rates
    ``q± = D/(2h²) ± b/(2h)`` where both are ``>= 0`` (then the mean drift and
    the variance rate are exact), upwind rates ``q± = D/(2h²) + max(±b, 0)/h``
    otherwise; no rate leaves the grid (reflecting edges).  For the OU model
    with ``N = 4σ²/h²`` an integer the chain is the Ehrenfest urn: its
    stationary law is Binomial(N, ½) with sd exactly ``σ``, and
    ``E[θ(t)] = θ(0) e^{-t/l}`` exactly.
    """
    bins = np.asarray(bins_deg, dtype=float)
    n = bins.size
    if n == 1:
        return np.zeros((1, 1))
    h = _bin_step(bins)
    b, diff = model.drift_diffusion(bins)
    base = diff / (2.0 * h * h)
    up = base + b / (2.0 * h)
    down = base - b / (2.0 * h)
    central = (up >= 0) & (down >= 0)
    up = np.where(central, up, base + np.maximum(b, 0.0) / h)
    down = np.where(central, down, base + np.maximum(-b, 0.0) / h)
    up[-1] = 0.0
    down[0] = 0.0
    q = np.zeros((n, n))
    idx = np.arange(n)
    q[idx[:-1], idx[:-1] + 1] = up[:-1]
    q[idx[1:], idx[1:] - 1] = down[1:]
    q[idx, idx] = -(up + down)
    return q


def transition_rows(
    model: ShiftModel,
    bins_deg: ArrayLike,
    from_index: ArrayLike,
    dt_s: ArrayLike,
    method: ChainMethod = "generator",
) -> NDArray[np.float64]:
    """Rows of the chain's transition matrix, one per (from-bin, time step) pair.

    Parameters
    ----------
    model : OUShift or DriftDiffusionShift
        Shift process.
    bins_deg : array_like, shape (n,)
        Equally spaced bin centres [°] (:func:`shift_bins`).
    from_index : array_like of int
        Bin the chain is in.
    dt_s : array_like
        Elapsed time [s] for each pair (broadcast with ``from_index``).
    method : {"generator", "integrate"}
        Discretisation (module docstring).

    Returns
    -------
    ndarray, shape (..., n)
        ``P(θ' in bin j | θ in bin i, Δt)``; every row sums to 1.
    """
    bins = np.asarray(bins_deg, dtype=float)
    i_from, dt = np.broadcast_arrays(
        np.asarray(from_index, dtype=np.intp), np.asarray(dt_s, dtype=float)
    )
    if np.any(dt < 0) or not np.all(np.isfinite(dt)):
        raise InputError("shift chain: time steps must be finite and >= 0")
    if method == "integrate":
        rows = _integrate_rows(model, bins, i_from, dt)
    elif method == "generator":
        q = generator_matrix(model, bins)
        flat_dt = dt.ravel()
        uniq, inv = np.unique(flat_dt, return_inverse=True)
        mats = expm(q[None, :, :] * uniq[:, None, None])
        rows = mats[inv.ravel(), i_from.ravel(), :].reshape(*dt.shape, bins.size)
    else:
        raise InputError(
            f"shift chain: unknown method {method!r}; expected one of {', '.join(CHAIN_METHODS)}"
        )
    rows = np.clip(rows, 0.0, None)
    return rows / rows.sum(axis=-1, keepdims=True)


def transition_matrix(
    model: ShiftModel, bins_deg: ArrayLike, dt_s: float, method: ChainMethod = "generator"
) -> NDArray[np.float64]:
    """Transition matrix ``M[i, j]`` of the chain over one step ``Δt`` [s] (rows sum to 1)."""
    bins = np.asarray(bins_deg, dtype=float)
    return transition_rows(model, bins, np.arange(bins.size), float(dt_s), method)


@dataclass(frozen=True)
class ChainDiagnostics:
    """Statistics of a discretised shift chain against the process it stands for.

    Attributes
    ----------
    stationary_sd_deg : float
        Sd of the chain's stationary law [°] (``nan`` if it has none).
    lag1_autocorr : float
        Autocorrelation of the stationary chain at one step.
    efold_lag : float
        First lag (steps) at which the autocorrelation falls to ``1/e``
        (``inf`` if not within ``max_lag`` steps).
    mean_stay_prob : float
        Mean of the diagonal ``M[i, i]`` (unweighted over bins).
    target_sd_deg, target_lag1, target_efold_lag : float
        The process's own values (``nan`` when not defined, e.g. no
        stationary law for a drift–diffusion shift).
    """

    stationary_sd_deg: float
    lag1_autocorr: float
    efold_lag: float
    mean_stay_prob: float
    target_sd_deg: float
    target_lag1: float
    target_efold_lag: float

    def relative_errors(self) -> dict[str, float]:
        """Relative errors of the chain's sd and lag-1 autocorrelation against the targets."""
        return {
            "sd": self.stationary_sd_deg / self.target_sd_deg - 1.0,
            "lag1": self.lag1_autocorr / self.target_lag1 - 1.0,
        }


def stationary_distribution(m: ArrayLike) -> NDArray[np.float64]:
    """Stationary law ``π = π M`` of a transition matrix (left eigenvector of 1)."""
    mat = np.asarray(m, dtype=float)
    n = mat.shape[0]
    a = np.vstack([mat.T - np.eye(n), np.ones((1, n))])
    rhs = np.zeros(n + 1)
    rhs[-1] = 1.0
    pi, *_ = np.linalg.lstsq(a, rhs, rcond=None)
    pi = np.clip(pi, 0.0, None)
    return pi / pi.sum()


def chain_diagnostics(
    m: ArrayLike,
    bins_deg: ArrayLike,
    model: ShiftModel | None = None,
    dt_s: float | None = None,
    max_lag: int = 5000,
) -> ChainDiagnostics:
    """Stationary sd, autocorrelation and persistence of a chain; targets from ``model``.

    Parameters
    ----------
    m : array_like, shape (n, n)
        Transition matrix over one step.
    bins_deg : array_like, shape (n,)
        Bin centres [°].
    model : OUShift, optional
        Process the chain discretises; gives the targets ``σ``,
        ``exp(-Δt/l)`` and ``-1/ln(1 - R)``.
    dt_s : float, optional
        Step of the chain [s] (needed for the targets).
    max_lag : int
        Longest lag searched for the e-folding lag.
    """
    mat = np.asarray(m, dtype=float)
    bins = np.asarray(bins_deg, dtype=float)
    pi = stationary_distribution(mat)
    mean = float(pi @ bins)
    var = float(pi @ (bins - mean) ** 2)
    centred = bins - mean
    if var <= 0:
        lag1, efold = math.nan, math.nan
    else:
        # corr(n) = Σ_i π_i c_i (M^n c)_i / var: iterate the vector, cheap in n
        v = centred.copy()
        lag1 = math.nan
        efold = math.inf
        for k in range(1, max_lag + 1):
            v = mat @ v
            rho = float(pi @ (centred * v)) / var
            if k == 1:
                lag1 = rho
            if rho <= math.exp(-1.0):
                efold = float(k)
                break
    stay = float(np.mean(np.diag(mat)))
    t_sd = t_lag1 = t_efold = math.nan
    if isinstance(model, OUShift) and dt_s is not None:
        t_sd = model.sigma_deg
        decay = math.exp(-dt_s / model.timescale_s)
        t_lag1 = decay
        t_efold = model.timescale_s / dt_s
    return ChainDiagnostics(
        stationary_sd_deg=math.sqrt(var),
        lag1_autocorr=lag1,
        efold_lag=efold,
        mean_stay_prob=stay,
        target_sd_deg=t_sd,
        target_lag1=t_lag1,
        target_efold_lag=t_efold,
    )
