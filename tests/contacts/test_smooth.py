import numpy as np
import pytest
from scipy import ndimage

from mocycle.contacts.smooth import gaussian, maximum, uniform


@pytest.mark.parametrize("sigma", [0.3, 1.0, 2.5, 30.0])
def test_gaussian_is_scipy_s_gaussian_filter1d_with_nearest_ends(sigma):
    x = np.random.default_rng(1).normal(size=(97, 4, 3)).cumsum(axis=0)
    ref = ndimage.gaussian_filter1d(x, sigma, axis=0, mode="nearest")
    assert np.abs(gaussian(x, sigma) - ref).max() < 1e-12 * np.abs(x).max()
    assert np.abs(gaussian(x[:, 0, 0], sigma) - ref[:, 0, 0]).max() < 1e-12 * np.abs(x).max()


@pytest.mark.parametrize("size", [1, 2, 3, 7, 12, 200])
def test_maximum_and_uniform_are_scipy_s_with_nearest_ends(size):
    x = np.random.default_rng(2).normal(size=60)
    assert np.array_equal(maximum(x, size), ndimage.maximum_filter1d(x, size, mode="nearest"))
    assert np.abs(uniform(x, size) - ndimage.uniform_filter1d(x, size, mode="nearest")).max() < 1e-12


@pytest.mark.parametrize("size", [1, 2, 3, 7, 12, 120, 200, 10**7])
def test_minimum_is_scipy_s_in_linear_time(size):
    """The running minimum (van Herk / Gil-Werman) equals minimum_filter1d with nearest ends, on (T,) and
    (T, C); a window wider than the take (the floor of a short take) is the whole take's minimum."""
    from mocycle.contacts.smooth import minimum

    x = np.random.default_rng(3).normal(size=(97, 4)).cumsum(axis=0)
    ref = ndimage.minimum_filter1d(x, min(size, 1000), axis=0, mode="nearest")
    assert np.array_equal(minimum(x, size), ref)
    assert np.array_equal(minimum(x[:, 0], size), ref[:, 0])
