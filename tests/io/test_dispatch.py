"""mocycle.read / mocycle.write: one way in and out for every format, chosen by the suffix."""

import json
import subprocess
import sys

import numpy as np
import pytest

import mocycle
from mocycle.datasets import synthetic_walk
from mocycle.errors import MotionFileError
from mocycle.io import READ_SUFFIXES, read_motion
from mocycle.io.swings_json import swings_document
from mocycle.keyframes import Compressed, compress
from mocycle.swings import Segmentation, segment


@pytest.fixture(scope="module")
def walk():
    return synthetic_walk(n_frames=120, fps=60, seed=0).motion


def test_bvh_round_trip(tmp_path, walk):
    back = mocycle.read(mocycle.write(walk, tmp_path / "w.BVH"))
    assert back.n_frames == walk.n_frames and abs(back.frame_time - walk.frame_time) < 1e-12
    assert np.allclose(back.world_positions(), walk.world_positions(), atol=1e-4)


def test_mck_round_trip(tmp_path, walk):
    packed = compress(walk, count=6)
    back = mocycle.read(mocycle.write(packed, tmp_path / "w.mck"))
    assert isinstance(back, Compressed)
    assert np.array_equal(back.key_idx, packed.key_idx)
    assert back.decompress().n_frames == walk.n_frames


@pytest.mark.parametrize("suffix", [".mosw", ".json"])
def test_swings_round_trip(tmp_path, walk, suffix):
    seg = segment(walk)
    back = mocycle.read(mocycle.write(seg, tmp_path / f"w{suffix}"))
    assert isinstance(back, Segmentation)
    assert back.n_swings == seg.n_swings and back.n_frames == seg.n_frames


def test_swings_json_is_what_the_cli_writes(tmp_path, walk):
    seg = segment(walk)
    path = mocycle.write(seg, tmp_path / "w.json")
    assert json.loads(path.read_text()) == json.loads(json.dumps(swings_document(seg), indent=1))


def test_result_with_to_dict_written_as_json(tmp_path):
    class Result:
        def to_dict(self):
            return {"period_frames": 60.0}

    path = mocycle.write(Result(), tmp_path / "r.json")
    assert json.loads(path.read_text()) == {"period_frames": 60.0}


def test_unknown_suffix_names_file_and_known_suffixes(tmp_path):
    with pytest.raises(MotionFileError) as info:
        mocycle.read(tmp_path / "take.c3d")
    msg = str(info.value)
    assert "take.c3d" in msg and "'.c3d'" in msg
    assert all(s in msg for s in READ_SUFFIXES)


def test_folder_is_refused_clearly(tmp_path):
    with pytest.raises(MotionFileError, match="is a folder"):
        mocycle.read(tmp_path)
    with pytest.raises(MotionFileError, match="is a folder"):
        read_motion(tmp_path)


def test_write_refuses_a_suffix_that_does_not_fit(tmp_path, walk):
    with pytest.raises(MotionFileError, match="a Motion is written as .bvh"):
        mocycle.write(walk, tmp_path / "w.mck")
    with pytest.raises(MotionFileError, match="cannot write a list"):
        mocycle.write([1, 2], tmp_path / "w.json")
    with pytest.raises(MotionFileError, match="unknown file type"):
        mocycle.write(walk, tmp_path / "w.amc")  # read only
    assert not list(tmp_path.iterdir())


def test_read_motion_refuses_other_mocycle_files(tmp_path, walk):
    path = mocycle.write(segment(walk), tmp_path / "w.mosw")
    with pytest.raises(MotionFileError, match="reads motions from .bvh, .amc"):
        read_motion(path)


def test_json_that_is_not_swings_is_refused(tmp_path):
    path = tmp_path / "x.json"
    path.write_text('{"period_frames": 60}')
    with pytest.raises(MotionFileError, match="x.json: not a JSON file mocycle reads"):
        mocycle.read(path)
    path.write_text("{not json")
    with pytest.raises(MotionFileError, match="not a JSON file"):
        mocycle.read(path)


@pytest.mark.parametrize("first", ["mocycle.io.mck", "mocycle.io.mosw", "mocycle.keyframes", "mocycle.swings"])
def test_codec_modules_import_in_any_order(first):
    code = f"import {first}; from mocycle.keyframes import compress; from mocycle.swings import write_swings"
    subprocess.run([sys.executable, "-c", code], check=True)
