"""Rotation curves that stay continuous in time.

scipy's ``Rotation`` gives each rotation one canonical Euler triple or rotation
vector; along a motion those jump by ±360° or switch to the other Euler
solution.  These helpers pick, frame by frame, the equivalent value closest to
the previous frame, so curves written to BVH or fed to regressions are smooth.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial.transform import Rotation

TWO_PI = 2.0 * np.pi


def continuous_quats(q: np.ndarray) -> np.ndarray:
    """Flip quaternion signs so that consecutive frames have a non-negative dot product.

    ``q``: ``(T, ..., 4)``.  Returns a new array.
    """
    q = np.array(q, dtype=np.float64, copy=True)
    if q.shape[0] < 2:
        return q
    dots = np.sum(q[1:] * q[:-1], axis=-1)
    flips = np.cumsum(dots < 0, axis=0) % 2
    q[1:][flips.astype(bool)] *= -1.0
    return q


def _full_order(order: str) -> str:
    """Extend a 1- or 2-axis intrinsic order to 3 axes (missing axes appended)."""
    order = order.upper()
    return order + "".join(a for a in "XYZ" if a not in order)[: 3 - len(order)]


def _wrap_near(angles: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``angles`` shifted by whole turns to lie within π of ``ref``."""
    return angles - TWO_PI * np.round((angles - ref) / TWO_PI)


def continuous_euler(quats: np.ndarray, order: str) -> np.ndarray:
    """Intrinsic Euler angles (radians) continuous in time.

    Parameters
    ----------
    quats : ``(T, N, 4)`` quaternions ``(x, y, z, w)``: N joints sharing one order.
    order : intrinsic axis order as in BVH channels, e.g. ``"ZYX"``; 1 or 2
        letters for joints with fewer rotation channels.

    Returns
    -------
    ``(T, N, len(order))`` angles: frame 0 is scipy's canonical triple, each later
    frame the equivalent triple (either Euler solution, any whole turns)
    closest to the frame before.
    """
    quats = np.asarray(quats, dtype=np.float64)
    T, N = quats.shape[:2]
    k = len(order)
    if k == 0:
        return np.zeros((T, N, 0))
    full = _full_order(order)
    with warnings.catch_warnings():
        # At gimbal lock scipy warns and sets the third angle to 0; the
        # continuity pass below then picks the split closest to the neighbours.
        warnings.simplefilter("ignore", UserWarning)
        a = Rotation.from_quat(quats.reshape(-1, 4)).as_euler(full).reshape(T, N, 3)
    if k < 3:
        # Only the primary solution keeps the dropped angles at zero.
        return np.unwrap(a[..., :k], axis=0)
    # The other solution of the same rotation.
    b = a.copy()
    b[..., 0] += np.pi
    b[..., 2] += np.pi
    b[..., 1] = -a[..., 1] if full[0] == full[2] else np.pi - a[..., 1]
    out = np.unwrap(a, axis=0)
    # Where the unwrapped primary solution still jumps, choose frame by frame.
    jumps = np.abs(np.diff(out, axis=0)).max(axis=2) > np.pi / 2  # (T-1, N)
    cols = np.flatnonzero(jumps.any(axis=0))
    if cols.size:
        start = int(np.argmax(jumps[:, cols].any(axis=1)))
        aa, bb = a[:, cols], b[:, cols]
        prev = out[start, cols]
        for t in range(start + 1, T):
            ca = _wrap_near(aa[t], prev)
            cb = _wrap_near(bb[t], prev)
            use_b = np.sum((cb - prev) ** 2, axis=1) < np.sum((ca - prev) ** 2, axis=1)
            prev = np.where(use_b[:, None], cb, ca)
            out[t, cols] = prev
    return out


