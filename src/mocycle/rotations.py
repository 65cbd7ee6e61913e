"""Every rotation helper of the project, in one place.

Quaternions are ``(x, y, z, w)`` arrays (scipy's order), matrices ``(..., 3, 3)``.

* **Curves continuous in time.**  scipy's ``Rotation`` gives each rotation one canonical
  Euler triple or rotation vector; along a motion those jump by ±360° or switch to the
  other Euler solution.  :func:`continuous_euler`, :func:`continuous_rotvec` and
  :func:`continuous_quats` pick, frame by frame, the equivalent value closest to the
  previous frame, so curves written to BVH or fed to regressions are smooth.
* **Vectorised quaternion algebra** on ``(..., 4)`` arrays: :func:`quat_multiply`
  (about 10× faster than ``Rotation.__mul__`` on 100 000 products), :func:`quat_conj`,
  :func:`quat_log` / :func:`quat_exp`, :func:`euler_to_quats` (:func:`euler_quat_components`,
  :func:`half_angle_sincos`), :func:`axis_angle_quats`,
  :func:`twist_angles`, :func:`quat_angles` (geodesic), :func:`slerp`; single rotations:
  :func:`rotvec_quat`, :func:`quat_rotvec`.
* **Matrices**: :func:`axis_rotations` (about one axis), :func:`nearest_rotations` (Newton polar
  iterations, :func:`fast_nearest_rotation`; :func:`svd_nearest_rotations` the SVD reference),
  :func:`matrix_quats` (of exact rotations, without scipy's orthogonality checks),
  :func:`angle_to_nearest_rotation`.
* **Means**: :func:`mean_rotations` (per joint over time, scipy), :func:`weighted_rotation_mean`
  (weighted chordal mean of many sets at once), :func:`mean_quat` (nearby quaternions).
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial.transform import Rotation

from .errors import MocycleError

TWO_PI = 2.0 * np.pi
_BLOCK = 4096  # frames per block of continuous_rotvec: its (frames, joints) temporaries stay in the cache


def vector_norms(v: np.ndarray, keepdims: bool = False) -> np.ndarray:
    """``np.linalg.norm(v, axis=-1)`` of float64 vectors ``(..., k)``, bit for bit: the squares summed component
    by component in its order.  5-9x faster for quaternions and 3-vectors (numpy's reduction over a short last
    axis pays per vector); ``k > 4`` goes to numpy."""
    v = np.asarray(v, dtype=np.float64)
    k = v.shape[-1]
    if k == 0 or k > 4:
        return np.linalg.norm(v, axis=-1, keepdims=keepdims)
    out = v[..., 0] * v[..., 0]
    for i in range(1, k):
        out = out + v[..., i] * v[..., i] if np.ndim(out) == 0 else np.add(out, v[..., i] * v[..., i], out=out)
    out = np.sqrt(out)
    return out[..., None] if keepdims else out


def continuous_quats(q: np.ndarray, inplace: bool = False) -> np.ndarray:
    """Flip quaternion signs so that consecutive frames have a non-negative dot product.

    ``q``: ``(T, ..., 4)``.  Returns a new array, or ``q`` itself flipped in place with ``inplace`` (a float64
    array the caller owns).
    """
    q = q if inplace else np.array(q, dtype=np.float64, copy=True)
    if q.shape[0] < 2:
        return q
    turns = np.empty((q.shape[0] - 1,) + q.shape[1:-1], dtype=bool)  # a sign change between t and t + 1
    for f0 in range(0, q.shape[0] - 1, _BLOCK):  # blocks of frames: no float (T, ...) temporary
        f1 = min(f0 + _BLOCK, q.shape[0] - 1)
        turns[f0:f1] = np.einsum("t...k,t...k->t...", q[f0 + 1:f1 + 1], q[f0:f1]) < 0
    flips = np.logical_xor.accumulate(turns, axis=0)  # frames after an odd number of sign changes
    if flips.any():
        np.negative(q[1:], out=q[1:], where=flips[..., None])  # in place, no float temporary
    return q


def _full_order(order: str) -> str:
    """Extend a 1- or 2-axis intrinsic order to 3 axes (missing axes appended)."""
    order = order.upper()
    return order + "".join(a for a in "XYZ" if a not in order)[: 3 - len(order)]


def _wrap_near(angles: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``angles`` shifted by whole turns to lie within π of ``ref``."""
    return angles - TWO_PI * np.round((angles - ref) / TWO_PI)


