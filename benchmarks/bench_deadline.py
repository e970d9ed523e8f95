"""Wang et al. (2024) Figs 3, 4(a) and 4(b) with the risk-aware deadline solver (one core).

Usage::

    python benchmarks/bench_deadline.py --grid 401,512            # all three figures
    python benchmarks/bench_deadline.py --smoke      # Fig 3 on a 21 x 32 grid, 200 runs
    python benchmarks/bench_deadline.py --grid 801,1024 --runs 20000 --json out.json
    python benchmarks/bench_deadline.py --grid 401,512 --interp cubic --figs 4b
    python benchmarks/bench_deadline.py --grid 801,1024 --solve-only --s-max 5
                                                   # time a few budget slices only
    python benchmarks/bench_deadline.py --grid 401,512 --figs 4b --solve-only \
        --engine numpy,numba,numpy,numba           # NumPy vs the numba kernels, one run
    git worktree add /tmp/base bc3c50e
    python benchmarks/bench_deadline.py --grid 801,1024 --figs 3 --solve-only \
        --engine numba --baseline /tmp/base --repeat 2   # this code vs an older checkout

``--grid NR1,NT`` gives the nodes in ``r`` (``n_r + 1``) and the intervals in ``θ``; the
budget step is the largest ``Δs = C/n`` with ``f_max Δs <= Δr`` (the CLI's rule), the
paper's ``Δs = Δr/f_max`` (``--ds-cells 2``: twice that).  Every figure is solved,
simulated (seeded, common random numbers for all policies) and compared with the paper in
the same run; the probabilities and means are printed next to the paper's and as
differences (pp) and ratios.  BLAS and OpenMP threads are pinned to one before NumPy is imported.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.boat.polar import Polar  # noqa: E402
from sailroute.strategy.deadline import (  # noqa: E402
    DeadlineGrid,
    simulate_deadline,
    solve_deadline,
    solve_risk_neutral,
)
from sailroute.strategy.shiftmodel import DriftDiffusionShift  # noqa: E402

SO40_TWA = [
    0,
    5,
    10,
    15,
    20,
    25,
    32,
    36,
    40,
    45,
    52,
    60,
    70,
    80,
    90,
    100,
    110,
    120,
    130,
    140,
    150,
    160,
    170,
    180,
]
SO40_KN = [
    0.0,
    0.6,
    1.2,
    1.8,
    2.1,
    2.5,
    4.1,
    4.6,
    5.0,
    5.4,
    5.8,
    6.2,
    6.4,
    6.5,
    6.5,
    6.5,
    6.4,
    6.2,
    5.7,
    5.2,
    4.7,
    4.2,
    3.9,
    3.6,
]
C = 2.0
SIGMA = 0.05
F_MAX = 0.05

# name: (a, start, deadlines, paper numbers).  Paper: 1601 x 1601, Δs = 0.025, bicubic ENO,
# golden-section steering refinement, 1e5 runs, Δt = 0.005 (Wang et al. 2024, Figs 3-4).
FIGS = {
    "3": (
        0.0,
        (1.93, 0.56, 1),
        (53.0, 56.0),
        {
            "mean_rn": 54.46,
            "mean_ra": {53.0: 55.57, 56.0: 55.95},
            "p_rn": {56.0: 0.525},
            "p_ra": {56.0: 0.589},
            # "a 10.6% improvement in P(T <= 53)": read as percentage points
            "gain": {53.0: 0.106},
        },
    ),
    "4a": (
        0.05,
        (1.80, 2.67, 1),
        (42.0,),
        {"mean_rn": 43.83, "mean_ra": {42.0: 44.30}, "p_rn": {42.0: 0.058}, "p_ra": {42.0: 0.172}},
    ),
    "4b": (
        0.15,
        (1.80, 2.01, 1),
        (43.5,),
        {"mean_rn": 43.93, "mean_ra": {43.5: 43.97}, "p_rn": {43.5: 0.088}, "p_ra": {43.5: 0.266}},
    ),
}


def so40() -> Polar:
    """Sun Odyssey 40, TWS 8 kn column, scaled to ``f_max = 0.05`` (nondimensional)."""
    return Polar.from_arrays(
        np.array(SO40_TWA, float),
        np.array([1.0]),
        (np.array(SO40_KN) * F_MAX / 6.5)[:, None],
        name="SO40",
        interpolation="linear",
    )


def paper_grid(
    n_r_nodes: int, n_theta: int, s_max: float, interp: str, refine: str, ds_cells: float = 1.0
) -> DeadlineGrid:
    """The paper's domain; ``Δs = C/n``, the largest with ``f_max Δs <= ds_cells Δr``."""
    n_r = n_r_nodes - 1
    dr = 2.0 / n_r
    n = max(1, math.ceil(C * F_MAX / (ds_cells * dr) - 1e-9))
    ds = C / n
    s_max = ds * math.ceil(s_max / ds - 1e-9)
    return DeadlineGrid(
        2.0, n_r, n_theta, 0.1, ds, s_max, interpolation=interp, refine_controls=refine
    )


