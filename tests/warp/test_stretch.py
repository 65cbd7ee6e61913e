import numpy as np
import pytest
from scipy.signal import detrend
from scipy.spatial.transform import Rotation

from conftest import shared_path
from helpers import max_angle, random_motion
from mocycle.datasets import humanoid_skeleton, synthetic_gesture, synthetic_still, synthetic_walk
from mocycle.errors import MocycleError, MocycleWarning, NoPeriodicMotion
from mocycle.features import pose_matrix
from mocycle.io import read
from mocycle.motion import EndSite, Motion, Skeleton, concatenate
from mocycle.warp import fundamental_cycles, group_cycle, joint_groups, stretch_motion, warp_curves
from mocycle.warp.stretch import refine_window


def dominant_frequency(x: np.ndarray) -> float:
    """Cycles per frame at the peak of the (zero-padded, Hann-windowed) power spectrum of a detrended curve."""
    x = detrend(np.asarray(x, dtype=np.float64), axis=0)
    n = x.shape[0]
    P = np.abs(np.fft.rfft(x * np.hanning(n), 16 * n)) ** 2
    return (int(np.argmax(P[1:])) + 1) / (16 * n)


def max_step(x: np.ndarray) -> float:
    return float(np.abs(np.diff(x, axis=0)).max())


# -- curves -------------------------------------------------------------------------------------------------------


def test_factor_one_gives_the_curves_back():
    X = np.random.default_rng(0).normal(size=(130, 4))
    assert np.abs(warp_curves(X, 1.0, 30) - X).max() < 1e-12


@pytest.mark.parametrize("T", [300, 317])
def test_a_periodic_curve_comes_back_as_its_exact_continuation(T):
    """Window = the integer period: factor 2 continues the signal, whether or not the take ends on a cycle."""
    t = np.arange(2 * T)
    x = np.sin(2 * np.pi * t / 60) + 0.3 * np.sin(2 * np.pi * t / 20 + 1)
    X = np.stack([x, np.cos(2 * np.pi * t / 30)], axis=1)
    Y = warp_curves(X[:T], 2.0, 60)
    assert Y.shape == (2 * T, 2)
    assert np.abs(Y - X).max() < 1e-10


def test_stretch_keeps_the_frequency_and_resampling_halves_it():
    t = np.arange(250.0)
    x = np.sin(2 * np.pi * t / 40.7 + 0.3)  # a non-integer period, not ending on a cycle
    window = refine_window(x, fundamental_cycles(x[:, None])[0])
    assert window in (40, 41)
    y = warp_curves(x, 2.0, window)
    resampled = np.interp(np.linspace(0, 249, 500), t, x)
    concat = np.tile(x, 2)
    f0 = dominant_frequency(x)
    assert abs(dominant_frequency(y) / f0 - 1) < 0.05
    assert abs(dominant_frequency(resampled) / f0 - 0.5) < 0.05
    assert abs(y.std() / x.std() - 1) < 0.05
    assert max_step(y) <= 1.05 * max_step(x)
    assert max_step(concat) > 1.5 * max_step(x)  # the join of the naive concatenation jumps


def test_decaying_pendulum_keeps_its_frequency_and_its_decay():
    t = np.arange(300.0)
    x = (1 - t / 360) ** 2 * np.cos(2 * np.pi * t / 50)
    y = warp_curves(x, 2.0, 50)
    assert abs(dominant_frequency(y) / dominant_frequency(x) - 1) < 0.02
    peaks_in = [np.abs(x[k: k + 50]).max() for k in range(0, 250, 50)]
    peaks_out = [np.abs(y[k: k + 100]).max() for k in range(0, 500, 100)]
    assert np.allclose(peaks_out, peaks_in, rtol=0.1)  # the envelope is stretched, not flattened
    assert np.allclose(y[-25:], x[-25:], atol=1e-10)  # the last cycle is kept once, at the end
    assert max_step(y) <= 1.01 * max_step(x)


def test_window_one_is_sample_and_hold_reparametrisation():
    """Paper 004 §5.1: with a window of 1 the warp only repeats samples (a plain expansion in time)."""
    x = np.random.default_rng(3).normal(size=40)
    y = warp_curves(x, 2.0, 1)
    assert np.allclose(y[:78], np.repeat(x[:39], 2))
    assert np.allclose(y[78:], x[38:])  # the last block (sample) is never replicated


