"""Fit a boat polar to logged data: filters, percentile envelope, smoothing, fill.

Pure array core of ``sailroute polar fit`` (see ``docs/polar-fit.md``).  Input is
one array per quantity, one element per log sample, in SI units: TWS [m s⁻¹],
TWA [°] (signed: + starboard tack, - port; unsigned is accepted but then tacks
are seen only through the turn rate), boat speed [m s⁻¹] and optionally the time
[s] and a heading [°] for the manoeuvre and acceleration filters.

Method
------
1. **Filters** (each sample is counted under the first rule that drops it):

   ``non_finite``
       any input NaN/inf, or a negative speed;
   ``low_wind``
       TWS below :attr:`FitFilters.min_tws_ms`;
   ``manoeuvre``
       \\|turn rate\\| above :attr:`FitFilters.max_turn_rate_deg_s` (from the
       heading if given, else from the signed TWA), or within
       :attr:`FitFilters.manoeuvre_window_s` of a tack or gybe (a sign change
       of the TWA, i.e. the wind crossing the bow or the stern);
   ``acceleration``
       \\|dV/dt\\| above :attr:`FitFilters.max_accel_per_s` times the speed
       (a boat speeding up or slowing down by more than that fraction per
       second is not in steady state);
   ``outside_bins``
       TWS beyond the outer edges of the TWS bins;
   ``outlier``
       speed above the cell's median + :attr:`FitFilters.outlier_k` scaled MADs
       (1.4826 MAD, a robust standard deviation).

   The time-based rules need ``t_s``; without it they are skipped.
2. **Bins**: each sample goes to the nearest TWS node and the nearest TWA node
   (bin edges halfway between nodes).
3. **Envelope**: the ``percentile`` of the speeds in each cell with at least
   ``min_count`` samples.  A cell spans a range of TWS and TWA, and the upper
   percentile would favour its faster corner; so each sample's speed is first
   moved to the cell's node along the current fit (``v * P(node) / P(sample)``,
   ratio clipped to [0.5, 2]) and the percentile recomputed, twice.
4. **Monotone in TWS where the data say so**: along each TWA row, a drop of the
   envelope from one covered TWS cell to the next is kept when it exceeds twice
   the combined standard error of the two percentiles (normal approximation,
   ``se = 1.4826 MAD sqrt(p (1 - p) / n) / phi(z_p)``); the row is split at
   such drops and each piece is made non-decreasing by count-weighted
   isotonic regression (pool adjacent violators).
5. **Fill and trim**: TWS columns and TWA rows with no covered cell are left out
   of the polar.  Empty cells are filled, in order: linear along TWS between
   covered cells of the row; else from the nearest column that has the row,
   scaled by the median ratio of the two columns over their common rows (the
   neighbour's shape in TWA); fallbacks, for a polar with one TWS column: PCHIP
   along TWA between filled cells of the column, else the nearest value of the
   row, then of the column.  Filled cells keep ``counts == 0`` and ``covered == False``.

The result is a valid :class:`~sailroute.boat.polar.Polar` (finite, >= 0) with
``"pchip"`` interpolation.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sailroute.boat.polar import Polar, fold_twa
from sailroute.errors import InputError
from sailroute.numerics import pchip
from sailroute.units import wrap180

RULES: Final = ("non_finite", "low_wind", "manoeuvre", "acceleration", "outside_bins", "outlier")
"""Names of the filter rules, in the order they are applied."""

_MAD_TO_SIGMA: Final = 1.4826
_CORRECTION_PASSES: Final = 2
_SIGNIFICANT_Z: Final = 2.0


@dataclass(frozen=True)
class FitFilters:
    """Rules that drop samples before the envelope is taken.

    Parameters
    ----------
    min_tws_ms : float
        Drop samples with TWS below this [m s⁻¹] (instruments are unreliable
        and boats drift in calms).
    max_turn_rate_deg_s : float
        Drop samples turning faster than this [° s⁻¹].
    manoeuvre_window_s : float
        Drop samples within this time [s] before or after a tack or gybe
        (a sign change of the TWA).
    max_accel_per_s : float
        Drop samples with ``|dV/dt| > max_accel_per_s * V`` [s⁻¹]: the speed
        changing by more than this fraction per second.
    outlier_k : float
        Drop samples faster than the cell median + ``outlier_k`` robust
        standard deviations (1.4826 MAD).
    """

    min_tws_ms: float = 1.0
    max_turn_rate_deg_s: float = 6.0
    manoeuvre_window_s: float = 10.0
    max_accel_per_s: float = 0.05
    outlier_k: float = 3.0

    def __post_init__(self) -> None:
        check_non_negative(self, "fit filters")


def check_non_negative(settings: object, what: str) -> None:
    """Every field of a settings dataclass a finite number >= 0, else an error naming it."""
    for f in fields(settings):  # type: ignore[arg-type]
        v = getattr(settings, f.name)
        if not (isinstance(v, (int, float)) and np.isfinite(v) and v >= 0):
            raise InputError(f"{what}: {f.name} must be a finite number >= 0; got {v!r}")


@dataclass(frozen=True, eq=False)
class PolarFit:
    """Result of :func:`fit_polar`.

    Attributes
    ----------
    polar : Polar
        The fitted polar (rows/columns with data only), speeds [m s⁻¹].
    counts : ndarray of int, shape (m, n)
        Samples per cell of ``polar``'s grid after filtering.
    raw_ms : ndarray, shape (m, n)
        The percentile of each covered cell before smoothing [m s⁻¹]; NaN
        where ``counts < min_count``.
    covered : ndarray of bool, shape (m, n)
        Cells with at least ``min_count`` samples; the others were filled.
    coverage : float
        Fraction of ``polar``'s cells that are covered.
    dropped : dict of str to int
        Samples dropped by each rule of :data:`RULES`.
    n_samples, n_used : int
        Samples given and samples that reached the bins.
    percentile : float
        Envelope percentile used.
    empty_tws_ms, empty_twa_deg : ndarray
        Requested TWS [m s⁻¹] / TWA [°] nodes left out for lack of data.
    tws_ms, twa_deg, bsp_ms, used : ndarray
        The samples as given (TWA folded to [0, 180]) and the mask of those kept
        (for plots).
    """

    polar: Polar
    counts: NDArray[np.int64]
    raw_ms: NDArray[np.float64]
    covered: NDArray[np.bool_]
    coverage: float
    dropped: dict[str, int]
    n_samples: int
    n_used: int
    percentile: float
    empty_tws_ms: NDArray[np.float64]
    empty_twa_deg: NDArray[np.float64]
    tws_ms: NDArray[np.float64] = field(repr=False)
    twa_deg: NDArray[np.float64] = field(repr=False)
    bsp_ms: NDArray[np.float64] = field(repr=False)
    used: NDArray[np.bool_] = field(repr=False)


def fit_polar(
    tws_ms: ArrayLike,
    twa_deg: ArrayLike,
    bsp_ms: ArrayLike,
    t_s: ArrayLike | None = None,
    *,
    tws_bins_ms: ArrayLike,
    twa_bins_deg: ArrayLike,
    heading_deg: ArrayLike | None = None,
    percentile: float = 90.0,
    min_count: int = 5,
    filters: FitFilters | None = None,
    name: str = "fitted",
    options: Mapping[str, str] | None = None,
) -> PolarFit:
    """Fit a polar to logged samples (see the module docstring for the method).

    Parameters
    ----------
    tws_ms, twa_deg, bsp_ms : array_like, shape (k,)
        True wind speed [m s⁻¹], signed true wind angle [°] and boat speed
        [m s⁻¹] of each sample.
    t_s : array_like, shape (k,), optional
        Sample times [s], increasing; needed by the manoeuvre and acceleration
        filters.
    tws_bins_ms : array_like
        TWS nodes (columns) [m s⁻¹], strictly increasing, > 0.
    twa_bins_deg : array_like
        TWA nodes (rows) [°], strictly increasing within [0, 180].
    heading_deg : array_like, shape (k,), optional
        Heading or COG [°] for the turn rate; default the signed TWA.
    percentile : float
        Envelope percentile in (0, 100].
    min_count : int
        Samples a cell needs to count as covered (>= 1).
    filters : FitFilters, optional
        Filter thresholds; default :class:`FitFilters()`.
    name : str
        Name of the returned polar.
    options : mapping of str to str, optional
        What the messages call the parameters ``percentile``, ``min_count``,
        ``tws_bins_ms`` and ``twa_bins_deg`` (a command line's options, e.g.
        ``{"min_count": "--min-count"}``); default ``fit_polar: <parameter>``.

    Returns
    -------
    PolarFit

    Raises
    ------
    InputError
        Arrays of different lengths, bad bins or options, or no cell with
        enough samples after filtering (the message gives the filter counts).
    """
    filters = FitFilters() if filters is None else filters
    tws = np.asarray(tws_ms, dtype=float).ravel()
    twa_s = np.asarray(twa_deg, dtype=float).ravel()
    bsp = np.asarray(bsp_ms, dtype=float).ravel()
    k = tws.size
    arrays = {"twa_deg": twa_s, "bsp_ms": bsp}
    t = None if t_s is None else np.asarray(t_s, dtype=float).ravel()
    hdg = None if heading_deg is None else np.asarray(heading_deg, dtype=float).ravel()
    if t is not None:
        arrays["t_s"] = t
    if hdg is not None:
        arrays["heading_deg"] = hdg
    for nm, a in arrays.items():
        if a.size != k:
            raise InputError(
                f"fit_polar: {nm} has {a.size} samples, tws_ms has {k}; give one value per sample"
            )
    named = dict(options or {})

    def label(param: str) -> str:
        return named.get(param, f"fit_polar: {param}")

    tws_n = _check_nodes(tws_bins_ms, label("tws_bins_ms"), lo=0.0, hi=np.inf, strict_lo=True)
    twa_n = _check_nodes(twa_bins_deg, label("twa_bins_deg"), lo=0.0, hi=180.0, strict_lo=False)
    if not 0.0 < percentile <= 100.0:
        raise InputError(f"{label('percentile')} must be in (0, 100], e.g. 90; got {percentile}")
    if not np.isfinite(min_count) or int(min_count) != min_count or min_count < 1:
        raise InputError(
            f"{label('min_count')} must be a whole number >= 1, e.g. 5; got {min_count}"
        )
    q = percentile / 100.0
    twa = fold_twa(twa_s)

    # --- filters (first rule wins) ----------------------------------------------
    reason = np.full(k, -1, dtype=np.int64)

    def drop(mask: NDArray[np.bool_], rule: str) -> None:
        reason[(reason < 0) & mask] = RULES.index(rule)

    bad = ~(np.isfinite(tws) & np.isfinite(twa_s) & np.isfinite(bsp)) | (bsp < 0) | (tws < 0)
    if t is not None:
        bad |= ~np.isfinite(t)
    drop(bad, "non_finite")
    drop(tws < filters.min_tws_ms, "low_wind")
    if t is not None and k >= 3:
        drop(_manoeuvres(t, twa_s, hdg, filters) & (reason < 0), "manoeuvre")
        drop(_accelerating(t, bsp, filters), "acceleration")
    tws_edges = _edges(tws_n)
    twa_edges = _edges(twa_n, lo=0.0, hi=180.0)
    drop((tws < tws_edges[0]) | (tws > tws_edges[-1]), "outside_bins")
    keep = reason < 0
    nj = tws_n.size
    n_cells = twa_n.size * nj
    cell = np.full(k, -1, dtype=np.int64)
    ii = np.clip(np.searchsorted(twa_edges, twa[keep], side="right") - 1, 0, twa_n.size - 1)
    jj = np.clip(np.searchsorted(tws_edges, tws[keep], side="right") - 1, 0, nj - 1)
    cell[keep] = ii * nj + jj
    # outliers: above median + k sigma_MAD of the cell
    med = _grouped_quantile(cell[keep], bsp[keep], n_cells, 0.5)[1]
    mad = _grouped_quantile(cell[keep], np.abs(bsp[keep] - med[cell[keep]]), n_cells, 0.5)[1]
    bound = med + filters.outlier_k * _MAD_TO_SIGMA * mad
    out = np.zeros(k, dtype=bool)
    out[keep] = bsp[keep] > bound[cell[keep]]
    drop(out, "outlier")
    keep = reason < 0
    dropped = {r: int(np.sum(reason == n)) for n, r in enumerate(RULES)}
    g = cell[keep]
    v, s_tws, s_twa = bsp[keep], tws[keep], twa[keep]

    # --- envelope with the within-cell gradient correction ---------------------------
    counts, env = _grouped_quantile(g, v, n_cells, q)
    counts = counts.reshape(twa_n.size, nj)
    covered = counts >= min_count
    if not covered.any():
        where = "" if named else "fit_polar: "
        raise InputError(
            f"{where}no TWS/TWA cell has {min_count} samples after filtering "
            f"({k} samples; dropped: {_fmt_dropped(dropped)}); give a longer log, wider bins "
            f"(fewer TWS nodes: {label('tws_bins_ms')}, a larger TWA step: "
            f"{label('twa_bins_deg')}), a lower {label('min_count')} or looser filters"
        )
    raw = np.where(covered, env.reshape(counts.shape), np.nan)
    node_tws = tws_n[g % nj]
    node_twa = twa_n[g // nj]
    v_final = v
    for _ in range(_CORRECTION_PASSES):
        prov = _extended(
            *_finish(raw, counts, covered, tws_n, twa_n, q, v, g, name), tws_edges, twa_edges
        )
        at_node = prov.speed(node_tws, node_twa)
        at_sample = prov.speed(s_tws, s_twa)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(at_sample > 0, at_node / at_sample, 1.0)
        moved = v * np.clip(ratio, 0.5, 2.0)
        raw = np.where(
            covered, _grouped_quantile(g, moved, n_cells, q)[1].reshape(counts.shape), np.nan
        )
        v_final = moved
    polar, rows, cols = _finish(raw, counts, covered, tws_n, twa_n, q, v_final, g, name)
    sub = np.ix_(rows, cols)
    cov_sub = covered[sub]
    used = np.zeros(k, dtype=bool)
    used[keep] = True
    for a in (tws, twa, bsp, used):
        a.setflags(write=False)
    return PolarFit(
        polar=polar,
        counts=counts[sub],
        raw_ms=raw[sub],
        covered=cov_sub,
        coverage=float(cov_sub.mean()),
        dropped=dropped,
        n_samples=k,
        n_used=int(keep.sum()),
        percentile=float(percentile),
        empty_tws_ms=tws_n[~cols],
        empty_twa_deg=twa_n[~rows],
        tws_ms=tws,
        twa_deg=twa,
        bsp_ms=bsp,
        used=used,
    )


# --- filters ------------------------------------------------------------------------


def _rate(t: NDArray, angle_deg: NDArray) -> NDArray:
    """|d angle / dt| [° s⁻¹] of an angle series, unwrapped, NaN-safe."""
    a = np.where(np.isfinite(angle_deg), angle_deg, 0.0)
    un = np.degrees(np.unwrap(np.radians(a)))
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.abs(np.gradient(un, t))
    return np.where(np.isfinite(r), r, 0.0)


def _manoeuvres(
    t: NDArray, twa_s: NDArray, hdg: NDArray | None, filters: FitFilters
) -> NDArray[np.bool_]:
    """Samples turning fast or within the window of a tack/gybe."""
    rate = _rate(t, hdg if hdg is not None else twa_s)
    turning = rate > filters.max_turn_rate_deg_s
    sign = np.sign(np.where(np.isfinite(twa_s), twa_s, 0.0))
    # carry the last non-zero sign forward so that a 0 sample is no tack by itself
    nz = np.flatnonzero(sign)
    if nz.size < 2:
        return turning
    s_nz = sign[nz]
    flips = np.flatnonzero(s_nz[1:] != s_nz[:-1])
    if flips.size == 0:
        return turning
    # time of each tack/gybe: midway between the last sample before and first after
    t_flip = 0.5 * (t[nz[flips]] + t[nz[flips + 1]])
    pos = np.searchsorted(t_flip, t)
    near = np.full(t.size, np.inf)
    left = pos > 0
    near[left] = np.abs(t[left] - t_flip[pos[left] - 1])
    right = pos < t_flip.size
    near[right] = np.minimum(near[right], np.abs(t_flip[pos[right]] - t[right]))
    return turning | (near <= filters.manoeuvre_window_s)


def _accelerating(t: NDArray, bsp: NDArray, filters: FitFilters) -> NDArray[np.bool_]:
    v = np.where(np.isfinite(bsp), bsp, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        dv = np.abs(np.gradient(v, t))
    dv = np.where(np.isfinite(dv), dv, 0.0)
    return dv > filters.max_accel_per_s * np.maximum(v, 0.1)


# --- envelope, monotonicity, fill ----------------------------------------------------


def _grouped_quantile(
    g: NDArray, v: NDArray, n: int, q: float
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """Count and ``q``-quantile (linear, as ``np.quantile``) of ``v`` per group ``g``."""
    counts = np.bincount(g, minlength=n).astype(np.int64)
    res = np.full(n, np.nan)
    if g.size == 0:
        return counts, res
    order = np.lexsort((v, g))
    vs = v[order]
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    ok = counts > 0
    pos = q * (counts[ok] - 1)
    lo = np.floor(pos).astype(np.int64)
    hi = np.minimum(lo + 1, counts[ok] - 1)
    frac = pos - lo
    res[ok] = vs[start[ok] + lo] * (1.0 - frac) + vs[start[ok] + hi] * frac
    return counts, res


def _quantile_se(v: NDArray, g: NDArray, n_cells: int, counts: NDArray, q: float) -> NDArray:
    """Standard error of each cell's ``q``-quantile (normal approximation, MAD sigma)."""
    from scipy.stats import norm

    med = _grouped_quantile(g, v, n_cells, 0.5)[1]
    mad = _grouped_quantile(g, np.abs(v - med[g]), n_cells, 0.5)[1]
    qq = min(max(q, 0.01), 0.99)
    factor = np.sqrt(qq * (1.0 - qq)) / norm.pdf(norm.ppf(qq))
    with np.errstate(divide="ignore", invalid="ignore"):
        se = _MAD_TO_SIGMA * mad * factor / np.sqrt(counts.ravel())
    return se.reshape(counts.shape)


