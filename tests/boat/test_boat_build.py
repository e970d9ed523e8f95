"""Built-in polars (shipped = fresh VPP run) and the course file's ``boat:`` factory."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sailroute.boat.build import (
    BUILTIN_DECIMALS,
    BUILTIN_TWA_DEG,
    BUILTIN_TWS_KN,
    boat_from_spec,
    builtin_kind,
    builtin_names,
    builtin_polar,
    vpp_polar,
)
from sailroute.boat.io import write_pol
from sailroute.boat.kinetics import RACE, STEADY, Kinetics
from sailroute.boat.laser import CLASSES
from sailroute.errors import InputError
from sailroute.units import KNOT
from tests.conftest import ROOT


def check_shipped(name: str) -> None:
    shipped = builtin_polar(name)
    cls, kinetics = builtin_kind(name)
    fresh = vpp_polar(CLASSES[cls], kinetics=kinetics)
    np.testing.assert_array_equal(shipped.twa_deg, BUILTIN_TWA_DEG)
    np.testing.assert_allclose(shipped.tws_ms / KNOT, BUILTIN_TWS_KN, rtol=1e-15)
    # the file holds knots rounded to BUILTIN_DECIMALS: equal to half a unit of the last digit
    tol = 0.5 * 10.0**-BUILTIN_DECIMALS * KNOT * (1 + 1e-9)
    np.testing.assert_allclose(shipped.speed_ms, fresh.speed_ms, rtol=0, atol=tol)


@pytest.mark.parametrize("name", ["ilca7", "ilca7-steady"])
def test_shipped_ilca7_equals_a_fresh_vpp_run(name: str) -> None:
    check_shipped(name)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ilca6", "ilca4", "ilca6-steady", "ilca4-steady"])
def test_shipped_other_classes_equal_fresh_vpp_runs(name: str) -> None:
    check_shipped(name)


@pytest.mark.parametrize(("name", "kinetics"), [("ilca7", RACE), ("ilca7-steady", STEADY)])
def test_shipped_file_text_is_what_the_script_writes(
    tmp_path: Path, name: str, kinetics: Kinetics
) -> None:
    # byte-level: the regeneration script's writer reproduces the shipped files
    text = write_pol(
        vpp_polar(CLASSES["ilca7"], kinetics=kinetics),
        tmp_path / "x.pol",
        unit="kn",
        decimals=BUILTIN_DECIMALS,
    ).read_text()
    assert text == (ROOT / "sailroute" / "boat" / "data" / f"{name}.pol").read_text()


def test_builtin_polar_is_cached_and_named() -> None:
    assert builtin_names() == (
        "ilca4",
        "ilca4-steady",
        "ilca6",
        "ilca6-steady",
        "ilca7",
        "ilca7-steady",
    )
    a = builtin_polar()
    assert a is builtin_polar("ilca7")
    assert a.name == "ILCA 7" and a.interpolation == "pchip"
    assert builtin_polar("ILCA6").name == "ILCA 6"
    assert builtin_polar("ilca7-steady").name == "ILCA 7 steady"
    assert builtin_polar("ilca7", "linear").interpolation == "linear"
    with pytest.raises(InputError, match="unknown built-in boat 'ilca8'; expected one of"):
        builtin_polar("ilca8")


# --- boat_from_spec ------------------------------------------------------------------------


def test_spec_builtin_polar_and_vpp(tmp_path: Path) -> None:
    assert boat_from_spec({"builtin": "ilca7"}, base_dir=tmp_path, where="c.yaml") is (
        builtin_polar("ilca7")
    )
    (tmp_path / "polars").mkdir()
    (tmp_path / "polars" / "mine.pol").write_text("TWA/TWS;2;4\n45;1.0;2.0\n90;1.5;3.0\n")
    p = boat_from_spec(
        {
            "polar": "polars/mine.pol",
            "speed_unit": "m/s",
            "wind_unit": "m/s",
            "interpolation": "linear",
        },
        base_dir=tmp_path,
        where="c.yaml",
    )
    assert p.speed(4.0, 90.0) == 3.0 and p.interpolation == "linear"
    q = boat_from_spec(
        {"vpp": {"class": "ilca6", "crew_mass_kg": 64}}, base_dir=tmp_path, where="c.yaml"
    )
    assert q.name == "ILCA 6"
    r = boat_from_spec(
        {"vpp": {"class": "ilca6", "crew_mass_kg": 64}}, base_dir=tmp_path, where="c.yaml"
    )
    assert r is q  # cached per parameter set
    # a lighter sailor changes the polar
    ref = builtin_polar("ilca6")
    assert not np.allclose(q.speed(8.0, 45.0), ref.speed(8.0, 45.0))


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        (
            {"builtin": "ilca8"},
            "courses/x.yaml: boat.builtin: expected one of 'ilca4', 'ilca4-steady', 'ilca6', "
            "'ilca6-steady', 'ilca7', 'ilca7-steady'; got 'ilca8'",
        ),
        (
            {"builtin": "ilca7", "polar": "a.pol"},
            "courses/x.yaml: boat: give exactly one of 'builtin', 'polar' or 'vpp'; "
            "got builtin, polar",
        ),
        ({"name": "x"}, "give exactly one of 'builtin', 'polar' or 'vpp'; got keys \\['name'\\]"),
        (
            {"builtin": "ilca7", "crew": 70},
            "courses/x.yaml: boat.crew: unknown key for a 'builtin' boat; valid keys: "
            "allow_extrapolation, builtin, efficiency, interpolation",
        ),
        ({"polar": "missing.pol"}, "boat.polar: file not found: .*missing.pol"),
        (
            {"polar": "a.pol", "speed_unit": "furlong"},
            "boat.speed_unit: expected one of 'kn', 'm/s', 'km/h', 'mph'; got 'furlong'",
        ),
        ("ilca7", "boat: expected a mapping"),
    ],
)
def test_spec_errors_name_the_key(spec: object, message: str, tmp_path: Path) -> None:
    with pytest.raises(InputError, match=message):
        boat_from_spec(spec, base_dir=tmp_path, where="courses/x.yaml")  # type: ignore[arg-type]


def test_spec_lists_every_problem(tmp_path: Path) -> None:
    with pytest.raises(InputError) as exc:
        boat_from_spec(
            {"vpp": {"class": "ilca9", "crew_mass_kg": "heavy"}, "interpolation": "cubic"},
            base_dir=tmp_path,
            where="courses/x.yaml",
        )
    msg = str(exc.value)
    assert msg.startswith("courses/x.yaml: boat: 3 problems in the boat spec\n")
    assert "boat.interpolation: expected one of 'pchip', 'linear'; got 'cubic'" in msg
    assert "boat.vpp.class: expected one of 'ilca4', 'ilca6', 'ilca7'; got 'ilca9'" in msg
    assert "boat.vpp.crew_mass_kg: expected a number; got 'heavy'" in msg


# --- one mechanism (sailroute.checks): did-you-mean, lines, every problem at once ---------


def _message(spec: object, tmp_path: Path, **kw: object) -> str:
    with pytest.raises(InputError) as exc:
        boat_from_spec(spec, base_dir=tmp_path, where="courses/x.yaml", **kw)  # type: ignore[arg-type]
    return str(exc.value)


def test_unknown_key_of_a_builtin_boat_gets_the_course_did_you_mean(tmp_path: Path) -> None:
    msg = _message({"builtin": "ilca7", "interpolaton": "linear"}, tmp_path)
    assert msg == (
        "courses/x.yaml: boat.interpolaton: unknown key for a 'builtin' boat; "
        "did you mean 'interpolation'? valid keys: allow_extrapolation, builtin, "
        "efficiency, interpolation"
    )


def test_unknown_efficiency_key_gets_the_course_did_you_mean(tmp_path: Path) -> None:
    msg = _message({"builtin": "ilca7", "efficiency": {"upwnd": 0.9}}, tmp_path)
    assert msg == (
        "courses/x.yaml: boat.efficiency.upwnd: unknown key; did you mean "
        "'upwind'? valid keys: upwind, reach, downwind"
    )


def test_unknown_kinetics_key_and_misspelt_form_get_a_did_you_mean(tmp_path: Path) -> None:
    msg = _message({"vpp": {}, "kinetics": {"sea_age": 3}}, tmp_path)
    assert msg.startswith(
        "courses/x.yaml: boat.kinetics.sea_age: unknown key; did you mean "
        "'sea_age_h'? valid keys: fetch_m, sea_age_h, "
    )
    msg = _message({"biultin": "ilca7"}, tmp_path)
    assert msg == (
        "courses/x.yaml: boat: give exactly one of 'builtin', 'polar' or 'vpp'; "
        "got keys ['biultin'] (did you mean 'builtin'?)"
    )


def test_efficiency_and_other_boat_problems_are_reported_together(tmp_path: Path) -> None:
    # before, the efficiency check raised alone and hid the other problems
    msg = _message(
        {"builtin": "ilca8", "efficiency": {"reach": 1.6}, "interpolation": "cubic"}, tmp_path
    )
    assert msg.splitlines() == [
        "courses/x.yaml: boat: 3 problems in the boat spec",
        "  - courses/x.yaml: boat.interpolation: expected one of 'pchip', 'linear'; got 'cubic'",
        "  - courses/x.yaml: boat.efficiency.reach: expected a speed factor in (0, 1.5] "
        "(1.0 = the polar as is); got 1.6",
        "  - courses/x.yaml: boat.builtin: expected one of 'ilca4', 'ilca4-steady', "
        "'ilca6', 'ilca6-steady', 'ilca7', 'ilca7-steady'; got 'ilca8' "
        "(did you mean 'ilca7'?)",
    ]


def test_boat_problems_carry_their_line_in_a_course_file(tmp_path: Path) -> None:
    from sailroute.course.load import build_boat, load_course

    course = tmp_path / "c.yaml"
    course.write_text(
        "name: lines\n"  # 1
        "start_time: '2024-05-01T12:00:00+02:00'\n"  # 2
        "marks:\n"  # 3
        "  pin: {lat: 45.0, lon: 13.0}\n"  # 4
        "  boat: {lat: 45.0, lon: 13.002}\n"  # 5
        "  top: {lat: 45.009, lon: 13.001}\n"  # 6
        "lines:\n"  # 7
        "  start: [pin, boat]\n"  # 8
        "legs:\n"  # 9
        "  - {to: top, rounding: port}\n"  # 10
        "scenarios:\n"  # 11
        "  steady: {type: uniform, tws_kn: 10, twd_deg: 0}\n"  # 12
        "boat:\n"  # 13
        "  builtin: ilca7\n"  # 14
        "  efficiency:\n"  # 15
        "    upwind: 0.9\n"  # 16
        "    reachh: 1.0\n"  # 17
        "  allow_extrapolation: yes please\n",  # 18
        encoding="utf-8",
    )
    with pytest.raises(InputError) as exc:
        build_boat(load_course(course))
    assert str(exc.value).splitlines() == [
        f"{course}:13: boat: 2 problems in the boat spec",
        f"  - {course}:18: boat.allow_extrapolation: expected true or false; got 'yes please'",
        f"  - {course}:17: boat.efficiency.reachh: unknown key; did you mean 'reach'? "
        "valid keys: upwind, reach, downwind",
    ]
