"""The pose rows the loop's fit, metrics and checks read block by block equal the arrays they stand for."""

import numpy as np
import pytest

import mocycle.cycle.extract as extract_module
import mocycle.cycle.metric_rows as metric_rows_module
from mocycle.cycle import extract_cycle, loop_metrics
from mocycle.cycle.checks import _lag_differences, best_cut_error, loop_checks, moving_columns
from mocycle.cycle.metric_rows import MetricRows, metric_features
from mocycle.cycle.representation import CycleSpace
from mocycle.datasets import synthetic_walk
from mocycle.motion import Motion
from mocycle.phase.period import autocorrelation_period, autocorrelation_period_of_blocks


@pytest.fixture(scope="module")
def walk():
    """A walk whose last joint never moves and whose joint 3 turns about one axis only (still columns)."""
    take = synthetic_walk(n_frames=420, fps=60, noise_deg=1.0, seed=11).motion
    q = take.rotations.copy()
    q[:, -1] = [0.0, 0.0, 0.0, 1.0]
    return Motion(take.skeleton, q, take.translations, take.frame_time)


@pytest.fixture(autouse=True, params=["made as read", "kept"])
def small_blocks(monkeypatch, request):
    monkeypatch.setattr(MetricRows, "BLOCK", 64)  # several blocks, the last one short
    if request.param == "made as read":  # no motion's rows are kept: every read makes its blocks
        monkeypatch.setattr(metric_rows_module, "KEPT_ROWS_BYTES", 0)


def test_kept_rows_are_the_rows_made_as_read(walk, monkeypatch):
    monkeypatch.setattr(metric_rows_module, "KEPT_ROWS_BYTES", 32 * 2**20)
    kept = MetricRows(walk)
    assert kept.kept is not None and not kept.kept.flags.writeable
    monkeypatch.setattr(metric_rows_module, "KEPT_ROWS_BYTES", 0)
    made = MetricRows(walk)
    assert made.kept is None
    index = np.array([3, 3, 0, 302, 64, 65, 200])
    for a, b in ((kept, made), (kept.moving(), made.moving()), (kept.region(30, 333), made.region(30, 333))):
        for key in (slice(0, None), slice(10, 150), index):
            got, want = a[key], b[key]
            assert got.flags.writeable  # a new array, laid out as the one made (the same rounding downstream)
            assert (got.strides, got.flags.c_contiguous, got.flags.f_contiguous) == \
                (want.strides, want.flags.c_contiguous, want.flags.f_contiguous)
            assert got.tobytes() == want.tobytes()
        assert np.array_equal(a.still(), b.still())
        assert a.spread() == b.spread()
        assert all(x.tobytes() == y.tobytes() for x, y in zip(a.column_blocks(), b.column_blocks(), strict=True))


def test_metric_rows_are_the_metric_features(walk):
    Y = metric_features(walk)
    rows = MetricRows(walk)
    assert rows.shape == Y.shape
    np.testing.assert_array_equal(rows[0:walk.n_frames], Y)
    np.testing.assert_array_equal(rows[10:150], Y[10:150])
    index = np.array([3, 3, 0, 417, 64, 65, 200])
    np.testing.assert_array_equal(rows[index], Y[index])
    np.testing.assert_array_equal(rows.region(100, 300)[5:77], Y[100:300][5:77])
    moving = moving_columns(Y)
    assert moving.shape[1] < Y.shape[1]  # the fixture has still columns
    np.testing.assert_array_equal(rows.moving()[0:walk.n_frames], moving)
    np.testing.assert_array_equal(np.concatenate(list(rows.moving().column_blocks()), axis=1), moving)
    assert rows.moving().spread() == pytest.approx(
        float(np.sqrt(((moving - moving.mean(axis=0)) ** 2).sum() / walk.n_frames)), rel=1e-12)
    for lag in (1, 50, 64, 300):
        np.testing.assert_allclose(rows.moving().lag_differences(lag), _lag_differences(moving, lag),
                                   rtol=1e-9, atol=1e-13)



def _one_lag(q: np.ndarray, lag: int) -> np.ndarray:
    """The squared distances of rows ``lag`` apart as made one lag at a time (before issue 38's runs of lags)."""
    cos = np.einsum("tjk,tjk->tj", q[:q.shape[0] - lag], q[lag:])
    return 4.0 * (q.shape[1] - np.einsum("tj,tj->t", cos, cos))


@pytest.mark.parametrize("joints", ["every", "some"])
def test_lags_made_together_are_each_lag_made_alone(walk, joints):
    rows = MetricRows(walk).moving()
    q = walk.rotations
    if joints == "some":  # columns of joints 1, 2 and 5 only: the others' quaternions are left out
        rows = rows.select(np.isin(rows.columns // 9, [1, 2, 5]))
        q = np.take(q, rows.joints[[1, 2, 5]], axis=1)
    lags = [1, 2, 3, 50, 51, 52, 53, 64, 65, 300, 419, 420, 500]  # runs, a lone lag, lags at and past the end
    together = rows.lag_differences_of(lags)
    assert sorted(together) == lags
    for lag in lags:
        np.testing.assert_array_equal(together[lag], _one_lag(q, lag) if lag < q.shape[0] else np.empty(0))
        np.testing.assert_array_equal(rows.lag_differences(lag), together[lag])

def test_the_autocorrelation_of_column_blocks_is_that_of_the_array(walk):
    Y = moving_columns(metric_features(walk))
    rows = MetricRows(walk).moving()
    # the FFT rounds by the blocks' memory layout: the same period to the last bits
    assert autocorrelation_period_of_blocks(rows.column_blocks(), Y.shape[0], min_lag=15) == pytest.approx(
        autocorrelation_period(Y, min_lag=15), rel=1e-13)


def test_encoded_rows_are_the_encoded_matrix(walk):
    space = CycleSpace.fit(walk)
    P, L = space.encode(walk)
    rows, L2 = space.encode_rows(walk)
    np.testing.assert_array_equal(L2, L)
    assert rows.shape == P.shape
    np.testing.assert_array_equal(rows[0:walk.n_frames], P)
    np.testing.assert_array_equal(rows[37:260], P[37:260])
    with pytest.raises(TypeError):
        rows[::2]


def test_a_cycle_fitted_from_rows_made_as_read_is_the_same_cycle(walk, monkeypatch):
    held = extract_cycle(walk)
    monkeypatch.setattr(extract_module, "LAZY_P_BYTES", 0)  # every take's rows made as read
    monkeypatch.setattr("mocycle.cycle.representation.BLOCK_FRAMES", 50)
    lazy = extract_cycle(walk)
    np.testing.assert_array_equal(lazy.P, held.P)
    np.testing.assert_array_equal(lazy.L, held.L)
    assert loop_metrics(walk, lazy) == loop_metrics(walk, held)
    assert best_cut_error(walk, held) == best_cut_error(walk, held, features=moving_columns(
        metric_features(walk, rows=slice(*max(held.axis.regions, key=lambda r: r[1] - r[0])))))
    assert loop_checks(walk, held) == []
