"""wind_from_spec: the factory the course loader calls (spec keys, errors, coverage)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import T0

from sailroute.errors import InputError, OutOfCoverageError, WindDataError
from sailroute.geo import LocalFrame
from sailroute.units import KNOT, wind_speed_direction
from sailroute.wind.blended import BlendedWind
from sailroute.wind.build import wind_from_spec
from sailroute.wind.grid import GridWind
from sailroute.wind.stations import StationWind
from sailroute.wind.uniform import UniformWind
from tests.conftest import ROOT, WIND_DATA

WHERE = "courses/x.yaml: scenarios.wrf10[0]"


def build(spec, frame=None, base_dir=Path("."), **kw):
    return wind_from_spec(
        spec, frame=frame or LocalFrame(45.0, 10.0), base_dir=base_dir, where=WHERE, **kw
    )


def test_uniform_constant_and_table() -> None:
    f = build({"type": "uniform", "tws_kn": 10, "twd_deg": 108})
    assert isinstance(f, UniformWind)
    s, d = wind_speed_direction(*f.sample(0.0, 0.0, 0.0))
    assert float(s) == pytest.approx(10 * KNOT) and float(d) == pytest.approx(108.0)
    g = build(
        {
            "type": "uniform",
            "interpolation": "previous",
            "table": [
                {"time": "2018-04-24T12:00:00+02:00", "tws_ms": 5.0, "twd_deg": 100},
                {"time": "2018-04-24T12:30:00+02:00", "tws_kn": 12, "twd_deg": 110},
            ],
        }
    )
    s, d = wind_speed_direction(*g.sample(T0 + 2 * 3600 + 1200.0, 0.0, 0.0))  # 12:20 CEST
    assert (float(s), float(d)) == pytest.approx((5.0, 100.0))


def test_every_problem_listed_with_its_key_path() -> None:
    with pytest.raises(InputError) as e:
        build({"type": "uniform", "tws_kn": "ten", "twd": 108, "clamp": "yes"})
    msg = str(e.value)
    assert msg.startswith(f"{WHERE}: 4 problems in the wind spec")
    assert f"{WHERE}.tws_kn: expected a number >= 0; got 'ten'" in msg
    assert f"{WHERE}.twd: unknown key; did you mean 'twd_deg'?" in msg
    assert f"{WHERE}.twd_deg: missing required key" in msg
    assert f"{WHERE}.clamp: expected true or false; got 'yes'" in msg
    with pytest.raises(
        InputError,
        match=r"scenarios.wrf10\[0\].type: expected one of 'uniform', "
        r"'wrf', 'netcdf', 'grib', 'stations', 'blended', "
        r"'measured'; got 'hdf5'",
    ):
        build({"type": "hdf5"})


def test_wind_direction_outside_the_compass_is_an_error() -> None:
    # directions are [0, 360] (docs/nomenclature.md); 2700 for 270 is a typo, not 180
    with pytest.raises(InputError, match=r"wrf10\[0\].twd_deg: expected a number in \[0, 360\]"):
        build({"type": "uniform", "tws_kn": 10, "twd_deg": 2700})
    with pytest.raises(InputError, match=r"table\[1\].twd_deg: expected a number in \[0, 360\]"):
        build(
            {
                "type": "uniform",
                "table": [
                    {"time": "2018-04-24T12:00:00+02:00", "tws_ms": 5.0, "twd_deg": 100},
                    {"time": "2018-04-24T12:30:00+02:00", "tws_ms": 5.0, "twd_deg": -10},
                ],
            }
        )
    f = build({"type": "uniform", "tws_kn": 10, "twd_deg": 360})  # north, both ways
    assert float(wind_speed_direction(*f.sample(0.0, 0.0, 0.0))[1]) % 360.0 == pytest.approx(0.0)


def test_a_non_number_names_file_key_and_value(tiny_wrf, tmp_path) -> None:
    path = tiny_wrf()
    with pytest.raises(InputError) as e:
        build({"type": "wrf", "path": path.name, "time_step_min": "ten"}, base_dir=path.parent)
    assert str(e.value) == (
        "courses/x.yaml: scenarios.wrf10[0].time_step_min: expected a number > 0; got 'ten'"
    )


def test_wrf_spec_options_reach_the_field(tiny_wrf, frame) -> None:
    path = tiny_wrf()
    f = build(
        {
            "type": "wrf",
            "path": path.name,
            "height_m": 2.68,
            "time_step_min": 10,
            "interpolation": "nearest",
            "levels": "model",
            "shear": "power",
            "fallback_exponent": 0.12,
            "exponent_range": [0.0, 0.5],
            "margin_m": 1500,
            "clamp": False,
        },
        frame=frame,
        base_dir=path.parent,
        crop_bbox=(-500.0, 500.0, -500.0, 500.0),
        time_window=(T0 + 60.0, T0 + 900.0),
    )
    assert isinstance(f, GridWind)
    assert f.interpolation == "nearest" and f.time_step_s == 600.0
    assert f.info["levels"] == "model" and f.info["height_m"] == 2.68
    w = f.info["window"]
    assert (w.k0, w.k1) == (0, 3)  # 08:00 (block start before 08:01) .. 08:20
    assert float(np.hypot(*f.sample(T0 + 300.0, 0.0, 0.0))) == pytest.approx(
        5 * 0.268**0.15, abs=1e-5
    )


def test_wrf_coverage_checked_up_front(tiny_wrf, frame) -> None:
    path = tiny_wrf()
    spec = {"type": "wrf", "path": path.name}
    with pytest.raises(OutOfCoverageError, match=r"needed: .*\n.*covered:"):
        build(spec, frame=frame, base_dir=path.parent, time_window=(T0, T0 + 7200.0))
    f = build(
        spec | {"clamp": True}, frame=frame, base_dir=path.parent, time_window=(T0, T0 + 7200.0)
    )
    assert f.sample(T0 + 7200.0, 0.0, 0.0)[0].shape == ()
    with pytest.raises(InputError, match=r"wrf10\[0\].path: file not found"):
        build({"type": "wrf", "path": "nope.nc"}, base_dir=path.parent)
    with pytest.raises(InputError, match=r"levels: 'model' levels are only used for a height"):
        build({"type": "wrf", "path": path.name, "levels": "model"}, base_dir=path.parent)


def test_wrf_data_errors_carry_the_spec_location(tiny_wrf, tmp_path) -> None:
    bad = tmp_path / "bad.nc"
    bad.write_text("hello")
    with pytest.raises(WindDataError) as e:
        build({"type": "wrf", "path": "bad.nc"}, base_dir=tmp_path)
    assert str(e.value).startswith(f"{WHERE}: ")
    assert "bad.nc: cannot be read as NetCDF" in str(e.value)


def test_stations_spec(tmp_path) -> None:
    frame = LocalFrame(45.55, 13.65)
    f = build(
        {
            "type": "stations",
            "path": "coach_wind_1hz_excerpt.csv",
            "timezone": "+01:00",
            "resample_s": 60,
            "station": "coach",
            "radius_m": 1500,
            "method": "idw",
        },
        frame=frame,
        base_dir=WIND_DATA,
    )
    assert isinstance(f, StationWind) and f.data.stations == ("coach",)
    assert len(f.data) == 15
    with pytest.raises(InputError) as e:
        build(
            {
                "type": "stations",
                "path": "coach_wind_1hz_excerpt.csv",
                "timezone": "CET",
                "speed_unit": "knts",
                "columns": {"tws": "x"},
                "method": "kriging",
            },
            frame=frame,
            base_dir=WIND_DATA,
        )
    msg = str(e.value)
    for key in (
        "timezone:",
        "speed_unit: expected one of",
        "columns.tws: unknown canonical",
        "method: expected one of 'idw', 'rbf'",
    ):
        assert f"{WHERE}.{key}" in msg


def test_blended_spec_and_nested_key_paths(tiny_wrf, frame, station_csv) -> None:
    path = tiny_wrf()
    csvp = station_csv(
        [
            ["2018-04-24T08:00:00Z", "A", 45.0, 10.0, 12, 160],
            ["2018-04-24T08:30:00Z", "A", 45.0, 10.0, 12, 160],
        ]
    )
    assert csvp.parent == path.parent
    f = build(
        {
            "type": "blended",
            "wrf": {"path": path.name},
            "stations": {"path": csvp.name, "speed_unit": "kn"},
            "length_scale_m": 3000,
        },
        frame=frame,
        base_dir=path.parent,
    )
    assert isinstance(f, BlendedWind) and f.length_scale_m == 3000
    s, d = wind_speed_direction(*f.sample(T0 + 900.0, 0.0, 0.0))
    assert float(s) == pytest.approx(12 * KNOT, rel=1e-5) and float(d) == pytest.approx(160, 1e-3)
    with pytest.raises(InputError) as e:
        build(
            {
                "type": "blended",
                "wrf": {"path": path.name, "heigth_m": 2},
                "stations": {"speed_unit": "kn"},
                "length_scale_m": -1,
            },
            frame=frame,
            base_dir=path.parent,
        )
    msg = str(e.value)
    assert f"{WHERE}.wrf.heigth_m: unknown key; did you mean 'height_m'?" in msg
    assert f"{WHERE}.stations.path: missing required key" in msg
    assert f"{WHERE}.length_scale_m: expected a number > 0; got -1" in msg


def test_shipped_example_data_load() -> None:
    """data/ files used by the example courses go through the real readers."""
    frame = LocalFrame(43.069067, 6.198550)
    f = build(
        {
            "type": "wrf",
            "path": "hyeres-2018-04-24-synthetic-wrfout.nc",
            "height_m": 2.68,
            "time_step_min": 10,
        },
        frame=frame,
        base_dir=ROOT / "data",
        crop_bbox=(-2000.0, 500.0, -500.0, 1000.0),
        time_window=(T0 + 7800, T0 + 11400),
    )
    s, d = wind_speed_direction(*f.sample(T0 + 8400.0, 0.0, 0.0))  # 10:20Z
    assert 2.5 < float(s) < 4.5 and 135.0 < float(d) < 160.0  # thesis §3.8: ~3 m/s, ~147 deg
    g = build(
        {
            "type": "stations",
            "path": "trieste-coach-2018-02-15.csv",
            "speed_unit": "kn",
            "resample_s": 10,
        },
        frame=LocalFrame(45.55, 13.67),
        base_dir=ROOT / "data",
    )
    assert g.data.stations == ("coach",) and g.data.n_raw == 4300
