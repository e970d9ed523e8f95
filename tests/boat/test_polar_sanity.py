"""Polar sanity: wind above the polar, absurd speeds, units from
file names and headers, degenerate axes, all-zero tables (docs/usage.md, "Polar sanity").

Every test here failed before the checks existed: the values were accepted silently
(clamped, read in the wrong unit) or crashed with a traceback.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest

from sailroute.boat.build import boat_from_spec, builtin_polar
from sailroute.boat.io import parse_long_csv, parse_pol, read_orc_json, read_polar, unit_from_name
from sailroute.boat.polar import MAX_BOAT_SPEED_KN, MAX_TWS_KN, Polar
from sailroute.boat.sanity import check_wind_range, peak_wind, require_speed
from sailroute.course.load import course_from_mapping
from sailroute.errors import InputError
from sailroute.planning.route import (
    RunOptions,
    check_boat_and_winds,
    compare_scenarios,
    plan_course,
)
from sailroute.progress import Progress
from sailroute.units import KMH
from sailroute.wind.analytic import AnalyticWind
from sailroute.wind.base import Coverage
from sailroute.wind.uniform import UniformWind
from tests.conftest import SHARED_REAL, TESTS_DATA, requires_shared

POL = "TWA\\TWS\t6\t12\t20\n45\t4\t5.5\t6\n90\t5\t6.5\t7.5\n150\t4.5\t6\t8\n"


def wl_course(tmp_path: Path, boat: dict, scenarios: dict) -> dict:
    """A one-lap windward-leeward course mapping (file in ``tmp_path``)."""
    return {
        "name": "sanity",
        "start_time": "2024-06-01T14:00:00+02:00",
        "template": {
            "type": "windward-leeward",
            "centre": {"lat": 43.07, "lon": 6.2},
            "twd_deg": 270,
            "leg_length_m": 400,
            "laps": 1,
            "gate_width_m": 40,
            "start_line_length_m": 80,
            "finish": "leeward",
        },
        "boat": boat,
        "scenarios": scenarios,
    }


def load(tmp_path: Path, boat: dict, scenarios: dict):
    return course_from_mapping(
        wl_course(tmp_path, boat, scenarios), source=tmp_path / "sanity.yaml"
    )


# --- 1. wind above the polar's highest TWS -----------------------------------------------


def test_uniform_wind_above_the_polar_is_an_error_with_the_numbers_and_the_fix(tmp_path):
    course = load(
        tmp_path, {"builtin": "ilca7"}, {"gale": {"type": "uniform", "tws_ms": 60, "twd_deg": 90}}
    )
    with pytest.raises(InputError) as err:
        plan_course(course)
    msg = str(err.value)
    assert "sanity.yaml" in msg and "scenarios.gale" in msg
    assert "60.0 m/s (116.6 kn)" in msg  # the wind found, both units
    assert "1.0 .. 28.0 kn" in msg and "0.51 .. 14.40 m/s" in msg  # the polar's range
    assert "a polar with higher TWS columns" in msg
    assert "allow_extrapolation: true" in msg


def test_wind_within_the_polar_passes_and_just_above_fails() -> None:
    polar = builtin_polar("ilca7")
    top = float(polar.tws_ms[-1])
    bbox, window = (0.0, 100.0, 0.0, 100.0), (0.0, 600.0)
    at_top = peak_wind(UniformWind(top, 270.0), bbox, window)
    assert check_wind_range(polar, at_top, allow_extrapolation=False, where="x") is None
    above = peak_wind(UniformWind(top + 0.01, 270.0), bbox, window)
    with pytest.raises(InputError, match="above the highest TWS column"):
        check_wind_range(polar, above, allow_extrapolation=False, where="x")


def test_allow_extrapolation_turns_the_error_into_one_warning(tmp_path):
    course = load(
        tmp_path,
        {"builtin": "ilca7", "allow_extrapolation": True},
        {"gale": {"type": "uniform", "tws_kn": 30, "twd_deg": 270}},
    )
    stream = io.StringIO()
    progress = Progress(course.n_legs, stream, enabled=False)  # --quiet still warns
    run = plan_course(course, options=RunOptions(progress=progress))
    text = stream.getvalue()
    assert text.count("warning:") == 1
    assert "30.0 kn" in text and "allow_extrapolation is true" in text
    assert run.notes and "30.0 kn" in run.notes[0]
    assert run.plan.total_time_s > 0


def test_allow_extrapolation_must_be_a_boolean(tmp_path):
    with pytest.raises(
        InputError,
        match=r"boat\.allow_extrapolation: expected true or false; "
        r"got 'yes'",
    ):
        boat_from_spec(
            {"builtin": "ilca7", "allow_extrapolation": "yes"}, base_dir=tmp_path, where="c.yaml"
        )


def test_compare_scenarios_lists_every_scenario_that_exceeds(tmp_path):
    course = load(
        tmp_path,
        {"builtin": "ilca7"},
        {
            "ok": {"type": "uniform", "tws_kn": 12, "twd_deg": 270},
            "gale": {"type": "uniform", "tws_kn": 40, "twd_deg": 270},
            "storm": {"type": "uniform", "tws_kn": 50, "twd_deg": 270},
        },
    )
    with pytest.raises(InputError) as err:
        compare_scenarios(course)
    msg = str(err.value)
    assert "the wind exceeds the polar in 2 scenarios" in msg
    assert "scenarios.gale" in msg and "40.0 kn" in msg
    assert "scenarios.storm" in msg and "50.0 kn" in msg
    assert "scenarios.ok" not in msg


def test_peak_wind_finds_a_local_gust_in_space_and_time() -> None:
    # 5 m/s everywhere, a 20 m/s gust centred 100 m east of the marks' box (inside the 250 m
    # margin) at y = 500 m, t = 1800 s; the data end at x = 1100 m, so the grid must stop there
    def func(t, x, y):
        r2 = ((x - 1100.0) / 150.0) ** 2 + ((y - 500.0) / 150.0) ** 2
        gust = 15.0 * np.exp(-r2 - ((t - 1800.0) / 200.0) ** 2)
        return -(5.0 + gust), 0.0 * t

    cover = Coverage(0.0, 3600.0, -5000.0, 1100.0, -5000.0, 5000.0)
    wind = AnalyticWind(func, cover)
    peak = peak_wind(wind, (0.0, 1000.0, 0.0, 1000.0), (0.0, 3600.0))
    assert peak.tws_ms == pytest.approx(20.0)  # grid points and 5-min times hit the centre
    assert (peak.x, peak.y, peak.t) == pytest.approx((1100.0, 500.0, 1800.0))
    with pytest.raises(
        InputError,
        match=r"20\.0 m/s \(38\.9 kn\) at x 1100 m, y 500 m, "
        r"1970-01-01T00:30:00\.000Z",
    ):
        check_wind_range(builtin_polar("ilca7"), peak, allow_extrapolation=False, where="w")


def test_station_wind_above_the_polar_names_where_and_when(tmp_path):
    # a measured-wind (stations) scenario whose wind builds to 20 m/s at the end of the race
    t0 = np.datetime64("2024-06-01T11:50:00")
    rows = ["time,station,lat,lon,speed,direction"]
    for k in range(0, 121, 5):  # 11:50 .. 13:50 UTC, every 5 min
        speed = 5.0 + 15.0 * max(0.0, (k - 10) / 90.0) if k <= 100 else 20.0
        rows.append(f"{t0 + np.timedelta64(k, 'm')}Z,coach,43.07,6.2,{speed:.3f},270")
    (tmp_path / "wind.csv").write_text("\n".join(rows) + "\n")
    course = load(
        tmp_path,
        {"builtin": "ilca7"},
        {"measured": {"wind": {"type": "stations", "path": "wind.csv", "speed_unit": "m/s"}}},
    )
    with pytest.raises(InputError) as err:
        plan_course(course)
    msg = str(err.value)
    assert "scenarios.measured" in msg
    assert "20.0 m/s (38.9 kn)" in msg and "2024-06-01T13:30:00.000Z" in msg  # race end


# --- 2. absurd polar speeds --------------------------------------------------------------


@pytest.mark.parametrize("value", ["1e6", "1e300"])
def test_absurd_boat_speed_names_line_cell_value_and_unit(value: str) -> None:
    text = POL.replace("\t6.5\t", f"\t{value}\t")
    with pytest.raises(InputError) as err:
        parse_pol(text, "fast.pol")
    msg = str(err.value)
    assert msg.startswith(f"fast.pol:3: cell 3: boat speed {float(value):g} kn")
    assert f"above {MAX_BOAT_SPEED_KN:g} kn" in msg and "65.45 kn" in msg
    assert "unit mistake" in msg and "km/h" in msg


def test_km_h_table_read_as_knots_is_refused_by_the_speed_bound() -> None:
    # an F50-like table (85 "kn") in a file that says nothing about its unit
    text = "TWA\\TWS,10,30,50\n60,20,50,70\n120,30,70,84.9\n"
    with pytest.raises(InputError, match=r"x\.csv:3: cell 4: boat speed 84\.9 kn at TWA 120"):
        parse_pol(text, "x.csv")
    p = parse_pol(text, "x.csv", speed_unit="km/h")
    assert p.speed_ms.max() == pytest.approx(84.9 * KMH)


def test_absurd_tws_column_is_refused() -> None:
    with pytest.raises(
        InputError,
        match=rf"w\.pol:1: cell 4: wind speed 120 kn .* above "
        rf"{MAX_TWS_KN:g} kn",
    ):
        parse_pol(POL.replace("\t20\n", "\t120\n", 1), "w.pol")


def test_absurd_speed_in_long_csv_and_json_names_the_line_or_key(tmp_path: Path) -> None:
    csv_text = "tws,twa,speed\n6,45,4\n6,90,1e6\n12,45,5\n12,90,6\n"
    with pytest.raises(InputError, match=r"l\.csv:3: cell 3: boat speed 1e\+06 kn"):
        parse_long_csv(csv_text, "l.csv")
    doc = {
        "format": "sailroute-polar",
        "speed_unit": "m/s",
        "twa_deg": [45, 90],
        "tws": [3, 6],
        "speed": [[2, 3], [2.5, 1e300]],
    }
    (tmp_path / "j.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match=r"j\.json: speed\[1\]\[1\]: boat speed 1e\+300 m/s"):
        read_polar(tmp_path / "j.json")


# --- 3. units from file names and headers -------------------------------------------------


@pytest.mark.parametrize(
    ("name", "unit"),
    [
        ("2502_m8_APW_HSB2_HSRW.kph.csv", "km/h"),
        ("polar_kmh.pol", "km/h"),
        ("polar.kmh.pol", "km/h"),
        ("boat_ms.csv", "m/s"),
        ("boat-mps.pol", "m/s"),
        ("j24-polars-knots.csv", "kn"),
        ("x_mph.txt", "mph"),
        ("msd_polar.pol", None),
        ("kph_2020_polar.pol", None),
        ("laser.pol", None),
        ("<polar>", None),
    ],
)
def test_unit_from_name_takes_only_the_last_unambiguous_word(name: str, unit: str | None):
    assert unit_from_name(name) == unit


def test_kph_file_name_is_read_in_km_h(tmp_path: Path) -> None:
    text = "TWA/TWS,3.6,18,36\n40,3,20,40\n90,5,30,60\n150,4,25,55\n"
    path = tmp_path / "mine.kph.csv"
    path.write_text(text)
    p = read_polar(path)
    assert p.tws_ms[0] == pytest.approx(1.0)  # 3.6 km/h
    assert p.speed_ms[1, 2] == pytest.approx(60 * KMH)
    assert read_polar(path, speed_unit="km/h").speed_ms[1, 2] == pytest.approx(60 * KMH)
    with pytest.raises(
        InputError,
        match=r"mine\.kph\.csv: speed_unit='kn' says the boat speed "
        r"unit is 'kn' but the file name 'mine\.kph\.csv' says "
        r"'km/h'; make them agree",
    ):
        read_polar(path, speed_unit="kn")


def test_header_unit_is_used_and_must_agree(tmp_path: Path) -> None:
    p = parse_pol("TWA\\TWS (m/s)\t3\t6\n45\t2\t3\n90\t2.5\t3.5\n", "h.pol")
    assert p.tws_ms[1] == 6.0 and p.speed_ms[1, 1] == 3.5
    q = parse_pol("twa/tws_kmh;18;36\n45;10;20\n90;12;25\n", "h.pol")
    assert q.tws_ms[0] == pytest.approx(5.0)
    with pytest.raises(
        InputError,
        match=r"the label cell 'TWA\\\\TWS \[km/h\]' \(line 1\) says "
        r"the boat speed unit is 'km/h' but the file name "
        r"'p_kn\.pol' says 'kn'",
    ):
        parse_pol("TWA\\TWS [km/h]\t18\t36\n45\t10\t20\n90\t12\t25\n", "p_kn.pol")


def test_long_csv_takes_the_name_unit_for_unsuffixed_columns(tmp_path: Path) -> None:
    (tmp_path / "speeds_kmh.csv").write_text("tws,twa,speed\n18,45,10\n18,90,12\n")
    p = read_polar(tmp_path / "speeds_kmh.csv")
    assert p.tws_ms[0] == pytest.approx(5.0) and p.speed_ms[1, 0] == pytest.approx(12 * KMH)
    (tmp_path / "speeds_kn.csv").write_text("tws_ms,twa,speed\n3,45,10\n3,90,12\n")
    with pytest.raises(
        InputError,
        match=r"column 'tws_ms' says the wind speed unit is 'm/s' but "
        r"the file name 'speeds_kn\.csv' says 'kn'",
    ):
        read_polar(tmp_path / "speeds_kn.csv")


def test_json_speed_unit_must_agree_with_the_name(tmp_path: Path) -> None:
    doc = {
        "format": "sailroute-polar",
        "speed_unit": "m/s",
        "twa_deg": [45, 90],
        "tws": [3],
        "speed": [[2], [2.5]],
    }
    (tmp_path / "p_kph.json").write_text(json.dumps(doc))
    with pytest.raises(
        InputError,
        match=r"its speed_unit 'm/s' says the boat speed unit is "
        r"'m/s' but the file name 'p_kph\.json' says 'km/h'",
    ):
        read_polar(tmp_path / "p_kph.json")


@requires_shared
def test_shared_f50_kph_csv_is_read_in_km_h_without_options() -> None:
    p = read_polar(SHARED_REAL / "polars/sailgp-f50/2502_m8_APW_HSB2_HSRW.kph.csv")
    assert p.tws_ms[-1] == pytest.approx(50.8 * KMH)
    assert p.speed_ms.max() == pytest.approx(84.93 * KMH)
    with pytest.raises(InputError, match="make them agree"):
        read_polar(SHARED_REAL / "polars/sailgp-f50/2502_m8_APW_HSB2_HSRW.kph.csv", speed_unit="kn")


# --- 4. degenerate axes and non-finite ORC values ------------------------------------------


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            POL.replace("\n45\t", "\n1e-320\t"),
            r"d\.pol:2: cell 1: TWA 0\.0 and 1e-320 deg are closer than 1e-06 deg",
        ),
        (
            POL.replace("\n150\t", "\n179.9999999\t"),
            r"d\.pol:4: cell 1: TWA 179\.9999999 and 180\.0 deg are closer than 1e-06 deg",
        ),
        (
            POL.replace("\t6\t12", "\t1e-320\t12"),
            r"d\.pol:1: cell 2: TWS 0\.0 and 5\.1\d*e-321 m/s are closer than 1e-06 m/s",
        ),
        (
            POL.replace("\n90\t", "\n45.0000000001\t"),
            r"d\.pol:3: cell 1: TWA 45\.0 and 45\.0000000001 deg are closer",
        ),
    ],
)
def test_too_close_axis_values_are_refused_not_a_scipy_traceback(text: str, message: str):
    with pytest.raises(InputError, match=message):
        parse_pol(text, "d.pol")


def test_polar_constructor_refuses_a_denormal_twa() -> None:
    with pytest.raises(InputError, match="closer than 1e-06 deg"):
        Polar.from_arrays(np.array([1e-320, 90.0]), np.array([5.0]), np.ones((2, 1)))


def orc_with(tmp_path: Path, old: str, new: str) -> Path:
    text = (TESTS_DATA / "boat" / "ITA_ITA455J70.json").read_text()
    doc = json.loads(text)
    raw = json.dumps(doc)
    assert old in raw
    path = tmp_path / "orc.json"
    path.write_text(raw.replace(old, new, 1))
    return path


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            '"beat_angle": [43.6',
            '"beat_angle": [1e400',
            r"orc\.json: vpp\.beat_angle\[0\]: expected an angle in \(0, 90\) deg; got inf",
        ),
        ('"beat_angle": [43.6', '"beat_angle": [Infinity', r"vpp\.beat_angle\[0\]: .*got inf"),
        ('"beat_angle": [43.6', '"beat_angle": [90', r"vpp\.beat_angle\[0\]: .*got 90\.0"),
        (
            '"angles": [52',
            '"angles": [-Infinity',
            r"orc\.json: vpp\.angles\[0\]: expected an angle in \[0, 180\] deg; got -inf",
        ),
        (
            '"run_vmg": [2.49',
            '"run_vmg": [NaN',
            r"vpp\.run_vmg\[0\]: expected a VMG >= 0 kn; got nan",
        ),
    ],
)
def test_orc_non_finite_values_name_the_key(tmp_path: Path, old: str, new: str, message: str):
    path = orc_with(tmp_path, old, new)
    with pytest.raises(InputError, match=message):
        read_orc_json(path)
    with pytest.raises(InputError, match=message):
        read_polar(path)


# --- 5. all-zero polar ------------------------------------------------------------------------


def test_all_zero_polar_file_has_no_speed(tmp_path: Path) -> None:
    path = tmp_path / "zero.pol"
    path.write_text("TWA\\TWS\t6\t12\n45\t0\t0\n90\t0\t0\n")
    with pytest.raises(
        InputError,
        match=r"zero\.pol: this polar has no speed: every boat speed "
        r"in the table is 0",
    ):
        read_polar(path)
    (tmp_path / "zero.csv").write_text("tws,twa,speed\n6,45,0\n6,90,0\n")
    with pytest.raises(InputError, match="this polar has no speed"):
        read_polar(tmp_path / "zero.csv")


def test_all_zero_polar_through_the_course_is_not_reported_as_calm(tmp_path: Path) -> None:
    (tmp_path / "zero.pol").write_text("TWA\\TWS\t6\t12\n45\t0\t0\n90\t0\t0\n")
    course = load(
        tmp_path, {"polar": "zero.pol"}, {"s": {"type": "uniform", "tws_kn": 10, "twd_deg": 270}}
    )
    with pytest.raises(InputError) as err:
        plan_course(course)
    assert "zero.pol: this polar has no speed" in str(err.value)
    assert "calm" not in str(err.value)


def test_zero_table_stays_legal_for_polar_itself_but_not_for_routing(tmp_path: Path) -> None:
    zero = Polar.from_arrays(
        np.array([0.0, 90.0, 180.0]), np.array([0.0, 5.0]), np.zeros((3, 2)), name="z"
    )
    assert zero.speed(5.0, 90.0) == 0.0  # internal use (tests, tapers) may build one
    with pytest.raises(InputError, match=r"c\.yaml:3: boat: this polar \(z\) has no speed"):
        require_speed(zero, "c.yaml:3: boat")
    course = load(
        tmp_path, {"builtin": "ilca7"}, {"s": {"type": "uniform", "tws_kn": 10, "twd_deg": 270}}
    )
    wind = UniformWind(5.0, 270.0)
    with pytest.raises(InputError, match="has no speed"):
        check_boat_and_winds(course, zero, {"s": wind})