def _pava(y: NDArray, w: NDArray) -> NDArray:
    """Weighted isotonic (non-decreasing) regression, pool adjacent violators."""
    vals: list[float] = []
    wts: list[float] = []
    lens: list[int] = []
    for yi, wi in zip(y, w, strict=True):
        vals.append(float(yi))
        wts.append(float(wi))
        lens.append(1)
        while len(vals) > 1 and vals[-2] > vals[-1]:
            wsum = wts[-2] + wts[-1]
            vals[-2] = (vals[-2] * wts[-2] + vals[-1] * wts[-1]) / wsum
            wts[-2] = wsum
            lens[-2] += lens[-1]
            del vals[-1], wts[-1], lens[-1]
    return np.repeat(vals, lens)


def _monotone_in_tws(raw: NDArray, counts: NDArray, se: NDArray) -> NDArray:
    """Non-decreasing along TWS per row, except across significant drops."""
    out = raw.copy()
    for i in range(raw.shape[0]):
        js = np.flatnonzero(np.isfinite(raw[i]))
        if js.size < 2:
            continue
        y, w, s = raw[i, js], counts[i, js].astype(float), se[i, js]
        drop = y[:-1] - y[1:]
        tol = _SIGNIFICANT_Z * np.sqrt(np.nan_to_num(s[:-1]) ** 2 + np.nan_to_num(s[1:]) ** 2)
        cuts = np.flatnonzero(drop > tol) + 1
        pieces = [
            _pava(yy, ww) for yy, ww in zip(np.split(y, cuts), np.split(w, cuts), strict=True)
        ]
        out[i, js] = np.concatenate(pieces)
    return out


