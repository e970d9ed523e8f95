"""``sailroute polar fit`` on a fleet: 25 tracks x 30 min at 1 Hz, wall and CPU time.

Usage::

    .venv/bin/python benchmarks/bench_polar_learn.py [--boats 25] [--minutes 30] [--repeat 2]
    .venv/bin/python benchmarks/bench_polar_learn.py --smoke   # 3 boats x 10 min, once

The fleet is ``tests/fleetgen.py``'s: boats routed by sailroute's isochrone router round a
windward-leeward course in a shifting wind, recorded at 1 Hz with GPS error.  It is written
once as files (generation is not timed), then ``run_fit_command`` (the command line's
code: reading the files, the samples in the wind ``analyze`` would judge them in, the
steady blocks, the learning with its bootstrap of 200 replicates, the race pace, the four
output files with the plot) is timed, alternately on

* ``gps``: GPX tracks and the course (the wind direction inferred from the tracks, TWS of
  the course's scenario), and
* ``measured``: CSV logs with the wind each boat sailed in as TWS/TWD columns, and the
  course.

Wall time and the process's CPU time; the load average is printed (a shared machine).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sailroute.commands.polar_fit import run_fit_command  # noqa: E402
from sailroute.track.kinematics import track_xy  # noqa: E402
from sailroute.units import KNOT, wind_speed_direction  # noqa: E402
from tests.fleetgen import FaultPlan, messy_fleet  # noqa: E402


def write_measured(fleet: object, folder: Path) -> list[Path]:
    """CSV logs with the wind each boat sailed in (kn, deg) beside its positions."""
    out = []
    for tr in fleet.tracks:  # type: ignore[attr-defined]
        x, y = track_xy(tr, fleet.course.frame)  # type: ignore[attr-defined]
        tws, twd = wind_speed_direction(*fleet.wind.sample(tr.t_s, x, y))  # type: ignore[attr-defined]
        stamps = np.datetime_as_string((tr.t_s * 1000).astype("datetime64[ms]"), unit="ms")
        rows = [
            f"{s}Z,{la:.7f},{lo:.7f},{w / KNOT:.3f},{d:.2f}"
            for s, la, lo, w, d in zip(stamps, tr.lat_deg, tr.lon_deg, tws, twd, strict=True)
        ]
        p = folder / f"{tr.name}.csv"
        p.write_text("time,lat,lon,tws_kn,twd_deg\n" + "\n".join(rows) + "\n", encoding="utf-8")
        out.append(p)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--boats", type=int, default=25)
    ap.add_argument("--minutes", type=float, default=30.0)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--smoke", action="store_true", help="3 boats x 10 min, once, 20 replicates")
    args = ap.parse_args()
    boot = 200
    if args.smoke:
        args.boats, args.minutes, args.repeat, boot = 3, 10.0, 1, 20
    fleet = messy_fleet(
        0, n_boats=args.boats, minutes=args.minutes, faults=FaultPlan.clean(), sample_s=(1, 1)
    )
    n_fix = sum(len(t) for t in fleet.tracks)
    with tempfile.TemporaryDirectory(prefix="bench-polar-learn-") as d:
        tmp = Path(d)
        (tmp / "gps").mkdir()
        (tmp / "measured").mkdir()
        course, gpx = fleet.write(tmp / "gps", "gpx")
        csv = write_measured(fleet, tmp / "measured")
        print(
            f"{len(fleet.tracks)} tracks, {n_fix} fixes ({n_fix / len(fleet.tracks) / 60:.0f} "
            "min each at 1 Hz)"
        )
        print("| input | wall [s] | CPU [s] | blocks | learned cells |")
        print("|---|---|---|---|---|")
        for k in range(args.repeat):
            for tag, logs in (("gps", gpx), ("measured", csv)):
                w0, c0 = time.perf_counter(), time.process_time()
                res = run_fit_command(
                    logs, courses=[course], out_dir=tmp / f"out-{tag}-{k}", bootstrap=boot
                )
                wall, cpu = time.perf_counter() - w0, time.process_time() - c0
                lp = res.data.fit.learned
                print(
                    f"| {tag} | {wall:.1f} | {cpu:.1f} | {res.data.fit.blocks.size} | "
                    f"{int((lp.status == 'learned').sum())} |"
                )
    load = Path("/proc/loadavg").read_text(encoding="utf-8").strip()
    print(f"load average: {load} (a shared machine)")


if __name__ == "__main__":
    main()
