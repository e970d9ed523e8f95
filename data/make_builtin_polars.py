"""Regenerate the shipped ILCA polars in ``sailroute/boat/data/`` from the VPP.

Usage::

    python data/make_builtin_polars.py            # writes ilca{4,6,7}.pol (race) and
                                                  # ilca{4,6,7}-steady.pol (steady VPP)
    python data/make_builtin_polars.py --check    # exit 1 if a shipped file is stale

The grid is :data:`sailroute.boat.build.BUILTIN_TWS_KN` (1-28 kn at the sail's
centre-of-effort height) x :data:`~sailroute.boat.build.BUILTIN_TWA_DEG`
(0-180° in 2.5° steps); files are in knots with
:data:`~sailroute.boat.build.BUILTIN_DECIMALS` decimals.  The test
``tests/boat/test_builtin.py`` re-runs the VPP and compares, so the files cannot
drift from the model.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from sailroute.boat.build import BUILTIN_DECIMALS, builtin_kind, builtin_names, vpp_polar
from sailroute.boat.io import write_pol
from sailroute.boat.laser import CLASSES

DATA = Path(__file__).resolve().parents[1] / "sailroute" / "boat" / "data"


def render(name: str) -> str:
    """Text of the shipped ``.pol`` file of the built-in boat ``name``."""
    cls, kinetics = builtin_kind(name)
    polar = vpp_polar(CLASSES[cls], kinetics=kinetics)
    with tempfile.TemporaryDirectory() as tmp:
        path = write_pol(polar, Path(tmp) / f"{name}.pol", unit="kn", decimals=BUILTIN_DECIMALS)
        return path.read_text(encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    """Write (or with ``--check`` compare) the shipped polars; return the exit code."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="only compare, do not write")
    args = ap.parse_args(argv)
    stale = []
    for name in builtin_names():
        text = render(name)
        target = DATA / f"{name}.pol"
        if args.check:
            if not target.is_file() or target.read_text(encoding="utf-8") != text:
                stale.append(name)
        else:
            target.write_text(text, encoding="utf-8")
            print(f"wrote {target}")
    if stale:
        print("stale: " + ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
