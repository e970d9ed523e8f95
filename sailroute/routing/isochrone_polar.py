"""Polar tables of the isochrone kernel, and the lookups in them.

:func:`polar_tables` samples a polar once per polar object and heading step (cached,
keyed weakly on the polar): the boat speed on a grid of |TWA| and of TWS nodes, the VMG
angles and the VMG, the top speed and the polar's support (the best speed component
towards each direction).  :func:`_device_tables` puts them in the kernel's array module;
:func:`_support` (the polar support towards a direction) and :func:`_grid_speeds` (the
boat speed of the grid columns of a step) interpolate in them at each point's TWS.

Used by the driver (:mod:`sailroute.routing.isochrone`, which builds the tables of a
leg), :mod:`sailroute.routing.batch`, the time to go
(:mod:`~sailroute.routing.isochrone_togo`), the step inputs
(:mod:`~sailroute.routing.isochrone_inputs`) and the candidate kernel
(:mod:`~sailroute.routing.isochrone_kernel`).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.polar import Polar
from sailroute.numerics import clip, sorted_distinct
from sailroute.routing.isochrone_records import _StepInputs

# --------------------------------------------------------------------------------------
# polar tables (cached per polar and heading step)

TABLE_TWS_STEP_MS = 0.05
"""TWS spacing of the cached polar table of the grid candidates [m s⁻¹]."""


@dataclass(frozen=True, eq=False)
class PolarTables:
    """Polar sampled for the isochrone kernel.

    Attributes
    ----------
    twa_deg : ndarray, shape (n_a,)
        Grid of ``|TWA|`` [°], ``180/n_a, 2·180/n_a, ..., 180``.
    cos_a, sin_a : ndarray, shape (n_a,)
        Their cosine and sine.
    tws_ms : ndarray, shape (n_w,)
        TWS nodes [m s⁻¹]: every 0.05 m s⁻¹ from 0 to the polar's top TWS,
        plus the polar's own columns (so a bilinear polar is reproduced exactly).
    speed_ms : ndarray, shape (n_w, n_a)
        Boat speed at the nodes [m s⁻¹].
    up_deg, down_deg : ndarray, shape (n_w,)
        Upwind and downwind VMG angles [°] at the nodes.
    up_vmg_ms, down_vmg_ms : ndarray, shape (n_w,)
        The VMG there [m s⁻¹] (positive).
    vmax_ms : ndarray, shape (n_w,)
        Highest boat speed on the grid at the nodes [m s⁻¹].
    sup_beta_deg : ndarray, shape (n_b,)
        Directions ``beta`` [°] in ``[-180, 180]``, measured from the upwind direction
        towards one side (every 1°).
    sup_ms, sup_deg : ndarray, shape (n_w, n_b)
        Support of the polar: the largest speed component ``S(a) cos(a - beta)`` over
        the headings of that side [m s⁻¹], and the |TWA| ``a`` giving it [°] (grid
        maximum refined by a parabola, or a VMG angle).  Filled in blocks of
        :data:`SUPPORT_BLOCK` rows when first needed (:meth:`fill_support`; NaN before):
        a course in one wind reads a few rows of several hundred.
    sup_ready : ndarray of bool, shape (ceil(n_w / SUPPORT_BLOCK),)
        Which blocks of rows of ``sup_ms`` and ``sup_deg`` are filled.
    """

    twa_deg: NDArray[np.float64]
    cos_a: NDArray[np.float64]
    sin_a: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    speed_ms: NDArray[np.float64]
    up_deg: NDArray[np.float64]
    down_deg: NDArray[np.float64]
    up_vmg_ms: NDArray[np.float64]
    down_vmg_ms: NDArray[np.float64]
    vmax_ms: NDArray[np.float64]
    sup_beta_deg: NDArray[np.float64]
    sup_ms: NDArray[np.float64]
    sup_deg: NDArray[np.float64]
    sup_ready: NDArray[np.bool_]

    def fill_support(self, lo: int = 0, hi: int | None = None) -> PolarTables:
        """Fill the support rows ``lo`` to ``hi`` (both included; default: all) where
        they are still empty; returns ``self``.  Every block is computed as the whole
        table would be (:func:`_support_table`), so the numbers do not depend on the
        order in which rows are asked for."""
        last = self.tws_ms.shape[0] - 1 if hi is None else min(hi, self.tws_ms.shape[0] - 1)
        b0, b1 = max(lo, 0) // SUPPORT_BLOCK, last // SUPPORT_BLOCK + 1
        if self.sup_ready[b0:b1].all():
            return self
        for b in range(b0, b1):
            if not self.sup_ready[b]:
                r0, r1 = b * SUPPORT_BLOCK, min((b + 1) * SUPPORT_BLOCK, self.tws_ms.shape[0])
                self.sup_ms[r0:r1], self.sup_deg[r0:r1] = _support_table(
                    self.twa_deg,
                    self.speed_ms[r0:r1],
                    self.up_deg[r0:r1],
                    self.down_deg[r0:r1],
                    self.up_vmg_ms[r0:r1],
                    self.down_vmg_ms[r0:r1],
                    self.sup_beta_deg,
                )
                self.sup_ready[b] = True
        return self


SUPPORT_BLOCK = 64
"""Rows of :attr:`PolarTables.sup_ms` filled at a time [-]."""

_TABLE_CACHE: weakref.WeakKeyDictionary[Any, dict[int, PolarTables]] = weakref.WeakKeyDictionary()


def _vmg_angles(polar: Polar, tws: NDArray, upwind: bool) -> tuple[NDArray, NDArray]:
    a, v = polar.vmg_upwind(tws) if upwind else polar.vmg_downwind(tws)
    return np.asarray(a, dtype=float), np.asarray(v, dtype=float)


def polar_tables(polar: Polar, heading_step_deg: float) -> PolarTables:
    """Sample ``polar`` for the kernel (cached per polar object and TWA grid).

    Parameters
    ----------
    polar : Polar
        Boat polar.
    heading_step_deg : float
        Requested TWA step [°]; the grid uses ``n_a = ceil(180/step)`` equal steps.

    Returns
    -------
    PolarTables
    """
    n_a = max(2, math.ceil(180.0 / heading_step_deg - 1e-9))
    try:
        per_polar = _TABLE_CACHE.setdefault(polar, {})
    except TypeError:  # not weak-referenceable: no caching
        per_polar = {}
    cached = per_polar.get(n_a)
    if cached is not None:
        return cached
    a = np.linspace(180.0 / n_a, 180.0, n_a)
    own = np.asarray(polar.tws_ms, dtype=float).ravel()
    top = float(own.max()) if own.size and own.max() > 0 else 30.0
    nodes = sorted_distinct(
        np.concatenate(
            [
                np.linspace(0.0, top, math.ceil(top / TABLE_TWS_STEP_MS) + 1),
                own[(own >= 0) & (own <= top)],
            ]
        )
    )
    speed = np.asarray(polar.speed(nodes[:, None], a[None, :]), dtype=float)
    up, vu = _vmg_angles(polar, nodes, True)
    down, vd = _vmg_angles(polar, nodes, False)
    up = _backfill_calm(up, vu)
    down = _backfill_calm(down, vd)
    rad = np.radians(a)
    vmax = np.maximum(
        speed.max(axis=1), np.asarray(polar.speed(nodes, np.stack([up, down], 1).T)).max(axis=0)
    )
    vu, vd = np.maximum(vu, 0.0), np.maximum(vd, 0.0)
    beta = np.linspace(-180.0, 180.0, 361)
    empty = np.full((nodes.shape[0], beta.shape[0]), np.nan)
    tables = PolarTables(
        a,
        np.cos(rad),
        np.sin(rad),
        nodes,
        speed,
        up,
        down,
        vu,
        vd,
        vmax,
        beta,
        empty,
        empty.copy(),
        np.zeros(-(-nodes.shape[0] // SUPPORT_BLOCK), dtype=np.bool_),
    )
    per_polar[n_a] = tables
    return tables


def _support_table(
    a: NDArray,
    speed: NDArray,
    up: NDArray,
    down: NDArray,
    vu: NDArray,
    vd: NDArray,
    beta: NDArray,
) -> tuple[NDArray, NDArray]:
    """Largest speed component towards ``beta`` and its |TWA|, per TWS node of
    ``speed``'s rows (see :class:`PolarTables`); grid maxima refined by a parabola
    through their neighbours."""
    n_w, n_a = speed.shape
    cb, sb = np.cos(np.radians(beta)), np.sin(np.radians(beta))
    ca, sa = np.cos(np.radians(a)), np.sin(np.radians(a))
    cos_ab = ca[None, :] * cb[:, None] + sa[None, :] * sb[:, None]  # (n_b, n_a)
    val = np.empty((n_w, beta.size))
    ang = np.empty((n_w, beta.size))
    step = a[1] - a[0]
    for r0 in range(0, n_w, 64):
        r1 = min(n_w, r0 + 64)
        obj = speed[r0:r1, None, :] * cos_ab[None]  # (rows, n_b, n_a)
        k = np.argmax(obj, axis=2)
        f1 = np.take_along_axis(obj, k[..., None], 2)[..., 0]
        f0 = np.take_along_axis(obj, np.maximum(k - 1, 0)[..., None], 2)[..., 0]
        f2 = np.take_along_axis(obj, np.minimum(k + 1, n_a - 1)[..., None], 2)[..., 0]
        den = f0 - 2.0 * f1 + f2
        inner = (k > 0) & (k < n_a - 1) & (den < 0)
        off = np.where(inner, 0.5 * (f0 - f2) / np.where(inner, den, -1.0), 0.0)
        best, where = f1, a[k] + np.clip(off, -0.5, 0.5) * step
        for ang_c, v_c in ((up[r0:r1], vu[r0:r1]), (down[r0:r1], vd[r0:r1])):
            c = np.abs(np.cos(np.radians(ang_c)))
            v_c = np.where(c > 1e-9, v_c / np.where(c > 1e-9, c, 1.0), 0.0)  # VMG -> speed
            rc = np.radians(ang_c)[:, None]
            o = v_c[:, None] * (np.cos(rc) * cb[None, :] + np.sin(rc) * sb[None, :])
            better = o > best
            best = np.where(better, o, best)
            where = np.where(better, ang_c[:, None], where)
        val[r0:r1] = best
        ang[r0:r1] = where
    return val, ang


def _backfill_calm(angle: NDArray, vmg: NDArray) -> NDArray:
    """Replace the angle at calm nodes (no VMG) by the first windy node's angle."""
    ok = vmg > 0
    if not ok.any():
        return angle
    first = int(np.flatnonzero(ok)[0])
    out = angle.copy()
    out[:first] = angle[first]
    return out


