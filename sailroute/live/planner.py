"""Where the re-plans are computed: here, or in a worker process.

Routing is numpy work in many small steps and holds Python's interpreter lock most of
the time; in the same process as the input reader it slows the reader down (at 1 Hz this
does not matter, a replay at 60x falls behind).  :class:`ProcessPlanner` runs
:class:`PlanCore` in one worker process (``spawn``: safe with the reader's threads; the
worker builds the course's boat and forecast itself, as ``compare-scenarios``' workers
do), so the reader keeps the interpreter to itself.  :class:`ThreadPlanner` runs it in
the calling thread (no start-up cost; tests, and callers that pass wind objects that are
not in the course file).
"""

from __future__ import annotations

import multiprocessing
import signal
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Protocol

from sailroute.boat.model import BoatModel
from sailroute.course.model import Course
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
from sailroute.wind.base import WindField


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
    """Route a :class:`PlanRequest`, then (on demand) the side that pays of its first leg."""

    def __init__(
        self, course: Course, forecast: WindField, boat: BoatModel, routing: RoutingSettings
    ) -> None:
        self.course, self.forecast, self.boat, self.routing = course, forecast, boat, routing
        self._last: tuple[PlanRequest, LiveWind, LegResult] | None = None

    def route(self, req: PlanRequest) -> LivePlan:
        """The remaining course for ``req`` (raises the routers' errors)."""
        w0, c0 = time.perf_counter(), time.thread_time()
        wind = LiveWind(
            self.forecast,
            req.t,
            req.x,
            req.y,
            req.tws_ms,
            req.twd_deg,
            self.course.frame,
            req.fade_s,
        )
        results = route_remaining(
            self.course, wind, self.boat, self.routing, req.leg, (req.x, req.y), req.t
        )
        self._last = (req, wind, results[0])
        return summarise(
            self.course,
            results,
            number=req.number,
            t=req.t,
            leg=req.leg,
            wind=wind,
            boat=self.boat,
            measured=(req.tws_ms, req.twd_deg),
            reason=req.reason,
            compute_s=time.perf_counter() - w0,
            compute_cpu_s=time.thread_time() - c0,
        )

    def side(self, number: int) -> SidePays | None:
        """The side that pays on the first leg of re-plan ``number`` (None if not the last)."""
        if self._last is None or self._last[0].number != number:
            return None
        req, wind, first = self._last
        return side_that_pays(
            first, leg_target(self.course, req.leg), wind, self.boat, self.routing
        )


class Planner(Protocol):
    """Computes re-plans (:class:`ThreadPlanner` or :class:`ProcessPlanner`)."""

    def route(self, req: PlanRequest) -> LivePlan:
        """See :meth:`PlanCore.route`."""
        ...

    def side(self, number: int) -> SidePays | None:
        """See :meth:`PlanCore.side`."""
        ...

    def close(self) -> None:
        """Release the worker, if any."""
        ...


class ThreadPlanner:
    """:class:`PlanCore` in the calling thread."""

    def __init__(self, core: PlanCore) -> None:
        self._core = core

    def route(self, req: PlanRequest) -> LivePlan:
        """See :meth:`PlanCore.route`."""
        return self._core.route(req)

    def side(self, number: int) -> SidePays | None:
        """See :meth:`PlanCore.side`."""
        return self._core.side(number)

    def close(self) -> None:
        """Nothing to release."""


_WORKER: PlanCore | None = None


def _init_worker(course: Course, scenario: str, router: str | None) -> None:
    """Build the boat and the forecast in the worker (once)."""
    global _WORKER
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    from sailroute.course.load import build_specs
    from sailroute.planning.route import settings_for

    boat, winds = build_specs(course, [scenario])
    _WORKER = PlanCore(course, winds[scenario], boat, settings_for(course, router))


def _route(req: PlanRequest) -> LivePlan:
    assert _WORKER is not None
    return _WORKER.route(req)


def _side(number: int) -> SidePays | None:
    assert _WORKER is not None
    return _WORKER.side(number)


def _ready() -> bool:
    return _WORKER is not None


class ProcessPlanner:
    """:class:`PlanCore` in one worker process that builds the course's scenario itself.

    Parameters
    ----------
    course : Course
        The course (pickled to the worker).
    scenario : str
        The forecast scenario's name.
    router : str, optional
        Router override.
    """

    def __init__(self, course: Course, scenario: str, router: str | None = None) -> None:
        self._pool = ProcessPoolExecutor(
            max_workers=1,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_init_worker,
            initargs=(course, scenario, router),
        )
        self._warm = self._pool.submit(_ready)  # start it now, not at the first re-plan

    def route(self, req: PlanRequest) -> LivePlan:
        """See :meth:`PlanCore.route` (errors of the worker are raised here)."""
        return self._pool.submit(_route, req).result()

    def side(self, number: int) -> SidePays | None:
        """See :meth:`PlanCore.side`."""
        return self._pool.submit(_side, number).result()

    def close(self) -> None:
        """End the worker (after the re-plan under way, if any)."""
        self._pool.shutdown(wait=True, cancel_futures=True)
