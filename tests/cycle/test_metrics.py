import numpy as np
from scipy.spatial.transform import Rotation

from mocycle.cycle import extract_cycle
from mocycle.cycle.metric_rows import metric_features
from mocycle.cycle.metrics import foot_points, foot_sliding, jerk_ratio, loop_metrics, template_error
from mocycle.cycle.seam import _changes, calmest_sample, calmest_start, seam_ratios
from mocycle.datasets import synthetic_still, synthetic_walk


def _loop(N=40, D=3, phase=0.0):
    t = (np.arange(N) / N + phase)[:, None]
    return np.hstack([np.sin(2 * np.pi * (t + k / D)) + 0.3 * np.cos(4 * np.pi * t) for k in range(D)])


def test_metric_distance_is_about_the_angle_and_does_not_wrap_at_a_half_turn():
    walk = synthetic_walk(n_frames=5).motion
    J, first = walk.n_joints, walk[:1]
    axes = Rotation.random(J, random_state=0).apply([1.0, 0.0, 0.0])
    for deg in (1.0, 20.0, 179.0, 181.0, 359.0):
        turned = first.replace(rotations=(Rotation.from_rotvec(np.radians(deg) * axes)
                                          * Rotation.from_quat(first.rotations[0])).as_quat()[None])
        d = np.linalg.norm((metric_features(turned) - metric_features(first)).reshape(J, 9), axis=1)
        assert np.allclose(d, 2 * np.sin(np.radians(deg) / 2))   # chordal: 2 sin(θ/2), symmetric about 180°
    assert abs(2 * np.sin(np.radians(10)) / np.radians(20) - 1) < 0.006  # within 0.6 % of θ up to 20°
    assert metric_features(walk).shape == (5, 9 * J)


def test_template_error_is_zero_for_the_repeated_cycle_and_finds_the_offset():
    C = _loop()
    Y = np.tile(C, (3, 1))[7:90]
    err, n = template_error(Y, C)
    assert err < 1e-6 and n == 7
    noisy = Y + 0.01 * np.random.default_rng(0).normal(size=Y.shape)
    assert 0.005 < template_error(noisy, C)[0] < 0.03


def test_seam_ratios_flag_a_pop_and_pass_a_smooth_loop():
    smooth = seam_ratios(_loop())
    assert all(0.0 < v < 1.6 for v in smooth.values()), smooth
    popped = _loop()
    popped[-1] += 0.5  # the last frame jumps away and back
    pops = seam_ratios(popped)
    assert pops["pose"] > 3 and pops["pose_local"] > 3 and pops["velocity_local"] > 3


def test_calmest_start_picks_the_slowest_step():
    t = np.arange(48) / 48
    C = np.c_[np.sin(2 * np.pi * t) + 0.5 * np.sin(4 * np.pi * t)]
    k = calmest_start(C)
    rolled = np.roll(C, -k, axis=0)
    r = seam_ratios(rolled)
    assert r["pose"] <= 1.0 and r["velocity"] <= 1.0
    assert r["pose"] <= min(seam_ratios(np.roll(C, -j, axis=0))["pose"] for j in range(48)) + 0.6


def _scores(C, stride):
    """calmest_start's score of every start (its definition, written out)."""
    step, acc = _changes(C, stride)
    return np.maximum(step / np.median(step), np.maximum(acc, np.roll(acc, stride)) / np.median(acc))


def test_calmest_sample_finds_the_start_between_frames_from_a_few_samples():
    N, stride = 48, 10
    t = np.arange(N * stride) / (N * stride)
    rng = np.random.default_rng(3)
    for _ in range(20):
        a, b = rng.normal(size=2)
        C = np.c_[np.sin(2 * np.pi * t) + a * np.sin(4 * np.pi * t + b), np.cos(2 * np.pi * t + a)]
        read = []

        def at(rows, C=C, read=read):
            read.append(rows)
            return (C[rows],)

        k = calmest_sample(at, N * stride, stride)
        assert all(np.all(np.diff(r) > 0) for r in read)               # sorted, no sample twice
        assert sum(r.size for r in read) < 0.5 * N * stride               # not every sample made
        exact = _scores(C, stride)
        # as calm as calmest_start's start within 5 %: the ratios are to the medians of the frames (as the seam
        # check measures a loop), not of every sample, which moves the best start by a sample or so
        assert exact[k] <= exact.min() * 1.05
    walk = np.c_[np.sin(2 * np.pi * np.arange(N) / N)]                    # stride 1: calmest_start itself
    assert calmest_sample(lambda rows: (walk[rows],), N, 1) == calmest_start(walk)


def test_loop_blocks_at_rows_are_the_rows_of_loop_blocks():
    from mocycle.cycle.metric_rows import loop_blocks, loop_blocks_at

    cycle = extract_cycle(synthetic_walk(n_frames=300).motion)
    rows = np.array([0, 3, 4, 17, cycle.n_frames - 1])
    C, path = loop_blocks(cycle)
    C_at, path_at = loop_blocks_at(cycle, rows)
    assert np.allclose(C_at, C[rows], atol=1e-12) and np.allclose(path_at, path[rows], atol=1e-9)


