"""GPU (CuPy) against the CPU engines, in one run on one machine.

    python benchmarks/bench_gpu.py [--repeat 3] [--skip iso,dp,deadline] [--deadline-grids
                                    401,512:4b 801,1024:3] [--json out.json] [--smoke]

Three sections, each case run on the CPU engine and on CuPy in turn, after one warm-up run
of each (which compiles the kernels and fills the caches); times are the best wall time of
``--repeat`` runs, and the ratio is CPU / GPU (above 1: the GPU is faster):

* isochrone router (NumPy, one thread): the three legs of ``bench_isochrone.py`` (uniform
  wind, the synthetic WRF file, a gridded field) at the default settings, and the uniform
  leg with 4x the headings and 10x finer pruning sectors (larger fronts);
* grid DP (NumPy, one thread): Dębski's (2016) case, R = 13 rows, one pass, C = 32, 64,
  128, dynamic boat and its polar (``bench_griddp.py``'s table);
* deadline solver: Wang et al.'s (2024) figures (``bench_deadline.py``), risk-aware solve
  only, numba (one thread; NumPy where numba is missing) against CuPy; NumPy too on grids
  up to 401 x 512.  The GPU policy must be the CPU's bit for bit (``w`` and the actions
  of every band).

Prints the device, the CPU, and per case both times, the ratio and the largest difference
of the results.  BLAS and OpenMP threads are pinned to one before NumPy is imported.  Needs
CuPy and an NVIDIA GPU (``pip install -e '.[gpu]'``); without them it says so and exits
with code 0 (nothing to measure).  ``--smoke``: the isochrone section once.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import traceback  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_deadline as bd  # noqa: E402
import bench_isochrone as bi  # noqa: E402

from sailroute.backend import get_xp  # noqa: E402
from sailroute.boat.dynamic import DynamicBoat  # noqa: E402
from sailroute.errors import InputError  # noqa: E402
from sailroute.routing import isochrone  # noqa: E402
from sailroute.routing.griddp import solve_griddp  # noqa: E402
from sailroute.routing.settings import RoutingSettings, routing_settings  # noqa: E402
from sailroute.routing.types import Start, Target  # noqa: E402
from sailroute.strategy import _deadline_jit as _jit  # noqa: E402
from sailroute.strategy.deadline import solve_deadline  # noqa: E402
from sailroute.strategy.shiftmodel import DriftDiffusionShift  # noqa: E402
from sailroute.units import KNOT  # noqa: E402
from sailroute.wind.uniform import UniformWind  # noqa: E402


def cpu_name() -> str:
    """The CPU's model name (``/proc/cpuinfo``), else what ``platform`` says."""
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def best_of(fn: Callable[[], Any], repeat: int, sync: Callable[[], None]) -> tuple[float, Any]:
    """Warm-up run, then the best wall time [s] of ``repeat`` runs, and the last result."""
    out = fn()
    sync()
    best = math.inf
    for _ in range(repeat):
        tic = time.perf_counter()
        out = fn()
        sync()
        best = min(best, time.perf_counter() - tic)
    return best, out


def row(name: str, cpu: float, gpu: float, diff: str) -> dict:
    print(f"  {name:<46}{cpu:>10.3f}{gpu:>10.3f}{cpu / gpu:>8.2f}x  {diff}", flush=True)
    return {"case": name, "cpu_s": cpu, "gpu_s": gpu, "ratio": cpu / gpu, "diff": diff}


def header(title: str, cpu: str) -> None:
    print(
        f"\n## {title}\n  {'case':<46}{cpu:>10}{'CuPy s':>10}{'ratio':>9}  difference", flush=True
    )


