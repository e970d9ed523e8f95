"""Benchmark: route a 1.8 km beat with the isochrone router on one core, NumPy against compiled.

    python benchmarks/bench_isochrone.py [--repeat 7] [--dt 5] [--heading-step 2]
                                         [--sector 0.5] [--penalty 0] [--engines numpy,numba]
                                         [--smoke]

Cases (Laser/ILCA 7 polar from ``sailroute/boat/data/ilca7.pol`` when present, else a
synthetic Laser-like table):

* uniform wind, 8.5 kn from 0°, start (0, 0), windward mark 1809 m north (the
  thesis's validation beat, the thesis's §5.7);
* the synthetic Hyères wrfout in ``data/`` (bilinear + linear in time, height-corrected
  to 2.68 m), the mark 1809 m upwind of the start in the local wind at the start time;
* a gridded analytic field (500 m cells, 10-min slices, shifts and pressure bands)
  sampled bilinearly by :class:`~sailroute.wind.grid.GridWind`, same geometry.

Each case is routed by every engine of ``--engines`` (``routing.engine``: ``numpy``, the
NumPy step; ``numba``, the compiled step of ``sailroute/routing/isochrone_jit.py``,
when numba is installed), which must give the same route bit for bit.  Prints the
command and the load average, then per case and engine the best and median wall and
CPU time per leg over ``--repeat`` runs, the engines taking turns (after one warm-up
run of each, which also builds the cached polar tables and loads or compiles the
kernels), the number of steps, the mean and largest front size, the candidates tried
per step, the CPU time of a step split into a fixed part and a part per front point
(least squares over the steps of one run), the leg time, and the ratio of the engines'
best CPU and wall times.  The machine's load matters: compare numbers taken on the same
machine, in one run.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.backend import get_xp, xp_name  # noqa: E402
from sailroute.boat.polar import Polar  # noqa: E402
from sailroute.routing import isochrone  # noqa: E402
from sailroute.routing import isochrone_fast as fast  # noqa: E402
from sailroute.routing.settings import RoutingSettings, routing_settings  # noqa: E402
from sailroute.routing.types import Start, Target  # noqa: E402
from sailroute.units import KNOT, wind_components, wind_speed_direction  # noqa: E402
from sailroute.wind.uniform import UniformWind  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
POLAR_FILE = ROOT / "sailroute" / "boat" / "data" / "ilca7.pol"
WRF = ROOT / "data" / "hyeres-2018-04-24-synthetic-wrfout.nc"
LEG_M = 1809.0


def load_polar() -> Polar:
    try:
        from sailroute.boat.io import read_polar

        return read_polar(POLAR_FILE)
    except Exception:  # boat I/O not available: a smooth Laser-like table
        twa = np.array([0, 30, 40, 45, 50, 60, 75, 90, 105, 120, 135, 150, 165, 180.0])
        g = np.array(
            [0, 0.45, 0.68, 0.74, 0.79, 0.85, 0.92, 0.97, 1.0, 0.97, 0.9, 0.82, 0.66, 0.55]
        )
        tws = np.array([1, 2, 3, 4, 5, 6, 7, 8, 10, 12.0])
        return Polar.from_arrays(
            twa, tws, np.outer(g, 3.4 * (1 - np.exp(-tws / 3.5))), name="laser-like"
        )


def wrf_field():
    try:
        from sailroute.geo import LocalFrame
        from sailroute.wind.wrf import open_wrf
    except ImportError:
        return None
    path = WRF
    if not path.is_file():
        try:
            sys.path.insert(0, str(ROOT / "data"))
            import make_synthetic_wrf  # type: ignore[import-not-found]

            path = make_synthetic_wrf.main(Path(tempfile.mkdtemp()) / WRF.name)
        except Exception:
            return None
    return open_wrf(path, LocalFrame(43.069067, 6.198550), height_m=2.68)


def gridded_field(t0: float):
    from sailroute.wind.grid import GridWind

    xs = np.arange(-4000.0, 4001.0, 500.0)
    X, Y = np.meshgrid(xs, xs)
    times = t0 + np.arange(0.0, 4 * 3600.0 + 1, 600.0)
    T = times[:, None, None]
    twd = 10.0 * np.sin(X / 1500.0) + 6.0 * np.sin(2 * np.pi * T / 1800.0)
    tws = 8.5 * KNOT * (1.0 + 0.15 * np.cos(Y / 1200.0 + X / 2500.0))
    u, v = wind_components(tws + 0 * T, twd)
    return GridWind(times, X, Y, u, v, name="gridded analytic")


def beat(wind, t0: float) -> tuple[Start, Target]:
    u, v = wind.sample(t0, 0.0, 0.0)
    _, twd = wind_speed_direction(u, v)
    th = math.radians(float(twd))
    return Start((0.0, 0.0), name="start"), Target(
        "mark", (LEG_M * math.sin(th), LEG_M * math.cos(th)), rounding="port", name="1"
    )


def step_profile(start, target, t0, wind, polar, st, xp=np):
    """The leg, with the front size and the CPU time of each of its steps."""
    sizes: list[int] = []
    step_s: list[float] = []
    orig = isochrone._step

    def counting(f, *a, **k):  # front size and CPU time per step
        sizes.append(int(f.x.shape[0]))
        c0 = time.process_time()
        out = orig(f, *a, **k)
        step_s.append(time.process_time() - c0)
        return out

    isochrone._step = counting
    try:
        res = isochrone.route_isochrone(start, target, t0, wind, polar, st, xp=xp)
    finally:
        isochrone._step = orig
    return res, np.asarray(sizes, dtype=float), np.asarray(step_s)


def with_engine(st: RoutingSettings, engine: str) -> RoutingSettings:
    return dataclasses.replace(st, isochrone=dataclasses.replace(st.isochrone, engine=engine))


def run_case(name, wind, t0, polar, st, repeat, engines, xp=np):
    start, target = beat(wind, t0)
    runs = {e: with_engine(st, e) for e in engines}
    results = {}
    for e, se in runs.items():  # warm-up: polar tables, kernels loaded or compiled
        results[e] = isochrone.route_isochrone(start, target, t0, wind, polar, se, xp=xp)
    first = results[engines[0]]
    same = all(
        r.time_s == first.time_s and np.array_equal(r.track.x, first.track.x)
        for r in results.values()
    )
    walls = {e: [] for e in engines}
    cpus = {e: [] for e in engines}
    for _ in range(repeat):  # the engines take turns
        for e, se in runs.items():
            w0, c0 = time.perf_counter(), time.process_time()
            isochrone.route_isochrone(start, target, t0, wind, polar, se, xp=xp)
            walls[e].append(time.perf_counter() - w0)
            cpus[e].append(time.process_time() - c0)
    tab = isochrone.polar_tables(polar, st.isochrone.heading_step_deg)
    u, v = wind.sample(t0, 0.0, 0.0)
    tws = float(np.hypot(u, v))
    a_up = float(np.interp(tws, tab.tws_ms, tab.up_deg))
    a_dn = float(np.interp(tws, tab.tws_ms, tab.down_deg))
    hull = int(np.count_nonzero((tab.twa_deg > a_up) & (tab.twa_deg < a_dn)))
    print(f"{name}")
    for e, se in runs.items():
        _, sizes, step_s = step_profile(start, target, t0, wind, polar, se, xp)
        # CPU time of a step = fixed + per point x front size (least squares over the steps)
        per_point, fixed = np.polyfit(sizes, step_s, 1)
        print(
            f"  {e:<6} wall {1e3 * min(walls[e]):7.1f} ms best, "
            f"{1e3 * statistics.median(walls[e]):7.1f} ms median; cpu "
            f"{1e3 * min(cpus[e]):7.1f} ms best ({repeat} runs); per step {1e6 * fixed:.0f} us "
            f"fixed + {1e6 * per_point:.2f} us per front point"
        )
    if len(engines) == 2:
        a, b = engines
        print(
            f"  ratio {a} / {b}: {min(cpus[a]) / min(cpus[b]):.2f}x CPU, "
            f"{min(walls[a]) / min(walls[b]):.2f}x wall (best of each); the same route "
            f"bit for bit: {'yes' if same else 'NO'}"
        )
    print(
        f"  {sizes.size} steps, front {sizes.mean():.0f} points mean / {sizes.max():.0f} max, "
        f"{hull + 3} + 3 candidates per point (grid TWAs between the VMG angles "
        f"{a_up:.1f}-{a_dn:.1f} deg + 3 exact; 3 after a side change)"
    )
    res = first
    print(
        f"  leg time {res.time_s:.1f} s, {res.n_tacks} tacks, {res.n_gybes} gybes, "
        f"sailed {res.distance_m:.0f} m, start -> end ({res.end_xy[0]:.0f}, "
        f"{res.end_xy[1]:.0f}) m"
    )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--dt", type=float, default=None, help="dt_s (default: RoutingSettings)")
    ap.add_argument("--heading-step", type=float, default=None)
    ap.add_argument("--sector", type=float, default=None)
    ap.add_argument(
        "--penalty",
        type=float,
        default=None,
        help="tack and gybe penalty [s] (default: RoutingSettings)",
    )
    ap.add_argument("--backend", default="numpy", help="numpy | cupy | auto (array backend)")
    ap.add_argument(
        "--engines",
        default="numpy,numba",
        help="routing.engine values to compare (numba: only where it is installed)",
    )
    ap.add_argument(
        "--smoke", action="store_true", help="the uniform-wind leg once (checks the script runs)"
    )
    args = ap.parse_args()
    if args.smoke:
        args.repeat = 1
    xp = get_xp(args.backend)
    kw = {
        k: v
        for k, v in (
            ("dt_s", args.dt),
            ("heading_step_deg", args.heading_step),
            ("prune_sector_deg", args.sector),
            ("tack_penalty_s", args.penalty),
            ("gybe_penalty_s", args.penalty),
        )
        if v is not None
    }
    st = routing_settings(**kw)
    engines = [e for e in args.engines.split(",") if e != "numba" or fast.AVAILABLE]
    polar = load_polar()
    print(
        f"command: python {' '.join(sys.argv)}; load average (1, 5, 15 min): "
        f"{', '.join(f'{x:.2f}' for x in os.getloadavg())}"
    )
    print(
        f"isochrone router, one thread, numpy {np.__version__}; polar {polar.name!r}; "
        f"dt {st.isochrone.dt_s:g} s, heading step {st.isochrone.heading_step_deg:g} deg, sectors "
        f"{st.isochrone.prune_sector_deg:g} deg, tack {st.tack_penalty_s:g} s, gybe "
        f"{st.gybe_penalty_s:g} s; backend {xp_name(xp)}"
    )
    t0 = 1524567600.0  # 2018-04-24T11:00Z, inside the synthetic WRF file
    run_case(
        "uniform 8.5 kn from 0 deg, 1809 m beat",
        UniformWind(8.5 * KNOT, 0.0),
        t0,
        polar,
        st,
        args.repeat,
        engines,
        xp,
    )
    if args.smoke:
        return
    wrf = wrf_field()
    if wrf is not None:
        c = wrf.coverage
        t_w = c.t0 + 0.25 * (c.t1 - c.t0)
        run_case(
            f"WRF {wrf.name} (grid {wrf.shape}), 1809 m beat",
            wrf,
            t_w,
            polar,
            st,
            args.repeat,
            engines,
            xp,
        )
    else:
        print("WRF reader not available: WRF case skipped")
    run_case(
        "gridded analytic field (17 x 17 cells, 10-min slices), 1809 m beat",
        gridded_field(t0),
        t0 + 600.0,
        polar,
        st,
        args.repeat,
        engines,
        xp,
    )


if __name__ == "__main__":
    main()
