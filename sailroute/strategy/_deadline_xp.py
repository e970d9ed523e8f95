"""Sparse rows of the deadline solver on another array module (CuPy: the GPU engine).

The NumPy path of :func:`sailroute.strategy.deadline.solve_deadline` multiplies
node-major CSR rows with SciPy, whose mat-vec sums the entries of a row in order,
starting from 0 (``s += a x``).  :class:`DeviceRows` does the same sum where the rows
and the slice live on another array module:

- on CuPy, one CUDA thread per row, with round-to-nearest multiplies and adds that the
  compiler may not fuse into FMAs (``__fmul_rn``, ``__fadd_rn``), so the GPU policy is
  the NumPy policy bit for bit (``tests/test_gpu.py`` checks it on a GPU);
- on any other module (the tests' stand-in for NumPy), with whole-array operations in
  the same order.

Everything else of a budget slice (the max over the controls, the switch, the clip, the
keep) is the NumPy path's code run on the array module.  CuPy is optional
(``pip install 'sailroute[gpu]'``); this module imports it only when a kernel is needed.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from types import ModuleType
from typing import Any

import numpy as np

from sailroute.backend import xp_name

THREADS = 256
"""CUDA threads per block of the row kernel."""

_SOURCE = r"""
extern "C" __global__ void {name}(const {t}* __restrict__ data,
                                  const int* __restrict__ cols,
                                  const {t}* __restrict__ x,
                                  const long long e0, const long long n_rows,
                                  const int per_row, {t}* __restrict__ out) {{
    const long long r = (long long)blockIdx.x * blockDim.x + threadIdx.x;
    if (r >= n_rows) return;
    const long long e = e0 + r * per_row;
    {t} s = 0;
    for (int k = 0; k < per_row; ++k) s = {add}(s, {mul}(data[e + k], x[cols[e + k]]));
    out[r] = s;
}}
"""
_OPS = {
    "float32": ("float", "__fadd_rn", "__fmul_rn"),
    "float64": ("double", "__dadd_rn", "__dmul_rn"),
}


@lru_cache(maxsize=2)
def _kernel(dtype_name: str) -> Any:
    """The compiled row kernel for ``float32`` or ``float64`` (CuPy compiles it once)."""
    import cupy

    t, add, mul = _OPS[dtype_name]
    name = f"deadline_rows_{t}"
    return cupy.RawKernel(_SOURCE.format(name=name, t=t, add=add, mul=mul), name)


@dataclass(frozen=True, eq=False)
class DeviceRows:
    """``rows_per_node`` rows of ``per_row`` entries for every node, on array module ``xp``.

    The layout of ``deadline_rows._RowOperator`` (node-major, the entries of a row adjacent
    and in the order of the sum), held as flat ``data`` (value dtype) and ``cols``
    (int32) arrays of ``xp``.
    """

    data: Any
    cols: Any
    rows_per_node: int
    per_row: int
    xp: ModuleType

    @classmethod
    def of(cls, cols: Any, vals: Any, xp: ModuleType) -> DeviceRows:
        """From ``cols`` and ``vals`` of shape ``(n_nodes, rows_per_node, per_row)``
        (NumPy or ``xp`` arrays; copied to ``xp``)."""
        _, rows_per_node, per_row = cols.shape
        return cls(
            xp.ascontiguousarray(xp.asarray(vals).reshape(-1)),
            xp.ascontiguousarray(xp.asarray(cols).reshape(-1).astype(np.int32, copy=False)),
            int(rows_per_node),
            int(per_row),
            xp,
        )

    @classmethod
    def from_host(cls, op: Any, xp: ModuleType) -> DeviceRows:
        """A copy on ``xp`` of a ``deadline_rows._RowOperator`` (the same layout)."""
        return cls(xp.asarray(op.data), xp.asarray(op.indices), op.rows_per_node, op.per_row, xp)

    def apply(self, x: Any, node_lo: int, node_hi: int) -> Any:
        """Rows of nodes ``node_lo .. node_hi - 1`` times ``x`` (an ``xp`` array of the
        value dtype), shape ``(nodes, rows_per_node)``."""
        xp, per_row = self.xp, self.per_row
        n_rows = (node_hi - node_lo) * self.rows_per_node
        e0 = node_lo * self.rows_per_node * per_row
        if xp_name(xp) == "cupy":
            out = xp.empty(n_rows, dtype=self.data.dtype)
            if n_rows > 0:
                blocks = (n_rows + THREADS - 1) // THREADS
                _kernel(self.data.dtype.name)(
                    (blocks,),
                    (THREADS,),
                    (
                        self.data,
                        self.cols,
                        x,
                        np.int64(e0),
                        np.int64(n_rows),
                        np.int32(per_row),
                        out,
                    ),
                )
        else:
            d = self.data[e0 : e0 + n_rows * per_row].reshape(n_rows, per_row)
            c = self.cols[e0 : e0 + n_rows * per_row].reshape(n_rows, per_row)
            out = d[:, 0] * x[c[:, 0]]
            for k in range(1, per_row):
                out = out + d[:, k] * x[c[:, k]]
        return out.reshape(node_hi - node_lo, self.rows_per_node)
