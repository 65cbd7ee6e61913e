"""Background work for the studio: a job runs in a worker thread, reports its progress and can be cancelled.

Memory stays bounded: at most ``max_pending`` jobs wait or run (more is a 429), and finished jobs are kept in
a :class:`Held` store (least recently used evicted past a count and a byte budget); an id that was given out
and evicted is *gone* (410), one never given out is *not found* (404).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import itertools
import queue
import threading
import traceback
from collections import OrderedDict
from dataclasses import dataclass, field
from http import HTTPStatus

import numpy as np

from ..errors import LoopRefused, MocycleError
from ..tasks import words
from .validate import HTTPProblem

#: jobs held before they are reached, cancelled ones included: at most this many times ``max_pending``
LIVE_FACTOR = 4


def held_bytes(obj, skip=(), _seen=None, _depth=0) -> int:
    """About the bytes ``obj`` holds: its numpy arrays and bytes, 32 per number in lists, through dicts, lists,
    tuples and object attributes, each object counted once; objects whose ``id`` is in ``skip`` (a take shared
    with the library) are not counted."""
    seen = set(skip) if _seen is None else _seen
    if obj is None or isinstance(obj, (bool, int, float, str)) or id(obj) in seen or _depth > 8:
        return 0
    seen.add(id(obj))
    if isinstance(obj, (bytes, bytearray)):
        return len(obj)
    if isinstance(obj, np.ndarray):
        return obj.nbytes
    items: list[object] | tuple[object, ...]
    if isinstance(obj, dict):
        items = list(obj.values())
    elif isinstance(obj, (list, tuple)):
        if obj and isinstance(obj[0], (int, float)):
            return 32 * len(obj)
        items = obj
    elif hasattr(obj, "__dict__") or hasattr(obj, "__slots__"):
        items = list(getattr(obj, "__dict__", {}).values())
        items += [getattr(obj, n, None) for n in getattr(type(obj), "__slots__", ())]
    else:
        return 0
    return sum(held_bytes(v, skip, seen, _depth + 1) for v in items)


def _libc_trim():
    try:
        return ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").malloc_trim
    except (OSError, AttributeError):  # not glibc: nothing to do
        return None


_TRIM = _libc_trim()


def release_memory() -> None:
    """Give the memory freed by an evicted job or stroke back to the system (glibc's ``malloc_trim``): the
    server's worker threads each allocate from their own malloc arena, which otherwise keeps what was freed
    in it, so the process would stay at its highest even though what it holds is bounded."""
    if _TRIM is not None:
        _TRIM(0)


class Held:
    """Items by id, least recently used first out past ``max_items`` or ``max_bytes`` (each item's size given
    when stored); ``get`` of an evicted id raises :class:`HTTPProblem` ``GONE``, of an unknown id ``NOT_FOUND``."""

    def __init__(self, kind: str, max_items: int, max_bytes: int):
        self.kind, self.max_items, self.max_bytes = kind, max_items, max_bytes
        self._items: OrderedDict[str, tuple[object, int]] = OrderedDict()
        self._gone: OrderedDict[str, None] = OrderedDict()  # the last evicted ids, for a clearer message
        self.bytes = 0
        self.evicted = 0
        self._lock = threading.Lock()

    def put(self, key: str, item, size: int) -> None:
        with self._lock:
            if key in self._items:
                self.bytes -= self._items.pop(key)[1]
            self._items[key] = (item, size)
            self.bytes += size
            evicted = []
            while len(self._items) > self.max_items or (self.bytes > self.max_bytes and len(self._items) > 1):
                old, (item, old_size) = self._items.popitem(last=False)
                self.bytes -= old_size
                self.evicted += 1
                self._gone[old] = None
                evicted.append(item)
                while len(self._gone) > 4096:
                    self._gone.popitem(last=False)
        if evicted:
            del evicted, item
            release_memory()

    def peek(self, key: str):
        with self._lock:
            entry = self._items.get(key)
            if entry is not None:
                self._items.move_to_end(key)
            return None if entry is None else entry[0]

    def was_evicted(self, key: str) -> bool:
        with self._lock:
            return key in self._gone

    def __len__(self) -> int:
        return len(self._items)

    def values(self) -> list:
        with self._lock:
            return [item for item, _ in self._items.values()]


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
        """Its state; ``error`` whole, ``error_line`` the line the page shows of it (a refusal: its failed checks
        in plain words, :func:`~mocycle.tasks.words.refusal`; else :func:`~mocycle.tasks.words.brief`)."""
        line = None
        if self.error:
            facts = self.result.get("facts", {}) if isinstance(self.result, dict) else {}
            line = words.refusal(facts["failed_checks"]) if self.status == "refused" and facts.get(
                "failed_checks") else words.brief(self.error)
        return {"id": self.id, "kind": self.kind, "status": self.status, "progress": round(self.progress, 4),
                "error": self.error, "error_line": line}


class Jobs:
    """A queue of jobs on ``workers`` threads; ``submit(kind, fn)`` runs ``fn(job)`` (which may set
    ``job.progress`` and should look at ``job.cancelled()``); what it returns becomes ``job.result``.

    ``max_pending``: most jobs queued or running at once, not counting cancelled ones (``None``: no limit, for
    the library's analysis); finished jobs are kept in a :class:`Held` store of ``keep`` jobs and ``keep_bytes``
    bytes of results (``size(job)`` measures one); ``prefix`` starts the ids (``j``)."""

    def __init__(self, workers: int = 1, *, max_pending: int | None = None, keep: int = 10_000,
                 keep_bytes: int = 1 << 62, size=None, prefix: str = "j", ids=None):
        # daemon threads (not a ThreadPoolExecutor, whose threads the interpreter waits for at exit): Ctrl-C or
        # SIGTERM ends the server at once, even during a long loop
        self._queue: queue.SimpleQueue = queue.SimpleQueue()
        self._threads = [threading.Thread(target=self._serve, name=f"mocycle-studio-{k}", daemon=True)
                         for k in range(workers)]
        for thread in self._threads:
            thread.start()
        self._live: dict[str, Job] = {}  # queued or running
        self.finished = Held("job", keep, keep_bytes)
        self.max_pending = max_pending
        self._size = size or (lambda job: held_bytes(job.result))
        self._ids = ids if ids is not None else itertools.count(1)
        self._prefix = prefix
        self._lock = threading.Lock()

    def submit(self, kind: str, fn) -> Job:
        with self._lock:
            waiting = sum(not j.cancelled() for j in self._live.values())  # a cancelled one ends when reached
            if self.max_pending is not None and waiting >= self.max_pending:
                raise HTTPProblem(f"{waiting} jobs are waiting or running; at most {self.max_pending} "
                                  "(wait for one to finish or cancel it)", HTTPStatus.TOO_MANY_REQUESTS)
            if self.max_pending is not None and len(self._live) >= LIVE_FACTOR * self.max_pending:
                # cancelled jobs wait to be reached too: bounded all the same (submit and cancel in a loop)
                raise HTTPProblem(f"{len(self._live)} jobs, some cancelled, are waiting to be reached; try again "
                                  "shortly", HTTPStatus.TOO_MANY_REQUESTS)
            job = Job(id=f"{self._prefix}{next(self._ids)}", kind=kind)
            self._live[job.id] = job
        self._queue.put((job, fn))
        return job

    def _serve(self) -> None:
        while True:
            item = self._queue.get()
            if item is None:
                return
            self._run(*item)

    def _run(self, job: Job, fn) -> None:
        try:
            self._work(job, fn)
        finally:
            size = self._size(job)
            with self._lock:
                self._live.pop(job.id, None)
                self.finished.put(job.id, job, size)
            release_memory()  # what the work made and dropped

    @staticmethod
    def _work(job: Job, fn) -> None:
        if job.cancelled():
            job.status = "cancelled"
            return
        job.status = "running"
        try:
            job.result = fn(job)
            job.status = "cancelled" if job.cancelled() else "done"
            job.progress = 1.0
        except LoopRefused as exc:  # a result that fails its own checks: refused, with the reason
            job.status, job.error = "refused", words.hints(str(exc))  # option 'force' -> Force: no CLI flags here
            job.result = {"facts": {"refused": True, "reason": job.error,
                                    "failed_checks": [f.to_dict() for f in exc.failed]}}
        except Exception as exc:  # the page shows the message; the server keeps serving
            job.status, job.error = "failed", words.hints(str(exc)) or type(exc).__name__
            if not isinstance(exc, (ValueError, MocycleError)):
                traceback.print_exc()

    def get(self, job_id: str) -> Job | None:
        with self._lock:
            job = self._live.get(job_id)
        return job if job is not None else self.finished.peek(job_id)

    def find(self, job_id: str) -> Job:
        """The job, or :class:`HTTPProblem` ``GONE`` (finished and evicted) or ``NOT_FOUND``."""
        job = self.get(job_id)
        if job is not None:
            return job
        if self.finished.was_evicted(job_id):
            raise HTTPProblem(f"job {job_id} is gone: only the last {self.finished.max_items} finished jobs are "
                              "kept (and as many as fit the studio's memory budget); run it again", HTTPStatus.GONE)
        raise HTTPProblem(f"no job {job_id}", HTTPStatus.NOT_FOUND)

    def held(self) -> int:
        """How many jobs are kept (queued, running and finished)."""
        with self._lock:
            return len(self._live) + len(self.finished)

    def cancel(self, job_id: str) -> Job | None:
        job = self.get(job_id)
        if job is not None:
            job.cancel_event.set()
        return job

    def shutdown(self) -> None:
        """Cancel what waits or runs and let the threads end (without waiting for them)."""
        with self._lock:
            for job in self._live.values():
                job.cancel_event.set()
        for _ in self._threads:
            self._queue.put(None)
