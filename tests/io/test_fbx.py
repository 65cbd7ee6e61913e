"""FBX input through ufbx: a small ASCII FBX written here (bones with a pre-rotation and Mixamo names, a
mesh and a light beside them, two animation stacks, linear keys at 30 fps) reads as worked out by hand; damaged
files are one MotionFileError.  Blender-made files are checked in tests_blender/test_formats_in.py."""

from __future__ import annotations

import pytest

import mocycle
from mocycle.errors import MotionFileError

ufbx = pytest.importorskip("ufbx", reason="the FBX reader needs ufbx (pip install 'mocycle[fbx]')")
if not hasattr(ufbx, "bake_anim"):
    pytest.skip("the 'ufbx' installed is not the ufbx binding (pufbx installs a package of that name)",
                allow_module_level=True)

from mocycle.io.fbx import fbx_takes, read_fbx  # noqa: E402

SECOND = 46186158000  # FBX KTime ticks per second
FRAME = SECOND // 30


def model(uid, name, kind, props=""):
    return (f'\tModel: {uid}, "Model::{name}", "{kind}" {{\n\t\tVersion: 232\n\t\tProperties70:  {{\n'
            f'{props}\t\t}}\n\t\tShading: Y\n\t\tCulling: "CullingOff"\n\t}}\n')


def attribute(uid, name, kind="LimbNode"):
    return (f'\tNodeAttribute: {uid}, "NodeAttribute::{name}", "{kind}" {{\n'
            f'\t\tTypeFlags: "Skeleton"\n\t}}\n')


def p3(name, kind, x, y, z):
    return f'\t\t\tP: "{name}", "{kind}", "", "A",{x},{y},{z}\n'


def curve(uid, times, values):
    n = len(times)
    return (f'\tAnimationCurve: {uid}, "AnimCurve::", "" {{\n\t\tDefault: {values[0]}\n\t\tKeyVer: 4009\n'
            f'\t\tKeyTime: *{n} {{\n\t\t\ta: {",".join(str(t) for t in times)}\n\t\t}}\n'
            f'\t\tKeyValueFloat: *{n} {{\n\t\t\ta: {",".join(str(v) for v in values)}\n\t\t}}\n'
            f'\t\tKeyAttrFlags: *1 {{\n\t\t\ta: 260\n\t\t}}\n'  # linear
            f'\t\tKeyAttrDataFloat: *4 {{\n\t\t\ta: 0,0,0,0\n\t\t}}\n'
            f'\t\tKeyAttrRefCount: *1 {{\n\t\t\ta: {n}\n\t\t}}\n\t}}\n')


#: FBX TimeMode of a frame rate (FbxTime::EMode)
TIME_MODES = {120: 1, 100: 2, 60: 3, 50: 4, 48: 5, 30: 6, 25: 10, 24: 11}


def stack(uid, name, frames, fps=30):
    return (f'\tAnimationStack: {uid}, "AnimStack::{name}", "" {{\n\t\tProperties70:  {{\n'
            f'\t\t\tP: "LocalStart", "KTime", "Time", "",0\n'
            f'\t\t\tP: "LocalStop", "KTime", "Time", "",{(frames - 1) * (SECOND // fps)}\n\t\t}}\n\t}}\n'
            f'\tAnimationLayer: {uid + 1}, "AnimLayer::BaseLayer", "" {{\n\t}}\n')


def curve_node(uid, kind, x, y, z):
    return (f'\tAnimationCurveNode: {uid}, "AnimCurveNode::{kind}", "" {{\n\t\tProperties70:  {{\n'
            f'\t\t\tP: "d|X", "Number", "", "A",{x}\n\t\t\tP: "d|Y", "Number", "", "A",{y}\n'
            f'\t\t\tP: "d|Z", "Number", "", "A",{z}\n\t\t}}\n\t}}\n')


