"""Results keep their own numbers, not their inputs: small enough to pickle and ship (e.g. to dask workers).

Each result is pickled with a pickler that notes every object it meets: no input ``Motion`` may be
inside, and the pickle may be at most a small multiple of the bytes of the numbers it holds (its arrays,
and 8 bytes per number field of its records such as swings) plus a fixed allowance for the skeleton's
names and offsets.
"""

import dataclasses
import pickle
import warnings

import numpy as np
import pytest

from mocycle.cycle import blend_cycles, extract_cycle, transition
from mocycle.datasets import synthetic_walk
from mocycle.keyframes import compress
from mocycle.motion import Motion
from mocycle.phase import find_phase
from mocycle.swings import segment
from mocycle.warp import stretch_motion

SLACK = 1.5            # pickle bytes per array byte
FIXED = 24_000         # skeleton names, offsets, channels and small fields


def _numbers(value) -> int:
    if isinstance(value, (bool, str)):
        return 0
    if isinstance(value, (int, float)):
        return 1
    if isinstance(value, tuple):
        return sum(_numbers(v) for v in value)
    return 0


class _Census(pickle.Pickler):
    """A pickler that counts the bytes of the numbers it writes and keeps every Motion it meets."""

    def __init__(self, file):
        super().__init__(file, protocol=pickle.HIGHEST_PROTOCOL)
        self.array_bytes = 0
        self.motions = []

    def reducer_override(self, obj):
        if isinstance(obj, np.ndarray):
            self.array_bytes += obj.nbytes
        elif isinstance(obj, Motion):
            self.motions.append(obj)
        elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
            self.array_bytes += 8 * sum(_numbers(getattr(obj, f.name)) for f in dataclasses.fields(obj))
        return NotImplemented


def census(obj):
    import io

    buf = io.BytesIO()
    c = _Census(buf)
    c.dump(obj)
    return len(buf.getvalue()), c.array_bytes, c.motions


@pytest.fixture(scope="module")
def walk():
    return synthetic_walk(n_frames=360, fps=60, period_s=1.0, noise_deg=1.0, seed=0).motion


@pytest.fixture(scope="module")
def other():
    return synthetic_walk(n_frames=360, fps=60, period_s=0.8, phase0=0.3, seed=1).motion


def _assert_small(obj, allowed_motions=()):
    size, arrays, motions = census(obj)
    assert [id(m) for m in motions] == [id(m) for m in allowed_motions], \
        f"{type(obj).__name__} keeps {len(motions)} Motion object(s)"
    assert size <= SLACK * arrays + FIXED, f"{type(obj).__name__}: {size} bytes pickled for {arrays} array bytes"
    return size


def test_phase_result_keeps_no_features_or_estimator(walk):
    result = find_phase(walk)
    assert result.features is None and not hasattr(result, "estimator")
    size = _assert_small(result)
    assert size < 0.05 * len(pickle.dumps(walk))
    kept = find_phase(walk, keep_features=True)
    assert kept.features.shape[0] == walk.n_frames - 2  # delay 2


@pytest.mark.parametrize("method", ["harmonic", "centroid", "cut"])
def test_cycle_keeps_what_decoding_needs_not_the_input(walk, method):
    cycle = extract_cycle(walk, method=method)
    size = _assert_small(cycle)
    assert size < 0.75 * len(pickle.dumps(walk))  # less than the input's rotations alone (a take stores no
    # per-frame translations for joints that stand still)
    again = pickle.loads(pickle.dumps(cycle))
    assert np.allclose(again.motion("motion").world_positions(), cycle.motion("motion").world_positions())
    assert again.space.skeleton.same_as(walk.skeleton) and again.space.frame_time == walk.frame_time
    assert np.array_equal(again.space.static_translations, walk.translations[0])


def test_blend_and_transition(walk, other):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        blend = blend_cycles([walk, other], [0.5, 0.5])
        tr = transition(walk, other, cycles=2)
    _assert_small(blend)
    _assert_small(tr, allowed_motions=(tr.motion,))  # its output, not an input


def test_stretch_swings_and_keyframes(walk):
    _, report = stretch_motion(walk, factor=1.5)
    _assert_small(report)
    _assert_small(segment(walk))
    _assert_small(compress(walk, count=12))


def test_results_are_built_with_keywords(walk):
    cycle = extract_cycle(walk)
    with pytest.raises(TypeError):
        type(cycle)(cycle.space, cycle.P, cycle.L)
    with pytest.raises(TypeError):
        type(cycle.space)(walk.skeleton, walk.frame_time)
