import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocycle.rotations import (
    continuous_euler,
    continuous_euler_blocks,
    continuous_quats,
    euler_to_quats,
    half_angle_sincos,
    quat_exp,
    quat_log,
    quat_multiply,
)

ORDERS = ["ZYX", "XYZ", "ZXY", "YXZ", "XZY", "YZX", "ZXZ", "XYX"]


@pytest.mark.parametrize("order", ORDERS + ["X", "ZY"])
def test_euler_to_quats_matches_scipy(order):
    rng = np.random.default_rng(1)
    a = rng.uniform(-400, 400, size=(200, len(order)))
    q = euler_to_quats(a, order, degrees=True)
    r = Rotation.from_euler(order, a, degrees=True)
    assert (Rotation.from_quat(q).inv() * r).magnitude().max() < 1e-12


def test_quat_multiply_matches_scipy():
    rng = np.random.default_rng(2)
    a, b = Rotation.random(100, random_state=3), Rotation.random(100, random_state=4)
    q = quat_multiply(a.as_quat(), b.as_quat())
    assert (Rotation.from_quat(q).inv() * (a * b)).magnitude().max() < 1e-12
    assert rng is not None


@pytest.mark.parametrize("order", ORDERS)
def test_continuous_euler_has_no_flips_and_same_rotation(order):
    # A joint swinging through the places where canonical Euler angles flip.
    t = np.linspace(0, 1, 400)
    rotvec = np.stack([np.sin(2 * np.pi * t) * 3.0, np.cos(2 * np.pi * t) * 1.2, t * 9.0], axis=1)
    r = Rotation.from_rotvec(rotvec)
    q = continuous_quats(r.as_quat()[:, None])
    angles = continuous_euler(q, order)
    assert angles.shape == (400, 1, 3)
    back = Rotation.from_euler(order, angles[:, 0])
    assert (back.inv() * r).magnitude().max() < 1e-9
    step = np.abs(np.diff(angles[:, 0], axis=0)).max()
    canonical = np.abs(np.diff(r.as_euler(order), axis=0)).max()
    assert canonical > np.pi  # the raw angles do flip here ...
    assert step < 0.5  # ... the continuous ones do not


def test_continuous_quats_makes_dots_non_negative():
    q = Rotation.random(300, random_state=5).as_quat()[:, None]
    q[::3] *= -1
    c = continuous_quats(q)
    assert np.all(np.sum(c[1:] * c[:-1], axis=-1) >= 0)
    assert np.allclose(np.abs(c), np.abs(q))


def test_quat_log_is_continuous_through_half_turn_and_inverts():
    angle = np.linspace(0, 1.9 * np.pi, 200)
    r = Rotation.from_rotvec(angle[:, None] * [0, 0, 1.0])
    q = continuous_quats(r.as_quat()[:, None])[:, 0]
    v = quat_log(q)
    assert np.allclose(v[:, 2], angle, atol=1e-9)  # scipy's as_rotvec would wrap at pi
    assert (Rotation.from_quat(quat_exp(v)).inv() * r).magnitude().max() < 1e-9


def test_continuous_rotvec_follows_several_full_turns():
    from mocycle.rotations import continuous_rotvec

    angle = np.linspace(0, 5 * 2 * np.pi, 500)
    r = Rotation.from_rotvec(angle[:, None] * [0, 1.0, 0])
    v = continuous_rotvec(r.as_quat()[:, None])[:, 0]
    assert np.allclose(v[:, 1], angle, atol=1e-9)
    assert (Rotation.from_rotvec(v).inv() * r).magnitude().max() < 1e-9


def test_small_quaternion_helpers_agree_with_scipy():
    from mocycle.rotations import axis_angle_quats, quat_conj, quat_multiply, quat_rotvec, rotvec_quat, twist_angles

    axis = np.array([0.0, 0.6, 0.8])
    theta = np.linspace(-3.0, 3.0, 7)
    q = axis_angle_quats(axis, theta)
    assert np.allclose(q, Rotation.from_rotvec(np.outer(theta, axis)).as_quat() * np.sign(np.cos(theta / 2))[:, None])
    v = np.array([0.3, -0.2, 1.1])
    assert np.allclose(rotvec_quat(v), Rotation.from_rotvec(v).as_quat())
    assert np.allclose(quat_rotvec(-rotvec_quat(v)), v)
    assert np.allclose(quat_multiply(q, quat_conj(q)), [0, 0, 0, 1])
    assert np.allclose(twist_angles(q, axis), theta)


