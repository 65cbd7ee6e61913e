import warnings

import numpy as np
import pytest
from sklearn.exceptions import NotFittedError

from helpers import circular_error
from mocycle.datasets import synthetic_nonperiodic, synthetic_still, synthetic_walk, synthetic_walk_then_run
from mocycle.errors import MocycleError, MocycleWarning
from mocycle.phase import CircularCoordinates, choose_classes
from mocycle.phase.analysis import phase_features
from mocycle.phase.cohomology import _is_cocycle, _lift, greedy_permutation


def circular_rank_correlation(a, b):
    """Fisher-Lee style rank correlation of two circular samples (1 = same order up to rotation)."""
    n = len(a)
    ra = 2 * np.pi * np.argsort(np.argsort(a)) / n
    rb = 2 * np.pi * np.argsort(np.argsort(b)) / n
    return float(np.abs(np.mean(np.exp(1j * (ra - rb)))))


@pytest.fixture(scope="module")
def walk():
    take = synthetic_walk(n_frames=600, noise_deg=1.0, seed=4)
    return take, phase_features(take.motion)


def test_coordinate_follows_the_true_phase(walk):
    take, X = walk
    cc = CircularCoordinates().fit(X)
    assert cc.coords_.shape == (600, 1)
    f = cc.coords_[:, 0]
    assert np.all((f >= 0) & (f < 1))
    assert circular_rank_correlation(f, take.phase) > 0.99
    rank = np.argsort(np.argsort(f, kind="stable")) / f.size  # eq. 3.20
    assert circular_error(rank, take.phase) < 0.02
    # increases with time: the unwrapped coordinate goes forward about once per true cycle
    steps = np.diff(f) - np.round(np.diff(f))
    assert np.isclose(steps.sum(), take.unwrapped_phase[-1] - take.unwrapped_phase[0], atol=0.3)
    assert cc.classes_[0].n_cycles > 9


def test_transform_of_the_training_points_gives_the_same_coordinates(walk):
    _, X = walk
    cc = CircularCoordinates().fit(X)
    again = cc.transform(X)
    d = np.abs(again - cc.coords_)
    assert np.minimum(d, 1 - d).max() < 1e-9


def test_reversed_take_still_increases_with_time(walk):
    take, X = walk
    f = CircularCoordinates().fit(X[::-1]).coords_[:, 0]
    steps = np.diff(f) - np.round(np.diff(f))
    assert steps.sum() > 9


@pytest.mark.parametrize("make", [lambda: synthetic_still(noise_deg=0.5), lambda: synthetic_nonperiodic(seed=0),
                                  lambda: synthetic_nonperiodic(seed=1)], ids=["still", "nonperiodic0", "nonperiodic1"])
def test_no_periodic_motion_gives_no_class_and_a_reason(make):
    X = phase_features(make().motion)
    cc = CircularCoordinates(n_classes="auto").fit(X)
    assert cc.coords_.shape == (X.shape[0], 0) and cc.classes_ == []
    assert "no long H1 bar" in cc.reason_ or "not a periodic motion" in cc.reason_


def test_random_noise_has_no_periodic_motion():
    X = np.random.default_rng(0).normal(size=(400, 8))
    cc = CircularCoordinates(n_classes="auto").fit(X)
    assert cc.classes_ == []


def test_walk_then_run_gives_two_classes_one_per_gait():
    take = synthetic_walk_then_run(seed=2, noise_deg=1.0)
    cc = CircularCoordinates(n_classes="auto").fit(phase_features(take.motion))
    assert len(cc.classes_) == 2, cc.reason_
    (_, w0, w1), (_, r0, r1) = take.segments
    cycles = sorted(round(c.n_cycles) for c in cc.classes_)
    u = take.unwrapped_phase  # NaN inside the blend between the gaits
    walk_cycles = round(np.nanmax(u[w0:w1]) - np.nanmin(u[w0:w1]))
    run_cycles = round(np.nanmax(u[r0:r1]) - np.nanmin(u[r0:r1]))
    assert cycles == sorted([walk_cycles, run_cycles])


def test_too_few_frames_and_bad_parameters_are_rejected():
    with pytest.raises(MocycleError, match="at least 20 frames"):
        CircularCoordinates().fit(np.zeros((10, 3)))
    with pytest.raises(MocycleError, match="n_landmarks"):
        CircularCoordinates(n_landmarks=1).fit(np.zeros((30, 3)))
    with pytest.raises(MocycleError, match="scale_fraction"):
        CircularCoordinates(scale_fraction=1.5).fit(np.zeros((30, 3)))
    with pytest.raises(NotFittedError, match="not fitted"):
        CircularCoordinates().transform(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="at least 20 frames"):  # argument errors are ValueErrors
        CircularCoordinates().fit(np.zeros((10, 3)))


def test_constant_and_nan_columns_do_not_break_the_fit(walk):
    take, X = walk
    X = np.c_[X, np.full(len(X), 3.0), np.full(len(X), np.nan)]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cc = CircularCoordinates().fit(X)
    assert any(issubclass(w.category, MocycleWarning) for w in caught)
    assert circular_rank_correlation(cc.coords_[:, 0], take.phase) > 0.99
    with pytest.raises(MocycleError, match="every column"):
        CircularCoordinates().fit(np.full((40, 3), np.nan))


