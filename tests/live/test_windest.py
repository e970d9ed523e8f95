"""The change-point wind estimator: steps found in seconds, noise and spikes ignored."""

from __future__ import annotations

import csv
from datetime import datetime

import numpy as np
import pytest

from sailroute.live.windest import SETTLED, WindEstimator
from sailroute.units import wrap180
from tests.conftest import ROOT


def _feed(est: WindEstimator, twd: np.ndarray, tws: np.ndarray, t0: float = 1000.0) -> list:
    return [c for k in range(len(twd)) if (c := est.add(t0 + k, float(tws[k]), float(twd[k])))]


def test_a_clean_step_is_found_at_its_second_reading_and_followed_at_once() -> None:
    """60 s of 65° then 85°: the change is found when the second 85° reading comes in, it
    starts at the first one, and the estimate is the new wind at once (the 60-s mean
    would still be at 65.7°)."""
    est = WindEstimator()
    twd = np.r_[np.full(60, 65.0), np.full(20, 85.0)]
    found = []
    for k in range(80):
        c = est.add(1000.0 + k, 2.5, float(twd[k]))
        if c is not None:
            found.append((k, c))
            est_now = est.estimate()
    (k, c), *rest = found
    assert k == 61 and c.t == 1060.0 and c.kind == "direction" and rest == []
    assert c.before[1] == pytest.approx(65.0) and c.after[1] == pytest.approx(85.0)
    assert c.shift_deg == pytest.approx(20.0)
    assert est_now is not None and est_now[1] == pytest.approx(85.0)
    assert est.estimate() == pytest.approx((2.5, 85.0))
    # a speed step is a change too, across north
    est2 = WindEstimator()
    tws = np.r_[np.full(30, 2.5), np.full(10, 4.0)]
    (c2,) = _feed(est2, np.full(40, 358.0), tws)
    assert c2.kind == "speed" and c2.t == 1030.0 and c2.after[0] == pytest.approx(4.0)


def test_one_spike_is_not_a_change() -> None:
    """One reading 60° off (a gust on the sensor, a wave) changes nothing: the median of
    the test needs half of its readings beyond the threshold."""
    est = WindEstimator()
    twd = np.full(120, 65.0)
    twd[50] = 125.0
    assert _feed(est, twd[:80], np.full(80, 2.5)) == []
    assert 65.0 < est.estimate()[1] < 65.0 + 60.0 / 60  # one of the 61 readings in the mean
    assert _feed(est, twd[80:], np.full(40, 2.5), t0=1080.0) == []
    assert est.estimate()[1] == pytest.approx(65.0)  # the spike has left the 60-s window


def test_noise_needs_a_shift_that_stands_out_of_it() -> None:
    """White noise of 3° and 0.1 m/s for a quarter of an hour: no change found; a 20° step in it is
    found within 5 readings and the estimate is within 2° of the new wind 20 s after
    (the mean of about 18 readings: a standard error of 0.7°)."""
    rng = np.random.default_rng(7)
    n = 900
    twd = 65.0 + rng.normal(0.0, 3.0, n)
    tws = 2.5 + rng.normal(0.0, 0.1, n)
    assert _feed(WindEstimator(), twd, tws) == []
    for seed in range(5):
        rng = np.random.default_rng(seed)
        est = WindEstimator()
        twd = 65.0 + np.r_[np.zeros(120), np.full(30, 20.0)] + rng.normal(0.0, 3.0, 150)
        tws = 2.5 + rng.normal(0.0, 0.1, 150)
        found = [k for k in range(140) if est.add(1000.0 + k, tws[k], twd[k])]
        assert len(found) == 1 and 120 < found[0] < 125
        assert est.last_change is not None and 1120.0 <= est.last_change.t <= found[0] + 1000.0
        assert abs(float(wrap180(est.estimate()[1] - 85.0))) < 2.0


@pytest.mark.slow
def test_the_real_coach_boat_log() -> None:
    """The 73-minute 1 Hz Trieste log (a RIB's sensor: glitches of tens of degrees and
    knots for a few seconds): the rate the module docstring gives, about 50 changes an
    hour, and the noise it measured floors the test after the first minute."""
    with open(ROOT / "data" / "trieste-coach-2018-02-15.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    t = np.array([datetime.fromisoformat(r["time"]).timestamp() for r in rows])
    tws = np.array([float(r["speed"]) for r in rows]) * 1852 / 3600
    twd = np.array([float(r["direction"]) for r in rows])
    est = WindEstimator()
    changes = [c for k in range(len(t)) if (c := est.add(t[k], tws[k], twd[k]))]
    per_hour = len(changes) / ((t[-1] - t[0]) / 3600.0)
    assert 35 <= per_hour <= 65
    assert est._noise[0] > 1.0  # measured on references of SETTLED readings or more
    assert SETTLED >= 10
