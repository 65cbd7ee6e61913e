"""FBX and glTF in, checked against Blender: the project's synthetic walk, imported as BVH into Blender, exported
with Blender's own FBX and glTF exporters, read back with mocycle, plays as Blender plays it.

The fixtures are made here (never copied from ../shared/data):

* a Bandai-style rig (``joint_Root`` left at the origin, ``Hips`` carrying the travel), as FBX and GLB;
* a 100-joint rig (the synthetic skeleton plus finger, toe, hair and tail chains), as FBX and GLB;
* a Mixamo-style FBX: ``mixamorig:`` names, centimetres, Y up, a mesh bound to the armature, a light and a
  camera beside it, two actions exported as two takes.

Each frame's pairwise joint distances must match Blender's evaluated pose within 1% of the body's size after
one scale factor (units and axes may differ), the frame counts must be equal, and ``mocycle loop`` of the FBX
must loop at the BVH's period (within 3%).

Reading needs ufbx and pygltflib in the bpy environment (``make test-blender`` installs both; by hand:
``.venv-bpy52/bin/pip install ufbx pygltflib``); without them these tests skip and say so.

Files as animators keep them (issue 37): Blender's FBX and glTF exports of a take at 24 and at 60 fps read
at that rate with Blender's own frame count; an FBX whose first take holds a still pose (as Mixamo's empty
"Take 001") reads the take that moves by default.
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

from conftest import import_bvh

FPS = 30
PERIOD_S = 1.0
#: a little noise, as a capture has: an exactly periodic take has a perfect cut, which the loop's fit check
#: (the cycle against a plain cut) refuses to beat
NOISE_DEG = 0.5


def _need(module: str):
    try:
        found = __import__(module)
    except ImportError:
        found = None
    if found is None or (module == "ufbx" and not hasattr(found, "bake_anim")):
        pytest.skip(f"reading these files needs {module} in the bpy environment: .venv-bpy52/bin/pip install "
                    f"{module}")


def bandai_motion(n_frames: int = 150):
    """The synthetic walk with a static ``joint_Root`` at the origin above ``Hips``, which carries the travel."""
    from mocycle.datasets import synthetic_walk
    from mocycle.motion import EndSite, Motion, Skeleton

    walk = synthetic_walk(n_frames=n_frames, fps=FPS, period_s=PERIOD_S, noise_deg=NOISE_DEG, seed=3).motion
    sk = walk.skeleton
    six = ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")
    skeleton = Skeleton(("joint_Root",) + sk.names, [-1] + [p + 1 for p in sk.parents],
                        np.vstack([np.zeros(3), sk.offsets]), (six,) + sk.channels,
                        tuple(EndSite(s.parent + 1, s.offset, s.name) for s in sk.end_sites))
    T = walk.n_frames
    rot = np.concatenate([np.tile([0.0, 0, 0, 1], (T, 1, 1)), walk.rotations], axis=1)
    static = np.vstack([np.zeros(3), walk.translations[0]])
    return Motion(skeleton, rot, static, walk.frame_time, tracks={1: walk.root_positions})


def hundred_joint_motion(n_frames: int = 150):
    """The synthetic walk plus chains of small joints (five fingers of four joints on each hand, five toes of two
    on each foot, eight of hair on the head, ten of tail on the hips): 100 joints, the chains swinging at the
    walk's period."""
    from mocycle.datasets import synthetic_walk
    from mocycle.motion import Motion, Skeleton

    walk = synthetic_walk(n_frames=n_frames, fps=FPS, period_s=PERIOD_S, noise_deg=NOISE_DEG, seed=3).motion
    sk = walk.skeleton
    names, parents, offsets = list(sk.names), list(sk.parents), [tuple(o) for o in sk.offsets]
    zxy = ("Zrotation", "Xrotation", "Yrotation")
    channels = list(sk.channels)

    def chain(under: str, label: str, n: int, step):
        parent = names.index(under)
        for k in range(n):
            names.append(f"{label}{k + 1}")
            parents.append(parent)
            offsets.append(tuple(step))
            channels.append(zxy)
            parent = len(names) - 1

    for side, sign in (("Left", 1), ("Right", -1)):
        for f in range(5):
            chain(f"{side}Hand", f"{side}Finger{f}_", 4, (sign * 2.5, -1.0 + 0.5 * f, 0.4 * (f - 2)))
        for f in range(5):
            chain(f"{side}ToeBase", f"{side}Toe{f}_", 2, (0.5 * (f - 2), 0.0, 2.0))
    chain("Head", "Hair", 8, (0.0, 1.5, -1.0))
    chain("Hips", "Tail", 10, (0.0, -1.0, -2.0))
    assert len(names) == 100
    skeleton = Skeleton(tuple(names), parents, np.asarray(offsets), tuple(channels), sk.end_sites)
    T, J = walk.n_frames, len(names)
    t = np.arange(T) / FPS
    angle = 0.3 * np.sin(2 * np.pi * t / PERIOD_S)[:, None] * np.linspace(0.5, 1.0, J - sk.n_joints)[None]
    from scipy.spatial.transform import Rotation

    extra = Rotation.from_rotvec(np.stack([angle, 0.3 * angle, np.zeros_like(angle)], axis=-1).reshape(-1, 3))
    rot = np.concatenate([walk.rotations, extra.as_quat().reshape(T, -1, 4)], axis=1)
    static = np.vstack([walk.translations[0], np.asarray(offsets[sk.n_joints:])])
    return Motion(skeleton, rot, static, walk.frame_time, tracks={0: walk.root_positions})


