"""Run independent tasks serially or on a Dask cluster, with results in input order.

One small seam for "scale out" (Monte Carlo chunks, scenarios): a task is
``fn(item, *shared)`` for each ``item``; the results come back as a list in the
order of ``items``, whatever runs them.  So as long as ``fn`` is deterministic
(seeded per item, never by worker or time), a distributed run gives exactly the
serial run's results.

Schedulers (``docs/scale-out.md``):

* ``None`` or ``"serial"`` -- a plain loop in this process (the default; needs
  nothing beyond numpy);
* ``"processes"`` -- a :class:`distributed.LocalCluster` of worker processes on
  the loopback interface, started for the call (or for the ``with`` block of
  :func:`open_runner`) and closed afterwards;
* an address such as ``"tcp://10.0.0.5:8786"`` (or ``"10.0.0.5:8786"``) -- a
  :class:`distributed.Client` connected to an existing cluster, started with
  ``dask scheduler`` and ``dask worker tcp://...``.

Dask is an optional dependency (``pip install 'sailroute[dask]'``); it is only
imported when a non-serial scheduler is asked for.  ``fn`` must be picklable:
a top-level function of an installed module (not a lambda, a local function or
a function of a script that the workers cannot import), and so must ``items``
and ``shared``.  ``shared`` arguments are sent to every worker once
(``Client.scatter(..., broadcast=True)``), not once per task.
"""

from __future__ import annotations

import logging
import os
import re
import signal
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, TypeVar

from sailroute.errors import InputError

R = TypeVar("R")

SERIAL = "serial"
"""Run the tasks in a loop in this process."""
PROCESSES = "processes"
"""Start a local cluster of worker processes on 127.0.0.1 for the call."""
CONNECT_TIMEOUT_S = 10.0
"""Default time [s] to wait for an existing scheduler to answer."""
INSTALL_HINT = "pip install 'sailroute[dask]'"
_ADDRESS = re.compile(r"^(?:(?:tcp|tls|ws|wss)://\S+|[^\s/:]+:\d+)$", re.IGNORECASE)
"""``tcp://``, ``tls://``, ``ws://`` or ``wss://`` followed by the address, or ``host:port``."""
_EXPECTED = (
    "expected 'serial', 'processes' or a scheduler address such as tcp://HOST:8786 "
    "(tcp://, tls://, ws:// or wss://)"
)


def check_scheduler(scheduler: str | None) -> str:
    """Normalise a scheduler name, or raise :class:`InputError` explaining the choices.

    Parameters
    ----------
    scheduler : str or None
        ``None``/``"serial"``, ``"processes"``, or a scheduler address.

    Returns
    -------
    str
        ``"serial"``, ``"processes"`` or the address, stripped.  Only the form
        is checked here; whether Dask is installed and the scheduler answers is
        checked by :func:`open_runner`.
    """
    if scheduler is None:
        return SERIAL
    if not isinstance(scheduler, str):
        raise InputError(f"scheduler {scheduler!r}: {_EXPECTED}")
    s = scheduler.strip()
    if s.lower() in (SERIAL, PROCESSES):
        return s.lower()
    if _ADDRESS.match(s):
        return s
    raise InputError(f"scheduler {scheduler!r}: {_EXPECTED}")


@dataclass(frozen=True)
class TaskRunner:
    """An open scheduler: a Dask client, or ``None`` for the serial loop.

    Make one with :func:`open_runner`; pass it as ``scheduler=`` to
    :func:`map_tasks` (and to functions that accept a scheduler) to reuse one
    cluster for several batches of tasks.

    Attributes
    ----------
    client : distributed.Client or None
        The connected client; ``None`` runs serially.
    description : str
        ``"serial"``, ``"processes (N workers)"`` or the scheduler address.
    """

    client: Any
    description: str

    def map(
        self,
        fn: Callable[..., R],
        items: Iterable[Any],
        shared: Sequence[Any] = (),
        on_done: Callable[[int, R], None] | None = None,
    ) -> list[R]:
        """Run ``fn(item, *shared)`` for every item; results in the order of ``items``.

        ``on_done(index, result)`` is called as each task finishes (in the order they
        finish on a cluster), e.g. to report progress."""
        items = list(items)
        if self.client is None:
            out = []
            for k, item in enumerate(items):
                out.append(fn(item, *shared))
                if on_done is not None:
                    on_done(k, out[-1])
            return out
        # one future per shared value (a list is scattered element by element; a tuple
        # value stays one object), copied to every worker once
        shared_futures = (
            list(self.client.scatter(list(shared), broadcast=True, hash=False)) if shared else []
        )
        futures = [self.client.submit(fn, item, *shared_futures, pure=False) for item in items]
        try:
            if on_done is None:
                return list(self.client.gather(futures))
            return self._as_completed(futures, on_done)
        finally:
            for f in futures + shared_futures:
                f.release()

    @staticmethod
    def _as_completed(futures: list[Any], on_done: Callable[[int, Any], None]) -> list[Any]:
        """The futures' results in their order, ``on_done`` called as each finishes (a
        failed task raises its exception, as ``gather`` does)."""
        distributed = _import_distributed(PROCESSES)
        index = {f.key: k for k, f in enumerate(futures)}
        out: list[Any] = [None] * len(futures)
        for future, result in distributed.as_completed(futures, with_results=True):
            k = index[future.key]
            out[k] = result
            on_done(k, result)
        return out


