"""A reference polar from what the fleet sails: the course's polar scaled to the fleet.

A race analysis against a polar measures the polar as much as the sailing: a Snipe
judged with the ILCA polar "gains" minutes, a boat in a light-air sea state loses to a
flat-water VPP.  The fleet-relative reference keeps the *shape* of the course's polar
(its best VMG angles, how speed grows with the wind) and takes its *level* from the
fleet's own tracks:

1. every straight-line point of every boat (outside the manoeuvre windows, the polar
   above ``POLAR_MIN_MS``) gives a ratio ``r = SOG / polar(TWS, |TWA|)`` in the wind the
   point was judged in;
2. per TWA band (``band_deg`` wide), the ``percentile`` of ``r`` over the fleet is the
   band's factor (the speed the fleet's better moments reach, not its mean), for bands
   with at least ``min_count`` points;
3. the factors are interpolated linearly in TWA between covered bands and held
   constant beyond the first and last (no extrapolated trend); the reference polar's
   rows are multiplied by the factor at their TWA.

One factor per band for every TWS: a race's TWS range is narrow, and a per-cell fit
from one race's tracks would be noise.  The method and its limits are in
``docs/analysis.md``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.loss import POLAR_MIN_MS, manoeuvre_mask
from sailroute.boat.polar import Polar
from sailroute.errors import InputError

if TYPE_CHECKING:  # pragma: no cover
    from sailroute.analyze import TrackAnalysis

PERCENTILE: Final = 90.0
"""Percentile of the fleet's speed ratios that sets each band's level [%]."""
BAND_DEG: Final = 10.0
"""Width of the TWA bands [°]."""
MIN_COUNT: Final = 20
"""Points a band needs to set its own factor."""


@dataclass(frozen=True, eq=False)
class FleetPolar:
    """The fleet-relative reference polar and how it was made.

    Attributes
    ----------
    polar : Polar
        The reference polar scaled per TWA row.
    band_twa_deg : ndarray
        Centres of the TWA bands [°].
    factor : ndarray
        Each band's factor (NaN: too few points) [-].
    count : ndarray of int
        Points per band.
    percentile : float
        Percentile used [%].
    boats : tuple of str
        The tracks the factors come from.
    """

    polar: Polar
    band_twa_deg: NDArray[np.float64]
    factor: NDArray[np.float64]
    count: NDArray[np.int64]
    percentile: float
    boats: tuple[str, ...]

    def describe(self) -> str:
        """One line: the factors of the covered bands."""
        ok = np.isfinite(self.factor)
        parts = ", ".join(f"{c:.0f}°: {f:.2f}" for c, f in zip(self.band_twa_deg[ok],
                                                                 self.factor[ok], strict=True))
        return (f"fleet-relative polar ({self.polar.name}): P{self.percentile:.0f} of SOG/polar "
                f"of {len(self.boats)} track(s) per TWA band: {parts}")


def band_factors(twa_deg: NDArray, ratio: NDArray, *, percentile: float = PERCENTILE,
                 band_deg: float = BAND_DEG, min_count: int = MIN_COUNT
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Per-band percentile of speed ratios.

    Parameters
    ----------
    twa_deg : ndarray
        |TWA| of each point [°] (sign ignored).
    ratio : ndarray
        SOG / polar at each point [-]; non-finite values are left out.
    percentile, band_deg, min_count
        See the module notes.

    Returns
    -------
    centres, factor, count : ndarray
        Band centres [°], factors (NaN where ``count < min_count``), counts.
    """
    if not 0.0 < percentile <= 100.0:
        raise InputError(f"fleet polar: percentile must be in (0, 100]; got {percentile}")
    if not 0.0 < band_deg <= 90.0:
        raise InputError(f"fleet polar: band_deg must be in (0, 90]; got {band_deg}")
    a = np.abs(np.asarray(twa_deg, float))
    r = np.asarray(ratio, float)
    ok = np.isfinite(a) & np.isfinite(r) & (r > 0)
    n = int(np.ceil(180.0 / band_deg))
    centres = (np.arange(n) + 0.5) * band_deg
    idx = np.minimum((a[ok] / band_deg).astype(np.int64), n - 1)
    rr = r[ok]
    count = np.bincount(idx, minlength=n).astype(np.int64)
    factor = np.full(n, np.nan)
    order = np.argsort(idx, kind="stable")
    groups = np.split(rr[order], np.cumsum(count)[:-1])
    for k, g in enumerate(groups):
        if g.size >= min_count:
            factor[k] = float(np.percentile(g, percentile))
    return centres, factor, count


def scale_polar(reference: Polar, centres: NDArray, factor: NDArray, name: str) -> Polar:
    """``reference`` with each TWA row multiplied by the band factor at its angle.

    Factors are interpolated linearly between covered bands and held beyond the
    outermost ones.

    Raises
    ------
    InputError
        No band has a factor.
    """
    ok = np.isfinite(factor)
    if not ok.any():
        raise InputError("fleet polar: no TWA band has enough straight-line points to scale "
                         "the polar; analyse more or longer tracks, or judge against the "
                         "course's polar")
    f = np.interp(reference.twa_deg, centres[ok], factor[ok])
    return Polar.from_arrays(reference.twa_deg, reference.tws_ms,
                             reference.speed_ms * f[:, None], name=name,
                             interpolation=reference.interpolation)


def fleet_polar(analyses: Sequence[TrackAnalysis], reference: Polar, *,
                percentile: float = PERCENTILE, band_deg: float = BAND_DEG,
                min_count: int = MIN_COUNT) -> FleetPolar:
    """The fleet-relative reference from analyses made against ``reference``.

    Parameters
    ----------
    analyses : sequence of TrackAnalysis
        The fleet's tracks analysed once against the course's polar (their
        per-point TWA, SOG and polar speed, and their manoeuvre times).
    reference : Polar
        The course's polar.

    Returns
    -------
    FleetPolar
    """
    twa: list[NDArray] = []
    ratio: list[NDArray] = []
    for a in analyses:
        p = a.points
        man_t = np.array([m.t for leg in a.legs for m in leg.manoeuvres])
        straight = ~manoeuvre_mask(p.t, man_t)
        good = straight & (p.polar_ms >= POLAR_MIN_MS)
        twa.append(p.twa_deg[good])
        ratio.append(p.sog_ms[good] / p.polar_ms[good])
    centres, factor, count = band_factors(np.concatenate(twa) if twa else np.empty(0),
                                          np.concatenate(ratio) if ratio else np.empty(0),
                                          percentile=percentile, band_deg=band_deg,
                                          min_count=min_count)
    polar = scale_polar(reference, centres, factor, f"{reference.name} x fleet")
    return FleetPolar(polar, centres, factor, count, percentile,
                      tuple(a.track.name for a in analyses))


__all__ = ["BAND_DEG", "MIN_COUNT", "PERCENTILE", "FleetPolar", "band_factors", "fleet_polar",
           "scale_polar"]