def ascii_fbx(path, *, prefix="mixamorig:", frames=31, second_stack=True, fps=30, empty_first=False,
              foot_in_idle=False, up_axis=1, up_sign=1, unit=1.0, mesh_name="Body"):
    """Armature (null) > Hips (LimbNode, 90 up) > Knee (LimbNode, 40 down, pre-rotation 90 deg about Z) > Foot
    (LimbNode, 10 along X); a mesh (``mesh_name``) and a light beside them.  Stack "walk": the knee turns
    0 -> 90 deg about X over ``frames`` frames at ``fps`` (keys on every frame, the file's TimeMode says
    ``fps``); stack "idle": the hips rise by 5 over 11 frames (``foot_in_idle``: the foot turns too).
    ``empty_first``: a stack "Take 001" without curves comes first (as Mixamo's files have it).
    ``up_axis``/``up_sign``/``unit``: GlobalSettings' UpAxis, UpAxisSign and UnitScaleFactor."""
    hips, knee, foot = f"{prefix}Hips", f"{prefix}LeftLeg", f"{prefix}LeftFoot"
    frame = SECOND // fps
    objects = (model(1000, "Armature", "Null")
               + model(1001, hips, "LimbNode", p3("Lcl Translation", "Lcl Translation", 0, 90, 0))
               + attribute(2001, hips)
               + model(1002, knee, "LimbNode", p3("Lcl Translation", "Lcl Translation", 0, -40, 0)
                       + '\t\t\tP: "RotationActive", "bool", "", "",1\n'
                       + p3("PreRotation", "Vector3D", 0, 0, 90).replace('"A",', '"",'))
               + attribute(2002, knee)
               + model(1003, foot, "LimbNode", p3("Lcl Translation", "Lcl Translation", 10, 0, 0))
               + attribute(2003, foot)
               + model(1004, mesh_name, "Mesh") + model(1005, "Lamp", "Light"))
    stacks = (stack(3001, "walk", frames, fps) + curve_node(3003, "R", 0, 0, 0)
              + curve(3004, [k * frame for k in range(frames)], [90.0 * k / (frames - 1) for k in range(frames)]))
    connections = ['"OO",1000,0', '"OO",1001,1000', '"OO",2001,1001', '"OO",1002,1001', '"OO",2002,1002',
                   '"OO",1003,1002', '"OO",2003,1003', '"OO",1004,1000', '"OO",1005,0',
                   '"OO",3002,3001', '"OO",3003,3002', '"OP",3003,1002, "Lcl Rotation"', '"OP",3004,3003, "d|X"']
    if empty_first:
        stacks = stack(5001, "Take 001", 2, fps) + stacks
        connections += ['"OO",5002,5001']
    if second_stack:
        stacks += (stack(4001, "idle", 11, fps) + curve_node(4003, "T", 0, 90, 0)
                   + curve(4004, [k * frame for k in range(11)], [90.0 + 0.5 * k for k in range(11)]))
        connections += ['"OO",4002,4001', '"OO",4003,4002', '"OP",4003,1001, "Lcl Translation"',
                        '"OP",4004,4003, "d|Y"']
        if foot_in_idle:
            stacks += curve_node(4005, "R", 0, 0, 0) + curve(4006, [k * frame for k in range(11)],
                                                              [3.0 * k for k in range(11)])
            connections += ['"OO",4005,4002', '"OP",4005,1003, "Lcl Rotation"', '"OP",4006,4005, "d|Z"']
    text = ("; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}\n"
            "GlobalSettings:  {\n\tVersion: 1000\n\tProperties70:  {\n"
            f'\t\tP: "UpAxis", "int", "Integer", "",{up_axis}\n\t\tP: "UpAxisSign", "int", "Integer", "",{up_sign}\n'
            f'\t\tP: "UnitScaleFactor", "double", "Number", "",{unit}\n'
            f'\t\tP: "TimeMode", "enum", "", "",{TIME_MODES[fps]}\n\t}}\n}}\n'
            f"Objects:  {{\n{objects}{stacks}}}\n"
            "Connections:  {\n" + "".join(f"\tC: {c}\n" for c in connections) + "}\n")
    path.write_text(text)
    return path


def positions(motion):
    sk = motion.skeleton
    w = motion.world_positions(end_sites=True)
    labels = list(sk.names) + [s.name for s in sk.end_sites]
    return {n: w[:, i] for i, n in enumerate(labels)}


