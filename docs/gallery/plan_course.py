"""Plan a course: Hyères 2018 R1 in constant wind, leg by leg.

Loads ``courses/hyeres-r1.yaml``, routes its ``constant`` scenario (5.61 m/s from
108°, the thesis's scenario 1) with the isochrone router, prints each leg and the
race time against the real race's winner, and writes ``plan.json``, ``track.csv``,
``route.gpx`` and ``route.png``.

Run: ``python docs/gallery/plan_course.py [OUT_DIR]`` (default ``out/gallery``, or
``$SAILROUTE_GALLERY_OUT``); the files go to ``OUT_DIR/plan_course/``.
"""

import os
import sys
from pathlib import Path

import sailroute

ROOT = Path(__file__).resolve().parents[2]  # the repository (courses/, data/)
OUT = (
    Path(
        sys.argv[1] if len(sys.argv) > 1 else os.environ.get("SAILROUTE_GALLERY_OUT", "out/gallery")
    )
    / "plan_course"
)

course = sailroute.load_course(ROOT / "courses" / "hyeres-r1.yaml")
run = sailroute.plan_course(course, "constant")
plan = run.plan

print(f"{course.name}, scenario {plan.scenario!r}, {plan.router} router")
print(f"{'leg':<14} {'mode':<9} {'time s':>8} {'tacks':>5} {'gybes':>5} {'dist m':>7}")
for leg in plan.legs:
    r = leg.result
    print(
        f"{leg.spec.label:<14} {leg.mode or '?':<9} {leg.time_s:8.1f} {r.n_tacks:5d} "
        f"{r.n_gybes:5d} {r.distance_m:7.0f}"
    )

winner = sum(plan.references["winner"])  # the real race's winner [s]
print(f"legs_s = {','.join(f'{leg.time_s:.3f}' for leg in plan.legs)}")
print(f"total_time_s = {plan.total_time_s:.3f}")
print(f"winner_s = {winner:.1f}")
print(f"vs_winner_pct = {100 * (plan.total_time_s - winner) / winner:.2f}")

files = sailroute.write_plan_outputs(OUT, plan, wind=run.wind)
for kind, path in files.items():
    print(f"wrote {kind}: {path}")
