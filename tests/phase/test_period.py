"""Periods and phase remaps of a circular coordinate, checked against synthetic takes with exact phase."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import kstest

from mocycle.datasets import synthetic_walk, synthetic_walk_then_run
from mocycle.errors import MocycleError
from mocycle.features import pose_matrix
from mocycle.phase.period import (
    PeriodFit,
    autocorrelation_period,
    excitation_regions,
    fit_period,
    gmm_cdf_remap,
    rank_uniform,
    unwrap_phase,
)


def circ_diff(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a - b`` on the circle, in ``[-0.5, 0.5)`` cycles."""
    return np.mod(a - b + 0.5, 1.0) - 0.5


def walk_pose(n_frames: int, period_frames: float, fps: float = 60.0, **kw) -> np.ndarray:
    take = synthetic_walk(n_frames, fps=fps, period_s=period_frames / fps, **kw)
    X, _ = pose_matrix(take.motion, rep="expmap", root_features="velocity")
    return X


# -- unwrap_phase ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("kw", [{}, {"speed_change": 0.5, "phase0": 0.7}, {"period_s": 0.35, "phase0": 0.99}])
def test_unwrap_recovers_the_true_unwrapped_phase_exactly(kw):
    take = synthetic_walk(400, **kw)
    u = unwrap_phase(take.phase)
    true = take.unwrapped_phase - np.floor(take.unwrapped_phase[0])
    np.testing.assert_array_equal(u, true)
    assert u[0] == take.phase[0]
    assert u[-1] > 5.0  # it really unwrapped several cycles


def test_unwrap_of_a_decreasing_phase_is_a_decreasing_line():
    take = synthetic_walk(300)
    backwards = np.mod(-take.unwrapped_phase + 0.25, 1.0)
    u = unwrap_phase(backwards)
    assert np.all(np.diff(u) < 0)
    np.testing.assert_allclose(u, 0.25 - take.unwrapped_phase, atol=1e-12)
    fit = fit_period(u)
    assert fit.slope_cycles_per_frame < 0
    assert fit.period_frames == pytest.approx(60.0, rel=1e-9)


def test_unwrap_follows_the_pseudocode_on_a_half_cycle_step_and_keeps_the_first_value():
    # Fig. 3.8: offset = floor(x̂_{i-1} - x_i + 0.5); a step of exactly +0.5 counts as forward.
    np.testing.assert_array_equal(unwrap_phase([0.9, 0.1, 0.6, 0.1, 0.95]), [0.9, 1.1, 1.6, 2.1, 1.95])
    np.testing.assert_array_equal(unwrap_phase([1.7]), [1.7])


# -- fit_period ------------------------------------------------------------------------------------------------


def test_fit_period_of_a_constant_speed_walk():
    take = synthetic_walk(600, fps=120.0, period_s=0.9)  # 108 frames per cycle
    fit = fit_period(unwrap_phase(take.phase), frame_time=take.motion.frame_time)
    assert isinstance(fit, PeriodFit)
    assert fit.period_frames == pytest.approx(108.0, rel=1e-3)
    assert fit.period_s == pytest.approx(0.9, rel=1e-3)
    assert fit.slope_cycles_per_frame == pytest.approx(1 / 108, rel=1e-3)
    assert fit.n_periods == pytest.approx(599 / 108, rel=1e-3)
    assert fit.intercept == pytest.approx(0.0, abs=1e-9)
    assert fit.residual_rms < 1e-9
    with pytest.raises(AttributeError):
        fit.period_frames = 1.0  # frozen


def test_fit_period_over_some_frames_and_of_a_still_coordinate():
    take = synthetic_walk(600)
    u = unwrap_phase(take.phase)
    for frames in (slice(100, 400), np.arange(100, 400), (np.arange(600) >= 100) & (np.arange(600) < 400)):
        fit = fit_period(u, frames=frames)
        assert fit.period_frames == pytest.approx(60.0, rel=1e-3)
        assert fit.n_periods == pytest.approx(299 / 60, rel=1e-3)
        assert fit.period_s is None
    flat = fit_period(np.full(50, 0.3), frame_time=0.01)
    assert flat.period_frames == np.inf and flat.period_s == np.inf
    assert flat.n_periods == pytest.approx(0.0, abs=1e-9)


