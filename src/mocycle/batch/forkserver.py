"""Worker processes that start warm: a LocalCluster's workers are forked from Python's forkserver, which has
imported dask.distributed and the command's compute stack once, while this process was still importing dask
and starting the scheduler.

Without it each worker is a fresh interpreter (dask's default ``spawn``) that imports dask (0.5 CPU s) and the
stack (numpy, scipy, ripser, the task: about 1 CPU s) before its first take, and on a small library this
start-up is as long as the work (``docs/batch.md``). With it the import happens once, in parallel with the
parent, and a worker is a ``fork`` of a single-threaded process: cheap, and safe (no thread holds a lock).

dask starts its workers with ``multiprocessing.get_context(method)`` for its setting
``distributed.worker.multiprocessing-method`` (:data:`METHOD`); :func:`start` starts that forkserver first,
with our modules to preload (dask's own preload list would come too late: a forkserver preloads only when it
starts). dask's caveat for ``fork``/``forkserver``: the variables a process reads when it starts (the thread
counts BLAS reads when it loads) must be in the forkserver's environment, not in the nanny's: :func:`start`
gives it :data:`ONE_THREAD_ENV`. dask's other such variable, ``MALLOC_TRIM_THRESHOLD_=65536``, is left out on purpose
(:data:`.engine.QUIET`). Importing this module imports no dask.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Iterable, Mapping
from contextlib import contextmanager

__all__ = ["METHOD", "ONE_THREAD_ENV", "WORKER_MODULES", "running", "start", "stop", "warm_workers"]

#: dask's ``distributed.worker.multiprocessing-method`` for the LocalCluster's workers
METHOD = "forkserver"

#: the thread counts BLAS and OpenMP read when they load
ONE_THREAD_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}

#: what every worker runs whatever the command: dask itself, the take runner and what it writes with
#: (the command's own modules: :attr:`.commands.Command.imports`)
WORKER_MODULES = ("distributed", "threadpoolctl", "mocycle.batch.take", "mocycle.io", "mocycle.io.atomic",
                  "mocycle.cli.common")


@contextmanager
def _environment(values: Mapping[str, str]):
    """``os.environ`` with ``values`` for the block (the forkserver is a child: it inherits them)."""
    old = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _server():
    """multiprocessing's forkserver of this process (its module keeps one; ``None`` if that ever changes).

    Whether it runs and how to stop it are private attributes (``_forkserver_pid``, ``_stop``: CPython 3.8 to
    3.14); without them :func:`start` still starts one (``ensure_running`` is public) and it ends with this
    process instead of with the batch."""
    from multiprocessing import forkserver

    return getattr(forkserver, "_forkserver", None)


def running() -> bool:
    """Whether this process's forkserver is running."""
    server = _server()
    return server is not None and getattr(server, "_forkserver_pid", None) is not None


def start(modules: Iterable[str]) -> bool:
    """Start this process's forkserver, if none is running, with :data:`WORKER_MODULES` and ``modules`` to
    preload and BLAS/OpenMP on one thread (:data:`ONE_THREAD_ENV`). Returns at once: it imports them in the
    background, and a worker forked from it waits until they are loaded. Returns whether it started one.

    A forkserver already running (one of the caller's own) is kept as it is: its workers import what it lacks
    at their first take (slower, same results).
    """
    if METHOD not in multiprocessing.get_all_start_methods() or running():
        return False
    from multiprocessing import forkserver

    multiprocessing.get_context(METHOD).set_forkserver_preload(list(dict.fromkeys([*WORKER_MODULES, *modules])))
    with _environment(ONE_THREAD_ENV):
        forkserver.ensure_running()
    return True


def stop() -> None:
    """Stop this process's forkserver and wait for it (its workers are gone by then), so that no process of
    the batch outlives it and the workers' CPU time counts in this process's children."""
    server = _server()
    if running() and hasattr(server, "_stop"):
        server._stop()


@contextmanager
def warm_workers(modules: Iterable[str]):
    """A forkserver preloading ``modules`` for the block (:func:`start`), stopped after it if the block started
    it. Yields whether a forkserver is running (False where the platform has none: dask then spawns)."""
    started = start(modules)
    try:
        yield started or running()
    finally:
        if started:
            stop()
