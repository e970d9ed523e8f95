"""Allow ``python -m sailroute``; also the ``sailroute`` console script's entry point.

This module imports nothing heavy: :func:`main` imports the command line inside its
Ctrl-C guard, so an interrupt at any point of the start-up (typer, the command's
modules) ends in the same one line ``interrupted`` and exit code 130 as one during the
work, never in a traceback.  Before that it shortens the spin of OpenBLAS's idle
threads, which NumPy starts as it loads (:func:`_short_blas_spin`).
"""

from __future__ import annotations

import os
import sys

BLAS_THREAD_TIMEOUT = "22"
"""``OPENBLAS_THREAD_TIMEOUT`` of a command (where the environment sets none): an idle
OpenBLAS worker thread spins for 2**22 cycles (about 1.5 ms) before it sleeps, instead of
OpenBLAS's default 2**28 (about 0.1 s)."""


def main() -> None:
    """Console-script entry point: :func:`sailroute.cli.main` under a Ctrl-C guard."""
    _short_blas_spin()
    try:
        from sailroute.cli import main as cli_main

        cli_main()
    except KeyboardInterrupt:
        try:
            sys.stderr.write("interrupted\n")
            sys.stderr.flush()
        except (OSError, ValueError):  # pragma: no cover - stderr closed
            pass
        raise SystemExit(130) from None
    finally:
        _end_without_collections()


def _short_blas_spin() -> None:
    """Let NumPy's OpenBLAS worker threads sleep soon when they have no work
    (:data:`BLAS_THREAD_TIMEOUT`; a value in the environment is kept).

    OpenBLAS starts a worker thread per core as NumPy loads, and each spins for its
    timeout, about 0.1 s of CPU by default, before it sleeps: 60-90 ms of every command's
    CPU on 2 cores (more with more cores), with no BLAS work to wait for.  The number of
    threads and how a BLAS call splits its work among them are unchanged, and so are the
    results; a call that comes after a thread has gone to sleep wakes it.
    """
    os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", BLAS_THREAD_TIMEOUT)


def _end_without_collections() -> None:
    """Move every object the command made into the garbage collector's permanent
    generation (:func:`gc.freeze`) as the process ends.

    The interpreter's shutdown clears the modules and runs full collections over what is
    left; after a compiled routing step that is numba's type and lowering registries,
    some hundred thousand objects, and those collections cost about 0.25 s of CPU, a
    fifth of a single plan.  Frozen objects are still freed by their reference counts;
    only cycles among them are left to the end of the process, and the ``atexit``
    handlers and the flushing of ``sys.stdout`` and ``sys.stderr`` run as before.
    """
    import gc

    gc.freeze()


if __name__ == "__main__":
    main()
