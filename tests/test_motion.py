import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from helpers import max_angle, random_motion, tiny_skeleton
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.motion import Motion, Skeleton, concatenate


def test_skeleton_validation_messages():
    with pytest.raises(MocycleError, match="parents"):
        Skeleton(("a", "b"), [0, -1], np.zeros((2, 3)), ((), ()))
    with pytest.raises(MocycleError, match="unique"):
        Skeleton(("a", "a"), [-1, 0], np.zeros((2, 3)), ((), ()))
    with pytest.raises(MocycleError, match="channel"):
        Skeleton(("a",), [-1], np.zeros((1, 3)), (("Wrotation",),))


def test_skeleton_select_names_globs_and_groups():
    s = tiny_skeleton()
    assert s.select(None) == [0, 1, 2, 3]
    assert s.select(["Spine"]) == [3]
    assert s.select("legs") == [1, 2]
    assert s.select("*leg*,Hips") == [0, 1, 2]
    with pytest.raises(MocycleError, match="no joint matches"):
        s.select(["Tail"])
    assert s.euler_order(1) == "ZXY"
    assert s.position_axes(0) == [0, 1, 2]
    assert np.isclose(s.bone_lengths()[1], 40.0)  # Left Up Leg turns the 40-long shin
    assert np.isclose(s.bone_lengths()[2], np.hypot(40, 5))  # End Site


def test_motion_is_immutable_and_sign_continuous():
    m = random_motion()
    with pytest.raises(ValueError):
        m.rotations[0, 0, 0] = 1.0
    assert np.all(np.sum(m.rotations[1:] * m.rotations[:-1], axis=-1) >= 0)
    assert m.root_positions.shape == (50, 3)
    assert np.isclose(m.fps, 60) and np.isclose(m.duration, 49 / 60)


def test_motion_rejects_bad_input():
    s = tiny_skeleton()
    with pytest.raises(MocycleError, match="shape"):
        Motion(s, np.zeros((5, 3, 4)))
    q = np.zeros((5, 4, 4))
    q[..., 3] = 1
    with pytest.raises(MocycleError, match="frame_time must be a positive number"):
        Motion(s, q, frame_time=0)
    q[2, 1] = np.nan
    with pytest.raises(MocycleError, match="NaN"):
        Motion(s, q)


def test_forward_kinematics_by_hand():
    s = tiny_skeleton()
    q = np.zeros((1, 4, 4))
    q[..., 3] = 1
    q[0, 0] = Rotation.from_euler("Z", 90, degrees=True).as_quat()  # root turns 90 deg about z
    m = Motion(s, q, root_positions=[[1.0, 2.0, 3.0]])
    p = m.world_positions(end_sites=True)
    # Left Up Leg offset (10, -5, 0) rotated by 90 deg about z -> (5, 10, 0)
    assert np.allclose(p[0, 1], [1 + 5, 2 + 10, 3])
    # LeftLeg: further (0, -40, 0) -> (40, 0, 0)
    assert np.allclose(p[0, 2], [1 + 5 + 40, 2 + 10, 3])
    assert p.shape == (1, 6, 3)
    assert np.allclose(p[0, 4], p[0, 2] + [40, 0, 5])


def test_slicing_and_indexing():
    m = random_motion(40)
    part = m.slice(10, 20)
    assert part.n_frames == 10 and np.allclose(part.rotations, m.rotations[10:20])
    every_other = m[::2]
    assert every_other.n_frames == 20 and np.isclose(every_other.frame_time, 2 * m.frame_time)
    with pytest.raises(MocycleError, match="empty"):
        m.slice(30, 30)


def test_resample_keeps_frames_at_shared_times_and_interpolates_between():
    m = random_motion(61)  # 1 s at 60 fps
    down = m.resample(30)
    assert down.n_frames == 31 and np.isclose(down.fps, 30)
    assert max_angle(down.rotations, m.rotations[::2]) < 1e-9
    assert np.allclose(down.root_positions, m.root_positions[::2])
    up = m.resample(120)
    assert up.n_frames == 121
    assert max_angle(up.rotations[::2], m.rotations) < 1e-9
    # midpoints are slerp halfway between neighbours
    mid = Rotation.from_quat(up.rotations[1, 1])
    a, b = Rotation.from_quat(m.rotations[0, 1]), Rotation.from_quat(m.rotations[1, 1])
    assert np.isclose((a.inv() * mid).magnitude(), (mid.inv() * b).magnitude(), atol=1e-9)


@pytest.mark.parametrize("frame_time", [0.0333333, 1 / 30, 0.033333])
@pytest.mark.parametrize("n_frames, fps, expected", [(273, 60, 545), (108_000, 120, 431_997), (108_000, 25, 90_000),
                                                       (3, 120, 9), (108_001, 10, 36_001)])
