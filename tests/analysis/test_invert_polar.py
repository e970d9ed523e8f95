"""``invert_polar``: the wind in which a boat's polar sails the observed speed."""

from __future__ import annotations

import numpy as np

from sailroute.analysis.infer_tws import invert_polar
from sailroute.boat.build import builtin_polar

BOAT = builtin_polar("ilca7")


def test_the_polar_speed_gives_back_its_wind_and_order_does_not_matter() -> None:
    rng = np.random.default_rng(4)
    twa = rng.integers(45, 181, 3000).astype(float) * rng.choice([-1.0, 1.0], 3000)
    tws = rng.uniform(1.5, 5.0, 3000)  # where the ILCA 7's speed still rises with the wind
    sog = np.asarray(BOAT.steady_speed(tws, np.abs(twa)), float)
    got = invert_polar(BOAT, twa, sog)
    # linear between the 0.1 m/s rows of the inversion table
    np.testing.assert_allclose(got, tws, atol=0.02)
    perm = rng.permutation(twa.size)
    np.testing.assert_array_equal(invert_polar(BOAT, twa[perm], sog[perm]), got[perm])


def test_speeds_outside_the_polar_have_no_wind() -> None:
    twa = np.array([90.0, 90.0, -150.0, 120.0])
    top = float(np.max(BOAT.steady_speed(np.array([25.0]), np.array([90.0]))))
    slow = float(np.asarray(BOAT.steady_speed(np.array([0.5]), np.array([150.0])))[0])
    sog = np.array([top + 1.0, np.nan, 0.5 * slow, 2.0])
    got = invert_polar(BOAT, twa, sog)
    assert np.isnan(got[:3]).all()
    assert 0.5 < got[3] < 25.0
