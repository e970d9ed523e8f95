"""sailroute.numerics.pchip equals SciPy's PchipInterpolator (same algorithm, no import)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from sailroute.numerics import pchip


@pytest.mark.parametrize("seed", range(6))
def test_pchip_matches_scipy_on_random_tables(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 12))
    x = np.cumsum(rng.uniform(0.1, 3.0, n))
    y = rng.normal(size=(n, 4))
    y[rng.integers(0, n)] = 0.0  # flat pieces and sign changes
    xq = np.linspace(x[0] - 0.5, x[-1] + 0.5, 301)  # inside and a little outside
    for axis in (0, 1):
        yy = y if axis == 0 else y.T
        ours = pchip(x, yy, xq, axis=axis)
        ref = PchipInterpolator(x, yy, axis=axis)(xq)
        np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=1e-12)


def test_pchip_is_monotone_and_exact_at_nodes() -> None:
    x = np.array([0.0, 1.0, 2.0, 5.0, 6.0])
    y = np.array([0.0, 0.1, 2.0, 2.0, 3.0])  # monotone data, a plateau
    xq = np.linspace(0, 6, 601)
    v = pchip(x, y, xq)
    assert np.all(np.diff(v) >= -1e-15)  # no overshoot
    np.testing.assert_allclose(pchip(x, y, x), y, atol=1e-15)
    two = pchip([0.0, 2.0], [1.0, 3.0], [0.5, 1.0])  # two nodes: the straight line
    np.testing.assert_allclose(two, [1.5, 2.0], atol=1e-15)
