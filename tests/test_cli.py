import json

import numpy as np
import pytest
from typer.testing import CliRunner

import mocycle
from conftest import shared_path
from helpers import max_angle, random_motion
from mocycle.cli import app
from mocycle.io import read_bvh, write_bvh

runner = CliRunner()


def test_every_command_has_help():
    commands = ("", "info", "convert", "phase", "loop", "blend", "transition", "stretch", "swings", "search", "edit",
                "compress", "decompress", "project", "demo")
    for command in commands:
        result = runner.invoke(app, ([command] if command else []) + ["--help"])
        assert result.exit_code == 0 and "Usage" in result.output


def test_info_json_facts(tmp_path):
    m = random_motion(61)
    with pytest.warns(mocycle.MocycleWarning, match=r"BVH \(one word each\)"):
        path = write_bvh(m, tmp_path / "m.bvh")
    result = runner.invoke(app, ["info", str(path), "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    assert facts["frames"] == 61 and facts["joints"] == 4 and facts["channels"] == 15
    assert np.isclose(facts["fps"], 60) and np.isclose(facts["duration_s"], 1.0)
    steps = np.linalg.norm(np.diff(m.root_positions, axis=0), axis=1).sum()
    assert np.isclose(facts["root_path_length"], steps, rtol=1e-6)
    assert set(facts["rotation_range_deg"]["Left_Up_Leg"]) == {"Zrotation", "Xrotation", "Yrotation"}
    assert 0 < facts["rotation_spread_deg"]["Spine"] <= 180


def test_info_table_names_the_file(tmp_path):
    path = write_bvh(random_motion(10), tmp_path / "walk.bvh")
    result = runner.invoke(app, ["info", str(path)])
    assert result.exit_code == 0 and "walk.bvh" in result.output and "10 frames" in result.output


def test_bad_file_gives_one_error_line_and_exit_1(tmp_path):
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\nROOT a\n{\nOFFSET 0 0\n}\n")
    result = runner.invoke(app, ["info", str(bad)])
    assert result.exit_code == 1
    lines = [ln for ln in result.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "bad.bvh:4:" in lines[0] and "expected 3 numbers" in lines[0]
    missing = runner.invoke(app, ["info", str(tmp_path / "none.bvh")])
    assert missing.exit_code == 1 and "cannot read file" in missing.stderr


def test_convert_range_and_fps(tmp_path):
    src = write_bvh(random_motion(61), tmp_path / "in.bvh")
    out = tmp_path / "out.bvh"
    result = runner.invoke(app, ["convert", str(src), str(out), "--range", "10:41", "--fps", "30"])
    assert result.exit_code == 0, result.output
    m = read_bvh(out)
    assert m.n_frames == 16 and np.isclose(m.fps, 30)
    assert max_angle(m.rotations, read_bvh(src).rotations[10:41:2]) < 1e-6
    bad = runner.invoke(app, ["convert", str(src), str(tmp_path / "o.bvh"), "--range", "50:500"])
    assert bad.exit_code == 2 and "--range 50:500 is outside" in bad.stderr
    assert not (tmp_path / "o.bvh").exists()


def test_convert_rejects_other_output_types(tmp_path):
    src = write_bvh(random_motion(5), tmp_path / "in.bvh")
    result = runner.invoke(app, ["convert", str(src), str(tmp_path / "out.fbx")])
    assert result.exit_code == 1 and ".bvh" in result.stderr


@pytest.mark.filterwarnings("ignore")
def test_convert_asf_amc_to_bvh(tmp_path):
    asf, amc = shared_path("cmu", "01.asf"), shared_path("cmu", "01_01.amc")
    out = tmp_path / "01_01.bvh"
    result = runner.invoke(app, ["convert", str(asf), str(amc), str(out)])
    assert result.exit_code == 0, result.output
    m = read_bvh(out)
    assert m.n_frames == 2751 and m.n_joints == 31 and np.isclose(m.fps, 120)


def test_demo_writes_and_reads_back_the_synthetic_walk(tmp_path):
    result = runner.invoke(app, ["demo", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    m = read_bvh(tmp_path / "synthetic_walk.bvh")
    assert m.n_frames > 100 and "period" in result.output
