"""Armature + action ⇄ :class:`mocycle.Motion`.

Blender poses a bone in its own rest frame: ``M_j = M_p · (B_p⁻¹ B_j) · L_j`` (armature space), with ``B`` the
bone's rest matrix (``bone.matrix_local``) and ``L`` the basis from the F-curves (location, rotation). mocycle's
joints have world-aligned rest frames (as in BVH), so the local rotation of a joint is the basis rotation seen
from the rest frame, ``r_j = Rb_j · Rl_j · Rb_jᵀ``, and its local translation is ``t_j = s (h_j − h_p + Rb_j
loc_j)`` (``h`` the rest heads, ``s`` the object's scale). The root also carries the object's world matrix, so
the Motion is in Blender's world frame (Z up); rotation modes (quaternion, any Euler order, axis-angle) are
read and written in the bone's own mode, so the rig plays the new action unchanged.
"""

from __future__ import annotations

import bpy
import numpy as np
from scipy.spatial.transform import Rotation

from mocycle import Motion, Skeleton
from mocycle.errors import MocycleError
from mocycle.rotations import continuous_euler, euler_to_quats, quat_conj, quat_multiply

from . import channels

EULER_MODES = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")


def _path(bone_name: str, prop: str) -> str:
    return f'pose.bones["{bpy.utils.escape_identifier(bone_name)}"].{prop}'


def bone_order(arm) -> list:
    """The armature's bones, parents first (depth first in Blender's order); one root bone required."""
    roots = [b for b in arm.data.bones if b.parent is None]
    if len(roots) != 1:
        raise MocycleError(f"armature {arm.name!r} has {len(roots)} root bones; mocycle needs exactly one "
                           "(parent the others to one bone)")
    order, stack = [], [roots[0]]
    while stack:
        bone = stack.pop()
        order.append(bone)
        stack.extend(reversed(bone.children))
    return order


def _object_frame(arm):
    """(scale s, rotation R_O (3, 3), origin o (3,)) of the armature object; uniform scale only."""
    loc, rot, scale = arm.matrix_world.decompose()
    scale = np.array(scale)
    if np.ptp(scale) > 1e-6 * np.abs(scale).max():
        raise MocycleError(f"armature {arm.name!r} has a non-uniform scale {tuple(scale)}; apply it first")
    return float(scale[0]), np.array(rot.to_matrix()), np.array(loc)


def _rest(arm, bones):
    """Rest rotations Rb (J, 3, 3) and heads h (J, 3) in armature space, parents (J,)."""
    index = {b.name: j for j, b in enumerate(bones)}
    Rb = np.array([np.array(b.matrix_local.to_3x3()) for b in bones])
    h = np.array([np.array(b.head_local) for b in bones])
    parents = np.array([-1 if b.parent is None else index[b.parent.name] for b in bones])
    return Rb, h, parents


def _euler_channels(mode: str) -> tuple:
    """BVH-style channel names (intrinsic order) of a Blender Euler mode (extrinsic order)."""
    return tuple(f"{a}rotation" for a in (mode[::-1] if mode in EULER_MODES else "ZYX"))


def skeleton_of(arm, moving: set | None = None) -> Skeleton:
    """The armature's rest skeleton in world units: offsets ``s (h_j − h_p)`` (in the parent's frame, which only
    the root's rotation turns into the world), the root at its world head ``s R_O h + o``."""
    bones = bone_order(arm)
    s, R_O, o = _object_frame(arm)
    _, h, parents = _rest(arm, bones)
    offsets = s * (h - np.where(parents[:, None] >= 0, h[parents], 0.0))
    offsets[0] = s * R_O @ h[0] + o
    pos = ("Xposition", "Yposition", "Zposition")
    chans = []
    for j, b in enumerate(bones):
        rot = _euler_channels(arm.pose.bones[b.name].rotation_mode)
        chans.append((pos + rot) if j == 0 or (moving and b.name in moving) else rot)
    return Skeleton(tuple(b.name for b in bones), parents, offsets, tuple(chans))


def _curves(arm, action) -> dict:
    return {(fc.data_path, fc.array_index): fc for fc in channels.fcurves(arm, action)}


def _read(curves, path, size, frames, default) -> tuple[np.ndarray, bool]:
    """(T, size) values of a property's curves (the pose's value where a channel has no curve), any animated."""
    out = np.empty((len(frames), size))
    animated = False
    for i in range(size):
        fc = curves.get((path, i))
        if fc is None:
            out[:, i] = default[i]
        else:
            out[:, i] = channels.sample(fc, frames)
            animated = True
    return out, animated


