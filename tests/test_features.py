import numpy as np
import pytest

from helpers import max_angle, random_motion
from mocycle.errors import MocycleError
from mocycle.features import REPS, ROOTS, delay_embed, pose_matrix


@pytest.mark.parametrize("rep", REPS)
@pytest.mark.parametrize("root", ROOTS)
def test_decode_encode_reproduces_motion(rep, root):
    m = random_motion(60, spin=True)
    X, dec = pose_matrix(m, rep=rep, root_features=root)
    assert X.shape == (60, dec.n_features) and len(dec.columns) == X.shape[1]
    back = dec.decode(X)
    assert max_angle(back.rotations, m.rotations) < 1e-9
    assert np.allclose(back.translations, m.translations, atol=1e-9)


@pytest.mark.parametrize("rep", REPS)
def test_normalised_and_bone_weighted_features_still_decode(rep):
    m = random_motion(40)
    X, dec = pose_matrix(m, rep=rep, root_features="keep", normalize=True, weights="bone")
    # z-scored columns scaled by the joint's bone length relative to the longest bone
    spread = X.std(axis=0)
    thigh = [k for k, c in enumerate(dec.columns) if c.startswith("Left Up Leg:") and spread[k] > 1e-9]
    shin = [k for k, c in enumerate(dec.columns) if c.startswith("LeftLeg:") and spread[k] > 1e-9]
    assert np.allclose(spread[shin], 1.0)  # the longest bone (40.3 to its End Site)
    assert thigh and np.allclose(spread[thigh], 40.0 / np.hypot(40, 5))
    assert max_angle(dec.decode(X).rotations, m.rotations) < 1e-9


def test_expmap_is_continuous_for_a_spinning_joint():
    m = random_motion(200, spin=True)
    X, dec = pose_matrix(m, rep="expmap", root_features="drop")
    cols = [k for k, c in enumerate(dec.columns) if c.startswith("Left Up Leg:")]
    # no 2*pi (or 4*pi) wraps; near whole turns the exp map itself bends fast, hence pi/2
    assert np.abs(np.diff(X[:, cols], axis=0)).max() < np.pi / 2


def test_euler_columns_follow_each_joints_order():
    m = random_motion(10)
    _, dec = pose_matrix(m, rep="euler", root_features="keep")
    assert dec.columns[:3] == ("Hips:rz", "Hips:ry", "Hips:rx")
    assert "Left Up Leg:rz" in dec.columns and dec.columns[-3:] == ("root:x", "root:y", "root:z")


def test_root_velocity_is_first_differences():
    m = random_motion(30)
    X, dec = pose_matrix(m, rep="expmap", root_features="velocity")
    v = X[:, -3:]
    assert np.allclose(v[1:], np.diff(m.root_positions, axis=0))
    assert np.allclose(v[0], v[1])
    assert dec.columns[-1] == "root:vz"


def test_joint_subset_and_template_for_other_joints():
    m = random_motion(30)
    X, dec = pose_matrix(m, rep="expmap", root_features="drop", joints="legs")
    assert X.shape[1] == 6 and set(dec.joints) == {1, 2}
    other = random_motion(30, seed=5)
    mixed = dec.decode(dec.encode(other))
    assert max_angle(mixed.rotations[:, [1, 2]], other.rotations[:, [1, 2]]) < 1e-9
    assert max_angle(mixed.rotations[:, [0, 3]], m.rotations[:, [0, 3]]) < 1e-9


def test_decode_with_other_length_uses_mean_pose():
    m = random_motion(30)
    X, dec = pose_matrix(m, rep="quatlog", root_features="velocity", joints=["Spine"])
    short = dec.decode(X[:10])
    assert short.n_frames == 10
    assert max_angle(short.rotations[:, 3], m.rotations[:10, 3]) < 1e-9
    assert np.allclose(short.root_positions, m.root_positions[:10])


def test_quatlog_about_reference_is_zero_at_reference():
    m = random_motion(20)
    X, _ = pose_matrix(m, rep="quatlog", root_features="drop", reference=m)
    assert np.allclose(X[0], 0.0, atol=1e-12)
    assert not np.allclose(X[5], 0.0)


def test_constant_channels_do_not_break_normalisation():
    m = random_motion(20)
    still = m.replace(rotations=np.broadcast_to(m.rotations[:1], m.rotations.shape))
    X, dec = pose_matrix(still, rep="rotmat", root_features="keep", normalize=True)
    assert np.all(np.isfinite(X))
    assert max_angle(dec.decode(X).rotations, still.rotations) < 1e-9