def test_jerk_ratio_is_one_for_the_input_itself_and_small_for_a_denoised_cycle():
    C = _loop(60)
    Y = np.tile(C, (4, 1))
    assert abs(jerk_ratio([Y], C, 1 / 60) - 1) < 0.05
    noisy = Y + 0.002 * np.random.default_rng(1).normal(size=Y.shape)
    assert jerk_ratio([noisy], C, 1 / 60) < 0.2


def test_feet_are_one_per_leg_and_a_still_take_does_not_slide():
    walk = synthetic_walk(n_frames=120).motion
    names = walk.skeleton.names
    n = walk.n_joints
    feet = foot_points(walk)
    chains = []
    for i in feet:
        j = i if i < n else walk.skeleton.end_sites[i - n].parent
        chains.append(names[j])
    assert sorted(c[:4] for c in chains) == ["Left", "Righ"], chains
    assert foot_sliding(synthetic_still(noise_deg=0.0).motion) < 1e-6


def _hip_under_root(motion):
    """``motion`` with a joint inserted between the travel joint and all its children (iClone's
    ``RL_BoneRoot`` -> ``CC_Base_Hip``): the travel joint then has a single child carrying legs and spine."""
    from mocycle.motion import EndSite, Motion, Skeleton

    skel = motion.skeleton
    old = np.arange(skel.n_joints)
    new_index = np.where(old == 0, 0, old + 1)  # joint 0 stays, the rest move down by one
    parents = np.concatenate([[-1, 0], new_index[skel.parents[1:]]])
    parents[2:][skel.parents[1:] == 0] = 1  # the root's children hang from the inserted joint
    skeleton = Skeleton(names=(skel.names[0], "Hip") + skel.names[1:], parents=parents,
                        offsets=np.vstack([skel.offsets[:1], np.zeros((1, 3)), skel.offsets[1:]]),
                        channels=(skel.channels[0], ("Zrotation", "Yrotation", "Xrotation")) + skel.channels[1:],
                        end_sites=tuple(EndSite(int(new_index[e.parent]), e.offset, e.name) for e in skel.end_sites))
    T = motion.n_frames
    identity = np.tile([0.0, 0.0, 0.0, 1.0], (T, 1, 1))
    return Motion(skeleton, np.concatenate([motion.rotations[:, :1], identity, motion.rotations[:, 1:]], axis=1),
                  np.concatenate([motion.translations[:, :1], np.zeros((T, 1, 3)), motion.translations[:, 1:]], axis=1),
                  motion.frame_time)


def test_feet_are_one_per_leg_when_the_travel_joint_has_a_single_child():
    """The legs split at the hips (the leg fork), not below the travel joint: a rig whose travel joint carries
    legs and spine through one child (iClone) still gets one foot per leg, the same points as without it."""
    walk = synthetic_walk(n_frames=120).motion
    wrapped = _hip_under_root(walk)
    assert wrapped.travel_joint == 0 and list(wrapped.skeleton.parents).count(0) == 1
    keep = [0] + list(range(2, wrapped.n_joints + len(wrapped.skeleton.end_sites)))  # all but the inserted joint
    np.testing.assert_allclose(wrapped.world_positions(end_sites=True)[:, keep], walk.world_positions(end_sites=True),
                               atol=1e-9)
    names = wrapped.skeleton.names
    n = wrapped.n_joints
    sides = sorted(names[i if i < n else wrapped.skeleton.end_sites[i - n].parent][:4] for i in foot_points(wrapped))
    assert sides == ["Left", "Righ"], sides
    assert [i - 1 for i in foot_points(wrapped)] == foot_points(walk)
    assert abs(foot_sliding(wrapped) - foot_sliding(walk)) < 1e-9


def test_loop_metrics_has_every_number_the_cli_prints():
    take = synthetic_walk(n_frames=400, noise_deg=1.0)
    m = loop_metrics(take.motion, extract_cycle(take.motion))
    for key in ("rmse_h", "rmse_dh", "rmse_ddh", "template_error", "jerk_ratio", "seam_pose", "seam_velocity",
                "seam_pose_local", "seam_velocity_local", "foot_sliding", "input_foot_sliding"):
        assert np.isfinite(m[key]), key
    # the template error and the phase-aligned RMSE measure the same fit two ways
    assert 0.5 < m["template_error"] / m["rmse_h"] < 2.0
    assert m["foot_sliding"] < m["input_foot_sliding"] * 1.5


def test_foot_metrics_from_positions_the_caller_has_are_the_same():
    """loop_metrics runs forward kinematics once per motion and hands the positions on: the same numbers as
    each metric computing its own."""
    from mocycle.contacts.legs import body_height
    from mocycle.contacts.skate import skate

    walk = synthetic_walk(n_frames=240, fps=60, seed=2).motion
    up = np.array([0.0, 1.0, 0.0])
    W = walk.world_positions(end_sites=True)
    assert foot_points(walk, up, W) == foot_points(walk, up)
    assert foot_sliding(walk, up, W) == foot_sliding(walk, up)
    assert body_height(walk, up, W) == body_height(walk, up)
    assert skate(walk, up=up, positions=W) == skate(walk, up=up)
