"""The ``mocycle`` command: one sub-command per user task.

Thin by design: each command parses options, calls the library and prints.
Bad input ends with one ``error:`` line naming the file, the line and what
was expected, and exit code 1; usage errors exit with 2 (typer's convention).
Each command lives in its own module here and registers itself on ``app``.

Importing this package is cheap: :func:`main` installs the signal handlers
*before* the commands (typer, numpy, scipy) are imported, so Ctrl-C or SIGTERM
at any moment ends the run with one line and no traceback, and the atomic
writer removes its temporary file.
"""

from __future__ import annotations

import signal
import sys

__all__ = ["app", "guarded", "main", "run"]

EXIT_INTERRUPTED = 130  # 128 + SIGINT
EXIT_TERMINATED = 143  # 128 + SIGTERM


class Stopped(SystemExit):
    """Raised in the main thread on SIGINT or SIGTERM: unwinds every ``finally`` (the atomic writer
    removes its temporary file) and ends the run with ``128 + signal``."""


def _on_signal(signum, frame):
    raise Stopped(128 + signum)


def _commands():
    # Importing a command module registers its command; this order is the order in --help.
    from . import info, convert, phase, loop, blend, stretch, swings, keyframes, demo  # noqa: F401, I001
    from . import studio, report  # noqa: F401, I001
    from . import common

    return common


def __getattr__(name: str):
    if name == "app":
        return _commands().app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def run() -> None:
    """The command line itself (no signal handling: see :func:`main`)."""
    _commands().app()


def guarded(body=run) -> None:
    """Run ``body`` with SIGINT and SIGTERM turned into a clean unwind: exit 130 / 143 with one line."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        try:
            signal.signal(sig, _on_signal)
        except (ValueError, OSError):  # not the main thread, or no such signal here
            pass
    try:
        body()
    except (Stopped, KeyboardInterrupt) as exc:
        code = exc.code if isinstance(exc, Stopped) else EXIT_INTERRUPTED
        print("terminated" if code == EXIT_TERMINATED else "interrupted", file=sys.stderr)
        sys.exit(code)


def main() -> None:  # the console script (through mocycle.__main__)
    """Run the command line; Ctrl-C exits 130 and SIGTERM 143, each with one line, no traceback."""
    guarded(run)
