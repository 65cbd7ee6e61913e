"""Every task option is a CLI flag with the same default, and every CLI flag of a task command is a task option
(apart from the listed front-end flags), so the CLI, Blender properties and a web form say the same thing."""

from __future__ import annotations

import dataclasses

import pytest
import typer

from mocycle import tasks
from mocycle.cli import app
from mocycle.tasks.options import MISSING, flag_of
from mocycle.tasks.spec import SPECS

#: task -> CLI command, for the tasks that are commands (``author`` is the studio's only)
COMMANDS = {name: name for name, spec in SPECS.items() if spec.cli}

#: flags of the CLI that are no task option: where to write, how to print, what to draw.
FRONT_END_FLAGS = {"--json", "--output", "--plot", "--playback", "--feet-plot", "--force", "--help",
                   "--gltf-scale", "--gltf-up", "--closing-frame"}


def _command(name: str):
    group = typer.main.get_command(app)
    return group.commands[name]


@pytest.mark.parametrize("task", sorted(COMMANDS))
def test_every_option_is_a_flag_with_its_default(task):
    options = tasks.TASKS[task].Options
    params = {opt: p for p in _command(COMMANDS[task]).params if p.param_type_name == "option" for opt in p.opts}
    for f in dataclasses.fields(options):
        flag = flag_of(f)
        assert flag in params, f"{task}: option {f.name} has no CLI flag {flag}"
        p = params[flag]
        if f.default is MISSING:
            assert p.required, f"{task}: {flag} should be required like {f.name}"
        else:
            assert p.default == f.default, f"{task}: {flag} defaults to {p.default!r}, the option to {f.default!r}"
        assert p.help == f.metadata["help"], f"{task}: {flag} help differs from the option's"


@pytest.mark.parametrize("task", sorted(COMMANDS))
def test_every_flag_is_an_option(task):
    fields = dataclasses.fields(tasks.TASKS[task].Options)
    flags = {flag_of(f) for f in fields}
    old = {o for f in fields for o in f.metadata.get("old_flags", ())}
    for p in _command(COMMANDS[task]).params:
        if p.param_type_name == "option":
            long = [o for o in p.opts if o.startswith("--")][0]
            if p.hidden:  # a former name of a flag, read with a warning
                assert long in old, f"{task}: hidden flag {long} is no option's former name"
                continue
            assert long in flags or long in FRONT_END_FLAGS, f"{task}: CLI flag {long} is not a task option"


def test_flags_are_flags_not_values():
    """Boolean options are plain flags (``--json``, ``--optimize``, ``--align/--no-align``): no value."""
    from typer.testing import CliRunner

    for name in ("info", "compress", "blend", "project"):
        for p in _command(name).params:
            if p.param_type_name == "option" and isinstance(p.default, bool):
                assert p.is_flag, f"{name}: {p.opts} takes a value"
            if p.default is True:
                assert p.secondary_opts == ["--no-" + p.opts[0][2:]], p.opts
    text = CliRunner().invoke(app, ["compress", "--help"]).output
    assert "--json" in text and "<bool>" not in text and "BOOLEAN" not in text
