import numpy as np
import pytest

from mocycle.cycle.timeaxis import time_axis
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.phase import find_phase


@pytest.mark.parametrize("speed_change", [0.0, 0.3])
def test_smooth_axis_follows_the_true_time(speed_change):
    take = synthetic_walk(n_frames=600, noise_deg=1.0, speed_change=speed_change)
    pm = find_phase(take.motion).classes[0]
    axis = time_axis(pm, "smooth")
    frames = axis.frames()
    err = axis.x[frames] - take.unwrapped_phase[frames]
    err -= np.median(err)
    assert np.abs(err).max() < 0.03  # cycles: the within-cycle unevenness of the coordinate is gone
    raw = pm.unwrapped[frames] - take.unwrapped_phase[frames]
    assert np.abs(err).max() < np.abs(raw - np.median(raw)).max()
    s, e = axis.regions[0]
    truth = take.unwrapped_phase[e - 1] - take.unwrapped_phase[s] + 1 / axis.period_frames
    assert abs(axis.n_periods - truth) < 0.05


def test_all_axes_increase_and_span_the_periods():
    take = synthetic_walk(n_frames=400, noise_deg=1.0)
    pm = find_phase(take.motion).classes[0]
    for method in ("smooth", "rank", "gmm", "line"):
        axis = time_axis(pm, method)
        x = axis.x[axis.frames()]
        assert np.isfinite(x).all() and (np.diff(x) > -0.05).all(), method
        assert 6.0 < x[-1] - x[0] < 7.5, method


def test_unknown_axis_is_rejected():
    pm = find_phase(synthetic_walk(n_frames=200).motion).classes[0]
    with pytest.raises(MocycleError, match="smooth, rank, gmm, line"):
        time_axis(pm, "spline")