def test_fit_period_residual_of_a_speeding_up_walk():
    take = synthetic_walk(600, speed_change=0.5)
    fit = fit_period(unwrap_phase(take.phase))
    # the mean period lies between the start (60) and end (40) periods; the phase bends away from the line
    assert 40.0 < fit.period_frames < 60.0
    assert fit.residual_rms > 0.05


# -- autocorrelation_period ------------------------------------------------------------------------------------


@pytest.mark.parametrize(("period", "n_frames"), [(60.0, 480), (45.0, 360), (52.3, 400)])
def test_autocorrelation_period_of_a_walk(period, n_frames):
    X = walk_pose(n_frames, period)
    p = autocorrelation_period(X)
    assert p == pytest.approx(period, rel=0.02)
    assert p == pytest.approx(period, rel=0.002)  # measured: < 0.05 % off


def test_autocorrelation_period_with_noise_and_a_single_column():
    X = walk_pose(360, 45.0, noise_deg=2.0)
    assert autocorrelation_period(X) == pytest.approx(45.0, rel=0.02)
    t = np.arange(500)
    assert autocorrelation_period(np.sin(2 * np.pi * t / 33.3)) == pytest.approx(33.3, rel=1e-3)


def test_autocorrelation_period_without_a_cycle_is_nan():
    assert np.isnan(autocorrelation_period(np.full(300, 2.0)))
    assert np.isnan(autocorrelation_period(np.full((300, 4), -1.5)))
    rng = np.random.default_rng(1)
    assert np.isnan(autocorrelation_period(rng.normal(size=4000)))
    assert np.isnan(autocorrelation_period(rng.normal(size=(1000, 5))))
    assert np.isnan(autocorrelation_period(np.full((100, 2), np.nan)))
    # a slow sinusoid whose cycle is longer than max_lag has no maximum in range
    assert np.isnan(autocorrelation_period(np.sin(2 * np.pi * np.arange(300) / 250.0)))


def test_autocorrelation_period_ignores_nan_and_constant_columns():
    X = walk_pose(360, 45.0)
    reference = autocorrelation_period(X)
    bad = np.column_stack([X, np.full(len(X), 7.0), np.full(len(X), 0.1)])
    bad[10, -1] = np.nan
    bad = np.column_stack([np.full(len(X), np.nan), bad])
    assert autocorrelation_period(bad) == pytest.approx(reference, rel=1e-9)


def test_autocorrelation_period_lag_range():
    t = np.arange(600)
    x = np.sin(2 * np.pi * t / 20.0) + 0.8 * np.sin(2 * np.pi * t / 120.0)
    assert autocorrelation_period(x) == pytest.approx(20.0, abs=0.5)
    assert autocorrelation_period(x, min_lag=30) == pytest.approx(120.0, rel=0.02)
    assert np.isnan(autocorrelation_period(x, min_lag=25, max_lag=35))


# -- rank_uniform ----------------------------------------------------------------------------------------------


def test_rank_uniform_recovers_the_true_phase_up_to_a_rotation():
    take = synthetic_walk(600, period_s=0.9)  # 54 frames per cycle: not a divisor of 600
    true = take.phase
    warped = np.mod(true + 0.08 * np.sin(2 * np.pi * true) + 0.3, 1.0)  # monotone on the circle
    assert np.mean(np.abs(circ_diff(warped, true) - 0.3)) > 0.04
    r = rank_uniform(warped)
    d = circ_diff(r, true)
    rotation = np.angle(np.mean(np.exp(2j * np.pi * d))) / (2 * np.pi)
    assert np.mean(np.abs(circ_diff(d, rotation))) < 0.01


def test_rank_uniform_values_and_ties():
    rng = np.random.default_rng(3)
    x = rng.random(97)
    r = rank_uniform(x)
    np.testing.assert_array_equal(np.sort(r), np.arange(97) / 97)
    assert np.all(np.diff(r[np.argsort(x)]) > 0)
    np.testing.assert_array_equal(rank_uniform([0.5, 0.2, 0.5, 0.2]), [0.5, 0.0, 0.75, 0.25])


# -- gmm_cdf_remap ---------------------------------------------------------------------------------------------


