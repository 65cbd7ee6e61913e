import numpy as np
import pytest

from conftest import shared_files
from mocycle.datasets import synthetic_run, synthetic_walk
from mocycle.errors import MocycleError
from mocycle.io import write_bvh
from mocycle.swings import build_index, compare, precision_at_k, segment, signature
from mocycle.swings.search import bandai_content


def test_signature_shape_and_content():
    m = synthetic_walk(n_frames=240, fps=60, seed=0).motion
    sig = signature(segment(m), rate_hz=30)
    assert sig.n_samples == 120
    assert "LeftUpLeg" in sig.tracks and sig.tracks["LeftUpLeg"].shape == (120, 3)
    assert np.abs(sig.tracks["LeftUpLeg"]).max() > 0.5  # rad/s while swinging
    with pytest.raises(MocycleError, match="rate_hz"):
        signature(segment(m), rate_hz=0)


def test_a_shifted_copy_scores_higher_than_another_motion():
    walk = synthetic_walk(n_frames=420, fps=60, seed=0).motion
    sig = signature(segment(walk))
    shifted = signature(segment(walk[37:]))
    run = signature(segment(synthetic_run(n_frames=420, fps=60, seed=0).motion))
    self_score, _ = compare(sig, sig)
    shift_score, off = compare(shifted, sig)
    run_score, _ = compare(run, sig)
    assert self_score == pytest.approx(1.0)
    assert shift_score > 0.7 and run_score < 0.5


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("takes")
    for k in range(3):
        write_bvh(synthetic_walk(n_frames=240, fps=60, seed=k, period_s=1.0 + 0.1 * k, noise_deg=1).motion,
                  d / f"set_walk_s{k}.bvh")
        write_bvh(synthetic_run(n_frames=240, fps=60, seed=k, noise_deg=1).motion, d / f"set_run_s{k}.bvh")
    (d / "broken.bvh").write_text("HIERARCHY\nnonsense\n")
    return d


def test_index_ranks_the_same_content_first(folder):
    with pytest.warns(UserWarning, match="broken.bvh"):
        idx = build_index(folder)
    assert len(idx) == 6 and idx.skipped[0][0].name == "broken.bvh"
    hits = idx.query(folder / "set_walk_s0.bvh", top=3, exclude=folder / "set_walk_s0.bvh")
    assert all("walk" in h.path.name for h in hits[:2])
    assert hits[0].score >= hits[1].score >= hits[2].score
    p = precision_at_k(idx, label=bandai_content, k=2)
    assert p["precision"] >= 0.8 and set(p["by_label"]) == {"walk", "run"}


def test_bad_inputs(tmp_path, folder):
    with pytest.raises(MocycleError, match="not a folder"):
        build_index(tmp_path / "nope")
    with pytest.raises(MocycleError, match="no readable take"):
        build_index(tmp_path)
    with pytest.warns(UserWarning):
        idx = build_index(folder)
    with pytest.raises(MocycleError, match="top"):
        idx.query(folder / "set_run_s1.bvh", top=0)


@pytest.mark.slow
def test_real_bandai_precision_at_5_beats_chance():
    files = shared_files("bandai")
    if len(files) < 45:
        pytest.skip("the 45 Bandai takes are not all there")
    idx = build_index(files[0].parent)
    p = precision_at_k(idx, k=5)
    assert p["n_queries"] == 45
    assert p["precision"] > 0.6  # chance is about 14/44 = 0.32


def test_a_long_query_is_measured_on_evenly_spread_windows_and_still_finds_itself(monkeypatch):
    from mocycle.swings import search

    walk = synthetic_walk(n_frames=60 * 300, fps=60, noise_deg=0.5, seed=2).motion
    sig = signature(segment(walk))
    assert (sig.n_samples - 30) // 15 + 1 > search.MAX_QUERY_WINDOWS  # half-overlapping 1 s windows
    passes = []
    real = search.fftconvolve
    monkeypatch.setattr(search, "fftconvolve", lambda *a, **k: passes.append(1) or real(*a, **k))
    score, offset = compare(sig, sig)
    assert score == pytest.approx(1.0) and offset == 0.0
    assert len(passes) == search.MAX_QUERY_WINDOWS  # one pass over the candidate per window
