"""The terminal's words for the library's: each ``Options`` field's CLI flag, and a message's hints
(:class:`mocycle.errors.Hint`, ``option 'force'``) said as the flags that set them.  For the front ends run
from a shell (the CLI and ``mocycle batch``); Blender and the studio say hints as fields
(:func:`mocycle.tasks.words.hints`).  No numpy, no typer.
"""

from __future__ import annotations

import dataclasses

from ..errors import OptionError, render_hints
from .options import flag_of
from .spec import SPECS

__all__ = ["as_flags", "flags", "option_message"]


def flags(command: str | None = None) -> dict[str, str]:
    """Parameter names of the library -> the CLI flag that sets them (every task option, a few library names);
    ``command``: the task whose own flags win where two tasks name one parameter differently (``loop``'s
    ``which`` is ``--part``, ``blend``'s ``--class``). Asked only when an option is refused."""
    names = {f.name: flag_of(f) for spec in SPECS.values() if spec.cli for f in dataclasses.fields(spec.options)}
    if command in SPECS:
        names.update({f.name: flag_of(f) for f in dataclasses.fields(SPECS[command].options)})
    names.update({"n_classes": "--classes", "seed": "--seed-projection", "count": "--cycles",
                  "window": "--window", "gltf_scale": "--gltf-scale", "gltf_up": "--gltf-up"})
    return names


def option_message(exc: OptionError, command: str | None = None) -> str:
    """The error with the flag instead of the library's parameter name (``--cycles must be ...``)."""
    return f"{flags(command).get(exc.parameter, exc.parameter)} {exc.reason}"


def as_flags(text: str, command: str | None = None) -> str:
    """A library message with its hints (:class:`mocycle.errors.Hint`, ``option 'force'``) said as the flags
    that set them (``--force``, ``--model M2``)."""
    if "option " not in str(text):
        return str(text)
    names = flags(command)

    def name(option: str, value: str | None) -> str:
        return names.get(option, "--" + option.replace("_", "-")) + ("" if value is None else f" {value}")

    return render_hints(text, name)
