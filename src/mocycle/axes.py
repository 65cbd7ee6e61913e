"""The vertical axis of a take and headings about it: one place for loops, feet, IK and glTF.

BVH and ASF/AMC files do not say which way is up (CMU is Y-up, other exporters Z-up).
:func:`vertical_axis` detects it from the mean pose, or takes an override (``"y"``,
``"-z"``, a vector); detect it once per motion and pass the result on.
:func:`horizontal_basis` and :func:`heading_angles` measure the heading (the angle about
the vertical) of any direction, unwrapped in time.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from .errors import OptionError
from .motion import Motion
from .rotations import nearest_rotations

AXIS_NAMES = ("x", "y", "z", "+x", "+y", "+z", "-x", "-y", "-z")


def parse_up(up) -> np.ndarray:
    """A unit up vector ``(3,)`` from ``"y"``, ``"+z"``, ``"-y"``, ... or any non-zero 3-vector."""
    if isinstance(up, str):
        name = up.strip().lower()
        if name not in AXIS_NAMES:
            raise OptionError("up", f"must be one of {', '.join(AXIS_NAMES)} or a 3-vector; got {up!r}")
        v = np.zeros(3)
        v["xyz".index(name[-1])] = -1.0 if name.startswith("-") else 1.0
        return v
    v = np.asarray(up, dtype=np.float64).reshape(-1)
    norm = float(np.linalg.norm(v)) if v.shape == (3,) and np.all(np.isfinite(v)) else 0.0
    if norm == 0.0:
        raise OptionError("up", f"must be one of {', '.join(AXIS_NAMES)} or a non-zero 3-vector; got {up!r}")
    return v / norm


def vertical_axis(motion: Motion, up=None) -> np.ndarray:
    """The world up direction ``(3,)`` of a humanoid take.

    Parameters
    ----------
    motion : the take.
    up : ``None`` to detect it, or an override (``"y"``, ``"-z"``, a 3-vector), returned as a unit vector.

    Returns
    -------
    ``(3,)`` unit vector.  Detected: along +X, +Y or +Z or their negatives, the axis along which the mean
    pose is tallest; its sign puts most joints in the upper half (spine, arms, head and hands outnumber
    the legs).  The pose is the travel joint and the joints below it, taken relative to the travel joint.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> walk = synthetic_walk(n_frames=60).motion
    >>> vertical_axis(walk).tolist(), vertical_axis(walk, up="-z").tolist()
    ([0.0, 1.0, 0.0], [0.0, 0.0, -1.0])
    """
    if up is not None:
        return parse_up(up)
    return motion.cache("up", _detect_up).copy()  # detected once per motion


def _detect_up(motion: Motion) -> np.ndarray:
    """:func:`vertical_axis` detected from the mean pose (its docstring says how)."""
    step = max(1, motion.n_frames // 50)
    travel = motion.travel_joint
    parents = list(motion.skeleton.parents) + [site.parent for site in motion.skeleton.end_sites]

    def below_travel(i: int) -> bool:
        while i >= 0:
            if i == travel:
                return True
            i = parents[i]
        return False

    # The travel joint and everything below it, relative to the travel joint frame by frame: joints above
    # it (Bandai's static joint_Root at the room's origin) and the walk across the room would otherwise
    # stretch the mean pose along the walking direction.
    keep = [i for i in range(len(parents)) if below_travel(i)]
    W = motion[::step].world_positions(end_sites=True)
    pose = (W[:, keep] - W[:, travel:travel + 1]).mean(axis=0)  # (J', 3)
    extent = np.ptp(pose, axis=0)
    axis = int(np.argmax(extent))
    mid = 0.5 * (pose[:, axis].max() + pose[:, axis].min())
    v = np.zeros(3)
    v[axis] = 1.0 if np.median(pose[:, axis]) >= mid else -1.0
    return v


def up_in_parent_frame(motion: Motion, joint: int, world_up: np.ndarray) -> np.ndarray:
    """The world up ``(3,)`` seen from ``joint``'s parent: in the frame of the parent's mean world rotation
    over the take (the world up itself for a root).  Unit vector."""
    parent = int(motion.skeleton.parents[joint])
    if parent >= 0:
        mean_parent = nearest_rotations(_world_rotation(motion[:: max(1, motion.n_frames // 50)], parent).mean(axis=0))
        up = mean_parent.T @ world_up
    else:
        up = np.asarray(world_up, dtype=np.float64)
    return up / np.linalg.norm(up)


def _world_rotation(motion: Motion, joint: int) -> np.ndarray:
    """World rotation matrices ``(T, 3, 3)`` of one joint: the products of :meth:`Motion.world_transforms`
    along its chain from the root only (not every joint of a 100-joint rig)."""
    chain = motion.skeleton.chain_to(joint)
    T = motion.n_frames
    local = Rotation.from_quat(motion.rotations[:, chain].reshape(-1, 4)).as_matrix().reshape(T, len(chain), 3, 3)
    world = local[:, 0]
    for k in range(1, len(chain)):
        world = world @ local[:, k]
    return world


def horizontal_basis(up: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors ``e1``, ``e2`` ``(3,)`` spanning the plane normal to the unit ``up`` (``e1 × e2 = up``
    up to sign convention ``e2 = up × e1``); ``e1`` is the coordinate axis least aligned with ``up``,
    made horizontal, so heading 0 is along it."""
    up = np.asarray(up, dtype=np.float64)
    least = np.eye(3)[int(np.argmin(np.abs(up)))]
    e1 = least - up * (least @ up)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(up, e1)


def heading_angles(directions: np.ndarray, e1: np.ndarray, e2: np.ndarray) -> np.ndarray:
    """Heading ``(T,)`` radians of ``directions`` ``(T, 3)`` in the horizontal basis ``e1``, ``e2``
    (:func:`horizontal_basis`): the angle from ``e1`` towards ``e2``, unwrapped in time."""
    d = np.asarray(directions, dtype=np.float64)
    return np.unwrap(np.arctan2(d @ e2, d @ e1))
