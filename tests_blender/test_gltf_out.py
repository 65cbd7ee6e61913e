"""glTF out, checked where people open it: a ``.glb`` that mocycle writes (``mocycle.write``, and a loop written
as ``mocycle loop IN -o x.glb`` writes it), imported with Blender's own glTF importer (``import_scene.gltf``),
plays the motion mocycle computes: every joint's world position, read from the imported armature's pose bones
frame by frame, is within 1e-4 of the body's height of ``Motion.world_positions()`` taken to glTF's metres and
+Y up by the writer's own frame (``docs/formats.md``: scale and up axis) and then to Blender's Z up.

The GLB is written with the mocycle of the installed extension; pygltflib (the ``gltf`` extra, not bundled in
the extension) comes from the test environment (``make test-blender`` installs it with bpy).
"""

import bpy
import numpy as np
import pytest

#: Blender's glTF importer turns glTF's +Y up, +Z forward into Blender's +Z up, -Y forward: (x, y, z) -> (x, -z, y)
GLTF_TO_BLENDER = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])
TOLERANCE = 1e-4  # of the body's height


@pytest.fixture(autouse=True)
def _pygltflib(extension):
    try:
        import pygltflib  # noqa: F401
    except ModuleNotFoundError:
        pytest.fail("pygltflib is missing from this bpy environment (make test-blender installs it)")


def import_glb(path, fps: float):
    """``bpy.ops.import_scene.gltf`` at the take's frame rate (else the importer resamples); the new armature."""
    sc = bpy.context.scene
    sc.render.fps, sc.render.fps_base = round(fps), round(fps) / fps
    before = set(bpy.data.objects)
    assert bpy.ops.import_scene.gltf(filepath=str(path)) == {"FINISHED"}
    (arm,) = [ob for ob in bpy.data.objects if ob not in before and ob.type == "ARMATURE"]
    return arm


def played(arm, names: list[str]) -> tuple[np.ndarray, tuple[float, float]]:
    """World positions ``(F, J, 3)`` of the bones ``names`` at every frame of the armature's action, as Blender
    evaluates them (bone heads: the glTF importer puts each bone's head at its node), and the action's range."""
    action = arm.animation_data.action
    assert action is not None, "the glTF importer assigned no action"
    start, end = action.frame_range
    assert start == int(start) and end == int(end)
    bones = [arm.pose.bones[n] for n in names]
    out = []
    for frame in range(int(start), int(end) + 1):
        bpy.context.scene.frame_set(frame)
        out.append([np.array(arm.matrix_world @ pb.head) for pb in bones])
    return np.array(out), (start, end)


def expected(motion, path) -> np.ndarray:
    """mocycle's world positions in Blender's axes after the writer's frame (checked against the file's extras)."""
    from pygltflib import GLTF2
    from scipy.spatial.transform import Rotation

    from mocycle.io.gltf import gltf_frame

    frame = gltf_frame(motion)  # the writer's default: scale "auto", the detected vertical onto +Y
    units = GLTF2().load(str(path)).scenes[0].extras["mocycle"]["units"]
    assert units["metres_per_unit"] == pytest.approx(frame.scale, rel=1e-12)
    assert np.allclose(Rotation.from_quat(units["source_to_gltf_rotation_xyzw"]).as_matrix(), frame.rotation,
                       atol=1e-12)
    return frame.point(motion.world_positions()) @ GLTF_TO_BLENDER.T


def compare(motion, path) -> tuple[np.ndarray, float, tuple[float, float]]:
    arm = import_glb(path, motion.fps)
    names = list(motion.skeleton.names)
    got, frame_range = played(arm, names)
    want = expected(motion, path)
    assert got.shape == want.shape, f"Blender plays {len(got)} frames, the motion has {len(want)}"
    height = float(np.ptp(want[0], axis=0).max())
    err = float(np.abs(got - want).max() / height)
    print(f"\n{path.name} in bpy {bpy.app.version_string}: {len(names)} joints x {len(got)} frames, largest joint "
          f"position difference {err:.1e} of the body's height ({height:.2f} m)")
    assert err <= TOLERANCE
    return got, height, frame_range


def test_walk_glb_plays_the_motion(scene, tmp_path):
    """A Y-up take whose root travels: every frame, every joint."""
    import mocycle
    from mocycle.datasets import synthetic_walk

    motion = synthetic_walk(n_frames=90, fps=30).motion
    path = tmp_path / "walk.glb"
    mocycle.write(motion, path)
    got, height, _ = compare(motion, path)
    assert np.ptp(got[:, 0], axis=0).max() > 0.2 * height  # the root really travels (not a pose held still)


def test_z_up_turning_walk_glb(scene, tmp_path):
    """A Z-up take turning as it walks: the writer turns its vertical onto +Y, Blender's importer back to +Z."""
    import mocycle
    from mocycle.datasets import synthetic_circle_walk

    motion = synthetic_circle_walk(n_frames=90, fps=30, up="z").motion
    path = tmp_path / "circle.glb"
    mocycle.write(motion, path)
    got, _, _ = compare(motion, path)
    assert np.argmax(np.ptp(got[0], axis=0)) == 2  # standing up along Blender's Z


