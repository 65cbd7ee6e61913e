"""Capture sessions: takes of one performer joined end to end, with the truth of each stretch.

A session is what a capture day gives: one long take in which the actor walks, turns, runs, waves and
gestures one thing after another.  :func:`join_takes` builds one from separate takes of one skeleton: each
take is turned about the vertical and shifted so that its travel joint (the hips) starts where the previous
take was, facing where it faced, and the two overlap in a short cross-fade (slerp of the rotations, a line
between the translations).  Each take's frames, split in the middle of the cross-fades, are one
**stretch** of the session, labelled with what the take does: the truth a segmentation is judged against.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import MocycleError
from ..features import HeadingFrame
from ..motion import Motion
from ..rotations import axis_angle_quats, axis_rotations, quat_multiply, slerp


@dataclass(frozen=True)
class Session:
    """A joined take and its truth: ``stretches`` is ``(label, start, stop)`` per joined take, in frame order,
    stop exclusive; two neighbours meet in the middle of their cross-fade."""

    motion: Motion
    stretches: list[tuple[str, int, int]]

    def label_at(self, frame: int) -> str:
        """The label of the stretch holding ``frame``."""
        for label, start, stop in self.stretches:
            if start <= frame < stop:
                return label
        raise IndexError(f"frame {frame} is outside the session's {self.motion.n_frames} frames")


def _aligned(take: Motion, frame: HeadingFrame, heading: float, position: np.ndarray) -> Motion:
    """``take`` turned about the vertical so its travel joint faces ``heading`` (rad, in ``frame``'s basis) at
    its first frame, and shifted horizontally so that joint starts at ``position`` (in its parent's frame); the
    travel joint's height stays the take's own."""
    j, up = frame.travel, frame.up
    _, psi = frame.tilt(take)
    turn = float(heading - psi[0])
    q = take.rotations.copy()
    q[:, j] = quat_multiply(axis_angle_quats(up, np.full(take.n_frames, turn)), q[:, j])
    R = axis_rotations(up, np.array([turn]))[0]
    t = take.joint_translations(j)
    start = position - up * (position @ up) + up * (t[0] @ up)
    return take.replace(rotations=q, tracks={j: (t - t[0]) @ R.T + start})


def join_takes(takes: Sequence[Motion], labels: Sequence[str], crossfade: int = 10) -> Session:
    """One session from ``takes`` (one skeleton, one frame time) labelled ``labels``: each take after the first
    turned and shifted to start where the previous one is at the first frame of their overlap (its travel
    joint's position and heading), the two blended over ``crossfade`` frames.

    Examples
    --------
    >>> from mocycle.datasets import synthetic_walk, synthetic_wave
    >>> s = join_takes([synthetic_walk(n_frames=240).motion, synthetic_wave(n_frames=240).motion], ["walk", "wave"])
    >>> s.motion.n_frames, s.stretches
    (470, [('walk', 0, 235), ('wave', 235, 470)])
    """
    if len(takes) != len(labels) or not takes:
        raise MocycleError("join_takes needs one label per take and at least one take")
    first = takes[0]
    if any(not t.skeleton.same_as(first.skeleton) for t in takes) or \
            any(not np.isclose(t.frame_time, first.frame_time) for t in takes):
        raise MocycleError("the takes of a session must share one skeleton and one frame time")
    c = int(crossfade)
    if c < 0 or any(t.n_frames <= 2 * c for t in takes):
        raise MocycleError(f"every take of a session needs more than {2 * c} frames (twice the cross-fade)")
    frame = HeadingFrame.fit(first)
    j = frame.travel
    aligned = [first]
    for take in takes[1:]:
        prev = aligned[-1]
        at = prev.n_frames - c
        _, psi = frame.tilt(prev)
        aligned.append(_aligned(take, frame, float(psi[at]), prev.joint_translations(j)[at]))
    moving = sorted({jj for m in aligned for jj in m.tracked_joints})
    w = (np.arange(1, c + 1) / (c + 1.0))[:, None]
    rotations, tracks = [aligned[0].rotations], {jj: [aligned[0].joint_translations(jj)] for jj in moving}
    stretches, start, offset = [], 0, 0
    for k, m in enumerate(aligned[1:], start=1):
        offset += aligned[k - 1].n_frames - c       # the joined frame where take k starts
        prev_q = rotations[-1]
        rotations[-1] = prev_q[:-c] if c else prev_q
        rotations.append(np.concatenate([slerp(prev_q[prev_q.shape[0] - c:], m.rotations[:c], w),
                                         m.rotations[c:]]))
        for jj in moving:
            prev_t = tracks[jj][-1]
            tracks[jj][-1] = prev_t[:-c] if c else prev_t
            t = m.joint_translations(jj)
            tracks[jj].append(np.concatenate([(1 - w) * prev_t[prev_t.shape[0] - c:] + w * t[:c], t[c:]]))
        stretches.append((labels[k - 1], start, offset + c // 2))
        start = offset + c // 2
    q = np.concatenate(rotations)
    stretches.append((labels[-1], start, q.shape[0]))
    joined = Motion(first.skeleton, q, first.translations_at(0), first.frame_time,
                    tracks={jj: np.concatenate(v) for jj, v in tracks.items()}, copy=False)
    return Session(joined, stretches)