def uptime() -> str:
    try:
        res = subprocess.run(["uptime"], capture_output=True, text=True, check=False)
        return res.stdout.strip()
    except OSError:  # pragma: no cover
        return "uptime unavailable"


def check_dtype(name: str, args: argparse.Namespace) -> dict:
    """Solve one figure in float32 and float64: times and the largest change of ``w``."""
    a, start, deadlines, _ = FIGS[name]
    n_r1, n_t = (int(v) for v in args.grid.split(","))
    s_max = args.s_max if args.s_max else 1.05 * max(deadlines)
    g = paper_grid(n_r1, n_t, s_max, args.interp, args.refine, args.ds_cells)
    m = DriftDiffusionShift(-math.degrees(a), math.degrees(SIGMA))
    ra32 = solve_deadline(so40(), 1.0, m, g, C, dtype="float32")
    ra64 = solve_deadline(so40(), 1.0, m, g, C, dtype="float64")
    dw = np.abs(ra64.w - ra32.w)
    c32, c64 = ra32.success_curve(*start), ra64.success_curve(*start)
    same = float(np.mean(ra32.steer == ra64.steer))
    out = {
        "fig": name,
        "grid": [g.n_r + 1, g.n_theta],
        "t32": ra32.solve_time_s,
        "t64": ra64.solve_time_s,
        "max_dw": float(dw.max()),
        "max_dw_start": float(np.max(np.abs(c64 - c32))),
        "same_steer": same,
        "same_switch": float(np.mean(ra32.switch == ra64.switch)),
    }
    print(
        f"Fig {name} {g.n_r + 1} x {g.n_theta}: float32 {ra32.solve_time_s:.1f} s, float64 "
        f"{ra64.solve_time_s:.1f} s; max |Δw| {out['max_dw']:.2e} (at the start "
        f"{out['max_dw_start']:.2e}); same steering {100 * same:.2f} %, same switch "
        f"{100 * out['same_switch']:.3f} % of node-slices; {uptime()}",
        flush=True,
    )
    return out


