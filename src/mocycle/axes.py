"""The vertical axis of a take and headings about it: one place for loops, feet, IK and glTF.

glTF files are +Y up by specification and FBX files declare their axes: their readers set the skeleton's
:attr:`~mocycle.motion.Skeleton.up`.  BVH and ASF/AMC files do not say which way is up (CMU is Y-up, other
exporters Z-up): :func:`vertical_axis` finds it from the body (the chest above the feet), or takes an
override (``"y"``, ``"-z"``, a vector); detect it once per motion and pass the result on.
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
    ``(3,)`` unit vector: ``up`` when given; else the vertical the file declares (the skeleton's
    :attr:`~mocycle.motion.Skeleton.up`: glTF, FBX); else detected from the body, along +X, +Y or +Z or their
    negatives: the axis nearest the direction from the feet to the chest, averaged over the take (the
    chest: where the upper body branches into arms and neck; the feet: the ends of the legs; the upper body
    is the branch of the hips holding the spine's joints by name, else the largest), never from where most
    joints hang (a hand's 20 finger joints hang below the hips when the arms are down).  A skeleton without
    that shape (no branching at the hips) falls back to the mean pose: the axis along which it is tallest,
    its sign putting most joints in the upper half.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> walk = synthetic_walk(n_frames=60).motion
    >>> vertical_axis(walk).tolist(), vertical_axis(walk, up="-z").tolist()
    ([0.0, 1.0, 0.0], [0.0, 0.0, -1.0])
    """
    if up is not None:
        return parse_up(up)
    if motion.skeleton.up is not None:  # the file says
        return np.array(motion.skeleton.up)
    return motion.cache("up", _detect_up).copy()  # detected once per motion


def _detect_up(motion: Motion) -> np.ndarray:
    """:func:`vertical_axis` detected from the body (its docstring says how)."""
    step = max(1, motion.n_frames // 50)
    W = motion[::step].world_positions(end_sites=True)
    parts = body_parts(motion.skeleton)
    if parts is not None:
        chest, feet = parts
        d = (W[:, chest] - W[:, feet].mean(axis=1)).mean(axis=0)
        size = float(np.ptp(W.mean(axis=0), axis=0).max())
        if np.linalg.norm(d) > 1e-3 * size:
            v = np.zeros(3)
            axis = int(np.argmax(np.abs(d)))
            v[axis] = 1.0 if d[axis] > 0 else -1.0
            return v
    return _mean_pose_up(motion, W)


def body_parts(skeleton) -> tuple[int, list[int]] | None:
    """The chest and the feet of a body, as columns of ``world_positions(end_sites=True)``, or ``None`` when
    the skeleton has no such shape.

    From the body's root (:meth:`Skeleton.body_root`, the hips) hang the legs and the upper body: the upper
    body is the branch holding the most spine, neck or head joints by name (``spine`` of
    :data:`~mocycle.motion.JOINT_GROUPS`), else the one with the most joints; the chest is the first joint
    down it with two or more joints below (arms and neck), or its last joint; the feet are the ends (leaves,
    End Sites included) of the branches holding leg joints by name, else of every other branch."""
    from .errors import MocycleError

    J = skeleton.n_joints
    parents = [int(p) for p in skeleton.parents] + [site.parent for site in skeleton.end_sites]
    children: list[list[int]] = [[] for _ in parents]
    for i, p in enumerate(parents):
        if p >= 0:
            children[p].append(i)
    root = skeleton.body_root()
    branches = [c for c in children[root] if c < J]
    if len(branches) < 2:
        return None

    def below(i: int) -> list[int]:
        out, todo = [], [i]
        while todo:
            k = todo.pop()
            out.append(k)
            todo += children[k]
        return out

    def named(group: str) -> set[int]:
        try:
            return set(skeleton.select(group))
        except MocycleError:
            return set()

    spine, legs = named("spine"), named("legs")
    trees = {c: below(c) for c in branches}
    upper = max(branches, key=lambda c: (len(spine.intersection(trees[c])), len(trees[c])))
    lower = [c for c in branches if c != upper and legs.intersection(trees[c])] or \
        [c for c in branches if c != upper]
    chest = upper
    while True:
        joints_below = [c for c in children[chest] if c < J]
        if len(joints_below) != 1:
            break
        chest = joints_below[0]
    feet = [k for c in lower for k in trees[c] if not children[k]]
    return chest, feet


def _mean_pose_up(motion: Motion, W: np.ndarray) -> np.ndarray:
    """The axis along which the mean pose is tallest, its sign putting most joints in the upper half: the
    fallback of a skeleton without a body's shape.  The pose is the travel joint and the joints below it,
    relative to the travel joint (joints above it, Bandai's static ``joint_Root`` at the room's origin, and the
    walk across the room would stretch it along the walking direction)."""
    travel = motion.travel_joint
    parents = list(motion.skeleton.parents) + [site.parent for site in motion.skeleton.end_sites]

    def below_travel(i: int) -> bool:
        while i >= 0:
            if i == travel:
                return True
            i = parents[i]
        return False

    keep = [i for i in range(len(parents)) if below_travel(i)]
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
