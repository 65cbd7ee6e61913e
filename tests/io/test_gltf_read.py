"""glTF input: mocycle's own GLB reads back to the motion written; LINEAR, STEP and CUBICSPLINE samplers on small
files built here with pygltflib; several animations by name; hostile files give one MotionFileError."""

from __future__ import annotations

import struct

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import mocycle
from mocycle.datasets import synthetic_walk, to_z_up
from mocycle.datasets.gltf_files import chain_document, gltf_file
from mocycle.errors import DefaultTake, MotionFileError
from mocycle.io.gltf import body_size
from mocycle.io.gltf_read import DEFAULT_FPS, gltf_takes, read_gltf

g = pytest.importorskip("pygltflib")

FLOAT = 5126


def positions_by_name(motion):
    """``{name: (T, 3)}`` world positions of joints and named End Sites."""
    sk = motion.skeleton
    w = motion.world_positions(end_sites=True)
    names = list(sk.names) + [s.name for s in sk.end_sites]
    return {n: w[:, i] for i, n in enumerate(names) if n is not None}


@pytest.mark.parametrize("z_up", [False, True])
def test_mocycle_glb_reads_back(tmp_path, z_up):
    walk = synthetic_walk(n_frames=180, fps=60).motion
    if z_up:
        walk = to_z_up(walk)
    path = mocycle.write(walk, tmp_path / "walk.glb")
    again = mocycle.read(path)
    assert again.n_frames == walk.n_frames
    assert again.frame_time == pytest.approx(walk.frame_time, rel=1e-9)
    assert again.skeleton.names == walk.skeleton.names
    assert list(again.skeleton.parents) == list(walk.skeleton.parents)
    assert len(again.skeleton.end_sites) == len(walk.skeleton.end_sites)
    a, b = positions_by_name(walk), positions_by_name(again)
    height = body_size(walk)
    for name in walk.skeleton.names:
        assert np.abs(a[name] - b[name]).max() < 1e-5 * height, name
    assert again.travel_joint == walk.travel_joint
    assert gltf_takes(path) == ["walk"]


def test_scale_of_a_foreign_glb_is_metres(tmp_path):
    """A file mocycle did not write keeps glTF's metres (its generator is not mocycle)."""
    walk = synthetic_walk(n_frames=30).motion
    path = mocycle.write(walk, tmp_path / "walk.glb")
    gl = g.GLTF2.load(path)
    gl.asset.generator = "someone else"
    gl.save(tmp_path / "other.glb")
    other = read_gltf(tmp_path / "other.glb")
    hip = positions_by_name(other)["Hips"]
    assert np.abs(hip - positions_by_name(walk)["Hips"] * 0.01).max() < 1e-6


# -- small files built here ---------------------------------------------------------------------------------------
def small_glb(path, samplers, *, skin=True, extra_nodes=None, animations=None, times=None, blob_edit=None,
              json_edit=None):
    """A two-joint chain (root at the origin, child 1 m up its Y, a tip 1 m above) with the given samplers on the
    child's rotation: ``samplers``: list of (name, interpolation, times, values[, node]) (``node``: the one
    turned, else the child)."""
    blob = bytearray()
    gl = g.GLTF2(asset=g.Asset(version="2.0", generator="test"))

    def add(array, kind):
        a = np.ascontiguousarray(array, dtype="<f4")
        gl.bufferViews.append(g.BufferView(buffer=0, byteOffset=len(blob), byteLength=a.nbytes))
        blob.extend(a.tobytes())
        gl.accessors.append(g.Accessor(bufferView=len(gl.bufferViews) - 1, componentType=FLOAT,
                                       count=len(a), type=kind))
        return len(gl.accessors) - 1

    gl.nodes = [g.Node(name="root", children=[1]), g.Node(name="child", translation=[0, 1, 0], children=[2]),
                g.Node(name="tip", translation=[0, 1, 0])] + (extra_nodes or [])
    if skin:
        gl.skins = [g.Skin(joints=[0, 1, 2])]
    anims = []
    for name, interp, t, v, *node in samplers:
        s = g.AnimationSampler(input=add(np.asarray(t)[:, None], "SCALAR"), output=add(v, "VEC4"),
                               interpolation=interp)
        anims.append(g.Animation(name=name, samplers=[s], channels=[
            g.AnimationChannel(sampler=0, target=g.AnimationChannelTarget(node=node[0] if node else 1,
                                                                          path="rotation"))]))
    gl.animations = anims
    gl.scenes = [g.Scene(nodes=[0])]
    gl.scene = 0
    gl.buffers = [g.Buffer(byteLength=len(blob))]
    if json_edit:
        json_edit(gl)
    gl.set_binary_blob(bytes(blob_edit(blob) if blob_edit else blob))
    gl.save_binary(str(path))
    return path