def basis_quats(mode: str, values: np.ndarray) -> np.ndarray:
    """Basis rotations (T, 4) scalar-last from a bone's rotation values in Blender's ``mode``."""
    if mode == "QUATERNION":  # (w, x, y, z)
        return values[:, [1, 2, 3, 0]]
    if mode == "AXIS_ANGLE":  # (angle, x, y, z)
        axis = values[:, 1:]
        norm = np.linalg.norm(axis, axis=1, keepdims=True)
        axis = np.where(norm > 1e-12, axis / np.maximum(norm, 1e-12), [0.0, 0.0, 1.0])
        return Rotation.from_rotvec(axis * values[:, :1]).as_quat()
    # Euler 'XYZ' turns about X, then Y, then Z (fixed axes): intrinsic 'ZYX' with angles (z, y, x)
    order = mode[::-1]
    return euler_to_quats(values[:, ["XYZ".index(a) for a in order]], order)


def mode_values(mode: str, q: np.ndarray) -> tuple[str, np.ndarray]:
    """(property, values (T, k)) of basis rotations ``q (T, 4)`` in the bone's ``mode``, continuous in time."""
    if mode == "QUATERNION":
        return "rotation_quaternion", q[:, [3, 0, 1, 2]]
    if mode == "AXIS_ANGLE":
        v = Rotation.from_quat(q).as_rotvec()
        angle = np.linalg.norm(v, axis=1, keepdims=True)
        axis = np.where(angle > 1e-12, v / np.maximum(angle, 1e-12), [0.0, 1.0, 0.0])
        return "rotation_axis_angle", np.hstack([angle, axis])
    order = mode[::-1]
    e = continuous_euler(q[:, None], order)[:, 0]  # angles in intrinsic order
    out = np.empty_like(e)
    for k, a in enumerate(order):
        out[:, "XYZ".index(a)] = e[:, k]
    return "rotation_euler", out


def _pose_default(pb, mode):
    if mode == "QUATERNION":
        return "rotation_quaternion", 4, tuple(pb.rotation_quaternion)
    if mode == "AXIS_ANGLE":
        return "rotation_axis_angle", 4, tuple(pb.rotation_axis_angle)
    return "rotation_euler", 3, tuple(pb.rotation_euler)


def frame_rate(scene) -> float:
    return scene.render.fps / scene.render.fps_base


def action_frames(action) -> tuple[int, int]:
    """(first, last) integer frame of the action's keys (or its manual frame range)."""
    a, b = action.frame_range
    return int(round(a)), int(round(b))


def to_motion(arm, action=None, frames: tuple[int, int] | None = None, fps: float | None = None) -> Motion:
    """The armature ``arm`` playing ``action`` (default its active one) at integer frames ``first..last``
    (inclusive; default the action's range) as a Motion in Blender's world frame and units."""
    action = action or (arm.animation_data and arm.animation_data.action)
    if action is None:
        raise MocycleError(f"armature {arm.name!r} has no action to read")
    first, last = frames or action_frames(action)
    if last < first:
        raise MocycleError(f"empty frame range {first}..{last}")
    t = np.arange(first, last + 1, dtype=np.float64)
    T = len(t)
    bones = bone_order(arm)
    s, R_O, o = _object_frame(arm)
    Rb, h, parents = _rest(arm, bones)
    curves = _curves(arm, action)
    q_basis = np.empty((T, len(bones), 4))
    loc = np.zeros((T, len(bones), 3))
    moving = set()
    for j, b in enumerate(bones):
        pb = arm.pose.bones[b.name]
        prop, size, default = _pose_default(pb, pb.rotation_mode)
        values, _ = _read(curves, _path(b.name, prop), size, t, default)
        q_basis[:, j] = basis_quats(pb.rotation_mode, values)
        if not (b.use_connect and j > 0):  # Blender ignores the location of connected bones
            loc[:, j], animated = _read(curves, _path(b.name, "location"), 3, t, tuple(pb.location))
            if animated:
                moving.add(b.name)
    qb = Rotation.from_matrix(Rb).as_quat()  # (J, 4): quaternion products, no (T, J) matrices
    r = quat_multiply(quat_multiply(qb[None], q_basis), quat_conj(qb)[None])
    r[:, 0] = quat_multiply(Rotation.from_matrix(R_O).as_quat()[None], r[:, 0])
    rest_off = h - np.where(parents[:, None] >= 0, h[parents], 0.0)
    trans = s * (rest_off[None] + np.einsum("jab,tjb->tja", Rb, loc))
    trans[:, 0] = (s * (np.einsum("ab,tb->ta", Rb[0], loc[:, 0]) + h[0])) @ R_O.T + o
    skeleton = skeleton_of(arm, moving)
    return Motion(skeleton, r, trans, 1.0 / (fps or frame_rate(bpy.context.scene)))


