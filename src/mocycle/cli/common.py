"""What every ``mocycle`` sub-command shares: the typer app, consoles, exit codes, error handling."""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable
from functools import wraps
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console

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



def main() -> None:  # the console script
    try:
        app()
    except KeyboardInterrupt:  # pragma: no cover
        err.print("interrupted")
        sys.exit(130)



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
