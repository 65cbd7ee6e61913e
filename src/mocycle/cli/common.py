"""What every ``mocycle`` sub-command shares: the typer app, consoles, exit codes, error handling."""

from __future__ import annotations

import json
import math
import os
import warnings
from collections.abc import Callable
from functools import wraps
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.markup import escape

from .. import __version__
from ..errors import LoopRefused, MocycleError, NoPeriodicMotion

app = typer.Typer(
    name="mocycle",
    help="Turn raw motion capture into reusable animation.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
out = Console(highlight=False)
err = Console(stderr=True, highlight=False)

FORCE_HELP = "Allow an output to replace one of the input files."

EXIT_ERROR = 1
EXIT_NOT_FOUND = 3  # the input is fine but holds no periodic motion, or its cycle is not a loop


def friendly(func: Callable) -> Callable:
    """Run a command: MocycleError -> one 'error:' line and exit 1 (3 for NoPeriodicMotion and LoopRefused);
    warnings -> 'warning:' lines."""

    @wraps(func)
    def wrapper(*args, **kwargs):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                result = func(*args, **kwargs)
            except MocycleError as exc:
                _print_warnings(caught)
                message = _naming_the_input(str(exc), kwargs)
                err.print(f"[bold red]error:[/] {escape(message)}", markup=True, soft_wrap=True)
                refused = isinstance(exc, (NoPeriodicMotion, LoopRefused))
                raise typer.Exit(EXIT_NOT_FOUND if refused else EXIT_ERROR) from None
        _print_warnings(caught)
        return result

    return wrapper


#: The command arguments that name input files.
INPUT_ARGUMENTS = ("path", "query", "first", "second", "paths")


def _naming_the_input(message: str, kwargs: dict) -> str:
    """``message`` with the input file in front when it names none of the command's files (so that in
    ``blend`` or ``transition`` the user can tell which take is meant).  Option errors stay as they are."""
    inputs = []
    for key in INPUT_ARGUMENTS:
        value = kwargs.get(key)
        inputs += [str(v) for v in value] if isinstance(value, (list, tuple)) else [str(value)] if value else []
    files = inputs + [str(v) for v in kwargs.values() if isinstance(v, Path)]
    if len(inputs) != 1 or any(f in message for f in files) or message.startswith("-") or " --" in message:
        return message
    return f"{inputs[0]}: {message}"


def _print_warnings(caught) -> None:
    for w in caught:
        if issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning)):
            continue
        err.print(f"[yellow]warning:[/] {escape(str(w.message))}", markup=True, soft_wrap=True)


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



# ------------------------------------------------------------ option parsing
def check_suffix(path: Path | None, suffix: str, option: str = "-o") -> None:
    """Refuse an output path without the expected suffix, before any work is done (nothing gets written)."""
    if path is not None and path.suffix.lower() != suffix:
        raise MocycleError(f"{path}: {option} must name a {suffix} file")


