import numpy as np
import pytest
from scipy import fft as sp_fft

from mocycle.errors import MocycleError
from mocycle.warp import bell, block_edges, fold, ilct, lct, unfold
from mocycle.warp.lct import max_overlap


@pytest.mark.parametrize("T,window", [(240, 60), (503, 60), (97, 7), (64, 32), (50, 1)])
def test_perfect_reconstruction_and_energy(T, window):
    X = np.random.default_rng(T).normal(size=(T, 5))
    edges = block_edges(T, window)
    overlap = window // 2
    C = lct(X, edges, overlap)
    assert C.shape == X.shape
    assert np.abs(ilct(C, edges, overlap) - X).max() < 1e-10
    assert abs(np.sum(C**2) - np.sum(X**2)) < 1e-10 * np.sum(X**2)


def test_the_transform_matrix_is_orthonormal_for_uneven_blocks():
    edges = np.array([0, 6, 20, 30, 44, 51])
    M = lct(np.eye(51), edges)  # default overlap: the largest allowed (3 here)
    assert max_overlap(edges) == 5  # inner blocks fold at both ends (10 // 2); the first folds only once
    assert np.abs(M.T @ M - np.eye(51)).max() < 1e-12
    assert np.abs(M @ M.T - np.eye(51)).max() < 1e-12


def test_one_curve_and_many_curves_agree():
    rng = np.random.default_rng(1)
    X = rng.normal(size=(120, 3))
    edges = block_edges(120, 25)
    C = lct(X, edges, 10)
    for d in range(3):
        assert np.allclose(lct(X[:, d], edges, 10), C[:, d], atol=1e-13)


def test_bell_is_an_orthogonal_smooth_cutoff():
    rise, fall = bell(16)  # r(t) and r(-t) at t = (j + 1/2) / 16
    assert np.allclose(rise**2 + fall**2, 1.0)
    full = np.concatenate([fall[::-1], rise])  # r over the whole fold, -1 .. 1
    assert np.all(np.diff(full) > 0)
    assert full[0] < 0.001 and full[-1] > 0.9999  # flat (zero slope) at both ends of the fold
    assert np.allclose(full[::-1] ** 2 + full**2, 1.0)


def test_fold_then_unfold_is_identity_and_only_touches_the_fold_regions():
    X = np.random.default_rng(2).normal(size=(90, 2))
    edges = block_edges(90, 30)
    Y = fold(X, edges, 5)
    assert np.allclose(unfold(Y, edges, 5), X, atol=1e-14)
    changed = np.flatnonzero(np.any(np.abs(Y - X) > 0, axis=1))
    assert set(changed) == set(range(25, 35)) | set(range(55, 65))


def test_no_overlap_is_a_blockwise_dct_iv():
    x = np.random.default_rng(3).normal(size=40)
    C = lct(x, block_edges(40, 10), overlap=0)
    for b in range(4):
        assert np.allclose(C[10 * b: 10 * b + 10], sp_fft.dct(x[10 * b: 10 * b + 10], type=4, norm="ortho"))


def test_atoms_are_smooth_and_localised():
    """One coefficient's atom: supported on its block plus the folds, with no jump at the block edges."""
    edges = block_edges(120, 40)
    C = np.zeros(120)
    C[40 + 2] = 1.0  # block 1, frequency (2 + 1/2) / 80 cycles per frame
    slope = 2 * np.pi * 2.5 / 80  # the steepest step of a cosine of that frequency, per unit amplitude
    atom = ilct(C, edges, 20)
    assert np.all(atom[:20] == 0) and np.all(atom[100:] == 0)
    assert np.abs(np.diff(atom)).max() < 1.5 * slope * np.abs(atom).max()
    hard = ilct(C, edges, 0)  # without the fold the atom ends with a jump
    assert np.abs(np.diff(hard)).max() > 3 * slope * np.abs(hard).max()


def test_block_edges_put_the_remainder_in_the_last_block():
    assert block_edges(100, 30).tolist() == [0, 30, 60, 100]
    assert block_edges(90, 30).tolist() == [0, 30, 60, 90]
    assert block_edges(5, 5).tolist() == [0, 5]
    with pytest.raises(MocycleError, match="at most the number of frames"):
        block_edges(10, 11)
    with pytest.raises(MocycleError, match="positive integer"):
        block_edges(10, 0)


def test_bad_input_gives_one_clear_error():
    edges = block_edges(60, 20)
    with pytest.raises(MocycleError, match="finite"):
        lct(np.full(60, np.nan), edges)
    with pytest.raises(MocycleError, match="edges must increase"):
        lct(np.zeros(60), [0, 30, 50])
    with pytest.raises(MocycleError, match="overlap must be at most 10"):
        lct(np.zeros(60), edges, 11)
    with pytest.raises(MocycleError, match=r"\(T,\) or \(T, D\)"):
        lct(np.zeros((60, 2, 2)), edges)
    with pytest.raises(MocycleError, match="integer"):
        lct(np.zeros(60), edges, 2.5)
