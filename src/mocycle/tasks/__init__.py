"""The task layer: one module per user task, the one API every front end calls.

Each task module has an ``Options`` frozen dataclass (defaults, units in the names, one help line per field,
validation in ``__post_init__``) and ``run(inputs, options) -> Report``. Inputs are :class:`~mocycle.Motion`
objects or motion file paths. The CLI, the Blender add-on, the web studio and the batch runner call these and
nothing deeper; :func:`schema` describes an Options class for forms and flags.

    >>> from mocycle import tasks
    >>> from mocycle.datasets import synthetic_walk
    >>> report = tasks.info.run(synthetic_walk(n_frames=120).motion)
    >>> report.facts["frames"], report.task
    (120, 'info')
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from .fields import AMC_FPS, SWING_THRESHOLD
from .options import Options, option, schema
from .report import Report

# The tasks are the specs' (:data:`mocycle.tasks.spec.SPECS`, in the order front ends list them); each module is
# imported on first use (``tasks.loop``), so that a front end pays only for the task it runs
# (``docs/performance.md``).

if TYPE_CHECKING:  # what __getattr__ gives, for IDEs and type checkers; at run time each loads on first use
    from types import ModuleType

    from . import blend, compress, decompress, edit, info, loop, phase, project, search, stretch, swings, transition

    TASKS: dict[str, ModuleType]


def __getattr__(name: str):
    from .spec import SPECS

    if name in SPECS:
        return importlib.import_module(f"{__name__}.{name}")
    if name == "TASKS":  # task name -> its module (each has ``Options`` and ``run``)
        return {n: importlib.import_module(f"{__name__}.{n}") for n in SPECS}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["AMC_FPS", "SWING_THRESHOLD", "TASKS", "Options", "Report", "blend", "compress", "decompress", "edit",
           "info", "loop", "option", "phase", "project", "schema", "search", "stretch", "swings", "transition"]
