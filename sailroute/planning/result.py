"""A routed course (:class:`Plan`) and a scenario comparison (:class:`Comparison`).

These are the pure data the report writers consume: ``tables``, ``files`` and
``plots`` never route or read wind files themselves.  Percent errors follow one
convention everywhere: ``(model − reference) / reference``, so a positive error
means the model is slower than the reference.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from sailroute.course.geometry import WindMode, feature_centre, leg_wind_mode
from sailroute.course.model import Course, LegSpec, Line
from sailroute.errors import InputError
from sailroute.routing.laylines import Layline
from sailroute.routing.startline import StartLineNumbers
from sailroute.routing.types import LegResult
from sailroute.wind.base import WindField


@dataclass(frozen=True, eq=False)
class PlannedLeg:
    """One routed leg.

    Attributes
    ----------
    spec : LegSpec
        The leg as defined in the course.
    result : LegResult
        The router's result.
    mode : {"upwind", "reach", "downwind"} or None
        Wind mode at the leg's start (None if unknown).
    start_line_fraction : float or None
        Where the leg started along the line or gate it started from, 0 at the
        line's first mark ``a`` and 1 at ``b``; None for a point start.
    """

    spec: LegSpec
    result: LegResult
    mode: WindMode | None = None
    start_line_fraction: float | None = None

    @property
    def time_s(self) -> float:
        """Leg time [s]."""
        return self.result.time_s


@dataclass(frozen=True, eq=False)
class Plan:
    """A whole course routed in one wind scenario.

    Attributes
    ----------
    course : Course
        The course.
    scenario : str
        Scenario name.
    legs : tuple of PlannedLeg
        Routed legs in order (chained: each starts where and when the previous ended).
    references : mapping of str to tuple of float
        Reference leg times [s] to compare with (course-wide plus the scenario's).
    router : str
        Router name.
    start_line : StartLineNumbers or None
        The start line in the wind at the gun (bias, favoured end; None without a
        start line or when not computed).
    laylines : tuple of tuple of Layline
        Per leg, the laylines to its mark or gate (empty tuples for reaches and lines;
        empty when not computed).
    """

    course: Course
    scenario: str
    legs: tuple[PlannedLeg, ...]
    references: Mapping[str, tuple[float, ...]] = field(default_factory=dict)
    router: str = ""
    start_line: StartLineNumbers | None = None
    laylines: tuple[tuple[Layline, ...], ...] = ()

    @property
    def total_time_s(self) -> float:
        """Sum of leg times [s] (= arrival time − start time for chained legs)."""
        return float(sum(leg.time_s for leg in self.legs))

    @property
    def t_start(self) -> float:
        """Start of the first leg [epoch s]."""
        return self.legs[0].result.t_start if self.legs else self.course.start_epoch

    @property
    def t_end(self) -> float:
        """Arrival at the end of the last leg [epoch s]."""
        return self.legs[-1].result.t_end if self.legs else self.course.start_epoch

    @property
    def results(self) -> tuple[LegResult, ...]:
        """The routers' results in leg order."""
        return tuple(leg.result for leg in self.legs)


def start_line_fraction(course: Course, i: int, start_xy: tuple[float, float]) -> float | None:
    """Where leg ``i`` started on the line/gate it starts from (0 at ``a``, 1 at ``b``).

    None when leg ``i`` starts at a mark.
    """
    feat = course.feature(course.legs[i].from_name)
    if isinstance(feat, Line):  # Gate is a Line
        return feat.fraction_of(start_xy)
    return None


def make_plan(
    course: Course,
    scenario: str,
    results: Sequence[LegResult],
    wind: WindField | None = None,
    *,
    router: str | None = None,
) -> Plan:
    """Assemble a :class:`Plan` from the routers' results, one per leg.

    Parameters
    ----------
    course : Course
        The course that was routed.
    scenario : str
        Scenario name (its references are added to the course-wide ones).
    results : sequence of LegResult
        One per leg, in order.
    wind : WindField, optional
        Used to classify each leg's wind mode at its start point and time; without
        it ``mode`` is None.
    router : str, optional
        Router name; default the first result's ``router``.

    Returns
    -------
    Plan
    """
    if len(results) != course.n_legs:
        raise InputError(
            f"{course.name}: {len(results)} leg results for a course of {course.n_legs} legs"
        )
    legs = []
    for spec, res in zip(course.legs, results, strict=True):
        target = feature_centre(course.feature(spec.to_name))
        mode = leg_wind_mode(wind, res.t_start, res.start_xy, target) if wind is not None else None
        frac = start_line_fraction(course, spec.index, res.start_xy)
        legs.append(PlannedLeg(spec, res, mode, frac))
    name = router if router is not None else (results[0].router if results else "")
    return Plan(course, scenario, tuple(legs), course.references_for(scenario), name)


def percent_error(model: float, reference: float) -> float:
    """``100 (model − reference) / reference`` [%]; positive: the model is slower."""
    return 100.0 * (model - reference) / reference


@dataclass(frozen=True, eq=False)
class Comparison:
    """Leg times of several scenarios side by side, with errors against references.

    Attributes
    ----------
    course_name : str
        Course name.
    leg_labels : tuple of str
        ``"from -> to"`` per leg.
    scenarios : tuple of str
        Scenario names, in order.
    times : ndarray, shape (n_scenarios, n_legs)
        Leg times [s].
    references : dict of str to ndarray, shape (n_legs,)
        References shared by every scenario (the course-wide ones, e.g. the race
        winner's leg times) [s].
    scenario_references : dict of str to dict of str to ndarray
        Scenario name → its own references (e.g. the thesis's output for that
        wind) [s].
    """

    course_name: str
    leg_labels: tuple[str, ...]
    scenarios: tuple[str, ...]
    times: np.ndarray
    references: dict[str, np.ndarray]
    scenario_references: dict[str, dict[str, np.ndarray]]

    @property
    def totals(self) -> np.ndarray:
        """Race time per scenario [s]."""
        return self.times.sum(axis=1)

    def delta_s(self, reference: str) -> np.ndarray:
        """``model − reference`` per scenario and leg [s], shape (n_scenarios, n_legs)."""
        return self.times - self.references[reference][None, :]

    def percent(self, reference: str) -> np.ndarray:
        """``100 (model − ref) / ref`` per scenario and leg [%] for a shared reference."""
        ref = self.references[reference][None, :]
        return 100.0 * (self.times - ref) / ref

    def total_percent(self, reference: str) -> np.ndarray:
        """Race-time error per scenario [%], ``(model − ref) / ref`` on the totals."""
        ref = float(self.references[reference].sum())
        return 100.0 * (self.totals - ref) / ref


def compare(plans: Sequence[Plan]) -> Comparison:
    """Put several plans of the same course side by side.

    Parameters
    ----------
    plans : sequence of Plan
        One per scenario, all of the same course (same number of legs).

    Returns
    -------
    Comparison
        A reference present with the same values in every plan is shared; any
        other reference stays attached to its scenario.
    """
    if not plans:
        raise InputError("compare: no plans to compare")
    n = len(plans[0].legs)
    for p in plans:
        if len(p.legs) != n:
            raise InputError(
                f"compare: scenario {p.scenario!r} has {len(p.legs)} legs, expected {n}"
            )
    times = np.array([[leg.time_s for leg in p.legs] for p in plans], dtype=float)
    first = {k: np.asarray(v, dtype=float) for k, v in plans[0].references.items()}
    shared = {
        k: v
        for k, v in first.items()
        if all(
            k in p.references and np.array_equal(np.asarray(p.references[k], float), v)
            for p in plans
        )
    }
    own = {
        p.scenario: {
            k: np.asarray(v, dtype=float) for k, v in p.references.items() if k not in shared
        }
        for p in plans
    }
    return Comparison(
        course_name=plans[0].course.name,
        leg_labels=tuple(leg.spec.label for leg in plans[0].legs),
        scenarios=tuple(p.scenario for p in plans),
        times=times,
        references=shared,
        scenario_references={k: v for k, v in own.items() if v},
    )
