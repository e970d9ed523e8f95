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
``e_i`` of the fleet are a mixture: clean starts, an exponential delay (mean ``λ``) after
the front row blurred by a normal error (the front row's spread along the course, ``σ_m``
metres, over ``v_i``, and :data:`SIGMA_T_S`); over-early boats, an exponential lead (mean
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

RECALL_WINDOW_S = 600.0
"""A boat that crosses back to the pre-start side within this time after starting [s] and
starts again has come back; most of the fleet doing so is a general recall."""

RECALL_SHARE = 0.5
"""Share of the started boats that must come back for a general recall."""


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
    """

    boat: str
    distance_m: float
    speed_ms: float
    abreast: bool

    @property
    def usable(self) -> bool:
        """Near the line, moving towards the course side: it enters the fleet estimate."""
        return (
            self.abreast
            and math.isfinite(self.distance_m)
            and math.isfinite(self.speed_ms)
            and self.speed_ms >= V_MIN_MS
        )


def observe_start(
    course: Course, t: NDArray, x: NDArray, y: NDArray, gun_t: float, boat: str, gap_s: float
) -> StartObservation | None:
    """The boat at the gun (None: its track does not span the gun)."""
    if t.size < 2 or not t[0] <= gun_t <= t[-1]:
        return None
    sg = start_geometry(course)
    gx, gy = float(np.interp(gun_t, t, x)), float(np.interp(gun_t, t, y))
    vx, vy = velocity_at(t, x, y, gun_t, gap_s)
    f = _segment_offset(_extended(sg, START_EXTENSION_M), gx, gy)[0]
    return StartObservation(
        boat,
        _side(sg, gx, gy),
        vx * sg.normal[0] + vy * sg.normal[1],
        0.0 <= f <= 1.0,
    )


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
        Spread of the front row along the course at the gun [m] (``σ_m``: where the boats
        were and the GPS error of where they were).
    delay_s : float
        Mean delay of a clean start after the front row [s] (``λ``).
    se_time_offset_s, se_shift_m : float
        Standard errors [s, m] (0 for the one not estimated).
    n_boats : int
        Boats in the estimate.
    clocks : mapping of str to StartClock
        Per boat: the gun and line in its track, and its threshold for over early.
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
    delay_s: float = math.nan
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
        """The boat's clock (the plain gun and surveyed line when it was not observed)."""
        return self.clocks.get(boat, self.plain_clock())

    def plain_clock(self) -> StartClock:
        """The fleet's gun and line for a boat not in the estimate, with the fleet's spread
        but no speed of its own (:data:`V_MIN_MS` … its GPS error counts in full)."""
        if self.model == "none":
            return StartClock.plain(self.gun_t)
        return self._clock(np.nan, None)

    def _clock(self, v: float, cov: NDArray | None) -> StartClock:
        sd = boat_sd_s(self.spread_m, v, self.se_time_offset_s, self.se_shift_m, cov)
        return StartClock(
            self.gun_t + self.time_offset_s,
            self.shift_m,
            max(OCS_MIN_S, Z_OCS * sd),
            sd,
        )

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
            text + f"; the front row spread {self.spread_m:.1f} m, a clean start "
            f"{self.delay_s:.1f} s behind it on average; over early is called beyond "
            f"{Z_OCS:.0f} sd"
        )


def boat_sd_s(
    spread_m: float, v: float, se_tau: float, se_shift: float, cov: NDArray | None = None
) -> float:
    """Standard deviation of one boat's start time about the fleet's front row [s]: the
    front row's spread over its speed towards the course side, :data:`SIGMA_T_S`, and the
    estimate's own error at that speed (``cov``: the covariance of ``(τ, δ)``)."""
    vv = v if math.isfinite(v) and v >= V_MIN_MS else V_MIN_MS
    if cov is not None:
        j = np.array([-1.0, 1.0 / vv])
        est = float(j @ cov @ j)
    else:
        est = se_tau**2 + (se_shift / vv) ** 2
    return math.sqrt((spread_m / vv) ** 2 + SIGMA_T_S**2 + max(est, 0.0))


# --- the fit ------------------------------------------------------------------------------

_MODELS = {"line": (False, True), "clock": (True, False), "both": (True, True)}
"""Model -> (τ free, δ free)."""


_N_TAIL = 5
"""Parameters besides the offsets: log σ_m, log λ, log κ, logit of the over-early and late
shares."""

