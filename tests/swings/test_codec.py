import numpy as np
import pytest

from conftest import shared_path
from mocycle.datasets import synthetic_walk
from mocycle.errors import MotionFileError
from mocycle.io import read
from mocycle.io.mosw import MAGIC
from mocycle.swings import decode, encode, geodesic_errors, playback, read_swings, segment, size_report, write_swings


@pytest.fixture(scope="module")
def walk():
    m = synthetic_walk(n_frames=300, fps=60, seed=4).motion
    return m, segment(m)


def test_round_trip_plays_back_the_same_motion(walk):
    m, seg = walk
    back = decode(encode(seg))
    assert back.n_frames == seg.n_frames and back.frame_time == pytest.approx(seg.frame_time)
    assert back.skeleton.same_as(seg.skeleton) and back.joints == seg.joints
    assert len(back.swings) == len(seg.swings) and len(back.holds) == len(seg.holds)
    a, b = playback(seg), playback(back)
    assert geodesic_errors(a, b).max() < 0.05  # quantisation only (degrees)
    assert np.abs(a.translations - b.translations).max() < 1e-3


def test_sizes_against_bvh_and_raw_channels(walk):
    m, seg = walk
    r = size_report(seg, m)
    assert r["compressed_bytes"] == len(encode(seg))
    assert r["raw_float32_bytes"] == m.n_frames * m.skeleton.n_channels * 4
    assert 0 < r["payload_bytes"] < r["compressed_bytes"]
    assert r["ratio_raw"] < 0.25 and r["ratio_bvh"] < r["ratio_raw"]


def test_file_write_read(tmp_path, walk):
    _, seg = walk
    p = write_swings(seg, tmp_path / "walk.mosw")
    assert p.read_bytes().startswith(MAGIC)
    assert read_swings(p).swings[0].joint == seg.swings[0].joint
    assert [x.name for x in tmp_path.iterdir()] == ["walk.mosw"]  # no temporary left behind


@pytest.mark.parametrize("data, word", [(b"BVH", "MOSW"), (b"MOSW\x07xx", "version"), (b"MOSW\x01garbage", "damaged")])
def test_bad_files_raise_one_clear_error(data, word):
    with pytest.raises(MotionFileError, match=word):
        decode(data)


def test_truncated_payload(walk):
    import zlib

    _, seg = walk
    raw = zlib.decompress(encode(seg)[5:])
    with pytest.raises(MotionFileError, match="truncated"):
        decode(MAGIC + zlib.compress(raw[: len(raw) // 2]))


def test_missing_file(tmp_path):
    with pytest.raises(MotionFileError, match="cannot read"):
        read_swings(tmp_path / "none.mosw")


def test_real_bandai_run_is_a_quarter_of_the_raw_channels_or_less():
    m = read(shared_path("bandai", "dataset-1_run_normal_001.bvh"))
    r = size_report(segment(m), m)
    assert r["ratio_raw"] <= 0.25
