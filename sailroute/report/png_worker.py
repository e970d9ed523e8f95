"""Draw ``route.png`` in a child process that loads matplotlib while the parent routes.

Importing matplotlib and drawing the map cost about 0.4 s of a 1.5 s ``sailroute plan``
(``docs/performance.md``); the routing before it uses one core.  :func:`start` launches
``python -m sailroute.report.png_worker`` at the beginning of a run: the child imports
matplotlib and the plotting code and then waits on its stdin.  :meth:`PngWorker.submit`
sends it the routed plan and the wind (pickled, well under 1 MB) and the path to write;
the parent writes its other files meanwhile, then :meth:`PngWorker.result` waits for the
answer.  The child leaves with ``os._exit`` right after answering: the interpreter's
teardown with matplotlib loaded took 0.11-0.16 s, which the parent used to wait for.  The
figure is made by the same function as in-process
(:func:`sailroute.report.plots.plot_plan`), so the file is the same byte for byte.

Anything unusual falls back to drawing in-process: a single CPU, a child that cannot
start, does not answer within :data:`TIMEOUT_S`, or reports an error.  The child ignores
SIGINT (a terminal's Ctrl-C reaches the whole process group); the parent closes it on
every way out (:meth:`PngWorker.close`, also a context manager).
"""

from __future__ import annotations

import contextlib
import os
import pickle
import select
import signal
import subprocess
import sys
from pathlib import Path
from types import TracebackType
from typing import Any

DPI = 150
"""Resolution of ``route.png`` [dots per inch]."""

PNG_COMPRESS = 3
"""zlib level of ``route.png``: 20 ms less than Pillow's default 6 for a 1 % larger file
(231 against 228 kB for the shipped example; level 1: the same time, 239 kB)."""

TIMEOUT_S = 60.0
"""Longest wait for the child's answer [s] before drawing in-process instead."""

EXIT_WAIT_S = 5.0
"""Longest wait [s] for the child to exit after its answer (it ends with ``os._exit``)."""

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
        self._job: tuple[Any, Any, Path, int] | None = None

    def submit(self, plan: Any, wind: Any, path: Path, dpi: int) -> None:
        """Hand ``plot_plan(plan, wind)`` at ``dpi`` to the child, to be written to ``path``
        while the caller writes its other files; :meth:`result` waits for it.  If the job
        cannot be handed over, the child is stopped (``proc`` is None afterwards)."""
        self._job = (plan, wind, path, dpi)
        if self.proc is None:
            return
        try:
            job = pickle.dumps((plan, wind, str(path), dpi), protocol=pickle.HIGHEST_PROTOCOL)
            assert self.proc.stdin is not None  # started with stdin=PIPE
            self.proc.stdin.write(job)
            self.proc.stdin.close()
        except (OSError, pickle.PicklingError, TypeError, AttributeError):
            self.close()

    def result(self) -> Path:
        """The path of the submitted drawing once written (drawn here if the child failed)."""
        if self._job is None:
            raise RuntimeError("PngWorker.result() before submit()")
        plan, wind, path, dpi = self._job
        self._job = None
        proc = self.proc  # still there only if it took the job
        try:
            if proc is not None and proc.stdout is not None:
                ready, _, _ = select.select([proc.stdout], [], [], TIMEOUT_S)
                if ready and proc.stdout.readline() == _OK and path.is_file():
                    # it leaves at once after its answer; if not, close() stops it
                    with contextlib.suppress(subprocess.TimeoutExpired):
                        proc.wait(timeout=EXIT_WAIT_S)
                    return path
        except (OSError, ValueError):
            pass
        finally:
            self.close()
        return draw_in_process(plan, wind, path, dpi)

    def draw(self, plan: Any, wind: Any, path: Path, dpi: int) -> Path:
        """Write ``plot_plan(plan, wind)`` to ``path`` at ``dpi``; return ``path``
        (:meth:`submit`, then :meth:`result`)."""
        self.submit(plan, wind, path, dpi)
        return self.result()

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

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()


def draw_in_process(plan: Any, wind: Any, path: Path, dpi: int) -> Path:
    """Draw and save ``route.png`` here; return ``path``."""
    from sailroute.report.plots import plot_plan

    plot_plan(plan, wind).savefig(path, dpi=dpi, pil_kwargs={"compress_level": PNG_COMPRESS})
    return path


def start(enabled: bool = True) -> PngWorker:
    """Launch the child when drawing is wanted and a second CPU is there to run it."""
    if not enabled or _cpus() < 2:
        return PngWorker(None)
    try:
        proc = subprocess.Popen(
            [sys.executable, "-m", "sailroute.report.png_worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
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
    import matplotlib.patches
    import matplotlib.transforms  # noqa: F401
    from matplotlib.figure import Figure

    import sailroute.planning.result
    import sailroute.report.plots  # noqa: F401

    # first text drawn loads the fonts: do it while the parent is still routing
    warm = Figure(figsize=(1, 1))
    warm.text(0.5, 0.5, "0")
    warm.canvas.draw()
    job = sys.stdin.buffer.read()
    if not job:  # the parent went away or drew in-process
        return 0
    plan, wind, path, dpi = pickle.loads(job)
    draw_in_process(plan, wind, Path(path), dpi)  # the file is closed when this returns
    sys.stdout.buffer.write(_OK)
    sys.stdout.buffer.flush()
    # skip the interpreter's teardown (0.1-0.16 s with matplotlib loaded, measured): the
    # parent is waiting for the answer, not for the exit
    os._exit(0)


if __name__ == "__main__":  # pragma: no cover - run as the child process
    sys.exit(_child())