def import_take(path, n_frames: int):
    """The BVH imported (its importer extends the scene to 250 frames, never shortens it: cut to the take)."""
    arm = import_bvh(path)
    sc = bpy.context.scene
    sc.frame_end = sc.frame_start + n_frames - 1
    return arm


def blender_positions(arm) -> tuple[list[str], np.ndarray]:
    """Bone names and their heads' world positions ``(T, B, 3)`` over the scene's frame range, as Blender
    evaluates the pose."""
    sc = bpy.context.scene
    frames = range(sc.frame_start, sc.frame_end + 1)
    names = [pb.name for pb in arm.pose.bones]
    out = np.empty((len(frames), len(names), 3))
    for i, f in enumerate(frames):
        sc.frame_set(f)
        mw = np.array(arm.matrix_world)
        for k, pb in enumerate(arm.pose.bones):
            out[i, k] = (mw @ np.append(np.array(pb.head), 1.0))[:3]
    return names, out


def mocycle_positions(motion) -> dict[str, np.ndarray]:
    sk = motion.skeleton
    w = motion.world_positions(end_sites=True)
    labels = list(sk.names) + [s.name for s in sk.end_sites]
    return {n: w[:, i] for i, n in enumerate(labels) if n is not None}


def distance_error(names: list[str], blender: np.ndarray, motion) -> float:
    """Largest difference of the pairwise joint distances (each frame), after one scale factor, over the body's
    size: 0 when mocycle plays what Blender plays, whatever the units and axes."""
    ours = mocycle_positions(motion)
    common = [n for n in names if n in ours]
    assert len(common) >= 0.9 * len(names), f"joints missing: {sorted(set(names) - set(ours))[:10]}"
    a = blender[:, [names.index(n) for n in common]]
    b = np.stack([ours[n] for n in common], axis=1)
    da = np.linalg.norm(a[:, :, None] - a[:, None], axis=-1)
    db = np.linalg.norm(b[:, :, None] - b[:, None], axis=-1)
    scale = np.median(db[da > 1e-9 * da.max()] / da[da > 1e-9 * da.max()])
    return float(np.abs(db / scale - da).max() / da.max())


