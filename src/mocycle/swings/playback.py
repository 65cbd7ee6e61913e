"""Playback of a :class:`Segmentation` (paper 003, section 4.3) and its error figures.

Inside a swing the joint turns about the swing's axis, ``q(t) = Rot(axis, θ(t)) ⊗ base``;
across the frames between swings the rotation is interpolated (slerp) from the
end of one swing through the holds' mean rotations (placed at their middle
frames) to the start of the next (the paper's section 4.4).
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate
from ..errors import MocycleError
from ..io.bvh import _channel_layout, channel_blocks
from ..motion import Motion
from ..rotations import quat_angles, quat_exp, quat_multiply, slerp
from .segment import Segmentation, swing_angles

PROFILES = ("hermite", "linear")


def _swing_table(swings: list, frame_time: float, profile: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every swing's rotations at each of its frames ``start..end``, all swings at once: which swing
    ``(m,)``, frame ``(m,)`` and quaternion ``(m, 4)``, in the order of ``swings`` (then of frames)."""
    if not swings:
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int), np.zeros((0, 4))
    start = np.array([s.start for s in swings])
    count = np.array([s.end for s in swings]) - start + 1
    owner = np.repeat(np.arange(len(swings)), count)
    frames = start[owner] + np.arange(owner.size) - np.repeat(np.cumsum(count) - count, count)

    def each(name: str) -> np.ndarray:
        return np.array([getattr(s, name) for s in swings], dtype=np.float64)[owner]

    theta = swing_angles(frames, each("start"), each("end"), each("start_angle"), each("end_angle"),
                         each("start_speed"), each("end_speed"), frame_time, profile)
    axis = np.array([s.axis for s in swings], dtype=np.float64)[owner]
    half = 0.5 * theta
    turn = np.concatenate([np.sin(half)[:, None] * axis, np.cos(half)[:, None]], axis=1)
    base = quat_exp(np.array([s.base for s in swings], dtype=np.float64))[owner]
    return owner, frames, quat_multiply(turn, base)


def _play_joint(seg: Segmentation, j: int, swings: list, table, holds: list | None = None) -> np.ndarray:
    """Joint ``j``'s rotations ``(T, 4)`` from its ``swings`` (in time order) and their :func:`_swing_table`;
    ``holds``: its holds (default ``seg.holds_of(j)``)."""
    T = seg.n_frames
    owner, frames, q = table
    holds = seg.holds_of(j) if holds is None else holds
    index = np.arange(len(swings))
    first = np.searchsorted(owner, index)
    last = np.searchsorted(owner, index, side="right") - 1
    # keys in the order start, end of each swing, then the holds' middles; at equal times the first one counts
    times = np.concatenate([np.array([(s.start, s.end) for s in swings], dtype=np.float64).reshape(-1),
                            np.array([0.5 * (h.start + h.end) for h in holds], dtype=np.float64)])
    hq = quat_exp(np.array([h.mean for h in holds], dtype=np.float64).reshape(-1, 3))
    values = np.concatenate([np.stack([q[first], q[last]], axis=1).reshape(-1, 4), hq])
    times, pick = np.unique(times, return_index=True)  # sorted, first occurrence of each time
    kq = values[pick]
    if times.size == 0:
        out = np.zeros((T, 4))
        out[:, 3] = 1.0
    elif times.size == 1:
        out = np.repeat(kq[:1], T, axis=0)
    else:
        kq /= np.linalg.norm(kq, axis=1, keepdims=True)
        at = np.clip(np.arange(T, dtype=float), times[0], times[-1])
        seg_of = np.clip(np.searchsorted(times, at, side="right") - 1, 0, len(times) - 2)
        u = (at - times[seg_of]) / (times[seg_of + 1] - times[seg_of])
        out = slerp(kq[seg_of], kq[seg_of + 1], u)  # shortest arc between keys, as scipy's Slerp
    out[frames] = q  # inside a swing its own curve; where swings overlap the later one wins
    return out


