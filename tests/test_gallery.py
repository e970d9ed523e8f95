"""The gallery scripts (docs/gallery/*.py) run, and what they print holds.

Each script runs in a fresh interpreter writing into ``tmp_path``; the checks
compare its printed ``name = value`` lines with an invariant or with the same
quantity computed here another way (docs/gallery/index.md says which).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

import sailroute
from tests.conftest import COURSES, ROOT

GALLERY = ROOT / "docs" / "gallery"
SCRIPTS = (
    "plan_course",
    "wrf_vs_stations",
    "vpp_polar",
    "strategy_map",
    "analyze_track",
    "race_day",
)


def run_script(name: str, out: Path) -> tuple[dict[str, str], str]:
    """Run ``docs/gallery/<name>.py OUT``; its ``key = value`` lines and its stdout."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    proc = subprocess.run(
        [sys.executable, str(GALLERY / f"{name}.py"), str(out)],
        capture_output=True,
        text=True,
        cwd=out,
        env=env,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    values = dict(re.findall(r"^(\S+) = (.+)$", proc.stdout, flags=re.MULTILINE))
    return values, proc.stdout


def floats(text: str) -> list[float]:
    return [float(v) for v in text.split(",")]


def test_every_gallery_script_is_tested_and_shown() -> None:
    assert sorted(p.stem for p in GALLERY.glob("*.py")) == sorted(SCRIPTS)
    page = (GALLERY / "index.md").read_text(encoding="utf-8")
    for name in SCRIPTS:
        assert f'--8<-- "docs/gallery/{name}.py"' in page


