"""Loop checks (issue 11, item 4): a cycle that is not a loop is refused, exit 3, ``--force`` writes it."""

import json
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

import mocycle.cli.blend  # noqa: F401  (registers the commands)
import mocycle.phase.analysis as analysis
from conftest import shared_path
from mocycle.cli import app
from mocycle.cycle import extract_cycle, loop_metrics
from mocycle.cycle.blend import blend_cycles
from mocycle.cycle.checks import MAX_FIT_RATIO, check_loop, loop_checks
from mocycle.datasets import synthetic_nonperiodic, synthetic_walk
from mocycle.errors import LoopRefused, MocycleWarning
from mocycle.io import read, write
from mocycle.phase import find_phase

runner = CliRunner()


@pytest.fixture(scope="module")
def walk():
    return synthetic_walk(n_frames=500, noise_deg=1.0, seed=1).motion


@pytest.fixture(scope="module")
def wrong_phase():
    """The phase of a walk 1.5 times slower: a found period that is wrong, as on CMU's basketball take."""
    return find_phase(synthetic_walk(n_frames=500, period_s=1.5, noise_deg=1.0, seed=4).motion)


def _squeezed(phase, cycles: float):
    """``phase`` with its coordinate slowed so the take holds only ``cycles`` cycles (the cycle outgrows it)."""
    c = phase.classes[0]
    k = cycles / (c.unwrapped[-1] - c.unwrapped[0])
    unwrapped = c.unwrapped[0] + k * (c.unwrapped - c.unwrapped[0])
    c = replace(c, unwrapped=unwrapped, coords=np.mod(unwrapped, 1.0), period_frames=c.period_frames / k,
                excitation=[(0, unwrapped.size)])
    return replace(phase, classes=[c])


def test_a_good_loop_passes(walk):
    cycle = extract_cycle(walk)
    assert loop_checks(walk, cycle) == []
    assert loop_checks(walk, cycle, loop_metrics(walk, cycle)) == []
    assert check_loop(walk, cycle) == []


@pytest.mark.parametrize("method", ["harmonic", "centroid", "cut"])
def test_a_wrong_period_fits_worse_than_a_plain_cut_and_is_refused(walk, wrong_phase, method):
    cycle = extract_cycle(walk, method=method, phase=wrong_phase)
    failed = {f.name: f for f in loop_checks(walk, cycle)}
    assert "fit" in failed and failed["fit"].value > 1.5 * MAX_FIT_RATIO
    with pytest.raises(LoopRefused, match="worse than a plain cut of 60 frames.*period found .* wrong") as info:
        check_loop(walk, cycle)
    assert info.value.failed[0].name == "fit"
    with pytest.warns(MocycleWarning, match="fails the loop check.*fit.*option 'force'"):
        assert check_loop(walk, cycle, force=True)


def test_a_joint_turning_a_full_circle_every_cycle_is_a_loop():
    """A left arm that spins once per cycle is a correct loop: the metrics' ruler must not wrap at ±π."""
    take = synthetic_walk(n_frames=600, noise_deg=1.0)
    motion = take.motion
    arm = motion.skeleton.index("LeftArm")
    q = motion.rotations.copy()
    spin = Rotation.from_rotvec(np.outer(2 * np.pi * take.unwrapped_phase, [0, 0, 1]))
    q[:, arm] = (spin * Rotation.from_quat(q[:, arm])).as_quat()
    spinning = motion.replace(rotations=q)
    cycle = extract_cycle(spinning)
    metrics = loop_metrics(spinning, cycle)
    for key in ("seam_pose", "seam_velocity", "seam_pose_local", "seam_velocity_local"):
        assert metrics[key] < 1.5, key
    plain = loop_metrics(motion, extract_cycle(motion))
    assert metrics["template_error"] < 1.5 * plain["template_error"]  # the spin costs little, not 30 times more
    assert loop_checks(spinning, cycle) == []
    assert loop_checks(spinning, cycle, metrics) == []


def test_a_cycle_longer_than_the_take_is_refused(walk):
    with pytest.warns(MocycleWarning):
        cycle = extract_cycle(walk, phase=_squeezed(find_phase(walk), 0.8))
    assert cycle.n_frames > walk.n_frames
    failed = {f.name: f for f in loop_checks(walk, cycle)}
    assert "length" in failed and "longer than the 500 frames" in failed["length"].reason


def test_a_jumping_seam_is_refused(walk):
    cycle = extract_cycle(walk)
    N = cycle.n_frames
    P = cycle.P.copy()
    P[N // 2:] = cycle.P[(np.arange(N // 2, N) + N // 4) % N]   # half the loop jumps a quarter of a cycle
    broken = replace(cycle, P=P).rolled(N // 2)                   # ... and the jump is at the wrap
    failed = {f.name: f for f in loop_checks(walk, broken)}
    assert "seam" in failed and failed["seam"].value > 3


def test_loop_cli_refuses_with_exit_3_and_force_writes(tmp_path, walk, wrong_phase, monkeypatch):
    src = write(walk, tmp_path / "walk.bvh")
    monkeypatch.setattr(analysis, "find_phase", lambda *a, **k: wrong_phase)
    out = tmp_path / "cycle.bvh"
    # by default the walk's strides overrule the phase's period (issue 28): a loop at the strides' period
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--json"])
    assert result.exit_code == 0 and json.loads(result.stdout)["period_source"] == "strides"
    out.unlink()
    # the phase on the legs, as asked: that phase is looped or refused, not overruled (on every frame, where the
    # stand-in phase was made: at 60 fps the phase is otherwise found on every second frame)
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--joints", "legs", "--step", "1"])
    assert result.exit_code == 3
    assert "not a loop" in result.output and "plain cut" in result.output and not out.exists()
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--force", "--json", "--joints", "legs",
                                 "--step", "1"])
    assert result.exit_code == 0 and out.exists()
    assert "warning:" in result.output and "--force" in result.output
    tr = runner.invoke(app, ["transition", str(src), str(src), "-o", str(tmp_path / "t.bvh"), "--joints", "legs"])
    assert tr.exit_code == 3 and "not a loop" in tr.output and not (tmp_path / "t.bvh").exists()


def test_blend_refuses_a_take_whose_cycle_is_not_a_loop(walk, wrong_phase, monkeypatch):
    good = extract_cycle(walk)
    monkeypatch.setattr(analysis, "find_phase", lambda *a, **k: wrong_phase)
    with pytest.raises(LoopRefused, match="bad take: not a loop"):
        blend_cycles([good, walk], labels=["good", "bad take"])
    with pytest.warns(MocycleWarning, match="bad take: kept although"):
        blend_cycles([good, walk], labels=["good", "bad take"], force=True)


def test_a_non_periodic_take_is_refused(tmp_path):
    src = write(synthetic_nonperiodic(n_frames=400, seed=2).motion, tmp_path / "wander.bvh")
    result = runner.invoke(app, ["loop", str(src), "-o", str(tmp_path / "c.bvh")])
    assert result.exit_code == 3 and "no repeating motion" in result.output


def test_shared_walk_passes_every_check():
    motion = read(shared_path("bandai", "dataset-1_walk_normal_001.bvh"))
    assert loop_checks(motion, extract_cycle(motion)) == []
