"""Hostile glTF files (issue 36): a buffer ``uri`` reads only inside the file's own folder and only regular files,
never more than its ``byteLength``; fields of the wrong JSON type are one error each; node, name and animation
handling is linear; a span of key times claiming millions of frames is held to the frame limits and read a block
at a time.  Each file is generated here."""

from __future__ import annotations

import os
import resource
import time
from pathlib import Path

import numpy as np
import pytest

import mocycle
from fuzzing import limits
from mocycle.datasets.gltf_files import chain_document, gltf_file
from mocycle.errors import MotionFileError
from mocycle.io._nodes import joint_names, skeleton_order, unique_names
from mocycle.io.gltf_read import gltf_takes, read_gltf

SECRET = b"TOKEN-5f1e2d3c4b5a"


def _watch_opens(monkeypatch) -> list[str]:
    """Every path ``os.open``, ``os.stat`` and ``open`` are asked for from now on (what a read looks at)."""
    seen: list[str] = []
    real_open, real_stat, real_builtin = os.open, os.stat, open

    def os_open(path, *args, **kwargs):
        seen.append(os.fsdecode(path))
        return real_open(path, *args, **kwargs)

    def os_stat(path, *args, **kwargs):
        if not isinstance(path, int):
            seen.append(os.fsdecode(path))
        return real_stat(path, *args, **kwargs)

    def builtin_open(path, *args, **kwargs):
        if not isinstance(path, int):
            seen.append(os.fsdecode(path))
        return real_builtin(path, *args, **kwargs)

    monkeypatch.setattr(os, "open", os_open)
    monkeypatch.setattr(os, "stat", os_stat)
    monkeypatch.setattr("builtins.open", builtin_open)
    return seen


@pytest.fixture
def secret(tmp_path) -> Path:
    """``tmp_path/secret/token.txt`` (outside the glTF's folder ``tmp_path/take``); the folder is made."""
    (tmp_path / "secret").mkdir()
    (tmp_path / "take").mkdir()
    path = tmp_path / "secret" / "token.txt"
    path.write_bytes(SECRET * 100)
    return path


def _refused(path: Path, *needles: str) -> str:
    with pytest.raises(MotionFileError) as info:
        read_gltf(path)
    message = str(info.value)
    for needle in needles:
        assert needle in message, message
    return message


@pytest.mark.parametrize("uri", ["../secret/token.txt", "%2e%2e/secret/token.txt", "sub/../../secret/token.txt",
                                 "./../secret/token.txt", "..%2fsecret%2ftoken.txt", "..\\secret\\token.txt"])
def test_a_relative_uri_out_of_the_folder_reads_nothing(tmp_path, secret, monkeypatch, uri):
    doc, blob = chain_document(3)
    doc["buffers"][0]["byteLength"] = 64
    path = gltf_file(tmp_path / "take" / "evil.gltf", doc, blob, uri=uri)
    seen = _watch_opens(monkeypatch)
    message = _refused(path, "buffers[0].uri")
    assert SECRET.decode() not in message and "6,400" not in message and "6400" not in message
    outside = [p for p in seen if not os.path.abspath(p).startswith(str(tmp_path / "take"))]
    assert outside == [], outside  # no byte outside the folder read: not even looked at


@pytest.mark.parametrize("target", ["absolute", "/etc/passwd", "/dev/zero", "file:///etc/passwd",
                                    "file:secret.bin", "http://example.com/x.bin", "C:/Windows/win.ini",
                                    "\\\\server\\share\\x.bin"])
def test_an_absolute_uri_or_a_scheme_is_refused_and_tells_nothing(tmp_path, secret, monkeypatch, target):
    uri = str(secret) if target == "absolute" else target
    doc, blob = chain_document(3)
    doc["buffers"][0]["byteLength"] = 10_000  # more than the secret holds: the old message told its size
    path = gltf_file(tmp_path / "take" / "evil.gltf", doc, blob, uri=uri)
    seen = _watch_opens(monkeypatch)
    t0 = time.perf_counter()
    message = _refused(path, "relative path to a file in the glTF's own folder")
    assert time.perf_counter() - t0 < 5
    assert "6,400" not in message and "holds" not in message
    assert not [p for p in seen if not os.path.abspath(p).startswith(str(tmp_path / "take"))]


