"""A class polar learned from a fleet's steady sailing, at levels, with its uncertainty.

Pure array core of ``sailroute polar fit`` on several logs (``docs/polar-fit.md``).  The
input is a fleet's steady straight-line blocks (:mod:`sailroute.boat.learn_blocks`); the
output is a :class:`LearnedPolar`: one table per **level** (a percentile of the boats,
e.g. ``median`` = P50 and ``top`` = P90), each cell with its sample count, the boats that
sailed it, its uncertainty and a status (learned, refused with a reason, or empty), and a
sanity verdict.

Method
------
1. **Cells.** Each block goes to the nearest TWS node and the nearest TWA node (bin edges
   halfway); the angles the fleet beats and runs at are rows of their own
   (:func:`with_sailed_rows`).  Besides the table's cells, every upwind block (TWA below
   70°) is one sample of the boat's **upwind VMG** in its TWS column, and every downwind
   block (above 120°) of its downwind VMG (the point-of-sail bands of
   :mod:`sailroute.boat.efficiency`).
2. **A boat's speed in a cell** is the ``percentile`` (default the median) of its blocks'
   speeds there, weighted by duration; its VMG made good the :data:`VMG_PERCENTILE` of its
   blocks' VMG.  A block's speed is first moved to the cell's node along the current fit
   (``v P(node) / P(block)``, ratio clipped to 0.5-2, twice), so that a cell sailed on its
   fast side is not read as fast at its node.
3. **Levels across boats.**  ``log v[b, c] = p[c] + a[b, band(c)]``: a cell's speed is the
   cell's own value times the boat's factor on that point of sail (upwind, reach,
   downwind), fitted by weighted least squares (weights: blocks).  The level ``q`` of
   cell ``c`` is ``exp(p[c] + Q_q(a[., band(c)]))``: the ``q``-th percentile of the boats'
   factors, so that a cell sailed by some of the boats is placed as the whole fleet
   would sail it.  One boat: every level is that boat.
4. **Learned or refused.**  A cell is learned when at least ``min_boats`` boats and
   ``min_blocks`` blocks sailed it, its blocks' mean TWA and TWS lie within a quarter of
   the cell of its node (else the value at the node would be an extrapolation of data
   sailed elsewhere), and it is not a tail of the beat or the run (:func:`_tails`).  Every
   other cell with data is refused, with the reason.
5. **Finish.**  Along each TWA row the learned values are made non-decreasing in TWS
   except across drops larger than twice their combined uncertainty (as
   :func:`sailroute.boat.fit.fit_polar`); then **no cell promises more VMG than the fleet
   made good**: upwind cells are capped at ``VMG_up / cos(TWA)`` and downwind cells at
   ``VMG_down / |cos(TWA)|`` of their column's level, the cap falling as ``cos`` of the
   angle beyond the fleet's median beat (run) angle.  A wind-angle error sends samples
   sailed at the boats' best angle into the cells beside it; at a lower angle upwind (a
   deeper one downwind) they promise a VMG no boat sailed, and a router would take it.
   Rows and columns without a learned cell are left out, but for a guard row beside the
   lowest upwind and the highest downwind learned row (:func:`_guard`); refused and empty
   cells inside are filled (:func:`sailroute.boat.fit` step 5, or from a ``shape`` polar)
   and listed.
6. **Uncertainty.**  ``n_boot`` bootstrap replicates resample the boats and, within each
   boat, its blocks (time blocks), and repeat steps 2-5 on the same grid.  Per cell: the
   standard deviation of ``log v`` (a relative uncertainty) with the within-cell move of
   step 2 added in quadrature, the P10 and P90, and the replicates' leading modes (the
   correlation of cells along a row and across the table), from which
   :func:`draw_polars` draws whole polars.

The result is independent of the order of the boats and the blocks; the bootstrap is
seeded.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.boat.efficiency import BOUNDARIES_DEG, band_factors, efficiency_factor
from sailroute.boat.fit import _check_nodes, _edges, _extended, _fill, _monotone_in_tws
from sailroute.boat.learn_blocks import Blocks
from sailroute.boat.polar import Polar, fold_twa
from sailroute.errors import InputError
from sailroute.numerics import pchip

LEVELS: Final = MappingProxyType({"median": 50.0, "top": 90.0})
"""Default levels: name to percentile of the boats [%]."""
DEFAULT_LEVEL: Final = "median"
"""The level a learned polar file gives where none is named."""
N_BOOT: Final = 200
"""Bootstrap replicates."""
N_MODES: Final = 8
"""Leading modes of the bootstrap kept for drawing whole polars."""
TAIL_FRACTION: Final = 0.25
"""An upwind (downwind) cell with fewer blocks than this fraction of its column's beat
(run) row is a tail of it (:func:`_tails`)."""
TAIL_SPAN_DEG: Final = 15.0
"""Rows this close to a beat (run) row can hold its tail [°]: a wind-angle error of a
block rarely exceeds it."""
VMG_PERCENTILE: Final = 75.0
"""Percentile of a boat's own blocks' VMG that its VMG made good is taken at [%]: above
the median, since boats sail round their best angle and only a few blocks at it."""
MAX_CLASS_RATIO: Final = 1.3
"""A boat this much faster or slower than the rest of the fleet in the same cells (the
factor of step 3, over all points of sail) cannot be of the same class [-]."""
MAX_CLASS_RATIO_APART: Final = 2.5
"""The same for boats that share no cell with the others, compared by speed over TWS."""
_CLIP: Final = float(np.log(2.0))
_ITER: Final = 40
_CORRECTION_PASSES: Final = 2
_OFFSET_FRACTION: Final = 0.25
_SIGNIFICANT_Z: Final = 2.0
BAND_NAMES: Final = ("upwind", "reach", "downwind")


@dataclass(frozen=True, eq=False)
class LevelTable:
    """One level of a learned polar (SI units; arrays over the table's rows x columns).

    Attributes
    ----------
    name : str
        ``median``, ``top``, ``p75``...
    percentile : float
        Percentile of the boats [%].
    speed_ms : ndarray, shape (m, n)
        Boat speed at each node [m s⁻¹] (refused and empty cells filled).
    sd_log : ndarray, shape (m, n)
        Standard deviation of ``log speed`` over the bootstrap [-] (0.05: about 5 %).
    p10_ms, p90_ms : ndarray, shape (m, n)
        P10 and P90 of the speed over the bootstrap [m s⁻¹].
    modes : ndarray, shape (k, m, n)
        Leading modes of ``log speed`` over the bootstrap (each scaled to its standard
        deviation): a draw is ``speed exp(sum z_k modes[k] + resid_sd_log e)``.
    resid_sd_log : ndarray, shape (m, n)
        What the modes leave of ``sd_log`` (independent per cell).
    vmg_up_ms, vmg_down_ms : ndarray, shape (n,)
        The fleet's VMG made good at this level per column [m s⁻¹] (NaN: not learned).
    race_pace : (float, float, float) or None
        The fleet's pace over whole legs at this level against this table, upwind, reach
        and downwind (:mod:`sailroute.analysis.racepace`; None: learned without courses).
    pace_sd_log : float or None
        Standard deviation of ``log`` of a boat's pace over one leg about ``race_pace``
        in the races learned from [-] (boats, shifts and races together:
        :func:`sailroute.analysis.racepace.race_pace`; None: learned without courses).
    """

    name: str
    percentile: float
    speed_ms: NDArray[np.float64]
    sd_log: NDArray[np.float64]
    p10_ms: NDArray[np.float64]
    p90_ms: NDArray[np.float64]
    modes: NDArray[np.float64]
    resid_sd_log: NDArray[np.float64]
    vmg_up_ms: NDArray[np.float64]
    vmg_down_ms: NDArray[np.float64]
    race_pace: tuple[float, float, float] | None = None
    pace_sd_log: float | None = None


@dataclass(frozen=True)
class PolarDraw:
    """One version of a learned level's table, drawn from its uncertainty.

    A drawn table is ``speed exp(offset)`` with ``offset`` (:meth:`log_offset`) either
    ``sum_k modes_z[k] modes[k] + resid_sd_log cells_z + pace_z pace_sd_log`` (a random
    draw: the bootstrap's correlated modes, each cell's own rest, and a common pace
    factor for the legs' scatter about the race pace) or, with ``quantile_z`` set, every
    cell at the same quantile of its own spread, ``quantile_z sqrt(sd_log² +
    pace_sd_log²)`` (the table at its P10, P50, P90).

    Attributes
    ----------
    modes_z : tuple of float
        Coefficients of the level's modes (missing ones 0).
    cells_z : tuple of float
        Per cell (row-major), the standard normal of its rest (empty: 0).
    pace_z : float
        Standard normal of the pace factor.
    quantile_z : float or None
        Every cell at this many of its standard deviations instead.
    """

    modes_z: tuple[float, ...] = ()
    cells_z: tuple[float, ...] = ()
    pace_z: float = 0.0
    quantile_z: float | None = None

    def log_offset(self, t: LevelTable) -> NDArray[np.float64]:
        """The draw's ``log speed`` change of each cell of ``t``, shape ``t.speed_ms.shape``."""
        pace_sd = float(t.pace_sd_log or 0.0)
        if self.quantile_z is not None:
            return np.asarray(self.quantile_z * np.hypot(t.sd_log, pace_sd), dtype=float)
        k = min(len(self.modes_z), t.modes.shape[0])
        out = np.tensordot(np.asarray(self.modes_z[:k], dtype=float), t.modes[:k], axes=1)
        out = np.zeros(t.speed_ms.shape) + out
        if self.cells_z:
            e = np.asarray(self.cells_z, dtype=float)
            if e.size != t.speed_ms.size:
                raise InputError(
                    f"a polar draw of {e.size} cells for a table of {t.speed_ms.size}; "
                    "draw it for this table (PolarDraw.random)"
                )
            out = out + t.resid_sd_log * e.reshape(t.speed_ms.shape)
        return np.asarray(out + self.pace_z * pace_sd, dtype=float)

    @staticmethod
    def random(t: LevelTable, rng: np.random.Generator, first: float | None = None) -> PolarDraw:
        """A random draw for table ``t``; ``first``, if given, is the first mode's
        coefficient (a stratum of a Latin hypercube), the rest from ``rng``."""
        z = np.atleast_1d(rng.standard_normal(t.modes.shape[0]))
        if first is not None and z.size:
            z[0] = first
        e = rng.standard_normal(t.speed_ms.size)
        return PolarDraw(
            tuple(np.ravel(z).tolist()), tuple(np.ravel(e).tolist()), float(rng.standard_normal())
        )


@dataclass(frozen=True, eq=False)
class LearnedPolar:
    """A polar learned from a fleet (module docstring); what a learned polar file holds.

    Attributes
    ----------
    name : str
        Name of the polar.
    twa_deg : ndarray, shape (m,)
        TWA rows [°].
    tws_ms : ndarray, shape (n,)
        TWS columns [m s⁻¹].
    levels : mapping of str to LevelTable
        The tables by level name.
    blocks, boats : ndarray of int, shape (m, n)
        Steady blocks and boats per cell.
    seconds : ndarray, shape (m, n)
        Seconds of steady sailing per cell [s].
    status : ndarray of str, shape (m, n)
        ``learned``, ``refused`` or ``empty``.
    reasons : tuple of str
        One line per refused cell: where and why.
    verdict : tuple of str
        The sanity verdict: best VMG angles against the angles sailed, rows that fall
        with the wind, refused cells, the boats' factors.
    provenance : mapping
        Races, boats, wind sources, settings (JSON-ready).
    """

    name: str
    twa_deg: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    levels: Mapping[str, LevelTable]
    blocks: NDArray[np.int64]
    boats: NDArray[np.int64]
    seconds: NDArray[np.float64]
    status: NDArray[np.str_]
    reasons: tuple[str, ...]
    verdict: tuple[str, ...]
    provenance: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))

    def level(self, name: str | None = None) -> LevelTable:
        """The table of level ``name`` (default :data:`DEFAULT_LEVEL`, else the first).

        Raises
        ------
        InputError
            No such level (the message lists the levels).
        """
        key = name if name is not None else DEFAULT_LEVEL
        if key not in self.levels:
            if name is None:
                key = next(iter(self.levels))
            else:
                raise InputError(
                    f"learned polar {self.name!r}: no level {name!r}; its levels are "
                    + ", ".join(f"{k} (P{t.percentile:g})" for k, t in self.levels.items())
                )
        return self.levels[key]

    def polar(
        self, level: str | None = None, interpolation: str = "pchip", pace: str = "steady"
    ) -> Polar:
        """The :class:`Polar` of a level, named ``"<name> (<level>)"``.

        Parameters
        ----------
        level : str, optional
            Level name (default :data:`DEFAULT_LEVEL`).
        interpolation : {"pchip", "linear"}
        pace : {"steady", "race"}
            ``steady``: the table as learned from steady sailing; ``race``: scaled by the
            level's race pace per point of sail (as a course's ``efficiency``,
            :func:`sailroute.boat.efficiency.scale_polar`).

        Raises
        ------
        InputError
            Unknown level or pace, or ``race`` for a polar learned without courses.
        """
        t = self.level(level)
        base = Polar.from_arrays(
            self.twa_deg,
            self.tws_ms,
            t.speed_ms,
            name=f"{self.name} ({t.name})",
            interpolation=interpolation,
        )
        if pace == "steady":
            return base
        if pace != "race":
            raise InputError(f"pace: expected 'steady' or 'race'; got {pace!r}")
        if t.race_pace is None:
            raise InputError(
                f"learned polar {self.name!r}: level {t.name!r} has no race pace (it was "
                "learned without the races' courses, so no leg was timed); use pace: steady "
                "or learn it again with --course"
            )
        from sailroute.boat.efficiency import scale_polar

        return scale_polar(base, *t.race_pace, key="race pace").with_name(
            f"{self.name} ({t.name}, race pace)"
        )

    def with_race_pace(
        self,
        pace: Mapping[str, tuple[float, float, float]],
        sd_log: Mapping[str, float] | None = None,
    ) -> LearnedPolar:
        """The same polar with each named level's race pace (and its legs' scatter) set."""
        sd = dict(sd_log or {})
        levels = {
            k: replace(t, race_pace=pace.get(k, t.race_pace), pace_sd_log=sd.get(k, t.pace_sd_log))
            for k, t in self.levels.items()
        }
        return replace(self, levels=MappingProxyType(levels))

    def drawn(self, level: str | None, draw: PolarDraw) -> LearnedPolar:
        """The same polar with the table of ``level`` replaced by a draw of it
        (:class:`PolarDraw`; cells without speed stay 0)."""
        t = self.level(level)
        speed = np.where(t.speed_ms > 0, t.speed_ms * np.exp(draw.log_offset(t)), 0.0)
        return replace(
            self, levels=MappingProxyType({**self.levels, t.name: replace(t, speed_ms=speed)})
        )


