"""A label placer for the maps: names, symbols and badges that overlap nothing.

Everything is in screen pixels.  Each :class:`Label` has an anchor (the point it belongs
to), a size, and says whether it may sit on the route (a tack symbol or a leg number
lies on its route; a mark's name must not).  :func:`place_labels` puts them one after
the other, in the order given, each at the candidate position of least cost:

* a position off the map, or over a fixed box (a mark, the boat, the scale bar) or a
  label already placed, costs most (in proportion to the area covered);
* then a crossing of a route segment, for a label that may not sit on the route;
* then the distance from the anchor (the nearest free place wins).

Candidates: the anchor itself (for a symbol, ``gap == 0``), then boxes touching circles
of growing radius round the anchor, in 16 directions.  A symbol moved off its anchor, or
a label placed farther than :data:`LEADER_PX` from where it would sit, gets a leader line
to its anchor.  ``route.png``
(:mod:`sailroute.report.plots`) uses this module; ``report.html`` runs the same rules in
its script (:mod:`sailroute.report.page_render`), on the sizes the browser measures.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["LEADER_PX", "Label", "Placed", "best_box", "place_labels", "segments_hit"]

LEADER_PX = 10.0
"""A label this much farther from its anchor than its ``gap`` gets a leader line [px]."""
STEPS_PX = (0.0, 6.0, 14.0, 26.0, 42.0, 64.0, 92.0, 130.0)
"""Distances tried beyond a label's ``gap`` [px]."""
DIRECTIONS = 16
"""Directions tried at each distance."""


@dataclass(frozen=True)
class Label:
    """Something to place.

    Attributes
    ----------
    x, y : float
        Anchor [px].
    w, h : float
        Size [px].
    gap : float
        Distance from the anchor to the nearest edge of the box where it sits by default
        [px]; 0: centred on the anchor (a symbol at its true place).
    on_route : bool
        May cover route segments.
    """

    x: float
    y: float
    w: float
    h: float
    gap: float = 4.0
    on_route: bool = False


@dataclass(frozen=True)
class Placed:
    """Where a label went: its box centre [px] and whether it needs a leader line."""

    cx: float
    cy: float
    leader: bool


def _overlap(boxes: NDArray, others: NDArray) -> NDArray:
    """Area of overlap of every box (C, 4) with every other (K, 4): shape (C, K)."""
    if others.size == 0:
        return np.zeros((len(boxes), 0))
    w = np.minimum(boxes[:, None, 2], others[None, :, 2]) - np.maximum(
        boxes[:, None, 0], others[None, :, 0]
    )
    h = np.minimum(boxes[:, None, 3], others[None, :, 3]) - np.maximum(
        boxes[:, None, 1], others[None, :, 1]
    )
    return np.clip(w, 0.0, None) * np.clip(h, 0.0, None)


def segments_hit(boxes: NDArray, segs: NDArray) -> NDArray:
    """How many segments (S, 4: ``x0, y0, x1, y1``) cross each box (C, 4: ``x0, y0, x1,
    y1``), shape (C,): the bounding boxes overlap and the box's corners are not all on
    one side of the segment's line."""
    if segs.size == 0:
        return np.zeros(len(boxes), dtype=int)
    sx0, sy0 = np.minimum(segs[:, 0], segs[:, 2]), np.minimum(segs[:, 1], segs[:, 3])
    sx1, sy1 = np.maximum(segs[:, 0], segs[:, 2]), np.maximum(segs[:, 1], segs[:, 3])
    near = (
        (sx1[None] >= boxes[:, None, 0])
        & (sx0[None] <= boxes[:, None, 2])
        & (sy1[None] >= boxes[:, None, 1])
        & (sy0[None] <= boxes[:, None, 3])
    )
    dx, dy = segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]
    signs = []
    for cx, cy in ((0, 1), (2, 1), (0, 3), (2, 3)):
        side = dx[None] * (boxes[:, None, cy] - segs[None, :, 1]) - dy[None] * (
            boxes[:, None, cx] - segs[None, :, 0]
        )
        signs.append(np.sign(side))
    s = np.stack(signs)
    one_side = np.all(s > 0, axis=0) | np.all(s < 0, axis=0)
    return np.sum(near & ~one_side, axis=1)


def _candidates(lab: Label) -> tuple[NDArray, NDArray]:
    """Candidate box centres (C, 2) and their distance beyond ``gap`` (C,)."""
    centres, dist = [], []
    if lab.gap <= 0:
        centres.append((lab.x, lab.y))
        dist.append(0.0)
    angles = 2.0 * math.pi * np.arange(DIRECTIONS) / DIRECTIONS
    ux, uy = np.cos(angles), np.sin(angles)
    for d in STEPS_PX:
        r = max(lab.gap, 0.0) + d
        if lab.gap <= 0 and d == 0.0:
            continue
        for a, b in zip(ux, uy, strict=True):
            centres.append((lab.x + a * (0.5 * lab.w + r), lab.y + b * (0.5 * lab.h + r)))
            dist.append(d + 0.01 * abs(b))  # sideways a little before above/below
    return np.asarray(centres, float), np.asarray(dist, float)


def _boxes(centres: NDArray, w: float, h: float) -> NDArray:
    return np.column_stack(
        [centres[:, 0] - w / 2, centres[:, 1] - h / 2, centres[:, 0] + w / 2, centres[:, 1] + h / 2]
    )


def best_box(
    centres: NDArray,
    dist: NDArray,
    w: float,
    h: float,
    on_route: bool,
    segs: NDArray,
    taken: NDArray,
    bounds: Sequence[float],
) -> int:
    """Index of the cheapest of the candidate centres (the costs of the module docstring)."""
    boxes = _boxes(centres, w, h)
    x0, y0, x1, y1 = bounds
    out = (
        np.clip(x0 - boxes[:, 0], 0, None)
        + np.clip(boxes[:, 2] - x1, 0, None)
        + np.clip(y0 - boxes[:, 1], 0, None)
        + np.clip(boxes[:, 3] - y1, 0, None)
    )
    over = _overlap(boxes, taken).sum(axis=1)
    cost = 1e7 * (out > 0) + 1e4 * out + 1e5 * (over > 0) + 1e2 * over + dist
    if not on_route:
        cost = cost + 1e5 * segments_hit(boxes, segs)
    return int(np.argmin(cost))


def place_labels(
    labels: Sequence[Label],
    segments: NDArray,
    fixed: NDArray,
    bounds: Sequence[float],
) -> list[Placed]:
    """Place ``labels`` in order (each avoids the ones before it).

    Parameters
    ----------
    labels : sequence of Label
    segments : ndarray, shape (S, 4)
        Route segments ``x0, y0, x1, y1`` [px].
    fixed : ndarray, shape (K, 4)
        Boxes nothing may cover ``x0, y0, x1, y1`` [px] (marks, the boat, furniture).
    bounds : sequence of float
        The map's box ``x0, y0, x1, y1`` [px].

    Returns
    -------
    list of Placed
    """
    segs = np.asarray(segments, float).reshape(-1, 4)
    taken = np.asarray(fixed, float).reshape(-1, 4)
    out = []
    for lab in labels:
        centres, dist = _candidates(lab)
        k = best_box(centres, dist, lab.w, lab.h, lab.on_route, segs, taken, bounds)
        cx, cy = centres[k]
        taken = np.vstack([taken, _boxes(centres[k : k + 1], lab.w, lab.h)])
        moved = (lab.gap <= 0 and k > 0) or dist[k] > LEADER_PX
        out.append(Placed(float(cx), float(cy), bool(moved)))
    return out
