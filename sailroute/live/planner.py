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

**A newer re-plan stops an older one.**  :meth:`Planner.supersede` tells the workers the
number of the newest urgent request; a route or side-that-pays computation of an older
request stops at its router's next time step (:class:`Superseded`), so the urgent one
has the CPU to itself.  An urgent request (``coarse``) is routed with twice the course's
time step and heading step (isochrone router: about a quarter of the work); the next
interval re-plan, :data:`~sailroute.live.engine.LiveSettings.every_s` later, routes at
the course's settings again.

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
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from typing import Any, Protocol

from sailroute.boat.model import BoatModel
from sailroute.course.model import Course
from sailroute.errors import OutOfCoverageError, SailrouteError
from sailroute.live.livewind import LiveWind
from sailroute.live.replan import (
    LivePlan,
    SidePays,
    leg_target,
    route_remaining,
    side_that_pays,
    summarise,
)
from sailroute.progress import Progress
from sailroute.routing.settings import RoutingSettings, routing_settings
from sailroute.routing.types import LegResult
from sailroute.timeutil import iso
from sailroute.wind.base import WindField
from sailroute.wind.uniform import UniformWind


class Superseded(SailrouteError):
    """A newer re-plan was requested: this one stopped."""


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
    coarse : bool
        Route with the coarse settings (:func:`coarse_settings`): an urgent re-plan.
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
    coarse: bool = False


def coarse_settings(settings: RoutingSettings) -> RoutingSettings | None:
    """The isochrone router's settings with twice the time and heading steps (None for
    another router: it routes urgent re-plans at its own settings)."""
    if settings.router != "isochrone":
        return None
    iso_ = settings.isochrone
    return routing_settings(
        settings, dt_s=2.0 * iso_.dt_s, heading_step_deg=min(2.0 * iso_.heading_step_deg, 6.0)
    )


class _Watch(Progress):
    """A silent progress display that stops the routing once ``stop()`` says so."""

    def __init__(self, n_legs: int, stop: Callable[[], bool]) -> None:
        super().__init__(n_legs, enabled=False)
        self._stop = stop

    def update(self, fraction: float | None = None, note: str = "") -> None:
        """Raise :class:`Superseded` when a newer re-plan was requested."""
        if self._stop():
            raise Superseded("a newer re-plan was requested")

    __call__ = update

    def warn(self, text: str) -> None:
        """Nothing printed from a re-plan (the engine says what matters on the page)."""


class PlanCore:
    """Route a :class:`PlanRequest`, and the side that pays of its first leg."""

    def __init__(
        self, course: Course, forecast: WindField, boat: BoatModel, routing: RoutingSettings
    ) -> None:
        self.course, self.forecast, self.boat, self.routing = course, forecast, boat, routing
        self.coarse = coarse_settings(routing)
        self.newest = 0  # the newest urgent request (ThreadPlanner: set by supersede)

    def _stop(self, number: int) -> Callable[[], bool]:
        return lambda: self.newest > number

    def _wind(self, req: PlanRequest, measured_only: bool) -> LiveWind:
        base = UniformWind(req.tws_ms, req.twd_deg) if measured_only else self.forecast
        return LiveWind(
            base, req.t, req.x, req.y, req.tws_ms, req.twd_deg, self.course.frame, req.fade_s
        )

    def route(self, req: PlanRequest) -> tuple[LivePlan, LegResult]:
        """The remaining course for ``req`` and its first routed leg (raises the routers'
        errors, and :class:`Superseded`); in the measured wind alone when the scenario's
        does not cover it."""
        w0, c0 = time.perf_counter(), time.thread_time()
        cov = self.forecast.coverage
        settings = self.coarse if req.coarse and self.coarse is not None else self.routing
        watch = _Watch(self.course.n_legs, self._stop(req.number))
        note = ""
        results = None
        if cov.t0 <= req.t < cov.t1:
            try:
                wind = self._wind(req, False)
                results = route_remaining(
                    self.course, wind, self.boat, settings, req.leg, (req.x, req.y), req.t, watch
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
                self.course, wind, self.boat, settings, req.leg, (req.x, req.y), req.t, watch
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
        """The side that pays on ``first``, the first leg of the plan for ``req`` (raises
        :class:`Superseded`)."""
        return side_that_pays(
            first,
            leg_target(self.course, req.leg),
            self._wind(req, measured_only),
            self.boat,
            self.coarse if req.coarse and self.coarse is not None else self.routing,
            progress=_Watch(1, self._stop(req.number)),
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

    def supersede(self, number: int) -> None:
        """Request ``number`` is urgent: computations of older requests may stop."""
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

    def supersede(self, number: int) -> None:
        """See :meth:`Planner.supersede`."""
        self._core.newest = max(self._core.newest, number)

    def close(self) -> None:
        """Nothing to release."""


_WORKER: PlanCore | None = None


def _init_worker(course: Course, scenario: str, router: str | None, newest: Any) -> None:
    """Build the boat and the forecast in the worker (once)."""
    global _WORKER
    # Ctrl-C, SIGTERM and SIGHUP are the parent's to handle: it ends the workers
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_IGN)
    from sailroute.course.load import build_specs
    from sailroute.planning.route import settings_for

    boat, winds = build_specs(course, [scenario])
    _WORKER = PlanCore(course, winds[scenario], boat, settings_for(course, router))
    _WORKER._stop = lambda number: lambda: newest.value > number  # type: ignore[method-assign]


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
        ctx = multiprocessing.get_context("spawn")
        self._newest = ctx.Value("q", 0, lock=False)
        self._pool = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=ctx,
            initializer=_init_worker,
            initargs=(course, scenario, router, self._newest),
        )
        # start them all now, not at the first re-plans
        self._warm = [self._pool.submit(_ready, 0.5) for _ in range(workers)]

    def route(self, req: PlanRequest) -> tuple[LivePlan, LegResult]:
        """See :meth:`PlanCore.route` (errors of the worker are raised here)."""
        return self._pool.submit(_route, req).result()

    def side(self, req: PlanRequest, first: LegResult, measured_only: bool) -> SidePays:
        """See :meth:`PlanCore.side`."""
        return self._pool.submit(_side, req, first, measured_only).result()

    def supersede(self, number: int) -> None:
        """See :meth:`Planner.supersede` (the workers read it at every router step)."""
        self._newest.value = max(self._newest.value, number)

    def close(self) -> None:
        """End the workers (after the re-plans under way, if any)."""
        self._pool.shutdown(wait=True, cancel_futures=True)