def _import_distributed(scheduler: str) -> Any:
    try:
        import distributed
    except ImportError:
        raise InputError(
            f"scheduler {scheduler!r} needs Dask, which is not installed: run "
            f"{INSTALL_HINT}, or use the default serial scheduler"
        ) from None
    return distributed


@contextmanager
def open_runner(
    scheduler: str | TaskRunner | None = None,
    n_workers: int | None = None,
    timeout_s: float = CONNECT_TIMEOUT_S,
) -> Iterator[TaskRunner]:
    """Start or connect to a scheduler for the ``with`` block; yield a :class:`TaskRunner`.

    Parameters
    ----------
    scheduler : str, TaskRunner or None
        ``None``/``"serial"``, ``"processes"``, an address, or an already open
        runner (yielded as is and left open).
    n_workers : int, optional
        Worker processes for ``"processes"``; default ``os.cpu_count()``.
        Ignored otherwise (an existing cluster has its own workers).
    timeout_s : float
        How long to wait for an existing scheduler to answer [s].

    Yields
    ------
    TaskRunner

    Raises
    ------
    InputError
        Unknown scheduler name, Dask not installed, bad ``n_workers``, or no
        scheduler answering at the address.
    """
    if isinstance(scheduler, TaskRunner):
        yield scheduler
        return
    name = check_scheduler(scheduler)
    if name == SERIAL:
        yield TaskRunner(None, SERIAL)
        return
    n = (os.cpu_count() or 1) if n_workers is None else n_workers
    if name == PROCESSES and (isinstance(n, bool) or not (isinstance(n, int) and n >= 1)):
        raise InputError(f"n_workers = {n_workers!r}: need a whole number >= 1 of worker processes")
    distributed = _import_distributed(name)
    if name == PROCESSES:
        import dask

        # the workers inherit the ignored SIGINT (Ctrl-C is the parent's to handle) and
        # this logging config (a cancelled run must not print each cancelled task)
        with (
            _sigint_ignored(),
            dask.config.set(
                {"logging": {"distributed.worker": "error", "distributed.nanny": "error"}}
            ),
        ):
            cluster = distributed.LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=":0",
            )
        try:
            with cluster, distributed.Client(cluster) as client:
                yield TaskRunner(client, f"{PROCESSES} ({n} workers on 127.0.0.1)")
        except KeyboardInterrupt:
            # the cluster is torn down mid-task: Dask logs every cancelled future
            for name_ in ("distributed", "asyncio"):
                logging.getLogger(name_).setLevel(logging.CRITICAL)
            raise
        return
    client = _connect(distributed, name, timeout_s)
    try:
        yield TaskRunner(client, name)
    finally:
        client.close()


@contextmanager
def _sigint_ignored() -> Iterator[None]:
    """Ignore SIGINT in this process for the block (main thread only; else a no-op).

    Processes started inside the block inherit the ignored SIGINT, and Python keeps it
    ignored at start-up, so a Ctrl-C at the terminal (sent to the whole process group)
    reaches only the parent, which stops the run and the cluster as the serial run stops.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def _connect(distributed: Any, address: str, timeout_s: float) -> Any:
    """A client connected to ``address``, or an :class:`InputError` saying how to fix it."""
    try:
        client = distributed.Client(address, timeout=timeout_s)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        raise InputError(
            f"scheduler {address!r}: could not connect to a Dask scheduler there within "
            f"{timeout_s:g} s ({exc}); start one with `dask scheduler` and workers with "
            f"`dask worker {address}`, check the host and port (default 8786), or use "
            "--scheduler processes for a local cluster"
        ) from None
    try:  # tasks sent to a scheduler without workers would wait forever
        client.wait_for_workers(1, timeout=timeout_s)
    except (OSError, TimeoutError) as exc:
        client.close()
        raise InputError(
            f"scheduler {address!r} answered but has no workers after {timeout_s:g} s "
            f"({exc}); start some with `dask worker {address}`"
        ) from None
    return client


def map_tasks(
    fn: Callable[..., R],
    items: Iterable[Any],
    *,
    shared: Sequence[Any] = (),
    scheduler: str | TaskRunner | None = None,
    n_workers: int | None = None,
    timeout_s: float = CONNECT_TIMEOUT_S,
    on_done: Callable[[int, R], None] | None = None,
) -> list[R]:
    """Run ``fn(item, *shared)`` for every item, serially or on Dask; results in input order.

    Parameters
    ----------
    fn : callable
        Picklable top-level function, deterministic in its arguments.
    items : iterable
        One task per item.
    shared : sequence, optional
        Extra arguments common to all tasks (sent to each worker once).
    scheduler : str, TaskRunner or None
        ``None``/``"serial"`` (default), ``"processes"`` (local cluster on
        127.0.0.1, closed afterwards), a scheduler address
        ``"tcp://HOST:PORT"``, or a runner from :func:`open_runner`.
    n_workers : int, optional
        Worker processes for ``"processes"`` (default ``os.cpu_count()``).
    timeout_s : float
        Connection timeout for an address [s].
    on_done : callable, optional
        ``on_done(index, result)`` as each task finishes (progress reports).

    Returns
    -------
    list
        ``[fn(item, *shared) for item in items]``, whatever the scheduler.

    Raises
    ------
    InputError
        See :func:`open_runner`; an exception raised by a task is re-raised
        as is.

    Examples
    --------
    >>> map_tasks(pow, [3, 1, 2], shared=(2,))
    [9, 1, 4]
    """
    with open_runner(scheduler, n_workers, timeout_s) as runner:
        return runner.map(fn, items, shared, on_done)
