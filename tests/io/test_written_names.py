"""Names from files round-trip through every writer (issue 36): a name a format cannot hold (a lone surrogate such
as a glTF's ``"\\ud800"``, ``{`` or ``}`` in BVH, a line break) is replaced, said once, and the file reads back."""

from __future__ import annotations

import dataclasses
import warnings

import pytest
from typer.testing import CliRunner

import mocycle
from mocycle.datasets import synthetic_walk
from mocycle.datasets.gltf_files import chain_document, gltf_file
from mocycle.errors import MocycleWarning
from mocycle.io.bvh import bvh_skeleton, format_bvh, parse_bvh
from mocycle.text import renamed, valid_unicode

ODD = {1: "\ud800", 2: "{", 3: "}", 4: "a b", 5: "x\udcffy", 6: "(", 7: "a{", 8: "tab\there", 9: " padded "}


def odd_walk():
    walk = synthetic_walk(n_frames=60).motion
    names = list(walk.skeleton.names)
    for j, name in ODD.items():
        names[j] = name
    return walk.replace(skeleton=dataclasses.replace(walk.skeleton, names=tuple(names)))


def written(obj, path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mocycle.write(obj, path)
    return [str(w.message) for w in caught if issubclass(w.category, MocycleWarning)]


def test_bvh_names_are_made_writable_and_read_back():
    motion = odd_walk()
    with pytest.warns(MocycleWarning, match=r"joint names changed to what BVH \(one word each\) can hold"):
        skel = bvh_skeleton(motion.skeleton)
    assert skel.names[1:10] == ("\ufffd", "(.1", ")", "a_b", "x\ufffdy", "(", "a(", "tab_here", "padded")
    assert len(set(skel.names)) == motion.n_joints
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert bvh_skeleton(skel) is skel  # nothing more to change: no warning
        again = parse_bvh(format_bvh(motion.replace(skeleton=skel)))
    assert again.skeleton.names == skel.names


@pytest.mark.parametrize("suffix", [".bvh", ".glb", ".mck", ".mosw", ".json"])
def test_every_writer_writes_odd_names_once_warned(tmp_path, suffix):
    motion = odd_walk()
    obj = motion
    if suffix == ".mck":
        from mocycle.keyframes import compress

        obj = compress(motion, count=5)
    elif suffix in (".mosw", ".json"):
        from mocycle.swings import segment

        obj = segment(motion)
    said = written(obj, tmp_path / f"odd{suffix}")
    assert len(said) == 1 and "changed to what" in said[0], said
    back = mocycle.read(tmp_path / f"odd{suffix}")
    if suffix == ".mck":
        back = back.decompress()
    skeleton = back.skeleton
    assert skeleton.n_joints == motion.n_joints
    assert all(valid_unicode(n) == n for n in skeleton.names)
    if suffix == ".glb":  # glTF holds braces, spaces and tabs: only the lone surrogates change
        assert skeleton.names[2:5] == ("{", "}", "a b") and skeleton.names[1] == "\ufffd"


def test_renamed_is_linear_and_keeps_names_unique():
    names = ["{"] * 50_000 + ["(", "(.1"]
    with pytest.warns(MocycleWarning, match="50000 joint names changed"):
        out = renamed(names, lambda n: n.replace("{", "("), "BVH")
    assert len(set(out)) == len(out) and out[-2:] == ["(", "(.1"] and out[0] == "(.2"


def test_the_cli_converts_a_gltf_with_a_surrogate_name(tmp_path):
    from mocycle.cli.common import app

    doc, blob = chain_document(4, names=["\ud800", "{", "}", "end"])
    path = gltf_file(tmp_path / "odd.gltf", doc, blob)
    for out in ("odd.bvh", "odd.glb"):
        done = CliRunner().invoke(app, ["convert", str(path), str(tmp_path / out)])
        assert done.exit_code == 0, done.output
        assert "Traceback" not in done.output and done.output.count("changed to what") == 1, done.output
        assert mocycle.read(tmp_path / out).n_joints == 3