def test_plan_course(tmp_path: Path) -> None:
    v, _ = run_script("plan_course", tmp_path)
    legs, total = floats(v["legs_s"]), float(v["total_time_s"])
    assert len(legs) == 5
    assert sum(legs) == pytest.approx(total, abs=5 * 5e-4)  # chained legs
    assert float(v["vs_winner_pct"]) == pytest.approx(
        100 * (total - float(v["winner_s"])) / float(v["winner_s"]), abs=0.01
    )
    out = tmp_path / "plan_course"
    doc = json.loads((out / "plan.json").read_text(encoding="utf-8"))
    assert doc["total_time_s"] == pytest.approx(total, abs=0.01)
    assert [leg["time_s"] for leg in doc["legs"]] == pytest.approx(legs, abs=0.01)
    assert (out / "route.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "track.csv").stat().st_size > 0 and (out / "route.gpx").stat().st_size > 0


def test_wrf_vs_stations(tmp_path: Path) -> None:
    v, _ = run_script("wrf_vs_stations", tmp_path)
    assert float(v["station_max_error_ms"]) < 1e-9
    for name in ("wrf", "stations"):
        assert sum(floats(v[f"{name}_legs_s"])) == pytest.approx(
            float(v[f"{name}_total_s"]), abs=5 * 5e-4
        )
    assert abs(float(v["stations_total_s"]) - float(v["wrf_total_s"])) < 5.0
    # independently: the CSV read back with read_stations is the forecast at the stations
    course = sailroute.load_course(COURSES / "hyeres-r1.yaml")
    wrf = sailroute.open_wind(
        course,
        type="wrf",
        height_m=2.68,
        path=ROOT / "data" / "hyeres-2018-04-24-synthetic-wrfout.nc",
    )
    data = sailroute.read_stations(tmp_path / "wrf_vs_stations" / "stations.csv")
    assert data.stations == ("1", "start2", "fin1") and len(data) == 3 * 19
    x, y = course.frame.to_xy(data.lat, data.lon)
    u, v_ = wrf.sample(data.t, x, y)
    speed = np.hypot(u, v_)
    np.testing.assert_allclose(data.speed_ms, speed, rtol=0, atol=1e-9)
    for name in data.stations:  # the positions are the marks'
        m = course.marks[name]
        sel = data.station == name
        xs, ys = course.frame.to_xy(data.lat[sel], data.lon[sel])
        assert np.max(np.hypot(xs - m.x, ys - m.y)) < 1e-6


def test_vpp_polar(tmp_path: Path) -> None:
    v, _ = run_script("vpp_polar", tmp_path)
    polar = sailroute.read_polar(
        tmp_path / "vpp_polar" / "ilca7-70kg.pol", speed_unit="kn", wind_unit="kn"
    )
    knot = 1852 / 3600
    np.testing.assert_allclose(polar.tws_ms, np.array([6.0, 10.0, 14.0]) * knot, atol=1e-9)
    twa = np.linspace(25.0, 90.0, 6501)
    for tws_kn in (6, 10, 14):
        vmg = polar.speed(tws_kn * knot, twa) * np.cos(np.radians(twa))
        k = int(np.argmax(vmg))
        # the .pol has 5e-5 kn resolution; the optimum is flat in TWA
        assert float(v[f"vmg_upwind_ms[{tws_kn}]"]) == pytest.approx(vmg[k], abs=2e-4)
        assert float(v[f"vmg_upwind_twa_deg[{tws_kn}]"]) == pytest.approx(twa[k], abs=1.0)


def test_strategy_map(tmp_path: Path) -> None:
    v, _ = run_script("strategy_map", tmp_path)
    expected, mean, se = (
        float(v[k]) for k in ("expected_time_s", "monte_carlo_mean_s", "monte_carlo_se_s")
    )
    assert 0 < se < 2.0
    assert abs(mean - expected) <= 4 * se  # the simulation runs the DP's own chain
    back, none, veer = (float(v[f"tack_share[{k}]"]) for k in ("-10", "+0", "+10"))
    # on starboard a back is a header: tack on more of the course than with no shift or a lift
    assert back > none > veer
    png = tmp_path / "strategy_map" / "policy_map.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def _epoch(text: str) -> float:
    return datetime.fromisoformat(text.replace("Z", "+00:00")).timestamp()


def test_analyze_track(tmp_path: Path) -> None:
    v, _ = run_script("analyze_track", tmp_path)
    legs = [dict(zip(*[iter(v[f"leg[{i}]"].split())] * 2, strict=True)) for i in range(4)]
    legs = [{k: float(x) for k, x in leg.items()} for leg in legs]
    for leg in legs:
        assert leg["loss"] == pytest.approx(leg["sailed"] - leg["optimal"], abs=2e-3)
        assert leg["loss"] == pytest.approx(
            leg["manoeuvres"] + leg["speed"] + leg["route"], abs=2e-3
        )
    for key, total in (
        ("sailed", "sailed_time_s"),
        ("optimal", "optimal_time_s"),
        ("loss", "loss_s"),
    ):
        assert sum(leg[key] for leg in legs) == pytest.approx(float(v[total]), abs=4e-3)
    # the sailed times are the leg boundaries written to analysis.json
    doc = json.loads((tmp_path / "analyze_track" / "analysis.json").read_text(encoding="utf-8"))
    for leg, written in zip(legs, doc["legs"], strict=True):
        span = _epoch(written["end_time"]) - _epoch(written["start_time"])
        assert leg["sailed"] == pytest.approx(span, abs=2e-3)


def test_race_day(tmp_path: Path) -> None:
    """Marks in a CSV -> course file -> plan -> plotter files: the start line in a wind
    10° off its square has bias 10°, the starboard (upwind) end favoured by L·sin 10°; the
    route's NMEA sentences parse with valid checksums and name the GPX route's points."""
    import xml.etree.ElementTree as ET

    import pynmea2

    v, _ = run_script("race_day", tmp_path)
    length, bias = float(v["line_length_m"]), float(v["bias_deg"])
    assert bias == pytest.approx(10.0, abs=0.05)  # the line runs east-west, the wind is 10°
    assert v["favoured_end"] == "boat"  # the east (starboard) end is upwind
    assert float(v["gain_m"]) == pytest.approx(length * np.sin(np.radians(bias)), abs=1e-2)
    out = tmp_path / "race_day"
    sentences = [
        pynmea2.parse(line, check=True)
        for line in (out / "route.nmea").read_text(encoding="ascii").splitlines()
        if line
    ]
    wpl = [s for s in sentences if s.sentence_type == "WPL"]
    ns = {"g": "http://www.topografix.com/GPX/1/1"}
    rte = ET.parse(out / "route.gpx").getroot().findall("g:rte/g:rtept", ns)
    assert len(wpl) == len(rte) >= 5  # the start, a point per leg end, the tacks and gybes
    assert {s.sentence_type for s in sentences} == {"WPL", "RTE"}
