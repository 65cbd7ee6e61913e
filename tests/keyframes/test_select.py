import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from mocycle.datasets import humanoid_skeleton, synthetic_walk
from mocycle.errors import MocycleError
from mocycle.keyframes import PoseSpace, select_keyframes
from mocycle.keyframes.distance import joint_weights
from mocycle.keyframes.select import keyframe_count, select_pb, select_rols, select_scs, select_uniform


def _piecewise(n=101, corner=37, seed=0):
    """Every joint slerps from pose A (frame 0) to B (frame ``corner``) to C (last frame)."""
    skel = humanoid_skeleton()
    J = skel.n_joints
    rng = np.random.default_rng(seed)
    poses = Rotation.from_rotvec(rng.normal(scale=0.6, size=(3 * J, 3))).as_quat().reshape(3, J, 4)
    q = np.empty((n, J, 4))
    for j in range(J):
        s = Slerp([0, corner, n - 1], Rotation.from_quat(poses[:, j]))
        q[:, j] = s(np.arange(n)).as_quat()
    return q, joint_weights(skel)


def test_keyframe_count():
    assert keyframe_count(100, ratio=0.03) == 3
    assert keyframe_count(20, ratio=0.03) == 2  # first and last at least
    assert keyframe_count(10, count=50) == 10
    for kw in ({"ratio": 0.0}, {"ratio": 1.5}, {"count": 1}, {"ratio": 0.1, "count": 3}, {}):
        with pytest.raises(MocycleError):
            keyframe_count(100, **kw)
    with pytest.raises(MocycleError, match="at least 2 frames"):
        keyframe_count(1, ratio=0.5)


def test_uniform():
    k = select_uniform(100, 5)
    assert k.tolist() == [0, 25, 50, 74, 99] or k.tolist() == [0, 25, 50, 75, 99]
    assert len(select_uniform(3, 3)) == 3


@pytest.mark.parametrize("select", [select_scs, select_pb])
def test_curve_selectors_find_the_corner(select):
    q, w = _piecewise()
    keys = select(q, w, 3)
    assert keys.tolist() == [0, 37, 100]


def test_scs_fills_uniformly_when_exact():
    q, w = _piecewise(n=50, corner=20)
    keys = select_scs(q, w, 6)
    assert len(keys) == 6 and {0, 20, 49} <= set(keys.tolist())


def test_rols_picks_k_control_points_with_the_ends():
    q, w = _piecewise(n=60, corner=25)
    space = PoseSpace(q, w)
    Q = np.c_[np.arange(60.0), np.abs(np.arange(60.0) - 25)]  # a 2-D projection with a corner
    keys = select_rols(space.distances, Q, 5)
    assert len(keys) == 5 and keys[0] == 0 and keys[-1] == 59 and np.all(np.diff(keys) > 0)
    assert np.array_equal(keys, select_rols(space.distances, Q, 5))  # deterministic
    with pytest.raises(MocycleError, match="ROLS"):
        select_rols(space.distances, Q[:10], 5)


@pytest.mark.parametrize("method", ["uniform", "scs", "pb", "rols"])
def test_every_selector_keeps_first_and_last(method):
    m = synthetic_walk(n_frames=150, fps=60, seed=2).motion
    keys = select_keyframes(method, PoseSpace(m), 6)
    assert len(keys) == 6 and keys[0] == 0 and keys[-1] == 149 and np.all(np.diff(keys) > 0)


def test_unknown_selector():
    m = synthetic_walk(n_frames=30, fps=30, seed=2).motion
    with pytest.raises(MocycleError, match="uniform, scs, pb, rols"):
        select_keyframes("best", PoseSpace(m), 3)
