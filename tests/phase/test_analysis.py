import json
from dataclasses import replace

import numpy as np
import pytest
from typer.testing import CliRunner

from conftest import shared_path
from helpers import circular_error
from mocycle.cli import app
from mocycle.cycle import extract_cycle, loop_metrics
from mocycle.datasets import (
    synthetic_circle_walk,
    synthetic_half_cycle_trap,
    synthetic_nonperiodic,
    synthetic_run,
    synthetic_still,
    synthetic_walk,
    synthetic_walk_then_run,
)
from mocycle.errors import MocycleError
from mocycle.io import read_bvh, write_bvh
from mocycle.motion import Motion
from mocycle.phase import find_phase
from mocycle.phase.analysis import _choose_period

runner = CliRunner()


@pytest.mark.parametrize("period_s, speed_change", [(1.0, 0.0), (0.75, 0.0), (1.0, 0.3)])
def test_period_and_phase_of_synthetic_walks(period_s, speed_change):
    take = synthetic_walk(n_frames=900, period_s=period_s, noise_deg=1.0, speed_change=speed_change, seed=7)
    result = find_phase(take.motion)
    assert len(result.classes) == 1, result.reason
    c = result.classes[0]
    true_period = float(np.mean(take.period_frames))  # mean period over the take
    assert abs(c.period_frames / true_period - 1) < 0.02
    assert np.isclose(c.period_s, c.period_frames / 60.0)
    assert abs(c.n_periods - (take.unwrapped_phase[-1] - take.unwrapped_phase[0])) < 0.5
    assert abs(result.autocorrelation_period_frames / true_period - 1) < 0.05
    assert c.coords.shape == (900,)  # the frames lost to delay embedding are filled in
    if speed_change == 0:
        assert circular_error(c.rank_uniform(), take.phase) < 0.02
        assert circular_error(c.gmm_cdf(), take.phase) < 0.03


def test_walk_then_run_excitation_regions_match_the_segments():
    take = synthetic_walk_then_run(seed=3, noise_deg=1.0)
    result = find_phase(take.motion)
    assert len(result.classes) == 2, result.reason
    by_start = sorted(result.classes, key=lambda c: c.excitation[0][0])
    (_, w0, w1), (_, r0, r1) = take.segments
    walk, run = by_start
    assert len(walk.excitation) == 1 and len(run.excitation) == 1
    (ws, we), (rs, re) = walk.excitation[0], run.excitation[0]
    # the blend window is 30 frames; it belongs to neither motion, and no region reaches past the switch
    assert abs(ws - w0) <= 10 and w1 - 20 <= we <= w1
    assert r0 <= rs <= r0 + 20 and abs(re - r1) <= 10
    assert abs(walk.period_frames - 60) < 1.5 and abs(run.period_frames - 42) < 1.5


def test_no_periodic_motion_is_an_empty_result_not_an_error():
    result = find_phase(synthetic_still(noise_deg=0.3).motion)
    assert result.classes == [] and result.reason
    assert result.to_dict()["classes"] == []


def test_too_short_and_still_takes_are_errors():
    take = synthetic_walk(n_frames=15)
    with pytest.raises(MocycleError, match="at least"):
        find_phase(take.motion)
    still = synthetic_still(n_frames=100)  # no noise: nothing moves at all
    with pytest.raises(MocycleError, match="nothing moves"):
        find_phase(still.motion)


def test_cli_phase_json_and_plot(tmp_path):
    path = write_bvh(synthetic_walk(n_frames=600, noise_deg=1.0, seed=1).motion, tmp_path / "walk.bvh")
    png = tmp_path / "phase.png"
    result = runner.invoke(app, ["phase", str(path), "--json", "--plot", str(png)])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    assert set(facts) >= {"classes", "autocorrelation_period_frames", "seconds"}
    (c,) = facts["classes"]
    assert set(c) >= {"birth", "death", "persistence", "period_frames", "period_s", "n_periods", "excitation"}
    assert abs(c["period_frames"] - 60) < 1.2 and abs(c["period_s"] - 1.0) < 0.02
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000