def continuous_euler(quats: np.ndarray, order: str, joints=None) -> np.ndarray:
    """Intrinsic Euler angles (radians) continuous in time.

    Parameters
    ----------
    quats : ``(T, N, 4)`` quaternions ``(x, y, z, w)``: N joints sharing one order.
    order : intrinsic axis order as in BVH channels, e.g. ``"ZYX"``; 1 or 2
        letters for joints with fewer rotation channels.
    joints : the N joints of ``quats`` (``(T, J, 4)``) to convert, read a block of frames at a time (the
        same as ``quats[:, joints]`` without that copy); default all.

    Returns
    -------
    ``(T, N, len(order))`` angles: frame 0 is scipy's canonical triple, each later
    frame the equivalent triple (either Euler solution, any whole turns)
    closest to the frame before.
    """
    quats = np.asarray(quats, dtype=np.float64)
    sel, T, N, k, full = _euler_setup(quats, order, joints)
    if k == 0:
        return np.zeros((T, N, 0))
    a = np.empty((T, N, 3))
    for f0 in range(0, T, _BLOCK):  # in blocks of frames: scipy's temporaries stay small
        a[f0:f0 + _BLOCK] = _primary_euler(quats, slice(f0, f0 + _BLOCK), sel, full)
    if k < 3:
        # Only the primary solution keeps the dropped angles at zero.
        return _unwrap_frames(np.ascontiguousarray(a[..., :k]))
    out = _unwrap_frames(a)
    # Where the unwrapped primary solution still jumps, choose frame by frame.
    jumps = np.empty((max(T - 1, 0), N), dtype=bool)
    for f0 in range(0, T - 1, _BLOCK):
        jumps[f0:f0 + _BLOCK] = _jumps(out[f0:f0 + _BLOCK + 1])
    cols = np.flatnonzero(jumps.any(axis=0))
    if cols.size:
        start = int(np.argmax(jumps[:, cols].any(axis=1)))
        aa = _primary_euler(quats, slice(None), sel[cols] if joints is not None else cols, full)
        _nearest_solutions(aa[start + 1:], out[start, cols], full, out, slice(start + 1, T), cols)
    return out


def continuous_euler_blocks(quats: np.ndarray, order: str, joints=None, block: int | None = None):
    """:func:`continuous_euler` a block of frames at a time: yields ``(rows, angles)``, the frames (a slice) and
    their angles ``(n, N, len(order))``, the same numbers, without a ``(T, N, 3)`` array (a writer's rows).

    Two passes over the quaternions: the first unwraps and finds where each joint's primary solution first
    jumps, the second makes the angles again and chooses between the two solutions from there on."""
    quats = np.asarray(quats, dtype=np.float64)
    sel, T, N, k, full = _euler_setup(quats, order, joints)
    block = _BLOCK if block is None else int(block)
    blocks = [slice(f0, min(T, f0 + block)) for f0 in range(0, T, block)]
    if k == 0:
        yield from ((rows, np.zeros((rows.stop - rows.start, N, 0))) for rows in blocks)
        return
    state = None
    if k < 3:
        for rows in blocks:
            a = np.ascontiguousarray(_primary_euler(quats, rows, sel, full)[..., :k])
            state = _unwrap_step(a, state)
            yield rows, a
        return
    first = np.full(N, T)  # each joint's first frame whose next frame jumps (T: none)
    last = None
    for rows in blocks:
        a = _primary_euler(quats, rows, sel, full)
        state = _unwrap_step(a, state)
        jumps = _jumps(a if last is None else np.concatenate([last[None], a]))  # (pairs, N)
        new = jumps.any(axis=0) & (first == T)
        if new.any():
            first[new] = (rows.start - (last is not None)) + np.argmax(jumps[:, new], axis=0)
        last = a[-1].copy()
    cols = np.flatnonzero(first < T)
    start = int(first[cols].min()) if cols.size else T
    state, prev = None, None
    for rows in blocks:
        a = _primary_euler(quats, rows, sel, full)
        raw = a[:, cols].copy()  # the primary solutions of the joints that jump, before unwrapping
        state = _unwrap_step(a, state)
        if rows.start <= start < rows.stop:
            prev = a[start - rows.start, cols]
        if prev is not None:
            t0 = max(start + 1, rows.start) - rows.start
            prev = _nearest_solutions(raw[t0:], prev, full, a, slice(t0, None), cols)
        yield rows, a


def _euler_setup(quats: np.ndarray, order: str, joints):
    """``(sel, T, N, k, full order)`` of :func:`continuous_euler`'s arguments."""
    if joints is None:
        return slice(None), quats.shape[0], quats.shape[1], len(order), _full_order(order)
    sel = np.asarray(joints, dtype=np.intp).reshape(-1)
    return sel, quats.shape[0], sel.size, len(order), _full_order(order)


def _primary_euler(quats: np.ndarray, rows: slice, sel, full: str) -> np.ndarray:
    """scipy's Euler angles ``(n, N, 3)`` (intrinsic ``full`` order) of ``quats[rows, sel]``.  At gimbal lock
    scipy warns and sets the third angle to 0; the continuity pass then picks the split closest to the
    neighbours."""
    block = quats[rows, sel]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return Rotation.from_quat(block.reshape(-1, 4)).as_euler(full).reshape(block.shape[:2] + (3,))


def _jumps(angles: np.ndarray) -> np.ndarray:
    """``(n - 1, N)``: where a joint's unwrapped angles ``(n, N, 3)`` jump by more than a quarter turn."""
    return np.abs(np.diff(angles, axis=0)).max(axis=2) > np.pi / 2


def _nearest_solutions(aa: np.ndarray, prev: np.ndarray, full: str, out: np.ndarray, rows: slice,
                       cols: np.ndarray) -> np.ndarray:
    """Frame by frame, the one of the two Euler solutions of the primary angles ``aa`` ``(n, C, 3)`` (any whole
    turns) closest to the frame before, starting from ``prev`` ``(C, 3)``, written to ``out[rows, cols]``;
    returns the last frame's."""
    bb = aa.copy()  # the other solution of the same rotation
    bb[..., 0] += np.pi
    bb[..., 2] += np.pi
    bb[..., 1] = -aa[..., 1] if full[0] == full[2] else np.pi - aa[..., 1]
    out_rows = range(*rows.indices(out.shape[0]))
    for t, row in enumerate(out_rows):
        ca = _wrap_near(aa[t], prev)
        cb = _wrap_near(bb[t], prev)
        use_b = np.sum((cb - prev) ** 2, axis=1) < np.sum((ca - prev) ** 2, axis=1)
        prev = np.where(use_b[:, None], cb, ca)
        out[row, cols] = prev
    return prev


