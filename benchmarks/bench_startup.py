"""The command line's start-up in fresh processes, against a baseline checkout, alternately
in one run.

Usage::

    git worktree add --detach /tmp/startup_base <commit>
    .venv/bin/python benchmarks/bench_startup.py --baseline /tmp/startup_base [--runs 7]
    .venv/bin/python benchmarks/bench_startup.py --smoke   # this tree against itself, 1 pair

Three commands, each in a new process, this tree (A) and the baseline (B, the same
interpreter with ``PYTHONPATH=<baseline>``) in turn, A B A B ... after a warm-up pair:

* ``python -m sailroute --help``: the interpreter, ``sailroute.cli`` and typer;
* ``python -c "import sailroute.commands.plan"``: what the ``plan`` command imports before
  it reads the course;
* ``python -c "load_course('courses/hyeres-r1.yaml')"``: the course loaded, its scenarios
  checked, its marks projected (``--only load``; not by default);
* ``sailroute plan courses/hyeres-r1.yaml --no-plots -q -o out``: the whole command,
  routing included, as the console script runs it (``sailroute.__main__.main``), with
  the CPU time spent in ``plan_course`` (the routing and the plan's numbers) taken by the
  process itself: the row "plan, outside plan_course" is the rest, what this benchmark is
  about (the interpreter, the imports, the parsing of the command line, loading the
  course, writing the files), without the noise of the routing.

The CPU time is the child's user + system time (``os.wait4``, ``child_cpu`` of
``benchmarks/bench_plan.py``), wall time beside it; the two bytecode set-ups of
``bench_plan.py`` (as run here, where ``PYTHONDONTWRITEBYTECODE=1`` compiles sailroute's
modules at every start, and a primed ``PYTHONPYCACHEPREFIX``).  Numba's cache of the
compiled step is primed on each side first (``--smoke``: left as it is), so that both route
alike.  Every ``plan`` writes into ``out`` of its own directory: its files and its
standard output must be the same bytes as the baseline's (the script exits 1 otherwise).
The table gives medians, and B - A and B / A as the medians of the pairs' differences and
ratios; the load average is printed before and after.
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_plan import (
    COURSE,
    ROOT,
    baseline_parser,
    child_cpu,
    load,
    prime_kernels,
    primed,
    start,
)

PLAN_CODE = f"""\
import sys, time
import sailroute.cli as cli  # (imports no NumPy: the entry point's set-up comes first)
guarded, spent = cli.run_guarded, []
def run_guarded(fn, **kwargs):
    import sailroute.commands.plan as command  # (imported by the command by now)
    inner = command.plan_course
    def timed(*args, **kw):
        t = time.process_time()
        try:
            return inner(*args, **kw)
        finally:
            spent.append(time.process_time() - t)
    command.plan_course = timed
    return guarded(fn, **kwargs)
cli.run_guarded = run_guarded
sys.argv = ["sailroute", "plan", {str(COURSE)!r}, "--no-plots", "-q", "-o", "out"]
from sailroute.__main__ import main
try:
    main()
finally:
    with open("plan_cpu_s", "w") as f:
        f.write(repr(sum(spent)))
