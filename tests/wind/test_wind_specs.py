"""Wind and current specs: parsed once into frozen dataclasses, built into fields from them."""

from __future__ import annotations

import dataclasses
import textwrap
from pathlib import Path

import numpy as np
import pytest
from conftest import T0

from sailroute.checks import Checker, Problems
from sailroute.course.load import load_course
from sailroute.errors import InputError
from sailroute.geo import LocalFrame
from sailroute.units import KNOT
from sailroute.wind.build import WIND_TYPES, build_current_field, build_wind_field
from sailroute.wind.specs import (
    CURRENT_KINDS,
    CURRENT_TYPES,
    WIND_KINDS,
    BlendedWindSpec,
    DiamondCurrentSpec,
    GribWindSpec,
    MeasuredWindSpec,
    NetcdfCurrentSpec,
    NetcdfWindSpec,
    StationReadSpec,
    StationsWindSpec,
    UniformCurrentSpec,
    UniformWindSpec,
    WrfWindSpec,
    check_wind_spec,
    parse_current_spec,
    parse_wind_spec,
)

WHERE = "courses/x.yaml:7: scenarios.a.wind"


def _touch(folder: Path, *names: str) -> None:
    """Empty files: parsing checks that a file is there, never what it holds."""
    for n in names:
        (folder / n).write_bytes(b"")


def _parse(spec: dict, base: Path) -> object:
    return parse_wind_spec(spec, base_dir=base, where=WHERE)


# ----------------------------------------------------------------------------- each type
def test_uniform_steady_and_table_in_si_units(tmp_path: Path) -> None:
    s = _parse({"type": "uniform", "tws_kn": 10, "twd_deg": 108}, tmp_path)
    assert s == UniformWindSpec(tws_ms=10 * KNOT, twd_deg=108.0, where=WHERE)
    t = _parse(
        {
            "type": "uniform",
            "interpolation": "previous",
            "clamp": True,
            "table": [
                {"time": "2018-04-24T10:00:00+02:00", "tws_ms": 5.0, "twd_deg": 100},
                {"time": "2018-04-24T08:30:00Z", "tws_kn": 12, "twd_deg": 110},
            ],
        },
        tmp_path,
    )
    assert isinstance(t, UniformWindSpec) and t.tws_ms is None and t.twd_deg is None
    assert t.table == ((T0, 5.0, 100.0), (T0 + 1800.0, 12 * KNOT, 110.0))  # epoch s, m/s
    assert (t.interpolation, t.clamp, t.where) == ("previous", True, WHERE)


def test_wrf_path_resolved_and_minutes_in_seconds(tmp_path: Path) -> None:
    _touch(tmp_path, "w.nc")
    s = _parse(
        {
            "type": "wrf",
            "path": "w.nc",
            "height_m": 2.68,
            "time_step_min": 10,
            "exponent_range": [0.0, 0.5],
            "levels": "model",
        },
        tmp_path,
    )
    assert isinstance(s, WrfWindSpec)
    assert s.path == (tmp_path / "w.nc").resolve() and s.path.is_absolute()
    assert (s.height_m, s.time_step_s, s.exponent_range, s.levels) == (
        2.68,
        600.0,
        (0.0, 0.5),
        "model",
    )
    assert s.margin_m is None and s.clamp is False


def test_netcdf_and_grib_keep_their_cf_keys_and_selection(tmp_path: Path) -> None:
    _touch(tmp_path, "g.nc", "g.grib2")
    n = _parse(
        {
            "type": "netcdf",
            "path": "g.nc",
            "variables": {"u": "u10", "v": "v10"},
            "time": "2018-04-24T08:00:00Z",
            "speed_unit": "kn",
            "select": {"number": 3},
        },
        tmp_path,
    )
    assert isinstance(n, NetcdfWindSpec) and n.time == T0
    assert dict(n.variables or ()) == {"u": "u10", "v": "v10"}
    assert n.select == (("number", 3),) and n.speed_unit == "kn"
    assert n.cf_keys == ("variables", "time", "speed_unit", "select")
    assert n.options()["select"] == {"number": 3} and n.options()["time_step_min"] is None
    g = _parse({"type": "grib", "path": "g.grib2", "filter": {"typeOfLevel": "surface"}}, tmp_path)
    assert type(g) is GribWindSpec and g.filter == (("typeOfLevel", "surface"),)
    assert g.cf_keys == ()


