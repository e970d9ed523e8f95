"""Benchmark: polar lookups, VMG optima and the Laser VPP on one core.

    python benchmarks/bench_polar.py [--n 100000] [--repeat 7] [--smoke]

Prints the best of ``--repeat`` runs:

* ``Polar.speed`` on ``--n`` random (TWS, TWA) points, µs per 10⁵ lookups, for the
  built-in ILCA 7 polar with the smooth ``pchip`` method (dense table, index
  arithmetic) and the ``linear`` method (searchsorted on the table axes);
* the one-off cost of building the dense table;
* ``vmg_upwind`` + ``vmg_downwind`` for 10⁴ wind speeds;
* the VPP: a full built-in polar (28 TWS x 73 TWA = 2044 points) for ILCA 7, and the
  ILCA 7 upwind/downwind VMG at 4, 6 and 8 m/s.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.boat.build import builtin_polar, vpp_polar  # noqa: E402
from sailroute.boat.laser import ILCA7  # noqa: E402
from sailroute.boat.polar import Polar  # noqa: E402


def best_of(fn: Callable[[], object], repeat: int) -> float:
    """Best wall time of ``repeat`` calls [s]."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    """Run the benchmarks and print the numbers."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=100_000, help="lookups per call")
    ap.add_argument("--repeat", type=int, default=7, help="repetitions (best is kept)")
    ap.add_argument(
        "--smoke",
        action="store_true",
        help="tiny sizes, one repetition, no full VPP run (checks the script runs)",
    )
    args = ap.parse_args()
    if args.smoke:
        args.n, args.repeat = 1000, 1
    rng = np.random.default_rng(0)
    tws = rng.uniform(0.0, 15.0, args.n)
    twa = rng.uniform(-180.0, 180.0, args.n)
    base = builtin_polar("ilca7")
    scale = 1e5 / args.n

    for method in ("pchip", "linear"):
        p = base.with_interpolation(method)
        p.speed(tws[:10], twa[:10])  # build caches
        t = best_of(lambda p=p: p.speed(tws, twa), args.repeat)
        print(
            f"Polar.speed [{method:6s}]: {t * 1e6 * scale:9.0f} us per 1e5 lookups "
            f"({args.n / t / 1e6:.1f} M lookups/s)"
        )

    def build() -> None:
        Polar.from_arrays(base.twa_deg, base.tws_ms, base.speed_ms).speed(5.0, 45.0)

    print(f"dense table build (73 x 28 -> 361 x 289): {best_of(build, args.repeat) * 1e3:.1f} ms")

    w = rng.uniform(1.0, 14.0, 10_000)
    t = best_of(lambda: (base.vmg_upwind(w), base.vmg_downwind(w)), max(1, args.repeat // 2))
    print(f"vmg_upwind + vmg_downwind, 1e4 TWS: {t * 1e3:.0f} ms")

    if args.smoke:
        print("VPP full ILCA 7 polar: skipped (--smoke)")
        return
    t0 = time.perf_counter()
    vpp_polar.__wrapped__(ILCA7)  # bypass the cache
    t_vpp = time.perf_counter() - t0
    print(f"VPP full ILCA 7 polar (2044 points): {t_vpp:.2f} s ({t_vpp / 2044 * 1e3:.2f} ms/point)")
    for w in (4.0, 6.0, 8.0):
        ua, uv = base.vmg_upwind(w)
        da, dv = base.vmg_downwind(w)
        print(
            f"ILCA 7 at {w:.0f} m/s: beat {float(ua):5.1f} deg VMG {float(uv):.3f} m/s; "
            f"run {float(da):5.1f} deg VMG {float(dv):.3f} m/s"
        )


if __name__ == "__main__":
    main()
