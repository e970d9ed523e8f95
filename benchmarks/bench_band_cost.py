"""The leg-time bands' cost in single plans: ``plan --ensemble N`` against a single
``plan`` of Hyères R1, in fresh processes of this tree, alternately in one run.

Usage::

    .venv/bin/python benchmarks/bench_band_cost.py [--members 100] [--runs 3]
    .venv/bin/python benchmarks/bench_band_cost.py --smoke   # 3 members, 1 pair

Each pair is ``python -m sailroute plan courses/hyeres-r1.yaml --ensemble N --no-plots
-q -o DIR`` and then the same without ``--ensemble``, each in a new process, as run here
(the environment unchanged); the CPU time is the child's user + system time
(``os.wait4``), wall time beside it.  The step kernels are primed first, as after any
compiled use (:func:`bench_plan.prime_kernels`: the module compiled ahead of time, or
numba's cache), and one warm-up pair runs before the timed ones.  The table gives the
medians and the band's cost in single plans as the median of the pairs' ratios; the load
average is printed before and after.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
from pathlib import Path

from bench_plan import COURSE, ROOT, child_cpu, load, prime_kernels


def plan_cpu(members: int, out: Path) -> tuple[float, float]:
    """CPU and wall [s] of one fresh ``plan`` (an ensemble of ``members``, 0: none)."""
    cmd = [sys.executable, "-m", "sailroute", "plan", str(COURSE), "--no-plots", "-q"]
    cmd += ["-o", str(out)] + (["--ensemble", str(members)] if members else [])
    cpu, wall, _ = child_cpu(cmd, ROOT, dict(os.environ), out.parent)
    return cpu, wall


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--members", type=int, default=100, help="ensemble members (default 100)")
    ap.add_argument("--runs", type=int, default=3, help="timed pairs (default 3)")
    ap.add_argument("--smoke", action="store_true", help="3 members, 1 pair, no warm-up")
    args = ap.parse_args(argv)
    if args.runs < 1 or args.members < 3:
        ap.error("--runs must be at least 1 and --members at least 3 (a band's smallest)")
    members, runs = (3, 1) if args.smoke else (args.members, args.runs)
    print(
        f"# bench_band_cost: {COURSE.relative_to(ROOT)}, plan --ensemble {members} "
        "against plan, --no-plots, fresh processes"
    )
    print(f"load average at the start: {load()}")
    print(f"kernels primed; auto finds them: {prime_kernels(dict(os.environ))}")
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        if not args.smoke:
            plan_cpu(members, tmp / "ensemble")
            plan_cpu(0, tmp / "single")
        rows = [
            (plan_cpu(members, tmp / "ensemble"), plan_cpu(0, tmp / "single")) for _ in range(runs)
        ]
    print(f"load average at the end: {load()}")
    ens = [e for e, _ in rows]
    one = [s for _, s in rows]
    ratios = [e[0] / s[0] for e, s in rows]
    print()
    print("| command | CPU (wall), median |")
    print("|---|---:|")
    print(
        f"| plan --ensemble {members} | {statistics.median(c for c, _ in ens):.2f} s "
        f"({statistics.median(w for _, w in ens):.2f} s) |"
    )
    print(
        f"| plan | {statistics.median(c for c, _ in one):.3f} s "
        f"({statistics.median(w for _, w in one):.3f} s) |"
    )
    print(
        f"\nthe bands cost **{statistics.median(ratios):.1f} single plans** in CPU "
        f"(pairs {min(ratios):.1f}-{max(ratios):.1f})"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
