"""The files in data/ used by the example courses: reproducible and as documented."""

from __future__ import annotations

import csv
import importlib.util
from datetime import UTC, datetime

import netCDF4
import numpy as np
import pytest

from sailroute.geo import LocalFrame
from sailroute.units import wind_speed_direction
from sailroute.wind.wrf import open_wrf
from tests.conftest import ROOT

DATA = ROOT / "data"
WRF = DATA / "hyeres-2018-04-24-synthetic-wrfout.nc"
START = datetime(2018, 4, 24, 10, 10, tzinfo=UTC).timestamp()
FRAME = LocalFrame(43.069067, 6.198550)


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, DATA / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_synthetic_wrf_is_reproduced_by_its_script(tmp_path) -> None:
    out = _load("make_synthetic_wrf").main(tmp_path / "again.nc")
    with netCDF4.Dataset(WRF) as a, netCDF4.Dataset(out) as b:
        for v in ("Times", "XLAT", "XLONG", "U10", "V10", "U", "V", "PH", "PHB", "COSALPHA"):
            np.testing.assert_array_equal(a[v][:], b[v][:])
        assert "SYNTHETIC" in a.TITLE and "NOT a forecast" in a.TITLE
        assert a.MAP_PROJ == 1 and (a.TRUELAT1, a.TRUELAT2, a.STAND_LON) == (43.0, 44.0, 6.2)
        assert a.DX == a.DY == 1000.0 and a["U10"].shape == (37, 25, 25)
    assert WRF.stat().st_size < 3_000_000


def test_synthetic_wrf_matches_its_design() -> None:
    f75 = open_wrf(WRF, FRAME, height_m=7.5)
    f_ce = open_wrf(WRF, FRAME, height_m=2.68)
    c = f75.coverage
    assert c.xmin < -10e3 and c.xmax > 10e3 and c.ymin < -10e3 and c.ymax > 10e3
    assert (c.t0, c.t1) == (START - 7800.0, START + 13800.0)  # 08:00Z .. 14:00Z
    # The fitted exponents come back as designed (0.10 .. 0.20) and none falls back.
    assert f_ce.info["fallback_fraction"] == 0.0
    assert 0.14 < f_ce.info["exponent_mean"] < 0.16
    t = START + np.array([0.0, 3600.0])
    x = np.zeros(2)
    s_n, d_n = wind_speed_direction(*f75.sample(t, x, x + 4000.0))
    s_s, _ = wind_speed_direction(*f75.sample(t, x, x - 4000.0))
    assert s_n[0] > s_s[0] and s_n[1] < s_s[1]  # north windier at the start, south later
    assert np.all((s_n > 3.0) & (s_n < 5.0))
    assert 140.0 < d_n[0] < 155.0  # SE at the start (thesis: ~147 deg)
    s_c0, _ = wind_speed_direction(*f_ce.sample(START, 0.0, 0.0))
    s_c1, _ = wind_speed_direction(*f_ce.sample(START + 3600.0, 0.0, 0.0))
    assert 2.7 < float(s_c0) < 3.5 and float(s_c1) > float(s_c0)  # ~3 m/s at 2.68 m, rising


@pytest.mark.skipif(
    not (ROOT.parent / "shared" / "data" / "real").is_dir(),
    reason="../shared/data/real not present",
)
@pytest.mark.shared
def test_coach_csv_is_reproduced_by_its_script(tmp_path) -> None:
    out = _load("make_trieste_coach").main(out=tmp_path / "coach.csv")
    assert out.read_text() == (DATA / "trieste-coach-2018-02-15.csv").read_text()


def test_coach_csv_schema() -> None:
    with open(DATA / "trieste-coach-2018-02-15.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == ["time", "station", "lat", "lon", "speed", "direction"]
    assert len(rows) == 4300
    assert all(r["time"].endswith("+01:00") and r["station"] == "coach" for r in rows)
