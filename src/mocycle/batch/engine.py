"""The dask.distributed side of a batch: a LocalCluster (one single-threaded worker process per core) or an
existing scheduler, BLAS pinned to one thread in every worker, one future per take.

A worker that dies mid-take loses nothing: the scheduler gives its takes to another worker (dask's own
retry; a take that kills ``distributed.scheduler.allowed-failures`` + 1 workers is reported as an error).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterable
from contextlib import ExitStack

import dask
from distributed import Client, LocalCluster, as_completed
from distributed.client import FutureCancelledError
from distributed.diagnostics.plugin import WorkerPlugin
from distributed.scheduler import KilledWorker

from ..errors import MocycleError
from .discover import Take
from .take import Job, message_of, process

__all__ = ["OneBlasThread", "default_workers", "run_takes"]

#: how long to wait for a scheduler's workers, seconds (the connection itself: dask's
#: ``distributed.comm.timeouts.connect``, e.g. ``DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT=5s``)
WORKERS_TIMEOUT_S = 60


def default_workers() -> int:
    """One worker per core this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


#: dask settings of a batch (the LocalCluster ships them to its workers): the event-loop tick monitor, the
#: statistical profiler, the system and memory monitors wake every 10-500 ms in every process; an idle
#: two-worker LocalCluster then burns 8 % of a core, 1.3 % with these (measured, docs/batch.md). A batch does
#: not need them finer: a take runs for a tenth of a second or more, and the memory limit is still enforced.
QUIET = {"distributed.admin.tick.interval": "1s", "distributed.worker.profile.enabled": False,
         "distributed.admin.system-monitor.interval": "2s", "distributed.worker.memory.monitor-interval": "1s"}

#: the thread counts BLAS and OpenMP read when they load
ONE_THREAD_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


class OneBlasThread(WorkerPlugin):
    """Pins BLAS and OpenMP to one thread in the worker, whatever started it (a nanny sets the variables,
    ``dask worker --no-nanny`` does not): each worker runs one take at a time, so more threads only fight
    over the cores. The variables cover the libraries loaded later; the task layer is imported first (numpy,
    scipy, scikit-learn, ripser load their thread pools) and then ``threadpool_limits(1)`` pins the pools
    already there. The import also takes the start-up cost out of the first take's time."""

    name = "mocycle-one-blas-thread"

    def setup(self, worker):
        os.environ.update(ONE_THREAD_ENV)
        pin_threads()


def pin_threads() -> None:
    """Load the libraries the tasks use and limit every BLAS/OpenMP pool loaded so far to one thread."""
    import scipy.linalg  # noqa: F401  (scipy's own BLAS)
    import sklearn.utils  # noqa: F401  (scikit-learn's OpenMP)
    from threadpoolctl import threadpool_limits

    import mocycle.tasks  # noqa: F401

    threadpool_limits(1)


def run_takes(job: Job, takes: Iterable[Take], on_row: Callable[[dict], None], *, scheduler: str | None = None,
              workers: int | None = None) -> dict:
    """Run ``process(job, take)`` for every take on dask; ``on_row(row)`` as each one finishes (any order).

    scheduler : the address of a running scheduler (``tcp://host:8786``); ``None``: a LocalCluster here.
    workers : LocalCluster: its number of workers (default: one per core, at most one per take); with a
        scheduler: wait until that many workers are connected (default 1).
    Returns how the batch ran: ``{"engine", "scheduler", "workers"}``.
    """
    try:
        return _run(job, list(takes), on_row, scheduler, workers)
    except (OSError, TimeoutError, FutureCancelledError) as exc:  # no scheduler, the cluster went away, no disk
        where = f"the dask scheduler at {scheduler}" if scheduler else "a local dask cluster"
        raise MocycleError(f"the batch stopped (on {where}): {type(exc).__name__}: {exc}") from None


def _run(job: Job, takes: list[Take], on_row, scheduler: str | None, workers: int | None) -> dict:
    with ExitStack() as stack:
        stack.enter_context(dask.config.set(QUIET))
        if scheduler is None:
            n = workers or max(1, min(default_workers(), len(takes)))
            cluster = stack.enter_context(LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                silence_logs=logging.ERROR, env=ONE_THREAD_ENV))
            client = stack.enter_context(Client(cluster))
        else:
            client = stack.enter_context(Client(scheduler))
            client.wait_for_workers(workers or 1, timeout=WORKERS_TIMEOUT_S)
        client.register_plugin(OneBlasThread())
        n_workers = len(client.scheduler_info()["workers"])
        futures = {client.submit(process, job, take, key=f"mocycle-{job.command}-{i}-{job.options_hash}",
                                 pure=False): take for i, take in enumerate(takes)}
        for future in as_completed(futures):
            take = futures[future]
            try:
                row = future.result()
            except KilledWorker as exc:  # the take itself kills workers
                row = lost_row(job, take, f"the take killed its workers ({message_of(exc)})")
            on_row(row)
        return {"engine": "dask.distributed", "scheduler": client.scheduler.address, "workers": n_workers}


def lost_row(job: Job, take: Take, message: str) -> dict:
    """The row of a take no worker could finish (status ``error``)."""
    return {"file": str(take.source), "rel": str(take.rel), "status": "error", "message": message, "figures": {},
            "seconds": None, "wall_seconds": None, "outputs": [], "warnings": [], "facts": None, "worker": None,
            "options_hash": job.options_hash, "record": None}