def quat_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a ⊗ b`` of ``(..., 4)`` quaternions ``(x, y, z, w)`` (broadcasts)."""
    ax, ay, az, aw = np.moveaxis(np.asarray(a, dtype=np.float64), -1, 0)
    bx, by, bz, bw = np.moveaxis(np.asarray(b, dtype=np.float64), -1, 0)
    return np.stack([
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ], axis=-1)


def euler_to_quats(angles: np.ndarray, order: str, degrees: bool = False) -> np.ndarray:
    """Quaternions ``(..., 4)`` from intrinsic Euler angles ``(..., k)`` in axis ``order``.

    Same result as ``Rotation.from_euler(order.upper(), ...)`` (checked in the
    tests), composed here as ``q_axis1 ⊗ q_axis2 ⊗ q_axis3`` on component arrays
    because scipy 1.17 takes 75 ms for the 85 000 rotations of a 2752-frame CMU
    take, which alone would miss the 0.1 s read budget (this takes about 5 ms).
    """
    angles = np.asarray(angles, dtype=np.float64)
    shape, k = angles.shape[:-1], angles.shape[-1]
    if k == 0:
        q = np.zeros(shape + (4,))
        q[..., 3] = 1.0
        return q
    half = angles.reshape(-1, k).T * (np.pi / 360.0 if degrees else 0.5)  # (k, n)
    s, c = np.sin(half), np.cos(half)
    order = order.upper()
    comp = [np.zeros(half.shape[1]) for _ in range(3)] + [c[0]]  # x, y, z, w
    comp["XYZ".index(order[0])] = s[0]
    for i, axis in enumerate(order[1:], start=1):
        # q ⊗ (sin·e_axis + cos) = cos·q + sin·(q ⊗ e_axis); q ⊗ e_axis permutes q's entries.
        perm, sign = _AXIS_PRODUCT[axis]
        comp = [c[i] * comp[m] + sign[m] * s[i] * comp[perm[m]] for m in range(4)]
    return np.stack(comp, axis=-1).reshape(shape + (4,))


# q ⊗ e for the pure unit quaternions e = x, y, z: entry permutation and signs.
_AXIS_PRODUCT = {
    "X": ((3, 2, 1, 0), (1.0, 1.0, -1.0, -1.0)),
    "Y": ((2, 3, 0, 1), (-1.0, 1.0, 1.0, -1.0)),
    "Z": ((1, 0, 3, 2), (1.0, -1.0, 1.0, -1.0)),
}


def quat_log(quats: np.ndarray) -> np.ndarray:
    """Rotation vectors (axis × angle, radians) of sign-continuous quaternions.

    Unlike ``Rotation.as_rotvec`` (angle in [0, π]) the angle runs in [0, 2π]
    following the quaternion's sign, so a joint that turns through 180° gives a
    continuous curve.  ``quats``: ``(..., 4)`` → ``(..., 3)``.
    """
    q = np.asarray(quats, dtype=np.float64)
    v = q[..., :3]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., 3:4])
    # angle / sin(angle / 2) -> 2 as s -> 0 (and w > 0).
    scale = np.where(s > 1e-12, angle / np.maximum(s, 1e-300), 2.0 * np.sign(q[..., 3:4] + 1e-300))
    return v * scale


def continuous_rotvec(quats: np.ndarray) -> np.ndarray:
    """Rotation vectors continuous in time, even for joints that turn several full circles.

    ``quats``: ``(T, N, 4)``.  Each frame takes, among the equivalent vectors
    ``u·(θ + 2πk)``, the one closest to the frame before; frame 0 is canonical
    (angle ≤ π).  Returns ``(T, N, 3)`` radians.
    """
    q = continuous_quats(quats)
    q = q * np.where(q[:1, :, 3:4] < 0, -1.0, 1.0)  # frame 0 canonical
    v = quat_log(q)  # continuous while the angle stays in [0, 2π]
    if v.shape[0] < 2:
        return v
    jumps = np.linalg.norm(np.diff(v, axis=0), axis=-1) > np.pi  # (T-1, N)
    cols = np.flatnonzero(jumps.any(axis=0))
    if cols.size:
        start = int(np.argmax(jumps[:, cols].any(axis=1)))
        prev = v[start, cols]
        for t in range(start + 1, v.shape[0]):
            cur = v[t, cols]
            theta = np.linalg.norm(cur, axis=-1, keepdims=True)
            pnorm = np.linalg.norm(prev, axis=-1, keepdims=True)
            u = np.where(theta > 1e-9, cur / np.maximum(theta, 1e-300), prev / np.maximum(pnorm, 1e-300))
            k = np.round((np.sum(prev * u, axis=-1, keepdims=True) - theta) / TWO_PI)
            prev = u * (theta + TWO_PI * k)
            v[t, cols] = prev
    return v


def quat_exp(rotvecs: np.ndarray) -> np.ndarray:
    """Quaternions ``(..., 4)`` from rotation vectors ``(..., 3)`` (any angle)."""
    r = np.asarray(rotvecs, dtype=np.float64)
    shape = r.shape[:-1]
    return Rotation.from_rotvec(r.reshape(-1, 3)).as_quat().reshape(*shape, 4)


def nearest_rotations(M: np.ndarray) -> np.ndarray:
    """Project ``(..., 3, 3)`` matrices onto the nearest rotations (Frobenius; SVD, determinant +1)."""
    U, _, Vt = np.linalg.svd(np.asarray(M, dtype=np.float64))
    d = np.where(np.linalg.det(U @ Vt) < 0, -1.0, 1.0)
    U = U.copy()
    U[..., :, 2] *= d[..., None]
    return U @ Vt


def mean_rotations(quats: np.ndarray) -> np.ndarray:
    """Mean rotation of each joint over time: ``(T, J, 4)`` -> ``(J, 4)`` (scipy's ``Rotation.mean``)."""
    q = np.asarray(quats, dtype=np.float64)
    return np.stack([Rotation.from_quat(q[:, j]).mean().as_quat() for j in range(q.shape[1])])
