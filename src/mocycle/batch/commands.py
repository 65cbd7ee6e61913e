"""What ``mocycle batch`` does per command: the output it writes for a take and the figures a results row
shows (a few of the task report's ``facts``; the whole facts go to ``results.json``)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from ..errors import MocycleError
from ..tasks.spec import SPECS, Output, Spec, row_figures

__all__ = ["COMMANDS", "Command", "check_suffix"]

#: the suffixes ``mocycle.write`` writes that do not hold a motion (every other one it writes does)
_NOT_MOTION = (".mck", ".mosw", ".json")


@dataclass(frozen=True)
class Command:
    """A task as batch runs it: a view of its spec (:data:`mocycle.tasks.spec.SPECS`), which declares the
    output (its first :class:`~mocycle.tasks.spec.Output`), the results columns (``figures``) and the modules
    its workers preload (``imports``: a LocalCluster's workers get them preloaded (:mod:`.forkserver`), so
    they are imported once per batch, not once per worker at its first take; ``tests/batch/test_commands.py``
    checks that none is missing)."""

    spec: Spec

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def output(self) -> Output | None:
        """What goes to ``OUTDIR/<rel><suffix>`` (``None``: the per-take JSON record only)."""
        return self.spec.outputs[0] if self.spec.outputs else None

    @property
    def writes(self) -> str | None:
        """``"motion"``, ``"compressed"``, ``"swings"`` or ``None``."""
        return None if self.output is None else self.output.writes

    @property
    def suffix(self) -> str | None:
        """The default output suffix."""
        return None if self.output is None else self.output.suffixes[0]

    @property
    def figures(self) -> Mapping[str, Callable[[Mapping], object]]:
        return self.spec.figures

    @property
    def imports(self) -> tuple[str, ...]:
        return self.spec.imports

    def suffixes(self) -> tuple[str, ...]:
        """The output suffixes this command can write (for motion asked of ``mocycle.io`` at run time, so a
        new motion format of ``mocycle.write`` is one for batch too)."""
        from ..io import WRITE_SUFFIXES

        if self.writes == "motion":
            return tuple(s for s in WRITE_SUFFIXES if s not in _NOT_MOTION)
        return () if self.output is None else self.output.suffixes


def check_suffix(command: Command, suffix: str | None) -> str | None:
    """The output suffix for ``command`` (``None`` when it writes only its record); one clear error when
    ``suffix`` is not one it writes."""
    if suffix is None:
        return command.suffix
    suffix = suffix.lower() if suffix.startswith(".") else "." + suffix.lower()
    allowed = command.suffixes()
    if not allowed:
        raise MocycleError(f"--suffix: batch {command.name} writes no file but its record (<take>.{command.name}"
                           f".json); leave --suffix out")
    if suffix not in allowed:
        raise MocycleError(f"--suffix: batch {command.name} writes {' or '.join(allowed)}; got {suffix}")
    return suffix


COMMANDS: dict[str, Command] = {name: Command(spec) for name, spec in SPECS.items() if spec.batch}


def motion_targets(report, target: Path) -> dict[str, Path]:
    """The motions a report holds that batch writes, by role, and where: ``target``, or with ``--part all``
    each loop's file as ``mocycle loop`` names it (:meth:`mocycle.tasks.spec.Output.targets` of the task's
    output)."""
    output = COMMANDS[report.task].output
    assert output is not None  # only a command that writes motions is asked
    return output.targets(report, target)


def part_rows(command: Command, facts: Mapping) -> list[dict]:
    """One set of figures per loop of a ``loop`` report (a take cut into parts gets a results row per part)."""
    return [row_figures(command.spec, {**facts, "loops": [loop]}) for loop in facts.get("loops") or []]
