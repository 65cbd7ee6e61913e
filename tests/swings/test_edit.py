import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import shared_path
from helpers import tiny_skeleton
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.io import read
from mocycle.motion import Motion
from mocycle.swings import edit_swing, segment

AXIS = np.array([0.0, 0.6, 0.8])


def two_swings(fps=60):
    """Joint 1: still 0.5 s, swing +60° in 0.5 s, still 1 s, swing back -60° in 0.5 s, still 0.5 s."""
    def ramp(n, a, b):
        u = np.linspace(0, 1, n)
        return a + (b - a) * (3 * u**2 - 2 * u**3)
    h = fps // 2
    theta = np.concatenate([np.zeros(h), ramp(h, 0, 60), np.full(2 * h, 60.0), ramp(h, 60, 0), np.zeros(h)])
    skel = tiny_skeleton()
    q = np.zeros((theta.size, skel.n_joints, 4))
    q[..., 3] = 1.0
    q[:, 1] = Rotation.from_rotvec(np.radians(theta)[:, None] * AXIS).as_quat()
    return Motion(skel, q, None, 1.0 / fps), theta


def angle_about_axis(m):
    rv = Rotation.from_quat(m.rotations[:, 1]).as_rotvec()
    return np.degrees(rv @ AXIS)


def test_angle_scale_turns_further_and_fades_back_before_the_next_swing():
    m, theta = two_swings()
    seg = segment(m, joints="Left Up Leg")
    assert len(seg.swings) == 2
    first, second = seg.swings_of(1)
    out = edit_swing(m, seg, "Left Up Leg", 0, angle_scale=1.5)
    got = angle_about_axis(out)
    assert got[first.end] == pytest.approx(1.5 * theta[first.end] - 0.5 * theta[first.start], abs=0.5)
    assert np.allclose(got[: first.start + 1], theta[: first.start + 1], atol=1e-6)
    assert np.allclose(got[second.start:], theta[second.start:], atol=1e-6)  # faded out by the next swing
    assert np.abs(np.diff(got)).max() < 6  # no jump
    others = np.delete(np.arange(m.n_joints), 1)
    assert np.array_equal(out.rotations[:, others], m.rotations[:, others])


def test_duration_scale_stretches_the_swing_and_keeps_the_next_one():
    m, theta = two_swings()
    seg = segment(m, joints="Left Up Leg")
    first, second = seg.swings_of(1)
    out = edit_swing(m, seg, 1, 0, duration_scale=2.0)
    got = angle_about_axis(out)
    L = first.end - first.start
    assert got[first.start + 2 * L] == pytest.approx(theta[first.end], abs=0.5)
    assert got[first.start + L] == pytest.approx(theta[first.start + L // 2], abs=1.0)
    assert np.allclose(got[second.start:], theta[second.start:], atol=1e-6)
    assert out.n_frames == m.n_frames


def test_identity_edit_changes_nothing():
    m, _ = two_swings()
    seg = segment(m)
    out = edit_swing(m, seg, "Left Up Leg", 1)
    assert np.allclose(out.rotations, m.rotations)


@pytest.mark.parametrize("kwargs, word", [
    (dict(joint="Left Up Leg", swing=5), "has 2 swings"),
    (dict(joint="Spine", swing=0), "no swings"),
    (dict(joint="Nope", swing=0), "no joint named"),
    (dict(joint="Left Up Leg", swing=0, angle_scale=-1), r"angle_scale must be a number in \[0, 10\]"),
    (dict(joint="Left Up Leg", swing=0, duration_scale=0), r"duration_scale must be a number in \[0.05, 20\]"),
    (dict(joint="Left Up Leg", swing=0, duration_scale=10), "largest scale"),
])
def test_bad_edits_raise_one_clear_error(kwargs, word):
    m, _ = two_swings()
    seg = segment(m)
    with pytest.raises(MocycleError, match=word):
        edit_swing(m, seg, **kwargs)


def test_segmentation_of_another_motion_is_refused():
    m, _ = two_swings()
    with pytest.raises(MocycleError, match="not of this motion"):
        edit_swing(m[:50], segment(m), "Left Up Leg", 0)


def test_real_bandai_arm_swing_smaller():
    m = read(shared_path("bandai", "dataset-1_walk_normal_001.bvh"))
    seg = segment(m)
    sw = seg.swings_of("UpperArm_L")[3]
    out = edit_swing(m, seg, "UpperArm_L", 3, angle_scale=0.5)
    j = m.skeleton.index("UpperArm_L")
    before = Rotation.from_quat(m.rotations[sw.end, j]) * Rotation.from_quat(m.rotations[sw.start, j]).inv()
    after = Rotation.from_quat(out.rotations[sw.end, j]) * Rotation.from_quat(out.rotations[sw.start, j]).inv()
    assert after.magnitude() < 0.75 * before.magnitude()


def test_an_edit_made_from_the_handed_over_take_is_the_same_edit():
    walk = synthetic_walk(n_frames=240, fps=60).motion
    seg = segment(walk, threshold=0.4)
    joint = seg.swings[0].name
    def own():  # a motion whose arrays it alone holds
        return Motion(walk.skeleton, walk.rotations, walk.translations, walk.frame_time)

    kept = edit_swing(own(), seg, joint, 0, angle_scale=1.3)
    given = own()
    handed = edit_swing(given, seg, joint, 0, angle_scale=1.3, hand_over=True)
    np.testing.assert_array_equal(handed.rotations, kept.rotations)
    np.testing.assert_array_equal(handed.translations, kept.translations)
    with pytest.raises(AttributeError):
        given.rotations  # noqa: B018 (emptied)
