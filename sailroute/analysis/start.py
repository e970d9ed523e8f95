"""The fleet's start: the gun and the line as the tracks see them, from the fleet itself.

A tracker's clock can run seconds off the committee's, and a start line can be laid tens of
metres from where the course file says.  Either makes every boat look over early (or late)
at the gun.  A fleet says which: at a good start the front row is on the line at the gun,
the rest a few seconds behind, and the odd boat over.  :func:`estimate_fleet_start` fits
that picture to where each boat was at the gun and how fast it sailed towards the course
side, and returns a :class:`~sailroute.analysis.segment.StartClock` per boat: the gun in the
tracks' clock, the line the fleet started on, and how far over a boat must be to be called
over early (:data:`Z_OCS` standard deviations).

The model (per boat *i*, at the course's gun): ``d_i`` its distance over the surveyed line
[m], ``v_i`` its speed towards the course side [m s⁻¹].  With the line laid ``shift_m``
(``δ``) up the course and the tracks stamped ``time_offset_s`` (``τ``) late, the boat
crossed the line the fleet used ``e_i = (δ − d_i)/v_i − τ`` seconds after the gun.  The
``e_i`` of the fleet are a mixture: clean starts, spread evenly over the ``W`` seconds after
the front row or (a share of them) over a wider ``W₂``, blurred by a normal error (the front
row's spread along the course, ``σ_m`` metres, over ``v_i``, and :data:`SIGMA_T_S`); over-early
boats, an exponential lead (mean
``κ``) before the gun; late starters, up to :data:`LATE_SPAN_S` after it.  The parameters
are the maximum of the likelihood with weak priors (so that three boats give an answer);
``δ`` alone, ``τ`` alone, or both are tried, and the one the data favour (BIC) is kept;
the standard errors come from the curvature of the likelihood.  ``τ`` has the sign of
:attr:`sailroute.wind.boatbias.BoatBias.time_offset_s`: a track's time minus the reference
clock's for the same moment, subtracted to correct.

Also here: :func:`detect_general_recall` (most of the fleet started, came back and started
again: a general recall whose restart gun was not given).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.segment import (
    LATE_START_S,
    OCS_MIN_S,
    START_EXTENSION_M,
    V_MIN_MS,
    StartClock,
    _crossings,
    _extended,
    _reversed,
    _segment_offset,
    _side,
    leg_target,
    start_geometry,
    velocity_at,
)
from sailroute.course.model import Course
from sailroute.timeutil import iso

__all__ = [
    "FleetStart",
    "GeneralRecall",
    "StartObservation",
    "detect_general_recall",
    "estimate_fleet_start",
    "observe_start",
]

Z_OCS = 3.0
"""A boat is called over early when over the fleet's line at the fleet's gun by more than
this many standard deviations (of the front row's spread, the GPS error over its speed and
the estimate's own error): one false call in ~700 clean starts."""

CROSS_WINDOW_S = 120.0
"""A boat's crossing of the line counts for the clock's estimate within this of the gun [s]."""

SIGMA_T_S = 0.3
"""Timing error of a boat's start [s] besides the front row's spread in metres (fixes
stamped to the second: 1/√12 s)."""

MIN_FLEET = 3
"""Fewest boats near the line at the gun for a fleet estimate; fewer keep the course's gun
and surveyed line."""

OCS_SPAN_S = 60.0
"""Over-early boats in the model lie up to this long before the gun [s]."""

LATE_SPAN_S = 600.0
"""Late starters in the model lie up to this long after the front row [s]."""

FLOOR_DENSITY = 1e-6
"""Density [s⁻¹] under every boat: a boat far outside the model (over by minutes, or
drifting) weighs no more than this."""

N_FRONT = 8
"""The earliest boats each tried as the front row in a fit."""

RECALL_WINDOW_S = 600.0
"""A boat that crosses back to the pre-start side within this time after starting [s] and
starts again has come back; most of the fleet doing so is a general recall."""

RECALL_SHARE = 0.5
"""Share of the started boats that must come back for a general recall."""

PULSE_S = 60.0
"""The boats of a start cross within this of their median time [s] (a general recall is
one start of the fleet, not boats sailing over the line one by one before it)."""

RECALL_BEFORE_S = 30.0
"""A general recall before the gun is looked for up to this before it [s]."""


@dataclass(frozen=True)
class StartObservation:
    """Where a boat was at the gun, against the surveyed start line.

    Attributes
    ----------
    boat : str
    distance_m : float
        Signed distance from the surveyed line (its infinite extension) at the gun [m]:
        + on the course side.
    speed_ms : float
        Velocity towards the course side at the gun [m s⁻¹] (the fixes 2 either side;
        NaN across a gap).
    abreast : bool
        Within the line's searched extension (:data:`START_EXTENSION_M` beyond each end).
    cross_s : float
        When it crossed the surveyed line (or its extension) towards the course side,
        nearest the gun: the last crossing before the gun when over at it, else the first
        after; relative to the gun [s] (NaN: none within :data:`CROSS_WINDOW_S`).
    cross_speed_ms : float
        Its velocity towards the course side at that crossing [m s⁻¹].
    """

    boat: str
    distance_m: float
    speed_ms: float
    abreast: bool
    cross_s: float = math.nan
    cross_speed_ms: float = math.nan

    def usable(self, model: str) -> bool:
        """Near the line and timed for ``model``: it enters the fleet estimate (the line's
        shift needs a boat moving towards the course side at the gun, the clock a
        crossing)."""
        if not (self.abreast and math.isfinite(self.distance_m)):
            return False
        moving = math.isfinite(self.speed_ms) and self.speed_ms >= V_MIN_MS
        crossed = math.isfinite(self.cross_s) and self.cross_speed_ms >= V_MIN_MS
        return moving if model == "line" else crossed if model == "clock" else moving and crossed


def observe_start(
    course: Course, t: NDArray, x: NDArray, y: NDArray, gun_t: float, boat: str, gap_s: float
) -> StartObservation | None:
    """The boat at the gun (None: its track does not span the gun)."""
    if t.size < 2 or not t[0] <= gun_t <= t[-1]:
        return None
    sg = start_geometry(course)
    wide = _extended(sg, START_EXTENSION_M)
    gx, gy = float(np.interp(gun_t, t, x)), float(np.interp(gun_t, t, y))
    vx, vy = velocity_at(t, x, y, gun_t, gap_s)
    f = _segment_offset(wide, gx, gy)[0]
    d = _side(sg, gx, gy)
    if d > 0:
        found = _crossings(t, x, y, wide, gun_t - CROSS_WINDOW_S, gap_s, gun_t)
        cross = [c for c in found if c.known][-1:]
    else:
        found = _crossings(t, x, y, wide, gun_t, gap_s, gun_t + CROSS_WINDOW_S)
        cross = [c for c in found if c.known][:1]
    cs = cv = math.nan
    if cross:
        cs = cross[0].t - gun_t
        cx, cy = velocity_at(t, x, y, cross[0].t, gap_s)
        cv = cx * sg.normal[0] + cy * sg.normal[1]
    return StartObservation(boat, d, vx * sg.normal[0] + vy * sg.normal[1], 0.0 <= f <= 1.0, cs, cv)


def _times(
    d: NDArray, v: NDArray, c: NDArray, vc: NDArray, tau: float, delta: float, model: str
) -> tuple[NDArray, NDArray]:
    """Each boat's start after the fleet's front row ``e`` [s] and the speed that turns a
    distance error into a time error [m s⁻¹], for ``model``: the line's shift from where the
    boat was at the gun (``(δ − d)/v``), the clock from when it crossed (``c − τ``), both from
    the crossing moved by the shift (``c + δ/v_c − τ``).  Where the crossing is unknown, the
    distance at the gun stands in; speeds are at least :data:`V_MIN_MS`."""
    vv = np.maximum(np.where(np.isfinite(v), v, 0.0), V_MIN_MS)
    vcc = np.maximum(np.where(np.isfinite(vc), vc, 0.0), V_MIN_MS)
    at_gun = (delta - d) / vv - tau
    if model == "line":
        return at_gun, vv
    crossed = c + (delta / vcc if model == "both" else 0.0) - tau
    ok = np.isfinite(c)
    return np.where(ok, crossed, at_gun), np.where(ok, vcc, vv)


@dataclass(frozen=True)
class FleetStart:
    """The fleet's gun and line, estimated from where the boats were at the course's gun.

    Attributes
    ----------
    gun_t : float
        The gun in the race's clock [epoch s] (the course's, or ``--gun``).
    time_offset_s : float
        The tracks' clock minus the race's [s] (as
        :attr:`~sailroute.wind.boatbias.BoatBias.time_offset_s`): the gun is at
        ``gun_t + time_offset_s`` in the tracks.
    shift_m : float
        The line the fleet started on lay this far up the course from the surveyed one [m].
    model : {"none", "line", "clock", "both"}
        What was estimated: nothing (fewer than :data:`MIN_FLEET` boats), the line's
        shift alone, the clock's offset alone, or both; the one the data favour.
    told_apart : bool
        The other single explanation fits clearly worse (BIC difference of 4 or more): the
        fleet says whether it was the line or the clock.
    spread_m : float
        Spread of the front row along the course [m] (``σ_m``: where the boats were and
        the GPS error of where they were).
    spread_s : float
        95 % of the clean starts lie within this time after the front row [s].
    se_time_offset_s, se_shift_m : float
        Standard errors [s, m] (0 for the one not estimated).
    n_boats : int
        Boats in the estimate.
    clocks : mapping of str to StartClock
        Per boat: the gun and line in its track and the verdict on over early
        (:attr:`StartClock.called`).
    speed_ms : float
        Median speed towards the course side at the gun of the boats in the estimate
        [m s⁻¹] (converts the line's shift into time).
    """

    gun_t: float
    time_offset_s: float = 0.0
    shift_m: float = 0.0
    model: str = "none"
    told_apart: bool = False
    spread_m: float = math.nan
    spread_s: float = math.nan
    se_time_offset_s: float = 0.0
    se_shift_m: float = 0.0
    n_boats: int = 0
    clocks: Mapping[str, StartClock] = field(default_factory=lambda: MappingProxyType({}))
    speed_ms: float = math.nan

    @property
    def track_gun_t(self) -> float:
        """The gun in the tracks' clock [epoch s]: ``gun_t + time_offset_s``."""
        return self.gun_t + self.time_offset_s

    def clock(self, boat: str) -> StartClock:
        """The boat's clock: the fleet's gun and line, and its verdict (a boat not
        observed at the gun: no verdict, over early beyond :data:`OCS_MIN_S`)."""
        return self.clocks.get(boat, StartClock(self.track_gun_t, self.shift_m))

    def describe(self) -> str:
        """One line for the fleet's notes."""
        if self.model == "none":
            return (
                f"start: the course's gun ({iso(self.gun_t)}) and surveyed line (fewer than "
                f"{MIN_FLEET} boats near the line at the gun for a fleet estimate)"
            )
        v = self.speed_ms
        parts = []
        if self.model in ("line", "both"):
            parts.append(
                f"the line used lay {self.shift_m:+.0f} ± {self.se_shift_m:.0f} m up the course "
                "from the surveyed one"
            )
        if self.model in ("clock", "both"):
            parts.append(
                f"the tracks' clock runs {self.time_offset_s:+.1f} ± "
                f"{self.se_time_offset_s:.1f} s off the gun's"
            )
        text = (
            f"start estimated from the fleet ({self.n_boats} boats at the gun, the front row "
            f"taken as on the line at the gun): " + " and ".join(parts)
        )
        if not self.told_apart and self.model in ("line", "clock") and math.isfinite(v) and v > 0:
            other = (
                f"a clock {-self.shift_m / v:+.1f} s off"
                if self.model == "line"
                else f"a line {-self.time_offset_s * v:+.0f} m up the course"
            )
            text += f" (or {other}: the boats' speeds at the gun cannot tell which)"
        return (
            text + f"; the front row spread {self.spread_m:.1f} m, the clean starts "
            f"within {self.spread_s:.0f} s of it; over early is called beyond {Z_OCS:.0f} sd"
        )


# --- the fit ------------------------------------------------------------------------------

_MODELS = {"line": (False, True), "clock": (True, False), "both": (True, True)}
"""Model -> (τ free, δ free)."""

_N_TAIL = 7
"""Parameters besides the offsets: log σ_m, log W, log W₂, log κ, logit of the wide body's
share of the clean starts, logits of the over-early and late shares."""

_PRIOR = (math.log(2.0), math.log(3.0), math.log(15.0), math.log(3.0))
"""Prior medians of the front row's spread [m], W, W₂ and κ [s] (log-normal)."""

_PRIOR_SD = (0.5, 1.0, 1.0, 1.0)
"""Their prior standard deviations in log: the front row's spread within a factor 1.65 of
2 m (a GPS receiver's error; the fleet widens it only with clear evidence), the rest a
factor e."""


def _unpack(theta: NDArray, free: tuple[bool, bool]) -> tuple[float, float, NDArray]:
    k = 0
    tau = delta = 0.0
    if free[0]:
        tau = float(theta[k])
        k += 1
    if free[1]:
        delta = float(theta[k])
        k += 1
    return tau, delta, theta[k : k + _N_TAIL]


def _emg(e: NDArray, s: NDArray, scale: float) -> NDArray:
    """Log density of an exponential delay (mean ``scale``) blurred by a normal error ``s``."""
    from scipy.special import log_ndtr

    out: NDArray = (
        -math.log(scale) + s * s / (2 * scale * scale) - e / scale + log_ndtr(e / s - s / scale)
    )
    return out


def _log_uniform(e: NDArray, s: NDArray, width: float) -> NDArray:
    """Log density of a delay spread evenly over ``[0, width]`` blurred by a normal error
    ``s``: ``log((Φ(e/s) − Φ((e − width)/s))/width)``, computed on the side of the smaller
    tail."""
    from scipy.special import log_ndtr

    a, b = e / s, (e - width) / s
    # Φ(a) − Φ(b) = Φ(−b) − Φ(−a): take the pair whose larger term is not near 1
    flip = b > 0
    hi = np.where(flip, -b, a)
    lo = np.where(flip, -a, b)
    lhi, llo = log_ndtr(hi), log_ndtr(lo)
    out: NDArray = lhi + np.log1p(-np.exp(np.minimum(llo - lhi, -1e-300))) - math.log(width)
    return out


def _log_mixture(
    e: NDArray,
    s: NDArray,
    widths: tuple[float, float],
    p_wide: float,
    kappa: float,
    p_ocs: float,
    p_late: float,
) -> NDArray:
    """Log density of each start time ``e`` [s]: a clean start (spread evenly over the
    first of ``widths`` after the front row, or with the share ``p_wide`` over the second),
    over early (an exponential lead, mean ``kappa``), late (spread evenly over
    :data:`LATE_SPAN_S`), all blurred by ``s``; and the floor.  The two widths let the
    body of the clean starts take any rough shape, so that ``s`` is the front row's own."""
    p_clean = max(1.0 - p_ocs - p_late, 1e-9)
    parts = np.empty((5, e.size))
    parts[0] = math.log(p_clean * (1.0 - p_wide)) + _log_uniform(e, s, widths[0])
    parts[1] = math.log(p_clean * p_wide) + _log_uniform(e, s, widths[1])
    parts[2] = math.log(max(p_ocs, 1e-12)) + _emg(-e, s, kappa)
    parts[3] = math.log(max(p_late, 1e-12)) + _log_uniform(e, s, LATE_SPAN_S)
    parts[4] = math.log(FLOOR_DENSITY)
    top = parts.max(axis=0)
    out: NDArray = top + np.log(np.exp(parts - top).sum(axis=0))
    return out


@dataclass(frozen=True)
class _Data:
    """The observations of the boats in a fit, as arrays."""

    d: NDArray
    v: NDArray
    c: NDArray
    vc: NDArray

    @classmethod
    def of(cls, obs: Sequence[StartObservation]) -> _Data:
        return cls(
            np.array([o.distance_m for o in obs]),
            np.array([o.speed_ms for o in obs]),
            np.array([o.cross_s for o in obs]),
            np.array([o.cross_speed_ms for o in obs]),
        )


def _neg_log_post(theta: NDArray, data: _Data, model: str) -> float:
    from scipy.special import expit

    tau, delta, tail = _unpack(theta, _MODELS[model])
    scales = [min(max(float(q), -5.0), 6.0) for q in tail[:4]]
    ls, lw, lw2, lk = scales
    # the shares between 0.05 % and 49 %: a share run to 0 leaves the posterior flat in it
    p_wide = float(expit(min(max(float(tail[4]), -7.0), 7.0)))
    p_ocs, p_late = (0.5 * float(expit(min(max(float(q), -7.0), 4.0))) for q in tail[5:7])
    e, v = _times(data.d, data.v, data.c, data.vc, tau, delta, model)
    s = np.sqrt((math.exp(ls) / v) ** 2 + SIGMA_T_S**2)
    widths = (math.exp(lw), math.exp(lw) + math.exp(lw2))
    ll_data = float(np.sum(_log_mixture(e, s, widths, p_wide, math.exp(lk), p_ocs, p_late)))
    # weak priors: the scales log-normal about _PRIOR; few over early or late (Beta(1, 9)
    # on each share); offsets within minutes and hundreds of metres
    prior = (
        -0.5 * sum(((q - m) / w) ** 2 for q, m, w in zip(scales, _PRIOR, _PRIOR_SD, strict=True))
        + 8.0 * math.log1p(-2 * p_ocs * 0.999)
        + 8.0 * math.log1p(-2 * p_late * 0.999)
        - 0.5 * (tau / 60.0) ** 2
        - 0.5 * (delta / 500.0) ** 2
    )
    return -(ll_data + prior)


def _hessian(f: Callable[[NDArray], float], x: NDArray, h: NDArray) -> NDArray:
    """Central-difference Hessian of ``f`` at ``x`` with steps ``h``."""
    n = x.size
    out = np.zeros((n, n))
    f0 = f(x)
    step = np.diag(h)
    for i in range(n):
        out[i, i] = (f(x + step[i]) - 2 * f0 + f(x - step[i])) / h[i] ** 2
        for j in range(i + 1, n):
            a, b = step[i], step[j]
            out[i, j] = out[j, i] = (f(x + a + b) - f(x + a - b) - f(x - a + b) + f(x - a - b)) / (
                4 * h[i] * h[j]
            )
    return out


@dataclass(frozen=True)
class _Fit:
    model: str
    theta: NDArray
    nlp: float
    n_params: int
    n: int


def _fit(obs: Sequence[StartObservation], model: str, start: _Fit | None = None) -> _Fit:
    """The maximum of the posterior for ``model`` over the boats it can use.

    Each of the :data:`N_FRONT` earliest boats in turn is taken as the front row (its
    start time 0) and the other parameters fitted with it held; the best is refined with
    everything free.
    """
    from scipy.optimize import minimize

    data = _Data.of([o for o in obs if o.usable(model)])
    free = _MODELS[model]
    tail = np.array([*_PRIOR, 0.0, -2.0, -2.0])
    if model == "line":
        heads = [np.array([d]) for d in data.d]
    elif model == "clock":
        heads = [np.array([c]) for c in data.c]
    else:
        assert start is not None
        tau, delta, _ = _unpack(start.theta, _MODELS[start.model])
        heads = [np.array([tau, delta])]
    # the front row is among the earliest boats: each of them in turn
    order = np.argsort(
        [float(_neg_log_post(np.concatenate([h, tail]), data, model)) for h in heads]
    )
    first = np.argsort([float(h[-1]) * (1.0 if model == "clock" else -1.0) for h in heads])
    heads = [heads[int(k)] for k in dict.fromkeys([*first[:N_FRONT].tolist(), *order[:2].tolist()])]
    cand = []
    for h in heads:

        def held(q: NDArray, h: NDArray = h) -> float:
            return _neg_log_post(np.concatenate([h, q]), data, model)

        r = minimize(held, tail, method="Powell", options={"maxfev": 120, "xtol": 1e-2})
        cand.append((float(r.fun), np.concatenate([h, r.x])))
    best: _Fit | None = None
    for _, x0 in sorted(cand, key=lambda c: c[0])[:1]:
        r = minimize(_neg_log_post, x0, args=(data, model), method="Powell", options={"xtol": 1e-3})
        if best is None or float(r.fun) < best.nlp:
            best = _Fit(
                model, np.asarray(r.x, float), float(r.fun), sum(free) + _N_TAIL, data.d.size
            )
    assert best is not None
    return best


def _clean_p95(tail: NDArray) -> float:
    """The time after the front row within which 95 % of the clean starts lie [s]."""
    from scipy.special import expit

    w1 = math.exp(float(tail[1]))
    w2 = w1 + math.exp(float(tail[2]))
    pw = float(expit(min(max(float(tail[4]), -7.0), 7.0)))
    grid = np.linspace(0.0, w2, 401)
    cdf = (1 - pw) * np.minimum(grid / w1, 1.0) + pw * grid / w2
    return float(grid[np.searchsorted(cdf, 0.95)])


def _covariance(fit: _Fit, obs: Sequence[StartObservation]) -> NDArray:
    """Covariance of ``(τ, δ)`` from the curvature of the posterior (a diagonal guess from
    the spread where it is not positive definite)."""
    data = _Data.of([o for o in obs if o.usable(fit.model)])
    free = _MODELS[fit.model]
    k = sum(free)
    cov2 = np.zeros((2, 2))
    idx = [j for j, f in enumerate(free) if f]
    try:
        h = np.full(fit.theta.size, 0.01)
        h[:k] = [0.05 if free[0] and j == 0 else 0.2 for j in range(k)]
        hess = _hessian(lambda th: _neg_log_post(th, data, fit.model), fit.theta, h)
        cov = np.linalg.inv(hess)
        for a, ia in enumerate(idx):
            for b, ib in enumerate(idx):
                cov2[ia, ib] = cov[a, b]
        if np.any(np.diag(cov2)[idx] <= 0) or not np.all(np.isfinite(cov2)):
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:
        sm = math.exp(float(fit.theta[k]))
        v = float(np.median(data.v))
        cov2 = np.diag(
            [(sm / v) ** 2 / fit.n if free[0] else 0.0, sm**2 / fit.n if free[1] else 0.0]
        )
    return cov2


def estimate_fleet_start(
    observations: Sequence[StartObservation],
    gun_t: float,
    models: Sequence[str] = ("line", "clock", "both"),
) -> FleetStart:
    """The fleet's gun and line from where its boats were at the gun, and each boat's
    verdict on over early.

    Parameters
    ----------
    observations : sequence of StartObservation
        One per boat that was on the water at the gun (:func:`observe_start`).
    gun_t : float
        The gun in the race's clock [epoch s].
    models : sequence of str
        The explanations tried (``"clock"`` alone where the gun itself is an estimate: a
        restart found in the tracks).

    Returns
    -------
    FleetStart
        ``model="none"`` (the course's gun and line, no verdicts: over early beyond
        :data:`~sailroute.analysis.segment.OCS_MIN_S`) with fewer than :data:`MIN_FLEET`
        usable boats.
    """
    usable = {m: sum(o.usable(m) for o in observations) for m in _MODELS}
    singles = [m for m in ("line", "clock") if m in models and usable[m] >= MIN_FLEET]
    if not singles:
        return FleetStart(gun_t, n_boats=max(usable.values()))
    fits = {m: _fit(observations, m) for m in singles}
    v = np.array([o.speed_ms for o in observations if o.usable("both")])
    if "both" in models and usable["both"] >= 8 and float(np.std(1.0 / v) / np.mean(1.0 / v)) > 0.1:
        fits["both"] = _fit(observations, "both", min(fits.values(), key=lambda f: f.nlp))
    # the same boats for every model: a model that can use fewer is charged for the rest
    # at the floor density
    n_all = max(f.n for f in fits.values())
    bic = {
        m: 2 * (f.nlp - (n_all - f.n) * math.log(FLOOR_DENSITY)) + f.n_params * math.log(n_all)
        for m, f in fits.items()
    }
    order = sorted(bic, key=lambda m: (bic[m], m != "line"))
    best = fits[order[0]]
    ranked = sorted(bic[m] for m in ("line", "clock") if m in bic)
    told = best.model == "both" or (len(ranked) == 2 and ranked[1] - ranked[0] >= 4.0)
    free = _MODELS[best.model]
    tau, delta, tail = _unpack(best.theta, free)
    spread_m, spread_s = math.exp(float(tail[0])), _clean_p95(tail)
    cov = _covariance(best, observations)
    est = FleetStart(
        gun_t,
        tau,
        delta,
        best.model,
        told,
        spread_m,
        spread_s,
        math.sqrt(max(cov[0, 0], 0.0)),
        math.sqrt(max(cov[1, 1], 0.0)),
        best.n,
        speed_ms=float(np.median([o.speed_ms for o in observations if o.usable(best.model)])),
    )
    return replace(est, clocks=MappingProxyType(_verdicts(est, observations, cov)))


def _verdicts(
    est: FleetStart, observations: Sequence[StartObservation], cov: NDArray
) -> dict[str, StartClock]:
    """Each observed boat's clock: its start after the front row under the fleet's model,
    its standard deviation, and over early when more than :data:`Z_OCS` of them ahead."""
    out = {}
    for o in observations:
        if not (o.abreast and math.isfinite(o.distance_m)):
            out[o.boat] = StartClock(est.track_gun_t, est.shift_m)
            continue
        data = _Data.of([o])
        e, v = _times(data.d, data.v, data.c, data.vc, est.time_offset_s, est.shift_m, est.model)
        j = np.array([-1.0, 1.0 / float(v[0]) if est.model != "clock" else 0.0])
        sd = math.sqrt(
            (est.spread_m / float(v[0])) ** 2 + SIGMA_T_S**2 + max(float(j @ cov @ j), 0.0)
        )
        over = -float(e[0])
        out[o.boat] = StartClock(
            est.track_gun_t,
            est.shift_m,
            max(OCS_MIN_S, Z_OCS * sd),
            sd,
            over_s=over,
            called=over > Z_OCS * sd,
            late_s=max(LATE_START_S, est.spread_s) + Z_OCS * sd,
        )
    return out


# --- general recall ------------------------------------------------------------------------


@dataclass(frozen=True)
class GeneralRecall:
    """Most of the fleet started, came back and started again.

    Attributes
    ----------
    boats : tuple of str
        The boats that came back and started again.
    n_started : int
        Boats that started the first time.
    first_t : float
        When the fleet started the first time [epoch s]: the median of its crossings.
    restart_t : float
        When the fleet crossed again [epoch s]: the first of its second crossings within
        the spread of the rest (the 10th percentile), an estimate of the restart's gun.
    """

    boats: tuple[str, ...]
    n_started: int
    first_t: float
    restart_t: float


def detect_general_recall(
    course: Course,
    tracks: Mapping[str, tuple[NDArray, NDArray, NDArray]],
    after_t: float,
    gap_s: Mapping[str, float],
    before_t: float = math.inf,
) -> GeneralRecall | None:
    """A general recall: most boats (:data:`RECALL_SHARE`, and at least :data:`MIN_FLEET`)
    crossed the start line together (within :data:`PULSE_S` of their median) between
    ``after_t`` and ``before_t`` (at most :data:`RECALL_WINDOW_S` after ``after_t``), crossed
    back within :data:`RECALL_WINDOW_S` before getting halfway to the first mark, and
    crossed forward again.

    Parameters
    ----------
    course : Course
    tracks : mapping of str to (t, x, y)
        Each boat's track in the course frame.
    after_t, before_t : float
        Where the first start is looked for [epoch s] (after the course's gun when it gives
        no restart; before the gun, to say there was a recall before it).
    gap_s : mapping of str to float
        Each track's gap limit (:func:`~sailroute.analysis.segment.gap_limit_s`).
    """
    sg = start_geometry(course)
    wide = _extended(sg, START_EXTENSION_M)
    back_geom = _reversed(wide)
    mx, my = leg_target(course, 0).centre
    half = 0.5 * abs(_side(sg, mx, my))
    first_t: dict[str, float] = {}
    again: dict[str, float] = {}
    t_to = min(after_t + RECALL_WINDOW_S, before_t)
    for boat, (t, x, y) in tracks.items():
        g = gap_s[boat]
        first = [c for c in _crossings(t, x, y, wide, after_t, g, t_to) if c.known]
        if not first:
            continue
        first_t[boat] = first[0].t
        back = [
            c
            for c in _crossings(t, x, y, back_geom, first[0].t, g, first[0].t + RECALL_WINDOW_S)
            if c.known
        ]
        if not back:
            continue
        m = (t >= first[0].t) & (t <= back[0].t)
        up = (x[m] - sg.a[0]) * sg.normal[0] + (y[m] - sg.a[1]) * sg.normal[1]
        if up.size and float(up.max()) > half:
            continue
        nxt = [c for c in _crossings(t, x, y, wide, back[0].t, g) if c.known]
        if nxt:
            again[boat] = nxt[0].t
    if not again:
        return None
    pulse = float(np.median([first_t[b] for b in again]))
    came = {b: v for b, v in again.items() if abs(first_t[b] - pulse) <= PULSE_S}
    if len(came) < max(MIN_FLEET, RECALL_SHARE * len(first_t)):
        return None
    return GeneralRecall(
        tuple(sorted(came)),
        len(first_t),
        pulse,
        float(np.percentile(list(came.values()), 10.0)),
    )
