"""Armature + action ⇄ Motion: BVH imports read back like ``mocycle.read``; ordinary rigs (rolled bones, every
rotation mode, a rotated, scaled, moved Y-up armature object) round-trip exactly and play what the Motion says."""

import bpy
import numpy as np
import pytest

from conftest import import_bvh, shared_path

#: Blender's BVH importer (forward -Z, up Y, its defaults) maps a file's (x, y, z) to Blender's (x, -z, y)
BVH_TO_BLENDER = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])


def relative_error(a: np.ndarray, b: np.ndarray) -> float:
    """Largest coordinate difference over the size of ``b``'s box."""
    return float(np.abs(a - b).max() / np.ptp(b.reshape(-1, 3), axis=0).max())


def check_bvh(addon, path):
    import mocycle

    arm = import_bvh(path)
    motion = addon.rig.to_motion(arm)
    ref = mocycle.read(path)
    assert motion.n_frames == ref.n_frames
    assert motion.frame_time == pytest.approx(ref.frame_time, rel=1e-6)
    idx = [motion.skeleton.names.index(n) for n in ref.skeleton.names]
    err = relative_error(motion.world_positions()[:, idx], ref.world_positions() @ BVH_TO_BLENDER.T)
    print(f"\n{path.name}: world joint positions, Blender import vs mocycle.read: relative error {err:.2e}")
    assert err <= 1e-4
    return arm, motion


def roundtrip(addon, arm, motion):
    """Motion -> new action -> Motion: rotations (quaternion distance) and translations (relative)."""
    action = addon.rig.write_action(arm, motion, "roundtrip")
    back = addon.rig.to_motion(arm, action, (1, motion.n_frames), fps=motion.fps)
    idx = [back.skeleton.names.index(n) for n in motion.skeleton.names]
    rot = np.abs(1 - np.abs(np.sum(back.rotations[:, idx] * motion.rotations, axis=-1))).max()
    trans = np.abs(back.translations[:, idx] - motion.translations).max() / np.abs(motion.translations).max()
    print(f"round trip: rotation 1-|q.q'| {rot:.1e}, translation relative {trans:.1e}")
    return rot, trans


def test_synthetic_walk_bvh(addon, scene, tmp_path):
    import mocycle
    from mocycle.datasets import synthetic_walk

    path = tmp_path / "walk.bvh"
    mocycle.write(synthetic_walk(n_frames=240, fps=30).motion, path)
    arm, motion = check_bvh(addon, path)
    assert max(roundtrip(addon, arm, motion)) <= 1e-6


def test_z_up_turning_walk_bvh(addon, scene, tmp_path):
    import mocycle
    from mocycle.datasets import synthetic_circle_walk

    path = tmp_path / "circle.bvh"
    mocycle.write(synthetic_circle_walk(n_frames=200, up="z").motion, path)
    arm, motion = check_bvh(addon, path)
    assert max(roundtrip(addon, arm, motion)) <= 1e-6


@pytest.mark.shared_data
@pytest.mark.parametrize("parts", [("cmu", "01_01.bvh"), ("cmu-iclone", "07_01.bvh"),
                                   ("bandai", "dataset-1_walk_normal_001.bvh")])
def test_real_bvh(addon, scene, parts):
    arm, motion = check_bvh(addon, shared_path(*parts))
    assert max(roundtrip(addon, arm, motion)) <= 1e-6


def build_rig(skeleton, matrix, modes, seed=0):
    """An armature with ``skeleton``'s rest pose (heads), random bone rolls and tails, object matrix ``matrix``
    and rotation mode ``modes[j % len(modes)]`` per bone: an ordinary rig, nothing like a BVH import."""
    import mocycle

    rng = np.random.default_rng(seed)
    heads = mocycle.Motion.rest(skeleton).world_positions()[0]
    data = bpy.data.armatures.new("Rig")
    ob = bpy.data.objects.new("Rig", data)
    bpy.context.scene.collection.objects.link(ob)
    bpy.context.view_layer.objects.active = ob
    bpy.ops.object.mode_set(mode="EDIT")
    bones = []
    for j, name in enumerate(skeleton.names):
        eb = data.edit_bones.new(name)
        eb.head = heads[j]
        kids = skeleton.children(j)
        direction = heads[kids[0]] - heads[j] if kids else rng.normal(size=3)
        if np.linalg.norm(direction) < 1e-3:
            direction = rng.normal(size=3)
        eb.tail = heads[j] + direction + rng.normal(scale=0.2 * np.linalg.norm(direction), size=3)
        eb.roll = rng.uniform(-np.pi, np.pi)
        if j:
            eb.parent = bones[skeleton.parents[j]]
        bones.append(eb)
    bpy.ops.object.mode_set(mode="OBJECT")
    ob.matrix_world = matrix
    for j, pb in enumerate(ob.pose.bones):
        pb.rotation_mode = modes[j % len(modes)]
    return ob


