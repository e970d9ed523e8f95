"""Race morning: marks pinged on the water -> a course file -> the plan -> the plotter.

Writes the marks a coach saved on a phone as a CSV (name, lat, lon, type, rounding), imports it
into a course file with a 10 kn wind from 10°, plans it with the built-in ILCA 7 race
polar, prints the start line's bias and favoured end, and writes the plan's files, among
them ``route.gpx`` (a route of waypoints at the marks and at each tack and gybe),
``route.kml`` and ``route.nmea`` (NMEA 0183 ``WPL`` and ``RTE`` sentences for a plotter).

Run: ``python docs/gallery/race_day.py [OUT_DIR]`` (default ``out/gallery``, or
``$SAILROUTE_GALLERY_OUT``); the files go to ``OUT_DIR/race_day/``.
"""

import os
import sys
from pathlib import Path

import sailroute
from sailroute.commands.course_import import run_course_import_command

OUT = (
    Path(
        sys.argv[1] if len(sys.argv) > 1 else os.environ.get("SAILROUTE_GALLERY_OUT", "out/gallery")
    )
    / "race_day"
)
OUT.mkdir(parents=True, exist_ok=True)

# the marks in the order of the course: the start line's ends, the windward and leeward
# marks (left to port), the windward mark again, the finish line's ends
marks = OUT / "marks.csv"
marks.write_text(
    "name,lat,lon,type,rounding\n"
    "pin,45.6400,13.7000,start,\n"
    "boat,45.6400,13.7040,start,\n"
    "W,45.6490,13.7020,mark,port\n"
    "L,45.6405,13.7020,mark,port\n"
    "W,45.6490,13.7020,mark,port\n"
    "pin,45.6400,13.7000,finish,\n"
    "boat,45.6400,13.7040,finish,\n",
    encoding="utf-8",
)
imported = run_course_import_command(
    marks,
    out=OUT / "race.yaml",
    boat="ilca7",
    wind_twd_deg=10.0,
    wind_tws_kn=10.0,
    start_time="2026-11-28T11:00:00+01:00",
)
print(imported.report)

course = sailroute.load_course(OUT / "race.yaml")
run = sailroute.plan_course(course)
plan = run.plan
for leg in plan.legs:
    print(f"{leg.spec.label:<14} {leg.mode or '?':<9} {leg.time_s:8.1f} s")
sl = plan.start_line
assert sl is not None  # the course starts on a line
print(f"line_length_m = {sl.length_m:.2f}")
print(f"bias_deg = {sl.bias_deg:.3f}")
print(f"favoured_end = {sl.favoured_end}")
print(f"gain_m = {sl.gain_m:.3f}")
print(f"total_time_s = {plan.total_time_s:.3f}")

files = sailroute.write_plan_outputs(OUT, plan, wind=run.wind)
for kind, path in files.items():
    print(f"wrote {kind}: {path}")
