"""Leave-one-boat-out table of the fleet wind methods on the SailGP Auckland 2025 logs.

    python benchmarks/bench_fleet_wind.py [--smoke] [--markdown]

Reads the three shared 1 Hz boat logs (NZL, AUS, GBR; ``../shared/data/real/races/
sailgp-auckland-2025``), splits each per race with ``TRK_RACE_NUM`` (races 25011905-08;
NZL has no log of race 08, so that race has two boats), and for each race builds the
fleet field from all boats but one and predicts the measured TWS/TWD (as logged, 1 Hz)
of the one left out, along its track.  Candidates and baselines:

* ``constant`` — the race's mean wind of the other boats;
* ``mean`` — the other boats' mean at each time (as logged, and smoothed 30 s);
* ``nearest`` — the nearest other boat at each time;
* ``idw`` — inverse distance between the other boats at each time;
* ``st-idw`` — inverse space-time distance over the records within ±60 s (with and
  without the per-boat bias correction);
* ``oi`` — the sensors' mean plus a Gaussian-process correction (fitted scales).

The candidates use the defaults of :func:`sailroute.wind.measured.fleet_wind`
(sensors smoothed 30 s, 10 s means, per-boat bias correction).  Prints speed RMS (kn)
and mean absolute direction error (°) per race and pooled, the per-boat biases of each
race, then a smoothing table
(``mean`` and ``nearest`` against the smoothing window) and the time to build a fleet
field of 3 boats x 20 min at 1 Hz and sample 1e5 points.  ``--smoke`` runs race
25011905 with three methods only.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import csv  # noqa: E402
import time  # noqa: E402
from datetime import UTC, datetime  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.geo import LocalFrame  # noqa: E402
from sailroute.track.model import Track  # noqa: E402
from sailroute.track.read import read_track  # noqa: E402
from sailroute.units import wind_components  # noqa: E402
from sailroute.wind.measured import (  # noqa: E402
    LooRow,
    MeasuredSeries,
    fleet_wind,
    leave_one_out,
    sensor_from_track,
)

ROOT = Path(__file__).resolve().parents[1]
LOGS = ROOT.parent / "shared" / "data" / "real" / "races" / "sailgp-auckland-2025" / "Boat_logs"
BOATS = ("NZL", "AUS", "GBR")
RACES = (25011905, 25011906, 25011907, 25011908)
FRAME = LocalFrame(-36.83, 174.76)

CANDIDATES: dict[str, dict[str, object]] = {
    "st-idw": {"method": "st-idw"},
    "st-idw, no bias correction": {"method": "st-idw", "estimate_bias": False},
    "oi": {"method": "oi"},
    "idw": {"method": "idw"},
}
BASELINES: dict[str, dict[str, object]] = {
    "constant (race mean)": {"method": "constant", "resample_s": 0.0, "estimate_bias": False},
    "mean at each time": {"method": "mean", "resample_s": 0.0, "estimate_bias": False},
    "nearest sensor": {"method": "nearest", "resample_s": 0.0, "estimate_bias": False},
}


def race_windows(boat: str) -> dict[int, tuple[float, float]]:
    """First and last time [epoch s] of each ``TRK_RACE_NUM`` in a boat's log."""
    out: dict[int, tuple[float, float]] = {}
    with (LOGS / f"data_{boat}.csv").open() as f:
        for row in csv.DictReader(f):
            r = row["TRK_RACE_NUM_unk"].strip()
            if not r:
                continue
            t = datetime.fromisoformat(row["DATETIME"]).replace(tzinfo=UTC).timestamp()
            a, b = out.get(int(float(r)), (t, t))
            out[int(float(r))] = (min(a, t), max(b, t))
    return out


def race_tracks() -> dict[int, list[Track]]:
    """Per race, the boats' logs cut to the race (boats without a log of it left out)."""
    out: dict[int, list[Track]] = {r: [] for r in RACES}
    for b in BOATS:
        tr = read_track(LOGS / f"data_{b}.csv", time_zone="UTC", name=b)
        for r, (t0, t1) in race_windows(b).items():
            if r in out:
                out[r].append(tr.between(t0, t1))
    return out


def table(
    races: dict[int, list[Track]],
    methods: dict[str, dict[str, object]],
    smooth_s: float | None = None,
) -> list[tuple[int, LooRow]]:
    """``(race, row)`` of :func:`leave_one_out` for every race; targets as logged."""
    rows = []
    for r, tracks in races.items():
        sens = [
            sensor_from_track(t) if smooth_s is None else sensor_from_track(t, smooth_s=smooth_s)
            for t in tracks
        ]
        raw = [sensor_from_track(t, smooth_s=0.0) for t in tracks]
        rows += [(r, row) for row in leave_one_out(sens, FRAME, methods, targets=raw)]
    return rows


