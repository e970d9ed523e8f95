"""Rings (closed polygons given as vertex lists): why one cannot be an area, which edges cross.

Used by the race-area checks (:mod:`sailroute.routing.obstacles`) and the course
importers (:mod:`sailroute.course.formats`), so both word a bad polygon the same way.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["ring_crossing", "ring_problem"]


def _cross(ax: NDArray, ay: NDArray, bx: NDArray, by: NDArray) -> NDArray:
    return ax * by - ay * bx


def ring_crossing(xy: NDArray) -> tuple[int, int] | None:
    """The first pair of edges of a closed ring that cross or touch, if any.

    Parameters
    ----------
    xy : ndarray, shape (n, 2)
        The vertices [m] (any planar units), the ring not repeating its first point.

    Returns
    -------
    (i, j) or None
        Edge ``i`` runs from vertex ``i`` to ``i + 1`` (``n - 1`` closes the ring back to
        vertex 0); None when no two non-adjacent edges meet.
    """
    p = np.asarray(xy, dtype=float)
    n = p.shape[0]
    if n < 4:
        return None
    a, b = p, np.roll(p, -1, axis=0)
    i, j = np.triu_indices(n, k=2)
    keep = ~((i == 0) & (j == n - 1))  # the first and last edges share vertex 0
    i, j = i[keep], j[keep]
    d1, d2 = b[i] - a[i], b[j] - a[j]
    r = a[j] - a[i]
    den = _cross(d1[:, 0], d1[:, 1], d2[:, 0], d2[:, 1])
    s_num = _cross(r[:, 0], r[:, 1], d2[:, 0], d2[:, 1])
    t_num = _cross(r[:, 0], r[:, 1], d1[:, 0], d1[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        s, t = s_num / den, t_num / den
    hit = (den != 0) & (s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)
    # parallel edges that overlap (collinear, sharing a stretch)
    scale = np.maximum(np.hypot(d1[:, 0], d1[:, 1]), 1e-12)
    collinear = (den == 0) & (np.abs(s_num) / scale < 1e-9)
    if collinear.any():
        dd = np.einsum("ij,ij->i", d1, d1)
        with np.errstate(divide="ignore", invalid="ignore"):
            u0 = np.einsum("ij,ij->i", r, d1) / dd
            u1 = np.einsum("ij,ij->i", r + d2, d1) / dd
        hit |= collinear & (np.maximum(u0, u1) >= 0) & (np.minimum(u0, u1) <= 1)
    k = np.flatnonzero(hit)
    return None if k.size == 0 else (int(i[k[0]]), int(j[k[0]]))


def ring_problem(xy: NDArray) -> str | None:
    """What makes a ring unusable as an area, or None for a simple polygon.

    Parameters
    ----------
    xy : ndarray, shape (n, 2)
        Vertices in the course frame [m], not repeating the first point.

    Returns
    -------
    str or None
        ``"expected at least 3 points ..."``, a repeated vertex, or the two edges
        that cross (1-based vertex numbers), worded to follow ``expected ...; got``.
    """
    p = np.asarray(xy, dtype=float)
    n = p.shape[0]
    if n < 3:
        return f"expected a ring of at least 3 points; got {n}"
    step = np.hypot(*(np.roll(p, -1, axis=0) - p).T)
    if np.any(step < 0.01):
        k = int(np.argmax(step < 0.01))
        return (
            f"expected distinct consecutive points; points {k + 1} and {(k + 1) % n + 1} "
            "are the same place (a ring does not repeat its first point at the end)"
        )
    hit = ring_crossing(p)
    if hit is not None:
        i, j = hit
        return (
            f"expected a simple polygon; its edge from point {i + 1} to {(i + 1) % n + 1} "
            f"crosses the edge from point {j + 1} to {(j + 1) % n + 1} (a self-"
            "intersecting ring: reorder the points along the edge)"
        )
    return None