"""
"""``sailroute plan`` as the console script runs it, with the CPU time [s] of
``plan_course`` (the routing and the plan's numbers) written to ``plan_cpu_s``: the timer
goes in as the command calls its guarded work, after its own imports."""
PLAN = ("-c", PLAN_CODE)
COMMANDS: dict[str, tuple[str, tuple[str, ...]]] = {
    "help": ("sailroute --help", ("-m", "sailroute", "--help")),
    "import": (
        'python -c "import sailroute.commands.plan"',
        ("-c", "import sailroute.commands.plan"),
    ),
    "load": (
        "python -c \"load_course('hyeres-r1.yaml')\"",
        ("-c", f"from sailroute.course.load import load_course; load_course({str(COURSE)!r})"),
    ),
    "plan": ("sailroute plan hyeres-r1.yaml --no-plots -q", PLAN),
}
OUTSIDE = "plan, outside plan_course"
"""The row of the plan's CPU less that of routing it: start-up, parsing, loading, writing."""


def outputs(cwd: Path, stdout: bytes) -> dict[str, bytes]:
    """A ``plan``'s standard output and the files it wrote into ``cwd/out``, by name."""
    files = {p.name: p.read_bytes() for p in sorted((cwd / "out").iterdir())}
    return {"standard output": stdout, **files}


def differing(a: dict[str, bytes], b: dict[str, bytes]) -> list[str]:
    """Names of the outputs that are not the same bytes on both sides (or on one only)."""
    return sorted(k for k in a.keys() | b.keys() if a.get(k) != b.get(k))


def _row(
    a: list[float], b: list[float], wall_a: list[float], wall_b: list[float]
) -> dict[str, Any]:
    """Medians of the pairs' CPU [s] and wall [s], and of their differences and ratios."""
    ratios = [y / x for x, y in zip(a, b, strict=True)]
    return {
        "cpu_a": statistics.median(a),
        "cpu_b": statistics.median(b),
        "wall_a": statistics.median(wall_a) if wall_a else None,
        "wall_b": statistics.median(wall_b) if wall_b else None,
        "diff": statistics.median(y - x for x, y in zip(a, b, strict=True)),
        "ratio": statistics.median(ratios),
        "spread": (min(ratios), max(ratios)),
    }


def bench(
    args: tuple[str, ...],
    env_a: dict[str, str],
    env_b: dict[str, str],
    base: Path,
    runs: int,
    tmp: Path,
    *,
    warm_up: bool,
) -> tuple[list[dict[str, Any]], list[str]]:
    """``runs`` pairs A B of one command (after a warm-up pair): its row (a plan: and the
    row outside ``plan_course``), and the outputs of a pair that differ."""
    cmd = [sys.executable, *args]
    cwd_a, cwd_b = tmp / "a", tmp / "b"
    cwd_a.mkdir(parents=True, exist_ok=True)
    cwd_b.mkdir(parents=True, exist_ok=True)
    if warm_up:  # (and the bytecode cache's priming)
        child_cpu(cmd, ROOT, env_a, cwd_a)
        child_cpu(cmd, base, env_b, cwd_b)
    cpu: tuple[list[float], list[float]] = ([], [])
    wall: tuple[list[float], list[float]] = ([], [])
    outside: tuple[list[float], list[float]] = ([], [])
    differ: list[str] = []
    for _ in range(runs):
        ca, wa, out_a = child_cpu(cmd, ROOT, env_a, cwd_a)
        cb, wb, out_b = child_cpu(cmd, base, env_b, cwd_b)
        for side, c, w in ((0, ca, wa), (1, cb, wb)):
            cpu[side].append(c)
            wall[side].append(w)
        if args is PLAN:
            differ = differing(outputs(cwd_a, out_a), outputs(cwd_b, out_b)) or differ
            outside[0].append(ca - float((cwd_a / "plan_cpu_s").read_text()))
            outside[1].append(cb - float((cwd_b / "plan_cpu_s").read_text()))
        elif out_a != out_b:
            differ = ["standard output"]
    rows = [_row(*cpu, *wall)]
    if args is PLAN:
        rows.append({**_row(*outside, [], []), "command": OUTSIDE})
    return rows, differ


def main(argv: list[str] | None = None) -> int:
    ap = baseline_parser(__doc__)
    ap.add_argument(
        "--only",
        nargs="+",
        choices=COMMANDS,
        default=["help", "import", "plan"],
        help="commands to time (default: help import plan)",
    )
    args = ap.parse_args(argv)
    base, runs = start(ap, args, "# bench_startup: the command line's start-up, fresh processes")
    env = dict(os.environ)
    print(f"PYTHONDONTWRITEBYTECODE={env.get('PYTHONDONTWRITEBYTECODE', '')!r}")
    rows: list[dict[str, Any]] = []
    differ: list[str] = []
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        setups = [("as run here", env, env)]
        if args.smoke:
            print("numba's cache as it is (--smoke)")
        else:
            warm_a, warm_b = primed(env, tmp / "pyc-a"), primed(env, tmp / "pyc-b")
            setups.append(("primed cache", warm_a, warm_b))
        if not args.smoke and "plan" in args.only:
            found = [prime_kernels(e, src) for e, src in ((env, ROOT), (env, base))]
            found += [prime_kernels(warm_a, ROOT), prime_kernels(warm_b, base)]
            print(f"numba's cache primed; auto finds the kernels, A and B: {found[:2]}")
        for setup, ea, eb in setups:
            for name, cmd in (COMMANDS[k] for k in args.only):
                got, diff = bench(cmd, ea, eb, base, runs, tmp / setup, warm_up=not args.smoke)
                rows += [{"command": name, **r, "setup": setup} for r in got]
                differ += [f"{name}: {k}" for k in diff]
    print(f"load average at the end: {load()}")
    print()
    print("| command | set-up | A: CPU (wall) | B: CPU (wall) | B - A CPU | B / A CPU (range) |")
    print("|---|---|---:|---:|---:|---:|")
    for r in rows:
        lo, hi = r["spread"]
        a, b = (
            f"{r[f'cpu_{k}']:.3f} s"
            + ("" if r[f"wall_{k}"] is None else f" ({r[f'wall_{k}']:.3f} s)")
            for k in "ab"
        )
        name = r["command"] if r["command"] == OUTSIDE else f"`{r['command']}`"
        print(
            f"| {name} | {r['setup']} | {a} | {b} | {r['diff'] * 1e3:+.0f} ms | "
            f"**{r['ratio']:.2f}x** ({lo:.2f}-{hi:.2f}) |"
        )
    differ = sorted(set(differ))
    print()
    if differ:
        print("FAIL: not the same bytes as the baseline: " + "; ".join(differ))
        return 1
    print("outputs (plan's files, every command's standard output) the same bytes as B: yes")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