def iso_section(cp: Any, repeat: int) -> list[dict]:
    header("Isochrone router, best wall time per leg", "NumPy s")
    polar = bi.load_polar()
    t0 = 1524567600.0
    cases: list[tuple[str, Any, float, RoutingSettings]] = [
        ("uniform 8.5 kn, 1809 m beat", UniformWind(8.5 * KNOT, 0.0), t0, RoutingSettings()),
    ]
    wrf = bi.wrf_field()
    if wrf is not None:
        c = wrf.coverage
        cases.append(
            ("synthetic WRF, 1809 m beat", wrf, c.t0 + 0.25 * (c.t1 - c.t0), RoutingSettings())
        )
    cases.append(
        ("gridded field, 1809 m beat", bi.gridded_field(t0), t0 + 600.0, RoutingSettings())
    )
    st0 = RoutingSettings()
    cases.append(
        (
            "uniform, headings/4, sectors/10 (big fronts)",
            UniformWind(8.5 * KNOT, 0.0),
            t0,
            routing_settings(
                heading_step_deg=st0.isochrone.heading_step_deg / 4,
                prune_sector_deg=st0.isochrone.prune_sector_deg / 10,
            ),
        )
    )
    out = []
    sync = cp.cuda.Device().synchronize
    for name, wind, t, st in cases:
        start, target = bi.beat(wind, t)

        def run(xp: Any, start=start, target=target, t=t, wind=wind, st=st) -> Any:
            return isochrone.route_isochrone(start, target, t, wind, polar, st, xp=xp)

        cpu, a = best_of(lambda run=run: run(np), repeat, lambda: None)
        gpu, b = best_of(lambda run=run: run(cp), repeat, sync)
        dxy = np.concatenate([a.track.x - b.track.x, a.track.y - b.track.y])
        diff = (
            f"leg {a.time_s:.3f} s, Δ {b.time_s - a.time_s:+.1e} s; track Δ "
            f"{np.max(np.abs(dxy)):.1e} m"
        )
        out.append(row(name, cpu, gpu, diff))
    return out


def dp_section(cp: Any, repeat: int) -> list[dict]:
    header("Grid DP, Dębski's case, R = 13, one pass, best wall time", "NumPy s")
    boat = DynamicBoat()
    polar = boat.steady_polar(np.arange(0.0, 61.0, 2.0), twa_step=1.0)
    wind, tgt = UniformWind(12.0, 5.0), Target("mark", (0.0, 500.0))
    sync = cp.cuda.Device().synchronize
    out = []
    for model_name, b in (("dynamic", boat), ("polar", polar)):
        for c in (32, 64, 128):
            s = routing_settings(
                router="griddp",
                dp_cols=c,
                dp_rows=13,
                dp_refinements=0,
                dp_half_width_m=400.0,
                tack_penalty_s=0.0,
                gybe_penalty_s=0.0,
                zone_m=0.01,
            )
            rep = repeat if c < 128 else 1

            def run(xp: Any, s: RoutingSettings = s, b: Any = b) -> Any:
                return solve_griddp(Start((0.0, 0.0)), tgt, 0.0, wind, b, s, xp=xp).result

            cpu, ra = best_of(lambda run=run: run(np), rep, lambda: None)
            gpu, rb = best_of(lambda run=run: run(cp), rep, sync)
            out.append(
                row(
                    f"{model_name}, C = {c}",
                    cpu,
                    gpu,
                    f"route {ra.time_s:.3f} s, Δ {rb.time_s - ra.time_s:+.1e} s",
                )
            )
    return out


