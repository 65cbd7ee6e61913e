"""The ``mocycle`` command: one sub-command per user task.

Thin by design: each command parses options, calls the library and prints.
Bad input ends with one ``error:`` line naming the file, the line and what
was expected, and exit code 1; usage errors exit with 2 (typer's convention).
Each command lives in its own module here and registers itself on ``app``.
"""

# Importing a command module registers its command; this order is the order in --help.
from . import info, convert, phase, loop, blend, stretch, swings, keyframes, demo  # noqa: F401, I001
from .common import app, main

__all__ = ["app", "main"]
