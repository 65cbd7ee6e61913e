import numpy as np
from scipy.spatial.transform import Rotation

from helpers import max_angle, random_motion
from mocycle.axes import vertical_axis
from mocycle.cycle.representation import CycleSpace
from mocycle.datasets import synthetic_walk
from mocycle.motion import Motion
from mocycle.rotations import axis_rotations, nearest_rotations


def _rotate_world(motion: Motion, rot: Rotation) -> Motion:
    """The same take seen in a rotated world (the root's rotation and translation turned by ``rot``)."""
    q = motion.rotations.copy()
    q[:, 0] = (rot * Rotation.from_quat(q[:, 0])).as_quat()
    t = motion.translations.copy()
    t[:, 0] = rot.apply(t[:, 0])
    return motion.replace(rotations=q, translations=t)


def test_encode_decode_round_trip_is_exact():
    for motion in (synthetic_walk(n_frames=120, noise_deg=2).motion, random_motion(80, spin=True)):
        space = CycleSpace.fit(motion)
        P, L = space.encode(motion)
        assert P.shape == (motion.n_frames, space.n_periodic) and L.shape == (motion.n_frames, 4)
        back = space.decode(P, L)
        assert max_angle(back.rotations, motion.rotations) < 1e-9
        assert np.allclose(back.translations, motion.translations)


def test_vertical_axis_of_y_up_and_z_up_takes():
    walk = synthetic_walk(n_frames=60).motion
    assert np.array_equal(vertical_axis(walk), [0, 1, 0])
    z_up = _rotate_world(walk, Rotation.from_euler("x", 90, degrees=True))
    assert np.array_equal(vertical_axis(z_up), [0, 0, 1])
    upside_down = _rotate_world(walk, Rotation.from_euler("x", 180, degrees=True))
    assert np.array_equal(vertical_axis(upside_down), [0, -1, 0])


def test_heading_is_unwrapped_through_full_turns_and_tilt_has_no_heading():
    walk = synthetic_walk(n_frames=240).motion
    turns = np.linspace(0, 3 * 2 * np.pi, walk.n_frames)  # three full turns about the vertical
    q = walk.rotations.copy()
    q[:, 0] = (Rotation.from_rotvec(np.outer(turns, [0, 1, 0])) * Rotation.from_quat(q[:, 0])).as_quat()
    spun = walk.replace(rotations=q)
    space = CycleSpace.fit(spun)
    _, L = space.encode(spun)
    _, L0 = space.encode(walk)
    assert np.allclose(L[:, 3] - L0[:, 3], turns, atol=1e-9)


def test_nearest_rotations_and_axis_rotations():
    R = Rotation.random(20, random_state=1).as_matrix()
    noisy = R + 0.01 * np.random.default_rng(0).normal(size=R.shape)
    fixed = nearest_rotations(noisy)
    assert np.allclose(fixed @ np.swapaxes(fixed, 1, 2), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(fixed), 1.0)
    assert np.abs(fixed - R).max() < 0.05
    A = axis_rotations(np.array([0.0, 0.0, 1.0]), np.array([np.pi / 2]))
    assert np.allclose(A[0] @ [1, 0, 0], [0, 1, 0])


def test_decode_of_a_repeated_cycle_projects_once_and_gives_the_same_motion():
    motion = synthetic_walk(n_frames=40, noise_deg=2).motion
    space = CycleSpace.fit(motion)
    P, L = space.encode(motion)
    P = P + np.random.default_rng(0).normal(scale=0.01, size=P.shape)   # not rotations: decode projects them
    L3 = np.vstack([L, L + 1.0, L + 2.0])
    once = space.decode(np.tile(P, (3, 1)), L3, projected=np.tile(space.project(P), (3, 1, 1, 1)))
    tiled = space.decode(np.tile(P, (3, 1)), L3)
    assert np.array_equal(once.rotations, tiled.rotations) and np.array_equal(once.translations, tiled.translations)