@dataclass(frozen=True, eq=False)
class LearnFit:
    """:func:`learn_polar`'s result: the learned polar and what it came from.

    Attributes
    ----------
    learned : LearnedPolar
    blocks : Blocks
        The blocks given.
    cell : ndarray of int
        Per block, its cell ``i * n + j`` on the full grid of nodes given (-1: outside the
        TWS bins).
    factors : ndarray, shape (boats, 3)
        Each boat's speed factor [-] upwind, reach and downwind against the fleet's cells
        (NaN: no block there).
    """

    learned: LearnedPolar
    blocks: Blocks
    cell: NDArray[np.int64]
    factors: NDArray[np.float64]


def parse_levels(text: str | Mapping[str, float] | None) -> dict[str, float]:
    """Levels from ``"median=50,top=90"`` (or ``"50,90"``: named ``median``, ``top`` and
    ``p<q>``), or a mapping.

    Raises
    ------
    InputError
        A percentile outside (0, 100], a repeated name, or nothing.
    """
    if text is None:
        return dict(LEVELS)
    items: list[tuple[str, Any]] = (
        list(text.items())
        if isinstance(text, Mapping)
        else [
            (k.strip(), v) if sep else ("", k)
            for k, sep, v in (p.partition("=") for p in text.split(",") if p.strip())
        ]
    )
    out: dict[str, float] = {}
    for name, val in items:
        try:
            q = float(val)
        except (TypeError, ValueError):
            q = float("nan")
        if not 0.0 < q <= 100.0:
            raise InputError(
                f"--levels: {val!r} is not a percentile in (0, 100]; give e.g. 'median=50,top=90'"
            )
        key = name or {50.0: "median", 90.0: "top"}.get(q, f"p{q:g}")
        if key in out:
            raise InputError(f"--levels: level {key!r} given twice; give each name once")
        out[key] = q
    if not out:
        raise InputError("--levels: no level given; give e.g. 'median=50,top=90'")
    return out