def pooled(rows: list[tuple[int, LooRow]]) -> dict[str, tuple[int, float, float, float]]:
    """Per label: records, speed RMS [kn], direction MAE [°], inside-hull fraction."""
    acc: dict[str, list[float]] = {}
    for _, row in rows:
        if row.boat == "pooled":
            continue
        a = acc.setdefault(row.label, [0, 0.0, 0.0, 0.0])
        a[0] += row.n
        a[1] += row.n * row.speed_rms_kn**2
        a[2] += row.n * row.dir_mae_deg
        a[3] += row.n * row.inside_hull
    return {k: (int(n), float(np.sqrt(s / n)), d / n, h / n) for k, (n, s, d, h) in acc.items()}


def timing() -> tuple[float, float]:
    """Seconds to build the default fleet field (3 boats x 20 min at 1 Hz) and to sample 1e5."""
    t0 = 1737256000.0
    t = t0 + np.arange(1200.0)
    series = []
    for k in range(3):
        x = 800 * np.sin(2 * np.pi * t / 300 + k) + 200 * k
        y = 600 * np.cos(2 * np.pi * t / 420 + k)
        lat, lon = FRAME.to_latlon(x, y)
        u, v = wind_components(10 + np.sin((t - t0) / 40), 60 + 10 * np.sin((t - t0) / 57))
        series.append(MeasuredSeries(f"B{k}", "", t, lat, lon, u, v))
    rng = np.random.default_rng(1)
    q = (
        rng.uniform(t0 + 60, t0 + 1100, 100_000),
        rng.uniform(-800, 800, 100_000),
        rng.uniform(-600, 600, 100_000),
    )
    best_b, best_s = np.inf, np.inf
    for _ in range(3):
        a = time.perf_counter()
        fw = fleet_wind(series, FRAME)
        b = time.perf_counter()
        fw.field.sample(*q)
        c = time.perf_counter()
        best_b, best_s = min(best_b, b - a), min(best_s, c - b)
    return best_b, best_s


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--smoke", action="store_true", help="race 25011905, three methods")
    args = ap.parse_args(argv)
    if not LOGS.is_dir():
        print(
            f"bench_fleet_wind.py: {LOGS} not present (the SailGP logs are read in place): "
            "nothing measured"
        )
        return 0
    races = race_tracks()
    methods = {**CANDIDATES, **BASELINES}
    if args.smoke:
        races = {25011905: races[25011905]}
        methods = {k: methods[k] for k in ("st-idw", "mean at each time", "constant (race mean)")}
    rows = table(races, methods)
    print("| race | method | boat left out | n | speed RMS (kn) | direction MAE (°) | in hull |")
    print("|---|---|---|---|---|---|---|")
    for r, row in rows:
        print(
            f"| {r} | {row.label} | {row.boat} | {row.n} | {row.speed_rms_kn:.2f} | "
            f"{row.dir_mae_deg:.2f} | {100 * row.inside_hull:.0f} % |"
        )
    print("\nPooled over the races:\n")
    print("| method | n | speed RMS (kn) | direction MAE (°) | in hull |")
    print("|---|---|---|---|---|")
    for k, (n, s, d, h) in pooled(rows).items():
        print(f"| {k} | {n} | {s:.3f} | {d:.2f} | {100 * h:.0f} % |")
    if not args.smoke:
        print("\nBiases of each race's boats against the fleet (all boats of the race):\n")
        for r, tracks in races.items():
            fw = fleet_wind(tracks, FRAME)
            print(f"- {r}: " + "; ".join(b.describe() for b in fw.biases))
        print("\nSmoothing of the sensors (pooled; targets as logged):\n")
        print(
            "| smooth_s (s) | mean: speed RMS (kn) | mean: dir MAE (°) | nearest: speed RMS "
            "(kn) | nearest: dir MAE (°) | st-idw: speed RMS (kn) | st-idw: dir MAE (°) |"
        )
        print("|---|---|---|---|---|---|---|")
        sm = {
            "mean": BASELINES["mean at each time"],
            "nearest": BASELINES["nearest sensor"],
            "st-idw": CANDIDATES["st-idw"],
        }
        for s in (0.0, 10.0, 30.0, 60.0, 120.0):
            p = pooled(table(races, sm, smooth_s=s))
            print(f"| {s:g} | " + " | ".join(f"{p[k][1]:.3f} | {p[k][2]:.2f}" for k in sm) + " |")
    b, s = timing()
    print(
        f"\nfleet field, 3 boats x 20 min at 1 Hz: build {b:.3f} s, sample 1e5 points "
        f"{s:.3f} s (best of 3)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
