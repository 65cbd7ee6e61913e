"""How many keyframes a take gets (issue 11, item 9): enough for its rhythm, a floor for the spatial scheme."""

import pytest

from conftest import shared_path
from mocycle.datasets import synthetic_nonperiodic, synthetic_walk
from mocycle.errors import MocycleError, MocycleWarning
from mocycle.io import read
from mocycle.keyframes import compress, error_per_frame_per_joint, keyframe_density
from mocycle.keyframes.density import KEYS_PER_PERIOD, MIN_KEYS, SPATIAL_MIN_KEYS


def test_auto_keeps_several_keys_per_period_of_a_fast_gait():
    walk = synthetic_walk(n_frames=300, fps=30, period_s=1.1, seed=2).motion   # 33 frames per cycle at 30 fps
    d = keyframe_density(walk)
    assert abs(d.period_frames - 33) < 1.5
    assert d.keys_per_period >= KEYS_PER_PERIOD and d.rule == "rhythm"
    assert d.count > round(0.03 * 300)                       # the thesis' 3 % would be one key per 33 frames
    auto = error_per_frame_per_joint(walk, compress(walk).decompress())
    thesis = error_per_frame_per_joint(walk, compress(walk, ratio=0.03).decompress())
    assert auto < 0.5 * thesis


def test_an_explicit_ratio_that_aliases_warns_and_is_kept():
    walk = synthetic_walk(n_frames=300, fps=30, period_s=1.1, seed=2).motion
    with pytest.warns(MocycleWarning, match="per period"):
        d = keyframe_density(walk, 0.03)
    assert d.count == 9 and d.keys_per_period < KEYS_PER_PERIOD


def test_no_rhythm_gets_the_ratio_or_the_floor():
    take = synthetic_nonperiodic(n_frames=100, seed=1).motion
    d = keyframe_density(take)
    assert d.count >= MIN_KEYS
    with pytest.raises(MocycleError, match="'auto' or a number"):
        keyframe_density(take, "many")


def test_the_spatial_scheme_has_a_floor_of_keys_on_short_takes():
    take = read(shared_path("bandai", "dataset-1_dash_chimpira_001.bvh"))   # 69 frames: 3 % is 2 keys
    packed = compress(take, ratio=0.03, scheme="spatial")
    assert packed.n_keyframes == SPATIAL_MIN_KEYS
    spatial = error_per_frame_per_joint(take, packed.decompress())
    slerp = error_per_frame_per_joint(take, compress(take, ratio=0.03).decompress())
    assert spatial < slerp   # with 2 keys it was 10 times slerp's
