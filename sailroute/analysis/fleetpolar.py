"""A reference polar from what the fleet sails: the course's polar scaled to the fleet.

A race analysis against a polar measures the polar as much as the sailing: a Snipe
judged with the ILCA polar "gains" minutes, a boat in a light-air sea state loses to a
flat-water VPP.  The fleet-relative reference keeps the *shape* of the course's polar
(its best VMG angles, how speed grows with the wind) and takes its *level* on each
point of sail from the fleet's own tracks:

1. every straight-line point of every boat (outside the manoeuvre windows, the polar
   above ``POLAR_MIN_MS``) gives a ratio ``r = SOG / polar(TWS, |TWA|)`` in the wind the
   point was judged in;
2. on each point of sail of the course's ``efficiency`` bands (upwind below 70°, reach
   70-120°, downwind above 120°), the ``percentile`` of ``r`` over the fleet is the
   band's factor, for bands with at least ``min_count`` points; a band without enough
   points takes the mean of the others;
3. the course's polar is scaled by these factors exactly as a course's
   ``boat: {efficiency: ...}`` scales it (:func:`sailroute.boat.efficiency.scale_polar`).

The factors are :func:`sailroute.boat.efficiency.band_factors`, which ``polar fit`` shares
(its race pace is the same three factors from leg times, :mod:`sailroute.analysis.racepace`;
``--shape`` scales a polar to the learned cells with them).

Three factors, not one per TWA row: the ratio at a single angle carries the error of
the wind direction (a boat 10° higher than the wind it is judged in shows a high ratio
at a low angle), and a per-angle envelope turns that noise into a polar that points
higher than any boat.  The 75th percentile: the pace of the fleet's better moments,
not its mean (against a mean, half of every boat's straight-line sailing "gains").
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.loss import POLAR_MIN_MS, manoeuvre_mask
from sailroute.boat.efficiency import BANDS, band_factors, scale_polar
from sailroute.boat.polar import Polar

PERCENTILE: Final = 75.0
"""Percentile of the fleet's speed ratios that sets each band's factor [%]."""
MIN_COUNT: Final = 30
"""Straight-line points a band needs to set its own factor."""
MAX_FACTOR: Final = 3.0
"""A fleet more than this many times faster than the polar is an error: the wind or
the polar cannot be the fleet's."""


@dataclass(frozen=True, eq=False)
class FleetPolar:
    """The fleet-relative reference polar and how it was made.

    Attributes
    ----------
    polar : Polar
        The course's polar scaled per point of sail.
    factor : ndarray, shape (3,)
        Upwind, reach and downwind factors [-] (:data:`sailroute.boat.efficiency.BANDS`).
    count : ndarray of int, shape (3,)
        Straight-line points per band.
    percentile : float
        Percentile used [%].
    boats : tuple of str
        The tracks the factors come from.
    """

    polar: Polar
    factor: NDArray[np.float64]
    count: NDArray[np.int64]
    percentile: float
    boats: tuple[str, ...]

    def describe(self) -> str:
        """One line: the factors and their support."""
        parts = ", ".join(
            f"{b} x{f:.2f} ({n} pts{'' if n >= MIN_COUNT else ', too few: the others mean'})"
            for b, f, n in zip(BANDS, self.factor, self.count, strict=True)
        )
        return (
            f"fleet-relative polar: {self.polar.name} scaled to P{self.percentile:.0f} of "
            f"SOG/polar of {len(self.boats)} track(s): {parts}"
        )


def straight_ratios(
    t: NDArray, twa_deg: NDArray, sog_ms: NDArray, polar_ms: NDArray, man_t: NDArray
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """One track's straight-line points: their TWA [°] and SOG / polar [-].

    Parameters
    ----------
    t, twa_deg, sog_ms, polar_ms : ndarray
        Per point: time [epoch s], TWA in the point's wind [°], SOG and polar speed
        [m s⁻¹].
    man_t : ndarray
        Times of the track's sailed manoeuvres [epoch s]; points inside their windows
        (:func:`sailroute.analysis.loss.manoeuvre_mask`) are left out, as are points
        where the polar is below ``POLAR_MIN_MS``.
    """
    good = ~manoeuvre_mask(t, man_t) & (polar_ms >= POLAR_MIN_MS)
    return twa_deg[good], sog_ms[good] / polar_ms[good]


def fleet_polar(
    samples: Sequence[tuple[NDArray, NDArray]],
    reference: Polar,
    boats: Sequence[str],
    *,
    percentile: float = PERCENTILE,
    min_count: int = MIN_COUNT,
) -> FleetPolar:
    """The fleet-relative reference from the fleet's straight-line speed ratios.

    Parameters
    ----------
    samples : sequence of (ndarray, ndarray)
        Per track, :func:`straight_ratios` of its points judged against ``reference``.
    reference : Polar
        The course's polar.
    boats : sequence of str
        The tracks' names (for the description).

    Returns
    -------
    FleetPolar

    Raises
    ------
    InputError
        Too few straight-line points, or a factor above :data:`MAX_FACTOR`.
    """
    twa = np.concatenate([np.empty(0), *(a for a, _ in samples)])
    ratio = np.concatenate([np.empty(0), *(r for _, r in samples)])
    factor, count = band_factors(twa, ratio, percentile=percentile, min_count=min_count)
    polar = scale_polar(reference, *factor, max_factor=MAX_FACTOR, key="fleet polar").with_name(
        f"{reference.name} x fleet"
    )
    return FleetPolar(polar, factor, count, percentile, tuple(boats))


__all__ = [
    "MAX_FACTOR",
    "MIN_COUNT",
    "PERCENTILE",
    "FleetPolar",
    "band_factors",
    "fleet_polar",
    "straight_ratios",
]