def test_a_link_out_of_the_folder_is_refused_and_one_inside_is_read(tmp_path, secret):
    doc, blob = chain_document(3)
    take = tmp_path / "take"
    os.symlink(secret, take / "link.bin")
    path = gltf_file(take / "evil.gltf", doc, blob, uri="link.bin")
    message = _refused(path, "leads outside the glTF's own folder")
    assert SECRET.decode() not in message
    (take / "data").mkdir()
    (take / "data" / "real.bin").write_bytes(blob)
    os.symlink(take / "data" / "real.bin", take / "inside.bin")
    good = read_gltf(gltf_file(take / "good.gltf", doc, blob, uri="inside.bin"))
    sub = read_gltf(gltf_file(take / "sub.gltf", doc, blob, uri="data/real.bin"))
    spaced = gltf_file(take / "spaced.gltf", doc, blob, uri="with%20space.bin")
    (take / "with space.bin").write_bytes(blob)
    assert good.n_frames == sub.n_frames == read_gltf(spaced).n_frames == 31


def test_a_fifo_or_a_device_as_buffer_or_file_never_blocks(tmp_path):
    take = tmp_path / "take"
    take.mkdir()
    doc, blob = chain_document(3)
    fifo = gltf_file(take / "fifo.gltf", doc, blob, uri="pipe.bin")
    zero = gltf_file(take / "zero.gltf", doc, blob, uri="zero.bin")
    folder = gltf_file(take / "folder.gltf", doc, blob, uri="folder.bin")
    for name in ("pipe.bin", "zero.bin", "folder.bin"):
        (take / name).unlink()
    os.mkfifo(take / "pipe.bin")
    os.symlink("/dev/zero", take / "zero.bin")
    (take / "folder.bin").mkdir()
    os.mkfifo(take / "walk.gltf")
    os.mkfifo(take / "walk.glb")
    with limits(seconds=10):
        _refused(fifo, "a named pipe, not a regular file")
        _refused(zero, "leads outside")
        _refused(folder, "a folder, not a regular file")
        _refused(take / "walk.gltf", "a named pipe, not a regular file")
        _refused(take / "walk.glb", "a named pipe")


def test_byte_length_bounds_what_is_read(tmp_path):
    """A 4 GiB file named by a buffer of byteLength 96 costs 96 bytes; one shorter than byteLength is refused."""
    take = tmp_path / "take"
    take.mkdir()
    doc, blob = chain_document(3)
    big = take / "huge.bin"
    with open(big, "wb") as fh:  # sparse: takes no disk
        fh.write(blob)
        fh.truncate(4 << 30)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    motion = read_gltf(gltf_file(take / "big.gltf", doc, blob, uri="huge.bin"))
    assert motion.n_frames == 31
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100_000  # kB: far below 4 GiB
    short = gltf_file(take / "short.gltf", doc, blob, uri="short.bin")
    (take / "short.bin").write_bytes(blob[:-8])
    _refused(short, f"holds {len(blob) - 8:,} bytes")


BAD_TYPES = {
    "accessors[1].type": (lambda d: d["accessors"][1].update(type=[]), "accessors[1].type must be text; got a list"),
    "componentType": (lambda d: d["accessors"][0].update(componentType=[]), "accessors[0].componentType must be "
                                                                              "a whole number"),
    "target.path": (lambda d: d["animations"][0]["channels"][0]["target"].update(path=[]), ".target.path must be text"),
    "target": (lambda d: d["animations"][0]["channels"][0].update(target=3), ".target must be an object"),
    "node name": (lambda d: d["nodes"][1].update(name=7), "nodes[1].name must be text; got a number"),
    "children": (lambda d: d["nodes"][0].update(children=["1"]), "nodes[0].children[0] must be a whole number"),
    "children true": (lambda d: d["nodes"][0].update(children=[True]), "must be a whole number; got true/false"),
    "nodes item": (lambda d: d["nodes"].append(5), "nodes[3] must be an object"),
    "count": (lambda d: d["accessors"][0].update(count=2.5), "accessors[0].count must be a whole number"),
    "byteLength": (lambda d: d["buffers"][0].update(byteLength="96"), "buffers[0].byteLength must be"),
    "uri": (lambda d: d["buffers"][0].update(uri=["x"]), "buffers[0].uri must be text"),
    "translation": (lambda d: d["nodes"][1].update(translation=[0, "1", 0]), "nodes[1].translation[1] must be a "
                                                                               "number"),
    "animations": (lambda d: d.update(animations={"a": 1}), "animations must be a list; got an object"),
    "sampler": (lambda d: d["animations"][0]["channels"][0].update(sampler=None, target=None), None),
    "interpolation": (lambda d: d["animations"][0]["samplers"][0].update(interpolation=1), "interpolation must be"),
    "skin joints": (lambda d: d["skins"][0].update(joints="all"), "skins[0].joints must be a list"),
    "asset": (lambda d: d.update(asset=[]), "asset must be an object"),
    "generator": (lambda d: d["asset"].update(generator={"a": 1}), "asset.generator must be text"),
    "normalized": (lambda d: d["accessors"][0].update(normalized=1), "normalized must be true or false"),
}


