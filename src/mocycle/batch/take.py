"""The work of one take, as a worker runs it: call the task, write its outputs atomically, map the outcome
to a status, and leave a record beside the outputs (what ``--resume`` and ``results.*`` read).

Statuses: ``ok``; ``no-periodic-motion`` (:class:`~mocycle.errors.NoPeriodicMotion`, or a phase that finds
no class); ``refused`` (:class:`~mocycle.errors.LoopRefused`: a cycle that fails its loop checks); ``error``
(anything else: bad file, bad data, a bug; the message says which).
"""

from __future__ import annotations

import hashlib
import json
import time
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path

from .. import __version__
from ..errors import LoopRefused, MocycleError, NoPeriodicMotion
from ..tasks.options import Options
from .commands import COMMANDS, motion_targets
from .discover import Take

__all__ = ["STATUSES", "Job", "fresh_record", "process", "status_of"]

STATUSES = ("ok", "no-periodic-motion", "refused", "error")


@dataclass(frozen=True)
class Job:
    """What every take of a batch shares (sent to the workers once per take; small and picklable).

    command : the task name; options : its ``Options``; outdir : the output folder (absolute);
    suffix : the output suffix (``None``: the command writes only its record).
    """

    command: str
    options: Options
    outdir: Path
    suffix: str | None

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
    """
    from .. import tasks
    from ..io import write
    from ..io.atomic import atomic_write

    t0 = time.perf_counter()
    command = COMMANDS[job.command]
    row = {"file": str(take.source), "rel": str(take.rel), "status": "ok", "message": "", "figures": {},
           "seconds": None, "wall_seconds": None, "outputs": [], "warnings": [], "facts": None}
    written: list[Path] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            report = getattr(tasks, job.command).run(take.source, job.options)  # that task's module only
            row["facts"], row["seconds"] = dict(report.facts), report.seconds
            row["warnings"] = list(report.warnings)
            row["figures"] = _figures(command, report.facts)
            if job.command == "phase" and not report.facts["classes"]:
                row["status"], row["message"] = "no-periodic-motion", report.facts["reason"]
            else:
                _write_outputs(job, command, take, report, write, written)
        except Exception as exc:  # one bad take never stops the batch: its row says what happened
            row["status"], row["message"] = status_of(exc), message_of(exc)
            for path in written:  # a take that failed part-way leaves none of its outputs
                path.unlink(missing_ok=True)
            written = []
    row["warnings"] += [str(w.message) for w in caught if not issubclass(w.category, DeprecationWarning)
                        and str(w.message) not in row["warnings"]]
    row["outputs"] = [p.relative_to(job.outdir).as_posix() for p in written]
    record = job.record_path(take)
    _remove_stale(job.outdir, record, set(row["outputs"]))
    row["wall_seconds"] = time.perf_counter() - t0
    row["worker"] = _worker_name()
    row["options_hash"] = job.options_hash
    row["record"] = record.relative_to(job.outdir).as_posix()
    record.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(record, json_text(row))
    return row


def _figures(command, facts) -> dict:
    out = {}
    for name, get in command.figures.items():
        try:
            out[name] = get(facts)
        except (KeyError, IndexError, TypeError):
            out[name] = None
    return out


def _write_outputs(job: Job, command, take: Take, report, write, written: list[Path]) -> None:
    """Write the take's outputs; ``written`` gets each file as soon as it is whole."""
    if command.writes is None:
        return
    target = take.output(job.outdir, job.suffix)
    target.parent.mkdir(parents=True, exist_ok=True)
    if command.writes == "motion":
        for role, path in motion_targets(report, target).items():
            written.append(write(report.motions[role], path))
        return
    written.append(write(report.result, target))  # a Compressed take (.mck) or a Segmentation (.mosw / .json)


def _remove_stale(outdir: Path, record: Path, keep: set[str]) -> None:
    """Remove the outputs the previous record of this take lists (relative to ``outdir``) that this run did not
    write; nothing outside ``outdir``."""
    try:
        old = json.loads(record.read_text(encoding="utf-8"))
        for name in old.get("outputs", []):
            path = (outdir / name).resolve()
            if name not in keep and outdir in path.parents:
                path.unlink(missing_ok=True)
    except (OSError, ValueError, AttributeError):
        pass


def fresh_record(job: Job, take: Take) -> dict | None:
    """The record of an earlier run of this take that ``--resume`` may keep, else ``None``.

    Kept when the record was made with the same options hash, its status is not ``error`` (errors are tried
    again), every output it lists exists, and the record and outputs are newer than the take's input files.
    """
    record = job.record_path(take)
    try:
        row = json.loads(record.read_text(encoding="utf-8"))
        if row.get("options_hash") != job.options_hash or row.get("status") not in STATUSES[:3]:
            return None
        made = [record] + [job.outdir / p for p in row.get("outputs", [])]
        oldest_output = min(p.stat().st_mtime for p in made)
        newest_input = max(p.stat().st_mtime for p in take.inputs())
    except (OSError, ValueError, AttributeError, TypeError):
        return None
    return row if oldest_output >= newest_input else None


def json_text(data) -> str:
    """Strict JSON (non-finite numbers as null, and it says which), as the CLI's ``--json`` writes it."""
    from ..cli.common import json_text

    return json_text(data, indent=1)
