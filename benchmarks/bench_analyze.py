"""Benchmark: ``sailroute analyze`` on a fleet and on one very long instrument log.

    python benchmarks/bench_analyze.py [--points 300000] [--repeat 1] [--smoke]

Both cases use the shipped Snipe example (``courses/snipe-valencia-p01.yaml``, a 1 Hz
Garmin track of 33 min, ``data/snipe-valencia-2025-06-21-ESP30782-P01.gpx``) and time
what the command does: read the files, analyse, write every output (JSON, CSV, PNG and
report.html) into a temporary folder.

* **fleet**: three boats of 28 min at 1 Hz (the race is 25 min; 20 min would
  end before the finish): the real track from a minute before the gun to its end, and two
  copies of it, 4 s and 9 s behind and 3 m and 6 m to the side, as three GPX files in one
  run;
* **long log**: one GPX of ``--points`` fixes (default 300 000): the real track
  interpolated to 10 Hz, with whole copies of it before and after the race (hours at
  10 Hz, as a log left running all day), written as a GPX file first (not timed).

Prints the machine's load average (``os.getloadavg``) before and after, then the best of
``--repeat`` wall times.  ``--smoke``: 3 boats and a 20 000-point log, one repetition
(a check that the script runs, for CI).
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.commands.analyze import run_analyze_command  # noqa: E402
from sailroute.course.load import load_course  # noqa: E402
from sailroute.timeutil import iso  # noqa: E402
from sailroute.track.read import read_track  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_polar import best_of  # noqa: E402  (one timing rule for the benchmarks)

ROOT = Path(__file__).resolve().parents[1]
COURSE = ROOT / "courses" / "snipe-valencia-p01.yaml"
TRACK = ROOT / "data" / "snipe-valencia-2025-06-21-ESP30782-P01.gpx"


def write_gpx(path: Path, t: np.ndarray, lat: np.ndarray, lon: np.ndarray) -> Path:
    """A minimal GPX 1.1 track of the fixes (times [epoch s], degrees)."""
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<gpx version="1.1" creator="bench_analyze" '
        'xmlns="http://www.topografix.com/GPX/1/1"><trk><name>bench</name><trkseg>',
    ]
    lines += [
        f'<trkpt lat="{la:.8f}" lon="{lo:.8f}"><time>{iso(float(tt))}</time></trkpt>'
        for tt, la, lo in zip(t, lat, lon, strict=True)
    ]
    lines.append("</trkseg></trk></gpx>")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def fleet_files(d: Path) -> list[Path]:
    """Three 1 Hz GPX files of the race (the real track and two shifted copies)."""
    course = load_course(COURSE)
    tr = read_track(TRACK)
    gun = course.start_epoch
    m = tr.t_s >= gun - 60.0
    t, lat, lon = tr.t_s[m], tr.lat_deg[m], tr.lon_deg[m]
    out = []
    for k, (lag, side) in enumerate(((0.0, 0.0), (4.0, 3.0), (9.0, 6.0))):
        dlat = side / 111_320.0  # metres north as degrees
        out.append(write_gpx(d / f"boat{k + 1}.gpx", t + lag, lat + dlat, lon))
    return out


def long_log(d: Path, n: int) -> Path:
    """One GPX of ``n`` fixes at 10 Hz: the real track interpolated, repeated before and
    after the race."""
    tr = read_track(TRACK)
    t0, t1 = tr.t_s[0], tr.t_s[-1]
    tq = np.arange(t0, t1, 0.1)
    lat = np.interp(tq, tr.t_s, tr.lat_deg)
    lon = np.interp(tq, tr.t_s, tr.lon_deg)
    span = tq[-1] - tq[0] + 0.1
    copies = max(int(np.ceil(n / tq.size)), 1)
    before = (copies - 1) // 2
    ts = np.concatenate([tq + (k - before) * span for k in range(copies)])
    la = np.tile(lat, copies)
    lo = np.tile(lon, copies)
    # keep the race copy whole: trim from both ends
    extra = ts.size - n
    cut0 = min(extra // 2, before * tq.size)
    sl = slice(cut0, cut0 + n)
    return write_gpx(d / "long.gpx", ts[sl], la[sl], lo[sl])


def main() -> None:
    """Run the benchmarks and print the numbers."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", type=int, default=300_000, help="fixes in the long log")
    ap.add_argument("--repeat", type=int, default=1, help="repetitions (best is kept)")
    ap.add_argument("--smoke", action="store_true", help="small and once (CI)")
    args = ap.parse_args()
    n = 20_000 if args.smoke else args.points
    repeat = 1 if args.smoke else args.repeat
    print(
        f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())} "
        f"({os.cpu_count()} CPUs)"
    )
    with tempfile.TemporaryDirectory(prefix="bench-analyze-") as tmp:
        d = Path(tmp)
        boats = fleet_files(d)
        sizes = [len(read_track(p)) for p in boats]
        k = [0]

        def fleet() -> object:
            k[0] += 1
            return run_analyze_command(COURSE, boats, out_dir=d / f"fleet{k[0]}")

        t = best_of(fleet, repeat)
        res = run_analyze_command(COURSE, boats, out_dir=d / "fleet-check", plots=False)
        winds = sorted({leg.wind_source for a in res.data for leg in a.legs})
        print(
            f"fleet: {len(boats)} boats x {sizes[0]} fixes (1 Hz, {sizes[0] / 60:.0f} min), "
            f"read + analyse + write: {t:6.2f} s (wind: {', '.join(winds)})"
        )
        log = long_log(d, n)

        def one() -> object:
            k[0] += 1
            return run_analyze_command(COURSE, [log], out_dir=d / f"long{k[0]}")

        t = best_of(one, repeat)
        res = run_analyze_command(COURSE, [log], out_dir=d / "check", plots=False)
        a = res.data[0]
        hours = (a.track.t_end - a.track.t_start) / 3600
        print(
            f"long log: {len(a.track)} fixes (10 Hz, {hours:.1f} h, "
            f"{log.stat().st_size / 1e6:.0f} MB GPX), read + analyse + write: {t:6.2f} s "
            f"(race {a.sailed_time_s:.1f} s sailed, {len(a.legs)} legs)"
        )
    print(f"load average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
