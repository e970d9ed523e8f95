"""Small numerical helpers shared by the layers: one implementation per algorithm.

NumPy only, no SciPy import: this module is on the path of every ``sailroute plan``
and SciPy's import costs about 0.3-0.4 s.  The array helpers are pure and work on
any NumPy-compatible array module (``xp``: NumPy or CuPy) where their callers need it.

* :func:`clip`: ``np.clip`` at half the call overhead on small arrays (the isochrone
  step, the polar look-up).
* :func:`sorted_distinct`: ``np.unique`` without ``numpy.ma`` (the start line's sample
  times, the polar tables' wind-speed nodes).
* :func:`distinct_objects`: the distinct objects of a sequence by identity and each
  item's index among them (the members of an ensemble grouped by polar, wind or boat).
* :func:`golden_max`, :func:`golden_steps`: vectorised golden-section search (one
  maximiser per item, fixed number of steps) for the VMG optima of a polar, the
  VPP's sail controls and the deadline solver's steering refinement.
* :func:`hermite_basis`, :func:`hermite`, :func:`hermite_slope`,
  :func:`hermite_coefficients`, :func:`hermite_crossing`: the cubic Hermite
  interpolant of one step (values and derivatives at both ends), used by the
  dynamic boat's tables and RK4 step ends and by the multi-spline router's edges.
* :func:`rk4_step`: one classical fourth-order Runge-Kutta step of an autonomous
  system, vectorised over items with per-item steps.
* :func:`pchip`, :func:`pchip_slopes`: the monotone piecewise-cubic Hermite
  interpolant of Fritsch and Carlson with the end-point rule of Moler (*Numerical
  Computing with MATLAB*, §3.6), the same algorithm as
  :class:`scipy.interpolate.PchipInterpolator` (its values agree to rounding,
  ``tests/unit/test_numerics.py``), for the polar's dense table and the polar fit.

Angles are not here: :func:`sailroute.units.wrap180` / :func:`~sailroute.units.wrap360`
(and :func:`sailroute.geo.wrap_lon`, :func:`sailroute.boat.polar.fold_twa`) are the
one home of the angle conventions.  Why these are ours and not SciPy's solvers:
``docs/design.md`` (section "Numerical helpers").
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any, Final, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

T = TypeVar("T")

INV_PHI: Final = (math.sqrt(5.0) - 1.0) / 2.0
"""``1/φ = (√5 − 1)/2 ≈ 0.618``: the bracket shrinks by this factor per golden-section step."""


# --------------------------------------------------------------------------------------
# elementwise


def clip(x: Any, lo: Any, hi: Any, xp: ModuleType = np) -> Any:
    """``xp.clip(x, lo, hi)`` computed as ``xp.minimum(xp.maximum(x, lo), hi)``.

    The same values (NaN stays NaN; a ``-0.0`` at a bound of 0 may keep its sign) at
    about half the call overhead of ``np.clip`` on the small arrays of a routing step
    (1.3 µs against 2.2 µs for floats, 4.0 µs for integers, measured): the isochrone
    router calls it about 20 times per step.
    """
    return xp.minimum(xp.maximum(x, lo), hi)


def sorted_distinct(x: ArrayLike) -> NDArray:
    """The distinct values of ``x``, sorted: ``np.unique(x)`` of an array without NaN.

    ``np.unique`` imports ``numpy.ma`` (about 8 ms), which nothing else of a plan needs.
    """
    a = np.sort(np.asarray(x).ravel())
    return a[np.concatenate([[True], a[1:] != a[:-1]])] if a.size else a


def distinct_objects(items: Sequence[T]) -> tuple[list[T], NDArray[np.int64]]:
    """The distinct objects of ``items`` by identity, in order of first use, and the
    index of each item among them (an int64 array, one per item)."""
    index: dict[int, int] = {}
    distinct: list[T] = []
    codes = np.empty(len(items), dtype=np.int64)
    for k, item in enumerate(items):
        j = index.setdefault(id(item), len(distinct))
        if j == len(distinct):
            distinct.append(item)
        codes[k] = j
    return distinct, codes


# --------------------------------------------------------------------------------------
# golden-section search


def golden_steps(width: float, tol: float) -> int:
    """Golden-section steps that shrink a bracket of ``width`` to ``tol`` or less (>= 1).

    Parameters
    ----------
    width, tol : float
        Initial bracket width and the wanted final width (same unit, ``tol > 0``).

    Returns
    -------
    int
        ``max(1, ceil(log(width / tol) / log φ))``.
    """
    return max(1, math.ceil(math.log(width / tol) / math.log((1.0 + math.sqrt(5.0)) / 2.0)))


def golden_max(f: Callable[[Any], Any], lo: Any, hi: Any, n: int, xp: ModuleType = np) -> Any:
    """Vectorised golden-section search for the maximiser of ``f`` on ``[lo, hi]``.

    Parameters
    ----------
    f : callable
        ``f(x) -> values``, elementwise over items: ``x`` has the shape of ``lo``
        and item ``i`` of the result depends on item ``i`` of ``x`` only.  It is
        called ``n + 2`` times, always with the full shape.
    lo, hi : array
        Bracket per item (any unit, ``lo <= hi``).
    n : int
        Steps; the bracket shrinks to ``(hi − lo) · INV_PHI**n``.
    xp : module
        Array module of ``lo``, ``hi`` and ``f``'s values (NumPy or CuPy).

    Returns
    -------
    array
        Midpoint of the final bracket, shape of ``lo``: within half its width of the
        maximiser where ``f`` is unimodal on ``[lo, hi]`` (ties keep the left part).
    """
    c = hi - INV_PHI * (hi - lo)
    d = lo + INV_PHI * (hi - lo)
    fc, fd = f(c), f(d)
    for _ in range(n):
        left = fc >= fd  # the maximum lies in [lo, d], else in [c, hi]
        hi = xp.where(left, d, hi)
        lo = xp.where(left, lo, c)
        new = xp.where(left, hi - INV_PHI * (hi - lo), lo + INV_PHI * (hi - lo))
        fnew = f(new)
        c, d = xp.where(left, new, d), xp.where(left, c, new)
        fc, fd = xp.where(left, fnew, fd), xp.where(left, fc, fnew)
    return 0.5 * (lo + hi)


# --------------------------------------------------------------------------------------
# cubic Hermite steps


def hermite_basis(t: Any) -> tuple[Any, Any, Any, Any]:
    """Cubic Hermite basis ``(h00, h10, h01, h11)`` at fractions ``t`` of the step [-].

    ``h00 = 2t³ − 3t² + 1``, ``h10 = t³ − 2t² + t``, ``h01 = 3t² − 2t³``,
    ``h11 = t³ − t²``: the cubic with values ``y0, y1`` and derivatives ``d0, d1``
    (per unit ``t``) at ``t = 0, 1`` is ``h00 y0 + h10 d0 + h01 y1 + h11 d1``.
    """
    t2 = t * t
    t3 = t2 * t
    return 2 * t3 - 3 * t2 + 1, t3 - 2 * t2 + t, 3 * t2 - 2 * t3, t3 - t2


def hermite(y0: Any, y1: Any, d0: Any, d1: Any, t: Any, h: Any = None) -> Any:
    """Cubic Hermite interpolant of one step at fractions ``t`` (broadcast).

    Parameters
    ----------
    y0, y1 : array
        Values at the step's start and end.
    d0, d1 : array
        Derivatives there, per unit of the step variable (``dy/dx``).
    t : array
        Fraction of the step, ``(x − x0) / h`` [-]; exact for cubics, extrapolates
        outside ``[0, 1]``.
    h : array or float, optional
        Step width in ``x`` (``x1 − x0``); without it ``d0, d1`` are per unit ``t``
        (``h = 1``, and two array products fewer: this is the hot path of the
        dynamic boat's loss table).

    Returns
    -------
    array
        ``h00 y0 + h10 h d0 + h01 y1 + h11 h d1`` (:func:`hermite_basis`).
    """
    h00, h10, h01, h11 = hermite_basis(t)
    if h is None:
        return h00 * y0 + h10 * d0 + h01 * y1 + h11 * d1
    return h00 * y0 + h10 * h * d0 + h01 * y1 + h11 * h * d1


def hermite_slope(y0: Any, y1: Any, d0: Any, d1: Any, t: Any, h: Any = 1.0) -> Any:
    """``d/dt`` of :func:`hermite` (same parameters): the derivative per unit ``t``."""
    t2 = t * t
    return (
        (6 * t2 - 6 * t) * y0
        + (3 * t2 - 4 * t + 1) * h * d0
        + (-6 * t2 + 6 * t) * y1
        + (3 * t2 - 2 * t) * h * d1
    )


def hermite_coefficients(y0: Any, y1: Any, d0: Any, d1: Any) -> tuple[Any, Any, Any, Any]:
    """Power-form coefficients ``(c0, c1, c2, c3)`` of :func:`hermite` with ``h = 1``.

    ``hermite(y0, y1, d0, d1, t) = c0 + t (c1 + t (c2 + t c3))`` (to rounding), for
    kernels that evaluate the cubic by Horner's rule.
    """
    return y0, d0, 3 * (y1 - y0) - 2 * d0 - d1, 2 * (y0 - y1) + d0 + d1


def hermite_crossing(
    y0: NDArray,
    y1: NDArray,
    d0: NDArray,
    d1: NDArray,
    h: NDArray,
    target: NDArray,
    iterations: int = 6,
) -> NDArray:
    """Fraction ``t ∈ [0, 1]`` of a step where the Hermite cubic reaches ``target``.

    Newton iterations on ``hermite(y0, y1, d0, d1, t, h) = target`` from the linear
    guess, clipped to ``[0, 1]``; meant for a monotone step (``y0 <= target <= y1``,
    e.g. the distance sailed in the last step of an integration).

    Parameters
    ----------
    y0, y1, d0, d1, h : ndarray
        The step, as in :func:`hermite`.
    target : ndarray
        Value to reach (unit of ``y``).
    iterations : int
        Newton iterations (quadratic convergence: 6 reach rounding from the linear
        guess on a monotone step).

    Returns
    -------
    ndarray
        ``t`` [-], shape of the broadcast inputs.
    """
    span = np.where(y1 > y0, y1 - y0, 1.0)
    th = np.clip((target - y0) / span, 0.0, 1.0)
    for _ in range(iterations):
        val = hermite(y0, y1, d0, d1, th, h) - target
        der = hermite_slope(y0, y1, d0, d1, th, h)
        der = np.where(np.abs(der) > 1e-300, der, 1e-300)
        th = np.clip(th - val / der, 0.0, 1.0)
    return th


# --------------------------------------------------------------------------------------
# Runge-Kutta


def rk4_step(
    f: Callable[..., Any], y: Any, h: Any, k1: Any = None, args: tuple[Any, ...] = ()
) -> tuple[Any, Any]:
    """One classical fourth-order Runge-Kutta step of the autonomous system ``y' = f(y)``.

    Parameters
    ----------
    f : callable
        ``f(y, *args) -> dy/dx``, same shape as ``y``.
    y : array, shape (n_state, ...)
        State at the step's start (items along the trailing axes).
    h : array or float
        Step per item (broadcast against ``y``, e.g. shape ``(...)``), unit of ``x``.
    k1 : array, optional
        ``f(y, *args)`` if the caller already has it (e.g. to choose ``h``).
    args : tuple
        Extra arguments of ``f`` (per-item parameters, shaped like the items).

    Returns
    -------
    y_new, k1 : array
        State after the step (local error O(h⁵), global O(h⁴)) and ``f(y, *args)``, the
        start derivative (for a Hermite end of step).
    """
    if k1 is None:
        k1 = f(y, *args)
    k2 = f(y + 0.5 * h * k1, *args)
    k3 = f(y + 0.5 * h * k2, *args)
    k4 = f(y + h * k3, *args)
    return y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4), k1


# --------------------------------------------------------------------------------------
# PCHIP


def _edge(h0: NDArray, h1: NDArray, m0: NDArray, m1: NDArray) -> NDArray:
    """One-sided three-point end slope, kept shape-preserving (Moler's pchiptx)."""
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    wrong_sign = np.sign(d) != np.sign(m0)
    overshoot = (np.sign(m0) != np.sign(m1)) & (np.abs(d) > 3.0 * np.abs(m0))
    d = np.where(overshoot & ~wrong_sign, 3.0 * m0, d)
    return np.where(wrong_sign, 0.0, d)


def pchip_slopes(x: NDArray, y: NDArray) -> NDArray[np.float64]:
    """PCHIP node derivatives of ``y`` (nodes along axis 0) at strictly increasing ``x``."""
    h = np.diff(x).reshape((-1,) + (1,) * (y.ndim - 1))
    m = np.diff(y, axis=0) / h
    if y.shape[0] == 2:
        return np.concatenate([m, m], axis=0)
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    flat = (np.sign(m[1:]) != np.sign(m[:-1])) | (m[1:] == 0) | (m[:-1] == 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        inner = np.where(flat, 0.0, (w1 + w2) / (w1 / m[:-1] + w2 / m[1:]))
    first = _edge(h[0], h[1], m[0], m[1])
    last = _edge(h[-1], h[-2], m[-1], m[-2])
    return np.concatenate([first[None], inner, last[None]], axis=0)


def pchip(x: ArrayLike, y: ArrayLike, xq: ArrayLike, axis: int = 0) -> NDArray[np.float64]:
    """Monotone cubic (PCHIP) interpolation of ``y`` at ``xq``.

    Parameters
    ----------
    x : array_like, shape (n,)
        Strictly increasing nodes (n >= 2).
    y : array_like
        Values, with the nodes along ``axis``.
    xq : array_like, shape (k,)
        Query points; outside ``[x[0], x[-1]]`` the end cubics extrapolate, as SciPy's.
    axis : int
        Axis of ``y`` that runs along ``x``.

    Returns
    -------
    ndarray
        ``y`` with ``axis`` replaced by the ``k`` query points.
    """
    x = np.asarray(x, dtype=float)
    yy = np.moveaxis(np.asarray(y, dtype=float), axis, 0)
    xq = np.asarray(xq, dtype=float)
    d = pchip_slopes(x, yy)
    k = np.clip(np.searchsorted(x, xq, side="right") - 1, 0, x.size - 2)
    h = (x[k + 1] - x[k]).reshape((-1,) + (1,) * (yy.ndim - 1))
    t = (xq - x[k]).reshape(h.shape)
    y0, y1, d0, d1 = yy[k], yy[k + 1], d[k], d[k + 1]
    m = (y1 - y0) / h
    c2 = (3.0 * m - 2.0 * d0 - d1) / h
    c3 = (d0 + d1 - 2.0 * m) / (h * h)
    out = y0 + t * (d0 + t * (c2 + t * c3))
    return np.moveaxis(out, 0, axis)
