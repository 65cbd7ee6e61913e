"""The look at an FBX file before the loader (issue 36): a deflate bomb is refused from its array headers, without
decompressing, whatever the FBX binding; a FIFO never blocks; a file name that is not UTF-8 reads; a chain of
10,000 bones reads within 10 s and a gigabyte.  Every file is written here (mocycle.datasets.fbx_files)."""

from __future__ import annotations

import os
import struct
import time
import zlib

import numpy as np
import pytest

from fuzzing import limits
from mocycle.datasets.fbx_files import Node, ObjectName, bomb_scene, chain_scene, fbx_bytes, write_fbx, zeros_stream
from mocycle.errors import MotionFileError
from mocycle.io.fbx_scan import array_budget, check_arrays, declared_bytes

pytest.importorskip("ufbx", reason="the FBX reader needs its binding (pip install 'mocycle[fbx]')")

from mocycle.io.fbx import fbx_takes, read_fbx  # noqa: E402


def test_the_zeros_stream_is_a_real_zlib_stream():
    for n in (0, 1, 65521, (1 << 24) + 5, 3 << 24):
        data = zeros_stream(n)
        out = zlib.decompress(data)
        assert len(out) == n and not any(out)


def test_declared_bytes_sums_every_array_as_decoded():
    nodes = chain_scene(3, frames=31)
    data = fbx_bytes(nodes)
    # KeyTime 31 int64, KeyValueFloat 31 float32, flags 1 int32, data 4 float32, ref count 1 int32
    assert declared_bytes(data)[0] == 31 * 8 + 31 * 4 + 4 + 16 + 4
    wide = fbx_bytes(nodes, version=7500)
    assert declared_bytes(wide)[0] == declared_bytes(data)[0]
    text = fbx_bytes(nodes, binary=False)
    assert declared_bytes(text) == (4 * len(text), "the ASCII file's text")


def test_the_budget():
    assert array_budget(1000) == 256 << 20
    assert array_budget(100 << 20) == 3200 << 20
    assert array_budget(1 << 31) == 4 << 30


@pytest.mark.parametrize("version", [7400, 7500])
def test_a_deflate_bomb_is_refused_before_the_loader(tmp_path, version):
    """300 million zero doubles (2.4 GB) in a 2.3 MB file: read at 2.8 GB and 50 s before; now refused from the
    array's header in well under 10 s and 1 GB."""
    path = write_fbx(tmp_path / "bomb.fbx", bomb_scene(), version=version)
    assert path.stat().st_size < 3_000_000
    t0 = time.perf_counter()
    with limits(headroom=1 << 30, seconds=10):
        for read in (read_fbx, fbx_takes):
            with pytest.raises(MotionFileError, match=r"arrays would decode to 2,400,000,\d+ bytes or more "
                                                      r"\(the largest: Vertices at byte \d+: 300,000,000 values\)"):
                read(path)
    assert time.perf_counter() - t0 < 10


def test_a_small_bomb_in_a_big_budget_is_read(tmp_path):
    """Arrays within the budget are the loader's: a mesh of 999,999 zero doubles beside the bones reads."""
    path = write_fbx(tmp_path / "mesh.fbx", bomb_scene(999_999))
    assert read_fbx(path).skeleton.names == ("bone0", "bone1")


def test_raw_arrays_count_what_they_hold(tmp_path):
    """An uncompressed array claiming 300 million values but holding 8 bytes is damage the loader reports, not
    gigabytes: the scan counts the bytes present."""
    data = bytearray(fbx_bytes(chain_scene(3)))
    at = data.index(b"KeyAttrFlags") + len(b"KeyAttrFlags")
    assert data[at:at + 1] == b"i"
    data[at + 1:at + 5] = struct.pack("<I", 300_000_000)
    assert declared_bytes(bytes(data))[0] < 1000
    path = tmp_path / "raw.fbx"
    path.write_bytes(bytes(data))
    with limits(headroom=1 << 30, seconds=10):
        try:
            read_fbx(path)
        except MotionFileError:
            pass


