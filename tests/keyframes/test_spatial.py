import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers import max_angle
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.keyframes import PoseSpace, error_per_frame_per_joint, project_one_step
from mocycle.keyframes.select import select_uniform
from mocycle.keyframes.spatial import (
    BackProjection,
    angle_to_nearest_rotation,
    fast_nearest_rotation,
    nearest_rotation,
    optimize_projection,
    reconstruct_spatial,
)


@pytest.fixture(scope="module")
def walk():
    return synthetic_walk(n_frames=240, fps=60, seed=4).motion


def test_nearest_rotation_variants_agree():
    rng = np.random.default_rng(0)
    R = Rotation.random(500, random_state=1).as_matrix()
    M = R * rng.uniform(0.5, 1.2, (500, 1, 1)) + rng.normal(scale=0.05, size=(500, 3, 3))
    A = nearest_rotation(M)
    assert np.allclose(A @ A.transpose(0, 2, 1), np.eye(3), atol=1e-12) and np.all(np.linalg.det(A) > 0)
    assert np.allclose(nearest_rotation(R * 0.7), R, atol=1e-12)
    assert np.allclose(fast_nearest_rotation(M), A, atol=1e-9)
    assert np.allclose(fast_nearest_rotation(-R[:3]), nearest_rotation(-R[:3]), atol=1e-12)  # det < 0 -> SVD
    truth = Rotation.from_matrix(np.einsum("nba,nbc->nac", R, A)).magnitude()
    assert np.abs(angle_to_nearest_rotation(np.einsum("nba,nbc->nac", R, M)) - truth).max() < 1e-3


def test_back_projection_interpolates_the_markers(walk):
    keys = np.array([0, 40, 90, 150, 239])
    markers = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [0.5, 2.0]])
    root = walk.root_positions[keys]
    bp = BackProjection(markers, walk.rotations[keys], root)
    q, r = bp(markers)
    assert max_angle(q, walk.rotations[keys]) < 1e-9
    assert np.allclose(r, root)
    q_mid, _ = bp(np.array([[0.5, 0.5]]))
    assert np.allclose(np.linalg.norm(q_mid, axis=-1), 1.0)


def test_back_projection_survives_repeated_markers(walk):
    keys = np.array([0, 60, 120, 239])
    markers = np.array([[0, 0], [1, 0], [1, 0], [2, 0]])  # repeated and collinear
    q, _ = BackProjection(markers, walk.rotations[keys])(markers[[0, 3]])
    assert np.all(np.isfinite(q))


def test_reconstruct_keeps_keyframes(walk):
    keys = select_uniform(240, 8)
    pts = project_one_step("pca", PoseSpace(walk))
    q, root = reconstruct_spatial(keys, walk.rotations[keys], pts, walk.root_positions[keys])
    assert np.array_equal(q[keys], walk.rotations[keys]) and np.array_equal(root[keys], walk.root_positions[keys])


def test_algorithm_12_lowers_the_error(walk):
    space = PoseSpace(walk)
    keys = select_uniform(240, 8)
    rng = np.random.default_rng(0)
    pts = project_one_step("mds", space) + rng.normal(scale=5.0, size=(240, 2))  # a poor projection
    res = optimize_projection(pts, keys, walk.rotations, space.weights)
    assert np.array_equal(res.points[keys], pts[keys])
    assert res.error_after < 0.8 * res.error_before and res.moved > 100
    before = walk.replace(rotations=reconstruct_spatial(keys, walk.rotations[keys], pts)[0])
    after = walk.replace(rotations=reconstruct_spatial(keys, walk.rotations[keys], res.points)[0])
    assert error_per_frame_per_joint(walk, after) < 0.8 * error_per_frame_per_joint(walk, before)


def test_optimize_bad_input(walk):
    w = PoseSpace(walk).weights
    keys = select_uniform(240, 8)
    with pytest.raises(MocycleError, match=r"\(240, 2\)"):
        optimize_projection(np.zeros((10, 2)), keys, walk.rotations, w)
    with pytest.raises(MocycleError, match="alpha"):
        optimize_projection(np.zeros((240, 2)), keys, walk.rotations, w, alpha=2)
    with pytest.raises(MocycleError, match="markers"):
        BackProjection(np.zeros((3, 3)), walk.rotations[:3])
