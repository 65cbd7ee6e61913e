"""The project's own error and warning types.

Every public entry point raises :class:`MocycleError` (or a subclass) for bad
input, with one message that names the file, the line and what was expected.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from os import PathLike


@dataclass(frozen=True)
class Hint:
    """What would help, named in the library's own terms: an ``Options`` field (``option``) and, when it
    matters, the value to give it.  A message below the front ends says it as ``str(hint)``,
    ``"option 'force'"`` or ``"option 'model' = M2"``, never as a CLI flag; each front end renders it in its own
    terms with :func:`render_hints` (the CLI as ``--force`` / ``--model M2``, Blender and the studio as the
    field's name)."""

    option: str
    value: object | None = None

    def __str__(self) -> str:
        return f"option '{self.option}'" + ("" if self.value is None else f" = {self.value}")


#: a :class:`Hint` as it stands in a message (messages reach the front ends as text: a report's warnings)
HINT = re.compile(r"\boption '([a-z][a-z0-9_]*)'(?: = ([^\s;,()]+))?")


def render_hints(text: str, name: Callable[[str, str | None], str]) -> str:
    """``text`` with each hint in it said as ``name(option, value)`` (``value`` None when the hint has none)."""
    return HINT.sub(lambda m: name(m.group(1), m.group(2)), str(text))


class MocycleError(Exception):
    """Base class of every error mocycle raises on purpose."""


class MotionFileError(MocycleError, ValueError):
    """A motion file could not be read: says which file, which line, what was expected."""

    def __init__(self, message: str, path: str | PathLike | None = None, line: int | None = None):
        self.path = None if path is None else str(path)
        self.line = line
        self.reason = message
        where = ""
        if self.path is not None:
            where = self.path + (f":{line}" if line is not None else "") + ": "
        elif line is not None:
            where = f"line {line}: "
        super().__init__(where + message)


class OptionError(MocycleError, ValueError):
    """An argument is out of its allowed values; ``parameter`` names it (the CLI shows the matching flag).

    The message reads ``"<parameter> <what was expected>; got <value>"``; ``reason`` is the part after the name.
    """

    def __init__(self, parameter: str, reason: str):
        self.parameter = parameter
        self.reason = reason
        super().__init__(f"{parameter} {reason}")


class DataError(MocycleError, ValueError):
    """Data given as an array is unusable (wrong shape, too few rows): bad input, like a bad file."""


class MocycleWarning(UserWarning):
    """Something odd but recoverable in the input (e.g. a wrong ``Frames:`` count)."""


class DefaultTake(MocycleWarning):
    """No take was named in a file holding several: which one was read (the first that moves the skeleton) and
    which others the file holds.  ``mocycle info``, which lists the takes itself, leaves it out."""


class NoPeriodicMotion(MocycleError):
    """The input is fine but holds no periodic motion (the CLI exits with code 3).  ``facts``: the task's facts
    when a task raised it (its parts and why none looped), else None."""

    facts: dict | None = None


class LoopRefused(MocycleError):
    """A cycle was made but fails the checks of a loop (:mod:`mocycle.cycle.checks`); the CLI exits with
    code 3 and the option ``force`` writes it anyway.  ``failed``: the failed checks, each with its reason;
    ``facts``: the task's facts when a task raised it (its parts and why each did not loop), else None."""

    facts: dict | None = None

    def __init__(self, message: str, failed=()):
        super().__init__(message)
        self.failed = list(failed)
