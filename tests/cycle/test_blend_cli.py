import json

import numpy as np
import pytest
from typer.testing import CliRunner

import mocycle.cli.blend  # noqa: F401  (registers the commands)
from mocycle.cli import app
from mocycle.datasets import synthetic_walk
from mocycle.io import read, write
from mocycle.motion import Motion, Skeleton

runner = CliRunner()


@pytest.fixture(scope="module")
def walks(tmp_path_factory):
    d = tmp_path_factory.mktemp("walks")
    a = write(synthetic_walk(n_frames=300, period_s=1.0).motion, d / "slow.bvh")
    b = write(synthetic_walk(n_frames=300, period_s=0.8, phase0=0.4).motion, d / "fast.bvh")
    return a, b


def test_blend_json_and_bvh(walks, tmp_path):
    out = tmp_path / "blend.bvh"
    result = runner.invoke(app, ["blend", str(walks[0]), str(walks[1]), "--weights", "0.7,0.3", "-o", str(out),
                                 "--json", "--root", "motion", "--cycles", "2"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    for key in ("period_frames", "weights", "phase_offsets", "seconds", "cycle_frames", "seam", "input_seams"):
        assert key in facts
    assert np.allclose(facts["weights"], [0.7, 0.3])
    assert 48 < facts["period_frames"] < 60 and abs(facts["period_frames"] - (0.7 * 60 + 0.3 * 48)) < 0.5
    assert facts["phase_offsets"][0] == 0.0 and 0 <= facts["phase_offsets"][1] < 1
    assert facts["seam"]["seam_pose"] <= 1.0
    motion = read(out)
    assert motion.n_frames == 2 * facts["cycle_frames"] == facts["frames_out"]
    assert motion.root_positions[-1, 2] - motion.root_positions[0, 2] > 1.8 * 135   # walks on


def test_blend_table_with_equal_weights(walks, tmp_path):
    out = tmp_path / "blend.bvh"
    result = runner.invoke(app, ["blend", str(walks[0]), str(walks[1]), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "phase offsets" in result.output and "seam jump" in result.output and out.exists()


def test_transition_json_and_bvh(walks, tmp_path):
    out = tmp_path / "transition.bvh"
    result = runner.invoke(app, ["transition", str(walks[0]), str(walks[1]), "--cycles", "3", "-o", str(out),
                                 "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    assert abs(facts["period_frames_start"] - 60) < 1.0 and abs(facts["period_frames_end"] - 48) < 1.0
    assert facts["cycles"] == 3 and "seconds" in facts and "smoothness" in facts
    motion = read(out)
    assert motion.n_frames == facts["frames"] and abs(motion.n_frames - 3 * 54) <= 1
    text = runner.invoke(app, ["transition", str(walks[0]), str(walks[1]), "-o", str(out)])
    assert text.exit_code == 0 and "period 60" in text.output


@pytest.mark.parametrize("args,message", [
    (["--weights", "1,2,3"], "needs 2 numbers"),
    (["--weights", "1,x"], "comma-separated"),
    (["--weights", "0,0"], "all zero"),
    (["--weights", "-1,2"], ">= 0"),
    (["--cycles", "0"], "positive integer"),
])
def test_blend_bad_options_exit_2(walks, tmp_path, args, message):
    out = tmp_path / "x.bvh"
    result = runner.invoke(app, ["blend", str(walks[0]), str(walks[1]), "-o", str(out), *args])
    assert result.exit_code == 2 and message in result.output, result.output
    assert not out.exists()


def test_blend_needs_two_takes_and_a_bvh_output(walks, tmp_path):
    result = runner.invoke(app, ["blend", str(walks[0]), "-o", str(tmp_path / "x.bvh")])
    assert result.exit_code == 2 and "at least two takes" in result.output
    result = runner.invoke(app, ["blend", str(walks[0]), str(walks[1]), "-o", str(tmp_path / "x.txt")])
    assert result.exit_code == 1 and ".bvh" in result.output


def test_different_skeletons_exit_1_naming_the_joints(walks, tmp_path):
    m = read(walks[0])
    s = m.skeleton
    names = tuple("LeftKnee" if n == "LeftLeg" else n for n in s.names)
    other = write(Motion(Skeleton(names, s.parents, s.offsets, s.channels, s.end_sites), m.rotations,
                         m.translations, m.frame_time), tmp_path / "other.bvh")
    out = tmp_path / "x.bvh"
    for cmd in ("blend", "transition"):
        result = runner.invoke(app, [cmd, str(walks[0]), str(other), "-o", str(out)])
        assert result.exit_code == 1 and "LeftLeg" in result.output and "LeftKnee" in result.output, result.output
        assert not out.exists()


def test_blend_and_transition_take_the_phase_options(walks, tmp_path):
    out = tmp_path / "blend.bvh"
    result = runner.invoke(app, ["blend", str(walks[0]), str(walks[1]), "-o", str(out), "--json", "--joints", "legs",
                                 "--pca", "6", "--delay", "1", "--classes", "1", "--min-periods", "1.5"])
    assert result.exit_code == 0, result.output
    assert abs(json.loads(result.stdout)["period_frames"] - 54) < 1.5
    refused = runner.invoke(app, ["transition", str(walks[0]), str(walks[1]), "-o", str(tmp_path / "t.bvh"),
                                  "--part", "2"])
    assert refused.exit_code == 2 and "--part" in refused.stderr and "1 part(s)" in refused.stderr
    done = runner.invoke(app, ["transition", str(walks[0]), str(walks[1]), "-o", str(tmp_path / "t.bvh"),
                               "--joints", "legs", "--min-periods", "2"])
    assert done.exit_code == 0, done.output


def test_take_for_each_input():
    from mocycle.errors import OptionError
    from mocycle.tasks.fields import take_for_each

    assert take_for_each(None, 2) == [None, None]
    assert take_for_each("Walking", 2) == ["Walking", "Walking"]
    assert take_for_each("Walking, Running", 2) == ["Walking", "Running"]
    assert take_for_each("Walking,", 2) == ["Walking", None]  # an empty item: that input's default
    with pytest.raises(OptionError, match="names 3 takes for 2 inputs"):
        take_for_each("a,b,c", 2)


def test_blend_and_transition_read_one_take_of_each_input(tmp_path):
    """Two takes of one game-tool file (one cycle each): each input reads its own take; before, a repeated
    ``--take`` kept the last for both inputs and a comma list was taken as one name."""
    from conftest import shared_path

    robot = str(shared_path("engine", "RobotExpressive.glb"))
    for task, extra in (("blend", []), ("transition", ["--cycles", "1"])):
        out = tmp_path / f"{task}.glb"
        result = runner.invoke(app, [task, robot, robot, "--take", "Walking,Running", "-o", str(out), "--json",
                                     *extra])
        assert result.exit_code == 0, result.output
        assert read(out).n_frames >= 20
    result = runner.invoke(app, ["blend", robot, robot, "--take", "Walking,Running,Idle", "-o",
                                 str(tmp_path / "x.glb")])
    assert result.exit_code == 2 and "names 3 takes for 2 inputs" in result.output
    assert not (tmp_path / "x.glb").exists()