# --------------------------------------------------------------------------------------
# the tables in the kernel's array module


@dataclass(frozen=True, eq=False)
class _DeviceTables:
    """The :class:`PolarTables` arrays in the kernel's array module ``xp`` (same units).

    ``n_w`` TWS nodes (rows), ``n_a`` grid |TWA|s, ``n_b`` support directions.
    """

    twa_deg: Any  # (n_a,) grid |TWA| [°]
    cos_a: Any  # (n_a,) its cosine
    sin_a: Any  # (n_a,) its sine
    tws_ms: Any  # (n_w,) TWS nodes [m s⁻¹]
    speed_ms: Any  # (n_w, n_a) boat speed [m s⁻¹]
    up_deg: Any  # (n_w,) upwind VMG angle [°]
    down_deg: Any  # (n_w,) downwind VMG angle [°]
    up_vmg_ms: Any  # (n_w,) upwind VMG [m s⁻¹]
    down_vmg_ms: Any  # (n_w,) downwind VMG [m s⁻¹]
    vmax_ms: Any  # (n_w,) highest boat speed [m s⁻¹]
    sup_ms: Any  # (n_w, n_b) polar support: best speed component [m s⁻¹]
    sup_deg: Any  # (n_w, n_b) the |TWA| giving it [°]
    # several polars (members with their own boat, stacked_tables): the first row of
    # each polar's TWS nodes and their number, shape (P,); None: one polar
    node_start: Any = None
    node_count: Any = None
    # the PolarTables whose sup_ms and sup_deg these are, filled on demand
    # (support_rows); None: filled in full
    lazy: PolarTables | None = None