def export(arm, path, kind: str, **extra):
    bpy.ops.object.select_all(action="DESELECT")
    arm.select_set(True)
    bpy.context.view_layer.objects.active = arm
    if kind == "fbx":
        result = bpy.ops.export_scene.fbx(filepath=str(path), bake_anim=True, **extra)
    else:
        result = bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLB", export_animations=True,
                                           **extra)
    assert result == {"FINISHED"}
    return path


def bvh_take(tmp_path, name, motion):
    import mocycle

    path = tmp_path / f"{name}.bvh"
    mocycle.write(motion, path)
    return path


@pytest.mark.parametrize("rig", ["bandai", "hundred"])
@pytest.mark.parametrize("kind", ["fbx", "glb"])
def test_blender_exports_read_as_blender_plays_them(extension, scene, tmp_path, rig, kind):
    _need("ufbx" if kind == "fbx" else "pygltflib")
    import mocycle

    motion = bandai_motion() if rig == "bandai" else hundred_joint_motion()
    bvh = bvh_take(tmp_path, rig, motion)
    arm = import_take(bvh, motion.n_frames)
    names, blender = blender_positions(arm)
    path = export(arm, tmp_path / f"{rig}.{kind}", kind)
    read = mocycle.read(path)
    err = distance_error(names, blender, read)
    print(f"\n{rig}.{kind}: {read.n_joints} joints, {read.n_frames} frames at {read.fps:g} fps; Blender "
          f"{blender.shape[1]} bones, {blender.shape[0]} frames; pairwise distances differ by {err:.2e} of the body")
    assert read.n_frames == blender.shape[0] == motion.n_frames
    assert read.fps == pytest.approx(FPS, rel=1e-6)
    assert err <= 0.01
    if rig == "bandai":
        assert "joint_Root" in read.skeleton.names
        root = mocycle_positions(read)["joint_Root"]
        assert np.ptp(root, axis=0).max() <= 1e-6 * np.abs(root).max(initial=1.0) + 1e-9  # the root stays put
        assert read.travel_joint == read.skeleton.names.index("Hips")
    if kind == "fbx":  # without the exporter's key reduction, the reader itself: as Blender plays within 1e-4
        exact = export(arm, tmp_path / f"{rig}_exact.fbx", kind, bake_anim_simplify_factor=0.0)
        err_exact = distance_error(names, blender, mocycle.read(exact))
        print(f"{rig}_exact.fbx (no key reduction): distances differ by {err_exact:.2e} of the body")
        assert err_exact <= 1e-4
    if kind == "fbx":  # the FBX loops, at the BVH's period
        from mocycle import tasks

        a = tasks.loop.run(bvh).facts
        b = tasks.loop.run(path).facts
        print(f"loop period: BVH {a['period_frames']:.3f} frames, FBX {b['period_frames']:.3f} frames")
        assert b["period_frames"] == pytest.approx(a["period_frames"], rel=0.03)


