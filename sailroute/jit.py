"""Optional compiled kernels: numba's ``njit`` where it is installed (the extra ``fast``).

The modules of compiled kernels (``sailroute/strategy/_deadline_jit.py``,
``sailroute/routing/isochrone_jit.py``) decorate their loops with :func:`jit` and
:func:`inline`.  Without numba :data:`AVAILABLE` is False, the functions stay plain
Python and their callers run their NumPy code instead.  Importing this module imports
numba (about 0.15 s of CPU; the first compiled call loads its registries, about 0.2 s
more): a router imports its kernels only when it uses them.
"""

from __future__ import annotations

import sys
from typing import Any

_BLAS_PROBE = "scipy.linalg.cython_blas"


def _array_math_without_blas_probe() -> None:
    """Import numba's array-math registry with SciPy's BLAS hidden from its probe.

    ``numba.np.arraymath`` (loaded by the first compiled call) imports
    ``scipy.linalg.cython_blas`` to learn whether ``np.convolve`` and ``np.correlate``
    may call BLAS for their inner products; that import loads ``scipy.linalg``, about
    0.15 s of CPU.  Hidden, those two use numba's own loop (the kernels call neither);
    ``np.dot`` and ``np.linalg`` in a kernel still find SciPy's BLAS when compiled.
    """
    if _BLAS_PROBE in sys.modules:  # already loaded: nothing to save
        return
    sys.modules[_BLAS_PROBE] = None  # type: ignore[assignment]  # its import fails
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        if sys.modules.get(_BLAS_PROBE, 0) is None:
            del sys.modules[_BLAS_PROBE]


try:  # optional extra
    import numba

    AVAILABLE = True
    """True when numba is installed and the compiled kernels can be used."""
    _array_math_without_blas_probe()
except ImportError:  # pragma: no cover - exercised where numba is not installed
    AVAILABLE = False

__all__ = ["AVAILABLE", "inline", "jit", "load_registries"]


def load_registries() -> None:
    """Load numba's typing and lowering registries now, as its first compiled call
    would (about 0.15 s of CPU): a caller can then pause the garbage collector over the
    whole start-up (:func:`sailroute.routing.isochrone_fast.kernels`).  Without numba,
    or with a numba whose internals differ, nothing happens here and the first call
    loads them."""
    if not AVAILABLE:
        return
    try:
        from numba.core.registry import cpu_target

        cpu_target.target_context.refresh()
    except (ImportError, AttributeError):  # pragma: no cover - another numba's layout
        pass


def jit(fn: Any) -> Any:
    """``fn`` compiled by numba (``fn`` itself without numba).

    ``cache=True`` writes the compiled code next to the module (``__pycache__``), or,
    where that folder is read-only, in numba's user-wide cache directory
    (``NUMBA_CACHE_DIR``): compiled once, then loaded."""
    return numba.njit(cache=True, nogil=True)(fn) if AVAILABLE else fn


def inline(fn: Any) -> Any:
    """As :func:`jit`, inlined into its callers by numba: a call passes every array as a
    struct of its fields, which in a kernel's inner loop costs more than the work."""
    return numba.njit(cache=True, nogil=True, inline="always")(fn) if AVAILABLE else fn
