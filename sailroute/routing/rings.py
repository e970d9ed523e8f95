"""Rings (closed polygons given as vertex lists): why one cannot be an area, which edges cross.

Used by the race-area checks (:mod:`sailroute.routing.obstacles`) and the course
importers (:mod:`sailroute.course.formats`), so both word a bad polygon the same way.
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import NDArray

__all__ = ["ring_crossing", "ring_problem"]


def _cross(ax: NDArray, ay: NDArray, bx: NDArray, by: NDArray) -> NDArray:
    return ax * by - ay * bx


CROSSING_BLOCK = 512
"""Edges tested at a time by :func:`ring_crossing`: its memory is bounded by this many
edges times the edges each one's box overlaps, not by the square of the ring's size."""


def _pairs_hit(a: NDArray, b: NDArray, i: NDArray, j: NDArray) -> NDArray:
    """Whether edge ``i`` (``a[i]`` to ``b[i]``) and edge ``j`` cross, touch or overlap."""
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
    return np.asarray(hit)


def ring_crossing(xy: NDArray) -> tuple[int, int] | None:
    """The first pair of edges of a closed ring that cross or touch, if any.

    Only pairs whose bounding boxes overlap are tested (found with a shapely
    ``STRtree``), :data:`CROSSING_BLOCK` edges at a time: O(n log n) time for the rings
    of a course, and memory bounded by the block, not O(n²) (a ring of 15 000 points
    would need gigabytes for every pair at once).

    Parameters
    ----------
    xy : ndarray, shape (n, 2)
        The vertices [m] (any planar units), the ring not repeating its first point.

    Returns
    -------
    (i, j) or None
        Edge ``i`` runs from vertex ``i`` to ``i + 1`` (``n - 1`` closes the ring back to
        vertex 0); None when no two non-adjacent edges meet.  The pair with the smallest
        ``i``, then the smallest ``j``.
    """
    p = np.asarray(xy, dtype=float)
    n = p.shape[0]
    if n < 4:
        return None
    a, b = p, np.roll(p, -1, axis=0)
    pad = 1e-9 * (1.0 + float(np.abs(p).max()))  # a point's box is a box, not empty
    lo, hi = np.minimum(a, b) - pad, np.maximum(a, b) + pad
    tree = shapely.STRtree(shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1]))
    for start in range(0, n, CROSSING_BLOCK):
        block = np.arange(start, min(start + CROSSING_BLOCK, n))
        sel, j = tree.query(shapely.box(*lo[block].T, *hi[block].T))
        i = block[sel]
        keep = (j >= i + 2) & ~((i == 0) & (j == n - 1))  # not adjacent, each pair once
        i, j = i[keep], j[keep]
        k = np.flatnonzero(_pairs_hit(a, b, i, j))
        if k.size:
            first = k[np.lexsort((j[k], i[k]))[0]]
            return int(i[first]), int(j[first])
    return None


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
