"""Areas of a course: the ``boundary`` routes stay inside and the ``obstacles`` they stay out of.

The course file's two keys (``docs/course-format.md``)::

    boundary:                     # the race area: routes stay inside
      points: [{lat: 36.84, lon: 174.76}, ...]   # a closed ring, not repeating the first point
      clearance_m: 0              # optional
    obstacles:                    # areas routes stay out of
      - {name: exclusion-1, points: [{lat: .., lon: ..}, ...], clearance_m: 0}

Each ring is a simple polygon: at least 3 vertices, no two consecutive vertices the same,
no edge crossing another.  :func:`ring_problem` is the one test, used by the course
loader and by the course importers (:mod:`sailroute.course.formats`).  The areas are
read into the :class:`~sailroute.course.model.Course`; the routers do not use them yet.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.checks import Checker, show
from sailroute.geo import LocalFrame

__all__ = ["AREA_KEYS", "Area", "check_areas", "contains", "ring_crossing", "ring_problem"]

AREA_KEYS = ("boundary", "obstacles")
"""The course file's top-level keys of areas."""

LatLon = tuple[float, float]


@dataclass(frozen=True)
class Area:
    """A polygon of the race area (the boundary, or an obstacle).

    Attributes
    ----------
    name : str
        ``"boundary"``, or the obstacle's name.
    points : tuple of (float, float)
        Vertices ``(lat, lon)`` [deg], the ring not repeating its first point.
    xy : tuple of (float, float)
        The same vertices in the course frame ``(x, y)`` [m].
    clearance_m : float
        Distance to keep from the edge [m] (>= 0).
    """

    name: str
    points: tuple[LatLon, ...]
    xy: tuple[tuple[float, float], ...]
    clearance_m: float = 0.0


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
        return (f"expected distinct consecutive points; points {k + 1} and {(k + 1) % n + 1} "
                "are the same place (a ring does not repeat its first point at the end)")
    hit = ring_crossing(p)
    if hit is not None:
        i, j = hit
        return (f"expected a simple polygon; its edge from point {i + 1} to {(i + 1) % n + 1} "
                f"crosses the edge from point {j + 1} to {(j + 1) % n + 1} (a self-"
                "intersecting ring: reorder the points along the edge)")
    return None


def contains(xy: NDArray, x: NDArray, y: NDArray) -> NDArray[np.bool_]:
    """Whether points lie inside a ring (even-odd rule).

    Parameters
    ----------
    xy : ndarray, shape (n, 2)
        The ring [m], not repeating its first point.
    x, y : ndarray
        Points [m].

    Returns
    -------
    ndarray of bool
    """
    p = np.asarray(xy, dtype=float)
    px, py = np.asarray(x, dtype=float)[..., None], np.asarray(y, dtype=float)[..., None]
    ax, ay = p[:, 0], p[:, 1]
    bx, by = np.roll(ax, -1), np.roll(ay, -1)
    up = (ay > py) != (by > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = ax + (py - ay) * (bx - ax) / (by - ay)
    return np.asarray(np.sum(up & (px < xc), axis=-1) % 2 == 1)


def _ring(c: Checker, raw: Any, key: str, frame: LocalFrame
          ) -> tuple[tuple[LatLon, ...], tuple[tuple[float, float], ...]] | None:
    """The ``points`` of an area at ``c.path``: ``(lat, lon)`` and ``(x, y)`` tuples."""
    if key not in raw:
        c.add(key, "missing required key; expected a list of {lat, lon} points")
        return None
    pts = raw[key]
    if not isinstance(pts, list):
        c.add(key, f"expected a list of {{lat, lon}} points; got {show(pts)}")
        return None
    out: list[LatLon] = []
    pc = c.child(key)
    for k, v in enumerate(pts):
        if not pc.child(k).is_mapping(v, "a point {lat: .., lon: ..}"):
            return None
        pc.child(k).keys(v, ("lat", "lon"), ("lat", "lon"))
        lat = pc.child(k).number(v, "lat", lo=-90.0, hi=90.0)
        lon = pc.child(k).number(v, "lon", lo=-180.0, hi=360.0)
        if lat is None or lon is None:
            return None
        out.append((lat, lon))
    x, y = frame.to_xy([p[0] for p in out], [p[1] for p in out])
    xy = np.column_stack([x, y]) if out else np.zeros((0, 2))
    problem = ring_problem(xy)
    if problem is not None:
        c.add(key, problem)
        return None
    return tuple(out), tuple((float(a), float(b)) for a, b in xy)


def _area(c: Checker, raw: Any, name: str | None, frame: LocalFrame) -> Area | None:
    if not c.is_mapping(raw, "a mapping with points (and clearance_m)"):
        return None
    keys = ("points", "clearance_m") if name is not None else ("name", "points", "clearance_m")
    c.keys(raw, keys)
    if name is None:
        name = c.string(raw, "name", None)
        if name is None:
            if "name" not in raw:
                c.add("name", "missing required key; expected the obstacle's name")
            return None
    clearance = c.number(raw, "clearance_m", 0.0, lo=0.0, hi=10_000.0)
    ring = _ring(c, raw, "points", frame)
    if ring is None or clearance is None:
        return None
    return Area(name, ring[0], ring[1], float(clearance))


def check_areas(c: Checker, data: Mapping[str, Any], frame: LocalFrame | None
                ) -> tuple[Area | None, tuple[Area, ...]]:
    """The ``boundary`` and ``obstacles`` of a course mapping; problems go to ``c``.

    Parameters
    ----------
    c : Checker
        The course file's top-level checker.
    data : mapping
        The parsed course file.
    frame : LocalFrame or None
        The course frame (None after a problem with the marks: nothing is checked).

    Returns
    -------
    (Area or None, tuple of Area)
        The boundary (None when absent) and the obstacles, in file order.
    """
    if frame is None:
        return None, ()
    boundary = None
    if data.get("boundary") is not None:
        boundary = _area(c.child("boundary"), data["boundary"], "boundary", frame)
    obstacles: list[Area] = []
    raw = data.get("obstacles")
    if raw is not None:
        if not isinstance(raw, Sequence) or isinstance(raw, str):
            c.add("obstacles", f"expected a list of {{name, points}} areas; got {show(raw)}")
        else:
            seen: set[str] = set()
            for k, item in enumerate(raw):
                area = _area(c.child("obstacles").child(k), item, None, frame)
                if area is not None:
                    if area.name in seen:
                        c.child("obstacles").child(k).add(
                            "name", f"expected a name used once; {area.name!r} is used twice")
                    seen.add(area.name)
                    obstacles.append(area)
    return boundary, tuple(obstacles)
