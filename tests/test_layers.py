"""The layers hold: io reads and writes files and imports no algorithm; the records the swings files hold
sit below both the swings algorithms and the codecs; Motion keeps derived values through its public cache."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from mocycle.datasets import synthetic_walk

ALGORITHMS = ("mocycle.keyframes", "mocycle.swings", "mocycle.cycle", "mocycle.phase", "mocycle.warp",
              "mocycle.contacts", "mocycle.features", "mocycle.tasks")


def _loaded_after(code: str) -> list[str]:
    """The mocycle modules a fresh interpreter has loaded after running ``code``."""
    script = f"{code}\nimport json, sys\nprint(json.dumps(sorted(m for m in sys.modules if m.startswith('mocycle'))))"
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.splitlines()[-1])


def test_io_codecs_import_no_algorithm():
    loaded = _loaded_after("import mocycle.io.mck, mocycle.io.mosw, mocycle.io.swings_json")
    assert "mocycle.segmentation" in loaded
    assert not [m for m in loaded if m.startswith(ALGORITHMS)], loaded


def test_swings_records_import_neither_swings_nor_codecs():
    loaded = _loaded_after("import mocycle.segmentation")
    assert not [m for m in loaded if m.startswith(("mocycle.swings", "mocycle.io.mosw", "mocycle.io.swings_json"))]


def test_the_keyframe_codec_names_no_algorithm():
    import mocycle.io.mck as mck
    from mocycle.swings import Segmentation, segment
    from mocycle.swings.segment import Segmentation as SegmentationToo

    for name in ("Compressed", "compress", "read_compressed", "decompress"):
        assert not hasattr(mck, name), name  # the take and its algorithm are mocycle.keyframes'
    assert Segmentation is SegmentationToo and segment.__module__ == "mocycle.swings.segment"


def test_a_keyframe_file_is_read_above_io(tmp_path):
    import mocycle
    from mocycle.errors import MotionFileError
    from mocycle.io import read
    from mocycle.keyframes import Compressed, compress

    path = mocycle.write(compress(synthetic_walk(n_frames=60).motion, count=4), tmp_path / "a.mck")
    assert isinstance(mocycle.read(path), Compressed)
    with pytest.raises(MotionFileError, match="mocycle.read"):
        read(path)


def test_a_read_segmentation_writes_back_in_a_fresh_process(tmp_path):
    from mocycle import write
    from mocycle.swings import segment

    path = write(segment(synthetic_walk(n_frames=120, fps=60).motion), tmp_path / "a.mosw")
    code = f"import mocycle; mocycle.write(mocycle.read({str(path)!r}), {str(tmp_path / 'b.mosw')!r})"
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).returncode == 0


def test_motion_cache_makes_once_and_hand_over_drops_it():
    walk = synthetic_walk(n_frames=60).motion
    calls = []

    def make(m):
        calls.append(m)
        return np.arange(3)

    assert walk.cache("three") is None
    first = walk.cache("three", make)
    assert walk.cache("three", make) is first and calls == [walk]
    walk.hand_over()
    assert walk.cache("three") is None  # the derived values went with the arrays
    with pytest.raises(AttributeError):
        walk.rotations  # noqa: B018