def test_weighted_rotation_mean_checks_its_weights():
    from mocycle.errors import MocycleError
    from mocycle.rotations import weighted_rotation_mean

    q = Rotation.random(4, random_state=0).as_quat().reshape(2, 2, 4)
    with pytest.raises(MocycleError, match="weights"):
        weighted_rotation_mean(q, [1.0, -1.0])
    with pytest.raises(MocycleError, match="weights"):
        weighted_rotation_mean(q, [1.0])


def test_nearest_rotations_match_the_svd_without_it():
    from mocycle.rotations import nearest_rotations, svd_nearest_rotations

    rng = np.random.default_rng(5)
    R = Rotation.random(2000, random_state=6).as_matrix()
    for noise in (0.0, 1e-3, 0.3, 0.8):
        M = R * rng.uniform(0.3, 1.2, (2000, 1, 1)) + noise * rng.normal(size=(2000, 3, 3))
        assert np.abs(nearest_rotations(M) - svd_nearest_rotations(M)).max() < 1e-12
    for noise in (1e-9, 1e-4, 1e-2, 0.03):  # near rotations (a harmonic fit): the Newton-Schulz steps
        M = R + noise * rng.normal(size=(2000, 3, 3))
        assert np.abs(nearest_rotations(M) - svd_nearest_rotations(M)).max() < 1e-12
    near_reflections = -R[:50] + 1e-4 * rng.normal(size=(50, 3, 3))  # orthogonal enough, but det -1
    assert np.allclose(nearest_rotations(near_reflections), svd_nearest_rotations(near_reflections), atol=1e-12)
    flipped = -R[:5]  # det -1: no polar iteration reaches a rotation, the SVD answers
    assert np.allclose(nearest_rotations(flipped), svd_nearest_rotations(flipped), atol=1e-12)
    assert np.linalg.det(nearest_rotations(flipped)) == pytest.approx(np.ones(5))
    assert nearest_rotations(np.zeros((0, 3, 3))).shape == (0, 3, 3)



def test_nearest_rotations_into_the_callers_rows():
    from mocycle.rotations import nearest_rotations

    rng = np.random.default_rng(8)
    M = Rotation.random(300, random_state=9).as_matrix().reshape(100, 3, 3, 3)
    M = M + 0.02 * rng.normal(size=M.shape)
    M[5, 1] *= -1.0  # det -1: the SVD writes this one
    R = np.full((120, 3, 3, 3), np.nan)
    assert nearest_rotations(M, out=R[10:110]) is not None
    np.testing.assert_array_equal(R[10:110], nearest_rotations(M))
    assert np.isnan(R[:10]).all() and np.isnan(R[110:]).all()
    with pytest.raises(ValueError, match="C-contiguous"):
        nearest_rotations(M, out=R[:100, :, :, :].swapaxes(0, 1))

def test_matrix_quats_and_mean_rotations_match_scipy():
    from mocycle.rotations import matrix_quats, mean_rotations

    R = Rotation.random(5000, random_state=7)
    assert np.abs(matrix_quats(R.as_matrix()) - Rotation.from_matrix(R.as_matrix()).as_quat()).max() < 1e-14
    near = Rotation.from_rotvec(0.3 * Rotation.random(600, random_state=8).as_rotvec()).as_quat().reshape(40, 15, 4)
    ours = mean_rotations(near)
    theirs = np.stack([Rotation.from_quat(near[:, j]).mean().as_quat() for j in range(15)])
    assert np.abs(ours - theirs).max() < 1e-12


@pytest.mark.parametrize("k", [1, 2, 3, 4, 6, 9])
def test_vector_norms_are_numpys_norms_bit_for_bit(k):
    from mocycle.rotations import vector_norms

    rng = np.random.default_rng(k)
    a = rng.normal(size=(300, 7, k)) * rng.choice([1e-8, 1.0, 1e8], size=(300, 7, k))
    for v in (a, a[..., ::-1], a[::3, 2:], a.transpose(1, 0, 2)):
        assert np.array_equal(vector_norms(v), np.linalg.norm(v, axis=-1))
        assert np.array_equal(vector_norms(v, keepdims=True), np.linalg.norm(v, axis=-1, keepdims=True))
    assert np.isnan(vector_norms(np.array([[np.nan, 1.0, 0.0]]))[0])
    assert np.isinf(vector_norms(np.array([[np.inf, 1.0, 0.0]]))[0])
    one = np.array([3.0, 4.0, 12.0])
    assert vector_norms(one) == np.linalg.norm(one) == 13.0 and vector_norms(one, keepdims=True).shape == (1,)


