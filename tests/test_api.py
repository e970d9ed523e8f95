"""The curated ``sailroute`` namespace (docs/api.md) and its thin wrappers (sailroute/api.py)."""

from __future__ import annotations

import ast
import dataclasses
import importlib
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sailroute
from sailroute.boat.build import vpp_polar
from sailroute.boat.kinetics import RACE
from sailroute.boat.laser import ILCA6, ILCA7
from sailroute.errors import InputError
from tests.conftest import COURSES, ROOT, TESTS_DATA

HEAVY = ("numpy", "scipy", "matplotlib", "netCDF4", "pyproj", "yaml")


def _modules_after(code: str) -> list[str]:
    """Top-level packages among ``HEAVY`` imported by ``code`` in a fresh interpreter."""
    probe = (
        f"import sys\n{code}\n"
        f"print(__import__('json').dumps(sorted({{m.split('.')[0] for m in sys.modules}}"
        f" & set({list(HEAVY)!r}))))"
    )
    out = subprocess.run(
        [sys.executable, "-c", probe],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_import_sailroute_imports_nothing_heavy() -> None:
    assert _modules_after("import sailroute") == []


def test_cli_start_up_imports_no_numerical_stack() -> None:
    # `sailroute --help` imports sailroute.cli: it must not pay for NumPy/SciPy/matplotlib
    loaded = _modules_after("import sailroute.cli")
    assert not {"numpy", "scipy", "matplotlib"} & set(loaded), loaded


def test_first_access_imports_only_what_the_name_needs() -> None:
    # a course loads without matplotlib; the names are resolved on first use
    loaded = _modules_after("import sailroute\nsailroute.load_course\nsailroute.Polar")
    assert "numpy" in loaded
    assert "matplotlib" not in loaded


def test_every_public_name_resolves_to_its_module_object() -> None:
    exports = sailroute._EXPORTS
    assert sorted(sailroute.__all__) == sorted(["__version__", *exports])  # no repeats
    assert len(sailroute.__all__) == len(exports) + 1
    for name, module in exports.items():
        obj = getattr(sailroute, name)
        assert obj is getattr(importlib.import_module(module), name), name
        assert name in dir(sailroute)
    assert sailroute.__version__ == "0.1.0"


def test_type_checking_imports_match_the_lazy_table() -> None:
    tree = ast.parse((ROOT / "sailroute" / "__init__.py").read_text(encoding="utf-8"))
    guarded = next(
        n
        for n in tree.body
        if isinstance(n, ast.If) and isinstance(n.test, ast.Name) and n.test.id == "TYPE_CHECKING"
    )
    imported = {
        alias.name: node.module
        for node in guarded.body
        if isinstance(node, ast.ImportFrom)
        for alias in node.names
    }
    assert imported == sailroute._EXPORTS


def test_api_reference_documents_every_public_name() -> None:
    text = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    rendered = set(__import__("re").findall(r"^::: sailroute\.(\w+)$", text, flags=8))
    assert rendered == set(sailroute._EXPORTS)


def test_unknown_name_is_an_attribute_error_that_points_to_all() -> None:
    assert not hasattr(sailroute, "no_such_name")
    with pytest.raises(AttributeError, match=r"no attribute 'plan'.*sailroute.__all__"):
        sailroute.__getattr__("plan")  # a module, not a public name


# --- open_wind ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def minimal() -> sailroute.Course:
    return sailroute.load_course(TESTS_DATA / "course" / "minimal.yaml")


def test_open_wind_uniform_from_keywords(minimal: sailroute.Course) -> None:
    wind = sailroute.open_wind(
        minimal, {"type": "uniform", "tws_kn": 5}, tws_kn=10, twd_deg=108
    )  # keywords win over the mapping
    u, v = wind.sample(minimal.start_epoch, 0.0, 0.0)
    s = 10 * 1852 / 3600
    # FROM 108°: the air moves towards 288°
    assert float(u) == pytest.approx(-s * math.sin(math.radians(108)), abs=1e-12)
    assert float(v) == pytest.approx(-s * math.cos(math.radians(108)), abs=1e-12)


def test_open_wind_resolves_paths_against_base_dir(minimal: sailroute.Course) -> None:
    hyeres = sailroute.load_course(COURSES / "hyeres-r1.yaml")
    by_path = sailroute.open_wind(
        hyeres,
        type="wrf",
        height_m=2.68,
        path=ROOT / "data" / "hyeres-2018-04-24-synthetic-wrfout.nc",
    )
    by_name = sailroute.open_wind(
        hyeres,
        {"type": "wrf", "height_m": 2.68, "path": "hyeres-2018-04-24-synthetic-wrfout.nc"},
        base_dir=ROOT / "data",
    )
    t = hyeres.start_epoch + np.array([0.0, 1800.0])
    np.testing.assert_array_equal(
        by_path.sample(t, -900.0, 300.0), by_name.sample(t, -900.0, 300.0)
    )


def test_open_wind_errors_teach(minimal: sailroute.Course) -> None:
    with pytest.raises(
        InputError,
        match=r"give a wind spec, e\.g\. open_wind\(course, "
        r"type='uniform'",
    ):
        sailroute.open_wind(minimal)
    with pytest.raises(InputError, match=r"open_wind\(uniform\).*twd_deg"):
        sailroute.open_wind(minimal, type="uniform", tws_kn=10)


# --- plan_with_wind ----------------------------------------------------------------


def test_plan_with_wind_equals_plan_course_in_the_same_wind(minimal: sailroute.Course) -> None:
    planned = sailroute.plan_course(minimal, "north").plan
    wind = sailroute.open_wind(minimal, type="uniform", tws_kn=10, twd_deg=0)
    mine = sailroute.plan_with_wind(minimal, wind, name="north")
    assert isinstance(mine, sailroute.PlannedCourse)
    assert mine.plan.scenario == "north" and mine.notes == ()
    assert [leg.time_s for leg in mine.plan.legs] == [leg.time_s for leg in planned.legs]
    assert mine.plan.total_time_s == pytest.approx(mine.plan.t_end - mine.plan.t_start, abs=1e-9)


def test_plan_with_wind_refuses_wind_above_the_polar(minimal: sailroute.Course) -> None:
    gale = sailroute.open_wind(minimal, type="uniform", tws_kn=40, twd_deg=0)
    with pytest.raises(InputError, match=r"plan_with_wind\(gale\).*polar"):
        sailroute.plan_with_wind(minimal, gale, name="gale")


# --- vpp -----------------------------------------------------------------------------

TWS = (3.0, 5.0)
TWA = (40.0, 90.0, 150.0)


def test_vpp_is_the_vpp_polar_of_the_class() -> None:
    polar = sailroute.vpp("ilca7", tws_ms=np.array(TWS), twa_deg=list(TWA))
    ref = vpp_polar(ILCA7, TWS, TWA)
    np.testing.assert_array_equal(polar.speed_ms, ref.speed_ms)
    assert polar.speed_ms.shape == (3, 2)
    six = sailroute.vpp({"class": "ilca6"}, tws_ms=TWS, twa_deg=TWA)
    np.testing.assert_array_equal(six.speed_ms, vpp_polar(ILCA6, TWS, TWA).speed_ms)


def test_vpp_crew_mass_and_race_kinetics() -> None:
    light = sailroute.vpp("ilca7", crew_mass_kg=60, tws_ms=TWS, twa_deg=TWA)
    ref = vpp_polar(dataclasses.replace(ILCA7, crew_mass_kg=60.0), TWS, TWA)
    np.testing.assert_array_equal(light.speed_ms, ref.speed_ms)
    assert not np.array_equal(light.speed_ms, vpp_polar(ILCA7, TWS, TWA).speed_ms)
    race = sailroute.vpp("ilca7", tws_ms=(6.0,), twa_deg=TWA, kinetics="race")
    np.testing.assert_array_equal(
        race.speed_ms, vpp_polar(ILCA7, (6.0,), TWA, kinetics=RACE).speed_ms
    )
    steady = sailroute.vpp("ilca7", tws_ms=(6.0,), twa_deg=TWA)
    assert np.max(np.abs(race.speed_ms - steady.speed_ms)) > 0.1  # the race model matters


def test_vpp_errors_teach(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"crew_mass_kg = 500: expected a sailor mass in 20-200"):
        sailroute.vpp("ilca7", crew_mass_kg=500)
    with pytest.raises(InputError, match=r"vpp: kinetics: expected 'race', 'steady'"):
        sailroute.vpp("ilca7", kinetics="fast")
    with pytest.raises(InputError, match="boat must be a class name"):
        sailroute.vpp(7)
    with pytest.raises(InputError, match=str(tmp_path / "nope.yaml")):
        sailroute.vpp(tmp_path / "nope.yaml")
