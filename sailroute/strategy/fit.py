"""Fit wind-shift models to measured directions (station or coach-boat logs).

From samples ``(t, TWD)``:

1. circular mean direction ``m`` and the unwrapped deviation series
   ``e(t) = unwrap(wrap180(TWD - m))`` [°] (no 359°/0° jumps);
2. resampling to a regular step ``Δt`` by linear interpolation in time;
3. :func:`fit_ou` -- stationary sd ``σ`` (sample sd of ``e``) and e-folding
   time ``l_t``: from the lag-1 autocorrelation ``φ`` of the regular series
   (AR(1)/Yule–Walker, ``l_t = -Δt / ln φ``) or from the first lag where the
   sample autocorrelation falls below ``1/e``;
4. :func:`fit_drift_diffusion` -- drift ``a`` by least-squares regression of
   ``e`` on time, diffusion ``s² = Σ (Δe - a Δt)² / Σ Δt`` from the increments.

Each estimate carries an asymptotic standard error (``*_se``) so that a test
or a user can judge it:

* ``se(σ̂) = σ/2 · sqrt(2 (1 + φ²) / (N (1 - φ²)))`` (variance of the sample
  variance of an AR(1) series of ``N`` samples, ``≈ σ sqrt(l_t / 2T)``);
* ``se(φ̂) = sqrt((1 - φ²) / N)`` and by the delta method
  ``se(l̂) = Δt se(φ̂) / (φ ln² φ)`` (AR(1) method); for the e-fold method
  Bartlett's variance of the sample autocorrelation at lag ``l/Δt`` divided by
  the slope ``1/(e l)`` of the autocorrelation there;
* ``se(â) = s sqrt(6 / (5 T))`` for the regression slope of a Brownian path of
  duration ``T`` (it is ``s/√T`` for the end-to-end estimator);
* ``se(ŝ) = ŝ / sqrt(2 N)``.

Instrument noise and sub-minute fluctuations on 1 Hz logs add a "nugget" to
the autocorrelation (a drop at lag 1 that the OU process does not have): the
lag-1 (AR(1)) time scale is then far too short, while the e-fold crossing is
not affected.  :func:`fit_station_file` therefore uses the e-fold method by
default.  The same noise inflates the increment variance of a diffusion fit;
resample to several seconds (``dt_s``) first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError
from sailroute.strategy.shiftmodel import DriftDiffusionShift, OUShift
from sailroute.units import circular_mean_deg, wrap180


@dataclass(frozen=True)
class OUFit:
    """Ornstein–Uhlenbeck fit of a direction series.

    Attributes
    ----------
    mean_deg : float
        Circular mean direction (TWD) [°].
    sigma_deg, sigma_se_deg : float
        Stationary sd of the shift [°] and its standard error.
    timescale_s, timescale_se_s : float
        e-folding time ``l_t`` [s] and its standard error.
    lag1 : float
        Lag-1 autocorrelation ``φ`` of the regular series.
    dt_s : float
        Step of the regular series [s].
    n_samples : int
        Samples of the regular series.
    duration_s : float
        Time span [s].
    method : str
        ``"ar1"`` or ``"efold"``.
    """

    mean_deg: float
    sigma_deg: float
    sigma_se_deg: float
    timescale_s: float
    timescale_se_s: float
    lag1: float
    dt_s: float
    n_samples: int
    duration_s: float
    method: str

    def model(self) -> OUShift:
        """The fitted process as an :class:`OUShift` (shift about the mean, ``mean_deg=0``)."""
        return OUShift(self.sigma_deg, self.timescale_s)

    def describe(self) -> dict[str, float | int | str]:
        """JSON-ready dict."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


