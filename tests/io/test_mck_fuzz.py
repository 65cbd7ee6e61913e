"""Fuzzing the ``.mck`` reader: damaged files give a MotionFileError naming the file, or a take that rebuilds.

Files are damaged inside the compressed payload (header JSON and arrays, then re-compressed) and in their
raw bytes; every example runs under a memory and a time limit (``fuzzing.limits``).
"""

from __future__ import annotations

import json
import struct
import warnings
import zlib

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fuzzing import fuzz_settings, limits, mutated, mutated_zlib_file, zlib_file
from mocycle.datasets import synthetic_walk
from mocycle.errors import MotionFileError
from mocycle.io.mck import MAGIC
from mocycle.keyframes import Compressed, compress
from mocycle.motion import Motion

WALK = synthetic_walk(n_frames=60, fps=30, seed=3).motion
FILES = {kw: compress(WALK, count=5, **dict(kw)).to_bytes()
         for kw in ((("scheme", "slerp"),), (("scheme", "hermite"),), (("scheme", "rbf"),),
                    (("scheme", "spatial"), ("projection", "pca")))}
PAYLOADS = [zlib.decompress(data[len(MAGIC):]) for data in FILES.values()]
FUZZ = fuzz_settings(120)


def check(data: bytes) -> Motion | None:
    """The file reads and rebuilds a finite take, or gives one MotionFileError naming the file."""
    with limits(), warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # numpy noise is a bug too
        try:
            packed = Compressed.from_bytes(data, path="fuzz.mck")
        except MotionFileError as exc:
            assert str(exc).startswith("fuzz.mck: "), str(exc)
            return None
        motion = packed.decompress()
    assert np.all(np.isfinite(motion.rotations)) and np.all(np.isfinite(motion.translations))
    assert motion.n_frames == packed.n_frames
    return motion


def _split(payload: bytes) -> tuple[dict, bytes]:
    (n,) = struct.unpack("<I", payload[:4])
    return json.loads(payload[4:4 + n]), payload[4 + n:]


def _join(header: dict, arrays: bytes) -> bytes:
    text = json.dumps(header).encode()
    return zlib_file(MAGIC, struct.pack("<I", len(text)) + text + arrays)


def test_every_scheme_reads_back():
    for data in FILES.values():
        assert check(data) is not None


@FUZZ
@given(st.sampled_from(PAYLOADS).flatmap(lambda p: mutated_zlib_file(MAGIC, p)))
def test_damaged_files(data):
    check(data)


@FUZZ
@given(st.sampled_from(PAYLOADS), st.data())
def test_damaged_arrays(payload, data):
    header, arrays = _split(payload)
    check(_join(header, data.draw(mutated(arrays, max_edits=12, same_size=True))))


ABSURD = st.one_of(st.sampled_from([0, 1, -1, 2**31, 10**9, 2**64, 1e308, 0.5, None, "x", [], {}, True]),
                   st.integers(-10, 10**12))


@FUZZ
@given(st.sampled_from(PAYLOADS), st.sampled_from(["n_frames", "frame_time", "scheme", "select", "projection",
                                                   "seed", "optimized", "skeleton"]), ABSURD)
def test_absurd_header_fields(payload, key, value):
    header, arrays = _split(payload)
    header[key] = value
    check(_join(header, arrays))


@FUZZ
@given(st.sampled_from(PAYLOADS), st.data())
def test_absurd_array_shapes(payload, data):
    header, arrays = _split(payload)
    entry = data.draw(st.sampled_from(header["arrays"]))
    shape = entry[2]
    if shape:
        shape[data.draw(st.integers(0, len(shape) - 1))] = data.draw(st.sampled_from([0, 1, 3, 10**9, 2**32 + 5]))
    if data.draw(st.booleans()):
        entry[1] = data.draw(st.sampled_from(["<f8", "<u4", "|O", "<U9", "V1000000000", ">f8"]))
    if data.draw(st.booleans()):
        entry[0] = data.draw(st.sampled_from(["key_idx", "track", "points", "other", ""]))
    check(_join(header, arrays))


@pytest.mark.parametrize("frames", [10**9, 2**32, 3])
def test_header_frame_count_is_checked_before_allocating(frames):
    header, arrays = _split(PAYLOADS[0])
    header["n_frames"] = frames
    for entry in header["arrays"]:
        if entry[0] == "track":
            entry[2][0] = frames
    with limits(), pytest.raises(MotionFileError, match="fuzz.mck: "):
        Compressed.from_bytes(_join(header, arrays), "fuzz.mck")


def test_zlib_bomb_is_refused_without_expanding():
    header, arrays = _split(PAYLOADS[0])
    text = json.dumps(header).encode()
    z = zlib.compressobj(9)
    bomb = MAGIC + z.compress(struct.pack("<I", len(text)) + text + arrays) + z.compress(bytes(64 << 20)) + z.flush()
    assert len(bomb) < 1 << 20
    with limits(headroom=32 << 20), pytest.raises(MotionFileError, match="more data than its header"):
        Compressed.from_bytes(bomb, "fuzz.mck")


@pytest.mark.parametrize("value", [np.nan, np.inf, 1e300])
def test_non_finite_and_huge_values(value):
    header, arrays = _split(PAYLOADS[0])
    data = bytearray(arrays)
    data[-8:] = np.array([value]).tobytes()  # the last number of 'static'
    with pytest.raises(MotionFileError, match="fuzz.mck: .*static"):
        Compressed.from_bytes(_join(header, bytes(data)), "fuzz.mck")
