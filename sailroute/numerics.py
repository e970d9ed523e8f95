"""Small numerical helpers shared by the layers (NumPy only, no SciPy import).

:func:`pchip` is the monotone piecewise-cubic Hermite interpolant of Fritsch and
Carlson with the end-point rule of Moler (*Numerical Computing with MATLAB*, §3.6), the
same algorithm as :class:`scipy.interpolate.PchipInterpolator` (its values agree to
rounding, ``tests/unit/test_numerics.py``).  It lives here so that a polar lookup, on the
path of every ``sailroute plan``, does not pay SciPy's import (about 0.3-0.4 s).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


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
