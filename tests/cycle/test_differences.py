import numpy as np
import pytest

from mocycle.cycle.differences import (
    central_acceleration,
    central_velocity,
    forward_jerk,
    periodic_central,
)
from mocycle.errors import MocycleError


def test_central_differences_are_exact_on_degree_8_polynomials():
    t = np.arange(30) * 0.1
    coef = np.array([0.3, -1.0, 0.5, 2.0, -0.7, 0.1, 0.05, -0.02, 0.01])
    y = np.polyval(coef, t)
    dy, ddy = np.polyval(np.polyder(coef), t), np.polyval(np.polyder(coef, 2), t)
    assert np.allclose(central_velocity(y, 0.1)[:, 0], dy[4:-4], rtol=1e-8, atol=1e-8)
    assert np.allclose(central_acceleration(y, 0.1)[:, 0], ddy[4:-4], rtol=1e-6, atol=1e-6)


def test_eighth_order_accuracy_on_a_sine_per_period():
    N = 60  # frames per period, step 1/N as in eq. 3.25
    x = np.arange(200) / N
    y = np.sin(2 * np.pi * x)
    v = central_velocity(y, 1 / N)[:, 0]
    a = central_acceleration(y, 1 / N)[:, 0]
    assert np.abs(v - 2 * np.pi * np.cos(2 * np.pi * x[4:-4])).max() < 1e-9
    assert np.abs(a + (2 * np.pi) ** 2 * np.sin(2 * np.pi * x[4:-4])).max() < 1e-7


def test_forward_jerk_is_exact_on_cubics_and_periodic_version_covers_every_frame():
    t = np.arange(20) * 0.5
    y = 2 * t ** 3 - t ** 2 + 4
    assert np.allclose(forward_jerk(y, 0.5)[:, 0], 12.0)
    N = 40
    x = np.arange(N) / N
    j = forward_jerk(np.sin(2 * np.pi * x)[:, None], 1 / N, periodic=True)
    assert j.shape == (N, 1)
    assert np.abs(j[:, 0] + (2 * np.pi) ** 3 * np.cos(2 * np.pi * x)).max() < 0.02 * (2 * np.pi) ** 3
    p = periodic_central(np.sin(2 * np.pi * x)[:, None], 1 / N, 1)
    assert np.abs(p[:, 0] - 2 * np.pi * np.cos(2 * np.pi * x)).max() < 1e-6


def test_too_short_or_bad_step_is_rejected():
    with pytest.raises(MocycleError, match="at least 9 frames"):
        central_velocity(np.zeros(8), 1.0)
    with pytest.raises(MocycleError, match="step must be a positive number"):
        central_acceleration(np.zeros(20), 0.0)
