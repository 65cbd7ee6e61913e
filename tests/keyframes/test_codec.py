import numpy as np
import pytest

from helpers import max_angle
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError, MotionFileError
from mocycle.keyframes import Compressed, compress, error_per_frame_per_joint, read_compressed


@pytest.fixture(scope="module")
def walk():
    return synthetic_walk(n_frames=300, fps=60, seed=1).motion


@pytest.mark.parametrize("kw", [{"scheme": "slerp"}, {"scheme": "hermite", "select": "scs"},
                                {"scheme": "spatial", "projection": "mds", "optimize": True},
                                {"scheme": "spatial", "projection": "rbfp", "select": "rols"}])
def test_round_trip_keeps_keyframes_exactly(walk, kw, tmp_path):
    packed = compress(walk, ratio=0.03, **kw)
    path = packed.save(tmp_path / "w.mck")
    back = read_compressed(path)
    a, b = packed.decompress(), back.decompress()
    k = back.key_idx
    assert np.array_equal(k, packed.key_idx) and len(k) == 9
    assert max_angle(b.rotations[k], walk.rotations[k]) < 1e-12
    assert np.array_equal(b.translations[k], walk.translations[k])
    assert max_angle(a.rotations, b.rotations) < 1e-9  # the file rebuilds what compress rebuilt
    assert np.abs(b.translations - walk.translations).max() < 1e-4  # float32 track
    assert b.skeleton.same_as(walk.skeleton) and b.frame_time == walk.frame_time


def test_spatial_beats_slerp_on_a_periodic_walk(walk):
    # at the thesis' 3 % (under 2 keys per gait cycle), where slerp aliases and the 2-D trajectory does not
    slerp = error_per_frame_per_joint(walk, compress(walk, ratio=0.03, scheme="slerp").decompress())
    spatial = error_per_frame_per_joint(walk, compress(walk, ratio=0.03, scheme="spatial", projection="mds",
                                                       optimize=True).decompress())
    assert spatial < 0.5 * slerp


def test_size_report_formulas(walk):
    for scheme, extra in (("slerp", 3), ("spatial", 5)):
        packed = compress(walk, count=9, scheme=scheme)
        rep = packed.size_report()
        dof, r = 22, 9 / 300
        assert rep["formula_ratio"] == pytest.approx((r * (3 * dof + 1) + extra) / (3 * dof + 3))
        assert rep["compressed_bytes"] == len(packed.to_bytes()) < rep["bvh_bytes"] / 5


def test_damaged_files(walk, tmp_path):
    data = compress(walk).to_bytes()
    with pytest.raises(MotionFileError, match="damaged.*truncated"):
        Compressed.from_bytes(data[:-40])
    with pytest.raises(MotionFileError, match="not a mocycle keyframe file"):
        Compressed.from_bytes(b"BVH" + data)
    with pytest.raises(MotionFileError, match="cannot read"):
        read_compressed(tmp_path / "missing.mck")


def test_bad_options(walk):
    for kw, msg in (({"scheme": "cubic"}, "scheme must be"), ({"select": "best"}, "select must be one of"),
                    ({"scheme": "spatial", "projection": "umap"}, "projection must be"),
                    ({"ratio": 2.0}, r"ratio must be a number in \(0, 1\]"), ({"seed": "lamp"}, "seed must be one of")):
        with pytest.raises(MocycleError, match=msg):
            compress(walk, **kw)


def test_real_walk_spatial_beats_slerp():
    from conftest import shared_path
    from mocycle.io import read

    m = read(shared_path("cmu-iclone", "07_12.bvh"))
    slerp = error_per_frame_per_joint(m, compress(m, scheme="slerp").decompress())
    spatial = error_per_frame_per_joint(m, compress(m, scheme="spatial", projection="tsne",
                                                   optimize=True).decompress())
    assert spatial < 0.8 * slerp  # 0.199 vs 0.298