def support_rows(dev: _DeviceTables, node: Any) -> None:
    """Fill the support rows ``node`` and ``node + 1`` of ``dev`` where still empty
    (:meth:`PolarTables.fill_support`), before a lookup there."""
    if dev.lazy is not None and node.shape[0]:
        dev.lazy.fill_support(int(node.min()), int(node.max()) + 1)


def stacked_tables(tabs: Sequence[PolarTables]) -> _DeviceTables:
    """The tables of several polars (on the same |TWA| grid) as one, NumPy: their TWS
    nodes one polar after the other (each point's rows stay within its own polar's,
    :func:`node_rows`), so that a lookup at a point's row reads its own polar's numbers."""
    first = tabs[0]

    def rows(name: str) -> NDArray:
        return np.concatenate([getattr(t.fill_support(), name) for t in tabs], axis=0)

    counts = np.array([t.tws_ms.shape[0] for t in tabs], dtype=np.int64)
    return _DeviceTables(
        first.twa_deg,
        first.cos_a,
        first.sin_a,
        rows("tws_ms"),
        rows("speed_ms"),
        rows("up_deg"),
        rows("down_deg"),
        rows("up_vmg_ms"),
        rows("down_vmg_ms"),
        rows("vmax_ms"),
        rows("sup_ms"),
        rows("sup_deg"),
        np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64),
        counts,
    )


