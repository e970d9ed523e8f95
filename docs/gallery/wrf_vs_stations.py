"""WRF against stations: how much do three anemometers miss of a model wind field?

Opens the (synthetic) WRF forecast of Hyères 2018 R1 for the course, samples it
every 5 minutes at three positions as if three anemometers stood there, writes
those "measurements" as a station CSV, reads it back as a station wind
(inverse-distance weighting between the three), and routes the course in both.
The station wind reproduces the forecast exactly at the stations (its defining
property) and only approximates it in between.  This synthetic forecast varies
mostly in time, so three stations capture it well: the leg times agree within a
second.

Run: ``python docs/gallery/wrf_vs_stations.py [OUT_DIR]``; the station CSV goes to
``OUT_DIR/wrf_vs_stations/``.
"""

import os
import sys
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

import sailroute
from sailroute.units import wind_speed_direction

ROOT = Path(__file__).resolve().parents[2]
OUT = (
    Path(
        sys.argv[1] if len(sys.argv) > 1 else os.environ.get("SAILROUTE_GALLERY_OUT", "out/gallery")
    )
    / "wrf_vs_stations"
)

course = sailroute.load_course(ROOT / "courses" / "hyeres-r1.yaml")
wrf = sailroute.open_wind(
    course, type="wrf", height_m=2.68, path=ROOT / "data" / "hyeres-2018-04-24-synthetic-wrfout.nc"
)

# three "anemometers": on the windward mark, at the north end of the start line and
# at the finish (the course's corners), one record every 5 min of the race window
# (open_wind reads the WRF slices of that window only)
names = ["1", "start2", "fin1"]
xy = np.array([(course.marks[n].x, course.marks[n].y) for n in names])
t0 = course.start_epoch
times = np.arange(t0, t0 + course.time_limit_s + 1.0, 300.0)
lat, lon = course.frame.to_latlon(xy[:, 0], xy[:, 1])
OUT.mkdir(parents=True, exist_ok=True)
csv = OUT / "stations.csv"
with open(csv, "w", encoding="utf-8") as f:
    f.write("time,station,lat,lon,speed_ms,direction\n")
    for k, name in enumerate(names):
        u, v = wrf.sample(times, np.full(times.size, xy[k, 0]), np.full(times.size, xy[k, 1]))
        speed, twd_local = wind_speed_direction(u, v)
        # local-frame direction -> true direction (meridian convergence, < 0.05° here)
        twd = (twd_local - course.frame.grid_north_deg(lat[k], lon[k])) % 360.0
        for t, s, d in zip(times, speed, twd, strict=True):
            when = datetime.fromtimestamp(t, UTC).isoformat()
            f.write(f"{when},{name},{lat[k]:.17g},{lon[k]:.17g},{s:.17g},{d:.17g}\n")

stations = sailroute.open_wind(course, type="stations", path=csv)

# the defining property: at a station, the station wind is what was recorded there
err = 0.0
for k in range(len(names)):
    us, vs = stations.sample(times, xy[k, 0], xy[k, 1])
    uw, vw = wrf.sample(times, xy[k, 0], xy[k, 1])
    err = max(err, float(np.max(np.hypot(us - uw, vs - vw))))

# in between they differ: the middle of the course at the start
mid = xy.mean(axis=0)
uw, vw = wrf.sample(t0, mid[0], mid[1])
us, vs = stations.sample(t0, mid[0], mid[1])

plans = {
    "wrf": sailroute.plan_with_wind(course, wrf, name="wrf").plan,
    "stations": sailroute.plan_with_wind(course, stations, name="stations").plan,
}
print(f"{'leg':<14} {'WRF s':>8} {'stations s':>10} {'diff s':>7}")
for a, b in zip(plans["wrf"].legs, plans["stations"].legs, strict=True):
    print(f"{a.spec.label:<14} {a.time_s:8.1f} {b.time_s:10.1f} {b.time_s - a.time_s:7.1f}")
for name, plan in plans.items():
    print(f"{name}_legs_s = {','.join(f'{leg.time_s:.3f}' for leg in plan.legs)}")
    print(f"{name}_total_s = {plan.total_time_s:.3f}")
print(f"station_max_error_ms = {err:.3e}")
print(f"mid_course_difference_ms = {float(np.hypot(us - uw, vs - vw)):.3f}")
print(f"wrote stations: {csv}")
