import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers import random_motion, tiny_skeleton
from mocycle.datasets import humanoid_skeleton
from mocycle.errors import MocycleError
from mocycle.keyframes.distance import (
    error_per_frame_per_joint,
    frame_errors,
    joint_weights,
    pose_distance,
    pose_distance_matrix,
    pose_vectors,
    stress,
)


def test_weights_are_longest_path_to_an_end_effector():
    # Hips -> Left Up Leg -> LeftLeg (End Site); Hips -> Spine (End Site)
    assert joint_weights(tiny_skeleton()).tolist() == [3.0, 2.0, 1.0, 1.0]
    skel = humanoid_skeleton()
    w = joint_weights(skel)
    leaves = [j for j in range(skel.n_joints) if not skel.children(j)]
    assert np.all(w[leaves] == 1) and w[0] == w.max()
    for j in range(1, skel.n_joints):
        assert w[skel.parents[j]] >= w[j] + 1


def test_pose_distance_is_eq_3_2_with_matrices():
    m = random_motion(20, seed=3)
    w = joint_weights(m.skeleton)
    A, B = m.rotation_matrices()[2], m.rotation_matrices()[11]
    tr = np.einsum("jab,jab->j", A, B)  # Tr[A B^T]
    expected = float(np.sum(w * np.arccos(np.clip((tr - 1) / 2, -1, 1))))
    assert pose_distance(m.rotations[2], m.rotations[11], w) == pytest.approx(expected, abs=1e-7)
    assert pose_distance(m.rotations[5], -m.rotations[5], w) == pytest.approx(0.0, abs=1e-7)  # q and -q


def test_distance_matrix_matches_pairs_and_is_symmetric():
    m = random_motion(30, seed=1)
    w = joint_weights(m.skeleton)
    D = pose_distance_matrix(m.rotations, w)
    assert np.allclose(D, D.T) and np.all(np.diag(D) == 0)
    i, j = 4, 17
    assert D[i, j] == pytest.approx(float(pose_distance(m.rotations[i], m.rotations[j], w)), abs=1e-6)
    D2 = pose_distance_matrix(m.rotations, w, m.rotations[[0, 5]])
    assert D2.shape == (30, 2) and np.allclose(D2, D[:, [0, 5]], atol=1e-6)


def test_error_per_frame_per_joint():
    m = random_motion(40, seed=2)
    assert error_per_frame_per_joint(m, m) == 0.0
    q = m.rotations.copy()
    turn = Rotation.from_rotvec([0.0, 0.3, 0.0])
    q[:, 1] = (Rotation.from_quat(q[:, 1]) * turn).as_quat()
    other = m.replace(rotations=q)
    w = joint_weights(m.skeleton)
    assert np.allclose(frame_errors(m, other), w[1] * 0.3, atol=1e-7)
    assert error_per_frame_per_joint(m, other) == pytest.approx(w[1] * 0.3 / 4, abs=1e-7)
    with pytest.raises(MocycleError, match="differ in length"):
        error_per_frame_per_joint(m, m[:10])


def test_stress_eq_4_1():
    rng = np.random.default_rng(0)
    Y = rng.normal(size=(25, 2))
    D = np.linalg.norm(Y[:, None] - Y[None], axis=-1)
    assert stress(D, Y) == pytest.approx(0.0, abs=1e-12)
    assert stress(D, 2 * Y) == pytest.approx(0.25)  # sum (2d - d)^2 / sum (2d)^2
    with pytest.raises(MocycleError, match="stress"):
        stress(D, Y[:5])


def test_pose_vectors_small_angle_distance():
    m = random_motion(10, seed=4)
    w = joint_weights(m.skeleton)
    q = m.rotations[:1].copy()
    q2 = q.copy()
    q2[0, 2] = (Rotation.from_quat(q[0, 2]) * Rotation.from_rotvec([1e-3, 0, 0])).as_quat()
    X = pose_vectors(np.concatenate([q, q2]), w)
    assert X.shape == (2, 36)
    assert np.linalg.norm(X[0] - X[1]) == pytest.approx(w[2] * 1e-3, rel=1e-3)


def test_frame_errors_block_by_block_are_the_pose_distances_of_the_whole_take(monkeypatch):
    import importlib

    from mocycle.datasets import synthetic_walk

    distance = importlib.import_module("mocycle.keyframes.distance")
    a = synthetic_walk(n_frames=200, fps=60, noise_deg=0.0, seed=1).motion
    b = synthetic_walk(n_frames=200, fps=60, noise_deg=3.0, seed=2).motion
    whole = distance.pose_distance(a.rotations, b.rotations, distance.joint_weights(a.skeleton))
    monkeypatch.setattr(distance, "ERROR_BLOCK", 48)  # five blocks, the last one short
    np.testing.assert_array_equal(distance.frame_errors(a, b), whole)
    assert whole.min() > 0


def test_project_refuses_a_take_too_long_for_all_pairs_before_any_work(monkeypatch):
    import mocycle.keyframes as keyframes
    from mocycle import tasks
    from mocycle.keyframes.distance import MAX_PAIRWISE_FRAMES
    from mocycle.motion import Motion, Skeleton

    def no_work(*args, **kwargs):
        raise AssertionError("the poses were projected before the take's length was checked")

    monkeypatch.setattr(keyframes, "PoseSpace", no_work)
    skeleton = Skeleton(("root", "tip"), [-1, 0], [[0, 0, 0], [0, 1, 0]], (("Xposition", "Yposition", "Zposition",
                        "Zrotation", "Xrotation", "Yrotation"), ("Zrotation", "Xrotation", "Yrotation")))
    take = Motion.rest(skeleton, MAX_PAIRWISE_FRAMES + 1)
    with pytest.raises(MocycleError, match=f"at most {MAX_PAIRWISE_FRAMES} frames; got {MAX_PAIRWISE_FRAMES + 1}"):
        tasks.project.run(take)