def test_bad_arguments_are_rejected_with_the_choices():
    m = random_motion(10)
    with pytest.raises(MocycleError, match="euler, expmap"):
        pose_matrix(m, rep="quaternion")
    with pytest.raises(MocycleError, match="keep, velocity, heading, drop"):
        pose_matrix(m, root_features="fly")
    with pytest.raises(MocycleError, match="no joint matches"):
        pose_matrix(m, joints=["Tail"])
    with pytest.raises(MocycleError, match="one value per joint"):
        pose_matrix(m, weights=np.ones(2))
    _, dec = pose_matrix(m)
    with pytest.raises(MocycleError, match="shape"):
        dec.decode(np.zeros((5, 2)))


def test_delay_embedding_eq_3_26():
    X = np.arange(20.0).reshape(10, 2)
    E = delay_embed(X, 2)
    assert E.shape == (8, 6)
    assert np.array_equal(E[0], [0, 1, 2, 3, 4, 5])
    assert np.array_equal(E[:, :2], X[:8])
    assert np.array_equal(delay_embed(X, 0), X)
    assert delay_embed(X, 2, step=3).shape == (4, 6)
    with pytest.raises(MocycleError, match="needs more than"):
        delay_embed(X, 10)


def test_root_columns_follow_the_travel_joint_when_the_root_is_static():
    # Bandai-style file: a static joint_Root, the travel in Hips' position channels.
    m = random_motion(30)
    trans = np.array(m.translations)
    trans[:, 1] = trans[:, 0]
    trans[:, 0] = 0.0
    bandai_like = m.replace(translations=trans)
    assert bandai_like.travel_joint == 1 and m.travel_joint == 0
    X, dec = pose_matrix(bandai_like, rep="expmap", root_features="velocity")
    assert np.allclose(X[1:, -3:], np.diff(trans[:, 1], axis=0))
    assert np.allclose(dec.decode(X).translations, trans)


@pytest.mark.parametrize("up", ["y", "z"])
def test_heading_root_features_do_not_depend_on_where_the_walker_faces(up):
    # paper 001 §4.1: root position and orientation as first differences
    from mocycle.datasets import synthetic_circle_walk

    straight = synthetic_circle_walk(n_frames=90, fps=30.0, turn_per_cycle_deg=0.0, up=up).motion
    circle = synthetic_circle_walk(n_frames=90, fps=30.0, turn_per_cycle_deg=90.0, up=up).motion
    Xs, dec = pose_matrix(straight, rep="expmap", root_features="heading")
    Xc, _ = pose_matrix(circle, rep="expmap", root_features="heading")
    assert dec.columns[-4:] == ("root:hx", "root:hy", "root:hz", "root:dheading")
    assert np.allclose(Xc[:, :-4], Xs[:, :-4], atol=1e-9)          # rotations, the root's tilt included
    turn = np.diff(Xc[:, -1] - Xs[:, -1])
    assert np.allclose(Xc[1:, -1] - Xs[1:, -1], np.radians(90.0) / 30.0, rtol=1e-6) and np.allclose(turn, 0)
    speed = np.linalg.norm(Xs[:, -4:-1], axis=1).max()
    assert np.abs(Xc[:, -4:-1] - Xs[:, -4:-1]).max() < 0.05 * speed  # velocity in the heading frame
    Xv, _ = pose_matrix(circle, rep="expmap", root_features="velocity")      # world axes: they turn with the walker
    assert np.abs(Xv[:, -3:] - Xs[:, -4:-1]).max() > 0.5 * speed


@pytest.mark.parametrize("shape", [(30000, 2), (30000, 5), (20001, 70), (9000, 909), (30000, 1), (500, 40)])
def test_column_sums_of_squares_are_numpys_bits(shape, monkeypatch):
    import mocycle.features as features_module

    monkeypatch.setattr(features_module, "SQUARES_BLOCK", 4096)
    X = np.random.default_rng(shape[1]).standard_normal(shape) * np.linspace(0.01, 100.0, shape[1])
    np.testing.assert_array_equal(features_module.column_sums_of_squares(X), np.add.reduce(np.square(X), axis=0))


def test_root_is_the_old_name_of_root_features():
    # a loop's root (inplace/motion) and the features' root handling were one word for two ideas
    m = random_motion(10)
    X, dec = pose_matrix(m, root_features="drop")
    with pytest.warns(DeprecationWarning, match="root is now called root_features"):
        X_old, dec_old = pose_matrix(m, root="drop")
    assert np.array_equal(X, X_old) and dec_old.root_features == "drop"