def joint_quats(seg: Segmentation, j: int, profile: str = "hermite") -> np.ndarray:
    """Played-back local rotations ``(T, 4)`` of joint ``j``."""
    swings = seg.swings_of(j)
    return _play_joint(seg, j, swings, _swing_table(swings, seg.frame_time, profile))


def playback(seg: Segmentation, profile: str = "hermite") -> Motion:
    """Rebuild the motion from swings, holds and the translation keys.

    ``profile``: ``"hermite"`` (angle follows the cubic with the stored end
    speeds) or ``"linear"`` (the paper's start-to-end angle interpolation).

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk
    >>> from mocycle.swings import segment
    >>> walk = synthetic_walk(n_frames=300, fps=60).motion
    >>> again = playback(segment(walk, threshold=0.4))
    >>> again.n_frames, playback_errors(walk, again)["geodesic_error_deg"] < 3.0
    (300, True)
    """
    _validate.choice("profile", profile, PROFILES)
    T, J = seg.n_frames, seg.skeleton.n_joints
    swings = sorted(seg.swings, key=lambda s: (s.joint, s.start))  # as swings_of, all joints at once
    bounds = np.searchsorted(np.array([s.joint for s in swings], dtype=int), np.arange(J + 1))
    holds = sorted(seg.holds, key=lambda h: (h.joint, h.start))  # as holds_of, all joints at once
    hold_bounds = np.searchsorted(np.array([h.joint for h in holds], dtype=int), np.arange(J + 1))
    quats = np.empty((T, J, 4))
    for j in range(J):  # one joint's swing table at a time: its rows are a joint's frames, not the take's
        mine = swings[bounds[j]:bounds[j + 1]]
        quats[:, j] = _play_joint(seg, j, mine, _swing_table(mine, seg.frame_time, profile),
                                  holds[hold_bounds[j]:hold_bounds[j + 1]])
    static = np.array(seg.skeleton.offsets, dtype=np.float64)
    tracks = {}
    frames = np.arange(T)
    for j, (kf, kv) in seg.translation_keys.items():
        if len(kf) == 1:
            static[j] = kv[0]
        else:
            tracks[j] = np.stack([np.interp(frames, kf, kv[:, a]) for a in range(3)], axis=1)
    return Motion(seg.skeleton, quats, static, seg.frame_time, tracks=tracks, copy=False)  # arrays made here


def _euler_near(quats: np.ndarray, order: str, ref: np.ndarray) -> np.ndarray:
    """Euler angles (radians) of ``quats`` (T, N, 4) in ``order``, per frame the triple nearest ``ref``."""
    from ..rotations import _full_order

    T, N = quats.shape[:2]
    k = len(order)
    full = _full_order(order)
    with warnings.catch_warnings():  # at gimbal lock scipy warns; the nearest-triple choice below copes
        warnings.simplefilter("ignore", UserWarning)
        a = Rotation.from_quat(quats.reshape(-1, 4)).as_euler(full).reshape(T, N, 3)[..., :k]
    cands = [a]
    if k == 3:
        b = a.copy()
        b[..., 0] += np.pi
        b[..., 2] += np.pi
        b[..., 1] = -a[..., 1] if full[0] == full[2] else np.pi - a[..., 1]
        cands.append(b)
    best, best_d = None, None
    for c in cands:
        c = c - 2 * np.pi * np.round((c - ref) / (2 * np.pi))
        d = np.sum((c - ref) ** 2, axis=-1, keepdims=True)
        if best is None or best_d is None:  # the first candidate (the two are set together)
            best, best_d = c, d
        else:
            best = np.where(d < best_d, c, best)
            best_d = np.minimum(d, best_d)
    assert best is not None  # cands holds a
    return best