def test_loop_glb_plays_the_cycle_and_loops(scene, tmp_path):
    """What ``mocycle loop walk.bvh -o walk_loop.glb`` writes (the task, then the front ends' ``for_output``: the
    cycle with its closing key): Blender plays the cycle, and its last key is its first pose (the action loops)."""
    import mocycle
    from mocycle.datasets import synthetic_walk
    from mocycle.tasks import loop
    from mocycle.tasks.clips import for_output

    report = loop.run(synthetic_walk(n_frames=240, fps=30).motion)
    path = tmp_path / "walk_loop.glb"
    motion, clip = for_output(report, "loop", path)
    mocycle.write(motion, path, clip=clip)
    n = report.facts["cycle_frames"]
    assert motion.n_frames == n + 1  # the closing key
    got, height, (start, end) = compare(motion, path)
    assert end - start == n  # the action lasts one period
    seam = float(np.abs(got[-1] - got[0]).max() / height)
    step = float(np.median(np.abs(np.diff(got, axis=0)).max(axis=(1, 2))) / height)
    print(f"loop: {n} frames, last key vs first {seam:.1e} of the height (a frame's step: {step:.1e})")
    assert seam <= TOLERANCE


def fingered_walk():
    """The synthetic walk with five fingers of four joints on each hand hanging down (40 joints below the hips
    while the arms swing down, as Mixamo rigs have them), which turned the detected vertical upside down."""
    from mocycle.datasets import synthetic_walk
    from mocycle.motion import Motion, Skeleton

    walk = synthetic_walk(n_frames=90, fps=30, seed=2).motion
    sk = walk.skeleton
    names, parents, offsets = list(sk.names), list(sk.parents), [tuple(o) for o in sk.offsets]
    channels = list(sk.channels)
    world_rotations, _ = walk.world_transforms()
    for side in ("Left", "Right"):
        hand = names.index(f"{side}Hand")
        down = world_rotations[:, hand].mean(axis=0).T
        for f in range(5):
            parent = hand
            for k in range(4):
                names.append(f"{side}Finger{f}_{k}")
                parents.append(parent)
                offsets.append(tuple(down @ [0.4 * (f - 2), -3.0, 0.0]))
                channels.append(("Zrotation", "Xrotation", "Yrotation"))
                parent = len(names) - 1
    skeleton = Skeleton(tuple(names), parents, np.asarray(offsets), tuple(channels), sk.end_sites)
    T, extra = walk.n_frames, len(names) - sk.n_joints
    rot = np.concatenate([walk.rotations, np.tile([0.0, 0, 0, 1], (T, extra, 1))], axis=1)
    static = np.vstack([walk.translations[0], np.asarray(offsets[sk.n_joints:])])
    return Motion(skeleton, rot, static, walk.frame_time, tracks={0: walk.root_positions})


def blender_export(motion, tmp_path, kind: str):
    """``motion`` (centimetres) as BVH, imported by Blender in metres and exported by its FBX (Y up, or Z up:
    ``fbx-z``) or glTF exporter; the file."""
    import mocycle

    bvh = mocycle.write(motion, tmp_path / "take.bvh")
    assert bpy.ops.import_anim.bvh(filepath=str(bvh), global_scale=0.01, update_scene_fps=True,
                                   update_scene_duration=True) == {"FINISHED"}
    arm = bpy.context.active_object
    sc = bpy.context.scene
    sc.frame_end = sc.frame_start + motion.n_frames - 1
    bpy.ops.object.select_all(action="DESELECT")
    arm.select_set(True)
    bpy.context.view_layer.objects.active = arm
    if kind == "glb":
        path = tmp_path / "take.glb"
        assert bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLB", export_animations=True) == {
            "FINISHED"}
    else:
        path = tmp_path / f"take_{kind}.fbx"
        axes = {"fbx-y": ("Y", "-Z"), "fbx-z": ("Z", "Y")}[kind]
        assert bpy.ops.export_scene.fbx(filepath=str(path), bake_anim=True, axis_up=axes[0],
                                        axis_forward=axes[1]) == {"FINISHED"}
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    return path


@pytest.mark.parametrize("source", ["bvh", "fbx-y", "fbx-z", "glb"])
def test_written_glb_stands_upright(scene, tmp_path, source):
    """A Mixamo-like take (40 finger joints hanging below the hips) read from BVH, from Blender's FBX (declaring
    Y up, or Z up) and from its glTF, then written as ``.glb``: Blender's own importer shows the head above the
    feet, every frame, by most of the body's height."""
    try:
        import ufbx  # noqa: F401
    except ModuleNotFoundError:
        if source.startswith("fbx"):
            pytest.fail("ufbx is missing from this bpy environment (make test-blender installs it)")
    import mocycle

    motion = fingered_walk()
    path = tmp_path / "take.bvh" if source == "bvh" else blender_export(motion, tmp_path, source)
    if source == "bvh":
        mocycle.write(motion, path)
    read = mocycle.read(path)
    out = mocycle.write(read, tmp_path / f"{source}.glb")
    arm = import_glb(out, read.fps)
    names = [n for n in ("Head", "LeftFoot", "RightFoot") if n in arm.pose.bones]
    assert len(names) == 3, f"bones missing: {sorted(b.name for b in arm.pose.bones)[:8]}"
    got, _ = played(arm, names)
    height = got[:, 0, 2] - np.minimum(got[:, 1, 2], got[:, 2, 2])
    print(f"\n{source} -> {out.name}: up read as {read.skeleton.up or 'detected'}; head above the lower foot by "
          f"{height.min():.2f} to {height.max():.2f} m in Blender")
    assert 1.0 < height.min() <= height.max() < 2.0  # metres: the body stands (1.5 m from feet to head)