def test_bones_pre_rotation_and_keys(tmp_path):
    path = ascii_fbx(tmp_path / "rig.fbx")
    m = read_fbx(path)
    # bones only (the armature null above them, the mesh and the light are no joints); the foot does not move:
    # an End Site
    assert m.skeleton.names == ("mixamorig:Hips", "mixamorig:LeftLeg")
    assert [s.name for s in m.skeleton.end_sites] == ["mixamorig:LeftFoot"]
    assert m.n_frames == 31 and m.fps == pytest.approx(30.0)
    p = positions(m)
    assert p["mixamorig:LeftLeg"][0] == pytest.approx([0, 50, 0], abs=1e-9)
    # the foot: 10 along the knee's X, after the pre-rotation (90 deg about Z: X -> Y) and the animated turn
    # about X (applied first: R = Pre * Rx); X stays X under Rx, so the foot sits 10 above the knee throughout
    assert p["mixamorig:LeftFoot"][0] == pytest.approx([0, 60, 0], abs=1e-6)
    assert p["mixamorig:LeftFoot"][-1] == pytest.approx([0, 60, 0], abs=1e-6)
    # the knee's turn shows in its world rotation: 90 deg about X at the end, composed after the pre-rotation
    from scipy.spatial.transform import Rotation

    world = Rotation.from_quat(m.rotations[-1, 0]) * Rotation.from_quat(m.rotations[-1, 1])
    expected = Rotation.from_euler("z", 90, degrees=True) * Rotation.from_euler("x", 90, degrees=True)
    assert (world.inv() * expected).magnitude() < 1e-6
    mid = Rotation.from_quat(m.rotations[15, 0]) * Rotation.from_quat(m.rotations[15, 1])
    assert (mid.inv() * Rotation.from_euler("z", 90, degrees=True)
            * Rotation.from_euler("x", 45, degrees=True)).magnitude() < 1e-6


def test_takes_by_name(tmp_path):
    path = ascii_fbx(tmp_path / "rig.fbx")
    assert fbx_takes(path) == ["walk", "idle"]
    idle = mocycle.read(path, take="idle")
    assert idle.n_frames == 11
    assert positions(idle)["mixamorig:Hips"][-1] == pytest.approx([0, 95, 0], abs=1e-6)
    assert idle.travel_joint == 0
    assert mocycle.read(path, take="1").n_frames == 11
    with pytest.raises(MotionFileError, match="no take named 'run'; the file holds: walk, idle"):
        read_fbx(path, take="run")
    from mocycle import tasks

    facts = tasks.info.run(path, tasks.info.Options(take="idle")).facts
    assert facts["takes"] == ["walk", "idle"] and facts["take"] == "idle" and facts["frames"] == 11


def test_mixamo_names_find_the_joint_groups(tmp_path):
    m = read_fbx(ascii_fbx(tmp_path / "rig.fbx"))
    assert m.skeleton.select("legs") == [1]
    assert m.skeleton.select("mixamorig:Hips") == [0]


def test_sample_rate_option(tmp_path):
    m = read_fbx(ascii_fbx(tmp_path / "rig.fbx"), fps=60)
    assert m.n_frames == 61 and m.fps == 60


