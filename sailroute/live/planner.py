"""Where the re-plans are computed: here, or in worker processes.

Routing is numpy work in many small steps and holds Python's interpreter lock most of
the time; in the same process as the input reader it slows the reader down (at 1 Hz this
does not matter, a replay at 60x falls behind).  :class:`ProcessPlanner` runs
:class:`PlanCore` in worker processes (``spawn``: safe with the reader's threads; each
worker builds the course's boat and forecast itself, as ``compare-scenarios``' workers
do), so the reader keeps the interpreter to itself.  It has two workers: a re-plan for a
wind shift or a rounding never waits for an interval re-plan that is still being
computed.  :class:`ThreadPlanner` runs the core in the calling thread (no start-up cost;
tests, and callers that pass wind objects that are not in the course file).

:class:`PlanCore` keeps no state between calls, so any worker can answer any request:
:meth:`~PlanCore.route` returns the plan and its first routed leg, and
:meth:`~PlanCore.side` takes that leg back.

**A wind that runs out.**  When the scenario's wind (a forecast file, or a recorded
``measured`` wind) does not cover the time the route needs, the re-plan routes in the
measured wind alone, uniform and steady (:data:`MEASURED_ONLY`), and says so in the
plan's ``wind_note``: the page shows it as a banner.
"""

from __future__ import annotations

import math
import multiprocessing
import signal
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from typing import Protocol

from sailroute.boat.model import BoatModel
from sailroute.course.model import Course
from sailroute.errors import OutOfCoverageError
from sailroute.live.livewind import LiveWind
from sailroute.live.replan import (
    LivePlan,
    SidePays,
    leg_target,
    route_remaining,
    side_that_pays,
    summarise,
)
from sailroute.routing.settings import RoutingSettings
from sailroute.routing.types import LegResult
from sailroute.timeutil import iso
from sailroute.wind.base import WindField
from sailroute.wind.uniform import UniformWind

MEASURED_ONLY: str = "measured wind only"
"""How a plan routed without the scenario's wind names its wind."""
WORKERS: int = 2
"""Worker processes of :class:`ProcessPlanner`."""


@dataclass(frozen=True)
class PlanRequest:
    """One re-plan to compute.

    Attributes
    ----------
    number : int
        Re-plan number.
    reason : str
        What triggered it.
    t : float
        Data time [epoch s].
    x, y : float
        The boat [m, course frame].
    leg : int
        The leg being sailed (0-based).
    tws_ms, twd_deg : float
        The measured wind [m s⁻¹, ° from].
    fade_s : float
        Fade time of the measured wind ahead [s].
    """

    number: int
    reason: str
    t: float
    x: float
    y: float
    leg: int
    tws_ms: float
    twd_deg: float
    fade_s: float


class PlanCore:
    """Route a :class:`PlanRequest`, and the side that pays of its first leg."""

    def __init__(
        self, course: Course, forecast: WindField, boat: BoatModel, routing: RoutingSettings
    ) -> None:
        self.course, self.forecast, self.boat, self.routing = course, forecast, boat, routing

    def _wind(self, req: PlanRequest, measured_only: bool) -> LiveWind:
        base = UniformWind(req.tws_ms, req.twd_deg) if measured_only else self.forecast
        return LiveWind(
            base, req.t, req.x, req.y, req.tws_ms, req.twd_deg, self.course.frame, req.fade_s
        )

    def route(self, req: PlanRequest) -> tuple[LivePlan, LegResult]:
        """The remaining course for ``req`` and its first routed leg (raises the routers'
        errors); in the measured wind alone when the scenario's does not cover it."""
        w0, c0 = time.perf_counter(), time.thread_time()
        cov = self.forecast.coverage
        note = ""
        results = None
        if cov.t0 <= req.t < cov.t1:
            try:
                wind = self._wind(req, False)
                results = route_remaining(
                    self.course, wind, self.boat, self.routing, req.leg, (req.x, req.y), req.t
                )
            except OutOfCoverageError:
                if math.isinf(cov.t0) and math.isinf(cov.t1):
                    raise  # not a matter of time
        if results is None:
            span = " .. ".join(iso(v) if math.isfinite(v) else "" for v in (cov.t0, cov.t1))
            note = (
                f"the scenario's wind ({span}) does not cover the route from "
                f"{iso(req.t)}: routed in the {MEASURED_ONLY} (uniform and steady)"
            )
            wind = self._wind(req, True)
            results = route_remaining(
                self.course, wind, self.boat, self.routing, req.leg, (req.x, req.y), req.t
            )
        plan = summarise(
            self.course,
            results,
            number=req.number,
            t=req.t,
            leg=req.leg,
            boat=self.boat,
            measured=(req.tws_ms, req.twd_deg),
            reason=req.reason,
            compute_s=time.perf_counter() - w0,
            compute_cpu_s=time.thread_time() - c0,
        )
        return replace(plan, wind_note=note), results[0]

    def side(self, req: PlanRequest, first: LegResult, measured_only: bool) -> SidePays:
        """The side that pays on ``first``, the first leg of the plan for ``req``."""
        return side_that_pays(
            first,
            leg_target(self.course, req.leg),
            self._wind(req, measured_only),
            self.boat,
            self.routing,
        )


