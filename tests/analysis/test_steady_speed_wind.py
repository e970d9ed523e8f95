"""The inferred wind's field with a steady scenario speed: the numbers of
``SpeedDirectionWind``, computed without sampling the steady wind at every point."""

from __future__ import annotations

import numpy as np

from sailroute.analysis.debrief import SteadySpeedWind, speed_direction_wind
from sailroute.analysis.infer_wind import InferredWindField
from sailroute.wind.combine import SpeedDirectionWind
from sailroute.wind.uniform import UniformWind

T0 = 1.7e9


def _direction() -> InferredWindField:
    """A direction veering 40° (through north) and a speed falling to calm over 10 min."""
    t = T0 + np.arange(0.0, 601.0, 30.0)
    twd = np.linspace(340.0, 380.0, t.size)  # unwrapped
    tws = np.linspace(5.0, 0.0, t.size)
    return InferredWindField(t, twd, tws, clamp=True)


def test_steady_speed_samples_as_the_general_combination() -> None:
    steady = UniformWind(4.3, 212.0)
    direction = _direction()
    fast = speed_direction_wind(steady, direction, "inferred wind")
    assert isinstance(fast, SteadySpeedWind)
    plain = SpeedDirectionWind(steady, direction, "inferred wind")
    rng = np.random.default_rng(2)
    t = T0 + rng.uniform(-120.0, 720.0, 5000)  # before and after the span: held
    x, y = rng.uniform(-2e3, 2e3, (2, t.size))
    for got, want in zip(fast.sample(t, x, y), plain.sample(t, x, y), strict=True):
        np.testing.assert_array_equal(got, want)
    assert fast.coverage == plain.coverage and fast.clamp == plain.clamp
    # speed 4.3 m/s everywhere, including where the direction's own speed is calm
    s = np.hypot(*fast.sample(t, x, y))
    np.testing.assert_allclose(s, 4.3, rtol=1e-12)


def test_a_wind_that_changes_keeps_the_general_combination() -> None:
    table = UniformWind([4.0, 6.0], [200.0, 220.0], times=[T0, T0 + 600.0])
    got = speed_direction_wind(table, _direction(), "inferred wind")
    assert type(got) is SpeedDirectionWind