def test_mixamo_style_fbx(extension, scene, tmp_path):
    """``mixamorig:`` names, centimetres, Y up, a skinned mesh, a light and a camera, two takes."""
    _need("ufbx")
    import mocycle
    from mocycle import tasks
    from mocycle.datasets import synthetic_walk

    walk = synthetic_walk(n_frames=150, fps=FPS, period_s=PERIOD_S).motion
    arm = import_take(bvh_take(tmp_path, "walk", walk), walk.n_frames)
    for bone in arm.data.bones:
        bone.name = "mixamorig:" + bone.name
    arm.name = "Armature"
    sc = bpy.context.scene
    sc.unit_settings.system = "METRIC"
    sc.unit_settings.scale_length = 0.01
    sc.unit_settings.length_unit = "CENTIMETERS"
    # a mesh bound to the armature (one vertex group per bone), a light and a camera beside it
    mesh = bpy.data.meshes.new("Body")
    verts = [tuple(b.head_local) for b in arm.data.bones] + [tuple(b.tail_local) for b in arm.data.bones]
    mesh.from_pydata(verts, [], [])
    body = bpy.data.objects.new("Body", mesh)
    sc.collection.objects.link(body)
    body.parent = arm
    modifier = body.modifiers.new("Armature", "ARMATURE")
    modifier.object = arm
    for k, bone in enumerate(arm.data.bones):
        group = body.vertex_groups.new(name=bone.name)
        group.add([k, k + len(arm.data.bones)], 1.0, "REPLACE")
    for data in (bpy.data.lights.new("Sun", "SUN"), bpy.data.cameras.new("Camera")):
        sc.collection.objects.link(bpy.data.objects.new(data.name, data))
    # a second take: the same walk, slower (the first action stays the one the armature plays)
    first = arm.animation_data.action
    first.name = "walk"
    second = first.copy()
    second.name = "walk_half"
    for fc in _fcurves(second, arm):
        for key in fc.keyframe_points:
            key.co.x = 1 + (key.co.x - 1) * 2
            key.handle_left.x = 1 + (key.handle_left.x - 1) * 2
            key.handle_right.x = 1 + (key.handle_right.x - 1) * 2
    second.use_fake_user = True
    names, blender = blender_positions(arm)
    bpy.ops.object.select_all(action="SELECT")
    path = tmp_path / "mixamo.fbx"
    assert bpy.ops.export_scene.fbx(filepath=str(path), bake_anim=True, bake_anim_use_all_actions=True,
                                    object_types={"ARMATURE", "MESH", "LIGHT", "CAMERA"}, axis_up="Y",
                                    axis_forward="Z", apply_unit_scale=True) == {"FINISHED"}
    report = tasks.info.run(path)
    takes = report.facts["takes"]
    print(f"\nmixamo.fbx takes: {takes}")
    assert len(takes) >= 2 and any("walk_half" in t for t in takes) and any(t.endswith("walk") for t in takes)
    name = next(t for t in takes if t.endswith("|walk") or t == "walk")
    read = mocycle.read(path, take=name)
    assert all(n.startswith("mixamorig:") for n in read.skeleton.names)  # bones only: no mesh, light, camera
    assert read.skeleton.select("legs") and read.skeleton.select("arms") and read.skeleton.select("spine")
    err = distance_error(names, blender, read)
    height = float(np.ptp(read.world_positions()[0], axis=0).max())
    print(f"mixamo.fbx take {name!r}: {read.n_frames} frames, body {height:.4g} file units, distances differ by "
          f"{err:.2e}")
    assert read.n_frames == blender.shape[0]
    assert err <= 0.01
    assert 50 < height < 300  # centimetres, as the scene's unit says (metres would be 1.5)
    slow = mocycle.read(path, take=next(t for t in takes if "walk_half" in t))
    assert slow.n_frames >= 2 * read.n_frames - 3
    loop = tasks.loop.run(path, tasks.loop.Options(take=name)).facts  # a plain walk: the loop passes its checks
    assert loop["period_frames"] == pytest.approx(PERIOD_S * FPS, rel=0.03)
    assert not loop["failed_checks"]


def _fcurves(action, arm):
    """The F-curves of ``action``: slotted (4.4+) or legacy."""
    if hasattr(action, "layers") and action.layers:
        out = []
        for layer in action.layers:
            for strip in layer.strips:
                for bag in strip.channelbags:
                    out += list(bag.fcurves)
        return out
    return list(action.fcurves)


