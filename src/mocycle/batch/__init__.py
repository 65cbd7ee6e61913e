"""``mocycle batch``: one command over a whole library of takes, on dask.distributed.

A front end like the CLI: each take is one call of the task layer (``mocycle.tasks.<command>.run``) in a
worker process (:mod:`.take`); :mod:`.discover` finds the takes, :mod:`.engine` runs them on a LocalCluster
or an existing scheduler, :mod:`.results` writes ``results.csv`` and ``results.json``. Importing this package
does not import dask (only :func:`run_batch` does).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from contextlib import ExitStack
from pathlib import Path

from ..tasks.options import Options
from . import forkserver
from .commands import COMMANDS, check_suffix
from .discover import Take, find_takes
from .take import Job, fresh_record

__all__ = ["COMMANDS", "Job", "Take", "find_takes", "run_batch"]


def run_batch(command: str, inputs: list, outdir: str | Path, options: Options, *, suffix: str | None = None,
              resume: bool = False, scheduler: str | None = None, workers: int | None = None,
              progress: Callable | None = None) -> tuple[list[dict], dict]:
    """Run ``command`` over the takes of ``inputs``; write the outputs under ``outdir`` and the results files.

    progress : ``progress(total, resumed)`` -> an object with ``advance(row)`` usable as a context manager
        (:func:`.progress.progress_for`); ``None``: silent.
    Returns the rows (in the order of the takes) and ``summary``-style run facts (``results.json``'s ``run``).

    Raises MocycleError (nothing is run) for bad inputs, a bad suffix or an output folder that cannot be made;
    a failure of the engine itself (no scheduler, all workers gone) propagates.
    """
    t0 = time.perf_counter()
    outdir = Path(outdir).resolve()
    suffix = check_suffix(COMMANDS[command], suffix)
    takes = find_takes(inputs, outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    job = Job(command=command, options=options, outdir=outdir, suffix=suffix)
    _refuse_overwriting_inputs(job, takes)
    rows: dict[Path, dict] = {}
    if resume:
        for take in takes:
            row = fresh_record(job, take)
            if row is not None:
                rows[take.source] = {**row, "resumed": True}
    todo = [t for t in takes if t.source not in rows]
    run = {"engine": None, "scheduler": None, "workers": 0, "worker_start": None}
    with ExitStack() as stack:
        if todo and scheduler is None:  # the workers' imports begin now, while this process imports dask
            stack.enter_context(forkserver.warm_workers(COMMANDS[command].imports))
        from .results import summary, write_results  # (numpy, scipy: mocycle.io)

        shown = progress(len(takes), len(rows)) if progress is not None else None
        if todo:
            from .engine import run_takes

            if shown is not None:
                stack.enter_context(shown)

            def on_row(row):
                rows[Path(row["file"])] = {**row, "resumed": False}
                if shown is not None:
                    shown.advance(row)

            run = run_takes(job, todo, on_row, scheduler=scheduler, workers=workers)
    ordered = [rows[t.source] for t in takes]
    run = {**run, "wall_seconds": time.perf_counter() - t0, "options_hash": job.options_hash, "suffix": suffix}
    write_results(outdir, command, options.to_dict(), ordered, run)
    return ordered, {**run, **summary(ordered)}


def _refuse_overwriting_inputs(job: Job, takes: list[Take]) -> None:
    from ..errors import MocycleError

    sources = {t.source.resolve() for t in takes}
    for take in takes:
        for path in ([take.output(job.outdir, job.suffix)] if job.suffix else []) + [job.record_path(take)]:
            if path.resolve() in sources:
                raise MocycleError(f"{path}: the output of {take.source} would replace an input; choose another -o")
