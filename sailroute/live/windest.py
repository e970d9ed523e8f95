"""The measured wind now, and the shifts in it: a change-point estimator.

A long mean is steady but slow (a 60-s mean turns by a third of a 20° step in 20 s);
a short one is quick but noisy.  :class:`WindEstimator` keeps both virtues: its
estimate is the vector mean of the readings since the last *change point*, over at
most ``window_s``, and every reading tests whether the wind has just changed:

* the **test** is the last ``k`` readings (:data:`SHORT`), the **reference** the
  segment before them (at least :data:`MIN_REFERENCE` readings);
* direction: the median of the test readings' departures from the reference's mean
  direction, less the reference's median departure, against ``max(shift_deg, z σ_d)``;
  ``σ_d`` is the robust spread (1.4826 × the median absolute departure) of the medians
  of ``k`` consecutive reference readings, so the noise's own persistence (a sensor's
  wander over a few seconds) is in it;
* speed: the same with the speeds, against ``max(change_ms, z σ_s)``.

The spreads are floored by :data:`MIN_SPREAD_DEG` and :data:`MIN_SPREAD_MS`, and, once a
reference of :data:`SETTLED` readings has measured the feed's noise, by that noise: the
short references after a change do not make the test touchy.  A median of ``k`` = 4
needs half the readings beyond the threshold, so a spike of one reading never triggers;
a clean step is found at its second reading.  At a change the segment restarts with the
test readings beyond half the change (the new wind's), so the estimate is the new wind
at once, and then the mean of more readings as they come.  Noisy wind raises ``σ`` and
with it the threshold: a shift must stand out of the wind's own spread to count (a 20°
step in white noise of 10° standard deviation does not, and is followed by the mean
within ``window_s``).

On the real 1 Hz log of the Trieste coach boat (``data/trieste-coach-2018-02-15.csv``,
73 minutes, with the glitches of a RIB's wind sensor) the defaults find about 50
changes an hour.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from sailroute.units import wind_components, wind_speed_direction, wrap180

DEFAULT_WINDOW_S: float = 60.0
"""Longest span of the estimate's mean [s]."""
SHORT: int = 4
"""Readings in the change test (its median needs two of them beyond the threshold)."""
MIN_REFERENCE: int = 5
"""Readings the reference needs before a test is made."""
SETTLED: int = 20
"""A reference this long measures the feed's noise, which then floors the noise of the
shorter references after a change."""
Z: float = 5.0
"""Threshold in standard errors of the difference of means."""
MIN_SPREAD_DEG: float = 1.0
"""Floor of the direction spread [°] (a clean feed is not infinitely precise)."""
MIN_SPREAD_MS: float = 0.1
"""Floor of the speed spread [m s⁻¹]."""
TREND_STEP_S: float = 10.0
"""Spacing of the trend's points [s]."""


@dataclass(frozen=True)
class Change:
    """A change point.

    Attributes
    ----------
    t : float
        Time of the first reading of the new wind [epoch s].
    kind : {"direction", "speed", "both"}
        What changed.
    before, after : (float, float)
        ``(tws [m s⁻¹], twd [°])`` of the old segment and of the new readings.
    """

    t: float
    kind: str
    before: tuple[float, float]
    after: tuple[float, float]

    @property
    def shift_deg(self) -> float:
        """The direction change, + clockwise (veer) [°]."""
        return float(wrap180(self.after[1] - self.before[1]))


def _mean(a: np.ndarray) -> tuple[float, float]:
    """Vector mean ``(tws, twd)`` of rows ``(t, u, v, tws, twd)``."""
    s, d = wind_speed_direction(a[:, 1].mean(), a[:, 2].mean())
    return float(s), float(d)


def _spread(dev: np.ndarray, floor: float) -> float:
    return max(1.4826 * float(np.median(np.abs(dev - np.median(dev)))), floor)


def _block_spread(x: np.ndarray, k: int, floor: float) -> float:
    """Robust spread of the medians of ``k`` consecutive values of ``x`` (floored):
    the noise of the test's median, with the noise's own persistence in it."""
    if x.size < k + 2:
        return max(_spread(x, floor), floor)
    w = np.lib.stride_tricks.sliding_window_view(x, k)
    return _spread(np.median(w, axis=1), floor)


