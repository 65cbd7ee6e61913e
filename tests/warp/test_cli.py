import json

import numpy as np
from typer.testing import CliRunner

import mocycle.cli.stretch  # noqa: F401  (registers the command)
from mocycle.cli import app
from mocycle.datasets import synthetic_walk
from mocycle.io import read_bvh, write_bvh

runner = CliRunner()


def walk_file(tmp_path, n=240):
    return write_bvh(synthetic_walk(n, fps=60, period_s=1.0).motion, tmp_path / "walk.bvh")


def test_stretch_json_facts_and_output_file(tmp_path):
    src = walk_file(tmp_path)
    out = tmp_path / "long.bvh"
    result = runner.invoke(app, ["stretch", str(src), "--factor", "2", "-o", str(out), "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    assert set(facts) >= {"factor", "frames_in", "frames_out", "windows", "seconds"}
    assert facts["factor"] == 2.0 and facts["frames_in"] == 240 and facts["frames_out"] == 480
    assert facts["windows"] == {"legs": 60, "arms": 60, "spine": 60}
    assert facts["seconds"] > 0
    m = read_bvh(out)
    assert m.n_frames == 480 and np.isclose(m.fps, 60)


def test_stretch_table_and_given_window(tmp_path):
    src = walk_file(tmp_path)
    out = tmp_path / "long.bvh"
    result = runner.invoke(app, ["stretch", str(src), "--factor", "1.5", "-o", str(out), "--window", "30"])
    assert result.exit_code == 0, result.output
    assert "240 frames" in result.output and "360 frames" in result.output and "given" in result.output
    assert read_bvh(out).n_frames == 360


def test_stretch_errors_are_one_line_and_write_nothing(tmp_path):
    src = walk_file(tmp_path)
    out = tmp_path / "long.bvh"
    for args, message in (
        (["--factor", "2", "--window", "500"], "half the take"),
        (["--factor", "2", "--window", "zero"], "--window must be"),
        (["--factor", "-2"], "factor must be a positive"),
    ):
        result = runner.invoke(app, ["stretch", str(src), "-o", str(out)] + args)
        assert result.exit_code == 1, result.output
        lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error:") and message in lines[0], lines
        assert not out.exists()
    bad_suffix = runner.invoke(app, ["stretch", str(src), "--factor", "2", "-o", str(tmp_path / "x.txt")])
    assert bad_suffix.exit_code == 1 and ".bvh" in bad_suffix.stderr
    missing = runner.invoke(app, ["stretch", str(tmp_path / "none.bvh"), "--factor", "2", "-o", str(out)])
    assert missing.exit_code == 1 and not out.exists()
    usage = runner.invoke(app, ["stretch", str(src), "-o", str(out)])
    assert usage.exit_code == 2  # --factor is required


def test_stretch_help():
    result = runner.invoke(app, ["stretch", "--help"])
    assert result.exit_code == 0 and "--factor" in result.output and "--window" in result.output


def test_stretch_refuses_a_one_off_gesture_with_exit_3_and_force_warps(tmp_path):
    from mocycle.datasets import synthetic_gesture

    src = write_bvh(synthetic_gesture(240, fps=60).motion, tmp_path / "gesture.bvh")
    out = tmp_path / "long.bvh"
    result = runner.invoke(app, ["stretch", str(src), "--factor", "2", "-o", str(out)])
    assert result.exit_code == 3 and "no periodic motion to stretch" in result.output and not out.exists()
    result = runner.invoke(app, ["stretch", str(src), "--factor", "2", "-o", str(out), "--force", "--json"])
    assert result.exit_code == 0 and "warning:" in result.output and read_bvh(out).n_frames == 480
