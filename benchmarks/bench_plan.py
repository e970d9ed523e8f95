"""A single ``sailroute plan`` of Hyères R1 without plots, in fresh processes, against a
baseline checkout, alternately in one run.

Usage::

    git worktree add /tmp/base <commit>
    .venv/bin/python benchmarks/bench_plan.py --baseline /tmp/base [--runs 7]
        [--cold-kernels]
    .venv/bin/python benchmarks/bench_plan.py --smoke   # this tree against itself, 1 pair

Each run is ``python -m sailroute plan courses/hyeres-r1.yaml --no-plots -q -o DIR`` in a
new process, this tree (A) and the baseline (B, the same interpreter with
``PYTHONPATH=<baseline>``) in turn, A B A B ...  The CPU time is the child's user +
system time (``os.wait4``), the primary figure; wall time is printed beside it.  Two
bytecode set-ups, as in docs/performance.md ("CLI start-up and the main job"):

* ``as run here``: the environment unchanged.  Where ``PYTHONDONTWRITEBYTECODE=1`` (this
  sandbox), sailroute's own modules compile from source at every start and its
  dependencies load their installed ``.pyc``;
* ``primed cache``: a ``.pyc`` cache for everything in a temporary ``PYTHONPYCACHEPREFIX``
  (primed by one run of each side), as after a normal install.

The compiled step's kernels (``routing.engine: auto`` loads them where they are built,
:func:`sailroute.routing.isochrone_fast.kernels_cached`: the module compiled ahead of
time, or numba's cache) are primed first by a run on ``engine: numba``, which builds
them where they are not; ``--cold-kernels`` gives A an empty ``NUMBA_CACHE_DIR`` instead
(the folder of both), so that ``auto`` routes on NumPy.  Every run's leg times are read
back from its ``plan.json`` (to the ms) and, unrounded, from one more plan of each side
in-process: they must equal the baseline's to 1e-6 s (the script exits 1 otherwise).
The table gives medians, and the ratio B/A as the median of the pairs' ratios; the load
average is printed before and after.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
COURSE = ROOT / "courses" / "hyeres-r1.yaml"
TOLERANCE_S = 1e-6
"""Largest difference of a leg time allowed between the two sides [s]."""


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def child_cpu(
    cmd: list[str], src: Path, env: dict[str, str], cwd: Path
) -> tuple[float, float, bytes]:
    """Run ``cmd`` in a fresh process with ``sailroute`` imported from ``src``: CPU [s] of
    the child (user + system, ``os.wait4``), wall [s] and its standard output; exits with
    the command and its standard error where it fails."""
    full = dict(env, PYTHONPATH=str(src))
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as out_f, tempfile.TemporaryFile() as err_f:
        proc = subprocess.Popen(cmd, cwd=cwd, env=full, stdout=out_f, stderr=err_f)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        out_f.seek(0)
        err_f.seek(0)
        stdout, err = out_f.read(), err_f.read().decode(errors="replace")
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} (from {src}) failed ({proc.returncode}):\n{err}")
    return usage.ru_utime + usage.ru_stime, wall, stdout


def run_once(src: Path, env: dict[str, str], out: Path) -> tuple[float, float, list[float]]:
    """One fresh ``plan`` from ``src``: CPU [s] of the child, wall [s], leg times [s]."""
    cmd = [sys.executable, "-m", "sailroute", "plan", str(COURSE), "--no-plots", "-q"]
    cmd += ["-o", str(out)]
    cpu, wall, _ = child_cpu(cmd, src, env, out.parent)
    legs = json.loads((out / "plan.json").read_text())["legs"]
    return cpu, wall, [float(leg["time_s"]) for leg in legs]


def exact_leg_times(src: Path, env: dict[str, str]) -> list[float]:
    """The leg times [s] of the plan from ``src``, unrounded (``plan.json`` keeps ms)."""
    code = (
        "from sailroute.course.load import load_course\n"
        "from sailroute.planning.route import plan_course\n"
        f"run = plan_course(load_course({str(COURSE)!r}))\n"
        "print(repr([leg.time_s for leg in run.plan.legs]))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        env=dict(env, PYTHONPATH=str(src)),
        cwd=src.parent,
        capture_output=True,
        text=True,
        check=True,
    )
    return [float(x) for x in out.stdout.strip().strip("[]").split(",")]


def prime_kernels(env: dict[str, str], src: Path = ROOT) -> str:
    """Route the course once on ``engine: numba`` from ``src`` (compiles the step kernels
    into numba's cache, or loads them); whether ``auto`` now finds them cached."""
    code = (
        "import dataclasses, sys\n"
        "from sailroute.course.load import load_course\n"
        "from sailroute.planning.route import plan_course\n"
        "from sailroute.routing import isochrone_fast\n"
        f"c = load_course({str(COURSE)!r})\n"
        "r = c.routing\n"
        "r = dataclasses.replace(r, isochrone=dataclasses.replace(r.isochrone, engine='numba'))\n"
        "plan_course(dataclasses.replace(c, routing=r))\n"
        "print(isochrone_fast._step_kernels_in_cache())\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        env=dict(env, PYTHONPATH=str(src)),
        cwd=src.parent,  # not a folder holding a sailroute (``-c`` puts it first on the path)
        capture_output=True,
        text=True,
        check=True,
    )
    return out.stdout.strip()


def bench(
    name: str,
    env_a: dict[str, str],
    env_b: dict[str, str],
    base: Path,
    runs: int,
    tmp: Path,
    *,
    warm_up: bool = True,
) -> dict[str, Any]:
    """``runs`` pairs A B after one warm-up pair; medians and the pairs' ratio."""
    a_out, b_out = tmp / "a", tmp / "b"
    if warm_up:  # (and the bytecode cache's priming)
        run_once(ROOT, env_a, a_out)
        run_once(base, env_b, b_out)
    cpu_a, cpu_b, wall_a, wall_b, ratios = [], [], [], [], []
    worst = 0.0
    for _ in range(runs):
        ca, wa, la = run_once(ROOT, env_a, a_out)
        cb, wb, lb = run_once(base, env_b, b_out)
        if len(la) != len(lb):
            raise SystemExit(f"{name}: {len(la)} legs against the baseline's {len(lb)}")
        worst = max([worst, *(abs(x - y) for x, y in zip(la, lb, strict=True))])
        cpu_a.append(ca)
        cpu_b.append(cb)
        wall_a.append(wa)
        wall_b.append(wb)
        ratios.append(cb / ca)
    return {
        "name": name,
        "cpu_a": statistics.median(cpu_a),
        "cpu_b": statistics.median(cpu_b),
        "wall_a": statistics.median(wall_a),
        "wall_b": statistics.median(wall_b),
        "ratio": statistics.median(ratios),
        "spread": (min(ratios), max(ratios)),
        "worst_s": worst,
        "legs_s": la,
    }


def primed(env: dict[str, str], cache: Path) -> dict[str, str]:
    """``env`` with a bytecode cache of its own in ``cache`` (``PYTHONPYCACHEPREFIX``),
    which the first run (the warm-up) writes: as after a normal install."""
    out = dict(env, PYTHONPYCACHEPREFIX=str(cache))
    out.pop("PYTHONDONTWRITEBYTECODE", None)
    return out


def baseline_parser(doc: str) -> argparse.ArgumentParser:
    """The options of a benchmark of this tree against a baseline checkout: ``--baseline``,
    ``--runs`` (pairs) and ``--smoke`` (1 pair against itself)."""
    ap = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    ap.add_argument("--baseline", type=Path, help="checkout of the baseline (--smoke: this tree)")
    ap.add_argument("--runs", type=int, default=7, help="pairs per set-up (default 7)")
    ap.add_argument(
        "--smoke", action="store_true", help="1 pair, the set-up as run here, no warm-up"
    )
    return ap


def start(ap: argparse.ArgumentParser, args: argparse.Namespace, title: str) -> tuple[Path, int]:
    """The baseline checkout (``--smoke``: this tree) and the pairs to run; prints the
    title, both trees and the load average."""
    if args.baseline is None and not args.smoke:
        ap.error("--baseline is required (a checkout of the commit to compare with)")
    base = ROOT if args.baseline is None else args.baseline.resolve()
    if not (base / "sailroute" / "__main__.py").is_file():
        raise SystemExit(f"--baseline {base}: not a sailroute checkout (no sailroute/__main__.py)")
    print(title)
    print(f"A: {ROOT}   B: {base}   python {sys.version.split()[0]}, {os.cpu_count()} cores")
    print(f"load average at the start: {load()}")
    return base, 1 if args.smoke else args.runs


def main(argv: list[str] | None = None) -> int:
    ap = baseline_parser(__doc__)
    ap.add_argument(
        "--cold-kernels", action="store_true", help="A without built kernels (auto: NumPy)"
    )
    args = ap.parse_args(argv)
    title = f"# bench_plan: {COURSE.relative_to(ROOT)}, plan --no-plots, fresh processes"
    base, runs = start(ap, args, title)
    rows = []
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        env = dict(os.environ)
        env_a = dict(env)
        if args.smoke:
            print("the kernels for A as they are (--smoke)")
        elif args.cold_kernels:
            env_a["NUMBA_CACHE_DIR"] = str(tmp / "numba-empty")
            print("the kernels for A: none built (auto routes a single plan on NumPy)")
        else:
            print(f"the kernels for A primed; auto finds them: {prime_kernels(env)}")
        print(f"PYTHONDONTWRITEBYTECODE={env.get('PYTHONDONTWRITEBYTECODE', '')!r}")
        setups = [("as run here", env_a, env)]
        if not args.smoke:
            warm_a, warm_b = primed(env_a, tmp / "pyc-a"), primed(env, tmp / "pyc-b")
            if not args.cold_kernels:  # numba's own .pyc into the prefix too
                prime_kernels(warm_a)
            setups.append(("primed cache", warm_a, warm_b))
        for name, ea, eb in setups:
            (tmp / "a").mkdir(exist_ok=True)
            (tmp / "b").mkdir(exist_ok=True)
            rows.append(bench(name, ea, eb, base, runs, tmp, warm_up=not args.smoke))
    print(f"load average at the end: {load()}")
    print()
    print("| set-up | A: CPU (wall) | B: CPU (wall) | B / A CPU, median of pairs (range) |")
    print("|---|---:|---:|---:|")
    for r in rows:
        lo, hi = r["spread"]
        print(
            f"| {r['name']} | {r['cpu_a']:.3f} s ({r['wall_a']:.3f} s) | "
            f"{r['cpu_b']:.3f} s ({r['wall_b']:.3f} s) | "
            f"**{r['ratio']:.2f}x** ({lo:.2f}-{hi:.2f}) |"
        )
    exact_a, exact_b = exact_leg_times(ROOT, env_a), exact_leg_times(base, env)
    if len(exact_a) != len(exact_b):
        raise SystemExit(f"{len(exact_a)} legs against the baseline's {len(exact_b)}")
    worst = max(
        [
            *(r["worst_s"] for r in rows),
            *(abs(x - y) for x, y in zip(exact_a, exact_b, strict=True)),
        ]
    )
    legs = ", ".join(repr(t) for t in exact_a)
    print(f"\nleg times [s], unrounded: {legs}; largest difference from B: {worst:.3g} s")
    if worst > TOLERANCE_S:
        print(f"FAIL: a leg time differs by more than {TOLERANCE_S} s")
        return 1
    print(f"same leg times to {TOLERANCE_S} s: yes")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