#: Frames per block of the long per-frame passes (their temporaries stay a few MB).
_BLOCK = 8192


def _unwrap_step(p: np.ndarray, state):
    """Unwrap the frames ``p`` ``(n, ...)`` in place, going on from ``state`` (``None`` at the take's first
    frame, which stays as it is); returns the state for the next frames.  Blocks of any length give
    ``np.unwrap``'s numbers: the corrections are summed in frame order."""
    if state is None:
        last, carry, body = p[0].copy(), np.zeros(p.shape[1:]), p[1:]
    else:
        (last, carry), body = state, p
    if body.shape[0]:
        raw_last = body[-1].copy()
        dd = np.diff(np.concatenate([last[None], body]), axis=0)
        ddmod = np.mod(dd + np.pi, TWO_PI) - np.pi
        ddmod[(ddmod == -np.pi) & (dd > 0)] = np.pi
        correct = ddmod - dd
        correct[np.abs(dd) < np.pi] = 0.0
        correct[0] += carry  # the running sum goes on from the block before, in the same order
        np.cumsum(correct, axis=0, out=correct)
        carry = correct[-1].copy()
        body += correct
        last = raw_last
    return last, carry


def _unwrap_frames(p: np.ndarray) -> np.ndarray:
    """``np.unwrap(p, axis=0)`` computed in place, block by block of frames (the same numbers)."""
    state = None
    for f0 in range(0, p.shape[0], _BLOCK):
        state = _unwrap_step(p[f0:f0 + _BLOCK], state)
    return p


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
    # (k, n) angles, each axis contiguous in memory
    flat = np.ascontiguousarray(angles.reshape(-1, k).T)
    comp = euler_quat_components(flat, order, degrees)
    out = np.empty((flat.shape[1], 4))
    for m in range(4):
        out[:, m] = 0.0 if comp[m] is None else comp[m]
    return out.reshape(shape + (4,))


def euler_quat_components(angles: np.ndarray, order: str, degrees: bool = False) -> list[np.ndarray | None]:
    """The x, y, z, w arrays of :func:`euler_to_quats` from Euler angles ``(k, ...)`` (degrees or radians), axis
    by axis along the first dimension; ``None`` for a component that is exactly zero (one-axis orders)."""
    s, c = half_angle_sincos(angles, degrees)
    order = order.upper()
    comp: list[np.ndarray | None] = [None, None, None, c[0]]  # x, y, z, w; None: exactly zero
    comp["XYZ".index(order[0])] = s[0]
    for i, axis in enumerate(order[1:angles.shape[0]], start=1):
        # q ⊗ (sin·e_axis + cos) = cos·q + sin·(q ⊗ e_axis); q ⊗ e_axis permutes q's entries (zeros skipped).
        perm, sign = _AXIS_PRODUCT[axis]
        new = []
        for m in range(4):
            a, b = comp[m], comp[perm[m]]
            cos_a = None if a is None else c[i] * a
            sin_b = None if b is None else s[i] * b
            if sin_b is None:
                new.append(cos_a)
            elif cos_a is None:
                new.append(sin_b if sign[m] > 0 else np.negative(sin_b, out=sin_b))
            else:
                new.append(np.add(cos_a, sin_b, out=cos_a) if sign[m] > 0 else np.subtract(cos_a, sin_b, out=cos_a))
        comp = new
    return comp


#: table steps of :func:`half_angle_sincos` per turn of the half angle: 360/4096 = 0.087890625 degrees, a binary
#: fraction, so an angle's remainder after the nearest step is exact
SINCOS_STEPS = 4096
_STEP_DEGREES = 360.0 / SINCOS_STEPS


def _sincos_table(n: int) -> tuple[np.ndarray, np.ndarray]:
    """sin and cos of ``i * 360 / n`` degrees, ``i < n``: ``np.sin``/``np.cos`` of the angle folded into the
    first octant (an argument of at most pi/4, rounded once), the other octants by symmetry, so that
    multiples of 45 degrees are exact to the bit and the table is symmetric (``sin(-a) = -sin(a)`` bit for bit)."""
    q = n // 8
    i = np.arange(n)
    within, quadrant = i % (2 * q), i // (2 * q)
    folded = np.minimum(within, 2 * q - within) * (2.0 * np.pi / n)
    sf, cf = np.sin(folded), np.cos(folded)
    sf[within == q] = cf[within == q] = np.sqrt(0.5)  # 45 degrees: both correctly rounded, and equal
    low = within <= q
    s, c = np.where(low, sf, cf), np.where(low, cf, sf)
    # turn by quadrant × 90°: (sin, cos) -> (cos, -sin)
    sin = np.select([quadrant == 0, quadrant == 1, quadrant == 2], [s, c, -s], -c)
    cos = np.select([quadrant == 0, quadrant == 1, quadrant == 2], [c, -s, -c], s)
    return sin, cos