def _fill(tab: NDArray, tws: NDArray, twa: NDArray) -> NDArray:
    """Fill NaN cells (rules in the module docstring, step 5)."""
    out = tab.copy()
    for i in range(out.shape[0]):  # linear along TWS between covered cells
        ok = np.flatnonzero(np.isfinite(tab[i]))
        if ok.size >= 2:
            inner = np.arange(ok[0], ok[-1] + 1)
            out[i, inner] = np.interp(tws[inner], tws[ok], tab[i, ok])
    if np.isnan(out).any():  # shape of the nearest column, scaled
        base = out.copy()
        for j in range(out.shape[1]):
            miss = np.isnan(base[:, j])
            if not miss.any():
                continue
            for k in np.argsort(np.abs(tws - tws[j]), kind="stable")[1:]:
                common = np.isfinite(base[:, j]) & np.isfinite(base[:, k]) & (base[:, k] > 0)
                take = miss & np.isfinite(base[:, k]) & np.isnan(out[:, j])
                if not take.any():
                    continue
                r = float(np.median(base[common, j] / base[common, k])) if common.any() else 1.0
                out[take, j] = base[take, k] * r
                if not np.isnan(out[:, j]).any():
                    break
    for j in range(out.shape[1]):  # PCHIP along TWA
        ok = np.flatnonzero(np.isfinite(out[:, j]))
        if ok.size >= 2:
            inner = np.arange(ok[0], ok[-1] + 1)
            out[inner, j] = pchip(twa[ok], out[ok, j], twa[inner])
    for i in range(out.shape[0]):  # last resort: nearest value of the row
        ok = np.flatnonzero(np.isfinite(out[i]))
        miss = np.flatnonzero(np.isnan(out[i]))
        if ok.size and miss.size:
            near = ok[np.argmin(np.abs(tws[miss][:, None] - tws[ok][None, :]), axis=1)]
            out[i, miss] = out[i, near]
    for j in range(out.shape[1]):  # ... or of the column (a single covered row)
        ok = np.flatnonzero(np.isfinite(out[:, j]))
        miss = np.flatnonzero(np.isnan(out[:, j]))
        if ok.size and miss.size:
            near = ok[np.argmin(np.abs(twa[miss][:, None] - twa[ok][None, :]), axis=1)]
            out[miss, j] = out[near, j]
    return np.maximum(out, 0.0)