def test_lift_maps_large_residues_to_negative_integers_and_checks_triangles():
    cocycle = np.array([[0, 1, 46], [1, 2, 1]])  # 46 = -1 mod 47
    Z = _lift(cocycle, 47, 3)
    assert Z[0, 1] == -1 and Z[1, 0] == 1 and Z[1, 2] == 1
    triangle = np.ones((3, 3), bool)
    np.fill_diagonal(triangle, False)
    assert _is_cocycle(Z, triangle)  # -1 + 1 + 0 = 0 around (0, 1, 2)
    Z[1, 2], Z[2, 1] = 2, -2
    assert not _is_cocycle(Z, triangle)
    assert _is_cocycle(Z, np.zeros((3, 3), bool))  # no triangle, nothing to violate


def test_choose_classes_reads_the_gap():
    bars = np.array([[1.0, 6.0], [1.1, 5.0], [1.0, 1.4], [2.0, 2.3]])
    chosen, reason = choose_classes(bars, "auto")
    assert chosen == [0, 1] and "gap" in reason
    chosen, reason = choose_classes(bars, 3)
    assert chosen == [0, 1, 2]
    chosen, reason = choose_classes(np.array([[1.0, 1.3]]), "auto")
    assert chosen == [] and "no long H1 bar" in reason
    assert choose_classes(np.zeros((0, 2)))[0] == []


def test_greedy_permutation_picks_farthest_points_and_reports_distances():
    X = np.array([[0.0, 0], [1, 0], [10, 0], [5, 0], [9, 0]])
    idx, dist = greedy_permutation(X, 3)
    assert idx.tolist() == [0, 2, 3]  # start, farthest from 0, farthest from {0, 2}
    assert np.allclose(dist, np.abs(X[idx, 0][:, None] - X[:, 0][None, :]))


def _plain_greedy(X, n):
    """The textbook farthest-point loop on |x - l| (what greedy_permutation must pick)."""
    idx = [0]
    nearest = np.full(X.shape[0], np.inf)
    for _ in range(n - 1):
        nearest = np.minimum(nearest, np.sqrt(((X - X[idx[-1]]) ** 2).sum(axis=1)))
        idx.append(int(np.argmax(nearest)))
    return np.array(idx)


@pytest.mark.parametrize("case", ["lattice", "held poses", "repeated cycle", "constant", "noise", "small"])
def test_greedy_permutation_picks_the_plain_algorithms_landmarks_on_ties_and_copies(case):
    rng = np.random.default_rng(1)
    X = {"lattice": lambda: rng.integers(0, 3, size=(1500, 4)).astype(float),  # many rows equally far
         "held poses": lambda: np.r_[np.zeros((700, 6)), rng.normal(size=(300, 6))],
         "repeated cycle": lambda: np.tile(rng.normal(size=(60, 8)), (20, 1)),  # exact copies, 20 of each row
         "constant": lambda: np.ones((800, 5)),
         "noise": lambda: rng.normal(size=(2000, 24)),
         "small": lambda: rng.normal(size=(300, 3))}[case]()
    n = min(120, X.shape[0])
    idx, dist = greedy_permutation(X, n)
    np.testing.assert_array_equal(idx, _plain_greedy(X, n))
    full = np.sqrt(((X[idx][:, None] - X[None]) ** 2).sum(-1))
    assert np.abs(dist - full).max() < 1e-6 * (1.0 + full.max())


# -- the scikit-learn estimator contract ---------------------------------------------------------------------------
# CircularCoordinates is a scikit-learn transformer and passes check_estimator except for these documented checks:
EXPECTED_FAILED_CHECKS = {
    "check_n_features_in_after_fitting": "fits 15 rows; circular coordinates need at least 20 frames",
    "check_fit2d_1feature": "fits 10 rows; circular coordinates need at least 20 frames",
    "check_estimators_pickle": "puts NaN in every column; fit drops NaN columns and refuses when none is left",
}


def _sklearn_checks():
    try:
        from sklearn.utils.estimator_checks import parametrize_with_checks

        return parametrize_with_checks([CircularCoordinates(n_landmarks=30)],
                                       expected_failed_checks=lambda est: EXPECTED_FAILED_CHECKS)
    except TypeError:  # scikit-learn < 1.6 has no expected_failed_checks
        skip = pytest.mark.skip(reason="scikit-learn < 1.6: no expected_failed_checks")
        return pytest.mark.parametrize(("estimator", "check"), [pytest.param(None, None, marks=skip)])


@_sklearn_checks()
def test_scikit_learn_estimator_contract(estimator, check):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check(estimator)


def test_landmarks_of_a_long_take_come_from_a_bounded_pool_and_cover_every_row():
    from mocycle.phase.cohomology import LANDMARK_POOL, cover_radius, landmark_pool

    assert landmark_pool(50).tolist() == list(range(50))
    pool = landmark_pool(3 * LANDMARK_POOL)
    assert pool.size == LANDMARK_POOL and pool[0] == 0 and np.all(np.diff(pool) > 0)
    assert np.array_equal(pool, landmark_pool(3 * LANDMARK_POOL))  # seeded: the same take, the same landmarks
    take = synthetic_walk(n_frames=LANDMARK_POOL + 2000, noise_deg=1.0, seed=4)
    X = phase_features(take.motion)
    cc = CircularCoordinates().fit(X)
    assert np.isin(cc.landmarks_, landmark_pool(X.shape[0])).all()
    # the cover radius is measured on every row, not only the pool's
    full = np.sqrt(((X[:, None, :] - cc.landmark_points_[None]) ** 2).sum(-1)).min(axis=1).max()
    assert np.isclose(cc.cover_radius_, full) and np.isclose(cover_radius(X, cc.landmark_points_), full)
    assert circular_rank_correlation(cc.coords_[:, 0], take.phase) > 0.99
