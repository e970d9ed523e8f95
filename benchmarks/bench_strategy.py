"""Benchmark of the tack-strategy solvers (single thread).

Usage::

    python benchmarks/bench_strategy.py            # SDP, Monte Carlo, deadline solves
    python benchmarks/bench_strategy.py --paper    # + Wang et al. (2024) Figs 3, 4(a)
    python benchmarks/bench_strategy.py --scheduler processes --workers 2
                                                   # + Monte Carlo on Dask vs serial
    python benchmarks/bench_strategy.py --smoke    # a 400 m beat, small grids, 100 runs

Prints seconds (best of ``--repeat`` for the SDP) and the numbers the paper reports next to
ours.  BLAS threads are pinned to one before numpy is imported.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.boat.build import builtin_polar  # noqa: E402
from sailroute.parallel import open_runner  # noqa: E402
from sailroute.strategy import (  # noqa: E402
    BeatGrid,
    DeadlineGrid,
    DeadlinePolicy,
    DriftDiffusionShift,
    ExpectedTimePolicy,
    OUShift,
    RiskNeutralPolicy,
    simulate,
    simulate_deadline,
    solve_deadline,
    solve_expected_time,
    solve_risk_neutral,
)
from sailroute.units import KNOT  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_deadline import so40  # noqa: E402  (one Sun Odyssey 40 table for the benchmarks)


def bench_sdp(repeat: int, runs: int, grid: BeatGrid | None = None) -> ExpectedTimePolicy:
    polar = builtin_polar("ilca7")
    grid = BeatGrid() if grid is None else grid
    model = OUShift(10.0, 600.0)
    times = []
    for _ in range(repeat):
        pol = solve_expected_time(polar, 10 * KNOT, model, grid, 5.0)
        times.append(pol.solve_time_s)
    n_cand = grid.n_x * (2 * grid.d_max + 1) * grid.theta_deg.size * grid.n_rows
    print(
        f"SDP {grid.n_x} x {grid.n_rows} rows x 2 tacks x {grid.theta_deg.size} shifts, "
        f"|x'-x| <= {grid.d_max} nodes ({n_cand:.2e} candidates; naive 3.9e9): "
        f"{min(times):.2f} s (best of {repeat}); E[T] = {pol.expected_time():.1f} s"
    )
    t0 = time.perf_counter()
    sim = simulate(pol, runs, seed=1)
    dt = time.perf_counter() - t0
    s = sim.summary()
    print(
        f"Monte Carlo {runs} runs: {dt:.2f} s; mean {s['mean_s']:.1f} ± {s['se_mean_s']:.1f} s, "
        f"tacks {s['tacks']['mean']:.2f}"
    )
    return pol


def bench_deadline_physical(
    n_r: int = 100,
    n_theta: int = 128,
    interps: tuple[str, ...] = ("linear", "cubic"),
    runs: int = 4000,
) -> tuple[RiskNeutralPolicy, DeadlinePolicy]:
    polar = builtin_polar("ilca7")
    model = DriftDiffusionShift(0.0, 0.4275)
    for interp in interps:
        grid = DeadlineGrid(2000.0, n_r, n_theta, 20.0, 5.0, 1300.0, interpolation=interp)
        ra = solve_deadline(polar, 10 * KNOT, model, grid, 5.0)
        print(
            f"deadline solve, 1600 m beat, {grid.n_r + 1} x {grid.n_theta} x 2 nodes, "
            f"{grid.n_s} budget steps of {grid.ds_s:g} s, {interp}: {ra.solve_time_s:.2f} s"
        )
    rn = solve_risk_neutral(polar, 10 * KNOT, model, grid, 5.0, tol_s=1e-3)
    print(
        f"risk-neutral value iteration, same grid: {rn.solve_time_s:.2f} s ({rn.iterations} sweeps)"
    )
    t0 = time.perf_counter()
    simulate_deadline(rn, runs, 1, (1600.0, 0.0, 1), ra=ra, deadline_s=800.0)
    print(f"deadline Monte Carlo, {runs} runs (Δt = 1 s): {time.perf_counter() - t0:.2f} s")
    return rn, ra


def bench_scale_out(
    pol: ExpectedTimePolicy,
    rn: RiskNeutralPolicy,
    ra: DeadlinePolicy,
    runs: int,
    scheduler: str,
    n_workers: int | None,
    repeat: int,
) -> None:
    """Monte Carlo serial vs on ``scheduler`` (cluster start timed separately)."""
    start = (1600.0, 0.0, 1)
    t0 = time.perf_counter()
    with open_runner(scheduler, n_workers) as runner:
        print(f"Dask: {runner.description}, ready in {time.perf_counter() - t0:.2f} s")
        for n in (runs, 5 * runs):
            cases = (
                ("expected-time MC", lambda sch, n=n: simulate(pol, n, 1, scheduler=sch)),
                (
                    "deadline MC",
                    lambda sch, n=n: simulate_deadline(
                        rn, n, 1, start, ra=ra, deadline_s=800.0, scheduler=sch
                    ),
                ),
            )
            for name, run in cases:
                t_serial, t_dist = math.inf, math.inf
                for _ in range(repeat):
                    t0 = time.perf_counter()
                    a = run(None)
                    t_serial = min(t_serial, time.perf_counter() - t0)
                    t0 = time.perf_counter()
                    b = run(runner)
                    t_dist = min(t_dist, time.perf_counter() - t0)
                same = np.array_equal(a.leg_time_s, b.leg_time_s)
                print(
                    f"  {name}, {n} runs: serial {t_serial:.2f} s, Dask {t_dist:.2f} s "
                    f"(best of {repeat}), identical leg times: {same}"
                )


def bench_paper(n_r: int, n_theta: int, ds: float, runs: int, interp: str) -> None:
    polar = so40()
    cases = [
        (
            "Fig 3",
            0.0,
            (1.93, 0.56, 1),
            (53.0, 56.0),
            62.0,
            "E[T] μ* 54.46, α53 55.57, α56 55.95; P(T<=56) 52.5% -> 58.9% (α56)",
        ),
        (
            "Fig 4a",
            0.05,
            (1.80, 2.67, 1),
            (42.0,),
            48.0,
            "E[T] 43.83 -> 44.30; P(T<=42) 5.8% -> 17.2%; switches μ* 2 (99.9%), α 0 (99.1%)",
        ),
    ]
    for name, a, start, deadlines, s_max, paper in cases:
        grid = DeadlineGrid(2.0, n_r, n_theta, 0.1, ds, s_max, interpolation=interp)
        m = DriftDiffusionShift(-math.degrees(a), math.degrees(0.05))
        ra = solve_deadline(polar, 1.0, m, grid, 2.0)
        rn = solve_risk_neutral(polar, 1.0, m, grid, 2.0, tol_s=1e-3)
        print(
            f"{name}: grid {n_r + 1} x {n_theta} x 2, Δs {ds:g}, {interp}: risk-aware "
            f"{ra.solve_time_s:.1f} s, risk-neutral {rn.solve_time_s:.1f} s "
            f"({rn.iterations} sweeps)"
        )
        print(f"  paper: {paper}")
        sim_rn = simulate_deadline(rn, runs, 1, start, dt_s=0.01)
        t = sim_rn.leg_time_s
        probs = ", ".join(f"P(T<={d:g}) {100 * np.mean(t <= d):.1f}%" for d in deadlines)
        sw = np.bincount(sim_rn.n_switches) / runs
        print(
            f"  μ*: value {rn.expected_time(*start):.2f}, MC mean {np.mean(t):.2f}, {probs}, "
            f"switches {np.argmax(sw)} ({100 * sw.max():.1f}%)"
        )
        curve = ra.success_curve(*start)
        for d in deadlines:
            sim = simulate_deadline(rn, runs, 1, start, ra=ra, deadline_s=d, dt_s=0.01)
            t = sim.leg_time_s
            sw = np.bincount(sim.n_switches) / runs
            print(
                f"  α^{d:g}: w {curve[round(d / ds)]:.3f}, MC P(T<={d:g}) "
                f"{100 * np.mean(t <= d):.1f}%, mean {np.mean(t):.2f}, switches "
                f"{np.argmax(sw)} ({100 * sw.max():.1f}%)"
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--runs", type=int, default=4000)
    ap.add_argument(
        "--paper", action="store_true", help="reproduce Wang et al. (2024) Figs 3 and 4(a)"
    )
    ap.add_argument(
        "--paper-grid",
        default="200,256,0.2",
        help="n_r,n_theta,ds for --paper (default 200,256,0.2)",
    )
    ap.add_argument("--paper-interp", default="linear", choices=("linear", "cubic"))
    ap.add_argument(
        "--scheduler",
        default=None,
        help="also time the Monte Carlo on Dask: processes | tcp://HOST:PORT",
    )
    ap.add_argument("--workers", type=int, default=None, help="workers for --scheduler processes")
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="a 400 m beat, small grids, 100 runs, once (checks the script runs)",
    )
    args = ap.parse_args()
    if args.smoke:
        bench_sdp(1, 100, BeatGrid(length_m=400.0, half_width_m=200.0, lateral_m=4.0))
        bench_deadline_physical(20, 32, ("linear",), 100)
        return
    pol = bench_sdp(args.repeat, args.runs)
    rn, ra = bench_deadline_physical()
    if args.scheduler:
        bench_scale_out(pol, rn, ra, args.runs, args.scheduler, args.workers, args.repeat)
    if args.paper:
        n_r, n_t, ds = args.paper_grid.split(",")
        bench_paper(int(n_r), int(n_t), float(ds), args.runs, args.paper_interp)


if __name__ == "__main__":
    main()