_PRIOR = (math.log(3.0), math.log(3.0), math.log(3.0))
"""Prior medians of the front row's spread [m], λ and κ [s] (log-normal, a factor e either
way)."""


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


def _log_mixture(
    e: NDArray, s: NDArray, lam: float, kappa: float, p_ocs: float, p_late: float
) -> NDArray:
    """Log density of each start time ``e`` [s]: a clean start (an exponential delay after
    the front row, mean ``lam``), over early (an exponential lead, mean ``kappa``), late
    (uniform up to :data:`LATE_SPAN_S`, its blurred edge at 0 neglected), all blurred by
    ``s``; and the floor."""
    from scipy.special import log_ndtr

    p_clean = max(1.0 - p_ocs - p_late, 1e-9)
    parts = np.empty((4, e.size))
    parts[0] = math.log(p_clean) + _emg(e, s, lam)
    parts[1] = math.log(max(p_ocs, 1e-12)) + _emg(-e, s, kappa)
    parts[2] = math.log(max(p_late, 1e-12)) - math.log(LATE_SPAN_S) + log_ndtr(e / s)
    parts[2, e > LATE_SPAN_S] = -np.inf
    parts[3] = math.log(FLOOR_DENSITY)
    top = parts.max(axis=0)
    out: NDArray = top + np.log(np.exp(parts - top).sum(axis=0))
    return out


