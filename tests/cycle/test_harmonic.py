import numpy as np
import pytest

from mocycle.cycle.differences import HALF, central_acceleration, central_velocity
from mocycle.cycle.harmonic import HarmonicRegression, harmonic_basis, max_harmonics
from mocycle.errors import MocycleError

N = 50  # frames per period


def _curves(n_frames=400, noise=0.0, seed=0, drift=None):
    rng = np.random.default_rng(seed)
    x = np.arange(n_frames) / N
    K, D = 4, 6
    coef = rng.normal(size=(2 * K + 1, D)) / (1 + np.arange(2 * K + 1))[:, None]
    Y = harmonic_basis(x, K) @ coef
    if drift is not None:
        Y = Y + np.outer(x, drift)
    Y_noisy = Y + noise * rng.normal(size=Y.shape)
    xd = x[HALF:-HALF]
    return x, Y, Y_noisy, xd, central_velocity(Y_noisy, 1 / N), central_acceleration(Y_noisy, 1 / N), coef


@pytest.mark.parametrize("model", ["M1", "M2", "M3"])
def test_noise_free_curves_are_recovered_by_every_model(model):
    x, Y, _, xd, dY, ddY, coef = _curves()
    fit = HarmonicRegression(6, model).fit(x, Y, xd, dY, ddY)
    xs = np.linspace(0, 1, 37)
    assert np.abs(fit.predict(xs) - harmonic_basis(xs, 4) @ coef).max() < 1e-6
    assert fit.rmse_[0] < 1e-6


def test_linear_term_recovers_the_drift_per_period():
    drift = np.array([140.0, 0.0, -3.0, 0.5, 0.0, 1.0])
    x, Y, _, xd, dY, ddY, _ = _curves(drift=drift)
    fit = HarmonicRegression(5, "M1", linear=True).fit(x, Y, xd, dY, ddY)
    assert np.allclose(fit.drift_, drift, atol=1e-6)
    still = fit.predict(np.array([0.25, 1.25, 7.25]), drift=False)
    assert np.allclose(still[0], still[1]) and np.allclose(still[0], still[2])


def test_m1_weights_follow_the_group_variances_and_m3_weights_are_one():
    x, _, Yn, xd, dY, ddY, _ = _curves(noise=0.01)
    m1 = HarmonicRegression(8, "M1").fit(x, Yn, xd, dY, ddY)
    s2p, s2v, s2a = m1.sigma2_
    assert np.allclose(m1.alpha_, s2p / s2v) and np.allclose(m1.gamma_, s2p / s2a)
    # differences amplify white noise: velocity noise per period is far larger than the position noise
    assert (m1.alpha_ < 1e-2).all() and (m1.gamma_ < m1.alpha_).all()
    m3 = HarmonicRegression(8, "M3").fit(x, Yn, xd, dY, ddY)
    assert (m3.alpha_ == 1).all() and (m3.gamma_ == 1).all()
    # the thesis' finding: M3 over-weights the noisy accelerations, so its position error is the largest
    m2 = HarmonicRegression(8, "M2").fit(x, Yn)
    assert m3.rmse_[0] > m1.rmse_[0] >= m2.rmse_[0] - 1e-12
    assert m1.rmse_[0] < 1.05 * m2.rmse_[0]


def test_batched_fgls_equals_one_weighted_least_squares_per_dof():
    x, _, Yn, xd, dY, ddY, _ = _curves(noise=0.02, seed=3)
    K = 7
    fit = HarmonicRegression(K, "M1").fit(x, Yn, xd, dY, ddY)
    P, V, A = harmonic_basis(x, K), harmonic_basis(xd, K, 1), harmonic_basis(xd, K, 2)
    for j in range(Yn.shape[1]):
        a, g = np.sqrt(fit.alpha_[j]), np.sqrt(fit.gamma_[j])
        B = np.vstack([P, a * V, g * A])
        t = np.concatenate([Yn[:, j], a * dY[:, j], g * ddY[:, j]])
        assert np.allclose(fit.coef_[:, j], np.linalg.lstsq(B, t, rcond=None)[0], atol=1e-7)



@pytest.mark.parametrize("rows", [8192, 64])  # one block (its factors shared), several (the first block's shared)
def test_fits_sharing_their_designs_factors_are_the_fits_alone(rows):
    from mocycle.cycle.harmonic import _array_blocks

    x, _, Yn, xd, dY, ddY, _ = _curves(noise=0.02, seed=5)
    _, _, Zn, _, dZ, ddZ, _ = _curves(noise=0.03, seed=6)
    alone = [HarmonicRegression(7, "M1", linear=linear).fit_blocks(_array_blocks(x, Y, rows=rows),
                                                                    _array_blocks(xd, d, dd, rows=rows))
             for linear, Y, d, dd in ((False, Yn, dY, ddY), (False, Zn, dZ, ddZ), (True, Zn, dZ, ddZ))]
    shared: dict = {}
    together = [HarmonicRegression(7, "M1", linear=linear).fit_blocks(_array_blocks(x, Y, rows=rows),
                                                                       _array_blocks(xd, d, dd, rows=rows),
                                                                       shared=shared)
                for linear, Y, d, dd in ((False, Yn, dY, ddY), (False, Zn, dZ, ddZ), (True, Zn, dZ, ddZ))]
    assert len(shared) == 6  # the first blocks' three designs, each with and without the linear term
    for a, b in zip(alone, together, strict=True):
        for name in ("coef_", "alpha_", "gamma_", "sigma2_", "rmse_"):
            np.testing.assert_array_equal(getattr(b, name), getattr(a, name))

