"""Fuzzing the swings JSON reader (``mocycle.read("x.json")``, ``Segmentation.from_dict``): a damaged
document gives one MotionFileError naming the file, or swings that play back a finite take.

Documents are damaged field by field (absurd values of every JSON type, huge and negative counts, missing
keys) and byte by byte; every example runs under a memory and a time limit (``fuzzing.limits``).
"""

from __future__ import annotations

import copy
import json
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import mocycle
from fuzzing import fuzz_settings, limits, mutated
from mocycle.datasets import synthetic_walk
from mocycle.errors import MotionFileError
from mocycle.io.swings_json import segmentation_from_dict, swings_document
from mocycle.swings import playback, segment

SEG = segment(synthetic_walk(n_frames=90, fps=30, seed=2).motion)
DOC = swings_document(SEG)
TEXT = json.dumps(DOC).encode()
FUZZ = fuzz_settings(150)
ODD = [None, True, False, -1, 0, 1, 2, 10**9, 2**31, 2**63, -(2**63), 10**400, 1e308, -1e308, 0.5, -0.5, 1e-320,
       "", "x", "3", [], {}, [0.0], [0.0, 0.0, 0.0], [[0.0, 0.0, 0.0]], [1e308, 1e308, 1e308], {"0": {}}]


def _paths(node, prefix=()):
    """Paths to every field of the document (the first 3 items of each list)."""
    yield prefix
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node[:3]):
            yield from _paths(v, prefix + (i,))


PATHS = [p for p in _paths(DOC) if p]


def read_bytes(data: bytes):
    """``mocycle.read`` of ``data`` saved as a .json file."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "x.json"
        path.write_bytes(data)
        return mocycle.read(path)


def check(data: bytes):
    """The file reads and plays back a finite take, or gives one MotionFileError naming the file."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.json"
        path.write_bytes(data)
        with limits(), warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)  # numpy noise is a bug too
            try:
                seg = mocycle.read(path)
            except MotionFileError as exc:
                assert str(exc).startswith(str(path) + ": "), str(exc)
                return None
            motion = playback(seg)
    assert motion.n_frames == seg.n_frames
    assert np.all(np.isfinite(motion.rotations)) and np.all(np.isfinite(motion.translations))
    return seg


@st.composite
def edited_document(draw) -> bytes:
    doc = copy.deepcopy(DOC)
    for _ in range(draw(st.integers(1, 4))):
        path = draw(st.sampled_from(PATHS))
        node = doc
        try:
            for key in path[:-1]:
                node = node[key]
            if draw(st.integers(0, 4)) == 0 and isinstance(node, dict):
                node.pop(path[-1], None)
            else:
                node[path[-1]] = copy.deepcopy(draw(st.sampled_from(ODD)))
        except (KeyError, IndexError, TypeError):  # an earlier edit changed the way there
            pass
    return json.dumps(doc).encode()


def test_document_reads_back():
    seg = check(TEXT)
    assert seg is not None and seg.swings == SEG.swings and seg.holds == SEG.holds


@FUZZ
@given(edited_document())
def test_damaged_fields(data):
    check(data)


@FUZZ
@given(mutated(TEXT, max_edits=8))
def test_damaged_bytes(data):
    check(data)


@pytest.mark.parametrize("field, value, message", [
    ("frames", 10**9, "frames"),  # would play back (1e9, J, 4) quaternions
    ("frames", 2**63, "frames"),
    ("frame_time", 0.0, "frame time"),
])
def test_absurd_sizes_are_refused_before_playback(field, value, message):
    doc = copy.deepcopy(DOC)
    doc[field] = value
    with limits(), pytest.raises(MotionFileError, match=message):
        read_bytes(json.dumps(doc).encode())


def test_swing_past_the_take_and_bad_axis_are_refused():
    doc = copy.deepcopy(DOC)
    doc["swings"][0]["end"] = 10**9
    with pytest.raises(MotionFileError, match="outside the take"):
        segmentation_from_dict(doc)
    doc = copy.deepcopy(DOC)
    doc["swings"][0]["axis"] = [0.0, 0.0, 0.0]
    with pytest.raises(MotionFileError, match="axis is not a unit vector"):
        segmentation_from_dict(doc)


def test_deep_nesting_and_nan_constants_are_refused():
    with pytest.raises(MotionFileError, match="not a JSON file"):
        read_bytes(b"[" * 100_000 + b"]" * 100_000)
    with pytest.raises(MotionFileError, match="not a JSON file"):
        read_bytes(TEXT.replace(b'"threshold": 0.4', b'"threshold": NaN'))
