"""Editing by swings (paper 003, section 5.3): scale a swing's angle or change its duration.

The edit is applied to the original motion, not to its lossy playback, so all
other detail stays: only joint ``J``'s rotations change.

* **angle scale** ``s``: inside the swing the joint turns ``s`` times as far
  about the swing's axis from where the swing starts,
  ``q'(t) = Rot(axis, (s-1)(θ(t) - θ_start)) ⊗ q(t)``; the extra turn reached
  at the swing's end fades out linearly until the joint's next swing starts
  (over the next swing when it follows at once; kept to the end of the take
  after the last swing).
* **duration scale** ``d``: the swing's frames are stretched in time to
  ``d`` times as many, eating into (or giving back to) the hold after it,
  which is squeezed (or stretched) so that the next swing keeps its timing;
  when the next swing follows at once, that swing is squeezed instead and
  keeps its end.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from .. import _validate
from ..errors import MocycleError
from ..motion import Motion
from ..rotations import axis_angle_quats, quat_conj, quat_multiply, rotvec_quat, twist_angles
from .segment import Segmentation


def _resample(q: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Rotations ``q`` (T, 4) slerped at fractional frame ``times``."""
    T = q.shape[0]
    if T == 1:
        return np.repeat(q, len(times), axis=0)
    return Slerp(np.arange(T, dtype=float), Rotation.from_quat(q))(np.clip(times, 0, T - 1)).as_quat()


def edit_swing(motion: Motion, seg: Segmentation, joint: str | int, swing: int, angle_scale: float = 1.0,
               duration_scale: float = 1.0, *, hand_over: bool = False) -> Motion:
    """The motion with swing ``swing`` (0-based, in time order) of ``joint`` edited.

    ``seg`` is the segmentation of ``motion``.  ``angle_scale`` (0-10) scales
    the angle the swing turns through; ``duration_scale`` (> 0) its length in
    frames, limited by the room up to the joint's next swing (the error says how far it can go).
    ``hand_over``: the caller gives ``motion`` up, and the edited take is made from its arrays
    (:meth:`~mocycle.motion.Motion.hand_over`: ``motion`` is emptied once the edit is checked; a long take is
    edited without a second copy of it).
    """
    if seg.n_frames != motion.n_frames or not seg.skeleton.same_as(motion.skeleton):
        raise MocycleError("the segmentation is not of this motion (frames or skeleton differ)")
    j = motion.skeleton.index(joint) if isinstance(joint, str) else int(joint)
    name = motion.skeleton.names[j]
    swings = seg.swings_of(j)
    if not swings:
        raise MocycleError(f"joint {name!r} has no swings; joints with swings: "
                           f"{', '.join(sorted({s.name for s in seg.swings})) or 'none'}")
    if not 0 <= swing < len(swings):
        raise MocycleError(f"joint {name!r} has {len(swings)} swings (0-{len(swings) - 1}); "
                           f"got option 'swing' = {swing}")
    angle_scale = _validate.real("angle_scale", angle_scale, 0.0, 10.0)
    duration_scale = _validate.real("duration_scale", duration_scale, 0.05, 20.0)
    sw = swings[swing]
    nxt = swings[swing + 1] if swing + 1 < len(swings) else None
    T = motion.n_frames
    q = np.array(motion.rotations[:, j])
    if angle_scale != 1.0:
        axis = np.asarray(sw.axis)
        base = rotvec_quat(np.asarray(sw.base))
        idx = np.arange(sw.start, sw.end + 1)
        theta = twist_angles(quat_multiply(q[idx], quat_conj(base)[None, :]), axis)
        delta = np.zeros(T)
        delta[idx] = (angle_scale - 1.0) * (theta - theta[0])
        d_end = delta[sw.end]
        if nxt is None:
            delta[sw.end + 1:] = d_end
        else:
            fade_end = nxt.start if nxt.start > sw.end + 1 else nxt.end
            k = np.arange(sw.end + 1, fade_end + 1)
            delta[k] = d_end * (1.0 - (k - sw.end) / (fade_end - sw.end))
        q = quat_multiply(axis_angle_quats(axis, delta), q)
    if duration_scale != 1.0:
        # room: up to the next swing's start, or when it follows at once, up to its end (it is squeezed)
        limit = T - 1 if nxt is None else (nxt.start if nxt.start > sw.end else nxt.end)
        length = sw.end - sw.start
        new_end = sw.start + int(round(duration_scale * length))
        if new_end > limit:
            room = (limit - sw.start) / max(length, 1)
            raise MocycleError(f"option 'duration_scale' = {duration_scale:g} makes swing {swing} of {name!r} end at "
                               f"frame {new_end}, past {'its next swing at frame' if nxt else 'the last frame'} "
                               f"{limit}; the largest scale here is {room:.3g}")
        if new_end <= sw.start:
            raise MocycleError(f"option 'duration_scale' = {duration_scale:g} shrinks swing {swing} of {name!r} "
                               f"({length + 1} frames) to nothing; the smallest scale here is {1 / max(length, 1):.3g}")
        # old time for each new frame in start..limit: the swing stretched, the rest squeezed to keep `limit`
        new = np.arange(sw.start, limit + 1, dtype=float)
        old = np.interp(new, [sw.start, new_end, limit], [sw.start, sw.end, limit]) if limit > new_end else \
            np.interp(new, [sw.start, new_end], [sw.start, sw.end])
        q[sw.start:limit + 1] = _resample(q, old)
    if hand_over:
        skeleton, frame_time = motion.skeleton, motion.frame_time
        rotations, static, tracks = motion.hand_over()
        rotations[:, j] = q
        return Motion(skeleton, rotations, static, frame_time, tracks=tracks, copy=False)
    # a new array, handed over (no second copy); the translations are shared
    return motion.replace(rotations=_fix_joint(motion, j, q), copy=False)


def _fix_joint(motion: Motion, j: int, q: np.ndarray) -> np.ndarray:
    rot = np.array(motion.rotations)
    rot[:, j] = q
    return rot
