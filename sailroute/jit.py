"""Optional compiled kernels: numba's ``njit`` where it is installed (the extra ``fast``).

The modules of compiled kernels (``sailroute/strategy/_deadline_jit.py``,
``sailroute/routing/isochrone_jit.py``) decorate their loops with :func:`jit` and
:func:`inline`.  Without numba :data:`AVAILABLE` is False, the functions stay plain
Python and their callers run their NumPy code instead.  Importing this module imports
numba (about 0.3 s of CPU): a router imports its kernels only when it uses them.
"""

from __future__ import annotations

from typing import Any

try:  # optional extra
    import numba

    AVAILABLE = True
    """True when numba is installed and the compiled kernels can be used."""
except ImportError:  # pragma: no cover - exercised where numba is not installed
    AVAILABLE = False

__all__ = ["AVAILABLE", "inline", "jit"]


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