def turn(deg):
    return Rotation.from_euler("x", deg, degrees=True).as_quat()


def tip_angle(motion):
    """The child's turn about X (degrees), from the tip's world position."""
    p = positions_by_name(motion)
    d = p["tip"] - p["child"]
    return np.degrees(np.arctan2(d[:, 2], d[:, 1]))


def test_linear_sampler_slerps(tmp_path):
    path = small_glb(tmp_path / "a.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])])
    m = read_gltf(path, fps=10)
    assert m.n_frames == 11 and m.fps == pytest.approx(10)
    assert tip_angle(m) == pytest.approx(np.linspace(0, 90, 11), abs=1e-4)


def test_step_sampler_holds(tmp_path):
    path = small_glb(tmp_path / "a.glb", [("swing", "STEP", [0.0, 0.5, 1.0], [turn(0), turn(40), turn(80)])])
    m = read_gltf(path, fps=4)
    assert tip_angle(m) == pytest.approx([0, 0, 40, 40, 80], abs=1e-4)


def test_cubicspline_sampler_is_hermite(tmp_path):
    # values 0 and 90 degrees (as quaternions, rotation about X), tangents zero: smoothstep in the quaternion's
    # components, normalised; check one inner frame against the formula
    zero = np.zeros(4)
    v0, v1 = turn(0), turn(90)
    values = [zero, v0, zero, zero, v1, zero]
    path = small_glb(tmp_path / "a.glb", [("swing", "CUBICSPLINE", [0.0, 1.0], values)])
    m = read_gltf(path, fps=4)
    s = 0.25
    h = (2 * s ** 3 - 3 * s ** 2 + 1) * v0 + (-2 * s ** 3 + 3 * s ** 2) * v1
    h /= np.linalg.norm(h)
    expected = np.degrees(2 * np.arctan2(h[0], h[3]))
    got = tip_angle(m)
    assert got[1] == pytest.approx(expected, abs=1e-3)
    assert got[0] == pytest.approx(0, abs=1e-4) and got[-1] == pytest.approx(90, abs=1e-4)
    assert abs(got[1] - 22.5) > 1  # not linear


def test_cubicspline_needs_three_values_a_key(tmp_path):
    path = small_glb(tmp_path / "a.glb", [("swing", "CUBICSPLINE", [0.0, 1.0], [turn(0), turn(90)])])
    with pytest.raises(MotionFileError, match="3 values per key"):
        read_gltf(path)


def test_regular_keys_set_the_frame_rate(tmp_path):
    t = np.arange(25) / 24
    path = small_glb(tmp_path / "a.glb", [("swing", "LINEAR", t, [turn(k) for k in range(25)])])
    m = read_gltf(path)
    assert m.fps == 24.0 and m.n_frames == 25
    irregular = small_glb(tmp_path / "b.glb", [("swing", "LINEAR", [0.0, 0.1, 0.35, 1.0],
                                               [turn(0), turn(5), turn(10), turn(20)])])
    with pytest.warns(mocycle.MocycleWarning, match="the keys of take 'swing' lie on no regular grid"):
        m = read_gltf(irregular)
    assert m.fps == DEFAULT_FPS and m.n_frames == 31


def test_several_animations_by_name(tmp_path):
    path = small_glb(tmp_path / "a.glb", [("first", "LINEAR", [0.0, 1.0], [turn(0), turn(10)]),
                                          ("second", "LINEAR", [0.0, 2.0], [turn(0), turn(60)])])
    assert gltf_takes(path) == ["first", "second"]
    with pytest.warns(DefaultTake, match=r"read take 'first' \(the first that moves the skeleton\); the file also "
                                         r"holds 'second': choose one with option 'take'"):
        assert read_gltf(path, fps=10).n_frames == 11
    second = read_gltf(path, take="second", fps=10)
    assert second.n_frames == 21 and tip_angle(second)[-1] == pytest.approx(60, abs=1e-4)
    assert mocycle.read(path, take="1", sample_fps=10).n_frames == 21
    with pytest.raises(MotionFileError, match="no animation named 'third'; the file holds: first, second"):
        read_gltf(path, take="third")


def test_without_skin_the_animated_nodes_form_the_skeleton(tmp_path):
    path = small_glb(tmp_path / "a.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])], skin=False)
    m = read_gltf(path, fps=2)
    assert m.skeleton.names == ("child",)


def test_nodes_above_the_skeleton_are_composed_into_the_root(tmp_path):
    """An armature node scaled by 0.01 and turned Z-up to Y-up above the root: world positions keep both."""
    def edit(gl):
        gl.nodes.append(g.Node(name="Armature", children=[0], scale=[0.01] * 3,
                               rotation=turn(-90).tolist()))
        gl.scenes = [g.Scene(nodes=[3])]

    path = small_glb(tmp_path / "a.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])], json_edit=edit)
    m = read_gltf(path, fps=2)
    tip = positions_by_name(m)["tip"]
    assert tip[0] == pytest.approx([0, 0, -0.02], abs=1e-9)  # 2 m up the rig's Y = 2 cm along -Z... turned
    assert m.skeleton.names[0] == "root"


# -- hostile files --------------------------------------------------------------------------------------------------
def good(tmp_path):
    return small_glb(tmp_path / "good.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])])


def test_truncated_files(tmp_path):
    data = good(tmp_path).read_bytes()
    for cut in (0, 3, 12, 19, 40, len(data) // 2, len(data) - 1):
        bad = tmp_path / f"cut{cut}.glb"
        bad.write_bytes(data[:cut])
        with pytest.raises(MotionFileError) as info:
            read_gltf(bad)
        assert str(bad) in str(info.value)


def test_counts_beyond_the_buffer(tmp_path):
    for count in (3, 10**9, 2**31 - 1):
        def edit(gl, count=count):
            gl.accessors[1].count = count
        path = small_glb(tmp_path / f"c{count}.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])],
                         json_edit=edit)
        with pytest.raises(MotionFileError, match="need .* bytes; its bufferView holds"):
            read_gltf(path)


def test_wrong_counts_and_indices(tmp_path):
    def fewer_times(gl):
        gl.accessors[0].count = 1
        gl.bufferViews[0].byteLength = 4

    cases = {"key times but": fewer_times,
             "must be a whole number": lambda gl: setattr(gl.animations[0].samplers[0], "input", 99),
             "componentType": lambda gl: setattr(gl.accessors[0], "componentType", 1),
             "nodes must form a tree": lambda gl: setattr(gl.nodes[2], "children", [1]),
             "cycle|two parents": lambda gl: setattr(gl.nodes[2], "children", [0]),
             "bufferViews.* ends at byte": lambda gl: setattr(gl.bufferViews[1], "byteOffset", 10**6),
             "byteStride": lambda gl: setattr(gl.bufferViews[1], "byteStride", 8)}
    for k, (pattern, edit) in enumerate(cases.items()):
        path = small_glb(tmp_path / f"w{k}.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])],
                         json_edit=edit)
        with pytest.raises(MotionFileError, match=pattern):
            read_gltf(path)


def test_a_cycle_in_the_node_tree(tmp_path):
    def edit(gl):
        gl.nodes[2].children = [0]  # root -> child -> tip -> root: no node at the top

    path = small_glb(tmp_path / "cycle.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])], json_edit=edit)
    with pytest.raises(MotionFileError, match="cycle|two parents"):
        read_gltf(path)


def test_nan_values_and_decreasing_times(tmp_path):
    nan = small_glb(tmp_path / "nan.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), [np.nan, 0, 0, 1]])])
    with pytest.raises(MotionFileError, match="NaN"):
        read_gltf(nan)
    back = small_glb(tmp_path / "back.glb", [("swing", "LINEAR", [1.0, 0.0], [turn(0), turn(9)])])
    with pytest.raises(MotionFileError, match="increasing"):
        read_gltf(back)


def test_huge_animation_span_is_refused(tmp_path):
    path = small_glb(tmp_path / "long.glb", [("swing", "LINEAR", [0.0, 1e6], [turn(0), turn(9)])])
    with pytest.raises(MotionFileError, match="frames"):
        read_gltf(path, fps=1000)


def test_not_json_and_not_glb(tmp_path):
    junk = tmp_path / "junk.gltf"
    junk.write_text("{ this is not json")
    with pytest.raises(MotionFileError, match="junk.gltf"):
        mocycle.read(junk)
    fake = tmp_path / "fake.glb"
    fake.write_bytes(b"glTF" + struct.pack("<II", 2, 10**9) + b"\0" * 30)
    with pytest.raises(MotionFileError, match="truncated"):
        mocycle.read(fake)
    # the header claims no room for any chunk (found by benchmarks/fuzz.py: an AttributeError before)
    for claimed in (0, 2, 12):
        fake.write_bytes(b"glTF" + struct.pack("<II", 2, claimed) + b"\0" * 30)
        with pytest.raises(MotionFileError, match="no room for the JSON chunk"):
            mocycle.read(fake)


def test_cli_info_lists_the_takes_and_take_chooses(tmp_path):
    import json

    from typer.testing import CliRunner

    from mocycle.cli import app

    path = small_glb(tmp_path / "a.glb", [("first", "LINEAR", [0.0, 1.0], [turn(0), turn(10)]),
                                          ("second", "LINEAR", [0.0, 2.0], [turn(0), turn(60)])])
    runner = CliRunner()
    done = runner.invoke(app, ["info", str(path), "--json"])
    assert done.exit_code == 0, done.output
    facts = json.loads(done.output)
    assert facts["takes"] == ["first", "second"] and facts["take"] == "first"
    done = runner.invoke(app, ["info", str(path), "--take", "second", "--json"])
    assert done.exit_code == 0, done.output
    facts = json.loads(done.output)
    assert facts["take"] == "second" and facts["duration_s"] == pytest.approx(2.0) and facts["fps"] == 30
    done = runner.invoke(app, ["info", str(path), "--take", "third"])
    assert done.exit_code == 1 and "no animation named 'third'" in done.output
    assert "Traceback" not in done.output
    out = tmp_path / "second.bvh"
    done = runner.invoke(app, ["convert", str(path), str(out), "--take", "second"])
    assert done.exit_code == 0, done.output
    assert mocycle.read(out).n_frames == 61  # two seconds at 30 fps (two keys far apart: sparse, 30 fps)


def test_gltf_text_with_data_uri_and_bin_file(tmp_path):
    path = small_glb(tmp_path / "a.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])])
    expected = tip_angle(read_gltf(path, fps=10))
    gl = g.GLTF2.load(path)
    gl.convert_buffers(g.BufferFormat.DATAURI)
    gl.save_json(str(tmp_path / "uri.gltf"))
    assert tip_angle(mocycle.read(tmp_path / "uri.gltf", sample_fps=10)) == pytest.approx(expected, abs=1e-9)
    gl = g.GLTF2.load(path)
    gl._path = tmp_path
    gl.convert_buffers(g.BufferFormat.BINFILE)
    gl.save_json(str(tmp_path / "file.gltf"))
    assert any(p.suffix == ".bin" for p in tmp_path.iterdir())
    assert tip_angle(mocycle.read(tmp_path / "file.gltf", sample_fps=10)) == pytest.approx(expected, abs=1e-9)


def test_the_default_take_is_the_first_that_moves(tmp_path):
    """A first animation whose keys all hold one pose is not the default; the warning names the take read."""
    path = small_glb(tmp_path / "a.glb", [("still", "LINEAR", [0.0, 1.0], [turn(5), turn(5)]),
                                          ("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])])
    with pytest.warns(DefaultTake, match=r"read take 'swing' \(the first that moves the skeleton\); the file also "
                                         r"holds 'still' \(still\)"):
        m = read_gltf(path, fps=10)
    assert tip_angle(m)[-1] == pytest.approx(90, abs=1e-4)
    assert m.cache("take") == "swing"
    from mocycle import tasks

    facts = tasks.info.run(path).facts
    assert facts["take"] == "swing" and facts["takes"] == ["still", "swing"]


def test_every_take_has_the_same_joints(tmp_path):
    """The tip (a leaf) turns in "b" only: a joint in both takes, not an End Site in "a"."""
    path = small_glb(tmp_path / "a.glb", [("a", "LINEAR", [0.0, 1.0], [turn(0), turn(10)]),
                                          ("b", "LINEAR", [0.0, 1.0], [turn(0), turn(20)], 2)])
    a, b = read_gltf(path, take="a"), read_gltf(path, take="b")
    assert a.skeleton.names == b.skeleton.names == ("root", "child", "tip")


def test_a_node_named_like_a_joint_does_not_rename_it(tmp_path):
    """RobotExpressive has a mesh node "Torso" beside the joint "Torso", which was read as "Torso.1"."""
    path = small_glb(tmp_path / "a.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])],
                     extra_nodes=[g.Node(name="child"), g.Node(name="root")])
    m = read_gltf(path)
    assert m.skeleton.names == ("root", "child")


def test_one_frame_rate_for_every_take(tmp_path):
    """The file's rate is its animations' key rate: a take whose keys lie on no grid is sampled at it (not at
    30 fps) and says so."""
    t = np.arange(25) / 24
    path = small_glb(tmp_path / "a.glb", [("walk", "LINEAR", t, [turn(k) for k in range(25)]),
                                          ("run", "LINEAR", [0.0, 0.1, 0.35, 1.0],
                                           [turn(0), turn(5), turn(10), turn(20)])])
    assert read_gltf(path, take="walk").fps == 24
    with pytest.warns(mocycle.MocycleWarning, match="the keys of take 'run' lie on no regular grid of the file's "
                                                    "24 fps frames; sampled at 24 fps"):
        run = read_gltf(path, take="run")
    assert run.fps == 24 and run.n_frames == 25


def test_the_vertical_and_unit_are_declared(tmp_path):
    """glTF is metres and +Y up; a file mocycle wrote reads back with the vertical and unit of the motion
    written."""
    path = small_glb(tmp_path / "a.glb", [("swing", "LINEAR", [0.0, 1.0], [turn(0), turn(90)])])
    m = read_gltf(path)
    assert m.skeleton.up == (0.0, 1.0, 0.0) and m.skeleton.metres_per_unit == 1.0
    walk = to_z_up(synthetic_walk(n_frames=30).motion)
    again = mocycle.read(mocycle.write(walk, tmp_path / "walk.glb"))
    assert again.skeleton.up == pytest.approx((0.0, 0.0, 1.0), abs=1e-9)
    assert again.skeleton.metres_per_unit == pytest.approx(0.01)


def _walk_and_slide_document():
    """Two takes of one 3-node chain: ``turn`` turns the root; ``slide`` also moves node 1 along X."""
    times = np.arange(31) / 30
    doc, blob = chain_document(3, times=times, n_animations=2,
                                                           animation_names=["turn", "slide"])
    slide = np.stack([np.linspace(0.0, 0.05, 31), np.full(31, 0.1), np.zeros(31)], axis=1).astype("<f4")
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": slide.nbytes})
    doc["accessors"].append({"bufferView": 2, "componentType": 5126, "count": 31, "type": "VEC3"})
    blob += slide.tobytes()
    doc["buffers"][0]["byteLength"] = len(blob)
    doc["animations"][1]["samplers"].append({"input": 0, "output": 2, "interpolation": "LINEAR"})
    doc["animations"][1]["channels"].append({"sampler": 1, "target": {"node": 1, "path": "translation"}})
    return doc, blob


def test_every_take_of_a_file_has_one_skeleton(tmp_path):
    """A joint whose translation one take keys has position channels in every take (RobotExpressive's Walking
    keys feet and pole targets its Running leaves still): the takes blend and join without a skeleton error."""
    from mocycle.cycle.blend import skeleton_differences

    path = gltf_file(tmp_path / "two.glb", *_walk_and_slide_document())
    turn, slide = read_gltf(path, take="turn"), read_gltf(path, take="slide")
    assert turn.skeleton.position_axes(1) and slide.skeleton.position_axes(1)
    assert skeleton_differences(turn.skeleton, slide.skeleton) == []
    bone = turn.world_positions()[:, 1] - turn.world_positions()[:, 0]
    assert np.allclose(np.linalg.norm(bone, axis=1), 0.1, atol=1e-6)  # the turn's node 1 rests where it did
