"""One declaration per task (``mocycle.tasks.spec``): every front end is made from it, so a new option or output
of a task reaches the CLI, batch and the studio without a second edit (Blender: ``tests_blender``)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Annotated

import pytest
import typer
from typer.testing import CliRunner

from mocycle import tasks
from mocycle.batch.commands import COMMANDS
from mocycle.cli.batch import options_parser, parse_command_line
from mocycle.cli.common import COMMANDS as CLI_COMMANDS
from mocycle.cli.common import task_command
from mocycle.tasks.options import Integer, option
from mocycle.tasks.spec import SPECS

pytest.importorskip("starlette")

#: the modules of mocycle.tasks that are the task layer's own, not a task
NOT_TASKS = {"__init__", "clips", "feet_option", "fields", "flags", "keyframe_fields", "options", "report", "spec",
             "words"}


def test_every_task_has_a_spec_and_every_command_one_summary():
    # SPECS is the one list of tasks: every task module is reachable by its spec's name, and no other
    task_modules = {p.stem for p in Path(tasks.__file__).parent.glob("*.py")} - NOT_TASKS
    assert task_modules == set(SPECS) and set(tasks.TASKS) == set(SPECS)
    for name, spec in SPECS.items():
        assert dataclasses.is_dataclass(spec.options), name
        if spec.cli:
            assert CLI_COMMANDS[name][1] == spec.summary
    assert set(COMMANDS) == {n for n, s in SPECS.items() if s.batch}


@pytest.fixture
def knob(monkeypatch):
    """The loop task with one more option, as one edit of ``tasks/loop.py`` would declare it."""

    @dataclasses.dataclass(frozen=True)
    class Options(tasks.loop.Options):
        extra_knob: int = option(3, "A new knob (a test's).", Integer(1, 9))

    monkeypatch.setattr(tasks.loop, "Options", Options)
    return Options


def test_a_new_option_reaches_the_cli(knob, tmp_path):
    app = typer.Typer()
    seen = {}

    @task_command("loop", into=app)
    def loop(path: Annotated[Path, typer.Argument()], *, options, output):
        """Extract one seamless typical cycle (frame N would equal frame 0) and write it as BVH or glTF."""
        seen.update(options=options, output=output)

    take = tmp_path / "walk.bvh"
    take.write_text("x")
    result = CliRunner().invoke(app, [str(take), "-o", str(tmp_path / "out.bvh"), "--extra-knob", "5",
                                      "--cycles", "2"])
    assert result.exit_code == 0, result.output
    assert seen["options"].extra_knob == 5 and seen["options"].cycles == 2
    assert seen["output"] == tmp_path / "out.bvh"
    bad = CliRunner().invoke(app, [str(take), "-o", str(tmp_path / "out.bvh"), "--extra-knob", "12"])
    assert bad.exit_code == 2 and "--extra-knob" in bad.output  # the field's own check, named by its flag
    wrong = CliRunner().invoke(app, [str(take), "-o", str(tmp_path / "out.mck")])
    assert wrong.exit_code == 1 and ".bvh or .glb" in wrong.output  # the spec's suffixes, before any work


def test_a_new_output_reaches_the_cli(monkeypatch, tmp_path):
    """An output added to a spec is a CLI option, checked before any work and written by ``write``."""
    from mocycle.datasets import synthetic_walk
    from mocycle.io import read_bvh, write
    from mocycle.tasks.spec import Output

    extra = Output("input", "motion", (".bvh", ".glb"), flag="--input-copy", required=False, help="The take read.")
    monkeypatch.setitem(SPECS, "stretch", dataclasses.replace(SPECS["stretch"],
                                                              outputs=(*SPECS["stretch"].outputs, extra)))
    app = typer.Typer()

    @task_command("stretch", into=app)
    def stretch(path: Annotated[Path, typer.Argument()], *, options, write):
        """Lengthen a take by time-frequency warping: its cycles are replicated, not slowed down."""
        report = tasks.stretch.run(path, options)
        write(report)
        write(report, "--input-copy")

    take = write(synthetic_walk(n_frames=180).motion, tmp_path / "walk.bvh")
    args = [str(take), "--factor", "1.5", "-o", str(tmp_path / "long.bvh")]
    wrong = CliRunner().invoke(app, [*args, "--input-copy", str(tmp_path / "copy.txt")])
    assert wrong.exit_code == 1 and "--input-copy" in wrong.output and not (tmp_path / "long.bvh").exists()
    result = CliRunner().invoke(app, [*args, "--input-copy", str(tmp_path / "copy.bvh")])
    assert result.exit_code == 0, result.output
    assert read_bvh(tmp_path / "copy.bvh").n_frames == 180 and read_bvh(tmp_path / "long.bvh").n_frames == 270


def test_a_new_option_reaches_batch(knob):
    assert "--extra-knob" in {o for p in options_parser("loop").params for o in p.opts}
    command, inputs, options = parse_command_line(["loop", "a.bvh", "--extra-knob", "4"])
    assert (command, inputs, options.extra_knob) == ("loop", ["a.bvh"], 4)


def test_a_new_option_reaches_the_studio(knob, monkeypatch):
    import asyncio

    from mocycle.studio import validate
    from mocycle.studio.app import options

    # the form shows the option once the spec names it for the studio (that edit is the same line of the spec)
    monkeypatch.setitem(SPECS, "loop", dataclasses.replace(SPECS["loop"], studio=(*SPECS["loop"].studio,
                                                                                  "extra_knob")))
    body = json.loads(asyncio.run(options(None)).body)
    assert body["loop"]["properties"]["extra_knob"]["maximum"] == 9
    assert "extra_knob" in body["forms"]["loop"]
    assert validate.loop_request({"extra_knob": 4})[0] == {"extra_knob": 4}


@pytest.mark.parametrize("name", [n for n, s in SPECS.items() if s.cli])
def test_every_output_of_a_spec_is_a_cli_option(name):
    from mocycle.cli import app

    command = typer.main.get_command(app).commands[name]
    flags = {o for p in command.params for o in p.opts}
    for out in SPECS[name].outputs:
        assert out.flag in flags
    assert ("--gltf-scale" in flags) == SPECS[name].writes_motion()
    assert ("--closing-frame" in flags) == any(o.loop for o in SPECS[name].outputs)


def test_the_studio_forms_are_the_specs():
    import asyncio

    from mocycle.studio.app import options

    body = json.loads(asyncio.run(options(None)).body)
    assert body["forms"] == {"loop": list(SPECS["loop"].studio), "plane": list(SPECS["project"].studio),
                             "author": list(SPECS["author"].studio)}
    for form, fields in body["forms"].items():
        assert set(fields) <= set(body[form]["properties"]), form


def test_a_loop_output_names_one_file_per_part():
    """Output.targets is how the CLI and batch name a report's files."""
    from types import SimpleNamespace

    out = SPECS["loop"].outputs[0]
    report = SimpleNamespace(facts={"loops": [{"role": "loop.part1", "kind": "walk turning left"},
                                              {"role": "loop.part3", "kind": "walk straight"}]},
                             motions={"loop.part1": 1, "loop.part3": 2})
    assert out.targets(report, Path("o/walk.bvh")) == {"loop.part1": Path("o/walk.part1-walk-turning-left.bvh"),
                                                       "loop.part3": Path("o/walk.part3-walk-straight.bvh")}
    assert SPECS["stretch"].outputs[0].targets(SimpleNamespace(facts={}, motions={}), Path("s.bvh")) == \
        {"stretched": Path("s.bvh")}