def node_rows(tws: Any, dev: _DeviceTables, polar: Any, xp: ModuleType) -> Any:
    """Table row at or below each TWS [m s⁻¹] (the weight of the next row is its
    remainder), kept inside the table: ``polar`` the polar of each point (an index
    into :func:`stacked_tables`' polars) or None (one polar)."""
    nodes = dev.tws_ms
    if dev.node_start is None or polar is None:
        return clip(xp.searchsorted(nodes, tws, side="right") - 1, 0, nodes.shape[0] - 2, xp=xp)
    row = xp.empty(tws.shape, dtype=xp.int64)
    for p, (start, count) in enumerate(zip(dev.node_start, dev.node_count, strict=True)):
        sel = polar == p
        own = nodes[start : start + count]
        row[sel] = start + clip(
            xp.searchsorted(own, tws[sel], side="right") - 1, 0, count - 2, xp=xp
        )
    return row


class PointPolars:
    """The polars of a front whose points sail different boats (the members of
    :mod:`sailroute.routing.batch`): :meth:`speed` as :meth:`Polar.speed`, each point with
    its own polar.

    Parameters
    ----------
    polars : sequence of Polar
        The different polars.
    index : ndarray of int, shape (n,)
        Each point's polar (an index into ``polars``).
    """

    def __init__(self, polars: Sequence[Polar], index: NDArray[np.int64]) -> None:
        self.polars = tuple(polars)
        self.index = index

    def speed(self, tws_ms: Any, twa_deg: Any) -> NDArray[np.float64]:
        """Boat speed [m s⁻¹] as :meth:`Polar.speed`; the points are along the last axis
        of the broadcast arguments."""
        tws, twa = np.broadcast_arrays(np.asarray(tws_ms, dtype=float), np.asarray(twa_deg))
        out = np.empty(tws.shape)
        for p, polar in enumerate(self.polars):
            cols = np.flatnonzero(self.index == p)
            if cols.shape[0]:
                out[..., cols] = polar.speed(tws[..., cols], twa[..., cols])
        return out


def _device_tables(tab: PolarTables, xp: ModuleType) -> _DeviceTables:
    """``tab`` in ``xp``: NumPy shares its arrays (the support rows filled on demand,
    :func:`support_rows`), another module gets copies of the full tables."""
    if xp is not np:
        tab.fill_support()
    return _DeviceTables(
        xp.asarray(tab.twa_deg),
        xp.asarray(tab.cos_a),
        xp.asarray(tab.sin_a),
        xp.asarray(tab.tws_ms),
        xp.asarray(tab.speed_ms),
        xp.asarray(tab.up_deg),
        xp.asarray(tab.down_deg),
        xp.asarray(tab.up_vmg_ms),
        xp.asarray(tab.down_vmg_ms),
        xp.asarray(tab.vmax_ms),
        xp.asarray(tab.sup_ms),
        xp.asarray(tab.sup_deg),
        lazy=tab if xp is np else None,
    )


# --------------------------------------------------------------------------------------
# lookups in the tables at the points' TWS


def _support(
    node: Any, weight: Any, beta_deg: Any, dev: _DeviceTables, xp: ModuleType
) -> tuple[Any, Any]:
    """Polar support towards ``beta_deg`` (from the upwind direction, towards the side)
    at the table rows ``node, weight``: the best speed component [m s⁻¹] and its |TWA|
    [°], interpolated bilinearly in (TWS, beta) from :attr:`PolarTables.sup_ms`."""
    support_rows(dev, node)
    pos = (beta_deg + 180.0) * (dev.sup_ms.shape[1] - 1) / 360.0
    col = clip(xp.floor(pos).astype(xp.int64), 0, dev.sup_ms.shape[1] - 2, xp=xp)
    frac = clip(pos - col, 0.0, 1.0, xp=xp)
    out = []
    for tab in (dev.sup_ms, dev.sup_deg):
        below = tab[node, col] + frac * (tab[node, col + 1] - tab[node, col])
        above = tab[node + 1, col] + frac * (tab[node + 1, col + 1] - tab[node + 1, col])
        out.append(below + weight * (above - below))
    return out[0], out[1]


def _grid_speeds(c: _StepInputs, dev: _DeviceTables) -> Any:
    """Boat speed [m s⁻¹] of the grid columns, shape (rows, n_grid)."""
    node, weight = c.wind.row, c.wind.weight
    s_lo = dev.speed_ms[node, c.first : c.stop]
    return s_lo + weight[:, None] * (dev.speed_ms[node + 1, c.first : c.stop] - s_lo)
