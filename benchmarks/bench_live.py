"""Benchmark: ``sailroute live`` latency from a wind change to the new route, and memory
over a one-hour replay.

    python benchmarks/bench_live.py [--shifts 5] [--hour-speed 60] [--tracemalloc] [--smoke]

1. Latency.  A TCP feed sends one second of instrument sentences (RMC, HDT, VHW, MWD)
   every wall second, as a 1 Hz instrument network does, for a boat on leg 2 of the
   Trieste course (``courses/trieste-coach-wl.yaml``, scenario ``mean``): the remainder is
   three legs (1 -> 4, 4 -> 1, 1 -> finish).  Once a re-plan is on the page, the feed's
   true wind turns by 15°; the time from the first sentence carrying the new direction
   to (a) the page's ``/state.json`` showing a re-plan in the new wind (polled every 5 ms)
   and (b) the NMEA port's ``RTE`` of that re-plan is measured, ``--shifts`` times.  The
   measured wind is the last second's reading here (``window_s`` 0.5 s), so the time is
   the pipeline's (decode, trigger, route, publish); with the default 60-s window a 15°
   step crosses the 5° threshold after 20 s of data, on top of it.
2. Memory.  A one-hour feed (the boat circling the course, the wind oscillating ±10°) is
   replayed from a file at ``--hour-speed`` times real time with a re-plan every 60 s of
   data; the process's resident memory is sampled every 0.5 s (with ``--tracemalloc`` also
   Python's heap, which slows the replay) and its growth between the end of the first
   quarter and the end is printed, with the replay's wall time against the feed's.

Prints the load average before and after (the machine is shared: the numbers are only
comparable at similar load).  ``--smoke``: 2 shifts and a 10-minute replay (CI).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import socket
import sys
import tempfile
import threading
import time
import tracemalloc
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from sailroute.commands.live import start_live  # noqa: E402
from sailroute.course.load import load_course  # noqa: E402
from sailroute.course.model import Course  # noqa: E402
from sailroute.live.convert import Row, nmea_lines  # noqa: E402
from sailroute.live.engine import LiveSettings  # noqa: E402

COURSE = ROOT / "courses" / "trieste-coach-wl.yaml"
KN = 1852.0 / 3600.0


def _load() -> str:
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def _rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


class LiveFeed:
    """1 Hz sentences to one TCP client: a boat drifting slowly towards the gate, the wind
    from ``self.twd``; ``changed_at`` is the wall time the first new direction went out."""

    def __init__(self, course: Course) -> None:
        self.course = course
        self.twd = 65.0
        self.changed_at: float | None = None
        self._sent_twd = 65.0
        self._sock = socket.create_server(("127.0.0.1", 0))
        self.port = self._sock.getsockname()[1]
        self._quit = threading.Event()
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        conn, _ = self._sock.accept()
        m1 = self.course.marks["1"].xy
        gate = self.course.gates["4"].midpoint
        t = self.course.start_epoch + 600.0
        s = 0
        while not self._quit.is_set():
            f = min(s / 1200.0, 0.5)  # 1 -> gate at ~0.4 m/s
            lat, lon = self.course.frame.to_latlon(
                m1[0] + (gate[0] - m1[0]) * f - 30.0, m1[1] + (gate[1] - m1[1]) * f
            )
            twd = self.twd
            row = Row(t + s, float(lat), float(lon), 0.8, 245.0, 245.0, 0.8, None, None, 5.0, twd)
            data = "".join(line + "\r\n" for line in nmea_lines(row)).encode()
            if twd != self._sent_twd and self.changed_at is None:
                self.changed_at = time.monotonic()
            self._sent_twd = twd
            try:
                conn.sendall(data)
            except OSError:
                return
            s += 1
            self._quit.wait(1.0)

    def close(self) -> None:
        self._quit.set()
        self._sock.close()


def latency(course: Course, shifts: int) -> None:
    feed = LiveFeed(course)
    engine = start_live(
        course,
        source=f"nmea+tcp://127.0.0.1:{feed.port}",
        scenario="mean",
        every_s=10_000,
        port=0,
        nmea_port=0,
        leg=2,
        settings=LiveSettings(window_s=0.5, side=False),
    )
    assert engine.page is not None and engine.nmea is not None
    url = f"http://127.0.0.1:{engine.page.port}/state.json"
    plotter = socket.create_connection(("127.0.0.1", engine.nmea.port))
    plotter.settimeout(0.005)
    buf = b""

    def state() -> dict:
        with urllib.request.urlopen(url) as r:
            return json.load(r)

    try:
        while not (s := state())["plan"]:
            time.sleep(0.05)
        page_ms, nmea_ms, route_ms, cpu_ms = [], [], [], []
        for k in range(shifts):
            time.sleep(1.5)
            before = s["plan"]["number"]
            new = 80.0 if k % 2 == 0 else 65.0
            feed.changed_at = None
            feed.twd = new
            got_page = got_nmea = None
            end = time.monotonic() + 60
            while (got_page is None or got_nmea is None) and time.monotonic() < end:
                if got_page is None:
                    s = state()
                    p = s["plan"]
                    if p["number"] > before and abs(p["wind_twd_deg"] - new) < 1.0:
                        got_page = time.monotonic()
                        route_ms.append(1000 * p["compute_s"])
                        cpu_ms.append(1000 * p["compute_cpu_s"])
                with contextlib.suppress(TimeoutError):
                    buf += plotter.recv(65536)
                if got_nmea is None and f",live{before + 1},".encode() in buf:
                    got_nmea = time.monotonic()
                time.sleep(0.005)
            assert feed.changed_at is not None and got_page and got_nmea, "no re-plan in 60 s"
            page_ms.append(1000 * (got_page - feed.changed_at))
            nmea_ms.append(1000 * (got_nmea - feed.changed_at))
            buf = b""
        legs = len(s["plan"]["leg_labels"])
    finally:
        engine.close()
        feed.close()
        plotter.close()
    print(f"wind change -> route, {legs}-leg remainder, {shifts} shifts of 15°, 1 Hz feed:")
    print(
        f"  page (/state.json) median {sorted(page_ms)[len(page_ms) // 2]:.0f} ms, "
        f"max {max(page_ms):.0f} ms"
    )
    print(
        f"  NMEA port (RTE)    median {sorted(nmea_ms)[len(nmea_ms) // 2]:.0f} ms, "
        f"max {max(nmea_ms):.0f} ms"
    )
    print(
        f"  of which routing   median {sorted(route_ms)[len(route_ms) // 2]:.0f} ms wall, "
        f"{sorted(cpu_ms)[len(cpu_ms) // 2]:.0f} ms CPU (the rest: waiting for a core)"
    )


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
    ap.add_argument("--shifts", type=int, default=5)
    ap.add_argument("--hour-speed", type=float, default=60.0)
    ap.add_argument("--tracemalloc", action="store_true", help="also trace Python's heap")
    ap.add_argument("--smoke", action="store_true", help="2 shifts, a 10-min replay (CI)")
    args = ap.parse_args()
    course = load_course(COURSE)
    seconds = 3600
    if args.smoke:
        args.shifts, seconds, args.hour_speed = 2, 600, 120.0
    print(f"load average before: {_load()} ({os.cpu_count()} CPUs)")
    latency(course, args.shifts)
    memory(course, seconds, args.hour_speed, args.tracemalloc)
    print(f"load average after: {_load()}")


if __name__ == "__main__":
    main()
