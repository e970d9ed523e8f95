"""A polar learned from a fleet's tracks: the path ``polar fit`` and ``analyze --reference
learned`` share.

The samples come from :mod:`sailroute.analysis.learnsamples` (each in the wind ``analyze``
judges it in), the steady blocks from :mod:`sailroute.boat.learn_blocks`, the polar at
levels with its uncertainty from :func:`sailroute.boat.learn.learn_polar`, and, with
courses, the race pace from :mod:`sailroute.analysis.racepace`.

:func:`learned_reference` is ``analyze``'s use of it: the analysed fleet's own median
level at its race pace (``docs/analysis.md``, reference), the course's polar filling the
cells the fleet did not sail (its shape, scaled per point of sail to the learned cells,
as ``polar fit --shape``).  ``--reference fleet`` is the case without any cell of its
own: the course's polar scaled by three factors from the fleet's straight-line speed
ratios (:mod:`sailroute.analysis.fleetpolar`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Final

import numpy as np
from numpy.typing import NDArray

from sailroute.analysis.learnsamples import FleetSamples, fleet_samples
from sailroute.boat.fit_samples import auto_tws_bins
from sailroute.boat.learn import N_BOOT, LearnFit, learn_polar
from sailroute.boat.learn_blocks import SteadyRules, steady_blocks
from sailroute.boat.polar import Polar
from sailroute.course.model import Course
from sailroute.track.model import Track

if TYPE_CHECKING:
    from sailroute.progress import Progress

__all__ = [
    "BEATEN_PCT",
    "LearnedReference",
    "beaten_legs",
    "beaten_note",
    "learn_fleet",
    "learned_reference",
]

BEATEN_PCT: Final = 10.0
"""A leg beats the course's polar when it is sailed this much faster than the leg's
optimal route [%]."""
TWS_STEP_MS: Final = 1.0
"""TWS node spacing of ``analyze``'s learned reference [m s⁻¹] (``polar fit``'s default
in m/s; its default in knots is 2 kn)."""
TWA_STEP_DEG: Final = 10.0
"""TWA node spacing of ``analyze``'s learned reference [°] (``polar fit``'s default)."""


def learn_fleet(
    tracks: Sequence[Track],
    courses: Sequence[Course] = (),
    scenario: str | None = None,
    *,
    twa_bins_deg: NDArray[np.float64],
    tws_bins_ms: NDArray[np.float64] | None = None,
    tws_step_ms: float = TWS_STEP_MS,
    levels: Mapping[str, float] | None = None,
    percentile: float = 50.0,
    min_boats: int | None = None,
    min_blocks: int = 3,
    n_boot: int = N_BOOT,
    seed: int = 0,
    rules: SteadyRules | None = None,
    name: str = "fleet",
    shape: Polar | None = None,
    options: Mapping[str, str] | None = None,
    provenance: Mapping[str, Any] | None = None,
    progress: Progress | None = None,
) -> tuple[LearnFit, FleetSamples, tuple[str, ...]]:
    """Learn a polar from a fleet's tracks (module docstring).

    Parameters
    ----------
    tracks : sequence of Track
        The fleet's logs and tracks, one per boat and day.
    courses : sequence of Course
        One per race (none: each log over its whole length in its own measured wind).
    scenario : str, optional
        Scenario of the courses (default each one's first).
    twa_bins_deg : ndarray
        TWA nodes [°].
    tws_bins_ms : ndarray, optional
        TWS nodes [m s⁻¹]; default every ``tws_step_ms`` over the steady blocks' 1st-99th
        percentile (:func:`sailroute.boat.fit_samples.auto_tws_bins`).
    levels, percentile, min_boats, min_blocks, n_boot, seed, name, shape, options
        As :func:`sailroute.boat.learn.learn_polar`.
    rules : SteadyRules, optional
        What counts as steady sailing.
    provenance : mapping, optional
        Kept in the learned polar.
    progress : Progress, optional
        Counts the boats while their samples are taken
        (:func:`~sailroute.analysis.learnsamples.fleet_samples`), then says what is
        learned from (steady blocks, boats, bootstrap replicates); None: silent.

    Returns
    -------
    fit : LearnFit
        With the race pace set when courses give leg times.
    samples : FleetSamples
    notes : tuple of str
        The samples' notes and the race pace's.

    Raises
    ------
    InputError
        As :func:`~sailroute.analysis.learnsamples.fleet_samples` and
        :func:`~sailroute.boat.learn.learn_polar` (no steady sailing, mixed classes, a
        fleet too small for any cell).
    """
    samples = fleet_samples(tracks, courses, scenario, progress=progress)
    blocks = steady_blocks(samples.series, rules)
    if progress is not None:
        progress.note(
            f"learning the polar from {blocks.size} steady blocks of {len(blocks.boats)} "
            f"boat(s) ({n_boot} bootstrap replicates)"
        )
    tws_n = (
        np.asarray(tws_bins_ms, dtype=float)
        if tws_bins_ms is not None
        else auto_tws_bins(blocks.tws_ms, tws_step_ms)
        if blocks.size
        else np.array([tws_step_ms])  # learn_polar says there is no steady sailing
    )
    kw: dict[str, Any] = {} if levels is None else {"levels": levels}
    fit = learn_polar(
        blocks,
        tws_bins_ms=tws_n,
        twa_bins_deg=twa_bins_deg,
        percentile=percentile,
        min_boats=min_boats,
        min_blocks=min_blocks,
        n_boot=n_boot,
        seed=seed,
        name=name,
        options=options,
        provenance={
            **dict(provenance or {}),
            "wind_source_seconds": {
                n: round(float(blocks.dur_s[blocks.source == k].sum()), 1)
                for k, n in enumerate(blocks.sources)
            },
        },
        shape=shape,
        **kw,
    )
    notes = list(samples.notes)
    if courses and samples.legs:
        from sailroute.analysis.racepace import race_pace

        learned, pace_notes = race_pace(fit.learned, courses, samples)
        fit = LearnFit(learned, fit.blocks, fit.cell, fit.factors)
        notes += pace_notes
    return fit, samples, tuple(notes)


@dataclass(frozen=True, eq=False)
class LearnedReference:
    """``analyze``'s reference learned from the analysed fleet.

    Attributes
    ----------
    polar : Polar
        The median level, at its race pace when the legs were timed.
    fit : LearnFit
        What it was learned from.
    pace : str
        ``race`` or ``steady``.
    """

    polar: Polar
    fit: LearnFit
    pace: str

    def describe(self) -> str:
        """One line: what the reference is and what it holds."""
        lp = self.fit.learned
        learned = int((lp.status == "learned").sum())
        t = lp.level("median")
        pace = (
            "at its race pace (upwind / reach / downwind x"
            + " / x".join(f"{v:.2f}" for v in t.race_pace)
            + ")"
            if self.pace == "race" and t.race_pace is not None
            else "steady (no leg timed: no race pace)"
        )
        boats = len(self.fit.blocks.boats)
        return (
            f"polar learned from this fleet: {self.polar.name}, the median boat of {boats} "
            f"{pace}, {learned} cells learned from the tracks, the rest from the course "
            "polar's shape"
        )


def learned_reference(
    course: Course, tracks: Sequence[Track], scenario: str, shape: Polar
) -> LearnedReference:
    """The polar learned from the analysed fleet (``analyze --reference learned``).

    Parameters
    ----------
    course : Course
        The race.
    tracks : sequence of Track
        The analysed boats' tracks.
    scenario : str
        The course's scenario (the wind of last resort).
    shape : Polar
        The course's polar: the shape of the cells the fleet did not sail.

    Raises
    ------
    InputError
        The fleet sailed too little steady sailing to learn from (the message of
        :func:`~sailroute.boat.learn.learn_polar`).
    """
    twa = np.append(np.arange(0.0, 180.0, TWA_STEP_DEG), 180.0)
    fit, _, _ = learn_fleet(
        tracks,
        [course],
        scenario,
        twa_bins_deg=twa,
        n_boot=0,
        name=f"{course.name} fleet",
        shape=shape,
        provenance={"course": str(course.source or course.name), "scenario": scenario},
    )
    t = fit.learned.level("median")
    pace = "race" if t.race_pace is not None else "steady"
    return LearnedReference(fit.learned.polar("median", pace=pace), fit, pace)


def beaten_legs(analyses: Sequence[Any], pct: float = BEATEN_PCT) -> tuple[int, int]:
    """Legs sailed more than ``pct`` % faster than their optimal route, of the known
    legs: ``(beaten, known)`` (each leg judged in the wind its boat had)."""
    beaten = known = 0
    for a in analyses:
        for leg in a.legs:
            if not (leg.known and np.isfinite(leg.optimal_time_s) and leg.sailed_time_s > 0):
                continue
            known += 1
            beaten += int(leg.optimal_time_s > (1.0 + pct / 100.0) * leg.sailed_time_s)
    return beaten, known


def beaten_note(analyses: Sequence[Any], polar_name: str) -> str | None:
    """The debrief's first line when the course's polar is beaten by more than
    :data:`BEATEN_PCT` on most legs (None otherwise)."""
    beaten, known = beaten_legs(analyses)
    if known == 0 or 2 * beaten <= known:
        return None
    return (
        f"the course polar ({polar_name}) is beaten by more than {BEATEN_PCT:.0f} % on "
        f"{beaten} of {known} legs (each judged in the wind its boat had): it is not this "
        "fleet's boat, and the losses below are its error; `analyze --reference learned` "
        "judges the legs against the polar learned from this fleet"
    )
