"""The degrees of freedom a cycle is regressed in, and back to a Motion.

A pose is split in two blocks (:class:`CycleSpace`):

* the **periodic block** ``P`` ``(T, 9J + 3m)``: every joint's local rotation
  as its 3×3 matrix (9 numbers) and the translations of the ``m`` other joints
  whose translation moves.  Matrix entries are continuous and periodic even
  for a joint that turns a full circle every cycle, so the regression has no
  Euler wrap and no ±π jump (the thesis' open problem, chapter 6); averages
  and fits are projected back onto rotations by SVD (the chordal mean).
  The travel joint (usually the root) contributes only its *tilt*: its
  rotation with the heading about the vertical axis taken out.
* the **drifting block** ``L`` ``(T, 4)``: the travel joint's translation
  (3, in its parent's frame, file units) and its heading about the vertical
  axis (1, radians, unwrapped).  These get the translation model with a
  linear term (KTH thesis eq. 3.27): walking moves on and turning keeps turning.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import MocycleError
from ..motion import Motion, Skeleton
from ..rotations import continuous_quats, nearest_rotations


def body_pose(motion: Motion) -> np.ndarray:
    """Mean world positions ``(J', 3)`` of the travel joint, the joints below it and their End Sites
    (about 50 frames of the take)."""
    step = max(1, motion.n_frames // 50)
    pose = motion[::step].world_positions(end_sites=True).mean(axis=0)
    skel, travel = motion.skeleton, motion.travel_joint
    above = set()
    j = int(skel.parents[travel])
    while j >= 0:
        above.add(j)
        j = int(skel.parents[j])
    keep = [j for j in range(skel.n_joints) if j not in above] + [
        skel.n_joints + i for i, s in enumerate(skel.end_sites) if s.parent not in above]
    return pose[keep]


def vertical_axis(motion: Motion) -> np.ndarray:
    """The world up direction ``(3,)`` of a humanoid take (unit vector along +X, +Y or +Z or their negatives).

    The axis along which the mean pose is tallest; its sign puts most joints in
    the upper half (spine, arms, head and hands outnumber the legs).  Only the
    body is measured: joints above the travel joint (a static ``joint_Root`` on
    the floor while the hips are 1.3 m away, as in the Bandai Namco dashes) are
    left out, so they cannot make a horizontal axis look tallest.
    """
    pose = body_pose(motion)
    extent = np.ptp(pose, axis=0)
    axis = int(np.argmax(extent))
    mid = 0.5 * (pose[:, axis].max() + pose[:, axis].min())
    up = np.zeros(3)
    up[axis] = 1.0 if np.median(pose[:, axis]) >= mid else -1.0
    return up


def axis_rotations(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(T, 3, 3)`` about the unit ``axis`` ``(3,)`` by ``angles`` ``(T,)`` radians."""
    u = np.asarray(axis, dtype=np.float64)
    c, s = np.cos(angles)[:, None, None], np.sin(angles)[:, None, None]
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return c * np.eye(3) + s * K + (1.0 - c) * np.outer(u, u)


@dataclass(frozen=True, eq=False, kw_only=True)
class CycleSpace:
    """How a motion maps to ``(P, L)`` and back (see the module docstring).

    It keeps what decoding needs, not the input motion: ``skeleton``; ``frame_time`` (s);
    ``static_translations`` ``(J, 3)``: every joint's translation in the input's first
    frame (what the joints whose translation does not move keep);
    ``travel``: index of the travel joint; ``up``: the vertical axis in the
    travel joint's parent frame; ``e1``, ``e2``: a horizontal basis there;
    ``forward``: the vector in the travel joint's own frame whose horizontal
    direction defines the heading; ``moving``: the other joints whose translation moves.
    """

    skeleton: Skeleton
    frame_time: float
    static_translations: np.ndarray
    travel: int
    up: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    forward: np.ndarray
    moving: tuple[int, ...]

    @classmethod
    def fit(cls, motion: Motion) -> CycleSpace:
        travel = motion.travel_joint
        up_world = vertical_axis(motion)
        parent = int(motion.skeleton.parents[travel])
        if parent >= 0:
            world_rot, _ = motion[:: max(1, motion.n_frames // 50)].world_transforms()
            mean_parent = nearest_rotations(world_rot[:, parent].mean(axis=0))
            up = mean_parent.T @ up_world
        else:
            up = up_world
        up = up / np.linalg.norm(up)
        least = np.eye(3)[int(np.argmin(np.abs(up)))]
        e1 = least - up * (least @ up)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(up, e1)
        mean_rot = motion.rotation(travel).mean().as_matrix()
        forward = mean_rot.T @ e1
        moved = np.ptp(motion.translations, axis=0).max(axis=1) > 1e-9
        moving = tuple(int(j) for j in np.flatnonzero(moved) if j != travel)
        return cls(skeleton=motion.skeleton, frame_time=motion.frame_time,
                   static_translations=motion.translations[0].copy(), travel=travel, up=up, e1=e1, e2=e2,
                   forward=forward, moving=moving)

    # -- sizes ----------------------------------------------------------
    @property
    def n_joints(self) -> int:
        return self.skeleton.n_joints

    @property
    def n_periodic(self) -> int:
        return 9 * self.n_joints + 3 * len(self.moving)

    @property
    def n_drifting(self) -> int:
        return 4

    def heading(self, rotations: np.ndarray) -> np.ndarray:
        """Unwrapped heading ``(T,)`` radians of the travel joint's rotation matrices ``(T, 3, 3)``."""
        f = rotations @ self.forward
        return np.unwrap(np.arctan2(f @ self.e2, f @ self.e1))

    # -- motion -> (P, L) -----------------------------------------------
    def encode(self, motion: Motion) -> tuple[np.ndarray, np.ndarray]:
        """``P (T, n_periodic)`` and ``L (T, 4)`` of a motion with the space's skeleton."""
        if not motion.skeleton.same_as(self.skeleton):
            raise MocycleError("this motion's skeleton differs from the one the cycle space was made for")
        R = motion.rotation_matrices()  # (T, J, 3, 3)
        psi = self.heading(R[:, self.travel])
        R = R.copy()
        R[:, self.travel] = np.swapaxes(axis_rotations(self.up, psi), 1, 2) @ R[:, self.travel]
        T = motion.n_frames
        parts = [R.reshape(T, -1)]
        if self.moving:
            parts.append(motion.translations[:, list(self.moving)].reshape(T, -1))
        P = np.concatenate(parts, axis=1)
        L = np.concatenate([motion.translations[:, self.travel], psi[:, None]], axis=1)
        return P, L

    # -- (P, L) -> motion -----------------------------------------------
    def decode(self, P: np.ndarray, L: np.ndarray) -> Motion:
        """A Motion on the space's skeleton and frame time from ``P (N, n_periodic)``, ``L (N, 4)``."""
        P, L = np.asarray(P, dtype=np.float64), np.asarray(L, dtype=np.float64)
        N, J = P.shape[0], self.n_joints
        if P.shape != (N, self.n_periodic) or L.shape != (N, self.n_drifting):
            raise MocycleError(f"expected P ({N}, {self.n_periodic}) and L ({N}, 4); got {P.shape}, {L.shape}")
        R = nearest_rotations(P[:, : 9 * J].reshape(N, J, 3, 3))
        R[:, self.travel] = axis_rotations(self.up, L[:, 3]) @ R[:, self.travel]
        quats = continuous_quats(Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat().reshape(N, J, 4))
        trans = np.broadcast_to(self.static_translations, (N, J, 3)).copy()
        if self.moving:
            trans[:, list(self.moving)] = P[:, 9 * J:].reshape(N, len(self.moving), 3)
        trans[:, self.travel] = L[:, :3]
        return Motion(self.skeleton, quats, trans, self.frame_time)
