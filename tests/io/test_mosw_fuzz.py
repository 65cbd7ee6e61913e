"""Fuzzing the ``.mosw`` reader: damaged files give a MotionFileError naming the file, or swings that play back.

Files are damaged inside the compressed payload (re-compressed) and in their raw bytes, and given absurd
counts; every example runs under a memory and a time limit (``fuzzing.limits``).
"""

from __future__ import annotations

import struct
import warnings
import zlib

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fuzzing import INTERESTING, fuzz_settings, limits, mutated, mutated_zlib_file, zlib_file
from mocycle.datasets import synthetic_walk
from mocycle.errors import MotionFileError
from mocycle.io.mosw import MAGIC
from mocycle.swings import decode, encode, playback, segment

WALK = synthetic_walk(n_frames=90, fps=30, seed=2).motion
SEG = segment(WALK)
FILE = encode(SEG)
PAYLOAD = zlib.decompress(FILE[len(MAGIC):])
(N_TEXT,) = struct.unpack("<I", PAYLOAD[:4])
BODY_START = 4 + N_TEXT  # frames, frame time, threshold, window, then the arrays
FUZZ = fuzz_settings(120)


def check(data: bytes):
    """The file decodes and plays back a finite take, or gives one MotionFileError naming the file."""
    with limits(), warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # numpy noise is a bug too
        try:
            seg = decode(data, path="fuzz.mosw")
        except MotionFileError as exc:
            assert str(exc).startswith("fuzz.mosw: "), str(exc)
            return None
        motion = playback(seg)
    assert motion.n_frames == seg.n_frames
    assert np.all(np.isfinite(motion.rotations)) and np.all(np.isfinite(motion.translations))
    return seg


def test_file_reads_back():
    seg = check(FILE)
    assert seg is not None and seg.n_swings == SEG.n_swings


@FUZZ
@given(mutated_zlib_file(MAGIC, PAYLOAD))
def test_damaged_files(data):
    check(data)


@FUZZ
@given(st.data())
def test_damaged_body(data):
    """The skeleton intact, the counts and arrays damaged (same size: the values, not the framing)."""
    body = data.draw(mutated(PAYLOAD[BODY_START:], max_edits=12, same_size=data.draw(st.booleans())))
    check(zlib_file(MAGIC, PAYLOAD[:BODY_START] + body))


@FUZZ
@given(st.integers(0, (len(PAYLOAD) - BODY_START) // 4), st.sampled_from([c for c in INTERESTING if len(c) == 4]))
def test_absurd_counts(word, value):
    body = bytearray(PAYLOAD[BODY_START:])
    body[4 * word: 4 * word + 4] = value
    check(zlib_file(MAGIC, PAYLOAD[:BODY_START] + bytes(body)))


@pytest.mark.parametrize("frames", [10**9, 2**32 - 1])
def test_frame_count_is_checked_before_playback(frames):
    body = struct.pack("<I", frames) + PAYLOAD[BODY_START + 4:]
    with limits(), pytest.raises(MotionFileError, match="fuzz.mosw: .*frames"):
        decode(zlib_file(MAGIC, PAYLOAD[:BODY_START] + body), "fuzz.mosw")


def test_zlib_bomb_is_refused_without_expanding():
    z = zlib.compressobj(9)
    bomb = MAGIC + z.compress(PAYLOAD) + z.compress(bytes(64 << 20)) + z.flush()
    assert len(bomb) < 1 << 20
    with limits(headroom=32 << 20), pytest.raises(MotionFileError, match="more data than its header"):
        decode(bomb, "fuzz.mosw")