def test_gmm_cdf_remap_flattens_a_non_uniform_coordinate():
    take = synthetic_walk(600, period_s=0.9)
    true = take.phase
    coords = np.mod(true + 0.08 * np.sin(2 * np.pi * true), 1.0)
    g = gmm_cdf_remap(coords)
    assert g.shape == coords.shape
    assert np.all((g >= 0.0) & (g <= 1.0))
    assert np.all(np.diff(g[np.argsort(coords)]) >= 0.0)
    ks_in, ks_out = kstest(coords, "uniform").statistic, kstest(g, "uniform").statistic
    assert ks_out < 0.5 * ks_in
    # it also undoes the warp: the remapped value is close to the true phase
    assert np.mean(np.abs(circ_diff(g, true))) < 0.2 * np.mean(np.abs(circ_diff(coords, true)))
    np.testing.assert_array_equal(gmm_cdf_remap(coords), g)  # deterministic for a fixed random_state


def test_gmm_cdf_remap_small_and_degenerate_inputs():
    g = gmm_cdf_remap([0.1, 0.5, 0.9])  # components capped at the number of distinct values
    assert np.all(np.diff(g) > 0) and np.all((g >= 0) & (g <= 1))
    c = gmm_cdf_remap(np.full(20, 0.3))
    assert np.all(np.isfinite(c)) and np.ptp(c) == 0.0


# -- excitation_regions ----------------------------------------------------------------------------------------


def test_excitation_region_is_the_walk_of_a_walk_then_run():
    take = synthetic_walk_then_run()
    T = take.n_frames
    end = int(np.flatnonzero(np.isnan(take.phase))[0])  # the walk's phase is known up to the blend
    rng = np.random.default_rng(0)
    coords = np.empty(T)
    coords[:end] = take.phase[:end]
    coords[end:] = np.mod(take.phase[end - 1] + 0.01 * rng.normal(size=T - end), 1.0)
    for window in (10, 30):
        regions = excitation_regions(coords, window=window)
        assert len(regions) == 1
        start, stop = regions[0]
        assert start == 0
        assert abs(stop - end) <= 0.25 * window + 2


def test_two_winding_parts_give_two_regions():
    rng = np.random.default_rng(1)
    T = 1000
    u = np.zeros(T)
    ramp = np.arange(200) / 50.0  # 4 cycles in 200 frames
    u[100:300] = ramp
    u[300:600] = ramp[-1]
    u[600:800] = ramp[-1] - ramp  # winding backwards this time
    u[800:] = 0.0
    coords = np.mod(0.3 + u + 0.01 * rng.normal(size=T), 1.0)
    regions = excitation_regions(coords, window=20)
    assert len(regions) == 2
    for (s, e), (s0, e0) in zip(regions, [(100, 300), (600, 800)], strict=True):
        assert abs(s - s0) <= 7 and abs(e - e0) <= 7
    assert regions == sorted(regions) and regions[0][1] < regions[1][0]


def test_no_region_without_winding():
    rng = np.random.default_rng(2)
    assert excitation_regions(np.full(500, 0.3), window=20) == []
    assert excitation_regions(np.mod(0.3 + 0.01 * rng.normal(size=500), 1.0), window=20) == []
    # less than one cycle in the whole take
    assert excitation_regions(np.linspace(0.0, 0.8, 500), window=20) == []


def test_excitation_regions_merge_short_gaps_and_drop_short_runs():
    T = 600
    u = np.zeros(T)
    rate = 1 / 40
    u[50:250] = np.arange(200) * rate
    u[250:265] = u[249]  # a 15-frame pause
    u[265:465] = u[249] + np.arange(200) * rate
    u[465:] = u[464]
    coords = np.mod(u, 1.0)
    assert len(excitation_regions(coords, window=10, max_gap=2)) == 2
    merged = excitation_regions(coords, window=10, max_gap=40)
    assert len(merged) == 1 and abs(merged[0][0] - 50) <= 4 and abs(merged[0][1] - 465) <= 4
    assert excitation_regions(coords, window=10, min_length=300) == []


# -- bad input -------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("func", [unwrap_phase, fit_period, rank_uniform, gmm_cdf_remap,
                                  lambda c: excitation_regions(c, window=5)])
@pytest.mark.parametrize(("bad", "message"), [
    (np.array([]), "at least"),
    (np.zeros((10, 2)), "1-D"),
    (np.array([0.1, np.nan, 0.3]), "NaN"),
    (np.array([0.1, np.inf, 0.3]), "finite"),
    (["a", "b"], "numbers"),
])
def test_bad_coordinates_raise(func, bad, message):
    with pytest.raises(MocycleError, match=message):
        func(bad)