@pytest.mark.parametrize("factor,n_out", [(2.0, 400), (3.3, 660), (1.5, 300), (0.5, 100), (1.004, 201)])
def test_output_length_is_round_t_times_factor(factor, n_out):
    t = np.arange(200.0)
    x = np.sin(2 * np.pi * t / 25)
    y = warp_curves(x, factor, 25)
    assert y.shape == (n_out,)
    assert abs(dominant_frequency(y) / dominant_frequency(x) - 1) < 0.05
    assert max_step(y) <= 1.05 * max_step(x)


def test_warp_rejects_bad_input():
    x = np.zeros(100)
    with pytest.raises(MocycleError, match="half the take"):
        warp_curves(x, 2.0, 51)
    with pytest.raises(MocycleError, match="positive"):
        warp_curves(x, 0.0, 10)
    with pytest.raises(MocycleError, match="positive"):
        warp_curves(x, float("nan"), 10)
    with pytest.raises(MocycleError, match="limit"):
        warp_curves(x, 1e6, 10)
    with pytest.raises(MocycleError, match="finite"):
        warp_curves(np.full(100, np.inf), 2.0, 10)
    with pytest.raises(MocycleError, match="overlap"):
        warp_curves(x, 2.0, 10, overlap=6)


# -- fundamental cycles and groups ----------------------------------------------------------------------------------


def test_fundamental_cycle_of_every_curve():
    t = np.arange(400.0)
    X = np.stack([np.sin(2 * np.pi * t / 20), np.sin(2 * np.pi * t / 50) + 0.3 * np.sin(2 * np.pi * t / 25),
                  np.zeros_like(t)], axis=1)
    cycles = fundamental_cycles(X)
    assert abs(cycles[0] - 20) < 0.3 and abs(cycles[1] - 50) < 0.5 and np.isnan(cycles[2])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fundamental_cycles_in_one_fft_are_autocorrelation_period_of_each_column(seed):
    """One FFT for all columns, the maximum chosen column by column: the same numbers as eq. 1 on each."""
    from mocycle.phase.period import autocorrelation_period

    walk = synthetic_walk(n_frames=[171, 300, 457][seed], fps=60, noise_deg=1.0, seed=seed).motion
    X, _ = pose_matrix(walk, rep="quatlog", root_features="drop")
    X = np.concatenate([X, np.random.default_rng(seed).normal(size=(X.shape[0], 3)), np.ones((X.shape[0], 1))], 1)
    X[:, -2] = np.nan  # a column with a NaN has no cycle
    expected = [autocorrelation_period(X[:, d], min_strength=0.3) if np.ptp(X[:, d]) > 0 else np.nan
                for d in range(X.shape[1])]
    got = fundamental_cycles(X)
    assert np.array_equal(got, expected, equal_nan=True)
    assert np.isfinite(got).sum() >= 10 and np.isnan(got[-2:]).all()


def test_group_cycle_is_the_largest_cycle_of_the_curves_that_move():
    t = np.arange(400.0)
    rng = np.random.default_rng(4)
    X = np.stack([np.sin(2 * np.pi * t / 50),  # e.g. a hip: the stride
                  0.5 * np.sin(2 * np.pi * t / 25),  # e.g. a bobbing joint: the step
                  0.01 * np.sin(2 * np.pi * t / 130) + 0.001 * rng.normal(size=t.size)], axis=1)  # barely moving
    assert abs(group_cycle(X) - 50) < 0.5
    assert np.isnan(group_cycle(np.zeros((100, 3))))


def test_joint_groups_cover_every_joint_once():
    skel = humanoid_skeleton()
    groups = joint_groups(skel)
    assert set(groups) == {"legs", "arms", "spine"}
    assert sorted(j for js in groups.values() for j in js) == list(range(skel.n_joints))
    name = {g: {skel.names[j] for j in js} for g, js in groups.items()}
    assert {"LeftUpLeg", "RightFoot", "LeftToeBase"} <= name["legs"]
    assert {"LeftArm", "RightHand", "LeftShoulder"} <= name["arms"]
    assert {"Hips", "Spine", "Head", "Neck"} <= name["spine"]


