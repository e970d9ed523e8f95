"""Benchmark the multi-spline refinement against Dębski (2016b), one CPU core.

Run::

    python benchmarks/bench_multispline.py            # both examples, all options (~1 min)
    python benchmarks/bench_multispline.py --quick    # Example 2 without the option runs
    python benchmarks/bench_multispline.py --smoke    # Example 1 on a tiny set-up (seconds)

One run prints, per example: the set-up, our wall time on one core
(``OMP_NUM_THREADS=1``), the paper's serial C and OpenCL times, the ratios, and
our result next to the paper's:

* **Example 1** (function fitting, the paper's test problem with a known
  answer): fit ``r_t(θ)`` on ``[0, π]`` with ``r(0) = r(π) = 0``
  (:func:`~sailroute.routing.multispline.fit_function`); result = L2 error
  (the DP minimises its square).  The paper's serial C time of its Table 1
  set-up is 56.5 s; the set-up's parameters are not known in full, so
  ``--ex1 NR NC NTS NREF`` takes them (default 16 rows, 64 nodes, 32 slopes,
  3 refinements).
* **Example 2** (routing in Dębski's spatially varying analytic wind, A = (0, 0)
  to the point B = (500 m, 0), n_r = 16, n_c = 32, n_ts = 8, 3 refinements,
  half-width 400 m, the paper's dynamic boat, no seconds penalties); result =
  route time t_f.  Paper: 25.6 s serial C, 7.6 s OpenCL, t_f ≈ 161 s.  Also
  run with the options ``spline_carry_speed`` and ``spline_start_from_rest``.

The paper's times are from its hardware; ours from whatever machine runs this,
so the ratios compare implementations only roughly.  The header gives the
load average at the start and the end.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.boat.dynamic import DynamicBoat  # noqa: E402
from sailroute.routing.multispline import fit_function, solve_spline  # noqa: E402
from sailroute.routing.settings import RoutingSettings, routing_settings  # noqa: E402
from sailroute.routing.types import Start, Target  # noqa: E402
from sailroute.wind.analytic import debski_test_wind  # noqa: E402

PAPER = {
    "ex1": {"serial_s": 56.5, "opencl_s": None, "result": None},
    "ex2": {"serial_s": 25.6, "opencl_s": 7.6, "result": 161.0},
}
"""Dębski (2016b) as published: times [s] and results (t_f [s] for Example 2)."""
EX1_DEFAULT = (16, 64, 32, 3)
EX2 = {"dp_rows": 16, "spline_cols": 32, "spline_slopes": 8, "spline_refinements": 3}
POINT_ZONE_M = 0.01  # the paper's B is a point: a 1 cm rounding segment


def _ratio(ours: float, paper: float | None) -> str:
    return f"{ours / paper:6.3f}" if paper else "   n/a"


def _fmt(v: float | None, spec: str) -> str:
    return "n/a" if v is None else format(v, spec)


def _best(fn, repeat: int):
    """Run ``fn`` ``repeat`` times; the fastest wall time [s] and its result."""
    best = (math.inf, None)
    for _ in range(repeat):
        tic = time.perf_counter()
        out = fn()
        wall = time.perf_counter() - tic
        if wall < best[0]:
            best = (wall, out)
    return best


def _row(example: str, setup: str, wall: float, paper: dict, result: str) -> None:
    print(
        f"{example:<10}{setup:<44}{wall:>9.2f}{_fmt(paper['serial_s'], '9.1f'):>9}"
        f"{_fmt(paper['opencl_s'], '8.1f'):>8}{_ratio(wall, paper['serial_s']):>9}"
        f"{_ratio(wall, paper['opencl_s']):>9}   {result}"
    )


def example1(setup: tuple[int, int, int, int], repeat: int) -> None:
    """The paper's function-fitting test problem."""
    nr, nc, nts, nref = setup
    wall, fit = _best(
        lambda: fit_function(n_rows=nr, n_cols=nc, n_slopes=nts, n_refine=nref), repeat
    )
    errs = " -> ".join(f"{math.sqrt(p.cost):.5f}" for p in fit.passes)
    edges = sum(p.edges for p in fit.passes)
    _row(
        "Example 1",
        f"n_r={nr} n_c={nc} n_ts={nts} refine={nref}",
        wall,
        PAPER["ex1"],
        f"L2 error per pass {errs} ({edges / 1e6:.0f} M edges; paper: not given)",
    )


def example2(repeat: int, options: bool) -> None:
    """Routing in Dębski's analytic wind with the dynamic boat."""
    boat = DynamicBoat()
    boat.table()  # built once per boat, outside the timings
    variants = [("flying start", False, False)]
    if options:
        variants += [
            ("carry speed", True, False),
            ("from rest", False, True),
            ("carry speed + from rest", True, True),
        ]
    for name, carry, rest in variants:
        s = routing_settings(
            router="spline",
            dp_half_width_m=400.0,
            tack_penalty_s=0.0,
            gybe_penalty_s=0.0,
            zone_m=POINT_ZONE_M,
            spline_carry_speed=carry,
            spline_start_from_rest=rest,
            **EX2,
        )

        def run(s: RoutingSettings = s):
            return solve_spline(
                Start((0.0, 0.0)), Target("mark", (500.0, 0.0)), 0.0, debski_test_wind(), boat, s
            )

        wall, (res, fit) = _best(run, repeat)
        edges = sum(p.edges for p in fit.passes)
        setup = f"n_r=16 n_c=32 n_ts=8 refine=3, {name}"
        _row(
            "Example 2",
            setup,
            wall,
            PAPER["ex2"],
            f"t_f {res.time_s:.3f} s (paper {PAPER['ex2']['result']:.0f} s; "
            f"{edges / 1e6:.1f} M edges; course {res.track.heading_deg[0]:.1f}° -> "
            f"{res.track.heading_deg[-2]:.1f}°)",
        )


def main() -> None:
    """Command-line entry point."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="Example 2 only, no option runs")
    ap.add_argument(
        "--ex1",
        nargs=4,
        type=int,
        metavar=("NR", "NC", "NTS", "NREF"),
        default=EX1_DEFAULT,
        help="Example 1 set-up (default %(default)s)",
    )
    ap.add_argument("--repeat", type=int, default=1, help="best of N runs (default 1)")
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="Example 1 on a tiny set-up only (checks the script runs)",
    )
    args = ap.parse_args()
    load0 = os.getloadavg()
    print(
        f"# sailroute multi-spline benchmark — {platform.processor() or platform.machine()}, "
        f"Python {platform.python_version()}, numpy {np.__version__}, 1 thread; "
        f"load average at start {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}"
    )
    print(
        f"{'example':<10}{'set-up':<44}{'ours s':>9}{'serial':>9}{'OpenCL':>8}"
        f"{'/serial':>9}{'/OpenCL':>9}   result"
    )
    if args.smoke:
        example1((6, 8, 4, 1), 1)
        return
    if not args.quick:
        example1(tuple(args.ex1), args.repeat)
    example2(args.repeat, not args.quick)
    load1 = os.getloadavg()
    print(f"# load average at end {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}")


if __name__ == "__main__":
    main()