_SIN_TABLE, _COS_TABLE = _sincos_table(SINCOS_STEPS)


def half_angle_sincos(angles: np.ndarray, degrees: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """``sin(a / 2)`` and ``cos(a / 2)`` of angles ``a`` (any shape).

    Radians: ``np.sin``/``np.cos`` of the halves.  Degrees (what BVH and FBX files hold) take a faster and more
    exact way, 2.5x faster than ``np.sin`` + ``np.cos`` on this project's machines and within 2 ulp of the
    exact values where converting to radians first is off by up to thousands of ulp near multiples of 360
    degrees (``tests/test_rotations.py``; ``scipy.special.sindg``/``cosdg`` are 3x slower than numpy):
    the half angle in degrees is split exactly into the nearest step ``k`` of :data:`SINCOS_STEPS` per turn
    and a remainder ``r`` of at most 0.044 degrees; then ``sin(k + r) = S_k cos r + C_k sin r`` and
    ``cos(k + r) = C_k cos r - S_k sin r`` from a table of ``S_k``, ``C_k`` and short Taylor series of ``sin r``
    and ``cos r - 1`` (their first omitted terms are below 1e-21).  Pieces of :data:`SINCOS_PIECE` angles at a
    time: the dozen temporaries stay in the cache and under malloc's 128 kB threshold for ``mmap`` (above it,
    every temporary of a 300-frame take was a fresh mapping to fault in, and the conversion was slower than
    ``np.sin``).
    """
    a = np.asarray(angles, dtype=np.float64)
    if not degrees:
        half = a * 0.5
        return np.sin(half), np.cos(half)
    flat = a.reshape(-1)
    sin, cos = np.empty(flat.shape), np.empty(flat.shape)
    for i in range(0, flat.size, SINCOS_PIECE):
        j = i + SINCOS_PIECE
        _half_sincos_degrees(flat[i:j], sin[i:j], cos[i:j])
    return sin.reshape(a.shape), cos.reshape(a.shape)


#: angles converted at a time by :func:`half_angle_sincos` (64 kB per temporary)
SINCOS_PIECE = 8192


def _half_sincos_degrees(a: np.ndarray, sin: np.ndarray, cos: np.ndarray) -> None:
    """:func:`half_angle_sincos` of degrees ``a`` (1-D) into ``sin`` and ``cos``."""
    steps = np.rint(a * (0.5 / _STEP_DEGREES))
    r = a * 0.5
    r -= steps * _STEP_DEGREES  # exact: both are multiples of the half angle's last bit, and |r| < 0.05
    r *= np.pi / 180.0
    with np.errstate(invalid="ignore"):  # NaN or inf: any index, the result is NaN all the same
        k = steps.astype(np.intp)
    k &= SINCOS_STEPS - 1
    sin_k, cos_k = _SIN_TABLE.take(k), _COS_TABLE.take(k)
    r2 = r * r
    sin_r = r2 * (1.0 / 120.0)  # sin r = r - r^3/6 + r^5/120
    sin_r -= 1.0 / 6.0
    sin_r *= r2
    sin_r *= r
    sin_r += r
    cos_r1 = np.multiply(r2, 1.0 / 24.0, out=steps)  # cos r - 1 = -r^2/2 + r^4/24
    cos_r1 -= 0.5
    cos_r1 *= r2
    np.multiply(sin_k, cos_r1, out=sin)
    np.multiply(cos_k, sin_r, out=r2)
    sin += r2
    sin += sin_k
    np.multiply(cos_k, cos_r1, out=cos)
    np.multiply(sin_k, sin_r, out=r2)
    cos -= r2
    cos += cos_k


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
    s = vector_norms(v, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., 3:4])
    # angle / sin(angle / 2) -> 2 as s -> 0 (and w > 0).
    scale = np.where(s > 1e-12, angle / np.maximum(s, 1e-300), 2.0 * np.sign(q[..., 3:4] + 1e-300))
    return v * scale