def test_unmatched_joints_follow_their_parent():
    skel = Skeleton(
        names=("root", "pelvis", "l_thigh", "l_shin", "r_clavicle", "r_hand", "r_index1", "eye"),
        parents=[-1, 0, 1, 2, 0, 4, 5, 0],
        offsets=np.ones((8, 3)),
        channels=(("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"),)
        + (("Zrotation", "Xrotation", "Yrotation"),) * 7,
        end_sites=(EndSite(3, (0.0, -1.0, 0.0)),),
    )
    groups = joint_groups(skel)
    assert groups == {"legs": [2, 3], "arms": [4, 5, 6], "spine": [0, 1, 7]}


# -- motions --------------------------------------------------------------------------------------------------------


def test_stretching_a_periodic_walk_continues_it():
    """A synthetic walk of 5 cycles stretched 2x is the 10-cycle walk (rotations exact, travel within 0.1%)."""
    short = synthetic_walk(300, fps=60, period_s=1.0).motion
    long = synthetic_walk(600, fps=60, period_s=1.0).motion
    out, report = stretch_motion(short, 2.0)
    assert (report.frames_in, report.frames_out) == (300, 600)
    assert report.windows == {"legs": 60, "arms": 60, "spine": 60}
    assert all(abs(c - 60) < 0.5 for c in report.cycles.values())
    assert out.frame_time == short.frame_time and out.skeleton is short.skeleton
    assert max_angle(out.rotations, long.rotations) < 1e-6
    travel = np.ptp(long.root_positions[:, 2])
    assert np.abs(out.translations - long.translations).max() < 1e-3 * travel


def test_stretching_a_walk_that_ends_mid_cycle_keeps_speed_cycle_and_smoothness():
    take = synthetic_walk(290, fps=60, period_s=0.95, noise_deg=0.5, seed=3).motion
    out, report = stretch_motion(take, 2.5)
    assert report.frames_out == 725
    X, _ = pose_matrix(take, rep="quatlog", root_features="drop")
    Y, _ = pose_matrix(out, rep="quatlog", root_features="drop")
    hip = int(np.argmax(X.std(axis=0)))
    assert abs(dominant_frequency(Y[:, hip]) / dominant_frequency(X[:, hip]) - 1) < 0.05
    assert abs(Y[:, hip].std() / X[:, hip].std() - 1) < 0.1

    def step_angle(m):
        q = m.rotations
        return 2 * np.arccos(np.abs(np.sum(q[1:] * q[:-1], axis=-1)).clip(0, 1)).max()

    assert step_angle(out) <= 1.5 * step_angle(take)
    v_in = np.diff(take.root_positions, axis=0).mean(axis=0)
    v_out = np.diff(out.root_positions, axis=0).mean(axis=0)
    assert np.allclose(v_out, v_in, atol=0.02 * np.linalg.norm(v_in))  # the character keeps travelling
    assert np.linalg.norm(out.root_positions[0] - take.root_positions[0]) < 0.02 * np.linalg.norm(v_in) * 290


def test_a_given_window_is_used_for_every_group():
    take = synthetic_walk(240, fps=60).motion
    out, report = stretch_motion(take, 1.5, window=30)
    assert report.windows == {"legs": 30, "arms": 30, "spine": 30}
    assert all(c is None for c in report.cycles.values())
    assert out.n_frames == 360
    d = report.to_dict()
    assert set(d) >= {"factor", "frames_in", "frames_out", "windows"} and d["windows"]["legs"] == 30