def test_bad_parameters_raise():
    u = np.arange(20) / 7.0
    with pytest.raises(MocycleError, match="two distinct frames"):
        fit_period(u, frames=[3, 3])
    with pytest.raises(MocycleError, match="at least 2 frames"):
        fit_period([0.5])
    with pytest.raises(MocycleError, match="frame indices"):
        fit_period(u, frames=np.array([0, 25]))
    with pytest.raises(MocycleError, match="boolean"):
        fit_period(u, frames=np.ones(5, dtype=bool))
    with pytest.raises(MocycleError, match="integer"):
        fit_period(u, frames=np.array([0.5, 2.0]))
    with pytest.raises(MocycleError, match="frame_time"):
        fit_period(u, frame_time=0.0)
    with pytest.raises(MocycleError, match="at least 4 frames"):
        autocorrelation_period(np.array([]))
    with pytest.raises(MocycleError, match="shape"):
        autocorrelation_period(np.zeros((10, 2, 2)))
    with pytest.raises(MocycleError, match="max_lag"):
        autocorrelation_period(np.zeros(50), min_lag=10, max_lag=5)
    with pytest.raises(MocycleError, match="max_lag"):
        autocorrelation_period(np.zeros(50), max_lag=49)
    with pytest.raises(MocycleError, match="min_strength"):
        autocorrelation_period(np.zeros(50), min_strength=1.5)
    with pytest.raises(MocycleError, match="n_components"):
        gmm_cdf_remap(u % 1, n_components=0)
    with pytest.raises(MocycleError, match="window"):
        excitation_regions(u % 1, window=0)
    with pytest.raises(MocycleError, match="threshold"):
        excitation_regions(u % 1, window=3, threshold=-1.0)
    with pytest.raises(MocycleError, match="min_rate"):
        excitation_regions(u % 1, window=3, min_rate=float("nan"))


def test_autocorrelation_period_of_a_long_take_is_the_cycle_not_a_multiple():
    """Over 50 000 frames the window hardly decays across a few cycles; the level maxima at 120, 180, ...
    frames must not win over the cycle of 60 frames by noise (they did on 5 of these 6 seeds)."""
    T = 50_000
    t = np.arange(T)
    for seed in range(6):
        rng = np.random.default_rng(seed)
        ph = t / 60.0 + 0.02 * np.cumsum(rng.normal(size=T)) / np.sqrt(T)
        X = np.c_[np.sin(2 * np.pi * ph), np.cos(2 * np.pi * ph) + 0.3 * np.sin(4 * np.pi * ph),
                  np.sin(6 * np.pi * ph)] + 0.3 * rng.normal(size=(T, 3))
        assert autocorrelation_period(X, min_lag=8) == pytest.approx(60.0, abs=0.1)


def test_circular_autocorrelation_is_the_same_at_fast_and_slow_fft_lengths():
    from mocycle.phase.period import _smooth_length, circular_autocorrelation

    assert [_smooth_length(n) for n in (1, 7, 11, 97, 99998, 199995)] == [1, 8, 12, 100, 100000, 200000]
    rng = np.random.default_rng(0)
    for T in (30, 97, 998):  # smooth, prime, 2 x 499: direct and zero-padded paths
        Y = rng.normal(size=(T, 3))
        direct = [sum(float(Y[:, d] @ np.roll(Y[:, d], -k)) for d in range(3)) for k in range(T)]
        assert np.allclose(circular_autocorrelation(Y), direct, rtol=0, atol=1e-9)


def test_a_long_take_s_columns_four_at_a_time_give_the_same_period(monkeypatch):
    import mocycle.phase.period as period_module

    T = 70_000  # past _LONG_TAKE: 4 columns at a time instead of 16
    t = np.arange(T)
    rng = np.random.default_rng(5)
    X = np.stack([np.sin(2 * np.pi * t / 97.3 + k) * (1 + k) for k in range(20)], axis=1)
    X += 0.1 * rng.standard_normal(X.shape)
    assert period_module.column_block_width(T) == 4
    four = autocorrelation_period(X, min_lag=20, max_lag=400)
    monkeypatch.setattr(period_module, "_LONG_TAKE", 1 << 30)
    assert period_module.column_block_width(T) == 16
    assert four == pytest.approx(autocorrelation_period(X, min_lag=20, max_lag=400), rel=1e-12)
    assert four == pytest.approx(97.3, rel=1e-3)
