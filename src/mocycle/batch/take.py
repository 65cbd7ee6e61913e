"""The work of one take, as a worker runs it: call the task, write its outputs atomically, map the outcome
to a status, and leave a record beside the outputs (what ``--resume`` and ``results.*`` read).

Statuses: ``ok``; ``no-periodic-motion`` (:class:`~mocycle.errors.NoPeriodicMotion`, or a phase that finds
no class); ``refused`` (:class:`~mocycle.errors.LoopRefused`: a cycle that fails its loop checks); ``error``
(anything else: bad file, bad data, a bug; the message says which).
"""

from __future__ import annotations

import hashlib
import json
import os
import threading
import time
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path

from .. import __version__
from ..errors import LoopRefused, MocycleError, NoPeriodicMotion
from ..tasks.flags import as_flags
from ..tasks.options import Options
from ..tasks.spec import row_figures
from ..text import json_text, path_hex, printable
from .commands import COMMANDS, motion_targets, part_rows
from .discover import Take

__all__ = ["STATUSES", "Job", "base_row", "fresh_record", "problem_row", "process", "row_key", "status_of",
           "take_key"]

STATUSES = ("ok", "no-periodic-motion", "refused", "error")
#: seconds a take may run in a batch by default (``mocycle batch --take-timeout``)
TAKE_TIMEOUT_S = 3600.0


@dataclass(frozen=True)
class Job:
    """What every take of a batch shares (sent to the workers once per take; small and picklable).

    command : the task name; options : its ``Options``; outdir : the output folder (absolute);
    suffix : the output suffix (``None``: the command writes only its record); timeout_s : see
    :func:`process`; run_id : what tells this run's records from an earlier run's.
    """

    command: str
    options: Options
    outdir: Path
    suffix: str | None
    #: seconds one take may run before its worker is stopped and its row says so (``None``: no limit)
    timeout_s: float | None = None
    #: this batch run (a take that overran in it is not run again within it)
    run_id: str = ""

    @property
    def options_hash(self) -> str:
        """A hash of what decides a take's outputs: command, options, suffix and mocycle's version."""
        text = json.dumps({"command": self.command, "options": self.options.to_dict(), "suffix": self.suffix,
                           "version": __version__}, sort_keys=True, default=repr)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def record_path(self, take: Take) -> Path:
        """``OUTDIR/<rel stem>.<command>.json``: the take's record (its row and the task's whole report)."""
        return self.outdir / take.rel.with_suffix(f".{self.command}.json")


def status_of(exc: BaseException) -> str:
    """The status of a take that raised ``exc``."""
    if isinstance(exc, NoPeriodicMotion):
        return "no-periodic-motion"
    if isinstance(exc, LoopRefused):
        return "refused"
    return "error"


def message_of(exc: BaseException) -> str:
    """One line: a mocycle error's own message; for anything else (a bug) the type and where it was raised."""
    if isinstance(exc, MocycleError):
        return str(exc)
    where = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
    at = f" (at {Path(where.filename).name}:{where.lineno})" if where else ""
    return f"{type(exc).__name__}: {exc}{at}"


def _worker_name() -> str | None:
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return None


def process(job: Job, take: Take) -> dict:
    """Run ``job`` on one take and return its row; never raises for a bad take (its row says ``error``).

    The outputs are written atomically (``mocycle.io.write``), then the record; outputs an earlier run left
    at this take's place that this run does not write again are removed, so the tree agrees with the row.
    A take that runs past ``job.timeout_s`` gets its record (status ``error``, saying so) written by a watchdog,
    which then ends the worker process: a thread cannot be stopped, a process can (a LocalCluster's nanny
    starts a new worker; the scheduler gives it the take again, which then returns that record at once).
    """
    overran = _overran(job, take)
    if overran is not None:
        return overran
    watchdog = None
    if job.timeout_s:
        watchdog = threading.Timer(job.timeout_s, _stop_overrunning, (job, take))
        watchdog.daemon = True
        watchdog.start()
    try:
        return _process(job, take)
    finally:
        if watchdog is not None:
            watchdog.cancel()


