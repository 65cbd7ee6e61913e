"""``mocycle batch``: one command over many takes, on dask.distributed (the work is in :mod:`mocycle.batch`).

The options of COMMAND are the flags of its task's ``Options`` (the same flags as ``mocycle COMMAND``,
derived from the same fields); the front-end flags of the single commands (``--json``, ``--plot``, their
``-o``) are not: batch has its own ``-o`` (the output folder) and ``--suffix``.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Annotated

import click
import typer

from ..batch.take import TAKE_TIMEOUT_S
from ..errors import MocycleError
from ..tasks.options import MISSING, Flag, flag_declaration, old_flag_warning
from ..tasks.spec import SPECS
from .common import EXIT_USAGE, app, err, escape, friendly, out, print_json

#: the commands batch runs (the ones that take one file), as their specs say
BATCH_COMMANDS = tuple(name for name, spec in SPECS.items() if spec.batch)


def options_parser(command: str) -> click.Command:
    """A click command that reads INPUTS and the flags of ``tasks.<command>.Options`` (each field's flag,
    its help; on/off fields as flags, ``--no-X`` for the ones on by default)."""
    params: list[click.Parameter] = [click.Argument(["inputs"], nargs=-1)]
    for f in dataclasses.fields(SPECS[command].options):
        decls, help = [flag_declaration(f), f.name], f.metadata["help"]
        if isinstance(f.metadata.get("check"), Flag):
            params.append(click.Option(decls, is_flag=True, default=f.default, help=help))
        else:
            params.append(click.Option(decls, required=f.default is MISSING, help=help))
            params += [click.Option([old, f"{f.name}__{old.strip('-')}"], hidden=True)
                       for old in f.metadata.get("old_flags", ())]
    return click.Command(f"mocycle batch {command}", params=params, add_help_option=False)


def parse_command_line(args: list[str]):
    """``COMMAND INPUTS... [options of COMMAND]`` -> (command, inputs, Options); a usage error says what
    is wrong (an unknown command or flag, a missing value) and exits 2."""
    if not args or args[0] not in BATCH_COMMANDS:
        got = f"; got {args[0]!r}" if args else ""
        raise click.UsageError(f"COMMAND must be one of {', '.join(BATCH_COMMANDS)}{got}")
    command, rest = args[0], list(args[1:])
    parser = options_parser(command)
    ctx = parser.make_context(parser.name, rest, resilient_parsing=False)
    given = {k: v for k, v in ctx.params.items() if k != "inputs" and "__" not in k
             and ctx.get_parameter_source(k) == click.core.ParameterSource.COMMANDLINE}
    for f in dataclasses.fields(SPECS[command].options):
        for old in f.metadata.get("old_flags", ()):
            value = ctx.params.get(f"{f.name}__{old.strip('-')}")
            if value is not None:
                err.print(f"[yellow]warning:[/] {escape(old_flag_warning(f, old))}", markup=True, soft_wrap=True)
                given.setdefault(f.name, value)
    options = SPECS[command].options(**given)  # an OptionError names the flag (exit 2)
    return command, list(ctx.params["inputs"]), options


@app.command(context_settings={"ignore_unknown_options": True})
@friendly
def batch(
    args: Annotated[list[str], typer.Argument(
        metavar="ARGS", show_default=False,
        help="COMMAND INPUTS... [options of COMMAND]: COMMAND is info, phase, loop, stretch, swings or compress; "
             "INPUTS are motion files (.bvh, .amc, .fbx, .glb, .gltf), folders "
             "(searched recursively) or glob patterns; then any flag of 'mocycle COMMAND' that sets an option "
             "of the task (e.g. --harmonics 5, --root motion, --factor 2).")],
    outdir: Annotated[Path, typer.Option("--output", "-o", help="The output folder (made when missing; checked "
                                                                "before any work): the outputs mirror the input "
                                                                "tree; results.csv and results.json go here.")],
    suffix: Annotated[str | None, typer.Option(
        help="Output suffix for the takes (default: .bvh for loop and stretch, .mck for compress, .mosw for "
             "swings; any motion format 'mocycle.write' writes for loop and stretch).")] = None,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Keep the takes whose record is theirs, was made with the same options and lists "
                         "outputs that are there with the size and SHA-256 it holds, all newer than the input; "
                         "run the rest (and the ones that ended in error).")] = False,
    scheduler: Annotated[str | None, typer.Option(
        help="Address of a running dask scheduler (tcp://host:8786); default: a LocalCluster here. Workers "
             "must see the inputs and the output folder at the same paths.")] = None,
    workers: Annotated[int | None, typer.Option(
        min=1, help="LocalCluster: number of worker processes (default one per core); with --scheduler: wait "
                    "for this many workers.")] = None,
    take_timeout: Annotated[float, typer.Option(
        min=0, help="Seconds one take may run; a take that runs longer gets an error row and its worker process "
                    "is stopped (a new one takes its place). 0: no limit.")] = TAKE_TIMEOUT_S,
    as_json: Annotated[bool, typer.Option("--json", help="Print the summary as JSON (no progress).")] = False,
):
    """Run one command over many takes on dask.distributed; a row per take in OUTDIR/results.csv and .json.

    Each take is one call of the task in a single-threaded worker process; its status is ok,
    no-periodic-motion, refused (a cycle that fails its loop checks) or error, with the message. One bad
    take never stops the batch: the exit code is 0 when every take was processed whatever its status, 1
    when the run itself failed (bad inputs, no scheduler), 2 for a bad option. Beside each take's outputs
    goes its record OUTDIR/<take>.<COMMAND>.json (status, figures, the task's whole report).
    """
    try:
        command, inputs, options = parse_command_line(args)
    except click.UsageError as exc:
        err.print(f"[bold red]error:[/] {escape(exc.format_message())}", markup=True, soft_wrap=True)
        raise typer.Exit(EXIT_USAGE) from None
    if not inputs:
        raise MocycleError(f"batch {command}: no INPUTS (files, folders or glob patterns)")
    from ..batch import run_batch
    from ..batch.progress import progress_for

    progress = None if as_json else (lambda total, resumed: progress_for(err, total, resumed))
    try:
        rows, run = run_batch(command, inputs, outdir, options, suffix=suffix, resume=resume, scheduler=scheduler,
                              workers=workers, progress=progress, take_timeout_s=take_timeout)
    except MocycleError as exc:  # refused before any work, or the run itself failed: --json still says so
        if as_json:
            print_json({"status": "error", "error": str(exc), "exit_code": 1})
        raise
    if as_json:
        print_json(run)
        return
    out.print(f"{run['takes']} takes: {run['ok']} ok, {run['no-periodic-motion']} no periodic motion, "
              f"{run['refused']} refused, {run['error']} error" + (f", {run['resumed']} kept (--resume)"
                                                                     if run["resumed"] else ""))
    if run["engine"]:
        out.print(f"  {run['workers']} worker(s) at {escape(run['scheduler'])}; {run['wall_seconds']:.2f} s wall, "
                  f"{run['task_seconds']:.2f} s in the tasks", soft_wrap=True)
    out.print(f"wrote {escape(Path(outdir) / 'results.csv')} and results.json", soft_wrap=True)
