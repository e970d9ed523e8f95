"""Benchmark: planning a course with ten obstacle polygons and a boundary, against none.

    python benchmarks/bench_obstacles.py [--laps 2] [--repeat 3] [--router isochrone] [--smoke]

The course is a windward-leeward of 1000 m legs laid by the template in a uniform
12 kn wind (no data files).  The obstructed copy adds a boundary 350 m or more round the marks
(20 m clearance) and ten 40 m x 40 m obstacles (10 m clearance) scattered over the
course area, some across the direct routes.  Each plan is timed as ``plan_course`` does
it (wind, boat, every leg routed), the two plans in turn, the best of ``--repeat`` each
(so both see the same load); the script prints the machine's load average
(``os.getloadavg``) before and after, both wall times, their ratio, the ratio of the
process CPU times (less sensitive to other processes on a shared machine) and the race
times (which differ: the obstructed routes go round).

It also times the two forms of the segment predicate on 200 000 random moves:
``Obstacles.segments_free`` (an orientation test against every ring edge, NumPy) and
``Obstacles.segments_free_shapely`` (``shapely.intersects`` on linestrings).

``--smoke``: one lap, one repetition (a check that the script runs, for CI).
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import math  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from sailroute.course.load import load_course  # noqa: E402
from sailroute.planning.route import plan_course  # noqa: E402
from sailroute.routing.obstacles import obstacles_for  # noqa: E402

COURSE = """
name: obstacle benchmark
start_time: "2024-06-01T14:00:00+02:00"
origin: {lat: 43.069067, lon: 6.198550}
template:
  type: windward-leeward
  centre: {x: 0, y: 0}
  twd_deg: 270
  leg_length_m: 1000
  laps: LAPS
  gate_width_m: 50
  start_line_length_m: 200
  finish: leeward
boat: {builtin: ilca7}
routing: {router: ROUTER, tack_penalty_s: 5.0, gybe_penalty_s: 3.0}
scenarios:
  steady: {type: uniform, tws_kn: 12, twd_deg: 270}
"""

# ten 40 m squares (centres, metres from the course centre; the windward mark is at
# (-500, 0), the leeward gate at (500, +-25), the start line at x = 550): some on or near
# the direct routes, some off them
CENTRES = [
    (350.0, 60.0),
    (200.0, -120.0),
    (80.0, 20.0),
    (-60.0, 180.0),
    (-200.0, -60.0),
    (-340.0, 90.0),
    (250.0, 260.0),
    (-120.0, -260.0),
    (380.0, -220.0),
    (-400.0, -150.0),
]


def area_yaml() -> str:
    """The boundary and the ten obstacles as course keys."""
    lines = [
        "boundary:",
        "  clearance_m: 20",
        "  points: [{x: 900, y: -600}, {x: 900, y: 600}, {x: -900, y: 600}, {x: -900, y: -600}]",
        "obstacles:",
    ]
    for k, (cx, cy) in enumerate(CENTRES):
        pts = ", ".join(
            f"{{x: {cx + dx:.0f}, y: {cy + dy:.0f}}}"
            for dx, dy in ((-20, -20), (20, -20), (20, 20), (-20, 20))
        )
        lines.append(f"  - {{name: buoy-field-{k + 1}, clearance_m: 10, points: [{pts}]}}")
    return "\n".join(lines) + "\n"


def main() -> None:
    """Time both plans and print the numbers."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--laps", type=int, default=2, help="windward-leeward laps")
    ap.add_argument("--repeat", type=int, default=3, help="repetitions (best is kept)")
    ap.add_argument("--router", default="isochrone", choices=("isochrone", "griddp"))
    ap.add_argument("--smoke", action="store_true", help="one lap, one repetition")
    args = ap.parse_args()
    if args.smoke:
        args.laps, args.repeat = 1, 1
    print(f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    with tempfile.TemporaryDirectory() as tmp:
        text = COURSE.replace("LAPS", str(args.laps)).replace("ROUTER", args.router)
        (Path(tmp) / "open.yaml").write_text(text, encoding="utf-8")
        (Path(tmp) / "area.yaml").write_text(text + area_yaml(), encoding="utf-8")
        open_course = load_course(Path(tmp) / "open.yaml")
        area_course = load_course(Path(tmp) / "area.yaml")
    plans = {}

    def run(name: str, course: object) -> None:
        plans[name] = plan_course(course, "steady").plan  # type: ignore[arg-type]

    wall = {"open": math.inf, "area": math.inf}
    cpu = dict(wall)
    for _ in range(args.repeat):  # in turn, so that both see the same load
        for name, course in (("open", open_course), ("area", area_course)):
            w0, c0 = time.perf_counter(), time.process_time()
            run(name, course)
            wall[name] = min(wall[name], time.perf_counter() - w0)
            cpu[name] = min(cpu[name], time.process_time() - c0)
    t_open, t_area = wall["open"], wall["area"]
    print(f"plan, {args.router}, {args.laps} lap(s), {open_course.n_legs} legs:")
    print(f"  no obstacles        {t_open:7.2f} s  race {plans['open'].total_time_s:7.1f} s")
    print(f"  10 obstacles + area {t_area:7.2f} s  race {plans['area'].total_time_s:7.1f} s")
    print(f"  ratio {t_area / t_open:.2f} (target <= 1.30)")
    c_open, c_area = cpu["open"], cpu["area"]
    print(f"  CPU time {c_open:.2f} s and {c_area:.2f} s, ratio {c_area / c_open:.2f}")

    obs = obstacles_for(area_course.area)
    assert obs is not None
    rng = np.random.default_rng(0)
    n = 20_000 if args.smoke else 200_000
    x0, y0 = rng.uniform(-900, 900, n), rng.uniform(-600, 600, n)
    ang = rng.uniform(0, 2 * np.pi, n)
    x1, y1 = x0 + 60 * np.sin(ang), y0 + 60 * np.cos(ang)
    for label, fn in (
        ("edge test (NumPy)", obs.segments_free),
        ("shapely.intersects", obs.segments_free_shapely),
    ):
        tic = time.perf_counter()
        free = fn(x0, y0, x1, y1)
        dt = time.perf_counter() - tic
        print(
            f"  segments_free {label:19s} {dt * 1e3:8.1f} ms per {n} moves ({free.mean():.3f} free)"
        )
    print(f"load average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
