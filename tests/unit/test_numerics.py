"""sailroute.numerics against closed forms, and its PCHIP against SciPy's (same algorithm).

Golden section: the maximiser of a parabola to the stated bracket; Hermite: a cubic
reproduced exactly; RK4: the O(h⁴) error ratio 16 under halving on y' = y; the angle
helper: the documented (-180, 180] range.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from sailroute.numerics import (
    INV_PHI,
    distinct_objects,
    golden_max,
    golden_steps,
    hermite,
    hermite_basis,
    hermite_coefficients,
    hermite_crossing,
    hermite_slope,
    pchip,
    rk4_step,
)
from sailroute.units import wrap180


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


# --------------------------------------------------------------------------- golden section


def test_golden_max_finds_the_vertex_of_parabolas_within_the_final_bracket() -> None:
    rng = np.random.default_rng(3)
    lo = rng.uniform(-5.0, 0.0, 200)
    hi = lo + rng.uniform(0.5, 4.0, 200)
    x0 = lo + rng.uniform(0.0, 1.0, 200) * (hi - lo)  # vertex inside, ends included
    x0[0], x0[1] = lo[0], hi[1]  # vertex at an end of the bracket
    calls = []

    def f(x: np.ndarray) -> np.ndarray:
        calls.append(x.shape)
        return 2.0 - 3.0 * (x - x0) ** 2

    n = 30
    x = golden_max(f, lo, hi, n)
    half_bracket = 0.5 * (hi - lo) * INV_PHI**n  # stated accuracy
    assert np.all(np.abs(x - x0) <= half_bracket * (1 + 1e-9) + 1e-12)
    assert len(calls) == n + 2 and set(calls) == {lo.shape}  # full shape, n + 2 calls


def test_golden_steps_reach_the_tolerance() -> None:
    assert golden_steps(1.0, 1e-3) == 15  # ceil(ln 1000 / ln φ) = ceil(14.35)
    assert INV_PHI**15 <= 1e-3 < INV_PHI**14
    assert golden_steps(1e-3, 1.0) == 1  # already narrow: still one step
    assert abs(INV_PHI * (1.0 + INV_PHI) - 1.0) < 1e-15  # 1/φ solves x² + x = 1


# --------------------------------------------------------------------------- Hermite

CUBIC = np.polynomial.Polynomial([0.3, -1.2, 0.7, 0.45])


def test_hermite_reproduces_a_cubic_exactly() -> None:
    d = CUBIC.deriv()
    x0, h = -0.8, 2.5
    t = np.linspace(-0.25, 1.25, 61)  # inside the step and extrapolated
    y = hermite(CUBIC(x0), CUBIC(x0 + h), d(x0), d(x0 + h), t, h)
    np.testing.assert_allclose(y, CUBIC(x0 + t * h), rtol=0, atol=1e-13)
    per_t = hermite(CUBIC(x0), CUBIC(x0 + h), h * d(x0), h * d(x0 + h), t)  # no h: d/dt
    np.testing.assert_allclose(per_t, y, rtol=0, atol=1e-13)
    # d/dt = h dp/dx; power form with h = 1 (derivatives per unit t)
    dt = hermite_slope(CUBIC(x0), CUBIC(x0 + h), d(x0), d(x0 + h), t, h)
    np.testing.assert_allclose(dt, h * d(x0 + t * h), rtol=0, atol=1e-12)
    c = hermite_coefficients(CUBIC(x0), CUBIC(x0 + h), h * d(x0), h * d(x0 + h))
    np.testing.assert_allclose(c[0] + t * (c[1] + t * (c[2] + t * c[3])), y, atol=1e-13)


def test_hermite_basis_is_a_partition_of_unity_with_the_end_conditions() -> None:
    t = np.linspace(0.0, 1.0, 11)
    h00, h10, h01, h11 = hermite_basis(t)
    np.testing.assert_allclose(h00 + h01, 1.0, atol=1e-15)
    assert (h00[0], h01[0], h10[0], h11[0]) == (1.0, 0.0, 0.0, 0.0)
    assert (h00[-1], h01[-1], h10[-1], h11[-1]) == (0.0, 1.0, 0.0, 0.0)


def test_hermite_crossing_inverts_a_monotone_step() -> None:
    # s(x) = x + x³/3 on [0.2, 1.7], increasing; targets spread over the step
    s = np.polynomial.Polynomial([0.0, 1.0, 0.0, 1.0 / 3.0])
    x0, h = 0.2, 1.5
    t_true = np.linspace(0.0, 1.0, 9)
    n = t_true.size
    one = np.ones(n)
    th = hermite_crossing(
        s(x0) * one,
        s(x0 + h) * one,
        s.deriv()(x0) * one,
        s.deriv()(x0 + h) * one,
        h * one,
        s(x0 + t_true * h),
    )
    np.testing.assert_allclose(th, t_true, rtol=0, atol=1e-13)


# --------------------------------------------------------------------------- RK4


def test_rk4_error_drops_sixteenfold_when_the_step_halves() -> None:
    def f(y: np.ndarray, rate: np.ndarray) -> np.ndarray:
        return rate * y  # y' = rate y, items along the trailing axis

    rate = np.array([1.0, -0.5])

    def solve(n: int) -> np.ndarray:
        y = np.ones((1, 2))
        for _ in range(n):
            y, _ = rk4_step(f, y, 1.0 / n, args=(rate,))
        return y[0]

    err = [np.abs(solve(n) - np.exp(rate)) for n in (8, 16, 32)]
    ratio = np.concatenate([err[0] / err[1], err[1] / err[2]])
    assert np.all((ratio > 15.0) & (ratio < 17.0)), ratio  # global error O(h⁴)
    y1, k1 = rk4_step(f, np.ones((1, 2)), np.array([0.1, 0.2]), args=(rate,))
    np.testing.assert_array_equal(k1, rate[None, :])  # start derivative returned
    # per-item steps: one step of 0.1 and of 0.2 (Taylor to h⁴ of exp)
    z = rate * np.array([0.1, 0.2])
    np.testing.assert_allclose(y1[0], 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24, rtol=1e-15)


# --------------------------------------------------------------------------- angles


def test_wrap180_maps_to_the_documented_half_open_range() -> None:
    got = wrap180([180.0, -180.0, 540.0, -190.0, 190.0, 0.0, -0.0, 359.5])
    np.testing.assert_array_equal(got, [180.0, 180.0, 180.0, 170.0, -170.0, 0.0, 0.0, -0.5])


def test_sorted_distinct_is_numpys_unique_without_nan() -> None:
    from sailroute.numerics import sorted_distinct

    rng = np.random.default_rng(3)
    for x in (
        rng.integers(-5, 5, size=40),
        rng.integers(0, 4, size=(3, 7)).astype(float) / 3.0,
        np.append(np.arange(1524564600.0, 1524564000.0 - 1e-9, -10.0), 1524564000.0),
        np.array([2.5]),
        np.array([], dtype=float),
    ):
        got, want = sorted_distinct(x), np.unique(x)
        assert got.dtype == want.dtype and np.array_equal(got, want)


def test_distinct_objects_are_kept_by_identity_in_order_of_first_use():
    a, b = [1.0], [1.0]  # equal, not the same object
    distinct, codes = distinct_objects([b, a, b, b, a])
    assert distinct[0] is b and distinct[1] is a and len(distinct) == 2
    assert codes.dtype == np.int64 and codes.tolist() == [0, 1, 0, 0, 1]
    empty, none = distinct_objects([])
    assert empty == [] and none.shape == (0,)