def test_damaged_files(tmp_path):
    good = ascii_fbx(tmp_path / "rig.fbx").read_bytes()
    for k, data in enumerate([b"", b"Kaydara FBX Binary  \x00\x1a\x00" + b"\xff" * 40, good[: len(good) // 3],
                              b"not an fbx file at all"]):
        bad = tmp_path / f"bad{k}.fbx"
        bad.write_bytes(data)
        with pytest.raises(MotionFileError) as info:
            read_fbx(bad)
        assert str(bad) in str(info.value)


def test_no_bones(tmp_path):
    path = tmp_path / "nobones.fbx"
    path.write_text(ascii_fbx(tmp_path / "x.fbx").read_text().replace('"LimbNode"', '"Null"'))
    with pytest.raises(MotionFileError, match="no bones"):
        read_fbx(path)


def test_scale_on_a_bone_scales_what_hangs_below(tmp_path):
    """Hips scaled by 2: the knee hangs 80 below it, the foot 20 above the knee (world positions as the file's)."""
    text = ascii_fbx(tmp_path / "x.fbx").read_text()
    scaled = text.replace(p3("Lcl Translation", "Lcl Translation", 0, 90, 0),
                          p3("Lcl Translation", "Lcl Translation", 0, 90, 0)
                          + p3("Lcl Scaling", "Lcl Scaling", 2, 2, 2), 1)
    assert scaled != text
    path = tmp_path / "scaled.fbx"
    path.write_text(scaled)
    p = positions(read_fbx(path))
    assert p["mixamorig:LeftLeg"][0] == pytest.approx([0, 10, 0], abs=1e-6)
    assert p["mixamorig:LeftFoot"][-1] == pytest.approx([0, 30, 0], abs=1e-6)


def test_the_declared_frame_rate(tmp_path):
    """Keys on a 24 fps grid in a file whose TimeMode says 24: 24 fps (baking at 30 put keys on both grids, which
    read as 120 fps); every take of the file at the same rate."""
    path = ascii_fbx(tmp_path / "rig24.fbx", fps=24, frames=63)
    walk = read_fbx(path, take="walk")
    assert walk.fps == 24 and walk.n_frames == 63
    assert read_fbx(path, take="idle").fps == 24
    sixty = read_fbx(ascii_fbx(tmp_path / "rig60.fbx", fps=60, frames=121), take="walk")
    assert sixty.fps == 60 and sixty.n_frames == 121
    assert read_fbx(path, take="walk", fps=48).n_frames == 125  # sample_fps still wins


def test_the_default_take_is_the_first_that_moves(tmp_path):
    """An empty first stack (Mixamo's "Take 001") is never the default; the warning names the take read and the
    others."""
    path = ascii_fbx(tmp_path / "mixamo.fbx", empty_first=True)
    assert fbx_takes(path) == ["Take 001", "walk", "idle"]
    with pytest.warns(mocycle.MocycleWarning, match=r"read take 'walk' \(the first that moves the skeleton\); "
                                                    r"the file also holds 'Take 001' \(still\), 'idle'"):
        m = read_fbx(path)
    assert m.n_frames == 31
    assert read_fbx(path, take="Take 001").n_frames <= 2  # asked for by name: read as it is


def test_one_take_no_warning(tmp_path):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_fbx(ascii_fbx(tmp_path / "one.fbx", second_stack=False))


def test_every_take_has_the_same_joints(tmp_path):
    """The foot (a leaf) turns in "idle" only: a joint in both takes, not an End Site in "walk"."""
    path = ascii_fbx(tmp_path / "rig.fbx", foot_in_idle=True)
    walk, idle = read_fbx(path, take="walk"), read_fbx(path, take="idle")
    assert walk.skeleton.names == idle.skeleton.names == ("mixamorig:Hips", "mixamorig:LeftLeg",
                                                          "mixamorig:LeftFoot")
    assert positions(walk)["mixamorig:LeftFoot"][-1] == pytest.approx([0, 60, 0], abs=1e-6)


def test_a_mesh_named_like_a_bone_does_not_rename_it(tmp_path):
    m = read_fbx(ascii_fbx(tmp_path / "rig.fbx", mesh_name="mixamorig:LeftLeg"), take="walk")
    assert m.skeleton.names == ("mixamorig:Hips", "mixamorig:LeftLeg")


@pytest.mark.parametrize("axis, sign, up", [(1, 1, (0, 1, 0)), (2, 1, (0, 0, 1)), (1, -1, (0, -1, 0))])
def test_the_declared_vertical_and_unit(tmp_path, axis, sign, up):
    m = read_fbx(ascii_fbx(tmp_path / "rig.fbx", up_axis=axis, up_sign=sign, unit=2.54), take="walk")
    assert m.skeleton.up == pytest.approx(up)
    assert m.skeleton.metres_per_unit == pytest.approx(0.0254)
    from mocycle.axes import vertical_axis

    assert vertical_axis(m).tolist() == pytest.approx(up)


def test_reading_survives_the_garbage_collector(tmp_path):
    """ufbx 0.0.5 hands its scene elements out one reference short and crashes when the collector frees its
    scene (exit 139); mocycle's reads, also the failed ones, with the collector running at every allocation and
    afterwards, in a process of their own."""
    import os
    import subprocess
    import sys

    good = ascii_fbx(tmp_path / "rig.fbx", empty_first=True, foot_in_idle=True)
    bones = tmp_path / "nobones.fbx"
    bones.write_text(good.read_text().replace('"LimbNode"', '"Null"'))
    script = f"""
import gc, warnings
warnings.simplefilter("ignore")
import mocycle
from mocycle.io.fbx import fbx_takes, read_fbx
gc.set_threshold(1, 1, 1)
kept = []
for k in range(20):
    kept.append(read_fbx({str(good)!r}))
    kept.append(read_fbx({str(good)!r}, take="idle"))
    fbx_takes({str(good)!r})
    for bad in ({str(bones)!r},):
        try:
            read_fbx(bad)
        except mocycle.MotionFileError:
            pass
    try:
        read_fbx({str(good)!r}, take="run")
    except mocycle.MotionFileError:
        pass
    gc.collect()
del kept
gc.collect()
print("done")
"""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0 and done.stdout.strip() == "done", (done.returncode, done.stderr[-2000:])
