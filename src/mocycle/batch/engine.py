"""The dask.distributed side of a batch: a LocalCluster (one single-threaded worker process per core) or an
existing scheduler, BLAS pinned to one thread in every worker, one future per take, the largest takes first.

The LocalCluster's workers are forked from a forkserver that has imported dask and the command's compute stack
(:mod:`.forkserver`), so a worker starts in a fraction of a second instead of importing everything itself.
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
from ..text import printable
from . import forkserver
from .commands import COMMANDS
from .discover import Take
from .forkserver import ONE_THREAD_ENV
from .take import Job, base_row, message_of, process

__all__ = ["ONE_THREAD_ENV", "OneBlasThread", "default_workers", "largest_first", "run_takes"]

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
#: And no ``MALLOC_TRIM_THRESHOLD_`` (dask sets 65536 in the workers it spawns, to hand freed memory back):
#: it fixes glibc's mmap threshold at 128 KiB, so every array larger than that is mapped and unmapped (page
#: faults); the loop task then spends 40 % more CPU (docs/batch.md). A take's memory is freed when it ends.
QUIET = {"distributed.admin.tick.interval": "1s", "distributed.worker.profile.enabled": False,
         "distributed.admin.system-monitor.interval": "2s", "distributed.worker.memory.monitor-interval": "1s",
         "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}


class OneBlasThread(WorkerPlugin):
    """Pins BLAS and OpenMP to one thread in the worker, whatever started it (the LocalCluster's forkserver and
    a nanny set the variables, ``dask worker --no-nanny`` does not): each worker runs one take at a time, so
    more threads only fight over the cores. The variables cover the libraries loaded later (a library reads
    them when it loads); ``threadpool_limits(1)`` pins the pools already loaded."""

    name = "mocycle-one-blas-thread"

    def setup(self, worker):
        os.environ.update(ONE_THREAD_ENV)
        pin_threads()


def pin_threads() -> None:
    """Limit every BLAS/OpenMP pool loaded so far to one thread (the ones loaded later read the variables)."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(1)


def largest_first(takes: list[Take]) -> list[Take]:
    """The takes by decreasing file size (a take's time grows with its frames): the long ones start first and
    the short ones fill in at the end, so the workers finish together instead of one waiting on a long last
    take."""
    def size(take: Take) -> int:
        try:
            return take.source.stat().st_size
        except OSError:  # its worker says what is wrong with it
            return 0

    return sorted(takes, key=size, reverse=True)


def run_takes(job: Job, takes: Iterable[Take], on_row: Callable[[dict], None], *, scheduler: str | None = None,
              workers: int | None = None) -> dict:
    """Run ``process(job, take)`` for every take on dask; ``on_row(row)`` as each one finishes (any order).

    scheduler : the address of a running scheduler (``tcp://host:8786``); ``None``: a LocalCluster here.
    workers : LocalCluster: its number of workers (default: one per core, at most one per take); with a
        scheduler: wait until that many workers are connected (default 1).
    Returns how the batch ran: ``{"engine", "scheduler", "workers", "worker_start"}`` (how the LocalCluster's
    workers were started: ``forkserver`` or ``spawn``; ``None`` on an existing scheduler).
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
            start = "spawn"  # dask's default
            if stack.enter_context(forkserver.warm_workers(COMMANDS[job.command].imports)):  # run_batch's, or ours
                start = forkserver.METHOD
                stack.enter_context(dask.config.set({"distributed.worker.multiprocessing-method": start}))
            n = workers or max(1, min(default_workers(), len(takes)))
            cluster = stack.enter_context(LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # its HTTP routes (it has them even without
                # a dashboard) on a free port of this host, not 8787, which another dask may hold (a warning)
                silence_logs=logging.ERROR, env=ONE_THREAD_ENV))
            client = stack.enter_context(Client(cluster))
        else:
            start = None  # the cluster's own business
            client = stack.enter_context(Client(scheduler))
            client.wait_for_workers(workers or 1, timeout=WORKERS_TIMEOUT_S)
        client.register_plugin(OneBlasThread())
        n_workers = len(client.scheduler_info()["workers"])
        ordered = largest_first(takes)  # higher priority runs first (dask would go by submission otherwise)
        futures = {client.submit(process, job, take, key=f"mocycle-{job.command}-{i}-{job.options_hash}",
                                 priority=len(ordered) - i, pure=False): take for i, take in enumerate(ordered)}
        for future in as_completed(futures):
            take = futures[future]
            try:
                row = future.result()
            except KilledWorker as exc:  # the take itself kills workers
                row = lost_row(job, take, f"the take killed its workers ({message_of(exc)})")
            except Exception as exc:  # whatever else one take raised is its row, never the batch's end
                if future.status != "error":  # not the take's own error: the cluster went away (the batch stops)
                    raise
                row = lost_row(job, take, f"the take failed outside its task ({message_of(exc)})")
            on_row(row)
        return {"engine": "dask.distributed", "scheduler": client.scheduler.address, "workers": n_workers,
                "worker_start": start}


def lost_row(job: Job, take: Take, message: str) -> dict:
    """The row of a take no worker could finish (status ``error``)."""
    return {**base_row(job, take), "status": "error", "message": printable(message), "record": None}
