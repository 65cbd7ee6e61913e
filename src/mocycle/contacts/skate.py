"""How much the feet skate: the foot-skate measure, and leg pops.

``skate`` — for each contact joint (ankle and toe of each foot), its
horizontal speed on each frame step weighted by ``2 - 2**(h/H)`` while its
height ``h`` above its lowest level is under ``H`` (weight 1 on the floor, 0 at
``H``), averaged over all frame steps, then over the contact joints; in file
units per second.  ``H`` is ``SKATE_HEIGHT`` of the body height.  A foot that
glides while it is down counts fully, one that lifts away counts less and less.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal, overload

import numpy as np

from ..motion import Motion
from ..rotations import vector_norms
from .legs import ChainArray, Foot, along, body_height, find_feet, leg_joints, up_axis

SKATE_HEIGHT = 0.015  # H, of the body height: 2.5 cm on a 1.7 m body, the usual absolute H


@overload
def skate(motion: Motion, feet: Sequence[Foot] | str | None = None, *, height: float = SKATE_HEIGHT,
          up: np.ndarray | None = None, per_joint: Literal[False] = False,
          positions: np.ndarray | ChainArray | None = None, body: float | None = None) -> float: ...


@overload
def skate(motion: Motion, feet: Sequence[Foot] | str | None = None, *, height: float = SKATE_HEIGHT,
          up: np.ndarray | None = None, per_joint: Literal[True],
          positions: np.ndarray | ChainArray | None = None, body: float | None = None) -> dict[str, float]: ...


@overload
def skate(motion: Motion, feet: Sequence[Foot] | str | None = None, *, height: float = SKATE_HEIGHT,
          up: np.ndarray | None = None, per_joint: bool = False,
          positions: np.ndarray | ChainArray | None = None, body: float | None = None) -> float | dict[str, float]: ...


def skate(motion: Motion, feet: Sequence[Foot] | str | None = None, *, height: float = SKATE_HEIGHT,
          up: np.ndarray | None = None, per_joint: bool = False,
          positions: np.ndarray | ChainArray | None = None, body: float | None = None) -> float | dict[str, float]:
    """The skate measure of the module docstring (units/s); ``per_joint=True``: a dict joint name -> value.
    ``positions``: ``motion.world_positions(end_sites=True)`` when the caller has it (saves recomputing); with
    ``body``, the body height in file units (e.g. ``Contacts.body`` of the same rig), any world positions
    ``[frames, joints]`` holding the contact joints (a leg chain's, :func:`~mocycle.contacts.legs.chain_transforms`)."""
    if feet is None or isinstance(feet, str):
        feet = find_feet(motion.skeleton, feet)
    up = up_axis(motion) if up is None else np.asarray(up, dtype=np.float64)
    if body is not None:
        H = height * float(body)
    elif isinstance(positions, ChainArray):  # body_height slices whole-body positions
        raise TypeError("skate: a chain's positions (ChainArray) need the body height (body)")
    else:
        H = height * body_height(motion, up, positions)
    joints = [j for f in feet for j in f.contact_joints]
    if motion.n_frames < 2:
        return {motion.skeleton.names[j]: 0.0 for j in joints} if per_joint else 0.0
    P = (motion.world_positions() if positions is None else positions)[:, joints]  # (T, C, 3)
    h = along(P, up)
    h = h - h.min(axis=0)
    step = np.diff(P, axis=0)
    del P  # (T, C, 3) arrays held one or two at a time (memory)
    vu = along(step, up)
    for k in range(3):  # the horizontal step in place: step - (step . up) up, axis by axis
        step[..., k] -= vu * up[k]
    speed = vector_norms(step) / motion.frame_time    # (T-1, C)
    hm = 0.5 * (h[1:] + h[:-1])
    # the exponent clipped at 1 (where the weight is 0 anyway): a foot far above a tiny body height (a still
    # take, a rig whose body height comes out near 0) overflowed 2**(h/H) and printed a numpy warning
    w = np.where(hm < H, 2.0 - 2.0 ** np.minimum(hm / H, 1.0), 0.0) if H > 0 else np.zeros_like(hm)
    values = (w * speed).mean(axis=0)
    if per_joint:
        return {motion.skeleton.names[j]: float(v) for j, v in zip(joints, values, strict=True)}
    return float(values.mean())


def largest_leg_step(motion: Motion, feet: Sequence[Foot] | None = None) -> float:
    """The largest frame-to-frame change of any leg joint's local rotation (radians): a knee pop shows here."""
    feet = find_feet(motion.skeleton) if feet is None else feet
    q = motion.rotations[:, leg_joints(feet)]
    if q.shape[0] < 2:
        return 0.0
    a, b = q[1:], q[:-1]   # the dot products summed component by component: np.sum's order, without its overhead
    dots = np.clip(np.abs(a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]
                          + a[..., 3] * b[..., 3]), 0.0, 1.0)
    return float(2.0 * np.arccos(dots).max())


#: A foot jump (:func:`foot_jumps`): a vertical step of an ankle or toe over JUMP_STEP of the body height in one
#: frame and JUMP_RATIO times its largest step over the two frames on either side (a jump, not a fast swing)
JUMP_STEP, JUMP_RATIO = 0.002, 4.0


def foot_jumps(motion: Motion, feet: Sequence[Foot] | None = None, *, wrap: bool = False) -> list[int]:
    """Frames ``t`` where an ankle or toe jumps vertically from frame ``t`` to ``t + 1`` (:data:`JUMP_STEP`,
    :data:`JUMP_RATIO`): a foot pop that :func:`largest_leg_step` misses when the legs' rotations change
    little (a held toe let go by its heel).  ``wrap``: the motion is a loop played round (the step from its
    last frame to its first counts, heights only, a loop's travel being horizontal)."""
    feet = find_feet(motion.skeleton) if feet is None else feet
    up = up_axis(motion)
    joints = sorted({j for f in feet for j in f.contact_joints})
    W = motion.world_positions(end_sites=True)  # once, for the feet and the body height
    h = along(W[:, joints], up)
    T = h.shape[0]
    if T < 2:
        return []
    ext = np.concatenate([h[-2:], h, h[:3]]) if wrap else np.concatenate([h[:1], h[:1], h, h[-1:], h[-1:]])
    d = np.abs(np.diff(ext, axis=0)) / body_height(motion, up, W)  # d[t + 2]: the step from frame t to t + 1
    n = T if wrap else T - 1
    step = d[2:n + 2]
    near = np.maximum.reduce([d[0:n], d[1:n + 1], d[3:n + 3], d[4:n + 4]])  # two steps on either side
    jumps = (step > JUMP_STEP) & (step > JUMP_RATIO * np.maximum(near, JUMP_STEP / 8))
    return np.flatnonzero(jumps.any(axis=1)).tolist()