@pytest.mark.parametrize("damage", ["end past the file", "end before the record", "property past the record",
                                    "closing record misplaced"])
def test_records_that_do_not_fit_together_are_refused(tmp_path, damage):
    data = bytearray(fbx_bytes(chain_scene(3)))
    objects = data.index(b"Objects") - 13
    end = struct.unpack_from("<I", data, objects)[0]
    if damage == "end past the file":
        struct.pack_into("<I", data, objects, len(data) + 100)
    elif damage == "end before the record":
        struct.pack_into("<I", data, objects, objects + 3)
    elif damage == "property past the record":
        at = data.index(b"KeyTime") + len(b"KeyTime") + 1  # the array header after the type code
        struct.pack_into("<I", data, at + 8, 10**6)  # compressedLength
    else:
        struct.pack_into("<I", data, end - 13, 99)  # Objects' closing record is no longer one
    with pytest.raises(MotionFileError, match="not a readable FBX file"):
        check_arrays(bytes(data), "x.fbx")


def test_the_scan_never_raises_anything_else():
    rng = np.random.default_rng(0)
    base = fbx_bytes(chain_scene(3))
    for _ in range(3000):
        data = bytearray(base)
        for _ in range(rng.integers(1, 6)):
            pos = int(rng.integers(0, len(data)))
            data[pos:pos + 4] = rng.bytes(4)
        try:
            check_arrays(bytes(data[: int(rng.integers(20, len(data) + 1))]), "x.fbx")
        except MotionFileError:
            pass


def test_ten_thousand_bones_read_within_ten_seconds_and_a_gigabyte(tmp_path):
    """An FBX chain of 10,000 bones took 22 s and 2.0 GB when ancestors were listed per node."""
    path = write_fbx(tmp_path / "chain.fbx", chain_scene(10_000))
    t0 = time.perf_counter()
    with limits(headroom=1 << 30, seconds=10):
        motion = read_fbx(path)
    assert motion.n_joints == 9_999 and motion.n_frames == 31
    assert time.perf_counter() - t0 < 10


@pytest.mark.parametrize("binary", [True, False])
def test_a_file_name_that_is_not_utf8_reads(tmp_path, binary):
    folder = os.fsencode(tmp_path)
    name = folder + b"/bad\xffname.fbx"
    with open(name, "wb") as fh:
        fh.write(fbx_bytes(chain_scene(3, names=["hips", "knee", "foot"]), binary))
    path = os.fsdecode(name)
    assert read_fbx(path).skeleton.names == ("hips", "knee")
    assert fbx_takes(path) == ["walk"]


def test_a_fifo_a_folder_and_a_missing_file_never_block(tmp_path):
    os.mkfifo(tmp_path / "pipe.fbx")
    (tmp_path / "folder.fbx").mkdir()
    with limits(seconds=10):
        with pytest.raises(MotionFileError, match="a named pipe, not a regular file"):
            read_fbx(tmp_path / "pipe.fbx")
        with pytest.raises(MotionFileError, match="folder"):
            read_fbx(tmp_path / "folder.fbx")
        with pytest.raises(MotionFileError, match="cannot read"):
            read_fbx(tmp_path / "missing.fbx")


def test_names_of_any_kind_in_a_binary_file(tmp_path):
    names = ["mixamorig:Hips", "{", "}", "a b", "\udcff"]
    path = write_fbx(tmp_path / "odd.fbx", chain_scene(5, names=names))
    motion = read_fbx(path)
    assert len(motion.skeleton.names) == 4  # names as the binding gives them; the writers make them safe
    mesh = Node("Model", (77, ObjectName("Model", "x"), "Mesh"))
    assert read_fbx(write_fbx(tmp_path / "m.fbx", chain_scene(3, extra=[mesh]))).n_joints == 2
