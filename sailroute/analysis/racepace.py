"""Race pace: how a fleet's whole legs compare with the learned polar's optimal legs.

A polar learned from steady straight-line sailing is the boat between manoeuvres.  A race
is more: tacks and gybes, the extra boards a boundary or a shift forces, the bear-away at
a mark.  Routed in a race's mean wind, a steady polar plans the race faster than the
fleet sails it (SailGP Auckland 2025: 12 % on the races' legs 2-6, ``docs/polar-fit.md``).

The race pace measures that gap on the races the polar was learned from.  Each race is
routed with the level's polar in its mean wind (the mean of the wind every sample was
judged in), and each boat's sailed leg ``k`` (both ends found) gives::

    f = (T_route - P) / (T_sailed - P)

with ``P`` the route's own manoeuvre penalties (tacks and gybes at the course's
``routing`` settings), so that a plan with the polar scaled by ``f`` sails the leg in
``T_sailed``.  Per boat and point of sail (the plan's leg mode: upwind, reach, downwind)
the factor is the ratio of the sums over its legs; the level's pace is the level's
percentile of the boats' factors, as the table's levels are (``median``: the median boat's
pace against the median table).  A point of sail without a timed leg takes the mean of the
others.  A course uses it with ``boat: {polar: FILE.json, level: median, pace: race}``:
the table scaled per point of sail as by a course's ``efficiency``.

This folds in the fleet-relative scaling of ``analyze --reference fleet``
(:mod:`sailroute.analysis.fleetpolar`): the same three factors on the same bands, here
from leg times rather than from speed ratios.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.learnsamples import FleetSamples
from sailroute.boat.learn import LearnedPolar
from sailroute.course.model import Course
from sailroute.units import circular_mean_deg

MAD_TO_SD = 1.4826
"""Median absolute deviation to standard deviation, for a normal scatter [-]."""
MIN_LEG_S = 10.0
"""Legs sailed faster than this after the penalties are left out [s]."""


def race_mean_wind(samples: FleetSamples, race: str) -> tuple[float, float] | None:
    """Mean TWS [m s⁻¹] and circular-mean TWD [°] of a race's samples (None: none)."""
    s = [x for x in samples.series if x.race == race]
    if not s:
        return None
    tws = np.concatenate([x.tws_ms for x in s])
    twd = np.concatenate([x.twd_deg for x in s])
    ok = np.isfinite(tws) & np.isfinite(twd)
    if not ok.any():
        return None
    return float(np.mean(tws[ok])), float(circular_mean_deg(twd[ok]))


def pace_factors(
    route_s: NDArray, penalty_s: NDArray, sailed_s: NDArray, band: NDArray, boat: NDArray
) -> NDArray[np.float64]:
    """Per boat and point of sail, ``sum(T_route - P) / sum(T_sailed - P)``.

    Parameters
    ----------
    route_s, penalty_s, sailed_s : ndarray, shape (legs,)
        Per sailed leg: the route's time, its penalties and the boat's time [s].
    band : ndarray of int
        Per leg: 0 upwind, 1 reach, 2 downwind.
    boat : ndarray of int
        Per leg: the boat (0 .. boats - 1).

    Returns
    -------
    ndarray, shape (boats, 3)
        NaN where a boat has no leg of that band.
    """
    nb = int(boat.max()) + 1 if boat.size else 0
    a = np.maximum(route_s - penalty_s, 0.0)
    b = sailed_s - penalty_s
    ok = (b >= MIN_LEG_S) & np.isfinite(a) & np.isfinite(b)
    num = np.zeros((nb, 3))
    den = np.zeros((nb, 3))
    np.add.at(num, (boat[ok], band[ok]), a[ok])
    np.add.at(den, (boat[ok], band[ok]), b[ok])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / den, np.nan)


def pace_scatter(
    route_s: NDArray, penalty_s: NDArray, sailed_s: NDArray, band: NDArray, pace: NDArray
) -> float | None:
    """The scatter of ``log`` of the legs' own factors about the level's pace of their
    point of sail [-]: ``1.4826 MAD`` (the standard deviation of a normal scatter, robust
    to the few legs a start, a penalty or a data gap makes several times too long; None:
    fewer than 3 legs).

    One leg's factor is ``(T_route - P) / (T_sailed - P)`` (:func:`pace_factors` on one
    leg); the scatter holds what moves one boat's leg off the race pace: the boat, the
    shifts and tactics of that leg, the race.
    """
    a = np.maximum(route_s - penalty_s, 0.0)
    b = sailed_s - penalty_s
    ok = (b >= MIN_LEG_S) & np.isfinite(a) & np.isfinite(b) & (a > 0)
    if ok.sum() < 3:
        return None
    r = np.log(a[ok] / b[ok]) - np.log(np.asarray(pace, dtype=float)[band[ok]])
    return float(MAD_TO_SD * np.median(np.abs(r - np.median(r))))


