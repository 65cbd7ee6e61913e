import json

import numpy as np
from typer.testing import CliRunner

from mocycle.cli import app
from mocycle.io import write
from tests.contacts.test_contacts import _planted_walk

runner = CliRunner()


def _walk(tmp_path):
    return write(_planted_walk(n_frames=300, fps=60.0, noise_deg=0.3)[1], tmp_path / "walk.bvh")


def test_loop_locks_the_feet_of_a_travelling_loop_and_reports_them(tmp_path):
    src, out, png = _walk(tmp_path), tmp_path / "cycle.bvh", tmp_path / "feet.png"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--json", "--root", "motion",
                                 "--feet-plot", str(png)])
    assert result.exit_code == 0, result.output
    feet = json.loads(result.stdout)["feet"]
    assert feet["mode"] == "lock" and set(feet["contacts"]) == {"left", "right"}
    n = json.loads(result.stdout)["cycle_frames"]
    for side in ("left", "right"):
        spans = feet["contacts"][side]["contacts"]
        assert spans and all(0 <= a < b <= 2 * n for a, b in spans)
    assert feet["skate_after"] > 0 and feet["skate_before"] > 0 and feet["largest_leg_step_after"] > 0
    assert png.stat().st_size > 10_000
    metrics = json.loads(result.stdout)["metrics"]
    assert metrics["skate"] == feet["skate_before"] and metrics["input_skate"] > 0  # metrics: the fitted cycle


def test_loop_feet_options(tmp_path):
    src, out = _walk(tmp_path), tmp_path / "cycle.bvh"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--json"])      # in place: kept by default
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["feet"]["mode"] == "keep"
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--feet", "slide"])
    assert result.exit_code == 2 and "--feet must be one of" in result.output   # a bad option value: usage
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--feet", "lock", "--foot-joints", "nope"])
    assert result.exit_code == 1 and "no joint named 'nope'" in result.output
    result = runner.invoke(app, ["loop", str(src), "-o", str(out), "--json", "--feet", "lock",
                                 "--foot-joints", "LeftFoot:LeftToeBase,RightFoot:RightToeBase"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["feet"]["contacts"]["left"]["joints"]["toe"] == "LeftToeBase"


def test_blend_locks_the_feet_of_a_travelling_blend(tmp_path):
    a = _walk(tmp_path)
    b = write(_planted_walk(n_frames=300, fps=60.0, noise_deg=0.3, period_s=1.1)[1], tmp_path / "slow.bvh")
    out = tmp_path / "blend.bvh"
    result = runner.invoke(app, ["blend", str(a), str(b), "-o", str(out), "--root", "motion", "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    assert facts["feet"]["mode"] == "lock" and facts["feet"]["contacts"]["right"]["contacts"]
    assert facts["seam"]["seam_pose"] < 2.0
    result = runner.invoke(app, ["blend", str(a), str(b), "-o", str(out), "--json"])
    assert json.loads(result.stdout)["feet"]["mode"] == "keep"


def test_stretch_and_transition_lock_travelling_output(tmp_path):
    a = _walk(tmp_path)
    out = tmp_path / "long.bvh"
    result = runner.invoke(app, ["stretch", str(a), "--factor", "1.5", "-o", str(out), "--json"])
    assert result.exit_code == 0, result.output
    feet = json.loads(result.stdout)["feet"]
    assert feet["mode"] == "lock" and feet["contacts"]["left"]["contacts"]
    result = runner.invoke(app, ["stretch", str(a), "--factor", "1.5", "-o", str(out), "--json", "--feet", "keep"])
    assert json.loads(result.stdout)["feet"]["mode"] == "keep"
    b = write(_planted_walk(n_frames=300, fps=60.0, noise_deg=0.3, period_s=1.1)[1], tmp_path / "slow.bvh")
    result = runner.invoke(app, ["transition", str(a), str(b), "-o", str(out), "--cycles", "2", "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["feet"]["mode"] == "lock"


def test_decompress_keeps_the_keyframes_by_default_and_locks_the_feet_when_asked(tmp_path):
    from mocycle.contacts import detect_contacts, ranges
    from mocycle.io import read_bvh
    from mocycle.keyframes import read_compressed

    src, mck = _walk(tmp_path), tmp_path / "walk.mck"
    assert runner.invoke(app, ["compress", str(src), "-o", str(mck)]).exit_code == 0
    keys = read_compressed(mck).key_idx
    kept, locked = tmp_path / "kept.bvh", tmp_path / "locked.bvh"
    result = runner.invoke(app, ["decompress", str(mck), "-o", str(kept), "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    assert facts["feet"]["mode"] == "keep" and facts["keyframes_exact"] is True
    result = runner.invoke(app, ["decompress", str(mck), "-o", str(locked), "--json", "--feet", "lock"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    assert facts["feet"]["mode"] == "lock" and facts["keyframes_exact"] is False
    assert facts["feet"]["skate_after"] < facts["feet"]["skate_before"]
    a, b = read_bvh(kept), read_bvh(locked)
    orig = read_bvh(src)
    same = lambda x, y: np.abs(np.sum(x * y, axis=-1)).min() > 1 - 1e-9  # noqa: E731  (q and -q alike)
    assert same(a.rotations[keys], orig.rotations[keys])          # keep: the keyframes come back exactly
    assert not same(b.rotations[keys], orig.rotations[keys])      # lock: some keyframe near a contact changed
    # locked: each contact of the rebuilt take is held still (to the BVH's printed precision)
    con = detect_contacts(a)
    W = b.world_positions()
    for c, j in enumerate(con.joints):
        for s, e in ranges(con.mask[:, c]):
            assert np.abs(W[s:e, j] - W[s, j]).max() < 1e-3
    assert runner.invoke(app, ["decompress", str(mck), "-o", str(locked), "--feet", "slide"]).exit_code == 2
