import json

import numpy as np
import pytest
from typer.testing import CliRunner

from conftest import shared_path
from helpers import circular_error
from mocycle.cli import app
from mocycle.datasets import synthetic_still, synthetic_walk, synthetic_walk_then_run
from mocycle.errors import MocycleError
from mocycle.io import read_bvh, write_bvh
from mocycle.phase import find_phase

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
    assert abs(ws - w0) <= 10 and abs(we - w1) <= 15  # the blend window is 30 frames
    assert abs(rs - r0) <= 15 and abs(re - r1) <= 10
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
    result = runner.invoke(app, ["phase", str(short)])
    assert result.exit_code == 1 and "at least" in result.stderr
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
