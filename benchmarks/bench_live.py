"""Benchmark: ``sailroute live`` from a wind step to a route in the new wind, in race time,
and memory over a one-hour replay.

    python benchmarks/bench_live.py [--step 20] [--steps 5] [--speeds 1,4]
                                    [--hour-speed 60] [--tracemalloc] [--smoke]

1. Step latency, from the command as a coach runs it: the Trieste course
   (``courses/trieste-coach-wl.yaml`` with its own routing settings and default scenario,
   ``measured``), the sailor's boat an AIS target beating towards mark 1, the coach
   boat's instruments 200 m off giving the wind at 1 Hz, replayed from a file at each
   of ``--speeds``; re-plans in the worker processes, every 10 s of data, with the side
   that pays (the defaults of ``sailroute live``).  After 120 s of 4.8 kn from 65°, the
   true wind steps by ``--step`` degrees every 40 s of data (65 -> 85 -> 65 ...), clean,
   ``--steps`` times.  The latency of a step is the data time at which a route computed
   in the new wind (its measured TWD within 2° of it) is published, minus the data time
   of the first reading of the new wind: race time, whatever the replay speed.  The
   re-plans' routing time (wall and CPU of the worker) and the process's CPU time are
   printed with it.
2. Memory.  A one-hour feed (the boat circling the course, the wind oscillating ±10°) is
   replayed from a file at ``--hour-speed`` times real time with a re-plan every 60 s of
   data; the process's resident memory is sampled every 0.5 s (with ``--tracemalloc`` also
   Python's heap, which slows the replay) and its growth between the end of the first
   quarter and the end is printed, with the replay's wall time against the feed's.

Prints the load average before and after (the machine is shared: the numbers are only
comparable at similar load).  ``--smoke``: 2 steps at speed 4, a 10-minute replay (CI).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sailroute.commands.live import start_live  # noqa: E402
from sailroute.course.load import load_course  # noqa: E402
from sailroute.course.model import Course  # noqa: E402
from sailroute.live.convert import Row, nmea_lines  # noqa: E402
from sailroute.live.engine import LiveSettings  # noqa: E402
from sailroute.nmea import checksum  # noqa: E402

COURSE = ROOT / "courses" / "trieste-coach-wl.yaml"
KN = 1852.0 / 3600.0


def _load() -> str:
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def _rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


MMSI = 247000321


def step_feed(course: Course, path: Path, step_deg: float, steps: int) -> list[tuple[float, float]]:
    """Write the step replay; ``(data time of the first new reading, new TWD)`` per step."""
    frame = course.frame
    mx, my = course.marks["1"].xy
    (ax, ay), (bx, by) = course.lines["start"].a.xy, course.lines["start"].b.xy
    sx, sy = (ax + bx) / 2.0, (ay + by) / 2.0
    d = math.hypot(mx - sx, my - sy)
    ux, uy = (mx - sx) / d, (my - sy) / d
    cog = math.degrees(math.atan2(ux, uy)) % 360.0
    t0 = course.start_epoch + 300.0
    settle, period = 120, 40
    n = settle + steps * period
    changes, lines = [], []
    for s in range(n):
        k = (s - settle) // period + 1 if s >= settle else 0
        twd = 65.0 + (step_deg if k % 2 else 0.0)
        if s >= settle and (s - settle) % period == 0:
            changes.append((t0 + s, twd))
        # the sailor beats up the leg at 1 m/s (VMG); the coach boat idles 200 m to its side
        bxy = (sx + ux * (40.0 + s), sy + uy * (40.0 + s))
        cxy = (bxy[0] + 200.0 * uy, bxy[1] - 200.0 * ux)
        cla, clo = frame.to_latlon(*cxy)
        row = Row(t0 + s, float(cla), float(clo), 0.2, 90.0, None, None, None, None, 4.8, twd)
        lines += [line + "\r\n" for line in nmea_lines(row)]
        bla, blo = frame.to_latlon(*bxy)
        lines.append(ais(MMSI, float(bla), float(blo), 1.0 / KN, cog, s % 60))
    path.write_text("".join(lines), encoding="ascii")
    return changes


def ais(mmsi: int, lat: float, lon: float, sog_kn: float, cog: float, second: int) -> str:
    """An AIS class B position report (message 18) as ``!AIVDM`` with its line end."""
    bits = "".join(
        [
            f"{18:06b}",
            "00",
            f"{mmsi:030b}",
            "0" * 8,
            f"{round(sog_kn * 10):010b}",
            "1",
            f"{round(lon * 600_000) & (2**28 - 1):028b}",
            f"{round(lat * 600_000) & (2**27 - 1):027b}",
            f"{round(cog * 10) % 3600:012b}",
            f"{511:09b}",
            f"{second:06b}",
            "0" * 29,
        ]
    )
    v = [int(bits[i : i + 6], 2) for i in range(0, 168, 6)]
    body = "AIVDM,1,1,,B," + "".join(chr(x + 48 if x < 40 else x + 56) for x in v) + ",0"
    return f"!{body}*{checksum(body)}\r\n"


def step_latency(course: Course, step_deg: float, steps: int, speed: float) -> None:
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "step.nmea"
        changes = step_feed(course, path, step_deg, steps)
        log = Path(d) / "live.jsonl"
        c0, w0 = os.times(), time.monotonic()
        engine = start_live(
            course, source=str(path), boat=str(MMSI), speed=speed, port=0, nmea_port=0, log=log
        )
        try:
            engine.wait()
        finally:
            engine.close()
        c1, wall = os.times(), time.monotonic() - w0
        plans = {
            r["number"]: r
            for r in (json.loads(x) for x in log.read_text().splitlines())
            if r["kind"] == "plan"
        }
    shown = [(n, clock) for n, _, clock in engine.published if clock is not None]
    lat = []
    for t_step, twd in changes:
        hit = next(
            (
                clock - t_step
                for n, clock in shown
                if clock >= t_step and abs((plans[n]["wind_twd_deg"] - twd + 180) % 360 - 180) < 2
            ),
            math.nan,
        )
        lat.append(hit)
    reasons: dict[str, int] = {}
    for p in plans.values():
        reasons[p["reason"]] = reasons.get(p["reason"], 0) + 1
    route = [p["compute_s"] for p in plans.values() if p["reason"] == "shift"]
    cpu = [p["compute_cpu_s"] for p in plans.values() if p["reason"] == "shift"]
    ok = [v for v in lat if math.isfinite(v)]
    print(f"speed {speed:g}x, {len(changes)} steps of {step_deg:g}°:")
    print(
        f"  step -> route in the new wind (race time): median {float(np.median(ok)):.1f} s, "
        f"max {max(lat):.1f} s, each {[round(v, 1) for v in lat]}"
    )
    print(
        f"  re-plans {len(plans)} {dict(sorted(reasons.items()))}; shift re-plans' routing "
        f"median {1000 * float(np.median(route)):.0f} ms wall / "
        f"{1000 * float(np.median(cpu)):.0f} ms CPU, max {1000 * max(route):.0f} ms wall"
    )
    cpu_s = (c1.user - c0.user) + (c1.system - c0.system)
    kids = (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)
    print(f"  run {wall:.1f} s wall; CPU {cpu_s:.1f} s this process, {kids:.1f} s the workers")


def memory(course: Course, seconds: int, speed: float, trace: bool) -> None:
    frame = course.frame
    cx, cy = course.marks["1"].xy
    rows = []
    for s in range(seconds):  # circling 200 m around a point below mark 1, 2.5 m/s
        a = 2.5 * s / 200.0
        lat, lon = frame.to_latlon(cx - 250.0 + 200.0 * math.sin(a), cy - 250 + 200.0 * math.cos(a))
        rows.append(
            Row(
                course.start_epoch + s,
                float(lat),
                float(lon),
                2.5 / KN,
                math.degrees(a + math.pi / 2) % 360,
                None,
                None,
                None,
                None,
                5.0 + math.sin(s / 300.0),
                65.0 + 10.0 * math.sin(s / 420.0),
            )
        )
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "hour.nmea"
        path.write_text("".join(line + "\r\n" for r in rows for line in nmea_lines(r)))
        if trace:
            tracemalloc.start()
        engine = start_live(
            course,
            source=str(path),
            scenario="mean",
            every_s=60.0,
            speed=speed,
            port=0,
            nmea_port=0,
            log=Path(d) / "live.jsonl",
            leg=1,
            boat="self",
            settings=LiveSettings(side=False),
        )
        rss, traced = [], []
        w0 = time.monotonic()
        try:
            while not engine.source_ended.is_set():
                rss.append(_rss_mb())
                traced.append(tracemalloc.get_traced_memory()[0] / 2**20 if trace else 0.0)
                time.sleep(0.5)
            replay = time.monotonic() - w0
            engine.wait(60)
        finally:
            engine.close()
        wall = time.monotonic() - w0
    q = max(len(rss) // 4, 1)
    print(
        f"{seconds / 60:.0f}-min replay at {speed:g}x: read in {replay:.1f} s "
        f"(the feed's pace: {seconds / speed:.1f} s), {wall:.1f} s with the last re-plan; "
        f"{engine.n_readings} readings, {engine.n_plans} re-plans"
    )
    heap = f"; Python heap {traced[q - 1]:.1f} -> {traced[-1]:.1f} MiB" if trace else ""
    print(
        f"  RSS after the first quarter {rss[q - 1]:.1f} MiB, at the end {rss[-1]:.1f} MiB "
        f"(max {max(rss):.1f}){heap}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--step", type=float, default=20.0, help="wind step [°]")
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--speeds", default="1,4", help="replay speeds, comma-separated")
    ap.add_argument("--hour-speed", type=float, default=60.0)
    ap.add_argument("--no-memory", action="store_true", help="only the step latency")
    ap.add_argument("--tracemalloc", action="store_true", help="also trace Python's heap")
    ap.add_argument("--smoke", action="store_true", help="2 steps at 4x, a 10-min replay (CI)")
    args = ap.parse_args()
    course = load_course(COURSE)
    seconds = 3600
    speeds = [float(v) for v in args.speeds.split(",")]
    if args.smoke:
        args.steps, speeds, seconds, args.hour_speed = 2, [4.0], 600, 120.0
    print(f"load average before: {_load()} ({os.cpu_count()} CPUs)")
    for speed in speeds:
        step_latency(course, args.step, args.steps, speed)
    if not args.no_memory:
        memory(course, seconds, args.hour_speed, args.tracemalloc)
    print(f"load average after: {_load()}")


if __name__ == "__main__":
    main()
