import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from helpers import max_angle, random_motion
from mocycle.errors import MocycleError
from mocycle.keyframes.temporal import SCHEMES, interpolate_curves, interpolate_rotations
from mocycle.rotations import euler_to_quats, slerp


def test_slerp_matches_scipy():
    rng = np.random.default_rng(0)
    a, b = Rotation.random(2, random_state=3).as_quat()
    u = rng.uniform(size=7)
    ours = slerp(np.broadcast_to(a, (7, 4)), np.broadcast_to(b, (7, 4)), u)
    ref = Slerp([0, 1], Rotation.from_quat([a, b]))(u).as_quat()
    assert max_angle(ours, ref) < 1e-9


@pytest.mark.parametrize("scheme", SCHEMES)
def test_keyframes_come_back_exactly(scheme):
    m = random_motion(60, seed=5)
    keys = np.array([0, 13, 30, 59])
    q = interpolate_rotations(m.skeleton, keys, m.rotations[keys], 60, scheme)
    assert q.shape == (60, 4, 4)
    assert np.array_equal(q[keys], m.rotations[keys])
    assert np.allclose(np.linalg.norm(q, axis=-1), 1.0)
    seg = np.searchsorted(keys, np.arange(60), side="right") - 1
    hold = m.rotations[keys[np.minimum(seg, 3)]]  # holding the last keyframe: the baseline to beat
    angle = lambda a, b: np.abs(np.sum(a * b, axis=-1)).clip(0, 1)  # noqa: E731  (cos of half angles)
    assert angle(q, m.rotations).mean() > angle(hold, m.rotations).mean()


def test_linear_and_hermite_reproduce_linear_euler_curves():
    m = random_motion(41, seed=1)
    skel = m.skeleton
    t = np.linspace(0, 1, 41)[:, None]
    q = m.rotations.copy()
    angles = np.hstack([0.8 * t, -0.5 * t, 0.3 + 0.2 * t])  # joint 2, order XYZ
    q[:, 2] = euler_to_quats(angles, skel.euler_order(2))
    keys = np.array([0, 20, 40])
    for scheme in ("linear", "hermite"):
        out = interpolate_rotations(skel, keys, q[keys], 41, scheme)
        assert max_angle(out[:, 2], q[:, 2]) < 1e-9


def test_slerp_and_rbf_reproduce_a_constant_turn():
    m = random_motion(31, seed=2)
    q = m.rotations.copy()
    q[:, 3] = Rotation.from_rotvec(np.outer(np.linspace(0, 1, 31), [0.2, 1.0, -0.4])).as_quat()
    keys = np.array([0, 30])
    assert max_angle(interpolate_rotations(m.skeleton, keys, q[keys], 31, "slerp")[:, 3], q[:, 3]) < 1e-9
    rbf = interpolate_rotations(m.skeleton, keys, q[keys], 31, "rbf")[:, 3]
    # the orthonormalised matrix blend follows the same great arc, only its timing differs from slerp
    rel = Rotation.from_quat(q[0, 3]).inv() * Rotation.from_quat(rbf)
    axes = rel.as_rotvec()[1:] / rel.magnitude()[1:, None]
    assert np.allclose(axes, [0.2, 1.0, -0.4] / np.linalg.norm([0.2, 1.0, -0.4]), atol=1e-9)
    assert max_angle(rbf[15], q[15, 3]) < 1e-9 and max_angle(rbf, q[:, 3]) < 0.03


def test_hermite_is_smoother_than_linear_between_keys():
    t = np.arange(101)
    keys = np.array([0, 25, 50, 75, 100])
    y = np.sin(t / 100 * 2 * np.pi)[:, None]
    lin = interpolate_curves(keys, y[keys], 101, "linear")
    her = interpolate_curves(keys, y[keys], 101, "hermite")
    assert np.abs(her - y).max() < np.abs(lin - y).max()


def test_bad_input():
    m = random_motion(20, seed=0)
    with pytest.raises(MocycleError, match="increase from frame 0 to frame 19"):
        interpolate_rotations(m.skeleton, np.array([0, 10]), m.rotations[[0, 10]], 20)
    with pytest.raises(MocycleError, match="linear, hermite, slerp, rbf"):
        interpolate_rotations(m.skeleton, np.array([0, 19]), m.rotations[[0, 19]], 20, "cubic")
    with pytest.raises(MocycleError, match="shape"):
        interpolate_rotations(m.skeleton, np.array([0, 19]), m.rotations[[0, 1, 19]], 20)
