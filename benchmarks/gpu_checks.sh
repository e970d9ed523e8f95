#!/usr/bin/env bash
# The GPU checks of docs/performance.md, on a machine with an NVIDIA GPU and CuPy:
#   bash benchmarks/gpu_checks.sh [OUTDIR]
# runs the GPU tests (CuPy results = NumPy results) and then bench_gpu.py; logs in OUTDIR.
#   bash benchmarks/gpu_checks.sh --smoke [OUTDIR]   (the GPU tests and bench_gpu.py --smoke)
# Without an NVIDIA GPU it says so and exits with code 0 (nothing to check).
set -uo pipefail
smoke=()
if [ "${1:-}" = "--smoke" ]; then smoke=(--smoke); shift; fi
if ! nvidia-smi -L >/dev/null 2>&1; then
    echo "gpu_checks.sh: no NVIDIA GPU here (nvidia-smi lists none), nothing checked"
    exit 0
fi
out="${1:-gpu-checks}"
mkdir -p "$out"
export PYTHONUNBUFFERED=1 PYTHONPATH="${PYTHONPATH:+$PYTHONPATH:}$(pwd)"
nvidia-smi -L 2>&1 | tee "$out/device.txt"
python3 -c "import cupy, numpy, numba; print('cupy', cupy.__version__, 'numpy', numpy.__version__, 'numba', numba.__version__)" 2>&1 | tee -a "$out/device.txt"
python3 -m pytest -q -p no:cacheprovider -m gpu -rs tests/test_gpu.py 2>&1 | tee "$out/pytest-gpu.log"
python3 benchmarks/bench_gpu.py --json "$out/bench_gpu.json" "${smoke[@]}" "${@:2}" 2>&1 | tee "$out/bench_gpu.log"