def test_cli_phase_exit_codes(tmp_path):
    still = write_bvh(synthetic_still(noise_deg=0.3).motion, tmp_path / "still.bvh")
    result = runner.invoke(app, ["phase", str(still)])
    assert result.exit_code == 3 and "no periodic motion found" in result.stderr
    short = write_bvh(synthetic_walk(n_frames=15).motion, tmp_path / "short.bvh")
    result = runner.invoke(app, ["phase", str(short)])  # valid but too short for a phase: nothing periodic
    assert result.exit_code == 3 and "too short" in result.stderr
    walk = write_bvh(synthetic_walk(n_frames=300).motion, tmp_path / "walk.bvh")
    for bad, code in ((["--classes", "zero"], 2), (["--pca", "-3"], 2), (["--delay", "-1"], 2),
                      (["--joints", "Tail"], 1)):
        result = runner.invoke(app, ["phase", str(walk), *bad])
        assert result.exit_code == code and result.stderr.startswith("error:"), bad
    bad_plot = runner.invoke(app, ["phase", str(walk), "--plot", str(tmp_path / "x.jpg")])
    assert bad_plot.exit_code == 1 and ".png" in bad_plot.stderr


@pytest.mark.parametrize("folder, name", [
    ("cmu-iclone", "02_01"), ("cmu-iclone", "07_01"), ("cmu-iclone", "05_01"),
    ("cmu-iclone", "07_10"),  # one H1 loop per walk cycle: found by joining them
    ("bandai", "dataset-1_walk_giant_001"),  # two classes for one motion: one is kept
])
def test_real_walks_agree_with_the_autocorrelation_period(folder, name):
    result = find_phase(read_bvh(shared_path(folder, f"{name}.bvh")))
    assert len(result.classes) == 1, result.reason
    assert abs(result.classes[0].period_frames / result.autocorrelation_period_frames - 1) < 0.05


# -- issue 11: turning walks, half cycles, short takes, subsets, separate regions ------------------------------


@pytest.mark.parametrize("up", ["y", "z"])
def test_a_walk_along_a_circle_keeps_its_period_and_turn(up):
    # 90 degrees per cycle over 5.6 cycles: with the root velocity in world axes the phase found 36 frames
    take = synthetic_circle_walk(n_frames=168, fps=30.0, period_s=1.0, turn_per_cycle_deg=90.0, noise_deg=2.0,
                                 up=up)
    result = find_phase(take.motion)
    assert len(result.classes) == 1, result.reason
    assert abs(result.classes[0].period_frames / 30.0 - 1) < 0.02
    cycle = extract_cycle(take.motion)
    assert abs(cycle.to_dict()["turn_per_cycle_deg"] - 90.0) < 3.0


def test_a_phase_that_wraps_once_per_step_is_doubled_to_the_full_cycle():
    take = synthetic_half_cycle_trap(n_frames=300, fps=30.0, period_s=1.0)  # exact: the trunk alone is faint
    result = find_phase(take.motion, joints="spine")  # the trunk repeats every step
    assert len(result.classes) == 1, result.reason
    c = result.classes[0]
    assert c.half_cycle and "across one period of 15.0" in c.period_reason and "trade places" in c.period_reason
    assert abs(c.period_frames / 30.0 - 1) < 0.02 and abs(c.n_periods - 10) < 1.0
    assert c.to_dict()["half_cycle_doubled"] is True
    # left and right trade places within the found cycle, not across it
    cycle = extract_cycle(take.motion, joints="spine")
    assert cycle.n_frames == 30
    plain = find_phase(synthetic_walk(n_frames=300, fps=30.0, noise_deg=1.0).motion).classes[0]
    assert not plain.half_cycle and abs(plain.period_frames / 30.0 - 1) < 0.02


def test_a_short_take_decides_between_disagreeing_periods_by_self_similarity():
    take = synthetic_run(n_frames=68, fps=30.0, period_s=0.9, noise_deg=1.0, seed=1)  # 2.5 cycles of 27 frames
    result = find_phase(take.motion, keep_features=True)
    assert len(result.classes) == 1, result.reason
    c = result.classes[0]
    assert abs(c.period_frames / 27.0 - 1) < 0.04
    assert {"cohomology", "autocorrelation"} <= set(c.period_candidates)
    # A cohomology period 11 % short (as seen on a 68-frame Bandai run) loses to the autocorrelation's.
    short = replace(c, period_frames=0.89 * c.period_frames, period_reason="")
    fixed = _choose_period(short, result.features, 8, float("nan"))
    assert fixed.period_source == "autocorrelation" and "self-similarity" in fixed.period_reason
    assert abs(fixed.period_frames / 27.0 - 1) < 0.04
    assert fixed.to_dict()["period_candidates"]["cohomology"] == pytest.approx(0.89 * c.period_frames)