def test_resample_counts_frames_exactly_at_any_length(frame_time, n_frames, fps, expected):
    """A file's frame time is rounded (0.0333333 s): the count is the 30 fps take's, however long the take
    (a tolerance that grew with the take gave 432,000 frames for 3,600 s at 120 fps)."""
    m = random_motion(n_frames).replace(frame_time=frame_time)
    up = m.resample(fps)
    assert up.n_frames == expected
    step = 30 / fps
    if step.is_integer() or (1 / step).is_integer():  # shared frames are the old frames
        k = max(1, round(1 / step))
        shared = up.rotations[::k] if step < 1 else up.rotations
        old = m.rotations if step < 1 else m.rotations[::round(step)]
        assert max_angle(shared[:len(old)], old[:len(shared)]) < 1e-9
    assert max_angle(up.rotations[-1:], m.rotations[-1:]) < 1e-9 or (n_frames - 1) * fps % 30


def test_frame_time_fraction_recognises_rounded_rates_only():
    from fractions import Fraction

    from mocycle.motion import frame_time_fraction

    assert frame_time_fraction(0.0333333) == Fraction(1, 30)
    assert frame_time_fraction(0.016667) == Fraction(1, 60)  # iClone's five digits
    assert frame_time_fraction(0.0083333) == Fraction(1, 120)  # CMU's
    assert frame_time_fraction(0.0333667) == Fraction(1001, 30000)  # NTSC 29.97
    assert frame_time_fraction(1 / 30) == Fraction(1, 30)
    assert frame_time_fraction(0.01) == Fraction(1, 100)
    assert frame_time_fraction(0.0123456789) == Fraction("0.0123456789")  # no whole rate: the decimal
    assert frame_time_fraction(2.5) == Fraction(5, 2)


def test_concatenate_checks_skeleton():
    m = random_motion(10)
    both = concatenate([m, m])
    assert both.n_frames == 20
    other = Motion.rest(Skeleton(("x",), [-1], [[0, 0, 0]], ((),)), 3)
    with pytest.raises(MocycleError, match="skeleton"):
        concatenate([m, other])


def test_a_motion_hands_its_own_arrays_over_and_copies_shared_ones():
    walk = synthetic_walk(n_frames=60).motion
    own = Motion(walk.skeleton, walk.rotations, walk.translations, walk.frame_time)  # arrays it alone holds
    address = own.rotations.__array_interface__["data"][0], own.root_positions.__array_interface__["data"][0]
    rotations, static, tracks = own.hand_over()
    assert list(tracks) == [0]
    assert (rotations.__array_interface__["data"][0], tracks[0].__array_interface__["data"][0]) == address
    assert rotations.flags.writeable and tracks[0].flags.writeable and static.flags.writeable
    with pytest.raises(AttributeError):
        own.translations  # noqa: B018 (emptied)

    shared = Motion(walk.skeleton, walk.rotations, walk.translations, walk.frame_time)
    view = shared[10:50]                                    # shares both arrays
    moved = shared.replace(translations=shared.translations + 1.0)  # shares the rotations
    before = view.rotations.copy(), view.translations.copy(), moved.rotations.copy()
    rotations, static, tracks = shared.hand_over()
    rotations[:] = 0.0
    static[:] = 0.0
    tracks[0][:] = 0.0
    np.testing.assert_array_equal(view.rotations, before[0])
    np.testing.assert_array_equal(view.translations, before[1])
    np.testing.assert_array_equal(moved.rotations, before[2])