def in_world(motion, R, s, o):
    """``motion`` moved by the object matrix (rotation R, uniform scale s, origin o)."""
    from scipy.spatial.transform import Rotation

    rot = motion.rotation_matrices().copy()
    rot[:, 0] = R @ rot[:, 0]
    trans = s * motion.translations.copy()
    trans[:, 0] = s * motion.translations[:, 0] @ R.T + o
    return motion.replace(rotations=Rotation.from_matrix(rot.reshape(-1, 3, 3)).as_quat().reshape(
        motion.rotations.shape), translations=trans)


def test_ordinary_rig_roundtrip_and_playback(addon, scene):
    """A Y-up skeleton in an armature turned Z-up by its object (+90° about X), scaled 0.01 and moved; bones
    rolled; quaternion, axis-angle and several Euler modes. The action written from a Motion reads back exactly
    and Blender's own pose evaluation puts every bone head where the Motion's forward kinematics do."""
    from mathutils import Matrix

    from mocycle.datasets import synthetic_walk

    walk = synthetic_walk(n_frames=90, fps=30).motion
    R = np.array(Matrix.Rotation(np.pi / 2, 3, "X"))
    s, o = 0.01, np.array([1.0, -2.0, 0.5])
    matrix = Matrix.Translation(o) @ Matrix(R).to_4x4() @ Matrix.Scale(s, 4)
    arm = build_rig(walk.skeleton, matrix, ["QUATERNION", "XZY", "AXIS_ANGLE", "ZYX", "YXZ", "XYZ"])
    target = in_world(walk, R, s, o)
    rot, trans = roundtrip(addon, arm, target)
    assert rot <= 1e-6 and trans <= 1e-6
    action = bpy.data.actions["roundtrip"]
    addon.rig.channels.assign(arm, action)
    expected = target.world_positions()
    names = list(target.skeleton.names)
    worst = 0.0
    for f in (1, 17, 45, 90):
        bpy.context.scene.frame_set(f)
        heads = np.array([np.array(arm.matrix_world @ arm.pose.bones[n].head) for n in names])
        worst = max(worst, relative_error(heads, expected[f - 1]))
    print(f"ordinary rig: Blender's pose vs the Motion's forward kinematics, relative error {worst:.1e}")
    assert worst <= 1e-5
    # and reading Blender's action gives back the same world positions
    assert relative_error(addon.rig.to_motion(arm, action).world_positions(), expected) <= 1e-6


def test_euler_modes_match_blender(addon, extension):
    """The Euler conversion agrees with mathutils for every mode (the mode letters are Blender's order)."""
    from mathutils import Euler

    rng = np.random.default_rng(1)
    angles = rng.uniform(-3, 3, size=(20, 3))
    for mode in addon.rig.EULER_MODES:  # mathutils works in float32
        q = addon.rig.basis_quats(mode, angles)
        for a, qq in zip(angles, q, strict=True):
            m = np.array(Euler(a, mode).to_quaternion())  # (w, x, y, z)
            assert min(np.abs(m - qq[[3, 0, 1, 2]]).max(), np.abs(m + qq[[3, 0, 1, 2]]).max()) < 1e-6
        prop, back = addon.rig.mode_values(mode, q)
        assert np.allclose(np.abs(np.sum(addon.rig.basis_quats(mode, back) * q, axis=1)), 1.0)


def test_non_uniform_scale_refused(addon, scene, tmp_path):
    import mocycle
    from mocycle.datasets import synthetic_walk
    from mocycle.errors import MocycleError

    path = tmp_path / "walk.bvh"
    mocycle.write(synthetic_walk(n_frames=30).motion, path)
    arm = import_bvh(path)
    arm.scale = (1.0, 2.0, 1.0)
    bpy.context.view_layer.update()
    with pytest.raises(MocycleError, match="non-uniform scale"):
        addon.rig.to_motion(arm)