def test_min_periods_is_the_limit_on_how_often_a_class_winds():
    take = synthetic_walk(n_frames=60, fps=30.0, period_s=1.0, noise_deg=0.5, seed=1)  # two cycles
    assert find_phase(take.motion).classes
    assert not find_phase(take.motion, min_periods=2.5).classes
    with pytest.raises(MocycleError, match="min_periods"):
        find_phase(take.motion, min_periods=0.5)


@pytest.mark.parametrize("seed", [1, 2])
def test_when_the_whole_body_finds_nothing_the_legs_are_tried(seed):
    # a walk whose upper body and root wander at random: only the legs are periodic
    walk = synthetic_walk(n_frames=100, fps=30.0, period_s=1.0, noise_deg=1.0, seed=seed)
    wander = synthetic_nonperiodic(n_frames=100, fps=30.0, seed=seed + 10).motion
    skel = walk.motion.skeleton
    upper = [j for j in range(skel.n_joints) if j not in skel.select("legs")]
    q = walk.motion.rotations.copy()
    q[:, upper] = wander.rotations[:, upper]
    motion = Motion(skel, q, wander.translations, walk.motion.frame_time)
    result = find_phase(motion)
    assert result.joints_used == "legs" and "also tried all" in result.reason
    assert result.classes and result.classes[0].joints_used == "legs"
    assert abs(result.classes[0].period_frames / 30.0 - 1) < 0.04
    assert result.to_dict()["joints_used"] == "legs"
    assert not find_phase(motion, joints="spine").classes  # an explicit choice is not second-guessed


def test_walk_then_run_regions_do_not_bleed_into_each_other():
    take = synthetic_walk_then_run(n_walk=240, n_run=120, fps=30.0, noise_deg=1.0, seed=2)
    result = find_phase(take.motion)
    assert len(result.classes) == 2, result.reason
    walk, run = result.classes
    (_, _, switch), _ = take.segments
    assert walk.excitation[-1][1] <= switch and run.excitation[0][0] >= switch  # before this: 244 and 236
    alone = take.motion[switch:]
    run_alone = loop_metrics(alone, extract_cycle(alone))["template_error"]
    run_here = loop_metrics(take.motion, extract_cycle(take.motion, phase=result, which=1))["template_error"]
    assert run_here < 1.2 * run_alone  # before this: 1.7 times (0.34 rad against 0.20)


def test_a_take_too_short_for_a_phase_has_no_periodic_motion():
    """Valid input shorter than a phase needs is the outcome 'no periodic motion' (CLI exit 3), not a bad file."""
    from mocycle.errors import NoPeriodicMotion

    with pytest.raises(NoPeriodicMotion, match="needs at least"):
        find_phase(synthetic_walk(n_frames=20).motion)


@pytest.mark.parametrize("frames, columns", [(157, 241), (40, 300), (300, 50), (20, 21)])
def test_principal_components_are_the_svd_scores(frames, columns):
    """Both scatter-matrix routes (fewer frames than columns: the Gram matrix) give the SVD's scores with
    scikit-learn's sign rule."""
    from scipy.linalg import svd

    from mocycle.phase.analysis import _component_signs, principal_components

    rng = np.random.default_rng(frames)
    X = rng.standard_normal((frames, columns)) * np.linspace(3.0, 0.1, columns) + 5.0
    U, S, Vt = svd(X - X.mean(axis=0), full_matrices=False)
    expected = U[:, :8] * _component_signs(Vt[:8]) * S[:8]
    got = principal_components(X, 8)
    assert got.shape == (frames, 8)
    np.testing.assert_allclose(got, expected, atol=1e-9 * np.abs(expected).max())
    mine = X.copy()  # centred in place when the caller gives it up: the same scores
    np.testing.assert_array_equal(principal_components(mine, 8, overwrite=True), got)
    np.testing.assert_allclose(mine.mean(axis=0), 0.0, atol=1e-12)
