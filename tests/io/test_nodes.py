"""What the glTF and FBX readers share in ``mocycle.io._nodes``: the take read by default, the frames' times."""

import warnings

import numpy as np
import pytest

from mocycle.errors import DefaultTake, MotionFileError
from mocycle.io._nodes import default_take, frame_times, key_rate


def test_default_take_is_the_first_that_moves():
    looked = []

    def moves(k):
        looked.append(k)
        return k in (1, 2)

    with pytest.warns(DefaultTake, match=r"f.glb: read take 'walk' \(the first that moves the skeleton\); the file "
                                         r"also holds 'Take 001' \(still\), 'run': choose one with option 'take'"):
        assert default_take(["Take 001", "walk", "run"], moves, "f.glb", "animation") == 1
    assert looked == [0, 1]  # the takes after the one read are not looked at


def test_default_take_when_none_moves():
    """The first is read, and every other take is said to be still (each was looked at)."""
    with pytest.warns(DefaultTake, match=r"read take 'a' \(the first: no take moves the skeleton\); the file also "
                                         r"holds 'b' \(still\), 'c' \(still\)"):
        assert default_take(["a", "b", "c"], lambda k: False, "f.fbx", "take") == 0


def test_one_take_no_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert default_take(["only"], lambda k: False, "f.fbx", "take") == 0


def test_frame_times():
    assert np.allclose(frame_times(0.5, 1.5, 30.0, 3, "f.glb"), 0.5 + np.arange(31) / 30.0)
    assert np.array_equal(frame_times(0.0, 0.0, 30.0, 3, "f.glb"), [0.0])
    with pytest.raises(MotionFileError, match="the animation spans"):
        frame_times(0.0, 1e12, 30.0, 3, "f.glb")
    with pytest.raises(MotionFileError):
        frame_times(0.0, 1.0, 1e9, 3, "f.glb")  # a frame time mocycle does not read


def test_key_rate():
    assert key_rate(1 / 30) == 30.0
    assert key_rate(1 / 29.97) == pytest.approx(29.97)
    assert key_rate(0.5) is None  # two keys a second: authored keys, not frames
    assert key_rate(None) is None