def to_basis(arm, motion: Motion) -> tuple[list, np.ndarray, np.ndarray]:
    """The bones (parents first) and, per frame, their basis quaternions (T, J, 4) and locations (T, J, 3)
    that make ``arm`` play ``motion`` (its joints matched to bones by name)."""
    bones = bone_order(arm)
    names = [b.name for b in bones]
    if sorted(names) != sorted(motion.skeleton.names):
        missing = sorted(set(motion.skeleton.names) ^ set(names))
        raise MocycleError(f"the motion's joints are not the bones of {arm.name!r}: {', '.join(missing[:8])}")
    idx = [motion.skeleton.names.index(n) for n in names]
    s, R_O, o = _object_frame(arm)
    Rb, h, parents = _rest(arm, bones)
    r = motion.rotations[:, idx].copy()
    t = motion.translations[:, idx]
    r[:, 0] = quat_multiply(quat_conj(Rotation.from_matrix(R_O).as_quat())[None], r[:, 0])
    qb = Rotation.from_matrix(Rb).as_quat()
    q = quat_multiply(quat_multiply(quat_conj(qb)[None], r), qb[None])
    rest_off = h - np.where(parents[:, None] >= 0, h[parents], 0.0)
    local = t / s - rest_off[None]
    local[:, 0] = ((t[:, 0] - o) @ R_O) / s - h[0]
    loc = np.einsum("jba,tjb->tja", Rb, local)
    return bones, q, loc


def write_action(arm, motion: Motion, name: str, first_frame: int = 1, wrap: Motion | None = None,
                 travel: bool = False):
    """A new action ``name`` for ``arm`` playing ``motion`` from ``first_frame``, keys written in bulk.

    ``wrap``: one more frame (the pose after the last, i.e. the first pose again, moved on by the travel for a
    moving root); with it the action becomes a loop: frame range ``first_frame .. first_frame + T`` (period
    ``T`` frames), ``use_cyclic``, and a Cycles modifier on every curve (``travel``: the root's location
    repeats with offset, so a walk moves on). Returns the action (not yet assigned).
    """
    full = motion if wrap is None else _append(motion, wrap)
    bones, q, loc = to_basis(arm, full)
    T = len(full.rotations)
    frames = first_frame + np.arange(T, dtype=np.float64)
    rest_q = np.zeros(4)
    rest_q[3] = 1.0
    action, add = channels.new_action(arm, name)
    for j, b in enumerate(bones):
        pb = arm.pose.bones[b.name]
        curves = []
        prop, values = mode_values(pb.rotation_mode, q[:, j])
        for i in range(values.shape[1]):
            fc = add(_path(b.name, prop), i, b.name)
            channels.write_keys(fc, frames, values[:, i])
            curves.append(fc)
        if not (b.use_connect and j > 0) and (j == 0 or np.abs(loc[:, j]).max() > 1e-7):
            for i in range(3):
                fc = add(_path(b.name, "location"), i, b.name)
                channels.write_keys(fc, frames, loc[:, j, i])
                if wrap is not None:
                    _cycles(fc, offset=travel and j == 0)
        for fc in curves:
            if wrap is not None:
                _cycles(fc, offset=False)
    if wrap is not None:
        action.use_frame_range = True
        action.frame_start, action.frame_end = first_frame, first_frame + T - 1
        action.use_cyclic = True
    return action


def _cycles(fc, offset: bool) -> None:
    mod = fc.modifiers.new("CYCLES")
    if offset:
        mod.mode_before = mod.mode_after = "REPEAT_OFFSET"


def _append(motion: Motion, extra: Motion) -> Motion:
    return Motion(motion.skeleton, np.concatenate([motion.rotations, extra.rotations[:1]]),
                  np.concatenate([motion.translations, extra.translations[:1]]), motion.frame_time)
