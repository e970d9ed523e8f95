"""The space-time interpolation of several moving sensors (:class:`FleetField`): the fleet
mean, inverse-distance weights in space or in space and time, optimal interpolation of the
residuals (a Gaussian-process fit), the nearest sensor or a constant (:data:`FLEET_METHODS`)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.errors import InputError, OutOfCoverageError
from sailroute.timeutil import iso
from sailroute.wind.base import Coverage, prepare_points

if TYPE_CHECKING:
    from sailroute.geo import LocalFrame

from sailroute.wind.measuredseries import MeasuredSeries

FLEET_METHODS: Final = ("mean", "idw", "st-idw", "oi", "nearest", "constant")
"""Methods of :class:`FleetField`: the candidates ``idw`` (inverse distance between the
sensors at each time), ``st-idw`` (inverse space-time distance over nearby records),
``oi`` (optimal interpolation: the sensors' mean plus a Gaussian-process correction with
fitted length and time scales), and the baselines ``mean`` (the sensors' mean at each
time), ``nearest`` (the nearest sensor at each time), ``constant`` (one mean wind)."""


@dataclass(frozen=True, eq=False)
class _Sensor:
    name: str
    series: MeasuredSeries
    t: NDArray
    x: NDArray
    y: NDArray
    u: NDArray
    v: NDArray


@dataclass(frozen=True, eq=False)
class _OiFit:
    """Fitted optimal-interpolation state: observations, weights and scales."""

    t: NDArray
    x: NDArray
    y: NDArray
    alpha: NDArray  # (n, 2): (K + noise I)^-1 residuals
    sigma2: float
    length_m: float
    time_s: float
    noise2: float


@dataclass(frozen=True, eq=False)
class FleetField:
    """Several moving sensors as one :class:`~sailroute.wind.base.WindField`.

    Built by :func:`fleet_wind` (use that); the sensors are already bias-corrected
    and resampled.  Coverage: the span during which every sensor has logged (the
    intersection; the message on a miss names the logs that limit it) and the
    sensors' box plus ``radius_m``.  At a time where a sensor is in a hole it is
    left out; where every sensor is in a hole, sampling raises.

    Parameters
    ----------
    sensors : sequence of MeasuredSeries
        The sensors.
    frame : LocalFrame
        The course's local frame.
    method : str
        One of :data:`FLEET_METHODS`.
    power : float
        IDW exponent (``idw``, ``st-idw``).
    speed_scale_ms : float
        ``st-idw``: metres per second of time difference in the space-time distance
        [m s⁻¹].
    window_s : float
        ``st-idw``: records within ``±window_s`` of the time are used [s].
    oi_scales : (float, float, float, float), optional
        ``oi``: ``(sigma [m s⁻¹], length [m], time [s], noise [m s⁻¹])``; fitted by
        maximum likelihood when None.
    radius_m : float
        Coverage box margin around every sensor position [m].
    clamp : bool
        Clamp points to the coverage instead of raising.
    name : str
        Label for messages.
    """

    sensors: tuple[MeasuredSeries, ...]
    frame: LocalFrame
    method: str = "mean"
    power: float = 2.0
    speed_scale_ms: float = 5.0
    window_s: float = 60.0
    oi_scales: tuple[float, float, float, float] | None = None
    radius_m: float = 2000.0
    clamp: bool = False
    name: str = "fleet wind"

    def __post_init__(self) -> None:
        self._state  # noqa: B018  (built now: building it checks the inputs)
        self._oi_state  # noqa: B018

    @cached_property
    def _state(self) -> tuple[tuple[_Sensor, ...], Coverage, str]:
        if self.method not in FLEET_METHODS:
            raise InputError(
                f"{self.name}: method {self.method!r}; expected one of {', '.join(FLEET_METHODS)}"
            )
        if not self.sensors:
            raise InputError(f"{self.name}: no sensors")
        if not (
            self.power > 0
            and self.speed_scale_ms >= 0
            and self.window_s >= 0
            and self.radius_m >= 0
        ):
            raise InputError(
                f"{self.name}: power must be > 0 and speed_scale_ms, window_s, "
                f"radius_m >= 0 (got {self.power}, {self.speed_scale_ms}, "
                f"{self.window_s}, {self.radius_m})"
            )
        sens = []
        for s in self.sensors:
            if len(s) < 1:
                raise InputError(f"{self.name}: the log of {s.label} has no wind records")
            x, y, u, v = s.local(self.frame)
            sens.append(_Sensor(s.boat, s, s.t, x, y, u, v))
        starts = [float(s.t[0]) for s in sens]
        ends = [float(s.t[-1]) for s in sens]
        t0, t1 = max(starts), min(ends)
        first = sens[int(np.argmax(starts))].series
        last = sens[int(np.argmin(ends))].series
        limit = (
            f"the time span is limited by the log of {first.label} (starts "
            f"{iso(t0)}) and the log of {last.label} (ends {iso(t1)})"
        )
        if t0 > t1:
            raise InputError(
                f"{self.name}: the logs never overlap in time: {limit}; use logs of the same race"
            )
        xs = np.concatenate([s.x for s in sens])
        ys = np.concatenate([s.y for s in sens])
        r = self.radius_m
        cov = Coverage(
            t0,
            t1,
            float(xs.min()) - r,
            float(xs.max()) + r,
            float(ys.min()) - r,
            float(ys.max()) + r,
            frame=self.frame,
            source_span=(min(starts), max(ends)),
        )
        return tuple(sens), cov, limit

    @cached_property
    def _oi_state(self) -> _OiFit | None:
        return self._fit_oi(self._state[0]) if self.method == "oi" else None

    @property
    def coverage(self) -> Coverage:
        """Common time span of the sensors; their box plus ``radius_m``."""
        return self._state[1]

    @property
    def limit_note(self) -> str:
        """Which logs limit the time span."""
        return self._state[2]

    @property
    def oi_scales_fitted(self) -> tuple[float, float, float, float] | None:
        """``oi``: ``(sigma [m s⁻¹], length [m], time [s], noise [m s⁻¹])`` in use."""
        oi = self._oi_state
        if oi is None:
            return None
        return (float(np.sqrt(oi.sigma2)), oi.length_m, oi.time_s, float(np.sqrt(oi.noise2)))

    def available(self, t: ArrayLike) -> NDArray[np.bool_]:
        """Mask of times [epoch s] inside the time span where some sensor is not in a hole."""
        t = np.asarray(t, dtype=float).ravel()
        c = self.coverage
        return (t >= c.t0) & (t <= c.t1) & self._at(t)[4].any(axis=-1)

    # ---------------------------------------------------------------- per-sensor values
    def _at(self, t: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray]:
        """Per-sensor ``x, y, u, v, ok`` at times ``t``, each ``(n, S)`` (linear in time)."""
        cols: list[list[NDArray]] = [[], [], [], [], []]
        for s in self._state[0]:
            ts = s.t
            ok = (t >= ts[0]) & (t <= ts[-1])
            if ts.size == 1:
                i = np.zeros(t.size, np.intp)
                j, w = i, np.zeros(t.size)
            else:
                i = np.clip(np.searchsorted(ts, t, side="right") - 1, 0, ts.size - 2)
                j = i + 1
                w = np.clip((t - ts[i]) / (ts[j] - ts[i]), 0.0, 1.0)
            for c, a in zip(cols, (s.x, s.y, s.u, s.v), strict=False):
                c.append(a[i] + w * (a[j] - a[i]))
            if s.series.gaps:
                g0 = np.array([g for g, _ in s.series.gaps])
                g1 = np.array([g for _, g in s.series.gaps])
                k = np.maximum(np.searchsorted(g0, t, side="right") - 1, 0)
                ok &= ~((t > g0[k]) & (t < g1[k]))
            cols[4].append(ok)
        x, y, u, v, okk = (np.stack(c, axis=-1) for c in cols)
        return x, y, u, v, okk.astype(bool)

    def _combine(self, w: NDArray, u: NDArray, v: NDArray, t: NDArray) -> tuple[NDArray, NDArray]:
        tot = w.sum(axis=-1)
        if (tot <= 0).any():
            k = int(np.argmax(tot <= 0))
            raise OutOfCoverageError(
                f"{self.name}: {int((tot <= 0).sum())} of {tot.size} sample points fall where "
                f"every log has a gap (first at {iso(float(t[k]))}; gaps: "
                + "; ".join(
                    f"{s.series.label} {iso(a)} .. {iso(b)}"
                    for s in self._state[0]
                    for a, b in s.series.gaps
                )
                + "); the wind there is unknown. Use another wind for that time."
            )
        return (w * u).sum(axis=-1) / tot, (w * v).sum(axis=-1) / tot

    def _mean(self, t: NDArray, allow_missing: bool = False) -> tuple[NDArray, NDArray]:
        _, _, u, v, ok = self._at(t)
        if allow_missing:
            n = ok.sum(axis=-1)
            with np.errstate(invalid="ignore", divide="ignore"):
                return (u * ok).sum(axis=-1) / n, (v * ok).sum(axis=-1) / n
        return self._combine(ok.astype(float), u, v, t)

    # ---------------------------------------------------------------- optimal interpolation
    def _fit_oi(self, sens: tuple[_Sensor, ...]) -> _OiFit:
        t = np.concatenate([s.t for s in sens])
        x = np.concatenate([s.x for s in sens])
        y = np.concatenate([s.y for s in sens])
        u = np.concatenate([s.u for s in sens])
        v = np.concatenate([s.v for s in sens])
        mu, mv = self._mean(t, allow_missing=True)
        keep = np.isfinite(mu)
        t, x, y = t[keep], x[keep], y[keep]
        res = np.column_stack([u[keep] - mu[keep], v[keep] - mv[keep]])
        if self.oi_scales is not None:
            sig, lm, ts, nz = self.oi_scales
            p = (sig * sig, lm, ts, nz * nz)
        else:
            p = _fit_gp(t, x, y, res)
        k = _kernel(t, x, y, t, x, y, p[0], p[1], p[2])
        k[np.diag_indices_from(k)] += p[3]
        alpha = np.linalg.solve(k, res)
        return _OiFit(t, x, y, alpha, p[0], p[1], p[2], p[3])

    # ---------------------------------------------------------------- sampling
    def sample(self, t: ArrayLike, x: ArrayLike, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """Wind ``(u, v)`` [m s⁻¹] at epoch ``t`` [s], position ``x, y`` [m] (broadcast)."""
        try:
            t, x, y = prepare_points(self.coverage, t, x, y, clamp=self.clamp, name=self.name)
        except OutOfCoverageError as e:
            raise OutOfCoverageError(f"{e}\n  ({self.limit_note})") from None
        shape = t.shape
        t, x, y = t.ravel(), x.ravel(), y.ravel()
        if not t.size:
            return np.zeros(shape), np.zeros(shape)
        m = self.method
        if m == "constant":
            sens = self._state[0]
            uu = np.concatenate([s.u for s in sens]).mean()
            vv = np.concatenate([s.v for s in sens]).mean()
            u, v = np.full(t.size, uu), np.full(t.size, vv)
        elif m == "mean":
            u, v = self._mean(t)
        elif m in ("idw", "nearest"):
            sx, sy, su, sv, ok = self._at(t)
            d2 = np.maximum((x[:, None] - sx) ** 2 + (y[:, None] - sy) ** 2, 1e-24)
            if m == "idw":
                w = d2 ** (-0.5 * self.power) * ok
            else:
                d2 = np.where(ok, d2, np.inf)
                w = (d2 == d2.min(axis=1, keepdims=True)) & ok
            u, v = self._combine(w.astype(float), su, sv, t)
        elif m == "st-idw":
            u, v = self._st_idw(t, x, y)
        else:
            u, v = self._oi(t, x, y)
        return u.reshape(shape), v.reshape(shape)

    def _st_idw(self, t: NDArray, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
        """Inverse space-time distance over every record within ``±window_s``."""
        c2 = self.speed_scale_ms**2
        wsum = np.zeros(t.size)
        usum = np.zeros(t.size)
        vsum = np.zeros(t.size)
        any_ok = np.zeros(t.size, bool)
        for s in self._state[0]:
            ts = s.t
            ok = (t >= ts[0]) & (t <= ts[-1])
            if s.series.gaps:
                g0 = np.array([g for g, _ in s.series.gaps])
                g1 = np.array([g for _, g in s.series.gaps])
                k = np.maximum(np.searchsorted(g0, t, side="right") - 1, 0)
                ok &= ~((t > g0[k]) & (t < g1[k]))
            any_ok |= ok
            lo = np.searchsorted(ts, t - self.window_s, side="left")
            hi = np.searchsorted(ts, t + self.window_s, side="right")
            for m in range(int((hi - lo).max())):
                k = np.minimum(lo + m, ts.size - 1)
                dt = ts[k] - t
                d2 = np.maximum((x - s.x[k]) ** 2 + (y - s.y[k]) ** 2 + c2 * dt * dt, 1e-24)
                w = 1.0 / d2 if self.power == 2.0 else d2 ** (-0.5 * self.power)
                w *= (lo + m < hi) & ok
                wsum += w
                usum += w * s.u[k]
                vsum += w * s.v[k]
        if not any_ok.all():
            self._combine(
                any_ok[:, None].astype(float), np.zeros((t.size, 1)), np.zeros((t.size, 1)), t
            )
        return usum / wsum, vsum / wsum

    def _oi(self, t: NDArray, x: NDArray, y: NDArray) -> tuple[NDArray, NDArray]:
        oi = self._oi_state
        assert oi is not None
        u, v = self._mean(t)
        chunk = max(1, 2_000_000 // max(oi.t.size, 1))
        for a in range(0, t.size, chunk):
            sl = slice(a, a + chunk)
            k = _kernel(t[sl], x[sl], y[sl], oi.t, oi.x, oi.y, oi.sigma2, oi.length_m, oi.time_s)
            c = k @ oi.alpha
            u[sl] += c[:, 0]
            v[sl] += c[:, 1]
        return u, v


def _kernel(
    t1: NDArray,
    x1: NDArray,
    y1: NDArray,
    t2: NDArray,
    x2: NDArray,
    y2: NDArray,
    sigma2: float,
    length_m: float,
    time_s: float,
) -> NDArray:
    """Squared-exponential covariance in space and time, ``(n1, n2)``."""
    q = ((x1[:, None] - x2) ** 2 + (y1[:, None] - y2) ** 2) / (length_m * length_m) + (
        t1[:, None] - t2
    ) ** 2 / (time_s * time_s)
    return sigma2 * np.exp(-0.5 * q)


NOISE_FLOOR_MS: Final = 0.05
"""Smallest observation noise of the ``oi`` method [m s⁻¹] (an anemometer's resolution):
keeps the covariance matrix well conditioned when the boats agree to the last digit."""


def _fit_gp(
    t: NDArray, x: NDArray, y: NDArray, res: NDArray, max_points: int = 400
) -> tuple[float, float, float, float]:
    """Maximum-likelihood ``(sigma², length, time, noise²)`` for residuals ``(n, 2)``.

    Both components share the scales; at most ``max_points`` evenly spaced records
    enter the fit (the prediction uses them all).
    """
    from scipy.optimize import minimize

    if t.size > max_points:
        k = np.linspace(0, t.size - 1, max_points).astype(int)
        t, x, y, res = t[k], x[k], y[k], res[k]
    var = max(float(np.mean(res * res)), NOISE_FLOOR_MS**2)
    n = t.size

    def nll(p: NDArray) -> float:
        s2, lm, ts, n2 = np.exp(p)
        k = _kernel(t, x, y, t, x, y, s2, lm, ts)
        k[np.diag_indices_from(k)] += n2 + 1e-9
        try:
            c = np.linalg.cholesky(k)
        except np.linalg.LinAlgError:
            return 1e20
        z = np.linalg.solve(c, res)
        return float(0.5 * np.sum(z * z) + 2 * np.sum(np.log(np.diag(c))) + n * np.log(2 * np.pi))

    p0 = np.log([0.5 * var, 500.0, 120.0, 0.5 * var])
    bounds = [
        (np.log(var * 1e-3), np.log(var * 10)),
        (np.log(50.0), np.log(2e4)),
        (np.log(10.0), np.log(3600.0)),
        (np.log(max(var * 1e-3, NOISE_FLOOR_MS**2)), np.log(var * 10)),
    ]
    r = minimize(nll, p0, method="L-BFGS-B", bounds=bounds)
    s2, lm, ts, n2 = (float(a) for a in np.exp(r.x))
    return s2, lm, ts, n2