def test_a_turning_root_is_warped_as_line_plus_residual():
    """A root yaw that keeps growing (a walk turning 120 degrees) goes on turning, not back at each copy."""
    from scipy.spatial.transform import Rotation

    take = synthetic_walk(300, fps=60, period_s=1.0).motion
    yaw = Rotation.from_euler("y", np.linspace(0, 2 * np.pi / 3, 300)[:, None])
    q = take.rotations.copy()
    q[:, 0] = (yaw * Rotation.from_quat(q[:, 0])).as_quat()
    out, report = stretch_motion(take.replace(rotations=q), 2.0)
    assert "Hips:qy" in report.trend_curves
    heading = Rotation.from_quat(out.rotations[:, 0]).apply([0.0, 0.0, 1.0])
    turned = np.unwrap(np.arctan2(heading[:, 0], heading[:, 2]))
    assert abs((turned[-1] - turned[0]) - 4 * np.pi / 3) < 0.15  # 240 degrees over twice the length
    assert np.abs(np.diff(turned)).max() < 0.05
    straight, plain = stretch_motion(take, 2.0)
    assert plain.trend_curves == ()


def test_stretch_rejects_bad_input():
    take = synthetic_walk(120, fps=60).motion
    with pytest.raises(MocycleError, match="needs a Motion"):
        stretch_motion(np.zeros((10, 3)), 2.0)
    with pytest.raises(MocycleError, match="at least 8 frames"):
        stretch_motion(take[:5], 2.0)
    with pytest.raises(MocycleError, match="half the take"):
        stretch_motion(take, 2.0, window=61)
    with pytest.raises(MocycleError, match="'auto' or"):
        stretch_motion(take, 2.0, window="big")
    with pytest.raises(MocycleError, match="positive"):
        stretch_motion(take, -1.0)
    with pytest.raises(NoPeriodicMotion, match="no periodic motion to stretch.*option 'force'"):
        stretch_motion(synthetic_still(200).motion, 2.0)
    with pytest.warns(MocycleWarning, match="option 'force'"), \
            pytest.raises(MocycleError, match="does not look periodic"):
        stretch_motion(synthetic_still(200).motion, 2.0, force=True)


def test_a_still_group_borrows_the_cycle_of_the_others():
    take = synthetic_walk(300, fps=60, period_s=1.0).motion
    arms = joint_groups(take.skeleton)["arms"]
    q = take.rotations.copy()
    q[:, arms] = q[0, arms]  # arms held still
    _, report = stretch_motion(take.replace(rotations=q), 2.0)
    assert report.windows["arms"] == report.windows["legs"] == 60


def test_small_random_take_runs_and_keeps_shape():
    m = random_motion(64, seed=2)
    with pytest.raises(NoPeriodicMotion):
        stretch_motion(m, 2.0, window=16)
    with pytest.warns(MocycleWarning, match="no periodic motion"):
        out, report = stretch_motion(m, 2.0, window=16, force=True)
    assert report.forced and report.regions == ()
    assert isinstance(out, Motion) and out.n_frames == 128 and out.skeleton.same_as(m.skeleton)
    assert np.all(np.isfinite(out.rotations)) and np.all(np.isfinite(out.translations))


def test_real_bandai_walk():
    take = read(shared_path("bandai", "dataset-1_walk_normal_001.bvh"))
    out, report = stretch_motion(take, 2.0)
    assert report.frames_out == 2 * take.n_frames
    assert all(30 <= w <= 35 for w in report.windows.values()), report.windows  # one stride, ~1.07 s at 30 fps
    X, _ = pose_matrix(take, rep="quatlog", root_features="drop")
    Y, _ = pose_matrix(out, rep="quatlog", root_features="drop")
    f_in = dominant_frequency(X[:, np.argmax(X.std(axis=0))])
    f_out = dominant_frequency(Y[:, np.argmax(X.std(axis=0))])
    assert abs(f_out / f_in - 1) < 0.05
    assert max_step(Y) <= 1.5 * max_step(X)
    p_in, p_out = take.translations[:, take.travel_joint], out.translations[:, take.travel_joint]
    speed_in = np.linalg.norm(np.diff(p_in, axis=0), axis=1).mean()
    speed_out = np.linalg.norm(np.diff(p_out, axis=0), axis=1).mean()
    assert abs(speed_out / speed_in - 1) < 0.05


# -- only the periodic part is warped (issue 11, item 8) -------------------------------------------------------------


