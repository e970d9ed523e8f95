"""Shared fixtures and paths for the test suite."""

from __future__ import annotations

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
