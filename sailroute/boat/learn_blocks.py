"""Steady straight-line blocks of sailing: the samples a fleet polar is learned from.

A boat's log at 1 Hz is a poor sample of its polar one point at a time: GPS noise of a
metre turns into a course error of 20° and a speed error of 10 % between two fixes, the
wind sensor jitters by degrees, and a boat that is turning, accelerating out of a tack or
luffing at the start is not sailing its polar at all.  The learner therefore works on
**blocks**: stretches of ``block_s`` seconds of steady straight-line sailing, each reduced
to one mean TWS, one TWA (the mean wind direction against the block's course over ground)
and one speed (the block's displacement over its duration).

Steady means, on the velocity smoothed over ``smooth_s`` (the displacement across the
window), sample by sample; each dropped sample counts under the first rule that drops it:

``non_finite``
    a missing time, position or wind value;
``low_wind``
    TWS below :attr:`SteadyRules.min_tws_ms`;
``slow``
    speed over ground below :attr:`SteadyRules.min_speed_ms` (drifting, luffing head to
    wind: the course means nothing);
``manoeuvre``
    within :attr:`SteadyRules.manoeuvre_window_s` of a sample turning faster than
    :attr:`SteadyRules.max_turn_rate_deg_s` (tacks, gybes, roundings, and the
    acceleration out of them);
``acceleration``
    the smoothed speed changing by more than :attr:`SteadyRules.max_accel_per_s` of itself
    per second.

The kept samples form runs (no time gap over :attr:`SteadyRules.max_gap_s`, one wind
source); a run shorter than :attr:`SteadyRules.min_block_s` is dropped (``short``), a
longer one is cut into blocks of equal duration, each at least ``block_s`` long and
``block_m`` sailed (one block when the run is shorter): a block's course then carries a
GPS error of a metre over tens of metres, a degree or two, for a dinghy and a foiler
alike.

Speeds and angles are over the ground, as ``sailroute analyze`` judges a track and as the
routers sail a polar (no current, no leeway): a log's own boat-speed channel is not used.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Final

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.fit import check_non_negative
from sailroute.errors import InputError
from sailroute.units import bearing_deg, wrap180

RULES: Final = ("non_finite", "low_wind", "slow", "manoeuvre", "acceleration", "short")
"""Names of the rules that drop samples, in the order they are applied."""


@dataclass(frozen=True)
class SteadyRules:
    """What counts as steady straight-line sailing (module docstring).

    Parameters
    ----------
    min_tws_ms : float
        Samples in less wind are dropped [m s⁻¹].
    min_speed_ms : float
        Samples slower over the ground are dropped [m s⁻¹].
    smooth_s : float
        Width of the window over which velocity, turn rate and acceleration are taken [s].
    max_turn_rate_deg_s : float
        A sample whose course turns faster than this is a manoeuvre [° s⁻¹].
    manoeuvre_window_s : float
        Samples this close to a manoeuvre sample are dropped too [s].
    max_accel_per_s : float
        Largest steady change of speed, as a fraction of the speed per second [s⁻¹].
    max_gap_s : float
        A longer time gap ends a run [s].
    block_s : float
        Shortest duration of a block [s].
    block_m : float
        Shortest distance sailed in a block [m].
    min_block_s : float
        Shortest run kept (one block) [s].
    """

    min_tws_ms: float = 1.0
    min_speed_ms: float = 0.5
    smooth_s: float = 6.0
    max_turn_rate_deg_s: float = 8.0
    manoeuvre_window_s: float = 5.0
    max_accel_per_s: float = 0.05
    max_gap_s: float = 5.0
    block_s: float = 10.0
    block_m: float = 60.0
    min_block_s: float = 8.0

    def __post_init__(self) -> None:
        check_non_negative(self, "steady rules")
        if self.block_s <= 0 or self.smooth_s <= 0:
            raise InputError(
                f"steady rules: block_s and smooth_s must be > 0; got {self.block_s}, "
                f"{self.smooth_s}"
            )


@dataclass(frozen=True, eq=False)
class BoatSeries:
    """One boat's samples in one race, in the wind it is judged in (SI units).

    Attributes
    ----------
    boat : str
        Boat (track) name.
    race : str
        Race name (a course, or the log's file when there is none).
    t_s : ndarray, shape (k,)
        Times [epoch s], increasing.
    x_m, y_m : ndarray, shape (k,)
        Positions in a local metric frame [m east, m north].
    tws_ms, twd_deg : ndarray, shape (k,)
        True wind speed [m s⁻¹] and direction (from) [°] at each sample.
    source : ndarray of int, shape (k,)
        Index into ``sources`` of the wind each sample was judged in.
    sources : tuple of str
        Labels of the wind sources ("measured on board (...)", "scenario 'x'").
    """

    boat: str
    race: str
    t_s: NDArray[np.float64]
    x_m: NDArray[np.float64]
    y_m: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    twd_deg: NDArray[np.float64]
    source: NDArray[np.int64]
    sources: tuple[str, ...]

    def __post_init__(self) -> None:
        k = np.shape(self.t_s)
        bad = [
            f.name
            for f in fields(self)
            if f.name in ("x_m", "y_m", "tws_ms", "twd_deg", "source")
            and np.shape(getattr(self, f.name)) != k
        ]
        if len(k) != 1 or bad:
            raise InputError(
                f"boat series {self.boat!r}: {', '.join(bad) or 't_s'} must be 1-D arrays of "
                f"the length of t_s ({k}); give one value per sample"
            )


@dataclass(frozen=True, eq=False)
class Blocks:
    """Steady blocks of a fleet (:func:`steady_blocks`), one element per block.

    Attributes
    ----------
    boat, race, source : ndarray of int
        Index into ``boats``, ``races`` and ``sources``.
    t_s, dur_s : ndarray
        Block mid time [epoch s] and duration [s].
    tws_ms, twd_deg, twa_deg, speed_ms : ndarray
        Mean TWS [m s⁻¹] and TWD [°, in the series' frame], signed TWA of the mean wind
        against the block's course over ground [°] and the block's speed over ground
        [m s⁻¹].
    boats, races, sources : tuple of str
        Names.
    dropped : dict of str to int
        Samples dropped by each rule of :data:`RULES`.
    n_samples : int
        Samples given.
    """

    boat: NDArray[np.int64]
    race: NDArray[np.int64]
    source: NDArray[np.int64]
    t_s: NDArray[np.float64]
    dur_s: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    twd_deg: NDArray[np.float64]
    twa_deg: NDArray[np.float64]
    speed_ms: NDArray[np.float64]
    boats: tuple[str, ...]
    races: tuple[str, ...]
    sources: tuple[str, ...]
    dropped: dict[str, int]
    n_samples: int

    @property
    def size(self) -> int:
        """Number of blocks."""
        return int(self.t_s.size)

    def subset(self, keep: NDArray[np.bool_]) -> Blocks:
        """The blocks where ``keep`` is True (names and counts unchanged)."""
        arrays = {
            f.name: getattr(self, f.name)[keep]
            for f in fields(self)
            if isinstance(getattr(self, f.name), np.ndarray)
        }
        return Blocks(
            **arrays,
            boats=self.boats,
            races=self.races,
            sources=self.sources,
            dropped=dict(self.dropped),
            n_samples=self.n_samples,
        )


def _at(t: NDArray, tq: NDArray, v: NDArray) -> NDArray[np.float64]:
    return np.asarray(np.interp(tq, t, v), dtype=float)


def _steady_reasons(s: BoatSeries, r: SteadyRules) -> NDArray[np.int64]:
    """Per sample: the index in :data:`RULES` of the first rule that drops it, else -1."""
    t, x, y = s.t_s, s.x_m, s.y_m
    reason = np.full(t.size, -1, dtype=np.int64)

    def drop(mask: NDArray[np.bool_], rule: str) -> None:
        reason[(reason < 0) & mask] = RULES.index(rule)

    finite = np.isfinite(t) & np.isfinite(x) & np.isfinite(y)
    finite &= np.isfinite(s.tws_ms) & np.isfinite(s.twd_deg)
    drop(~finite, "non_finite")
    ok = np.flatnonzero(finite)
    if ok.size < 3:
        drop(np.ones(t.size, dtype=bool), "non_finite")
        return reason
    drop(s.tws_ms < r.min_tws_ms, "low_wind")
    tk, xk, yk = t[ok], x[ok], y[ok]
    h = 0.5 * r.smooth_s
    # velocity: the displacement across the window (clipped at the ends)
    lo, hi = np.maximum(tk - h, tk[0]), np.minimum(tk + h, tk[-1])
    span = np.maximum(hi - lo, 1e-9)
    vx = (_at(tk, hi, xk) - _at(tk, lo, xk)) / span
    vy = (_at(tk, hi, yk) - _at(tk, lo, yk)) / span
    sog = np.hypot(vx, vy)
    slow = np.zeros(t.size, dtype=bool)
    slow[ok] = sog < r.min_speed_ms
    drop(slow, "slow")
    cog = np.degrees(np.unwrap(np.radians(bearing_deg(vx, vy))))
    turn = np.abs(_at(tk, hi, cog) - _at(tk, lo, cog)) / span
    turning = tk[(turn > r.max_turn_rate_deg_s) & (sog >= r.min_speed_ms)]
    near = np.zeros(tk.size, dtype=bool)
    if turning.size:
        a = np.searchsorted(turning, tk - r.manoeuvre_window_s, side="left")
        b = np.searchsorted(turning, tk + r.manoeuvre_window_s, side="right")
        near = b > a
    man = np.zeros(t.size, dtype=bool)
    man[ok] = near
    drop(man, "manoeuvre")
    dv = np.abs(_at(tk, hi, sog) - _at(tk, lo, sog)) / span
    acc = np.zeros(t.size, dtype=bool)
    acc[ok] = dv > r.max_accel_per_s * np.maximum(sog, r.min_speed_ms)
    drop(acc, "acceleration")
    return reason


def _runs(keep: NDArray[np.bool_], t: NDArray, src: NDArray, max_gap: float) -> list[NDArray]:
    """Index arrays of the maximal runs of kept samples (no gap, one source)."""
    idx = np.flatnonzero(keep)
    if idx.size == 0:
        return []
    brk = (np.diff(idx) > 1) | (np.diff(t[idx]) > max_gap) | (np.diff(src[idx]) != 0)
    return np.split(idx, np.flatnonzero(brk) + 1)


def steady_blocks(series: Sequence[BoatSeries], rules: SteadyRules | None = None) -> Blocks:
    """Cut a fleet's samples into steady straight-line blocks (module docstring).

    Parameters
    ----------
    series : sequence of BoatSeries
        Every boat's samples, one entry per boat and race.
    rules : SteadyRules, optional
        Default :class:`SteadyRules()`.

    Returns
    -------
    Blocks

    Raises
    ------
    InputError
        No series.
    """
    r = SteadyRules() if rules is None else rules
    if not series:
        raise InputError("steady blocks: no boat series given; give at least one track")
    boats = tuple(dict.fromkeys(s.boat for s in series))
    races = tuple(dict.fromkeys(s.race for s in series))
    sources = tuple(dict.fromkeys(lab for s in series for lab in s.sources))
    out: dict[str, list[float]] = {
        k: [] for k in ("boat", "race", "source", "t", "dur", "tws", "twd", "twa", "speed")
    }
    dropped = dict.fromkeys(RULES, 0)
    n_samples = 0
    for s in series:
        n_samples += s.t_s.size
        reason = _steady_reasons(s, r)
        for k, rule in enumerate(RULES):
            dropped[rule] += int(np.sum(reason == k))
        src_map = np.array([sources.index(lab) for lab in s.sources], dtype=np.int64)
        src = src_map[s.source] if s.source.size else s.source
        for run in _runs(reason < 0, s.t_s, src, r.max_gap_s):
            t = s.t_s[run]
            d = float(t[-1] - t[0])
            if d < r.min_block_s or run.size < 2:
                dropped["short"] += run.size
                continue
            dist = float(np.hypot(s.x_m[run[-1]] - s.x_m[run[0]], s.y_m[run[-1]] - s.y_m[run[0]]))
            n = max(1, int(min(d / r.block_s, dist / max(r.block_m, 1e-9))))
            cut = np.searchsorted(t, t[0] + d * np.arange(1, n) / n)
            for part in np.split(run, cut):
                if part.size < 2:
                    continue
                _block(out, s, part, boats.index(s.boat), races.index(s.race), int(src[part[0]]))
    arr = {k: np.asarray(v, dtype=float) for k, v in out.items()}
    return Blocks(
        boat=arr["boat"].astype(np.int64),
        race=arr["race"].astype(np.int64),
        source=arr["source"].astype(np.int64),
        t_s=arr["t"],
        dur_s=arr["dur"],
        tws_ms=arr["tws"],
        twd_deg=arr["twd"],
        twa_deg=arr["twa"],
        speed_ms=arr["speed"],
        boats=boats,
        races=races,
        sources=sources,
        dropped=dropped,
        n_samples=n_samples,
    )


def _block(
    out: dict[str, list[float]], s: BoatSeries, part: NDArray, boat: int, race: int, src: int
) -> None:
    """Append one block's means to ``out``."""
    t = s.t_s[part]
    dt = float(t[-1] - t[0])
    dx = float(s.x_m[part[-1]] - s.x_m[part[0]])
    dy = float(s.y_m[part[-1]] - s.y_m[part[0]])
    th = np.radians(s.twd_deg[part])
    twd = float(np.degrees(np.arctan2(np.sin(th).mean(), np.cos(th).mean())))
    out["boat"].append(boat)
    out["race"].append(race)
    out["source"].append(src)
    out["t"].append(0.5 * float(t[0] + t[-1]))
    out["dur"].append(dt)
    out["tws"].append(float(np.mean(s.tws_ms[part])))
    out["twd"].append(twd % 360.0)
    out["twa"].append(float(wrap180(twd - float(bearing_deg(dx, dy)))))
    out["speed"].append(float(np.hypot(dx, dy) / dt))


__all__ = ["RULES", "Blocks", "BoatSeries", "SteadyRules", "steady_blocks"]