def _neg_log_post(theta: NDArray, d: NDArray, v: NDArray, free: tuple[bool, bool]) -> float:
    from scipy.special import expit

    tau, delta, tail = _unpack(theta, free)
    ls, ll, lk = (min(max(float(q), -5.0), 5.0) for q in tail[:3])
    p_ocs, p_late = 0.5 * float(expit(tail[3])), 0.5 * float(expit(tail[4]))
    e = (delta - d) / v - tau
    s = np.sqrt((math.exp(ls) / v) ** 2 + SIGMA_T_S**2)
    ll_data = float(np.sum(_log_mixture(e, s, math.exp(ll), math.exp(lk), p_ocs, p_late)))
    # weak priors: the scales log-normal about _PRIOR; few over early or late (Beta(1, 9)
    # on each share); offsets within minutes and hundreds of metres
    prior = (
        -0.5 * sum((q - m) ** 2 for q, m in zip((ls, ll, lk), _PRIOR, strict=True))
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


def _fit(d: NDArray, v: NDArray, model: str, start: _Fit | None = None) -> _Fit:
    """The maximum of the posterior for ``model``: each boat in turn taken as the front row
    (its start time 0) at the prior's scales, the best three refined."""
    from scipy.optimize import minimize

    free = _MODELS[model]
    tail = np.array([*_PRIOR, -2.0, -2.0])
    if model == "line":
        heads = [np.array([dk + vk * 0.0]) for dk, vk in zip(d, v, strict=True)]
    elif model == "clock":
        heads = [np.array([-dk / vk]) for dk, vk in zip(d, v, strict=True)]
    else:
        assert start is not None
        tau, delta, _ = _unpack(start.theta, _MODELS[start.model])
        heads = [np.array([tau, delta])]
    cand = [np.concatenate([h, tail]) for h in heads]
    score = [_neg_log_post(c, d, v, free) for c in cand]
    best: _Fit | None = None
    for k in np.argsort(score)[:2]:
        r = minimize(_neg_log_post, cand[int(k)], args=(d, v, free), method="Powell")
        if best is None or float(r.fun) < best.nlp:
            best = _Fit(model, np.asarray(r.x, float), float(r.fun), sum(free) + _N_TAIL)
    assert best is not None
    return best


def estimate_fleet_start(observations: Sequence[StartObservation], gun_t: float) -> FleetStart:
    """The fleet's gun and line from where its boats were at the gun.

    Parameters
    ----------
    observations : sequence of StartObservation
        One per boat that was on the water at the gun (:func:`observe_start`).
    gun_t : float
        The gun in the race's clock [epoch s].

    Returns
    -------
    FleetStart
        ``model="none"`` (the course's gun and line, :data:`~sailroute.analysis.segment.OCS_MIN_S`)
        with fewer than :data:`MIN_FLEET` usable boats.
    """
    use = [o for o in observations if o.usable]
    if len(use) < MIN_FLEET:
        return FleetStart(gun_t, n_boats=len(use))
    d = np.array([o.distance_m for o in use])
    v = np.array([o.speed_ms for o in use])
    n = d.size
    fits = {m: _fit(d, v, m) for m in ("line", "clock")}
    spread = float(np.std(1.0 / v) / np.mean(1.0 / v))
    if n >= 8 and spread > 0.1:
        fits["both"] = _fit(d, v, "both", min(fits.values(), key=lambda f: f.nlp))
    bic = {m: 2 * f.nlp + f.n_params * math.log(n) for m, f in fits.items()}
    order = sorted(bic, key=lambda m: (bic[m], m != "line"))
    best = fits[order[0]]
    singles = sorted(bic[m] for m in ("line", "clock"))
    told = singles[1] - singles[0] >= 4.0 or best.model == "both"
    free = _MODELS[best.model]
    tau, delta, tail = _unpack(best.theta, free)
    ls, ll = float(tail[0]), float(tail[1])
    k = sum(free)
    cov2 = np.zeros((2, 2))
    try:
        h = np.full(best.theta.size, 0.01)
        h[:k] = [0.05 if free[0] and j == 0 else 0.2 for j in range(k)]
        hess = _hessian(lambda th: _neg_log_post(th, d, v, free), best.theta, h)
        cov = np.linalg.inv(hess)
        idx = [j for j, f in enumerate(free) if f]
        for a, ia in enumerate(idx):
            for b, ib in enumerate(idx):
                cov2[ia, ib] = cov[a, b]
        if np.any(np.diag(cov2)[list(idx)] <= 0) or not np.all(np.isfinite(cov2)):
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:
        sm = math.exp(ls)
        cov2 = np.diag(
            [(sm / np.median(v)) ** 2 / n if free[0] else 0.0, sm**2 / n if free[1] else 0.0]
        )
    est = FleetStart(
        gun_t,
        tau,
        delta,
        best.model,
        told,
        math.exp(ls),
        math.exp(ll),
        math.sqrt(max(cov2[0, 0], 0.0)),
        math.sqrt(max(cov2[1, 1], 0.0)),
        n,
        speed_ms=float(np.median(v)),
    )
    clocks = {
        o.boat: est._clock(o.speed_ms if math.isfinite(o.speed_ms) else math.nan, cov2)
        for o in observations
    }
    return replace(est, clocks=MappingProxyType(clocks))


# --- general recall ------------------------------------------------------------------------


@dataclass(frozen=True)
class GeneralRecall:
    """Most of the fleet started at the gun, came back and started again.

    Attributes
    ----------
    boats : tuple of str
        The boats that came back and started again.
    n_started : int
        Boats that started at the gun.
    restart_t : float
        When the fleet crossed again [epoch s]: the first of its second crossings within
        the spread of the rest (the 10th percentile), an estimate of the restart's gun.
    """

    boats: tuple[str, ...]
    n_started: int
    restart_t: float


def detect_general_recall(
    course: Course,
    tracks: Mapping[str, tuple[NDArray, NDArray, NDArray]],
    gun_t: float,
    gap_s: Mapping[str, float],
) -> GeneralRecall | None:
    """A general recall the course does not give: most boats (:data:`RECALL_SHARE`, and at
    least :data:`MIN_FLEET`) crossed the start line after the gun, crossed back within
    :data:`RECALL_WINDOW_S` before getting halfway to the first mark, and crossed forward
    again.

    Parameters
    ----------
    course : Course
    tracks : mapping of str to (t, x, y)
        Each boat's track in the course frame.
    gun_t : float
        The gun [epoch s] (in the tracks' clock).
    gap_s : mapping of str to float
        Each track's gap limit (:func:`~sailroute.analysis.segment.gap_limit_s`).
    """
    sg = start_geometry(course)
    wide = _extended(sg, START_EXTENSION_M)
    back_geom = _reversed(wide)
    mx, my = leg_target(course, 0).centre
    half = 0.5 * abs(_side(sg, mx, my))
    started = 0
    again: dict[str, float] = {}
    for boat, (t, x, y) in tracks.items():
        g = gap_s[boat]
        first = [c for c in _crossings(t, x, y, wide, gun_t, g, gun_t + RECALL_WINDOW_S) if c.known]
        if not first:
            continue
        started += 1
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
    if len(again) < max(MIN_FLEET, RECALL_SHARE * started) or started == 0:
        return None
    return GeneralRecall(
        tuple(sorted(again)), started, float(np.percentile(list(again.values()), 10.0))
    )