@pytest.mark.parametrize("case", list(BAD_TYPES))
def test_fields_of_the_wrong_type_are_one_error(tmp_path, case):
    edit, expected = BAD_TYPES[case]
    doc, blob = chain_document(3)
    edit(doc)
    for suffix in (".gltf", ".glb"):
        path = gltf_file(tmp_path / f"bad{suffix}", doc, blob)
        if expected is None:  # a channel with neither sampler nor target: skipped (nothing to play)
            assert read_gltf(path).n_frames == 1
            continue
        _refused(path, expected)


@pytest.mark.parametrize("extras", [1, "x", [1], {"mocycle": 1}, {"mocycle": {"units": [1]}},
                                    {"mocycle": {"units": {"metres_per_unit": 10**400,
                                                           "source_to_gltf_rotation_xyzw": [0, 0, 0, 1]}}},
                                    {"mocycle": {"units": {"metres_per_unit": 1, "source_to_gltf_rotation_xyzw":
                                                           [[1], [2, 3]]}}}])
def test_extras_of_any_shape_are_not_ours(tmp_path, extras):
    doc, blob = chain_document(3)
    doc["asset"]["generator"] = "mocycle"
    doc["scenes"][0]["extras"] = extras
    assert read_gltf(gltf_file(tmp_path / "x.glb", doc, blob)).n_frames == 31


def test_a_surrogate_name_reads_and_converts(tmp_path):
    doc, blob = chain_document(3, names=["\ud800", "\udcff", "a{b}"])
    motion = read_gltf(gltf_file(tmp_path / "s.gltf", doc, blob))
    assert motion.skeleton.names == ("\ud800", "\udcff")


def test_ten_thousand_nodes_read_within_ten_seconds_and_a_gigabyte(tmp_path):
    """The chain took 53 s and 1.9 GB when parents and ancestors were found per node."""
    path = gltf_file(tmp_path / "chain.gltf", *chain_document(10_000))
    t0 = time.perf_counter()
    with limits(headroom=1 << 30, seconds=10):
        motion = read_gltf(path)
    assert motion.n_joints == 9_999 and motion.n_frames == 31  # the last node is an End Site
    assert time.perf_counter() - t0 < 10


