"""Every script in benchmarks/ runs: each with ``--smoke`` (a tiny size, seconds) as a
fresh process, exit 0 and its recognisable line of output.  The three slowest (about 7-10 s
each on a shared 2-core machine) are marked ``slow``; the others take about 20 s together.
"""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from tests.conftest import ROOT, SHARED_REAL

BENCH = ROOT / "benchmarks"
SLOW = pytest.mark.slow

CASES = [
    ("bench_polar.py", r"^Polar\.speed \[pchip \]: +\d+ us per 1e5 lookups"),
    ("bench_polar_learn.py", r"^\| gps \| [\d.]+ \| [\d.]+ \| \d+ \| \d+ \|$"),
    pytest.param(
        "polar_learn_validation.py",
        r"^\| Snipe P02 \(learned on P01\) \| 8 kn 110 deg"
        if SHARED_REAL.is_dir()
        else r"^Snipe: .* not present: left out$",
        marks=SLOW,
    ),
    ("bench_wind.py", r"^  wrf bilinear \+ linear time +[\d.]+ ms +[\d.]+ Mpoints/s$"),
    (
        "bench_polar_fit.py",
        r"^Tallinn 2023 vs ORC guide +14 +6\.6 %"
        if SHARED_REAL.is_dir()
        else r"^bench_polar_fit\.py: .* not present .*: nothing measured$",
    ),
    ("bench_course_io.py", r"^export gpx\+kml\+nmea +[\d.]+ ms +\(6 legs, \d+ track points\)$"),
    ("bench_isochrone.py", r"^  leg time \d+\.\d s, \d+ tacks, 0 gybes"),
    ("bench_ensemble.py", r"^  leg 1: 3/3 leg times identical; largest difference 0\.000 s"),
    (
        "race_polar_validation.py",
        r"^\| ilca7 \| Snipe P01 \(--smoke, 30 s steps\) \| 6 kn 110° \| 0\.\d{3} \| 0\.673 \|",
    ),
    ("bench_griddp.py", r"^Debski analytic wind +polar +8 +3 "),
    ("bench_multispline.py", r"^Example 1 n_r=6 n_c=8 n_ts=4 refine=1 .*L2 error per pass "),
    (
        "bench_analyze.py",
        r"^fleet: 3 boats x \d+ fixes \(1 Hz, \d+ min\), read \+ analyse \+ write: ",
    ),
    (
        "bench_infer_wind.py",
        r"^infer_wind, 3 boats, \d+ points, with polar: [\d.]+ ms "
        r"\(best of 1\); TWD RMS \d\.\d\d°$",
    ),
    (
        "bench_fleet_wind.py",
        r"^fleet field, 3 boats x 20 min at 1 Hz: build [\d.]+ s"
        if SHARED_REAL.is_dir()
        else r"^bench_fleet_wind\.py: .* not present .*: nothing measured$",
    ),
    ("bench_gpu.py", r"^(bench_gpu\.py: no GPU here, nothing measured: |GPU .* GiB; CPU )"),
    (
        "fleet_input.py",
        r"^fleet input: 16 tracks \(14 boats, 10 min, 1 Hz, \d+ fixes\) in .*: generated in "
        r"[\d.]+ s, written in [\d.]+ s$",
    ),
    ("gpu_checks.sh", r"^(gpu_checks\.sh: no NVIDIA GPU here|cupy \d)"),
    ("bench_obstacles.py", r"^  ratio \d+\.\d\d \(target <= 1\.30\)$"),
    pytest.param(
        "bench_strategy.py",
        r"^SDP 101 x 40 rows x 2 tacks x 19 shifts, .*"
        r"E\[T\] = \d+\.\d s$",
        marks=SLOW,
    ),
    pytest.param("bench_deadline.py", r"^  Monte Carlo 200 runs/policy ", marks=SLOW),
    pytest.param(
        "bands_calibration.py",
        r"^\| Snipe Valencia P01 \| TWS 1\.0 kn, TWD 10° \| "
        r"6 legs \(boat 1, boat 2\) \| \d/6 = \d+ % \| \d+ s \(",
        marks=SLOW,
    ),
    pytest.param("bench_plan.py", r"^same leg times to 1e-06 s: yes$", marks=SLOW),
    pytest.param(
        "bench_band_cost.py",
        r"^the bands cost \*\*\d+\.\d single plans\*\* in CPU \(pairs ",
        marks=SLOW,
    ),
    pytest.param(
        "bench_startup.py",
        r"^outputs \(plan's files, every command's standard output\) the same bytes as B: yes$",
        marks=SLOW,
    ),
    pytest.param(
        "bench_live.py",
        r"^  step -> route in the new wind \(race time\): median [\d.]+ s, max [\d.]+ s",
        marks=SLOW,
    ),
    pytest.param(
        "bench_peers.py", r"^- expansion and arrival test \(`_expand`\): [\d.]+ %$", marks=SLOW
    ),
]


def test_every_script_is_listed():
    listed = {c.values[0] if hasattr(c, "values") else c[0] for c in CASES}
    assert listed == {p.name for p in BENCH.iterdir() if p.suffix in (".py", ".sh")}


@pytest.mark.parametrize(("script", "line"), CASES)
def test_benchmark_runs_with_smoke(script, line, tmp_path):
    path = BENCH / script
    cmd = (
        ["bash", str(path), "--smoke", str(tmp_path / "gpu")]
        if script.endswith(".sh")
        else [sys.executable, str(path), "--smoke"]
    )
    res = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    assert re.search(line, res.stdout, flags=re.MULTILINE), res.stdout[-2000:]
    assert "Traceback" not in res.stderr
