"""Pose distance of the thesis (Costa 2018, eq. 3.2), the chapter-5 error and the stress of eq. 4.1.

Eq. 3.2 compares two poses joint by joint in rotation space:
``D_q(A, B) = Σ_r w_r · arccos((Tr[A_r B_rᵀ] - 1) / 2)``, the geodesic angle
(radians) between the local rotations, weighted by ``w_r`` = the number of bones
on the longest path from joint ``r`` down to an end effector, so that errors
high in the hierarchy (which cascade to every joint below) count more.  With
unit quaternions the angle is ``2·arccos(|q_a·q_b|)``, which is what the code uses.

The chapter-5 error is ``Σ_t D_q(original_t, reconstructed_t) / (T · J)``:
the *error per frame per joint*.
"""

from __future__ import annotations

import numpy as np

from ..errors import MocycleError
from ..motion import Motion, Skeleton
from ..rotations import quat_angles

#: Largest take the all-pairs (T × T) computations accept.
MAX_PAIRWISE_FRAMES = 6000


def joint_weights(skeleton: Skeleton) -> np.ndarray:
    """Eq. 3.2 weights ``(J,)``: bones on the longest path from each joint to an end effector.

    A joint whose children are all End Sites (or that has none) weighs 1; its
    parent 2; the root weighs the depth of the tree.
    """
    J = skeleton.n_joints
    height = np.zeros(J, dtype=np.int64)
    for j in range(J - 1, 0, -1):  # parents come before children
        p = skeleton.parents[j]
        height[p] = max(height[p], height[j] + 1)
    return (height + 1).astype(np.float64)


def pose_distance(qa: np.ndarray, qb: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Eq. 3.2 between poses ``(..., J, 4)`` and ``(..., J, 4)`` (broadcasting) → ``(...)``."""
    return quat_angles(qa, qb) @ np.asarray(weights, dtype=np.float64)


def frame_errors(original: Motion, reconstructed: Motion) -> np.ndarray:
    """Eq. 3.2 distance per frame ``(T,)`` between two motions of the same skeleton and length."""
    _check_pair(original, reconstructed)
    qa, qb = original.rotations, reconstructed.rotations
    angles = np.empty(qa.shape[:2])  # (T, J): the (T, J, 4) products are made a block of frames at a time
    for f0 in range(0, qa.shape[0], ERROR_BLOCK):
        angles[f0:f0 + ERROR_BLOCK] = quat_angles(qa[f0:f0 + ERROR_BLOCK], qb[f0:f0 + ERROR_BLOCK])
    return angles @ joint_weights(original.skeleton)  # as pose_distance: the same numbers


#: frames per block of :func:`frame_errors`
ERROR_BLOCK = 8192


def error_per_frame_per_joint(original: Motion, reconstructed: Motion) -> float:
    """The chapter-5 reconstruction error: ``Σ_t D_q(original_t, reconstructed_t) / (T · J)``."""
    e = frame_errors(original, reconstructed)
    return float(e.sum() / (original.n_frames * original.n_joints))


def _check_pair(a: Motion, b: Motion) -> None:
    if not a.skeleton.same_as(b.skeleton):
        raise MocycleError("the reconstructed motion's skeleton differs from the original's")
    if a.n_frames != b.n_frames:
        raise MocycleError(f"the motions differ in length: {a.n_frames} and {b.n_frames} frames")


def moving_joints(quats: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Indices of joints whose rotation changes over ``quats`` ``(T, J, 4)`` (others add 0 to every distance)."""
    q = np.asarray(quats)
    if q.shape[0] < 2:
        return np.arange(q.shape[1])
    dev = quat_angles(q, q[:1]).max(axis=0)
    return np.flatnonzero(dev > tol)


def check_pairwise_frames(n_frames: int) -> None:
    """Refuse more than :data:`MAX_PAIRWISE_FRAMES` frames for all-pairs pose distances (before any work)."""
    if n_frames > MAX_PAIRWISE_FRAMES:
        raise MocycleError(f"all-pairs pose distances need at most {MAX_PAIRWISE_FRAMES} frames; got "
                           f"{n_frames} (resample or cut the take first)")


def pose_distance_matrix(quats: np.ndarray, weights: np.ndarray, other: np.ndarray | None = None) -> np.ndarray:
    """All-pairs eq. 3.2 distances: ``(T, T)`` for ``quats`` ``(T, J, 4)``, or ``(T, M)`` against ``other``.

    Computed joint by joint as ``2·arccos(|Q_j Q_jᵀ|)`` (one matrix product per joint);
    joints that never move are skipped.  Raises beyond :data:`MAX_PAIRWISE_FRAMES` frames.
    """
    q = np.asarray(quats, dtype=np.float64)
    o = q if other is None else np.asarray(other, dtype=np.float64)
    check_pairwise_frames(max(q.shape[0], o.shape[0]))
    w = np.asarray(weights, dtype=np.float64)
    joints = moving_joints(np.concatenate([q, o]) if other is not None else q)
    D = np.zeros((q.shape[0], o.shape[0]))
    dot = np.empty_like(D)
    for j in joints:
        if w[j] == 0:
            continue
        np.matmul(q[:, j], o[:, j].T, out=dot)  # in place from here on: no (T, M) temporaries per joint
        np.abs(dot, out=dot)
        np.minimum(dot, 1.0, out=dot)
        np.arccos(dot, out=dot)
        dot *= 2.0 * w[j]
        D += dot
    if other is None:
        np.fill_diagonal(D, 0.0)
        D += D.T  # numpy buffers the overlapping operand
        D *= 0.5
    return D


def pose_vectors(quats: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Poses as vectors ``(T, 9J)`` for the projections that need coordinates (PCA, LLE, LAMP).

    The rotation-matrix entries of each joint times ``w_j / √2``: for small angles the
    Euclidean distance between two such vectors is ``√(Σ w_j² θ_j²)``, the L2 cousin of
    the L1 sum of eq. 3.2.
    """
    from scipy.spatial.transform import Rotation

    q = np.asarray(quats, dtype=np.float64)
    T, J = q.shape[:2]
    R = Rotation.from_quat(q.reshape(-1, 4)).as_matrix().reshape(T, J, 9)
    return (R * (np.asarray(weights)[None, :, None] / np.sqrt(2.0))).reshape(T, 9 * J)


def stress(D_high: np.ndarray, points: np.ndarray) -> float:
    """Eq. 4.1: ``Σ_{i<j} (δ_ij - d_ij)² / Σ_{i<j} δ_ij²`` with δ the 2-D and d the pose distances.

    ``D_high``: ``(n, n)`` distances (eq. 3.2); ``points``: ``(n, 2)``.  As in the
    thesis it is not scale-invariant; compare projections of one take at one scale.
    """
    from scipy.spatial.distance import pdist, squareform

    D = np.asarray(D_high, dtype=np.float64)
    Y = np.asarray(points, dtype=np.float64)
    if D.ndim != 2 or D.shape[0] != D.shape[1] or Y.shape != (D.shape[0], 2):
        raise MocycleError(f"stress needs an (n, n) distance matrix and (n, 2) points; got {D.shape}, {Y.shape}")
    d = squareform(D, checks=False)
    delta = pdist(Y)
    den = float(np.sum(delta**2))
    if den == 0:
        raise MocycleError("stress is undefined when every projected point is the same")
    return float(np.sum((delta - d) ** 2) / den)