def _finish(
    raw: NDArray,
    counts: NDArray,
    covered: NDArray,
    tws_n: NDArray,
    twa_n: NDArray,
    q: float,
    v: NDArray,
    g: NDArray,
    name: str,
) -> tuple[Polar, NDArray, NDArray]:
    """Monotone rule, trim empty rows/columns, fill, build the polar."""
    se = _quantile_se(v, g, counts.size, counts, q)
    mono = _monotone_in_tws(raw, counts, se)
    rows = np.asarray(covered.any(axis=1))  # (arrays: numpy's stubs say "bool or array")
    cols = np.asarray(covered.any(axis=0))
    if rows.sum() < 2:
        # a polar needs 2 TWA rows: keep the nearest empty neighbour too (filled)
        i = int(np.flatnonzero(rows)[0])
        rows[i + 1 if i + 1 < rows.size else i - 1] = True
    tab = _fill(mono[np.ix_(rows, cols)], tws_n[cols], twa_n[rows])
    return Polar.from_arrays(twa_n[rows], tws_n[cols], tab, name=name), rows, cols


def _extended(
    polar: Polar, rows: NDArray, cols: NDArray, tws_edges: NDArray, twa_edges: NDArray
) -> Polar:
    """``polar`` with one more row/column at each outer bin edge, extrapolated linearly.

    The provisional fit of the gradient correction must rate samples between the
    outermost nodes and the bin edges; :class:`Polar` itself clamps above the
    last TWS column and tapers to 0 below the first TWA row.
    """
    twa, tws, tab = polar.twa_deg, polar.tws_ms, polar.speed_ms
    ir, jc = np.flatnonzero(rows), np.flatnonzero(cols)
    lo_a, hi_a = twa_edges[ir[0]], twa_edges[ir[-1] + 1]
    lo_w, hi_w = tws_edges[jc[0]], tws_edges[jc[-1] + 1]

    def ext(x: NDArray, t: NDArray, at: float, first: bool, axis: int) -> tuple[NDArray, NDArray]:
        if x.size < 2 or (at >= x[0] if first else at <= x[-1]):
            return x, t
        a, b = (0, 1) if first else (-1, -2)
        ta, tb = np.take(t, [a], axis=axis), np.take(t, [b], axis=axis)
        new = np.maximum(ta + (ta - tb) * (at - x[a]) / (x[a] - x[b]), 0.0)
        if first:
            return np.concatenate([[at], x]), np.concatenate([new, t], axis=axis)
        return np.concatenate([x, [at]]), np.concatenate([t, new], axis=axis)

    twa, tab = ext(twa, tab, max(lo_a, 0.0), True, 0)
    twa, tab = ext(twa, tab, min(hi_a, 180.0), False, 0)
    tws, tab = ext(tws, tab, max(lo_w, 1e-6), True, 1)
    tws, tab = ext(tws, tab, hi_w, False, 1)
    return Polar.from_arrays(twa, tws, tab, name=polar.name)


