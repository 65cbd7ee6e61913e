import numpy as np
import pytest

from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.keyframes import ONE_STEP, PoseSpace, project_one_step, spatial_layout, stress
from mocycle.keyframes.projection import lamp_map, orient_axes, project_force, project_mds, rbfp_map


@pytest.fixture(scope="module")
def space():
    return PoseSpace(synthetic_walk(n_frames=120, fps=30, seed=3).motion)


@pytest.mark.parametrize("name", ONE_STEP)
def test_one_step_projections(space, name):
    Y = project_one_step(name, space)
    assert Y.shape == (120, 2) and np.all(np.isfinite(Y)) and np.ptp(Y, axis=0).min() > 0


def _planar(n=60, seed=0):
    Y = np.random.default_rng(seed).normal(size=(n, 2)) * [3.0, 1.0]
    return Y, np.linalg.norm(Y[:, None] - Y[None], axis=-1)


def test_classical_mds_recovers_planar_distances():
    Y, D = _planar()
    assert stress(D, project_mds(D)) < 1e-10


def test_force_scheme_finds_a_low_stress_layout():
    Y, D = _planar()
    P = project_force(D, iterations=200)
    assert stress(D, P) < 0.01
    assert stress(D, project_force(D, iterations=1)) > stress(D, P)


def test_rbfp_interpolates_the_control_points():
    Y, D = _planar(30)
    key = np.array([0, 3, 9, 14, 29])
    P = rbfp_map(D[:, key], D[np.ix_(key, key)], Y[key])
    assert np.allclose(P[key], Y[key], atol=1e-8)


def _lamp_one(x, Xs, Ys):
    """LAMP for one point, written as in Joia et al. 2011 (Algorithm 1)."""
    alpha = 1.0 / np.sum((Xs - x) ** 2, axis=1)
    xt, yt = alpha @ Xs / alpha.sum(), alpha @ Ys / alpha.sum()
    A = np.sqrt(alpha)[:, None] * (Xs - xt)
    B = np.sqrt(alpha)[:, None] * (Ys - yt)
    U, _, Vt = np.linalg.svd(A.T @ B, full_matrices=False)
    return (x - xt) @ (U @ Vt) + yt


def test_lamp_matches_the_paper_point_by_point():
    rng = np.random.default_rng(1)
    X = rng.normal(size=(300, 5))
    key = np.arange(0, 300, 7)
    L = rng.normal(size=(len(key), 2))
    P = lamp_map(X, key, L)
    assert np.allclose(P[key], L)
    for i in (1, 2, 150, 299):
        assert np.allclose(P[i], _lamp_one(X[i], X[key], L), atol=1e-9)


@pytest.mark.parametrize("projection,select", [("rbfp", "rols"), ("rbfp", "uniform"), ("lamp", "scs"),
                                               ("lle", "rols"), ("pca", "pb")])
def test_spatial_layout(space, projection, select):
    key, points = spatial_layout(space, projection, select, 6, seed="force")
    assert len(key) == 6 and key[0] == 0 and key[-1] == 119 and points.shape == (120, 2)
    assert np.all(np.isfinite(points))


def test_bad_names(space):
    with pytest.raises(MocycleError, match="projection must be one of"):
        spatial_layout(space, "umap", "uniform", 5)
    with pytest.raises(MocycleError, match="seed must be one of"):
        spatial_layout(space, "rbfp", "uniform", 5, seed="rbfp")
    with pytest.raises(MocycleError, match="PoseSpace"):
        PoseSpace(np.zeros((5, 3, 4)))


@pytest.mark.parametrize("n", [20, 80])   # np.linalg.eigh below 50 poses, scipy's eigsh above
def test_mds_plane_does_not_depend_on_the_eigenvectors_signs(n):
    """An eigenvector's sign is the LAPACK build's choice (numpy 1.26 and 2.x mirrored the project plane):
    the MDS plane is oriented so each axis's entry of largest magnitude is positive."""
    rng = np.random.default_rng(n)
    P = rng.normal(size=(n, 3)) * [3.0, 1.0, 0.1]
    D = np.linalg.norm(P[:, None] - P[None], axis=-1)
    Y = project_mds(D)
    top = Y[np.argmax(np.abs(Y), axis=0), [0, 1]]
    assert (top > 0).all()
    assert np.allclose(orient_axes(-Y), Y) and np.allclose(orient_axes(Y * [1, -1]), Y)