def with_sailed_rows(twa_nodes: NDArray, blocks: Blocks) -> NDArray[np.float64]:
    """TWA rows plus the angles the fleet sails upwind and downwind.

    A boat beats and runs near its best VMG angle, so most of a fleet's steady sailing
    lies in two narrow bands of TWA; their duration-weighted medians (blocks below 70°
    and above 120°, rounded to 0.5°) become rows of their own, and the given rows closer
    to them than half the rows' median spacing are left out (0 and 180° stay).  A band
    of wind-angle error of a few degrees then spreads the samples round a row where
    they were sailed, instead of across two rows that neither was sailed at (where the
    cell below would read the faster angle's speed and the cell above the slower one's).
    """
    nodes = np.asarray(twa_nodes, dtype=float)
    a = fold_twa(blocks.twa_deg)
    b1, b2 = BOUNDARIES_DEG
    step = float(np.median(np.diff(nodes))) if nodes.size > 1 else 10.0
    add = []
    for sel in (a < b1, a > b2):
        if sel.sum() >= 3:
            o = np.argsort(a[sel])
            cw = np.cumsum(blocks.dur_s[sel][o])
            add.append(round(2.0 * float(a[sel][o][np.searchsorted(cw, 0.5 * cw[-1])])) / 2.0)
    if not add:
        return nodes
    keep = [v for v in nodes if v in (0.0, 180.0) or all(abs(v - x) >= 0.5 * step for x in add)]
    return np.unique(np.concatenate([keep, add]))


# --- weighted quantiles --------------------------------------------------------------


def _group_quantile(
    g: NDArray[np.int64], v: NDArray, w: NDArray, n: int, q: float
) -> NDArray[np.float64]:
    """Weighted ``q``-quantile of ``v`` per group (interpolated between the weight
    midpoints); ``g`` sorted, ``v`` sorted within each group, ``w > 0``.  NaN for empty
    groups."""
    out = np.full(n, np.nan)
    if g.size == 0:
        return out
    tot = np.bincount(g, w, minlength=n)
    cnt = np.bincount(g, minlength=n)
    first = np.concatenate([[0], np.cumsum(cnt)[:-1]])
    cw = np.cumsum(w)
    base = cw - w
    key = g + (base + 0.5 * w - base[first[g]]) / tot[g]
    has = np.flatnonzero(cnt)
    target = has + q
    k = np.searchsorted(key, target, side="right") - 1
    lo_i, hi_i = first[has], first[has] + cnt[has] - 1
    k = np.clip(k, lo_i, hi_i)
    k1 = np.minimum(k + 1, hi_i)
    span = key[k1] - key[k]
    frac = np.where(span > 0, np.clip((target - key[k]) / np.where(span > 0, span, 1.0), 0, 1), 0)
    frac = np.where(target < key[lo_i], 0.0, frac)
    out[has] = v[k] + frac * (v[k1] - v[k])
    return out


def _wpercentile(x: NDArray, mult: NDArray, q: float) -> float:
    """Percentile ``q`` [%] of ``x`` with integer multiplicities (linear, as numpy)."""
    return float(np.percentile(np.repeat(x, mult), q))


# --- the fit ------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class _Design:
    """The entries (block, cell, log value) and the grid."""

    twa_n: NDArray[np.float64]
    tws_n: NDArray[np.float64]
    cell: NDArray[np.int64]  # per block, -1 outside
    e_block: NDArray[np.int64]
    e_cell: NDArray[np.int64]
    e_log: NDArray[np.float64]  # log speed or log VMG as sailed
    e_kind: NDArray[np.int64]  # 0 cell, 1 vmg up, 2 vmg down
    band: NDArray[np.int64]  # per cell (incl. the 2n VMG cells)
    n_boats: int
    sailed_up: NDArray[np.float64]  # per column: median upwind TWA sailed (NaN: none)
    sailed_dn: NDArray[np.float64]  # per column: median downwind TWA sailed
    shape_polar: Polar | None = None

    @property
    def shape(self) -> tuple[int, int]:
        return self.twa_n.size, self.tws_n.size

    @property
    def n_cells(self) -> int:
        return self.twa_n.size * self.tws_n.size + 2 * self.tws_n.size


def _sailed(col: NDArray, a: NDArray, w: NDArray, sel: NDArray, n: int) -> NDArray[np.float64]:
    """Per column, the duration-weighted median of the angles ``a`` where ``sel``."""
    out = np.full(n, np.nan)
    for j in range(n):
        k = sel & (col == j)
        if k.any():
            o = np.argsort(a[k])
            cw = np.cumsum(w[k][o])
            out[j] = float(a[k][o][np.searchsorted(cw, 0.5 * cw[-1])])
    return out


def _design(blocks: Blocks, twa_n: NDArray, tws_n: NDArray, shape: Polar | None = None) -> _Design:
    a = fold_twa(blocks.twa_deg)
    m, n = twa_n.size, tws_n.size
    tws_e, twa_e = _edges(tws_n), _edges(twa_n, lo=0.0, hi=180.0)
    inside = (blocks.tws_ms >= tws_e[0]) & (blocks.tws_ms <= tws_e[-1]) & (blocks.speed_ms > 0)
    i = np.clip(np.searchsorted(twa_e, a, side="right") - 1, 0, m - 1)
    j = np.clip(np.searchsorted(tws_e, blocks.tws_ms, side="right") - 1, 0, n - 1)
    cell = np.where(inside, i * n + j, -1)
    idx = np.flatnonzero(inside)
    b1, b2 = BOUNDARIES_DEG
    c = np.cos(np.radians(a))
    v = blocks.speed_ms
    up = idx[(a[idx] < b1) & (c[idx] > 0)]
    dn = idx[(a[idx] > b2) & (c[idx] < 0)]
    e_block = np.concatenate([idx, up, dn])
    e_cell = np.concatenate([cell[idx], m * n + j[up], m * n + n + j[dn]])
    e_log = np.log(np.concatenate([v[idx], v[up] * c[up], -v[dn] * c[dn]]))
    e_kind = np.concatenate([np.zeros(idx.size), np.ones(up.size), np.full(dn.size, 2)])
    band = np.concatenate(
        [np.repeat(np.digitize(twa_n, BOUNDARIES_DEG), n), np.zeros(n), np.full(n, 2)]
    ).astype(np.int64)
    w = blocks.dur_s
    return _Design(
        twa_n,
        tws_n,
        cell.astype(np.int64),
        e_block,
        e_cell.astype(np.int64),
        e_log,
        e_kind.astype(np.int64),
        band,
        len(blocks.boats),
        _sailed(j, a, w, inside & (a < b1), n),
        _sailed(j, a, w, inside & (a > b2), n),
        shape,
    )


