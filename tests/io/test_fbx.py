"""FBX input through ufbx (pufbx): a small ASCII FBX written here (bones with a pre-rotation and Mixamo names, a
mesh and a light beside them, two animation stacks, linear keys at 30 fps) reads as worked out by hand; damaged
files are one MotionFileError.  Blender-made files are checked in tests_blender/test_formats_in.py."""

from __future__ import annotations

import pytest

import mocycle
from mocycle.errors import MotionFileError

pytest.importorskip("pufbx", reason="the FBX reader needs pufbx (pip install 'mocycle[fbx]')")

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


def ascii_fbx(path, *, prefix="mixamorig:", frames=31, second_stack=True):
    """Armature (null) > Hips (LimbNode, 90 up) > Knee (LimbNode, 40 down, pre-rotation 90 deg about Z) > Foot
    (LimbNode, 10 along X); a mesh and a light beside them.  Stack "walk": the knee turns 0 -> 90 deg about X
    over ``frames`` frames at 30 fps; stack "idle": the hips rise by 5 over 11 frames."""
    hips, knee, foot = f"{prefix}Hips", f"{prefix}LeftLeg", f"{prefix}LeftFoot"
    objects = (model(1000, "Armature", "Null")
               + model(1001, hips, "LimbNode", p3("Lcl Translation", "Lcl Translation", 0, 90, 0))
               + attribute(2001, hips)
               + model(1002, knee, "LimbNode", p3("Lcl Translation", "Lcl Translation", 0, -40, 0)
                       + '\t\t\tP: "RotationActive", "bool", "", "",1\n'
                       + p3("PreRotation", "Vector3D", 0, 0, 90).replace('"A",', '"",'))
               + attribute(2002, knee)
               + model(1003, foot, "LimbNode", p3("Lcl Translation", "Lcl Translation", 10, 0, 0))
               + attribute(2003, foot)
               + model(1004, "Body", "Mesh") + model(1005, "Lamp", "Light"))
    last = (frames - 1) * FRAME
    stacks = (f'\tAnimationStack: 3001, "AnimStack::walk", "" {{\n\t\tProperties70:  {{\n'
              f'\t\t\tP: "LocalStart", "KTime", "Time", "",0\n\t\t\tP: "LocalStop", "KTime", "Time", "",{last}\n'
              f'\t\t}}\n\t}}\n\tAnimationLayer: 3002, "AnimLayer::BaseLayer", "" {{\n\t}}\n'
              f'\tAnimationCurveNode: 3003, "AnimCurveNode::R", "" {{\n\t\tProperties70:  {{\n'
              f'\t\t\tP: "d|X", "Number", "", "A",0\n\t\t\tP: "d|Y", "Number", "", "A",0\n'
              f'\t\t\tP: "d|Z", "Number", "", "A",0\n\t\t}}\n\t}}\n'
              + curve(3004, [k * FRAME for k in range(frames)], [90.0 * k / (frames - 1) for k in range(frames)]))
    connections = ['"OO",1000,0', '"OO",1001,1000', '"OO",2001,1001', '"OO",1002,1001', '"OO",2002,1002',
                   '"OO",1003,1002', '"OO",2003,1003', '"OO",1004,1000', '"OO",1005,0',
                   '"OO",3002,3001', '"OO",3003,3002', '"OP",3003,1002, "Lcl Rotation"', '"OP",3004,3003, "d|X"']
    if second_stack:
        stacks += (f'\tAnimationStack: 4001, "AnimStack::idle", "" {{\n\t\tProperties70:  {{\n'
                   f'\t\t\tP: "LocalStart", "KTime", "Time", "",0\n'
                   f'\t\t\tP: "LocalStop", "KTime", "Time", "",{10 * FRAME}\n\t\t}}\n\t}}\n'
                   f'\tAnimationLayer: 4002, "AnimLayer::BaseLayer", "" {{\n\t}}\n'
                   f'\tAnimationCurveNode: 4003, "AnimCurveNode::T", "" {{\n\t\tProperties70:  {{\n'
                   f'\t\t\tP: "d|X", "Number", "", "A",0\n\t\t\tP: "d|Y", "Number", "", "A",90\n'
                   f'\t\t\tP: "d|Z", "Number", "", "A",0\n\t\t}}\n\t}}\n'
                   + curve(4004, [k * FRAME for k in range(11)], [90.0 + 0.5 * k for k in range(11)]))
        connections += ['"OO",4002,4001', '"OO",4003,4002', '"OP",4003,1001, "Lcl Translation"',
                        '"OP",4004,4003, "d|Y"']
    text = ("; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}\n"
            "GlobalSettings:  {\n\tVersion: 1000\n\tProperties70:  {\n"
            '\t\tP: "UpAxis", "int", "Integer", "",1\n\t\tP: "UnitScaleFactor", "double", "Number", "",1\n'
            '\t\tP: "TimeMode", "enum", "", "",6\n\t}\n}\n'
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
