"""A model wind field (WRF) corrected by station observations.

At each station record the observed wind is compared with the model at the same
place and time: a speed ratio ``r = |obs| / |model|`` and a direction offset
``δ = TWD_obs − TWD_model``.  Both are smoothed in time per station (centred
window ``time_scale_s``; ``ln r`` arithmetically, ``δ`` as a circular mean)
and spread in space with Gaussian weights ``g = exp(−d² / 2L²)``:

``C(p) = Σ g_s C_s / max(1, Σ g_s)``

so the full correction applies at a station, several nearby stations are
averaged, and far from every station (``Σ g → 0``) the model is left unchanged.
Outside a station's time span its weight tapers linearly to zero over
``time_scale_s``.  The corrected wind is the model vector scaled by ``exp(C_ln r)``
and turned clockwise by ``C_δ``.  Limits are discussed in ``docs/design/wind.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError, WindDataError
from sailroute.geo import LocalFrame
from sailroute.units import wrap180
from sailroute.wind.base import Coverage, WindField, prepare_points
from sailroute.wind.height import DEFAULT_EXPONENT
from sailroute.wind.rotation import rotate_clockwise
from sailroute.wind.stations import StationData, local_records


@dataclass(frozen=True)
class StationCorrection:
    """Smoothed corrections of one station.

    Attributes
    ----------
    station : str
    t, x, y : ndarray
        Record times [epoch s] and local positions [m].
    log_ratio : ndarray
        Smoothed ``ln(|obs| / |model|)`` [-].
    offset_deg : ndarray
        Smoothed direction offset ``TWD_obs − TWD_model`` [°] (positive: the
        observed wind comes from further clockwise, i.e. veered).
    """

    station: str
    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    log_ratio: NDArray[np.float64]
    offset_deg: NDArray[np.float64]


def window_mean(t: NDArray, values: NDArray, valid: NDArray, width_s: float) -> NDArray:
    """Centred moving average over ``[t − width/2, t + width/2]`` of the valid samples.

    Parameters
    ----------
    t : ndarray (n,)
        Non-decreasing times [s].
    values : ndarray (n,)
        Samples.
    valid : ndarray of bool (n,)
        Samples to include.
    width_s : float
        Window width [s]; 0 means no smoothing.

    Returns
    -------
    ndarray (n,)
        NaN where the window holds no valid sample.
    """
    w = valid.astype(float)
    vals = np.where(valid, values, 0.0)
    cs = np.concatenate([[0.0], np.cumsum(vals)])
    cw = np.concatenate([[0.0], np.cumsum(w)])
    lo = np.searchsorted(t, t - 0.5 * width_s, side="left")
    hi = np.searchsorted(t, t + 0.5 * width_s, side="right")
    n = cw[hi] - cw[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, (cs[hi] - cs[lo]) / np.where(n > 0, n, 1.0), np.nan)


@dataclass(frozen=True, eq=False)
class BlendedWind:
    """Model wind corrected by observations (speed ratio and direction offset).

    Parameters
    ----------
    base : WindField
        The model field (typically from :func:`~sailroute.wind.wrf.open_wrf`), at
        ``height_m`` if set.
    stations : StationData
        Observations (resample high-rate logs first).
    frame : LocalFrame
        The base field's local frame.
    length_scale_m : float
        Gaussian length scale ``L`` of the spatial spreading [m].
    time_scale_s : float
        Width of the centred smoothing window of the corrections, and of the
        taper outside a station's time span [s].
    min_speed_ms : float
        Records where the observed or model speed is below this are not used
        (ratio and direction of a calm are noise) [m s⁻¹].
    ratio_range : (float, float)
        Speed ratios are clipped to this range [-].
    max_offset_deg : float
        Direction offsets are clipped to ``±max_offset_deg`` [°].
    height_m : float, optional
        Height of ``base`` [m]; observations are scaled from their measured height
        to it with the power law (``exponent``).  ``None``: used as measured.
    exponent : float
        Power-law exponent for that scaling [-].
    clamp : bool
        Clamp points to the coverage instead of raising.
    name : str
        Label for messages.

    Notes
    -----
    Coverage is the base field's coverage: the correction never extends the model.
    """

    base: WindField
    stations: StationData
    frame: LocalFrame
    length_scale_m: float = 2000.0
    time_scale_s: float = 600.0
    min_speed_ms: float = 1.0
    ratio_range: tuple[float, float] = (0.5, 2.0)
    max_offset_deg: float = 60.0
    height_m: float | None = None
    exponent: float = DEFAULT_EXPONENT
    clamp: bool = False
    name: str = "blended wind"

    def __post_init__(self) -> None:
        self._corr  # noqa: B018  (built now: building it checks the inputs)

    @cached_property
    def _corr(self) -> tuple[StationCorrection, ...]:
        """The stations' corrections of the base field (checked and built once)."""
        if not (self.length_scale_m > 0) or not (self.time_scale_s >= 0):
            raise InputError(f"{self.name}: length_scale_m must be > 0 and time_scale_s >= 0")
        lo, hi = self.ratio_range
        if not (0 < lo <= 1 <= hi):
            raise InputError(
                f"{self.name}: ratio_range must satisfy 0 < min <= 1 <= max, got {self.ratio_range}"
            )
        d = self.stations
        x, y, uo, vo = local_records(
            d, self.frame, self.height_m, self.name, exponent=self.exponent
        )
        inside = self.base.coverage.contains(d.t, x, y)
        if not inside.any():
            raise WindDataError(
                f"{self.name}: no station record of {d.source or 'the stations'} lies inside "
                f"the model field ({self.base.coverage.describe()}); the stations cannot "
                "correct it. Check times, positions and the model crop."
            )
        ub = np.zeros_like(uo)
        vb = np.zeros_like(vo)
        ub[inside], vb[inside] = self.base.sample(d.t[inside], x[inside], y[inside])
        so, sb = np.hypot(uo, vo), np.hypot(ub, vb)
        valid = inside & (so >= self.min_speed_ms) & (sb >= self.min_speed_ms)
        with np.errstate(divide="ignore", invalid="ignore"):
            logr = np.log(np.clip(so / np.where(sb > 0, sb, 1.0), lo, hi))
        off = wrap180(np.degrees(np.arctan2(uo, vo) - np.arctan2(ub, vb)))
        corr = []
        for s in d.stations:
            m = d.station == s
            tv, ok = d.t[m], valid[m]
            lr = window_mean(tv, logr[m], ok, self.time_scale_s)
            sn = window_mean(tv, np.sin(np.radians(off[m])), ok, self.time_scale_s)
            cs = window_mean(tv, np.cos(np.radians(off[m])), ok, self.time_scale_s)
            dd = np.degrees(np.arctan2(sn, cs))
            good = np.isfinite(lr) & np.isfinite(dd)
            if good.any():
                corr.append(
                    StationCorrection(
                        str(s),
                        tv[good],
                        x[m][good],
                        y[m][good],
                        lr[good],
                        np.clip(dd[good], -self.max_offset_deg, self.max_offset_deg),
                    )
                )
        return tuple(corr)

    @property
    def coverage(self) -> Coverage:
        """The base field's coverage."""
        return self.base.coverage

    @property
    def corrections(self) -> tuple[StationCorrection, ...]:
        """Per-station smoothed corrections (stations without usable records are absent)."""
        return self._corr

    def correction(
        self, t: ArrayLike, x: ArrayLike, y: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Spread corrections ``(ln r, δ [°])`` at points (broadcast, no coverage check)."""
        t, x, y = np.broadcast_arrays(
            np.asarray(t, float), np.asarray(x, float), np.asarray(y, float)
        )
        shape = t.shape
        t, x, y = t.ravel(), x.ravel(), y.ravel()
        num_r = np.zeros(t.size)
        num_d = np.zeros(t.size)
        den = np.zeros(t.size)
        inv2l2 = 0.5 / self.length_scale_m**2
        for c in self._corr:
            fixed = c.t.size == 1 or (np.ptp(c.x) == 0.0 and np.ptp(c.y) == 0.0)
            if fixed:
                sx, sy = c.x[0], c.y[0]
            else:
                sx, sy = np.interp(t, c.t, c.x), np.interp(t, c.t, c.y)
            if c.t.size == 1:
                lr, dd = c.log_ratio[0], c.offset_deg[0]
            else:
                lr, dd = np.interp(t, c.t, c.log_ratio), np.interp(t, c.t, c.offset_deg)
            outside = np.maximum(c.t[0] - t, 0.0) + np.maximum(t - c.t[-1], 0.0)
            if self.time_scale_s > 0:
                gt = np.clip(1.0 - outside / self.time_scale_s, 0.0, 1.0)
            else:
                gt = (outside == 0).astype(float)
            g = gt * np.exp(-((x - sx) ** 2 + (y - sy) ** 2) * inv2l2)
            num_r += g * lr
            num_d += g * dd
            den += g
        norm = np.maximum(den, 1.0)
        return (num_r / norm).reshape(shape), (num_d / norm).reshape(shape)

    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s] and local ``x, y`` [m] (broadcast)."""
        t, x, y = prepare_points(self.coverage, t, x, y, clamp=self.clamp, name=self.name)
        u, v = self.base.sample(t, x, y)
        lr, dd = self.correction(t, x, y)
        f = np.exp(lr)
        ur, vr = rotate_clockwise(u, v, dd)
        return np.asarray(ur * f, dtype=float), np.asarray(vr * f, dtype=float)
