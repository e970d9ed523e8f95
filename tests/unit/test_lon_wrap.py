"""Longitudes in (180, 360] are wrapped on input: GPX 1.1 and plan.json hold [-180, 180)."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from typer.testing import CliRunner

from sailroute.cli import app
from sailroute.geo import LocalFrame, wrap_lon

COURSE = """\
name: Newport east-longitude test
start_time: "2024-06-01T14:00:00-04:00"
marks:
  pin: {{lat: 41.4800, lon: {pin}}}
  boat: {{lat: 41.4800, lon: {boat}}}
  top: {{lat: 41.4890, lon: {top}}}
lines:
  start: [pin, boat]
legs:
  - {{from: start, to: top, rounding: port}}
scenarios:
  steady: {{wind: {{type: uniform, tws_kn: 10, twd_deg: 0}}}}
"""


def test_wrap_lon_range() -> None:
    np.testing.assert_allclose(
        wrap_lon([288.67, 180.0, -180.0, 360.0, 179.5]),
        [-71.33, -180.0, -180.0, 0.0, 179.5],
        atol=1e-9,
    )
    assert wrap_lon(288.67) == pytest.approx(-71.33)


def test_local_frame_latlon_stays_in_gpx_range() -> None:
    frame = LocalFrame(41.48, 288.67)  # an east-positive origin
    _, lon = frame.to_latlon(np.array([0.0, 500.0]), np.array([0.0, 0.0]))
    assert np.all((lon >= -180) & (lon < 180))
    assert lon[0] == pytest.approx(-71.33, abs=1e-9)


def test_0_360_course_gives_the_same_files_as_minus_180_180(tmp_path) -> None:
    out = {}
    for tag, (pin, boat, top) in {
        "east": (288.670, 288.672, 288.674),
        "west": (-71.330, -71.328, -71.326),
    }.items():
        course = tmp_path / f"{tag}.yaml"
        course.write_text(COURSE.format(pin=pin, boat=boat, top=top))
        res = CliRunner().invoke(
            app, ["plan", str(course), "-q", "--no-plots", "--out", str(tmp_path / tag)]
        )
        assert res.exit_code == 0, res.output
        out[tag] = tmp_path / tag
    # GPX 1.1 longitudeType is [-180, 180): every point of both files is in range
    ns = {"g": "http://www.topografix.com/GPX/1/1"}
    lons = {}
    for tag, d in out.items():
        root = ET.parse(d / "route.gpx").getroot()
        pts = root.findall(".//g:trkpt", ns) + root.findall(".//g:wpt", ns)
        assert pts
        lons[tag] = np.array([float(p.get("lon")) for p in pts])
        assert np.all((lons[tag] >= -180) & (lons[tag] < 180))
    np.testing.assert_allclose(lons["east"], lons["west"], atol=1e-9)
    a = json.loads((out["east"] / "plan.json").read_text())
    b = json.loads((out["west"] / "plan.json").read_text())
    assert a["total_time_s"] == pytest.approx(b["total_time_s"], rel=1e-9)
    assert "288." not in (out["east"] / "plan.json").read_text()
