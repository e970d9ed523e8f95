"""Array backend selection: NumPy always, CuPy optionally (GPU).

The data-parallel kernels (isochrone front expansion, grid-DP row relaxation,
Monte Carlo simulation) take an array-module argument ``xp``.  This module
resolves a user choice (``"numpy"``, ``"cupy"``, ``"auto"``) to a module and
moves arrays back to the host.  CuPy is never required: CI has no GPU and the
NumPy path is complete.
"""

from __future__ import annotations

from functools import lru_cache
from types import ModuleType
from typing import Any

import numpy as np

from sailroute.errors import InputError

BACKENDS = ("numpy", "cupy", "auto")


@lru_cache(maxsize=1)
def _cupy_or_none() -> ModuleType | None:
    try:
        import cupy
    except Exception:  # ImportError, or CUDA libraries missing
        return None
    try:
        if cupy.cuda.runtime.getDeviceCount() < 1:
            return None
    except Exception:
        return None
    return cupy


def get_xp(name: str = "numpy") -> ModuleType:
    """Resolve a backend name to an array module.

    Parameters
    ----------
    name : {"numpy", "cupy", "auto"}
        ``auto`` picks CuPy when a GPU is usable, else NumPy.

    Returns
    -------
    module
        ``numpy`` or ``cupy``.

    Raises
    ------
    InputError
        For an unknown name, or ``cupy`` requested without a usable GPU.
    """
    key = name.strip().lower()
    if key not in BACKENDS:
        raise InputError(f"backend {name!r}: expected one of {', '.join(BACKENDS)}")
    if key == "numpy":
        return np
    cp = _cupy_or_none()
    if key == "auto":
        return cp if cp is not None else np
    if cp is None:
        raise InputError(
            "backend 'cupy' requested but CuPy with a CUDA device is not available; "
            "install the 'gpu' extra (pip install 'sailroute[gpu]') on a machine with an NVIDIA "
            "GPU, or use --backend numpy"
        )
    return cp


def to_numpy(a: Any) -> np.ndarray:
    """Return ``a`` as a NumPy array (copies from the GPU when ``a`` is a CuPy array)."""
    get = getattr(a, "get", None)
    if callable(get) and type(a).__module__.startswith("cupy"):
        return np.asarray(get())
    return np.asarray(a)


def xp_name(xp: ModuleType) -> str:
    """``"numpy"`` or ``"cupy"`` for a module returned by :func:`get_xp`."""
    return "cupy" if xp.__name__.startswith("cupy") else "numpy"
