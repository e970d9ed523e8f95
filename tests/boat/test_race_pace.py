"""The race pace of a learned polar (``sailroute.analysis.racepace``): per boat and point of
sail the ratio of the route's to the sailed leg times, penalties out; a level's pace is the
level's percentile of the boats."""

from __future__ import annotations

import numpy as np
import pytest

from sailroute.analysis.racepace import MIN_LEG_S, level_pace, pace_factors


def test_pace_factors_are_ratios_of_sums_without_the_penalties() -> None:
    # boat 0: two beats routed in 100 s (10 s of penalties) and sailed in 130 and 110 s;
    # one run routed in 60 s (no penalty) sailed in 75 s.  boat 1: one beat.
    route = np.array([100.0, 100.0, 60.0, 100.0])
    pen = np.array([10.0, 10.0, 0.0, 10.0])
    sailed = np.array([130.0, 110.0, 75.0, 100.0])
    band = np.array([0, 0, 2, 0])
    boat = np.array([0, 0, 0, 1])
    f = pace_factors(route, pen, sailed, band, boat)
    assert f[0, 0] == pytest.approx((90.0 + 90.0) / (120.0 + 100.0))
    assert f[0, 2] == pytest.approx(60.0 / 75.0)
    assert f[1, 0] == pytest.approx(1.0)
    assert np.isnan(f[0, 1]) and np.isnan(f[1, 2])


def test_legs_too_short_to_time_are_left_out() -> None:
    f = pace_factors(
        np.array([30.0, 100.0]),
        np.array([25.0, 0.0]),
        np.array([25.0 + MIN_LEG_S - 1.0, 120.0]),
        np.array([0, 0]),
        np.array([0, 0]),
    )
    assert f[0, 0] == pytest.approx(100.0 / 120.0)


def test_a_level_takes_its_percentile_and_a_missing_band_the_others_mean() -> None:
    f = np.array([[0.80, np.nan, 0.90], [0.84, np.nan, 0.94], [0.88, np.nan, 0.98]])
    up, reach, down = level_pace(f, 50.0)  # type: ignore[misc]
    assert (up, down) == (pytest.approx(0.84), pytest.approx(0.94))
    assert reach == pytest.approx(0.89)
    assert level_pace(f, 90.0)[0] == pytest.approx(np.percentile([0.80, 0.84, 0.88], 90.0))
    assert level_pace(np.full((2, 3), np.nan), 50.0) is None