def level_pace(factors: NDArray, q: float) -> tuple[float, float, float] | None:
    """The ``q``-th percentile [%] of the boats' factors per point of sail; a band
    without any boat takes the mean of the others (None: no band has one)."""
    out = np.full(3, np.nan)
    for k in range(3):
        v = factors[:, k]
        v = v[np.isfinite(v)]
        if v.size:
            out[k] = float(np.percentile(v, q))
    if not np.isfinite(out).any():
        return None
    out = np.where(np.isfinite(out), out, np.nanmean(out))
    return (float(out[0]), float(out[1]), float(out[2]))


def race_pace(
    learned: LearnedPolar, courses: Sequence[Course], samples: FleetSamples
) -> tuple[LearnedPolar, tuple[str, ...]]:
    """Each level's race pace from the races it was learned on (module docstring).

    Parameters
    ----------
    learned : LearnedPolar
    courses : sequence of Course
        The races (their routing settings give the penalties).
    samples : FleetSamples
        The samples and leg times the polar was learned from
        (:func:`sailroute.analysis.learnsamples.fleet_samples`).

    Returns
    -------
    learned : LearnedPolar
        With each level's race pace and the legs' scatter about it (:func:`pace_scatter`)
        set (unchanged when no leg was timed).
    notes : tuple of str
        One line per race routed (the paces are the levels' own,
        :attr:`sailroute.boat.learn.LevelTable.race_pace`).
    """
    from sailroute.planning.result import make_plan
    from sailroute.planning.route import route_course, settings_for
    from sailroute.wind.uniform import UniformWind

    boats = sorted({lg.boat for lg in samples.legs})
    notes: list[str] = []
    rows: dict[str, list[tuple[float, float, float, int, int]]] = {k: [] for k in learned.levels}
    for c in courses:
        legs = [lg for lg in samples.legs if lg.race == c.name]
        wind = race_mean_wind(samples, c.name)
        if not legs or wind is None:
            continue
        field = UniformWind(*wind)
        settings = settings_for(c)
        for name in learned.levels:
            results = route_course(c, field, learned.polar(name), settings)
            plan = make_plan(c, "race mean", results, field)
            for k, pl in enumerate(plan.legs):
                r = pl.result
                pen = r.n_tacks * settings.tack_penalty_s + r.n_gybes * settings.gybe_penalty_s
                band = ("upwind", "reach", "downwind").index(pl.mode or "reach")
                for lg in legs:
                    sailed = float(lg.bounds[k + 1] - lg.bounds[k])
                    if np.isfinite(sailed):
                        rows[name].append((r.time_s, pen, sailed, band, boats.index(lg.boat)))
        notes.append(
            f"race pace: {c.name} routed in its mean wind {wind[0]:.2f} m/s from "
            f"{wind[1] % 360:.0f} deg, {sum(np.isfinite(np.diff(lg.bounds)).sum() for lg in legs)} "
            "sailed legs"
        )
    pace: dict[str, tuple[float, float, float]] = {}
    scatter: dict[str, float] = {}
    for name, t in learned.levels.items():
        if not rows[name]:
            continue
        a = np.asarray(rows[name], dtype=float)
        band_of = a[:, 3].astype(int)
        f = pace_factors(a[:, 0], a[:, 1], a[:, 2], band_of, a[:, 4].astype(int))
        p = level_pace(f, t.percentile)
        if p is not None:
            pace[name] = p
            sd = pace_scatter(a[:, 0], a[:, 1], a[:, 2], band_of, np.asarray(p))
            if sd is not None:
                scatter[name] = sd
    return learned.with_race_pace(pace, scatter), tuple(notes)


__all__ = [
    "MAD_TO_SD",
    "MIN_LEG_S",
    "level_pace",
    "pace_factors",
    "pace_scatter",
    "race_mean_wind",
    "race_pace",
]