def _overran(job: Job, take: Take) -> dict | None:
    """The record this run's watchdog left for ``take`` (it ran over the time limit), or ``None``."""
    try:
        row = json.loads(job.record_path(take).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return row if isinstance(row, dict) and row.get("overran_in") == job.run_id and job.run_id else None


def _stop_overrunning(job: Job, take: Take) -> None:
    """The watchdog: the take's record says it ran over the limit, then this worker process ends."""
    row = {**base_row(job, take), "status": "error", "overran_in": job.run_id, "worker": _worker_name(),
           "message": f"the take ran longer than --take-timeout ({job.timeout_s:g} s); its worker process was "
                      f"stopped", "wall_seconds": job.timeout_s, "output_checks": []}
    try:
        from ..io.atomic import atomic_write

        job.record_path(take).parent.mkdir(parents=True, exist_ok=True)
        atomic_write(job.record_path(take), json_text(row, indent=1))
    finally:
        os._exit(75)  # the whole worker: the take's thread cannot be stopped on its own


def _process(job: Job, take: Take) -> dict:
    from .. import tasks
    from ..io import write
    from ..io.atomic import atomic_write

    t0 = time.perf_counter()
    command = COMMANDS[job.command]
    row = base_row(job, take)
    written: list[Path] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            report = getattr(tasks, job.command).run(take.source, job.options)  # that task's module only
            row["facts"], row["seconds"] = dict(report.facts), report.seconds
            row["warnings"] = list(report.warnings)
            row["figures"] = row_figures(command.spec, report.facts)
            if job.command == "loop":  # a take cut into parts: a results row per part
                row["parts"] = part_rows(command, report.facts)
            if job.command == "phase" and not report.facts["classes"]:
                row["status"], row["message"] = "no-periodic-motion", report.facts["reason"]
            else:
                _write_outputs(job, command, take, report, write, written)
        except Exception as exc:  # one bad take never stops the batch: its row says what happened
            row["status"], row["message"] = status_of(exc), printable(message_of(exc))
            for path in written:  # a take that failed part-way leaves none of its outputs
                path.unlink(missing_ok=True)
            written = []
    row["warnings"] += [str(w.message) for w in caught if not issubclass(w.category, DeprecationWarning)
                        and str(w.message) not in row["warnings"]]
    # a batch is run from a shell: a message's hints (option 'force') said as the command's flags (--force)
    row["message"] = as_flags(row["message"], job.command)
    row["warnings"] = [as_flags(w, job.command) for w in row["warnings"]]
    row["outputs"] = [printable(p.relative_to(job.outdir).as_posix()) for p in written]
    record = job.record_path(take)
    try:
        row["output_checks"] = [_check_of(take, p) for p in written]
        _remove_stale(job, take, {c["tail"] for c in row["output_checks"]})
        row["wall_seconds"] = time.perf_counter() - t0
        row["worker"] = _worker_name()
        record.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(record, json_text(row, indent=1))
    except OSError as exc:  # a name too long, a read-only or immutable record or folder: the row says so
        row["status"] = "error"
        row["message"] = printable(f"cannot write its record {record.name} ({exc.strerror or exc})"
                                   + (f"; before that: {row['message']}" if row["message"] else ""))
        row["record"] = None
        row.setdefault("output_checks", [])
        row["wall_seconds"] = time.perf_counter() - t0
    return row


def base_row(job: Job, take: Take) -> dict:
    """The row of a take before it runs. ``file`` and ``rel`` are the paths as printable text
    (:func:`mocycle.text.printable`: a byte that is not UTF-8 as ``\\xNN``, control characters escaped); when
    that differs from the real name (a name that is not UTF-8), ``file_hex`` holds the path's bytes in hex."""
    row: dict[str, object] = {
        "file": printable(take.source), "rel": printable(take.rel.as_posix()), "status": "ok", "message": "",
        "figures": {}, "seconds": None, "wall_seconds": None, "outputs": [], "warnings": [], "facts": None,
        "worker": None, "options_hash": job.options_hash,
        "record": printable(job.record_path(take).relative_to(job.outdir).as_posix())}
    if path_hex(take.source) is not None:
        row["file_hex"] = path_hex(take.source)
    return row


def row_key(row: dict) -> tuple:
    """What tells the rows of two takes apart (the printable name and, for a name that is not UTF-8, its
    bytes)."""
    return row["file"], row.get("file_hex")


def take_key(take: Take) -> tuple:
    """:func:`row_key` of the take's row."""
    return printable(take.source), path_hex(take.source)


def problem_row(job: Job, take: Take) -> dict:
    """The row of a path that cannot be read as a take (:attr:`Take.problem`): status ``error``, no record."""
    return {**base_row(job, take), "status": "error", "message": printable(take.problem), "record": None}


def _tail(take: Take, path: Path) -> str:
    """What an output's name adds to the take's stem (``walk.class1.bvh`` -> ``.class1.bvh``); always text
    mocycle made (a role and a suffix), so a record can name its outputs whatever the take's name."""
    stem = take.rel.with_suffix("").name
    assert path.name.startswith(stem), (path, stem)
    return path.name[len(stem):]


def _output_of(job: Job, take: Take, tail: str) -> Path:
    return job.outdir / take.rel.parent / (take.rel.with_suffix("").name + tail)


def _digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _check_of(take: Take, path: Path) -> dict:
    """An output as its record lists it: its name after the take's stem, its size and its SHA-256."""
    return {"tail": _tail(take, path), "bytes": path.stat().st_size, "sha256": _digest(path)}


def _write_outputs(job: Job, command, take: Take, report, write, written: list[Path]) -> None:
    """Write the take's outputs; ``written`` gets each file as soon as it is whole."""
    if command.writes is None:
        return
    assert job.suffix is not None  # a command that writes a file has a suffix (check_suffix)
    target = take.output(job.outdir, job.suffix)
    target.parent.mkdir(parents=True, exist_ok=True)
    if command.writes == "motion":
        for role, path in motion_targets(report, target).items():
            written.append(write(report.motions[role], path))
        return
    written.append(write(report.result, target))  # a Compressed take (.mck) or a Segmentation (.mosw / .json)


def _remove_stale(job: Job, take: Take, keep: set[str]) -> None:
    """Remove the outputs the previous record of this take lists that this run did not write (``keep``: the
    tails of the ones it wrote); only when that record is this take's own (same file), nothing outside
    ``outdir``."""
    try:
        old = json.loads(job.record_path(take).read_text(encoding="utf-8"))
        if not _same_take(old, take):
            return
        if "output_checks" in old:
            stale = [_output_of(job, take, c["tail"]) for c in old["output_checks"]
                     if c["tail"] not in keep and "/" not in c["tail"]]
        else:  # a record of an older mocycle: its outputs by their names relative to the output folder
            kept = {_output_of(job, take, tail) for tail in keep}
            stale = [job.outdir / name for name in old.get("outputs", []) if job.outdir / name not in kept]
        for path in stale:
            if job.outdir in path.resolve().parents:
                path.unlink(missing_ok=True)
    except (OSError, ValueError, AttributeError, TypeError, KeyError):
        pass


def _same_take(record: dict, take: Take) -> bool:
    return (record.get("file"), record.get("file_hex")) == (printable(take.source), path_hex(take.source))


def fresh_record(job: Job, take: Take) -> dict | None:
    """The record of an earlier run of this take that ``--resume`` may keep, else ``None`` (the take runs again).

    Kept when the record is this take's (the same input file, the same relative path and record name), was
    made with the same options hash, its status is not ``error`` (errors are tried again), every output it
    lists exists with the size and SHA-256 the record holds, and the record and outputs are newer than the
    take's input files. A record of an older mocycle without the outputs' sizes and hashes is not kept.
    """
    record = job.record_path(take)
    try:
        row = json.loads(record.read_text(encoding="utf-8"))
        expected = base_row(job, take)
        if (row.get("options_hash") != job.options_hash or row.get("status") not in STATUSES[:3]
                or not _same_take(row, take) or row.get("rel") != expected["rel"]
                or row.get("record") != expected["record"]):
            return None
        checks = row.get("output_checks")
        if not isinstance(checks, list) or len(checks) != len(row.get("outputs", [])):
            return None
        made = [record]
        for check in checks:
            path = _output_of(job, take, check["tail"])
            if "/" in check["tail"] or path.stat().st_size != check["bytes"] or _digest(path) != check["sha256"]:
                return None
            made.append(path)
        oldest_output = min(p.stat().st_mtime for p in made)
        newest_input = max(p.stat().st_mtime for p in take.inputs())
    except (OSError, ValueError, AttributeError, TypeError, KeyError):
        return None
    return row if oldest_output >= newest_input else None
