"""Samples of one log for :func:`sailroute.boat.fit.fit_polar`, the TWS nodes of a fit,
and a fitted polar's errors against a reference.

:func:`samples_from_log` reads an **instrument log** (CSV read by
:func:`sailroute.track.read.read_track`) with TWS and TWA (or TWD and a heading) and a boat
speed: ``bsp`` if the log has it, else ``sog``.  ``sailroute polar fit`` learns from a
fleet instead (:mod:`sailroute.boat.learn`); it shares :func:`auto_tws_bins` and
:func:`compare_polars`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.boat.fit import twa_sign_from
from sailroute.boat.polar import Polar
from sailroute.errors import InputError
from sailroute.track.model import Track
from sailroute.units import wrap180

__all__ = [
    "DEFAULT_TWS_STEP",
    "FitSamples",
    "PolarErrors",
    "auto_tws_bins",
    "compare_polars",
    "samples_from_log",
]


DEFAULT_TWS_STEP: Final = {"kn": 2.0, "m/s": 1.0}
"""Spacing of the automatic TWS columns per display unit."""


@dataclass(frozen=True, eq=False)
class FitSamples:
    """Per-sample arrays for :func:`~sailroute.boat.fit.fit_polar` (SI units).

    Attributes
    ----------
    t_s : ndarray
        Time [epoch s].
    tws_ms, twa_deg, bsp_ms : ndarray
        True wind speed [m s⁻¹], signed TWA [°], boat speed [m s⁻¹].
    heading_deg : ndarray or None
        Heading or COG [°] for the turn-rate filter.
    speed_source : str
        ``"bsp"``, ``"sog"`` or ``"sog (from positions)"``.
    wind_source : str
        ``"log"`` or ``"course <file>, scenario <name>"``.
    notes : tuple of str
        What was derived or dropped on the way.
    """

    t_s: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    twa_deg: NDArray[np.float64]
    bsp_ms: NDArray[np.float64]
    heading_deg: NDArray[np.float64] | None
    speed_source: str
    wind_source: str
    notes: tuple[str, ...] = ()


@dataclass(frozen=True, eq=False)
class PolarErrors:
    """Fitted polar vs a reference polar on the covered cells.

    Attributes
    ----------
    rms_ms, mean_ms : float
        RMS and mean of ``fitted - reference`` [m s⁻¹].
    rms_pct, mean_pct : float
        The same relative to the reference [%].
    twa_deg : ndarray
        TWA rows that have covered cells [°].
    row_mean_pct, row_rms_pct : ndarray
        Mean and RMS relative error per row [%].
    row_cells : ndarray of int
        Covered cells per row.
    n_cells : int
        Covered cells compared.
    """

    rms_ms: float
    mean_ms: float
    rms_pct: float
    mean_pct: float
    twa_deg: NDArray[np.float64]
    row_mean_pct: NDArray[np.float64]
    row_rms_pct: NDArray[np.float64]
    row_cells: NDArray[np.int64]
    n_cells: int


def samples_from_log(track: Track) -> FitSamples:
    """Samples from an instrument log: its TWS, TWA and boat speed channels.

    TWA is taken signed from the log; a log that stores only ``|TWA|`` gets its
    sign from ``wrap180(TWD - heading)`` (heading, else COG) when it has those.
    A log with TWD and a heading but no TWA gets ``TWA = wrap180(TWD - heading)``.
    Boat speed is ``bsp`` if the log has it, else ``sog``.

    Raises
    ------
    InputError
        No TWS, no TWA (nor TWD with a heading/COG), or no boat speed.
    """
    ch = track.channels
    src = track.source or track.name
    notes: list[str] = []
    heading = finite_channel(ch, "hdg_deg")
    hname = "hdg"
    if heading is None:
        heading, hname = finite_channel(ch, "cog_deg"), "cog"
    tws = finite_channel(ch, "tws_ms")
    if tws is None:
        raise InputError(
            f"{src}: no true wind speed column (tws); an instrument log needs tws, twa and "
            "bsp or sog (map other headers with --columns tws=...,twa=...), or fit a GPS track "
            "against a course's wind with --course COURSE --scenario NAME"
        )
    twa = finite_channel(ch, "twa_deg")
    twd = finite_channel(ch, "twd_deg")
    if twa is None:
        if twd is None or heading is None:
            raise InputError(
                f"{src}: no true wind angle column (twa), nor twd with hdg or cog to derive "
                "it; map the column with --columns twa=HEADER"
            )
        twa = wrap180(twd - heading)
        notes.append(f"TWA from TWD - {hname}")
    elif np.nanmin(twa) >= 0 and twd is not None and heading is not None:
        twa = twa_sign_from(twd, heading, twa)
        notes.append(f"TWA is unsigned in the log; tack (sign) from TWD - {hname}")
    elif np.nanmin(twa) >= 0:
        notes.append(
            "TWA is unsigned and the log has no TWD/heading: tacks and gybes are "
            "found by the turn-rate rule only"
        )
    bsp = finite_channel(ch, "bsp_ms")
    source = "bsp"
    if bsp is None:
        bsp, source = finite_channel(ch, "sog_ms"), "sog"
    if bsp is None:
        raise InputError(
            f"{src}: no boat speed column (bsp, or sog); map it with --columns bsp=HEADER"
        )
    return FitSamples(
        t_s=np.asarray(track.t_s, float),
        tws_ms=tws,
        twa_deg=twa,
        bsp_ms=bsp,
        heading_deg=heading,
        speed_source=source,
        wind_source="log",
        notes=tuple(notes),
    )


def finite_channel(ch: Any, key: str) -> NDArray[np.float64] | None:
    a = ch.get(key)
    if a is None:
        return None
    a = np.asarray(a, float)
    return a if np.isfinite(a).any() else None


def auto_tws_bins(tws_ms: NDArray, step_ms: float) -> NDArray[np.float64]:
    """TWS nodes every ``step_ms`` [m s⁻¹] spanning the 1st-99th percentile of the data."""
    finite = tws_ms[np.isfinite(tws_ms)]
    if finite.size == 0:
        raise InputError("the log has no finite TWS value; check the tws column and its unit")
    lo, hi = np.percentile(finite, [1.0, 99.0])
    first = max(step_ms, np.round(lo / step_ms) * step_ms)
    last = max(first, np.round(hi / step_ms) * step_ms)
    return np.arange(first, last + 0.5 * step_ms, step_ms)


def compare_polars(polar: Polar, covered: NDArray[np.bool_], reference: Polar) -> PolarErrors:
    """Errors of a fitted polar against ``reference`` on its covered cells.

    The fitted speed of each covered cell (``polar.speed_ms``, ``covered`` of the same
    shape: a fit's covered or a learned polar's learned cells) is compared with
    ``reference.speed`` at the cell's node (TWS, TWA).  Only cells inside the
    reference's own table (its first to last TWA row and TWS column) count: outside it
    the reference is a taper or a clamp, not a measurement.
    """
    p = polar
    ref = reference.speed(p.tws_ms[None, :], p.twa_deg[:, None])
    inside = (
        (p.twa_deg[:, None] >= reference.twa_deg[0])
        & (p.twa_deg[:, None] <= reference.twa_deg[-1])
        & (p.tws_ms[None, :] >= reference.tws_ms[0])
        & (p.tws_ms[None, :] <= reference.tws_ms[-1])
    )
    cov = np.asarray(covered, dtype=bool) & inside
    if not cov.any():
        raise InputError(
            f"reference polar {reference.name!r} covers TWA {reference.twa_deg[0]:g}-"
            f"{reference.twa_deg[-1]:g} deg, TWS {reference.tws_ms[0]:.3g}-"
            f"{reference.tws_ms[-1]:.3g} m/s: no covered cell of the fit lies inside; "
            "check the reference's units (--reference-unit)"
        )
    d = (p.speed_ms - ref)[cov]
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(ref > 0, p.speed_ms / ref - 1.0, np.nan) * 100.0
    rows = np.flatnonzero(cov.any(axis=1))
    row_mean = np.array([np.nanmean(rel[i, cov[i]]) for i in rows])
    row_rms = np.array([np.sqrt(np.nanmean(rel[i, cov[i]] ** 2)) for i in rows])
    r = rel[cov]
    return PolarErrors(
        rms_ms=float(np.sqrt(np.mean(d**2))),
        mean_ms=float(np.mean(d)),
        rms_pct=float(np.sqrt(np.nanmean(r**2))),
        mean_pct=float(np.nanmean(r)),
        twa_deg=p.twa_deg[rows],
        row_mean_pct=row_mean,
        row_rms_pct=row_rms,
        row_cells=cov[rows].sum(axis=1).astype(np.int64),
        n_cells=int(cov.sum()),
    )
