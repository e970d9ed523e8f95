"""Draw ``route.png`` in a child process that loads matplotlib while the parent routes.

Importing matplotlib and drawing the map cost about 0.4 s of a 1.5 s ``sailroute plan``
(``docs/performance.md``); the routing before it uses one core.  :func:`start` launches
``python -m sailroute.report.png_worker`` at the beginning of a run: the child imports
matplotlib and the plotting code and then waits on its stdin.  :meth:`PngWorker.draw`
sends it the routed plan and the wind (pickled, well under 1 MB) and the path to write,
and waits for its answer.  The figure is made by the same function as in-process
(:func:`sailroute.report.plots.plot_plan`), so the file is the same byte for byte.

Anything unusual falls back to drawing in-process: a single CPU, a child that cannot
start, does not answer within :data:`TIMEOUT_S`, or reports an error.  The child ignores
SIGINT (a terminal's Ctrl-C reaches the whole process group); the parent closes it on
every way out (:meth:`PngWorker.close`, also a context manager).
"""

from __future__ import annotations

import os
import pickle
import signal
import subprocess
import sys
from pathlib import Path
from types import TracebackType
from typing import Any

DPI = 150
"""Resolution of ``route.png`` [dots per inch]."""

TIMEOUT_S = 60.0
"""Longest wait for the child's answer [s] before drawing in-process instead."""

_OK = b"ok\n"


def _cpus() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not on Linux
        return os.cpu_count() or 1


class PngWorker:
    """Handle on the child process (see the module docstring).

    Parameters
    ----------
    proc : subprocess.Popen or None
        The child; None draws in-process.
    """

    def __init__(self, proc: subprocess.Popen[bytes] | None) -> None:
        self.proc = proc

    def draw(self, plan: Any, wind: Any, path: Path, dpi: int) -> Path:
        """Write ``plot_plan(plan, wind)`` to ``path`` at ``dpi``; return ``path``."""
        if self.proc is not None:
            try:
                job = pickle.dumps((plan, wind, str(path), dpi), protocol=pickle.HIGHEST_PROTOCOL)
                out, _ = self.proc.communicate(job, timeout=TIMEOUT_S)
                if out == _OK and path.is_file():
                    return path
            except (OSError, subprocess.SubprocessError, pickle.PicklingError, TypeError,
                    AttributeError):
                pass
            finally:
                self.close()
        return draw_in_process(plan, wind, path, dpi)

    def close(self) -> None:
        """Stop the child if it still runs (idempotent)."""
        proc, self.proc = self.proc, None
        if proc is None:
            return
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for pipe in (proc.stdin, proc.stdout):
            if pipe is not None:
                pipe.close()

    def __enter__(self) -> PngWorker:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


def draw_in_process(plan: Any, wind: Any, path: Path, dpi: int) -> Path:
    """Draw and save ``route.png`` here; return ``path``."""
    from sailroute.report.plots import plot_plan

    plot_plan(plan, wind).savefig(path, dpi=dpi)
    return path


def start(enabled: bool = True) -> PngWorker:
    """Launch the child when drawing is wanted and a second CPU is there to run it."""
    if not enabled or _cpus() < 2:
        return PngWorker(None)
    try:
        proc = subprocess.Popen(
            [sys.executable, "-m", "sailroute.report.png_worker"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
        )
    except OSError:  # pragma: no cover - no interpreter to start
        return PngWorker(None)
    return PngWorker(proc)


def _child() -> int:
    """The child's side: import, wait for one job, draw it, answer ``ok``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # what plot_route draws with, and the classes the job unpickles into
    import matplotlib.collections
    import matplotlib.colors
    import matplotlib.transforms  # noqa: F401
    from matplotlib.figure import Figure

    import sailroute.plan
    import sailroute.report.plots  # noqa: F401

    # first text drawn loads the fonts: do it while the parent is still routing
    warm = Figure(figsize=(1, 1))
    warm.text(0.5, 0.5, "0")
    warm.canvas.draw()
    job = sys.stdin.buffer.read()
    if not job:  # the parent went away or drew in-process
        return 0
    plan, wind, path, dpi = pickle.loads(job)
    draw_in_process(plan, wind, Path(path), dpi)
    sys.stdout.buffer.write(_OK)
    return 0


if __name__ == "__main__":  # pragma: no cover - run as the child process
    sys.exit(_child())
