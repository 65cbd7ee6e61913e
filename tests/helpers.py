"""Small motions built in the tests themselves (no files, no randomness beyond a seed)."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from mocycle.motion import EndSite, Motion, Skeleton


def tiny_skeleton() -> Skeleton:
    """Root with 6 channels, a chain of three joints with mixed Euler orders, an End Site."""
    return Skeleton(
        names=("Hips", "Left Up Leg", "LeftLeg", "Spine"),
        parents=[-1, 0, 1, 0],
        offsets=[[0, 0, 0], [10, -5, 0], [0, -40, 0], [0, 10, 0]],
        channels=(
            ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation"),
            ("Zrotation", "Xrotation", "Yrotation"),
            ("Xrotation", "Yrotation", "Zrotation"),
            ("Yrotation", "Xrotation", "Zrotation"),
        ),
        end_sites=(EndSite(2, (0.0, -40.0, 5.0), None), EndSite(3, (0.0, 15.0, 0.0), "Head top")),
    )


def random_motion(n_frames: int = 50, seed: int = 0, spin: bool = False) -> Motion:
    """Smooth random rotations and a travelling root on :func:`tiny_skeleton`.

    ``spin=True`` makes joint 1 turn several full circles about its own axis.
    """
    rng = np.random.default_rng(seed)
    skel = tiny_skeleton()
    t = np.linspace(0, 1, n_frames)[:, None]
    J = skel.n_joints
    rotvecs = np.zeros((n_frames, J, 3))
    for j in range(J):
        a, b = rng.normal(size=(2, 3))
        rotvecs[:, j] = np.sin(2 * np.pi * (t * 1.5 + a[0])) * a + np.cos(2 * np.pi * t) * b * 0.5
    quats = Rotation.from_rotvec(rotvecs.reshape(-1, 3)).as_quat().reshape(n_frames, J, 4)
    if spin:
        turn = Rotation.from_euler("Z", 5 * 2 * np.pi * t)
        quats[:, 1] = (turn * Rotation.from_quat(quats[:, 1])).as_quat()
    root = np.cumsum(rng.normal(size=(n_frames, 3)), axis=0) + [0, 90, 0]
    return Motion(skel, quats, None, 1 / 60, root_positions=root)


def max_angle(q1: np.ndarray, q2: np.ndarray) -> float:
    """Largest rotation angle (radians) between two quaternion arrays of equal shape."""
    r1 = Rotation.from_quat(np.asarray(q1).reshape(-1, 4))
    r2 = Rotation.from_quat(np.asarray(q2).reshape(-1, 4))
    return float((r1.inv() * r2).magnitude().max())


def circular_error(a: np.ndarray, b: np.ndarray) -> float:
    """Mean |a - b| on the circle (cycles) after the best constant rotation."""
    offset = np.angle(np.mean(np.exp(2j * np.pi * (a - b)))) / (2 * np.pi)
    return float(np.mean(np.abs(np.angle(np.exp(2j * np.pi * (a - b - offset)))) / (2 * np.pi)))
