"""Ensemble routing: the members of Hyères R1 one by one against as one front per leg.

Usage::

    .venv/bin/python benchmarks/bench_ensemble.py [--members 100] [--wind wrf|uniform]
        [--repeat 1] [--only together|one-by-one] [--smoke]
    .venv/bin/python benchmarks/bench_ensemble.py --bands [--members 100] [--repeat 1]

The course is ``courses/hyeres-r1.yaml`` (five legs, isochrone router, its settings).  The
members are perturbed copies of one wind (:class:`~sailroute.wind.perturbed.PerturbedWind`):
``wrf`` (default), the synthetic WRF of the course's ``wrf-linear`` scenario turned by
``d`` degrees and scaled by ``1 + e``; ``uniform``, the course's constant 5.61 m/s from
108° likewise; ``d`` and ``e`` drawn once from a normal distribution (3° and 5 %;
``numpy.random.default_rng(2018)``).

Both ways are timed in this one run, alternately (one by one, together, one by one,
together, ... ``--repeat`` times; the best of each is reported) in one process, as wall
and CPU time, with the load average before and after:

* one by one: ``route_course`` per member on the NumPy step (``routing.engine: numpy``),
  as the bands routed their members before they were batched;
* together: ``route_course_batch``, one front per leg, on the engine ``auto`` (the
  compiled step where numba is installed).

The first legs' times are the same; the script prints how far the others differ
(``routing/batch.py`` explains why they may).  ``--only together`` (or ``one-by-one``)
times one way only.  ``--smoke``: 3 members, the first two legs (checks the script runs).

``--bands`` times the bands of ``plan --ensemble N`` in-process
(:func:`~sailroute.bands.route.band_summary`, constant scenario: the main ensemble, the
nominal and the one-at-a-time members, the side verdicts), the members one by one on the
NumPy step against together on ``auto``, and in the same rounds a single plan of the
course (``plan --no-plots`` in-process, on ``auto``) to give the band's cost in single
plans.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from sailroute.course.load import build_specs, load_course
from sailroute.planning.route import route_course, route_course_batch
from sailroute.routing.settings import RoutingSettings
from sailroute.wind.perturbed import PerturbedWind

ROOT = Path(__file__).resolve().parents[1]
COURSE = ROOT / "courses" / "hyeres-r1.yaml"


def load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def with_engine(s: RoutingSettings, engine: str) -> RoutingSettings:
    return dataclasses.replace(s, isochrone=dataclasses.replace(s.isochrone, engine=engine))


def timed(fn: Any) -> tuple[Any, float, float]:
    """``fn()``, its wall and CPU time [s]."""
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - w0, time.process_time() - c0


def race(ways: dict[str, Any], repeat: int) -> tuple[dict[str, Any], dict[str, Any]]:
    """Each way's result and best ``(wall, CPU)`` [s], the ways taking turns ``repeat``
    times."""
    best = {way: (np.inf, np.inf) for way in ways}
    got: dict[str, Any] = {}
    for _ in range(repeat):
        for way, fn in ways.items():
            got[way], wall, cpu = timed(fn)
            best[way] = (min(best[way][0], wall), min(best[way][1], cpu))
    return got, best


def report(best: dict[str, tuple[float, float]], n: int, unit: str) -> None:
    for way, (wall, cpu) in best.items():
        print(f"  {way:<11} {wall:8.2f} s ({cpu:.2f} s)  {wall / n * 1e3:7.1f} ms per {unit}")


def members_race(args: argparse.Namespace) -> None:
    """One by one against together: ``route_course`` and ``route_course_batch``."""
    n = 3 if args.smoke else args.members
    course = load_course(COURSE)
    if args.smoke:
        course = dataclasses.replace(course, legs=course.legs[:2])
    scenario = "wrf-linear" if args.wind == "wrf" else "constant"
    boat, winds = build_specs(course, [scenario])
    rng = np.random.default_rng(2018)
    turn, scale = rng.normal(0.0, 3.0, n), 1.0 + rng.normal(0.0, 0.05, n)
    members = [
        PerturbedWind(winds[scenario], speed_scale=float(e), direction_offset_deg=float(d))
        for d, e in zip(turn, scale, strict=True)
    ]
    s = course.routing
    alone, batch = with_engine(s, "numpy"), with_engine(s, "auto")
    ways = {
        "one by one": lambda: [route_course(course, m, boat, alone) for m in members],
        "together": lambda: route_course_batch(course, members, boat, batch),
    }
    if args.only is not None:
        ways = {args.only.replace("-", " "): ways[args.only.replace("-", " ")]}
    out, best = race(ways, args.repeat)
    print(f"load average at the end: {load()}")
    print(
        f"Hyères R1, {n} members ({args.wind}), {len(course.legs)} legs, isochrone "
        f"dt {s.isochrone.dt_s:g} s, {s.isochrone.heading_step_deg:g}°: best of "
        f"{args.repeat}, wall (CPU)"
    )
    report(best, n, "member")
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


def bands_race(args: argparse.Namespace) -> None:
    """The bands of ``plan --ensemble N`` one by one (NumPy) against together (auto), and
    a single plan."""
    from sailroute.bands.route import band_summary, route_members, route_together, spec_for
    from sailroute.commands.plan import run_plan_command

    n = 3 if args.smoke else args.members
    course = load_course(COURSE)
    spec, notes = spec_for(course, n)
    boat, winds = build_specs(course, ["constant"])
    out = Path(tempfile.mkdtemp())

    def band(route: Any, engine: str) -> Any:
        return band_summary(
            course,
            "constant",
            spec,
            wind=winds["constant"],
            boat=boat,
            settings=with_engine(course.routing, engine),
            route=route,
            notes=notes,
        )

    ways = {
        "one by one": lambda: band(route_members, "numpy"),
        "together": lambda: band(route_together, "auto"),
        "single plan": lambda: run_plan_command(course, out_dir=out / "plan", plots=False),
    }
    got, best = race(ways, args.repeat)
    print(f"load average at the end: {load()}")
    print(
        f"the bands of plan courses/hyeres-r1.yaml --ensemble {n} in-process (constant "
        f"scenario: the main ensemble, the nominal and the one-at-a-time members, the "
        f"sides), and plan --no-plots: best of {args.repeat}, wall (CPU)"
    )
    report(best, 1, "run")
    one, tog, single = best["one by one"], best["together"], best["single plan"]
    print(
        f"  ratio one by one / together: {one[0] / tog[0]:.2f}x wall ({one[1] / tog[1]:.2f}x CPU)"
    )
    print(
        f"  together = {tog[1] / single[1]:.1f} single plans in CPU ({tog[0] / single[0]:.1f} "
        f"in wall); one by one = {one[1] / single[1]:.1f}"
    )
    a, b = got["one by one"].times_s, got["together"].times_s
    worst = np.max(np.abs(a - b), axis=0)
    print(
        f"  main ensemble: leg 1 times identical for {int(np.sum(a[:, 0] == b[:, 0]))}/{n} "
        f"members; largest difference per leg [s]: {', '.join(f'{d:.3f}' for d in worst)}"
    )


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
    ap.add_argument("--bands", action="store_true", help="plan --ensemble N against a plan")
    ap.add_argument("--smoke", action="store_true", help="3 members, 2 legs")
    args = ap.parse_args()
    print(f"command: python {' '.join(sys.argv)}")
    print(f"load average (1, 5, 15 min) at the start: {load()}")
    if args.bands:
        bands_race(args)
    else:
        members_race(args)


if __name__ == "__main__":
    main()