@pytest.mark.parametrize("order", ["ZXY", "ZYX", "ZXZ", "ZX", "Y"])
def test_continuous_euler_a_block_at_a_time_is_the_same(order):
    # three joints: still, swinging through the places where the primary solution flips (from frame 150 on,
    # so the frame-by-frame choice starts mid-take), and turning on a random walk
    t = np.linspace(0, 1, 400)
    swing = np.stack([np.sin(2 * np.pi * t) * 3.0, np.cos(2 * np.pi * t) * 1.2, t * 9.0], axis=1)
    swing[:150] = swing[150]
    walk = np.cumsum(np.random.default_rng(2).normal(scale=0.2, size=(400, 3)), axis=0)
    q = np.stack([np.tile([0.0, 0, 0, 1], (400, 1)), Rotation.from_rotvec(swing).as_quat(),
                  Rotation.from_rotvec(walk).as_quat()], axis=1)
    q = continuous_quats(q)
    whole = continuous_euler(q, order, [2, 0, 1])
    for block in (1, 7, 150, 151, 400, 1000):
        parts = list(continuous_euler_blocks(q, order, [2, 0, 1], block))
        assert [rows.start for rows, _ in parts] == list(range(0, 400, block))
        np.testing.assert_array_equal(np.concatenate([a for _, a in parts]), whole)


def _reference_half_sincos(degrees: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sin and cos of half of ``degrees`` within about 1 ulp: the half angle folded exactly into [-45, 45]
    degrees around the nearest multiple of 90 (exact in floating point for these magnitudes), converted to
    radians there (one rounding of a small number), then np.sin/np.cos and the quadrant's swap."""
    half = degrees * 0.5
    quarter = np.rint(half / 90.0)
    rest = np.radians(half - quarter * 90.0)
    s, c = np.sin(rest), np.cos(rest)
    turn = quarter.astype(int) % 4
    sin = np.select([turn == 0, turn == 1, turn == 2], [s, c, -s], -c)
    cos = np.select([turn == 0, turn == 1, turn == 2], [c, -s, -c], s)
    return sin, cos


def test_half_angle_sincos_of_degrees_is_within_a_few_ulp_where_radians_first_is_not():
    rng = np.random.default_rng(7)
    a = np.concatenate([rng.uniform(-180, 180, 200_000), rng.uniform(-3000, 3000, 20_000),
                        rng.normal(0, 1e-3, 2_000), 360.0 * np.arange(-8, 9) + rng.normal(0, 1e-9, 17),
                        np.arange(-720, 720.5, 0.25)])
    sin, cos = half_angle_sincos(a, degrees=True)
    want_sin, want_cos = _reference_half_sincos(a)
    for got, want in ((sin, want_sin), (cos, want_cos)):
        ulp = np.abs(got - want) / np.spacing(np.maximum(np.abs(want), 1e-300))
        assert ulp.max() <= 3, ulp.max()
    # converting to radians first loses the small results near multiples of 360 degrees (why degrees differ)
    near = np.abs(want_sin) < 1e-8
    ulp_np = np.abs(np.sin(a[near] * np.pi / 360) - want_sin[near]) / np.spacing(np.abs(want_sin[near]))
    assert ulp_np.max() > 100


def test_half_angle_sincos_is_exact_at_right_angles_odd_and_periodic():
    a = np.array([0.0, 90.0, 180.0, 270.0, 360.0, -180.0, 540.0, 720.0])
    sin, cos = half_angle_sincos(a, degrees=True)
    np.testing.assert_array_equal(sin, [0.0, np.sqrt(0.5), 1.0, np.sqrt(0.5), 0.0, -1.0, -1.0, 0.0])
    np.testing.assert_array_equal(cos, [1.0, np.sqrt(0.5), 0.0, -np.sqrt(0.5), -1.0, 0.0, 0.0, 1.0])
    x = np.round(np.random.default_rng(3).uniform(-360, 360, 10_000) * 2.0**30) / 2.0**30  # x + 2160: exact
    s1, c1 = half_angle_sincos(x, degrees=True)
    s2, c2 = half_angle_sincos(-x, degrees=True)
    s3, c3 = half_angle_sincos(x + 720.0 * 3, degrees=True)
    np.testing.assert_array_equal(s2, -s1)
    np.testing.assert_array_equal(c2, c1)
    np.testing.assert_array_equal(s3, s1)
    np.testing.assert_array_equal(c3, c1)
    assert np.isnan(half_angle_sincos(np.array([np.nan, 1.0, np.nan]), degrees=True)[0][::2]).all()  # quietly


def test_half_angle_sincos_of_radians_is_numpys():
    x = np.random.default_rng(4).uniform(-10, 10, 1000)
    sin, cos = half_angle_sincos(x)
    np.testing.assert_array_equal(sin, np.sin(x * 0.5))
    np.testing.assert_array_equal(cos, np.cos(x * 0.5))
