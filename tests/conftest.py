"""Shared fixtures and paths for the test suite."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
TESTS_DATA = ROOT / "tests" / "data"
SHARED_REAL = ROOT.parent / "shared" / "data" / "real"

requires_shared = pytest.mark.skipif(
    not SHARED_REAL.is_dir(), reason="../shared/data/real not present"
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
