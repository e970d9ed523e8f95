"""Benchmark: wind inferred from 3 boats x 20 min of 1 Hz GPS tracks, on one core.

    python benchmarks/bench_infer_wind.py [--repeat 5] [--smoke]

The tracks are those of the known-answer tests (tests/analysis/test_infer_wind.py:
sailroute's own routes in the oscillating wind, 2 m of GPS noise, cut to the first
20 min of each boat).  Prints the best of ``--repeat`` runs of
:func:`~sailroute.analysis.infer_wind.infer_wind` in ms, without and with the polar (TWS),
and the direction RMS against the known wind.  ``--smoke``: one run of each (CI).
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sailroute.analysis.infer_wind import infer_wind  # noqa: E402
from sailroute.units import wrap180  # noqa: E402
from tests.analysis import test_infer_wind as known  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--smoke", action="store_true", help="one run of each (CI)")
    args = ap.parse_args()
    if args.smoke:
        args.repeat = 1
    starts = ((-100.0, 0.0, "starboard"), (0.0, 150.0, "port"), (100.0, 300.0, None))
    routes = {"osc": [known.route_boat(known.twd_osc, *s) for s in starts]}
    tracks = [
        tr.between(tr.t_start, tr.t_start + 1200.0) for tr in known.tracks(routes, "osc", 3, 2.0)
    ]
    n = sum(len(tr) for tr in tracks)
    for boat in (None, known.BOAT):
        best = np.inf
        for _ in range(args.repeat):
            tic = time.perf_counter()
            iw = infer_wind(tracks, known.FRAME, prior_twd_deg=known.BASE, boat=boat)
            best = min(best, time.perf_counter() - tic)
        ok = np.isfinite(iw.twd_deg)
        rms = float(np.sqrt(np.mean(wrap180(iw.twd_deg[ok] - known.twd_osc(iw.t[ok])) ** 2)))
        print(
            f"infer_wind, 3 boats, {n} points, {'with' if boat else 'without'} polar: "
            f"{1e3 * best:.1f} ms (best of {args.repeat}); TWD RMS {rms:.2f}°"
        )


if __name__ == "__main__":
    main()