class WindEstimator:
    """The measured wind since the last change point, and the change test (module docstring).

    Not thread-safe: the owner holds its lock around every call.

    Parameters
    ----------
    window_s : float
        Longest span of the mean [s].
    shift_deg, change_ms : float
        Smallest direction [°] and speed [m s⁻¹] changes that count.
    short : int
        Readings in the test.
    z : float
        Threshold in standard errors.
    history_s : float
        How far back :meth:`trend` goes [s] (one point per :data:`TREND_STEP_S`).
    """

    def __init__(
        self,
        window_s: float = DEFAULT_WINDOW_S,
        shift_deg: float = 5.0,
        change_ms: float = 0.5144,
        *,
        short: int = SHORT,
        z: float = Z,
        history_s: float = 1800.0,
    ) -> None:
        self.window_s, self.shift_deg, self.change_ms = window_s, shift_deg, change_ms
        self.short, self.z = short, z
        self._seg: deque[tuple[float, float, float, float, float]] = deque()
        self._trend: deque[tuple[float, float, float, float]] = deque(
            maxlen=int(history_s // TREND_STEP_S) + 1
        )
        self.n_changes = 0
        self.last_change: Change | None = None
        self._keep = short
        self._noise = (MIN_SPREAD_DEG, MIN_SPREAD_MS)

    def add(self, t: float, tws_ms: float, twd_deg: float) -> Change | None:
        """Add a reading at data time ``t`` [epoch s]; the change it reveals, if any."""
        u, v = wind_components(tws_ms, twd_deg)
        self._seg.append((t, float(u), float(v), tws_ms, twd_deg % 360.0))
        while len(self._seg) > self.short and self._seg[0][0] < t - self.window_s:
            self._seg.popleft()
        change = self._test()
        if change is not None:
            for _ in range(len(self._seg) - self._keep):
                self._seg.popleft()
            self.n_changes += 1
            self.last_change = change
        bucket = t // TREND_STEP_S * TREND_STEP_S
        if not self._trend or self._trend[-1][0] < bucket or change is not None:
            est = self.estimate()
            if est is not None:
                self._trend.append((t if change else bucket, est[0], est[1], self.spread()[0]))
        return change

    def _test(self) -> Change | None:
        n = len(self._seg) - self.short
        if n < MIN_REFERENCE:
            return None
        a = np.asarray(self._seg)
        ref, new = a[:n], a[n:]
        k = len(new)
        # direction: departures from the reference's mean direction of unit vectors
        dir_ref = float(np.degrees(np.arctan2(*np.mean(_units(ref[:, 4]), axis=0))))
        dev_ref = np.asarray(wrap180(ref[:, 4] - dir_ref))
        dev_new = np.asarray(wrap180(new[:, 4] - dir_ref))
        noise_d = _block_spread(dev_ref, k, MIN_SPREAD_DEG)
        noise_s = _block_spread(ref[:, 3], k, MIN_SPREAD_MS)
        if n >= SETTLED:  # the feed's own noise, kept for the short segments after a change
            self._noise = (noise_d, noise_s)
        noise_d, noise_s = max(noise_d, self._noise[0]), max(noise_s, self._noise[1])
        d_shift = float(np.median(dev_new) - np.median(dev_ref))
        d_lim = max(self.shift_deg, self.z * noise_d)
        s_change = float(np.median(new[:, 3]) - np.median(ref[:, 3]))
        s_lim = max(self.change_ms, self.z * noise_s)
        turned, blew = abs(d_shift) >= d_lim, abs(s_change) >= s_lim
        if not (turned or blew):
            return None
        # the new wind: the last readings on the far side of half the change
        far = np.ones(k, bool)
        if turned:
            far &= np.sign(d_shift) * (dev_new - np.median(dev_ref)) > 0.5 * abs(d_shift)
        if blew:
            far &= np.sign(s_change) * (new[:, 3] - np.median(ref[:, 3])) > 0.5 * abs(s_change)
        first = k - int(np.argmin(far[::-1])) if not far.all() else 0
        first = min(first, k - 1)
        kind = "both" if turned and blew else ("direction" if turned else "speed")
        self._keep = k - first
        return Change(float(new[first, 0]), kind, _mean(ref), _mean(new[first:]))

    def estimate(self) -> tuple[float, float] | None:
        """Vector mean of the segment: ``(tws [m s⁻¹], twd [° from])``, None when empty."""
        if not self._seg:
            return None
        return _mean(np.asarray(self._seg))

    def spread(self) -> tuple[float, float]:
        """Robust spread of the segment's direction [°] and speed [m s⁻¹] (0 with fewer
        than three readings)."""
        if len(self._seg) < 3:
            return 0.0, 0.0
        a = np.asarray(self._seg)
        d = float(np.degrees(np.arctan2(*np.mean(_units(a[:, 4]), axis=0))))
        return _spread(np.asarray(wrap180(a[:, 4] - d)), 0.0), _spread(a[:, 3], 0.0)

    @property
    def since(self) -> float | None:
        """Time of the segment's first reading [epoch s]."""
        return self._seg[0][0] if self._seg else None

    def trend(self) -> list[tuple[float, float, float, float]]:
        """``(t, tws [m s⁻¹], twd [°], spread [°])`` of the estimate every
        :data:`TREND_STEP_S` and at each change, oldest first."""
        return list(self._trend)


def _units(deg: np.ndarray) -> np.ndarray:
    """``(sin, cos)`` rows of directions [°] (``arctan2(*mean)`` is their mean direction)."""
    r = np.radians(deg)
    return np.column_stack([np.sin(r), np.cos(r)])
