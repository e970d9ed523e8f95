"""What an analysis of a sailed track finds: per point, per leg, per track.

Made by :func:`sailroute.analysis.debrief.analyze_track`; written and drawn by
:mod:`sailroute.report.analysis`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.loss import LossSplit
from sailroute.analysis.manoeuvres import SailedManoeuvre
from sailroute.analysis.segment import Segmentation
from sailroute.analysis.windsource import ABOVE_POLAR_PCT
from sailroute.course.model import Course
from sailroute.routing.types import LegResult
from sailroute.track.model import Track
from sailroute.wind.base import WindField

__all__ = ["LegAnalysis", "PointTable", "TrackAnalysis"]


@dataclass(frozen=True, eq=False)
class PointTable:
    """Per-point quantities of the analysed part of a track (start crossing to finish).

    All arrays have the same length.  ``leg`` is 1-based; a boundary time appears
    twice (end of one leg, start of the next), as in ``track.csv`` of ``plan``.

    Attributes
    ----------
    leg : ndarray of int
    t : ndarray
        [epoch s].
    x, y : ndarray
        [m], course frame.
    lat, lon : ndarray
        [°].
    sog_ms, cog_deg : ndarray
        Speed [m s⁻¹] and course [°] over ground (smoothed over ``SMOOTH_S``).
    tws_ms, twd_deg, twa_deg : ndarray
        Scenario wind at the point and TWA from COG [m s⁻¹, °, ° signed].
    polar_ms, polar_pct : ndarray
        Polar speed [m s⁻¹] and ``100 · SOG / polar`` [%] (NaN where the polar is
        below ``POLAR_MIN_MS``).
    vmg_ms : ndarray
        Velocity made good [m s⁻¹]: against the wind on upwind legs, with it on
        downwind legs, towards the target centre on reaches.
    loss_s : ndarray
        Cumulative time lost against the optimal legs [s].
    """

    leg: NDArray[np.int64]
    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    lat: NDArray[np.float64]
    lon: NDArray[np.float64]
    sog_ms: NDArray[np.float64]
    cog_deg: NDArray[np.float64]
    tws_ms: NDArray[np.float64]
    twd_deg: NDArray[np.float64]
    twa_deg: NDArray[np.float64]
    polar_ms: NDArray[np.float64]
    polar_pct: NDArray[np.float64]
    vmg_ms: NDArray[np.float64]
    loss_s: NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class LegAnalysis:
    """One leg, sailed against optimal.

    Attributes
    ----------
    index : int
        0-based leg index.
    label : str
        ``"from -> to"``.
    mode : str
        Wind mode at the leg start (upwind / reach / downwind).
    t_start, t_end : float
        Sailed leg start and end [epoch s]; NaN when unknown (a data gap, or never
        reached: see ``note``).
    start_xy, end_xy : tuple of float
        Where the boat started and ended the leg [m].
    detected : bool
        True when the end was found from the geometry (False: given).
    sailed_time_s, optimal_time_s, loss_s : float
        [s]; ``loss_s = sailed − optimal``.  An unknown leg (``known`` False) has NaN
        sailed time, loss and split, and an optimal time only when its start is known.
    sailed_distance_m, optimal_distance_m : float
        [m].
    sailed_tacks, sailed_gybes, optimal_tacks, optimal_gybes : int
    manoeuvres : tuple of SailedManoeuvre
        Sailed tacks/gybes in this leg.
    mean_vmg_ms, mean_sog_ms, mean_polar_pct : float
        Time-weighted means over the leg (polar % outside manoeuvre windows).
    split : LossSplit
        ``loss_s`` split into manoeuvres, speed and route (``analysis/loss.py``).
    side_sailed, side_optimal : str
        ``left`` / ``middle`` / ``right`` of the leg axis, looking from the leg start
        to the target; ``lateral_*_m`` the time-mean offsets [m] (+ right).
    optimal : LegResult or None
        The optimal route of the leg (None: the leg's start is unknown).
    note : str
        Why the leg is unknown, and when its start lies inside a clearance of the race
        area, that its optimal route ignores the area (empty otherwise).
    wind_source, wind_label : str
        The wind the leg was judged in (:data:`sailroute.analysis.windsource.KINDS`)
        and what it is.
    """

    index: int
    label: str
    mode: str
    t_start: float
    t_end: float
    start_xy: tuple[float, float]
    end_xy: tuple[float, float]
    detected: bool
    sailed_time_s: float
    optimal_time_s: float
    loss_s: float
    sailed_distance_m: float
    optimal_distance_m: float
    sailed_tacks: int
    sailed_gybes: int
    optimal_tacks: int
    optimal_gybes: int
    manoeuvres: tuple[SailedManoeuvre, ...]
    mean_vmg_ms: float
    mean_sog_ms: float
    mean_polar_pct: float
    split: LossSplit
    side_sailed: str
    side_optimal: str
    lateral_sailed_m: float
    lateral_optimal_m: float
    optimal: LegResult | None
    note: str = ""
    wind_source: str = "scenario"
    wind_label: str = ""

    @property
    def known(self) -> bool:
        """True when the sailed time is known (both ends found outside data gaps)."""
        return bool(np.isfinite(self.sailed_time_s))

    @property
    def above_polar(self) -> bool:
        """Sailed above :data:`~sailroute.analysis.windsource.ABOVE_POLAR_PCT` of the polar
        on average: the polar or the wind cannot be right for this boat."""
        return bool(np.isfinite(self.mean_polar_pct) and self.mean_polar_pct > ABOVE_POLAR_PCT)


@dataclass(frozen=True, eq=False)
class TrackAnalysis:
    """A whole track analysed.

    Attributes
    ----------
    course : Course
    track : Track
    scenario, router : str
    segmentation : Segmentation
        Start report and leg boundaries.
    legs : tuple of LegAnalysis
    points : PointTable
    wind : WindField
        The wind of the first leg (for plots).
    reference : str
        The polar the boat is judged against: ``"course polar <name>"`` or the
        fleet-relative polar's description (:mod:`sailroute.analysis.fleetpolar`).
    """

    course: Course
    track: Track
    scenario: str
    router: str
    segmentation: Segmentation
    legs: tuple[LegAnalysis, ...]
    points: PointTable
    wind: WindField
    reference: str = ""

    @property
    def known_legs(self) -> tuple[LegAnalysis, ...]:
        """The legs with a known sailed time (the totals are over these)."""
        return tuple(leg for leg in self.legs if leg.known)

    @property
    def complete(self) -> bool:
        """True when every leg's time is known."""
        return all(leg.known for leg in self.legs)

    @property
    def sailed_time_s(self) -> float:
        """Sum of the known legs' sailed times [s] (start crossing to finish when complete)."""
        return sum(leg.sailed_time_s for leg in self.known_legs)

    @property
    def optimal_time_s(self) -> float:
        """Sum of the optimal times of the known legs [s]."""
        return sum(leg.optimal_time_s for leg in self.known_legs)

    @property
    def loss_s(self) -> float:
        """Sum of the known legs' losses [s]."""
        return sum(leg.loss_s for leg in self.known_legs)

    @property
    def notes(self) -> tuple[str, ...]:
        """Start findings and why legs are unknown, one sentence each."""
        return self.segmentation.notes