@dataclass(frozen=True)
class DriftDiffusionFit:
    """Brownian-with-drift fit of a direction series.

    Attributes
    ----------
    mean_deg : float
        Circular mean direction (TWD) [°].
    drift_deg_per_s, drift_se_deg_per_s : float
        Drift [° s⁻¹] (positive veers) and its standard error.
    sigma_deg_per_sqrt_s, sigma_se_deg_per_sqrt_s : float
        Diffusion [° s⁻½] and its standard error.
    dt_s : float
        Step of the regular series [s].
    n_samples : int
    duration_s : float
    """

    mean_deg: float
    drift_deg_per_s: float
    drift_se_deg_per_s: float
    sigma_deg_per_sqrt_s: float
    sigma_se_deg_per_sqrt_s: float
    dt_s: float
    n_samples: int
    duration_s: float

    def model(self) -> DriftDiffusionShift:
        """The fitted process as a :class:`DriftDiffusionShift`."""
        return DriftDiffusionShift(self.drift_deg_per_s, self.sigma_deg_per_sqrt_s)

    def describe(self) -> dict[str, float | int | str]:
        """JSON-ready dict."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def unwrap_directions(direction_deg: ArrayLike) -> tuple[float, NDArray[np.float64]]:
    """Circular mean [°] and the unwrapped deviations from it [°].

    The deviations are continuous across 0°/360° (``numpy.unwrap`` on the
    wrapped deviations), so a slow veer through north is a smooth ramp.
    """
    d = np.asarray(direction_deg, dtype=float)
    if d.ndim != 1 or d.size < 3 or not np.all(np.isfinite(d)):
        raise InputError("direction series: need a 1-D array of at least 3 finite values [°]")
    m = circular_mean_deg(d)
    dev = np.degrees(np.unwrap(np.radians(wrap180(d - m))))
    return m, dev


def regular_series(
    t_s: ArrayLike, values: ArrayLike, dt_s: float | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """Resample ``values(t)`` to a regular step by linear interpolation.

    Parameters
    ----------
    t_s : array_like
        Strictly increasing times [s].
    values : array_like
        Samples at ``t_s``.
    dt_s : float, optional
        Step [s]; default the median sampling interval.

    Returns
    -------
    t_reg, v_reg : ndarray
        Regular times and values.
    dt_s : float
        The step used.
    """
    t = np.asarray(t_s, dtype=float)
    v = np.asarray(values, dtype=float)
    if t.shape != v.shape or t.ndim != 1:
        raise InputError("time and direction arrays must be 1-D and of equal length")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise InputError(
            "times must be finite and strictly increasing; drop or average duplicated "
            "records (e.g. read_stations(..., resample_s=2))"
        )
    step = float(np.median(np.diff(t))) if dt_s is None else float(dt_s)
    if not step > 0:
        raise InputError(f"resampling step {dt_s} s must be > 0")
    n = math.floor((t[-1] - t[0]) / step + 1e-9) + 1
    if n < 3:
        raise InputError(
            f"series spans {t[-1] - t[0]:g} s, too short for a {step:g} s step; need 3 samples"
        )
    tr = t[0] + step * np.arange(n)
    return tr, np.interp(tr, t, v), step


def fit_ou(
    t_s: ArrayLike,
    direction_deg: ArrayLike,
    dt_s: float | None = None,
    timescale_method: str = "ar1",
) -> OUFit:
    """Fit an :class:`OUShift` to a direction series (module docstring).

    Parameters
    ----------
    t_s : array_like
        Times [s] (epoch or relative), strictly increasing.
    direction_deg : array_like
        Wind directions (TWD) [°].
    dt_s : float, optional
        Regular step for the autocorrelation [s]; default the median interval.
    timescale_method : {"ar1", "efold"}
        Lag-1 regression, or the first crossing of ``1/e`` by the sample
        autocorrelation (linear interpolation in log between lags).

    Raises
    ------
    InputError
        If the series does not decorrelate (``φ >= 1``) or anticorrelates
        (``φ <= 0``): no OU time scale can be fitted; try a longer series or a
        different ``dt_s``.
    """
    mean, dev = unwrap_directions(direction_deg)
    _, e, step = regular_series(t_s, dev, dt_s)
    n = e.size
    c = e - e.mean()
    var = float(np.mean(c * c))
    if var <= 0:
        raise InputError("direction series is constant: no shift to fit")
    phi = float(np.sum(c[:-1] * c[1:]) / np.sum(c * c))
    if not 0 < phi < 1:
        raise InputError(
            f"lag-1 autocorrelation {phi:.3f} of the direction series is outside (0, 1) at a "
            f"{step:g} s step; no mean-reverting time scale can be fitted (try another dt_s)"
        )
    sigma = math.sqrt(var)
    phi_se = math.sqrt((1 - phi * phi) / n)
    if timescale_method == "ar1":
        tau = -step / math.log(phi)
        tau_se = step * phi_se / (phi * math.log(phi) ** 2)
    elif timescale_method == "efold":
        tau = _efold_time(c, step)
        # Bartlett's variance of the AR(1) sample autocorrelation at lag k = l/Δt,
        # over the slope |dρ/dτ| = 1/(e l) of the autocorrelation there
        p = math.exp(-step / tau)
        k = tau / step
        p2k = math.exp(-2.0)
        var_r = ((1 + p * p) * (1 - p2k) / (1 - p * p) - 2.0 * k * p2k) / n
        tau_se = math.e * tau * math.sqrt(max(var_r, 0.0))
    else:
        raise InputError(f"timescale_method {timescale_method!r}: expected 'ar1' or 'efold'")
    # sampling error of the sample variance of an AR(1) series with the fitted time scale
    pf = math.exp(-step / tau)
    sigma_se = 0.5 * sigma * math.sqrt(2.0 * (1 + pf * pf) / (n * (1 - pf * pf)))
    return OUFit(
        mean_deg=mean,
        sigma_deg=sigma,
        sigma_se_deg=sigma_se,
        timescale_s=tau,
        timescale_se_s=tau_se,
        lag1=phi,
        dt_s=step,
        n_samples=n,
        duration_s=step * (n - 1),
        method=timescale_method,
    )


def _efold_time(c: NDArray[np.float64], step: float) -> float:
    n = c.size
    nfft = 1 << (2 * n - 1).bit_length()
    f = np.fft.rfft(c, nfft)
    acf = np.fft.irfft(f * np.conj(f), nfft)[:n]
    acf = acf / acf[0]
    target = math.exp(-1.0)
    below = np.flatnonzero(acf < target)
    if below.size == 0:
        raise InputError(
            "the direction autocorrelation never falls below 1/e: the series is shorter than "
            "its time scale"
        )
    k = int(below[0])
    lo, hi = acf[k - 1], acf[k]
    frac = (math.log(lo) + 1.0) / (math.log(lo) - math.log(hi)) if hi > 0 else 0.5
    return step * (k - 1 + frac)


def fit_drift_diffusion(
    t_s: ArrayLike, direction_deg: ArrayLike, dt_s: float | None = None
) -> DriftDiffusionFit:
    """Fit a :class:`DriftDiffusionShift` (module docstring).

    Parameters
    ----------
    t_s : array_like
        Times [s], strictly increasing.
    direction_deg : array_like
        Wind directions (TWD) [°].
    dt_s : float, optional
        Resample to this regular step first [s]; default: use the samples as
        they are (irregular steps are fine).
    """
    mean, dev = unwrap_directions(direction_deg)
    t = np.asarray(t_s, dtype=float)
    if dt_s is not None:
        t, dev, _ = regular_series(t, dev, dt_s)
    else:
        regular_series(t, dev)  # validates the times
    dur = float(t[-1] - t[0])
    tc = t - t.mean()
    a = float(np.sum(tc * (dev - dev.mean())) / np.sum(tc * tc))
    de = np.diff(dev)
    dts = np.diff(t)
    s2 = float(np.sum((de - a * dts) ** 2) / np.sum(dts))
    s = math.sqrt(s2)
    n = de.size
    return DriftDiffusionFit(
        mean_deg=mean,
        drift_deg_per_s=a,
        drift_se_deg_per_s=s * math.sqrt(6.0 / (5.0 * dur)),
        sigma_deg_per_sqrt_s=s,
        sigma_se_deg_per_sqrt_s=s / math.sqrt(2.0 * n),
        dt_s=float(np.median(dts)),
        n_samples=int(t.size),
        duration_s=dur,
    )


def fit_station_file(
    path: str | Path,
    station: str | None = None,
    dt_s: float = 2.0,
    timezone: str | None = None,
    speed_unit: str | None = None,
    timescale_method: str = "efold",
) -> tuple[OUFit, DriftDiffusionFit]:
    """Read a station CSV and fit both shift models to one station's directions.

    Parameters
    ----------
    path : str or Path
        Station CSV (see :func:`sailroute.wind.stations.read_stations`).
    station : str, optional
        Station id; required when the file holds several stations.
    dt_s : float
        Records are averaged into bins of this many seconds (vector mean
        direction) before fitting [s].
    timezone : str, optional
        UTC offset for files whose timestamps carry none (only relative times
        matter for the fit).
    speed_unit : str, optional
        Unit of the speed column when its header does not say (the speed does
        not enter the fit, but the reader insists on knowing it).
    timescale_method : {"efold", "ar1"}
        See :func:`fit_ou`; the e-fold crossing is robust to instrument noise.

    Returns
    -------
    OUFit, DriftDiffusionFit
    """
    from sailroute.wind.stations import read_stations

    data = read_stations(path, resample_s=dt_s, timezone=timezone, speed_unit=speed_unit)
    names = data.stations
    if station is None:
        if len(names) != 1:
            raise InputError(
                f"{path}: holds {len(names)} stations ({', '.join(names)}); choose one with "
                "`station`"
            )
        station = names[0]
    elif station not in names:
        raise InputError(f"{path}: no station {station!r}; found {', '.join(names)}")
    one = data.select(station)
    return (
        fit_ou(one.t, one.direction_deg, dt_s, timescale_method),
        fit_drift_diffusion(one.t, one.direction_deg),
    )