def test_joint_names_are_linear_in_the_nodes():
    """The nodes outside the skeleton were looked up in a set made again per node: 20,000 nodes of one name
    took 12 s there alone."""
    n = 200_000
    with limits(seconds=10):
        names = joint_names(["joint"] * n, list(range(n // 2, n)))
    assert names[n // 2] == "joint" and names[0] == f"joint.{n // 2}" and len(set(names)) == n


def test_twenty_thousand_same_named_nodes_read_within_ten_seconds(tmp_path):
    path = gltf_file(tmp_path / "same.gltf", *chain_document(20_000, names=["joint"] * 20_000))
    with limits(headroom=1 << 30, seconds=10):
        motion = read_gltf(path)
    assert motion.n_joints == 19_999 and len(set(motion.skeleton.names)) == 19_999


def test_ten_thousand_same_named_animations_list_in_linear_time(tmp_path):
    path = gltf_file(tmp_path / "takes.gltf", *chain_document(3, n_animations=10_000,
                                                               animation_names=["walk"] * 10_000))
    with limits(seconds=10):
        names = gltf_takes(path)
        motion = read_gltf(path, take="walk.9999")
    assert names[:3] == ["walk", "walk.1", "walk.2"] and names[-1] == "walk.9999" and motion.n_frames == 31


def test_unique_names_and_skeleton_order_are_linear():
    n = 200_000
    t0 = time.perf_counter()
    names = unique_names(["joint"] * n)
    assert names[0] == "joint" and names[-1] == f"joint.{n - 1}" and len(set(names)) == n
    # names that already look numbered, then repeats of their base: each taken once, still linear
    mixed = unique_names([f"a.{k}" for k in range(1, 1000)] + ["a"] * 2000)
    assert len(set(mixed)) == 2999 and mixed[999] == "a" and mixed[1000] == "a.1000"
    parents = np.arange(-1, n - 1)  # a chain
    children = [[i + 1] for i in range(n - 1)] + [[]]
    order = skeleton_order(parents, children, [0, n // 2, n - 1], "chain")
    assert order == list(range(n))  # the nodes between chosen ones are joints too
    assert time.perf_counter() - t0 < 10


def test_skeleton_order_joins_several_roots_at_their_lowest_common_node():
    #      0
    #      1
    #    2   5
    #   3 4    6
    parents = np.array([-1, 0, 1, 2, 2, 1, 5])
    children = [[1], [2, 5], [3, 4], [], [], [6], []]
    assert skeleton_order(parents, children, [3, 6], "t") == [1, 2, 3, 5, 6]
    assert skeleton_order(parents, children, [4, 3], "t") == [2, 3, 4]
    assert skeleton_order(parents, children, [0, 6], "t") == [0, 1, 5, 6]
    with pytest.raises(MotionFileError, match="2 roots with no common parent"):
        skeleton_order(np.array([-1, -1]), [[], []], [0, 1], "t")


def test_a_span_claiming_millions_of_frames_is_held_to_the_limits(tmp_path, monkeypatch):
    """A 1 KB file whose two key times lie 10^6 frames apart: refused above MOCYCLE_MAX_FRAMES; within it read a
    block of frames at a time (the peak is the motion's own arrays, not a (T, 4) array per channel and node)."""
    doc, blob = chain_document(40, times=(0.0, 999_999 / 30))
    for node in doc["nodes"][1:]:  # every node animated by the same sampler
        doc["animations"][0]["channels"].append({"sampler": 0, "target": {"node": doc["nodes"].index(node),
                                                                          "path": "rotation"}})
    path = gltf_file(tmp_path / "long.gltf", doc, blob)
    assert path.stat().st_size < 8000
    monkeypatch.setenv("MOCYCLE_MAX_FRAMES", "500000")
    with limits(seconds=10):
        _refused(path, "would hold 1,000,000 frames", "MOCYCLE_MAX_FRAMES")
    monkeypatch.setenv("MOCYCLE_MAX_FRAMES", "2000000")
    doc, blob = chain_document(40, times=(0.0, 99_999 / 30))
    for k in range(1, 40):
        doc["animations"][0]["channels"].append({"sampler": 0, "target": {"node": k, "path": "rotation"}})
    path = gltf_file(tmp_path / "long.gltf", doc, blob)
    with limits(headroom=1 << 30, seconds=60):
        motion = read_gltf(path)
    assert motion.n_frames == 100_000 and motion.n_joints == 40
    # the motion's quaternions are 100,000 x 40 x 32 bytes = 128 MB; the reader's blocks add a few MB more
    assert motion.rotations.nbytes == 128_000_000


def test_the_cli_says_one_line_for_a_hostile_uri(tmp_path, secret):
    from typer.testing import CliRunner

    from mocycle.cli.common import app

    doc, blob = chain_document(3)
    path = gltf_file(tmp_path / "take" / "evil.gltf", doc, blob, uri="../secret/token.txt")
    done = CliRunner().invoke(app, ["convert", str(path), str(tmp_path / "x.bvh")])
    assert done.exit_code == 1 and "Traceback" not in done.output and SECRET.decode() not in done.output
    assert not (tmp_path / "x.bvh").exists()
    assert mocycle.read(gltf_file(tmp_path / "take" / "fine.gltf", doc, blob)).n_frames == 31


def test_five_thousand_animations_on_shared_keys_read_within_ten_seconds(tmp_path):
    """Found by the fuzzer: 5,000 copies of one animation of 30 channels (one input accessor) spent 13 s
    weighing each channel's keys against each frame rate; the file rate now weighs each key array once."""
    doc, blob = chain_document(30, times=np.arange(31) / 30)
    anim = doc["animations"][0]
    anim["channels"] = [{"sampler": 0, "target": {"node": i, "path": "rotation"}} for i in range(30)]
    doc["animations"] = [{**anim, "name": f"walk{k}"} for k in range(5000)]
    path = gltf_file(tmp_path / "many.glb", doc, blob)
    with limits(seconds=10), pytest.warns(mocycle.errors.DefaultTake) as caught:
        motion = read_gltf(path)
    assert motion.n_frames == 31 and motion.frame_time == pytest.approx(1 / 30)
    message = str(caught[0].message)
    assert "and 4979 more: choose one" in message and len(message) < 1000
