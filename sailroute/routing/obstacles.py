"""The race area: a boundary routes stay inside and obstacles they stay out of.

A course may name a ``boundary`` polygon (the race area) and ``obstacles`` polygons
(breakwaters, moorings, land), each with a clearance [m] kept from its edge
(``docs/course-format.md``).  The course loader stores them as :class:`AreaPolygon`
values in a :class:`RaceArea` (course frame, metres); :meth:`Obstacles.build` turns
that into one frozen object with the geometry buffered by the clearances and two
vectorised predicates that every router uses:

* :meth:`Obstacles.points_free`: which points lie in free water (inside the shrunk
  boundary, outside every grown obstacle);
* :meth:`Obstacles.segments_free`: which straight moves stay in free water: both
  ends free and no edge of any ring crossed (an orientation test against every edge,
  vectorised in NumPy; :meth:`Obstacles.segments_free_shapely` is the same predicate
  through ``shapely.intersects`` on linestrings, kept for comparison: see
  ``benchmarks/bench_obstacles.py``);
* :meth:`Obstacles.moves_free`: the same for a fan of moves from each of ``n``
  points (the isochrone's candidates, in its leg frame), with the same answers for a
  fraction of the work: bounding-box filters (the point's moves against each group of
  edges, each move against the groups near its point, then against each edge of those
  groups) and a box per group inside its blocked water (a move from free water that
  ends there is blocked without the edge test).

Polygons are shapely 2 geometries (validity, buffering, point-in-polygon in C),
imported by the functions that use them: a course without a race area routes, and
starts, without shapely.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "BOUNDARY_NAME",
    "AreaPolygon",
    "Obstacles",
    "RaceArea",
    "constraint_label",
    "land_filled",
    "land_obstacle",
    "obstacles_for",
    "polygon_problem",
]

BOUNDARY_NAME: Final = "the race-area boundary"
"""How messages name the boundary."""
QUAD_SEGS: Final = 4
"""Segments per quarter circle of a clearance buffer's rounded corners (the chord
cuts at most ``1 - cos(11.25°)``, 1.9 %, of the clearance at a corner)."""
_CHUNK: Final = 1 << 18
"""Most segment x edge pairs tested at once (memory of the orientation test)."""


def constraint_label(name: str) -> str:
    """How a message names the constraint ``name`` (:attr:`Obstacles.names`): as given when
    it is already a phrase (:data:`BOUNDARY_NAME`, ``"the ..."``), else ``obstacle 'name'``."""
    return name if name.startswith("the ") else f"obstacle {name!r}"


@dataclass(frozen=True)
class AreaPolygon:
    """A polygon of the race area in the course frame.

    Attributes
    ----------
    name : str
        Name for messages (``"breakwater"``; the boundary is ``"boundary"``).
    x, y : tuple of float
        Vertices [m east, m north of the course origin]: one ring, the first vertex
        not repeated.
    clearance_m : float
        Distance kept from the edge [m]: obstacles grow by it, the boundary shrinks.
    where : str
        Key path of the polygon in the course file, for messages.
    """

    name: str
    x: tuple[float, ...]
    y: tuple[float, ...]
    clearance_m: float = 0.0
    where: str = ""

    def polygon(self) -> Any:
        """The ring as a shapely Polygon (no clearance)."""
        import shapely

        return shapely.polygons(np.column_stack([self.x, self.y]))


@dataclass(frozen=True)
class RaceArea:
    """The race area of a course: boundary, obstacles and the land rule.

    Attributes
    ----------
    boundary : AreaPolygon or None
        Routes stay inside it; None: unbounded.
    obstacles : tuple of AreaPolygon
        Routes stay out of each.
    wind_land_is_obstacle : bool
        NaN (land) cells of a gridded wind become obstacles too.
    """

    boundary: AreaPolygon | None = None
    obstacles: tuple[AreaPolygon, ...] = ()
    wind_land_is_obstacle: bool = False

    @property
    def is_empty(self) -> bool:
        """True when nothing constrains the routes."""
        return self.boundary is None and not self.obstacles and not self.wind_land_is_obstacle


def polygon_problem(
    x: Sequence[float], y: Sequence[float], clearance_m: float = 0.0, *, boundary: bool = False
) -> str | None:
    """What is wrong with a ring, or None: fewer than 3 vertices, a zero area,
    self-intersection (shapely's ``explain_validity``), a boundary that a clearance
    leaves empty; the ring checks and wording of :func:`sailroute.routing.rings.ring_problem`
    come first."""
    import shapely

    from sailroute.routing.rings import ring_problem

    ring = ring_problem(np.column_stack([x, y]))
    if ring is not None:
        return ring
    poly = shapely.Polygon(np.column_stack([x, y]))
    if not shapely.is_valid(poly):
        return (
            f"the polygon is not valid ({shapely.is_valid_reason(poly)}): "
            "its edges must not cross; list the points in order round the ring"
        )
    if poly.area <= 0.0:
        return "the polygon has no area (its points are on one line)"
    if boundary and clearance_m > 0 and poly.buffer(-clearance_m).is_empty:
        return (
            f"clearance_m = {clearance_m:g} leaves no water inside the boundary; "
            "use a smaller clearance"
        )
    return None


def _rings(geom: Any) -> list[NDArray[np.float64]]:
    """Vertex arrays (closed) of every ring of a (multi)polygon."""
    import shapely

    out = []
    for part in shapely.get_parts(geom):
        for ring in shapely.get_rings(part):
            out.append(shapely.get_coordinates(ring))
    return out


def _edges(rings: list[NDArray[np.float64]]) -> NDArray[np.float64]:
    """``(E, 4)`` edges ``x0, y0, x1, y1`` of closed rings."""
    if not rings:
        return np.zeros((0, 4))
    return np.concatenate([np.hstack([r[:-1], r[1:]]) for r in rings])


@dataclass(frozen=True, eq=False)
class Obstacles:
    """The race area's constraints, ready for the routers (course frame, metres).

    Build with :meth:`build`.  Every predicate broadcasts its array arguments.

    Attributes
    ----------
    names : tuple of str
        One name per constraint; index ``-1`` (the last) is the boundary when there is
        one (:data:`BOUNDARY_NAME`).
    inside : shapely geometry or None
        The boundary shrunk by its clearance (prepared); None: unbounded.
    blocked : shapely geometry or None
        The union of the obstacles grown by their clearances (prepared); None: none.
    edges : ndarray
        ``(E, 4)`` every ring edge ``x0, y0, x1, y1`` [m], grouped: each obstacle's
        edges in runs of :data:`OBSTACLE_RUN`, then the boundary's in runs of
        :data:`BOUNDARY_RUN`.
    owner : ndarray of int
        ``(E,)`` index into ``names`` of each edge.
    group_box : ndarray
        ``(G, 4)`` bounding box ``xmin, ymin, xmax, ymax`` [m] of each group of edges.
    group_start : ndarray of int
        ``(G + 1,)`` the groups' first edges (and the end).
    group_edges : ndarray
        ``(G, K, 4)`` each group's edges, padded to the largest group's ``K`` (the
        padding is never read).
    group_edge_box : tuple of ndarray
        ``xmin, ymin, xmax, ymax``, each ``(G, K)``: the bounding box [m] of each of them
        (NaN for the padding, which meets nothing).
    core_box : ndarray
        ``(G, 4)`` per group of edges, a box ``xmin, ymin, xmax, ymax`` [m] of the
        *core* of the blocked water, where no move from free water can end without
        touching an edge: for an obstacle's groups, a box that lies :data:`CORE_M` or
        more inside the obstacle (NaN where none was found); for the boundary's, the
        box round the shrunk boundary grown by :data:`CORE_M` (outside it is core).
    core_outer : ndarray of bool
        ``(G,)`` the core of group ``g`` lies outside its box (the boundary's groups).
    """

    names: tuple[str, ...]
    inside: Any
    blocked: Any
    edges: NDArray[np.float64]
    owner: NDArray[np.int64]
    group_box: NDArray[np.float64]
    group_start: NDArray[np.int64]
    group_edges: NDArray[np.float64]
    group_edge_box: tuple[NDArray[np.float64], ...]
    core_box: NDArray[np.float64]
    core_outer: NDArray[np.bool_]
    _frames: dict[tuple[float, ...], NDArray[np.float64]] = field(
        default_factory=dict, repr=False, compare=False
    )
    _last: list[Any] = field(default_factory=list, repr=False, compare=False)

    @classmethod
    def build(cls, area: RaceArea, extra: Sequence[Any] = ()) -> Obstacles | None:
        """The constraints of ``area`` (None when it has none).

        Parameters
        ----------
        area : RaceArea
            Boundary and obstacles (validated by the course loader).
        extra : sequence of (str, shapely geometry)
            More obstacles, already in the course frame (e.g. land cells of a wind
            grid, :func:`land_obstacle`), without clearance.
        """
        if area.boundary is None and not area.obstacles and not extra:
            return None
        import shapely

        names: list[str] = []
        grown: list[Any] = []
        owners: list[int] = []
        rings: list[NDArray[np.float64]] = []
        for ob in area.obstacles:
            g = ob.polygon()
            if ob.clearance_m > 0:
                g = shapely.buffer(g, ob.clearance_m, quad_segs=QUAD_SEGS)
            grown.append(g)
            names.append(ob.name)
        for name, g in extra:
            grown.append(g)
            names.append(name)
        for k, g in enumerate(grown):
            r = _rings(g)
            rings += r
            owners += [k] * sum(len(a) - 1 for a in r)
        inside = None
        if area.boundary is not None:
            b = area.boundary
            inside = b.polygon()
            if b.clearance_m > 0:
                inside = shapely.buffer(inside, -b.clearance_m, quad_segs=QUAD_SEGS)
            r = _rings(inside)
            rings += r
            names.append(BOUNDARY_NAME)
            owners += [len(names) - 1] * sum(len(a) - 1 for a in r)
        if not names:
            return None
        blocked = shapely.union_all(grown) if grown else None
        for g in (inside, blocked):
            if g is not None:
                shapely.prepare(g)
        edges = _edges(rings)
        own = np.asarray(owners, dtype=np.int64)
        run = [BOUNDARY_RUN if n == BOUNDARY_NAME else OBSTACLE_RUN for n in names]
        starts = [0] + [
            i
            for i in range(1, own.size)
            if own[i] != own[i - 1] or (i - _first(own, i)) % run[own[i]] == 0
        ]
        bounds = np.asarray([*starts, own.size], dtype=np.int64)
        box = np.array(
            [
                [
                    min(edges[a:b, 0].min(), edges[a:b, 2].min()),
                    min(edges[a:b, 1].min(), edges[a:b, 3].min()),
                    max(edges[a:b, 0].max(), edges[a:b, 2].max()),
                    max(edges[a:b, 1].max(), edges[a:b, 3].max()),
                ]
                for a, b in itertools.pairwise(bounds)
            ]
        ).reshape(-1, 4)
        padded, edge_box = _padded(edges, bounds)
        cells = [_inner_box(g) for g in grown]
        if inside is not None:  # beyond the box of the boundary's core
            x0, y0, x1, y1 = shapely.bounds(shapely.buffer(inside, CORE_M, quad_segs=QUAD_SEGS))
            cells.append((x0, y0, x1, y1))
        first = own[bounds[:-1]]
        core_box = np.asarray(cells, dtype=float).reshape(-1, 4)[first]
        outer = np.asarray([names[k] == BOUNDARY_NAME for k in first], dtype=bool)
        return cls(
            tuple(names),
            inside,
            blocked,
            edges,
            own,
            box,
            bounds,
            padded,
            edge_box,
            core_box,
            outer,
        )

    # ------------------------------------------------------------------ predicates
    def points_free(self, x: ArrayLike, y: ArrayLike) -> NDArray[np.bool_]:
        """True where ``(x, y)`` [m] is in free water (strictly inside the shrunk
        boundary, not in or on a grown obstacle)."""
        xa, ya = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        return self._free_xy(xa, ya)

    def segments_cross(
        self, x0: ArrayLike, y0: ArrayLike, x1: ArrayLike, y1: ArrayLike
    ) -> NDArray[np.bool_]:
        """True where the segment touches or crosses any ring edge (orientation test,
        touching included, so a move through a vertex counts).  Each group of edges is
        tested only against the segments whose bounding box meets the group's, and each
        of its edges only against those whose bounding box meets the edge's
        (:func:`_cross_flat`)."""
        a = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x0, y0, x1, y1)))
        shape = a[0].shape
        sx0, sy0, sx1, sy1 = (v.reshape(-1) for v in a)
        hit = np.zeros(sx0.size, dtype=bool)
        if sx0.size == 0:
            return hit.reshape(shape)
        xlo, xhi = np.minimum(sx0, sx1), np.maximum(sx0, sx1)
        ylo, yhi = np.minimum(sy0, sy1), np.maximum(sy0, sy1)
        box, seg = (xlo, xhi, ylo, yhi), (sx0, sy0, sx1, sy1)
        for g in range(self.group_box.shape[0]):
            b = self.group_box[g]
            idx = np.flatnonzero((xhi >= b[0]) & (xlo <= b[2]) & (yhi >= b[1]) & (ylo <= b[3]))
            self._group_hits(g, idx, box, seg, hit)
        return hit.reshape(shape)

    def segments_free(
        self, x0: ArrayLike, y0: ArrayLike, x1: ArrayLike, y1: ArrayLike
    ) -> NDArray[np.bool_]:
        """True where the straight move ``(x0, y0) -> (x1, y1)`` [m] stays in free
        water: its start is free and no ring edge is touched or crossed (so its end is
        free too)."""
        a = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x0, y0, x1, y1)))
        return self.points_free(a[0], a[1]) & ~self.segments_cross(*a)

    def segments_free_shapely(
        self, x0: ArrayLike, y0: ArrayLike, x1: ArrayLike, y1: ArrayLike
    ) -> NDArray[np.bool_]:
        """:meth:`segments_free` through ``shapely.intersects`` on linestrings (the same
        answer up to touching; slower per segment, see ``benchmarks/bench_obstacles.py``)."""
        import shapely

        a = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (x0, y0, x1, y1)))
        shape = a[0].shape
        coords = np.stack(
            [
                np.column_stack([a[0].ravel(), a[1].ravel()]),
                np.column_stack([a[2].ravel(), a[3].ravel()]),
            ],
            axis=1,
        )
        lines = np.asarray(shapely.linestrings(coords))
        ok = np.ones(lines.shape, dtype=bool)
        if self.inside is not None:
            ok &= shapely.contains_properly(self.inside, lines)
        if self.blocked is not None:
            ok &= ~shapely.intersects(self.blocked, lines)
        return ok.reshape(shape)

    def moves_free(
        self,
        px: Any,
        py: Any,
        qx: Any,
        qy: Any,
        to_world: Callable[[Any, Any], tuple[Any, Any]] | None = None,
        *,
        starts_free: bool = False,
        reach: ArrayLike | None = None,
    ) -> NDArray[np.bool_]:
        """Which moves of a fan stay in free water.

        Parameters
        ----------
        px, py : array, shape (n,)
            Start of the moves of each row [m].
        qx, qy : array, shape (n, m)
            Their end points [m].
        to_world : callable, optional
            ``to_world(x, y)``: the course frame from the frame of ``px, py, qx, qy``, a
            rotation and a shift applied element by element (the isochrone's leg frame);
            only the ends of the moves that are tested are moved.  None: they are in the
            course frame.
        starts_free : bool
            The caller knows every start is in free water, so it is not tested again
            (an isochrone front after the first: each of its points ends a move found
            free).
        reach : array, shape (n,), optional
            An upper bound of each row's move lengths [m] (the moves' box is then the
            square round the start, not the box of the ends: a cheaper filter, the same
            answers).

        Returns
        -------
        ndarray of bool, shape (n, m)
            :meth:`segments_free` move by move, the same answers: a row whose moves'
            box meets no group of edges (:attr:`group_box`, seen in the frame of the
            moves) is decided by its start alone; a move of the other rows is blocked
            if it ends in the core of the blocked water (:attr:`core_box`), else tested
            against the groups near its row whose box meets its own, edge by edge
            (:meth:`_pairs_cross`).
        """
        lx, ly = np.asarray(px, dtype=float), np.asarray(py, dtype=float)
        qx, qy = np.asarray(qx, dtype=float), np.asarray(qy, dtype=float)
        tw = _same if to_world is None else to_world
        wx, wy = tw(lx, ly)
        start_ok = np.ones(lx.shape, dtype=bool) if starts_free else self._free_xy(wx, wy)
        out = np.broadcast_to(start_ok[:, None], qx.shape).copy()
        if qx.shape[1] == 0 or self.group_box.shape[0] == 0:
            return out
        gb = self._boxes_in(to_world)
        if reach is None:
            xlo, xhi = np.minimum(lx, qx.min(axis=1)), np.maximum(lx, qx.max(axis=1))
            ylo, yhi = np.minimum(ly, qy.min(axis=1)), np.maximum(ly, qy.max(axis=1))
        else:
            rr = np.asarray(reach, dtype=float)
            xlo, xhi, ylo, yhi = lx - rr, lx + rr, ly - rr, ly + rr
        near = (xhi[:, None] >= gb[:, 0]) & (xlo[:, None] <= gb[:, 2])
        near &= (yhi[:, None] >= gb[:, 1]) & (ylo[:, None] <= gb[:, 3])
        near &= start_ok[:, None]
        r, g = np.nonzero(near)  # (row, group) pairs
        if r.size == 0:
            return out
        x0, y0, x1, y1 = lx[r, None], ly[r, None], qx[r], qy[r]
        b = gb[g]
        p, j = np.nonzero(
            (np.maximum(x0, x1) >= b[:, 0, None])
            & (np.minimum(x0, x1) <= b[:, 2, None])
            & (np.maximum(y0, y1) >= b[:, 1, None])
            & (np.minimum(y0, y1) <= b[:, 3, None])
        )
        row, grp = r[p], g[p]
        ex, ey = tw(qx[row, j], qy[row, j])
        # a move from free water that ends in the core crosses an edge; the others are
        # tested edge by edge
        hit = self._in_core(ex, ey, grp)
        k = np.flatnonzero(~hit)
        rk = row[k]
        hit[k] = self._pairs_cross((wx[rk], wy[rk], ex[k], ey[k]), grp[k])
        out[row[hit], j[hit]] = False
        return out

    def fan_clear(
        self,
        px: Any,
        py: Any,
        reach: Any,
        to_world: Callable[[Any, Any], tuple[Any, Any]] | None = None,
    ) -> bool:
        """Whether no move of a fan can come near an edge: the box round every start
        ``px, py`` [m] grown by the largest ``reach`` [m] meets no group's box (seen in
        the frame of the moves, as in :meth:`moves_free`).  Then every move from free
        water stays in free water, and :meth:`moves_free` need not be called."""
        if self.group_box.shape[0] == 0 or np.size(px) == 0:
            return True
        r = float(np.max(reach))
        x0, x1 = float(np.min(px)) - r, float(np.max(px)) + r
        y0, y1 = float(np.min(py)) - r, float(np.max(py)) + r
        gb = self._boxes_in(to_world)
        near = (x1 >= gb[:, 0]) & (x0 <= gb[:, 2]) & (y1 >= gb[:, 1]) & (y0 <= gb[:, 3])
        return not bool(near.any())

    def _free_xy(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.bool_]:
        """:meth:`points_free` of float arrays of one shape."""
        import shapely

        if self.inside is not None:
            ok = np.asarray(shapely.contains_xy(self.inside, x, y), dtype=bool)
        else:
            ok = np.ones(x.shape, dtype=bool)
        if self.blocked is not None:
            ok &= ~np.asarray(shapely.intersects_xy(self.blocked, x, y), dtype=bool)
        return ok

    def _boxes_in(self, to_world: Callable[[Any, Any], tuple[Any, Any]] | None) -> Any:
        """``(G, 4)`` the groups' bounding boxes seen in the frame that ``to_world``
        leaves (the box round each box's corners moved back), grown by
        :data:`BOX_MARGIN_M` against rounding; kept per frame."""
        if to_world is None:
            return self.group_box + BOX_MARGIN_M * np.array([-1.0, -1.0, 1.0, 1.0])
        owner = getattr(to_world, "__self__", None)  # a frozen frame's bound method
        last = self._last[0] if self._last else None  # (frame, boxes), read at once
        if owner is not None and last is not None and last[0] is owner:
            return last[1]
        boxes = self._boxes_of(to_world)
        if owner is not None:
            self._last[:] = [(owner, boxes)]
        return boxes

    def _boxes_of(self, to_world: Callable[[Any, Any], tuple[Any, Any]]) -> Any:
        """:meth:`_boxes_in` for one frame, kept per its transform (at most 64)."""
        ox, oy = (float(v) for v in to_world(0.0, 0.0))
        ax, ay = (float(v) - o for v, o in zip(to_world(1.0, 0.0), (ox, oy), strict=True))
        bx, by = (float(v) - o for v, o in zip(to_world(0.0, 1.0), (ox, oy), strict=True))
        key = (ox, oy, ax, ay, bx, by)
        boxes = self._frames.get(key)
        if boxes is None:
            if len(self._frames) > 64:
                self._frames.clear()
            det = ax * by - ay * bx
            b = self.group_box
            cx = np.stack([b[:, 0], b[:, 0], b[:, 2], b[:, 2]], axis=1) - ox
            cy = np.stack([b[:, 1], b[:, 3], b[:, 1], b[:, 3]], axis=1) - oy
            x = (cx * by - cy * bx) / det
            y = (cy * ax - cx * ay) / det
            pad = BOX_MARGIN_M + 1e-9 * (np.abs(b).max(axis=1) + abs(ox) + abs(oy))
            boxes = np.stack(
                [
                    x.min(axis=1) - pad,
                    y.min(axis=1) - pad,
                    x.max(axis=1) + pad,
                    y.max(axis=1) + pad,
                ],
                axis=1,
            )
            self._frames[key] = boxes
        return boxes

    def _in_core(self, x: Any, y: Any, grp: Any) -> NDArray[np.bool_]:
        """True where ``(x, y)`` [m] lies in the core of the blocked water by the box of
        group ``grp`` (:attr:`core_box`; False where the box cannot tell)."""
        b = self.core_box[grp]
        inner = (x >= b[:, 0]) & (x <= b[:, 2]) & (y >= b[:, 1]) & (y <= b[:, 3])
        return inner ^ self.core_outer[grp]

    def _pairs_cross(
        self, segments: tuple[Any, Any, Any, Any], grp: NDArray[np.int64]
    ) -> NDArray[np.bool_]:
        """Which (segment, group) pairs touch or cross an edge of the group.

        ``segments`` are the flat arrays ``x0, y0, x1, y1`` [m]; pair ``k`` is segment
        ``k`` with group ``grp[k]``.  The pairs of each group are tested against the edges
        of the group whose bounding boxes meet the segment's (:meth:`_group_hits`).
        """
        hit = np.zeros(grp.size, dtype=bool)
        if grp.size == 0:
            return hit
        sx0, sy0, sx1, sy1 = segments
        box = (
            np.minimum(sx0, sx1),
            np.maximum(sx0, sx1),
            np.minimum(sy0, sy1),
            np.maximum(sy0, sy1),
        )
        order = np.argsort(grp, kind="stable")
        cut = np.flatnonzero(np.diff(grp[order])) + 1
        for run in np.split(order, cut):
            self._group_hits(int(grp[run[0]]), run, box, segments, hit)
        return hit

    def _group_hits(
        self,
        g: int,
        idx: NDArray[np.int64],
        box: tuple[Any, Any, Any, Any],
        seg: tuple[Any, Any, Any, Any],
        hit: NDArray[np.bool_],
    ) -> None:
        """Set ``hit`` where segment ``idx[k]`` (``seg``: flat ``x0, y0, x1, y1`` [m]; ``box``:
        their ``xlo, xhi, ylo, yhi``) touches or crosses an edge of group ``g``, each tested
        only against the edges whose own boxes meet its box, at most :data:`_CHUNK`
        (segment, edge) boxes at once (:func:`_cross_flat`)."""
        xlo, xhi, ylo, yhi = box
        sx0, sy0, sx1, sy1 = seg
        w = int(self.group_start[g + 1] - self.group_start[g])
        xmin, ymin, xmax, ymax = (v[g, :w] for v in self.group_edge_box)
        step = max(1, _CHUNK // w)
        for i in range(0, idx.size, step):
            k = idx[i : i + step]
            meet = xhi[k, None] >= xmin
            meet &= xlo[k, None] <= xmax
            meet &= yhi[k, None] >= ymin
            meet &= ylo[k, None] <= ymax
            pair, edge = np.nonzero(meet)
            k = k[pair]
            e = self.group_edges[g, edge]
            hit[k[_cross_flat(sx0[k], sy0[k], sx1[k], sy1[k], e)]] = True

    def edge_distance(self, x: ArrayLike, y: ArrayLike) -> NDArray[np.float64]:
        """Distance [m] from each point to the nearest ring edge."""
        xa, ya = (np.asarray(v, dtype=float).reshape(-1) for v in (x, y))
        best = np.full(xa.size, np.inf)
        e = self.edges
        if e.shape[0] == 0:
            return best
        dx, dy = e[:, 2] - e[:, 0], e[:, 3] - e[:, 1]
        den = np.maximum(dx * dx + dy * dy, 1e-300)
        step = max(1, _CHUNK // e.shape[0])
        for i in range(0, xa.size, step):
            ux = xa[i : i + step, None] - e[:, 0]
            uy = ya[i : i + step, None] - e[:, 1]
            f = np.clip((ux * dx + uy * dy) / den, 0.0, 1.0)
            best[i : i + step] = np.min(np.hypot(ux - f * dx, uy - f * dy), axis=1)
        return best

    def nearest_name(self, x: ArrayLike, y: ArrayLike) -> str:
        """The name of the constraint whose edge is nearest to any of the points."""
        xa, ya = (np.asarray(v, dtype=float).reshape(-1) for v in (x, y))
        if xa.size == 0 or self.edges.shape[0] == 0:
            return self.names[0]
        k = int(np.argmin(self.edge_distance(xa, ya)))
        e = self.edges
        dx, dy = e[:, 2] - e[:, 0], e[:, 3] - e[:, 1]
        ux, uy = xa[k] - e[:, 0], ya[k] - e[:, 1]
        f = np.clip((ux * dx + uy * dy) / np.maximum(dx * dx + dy * dy, 1e-300), 0.0, 1.0)
        j = int(np.argmin(np.hypot(ux - f * dx, uy - f * dy)))
        return self.names[int(self.owner[j])]

    def detour_m(self, a: tuple[float, float], b: tuple[float, float]) -> float:
        """Estimated extra length [m] of the way from ``a`` to ``b`` round what blocks the
        straight line: 0 when it is free, infinite when it leaves the boundary; else, for
        the worst obstacle crossing it, the two-piece path past its nearer side (its
        farthest vertex on that side from the line, at the obstacle's middle along it)."""
        import shapely

        if bool(self.segments_free(a[0], a[1], b[0], b[1])):
            return 0.0
        line = shapely.LineString([a, b])
        if self.inside is not None and not shapely.covers(self.inside, line):
            return math.inf
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        if self.blocked is None or length == 0.0:
            return 0.0
        ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
        worst = 0.0
        for part in shapely.get_parts(self.blocked):
            if not shapely.intersects(part, line):
                continue
            c = shapely.get_coordinates(shapely.convex_hull(part))
            u = (c[:, 0] - a[0]) * ux + (c[:, 1] - a[1]) * uy
            v = (c[:, 1] - a[1]) * ux - (c[:, 0] - a[0]) * uy
            w = min(max(float(v.max()), 0.0), max(float(-v.min()), 0.0))
            d1 = min(max(float(np.median(u)), 0.0), length)
            worst = max(worst, math.hypot(d1, w) + math.hypot(length - d1, w) - length)
        return worst

    def separated(self, a: tuple[float, float], b: tuple[float, float]) -> str | None:
        """The name of what separates the points ``a`` and ``b`` [m] (the constraint
        nearest to ``a`` round its part of free water), or None when one part of free
        water holds both (or either is not in free water: the routers report that)."""
        import shapely

        if not bool(np.all(self.points_free([a[0], b[0]], [a[1], b[1]]))):
            return None
        water = self.inside
        if water is None:
            assert self.blocked is not None
            x0, y0, x1, y1 = shapely.bounds(self.blocked)
            pad = 1000.0 + abs(a[0]) + abs(a[1]) + abs(b[0]) + abs(b[1])
            water = shapely.box(x0 - pad, y0 - pad, x1 + pad, y1 + pad)
        if self.blocked is not None:
            water = shapely.difference(water, self.blocked)
        for part in shapely.get_parts(water):
            if shapely.intersects_xy(part, *a):
                if shapely.intersects_xy(part, *b):
                    return None
                return self._enclosing(part)
        return None

    def _enclosing(self, part: Any) -> str:
        """The name of an obstacle whose edge bounds ``part`` (the boundary if none)."""
        import shapely

        e = self.edges
        lines = shapely.linestrings(np.stack([e[:, :2], e[:, 2:]], axis=1))
        touching = self.owner[shapely.distance(shapely.boundary(part), lines) < 1e-6]
        names = [self.names[int(k)] for k in np.unique(touching)]
        named = [n for n in names if n != BOUNDARY_NAME]
        return named[0] if named else BOUNDARY_NAME

    def describe(self) -> str:
        """``"obstacles 'a', 'b' and the race-area boundary"`` for messages."""
        named = [repr(n) for n in self.names if n != BOUNDARY_NAME]
        parts = [f"obstacle{'s' if len(named) > 1 else ''} " + ", ".join(named)] if named else []
        if BOUNDARY_NAME in self.names:
            parts.append(BOUNDARY_NAME)
        return " and ".join(parts)


BOUNDARY_RUN: Final = 1
"""Edges of the boundary per group of the segment test's bounding-box filter (one: the
boundary's box holds every point, an edge's box only those near it)."""
OBSTACLE_RUN: Final = 32
"""Most edges of an obstacle per group (a grown rectangle has 20: one group)."""


def _same(x: Any, y: Any) -> tuple[Any, Any]:
    """The identity change of frame (:meth:`Obstacles.moves_free`)."""
    return x, y


BOX_MARGIN_M: Final = 1e-3
"""Margin [m] of the groups' boxes seen in the frame of the moves
(:meth:`Obstacles.moves_free`): the change of frame rounds each point by far less."""


CORE_M: Final = 1e-3
"""Depth [m] of the core (:attr:`Obstacles.core_box`): far more than the rounding of the
orientation test, so a move that ends there crosses an edge by its arithmetic too."""


def _inner_box(grown: Any) -> tuple[float, float, float, float]:
    """A box inside the core of one grown obstacle (:data:`CORE_M` inside it): its
    bounding box shrunk towards a point inside it until the core holds it; NaN if no
    shrink of 1/64 or more fits."""
    import shapely

    core = shapely.buffer(grown, -CORE_M, quad_segs=QUAD_SEGS)
    if core.is_empty:
        return (math.nan,) * 4
    cx, cy = shapely.get_coordinates(shapely.point_on_surface(core))[0]
    x0, y0, x1, y1 = shapely.bounds(core)
    shapely.prepare(core)
    for f in (1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.35, 0.25, 0.125, 1.0 / 64):
        b = (cx + f * (x0 - cx), cy + f * (y0 - cy), cx + f * (x1 - cx), cy + f * (y1 - cy))
        if shapely.contains(core, shapely.box(*b)):
            return b
    return (math.nan,) * 4


def _padded(
    edges: NDArray[np.float64], bounds: NDArray[np.int64]
) -> tuple[NDArray[np.float64], tuple[NDArray[np.float64], ...]]:
    """``(G, K, 4)`` the edges of each group ``bounds[g]:bounds[g + 1]``, padded to the
    largest group's ``K`` (copies of the group's first edge), and their bounding boxes:
    ``xmin, ymin, xmax, ymax``, each ``(G, K)`` (NaN for the padding)."""
    width = np.diff(bounds)
    if width.size == 0:
        return np.zeros((0, 1, 4)), tuple(np.zeros((0, 1)) for _ in range(4))
    k = np.arange(int(width.max()))
    pad = k >= width[:, None]
    e = edges[bounds[:-1, None] + np.where(pad, 0, k)]
    box = (
        np.minimum(e[..., 0], e[..., 2]),
        np.minimum(e[..., 1], e[..., 3]),
        np.maximum(e[..., 0], e[..., 2]),
        np.maximum(e[..., 1], e[..., 3]),
    )
    for v in box:
        v[pad] = np.nan
    return e, box


def _first(owner: NDArray[np.int64], i: int) -> int:
    """Index of the first edge with the owner of edge ``i``."""
    return int(np.flatnonzero(owner == owner[i])[0])


def _cross_flat(a0: Any, b0: Any, a1: Any, b1: Any, e: NDArray[np.float64]) -> Any:
    """Which segments ``(a0, b0) -> (a1, b1)`` (shape (p,)) touch or cross their own edge
    ``e[k]`` (shape (p, 4)): both ends of each on either side of (or on) the other's
    line; collinear pairs meet only where their extents overlap."""
    ex0, ey0, ex1, ey1 = e[:, 0], e[:, 1], e[:, 2], e[:, 3]
    o1 = _orient(a0, b0, a1, b1, ex0, ey0)
    o2 = _orient(a0, b0, a1, b1, ex1, ey1)
    o3 = _orient(ex0, ey0, ex1, ey1, a0, b0)
    o4 = _orient(ex0, ey0, ex1, ey1, a1, b1)
    p12, p34 = o1 * o2, o3 * o4
    both = (p12 <= 0.0) & (p34 <= 0.0)
    maybe = np.flatnonzero(both & (p12 == 0.0) & (p34 == 0.0))  # holds every collinear pair
    if maybe.size:
        k = maybe[(o1[maybe] == 0.0) & (o2[maybe] == 0.0) & (o3[maybe] == 0.0) & (o4[maybe] == 0.0)]
        # collinear: they meet only where their extents overlap
        both[k] = (
            (np.minimum(a0[k], a1[k]) <= np.maximum(ex0[k], ex1[k]))
            & (np.maximum(a0[k], a1[k]) >= np.minimum(ex0[k], ex1[k]))
            & (np.minimum(b0[k], b1[k]) <= np.maximum(ey0[k], ey1[k]))
            & (np.maximum(b0[k], b1[k]) >= np.minimum(ey0[k], ey1[k]))
        )
    return both


def _orient(ax: Any, ay: Any, bx: Any, by: Any, cx: Any, cy: Any) -> Any:
    """Twice the signed area of the triangle ``a, b, c`` (> 0: counter-clockwise)."""
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


def land_obstacle(
    x: ArrayLike, y: ArrayLike, nan: ArrayLike, name: str = "land"
) -> tuple[str, Any] | None:
    """The NaN cells of a wind grid as one obstacle.

    Parameters
    ----------
    x, y : array
        Grid node coordinates [m] (course frame), 2-D ``(ny, nx)``.
    nan : array of bool
        ``(ny, nx)``: True where the grid has no wind at some time.
    name : str
        Name for messages.

    Returns
    -------
    tuple of (str, shapely geometry) or None
        None when no node is NaN.  Each NaN node blocks the box of one grid spacing
        round it: every point whose interpolation touches the node (axis-aligned boxes,
        so a rotated grid is covered with a margin of its rotation).
    """
    import shapely

    xa, ya = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    jj, ii = np.nonzero(np.asarray(nan, dtype=bool))
    if jj.size == 0:
        return None
    hx = float(np.max(np.abs(np.diff(xa, axis=1)))) if xa.shape[1] > 1 else 1.0
    hy = float(np.max(np.abs(np.diff(ya, axis=0)))) if ya.shape[0] > 1 else 1.0
    cx, cy = xa[jj, ii], ya[jj, ii]
    boxes = shapely.box(cx - hx, cy - hy, cx + hx, cy + hy)
    return name, shapely.union_all(boxes)


def land_filled(area: RaceArea, wind: Any) -> Any:
    """The wind to route in: with ``wind_land_is_obstacle`` and a gridded wind holding
    NaN (land) cells, a copy whose NaN nodes take the value of the nearest valid node.

    Routes stay out of the land (:func:`obstacles_for`), but the isochrone router's time
    to go samples the wind along the straight line to the target, which may cross it;
    the filled values serve only there: every point in free water lies a grid spacing or
    more from a NaN node, so its interpolated wind is unchanged.  Any other wind (or
    course) is returned as it is.
    """
    if not area.wind_land_is_obstacle:
        return wind
    from sailroute.wind.grid import GridWind  # (a gridded wind: the only one with land)

    if not isinstance(wind, GridWind):
        return wind
    u, v = np.asarray(wind.u, dtype=float), np.asarray(wind.v, dtype=float)
    nan = np.isnan(u) | np.isnan(v)
    if not nan.any() or nan.all():
        return wind
    from scipy.ndimage import distance_transform_edt

    fu, fv = u.copy(), v.copy()
    for k in range(u.shape[0]):
        if nan[k].any():
            _, (jj, ii) = distance_transform_edt(nan[k], return_indices=True)
            fu[k], fv[k] = u[k][jj, ii], v[k][jj, ii]
    return dataclasses.replace(wind, u=fu, v=fv, allow_nan=False)


def obstacles_for(area: RaceArea, wind: object = None) -> Obstacles | None:
    """The :class:`Obstacles` of a course's race area in the wind it is routed in.

    Parameters
    ----------
    area : RaceArea
        The course's ``boundary``, ``obstacles`` and ``wind_land_is_obstacle``.
    wind : WindField, optional
        With ``wind_land_is_obstacle``, a gridded wind
        (:class:`~sailroute.wind.grid.GridWind`) whose NaN cells become the obstacle
        ``"land"`` (:func:`land_obstacle`); any other wind adds none.

    Returns
    -------
    Obstacles or None
        None when the course constrains nothing.
    """
    extra = []
    if area.wind_land_is_obstacle:
        from sailroute.wind.grid import GridWind

        if isinstance(wind, GridWind):
            nan = np.isnan(np.asarray(wind.u, dtype=float)).any(axis=0)
            land = land_obstacle(wind.x, wind.y, nan)
            if land is not None:
                extra.append(land)
    return Obstacles.build(area, extra)
