"""Sessions joined from takes: each take starts where the last ended, facing where it faced, and the truth
of each stretch covers the joined take once."""

from __future__ import annotations

import numpy as np
import pytest

from mocycle.datasets import join_takes, synthetic_run, synthetic_walk, synthetic_walk_turn_walk, synthetic_wave
from mocycle.errors import MocycleError


def _hips(motion):
    P = motion.world_positions()
    sk = motion.skeleton
    d = P[:, sk.index("RightUpLeg")] - P[:, sk.index("LeftUpLeg")]
    return P[:, sk.index("Hips")], np.degrees(np.unwrap(np.arctan2(d[:, 2], -d[:, 0])))


def test_takes_join_where_the_last_one_ended():
    takes = [synthetic_walk_turn_walk(n_before_s=2.0, n_after_s=2.0).motion, synthetic_run(n_frames=240).motion,
             synthetic_wave(n_frames=240).motion]
    s = join_takes(takes, ["turn", "run", "wave"], crossfade=10)
    assert s.motion.n_frames == sum(t.n_frames for t in takes) - 20
    assert [x[0] for x in s.stretches] == ["turn", "run", "wave"]
    assert s.stretches[0][1] == 0 and s.stretches[-1][2] == s.motion.n_frames
    assert all(a[2] == b[1] for a, b in zip(s.stretches, s.stretches[1:], strict=False))
    pos, heading = _hips(s.motion)
    step = np.linalg.norm(np.diff(pos[:, [0, 2]], axis=0), axis=1)
    # no jump where takes meet: no frame moves the hips more than twice the largest step inside the takes
    inside = np.linalg.norm(np.diff(_hips(takes[1])[0][:, [0, 2]], axis=0), axis=1).max()
    assert step.max() < 2.0 * inside
    # the run goes on in the direction the turn ended in (the walk turned 90 degrees)
    border = s.stretches[1][1]
    assert abs((heading[border + 20] - heading[border - 20] + 180) % 360 - 180) < 15
    assert s.label_at(border) == "run" and s.label_at(border - 1) == "turn"


def test_a_session_needs_one_skeleton_and_enough_frames():
    walk = synthetic_walk(n_frames=120).motion
    with pytest.raises(MocycleError, match="one frame time"):
        join_takes([walk, synthetic_walk(n_frames=120, fps=30).motion], ["a", "b"])
    with pytest.raises(MocycleError, match="more than 20 frames"):
        join_takes([walk, walk[:15]], ["a", "b"])