def _correction(d: _Design, blocks: Blocks, prov: Polar) -> NDArray[np.float64]:
    """Per entry: ``log`` of the move of its value to its cell's node along ``prov``."""
    m, n = d.shape
    b = d.e_block
    tws, twa = blocks.tws_ms[b], fold_twa(blocks.twa_deg[b])
    col = np.where(d.e_kind == 0, d.e_cell % n, (d.e_cell - m * n) % n)
    node_tws = d.tws_n[col]
    out = np.zeros(b.size)
    k0 = d.e_kind == 0
    with np.errstate(divide="ignore", invalid="ignore"):
        r = prov.speed(node_tws[k0], d.twa_n[d.e_cell[k0] // n]) / prov.speed(tws[k0], twa[k0])
        out[k0] = np.log(r)
        for kind, fn in ((1, prov.vmg_upwind), (2, prov.vmg_downwind)):
            k = d.e_kind == kind
            if k.any():
                out[k] = np.log(fn(node_tws[k])[1] / fn(tws[k])[1])
    return np.clip(np.where(np.isfinite(out), out, 0.0), -_CLIP, _CLIP)


@dataclass(frozen=True, eq=False)
class _Cells:
    """Per boat and cell: the boat's value and weight (one fit or one replicate)."""

    value: NDArray[np.float64]  # (boats, cells) log, NaN where none
    weight: NDArray[np.float64]  # (boats, cells) blocks (x multiplicity), 0 where none


def _boat_cells(
    d: _Design, blocks: Blocks, e_log: NDArray, e_w: NDArray, q: float, order: NDArray | None
) -> _Cells:
    """The boats' ``q``-quantile per table cell and :data:`VMG_PERCENTILE` per VMG cell
    (``e_w``: each entry's weight, 0 = left out)."""
    nc = d.n_cells
    g = blocks.boat[d.e_block] * nc + d.e_cell
    if order is None:
        order = np.lexsort((e_log, g))
    o = order[e_w[order] > 0]
    dur = blocks.dur_s[d.e_block]
    n = d.n_boats * nc
    val = _group_quantile(g[o], e_log[o], e_w[o] * dur[o], n, q)
    vmg = _group_quantile(g[o], e_log[o], e_w[o] * dur[o], n, VMG_PERCENTILE / 100.0)
    is_vmg = np.arange(n) % nc >= d.shape[0] * d.shape[1]
    val = np.where(is_vmg, vmg, val)
    wt = np.bincount(g, e_w, minlength=n).astype(float)
    return _Cells(val.reshape(d.n_boats, nc), wt.reshape(d.n_boats, nc))


def _factor_fit(c: _Cells, band: NDArray) -> tuple[NDArray, NDArray]:
    """``log v[b, c] = p[c] + a[b, band(c)]`` by weighted least squares (alternating)."""
    w = c.weight
    has = w > 0
    m = np.where(has, c.value, 0.0)
    a = np.zeros((w.shape[0], 3))
    p = np.zeros(w.shape[1])
    onehot = band[None, :] == np.arange(3)[:, None]  # (3, cells)
    ws = w.sum(0)
    den = w @ onehot.T  # (boats, 3)
    for _ in range(_ITER):
        p = (w * (m - a[:, band])).sum(0) / np.where(ws > 0, ws, 1.0)
        num = (w * (m - p[None, :])) @ onehot.T
        a = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    return np.where(ws > 0, p, np.nan), np.where(den > 0, a, np.nan)


def _levels(c: _Cells, band: NDArray, qs: list[float], mult: NDArray) -> tuple[NDArray, NDArray]:
    """Per level and cell: ``p + Q_q(a)`` (log); and the boat factors (boats, 3)."""
    p, a = _factor_fit(c, band)
    out = np.full((len(qs), p.size), np.nan)
    for k in range(3):
        ok = np.isfinite(a[:, k]) & (mult > 0)
        if not ok.any():
            continue
        cols = band == k
        for li, q in enumerate(qs):
            out[li, cols] = p[cols] + _wpercentile(a[ok, k], mult[ok], q)
    return out, a


def _finish(
    lv: NDArray,
    learned: NDArray[np.bool_],
    se_log: NDArray,
    d: _Design,
    rows: NDArray[np.bool_],
    cols: NDArray[np.bool_],
    weight: NDArray,
) -> tuple[NDArray, NDArray, NDArray, list[str]]:
    """One level's table on the kept rows/columns: monotone in TWS, VMG cap, fill.

    Returns the table [m s⁻¹], the VMG targets up/down per column and the kept drops.
    """
    m, n = d.shape
    v = np.where(learned, np.exp(lv[: m * n].reshape(m, n)), np.nan)
    vmg_up = np.exp(lv[m * n : m * n + n])
    vmg_dn = np.exp(lv[m * n + n :])
    se = np.where(learned, se_log * v, np.nan)
    mono = _monotone_in_tws(v, weight, se)
    drops = []
    for i in range(m):
        js = np.flatnonzero(np.isfinite(mono[i]))
        for a, b in itertools.pairwise(js):
            if mono[i, b] < mono[i, a] - 1e-9:
                drops.append(f"{d.twa_n[i]:g}:{a}:{b}")
    capped = _cap(mono, d.twa_n, vmg_up, vmg_dn, d.sailed_up, d.sailed_dn)
    sub = capped[np.ix_(rows, cols)]
    tw, ta = d.tws_n[cols], d.twa_n[rows]
    if d.shape_polar is not None:
        sub = _from_shape(sub, d.shape_polar, tw, ta)
    tab = _fill(sub, tw, ta)
    tab = _cap(tab, ta, vmg_up[cols], vmg_dn[cols], d.sailed_up[cols], d.sailed_dn[cols])
    tab = _guard(tab, ta, np.asarray(learned[np.ix_(rows, cols)].any(axis=1), dtype=bool))
    return tab, vmg_up[cols], vmg_dn[cols], drops


def _guard(tab: NDArray, twa: NDArray, has: NDArray[np.bool_]) -> NDArray:
    """Rows below the lowest upwind and above the highest downwind learned row: no more
    VMG than that row's times ``cos²`` of the angle between them, and lowered further
    (3 % a step) until the table's PCHIP curve has no better VMG between them than at
    the learned row: the taper beyond the angles the fleet sailed does not move the best
    VMG angle away from them."""
    out = tab.copy()
    idx = np.flatnonzero(has)
    if idx.size == 0:
        return out
    c = np.cos(np.radians(twa))
    for edge, g in ((idx[0], idx[0] - 1), (idx[-1], idx[-1] + 1)):
        if not 0 <= g < twa.size or c[edge] * c[g] <= 1e-12:
            continue
        lim = tab[edge] * abs(c[edge] / c[g]) * np.cos(np.radians(twa[edge] - twa[g])) ** 2
        out[g] = np.minimum(out[g], lim)
        lo, hi = sorted((float(twa[g]), float(twa[edge])))
        grid = np.linspace(lo, hi, 41)
        sign = np.sign(c[edge])
        for _ in range(20):
            curve = pchip(twa, out, grid, axis=0)  # (41, n)
            vmg = curve * (sign * np.cos(np.radians(grid)))[:, None]
            bad = vmg.max(axis=0) > out[edge] * abs(c[edge]) * (1.0 + 1e-6)
            if not bad.any():
                break
            out[g] = np.where(bad, out[g] * 0.97, out[g])
    return out


def _from_shape(sub: NDArray, shape: Polar, tws: NDArray, twa: NDArray) -> NDArray:
    """Cells without a learned value from ``shape``, scaled per point of sail by the
    median of the learned cells' ratios to it
    (:func:`sailroute.boat.efficiency.band_factors`)."""
    ref = shape.speed(tws[None, :], twa[:, None])
    have = np.isfinite(sub) & (ref > 0.05)
    if not have.any():
        return sub
    a = np.broadcast_to(twa[:, None], sub.shape)
    factor, _ = band_factors(a[have], sub[have] / ref[have], percentile=50.0, min_count=1)
    f = efficiency_factor(a, *factor)
    return np.where(np.isfinite(sub), sub, ref * f)


def _cap(
    tab: NDArray,
    twa: NDArray,
    vmg_up: NDArray,
    vmg_dn: NDArray,
    sailed_up: NDArray,
    sailed_dn: NDArray,
) -> NDArray:
    """Cap upwind cells at ``VMG_up / cos(TWA)`` and downwind at ``VMG_down / |cos|``;
    below the fleet's median upwind angle (above its median downwind angle) the VMG cap
    falls as ``cos`` of the angle off it (a beat's VMG falls off at least that fast)."""
    a = twa[:, None]
    c = np.cos(np.radians(a))
    with np.errstate(divide="ignore", invalid="ignore"):
        off_up = np.where(a < sailed_up[None, :], np.cos(np.radians(sailed_up[None, :] - a)), 1.0)
        off_dn = np.where(a > sailed_dn[None, :], np.cos(np.radians(a - sailed_dn[None, :])), 1.0)
        lim = np.where(
            c > 1e-6,
            vmg_up[None, :] * np.nan_to_num(off_up, nan=1.0) / c,
            np.where(c < -1e-6, vmg_dn[None, :] * np.nan_to_num(off_dn, nan=1.0) / -c, np.inf),
        )
    lim = np.where(np.isfinite(lim), lim, np.inf)
    return np.where(np.isfinite(tab), np.minimum(tab, lim), tab)


def learn_polar(
    blocks: Blocks,
    *,
    tws_bins_ms: ArrayLike,
    twa_bins_deg: ArrayLike,
    levels: Mapping[str, float] | None = None,
    percentile: float = 50.0,
    min_boats: int | None = None,
    min_blocks: int = 3,
    n_boot: int = N_BOOT,
    seed: int = 0,
    name: str = "learned",
    options: Mapping[str, str] | None = None,
    provenance: Mapping[str, Any] | None = None,
    shape: Polar | None = None,
    sailed_rows: bool = True,
) -> LearnFit:
    """Learn a polar at levels from a fleet's steady blocks (module docstring).

    Parameters
    ----------
    blocks : Blocks
        The fleet's steady blocks (:func:`sailroute.boat.learn_blocks.steady_blocks`).
    tws_bins_ms : array_like
        TWS nodes [m s⁻¹], strictly increasing, > 0.
    twa_bins_deg : array_like
        TWA nodes [°], strictly increasing within [0, 180].
    levels : mapping of str to float, optional
        Level name to percentile of the boats [%]; default :data:`LEVELS`.
    percentile : float
        Percentile of a boat's own blocks in a cell [%] (50: its typical speed).
    min_boats : int, optional
        Boats a cell needs to be learned; default 2 (1 for a fleet of one).
    min_blocks : int
        Blocks a cell needs to be learned.
    n_boot : int
        Bootstrap replicates (0: no uncertainty).
    seed : int
        Seed of the bootstrap.
    name : str
        Name of the polar.
    options : mapping of str to str, optional
        What the messages call ``min_boats``, ``min_blocks``, ``percentile``,
        ``tws_bins_ms``, ``twa_bins_deg`` (a command line's options).
    provenance : mapping, optional
        Added to the learned polar's provenance (races, wind sources...).
    shape : Polar, optional
        A polar whose shape fills the table's cells without a learned value, scaled per
        point of sail to the learned cells; every requested row and column is kept.
        Without it, rows and columns without a learned cell are left out and the other
        cells are filled from the learned ones.
    sailed_rows : bool
        Add the angles the fleet sails upwind and downwind as rows
        (:func:`with_sailed_rows`).

    Returns
    -------
    LearnFit

    Raises
    ------
    InputError
        Bad options, a fleet smaller than ``min_boats``, boats whose speeds cannot be one
        class, or no cell learned (the message gives the counts).
    """
    named = dict(options or {})

    def label(p: str) -> str:
        return named.get(p, f"learn_polar: {p}")

    if blocks.size == 0:
        raise InputError(
            f"no steady straight-line sailing in {blocks.n_samples} samples (dropped: "
            + ", ".join(f"{k} {v}" for k, v in blocks.dropped.items())
            + "); give longer logs or the races' courses"
        )
    tws_n = _check_nodes(tws_bins_ms, label("tws_bins_ms"), lo=0.0, hi=np.inf, strict_lo=True)
    twa_n = _check_nodes(twa_bins_deg, label("twa_bins_deg"), lo=0.0, hi=180.0, strict_lo=False)
    lv_map = parse_levels(levels)
    nb = len(blocks.boats)
    mb = min(2, nb) if min_boats is None else min_boats
    _check_counts(label, percentile, mb, min_blocks, n_boot, blocks.boats)
    if sailed_rows:
        twa_n = with_sailed_rows(twa_n, blocks)
    d = _design(blocks, twa_n, tws_n, shape)
    _check_one_class(d, blocks)
    sup = _support(d, blocks, mb, min_blocks)
    if not sup.learned.any():
        raise InputError(
            f"no TWS/TWA cell was sailed by {mb} boat(s) in {min_blocks} steady blocks "
            f"({blocks.size} blocks of {nb} boat(s); most in one cell: {int(sup.cnt.max())}); "
            f"give longer logs, wider bins (fewer TWS nodes: {label('tws_bins_ms')}, a larger "
            f"TWA step: {label('twa_bins_deg')}) or lower {label('min_boats')} / "
            f"{label('min_blocks')}"
        )
    rows, cols = _kept(sup.learned, twa_n, shape is not None)
    qs = list(lv_map.values())
    lv, factors, e_log = _point(d, blocks, sup, percentile / 100.0, qs, rows, cols)
    reps = _bootstrap(d, blocks, sup, e_log, percentile / 100.0, qs, rows, cols, n_boot, seed)
    tables: dict[str, LevelTable] = {}
    verdict: list[str] = []
    sub = np.ix_(rows, cols)
    zero_se = np.zeros(d.shape)
    for li, (lname, pq) in enumerate(lv_map.items()):
        rep = np.asarray(reps[li]) if reps[li] else np.empty((0, rows.sum(), cols.sum()))
        first = _finish(lv[li], sup.learned, zero_se, d, rows, cols, sup.weight)[0]
        sd_full = np.zeros(d.shape)
        sd_full[sub] = _spread(rep, first)
        tab, vu, vd, drops = _finish(lv[li], sup.learned, sd_full, d, rows, cols, sup.weight)
        move = _move(
            tab, twa_n[rows], tws_n[cols], sup.a_mean[sub], sup.w_mean[sub], sup.learned[sub]
        )
        tables[lname] = _level_table(lname, pq, tab, rep, vu, vd, move)
        verdict += [f"{lname}: {x}" for x in _drops_text(drops, tws_n)]
    st, reasons = _status(sup, d, mb, min_blocks)
    learned_polar = LearnedPolar(
        name=name,
        twa_deg=twa_n[rows].copy(),
        tws_ms=tws_n[cols].copy(),
        levels=MappingProxyType(tables),
        blocks=sup.cnt[sub].astype(np.int64),
        boats=sup.nboats[sub].astype(np.int64),
        seconds=sup.secs[sub].astype(float),
        status=st[sub],
        reasons=reasons,
        verdict=(),
        provenance=MappingProxyType(
            {
                "boats": list(blocks.boats),
                "races": list(blocks.races),
                "wind_sources": list(blocks.sources),
                "percentile": percentile,
                "levels": dict(lv_map),
                "min_boats": mb,
                "min_blocks": min_blocks,
                "n_boot": n_boot,
                "seed": seed,
                "blocks": blocks.size,
                "samples": blocks.n_samples,
                "dropped": dict(blocks.dropped),
                "left_out_tws_ms": tws_n[~cols].tolist(),
                "left_out_twa_deg": twa_n[~rows].tolist(),
                **dict(provenance or {}),
            }
        ),
    )
    learned_polar = replace(
        learned_polar, verdict=tuple(verdict) + sanity_verdict(learned_polar, blocks, factors)
    )
    return LearnFit(learned_polar, blocks, d.cell, np.exp(factors))


def _check_counts(
    label: Callable[[str], str],
    percentile: float,
    min_boats: int,
    min_blocks: int,
    n_boot: int,
    boats: tuple[str, ...],
) -> None:
    """The options' ranges, and a fleet at least ``min_boats`` strong."""
    if not 0.0 < percentile <= 100.0:
        raise InputError(f"{label('percentile')} must be in (0, 100], e.g. 50; got {percentile}")
    for p, v, lo in (
        ("min_boats", min_boats, 1),
        ("min_blocks", min_blocks, 1),
        ("n_boot", n_boot, 0),
    ):
        if int(v) != v or v < lo:
            raise InputError(f"{label(p)} must be a whole number >= {lo}; got {v}")
    if min_boats > len(boats):
        raise InputError(
            f"{label('min_boats')} {min_boats}: the fleet has {len(boats)} boat(s) "
            f"({', '.join(boats)}); no cell can be sailed by {min_boats} boats: give more "
            f"logs or a lower {label('min_boats')}"
        )


@dataclass(frozen=True, eq=False)
class _Support:
    """What each cell was sailed with (the same for every level); arrays (m, n)."""

    cnt: NDArray[np.int64]
    secs: NDArray[np.float64]
    nboats: NDArray[np.int64]
    a_mean: NDArray[np.float64]
    w_mean: NDArray[np.float64]
    offset: NDArray[np.float64]
    w_off: NDArray[np.float64]
    tail: NDArray[np.int64]
    learned: NDArray[np.bool_]
    vmg_ok: NDArray[np.bool_]  # (2n,)

    @property
    def weight(self) -> NDArray[np.float64]:
        return self.cnt.astype(float)

    @property
    def mask(self) -> NDArray[np.bool_]:
        """Per cell of the design (table cells, then the 2n VMG cells): usable."""
        return np.concatenate([self.learned.ravel(), self.vmg_ok])


def _support(d: _Design, blocks: Blocks, min_boats: int, min_blocks: int) -> _Support:
    """Blocks, seconds, boats, mean angle and wind per cell, and which are learned."""
    m, n = d.shape
    real = d.e_kind == 0
    eb, ec = d.e_block[real], d.e_cell[real]
    dur = blocks.dur_s[eb]
    cnt = np.bincount(ec, minlength=m * n).reshape(m, n)
    secs = np.bincount(ec, dur, minlength=m * n).astype(float).reshape(m, n)
    pair = np.unique(blocks.boat[eb] * (m * n) + ec)
    nboats = np.bincount(pair % (m * n), minlength=m * n).reshape(m, n)
    a_sum = np.bincount(ec, dur * fold_twa(blocks.twa_deg[eb]), m * n).reshape(m, n)
    w_sum = np.bincount(ec, dur * blocks.tws_ms[eb], m * n).reshape(m, n)
    with np.errstate(invalid="ignore", divide="ignore"):
        a_mean = np.asarray(a_sum / secs, dtype=float)
        w_mean = np.asarray(w_sum / secs, dtype=float)
    offset = a_mean - d.twa_n[:, None]
    w_off = w_mean - d.tws_n[None, :]
    tail = _tails(cnt, d.twa_n)
    width_a = np.diff(_edges(d.twa_n, lo=0.0, hi=180.0))[:, None]
    width_w = np.diff(_edges(d.tws_n))[None, :]
    learned = (
        (nboats >= min_boats)
        & (cnt >= min_blocks)
        & (np.abs(offset) <= _OFFSET_FRACTION * width_a)
        & (np.abs(w_off) <= _OFFSET_FRACTION * width_w)
        & (tail < 0)
    )
    vc = d.e_cell[~real] - m * n
    vcnt = np.bincount(vc, minlength=2 * n)
    vpair = np.unique(blocks.boat[d.e_block[~real]] * (2 * n) + vc)
    vboats = np.bincount(vpair % (2 * n), minlength=2 * n)
    return _Support(
        cnt.astype(np.int64),
        secs,
        nboats.astype(np.int64),
        a_mean,
        w_mean,
        offset,
        w_off,
        tail,
        np.asarray(learned, dtype=bool),
        np.asarray((vboats >= min_boats) & (vcnt >= min_blocks), dtype=bool),
    )


def _kept(
    learned: NDArray[np.bool_], twa_n: NDArray, all_of_them: bool
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """The rows and columns of the table: those with a learned cell (all with a shape),
    plus a guard row beside the lowest upwind and the highest downwind learned row
    (filled and held to that row's VMG, :func:`_guard`) and the row on its other side
    (filled, so that the table's shape round the best angles is not bent by a long gap
    to the next learned row)."""
    m = twa_n.size
    rows = np.asarray(learned.any(axis=1)) | all_of_them
    cols = np.asarray(learned.any(axis=0)) | all_of_them
    lo, hi = np.flatnonzero(rows)[[0, -1]]
    if twa_n[lo] < 90.0:
        rows[max(lo - 1, 0) : lo + 2] = True
    if twa_n[hi] > 90.0:
        rows[hi - 1 : hi + 2] = True
    if rows.sum() < 2:
        i = int(np.flatnonzero(rows)[0])
        rows[i + 1 if i + 1 < m else i - 1] = True
    return rows, cols


def _point(
    d: _Design,
    blocks: Blocks,
    sup: _Support,
    q: float,
    qs: list[float],
    rows: NDArray[np.bool_],
    cols: NDArray[np.bool_],
) -> tuple[NDArray, NDArray, NDArray]:
    """Each level's log values per cell, the boats' factors and the entries' corrected
    log values (the within-cell correction along the provisional median fit, repeated)."""
    nb = d.n_boats
    ones = np.ones(d.e_block.size)
    shift = np.zeros(d.e_block.size)
    twa_e, tws_e = _edges(d.twa_n, lo=0.0, hi=180.0), _edges(d.tws_n)
    zero_se = np.zeros(d.shape)
    lv = np.zeros((len(qs) + 1, d.n_cells))
    factors = np.zeros((nb, 3))
    for _ in range(_CORRECTION_PASSES + 1):
        cells = _boat_cells(d, blocks, d.e_log + shift, ones, q, None)
        lv, factors = _levels(cells, d.band, [*qs, 50.0], np.ones(nb, dtype=np.int64))
        lv = np.where(sup.mask, lv, np.nan)
        prov_tab = _finish(lv[-1], sup.learned, zero_se, d, rows, cols, sup.weight)[0]
        prov = Polar.from_arrays(d.twa_n[rows], d.tws_n[cols], prov_tab)
        shift = _correction(d, blocks, _extended(prov, rows, cols, tws_e, twa_e))
    return lv[:-1], factors, d.e_log + shift


def _bootstrap(
    d: _Design,
    blocks: Blocks,
    sup: _Support,
    e_log: NDArray,
    q: float,
    qs: list[float],
    rows: NDArray[np.bool_],
    cols: NDArray[np.bool_],
    n_boot: int,
    seed: int,
) -> list[list[NDArray]]:
    """Per level, the finished tables of ``n_boot`` replicates that resample the boats
    and, within each boat, its blocks."""
    rng = np.random.default_rng(seed)
    nb = d.n_boats
    order = np.lexsort((e_log, blocks.boat[d.e_block] * d.n_cells + d.e_cell))
    reps: list[list[NDArray]] = [[] for _ in qs]
    by_boat = [np.flatnonzero(blocks.boat == b) for b in range(nb)]
    zero_se = np.zeros(d.shape)
    m, n = d.shape
    for _ in range(n_boot):
        mult = rng.multinomial(nb, np.full(nb, 1.0 / nb))
        wblk = np.zeros(blocks.size)
        for b in np.flatnonzero(mult):
            ib = by_boat[b]
            if ib.size:
                wblk[ib] = rng.multinomial(ib.size, np.full(ib.size, 1.0 / ib.size)) * mult[b]
        cells = _boat_cells(d, blocks, e_log, wblk[d.e_block], q, order)
        lv, _ = _levels(cells, d.band, qs, mult.astype(np.int64))
        lv = np.where(sup.mask, lv, np.nan)
        for li in range(len(qs)):
            have = sup.learned & np.isfinite(lv[li, : m * n].reshape(m, n))
            if have.any():
                reps[li].append(_finish(lv[li], have, zero_se, d, rows, cols, sup.weight)[0])
    return reps


def _spread(rep: NDArray, first: NDArray) -> NDArray[np.float64]:
    """Standard deviation of ``log`` over the replicates (0 without any)."""
    if rep.shape[0] < 2:
        return np.zeros_like(first)
    with np.errstate(divide="ignore", invalid="ignore"):
        lr = np.log(np.maximum(rep, 1e-9))
    return np.asarray(np.nan_to_num(np.std(lr, axis=0, ddof=1)), dtype=float)


def _move(
    tab: NDArray, twa: NDArray, tws: NDArray, a_mean: NDArray, w_mean: NDArray, learned: NDArray
) -> NDArray[np.float64]:
    """Per learned cell, how far the table moves from where its blocks were sailed (their
    mean TWA and TWS) to its node, ``|log P(node) - log P(sailed)|``: the size of the
    within-cell correction, counted in the cell's uncertainty (0 elsewhere)."""
    p = Polar.from_arrays(twa, tws, np.maximum(tab, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        at = p.speed(np.nan_to_num(w_mean), np.nan_to_num(a_mean))
        mv = np.abs(np.log(tab / at))
    return np.where(learned & np.isfinite(mv), mv, 0.0)


def _level_table(
    name: str,
    pq: float,
    tab: NDArray,
    rep: NDArray,
    vu: NDArray,
    vd: NDArray,
    move: NDArray,
) -> LevelTable:
    """The level's table with its bootstrap statistics; ``move`` (log) adds to each
    cell's standard deviation in quadrature, as independent noise in the draws."""
    shape = tab.shape
    if rep.shape[0] >= 2:
        d = np.log(np.maximum(rep, 1e-9)) - np.log(np.maximum(tab, 1e-9))[None]
        sd = np.sqrt(np.std(d, axis=0, ddof=1) ** 2 + move**2)
        p10 = tab * np.exp(np.percentile(d, 10.0, axis=0))
        p90 = tab * np.exp(np.percentile(d, 90.0, axis=0))
        x = (d - d.mean(axis=0)).reshape(rep.shape[0], -1) / np.sqrt(rep.shape[0] - 1)
        _, s, vt = np.linalg.svd(x, full_matrices=False)
        k = min(N_MODES, s.size)
        modes = (s[:k, None] * vt[:k]).reshape(k, *shape)
        resid = np.sqrt(np.maximum(sd**2 - (modes**2).sum(axis=0), 0.0))
    else:
        sd = move.copy()
        p10 = p90 = tab.copy()
        modes = np.zeros((0, *shape))
        resid = move.copy()
    return LevelTable(name, pq, tab, sd, p10, p90, modes, resid, vu, vd)


def _tails(cnt: NDArray, twa_n: NDArray) -> NDArray[np.int64]:
    """Per cell, the row of its column's beat (run) when the cell is a tail of it, else -1.

    In each TWS column the upwind (downwind) row with the most blocks is where the boats
    beat (run); another upwind (downwind) row of that column within :data:`TAIL_SPAN_DEG`
    of it and with fewer than :data:`TAIL_FRACTION` of its blocks holds mostly the beat's
    (run's) own blocks moved there by wind-angle error (they read the beat's speed at
    another angle).
    """
    out = np.full(cnt.shape, -1, dtype=np.int64)
    band = np.digitize(twa_n, BOUNDARIES_DEG)
    for k in (0, 2):
        rows = np.flatnonzero(band == k)
        if rows.size < 2:
            continue
        for j in range(cnt.shape[1]):
            c = cnt[rows, j]
            top = int(rows[np.argmax(c)])
            near = np.abs(twa_n[rows] - twa_n[top]) <= TAIL_SPAN_DEG
            few = (c > 0) & (c < TAIL_FRACTION * cnt[top, j]) & (rows != top) & near
            out[rows[few], j] = top
    return out


def _status(
    sup: _Support, d: _Design, min_boats: int, min_blocks: int
) -> tuple[NDArray, tuple[str, ...]]:
    """Per cell ``learned``/``refused``/``empty``, and one line per refused cell."""
    cnt, nb = sup.cnt, sup.nboats
    st = np.where(sup.learned, "learned", np.where(cnt > 0, "refused", "empty")).astype(np.str_)
    lines = []
    for i, j in zip(*np.nonzero(st == "refused"), strict=True):
        why = []
        if nb[i, j] < min_boats:
            why.append(f"{nb[i, j]} boat(s), need {min_boats}")
        if cnt[i, j] < min_blocks:
            why.append(f"{cnt[i, j]} block(s), need {min_blocks}")
        if sup.tail[i, j] >= 0:
            k = int(sup.tail[i, j])
            why.append(
                f"a tail of the {'beat' if d.twa_n[k] < 90 else 'run'} sailed at "
                f"{d.twa_n[k]:g} deg ({cnt[i, j]} blocks against {cnt[k, j]}): read as "
                "wind-angle error, not sailed here"
            )
        if not why:
            why.append(
                f"sailed {sup.offset[i, j]:+.1f} deg and {sup.w_off[i, j]:+.2f} m/s off the "
                "node on average, more than a quarter of the cell (the value at the node "
                "would be extrapolated)"
            )
        lines.append(f"TWA {d.twa_n[i]:g} deg, TWS {d.tws_n[j]:.2f} m/s: {'; '.join(why)}")
    return st, tuple(lines)


def _drops_text(drops: list[str], tws_n: NDArray) -> list[str]:
    out = []
    for s in drops:
        a, j0, j1 = s.split(":")
        out.append(
            f"TWA {a} deg: speed falls from TWS {tws_n[int(j0)]:.2f} to {tws_n[int(j1)]:.2f} "
            "m/s beyond its uncertainty (kept)"
        )
    return out


def _check_one_class(d: _Design, blocks: Blocks) -> None:
    """Refuse boats whose speeds cannot be one class (:data:`MAX_CLASS_RATIO`)."""
    nb = d.n_boats
    if nb < 2:
        return
    ones = np.ones(d.e_block.size)
    cells = _boat_cells(d, blocks, d.e_log, ones, 0.5, None)
    real = np.zeros(d.n_cells, dtype=bool)
    real[: d.shape[0] * d.shape[1]] = True
    has = cells.weight[:, real] > 0
    # boats linked by shared cells
    comp = np.arange(nb)
    shared = (has.astype(int) @ has.T.astype(int)) > 0
    for _ in range(nb):
        comp = np.array([comp[shared[b]].min() for b in range(nb)])
    names = blocks.boats
    if np.unique(comp).size > 1:
        ratio = blocks.speed_ms / np.maximum(blocks.tws_ms, 0.1)
        med = np.array([np.median(ratio[blocks.boat == b]) for b in range(nb)])
        groups = [np.flatnonzero(comp == c) for c in np.unique(comp)]
        gm = [float(np.median(med[g])) for g in groups]
        hi, lo = int(np.argmax(gm)), int(np.argmin(gm))
        if gm[hi] / gm[lo] > MAX_CLASS_RATIO_APART:
            raise InputError(
                f"logs of different classes: {', '.join(names[b] for b in groups[hi])} sail "
                f"{gm[hi] / gm[lo]:.1f}x the speed per knot of wind of "
                f"{', '.join(names[b] for b in groups[lo])}, in winds and angles the others "
                "never sailed: these cannot be one boat; learn each class on its own"
            )
        return
    c = _Cells(np.where(has, cells.value[:, real], np.nan), cells.weight[:, real])
    _, a = _factor_fit(c, d.band[real])
    w = np.array([(c.weight[:, d.band[real] == k]).sum(1) for k in range(3)]).T
    overall = np.nansum(np.nan_to_num(a) * w, axis=1) / np.maximum(w.sum(1), 1e-9)
    ratio = np.array([overall[b] - np.median(np.delete(overall, b)) for b in range(nb)])
    b = int(np.argmax(np.abs(ratio)))  # the boat furthest from the rest
    r = float(np.exp(ratio[b]))
    if r > MAX_CLASS_RATIO or r < 1.0 / MAX_CLASS_RATIO:
        raise InputError(
            f"logs of different classes: {names[b]} sails {r:.2f}x the speed of the rest "
            f"of the fleet in the same wind and at the same angles (one class differs by "
            f"less than {MAX_CLASS_RATIO:g}x): these cannot be one boat; learn each class "
            "on its own, or leave the log out"
        )


def sanity_verdict(learned: LearnedPolar, blocks: Blocks, factors: NDArray) -> tuple[str, ...]:
    """The sanity verdict of a learned polar (one line each).

    * per level and TWS column, the best upwind and downwind VMG angles against the
      angles the fleet sailed there (P10-P90 of its steady blocks, upwind below 70°,
      downwind above 120°): an optimum outside them is flagged;
    * the refused cells (count; :attr:`LearnedPolar.reasons` lists them);
    * the boats' factors upwind / reach / downwind.
    """
    out: list[str] = []
    a = fold_twa(blocks.twa_deg)
    tws_e = _edges(learned.tws_ms)
    col = np.clip(
        np.searchsorted(tws_e, blocks.tws_ms, side="right") - 1, 0, learned.tws_ms.size - 1
    )
    b1, b2 = BOUNDARIES_DEG
    for lname in learned.levels:
        p = learned.polar(lname)
        up_a = p.vmg_upwind(learned.tws_ms)[0]
        dn_a = p.vmg_downwind(learned.tws_ms)[0]
        for j, tws in enumerate(learned.tws_ms):
            for kind, ang, sel in (
                ("beat", up_a[j], (col == j) & (a < b1)),
                ("run", dn_a[j], (col == j) & (a > b2)),
            ):
                if sel.sum() < 3:
                    continue
                lo, hi = np.percentile(a[sel], [10.0, 90.0])
                if ang < lo - 3.0 or ang > hi + 3.0:
                    out.append(
                        f"{lname}: TWS {tws:.2f} m/s: best {kind} angle {ang:.1f} deg lies "
                        f"outside the angles the fleet sailed ({lo:.0f}-{hi:.0f} deg): the "
                        "polar's shape there is not the data's"
                    )
    n_ref = int((learned.status == "refused").sum())
    if n_ref:
        out.append(f"{n_ref} cell(s) refused (listed), filled from the learned cells")
    for b, name in enumerate(blocks.boats):
        f = factors[b]
        out.append(
            f"boat {name}: x"
            + " / x".join("-" if not np.isfinite(x) else f"{np.exp(x):.3f}" for x in f)
            + " of the fleet's cells (upwind / reach / downwind)"
        )
    return tuple(out)


def draw_polars(
    learned: LearnedPolar, level: str | None, n: int, rng: np.random.Generator
) -> tuple[Polar, ...]:
    """Draw ``n`` whole polars of a level from its uncertainty.

    Each member is ``speed exp(sum_k z_k modes[k] + resid_sd_log e)`` with ``z`` and
    ``e`` standard normal: the bootstrap's leading modes carry the correlation of the
    cells (along a row, across the table), the residual keeps each cell's own spread.
    The bootstrap's uncertainty alone: the legs' scatter about the race pace
    (``pace_sd_log``) is left out (a band's members add it: :class:`PolarDraw`).

    Parameters
    ----------
    learned : LearnedPolar
    level : str or None
        Level name (default the file's default).
    n : int
        Members (>= 1).
    rng : numpy.random.Generator

    Returns
    -------
    tuple of Polar
        Named ``"<name> (<level>) #k"``.
    """
    if int(n) != n or n < 1:
        raise InputError(f"draw_polars: n must be a whole number >= 1; got {n}")
    t = learned.level(level)
    out = []
    for k in range(int(n)):
        z = rng.standard_normal(t.modes.shape[0])
        e = rng.standard_normal(t.speed_ms.size)
        d = PolarDraw(tuple(np.ravel(z).tolist()), tuple(np.ravel(e).tolist()))
        out.append(
            learned.drawn(t.name, d).polar(t.name).with_name(f"{learned.name} ({t.name}) #{k + 1}")
        )
    return tuple(out)


__all__ = [
    "BAND_NAMES",
    "DEFAULT_LEVEL",
    "LEVELS",
    "MAX_CLASS_RATIO",
    "MAX_CLASS_RATIO_APART",
    "N_BOOT",
    "N_MODES",
    "LearnFit",
    "LearnedPolar",
    "LevelTable",
    "draw_polars",
    "learn_polar",
    "parse_levels",
    "sanity_verdict",
    "with_sailed_rows",
]
