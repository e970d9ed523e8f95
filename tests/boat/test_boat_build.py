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
    text = write_pol(vpp_polar(CLASSES["ilca7"], kinetics=kinetics), tmp_path / "x.pol",
                     unit="kn", decimals=BUILTIN_DECIMALS).read_text()
    assert text == (ROOT / "sailroute" / "boat" / "data" / f"{name}.pol").read_text()


def test_builtin_polar_is_cached_and_named() -> None:
    assert builtin_names() == ("ilca4", "ilca4-steady", "ilca6", "ilca6-steady", "ilca7",
                               "ilca7-steady")
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
        builtin_polar("ilca7"))
    (tmp_path / "polars").mkdir()
    (tmp_path / "polars" / "mine.pol").write_text("TWA/TWS;2;4\n45;1.0;2.0\n90;1.5;3.0\n")
    p = boat_from_spec({"polar": "polars/mine.pol", "speed_unit": "m/s", "wind_unit": "m/s",
                        "interpolation": "linear"}, base_dir=tmp_path, where="c.yaml")
    assert p.speed(4.0, 90.0) == 3.0 and p.interpolation == "linear"
    q = boat_from_spec({"vpp": {"class": "ilca6", "crew_mass_kg": 64}}, base_dir=tmp_path,
                       where="c.yaml")
    assert q.name == "ILCA 6"
    r = boat_from_spec({"vpp": {"class": "ilca6", "crew_mass_kg": 64}}, base_dir=tmp_path,
                       where="c.yaml")
    assert r is q  # cached per parameter set
    # a lighter sailor changes the polar
    ref = builtin_polar("ilca6")
    assert not np.allclose(q.speed(8.0, 45.0), ref.speed(8.0, 45.0))


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ({"builtin": "ilca8"},
         "courses/x.yaml: boat.builtin: expected one of 'ilca4', 'ilca4-steady', 'ilca6', "
         "'ilca6-steady', 'ilca7', 'ilca7-steady'; got 'ilca8'"),
        ({"builtin": "ilca7", "polar": "a.pol"},
         "courses/x.yaml: boat: give exactly one of 'builtin', 'polar' or 'vpp'; "
         "got builtin, polar"),
        ({"name": "x"}, "give exactly one of 'builtin', 'polar' or 'vpp'; got keys \\['name'\\]"),
        ({"builtin": "ilca7", "crew": 70},
         "boat.crew: unknown key for a 'builtin' boat; allowed: 'allow_extrapolation', "
         "'builtin', 'efficiency', 'interpolation'"),
        ({"polar": "missing.pol"}, "boat.polar: file '.*missing.pol' not found"),
        ({"polar": "a.pol", "speed_unit": "furlong"},
         "boat.speed_unit: expected one of 'kn', 'm/s', 'km/h', 'mph'; got 'furlong'"),
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
            base_dir=tmp_path, where="courses/x.yaml",
        )
    msg = str(exc.value)
    assert msg.startswith("courses/x.yaml: 3 problems")
    assert "boat.interpolation: expected one of 'pchip', 'linear'; got 'cubic'" in msg
    assert "boat.vpp.class: expected one of 'ilca4', 'ilca6', 'ilca7'; got 'ilca9'" in msg
    assert "boat.vpp.crew_mass_kg: expected a number; got 'heavy'" in msg