def _reports(tmp_path) -> dict:
    """One report of every task on generated takes (the optional facts asked for where a task has them)."""
    import mocycle
    from mocycle.datasets import synthetic_walk

    walk = mocycle.write(synthetic_walk(n_frames=240).motion, tmp_path / "walk.bvh")
    other = mocycle.write(synthetic_walk(n_frames=240, period_s=0.8, seed=1).motion, tmp_path / "other.bvh")
    compressed = tasks.compress.run(walk)
    compressed.result.save(tmp_path / "walk.mck")
    return {"info": [tasks.info.run(walk)], "phase": [tasks.phase.run(walk)],
            "loop": [tasks.loop.run(walk), tasks.loop.run(walk, tasks.loop.Options(which="all", root="motion"))],
            "blend": [tasks.blend.run([walk, other])], "transition": [tasks.transition.run([walk, other])],
            "stretch": [tasks.stretch.run(walk, tasks.stretch.Options(factor=1.5))],
            "swings": [tasks.swings.run(walk)], "search": [tasks.search.run(walk, tmp_path)],
            "edit": [tasks.edit.run(walk, tasks.edit.Options(joint="LeftUpLeg", swing=0, angle_scale=1.2))],
            "compress": [compressed], "decompress": [tasks.decompress.run(tmp_path / "walk.mck")],
            "project": [tasks.project.run(walk), tasks.project.run(walk, tasks.project.Options(optimize=True))]}


def test_every_report_has_the_facts_its_spec_declares(tmp_path):
    """A task's facts have one shape, the spec's: every declared key, and no other but the optional ones."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reports = _reports(tmp_path)
    for name, runs in reports.items():
        spec = SPECS[name]
        for report in runs:
            keys = set(report.facts)
            assert set(spec.facts) <= keys, f"{name}: missing {sorted(set(spec.facts) - keys)}"
            assert keys <= {*spec.facts, *spec.optional_facts}, \
                f"{name}: undeclared {sorted(keys - {*spec.facts, *spec.optional_facts})}"
    assert "stress_optimized" in reports["project"][1].facts
