"""Benchmark the grid-DP and multi-spline routers (one CPU core).

Run::

    python benchmarks/bench_griddp.py            # full run (~2 min)
    python benchmarks/bench_griddp.py --quick    # C <= 64 only
    python benchmarks/bench_griddp.py --smoke    # C = 8 table only (seconds)

Prints, for Dębski's (2016) test case (800 m x 500 m, 12 m/s wind 5° off the
leg axis) and his spatially varying analytic wind:

* grid DP wall time, segment evaluations and route time for C = 32, 64, 128
  nodes per row (R = 13 rows), dynamic boat and its steady polar, one pass
  and with mesh refinement;
* the mesh convergence in C next to the paper's t_f (R = 30 rows);
* multi-spline timings (the paper's function-fitting problem, and routing);
* the accuracy of the fast segment kernel against RK4.

The paper needed 874 s (serial C) and 21 s (OpenCL GPU) for C = 128 on its
hardware; numbers here are from whatever machine runs this script.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.backend import get_xp  # noqa: E402
from sailroute.boat.dynamic import DynamicBoat, build_table  # noqa: E402
from sailroute.routing.griddp import solve_griddp  # noqa: E402
from sailroute.routing.multispline import fit_function, solve_spline  # noqa: E402
from sailroute.routing.settings import routing_settings  # noqa: E402
from sailroute.routing.types import Start, Target  # noqa: E402
from sailroute.wind.analytic import debski_test_wind  # noqa: E402
from sailroute.wind.uniform import UniformWind  # noqa: E402

PAPER_TF = {8: 1212.32, 16: 655.36, 32: 411.25, 64: 357.85, 128: 352.17}
A = Start((0.0, 0.0))
POINT_ZONE_M = 0.01  # the papers' B is a point: a 1 cm rounding segment


def _grid_rows(cols: list[int], quick: bool, xp=np) -> None:
    boat = DynamicBoat()
    polar = boat.steady_polar(np.arange(0.0, 61.0, 2.0), twa_step=1.0)
    paper_wind = UniformWind(12.0, 5.0)
    paper_tgt = Target("mark", (0.0, 500.0))
    debski, debski_tgt = debski_test_wind(), Target("mark", (500.0, 0.0))
    print("\n## Grid DP, R = 13 rows, half-width 400 m (one core)")
    print(
        f"{'case':<22}{'model':<9}{'C':>5}{'passes':>7}{'wall s':>9}{'evals':>13}"
        f"{'Mevals/s':>10}{'route s':>10}"
    )
    for name, wind, tgt in (
        ("paper 12 m/s, 5 deg", paper_wind, paper_tgt),
        ("Debski analytic wind", debski, debski_tgt),
    ):
        for model_name, b in (("dynamic", boat), ("polar", polar)):
            for c in cols:
                for ref in (0, 2):
                    s = routing_settings(
                        router="griddp",
                        dp_cols=c,
                        dp_rows=13,
                        dp_refinements=ref,
                        dp_half_width_m=400.0,
                        tack_penalty_s=0.0,
                        gybe_penalty_s=0.0,
                        zone_m=POINT_ZONE_M,
                    )
                    tic = time.perf_counter()
                    sol = solve_griddp(A, tgt, 0.0, wind, b, s, xp=xp)
                    wall = time.perf_counter() - tic
                    ev = sum(p.segment_evals for p in sol.passes)
                    print(
                        f"{name:<22}{model_name:<9}{c:>5}{ref + 1:>7}{wall:>9.2f}{ev:>13,d}"
                        f"{ev / wall / 1e6:>10.1f}{sol.result.time_s:>10.2f}"
                    )
    del quick


def _paper_convergence(quick: bool) -> None:
    boat = DynamicBoat()
    cols = [8, 16, 32, 64] + ([] if quick else [128])
    print("\n## Mesh convergence, paper case, R = 30 rows, one pass, dynamic boat")
    print("   (the paper's row count is not stated; R = 30 reproduces its C = 8 value)")
    print(f"{'C':>5}{'t_f here s':>12}{'paper t_f s':>13}{'wall s':>9}")
    for c in cols:
        s = routing_settings(
            router="griddp",
            dp_cols=c,
            dp_rows=30,
            dp_refinements=0,
            dp_half_width_m=400.0,
            dp_samples=1,
            zone_m=POINT_ZONE_M,
        )
        tic = time.perf_counter()
        sol = solve_griddp(A, Target("mark", (0.0, 500.0)), 0.0, UniformWind(12.0, 5.0), boat, s)
        print(
            f"{c:>5}{sol.result.time_s:>12.2f}{PAPER_TF[c]:>13.2f}{time.perf_counter() - tic:>9.2f}"
        )
    bound = 500.0 * np.cos(np.radians(5.0)) / (12.0 * boat.best_vmg()[1])
    print(f"  lower bound L cos5°/VMG* = {bound:.2f} s (plus momentum losses at start/tack)")


def _splines() -> None:
    print("\n## Multi-spline")
    tic = time.perf_counter()
    fit = fit_function(n_refine=4)
    wall = time.perf_counter() - tic
    errs = ", ".join(f"{np.sqrt(p.cost):.4f}" for p in fit.passes)
    print(
        f"function fitting (10 rows, 25 nodes, 7 slopes, 4 refinements): {wall:.2f} s; "
        f"L2 error per pass: {errs}"
    )
    boat = DynamicBoat()
    polar = boat.steady_polar(np.arange(0.0, 61.0, 2.0), twa_step=1.0)
    for model_name, b, pens in (("polar", polar, (0.0, 1e3)), ("dynamic", boat, (0.0,))):
        for pen in pens:
            s = routing_settings(
                router="spline",
                dp_rows=13,
                dp_half_width_m=400.0,
                tack_penalty_s=pen,
                gybe_penalty_s=pen,
                zone_m=POINT_ZONE_M,
            )
            tic = time.perf_counter()
            res, fit = solve_spline(A, Target("mark", (500.0, 0.0)), 0.0, debski_test_wind(), b, s)
            wall = time.perf_counter() - tic
            edges = sum(p.edges for p in fit.passes)
            print(
                f"Debski wind, {model_name:<8} penalty {pen:>6.0f} s: {wall:6.2f} s, "
                f"{edges:,d} edges, route {res.time_s:.2f} s, tacks {res.n_tacks}, "
                f"course {res.track.heading_deg[0]:.1f}° -> {res.track.heading_deg[-2]:.1f}°"
            )


def _kernel_accuracy() -> None:
    print("\n## Segment kernel")
    tic = time.perf_counter()
    build_table(0.03, 0.005, 0.7)
    print(f"lookup table build: {time.perf_counter() - tic:.2f} s (once per boat)")
    boat = DynamicBoat()
    rng = np.random.default_rng(0)
    n = 300
    ell = rng.uniform(3.0, 60.0, n)
    twa = rng.uniform(11.0, 180.0, n)
    tws = rng.uniform(3.0, 20.0, n)
    v0 = rng.uniform(0.0, 2.0, n) * boat.steady_speed(tws, twa)
    tic = time.perf_counter()
    t_ref, _ = boat.simulate(ell, twa, tws, v0, dt_s=0.002)
    t_rk = time.perf_counter() - tic
    tic = time.perf_counter()
    t_fast, _ = boat.segment(ell, twa, tws, v0)
    t_f = time.perf_counter() - tic
    err = np.abs(t_fast - t_ref)
    print(
        f"{n} random segments: RK4 (dt 2 ms) {t_rk:.2f} s, table {t_f * 1e3:.1f} ms; "
        f"max |error| {err.max():.2e} s, max relative {np.max(err / t_ref):.1e}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="skip C = 128")
    ap.add_argument(
        "--backend",
        default="numpy",
        help="numpy | cupy | auto: array backend of the grid-DP rows table",
    )
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="the grid-DP table at C = 8 only (checks the script runs)",
    )
    args = ap.parse_args()
    print(
        f"# sailroute grid-DP benchmark — {platform.processor() or platform.machine()}, "
        f"Python {platform.python_version()}, numpy {np.__version__}, 1 thread"
    )
    DynamicBoat().table()  # build the lookup table outside the timings
    cols = [8] if args.smoke else [32, 64] + ([] if args.quick else [128])
    _grid_rows(cols, args.quick, get_xp(args.backend))
    if args.smoke:
        return
    _paper_convergence(args.quick)
    _splines()
    _kernel_accuracy()


if __name__ == "__main__":
    main()
