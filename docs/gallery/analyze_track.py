"""Analyse a sailed track: where did a Snipe lose time against the optimal route?

Reads the GPS track of a Snipe in race 1 of a Valencia regatta (2025-06-21,
``data/snipe-valencia-2025-06-21-ESP30782-P01.gpx``), finds its start and mark
roundings on ``courses/snipe-valencia-p01.yaml``, routes each leg optimally from
where and when the boat started it, and splits the difference into manoeuvres,
speed and route (``docs/analysis.md``).  The ILCA polar stands in for the Snipe's,
so a negative loss (the boat faster than "optimal") means the polar is slow for
this boat, not that the sailor beat physics.

Run: ``python docs/gallery/analyze_track.py [OUT_DIR]``; ``analysis.json``,
``analysis.csv`` and ``points.csv`` go to ``OUT_DIR/analyze_track/``.
"""

import os
import sys
from pathlib import Path

import sailroute
from sailroute.report.analysis import write_analysis

ROOT = Path(__file__).resolve().parents[2]
OUT = (
    Path(
        sys.argv[1] if len(sys.argv) > 1 else os.environ.get("SAILROUTE_GALLERY_OUT", "out/gallery")
    )
    / "analyze_track"
)

course = sailroute.load_course(ROOT / "courses" / "snipe-valencia-p01.yaml")
track = sailroute.read_track(ROOT / "data" / "snipe-valencia-2025-06-21-ESP30782-P01.gpx")
result = sailroute.analyze_track(course, track)

print(f"{track.name} on {course.name}")
print(
    f"{'leg':<10} {'mode':<9} {'sailed s':>8} {'optimal s':>9} {'lost s':>7} "
    f"{'manoeuv.':>8} {'speed':>7} {'route':>7} {'side':>14}"
)
for leg in result.legs:
    s = leg.split
    print(
        f"{leg.label:<10} {leg.mode:<9} {leg.sailed_time_s:8.1f} {leg.optimal_time_s:9.1f} "
        f"{leg.loss_s:7.1f} {s.manoeuvres:8.1f} {s.speed:7.1f} {s.route:7.1f} "
        f"{leg.side_sailed + '/' + leg.side_optimal:>14}"
    )
for leg in result.legs:
    s = leg.split
    print(
        f"leg[{leg.index}] = sailed {leg.sailed_time_s:.3f} optimal {leg.optimal_time_s:.3f} "
        f"loss {leg.loss_s:.3f} manoeuvres {s.manoeuvres:.3f} speed {s.speed:.3f} "
        f"route {s.route:.3f}"
    )
print(f"sailed_time_s = {result.sailed_time_s:.3f}")
print(f"optimal_time_s = {result.optimal_time_s:.3f}")
print(f"loss_s = {result.loss_s:.3f}")

files = write_analysis(OUT, result, plots=False)
for kind, path in files.items():
    print(f"wrote {kind}: {path}")