def test_stations_blended_and_measured_hold_their_parts(tmp_path: Path) -> None:
    _touch(tmp_path, "st.csv", "w.nc", "a.gpx", "b.gpx")
    s = _parse(
        {
            "type": "stations",
            "path": "st.csv",
            "position": {"lat": 45.0, "lon": 10.0},
            "missing": ["NA"],
            "station": 41008,
            "radius_m": 500,
        },
        tmp_path,
    )
    assert isinstance(s, StationsWindSpec) and s.radius_m == 500.0
    assert s.read.path == (tmp_path / "st.csv").resolve()
    assert (s.read.position, s.read.station, s.read.missing[-1]) == ((45.0, 10.0), "41008", "NA")
    assert s.read.where == WHERE  # the station keys are the spec's own
    b = _parse(
        {
            "type": "blended",
            "wrf": {"path": "w.nc", "height_m": 3},
            "stations": {"path": "st.csv"},
            "ratio_range": [0.5, 2],
        },
        tmp_path,
    )
    assert isinstance(b, BlendedWindSpec) and b.ratio_range == (0.5, 2.0)
    assert isinstance(b.wrf, WrfWindSpec) and b.wrf.height_m == 3.0
    assert b.wrf.where == WHERE + ".wrf"
    assert isinstance(b.stations, StationReadSpec) and b.stations.where == WHERE + ".stations"
    m = _parse({"type": "measured", "tracks": ["a.gpx", "b.gpx"], "resample_s": 5}, tmp_path)
    assert isinstance(m, MeasuredWindSpec) and m.resample_s == 5.0
    assert m.tracks == ((tmp_path / "a.gpx").resolve(), (tmp_path / "b.gpx").resolve())
    assert m.track_wheres == (WHERE + ".tracks[0]", WHERE + ".tracks[1]")


def test_current_types_in_si_units(tmp_path: Path) -> None:
    _touch(tmp_path, "c.nc")
    where = "x.yaml: scenarios.a.current"
    u = parse_current_spec(
        {"type": "uniform", "speed_kn": 1.5, "set_deg": 90}, base_dir=tmp_path, where=where
    )
    assert u == UniformCurrentSpec(rate_ms=1.5 * KNOT, set_deg=90.0, where=where)
    d = parse_current_spec(
        {
            "type": "diamonds",
            "high_water": "2018-04-24T08:00:00Z",
            "table": [[-6, 250, 0.4], [0, 70, 1.2]],
        },
        base_dir=tmp_path,
    )
    assert isinstance(d, DiamondCurrentSpec) and d.high_water == T0
    assert d.table == ((-6.0, 250.0, 0.4 * KNOT), (0.0, 70.0, 1.2 * KNOT))
    n = parse_current_spec(
        {"type": "netcdf", "path": "c.nc", "variables": {"u": "uo", "v": "vo"}},
        base_dir=tmp_path,
    )
    assert isinstance(n, NetcdfCurrentSpec) and n.path == (tmp_path / "c.nc").resolve()
    assert n.variables == (("u", "uo"), ("v", "vo"))