# --- helpers --------------------------------------------------------------------------


def _check_nodes(
    nodes: ArrayLike, what: str, *, lo: float, hi: float, strict_lo: bool
) -> NDArray[np.float64]:
    a = np.asarray(nodes, dtype=float).ravel()
    if a.size < 1 or not np.all(np.isfinite(a)) or np.any(np.diff(a) <= 0):
        raise InputError(f"{what} must be finite and strictly increasing; got {a}")
    if (a[0] <= lo if strict_lo else a[0] < lo) or a[-1] > hi:
        raise InputError(f"{what} must lie in {'(' if strict_lo else '['}{lo:g}, {hi:g}]; got {a}")
    return a


def _edges(nodes: NDArray, lo: float | None = None, hi: float | None = None) -> NDArray:
    """Bin edges halfway between nodes; the outer bins as wide as their inner half."""
    if nodes.size == 1:
        half = 0.5 * nodes[0] if lo is None else 180.0
        e = np.array([nodes[0] - half, nodes[0] + half])
    else:
        mid = 0.5 * (nodes[1:] + nodes[:-1])
        e = np.concatenate([[2 * nodes[0] - mid[0]], mid, [2 * nodes[-1] - mid[-1]]])
    if lo is not None:
        e[0] = min(e[0], lo)
    if hi is not None:
        e[-1] = max(e[-1], hi)
    return e


def _fmt_dropped(d: dict[str, int]) -> str:
    return ", ".join(f"{k} {v}" for k, v in d.items())


def twa_sign_from(
    twd_deg: ArrayLike, heading_deg: ArrayLike, twa_deg: ArrayLike
) -> NDArray[np.float64]:
    """Signed TWA from an unsigned one: the sign of ``wrap180(twd - heading)``.

    Logs often store ``|TWA|``; the tack (sign) is needed to find tacks and
    gybes.  Where TWD or heading is missing the value stays unsigned.
    """
    a = np.abs(np.asarray(twa_deg, dtype=float))
    s = np.sign(wrap180(np.asarray(twd_deg, float) - np.asarray(heading_deg, float)))
    return np.where(np.isfinite(s) & (s != 0), s * a, a)