def test_translations_are_stored_once_per_joint_that_stands_still():
    walk = synthetic_walk(n_frames=80).motion
    full = walk.translations.copy()
    full[:, 5] += np.linspace(0.0, 1.0, 80)[:, None]  # a second joint that moves
    m = Motion(walk.skeleton, walk.rotations, full, walk.frame_time)
    assert m.tracked_joints == (0, 5) and list(m.tracks) == [0, 5] and m.moving_joints() == [0, 5]
    still_track = m.replace(tracks={7: np.broadcast_to(full[0, 7], (80, 3))})  # tracked, but it stands still
    assert still_track.tracked_joints == (0, 5, 7) and still_track.moving_joints() == [0, 5]
    assert m.moving_joints(tol=2.0) == [0]  # joint 5 moves by 1.0
    np.testing.assert_array_equal(m.translations, full)
    np.testing.assert_array_equal(m.translations_at(7), full[7])
    np.testing.assert_array_equal(m.translations_at([3, 1, 3]), full[[3, 1, 3]])
    np.testing.assert_array_equal(m.translations_at(slice(10, 60, 7)), full[10:60:7])
    np.testing.assert_array_equal(m.joint_translations(2), full[:, 2])
    assert not m.joint_translations(2).flags.writeable and not m.translations.flags.writeable
    np.testing.assert_array_equal(m[20:30].translations, full[20:30])
    np.testing.assert_array_equal(m[::3].translations, full[::3])
    # a track replaces one joint's translations; the others are kept (shared)
    moved = m.replace(tracks={3: full[:, 3] + 2.0})
    assert moved.tracked_joints == (0, 3, 5) and moved.joint_translations(5) is m.joint_translations(5)
    np.testing.assert_array_equal(moved.joint_translations(3), full[:, 3] + 2.0)
    # (J, 3) translations: the same at every frame; joints that move in one part of a take move in the whole
    still = m.replace(translations=full[0])
    assert still.tracked_joints == () and still.travel_joint == 0
    both = concatenate([still, m.replace(tracks={7: full[:, 7] + 0.5})])
    np.testing.assert_array_equal(both.translations[80:, 7], full[:, 7] + 0.5)
    np.testing.assert_array_equal(both.translations[:80], np.broadcast_to(full[0], (80,) + full.shape[1:]))
    with pytest.raises(MocycleError, match=r"track of joint 3 must have shape \(80, 3\)"):
        m.replace(tracks={3: full[:10, 3]})
    with pytest.raises(MocycleError, match="NaN"):
        Motion(walk.skeleton, walk.rotations, full[0], walk.frame_time, tracks={4: np.full((80, 3), np.nan)})
    with pytest.raises(MocycleError, match="track for joint 'hips'"):
        Motion(walk.skeleton, walk.rotations, full[0], walk.frame_time, tracks={"hips": full[:, 0]})
    with pytest.raises(MocycleError, match="track for joint 22"):
        m.replace(tracks={22: full[:, 0]})
    with pytest.raises(MocycleError, match=r"translations must have shape \(80, 22, 3\) or \(22, 3\)"):
        Motion(walk.skeleton, walk.rotations, full[:, :3], walk.frame_time)


def test_one_joints_path_is_its_column_of_the_world_positions(monkeypatch):
    import mocycle.motion as motion_module

    walk = synthetic_walk(n_frames=150, noise_deg=2.0).motion
    monkeypatch.setattr(motion_module, "_FK_BLOCK", 64)  # three blocks, the last one short
    W = walk.world_positions()
    for j in (0, walk.travel_joint, walk.n_joints - 1):
        np.testing.assert_array_equal(walk.joint_path(j), W[:, j])


def test_every_steps_frame_of_the_world_positions_is_that_of_the_motion_sliced(monkeypatch):
    import mocycle.motion as motion_module

    walk = synthetic_walk(n_frames=151, noise_deg=2.0).motion
    monkeypatch.setattr(motion_module, "_FK_BLOCK", 16)  # blocks of the frames taken, the last one short
    for step in (1, 2, 3, 7, 50):
        np.testing.assert_array_equal(walk.world_positions(end_sites=True, step=step),
                                      walk[::step].world_positions(end_sites=True))
    with pytest.raises(ValueError):
        walk.world_positions(step=0)


def test_the_body_root_is_where_the_skeleton_branches():
    """A take where no joint moves (one frame, a still pose) takes the body's root as its travel joint, not a
    static joint above it (Bandai's joint_Root at the room's origin)."""
    walk = synthetic_walk(n_frames=2).motion
    sk = walk.skeleton
    assert sk.body_root() == 0 and len(sk.children(0)) > 1  # the Hips branch
    rooted = Skeleton(("joint_Root", "extra", *sk.names), [-1, 0, *(sk.parents + 2)],
                      np.vstack([[0, 0, 0], [0, 0, 0], sk.offsets]),
                      [("Xposition", "Yposition", "Zposition"), ("Zrotation", "Xrotation", "Yrotation"), *sk.channels])
    assert rooted.body_root() == 2
    chain = Skeleton(("a", "b", "c"), [-1, 0, 1], np.zeros((3, 3)), [("Zrotation", "Xrotation", "Yrotation")] * 3)
    assert chain.body_root() == 0  # no branch: the root
    q = np.concatenate([np.tile([0, 0, 0, 1.0], (1, 2, 1)), walk.rotations[:1]], axis=1)
    t = np.concatenate([np.zeros((1, 2, 3)), walk.translations[:1]], axis=1)
    t[:, 2] += [400.0, 0, 0]
    one = Motion(rooted, q, t, walk.frame_time)
    assert one.moving_joints(1e-9) == [] and one.travel_joint == 2