def test_derivative_bases_are_the_derivatives():
    x = np.linspace(0, 2, 101)
    h = 1e-6
    for d in (1, 2):
        numeric = (harmonic_basis(x + h, 3, d - 1, True) - harmonic_basis(x - h, 3, d - 1, True)) / (2 * h)
        assert np.allclose(harmonic_basis(x, 3, d, True), numeric, atol=1e-4 * (2 * np.pi * 3) ** d)


def test_bad_options_say_the_limit():
    x, Y, _, xd, dY, ddY, _ = _curves(n_frames=30)
    with pytest.raises(MocycleError, match=r"K <= 14"):
        HarmonicRegression(20, "M2").fit(x, Y)
    with pytest.raises(MocycleError, match="model must be one of"):
        HarmonicRegression(3, "M4").fit(x, Y)
    with pytest.raises(MocycleError, match="needs velocities"):
        HarmonicRegression(3, "M1").fit(x, Y)
    with pytest.raises(MocycleError, match="positive integer"):
        HarmonicRegression(0, "M2").fit(x, Y)
    with pytest.raises(MocycleError, match="finite"):
        HarmonicRegression(3, "M2").fit(x, np.full_like(Y, np.nan))
    with pytest.raises(MocycleError, match="fit the regression"):
        HarmonicRegression(3).predict(x)
    assert max_harmonics(30) == 14 and max_harmonics(300, cycle_frames=25) == 12


def test_least_squares_is_lstsq_also_without_full_rank():
    from mocycle.cycle.harmonic import least_squares

    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(0, 3, 120))
    Y = rng.normal(size=(120, 300))
    for B in (harmonic_basis(x, 8), harmonic_basis(x, 8, derivative=1)[:, 1:],  # full rank
              np.column_stack([harmonic_basis(x, 4), harmonic_basis(x, 4)[:, 1]])):  # a repeated column
        np.testing.assert_allclose(least_squares(B, Y), np.linalg.lstsq(B, Y, rcond=None)[0], atol=1e-10)


def test_still_columns_are_their_constant_exactly():
    """A column that is one value on every row (a joint that never moves) is predicted as that value, bit for
    bit, whatever the model; the moving columns get the fit they get alone (within rounding: BLAS may sum in
    another order for another number of columns)."""
    rng = np.random.default_rng(4)
    x = np.linspace(0, 4, 240, endpoint=False)
    moving = np.column_stack([np.sin(2 * np.pi * x), np.cos(4 * np.pi * x)]) + 0.01 * rng.normal(size=(240, 2))
    Y = np.column_stack([moving[:, 0], np.full(240, 0.3), moving[:, 1], np.full(240, -1.7)])
    xd, dY, ddY = x[HALF:-HALF], central_velocity(Y, 1 / 60), central_acceleration(Y, 1 / 60)
    for model in ("M1", "M2", "M3"):
        both = HarmonicRegression(6, model).fit(x, Y, xd, dY, ddY)
        alone = HarmonicRegression(6, model).fit(x, moving, xd, dY[:, [0, 2]], ddY[:, [0, 2]])
        fine = np.linspace(0, 1, 97)
        assert np.array_equal(both.predict(fine)[:, [1, 3]], np.tile([0.3, -1.7], (97, 1)))
        np.testing.assert_allclose(both.predict(fine)[:, [0, 2]], alone.predict(fine), rtol=1e-12, atol=1e-12)


def test_n_harmonics_is_the_old_name_of_harmonics():
    # K, the number of harmonics, is called harmonics everywhere; the old keyword works for one release
    import warnings

    from mocycle.errors import OptionError

    x = np.linspace(0, 2, 60, endpoint=False)
    with pytest.warns(DeprecationWarning, match="n_harmonics is now called harmonics"):
        old = HarmonicRegression(n_harmonics=5)
    assert old.harmonics == 5
    with pytest.warns(DeprecationWarning):
        assert old.n_harmonics == 5
    with pytest.warns(DeprecationWarning):
        assert np.array_equal(harmonic_basis(x, n_harmonics=3), harmonic_basis(x, 3))
    with pytest.raises(OptionError, match="give harmonics only"):
        HarmonicRegression(6, n_harmonics=5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert HarmonicRegression(harmonics=4).harmonics == 4


def test_kept_designs_are_harmonic_basis_and_stay_within_their_bound(monkeypatch):
    from mocycle.cycle import harmonic as h

    designs = h._Designs(budget=200_000)
    monkeypatch.setattr(h, "_DESIGNS", designs)
    rng = np.random.default_rng(4)
    axes = [rng.uniform(-2.0, 5.0, n) for n in (37, 300, 301)]
    for _ in range(3):  # hits and misses, evictions on the way
        for x in axes:
            for derivative in (0, 1, 2):
                for linear in (False, True):
                    B = h._design(x, 7, derivative, linear)
                    assert not B.flags.writeable
                    assert B.tobytes() == h.harmonic_basis(x, 7, derivative, linear).tobytes()
                    assert designs.held <= designs.budget
    with pytest.raises(MocycleError):
        h._design(axes[0], 7, 3)
