"""The authored animation's root, from its feet (thesis 002, chapter 6, last step).

A spatial-keyframe animation gives joint rotations only.  The thesis places the root "for each frame
ensuring a fixed position for the foot end effector with lowest Y coordinate at ground level": the
lowest foot point of each frame stays where it was on the frame before (horizontally) and touches the
floor (vertically), so the body walks by pushing off its planted foot.
"""

from __future__ import annotations

import numpy as np

from ..errors import MocycleError
from ..motion import Motion, chain_kinematics_blocks
from .legs import find_feet, up_axis


def foot_points(motion: Motion, foot_joints: str | None = None) -> np.ndarray:
    """Indices into ``world_positions(end_sites=True)`` of the points that may touch the floor: each foot's
    ankle, toe and the End Sites below them; when no feet are found by name, every End Site (or every joint)."""
    skel = motion.skeleton
    try:
        joints = sorted({j for f in find_feet(skel, foot_joints) for j in f.contact_joints})
    except MocycleError:
        if foot_joints:
            raise
        joints = []
    if not joints:
        sites = [skel.n_joints + i for i in range(len(skel.end_sites))]
        return np.asarray(sites or list(range(skel.n_joints)), dtype=np.int64)
    sites = [skel.n_joints + i for i, s in enumerate(skel.end_sites) if s.parent in joints]
    return np.asarray(joints + sites, dtype=np.int64)


def floor_height(motion: Motion, foot_joints: str | None = None, up: np.ndarray | None = None) -> float:
    """The ground of a take along ``up``: the lowest any foot point comes over the take (file units)."""
    up = up_axis(motion) if up is None else np.asarray(up, dtype=np.float64)
    points, up = foot_points(motion, foot_joints), up / np.linalg.norm(up)
    # a block of frames at a time: the forward kinematics of every joint of a long take are not held
    return min(float((motion[f0:f0 + FLOOR_BLOCK].world_positions(end_sites=True)[:, points] @ up).min())
               for f0 in range(0, motion.n_frames, FLOOR_BLOCK))


#: frames per block of :func:`floor_height`
FLOOR_BLOCK = 8192


def plant_lowest_foot(motion: Motion, floor: float | None = None, foot_joints: str | None = None,
                      up: np.ndarray | None = None) -> Motion:
    """``motion`` with its travel joint moved so that, frame by frame, the lowest foot point stays where it
    was on the previous frame (along the floor) and rests at ``floor`` (along ``up``).

    ``floor``: the ground height in file units (default: the lowest foot point of the first frame);
    ``up``: the vertical (default :func:`up_axis`).  Rotations are kept; only the travel joint's translation
    changes (in its parent's frame, so a static root above it is respected).
    """
    up = up_axis(motion) if up is None else np.asarray(up, dtype=np.float64)
    up = up / np.linalg.norm(up)
    pts = foot_points(motion, foot_joints)
    W = motion.world_positions(end_sites=True)[:, pts]  # (T, P, 3)
    heights = W @ up
    low = np.argmin(heights, axis=1)  # (T,) the planted point per frame
    T = motion.n_frames
    if floor is None:
        floor = float(heights[0, low[0]])
    shift = np.zeros((T, 3))
    rows = np.arange(T)
    for t in range(1, T):
        p = low[t]
        shift[t] = shift[t - 1] + W[t - 1, p] - W[t, p]
    shift -= np.outer(shift @ up, up)  # horizontal part: the planted point stays put
    shift += np.outer(floor - heights[rows, low], up)  # vertical: it touches the floor
    travel = motion.travel_joint
    parent = int(motion.skeleton.parents[travel])
    if parent >= 0:  # the world shift in the parent's frame
        for rows, Rw, _ in chain_kinematics_blocks(motion, motion.skeleton.chain_to(parent), 4096):
            shift[rows] = np.einsum("tba,tb->ta", Rw[:, -1], shift[rows])
    return motion.replace(tracks={travel: motion.joint_translations(travel) + shift}, copy=False)
