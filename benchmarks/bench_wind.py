"""Benchmark: sample 1e6 random (t, x, y) points from wind fields on one core.

    python benchmarks/bench_wind.py [--n 1000000] [--repeat 5] [--smoke]

Uses the synthetic Hyères wrfout in data/ (25 x 25 cells, 37 slices; regenerated in a
temporary folder if missing) with a height correction to 2.68 m, and prints the best of
``--repeat`` runs in ms and Mpoints/s for bilinear + linear-in-time, nearest, frozen
10-min blocks, plus station IDW (3 stations) and the blended field for comparison.  The
last line samples a *real* wrfout (the wrf-python CI crop in tests/data/wind: WRF 3.8.1,
Mercator, 16 x 24 cells, 4 slices, model-level height correction) over its whole coverage.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.geo import LocalFrame  # noqa: E402
from sailroute.wind.blended import BlendedWind  # noqa: E402
from sailroute.wind.stations import StationData, StationWind  # noqa: E402
from sailroute.wind.wrf import open_wrf  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
WRF = ROOT / "data" / "hyeres-2018-04-24-synthetic-wrfout.nc"
REAL_WRF = ROOT / "tests" / "data" / "wind" / "wrfpython_ci_crop.nc"
FRAME = LocalFrame(43.069067, 6.198550)


def wrf_path() -> Path:
    if WRF.is_file():
        return WRF
    sys.path.insert(0, str(ROOT / "data"))
    import make_synthetic_wrf  # type: ignore[import-not-found]

    return make_synthetic_wrf.main(Path(tempfile.mkdtemp()) / WRF.name)


def stations(t0: float, t1: float) -> StationData:
    t = np.arange(t0, t1 + 1, 60.0)
    xy = [(-3000.0, -2000.0), (2500.0, 0.0), (0.0, 3000.0)]
    rec = []
    for k, (x, y) in enumerate(xy):
        la, lo = FRAME.to_latlon(x, y)
        for j, tt in enumerate(t):
            rec.append(
                (
                    f"S{k}",
                    tt,
                    float(la),
                    float(lo),
                    4.0 + 0.5 * np.sin(j / 7 + k),
                    140.0 + 5 * np.cos(j / 11 + k),
                )
            )
    a = list(zip(*rec, strict=True))
    n = len(rec)
    return StationData(
        np.array(a[0]),
        np.array(a[1]),
        np.array(a[2]),
        np.array(a[3]),
        np.array(a[4]),
        np.array(a[5]),
        np.full(n, np.nan),
        np.full(n, np.nan),
    )


def best_ms(fn, repeat: int) -> float:
    fn()  # warm-up
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return 1e3 * min(times)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument(
        "--smoke", action="store_true", help="1000 points, one repetition (checks the script runs)"
    )
    args = ap.parse_args()
    if args.smoke:
        args.n, args.repeat = 1000, 1
    path = wrf_path()
    fields = {
        "wrf bilinear + linear time": open_wrf(path, FRAME, height_m=2.68),
        "wrf nearest + linear time": open_wrf(path, FRAME, height_m=2.68, interpolation="nearest"),
        "wrf bilinear, frozen 10 min": open_wrf(path, FRAME, height_m=2.68, time_step_min=10),
    }
    base = fields["wrf bilinear + linear time"]
    c = base.coverage
    st = stations(c.t0, c.t1)
    fields["stations idw (3 stations)"] = StationWind(st, FRAME, radius_m=20000.0)
    fields["blended (wrf + 3 stations)"] = BlendedWind(base, st, FRAME)
    rng = np.random.default_rng(0)
    n = args.n
    t = rng.uniform(c.t0, c.t1, n)
    x = rng.uniform(-3000.0, 3000.0, n)
    y = rng.uniform(-3000.0, 3000.0, n)
    info = base.info
    print(
        f"WRF field: {Path(info['path']).name}, grid {base.shape} (nt, ny, nx), "
        f"levels={info['levels']}, height {info['height_m']} m, map degree "
        f"{info['map_degree']} (misfit {info['map_residual_cells']:.1e} cells)"
    )
    print(f"{n:,} random points, best of {args.repeat}, one thread (numpy {np.__version__})")
    for name, f in fields.items():
        ms = best_ms(lambda f=f: f.sample(t, x, y), args.repeat)
        print(f"  {name:30s} {ms:8.1f} ms  {n / ms / 1e3:6.2f} Mpoints/s")
    if REAL_WRF.is_file():
        real = open_wrf(REAL_WRF, LocalFrame(22.9, -91.8), height_m=2.68)
        rc = real.coverage
        rt = rng.uniform(rc.t0, rc.t1, n)
        rx = rng.uniform(rc.xmin, rc.xmax, n)
        ry = rng.uniform(rc.ymin, rc.ymax, n)
        ms = best_ms(lambda: real.sample(rt, rx, ry), args.repeat)
        label = f"real wrfout {real.shape}"
        print(
            f"  {label:30s} {ms:8.1f} ms  {n / ms / 1e3:6.2f} Mpoints/s  "
            f"(wrf-python CI crop, map degree {real.index_map.degree})"
        )


if __name__ == "__main__":
    main()