def test_parsing_reads_no_file_content_building_does(tmp_path: Path) -> None:
    _touch(tmp_path, "empty.nc")
    s = _parse({"type": "wrf", "path": "empty.nc"}, tmp_path)  # an empty file parses
    with pytest.raises(InputError, match=r"^courses/x\.yaml:7: scenarios\.a\.wind: "):
        build_wind_field(s, frame=LocalFrame(45.0, 10.0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"scenarios\.a\.wind\.path: file not found: "):
        _parse({"type": "wrf", "path": "none.nc"}, tmp_path)


def test_specs_are_frozen() -> None:
    s = UniformWindSpec(tws_ms=5.0, twd_deg=90.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.tws_ms = 6.0  # type: ignore[misc]


# ----------------------------------------------------------------------------- registry
def test_every_type_has_its_dataclass_parser_and_builder() -> None:
    assert (
        WIND_TYPES
        == tuple(WIND_KINDS)
        == (
            "uniform",
            "wrf",
            "netcdf",
            "grib",
            "stations",
            "blended",
            "measured",
        )
    )
    assert CURRENT_TYPES == tuple(CURRENT_KINDS) == ("uniform", "diamonds", "netcdf")
    for kinds in (WIND_KINDS, CURRENT_KINDS):
        for name, kind in kinds.items():
            assert kind.spec.type == name  # type: ignore[attr-defined]
            assert callable(kind.parse) and callable(kind.build)
            assert dataclasses.is_dataclass(kind.spec)
            assert kind.spec.__dataclass_params__.frozen  # type: ignore[attr-defined]
            assert "where" in {f.name for f in dataclasses.fields(kind.spec)}
    assert len({k.spec for k in WIND_KINDS.values()}) == len(WIND_KINDS)


def test_checker_variant_records_problems_and_returns_none(tmp_path: Path) -> None:
    probs = Problems("c.yaml", {"scenarios.a.wind": 7, "scenarios.a.wind.twd": 9})
    chk = Checker(probs, "scenarios.a.wind")
    assert check_wind_spec({"type": "uniform", "tws_kn": 10, "twd": 1}, chk, tmp_path) is None
    assert probs.items[0].startswith("c.yaml:9: scenarios.a.wind.twd: unknown key; did you mean")
    assert probs.items[1] == (
        "c.yaml:7: scenarios.a.wind.twd_deg: missing required key; expected a number in [0, 360]"
    )


# ----------------------------------------------------------------------------- building
def test_one_spec_built_twice_gives_equal_fields(tiny_wrf, frame, tmp_path: Path) -> None:
    path = tiny_wrf()
    spec = parse_wind_spec(
        {"type": "wrf", "path": path.name, "height_m": 3.0, "time_step_min": 5},
        base_dir=path.parent,
    )
    a = build_wind_field(spec, frame=frame)
    b = build_wind_field(spec, frame=frame)
    assert a is not b and a.coverage == b.coverage
    t = T0 + np.array([0.0, 450.0, 1500.0])
    x, y = np.array([-900.0, 0.0, 1200.0]), np.array([300.0, 0.0, -800.0])
    np.testing.assert_array_equal(np.asarray(a.sample(t, x, y)), np.asarray(b.sample(t, x, y)))
    u = parse_wind_spec({"type": "uniform", "tws_ms": 5, "twd_deg": 200}, base_dir=tmp_path)
    one, two = build_wind_field(u, frame=frame), build_wind_field(u, frame=frame)
    np.testing.assert_array_equal(one.sample(T0, 0.0, 0.0), two.sample(T0, 0.0, 0.0))
    c = parse_current_spec({"type": "uniform", "speed_ms": 1, "set_deg": 90}, base_dir=tmp_path)
    cu, cv = build_current_field(c, frame=frame).sample(T0, 0.0, 0.0)
    assert (float(cu), float(cv)) == pytest.approx((1.0, 0.0), abs=1e-12)  # set 90: east


# ----------------------------------------------------------------------------- course loader
COURSE = textwrap.dedent("""\
    name: t
    start_time: "2018-04-24T08:00:00Z"
    origin: {lat: 45.0, lon: 10.0}
    marks:
      a: {x: -100, y: 0}
      b: {x: 100, y: 0}
      top: {x: 0, y: 1000}
    lines: {start: [a, b]}
    legs:
      - {from: start, to: top, rounding: port}
      - {to: start}
    scenarios:
      steady:
        wind: {type: uniform, tws_kn: 10, twd_deg: 0}
        current:
          type: uniform
          speed_kn: 1
          set_dge: 90
      ens:
        members:
          - {type: uniform, tws_kn: 10, twd_deg: 0}
          - {type: uniform, tws_kn: 10, twd_deg: 400}
""")


def test_load_course_reports_wind_and_current_key_problems(tmp_path: Path) -> None:
    path = tmp_path / "c.yaml"
    path.write_text(COURSE, encoding="utf-8")
    with pytest.raises(InputError) as e:
        load_course(path)
    msg = str(e.value)
    assert msg.startswith(f"{path}: 3 problems in the course file")
    assert (
        f"{path}:18: scenarios.steady.current.set_dge: unknown key; did you mean 'set_deg'?"
    ) in msg
    assert f"{path}:15: scenarios.steady.current.set_deg: missing required key" in msg
    assert (
        f"{path}:22: scenarios.ens.members[1].twd_deg: expected a number in [0, 360]; got 400"
    ) in msg
    fixed = COURSE.replace("set_dge", "set_deg").replace("400", "40")
    path.write_text(fixed, encoding="utf-8")
    c = load_course(path)
    assert c.scenarios["steady"].current == UniformCurrentSpec(
        rate_ms=KNOT, set_deg=90.0, where=f"{path}:15: scenarios.steady.current"
    )
    assert dict(c.scenarios["steady"].current_given or {}) == {
        "type": "uniform",
        "speed_kn": 1,
        "set_deg": 90,
    }
    w = c.scenarios["ens#2"].wind
    assert isinstance(w, UniformWindSpec) and w.twd_deg == 40.0
    assert w.where == f"{path}:22: scenarios.ens.members[1]"