class Planner(Protocol):
    """Computes re-plans (:class:`ThreadPlanner` or :class:`ProcessPlanner`); callable
    from several threads at once."""

    def route(self, req: PlanRequest) -> tuple[LivePlan, LegResult]:
        """See :meth:`PlanCore.route`."""
        ...

    def side(self, req: PlanRequest, first: LegResult, measured_only: bool) -> SidePays:
        """See :meth:`PlanCore.side`."""
        ...

    def close(self) -> None:
        """Release the workers, if any."""
        ...


class ThreadPlanner:
    """:class:`PlanCore` in the calling thread."""

    def __init__(self, core: PlanCore) -> None:
        self._core = core

    def route(self, req: PlanRequest) -> tuple[LivePlan, LegResult]:
        """See :meth:`PlanCore.route`."""
        return self._core.route(req)

    def side(self, req: PlanRequest, first: LegResult, measured_only: bool) -> SidePays:
        """See :meth:`PlanCore.side`."""
        return self._core.side(req, first, measured_only)

    def close(self) -> None:
        """Nothing to release."""


_WORKER: PlanCore | None = None


def _init_worker(course: Course, scenario: str, router: str | None) -> None:
    """Build the boat and the forecast in the worker (once)."""
    global _WORKER
    # Ctrl-C, SIGTERM and SIGHUP are the parent's to handle: it ends the workers
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_IGN)
    from sailroute.course.load import build_specs
    from sailroute.planning.route import settings_for

    boat, winds = build_specs(course, [scenario])
    _WORKER = PlanCore(course, winds[scenario], boat, settings_for(course, router))


def _route(req: PlanRequest) -> tuple[LivePlan, LegResult]:
    assert _WORKER is not None
    return _WORKER.route(req)


def _side(req: PlanRequest, first: LegResult, measured_only: bool) -> SidePays:
    assert _WORKER is not None
    return _WORKER.side(req, first, measured_only)


def _ready(hold_s: float) -> bool:
    time.sleep(hold_s)  # keep this worker busy, so that the next task starts another
    return _WORKER is not None


class ProcessPlanner:
    """:class:`PlanCore` in :data:`WORKERS` worker processes that build the course's
    scenario themselves.

    Parameters
    ----------
    course : Course
        The course (pickled to the workers).
    scenario : str
        The forecast scenario's name.
    router : str, optional
        Router override.
    workers : int
        Worker processes.
    """

    def __init__(
        self, course: Course, scenario: str, router: str | None = None, workers: int = WORKERS
    ) -> None:
        self._pool = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_init_worker,
            initargs=(course, scenario, router),
        )
        # start them all now, not at the first re-plans
        self._warm = [self._pool.submit(_ready, 0.5) for _ in range(workers)]

    def route(self, req: PlanRequest) -> tuple[LivePlan, LegResult]:
        """See :meth:`PlanCore.route` (errors of the worker are raised here)."""
        return self._pool.submit(_route, req).result()

    def side(self, req: PlanRequest, first: LegResult, measured_only: bool) -> SidePays:
        """See :meth:`PlanCore.side`."""
        return self._pool.submit(_side, req, first, measured_only).result()

    def close(self) -> None:
        """End the workers (after the re-plans under way, if any)."""
        self._pool.shutdown(wait=True, cancel_futures=True)
