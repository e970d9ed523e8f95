"""Shared fixtures and paths for the test suite."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TypeVar

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
