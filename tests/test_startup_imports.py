"""What a plan's start-up imports: the readers and libraries of its own course only.

A course without a race area and a scenario of uniform wind loads, builds its wind and
routes with neither shapely, the gridded wind, the readers (WRF, CF NetCDF, stations,
NDBC, blended), ``numpy.ma`` (on the NumPy step) nor pydantic; ``sailroute.wind`` still
names every source; the command shortens the idle spin of OpenBLAS's threads.
"""

from __future__ import annotations

import importlib
import os

import pytest

import sailroute.wind
from tests.conftest import python_c

NOT_FOR_A_UNIFORM_PLAN = (
    "pydantic",
    "shapely",
    "numpy.ma",
    "sailroute.wind.grid",
    "sailroute.wind.wrf",
    "sailroute.wind.cf",
    "sailroute.wind.stations",
    "sailroute.wind.stationread",
    "sailroute.wind.ndbc",
    "sailroute.wind.blended",
)


def test_a_uniform_plan_of_hyeres_imports_no_reader_shapely_or_pydantic(tmp_path) -> None:
    # the course has wrf scenarios (parsed, not built) and no race area
    code = (
        "import sys\n"
        "from sailroute.cli import main\n"
        f"sys.argv = ['sailroute', 'plan', 'courses/hyeres-r1.yaml', '--no-plots', '-q',"
        f" '-o', {str(tmp_path)!r}]\n"
        "try:\n    main()\nexcept SystemExit as e:\n    assert not e.code, e.code\n"
        f"print([m for m in {NOT_FOR_A_UNIFORM_PLAN!r} if m in sys.modules])\n"
        "print('numba' in sys.modules)\n"
    )
    res = python_c(code)
    *_, imported, compiled = res.stdout.splitlines()
    # numba's dispatch imports numpy.ma itself (typeof checks for masked arrays)
    allowed = "['numpy.ma']" if compiled == "True" else "[]"
    assert imported in ("[]", allowed), res.stdout + res.stderr
    assert (tmp_path / "route.gpx").is_file()


@pytest.mark.parametrize("name", sailroute.wind.__all__)
def test_the_wind_package_names_each_source(name: str) -> None:
    module = importlib.import_module(sailroute.wind._EXPORTS[name])
    assert getattr(sailroute.wind, name) is getattr(module, name)


def test_the_wind_package_lists_its_names_once() -> None:
    assert sorted(sailroute.wind.__all__) == sorted(sailroute.wind._EXPORTS)
    with pytest.raises(AttributeError, match=r"'sailroute\.wind' has no attribute 'open_wfr'"):
        _ = sailroute.wind.open_wfr


@pytest.mark.parametrize(("given", "used"), [(None, "22"), ("28", "28")])
def test_the_command_shortens_openblas_idle_spin_unless_told(given: str | None, used: str) -> None:
    # before NumPy loads (OpenBLAS reads it then); a value in the environment is kept
    code = (
        "import os, sys\n"
        "from sailroute.__main__ import main\n"
        "sys.argv = ['sailroute', '--version']\n"
        "try:\n    main()\nexcept SystemExit:\n    pass\n"
        "print(os.environ['OPENBLAS_THREAD_TIMEOUT'], 'numpy' in sys.modules)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_THREAD_TIMEOUT"}
    if given is not None:
        env["OPENBLAS_THREAD_TIMEOUT"] = given
    res = python_c(code, env)
    assert res.stdout.split()[-2:] == [used, "False"], res.stdout + res.stderr


def test_bands_without_plots_import_no_page_writer_or_learned_polar(tmp_path) -> None:
    # the page writer (and shapely behind its charts) only where plots are written; the
    # learned polar's modules only where the course's boat is a learned polar
    code = (
        "import sys\n"
        "from sailroute.cli import main\n"
        "sys.argv = ['sailroute', 'plan', 'courses/hyeres-r1.yaml', '--ensemble', '3',"
        f" '--no-plots', '-q', '-o', {str(tmp_path)!r}]\n"
        "try:\n    main()\nexcept SystemExit as e:\n    assert not e.code, e.code\n"
        "names = ('sailroute.report.page_render', 'shapely', 'sailroute.boat.learn',"
        " 'sailroute.boat.learnfile')\n"
        "print([m for m in names if m in sys.modules])\n"
    )
    res = python_c(code)
    assert res.stdout.splitlines()[-1] == "[]", res.stdout + res.stderr
    assert (tmp_path / "bands.json").is_file()