def run_fig(name: str, args: argparse.Namespace) -> dict:
    a, start, deadlines, paper = FIGS[name]
    n_r1, n_t = (int(v) for v in args.grid.split(","))
    s_max = args.s_max if args.s_max else 1.05 * max(deadlines)
    g = paper_grid(n_r1, n_t, s_max, args.interp, args.refine, args.ds_cells)
    m = DriftDiffusionShift(-math.degrees(a), math.degrees(SIGMA))
    polar = so40()
    print(
        f"Fig {name}: grid {g.n_r + 1} x {g.n_theta} x 2, Δs {g.ds_s:g} ({g.n_s} slices), "
        f"{g.interpolation}, refine {g.refine_controls}; {uptime()}",
        flush=True,
    )
    ra = solve_deadline(polar, 1.0, m, g, C, dtype=args.dtype, engine=args.engine)
    out: dict = {
        "fig": name,
        "grid": [g.n_r + 1, g.n_theta],
        "ds": g.ds_s,
        "n_s": g.n_s,
        "interpolation": g.interpolation,
        "refine": g.refine_controls,
        "dtype": args.dtype,
        "engine": args.engine,
        "solve_s": ra.solve_time_s,
        "rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6,
    }
    print(
        f"  risk-aware solve ({args.engine}) {ra.solve_time_s:.1f} s "
        f"({1e3 * ra.solve_time_s / g.n_s:.1f} ms/slice), peak RSS {out['rss_gb']:.1f} GB",
        flush=True,
    )
    if args.solve_only:
        return out
    rn = solve_risk_neutral(polar, 1.0, m, g, C, tol_s=1e-3)
    out["rn_solve_s"] = rn.solve_time_s
    out["rn_sweeps"] = rn.iterations
    print(f"  risk-neutral solve {rn.solve_time_s:.1f} s ({rn.iterations} sweeps)", flush=True)
    t0 = time.perf_counter()
    sim_rn = simulate_deadline(rn, args.runs, args.seed, start, dt_s=args.dt)
    t_rn = sim_rn.leg_time_s
    curve = ra.success_curve(*start)
    rows = []
    out["mean_rn"] = float(np.mean(t_rn))
    out["value_rn"] = rn.expected_time(*start)
    rows.append(("E[T] μ*", paper["mean_rn"], out["mean_rn"], "abs"))
    out["p_rn"], out["p_ra"], out["mean_ra"], out["w"] = {}, {}, {}, {}
    out["switches"] = {"rn": np.bincount(sim_rn.n_switches).tolist()}
    for d in deadlines:
        sim = simulate_deadline(rn, args.runs, args.seed, start, ra=ra, deadline_s=d, dt_s=args.dt)
        t = sim.leg_time_s
        p_rn, p_ra = float(np.mean(t_rn <= d)), float(np.mean(t <= d))
        out["p_rn"][d], out["p_ra"][d] = p_rn, p_ra
        out["mean_ra"][d] = float(np.mean(t))
        out["w"][d] = float(curve[round(d / g.ds_s)])
        out["switches"][f"ra{d:g}"] = np.bincount(sim.n_switches).tolist()
        rows.append((f"P(T<={d:g}) μ*", paper["p_rn"].get(d), p_rn, "pp"))
        rows.append((f"P(T<={d:g}) α^{d:g}", paper["p_ra"].get(d), p_ra, "pp"))
        rows.append((f"E[T] α^{d:g}", paper["mean_ra"][d], out["mean_ra"][d], "abs"))
        rows.append(
            (
                f"E[T] α^{d:g} / E[T] μ* - 1",
                paper["mean_ra"][d] / paper["mean_rn"] - 1,
                out["mean_ra"][d] / out["mean_rn"] - 1,
                "pct",
            )
        )
        rows.append(
            (
                f"P α^{d:g} / P μ*",
                (paper["p_ra"][d] / paper["p_rn"][d]) if d in paper["p_rn"] else None,
                p_ra / max(p_rn, 1e-12),
                "ratio",
            )
        )
        gain = paper.get("gain", {}).get(d)
        if d in paper["p_rn"]:
            gain = paper["p_ra"][d] - paper["p_rn"][d]
        rows.append((f"P α^{d:g} - P μ*", gain, p_ra - p_rn, "pp"))
    out["mc_s"] = time.perf_counter() - t0
    out["rows"] = []
    for label, ref, val, kind in rows:
        if kind in ("pp", "pct"):
            txt = f"{100 * val:6.1f} %"
            ref_txt = "     –" if ref is None else f"{100 * ref:6.1f} %"
            diff = None if ref is None else 100 * (val - ref)
            within = kind == "pp" and diff is not None and abs(diff) <= 1.0
            diff_txt = (
                "" if diff is None else (f"{diff:+5.1f} pp {'(within 1 pp)' if within else ''}")
            )
        else:
            txt = f"{val:8.2f}"
            ref_txt = "       –" if ref is None else f"{ref:8.2f}"
            diff = None if ref is None else val - ref
            diff_txt = "" if diff is None else f"{diff:+6.2f}"
        out["rows"].append({"quantity": label, "paper": ref, "ours": val, "diff": diff})
        print(f"  {label:28s} paper {ref_txt}  ours {txt}  {diff_txt}")
    se = math.sqrt(0.25 / args.runs)
    print(
        f"  Monte Carlo {args.runs} runs/policy (SE <= {100 * se:.2f} pp), Δt {args.dt:g}: "
        f"{out['mc_s']:.1f} s; w(start) "
        + ", ".join(f"{d:g}: {v:.3f}" for d, v in out["w"].items()),
        flush=True,
    )
    return out