def continuous_rotvec(quats: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Rotation vectors continuous in time, even for joints that turn several full circles.

    ``quats``: ``(T, N, 4)``.  Each frame takes, among the equivalent vectors
    ``u·(θ + 2πk)``, the one closest to the frame before; frame 0 is canonical
    (angle ≤ π).  Returns ``(T, N, 3)`` radians (written into ``out`` when given, e.g. a view of the
    caller's feature matrix).
    """
    q = np.asarray(quats, dtype=np.float64)
    T, N = q.shape[:2]
    v = np.empty((T, N, 3)) if out is None else out
    if v.shape != (T, N, 3):
        raise ValueError(f"out must have shape {(T, N, 3)}; got {v.shape}")
    turned = np.zeros(N, dtype=bool)  # joints whose angle passes π/2 somewhere
    sign = np.where(q[0, :, 3] < 0, -1.0, 1.0)  # frame 0 canonical
    # quat_log of the sign-continuous quaternions (continuous_quats) without making them: one sign and one
    # scale per (frame, joint), by blocks of frames that stay in the cache
    for a in range(0, T, _BLOCK):
        b = min(a + _BLOCK, T)
        lo = max(a - 1, 0)
        # the four components of frames lo..b-1 as contiguous (frames, N) arrays: every step below is a
        # plain elementwise pass (numpy's reductions over a 4-element last axis pay per quaternion)
        x, y, z, w = (np.ascontiguousarray(q[lo:b, :, k]) for k in range(4))
        dots = x[1:] * x[:-1]  # frame t against t - 1, t in (lo, b), summed in einsum's order
        dots += y[1:] * y[:-1]
        dots += z[1:] * z[:-1]
        dots += w[1:] * w[:-1]
        flip = dots < 0
        if a == 0:
            flip = np.concatenate([np.zeros((1, N), dtype=bool), flip])
        else:  # drop frame lo = a - 1
            x, y, z, w = x[1:], y[1:], z[1:], w[1:]
        signs = sign * (1.0 - 2.0 * (np.cumsum(flip, axis=0) % 2)) if flip.any() else np.broadcast_to(sign, (b - a, N))
        sign = signs[-1].copy()
        s = x * x
        s += y * y
        s += z * z
        np.sqrt(s, out=s)
        w = signs * w
        angle = 2.0 * np.arctan2(s, w)  # continuous while it stays in [0, 2π]
        turned |= (angle > 0.5 * np.pi).any(axis=0)
        scale = np.where(s > 1e-12, angle / np.maximum(s, 1e-300), 2.0 * np.sign(w + 1e-300))  # as quat_log
        scale *= signs
        np.multiply(x, scale, out=v[a:b, :, 0])
        np.multiply(y, scale, out=v[a:b, :, 1])
        np.multiply(z, scale, out=v[a:b, :, 2])
    if T < 2:
        return v
    # a jump (> π between frames) needs an angle above π/2 at one of its two frames: only those joints are checked
    cols = np.flatnonzero(turned)
    if cols.size:
        jumps = vector_norms(np.diff(v[:, cols], axis=0)) > np.pi  # (T-1, n)
        hit = jumps.any(axis=0)
        cols, jumps = cols[hit], jumps[:, hit]
    if cols.size:
        start = int(np.argmax(jumps.any(axis=1)))
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


def svd_nearest_rotations(M: np.ndarray) -> np.ndarray:
    """Project ``(..., 3, 3)`` matrices onto the nearest rotations (Frobenius) by SVD, determinant +1.

    The reference method; :func:`nearest_rotations` gives the same matrices faster and falls back on this
    one only where its iterations do not apply."""
    U, _, Vt = np.linalg.svd(np.asarray(M, dtype=np.float64))
    d = np.where(np.linalg.det(U @ Vt) < 0, -1.0, 1.0)
    U = U.copy()
    U[..., :, 2] *= d[..., None]
    return U @ Vt


def nearest_rotations(M: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Project ``(..., 3, 3)`` matrices onto the nearest rotations (Frobenius, determinant +1); ``out``: a
    C-contiguous float64 array of ``M``'s shape to write them into (returned), e.g. rows of the caller's.

    Matrices that are already nearly rotations (``|XᵀX - I|`` under :data:`NEAR_ORTHOGONAL` entry by entry,
    ``det > 0``: a harmonic fit of rotation matrices, a blend of nearby rotations) take Newton–Schulz
    steps ``X ← X (3I - XᵀX) / 2`` until ``XᵀX`` is the identity to 1e-8, then one more
    (:func:`_newton_schulz`; the error squares at each step: 0.1, 7e-3, 4e-5, 1e-9, rounding); the others take the
    scaled Newton polar iterations of :func:`fast_nearest_rotation`, run until they converge, and
    matrices with ``det <= 0`` or that do not converge go to the SVD (:func:`svd_nearest_rotations`).
    The same matrices as the SVD within about 1e-14, several times faster on many small matrices.
    Blocks of :data:`_NEAREST_BLOCK` matrices at a time (each matrix's result does not depend on the
    others): their temporaries stay in the cache.
    """
    M = np.asarray(M, dtype=np.float64)
    flat = M.reshape(-1, 9)
    if out is None:
        out = np.empty(M.shape)
    elif out.shape != M.shape or out.dtype != np.float64 or not out.flags.c_contiguous:
        raise ValueError(f"out must be a C-contiguous float64 array of shape {M.shape}")
    written = out.reshape(-1, 9)  # a view: out is contiguous
    for b in range(0, flat.shape[0], _NEAREST_BLOCK):
        block = flat[b:b + _NEAREST_BLOCK]
        rows = written[b:b + _NEAREST_BLOCK]
        near = _newton_schulz(block, rows)
        if not near.all():
            rows[~near] = fast_nearest_rotation(block[~near].reshape(-1, 3, 3)).reshape(-1, 9)
    return out


#: matrices per block of :func:`nearest_rotations` (1.3-1.5x faster than one block of 50 000 near-rotations)
_NEAREST_BLOCK = 16384
#: largest ``|XᵀX - I|`` entry of a matrix that :func:`nearest_rotations` orthogonalises by Newton–Schulz steps
NEAR_ORTHOGONAL = 0.1


def _gram(x: list) -> tuple:
    """The six entries ``s00, s11, s22, s01, s02, s12`` of ``XᵀX`` from the nine entries of ``X`` (row-major)."""
    a, b, c, d, e, f, g, h, i = x
    return (a * a + d * d + g * g, b * b + e * e + h * h, c * c + f * f + i * i,
            a * b + d * e + g * h, a * c + d * f + g * i, b * c + e * f + h * i)


def _orthogonality_error(s: tuple) -> np.ndarray:
    """The largest ``|XᵀX - I|`` entry from :func:`_gram`'s six entries."""
    err = np.abs(s[0] - 1.0)
    for v in (np.abs(s[1] - 1.0), np.abs(s[2] - 1.0), np.abs(s[3]), np.abs(s[4]), np.abs(s[5])):
        np.maximum(err, v, out=err)
    return err


def _newton_schulz(flat: np.ndarray, out: np.ndarray, max_steps: int = 8) -> np.ndarray:
    """The orthogonal polar factors of the rows of ``flat`` ``(n, 9)`` that are near rotations, written into
    those rows of ``out`` ``(n, 9)`` (the others are left as they are).

    Returns ``near`` ``(n,)`` (``|XᵀX - I| < NEAR_ORTHOGONAL`` and ``det X > 0``), the rows written: Newton–Schulz
    steps ``X ← X (3I - XᵀX) / 2`` (quadratic convergence to the polar factor when
    ``|XᵀX - I| < 1``; the error after a step is about ``0.75 err²``) until every row is orthonormal to 1e-8,
    then one more step, which leaves rounding."""
    x = list(np.ascontiguousarray(flat.T))  # nine contiguous arrays: the entries, row-major
    s = _gram(x)
    a, b, c, d, e, f, g, h, i = x
    det = a * (e * i - f * h) + b * (f * g - d * i) + c * (d * h - e * g)
    near = (_orthogonality_error(s) < NEAR_ORTHOGONAL) & (det > 0)
    if not near.all():
        x = [v[near] for v in x]
        s = tuple(v[near] for v in s)
    settled = False
    for _ in range(max_steps):
        if not x[0].size:
            break
        settled = bool(_orthogonality_error(s).max() < 1e-8)
        t00, t11, t22 = 1.5 - 0.5 * s[0], 1.5 - 0.5 * s[1], 1.5 - 0.5 * s[2]  # (3I - S) / 2
        t01, t02, t12 = -0.5 * s[3], -0.5 * s[4], -0.5 * s[5]
        a, b, c, d, e, f, g, h, i = x
        x = [a * t00 + b * t01 + c * t02, a * t01 + b * t11 + c * t12, a * t02 + b * t12 + c * t22,
             d * t00 + e * t01 + f * t02, d * t01 + e * t11 + f * t12, d * t02 + e * t12 + f * t22,
             g * t00 + h * t01 + i * t02, g * t01 + h * t11 + i * t12, g * t02 + h * t12 + i * t22]
        if settled:
            break
        s = _gram(x)
    if not settled and x[0].size:  # not converged in max_steps (cannot happen from 0.1): the other method
        near[np.flatnonzero(near)] = False
    elif near.all():
        np.stack(x, axis=1, out=out)
    else:
        out[near] = np.stack(x, axis=1)
    return near


def matrix_quats(R: np.ndarray) -> np.ndarray:
    """Quaternions ``(..., 4)`` of rotation matrices ``(..., 3, 3)`` (Markley's method, as scipy's
    ``Rotation.from_matrix`` on orthogonal input: the largest of ``x, y, z, w`` comes out positive).

    ``R`` must already be a rotation (e.g. from :func:`nearest_rotations`); no orthogonalisation here.
    """
    R = np.asarray(R, dtype=np.float64)
    shape = R.shape[:-2]
    a, b, c, d, e, f, g, h, i = np.moveaxis(R.reshape(-1, 9), -1, 0)
    tr = a + e + i
    choice = np.argmax(np.stack([a, e, i, tr]), axis=0)
    q = np.empty((a.size, 4))
    for k, comps in enumerate((
        (1 - tr + 2 * a, d + b, g + c, h - f),
        (d + b, 1 - tr + 2 * e, h + f, c - g),
        (g + c, h + f, 1 - tr + 2 * i, d - b),
        (h - f, c - g, d - b, 1 + tr),
    )):
        rows = choice == k
        if rows.any():
            q[rows] = np.stack([v[rows] for v in comps], axis=-1)
    q /= vector_norms(q, keepdims=True)
    return q.reshape(*shape, 4)


def mean_rotations(quats: np.ndarray) -> np.ndarray:
    """Mean rotation of each joint over time: ``(T, J, 4)`` -> ``(J, 4)``.

    scipy's ``Rotation.mean`` (the top eigenvector of ``mean(q qᵀ)``, Markley et al. 2007) for all joints
    in one batched ``eigh``."""
    q = np.asarray(quats, dtype=np.float64)
    if q.shape[0] == 0:
        raise MocycleError("the mean of no rotations is undefined")
    q = q / vector_norms(q, keepdims=True)
    K = np.einsum("tji,tjk->jik", q, q) / q.shape[0]
    return np.linalg.eigh(K)[1][..., -1]


def weighted_rotation_mean(quats: np.ndarray, weights) -> np.ndarray:
    """The weighted chordal L2 mean ``(..., 4)`` of rotations ``quats`` ``(K, ..., 4)`` with ``weights (K,)``:
    the rotation nearest (Frobenius) to ``Σ w_k R_k`` — the mean ``Rotation.mean(weights=)`` computes, for
    many sets at once.  ``weights``: ``>= 0``, not all zero (normalised here)."""
    q = np.asarray(quats, dtype=np.float64)
    try:
        w = np.asarray(weights, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise MocycleError(f"weights must be numbers, one per rotation set; got {weights!r}") from None
    if w.size != q.shape[0] or not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
        raise MocycleError(f"expected {q.shape[0]} finite weights >= 0, not all zero; got {w.tolist()}")
    w = w / w.sum()
    R = Rotation.from_quat(q.reshape(-1, 4)).as_matrix().reshape(*q.shape[:-1], 3, 3)
    M = np.tensordot(w, R, axes=1)
    return matrix_quats(nearest_rotations(M))


def axis_rotations(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(T, 3, 3)`` about the unit ``axis`` ``(3,)`` by ``angles`` ``(T,)`` radians."""
    u = np.asarray(axis, dtype=np.float64)
    c, s = np.cos(angles)[:, None, None], np.sin(angles)[:, None, None]
    K = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return c * np.eye(3) + s * K + (1.0 - c) * np.outer(u, u)


def axis_angle_quats(axis: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Quaternions ``(n, 4)`` of rotations by ``theta`` (n,) radians about one unit ``axis``."""
    half = 0.5 * np.asarray(theta, dtype=np.float64)
    return np.concatenate([np.sin(half)[:, None] * np.asarray(axis)[None, :], np.cos(half)[:, None]], axis=1)


def rotvec_quat(v: np.ndarray) -> np.ndarray:
    """Quaternion ``(4,)`` of a rotation vector ``(3,)`` (radians)."""
    v = np.asarray(v, dtype=np.float64)
    angle = float(np.linalg.norm(v))
    if angle < 1e-12:
        return np.array([0.5 * v[0], 0.5 * v[1], 0.5 * v[2], 1.0]) / np.sqrt(1 + 0.25 * angle**2)
    return np.concatenate([np.sin(angle / 2) * v / angle, [np.cos(angle / 2)]])


def quat_rotvec(q: np.ndarray) -> np.ndarray:
    """Rotation vector ``(3,)`` (angle ≤ π) of a quaternion ``(4,)``."""
    q = np.asarray(q, dtype=np.float64)
    return quat_log(q if q[3] >= 0 else -q)


def quat_conj(q: np.ndarray) -> np.ndarray:
    """Conjugate (the inverse of a unit quaternion) of ``(..., 4)`` quaternions."""
    return np.asarray(q) * np.array([-1.0, -1.0, -1.0, 1.0])


def mean_quat(q: np.ndarray) -> np.ndarray:
    """Mean ``(4,)`` of nearby quaternions ``(n, 4)``: the sign-aligned normalised sum (chordal mean)."""
    q = np.asarray(q, dtype=np.float64)
    q = q * np.where(q @ q[0] < 0, -1.0, 1.0)[:, None]
    s = q.sum(axis=0)
    return s / np.linalg.norm(s)


def twist_angles(q: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Angle (radians, unwrapped in time) of the twist of each quaternion ``(n, 4)`` about ``axis``."""
    return np.unwrap(2.0 * np.arctan2(q[:, :3] @ axis, q[:, 3]))


def quat_angles(qa: np.ndarray, qb: np.ndarray) -> np.ndarray:
    """Geodesic angle (radians, 0..π) between quaternions ``(..., 4)`` → ``(...)``: ``2·arccos|qa·qb|``."""
    dot = np.abs(np.sum(np.asarray(qa) * np.asarray(qb), axis=-1))
    return 2.0 * np.arccos(np.minimum(dot, 1.0))


def slerp(qa: np.ndarray, qb: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Spherical linear interpolation of quaternions ``(..., 4)`` at fractions ``u`` ``(...)`` (shortest arc)."""
    qa = np.asarray(qa, dtype=np.float64)
    qb = np.asarray(qb, dtype=np.float64)
    u = np.asarray(u, dtype=np.float64)[..., None]
    dot = np.sum(qa * qb, axis=-1, keepdims=True)
    qb = np.where(dot < 0, -qb, qb)
    dot = np.abs(dot)
    theta = np.arccos(np.minimum(dot, 1.0))
    s = np.sin(theta)
    small = s < 1e-9
    safe = np.where(small, 1.0, s)
    wa = np.where(small, 1.0 - u, np.sin((1.0 - u) * theta) / safe)
    wb = np.where(small, u, np.sin(u * theta) / safe)
    q = wa * qa + wb * qb
    return q / vector_norms(q, keepdims=True)


def fast_nearest_rotation(M: np.ndarray, max_iterations: int = 30, tol: float = 1e-10) -> np.ndarray:
    """Same result as :func:`svd_nearest_rotations`, by scaled Newton polar iterations ``X ← (γX + X⁻ᵀ/γ) / 2``.

    Written on the nine matrix entries as separate arrays (closed-form 3×3 inverse), several times
    faster than batched SVD.  Iterates until no entry moves by more than ``tol``, then once more
    (the convergence is quadratic, so the last step leaves about ``tol²``); matrices with
    ``det <= 0``, or not orthonormal to 1e-12 after ``max_iterations``, go to the SVD.
    """
    M = np.asarray(M, dtype=np.float64)
    shape = M.shape
    flat = M.reshape(-1, 9)
    if flat.shape[0] == 0:
        return M.copy()
    scale = np.sqrt(np.einsum("ij,ij->i", flat, flat) / 3.0)
    x = flat / np.where(scale > 0, scale, 1.0)[:, None]
    a, b, c, d, e, f, g, h, i = x.T
    bad = ~(a * (e * i - f * h) + b * (f * g - d * i) + c * (d * h - e * g) > 1e-6)
    if bad.any():
        x[bad] = np.eye(3).ravel()  # these go to the SVD below
    X = x
    active = np.arange(X.shape[0])  # the matrices still moving; the others are left out of later steps
    xs = list(X.T)  # 9 arrays (n_active,)
    last = np.zeros(X.shape[0], dtype=bool)  # one more step after settling
    for _ in range(max_iterations):
        a, b, c, d, e, f, g, h, i = xs
        # cofactor matrix (= det · X⁻ᵀ)
        C = [e * i - f * h, f * g - d * i, d * h - e * g,
             c * h - b * i, a * i - c * g, b * g - a * h,
             b * f - c * e, c * d - a * f, a * e - b * d]
        det = np.maximum(a * C[0] + b * C[1] + c * C[2], 1e-300)
        gam = det ** (-1.0 / 3.0)
        k = 1.0 / (gam * det)
        new = [0.5 * (gam * xv + k * cv) for xv, cv in zip(xs, C, strict=True)]
        move = np.abs(new[0] - xs[0])
        for nv, xv in zip(new[1:], xs[1:], strict=True):
            np.maximum(move, np.abs(nv - xv), out=move)
        done = last[active]
        last[active] = move < tol
        if done.all():
            X[active] = np.stack(new, axis=1)
            break
        if done.any():
            X[active[done]] = np.stack([v[done] for v in new], axis=1)
            keep = ~done
            active = active[keep]
            new = [v[keep] for v in new]
        xs = new
    else:
        X[active] = np.stack(xs, axis=1)
    cols = [X[:, 0::3], X[:, 1::3], X[:, 2::3]]  # XᵀX - I, entry by entry: 1e-12 or to the SVD
    err = np.zeros(X.shape[0])
    for m in range(3):
        for n in range(m, 3):
            np.maximum(err, np.abs(np.einsum("ij,ij->i", cols[m], cols[n]) - (m == n)), out=err)
    bad |= ~(err < 1e-12)
    X = X.reshape(-1, 3, 3)
    if np.any(bad):
        X[bad] = svd_nearest_rotations(flat[bad].reshape(-1, 3, 3))
    return X.reshape(shape)


def angle_to_nearest_rotation(N: np.ndarray, iterations: int = 4) -> np.ndarray:
    """Rotation angle (radians) of the pure rotation nearest to each ``(..., 3, 3)`` matrix ``N``.

    With ``N = R_targetᵀ·M`` this is the geodesic error of the orthonormalised ``M``
    without forming it: the nearest rotation's quaternion is the top eigenvector of
    Bar-Itzhack's symmetric 4×4 matrix of ``N``, found by a few power iterations from
    the column Shepperd's method would pick (exact for a pure rotation; within about
    1e-4 rad of the SVD answer for the near-rotations RBF interpolation gives).
    """
    N = np.asarray(N, dtype=np.float64)
    shape = N.shape[:-2]
    return nearest_rotation_angle_entries(list(N.reshape(-1, 9).T), iterations).reshape(shape)


def nearest_rotation_angle_entries(n: list, iterations: int = 4) -> np.ndarray:
    """:func:`angle_to_nearest_rotation` on the nine entries of ``N`` given as separate arrays (row-major)."""
    norm2 = n[0] * n[0]
    for v in n[1:]:
        norm2 = norm2 + v * v
    s = np.sqrt(3.0) / np.maximum(np.sqrt(norm2), 1e-300)
    a, b, c, d, e, f, g, h, i = (v * s for v in n)
    third = 1.0 / 3.0
    # Bar-Itzhack's matrix (quaternion order x, y, z, w), shifted by 1/3: a rotation's eigenvalues
    # 1, -1/3, -1/3, -1/3 become 4/3, 0, 0, 0
    k00, k11, k22, k33 = (a - e - i + 1) * third, (e - a - i + 1) * third, (i - a - e + 1) * third, \
        (a + e + i + 1) * third
    k01, k02, k03 = (b + d) * third, (c + g) * third, (h - f) * third
    k12, k13, k23 = (f + h) * third, (c - g) * third, (d - b) * third
    # start from the column of the largest diagonal entry (Shepperd): exact for a pure rotation
    pick = np.argmax(np.stack([k00, k11, k22, k33]), axis=0)
    p0, p1, p2 = pick == 0, pick == 1, pick == 2
    x = np.where(p0, k00, np.where(p1, k01, np.where(p2, k02, k03)))
    y = np.where(p0, k01, np.where(p1, k11, np.where(p2, k12, k13)))
    z = np.where(p0, k02, np.where(p1, k12, np.where(p2, k22, k23)))
    w = np.where(p0, k03, np.where(p1, k13, np.where(p2, k23, k33)))
    for _ in range(iterations):
        x, y, z, w = (k00 * x + k01 * y + k02 * z + k03 * w, k01 * x + k11 * y + k12 * z + k13 * w,
                      k02 * x + k12 * y + k22 * z + k23 * w, k03 * x + k13 * y + k23 * z + k33 * w)
        norm = np.sqrt(x * x + y * y + z * z + w * w)
        norm = np.where(norm > 0, norm, 1.0)
        x, y, z, w = x / norm, y / norm, z / norm, w / norm
    vec = np.sqrt(x * x + y * y + z * z)
    return 2.0 * np.arctan2(vec, np.abs(w))
