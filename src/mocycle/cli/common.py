"""What every ``mocycle`` sub-command shares: the typer app, consoles, exit codes, error handling."""

from __future__ import annotations

import dataclasses
import json
import sys
import warnings
from collections.abc import Callable, Mapping
from functools import wraps
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

from .. import __version__
from ..errors import LoopRefused, MocycleError, NoPeriodicMotion, OptionError
from ..tasks import TASKS
from ..tasks.loop import parse_range  # noqa: F401  (convert uses it)
from ..tasks.options import MISSING, Choice, flag_of

app = typer.Typer(
    name="mocycle",
    help="Turn raw motion capture into reusable animation.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # plain click help: flags show as `--json`, not `--json <bool>`
)
out = Console(highlight=False)
err = Console(stderr=True, highlight=False)

EXIT_ERROR = 1
EXIT_USAGE = 2  # a bad option value (typer/click use 2 for usage errors too)
EXIT_NOT_FOUND = 3  # the input is fine but holds no periodic motion, or its cycle is not a loop

#: parameter names of the library -> the CLI flag that sets them (every task option, and a few library names)
FLAGS = {f.name: flag_of(f) for task in TASKS.values() for f in dataclasses.fields(task.Options)}
FLAGS.update({"n_harmonics": "--harmonics", "time_axis_method": "--time", "phase_step": "--step",
              "n_classes": "--classes", "seed": "--seed-projection", "count": "--cycles",
              "window": "--window"})


def option_message(exc: OptionError) -> str:
    """The error with the flag instead of the library's parameter name (``--cycles must be ...``)."""
    return f"{FLAGS.get(exc.parameter, exc.parameter)} {exc.reason}"


def friendly(func: Callable) -> Callable:
    """Run a command: MocycleError -> one 'error:' line and exit 1 (2 for a bad option value, 3 for
    NoPeriodicMotion and LoopRefused); warnings (the command's and its reports') -> 'warning:' lines."""

    @wraps(func)
    def wrapper(*args, **kwargs):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                result = func(*args, **kwargs)
            except OptionError as exc:
                _print_warnings(caught)
                err.print(f"[bold red]error:[/] {option_message(exc)}", markup=True, soft_wrap=True)
                raise typer.Exit(EXIT_USAGE) from None
            except MocycleError as exc:
                _print_warnings(caught)
                err.print(f"[bold red]error:[/] {exc}", markup=True, soft_wrap=True)
                refused = isinstance(exc, (NoPeriodicMotion, LoopRefused))
                raise typer.Exit(EXIT_NOT_FOUND if refused else EXIT_ERROR) from None
        _print_warnings(caught)
        return result

    return wrapper


def _print_warnings(caught) -> None:
    for w in caught:
        if issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning)):
            continue
        err.print(f"[yellow]warning:[/] {w.message}", markup=True, soft_wrap=True)


def print_warnings(report) -> None:
    """The warnings a task recorded in its report, as 'warning:' lines."""
    for text in report.warnings:
        err.print(f"[yellow]warning:[/] {text}", markup=True, soft_wrap=True)


def _version(value: bool):
    if value:
        out.print(f"mocycle {__version__}")
        raise typer.Exit()


@app.callback()
def main_options(
    version: Annotated[bool, typer.Option("--version", callback=_version, is_eager=True,
                                          help="Print the version and exit.")] = False,
):
    """mocycle: periodic motion, seamless cycles, swings and keyframes from mocap files."""



# ------------------------------------------------------------ options derived from the task Options
def _field(options_cls, name: str) -> dataclasses.Field:
    for f in dataclasses.fields(options_cls):
        if f.name == name:
            return f
    raise KeyError(f"{options_cls.__module__}.Options has no field {name!r}")


def flag(options_cls, name: str, *short: str, **kwargs) -> typer.models.OptionInfo:
    """The typer option of an Options field: its flag (plus short names) and its help line."""
    f = _field(options_cls, name)
    names = flag_of(f)
    if f.default is True:  # a flag that is on by default also gets its --no- form
        names = f"{names}/--no-{names[2:]}"
    check = f.metadata.get("check")
    if isinstance(check, Choice) and "metavar" not in kwargs:  # --method <harmonic|centroid|cut>
        kwargs["metavar"] = f"<{'|'.join(check.choices)}>"
    return typer.Option(names, *short, help=f.metadata.get("help", ""), **kwargs)


def default(options_cls, name: str):
    """The default of an Options field (what the CLI flag defaults to); ``...`` for a required one."""
    d = _field(options_cls, name).default
    return ... if d is MISSING else d


def as_flag_text(value) -> str:
    return value if isinstance(value, str) else str(value)


def timing_line(report) -> str:
    """``time 2.42 s`` (with the labelled parts when there are several)."""
    parts = [f"{k} {v:.2f} s" for k, v in report.timings_s.items() if k != "total"]
    return f"  time {report.seconds:.2f} s" + (f" ({', '.join(parts)})" if parts else "")


def print_json(facts: Mapping, indent: int | None = 2) -> None:
    print(json.dumps(facts, indent=indent))


# ------------------------------------------------------------ option parsing
def check_suffix(path: Path | None, suffix: str, option: str = "-o") -> None:
    """Refuse an output path without the expected suffix, before any work is done (nothing gets written)."""
    if path is not None and path.suffix.lower() != suffix:
        raise MocycleError(f"{path}: {option} must name a {suffix} file")


def main() -> None:  # the console script
    try:
        app()
    except KeyboardInterrupt:  # pragma: no cover
        err.print("interrupted")
        sys.exit(130)
