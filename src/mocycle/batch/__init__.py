"""``mocycle batch``: one command over a whole library of takes, on dask.distributed.

A front end like the CLI: each take is one call of the task layer (``mocycle.tasks.<command>.run``) in a
worker process (:mod:`.take`); :mod:`.discover` finds the takes, :mod:`.engine` runs them on a LocalCluster
or an existing scheduler, :mod:`.results` writes ``results.csv`` and ``results.json``. Importing this package
does not import dask (only :func:`run_batch` does).
"""

from __future__ import annotations

import dataclasses
import os
import tempfile
import time
import uuid
from collections.abc import Callable
from contextlib import ExitStack
from pathlib import Path

from ..errors import MocycleError
from ..tasks.options import Options
from ..text import printable
from . import forkserver
from .commands import COMMANDS, check_suffix
from .discover import Take, find_takes
from .take import TAKE_TIMEOUT_S, Job, fresh_record, problem_row, row_key, take_key

__all__ = ["COMMANDS", "Job", "Take", "find_takes", "run_batch"]


def run_batch(command: str, inputs: list, outdir: str | Path, options: Options, *, suffix: str | None = None,
              resume: bool = False, scheduler: str | None = None, workers: int | None = None,
              progress: Callable | None = None,
              take_timeout_s: float | None = TAKE_TIMEOUT_S) -> tuple[list[dict], dict]:
    """Run ``command`` over the takes of ``inputs``; write the outputs under ``outdir`` and the results files.

    progress : ``progress(total, resumed)`` -> an object with ``advance(row)`` usable as a context manager
        (:func:`.progress.progress_for`); ``None``: silent.
    take_timeout_s : seconds a take may run; one that runs longer gets an ``error`` row and its worker process
        is stopped (:func:`.take.process`); ``None`` or 0: no limit.
    Returns the rows (in the order of the takes) and ``summary``-style run facts (``results.json``'s ``run``).

    Raises MocycleError (nothing is run) for an output folder that cannot be made or written (checked first),
    bad inputs, a bad suffix, or outputs whose names collide (:func:`check_collisions`); a failure of the
    engine itself (no scheduler, all workers gone) propagates. Paths found that cannot be read as takes
    (:attr:`Take.problem`) get a row with status ``error`` and are not sent to the workers.
    """
    t0 = time.perf_counter()
    outdir = check_outdir(Path(outdir))
    suffix = check_suffix(COMMANDS[command], suffix)
    takes = find_takes(inputs, outdir)
    if take_timeout_s is not None and not (take_timeout_s >= 0 and take_timeout_s < float("inf")):
        raise MocycleError(f"the take timeout must be a number of seconds >= 0; got {take_timeout_s!r}")
    if any(f.name == "workers" for f in dataclasses.fields(options)):  # each take runs on one worker process
        one_worker: dict[str, object] = {"workers": 1, "scheduler": None}  # fields of that task's Options only
        options = dataclasses.replace(options, **one_worker)
    job = Job(command=command, options=options, outdir=outdir, suffix=suffix, timeout_s=take_timeout_s or None,
              run_id=uuid.uuid4().hex)
    _refuse_overwriting_inputs(job, takes)
    check_collisions(job, takes)
    make_outdir(outdir)
    rows: dict[tuple, dict] = {}
    problems = [{**problem_row(job, t), "resumed": False} for t in takes if t.problem is not None]
    for row in problems:
        rows[row_key(row)] = row
    if resume:
        for take in takes:
            record = fresh_record(job, take) if take.problem is None else None
            if record is not None:
                rows[take_key(take)] = {**record, "resumed": True}
    todo = [t for t in takes if take_key(t) not in rows]
    run: dict[str, object] = {"engine": None, "scheduler": None, "workers": 0, "worker_start": None}
    with ExitStack() as stack:
        if todo and scheduler is None:  # the workers' imports begin now, while this process imports dask
            stack.enter_context(forkserver.warm_workers(COMMANDS[command].imports))
        from .results import summary, write_results  # (numpy, scipy: mocycle.io)

        kept = len(rows) - len(problems)
        shown = progress(len(takes), kept) if progress is not None else None
        if shown is not None and (todo or problems):
            stack.enter_context(shown)
            for row in problems:
                shown.advance(row, ran=False)
        if todo:
            from .engine import run_takes

            def on_row(row):
                rows[row_key(row)] = {**row, "resumed": False}
                if shown is not None:
                    shown.advance(row)

            run = run_takes(job, todo, on_row, scheduler=scheduler, workers=workers)
    ordered = [rows[take_key(t)] for t in takes]
    run = {**run, "wall_seconds": time.perf_counter() - t0, "options_hash": job.options_hash, "suffix": suffix}
    try:
        write_results(outdir, command, options.to_dict(), ordered, run)
    except OSError as exc:
        raise MocycleError(f"{outdir}: cannot write results.csv and results.json ({exc.strerror or exc})") from None
    return ordered, {**run, **summary(ordered)}


