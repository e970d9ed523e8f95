"""Ensemble routing: the members of Hyères R1 as one front per leg against one by one.

Usage::

    .venv/bin/python benchmarks/bench_ensemble.py [--members 100] [--wind wrf|uniform]
        [--smoke]

The course is ``courses/hyeres-r1.yaml`` (five legs, isochrone router, its settings).  The
members are perturbed copies of one wind: ``wrf`` (default), the synthetic WRF of the
course's ``wrf-linear`` scenario turned by ``d`` degrees and scaled by ``1 + e``;
``uniform``, the course's constant 5.61 m/s from 108° likewise; ``d`` and ``e`` drawn
once from a normal distribution (3° and 5 %; ``numpy.random.default_rng(2018)``).

Both ways are timed in this one run, alternately (one by one, together, one by one,
together, ... ``--repeat`` times; the best of each is reported) in one process, as wall
and CPU time, with the load average before and after; both give the same leg times for
the members whose legs start at the same point (the first leg), and the script prints
how far the others differ (``routing/batch.py`` explains why they may).
``--only together`` (or ``one-by-one``) times one way only.  ``--smoke``: 3 members, the
first two legs (checks the script runs).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from sailroute.course.load import build_specs, load_course
from sailroute.planning.route import route_course, route_course_batch
from sailroute.wind.base import Coverage

ROOT = Path(__file__).resolve().parents[1]
COURSE = ROOT / "courses" / "hyeres-r1.yaml"


@dataclasses.dataclass(frozen=True, eq=False)
class Perturbed:
    """``base`` turned by ``turn_deg`` (clockwise) and scaled by ``scale``."""

    base: Any
    turn_deg: float
    scale: float

    @property
    def coverage(self) -> Coverage:
        return self.base.coverage

    @property
    def clamp(self) -> bool:
        return self.base.clamp

    def sample(self, t: Any, x: Any, y: Any) -> tuple[np.ndarray, np.ndarray]:
        u, v = self.base.sample(t, x, y)
        c, s = np.cos(np.radians(self.turn_deg)), np.sin(np.radians(self.turn_deg))
        return self.scale * (c * u + s * v), self.scale * (-s * u + c * v)


def load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--members", type=int, default=100)
    ap.add_argument("--wind", choices=("wrf", "uniform"), default="wrf")
    ap.add_argument("--repeat", type=int, default=1, help="alternate runs of each way")
    ap.add_argument(
        "--only",
        choices=("together", "one-by-one"),
        default=None,
        help="time one way only (no ratio, no comparison)",
    )
    ap.add_argument("--smoke", action="store_true", help="3 members, 2 legs")
    args = ap.parse_args()
    n = 3 if args.smoke else args.members
    print(f"command: python {' '.join(sys.argv)}")
    print(f"load average (1, 5, 15 min) at the start: {load()}")
    course = load_course(COURSE)
    if args.smoke:
        course = dataclasses.replace(course, legs=course.legs[:2])
    scenario = "wrf-linear" if args.wind == "wrf" else "constant"
    boat, winds = build_specs(course, [scenario])
    rng = np.random.default_rng(2018)
    turn, scale = rng.normal(0.0, 3.0, n), 1.0 + rng.normal(0.0, 0.05, n)
    members = [
        Perturbed(winds[scenario], float(d), float(e)) for d, e in zip(turn, scale, strict=True)
    ]
    s = course.routing

    ways = ("one by one", "together") if args.only is None else (args.only.replace("-", " "),)
    best = {way: (np.inf, np.inf) for way in ways}
    out: dict[str, list[list[Any]]] = {}
    for _ in range(args.repeat):
        for way in best:
            w0, c0 = time.perf_counter(), time.process_time()
            if way == "one by one":
                res = [route_course(course, m, boat, s) for m in members]
            else:
                res = route_course_batch(course, members, boat, s)
            wall, cpu = time.perf_counter() - w0, time.process_time() - c0
            best[way] = (min(best[way][0], wall), min(best[way][1], cpu))
            out[way] = res
    print(f"load average at the end: {load()}")
    print(
        f"Hyères R1, {n} members ({args.wind}), {len(course.legs)} legs, isochrone "
        f"dt {s.isochrone.dt_s:g} s, {s.isochrone.heading_step_deg:g}°: best of "
        f"{args.repeat}, wall (CPU)"
    )
    for way, (wall, cpu) in best.items():
        print(f"  {way:<11} {wall:8.2f} s ({cpu:.2f} s)  {wall / n * 1e3:7.1f} ms per member")
    if args.only is not None:
        return
    ratio_w = best["one by one"][0] / best["together"][0]
    ratio_c = best["one by one"][1] / best["together"][1]
    print(f"  ratio one by one / together: {ratio_w:.2f}x wall ({ratio_c:.2f}x CPU)")
    one, tog = out["one by one"], out["together"]
    for leg in range(len(course.legs)):
        a = np.array([r[leg].time_s for r in one])
        b = np.array([r[leg].time_s for r in tog])
        same = int(np.sum(a == b))
        print(
            f"  leg {leg + 1}: {same}/{n} leg times identical; largest difference "
            f"{np.max(np.abs(a - b)):.3f} s (median leg time {np.median(b):.1f} s)"
        )
    ta = np.array([sum(x.time_s for x in r) for r in one])
    tb = np.array([sum(x.time_s for x in r) for r in tog])
    print(
        f"  race time: largest difference {np.max(np.abs(ta - tb)):.3f} s, "
        f"mean {np.mean(tb - ta):+.3f} s (together - one by one)"
    )


if __name__ == "__main__":
    main()
