"""The numpy twins of scipy calls that `mocycle loop` uses instead of importing scipy.signal, scipy.ndimage and
scipy.interpolate (start-up time, docs/performance.md): each must give scipy's numbers."""

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.ndimage import uniform_filter1d
from scipy.signal import find_peaks
from scipy.signal.windows import hann

from mocycle.cycle.metrics import PeriodicSpline
from mocycle.phase.period import local_maxima, moving_average, periodic_hann


@pytest.mark.parametrize("T", [0, 1, 2, 3, 10, 257, 1000])
def test_periodic_hann_is_scipys(T):
    np.testing.assert_allclose(periodic_hann(T), hann(T, sym=False), rtol=0, atol=1e-15)


@pytest.mark.parametrize("seed", range(5))
def test_local_maxima_are_find_peaks(seed):
    rng = np.random.default_rng(seed)
    x = np.round(rng.normal(size=300), 1)  # rounded: flat tops of several equal samples occur
    x[:3] = 5.0  # a plateau at the start is no peak
    np.testing.assert_array_equal(local_maxima(x), find_peaks(x)[0])


@pytest.mark.parametrize("size", [1, 2, 3, 8, 31, 400])
def test_moving_average_is_uniform_filter1d(size):
    x = np.random.default_rng(size).normal(size=333).cumsum() + 1e3
    np.testing.assert_allclose(moving_average(x, size), uniform_filter1d(x, size, mode="nearest"),
                               rtol=0, atol=1e-9)


def test_periodic_spline_is_cubic_spline():
    rng = np.random.default_rng(0)
    F = rng.normal(size=(17, 3))
    ours = PeriodicSpline(F)
    theirs = CubicSpline(np.arange(18), np.vstack([F, F[:1]]), bc_type="periodic")
    x = rng.uniform(0, 17, size=50)
    for nu in (0, 1, 2):
        np.testing.assert_allclose(ours(x, nu), theirs(x, nu), rtol=0, atol=1e-12)
