"""Laylines: the courses that just fetch a mark on one tack or gybe, traced back from it.

A boat on a **tack layline** sails close-hauled at the best upwind VMG angle and reaches
the mark without tacking again; on a **gybe layline** it sails at the best downwind VMG
angle and reaches the mark without gybing again.  The angle and the wind change along
the way, so the layline is traced back from the mark through the wind field: with ``s``
the distance back from the mark, ``TWA*`` the best-VMG angle at the local wind speed and
``h = TWD ∓ TWA*`` the heading on starboard (−) or port (+),

    d(x, y)/ds = −(sin h, cos h),    dt/ds = −1 / V(TWS, TWA*),

integrated with the midpoint rule (second order; the best-VMG angle is interpolated on
a TWS grid of 0.05 m s⁻¹).  The time runs backwards from the
moment the boat rounds the mark, so a wind that changes in time is followed too.  In a
uniform steady wind the layline is straight, at the bearing ``h + 180°`` from the mark.
A trace stops where the wind field's coverage ends (a field built with ``clamp``
continues at its edge values).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.model import BoatModel
from sailroute.routing.types import Side
from sailroute.units import heading_unit, wind_speed_direction, wrap360
from sailroute.wind.base import WindField

LaylineKind = Literal["tack", "gybe"]
"""``tack``: close-hauled laylines to a windward mark; ``gybe``: downwind ones to a
leeward mark or gate."""

N_STEPS = 50
"""Integration steps of a layline (its points are ``N_STEPS + 1`` or fewer)."""

TWS_NODES_PER_MS = 20
"""Nodes per m s⁻¹ of the TWS grid the best-VMG angles are interpolated on."""


@dataclass(frozen=True, eq=False)
class Layline:
    """One layline, from the mark outwards.

    Attributes
    ----------
    mark : str
        The mark it leads to.
    kind : {"tack", "gybe"}
        Close-hauled (``tack``) or at the best downwind VMG angle (``gybe``).
    tack : {"port", "starboard"}
        The tack (or gybe) sailed along it.
    x, y : ndarray
        Points [m], the first at the mark.
    t : ndarray
        Time a boat sailing it passes each point [epoch s] (the last is the earliest).
    heading_deg : ndarray
        Heading sailed at each point [°].
    """

    mark: str
    kind: LaylineKind
    tack: Side
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    t: NDArray[np.float64]
    heading_deg: NDArray[np.float64]

    @property
    def length_m(self) -> float:
        """Length along the points [m]."""
        return float(np.sum(np.hypot(np.diff(self.x), np.diff(self.y))))


class _VmgTable:
    """Best-VMG angles on a TWS grid of :data:`TWS_NODES_PER_MS` nodes per m s⁻¹, filled
    as needed and interpolated linearly (the angle is smooth in TWS: the error is of order
    0.001°; a TWS on a node is exact)."""

    def __init__(self, boat: BoatModel, kind: LaylineKind) -> None:
        self.boat, self.kind = boat, kind
        self.nodes: dict[int, float] = {}

    def __call__(self, tws_ms: NDArray) -> NDArray[np.float64]:
        pos = np.asarray(tws_ms, dtype=float) * TWS_NODES_PER_MS
        lo = np.floor(pos).astype(np.int64)
        need = sorted(
            {*lo.reshape(-1).tolist(), *(lo + 1).reshape(-1).tolist()} - self.nodes.keys()
        )
        if need:
            vals = vmg_angles(self.boat, np.array(need, dtype=float) / TWS_NODES_PER_MS, self.kind)
            self.nodes.update(zip(need, vals.tolist(), strict=True))
        a0 = np.vectorize(self.nodes.__getitem__, otypes=[float])(lo)
        a1 = np.vectorize(self.nodes.__getitem__, otypes=[float])(lo + 1)
        w = pos - lo
        return np.where(w == 0.0, a0, a0 + w * (a1 - a0))


def _state(
    wind: WindField,
    tables: tuple[_VmgTable, _VmgTable],
    boat: BoatModel,
    sign: NDArray,
    tack: NDArray,
    t: NDArray,
    x: NDArray,
    y: NDArray,
) -> tuple[NDArray, NDArray]:
    """Heading sailed [°] and boat speed [m s⁻¹] at the given points (vectorised);
    ``tack`` marks the points of tack laylines (the others are gybe laylines)."""
    tws, twd = wind_speed_direction(*wind.sample(t, x, y))
    twa = np.empty_like(tws)
    for table, on in ((tables[0], tack), (tables[1], ~tack)):
        if on.any():
            twa[on] = table(tws[on])
    heading = wrap360(twd - sign * twa)  # starboard (+1): wind over the right side
    return heading, np.asarray(boat.steady_speed(tws, twa), dtype=float)


def vmg_angles(boat: BoatModel, tws_ms: NDArray, kind: LaylineKind) -> NDArray[np.float64]:
    """Best upwind (``tack``) or downwind (``gybe``) VMG angle [°] at each TWS [m s⁻¹]
    (vectorised through the boat's polar when it has one)."""
    polar = boat.routing_polar()
    tws = np.asarray(tws_ms, dtype=float)
    if polar is not None:
        return (polar.vmg_upwind(tws) if kind == "tack" else polar.vmg_downwind(tws))[0]
    k = 0 if kind == "tack" else 1
    return np.array([boat.vmg_angles_deg(float(s))[k] for s in tws.reshape(-1)]).reshape(tws.shape)


def _inside(wind: WindField, t: NDArray, x: NDArray, y: NDArray) -> NDArray[np.bool_]:
    ok = np.isfinite(t) & np.isfinite(x) & np.isfinite(y)
    if wind.clamp:
        return ok
    return ok & wind.coverage.contains(t, x, y)


def trace_laylines(
    marks: Sequence[tuple[str, tuple[float, float]]],
    t_mark: float,
    wind: WindField,
    boat: BoatModel,
    kind: LaylineKind,
    length_m: float,
    *,
    n_steps: int = N_STEPS,
) -> tuple[Layline, ...]:
    """The starboard and port laylines to each mark, traced back ``length_m`` from it.

    Parameters
    ----------
    marks : sequence of (str, (float, float))
        Mark names and positions [m] (one mark, or a gate's two).
    t_mark : float
        When the boat rounds the mark [epoch s]; the traces run back in time from it.
    wind : WindField
        Wind field.
    boat : BoatModel
        Best-VMG angles (:meth:`~sailroute.boat.model.BoatModel.vmg_angles_deg`) and
        steady speeds.
    kind : {"tack", "gybe"}
        Upwind (best upwind VMG angle) or downwind (best downwind VMG angle) laylines.
    length_m : float
        Length of each trace [m] (about the leg's length).
    n_steps : int
        Integration steps.

    Returns
    -------
    tuple of Layline
        For each mark in order: starboard, then port.  A trace that leaves the wind's
        coverage ends at its last point inside it.
    """
    specs = [(name, xy, float(t_mark), float(length_m)) for name, xy in marks]
    return trace_many(specs, kind_of=[kind] * len(specs), wind=wind, boat=boat, n_steps=n_steps)


def trace_many(
    specs: Sequence[tuple[str, tuple[float, float], float, float]],
    kind_of: Sequence[LaylineKind],
    wind: WindField,
    boat: BoatModel,
    n_steps: int,
) -> tuple[Layline, ...]:
    """Starboard and port laylines of each ``(mark, xy, t_mark, length)`` in ``specs``,
    traced together (one wind sample per half step for all of them)."""
    n = 2 * len(specs)
    sign = np.tile([1.0, -1.0], len(specs))
    tack = np.repeat([k == "tack" for k in kind_of], 2)
    x = np.repeat([float(sp[1][0]) for sp in specs], 2)
    y = np.repeat([float(sp[1][1]) for sp in specs], 2)
    t = np.repeat([sp[2] for sp in specs], 2)
    ds_all = np.repeat([sp[3] / n_steps for sp in specs], 2)
    xs, ys, ts, hs = [x.copy()], [y.copy()], [t.copy()], []
    active = _inside(wind, t, x, y)
    h = np.full(n, np.nan)
    tables = (_VmgTable(boat, "tack"), _VmgTable(boat, "gybe"))
    for _ in range(n_steps):
        if not active.any():
            break
        a = np.flatnonzero(active)
        ds = ds_all[a]
        h1, v1 = _state(wind, tables, boat, sign[a], tack[a], t[a], x[a], y[a])
        h[a] = h1
        ex, ey = heading_unit(h1)
        with np.errstate(divide="ignore", invalid="ignore"):
            dt1 = np.where(v1 > 0, ds / v1, 0.0)
        xm, ym, tm = x[a] - 0.5 * ds * ex, y[a] - 0.5 * ds * ey, t[a] - 0.5 * dt1
        ok = _inside(wind, tm, xm, ym)
        h2, v2 = h1.copy(), v1.copy()
        if ok.any():
            h2[ok], v2[ok] = _state(
                wind, tables, boat, sign[a][ok], tack[a][ok], tm[ok], xm[ok], ym[ok]
            )
        ex2, ey2 = heading_unit(h2)
        with np.errstate(divide="ignore", invalid="ignore"):
            dt2 = np.where(v2 > 0, ds / v2, 0.0)
        nx, ny, nt = x[a] - ds * ex2, y[a] - ds * ey2, t[a] - dt2
        keep = ok & _inside(wind, nt, nx, ny)
        moved = a[keep]
        x[moved], y[moved], t[moved] = nx[keep], ny[keep], nt[keep]
        active[a[~keep]] = False
        xs.append(np.where(active, x, np.nan))
        ys.append(np.where(active, y, np.nan))
        ts.append(np.where(active, t, np.nan))
        hs.append(h.copy())
    px_all, py_all, pt_all = np.array(xs), np.array(ys), np.array(ts)  # (steps + 1, n)
    ph_all = np.array(hs) if hs else np.empty((0, n))
    out = []
    for k in range(n):
        good = np.isfinite(px_all[:, k])
        m = int(good.sum())  # a prefix: a trace that stops stays stopped
        heads = ph_all[: max(m - 1, 0), k]
        last = heads[-1] if heads.size else float("nan")
        out.append(
            Layline(
                specs[k // 2][0],
                kind_of[k // 2],
                "starboard" if sign[k] > 0 else "port",
                px_all[:m, k],
                py_all[:m, k],
                pt_all[:m, k],
                np.append(heads, last)[:m],
            )
        )
    return tuple(out)


def leg_layline_kind(mode: str | None) -> LaylineKind | None:
    """``tack`` for an upwind leg, ``gybe`` for a downwind one, None otherwise."""
    return {"upwind": "tack", "downwind": "gybe"}.get(mode or "")  # type: ignore[return-value]