def check_outdir(outdir: Path) -> Path:
    """The output folder as an absolute path, or one clear error before anything is read or run: ``-o`` names
    a file, a file stands where a folder of the path should be, or the nearest existing folder cannot be
    written."""
    outdir = Path(outdir).absolute()
    if outdir.exists() and not outdir.is_dir():
        raise MocycleError(f"{outdir}: -o names a file; it must be a folder (made when missing)")
    probe = outdir
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if not probe.is_dir():
        raise MocycleError(f"{outdir}: -o: {probe} is a file, not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise MocycleError(f"{outdir}: -o: the folder {probe} is not writable")
    return outdir.resolve()


def make_outdir(outdir: Path) -> None:
    """Make the output folder and prove it can take a file (a read-only file system, a full disk, permissions
    ``os.access`` does not see), before any work."""
    try:
        outdir.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=outdir, prefix=".mocycle-batch-probe."):
            pass
    except OSError as exc:
        raise MocycleError(f"{outdir}: -o: cannot write in this folder ({exc.strerror or exc})") from None


#: the files a batch writes at the top of the output folder
RESULTS_FILES = ("results.csv", "results.json")


def check_collisions(job: Job, takes: list[Take]) -> None:
    """Refuse, before any work, outputs whose names collide: two takes' outputs or records, or one with the
    batch's ``results.csv``/``results.json`` (``walk.bvh``'s record ``walk.swings.json`` is the output of
    ``walk.swings.bvh`` under ``batch swings --suffix .json``; the output of ``results.bvh`` would be
    ``results.json``). Every collision is named in the one error."""
    claims: dict[str, list[str]] = {}

    def claim(path: Path, what: str) -> None:
        claims.setdefault(os.path.normcase(str(path)), []).append(what)

    for name in RESULTS_FILES:
        claim(job.outdir / name, f"the batch's {name}")
    patterns = []
    output = COMMANDS[job.command].output
    for take in takes:
        if take.problem is not None:
            continue
        rel = printable(take.rel.as_posix())
        claim(job.record_path(take), f"the record of {rel}")
        if job.suffix:
            assert output is not None  # a suffix is an output's (check_suffix)
            target = take.output(job.outdir, job.suffix)
            claim(target, f"the output of {rel}")
            every = output.every_target(target, job.options)  # --part all: one file per part, parts unknown yet
            if every is not None:
                patterns.append((every, f"the outputs of {rel} (--part all)"))
    found = [(path, whats) for path, whats in claims.items() if len(whats) > 1]
    for pattern, what in patterns:
        found += [(path, [what, *whats]) for path, whats in claims.items() if pattern.match(path)]
    if found:
        shown = "; ".join(f"{printable(p)} would be {' and '.join(w)}" for p, w in sorted(found)[:5])
        more = f" (and {len(found) - 5} more)" if len(found) > 5 else ""
        raise MocycleError(f"output names collide, nothing was run: {shown}{more}. Rename the takes, choose "
                           f"another --suffix or batch them separately")


def _refuse_overwriting_inputs(job: Job, takes: list[Take]) -> None:
    sources = {t.source.resolve() for t in takes if t.problem is None}
    for take in takes:
        if take.problem is not None:
            continue
        for path in ([take.output(job.outdir, job.suffix)] if job.suffix else []) + [job.record_path(take)]:
            if path.resolve() in sources:
                raise MocycleError(f"{path}: the output of {take.source} would replace an input; choose another -o")
