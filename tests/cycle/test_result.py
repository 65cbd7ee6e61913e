"""The Cycle keeps what it derives from its arrays: each motion decoded once per (count, root)."""

import collections
import pickle
from dataclasses import replace

import numpy as np
import pytest

from mocycle import tasks
from mocycle.cycle import Cycle, extract_cycle
from mocycle.datasets import synthetic_walk
from mocycle.tasks.clips import closed_loop


@pytest.fixture(scope="module")
def walk():
    return synthetic_walk(n_frames=300, fps=60, seed=4).motion


@pytest.fixture(scope="module")
def cycle(walk):
    return extract_cycle(walk)


def test_repeat_is_decoded_once_per_count_and_root(cycle):
    twice = cycle.repeat(2, root="motion")
    assert cycle.repeat(2, root="motion") is twice and cycle.repeat(np.int64(2), "motion") is twice
    assert cycle.repeat(2) is not twice and cycle.repeat(3, root="motion") is not twice
    assert cycle.motion("motion") is cycle.repeat(1, root="motion")
    assert cycle.cache(("repeat", 2, "motion")) is twice and cycle.cache("nothing kept") is None


@pytest.mark.parametrize("root", ["motion", "inplace"])
@pytest.mark.parametrize("count", [1, 2, 3])
def test_a_repeat_is_the_decoded_repeated_arrays(walk, count, root):
    """Only the travel joint's quaternions are made per repeat: the same Motion as decoding the repeated arrays."""
    cycle = extract_cycle(walk)  # its own caches
    P = np.tile(cycle.P, (count, 1))
    whole = cycle.space.decode(P, cycle._repeat_L(count, root), cycle.rotation_matrices(count))
    repeated = cycle.repeat(count, root=root)
    np.testing.assert_array_equal(repeated.rotations, whole.rotations)
    np.testing.assert_array_equal(repeated.translations, whole.translations)


def test_kept_arrays_are_read_only(cycle):
    for array in (cycle.rotation_matrices(), cycle.quaternions(), cycle.inplace_L()):
        assert not array.flags.writeable
    assert cycle.rotation_matrices(2).flags.writeable  # a new array
    with pytest.raises(ValueError):
        cycle.inplace_L()[0, 0] = 1.0


def test_a_new_cycle_has_caches_of_its_own(cycle):
    R, motion = cycle.rotation_matrices(), cycle.motion()
    moved = replace(cycle, L=cycle.L + np.array([1.0, 0.0, 0.0, 0.0]))
    assert moved.cache("rotations") is None and moved.motion() is not motion
    np.testing.assert_array_equal(moved.rotation_matrices(), R)
    rolled = cycle.rolled(5)
    assert rolled.cache("rotations") is None and rolled.motion() is not motion
    on_path = cycle.on_path(cycle.L + np.array([1.0, 0.0, 0.0, 0.0]), cycle.drift)
    assert on_path.cache("rotations") is R and on_path.cache(("repeat", 1, "inplace")) is None  # P is the same
    with pytest.raises(ValueError, match="projected"):
        replace(cycle, projected=R[:-1])


def test_pickled_without_its_caches(cycle):
    cycle.repeat(3, root="motion")
    back = pickle.loads(pickle.dumps(cycle))
    assert isinstance(back, Cycle) and back.cache(("repeat", 3, "motion")) is None
    np.testing.assert_array_equal(back.repeat(3, root="motion").rotations, cycle.repeat(3, root="motion").rotations)


@pytest.mark.parametrize("root", ["motion", "inplace"])
def test_a_loop_run_decodes_each_motion_of_a_cycle_once(walk, root, monkeypatch):
    decoded = collections.Counter()
    real = Cycle._decode

    def counting(self, count, root):
        decoded[(id(self), count, root)] += 1
        return real(self, count, root)

    monkeypatch.setattr(Cycle, "_decode", counting)
    report = tasks.loop.run(walk, tasks.loop.Options(root=root))
    closed_loop(report.result, 1, root, report.motions["loop"])  # what a .glb output adds
    assert decoded and max(decoded.values()) == 1, decoded
