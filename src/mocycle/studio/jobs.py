"""Background work for the studio: a job runs in a worker thread, reports its progress and can be cancelled."""

from __future__ import annotations

import itertools
import threading
import traceback
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

from ..errors import LoopRefused, MocycleError


@dataclass
class Job:
    """One piece of background work: ``status`` queued → running → done / failed / cancelled, or refused (its
    work raised :class:`~mocycle.errors.LoopRefused`: ``error`` is the reason, ``result["facts"]`` the failed
    checks)."""

    id: str
    kind: str
    status: str = "queued"
    progress: float = 0.0
    error: str | None = None
    result: object = None
    cancel_event: threading.Event = field(default_factory=threading.Event, repr=False)

    def cancelled(self) -> bool:
        return self.cancel_event.is_set()

    def to_dict(self) -> dict:
        return {"id": self.id, "kind": self.kind, "status": self.status, "progress": round(self.progress, 4),
                "error": self.error}


class Jobs:
    """A queue of jobs on ``workers`` threads; ``submit(kind, fn)`` runs ``fn(job)`` (which may set
    ``job.progress`` and should look at ``job.cancelled()``); what it returns becomes ``job.result``."""

    def __init__(self, workers: int = 1):
        self._pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="mocycle-studio")
        self._jobs: dict[str, Job] = {}
        self._ids = itertools.count(1)
        self._lock = threading.Lock()

    def submit(self, kind: str, fn) -> Job:
        job = Job(id=f"j{next(self._ids)}", kind=kind)
        with self._lock:
            self._jobs[job.id] = job
        self._pool.submit(self._run, job, fn)
        return job

    @staticmethod
    def _run(job: Job, fn) -> None:
        if job.cancelled():
            job.status = "cancelled"
            return
        job.status = "running"
        try:
            job.result = fn(job)
            job.status = "cancelled" if job.cancelled() else "done"
            job.progress = 1.0
        except LoopRefused as exc:  # a result that fails its own checks: refused, with the reason
            job.status, job.error = "refused", str(exc)
            job.result = {"facts": {"refused": True, "reason": str(exc),
                                    "failed_checks": [f.to_dict() for f in exc.failed]}}
        except Exception as exc:  # the page shows the message; the server keeps serving
            job.status, job.error = "failed", str(exc) or type(exc).__name__
            if not isinstance(exc, (ValueError, MocycleError)):
                traceback.print_exc()

    def get(self, job_id: str) -> Job | None:
        with self._lock:
            return self._jobs.get(job_id)

    def cancel(self, job_id: str) -> Job | None:
        job = self.get(job_id)
        if job is not None:
            job.cancel_event.set()
        return job

    def shutdown(self) -> None:
        with self._lock:
            for job in self._jobs.values():
                job.cancel_event.set()
        self._pool.shutdown(wait=False, cancel_futures=True)