def test_a_one_off_gesture_is_refused_and_force_warps_it_whole():
    take = synthetic_gesture(240, fps=60).motion
    with pytest.raises(NoPeriodicMotion, match="no periodic motion to stretch"):
        stretch_motion(take, 2.0)
    with pytest.warns(MocycleWarning, match="repeats what happens once"):
        out, report = stretch_motion(take, 2.0, force=True)
    assert out.n_frames == 480 and report.forced


def _standing_start(stand: int = 90, walk_frames: int = 420):
    """A walk that starts from standing: the walk's first pose held (with a little sway) for ``stand`` frames."""
    walk = synthetic_walk(walk_frames, fps=60, period_s=1.0, noise_deg=0.5, seed=5).motion
    rng = np.random.default_rng(1)
    q = np.repeat(walk.rotations[:1], stand, axis=0)
    t = np.repeat(walk.translations[:1], stand, axis=0)
    sway = Rotation.from_rotvec(np.radians(0.5) * rng.normal(size=(stand * walk.n_joints, 3)))
    q = (sway * Rotation.from_quat(q.reshape(-1, 4))).as_quat().reshape(q.shape)
    still = walk.replace(rotations=q, translations=t)
    return concatenate([still, walk]), stand


def test_a_standing_start_is_kept_as_captured_and_only_the_walk_is_stretched():
    take, stand = _standing_start()
    out, report = stretch_motion(take, 2.0)
    assert out.n_frames == 2 * take.n_frames
    (s, e), = report.regions
    assert s >= stand - 30 and e == take.n_frames     # the walk, not the standing start
    assert report.regions_out[0][0] == s and report.regions_out[0][1] == out.n_frames
    # the standing start comes out once, as captured
    assert max_angle(out.rotations[:s], take.rotations[:s]) < 1e-9
    assert np.allclose(out.translations[:s], take.translations[:s])
    def standing(m):
        return int((np.linalg.norm(np.diff(m.root_positions, axis=0), axis=1) < 0.05).sum())

    assert standing(out) <= standing(take) + 5       # not a second standing start
    # no pop at the join: the largest frame step is an ordinary one
    X, _ = pose_matrix(take, rep="quatlog", root_features="drop")
    Y, _ = pose_matrix(out, rep="quatlog", root_features="drop")
    assert max_step(Y) <= 1.5 * max_step(X)
    steps = np.linalg.norm(np.diff(out.root_positions, axis=0), axis=1)
    assert steps.max() <= 1.5 * np.linalg.norm(np.diff(take.root_positions, axis=0), axis=1).max()


def test_a_walk_that_stops_keeps_its_ending_and_walks_further():
    take, stand = _standing_start()
    ending = take.replace(rotations=take.rotations[::-1].copy(), translations=take.translations[::-1].copy())  # a stop
    out, report = stretch_motion(ending, 1.5)
    (s, e), = report.regions
    assert s == 0 and e <= ending.n_frames - stand + 30
    # the walk grows by whole strides (60 frames), so that it ends as captured: about 1.5 times the take
    assert abs(out.n_frames - 1.5 * ending.n_frames) <= 30 and (out.n_frames - ending.n_frames) % 60 == 0
    X, _ = pose_matrix(ending, rep="quatlog", root_features="drop")
    Y, _ = pose_matrix(out, rep="quatlog", root_features="drop")
    assert max_step(Y) <= 1.5 * max_step(X)                                   # no pop where the walk stops
    assert np.abs(Y).max(axis=0).max() <= 1.05 * np.abs(X).max(axis=0).max()  # and no pose it never had
    n_end = ending.n_frames - e
    # the ending is the captured one, moved on by the longer walk (same poses, same relative path)
    assert max_angle(out.rotations[-n_end:, 1:], ending.rotations[-n_end:, 1:]) < 1e-9
    rel_in = ending.root_positions[-n_end:] - ending.root_positions[-n_end]
    rel_out = out.root_positions[-n_end:] - out.root_positions[-n_end]
    assert np.abs(rel_out - rel_in).max() < 1e-6 * (1 + np.abs(rel_in).max()) + 1e-6
    walked_in = np.linalg.norm(ending.root_positions[e - 1] - ending.root_positions[0])
    walked_out = np.linalg.norm(out.root_positions[-n_end - 1] - out.root_positions[0])
    assert walked_out > 1.3 * walked_in
