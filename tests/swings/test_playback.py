import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import shared_path
from helpers import tiny_skeleton
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.io import read
from mocycle.motion import Motion
from mocycle.rotations import quat_angles
from mocycle.swings import geodesic_errors, playback, playback_errors, segment, segmentation_error


def pendulum(fps=120, seconds=3.0, amp_deg=40.0, period_s=1.0):
    """Joint 1 swings back and forth about one axis (ease in / ease out); the root travels."""
    t = np.arange(int(seconds * fps)) / fps
    theta = np.radians(amp_deg) * np.sin(2 * np.pi * t / period_s)
    skel = tiny_skeleton()
    q = np.zeros((t.size, skel.n_joints, 4))
    q[..., 3] = 1.0
    axis = np.array([1.0, 0.2, 0.0]) / np.linalg.norm([1.0, 0.2, 0.0])
    q[:, 1] = (Rotation.from_rotvec(theta[:, None] * axis) * Rotation.from_rotvec([0, 0.3, 0])).as_quat()
    root = np.c_[100 * t, 90 + 2 * np.sin(4 * np.pi * t), 0 * t]
    return Motion(skel, q, None, 1.0 / fps, root_positions=root)


def test_pure_swing_motion_plays_back_closely():
    m = pendulum()
    seg = segment(m)
    assert seg.joints == [1] and seg.n_swings >= 5  # two swings per period
    pb = playback(seg)
    geo = geodesic_errors(m, pb)
    assert geo[1] < 0.5 and geo[[0, 2, 3]].max() < 1e-6
    assert np.abs(pb.root_positions - m.root_positions).max() < 0.2  # the translation track's tolerance
    errs = playback_errors(m, pb)
    assert errs["segmentation_error"] < 1.0 and errs["rotation_dofs"] == 12
    assert errs["per_angle_error_deg"] == pytest.approx(errs["segmentation_error"] / 12)


def test_hermite_profile_beats_the_papers_linear_one_on_eased_swings():
    m = pendulum()
    seg = segment(m)
    lin = geodesic_errors(m, playback(seg, "linear"))[1]
    her = geodesic_errors(m, playback(seg, "hermite"))[1]
    assert her < lin
    with pytest.raises(MocycleError, match="profile"):
        playback(seg, "cubic")


def test_segmentation_error_is_the_mean_euclidean_distance_of_euler_vectors():
    m = pendulum(seconds=1.0)
    assert segmentation_error(m, m) == pytest.approx(0.0, abs=1e-9)
    # turn joint 3 (order YXZ) by 10° about its own first channel axis (Y) at every frame
    q = np.array(m.rotations)
    q[:, 3] = (Rotation.from_quat(q[:, 3]) * Rotation.from_euler("Y", 10, degrees=True)).as_quat()
    assert segmentation_error(m, m.replace(rotations=q)) == pytest.approx(10.0, abs=1e-6)
    # the other Euler solution of the same rotation is the same pose: no error
    q2 = np.array(m.rotations)
    q2[:, 2] = Rotation.from_euler("XYZ", [170, 20, -160], degrees=True).as_quat()
    other = m.replace(rotations=q2)
    assert segmentation_error(other, other.replace(rotations=-q2)) == pytest.approx(0.0, abs=1e-6)
    with pytest.raises(MocycleError, match="differ"):
        segmentation_error(m, m[:10])


def test_synthetic_walk_plays_back_within_a_few_degrees():
    m = synthetic_walk(n_frames=300, fps=60, seed=2).motion
    pb = playback(segment(m))
    errs = playback_errors(m, pb)
    assert errs["geodesic_error_deg"] < 2.0
    assert errs["per_angle_error_deg"] < 0.41  # the paper's figure


def test_real_bandai_walk_plays_back():
    m = read(shared_path("bandai", "dataset-1_walk_normal_001.bvh"))
    errs = playback_errors(m, playback(segment(m)))
    assert errs["geodesic_error_deg"] < 3.0
    assert max(errs["geodesic_error_by_joint_deg"].values()) < 8.0


def test_vectorised_playback_is_the_per_swing_definition():
    """All swings at once give each swing's own curve and scipy's Slerp between the keys."""
    from scipy.spatial.transform import Slerp

    from mocycle.rotations import rotvec_quat
    from mocycle.swings.playback import joint_quats

    walk = synthetic_walk(n_frames=240, fps=60, seed=3).motion
    seg = segment(walk, threshold=0.4)
    played = playback(seg)
    checked = 0
    for j in range(walk.n_joints):
        swings, dt = seg.swings_of(j), seg.frame_time
        keys = {}
        for s in swings:
            ends = s.quats(np.array([s.start, s.end], dtype=float), dt)
            keys.setdefault(float(s.start), ends[0])
            keys.setdefault(float(s.end), ends[1])
        for h in seg.holds_of(j):
            keys.setdefault(0.5 * (h.start + h.end), rotvec_quat(np.asarray(h.mean)))
        if len(keys) < 2:
            continue
        times = np.array(sorted(keys))
        want = Slerp(times, Rotation.from_quat(np.stack([keys[t] for t in times])))(
            np.clip(np.arange(seg.n_frames, dtype=float), times[0], times[-1])).as_quat()
        for s in swings:
            idx = np.arange(s.start, s.end + 1)
            want[idx] = s.quats(idx.astype(float), dt)
        got = played.rotations[:, j]
        assert np.abs(np.abs(np.sum(got * want, axis=1)) - 1.0).max() < 1e-12
        one = joint_quats(seg, j)
        assert np.abs(np.abs(np.sum(got * one, axis=1)) - 1.0).max() < 1e-12
        checked += 1
    assert checked > walk.n_joints // 2


def test_playback_errors_block_by_block_equal_those_of_the_whole_difference_array(monkeypatch):
    import importlib

    from mocycle.swings.playback import euler_differences

    pb_module = importlib.import_module("mocycle.swings.playback")  # the module (the package exports a function)

    walk = synthetic_walk(n_frames=300, fps=60, noise_deg=1.0, seed=5).motion
    again = playback(segment(walk, threshold=0.4))
    d = euler_differences(walk, again)
    monkeypatch.setattr(pb_module, "DIFFERENCE_BLOCK", 70)  # five blocks, the last one short
    np.testing.assert_array_equal(euler_differences(walk, again), d)
    errs = playback_errors(walk, again)
    assert errs["segmentation_error"] == pytest.approx(float(np.linalg.norm(d, axis=1).mean()), rel=1e-12)
    assert errs["rms_angle_error_deg"] == pytest.approx(float(np.sqrt(np.mean(d ** 2))), rel=1e-12)
    assert errs["rotation_dofs"] == d.shape[1] > 0
    whole = np.degrees(quat_angles(walk.rotations, again.rotations)).mean(axis=0)
    np.testing.assert_array_equal(geodesic_errors(walk, again), whole)  # the same sums, block by block
