"""Paths and markers of the wind tests (mirrors ``tests/conftest.py``; importable from here
because pytest puts this folder on ``sys.path`` for its test modules)."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
WIND_DATA = ROOT / "tests" / "data" / "wind"
SHARED_REAL = ROOT.parent / "shared" / "data" / "real"

requires_shared = [
    pytest.mark.shared,
    pytest.mark.skipif(not SHARED_REAL.is_dir(), reason="../shared/data/real not present"),
]
