"""Per-boat biases of measured wind against the fleet (:func:`estimate_biases`): a speed
factor, a direction offset and a clock offset per boat, from the pairs of boats that sailed
near each other (:class:`BoatBias`, :func:`apply_bias`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from sailroute.units import wind_components, wind_speed_direction, wrap180

if TYPE_CHECKING:
    pass

from sailroute.wind.measuredseries import MeasuredSeries


@dataclass(frozen=True)
class BoatBias:
    """One boat's constant bias against the fleet's consensus.

    The boat's log reads ``speed_factor`` times the consensus speed,
    ``direction_offset_deg`` clockwise of the consensus direction, and stamps a
    wind ``time_offset_s`` later than the consensus does (a clock ahead, or a
    sensor that lags).  Correcting divides the speed by the factor, subtracts the
    direction offset and subtracts the time offset from the stamps.

    Attributes
    ----------
    boat : str
        Boat name.
    speed_factor : float
        Measured / consensus speed [-].
    direction_offset_deg : float
        Measured minus consensus direction [°].
    time_offset_s : float
        Measured minus consensus time of the same wind [s].
    n_samples : int
        Compared records (1 s steps, summed over the boats it was compared with) behind the
        estimate; 0 when the boat overlaps no other boat (no correction).
    clock_samples : int
        The part of ``n_samples`` from comparisons whose time offset was identified (a
        correlation peak inside ``±max_lag_s``, not at its edge); 0: the clock offset is
        not identified and is left at 0.
    """

    boat: str
    speed_factor: float = 1.0
    direction_offset_deg: float = 0.0
    time_offset_s: float = 0.0
    n_samples: int = 0
    clock_samples: int = 0

    def describe(self) -> str:
        """One line: ``NZL: speed x1.031, direction +2.4°, time +12.0 s (1612 samples)``."""
        clock = f"time {self.time_offset_s:+.1f} s" if self.clock_samples else "time not identified"
        return (
            f"{self.boat}: speed x{self.speed_factor:.3f}, direction "
            f"{self.direction_offset_deg:+.1f}°, {clock} ({self.n_samples} samples)"
        )


def _sample_series(s: MeasuredSeries, t: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """``(u, v, ok)`` of a series at times ``t`` (linear; ok False outside it and in holes)."""
    ok = (t >= s.t[0]) & (t <= s.t[-1])
    for a, b in s.gaps:
        ok &= ~((t > a) & (t < b))
    return np.interp(t, s.t, s.u), np.interp(t, s.t, s.v), ok


def _pair_offsets(
    a: MeasuredSeries, b: MeasuredSeries, max_lag_s: float, min_overlap: int
) -> tuple[float, float, float, int, bool] | None:
    """``(log speed ratio, direction offset [°], time offset [s], n, time identified)`` of
    ``a`` against ``b``; a best lag at the edge of the search is not identified (lag 0)."""
    t0, t1 = max(a.t[0], b.t[0]), min(a.t[-1], b.t[-1])
    if t1 - t0 < min_overlap:
        return None
    tg = np.arange(t0, t1 + 0.5)
    ub, vb, okb = _sample_series(b, tg)
    sb, db = wind_speed_direction(ub, vb)
    lags = np.arange(-max_lag_s, max_lag_s + 0.5)
    score = np.full(lags.size, -np.inf)
    for k, lag in enumerate(lags):
        ua, va, oka = _sample_series(a, tg + lag)
        m = oka & okb
        if m.sum() < min_overlap:
            continue
        sa, da = wind_speed_direction(ua[m], va[m])
        # direction anomalies about each series' own circular mean, speed anomalies
        xa = wrap180(da - _circmean(da))
        xb = wrap180(db[m] - _circmean(db[m]))
        score[k] = _corr(xa, xb, 0.05) + _corr(sa, sb[m], 0.005)
    if not np.isfinite(score).any():
        return None
    score = score - 1e-9 * np.abs(lags)  # a flat score (steady wind) gives lag 0
    k = int(np.argmax(score))
    identified = bool(
        0 < k < lags.size - 1 and np.isfinite(score[k - 1]) and np.isfinite(score[k + 1])
    )
    lag = float(lags[k]) if identified else 0.0
    if identified:
        den = score[k - 1] - 2 * score[k] + score[k + 1]
        if den < 0:
            lag += float(np.clip(0.5 * (score[k - 1] - score[k + 1]) / den, -0.5, 0.5))
    ua, va, oka = _sample_series(a, tg + lag)
    m = oka & okb
    sa, da = wind_speed_direction(ua[m], va[m])
    ddir = _circmean(wrap180(da - db[m]))
    return (
        float(np.log(np.mean(sa) / np.mean(sb[m]))),
        float(wrap180(ddir)),
        lag,
        int(m.sum()),
        identified,
    )


def _circmean(a: NDArray) -> float:
    r = np.radians(a)
    return float(np.degrees(np.arctan2(np.mean(np.sin(r)), np.mean(np.cos(r)))))


def _corr(a: NDArray, b: NDArray, floor: float) -> float:
    """Pearson correlation; 0 when either series varies less than ``floor`` (std)."""
    a = a - a.mean()
    b = b - b.mean()
    if a.std() < floor or b.std() < floor:
        return 0.0
    den = float(np.sqrt(np.sum(a * a) * np.sum(b * b)))
    return float(np.sum(a * b) / den) if den > 0 else 0.0


def estimate_biases(
    series: Sequence[MeasuredSeries],
    *,
    max_lag_s: float = 60.0,
    min_overlap_s: float = 60.0,
) -> tuple[BoatBias, ...]:
    """Per-boat speed factor, direction offset and time offset against the fleet.

    Every pair of boats that overlaps in time for at least ``min_overlap_s`` is
    compared on a 1 s grid: the time offset maximises the correlation of the
    two direction and speed series (lags up to ``±max_lag_s``, refined to a
    fraction of a second by a parabola; a best lag at the edge of the search is
    not identified and that pair does not enter the clock offsets), then the
    direction offset is the circular mean difference and the speed ratio the
    ratio of mean speeds at that lag.  The per-boat offsets are the weighted
    least-squares solution of the pairwise differences, fixed so that the fleet's
    median boat has no bias: the consensus is the median boat, so one faulty
    sensor out of three does not drag the others.

    Parameters
    ----------
    series : sequence of MeasuredSeries
        The boats (at least two for any estimate).
    max_lag_s : float
        Largest clock offset searched [s].
    min_overlap_s : float
        Shortest common stretch for a pair to count [s].

    Returns
    -------
    tuple of BoatBias
        One per series, in order (identity with ``n_samples = 0`` for a boat that
        overlaps no other).
    """
    n = len(series)
    rows: list[tuple[int, int, float, float, float, int, bool]] = []
    for i in range(n):
        for j in range(i + 1, n):
            r = _pair_offsets(series[i], series[j], max_lag_s, int(min_overlap_s))
            if r is not None:
                rows.append((i, j, *r))
    if not rows:
        return tuple(BoatBias(s.boat) for s in series)
    count = np.zeros(n, int)
    clock = np.zeros(n, int)
    for i, j, *_, m, ident in rows:
        count[i] += m
        count[j] += m
        clock[i] += m * ident
        clock[j] += m * ident
    sol = []
    for q, used in ((0, count), (1, count), (2, clock)):  # log speed ratio, direction, time
        a = np.zeros((len(rows) + 1, n))
        rhs = np.zeros(len(rows) + 1)
        for k, (i, j, *vals, m, ident) in enumerate(rows):
            w = np.sqrt(m) if (q < 2 or ident) else 0.0
            a[k, i], a[k, j], rhs[k] = w, -w, w * vals[q]
        a[-1, used > 0] = 1.0  # gauge (replaced by the median below)
        x = np.linalg.lstsq(a, rhs, rcond=None)[0]
        if (used > 0).any():
            x[used > 0] -= np.median(x[used > 0])
        x[used == 0] = 0.0
        sol.append(x)
    return tuple(
        BoatBias(
            s.boat,
            float(np.exp(sol[0][k])),
            float(sol[1][k]),
            float(sol[2][k]),
            int(count[k]),
            int(clock[k]),
        )
        for k, s in enumerate(series)
    )


def apply_bias(series: MeasuredSeries, bias: BoatBias) -> MeasuredSeries:
    """The series corrected for ``bias`` (stamps, direction and speed)."""
    s, d = wind_speed_direction(series.u, series.v)
    u, v = wind_components(s / bias.speed_factor, d - bias.direction_offset_deg)
    dt = bias.time_offset_s
    return MeasuredSeries(
        series.boat,
        series.file,
        series.t - dt,
        series.lat,
        series.lon,
        u,
        v,
        series.source,
        (*series.notes, f"bias corrected: {bias.describe()}"),
        tuple((a - dt, b - dt) for a, b in series.gaps),
        series.max_gap_s,
    )
