"""Real tracks without marks (Tallinn 2023 keelboat, J/24 Lake Washington 2015) analyse.

Neither data set gives mark positions, so the course is laid on the track itself: the start
at its first point, the windward and leeward marks at its most upwind and most downwind
points (rounded on the side the boat turned).  The losses then say little; what is checked
is that the reader, the leg detection, the routers and the decomposition run end to end on
these real files and give finite, self-consistent numbers.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sailroute.analysis.debrief import analyze_track
from sailroute.analysis.segment import turn_deg
from sailroute.course.load import load_course
from sailroute.geo import LocalFrame
from sailroute.timeutil import iso
from sailroute.track import read_track
from sailroute.units import KNOT, circular_mean_deg
from tests.conftest import SHARED_REAL, requires_shared


def course_on_track(tr, t0: float, t1: float, twd: float, wind_yaml: str, out: Path):
    m = (tr.t_s >= t0) & (tr.t_s <= t1)
    fr = LocalFrame(float(np.mean(tr.lat_deg[m])), float(np.mean(tr.lon_deg[m])))
    x, y = fr.to_xy(tr.lat_deg[m], tr.lon_deg[m])
    t = tr.t_s[m]
    up = np.radians(twd)
    along = x * np.sin(up) + y * np.cos(up)
    kw, kl = int(np.argmax(along)), int(np.argmin(along))

    def side(k: int) -> str:
        s = slice(max(k - 40, 0), k + 40)
        return "port" if turn_deg(x[s], y[s]) < 0 else "starboard"

    la, lo = fr.to_latlon(np.array([x[kw], x[kl]]), np.array([y[kw], y[kl]]))
    first, second = (("W", kw), ("L", kl)) if t[kw] < t[kl] else (("L", kl), ("W", kw))
    out.write_text(f"""name: track-derived course
start_time: "{iso(t[0])}"
time_limit_min: {int((t1 - t0) / 60) + 5}
marks:
  S: {{lat: {float(tr.lat_deg[m][0])}, lon: {float(tr.lon_deg[m][0])}}}
  W: {{lat: {float(la[0])}, lon: {float(lo[0])}}}
  L: {{lat: {float(la[1])}, lon: {float(lo[1])}}}
legs:
  - {{from: S, to: {first[0]}, rounding: {side(first[1])}}}
  - {{to: {second[0]}, rounding: {side(second[1])}}}
scenarios:
  wind: {wind_yaml}
""")
    return load_course(out)


def _check(a) -> None:
    assert len(a.legs) == 2
    for leg in a.legs:
        assert np.isfinite(leg.sailed_time_s) and leg.sailed_time_s > 0
        assert np.isfinite(leg.optimal_time_s) and leg.optimal_time_s > 0
        sp = leg.split
        assert sp.manoeuvres + sp.speed + sp.route == pytest.approx(
            leg.sailed_time_s - leg.optimal_time_s, abs=1e-6
        )
        assert leg.loss_s == pytest.approx(leg.sailed_time_s - leg.optimal_time_s, abs=1e-9)


@requires_shared
def test_tallinn_instrument_log_analyses(tmp_path: Path) -> None:
    tr = read_track(
        SHARED_REAL / "races" / "tallinn-wednesday-races-2023" / "kolmak_2023_09_27.csv",
        speed_unit="kn",
    )
    twd = tr.channels["twd_deg"]
    d = float(circular_mean_deg(twd[np.isfinite(twd)]))
    s = float(np.nanmedian(tr.channels["tws_ms"]))
    assert 12.0 < s / KNOT < 16.0  # the log's median TWS, 14.1 kn
    c = course_on_track(
        tr,
        tr.t_s[0],
        tr.t_s[-1],
        d,
        f"{{type: uniform, tws_ms: {s:.2f}, twd_deg: {d:.0f}}}",
        tmp_path / "tallinn.yaml",
    )
    _check(analyze_track(c, tr))


@requires_shared
def test_j24_phone_track_with_the_bridge_station_analyses(tmp_path: Path) -> None:
    # J/24 Lake Washington 2015 (phone GPS, test-only data) in the SR-520 bridge station's
    # wind; marks laid on the track between 0.5 h and 2.5 h after its start (a window where
    # the invented windward mark is really rounded; ending at 3.5 h it is not: the boat is
    # still beating at the window's end, and the analysis rightly says "never rounds 'W'")
    import csv

    with open(SHARED_REAL / "wind" / "lake-washington-sr520" / "tuesday-july-28-2015.csv") as f:
        rows = list(csv.DictReader(f))
    station = tmp_path / "sr520.csv"
    with open(station, "w") as f:
        f.write("time,lat,lon,speed_mph,direction\n")
        for r in rows:
            h = float(r["hod"])
            hh, mm = int(h), round((h - int(h)) * 60)
            if mm == 60:
                hh, mm = hh + 1, 0
            f.write(
                f"2015-07-28T{hh:02d}:{mm:02d}:00-07:00,47.641,-122.262,{r['speed']},"
                f"{r['direction']}\n"
            )
    tr = read_track(
        SHARED_REAL
        / "races"
        / "j24-lake-washington-2015"
        / "Sensor_record_20150728_211517_AndroSensor.csv",
        time_zone="-07:00",
    )
    t0 = tr.t_s[0] + 0.5 * 3600
    c = course_on_track(
        tr,
        t0,
        t0 + 2.0 * 3600,
        300.0,
        f"{{type: stations, path: {station}, radius_m: 8000}}",
        tmp_path / "j24.yaml",
    )
    _check(analyze_track(c, tr))