def run_baseline(fig: str, engine: str, args: argparse.Namespace) -> dict:
    """The same solve with the code in ``args.baseline`` (its own bench script, a fresh
    process: the solve and its peak memory)."""
    base = Path(args.baseline).resolve()
    flags = [
        "--grid",
        args.grid,
        "--figs",
        fig,
        "--engine",
        engine,
        "--interp",
        args.interp,
        "--refine",
        args.refine,
        "--ds-cells",
        str(args.ds_cells),
        "--dtype",
        args.dtype,
        "--solve-only",
    ]
    if args.s_max:
        flags += ["--s-max", str(args.s_max)]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "base.json"
        env = {**os.environ, "PYTHONPATH": str(base)}
        subprocess.run(
            [
                sys.executable,
                str(base / "benchmarks" / "bench_deadline.py"),
                *flags,
                "--json",
                str(out),
            ],
            env=env,
            check=True,
            capture_output=True,
        )
        result = json.loads(out.read_text(encoding="utf-8"))["results"][0]
    print(
        f"  baseline {base.name}: risk-aware solve ({engine}) {result['solve_s']:.1f} s, "
        f"peak RSS {result['rss_gb']:.1f} GB",
        flush=True,
    )
    return {**result, "baseline": str(base)}


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--grid", default="201,256", help="nodes in r, intervals in θ")
    ap.add_argument("--interp", default="linear", choices=("linear", "cubic"))
    ap.add_argument(
        "--refine", default="none", choices=("none", "golden"), help="steering-angle refinement"
    )
    ap.add_argument(
        "--ds-cells",
        type=float,
        default=1.0,
        help="budget step in radial cells at top speed (paper: 1)",
    )
    ap.add_argument("--dtype", default="float32", choices=("float32", "float64"))
    ap.add_argument(
        "--engine",
        default="auto",
        help="risk-aware solver kernels, auto, numpy or numba (the extra "
        "sailroute[fast]); a comma list runs every figure with each in turn",
    )
    ap.add_argument("--figs", default="3,4a,4b")
    ap.add_argument("--runs", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--dt", type=float, default=0.005, help="Euler–Maruyama step")
    ap.add_argument("--s-max", type=float, default=None, help="budget solved for (timing)")
    ap.add_argument("--solve-only", action="store_true")
    ap.add_argument(
        "--check-dtype",
        action="store_true",
        help="solve in float32 and float64 and compare w (no Monte Carlo)",
    )
    ap.add_argument("--json", default=None, help="write the results here")
    ap.add_argument(
        "--baseline",
        default=None,
        help="a checkout of older code: each solve is repeated there with its "
        "own copy of this script (same flags, --solve-only), alternating",
    )
    ap.add_argument("--repeat", type=int, default=1, help="rounds of solves (with --baseline)")
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="Fig 3 on a 21 x 32 grid with 200 runs (checks the script runs)",
    )
    args = ap.parse_args()
    if args.smoke:
        args.grid, args.figs, args.runs, args.dt = "21,32", "3", 200, 0.05
    print(uptime())
    run = check_dtype if args.check_dtype else run_fig
    results = []
    for _ in range(args.repeat):
        for f in args.figs.split(","):
            for engine in args.engine.split(","):
                results.append(
                    run(f.strip(), argparse.Namespace(**{**vars(args), "engine": engine.strip()}))
                )
                if args.baseline:
                    results.append(run_baseline(f.strip(), engine.strip(), args))
                    print(
                        f"  baseline / this code: "
                        f"{results[-1]['solve_s'] / results[-2]['solve_s']:.2f}x",
                        flush=True,
                    )
    print(uptime())
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"args": vars(args), "results": results}, fh, indent=1, default=str)


if __name__ == "__main__":
    main()
