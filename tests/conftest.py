"""Shared fixtures and paths for the test suite."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
COURSES = ROOT / "courses"
TESTS_DATA = ROOT / "tests" / "data"
WIND_DATA = TESTS_DATA / "wind"
SHARED_REAL = ROOT.parent / "shared" / "data" / "real"

F = TypeVar("F")


def requires_shared(test: F) -> F:
    """Mark a test ``shared`` (reads ../shared/data/real) and skip it when that is absent."""
    skip = pytest.mark.skipif(not SHARED_REAL.is_dir(), reason="../shared/data/real not present")
    return pytest.mark.shared(skip(test))


def python_c(code: str, env: Mapping[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """``python -c code`` in a fresh process from the repository root (exit 0 checked):
    for what a process imports or sets as it starts."""
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env, check=True
    )


def pytest_report_header(config: pytest.Config) -> list[str]:
    """Print dependency versions in the pytest header."""
    import matplotlib
    import netCDF4
    import pyproj
    import scipy
    import typer

    return [
        f"numpy {np.__version__}, scipy {scipy.__version__}, netCDF4 {netCDF4.__version__}, "
        f"pyproj {pyproj.__version__}, matplotlib {matplotlib.__version__}, "
        f"typer {typer.__version__}"
    ]


@pytest.fixture(scope="session")
def aot_module() -> Any:
    """The ahead-of-time module of the isochrone step's kernels, built where the router
    keeps it (numba's cache folder) unless it is there already: about 12 s of CPU once,
    as on a first compiled use after an install."""
    pytest.importorskip("numba")
    from sailroute.routing import isochrone_aot, isochrone_fast

    folder = isochrone_fast._cache_folder()
    if folder is None or not isochrone_aot.can_build():
        pytest.skip("the kernels cannot be compiled ahead of time here (no C compiler)")
    module = isochrone_aot.load(folder)
    if module is None:
        isochrone_aot.build(folder, isochrone_fast._just_in_time())
        module = isochrone_aot.load(folder)
    assert module is not None
    return module


@pytest.fixture(params=["jit", "aot"])
def compiled_kernels(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """The compiled isochrone steps of a test through numba's just-in-time kernels, then
    through the module compiled ahead of time, every call of which must fit its
    signatures (a call handed on to the just-in-time kernels fails the test)."""
    pytest.importorskip("numba")
    from sailroute.routing import isochrone_aot, isochrone_fast

    if request.param == "jit":
        kernels: Any = isochrone_fast._just_in_time()
    else:
        module = request.getfixturevalue("aot_module")
        kernels = isochrone_aot.Kernels(module, _no_handing_on)
    monkeypatch.setattr(isochrone_fast._Usage, "kernels", kernels)
    return str(request.param)


def _no_handing_on() -> Any:
    pytest.fail("a call the ahead-of-time kernels were not compiled for (SIGNATURES)")