def blender_import(path, fps: float | None = None) -> tuple[float, int, list[str]]:
    """Blender's own import of ``path`` into the empty scene: (the scene's frame rate after it, the frames of the
    action it made, the bone names).  The FBX importer sets the scene to the file's rate; the glTF importer keeps
    none and turns key times into frames at the scene's rate, set to ``fps`` first."""
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    for coll in (bpy.data.armatures, bpy.data.actions):
        for item in list(coll):
            coll.remove(item)
    sc = bpy.context.scene
    sc.render.fps, sc.render.fps_base = (round(fps), round(fps) / fps) if fps else (30, 1.0)
    if str(path).endswith(".fbx"):
        assert bpy.ops.import_scene.fbx(filepath=str(path)) == {"FINISHED"}
    else:
        assert bpy.ops.import_scene.gltf(filepath=str(path)) == {"FINISHED"}
    (arm,) = [ob for ob in bpy.data.objects if ob.type == "ARMATURE"]
    start, end = arm.animation_data.action.frame_range
    assert start == int(start) and end == int(end), f"keys off the frames of {sc.render.fps} fps: {start}..{end}"
    return sc.render.fps / sc.render.fps_base, int(end - start) + 1, [b.name for b in arm.data.bones]


@pytest.mark.parametrize("fps", [24, 60])
@pytest.mark.parametrize("kind", ["fbx", "glb"])
def test_exports_read_at_their_own_frame_rate(extension, scene, tmp_path, fps, kind):
    """A take at 24 or 60 fps, exported by Blender: mocycle reads it at that rate with Blender's frame count (the
    24 fps FBX read as 311 frames at 120 fps and the 60 fps one as 133 at 30, when the rate came from keys
    baked on a 30 fps grid)."""
    _need("ufbx" if kind == "fbx" else "pygltflib")
    import mocycle
    from mocycle.datasets import synthetic_walk

    walk = synthetic_walk(n_frames=2 * fps + 15, fps=fps, period_s=PERIOD_S, noise_deg=NOISE_DEG, seed=3).motion
    arm = import_take(bvh_take(tmp_path, f"walk{fps}", walk), walk.n_frames)
    assert bpy.context.scene.render.fps == fps
    path = export(arm, tmp_path / f"walk{fps}.{kind}", kind)
    read = mocycle.read(path)
    rate, frames, _ = blender_import(path, read.fps)
    print(f"\nwalk{fps}.{kind}: mocycle {read.n_frames} frames at {read.fps:g} fps; Blender {frames} at {rate:g}")
    assert read.fps == fps and read.n_frames == walk.n_frames
    assert rate == fps and frames == walk.n_frames


def test_a_still_first_take_is_not_the_default(extension, scene, tmp_path):
    """Two actions exported as two takes, the first holding one pose (as the empty "Take 001" six of ten Mixamo
    files begin with): the default take is the walk, and the warning says so."""
    _need("ufbx")
    import mocycle
    from mocycle import tasks
    from mocycle.datasets import synthetic_walk
    from mocycle.errors import DefaultTake
    from mocycle.io import takes

    walk = synthetic_walk(n_frames=150, fps=FPS, period_s=PERIOD_S, noise_deg=NOISE_DEG, seed=3).motion
    arm = import_take(bvh_take(tmp_path, "walk", walk), walk.n_frames)
    moving = arm.animation_data.action
    moving.name = "walk"
    still = moving.copy()
    still.name = "Take 001"  # exported before "walk"
    for fc in _fcurves(still, arm):
        hold = fc.keyframe_points[0].co.y
        for key in fc.keyframe_points:
            key.co.y = key.handle_left.y = key.handle_right.y = hold
    still.use_fake_user = True
    path = tmp_path / "two_takes.fbx"
    bpy.ops.object.select_all(action="SELECT")
    assert bpy.ops.export_scene.fbx(filepath=str(path), bake_anim=True, bake_anim_use_all_actions=True) == {
        "FINISHED"}
    names = takes(path)
    print(f"\ntwo_takes.fbx takes: {names}")
    assert len(names) == 2 and "Take 001" in names[0] and "walk" in names[1]
    with pytest.warns(DefaultTake, match=r"the first that moves the skeleton\); the file also holds '.*Take 001' "
                                         r"\(still\)"):
        read = mocycle.read(path)
    assert read.cache("take") == names[1] and read.n_frames == walk.n_frames
    loop = tasks.loop.run(path).facts
    assert loop["period_frames"] == pytest.approx(PERIOD_S * FPS, rel=0.03)
