"""What new users found when trying every command (issue 12, part 8): each fixed, each tested here."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from mocycle import tasks
from mocycle.cli import app
from mocycle.datasets import synthetic_nonperiodic, synthetic_run, synthetic_walk
from mocycle.io import read_bvh, write_bvh

runner = CliRunner()
README = Path(__file__).resolve().parents[1] / "README.md"


def _flags(command: str) -> set[str]:
    cmd = typer.main.get_command(app).commands[command]
    return {o for p in cmd.params if p.param_type_name == "option" for o in p.opts}


@pytest.fixture(scope="module")
def takes(tmp_path_factory):
    d = tmp_path_factory.mktemp("polish")
    walk = write_bvh(synthetic_walk(n_frames=240, fps=60, seed=1).motion, d / "walk.bvh")
    run = write_bvh(synthetic_run(n_frames=200, fps=60, seed=2).motion, d / "run.bvh")
    still = write_bvh(synthetic_nonperiodic(n_frames=200, fps=60, seed=3).motion, d / "still.bvh")
    return walk, run, still


def test_boolean_flags_show_no_value():
    for command in ("info", "compress", "project", "blend", "phase"):
        text = runner.invoke(app, [command, "--help"]).output
        assert "--json" in text and "<bool>" not in text and "BOOLEAN" not in text, command
    assert "--align / --no-align" in runner.invoke(app, ["blend", "--help"]).output


def test_fps_means_the_amc_rate_everywhere_but_convert():
    group = typer.main.get_command(app)
    for name in group.commands:
        flags = _flags(name)
        if name == "convert":
            assert {"--fps", "--amc-fps"} <= flags
        elif name not in ("decompress", "demo", "batch"):  # batch: --amc-fps is one of COMMAND's options
            assert "--amc-fps" in flags and "--fps" not in flags, name
    help_text = runner.invoke(app, ["convert", "--help"]).output
    assert "Resample the output" in help_text and "AMC input" in help_text


def test_seed_is_a_random_seed_and_the_projection_has_its_own_flag():
    for name in ("compress", "project"):
        assert "--seed-projection" in _flags(name) and "--seed" not in _flags(name)
    assert "--seed" in _flags("demo")


def test_swing_indices_in_table_json_and_plot(takes, tmp_path, monkeypatch):
    walk = takes[0]
    r = runner.invoke(app, ["swings", str(walk)])
    assert r.exit_code == 0 and "indices" in r.output and "0-" in r.output and "edit --swing" in r.output
    drawn = {}

    import mocycle.viz.swings as viz_swings

    def keep(fig, path, dpi=110):
        drawn["texts"] = [t.get_text() for ax in fig.axes for t in ax.texts]
        return Path(path)

    monkeypatch.setattr(viz_swings, "save", keep)
    report = tasks.swings.run(walk)
    viz_swings.plot_swings(report.result, tmp_path / "s.png")
    n_left = len(report.result.swings_of("LeftUpLeg"))
    assert drawn["texts"].count(str(n_left - 1)) >= 1 and len(drawn["texts"]) == report.facts["n_swings"]


def test_text_output_labels_its_time_and_says_what_it_wrote(takes, tmp_path):
    walk = takes[0]
    for args in (["phase", str(walk)], ["loop", str(walk), "-o", str(tmp_path / "l.bvh")],
                 ["swings", str(walk), "--playback", str(tmp_path / "p.bvh")],
                 ["stretch", str(walk), "--factor", "1.5", "-o", str(tmp_path / "s.bvh")]):
        r = runner.invoke(app, args)
        assert r.exit_code == 0, r.output
        assert re.search(r"^  time \d+\.\d+ s", r.output, re.M), args
        assert not re.search(r"^\s+\d+\.\d+ s\s*$", r.output, re.M), args  # no bare "2.417 s" line
    r = runner.invoke(app, ["swings", str(walk), "--playback", str(tmp_path / "p.bvh")])
    assert f"wrote {tmp_path / 'p.bvh'}" in r.output


@pytest.mark.parametrize("command", ["blend", "transition", "stretch"])
def test_blend_transition_and_stretch_plot(takes, tmp_path, command):
    walk, run, _ = takes
    png = tmp_path / f"{command}.png"
    args = {"blend": ["blend", str(walk), str(run)], "transition": ["transition", str(walk), str(run)],
            "stretch": ["stretch", str(walk), "--factor", "1.5"]}[command]
    r = runner.invoke(app, [*args, "-o", str(tmp_path / "o.bvh"), "--plot", str(png)])
    assert r.exit_code == 0, r.output
    assert png.read_bytes()[:4] == b"\x89PNG" and f"wrote {png}" in r.output
    bad = runner.invoke(app, [*args, "-o", str(tmp_path / "o2.bvh"), "--plot", str(tmp_path / "x.jpg")])
    assert bad.exit_code == 1 and ".png" in bad.stderr and not (tmp_path / "o2.bvh").exists()


def test_a_bad_choice_is_a_usage_error(takes, tmp_path):
    walk, run, _ = takes
    for args in (["loop", str(walk), "-o", str(tmp_path / "x.bvh"), "--method", "spline"],
                 ["blend", str(walk), str(run), "-o", str(tmp_path / "x.bvh"), "--method", "spline"],
                 ["compress", str(walk), "-o", str(tmp_path / "x.mck"), "--scheme", "cubic"]):
        r = runner.invoke(app, args)
        assert r.exit_code == 2, r.output
        assert r.stderr.startswith("error: --") and "must be one of" in r.stderr


def test_a_folder_is_called_a_folder(tmp_path):
    r = runner.invoke(app, ["info", str(tmp_path)])
    assert r.exit_code == 1 and "is a folder" in r.stderr and "(none)" not in r.stderr


def test_convert_keeps_the_last_frame(tmp_path):
    src = write_bvh(synthetic_walk(n_frames=273, fps=30).motion, tmp_path / "in.bvh")  # "0.0333333" in the file
    out = tmp_path / "out.bvh"
    r = runner.invoke(app, ["convert", str(src), str(out), "--fps", "60"])
    assert r.exit_code == 0, r.output
    m, original = read_bvh(out), read_bvh(src)
    assert m.n_frames == 545 and np.isclose(m.fps, 60)
    assert np.allclose(m.rotations[-1], original.rotations[-1], atol=1e-6)  # the end time is kept
    assert read_bvh(out).n_frames == 2 * original.n_frames - 1


def test_phase_plot_of_a_take_without_periodic_motion_says_so(takes, tmp_path, monkeypatch):
    import mocycle.viz.phase as viz_phase

    seen = {}

    def keep(fig, path, dpi=110):
        seen["titles"] = [ax.get_title() for ax in fig.axes]
        seen["labels"] = [ax.get_ylabel() for ax in fig.axes]
        seen["texts"] = [t.get_text() for ax in fig.axes for t in ax.texts]
        return Path(path)

    monkeypatch.setattr(viz_phase, "save", keep)
    r = runner.invoke(app, ["phase", str(takes[2]), "--plot", str(tmp_path / "p.png")])
    assert r.exit_code == 3
    assert any("no periodic motion" in t for t in seen["titles"])
    assert any("no periodic motion found" in t for t in seen["texts"])
    assert "phase of class 0" not in seen["labels"] and len(seen["titles"]) == 3  # no colour bar


def test_readme_says_what_the_code_does():
    text = README.read_text()
    assert "--projection tsne]" not in text
    default = tasks.project.Options().projection
    assert f"mocycle project IN [--projection {default}]" in text
    assert ".venv-numpy1" in text and "ten minutes" in text