def deadline_section(cp: Any, grids: list[str]) -> list[dict]:
    cpu = "numba" if _jit.AVAILABLE else "numpy"
    header("Deadline solver (risk-aware, bilinear, float32), solve time", f"{cpu} s")
    out = []
    pool = cp.get_default_memory_pool()
    for e in (cpu, "cupy", "numpy"):  # compile the kernels (numba caches them on disk)
        tiny = bd.paper_grid(41, 64, 5.0, "linear", "none")
        solve_deadline(bd.so40(), 1.0, DriftDiffusionShift(0.0, 3.0), tiny, bd.C, engine=e)
    for spec in grids:
        gpu_only = spec.endswith("!")
        shape, fig = spec.rstrip("!").split(":")
        n_r1, n_t = (int(v) for v in shape.split(","))
        a, _, deadlines, _ = bd.FIGS[fig]
        g = bd.paper_grid(n_r1, n_t, 1.05 * max(deadlines), "linear", "none")
        m = DriftDiffusionShift(-math.degrees(a), math.degrees(bd.SIGMA))
        polar = bd.so40()
        engines = (
            ["cupy"]
            if gpu_only
            else [cpu, "cupy"] + (["numpy"] if cpu != "numpy" and n_r1 * n_t <= 401 * 512 else [])
        )
        pols = {}
        for e in engines:
            pool.free_all_blocks()
            pols[e] = solve_deadline(polar, 1.0, m, g, bd.C, engine=e)
            print(
                f"  Fig {fig} {n_r1} x {n_t} ({g.n_s} slices), {e}: "
                f"{pols[e].solve_time_s:.2f} s"
                + (f", GPU pool {pool.total_bytes() / 1e9:.1f} GB" if e == "cupy" else ""),
                flush=True,
            )
        if gpu_only:
            out.append(
                {
                    "case": f"Fig {fig}, {n_r1} x {n_t}",
                    "gpu_s": pols["cupy"].solve_time_s,
                    "gpu_pool_gb": pool.total_bytes() / 1e9,
                }
            )
            continue
        ref, dev = pols[cpu], pols["cupy"]
        same = np.array_equal(ref.bands.w, dev.bands.w) and np.array_equal(
            ref.bands.action, dev.bands.action
        )
        dw = float(np.max(np.abs(ref.bands.w.astype(float) - dev.bands.w)))
        out.append(
            row(
                f"Fig {fig}, {n_r1} x {n_t}, {g.n_s} slices",
                ref.solve_time_s,
                dev.solve_time_s,
                f"bit for bit: {same} (max |Δw| {dw:.1e})",
            )
        )
        if "numpy" in pols:
            t_np = pols["numpy"].solve_time_s
            print(f"  (NumPy {t_np:.2f} s: {t_np / dev.solve_time_s:.1f}x the CuPy time)")
        del pols, ref, dev
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--skip", default="", help="comma list of iso, dp, deadline")
    ap.add_argument(
        "--deadline-grids",
        nargs="*",
        default=["401,512:4b", "801,1024:3"],
        help="NR1,NT:FIG, solved with numba and CuPy (a trailing ! : CuPy only)",
    )
    ap.add_argument("--json", default=None)
    ap.add_argument(
        "--smoke", action="store_true", help="the isochrone section once (checks the script runs)"
    )
    args = ap.parse_args()
    if args.smoke:
        args.repeat, args.skip = 1, "dp,deadline"
    try:
        cp = get_xp("cupy")
    except InputError as exc:
        print(f"bench_gpu.py: no GPU here, nothing measured: {exc}")
        sys.exit(0)
    dev = cp.cuda.runtime.getDeviceProperties(cp.cuda.Device().id)
    print(
        f"GPU {dev['name'].decode()}, {dev['totalGlobalMem'] / 2**30:.0f} GiB; CPU "
        f"{cpu_name()}, {os.cpu_count()} cores (one used); "
        f"numpy {np.__version__}, cupy {cp.__version__}",
        flush=True,
    )
    skip = set(args.skip.split(","))
    results: dict[str, list[dict]] = {}
    for key, fn in (
        ("iso", lambda: iso_section(cp, args.repeat)),
        ("dp", lambda: dp_section(cp, args.repeat)),
        ("deadline", lambda: deadline_section(cp, args.deadline_grids)),
    ):
        if key in skip:
            continue
        try:
            results[key] = fn()
        except Exception:  # report and go on: the first GPU run is a test
            traceback.print_exc()
            results[key] = [{"error": traceback.format_exc()}]
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
