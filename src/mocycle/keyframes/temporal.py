"""Temporal keyframe reconstruction (thesis section 3.0.1): rebuild every frame from the keyframes by time.

Schemes (``SCHEMES``):

``linear``   linear interpolation of each joint's Euler angles (its own BVH order),
             made continuous over the keyframes (Lim & Thalmann)
``hermite``  cubic Hermite on the same Euler curves, Catmull-Rom tangents from the
             neighbouring keyframes (Xiao et al.; no tangents are stored)
``slerp``    spherical linear interpolation of the quaternions
``rbf``      a 1-D RBF in time with Igarashi's kernel (linear, ``φ(r) = r``, plus a
             linear polynomial) on the rotation matrices, orthonormalised (SVD).  In
             1-D that interpolant is piecewise linear in the matrix entries.

Every function takes the keyframes as arrays (what a ``.mck`` file holds), so
compression and decompression run the same code.  Keyframes come back exactly.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicHermiteSpline, RBFInterpolator, make_interp_spline
from scipy.spatial.transform import Rotation

from .. import _validate, defaults
from ..errors import MocycleError
from ..motion import Skeleton
from ..rotations import continuous_euler, euler_to_quats, matrix_quats, nearest_rotations, slerp

#: the temporal schemes (one home: :mod:`mocycle.defaults`)
SCHEMES = defaults.TEMPORAL_SCHEMES

#: frames interpolated at a time
BLOCK_FRAMES = 8192


def check_keys(key_idx, n_frames: int) -> np.ndarray:
    """Validated keyframe indices: increasing, within ``[0, n_frames)``, first and last frame included."""
    idx = np.asarray(key_idx)
    if idx.ndim != 1 or idx.size < 2 or not np.issubdtype(idx.dtype, np.integer):
        raise MocycleError(f"keyframe indices must be a 1-D integer array of at least 2 frames; got {idx!r}")
    idx = idx.astype(np.int64)
    if idx[0] != 0 or idx[-1] != n_frames - 1 or np.any(np.diff(idx) <= 0):
        raise MocycleError(f"keyframe indices must increase from frame 0 to frame {n_frames - 1}; "
                           f"got {idx[:3].tolist()}...{idx[-3:].tolist()}")
    return idx


def segments(key_idx: np.ndarray, n_frames: int) -> tuple[np.ndarray, np.ndarray]:
    """For every frame: the keyframe segment it lies in ``(T,)`` and its fraction in ``[0, 1]`` ``(T,)``."""
    t = np.arange(n_frames)
    seg = np.clip(np.searchsorted(key_idx, t, side="right") - 1, 0, len(key_idx) - 2)
    a, b = key_idx[seg], key_idx[seg + 1]
    return seg, (t - a) / (b - a)


def interpolate_rotations(skeleton: Skeleton, key_idx, key_quats: np.ndarray, n_frames: int,
                          scheme: str = "slerp") -> np.ndarray:
    """Local rotations ``(T, J, 4)`` of every frame from the keyframes' ``(K, J, 4)``."""
    _validate.choice("scheme", scheme, SCHEMES)
    idx = check_keys(key_idx, n_frames)
    kq = np.asarray(key_quats, dtype=np.float64)
    J = skeleton.n_joints
    if kq.shape != (len(idx), J, 4):
        raise MocycleError(f"keyframe rotations must have shape ({len(idx)}, {J}, 4); got {kq.shape}")
    t = np.arange(n_frames, dtype=np.float64)
    if scheme == "slerp":
        seg, u = segments(idx, n_frames)
        out = np.empty((n_frames, J, 4))
        for f0 in range(0, n_frames, BLOCK_FRAMES):  # frame by frame the same; no (T, J, 4) temporaries
            s, v = seg[f0:f0 + BLOCK_FRAMES], u[f0:f0 + BLOCK_FRAMES]
            out[f0:f0 + BLOCK_FRAMES] = slerp(kq[s], kq[s + 1], np.broadcast_to(v[:, None], (v.size, J)))
    elif scheme == "rbf":
        R = Rotation.from_quat(kq.reshape(-1, 4)).as_matrix().reshape(len(idx), J * 9)
        f = RBFInterpolator(idx[:, None].astype(np.float64), R, kernel="linear", degree=1)
        M = f(t[:, None]).reshape(n_frames, J, 3, 3)
        out = matrix_quats(nearest_rotations(M))
    else:
        out = np.empty((n_frames, J, 4))
        groups: dict[str, list[int]] = {}
        for j in range(J):
            groups.setdefault(skeleton.euler_order(j), []).append(j)
        for order, joints in groups.items():
            if not order:  # no rotation channels: the rotation never changes
                out[:, joints] = kq[0, joints]
                continue
            ang = continuous_euler(kq[:, joints], order).reshape(len(idx), -1)
            curve = interpolate_curves(idx, ang, n_frames, scheme)
            out[:, joints] = euler_to_quats(curve.reshape(n_frames, len(joints), len(order)), order)
    out[idx] = kq
    return out


def interpolate_curves(key_idx, key_values: np.ndarray, n_frames: int, scheme: str = "linear") -> np.ndarray:
    """Real-valued curves ``(T, D)`` from their keyframe values ``(K, D)``: linear, or Hermite (Catmull-Rom)."""
    idx = np.asarray(key_idx)
    y = np.asarray(key_values, dtype=np.float64)
    t = np.arange(n_frames, dtype=np.float64)
    tk = idx.astype(np.float64)
    if scheme == "hermite" and len(idx) > 2:
        dydx = np.gradient(y, tk, axis=0)
        out = CubicHermiteSpline(tk, y, dydx, axis=0)(t)
    else:
        out = make_interp_spline(tk, y, k=1, axis=0)(t)
    out[idx] = y
    return out
