"""The plot data: what each figure shows, computed without matplotlib."""

import numpy as np
import pytest

from mocycle.cycle import extract_cycle
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.phase import find_phase
from mocycle.swings import segment
from mocycle.viz import loop_plot_data, phase_plot_data, projection_plot_data, swings_plot_data


@pytest.fixture(scope="module")
def walk():
    return synthetic_walk(n_frames=300, fps=60, period_s=1.0, seed=0).motion


def test_phase_plot_data(walk):
    data = phase_plot_data(find_phase(walk, keep_features=True))
    assert len(data["classes"]) == 1 and data["classes"][0]["period_frames"] == pytest.approx(60, rel=0.05)
    assert data["xy"].shape == (walk.n_frames - 2, 2) and data["phase"].shape == (walk.n_frames - 2,)
    assert data["barcode"].shape[1] == 2 and np.all(data["barcode"][:, 1] >= data["barcode"][:, 0])
    assert phase_plot_data(find_phase(walk))["xy"] is None   # features not kept: nothing to project


def test_loop_plot_data(walk):
    cycle = extract_cycle(walk)
    data = loop_plot_data(walk, cycle, n_joints=2)
    N = cycle.n_frames
    assert data["input_xy"].shape == (walk.n_frames, 2) and data["cycle_xy"].shape == (N + 1, 2)
    assert np.allclose(data["cycle_xy"][0], data["cycle_xy"][-1])   # closed loop
    assert len(data["curves"]) == 2 and data["curves"][0]["cycle_deg"].shape == (2 * N,)
    assert np.all((data["input_phase"] >= 0) & (data["input_phase"] < 1))


def test_swings_plot_data(walk):
    seg = segment(walk)
    data = swings_plot_data(seg)
    assert [r["name"] for r in data["rows"]] == [seg.skeleton.names[j] for j in seg.joints]
    assert sum(len(r["swings"]) for r in data["rows"]) == seg.n_swings
    assert data["max_turn_deg"] == max(s["turn_deg"] for r in data["rows"] for s in r["swings"])


def test_projection_plot_data_checks_its_input():
    pts = np.random.default_rng(0).normal(size=(20, 2))
    data = projection_plot_data(pts, [0, 10, 19], optimized=pts + 1)
    assert len(data["panels"]) == 2 and data["key_idx"].tolist() == [0, 10, 19]
    with pytest.raises(MocycleError, match="keyframe indices"):
        projection_plot_data(pts, [25])
    with pytest.raises(MocycleError, match=r"shape \(T, 2\)"):
        projection_plot_data(pts[:, :1], [0])
