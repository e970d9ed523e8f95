"""Every data file the project ships or tests with is documented, and none is unlicensed.

The folders below hold third-party or generated data.  Each file must be named in its
folder's README.md (source, commit, licence), and no file may be a copy of a file whose
licence is "none stated" in ``../shared/data/real`` (those are read in place only).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from tests.conftest import ROOT, SHARED_REAL

DATA_DIRS = (
    "data",
    "sailroute/boat/data",
    "tests/data/boat",
    "tests/data/wind",
    "tests/data/course",
)
# shared/data/real folders whose README says "Licence: none stated" (internal testing only)
UNLICENSED = (
    "wrf/ligurian-sea",
    "wind/lake-washington-sr520",
    "polars/sailgp-f50",
    "polars/j24-long-format",
    "races/sailgp-auckland-2025",
    "races/j24-lake-washington-2015",
    "races/sf-bay-yra-marks",
)


def data_files() -> list[Path]:
    out = []
    for d in DATA_DIRS:
        for p in sorted((ROOT / d).iterdir()):
            if p.is_file() and p.name != "README.md" and p.suffix != ".pyc":
                out.append(p)
    return out


def test_every_data_file_is_documented_in_its_readme() -> None:
    files = data_files()
    assert len(files) >= 25  # the folders really were found
    missing = [
        str(p.relative_to(ROOT))
        for p in files
        if p.name not in (p.parent / "README.md").read_text(encoding="utf-8")
    ]
    assert missing == []


def test_mit_and_apache_copies_carry_their_notice() -> None:
    # MIT and Apache-2.0 require the licence text to travel with the copies
    for folder, notice in (
        ("sailroute/boat/data", "LICENSE-Python-VPP.txt"),
        ("tests/data/boat", "LICENSE-Python-VPP.txt"),
        ("tests/data/boat", "LICENSE-orc-data.txt"),
        ("tests/data/wind", "LICENSE-anemomind.txt"),
        ("tests/data/wind", "LICENSE-wrf-python.txt"),
    ):
        text = (ROOT / folder / notice).read_text(encoding="utf-8")
        assert "Permission is hereby granted" in text or "Apache License" in text, notice


@pytest.mark.shared
@pytest.mark.skipif(not SHARED_REAL.is_dir(), reason="../shared/data/real not present")
def test_no_copy_of_an_unlicensed_file() -> None:
    def digest(p: Path) -> str:
        return hashlib.sha256(p.read_bytes()).hexdigest()

    banned = {
        digest(p): str(p.relative_to(SHARED_REAL))
        for d in UNLICENSED
        for p in (SHARED_REAL / d).rglob("*")
        if p.is_file() and p.name != "README.md"
    }
    assert len(banned) >= 10
    for d in UNLICENSED:  # the list above still matches the shared READMEs
        assert "none stated" in (SHARED_REAL / d / "README.md").read_text().lower(), d
    copies = {
        str(p.relative_to(ROOT)): banned[h] for p in data_files() if (h := digest(p)) in banned
    }
    assert copies == {}