def check_output(path: Path | None, inputs=(), force: bool = False, suffix: str | tuple[str, ...] | None = None,
                 option: str = "-o") -> None:
    """Refuse an output before any work is done: wrong suffix, a folder that is missing or not writable,
    a folder in its place, or one of the ``inputs`` (unless ``force``).  Nothing gets written here."""
    if path is None:
        return
    if suffix is not None:
        suffixes = (suffix,) if isinstance(suffix, str) else tuple(suffix)
        if path.suffix.lower() not in suffixes:
            raise MocycleError(f"{path}: {option} must name a {' or '.join(suffixes)} file")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise MocycleError(f"{path}: {option}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise MocycleError(f"{path}: {option}: the folder {folder} is not writable")
    if path.is_dir():
        raise MocycleError(f"{path}: {option} names a folder; expected a file")
    for source in inputs:
        if source is not None and _same_file(path, Path(source)):
            if not force:
                raise MocycleError(f"{path}: {option} is the input {source}; pass --force to replace it")


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def check_folder(folder: Path, option: str = "--out") -> None:
    """Refuse an output folder that cannot be made or written, before any work is done."""
    probe = folder
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise MocycleError(f"{folder}: {option}: {probe} is a file, not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise MocycleError(f"{folder}: {option}: {probe} is not writable")


def write_text(path: Path, text: str | bytes, what: str = "file") -> Path:
    """Write an output through the atomic writer; an OS error becomes one clear MocycleError."""
    from ..io.atomic import atomic_write

    try:
        return atomic_write(path, text)
    except OSError as exc:
        raise MocycleError(f"{path}: cannot write the {what} ({exc.strerror or exc})") from None


def parse_range(text: str | None, n_frames: int) -> tuple[int, int]:
    if not text:
        return 0, n_frames
    try:
        a, _, b = text.partition(":")
        start = int(a) if a.strip() else 0
        stop = int(b) if b.strip() else n_frames
    except ValueError:
        raise MocycleError(f"--range must look like START:STOP (frame numbers); got {text!r}") from None
    if start < 0:
        start += n_frames
    if stop < 0:
        stop += n_frames
    if not 0 <= start < stop <= n_frames:
        raise MocycleError(f"--range {text} is outside the take's {n_frames} frames")
    return start, stop


def count_option(text: str, option: str, words: dict[str, object]) -> object:
    """A positive integer option that also takes a few words (e.g. 'auto')."""
    if text in words:
        return words[text]
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise MocycleError(f"{option} must be {' or '.join(repr(w) for w in words)} or a positive integer; "
                           f"got {text!r}")
    return n



# ------------------------------------------------------------ output
def json_text(facts, indent: int | None = 2) -> str:
    """Strict JSON of ``facts``: NaN and infinities become ``null``, and the JSON says which and why.

    ``json.dumps`` would write ``NaN``/``Infinity``, which JSON parsers refuse.  The paths of the values
    written as ``null`` are listed under ``"null_because_not_finite"`` (for a dict at the top).
    """
    nulls: list[str] = []

    def clean(x, where: str):
        if isinstance(x, (float, np.floating)):
            if math.isfinite(x):
                return float(x)
            nulls.append(f"{where or 'value'} ({x})")
            return None
        if isinstance(x, np.integer):
            return int(x)
        if isinstance(x, np.ndarray):
            x = x.tolist()
        if isinstance(x, dict):
            return {k: clean(v, f"{where}.{k}" if where else str(k)) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v, f"{where}[{i}]") for i, v in enumerate(x)]
        return x

    out = clean(facts, "")
    if nulls and isinstance(out, dict):
        out["null_because_not_finite"] = nulls
    return json.dumps(out, indent=indent, allow_nan=False)


# ------------------------------------------------------- the phase options
# What ``phase`` takes to find the periodic motion; ``loop``, ``blend`` and ``transition`` take the same.
JointsOption = Annotated[str | None, typer.Option(
    help="Joints to find the phase on: names, glob patterns or groups (legs, arms, spine), comma-separated; "
         "default the whole body, then legs, then arms until one shows a periodic motion.")]
ClassesOption = Annotated[str, typer.Option(help="How many periodic motions to look for: 'auto' or N.")]
PcaOption = Annotated[str, typer.Option(help="PCA dimensions before the cohomology: 'auto' (8), N or 'none'.")]
DelayOption = Annotated[int, typer.Option(help="Delay embedding factor m (KTH thesis eq. 3.26; it used 2).")]
MinPeriodsOption = Annotated[float, typer.Option(
    help="Periods a periodic motion must cover (>= 1); below 1.5 the result is kept with a warning.")]


def phase_options(joints: str | None, classes: str, pca: str, delay: int, min_periods: float) -> dict:
    """The phase options of the command line as keyword arguments of ``find_phase``/``extract_cycle``."""
    if delay < 0:
        raise MocycleError(f"--delay must be >= 0; got {delay}")
    if not min_periods >= 1.0:
        raise MocycleError(f"--min-periods must be a number >= 1; got {min_periods:g}")
    return {
        "joints": joints,
        "classes": count_option(classes, "--classes", {"auto": "auto"}),
        "pca": count_option(pca, "--pca", {"auto": "auto", "none": None, "0": None}),
        "delay": delay,
        "min_periods": min_periods,
    }