def euler_differences(original: Motion, other: Motion) -> np.ndarray:
    """Per frame and rotation channel, ``other``'s Euler angle minus ``original``'s, degrees ``(T, R)``.

    Both motions are written in the original file's channels and orders;
    ``other``'s triples are the equivalent ones nearest the original's, so the
    difference measures the pose, not the choice of Euler solution.
    """
    blocks = list(_euler_difference_blocks(original, other))
    return np.concatenate(blocks, axis=0) if blocks[0].shape[1] else np.zeros((original.n_frames, 0))


#: frames per block of :func:`_euler_difference_blocks`
DIFFERENCE_BLOCK = 8192


def _euler_difference_blocks(original: Motion, other: Motion):
    """:func:`euler_differences` a block of :data:`DIFFERENCE_BLOCK` frames at a time (the same numbers): a
    caller that reduces them holds no ``(T, R)`` array, nor the original's channels."""
    if not original.skeleton.same_as(other.skeleton) or original.n_frames != other.n_frames:
        raise MocycleError(f"motions differ in skeleton or length ({original!r} vs {other!r})")
    layout = [(j, rot_cols, order) for j, (rot_cols, order, _, _) in enumerate(_channel_layout(original.skeleton))
              if rot_cols]
    for rows, ref in channel_blocks(original, DIFFERENCE_BLOCK):
        n = rows.stop - rows.start
        diffs = []
        for j, rot_cols, order in layout:
            r = np.radians(ref[:, rot_cols])[:, None, :]
            mine = _euler_near(other.rotations[rows, j:j + 1], order, r)
            diffs.append(np.degrees(mine - r).reshape(n, -1))
        yield np.concatenate(diffs, axis=1) if diffs else np.zeros((n, 0))


def segmentation_error(original: Motion, other: Motion) -> float:
    """The paper's Segmentation Error: per-frame Euclidean distance of the Euler DOF vectors (degrees),
    averaged over frames."""
    d = euler_differences(original, other)
    return float(np.linalg.norm(d, axis=1).mean()) if d.size else 0.0


def geodesic_errors(original: Motion, other: Motion) -> np.ndarray:
    """Mean geodesic angle (degrees) between the local rotations of each joint, ``(J,)``."""
    if not original.skeleton.same_as(other.skeleton) or original.n_frames != other.n_frames:
        raise MocycleError(f"motions differ in skeleton or length ({original!r} vs {other!r})")
    # a block of frames at a time (no (T, J, 4) product), the rows added in frame order as mean(axis=0) adds them
    total = np.zeros((1, original.n_joints))
    for f0 in range(0, original.n_frames, DIFFERENCE_BLOCK):
        rows = slice(f0, f0 + DIFFERENCE_BLOCK)
        angles = np.degrees(quat_angles(original.rotations[rows], other.rotations[rows]))
        total = np.add.reduce(np.concatenate([total, angles]) if f0 else angles, axis=0, keepdims=True)
    return total[0] / original.n_frames


def playback_errors(original: Motion, other: Motion) -> dict:
    """Segmentation Error (deg), the paper's per-angle figure (error / rotation DOFs), the RMS per angle,
    the mean geodesic error over joints and per joint (deg)."""
    norms, squares, n_dof = [], 0.0, 0
    for d in _euler_difference_blocks(original, other):  # block by block: no (T, R) arrays
        n_dof = d.shape[1]
        norms.append(np.linalg.norm(d, axis=1))
        squares += float(np.sum(d ** 2))
    seg_err = float(np.concatenate(norms).mean()) if n_dof else 0.0
    geo = geodesic_errors(original, other)
    return dict(
        segmentation_error=seg_err,
        per_angle_error_deg=seg_err / n_dof if n_dof else 0.0,
        rms_angle_error_deg=float(np.sqrt(squares / (original.n_frames * n_dof))) if n_dof else 0.0,
        rotation_dofs=n_dof,
        geodesic_error_deg=float(geo.mean()),
        geodesic_error_by_joint_deg={n: float(g) for n, g in zip(original.skeleton.names, geo, strict=True)},
    )
