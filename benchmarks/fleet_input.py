"""Input for the analyze benchmark: a generated messy fleet written to a folder.

    python benchmarks/fleet_input.py [--out DIR] [--boats 60] [--minutes 45] [--seed 0]
                                     [--format gpx] [--clean] [--smoke]

Writes ``course.yaml``, one track file per boat (fixes every second, the default faults
and GPS error of ``tests/fleetgen.py`` unless ``--clean``, a 7 s tracker clock lag) and
``truth.json`` (each boat's status, start, leg ends and faults on the true clock) into
``DIR`` (default ``out/fleet-input``), then prints what it wrote, the time it took to
generate and write, and the machine's load average.  ``--smoke``: 14 boats of 10 min
into a temporary folder (a check that the script runs, for CI).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.fleetgen import FaultPlan, messy_fleet  # noqa: E402


def write_fleet(
    out: Path, boats: int, minutes: float, seed: int, fmt: str, clean: bool
) -> tuple[float, float, int, int]:
    """Generate and write the fleet; returns the generation and writing times [s], the
    tracks and the fixes written."""
    tic = time.perf_counter()
    plan = FaultPlan.clean(noise_white_m=0.7, noise_corr_m=1.5) if clean else FaultPlan()
    fleet = messy_fleet(seed, n_boats=boats, minutes=minutes, faults=plan, sample_s=(1, 1))
    gen = time.perf_counter() - tic
    tic = time.perf_counter()
    _, paths = fleet.write(out, fmt)
    (out / "truth.json").write_text(json.dumps(fleet.truth_json(), indent=1), encoding="utf-8")
    return gen, time.perf_counter() - tic, len(paths), sum(len(t) for t in fleet.tracks)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "fleet-input")
    ap.add_argument("--boats", type=int, default=60)
    ap.add_argument("--minutes", type=float, default=45.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--format", choices=("gpx", "csv"), default="gpx")
    ap.add_argument("--clean", action="store_true", help="no faults (GPS error kept)")
    ap.add_argument("--smoke", action="store_true", help="small, into a temporary folder (CI)")
    args = ap.parse_args()
    print(f"load average before: {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) if args.smoke else args.out
        boats, minutes = (14, 10.0) if args.smoke else (args.boats, args.minutes)
        gen, wrote, n, fixes = write_fleet(out, boats, minutes, args.seed, args.format, args.clean)
        print(
            f"fleet input: {n} tracks ({boats} boats, {minutes:.0f} min, 1 Hz, {fixes} fixes) "
            f"in {out}: generated in {gen:.1f} s, written in {wrote:.1f} s"
        )
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
