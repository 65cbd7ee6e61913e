"""ChannelConverter: a take's channel rows converted a chunk at a time are the take converted whole, bit for bit."""

import numpy as np
import pytest

from helpers import random_motion
from mocycle.io import bvh_channels
from mocycle.io.bvh import motion_channels
from mocycle.io.bvh_channels import ChannelConverter


def _arrays(skel, values, cuts):
    conv = ChannelConverter(skel, len(values))
    for a, b in zip([0, *cuts], [*cuts, len(values)], strict=True):
        assert conv.add(values[a:b])
    return conv.arrays()


def _assert_same(x, y):
    (qa, sa, ta), (qb, sb, tb) = x, y
    assert qa.tobytes() == qb.tobytes() and sa.tobytes() == sb.tobytes()
    assert list(ta) == list(tb) and all(ta[j].tobytes() == tb[j].tobytes() for j in ta)


def _spun_channels(n=300):
    m = random_motion(n, spin=True)
    values = motion_channels(m)
    rng = np.random.default_rng(3)
    rot = [k for k, c in enumerate(c for chans in m.skeleton.channels for c in chans) if "rotation" in c]
    for frame in rng.choice(n, 40, replace=False):  # a whole turn more: the quaternion's sign flips
        values[frame, rng.choice(rot)] += 360.0
    for frame in rng.choice(n, 8, replace=False):  # and stays flipped from there on
        values[frame:, rng.choice(rot)] += 360.0
    return m.skeleton, values


@pytest.mark.parametrize("seed", range(4))
def test_chunks_of_any_size_and_order_make_the_same_arrays(seed):
    skel, values = _spun_channels()
    whole = _arrays(skel, values, [])
    cuts = sorted(np.random.default_rng(seed).choice(np.arange(1, len(values)), 6, replace=False).tolist())
    _assert_same(_arrays(skel, values, cuts), whole)
    _assert_same(_arrays(skel, np.asfortranarray(values), cuts), whole)  # a column-major parser's chunks


@pytest.mark.parametrize("seed", range(3))
def test_chunks_converted_at_once_in_threads_then_committed_in_order_make_the_same_arrays(seed):
    from concurrent.futures import ThreadPoolExecutor

    skel, values = _spun_channels()
    whole = _arrays(skel, values, [])
    rng = np.random.default_rng(seed)
    cuts = sorted(rng.choice(np.arange(1, len(values)), 8, replace=False).tolist())
    spans = list(zip([0, *cuts], [*cuts, len(values)], strict=True))
    conv = ChannelConverter(skel, len(values))
    order = rng.permutation(len(spans))  # converted in any order, several at once
    with ThreadPoolExecutor(3) as pool:
        futures = {k: pool.submit(conv.convert, spans[k][0], values[slice(*spans[k])]) for k in order}
        converted = [futures[k].result() for k in range(len(spans))]
    assert not conv.commit(spans[1][0], values[slice(*spans[1])], converted[1])  # not the next rows
    for (a, b), done in zip(spans, converted, strict=True):
        assert conv.commit(a, values[a:b], done)
    _assert_same(conv.arrays(), whole)


def test_rows_past_the_frame_count_are_not_converted():
    skel, values = _spun_channels()
    conv = ChannelConverter(skel, 200)
    assert conv.convert(150, values[:100]) is None and conv.convert(100, values[:100]) is not None


@pytest.mark.parametrize("block", [1, 7, None])
def test_block_size_does_not_change_the_arrays(monkeypatch, block):
    skel, values = _spun_channels()
    whole = _arrays(skel, values, [])
    monkeypatch.setattr(bvh_channels, "BLOCK_FRAMES", block)
    _assert_same(_arrays(skel, values, [50, 51, 200]), whole)


def _standing_root(values, x=0.0):
    """The root's position channels (the first three) constant: ``(x, 90, -3)``."""
    values[:, :3] = (x, 90.0, -3.0)
    return values


def test_a_position_channel_that_starts_changing_late_gets_its_whole_track():
    skel, values = _spun_channels()
    _standing_root(values, 12.5)
    values[250:, 0] = np.linspace(12.5, 40.0, len(values) - 250)  # the root's X: moving from frame 250
    arrays = _arrays(skel, values, [100, 200, 260])
    quats, static, tracks = arrays
    assert list(tracks) == [0] and tracks[0].tobytes() == np.ascontiguousarray(values[:, :3]).tobytes()
    _assert_same(arrays, _arrays(skel, values, []))
    _standing_root(values, 12.5)
    quats, static, tracks = _arrays(skel, values, [100, 200, 260])
    assert tracks == {} and static[0].tolist() == [12.5, 90.0, -3.0]


def test_zeros_of_both_signs_before_a_late_change_need_the_take_whole():
    """A channel at 0.0 that holds -0.0 in an early chunk and changes in a later one cannot be rebuilt bit for
    bit from the first row: add refuses (the reader then converts the take in one chunk, which can)."""
    skel, values = _spun_channels()
    _standing_root(values)
    values[10:20, 0] = -0.0
    values[250:, 0] = np.linspace(0.0, 3.0, len(values) - 250)
    conv = ChannelConverter(skel, len(values))
    assert conv.add(values[:100]) and conv.add(values[100:200])
    assert not conv.add(values[200:])
    quats, static, tracks = _arrays(skel, values, [])
    assert tracks[0][:, 0].tobytes() == values[:, 0].tobytes()
    values[10:20, 0] = 0.0  # one sign only: chunks are fine
    _assert_same(_arrays(skel, values, [100, 200]), _arrays(skel, values, []))


def test_a_first_row_of_negative_zero_needs_every_later_zero_negative():
    """The same with the signs the other way round: the first row holds -0.0, an early chunk also +0.0."""
    skel, values = _spun_channels()
    _standing_root(values, -0.0)
    values[250:, 0] = np.linspace(1.0, 3.0, len(values) - 250)
    # every zero before the change negative, as the first row's: chunks are fine
    _assert_same(_arrays(skel, values, [100, 200]), _arrays(skel, values, []))
    values[120:130, 0] = 0.0
    conv = ChannelConverter(skel, len(values))
    assert conv.add(values[:100]) and conv.add(values[100:200])
    assert not conv.add(values[200:])
    quats, static, tracks = _arrays(skel, values, [])
    assert tracks[0][:, 0].tobytes() == values[:, 0].tobytes()


def test_constant_zeros_of_both_signs_stay_one_constant_as_before():
    skel, values = _spun_channels()
    _standing_root(values)
    values[10:20, 0] = -0.0  # == 0.0: the channel never changes
    for cuts in ([], [100, 200]):
        quats, static, tracks = _arrays(skel, values, cuts)
        assert tracks == {} and static[0].tolist() == [0.0, 90.0, -3.0]


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf, 1e31])
def test_a_value_not_finite_or_too_large_is_refused(bad):
    skel, values = _spun_channels()
    values[123, 4] = bad
    conv = ChannelConverter(skel, len(values))
    assert conv.add(values[:100])
    assert not conv.add(values[100:])


def test_more_rows_than_allocated_are_refused_and_fewer_are_trimmed():
    skel, values = _spun_channels()
    conv = ChannelConverter(skel, 200)
    assert not conv.add(values)
    conv = ChannelConverter(skel, 400)
    assert conv.add(values)
    quats, static, tracks = conv.arrays()
    assert quats.shape[0] == 300 and quats.base is None and all(t.shape == (300, 3) for t in tracks.values())
    _assert_same((quats, static, tracks), _arrays(skel, values, []))
