"""Ground truth of the synthetic takes: shapes, phase, periodicity, noise, root, skeleton."""

from __future__ import annotations

import time

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocycle.datasets import (
    SyntheticTake,
    humanoid_skeleton,
    synthetic_nonperiodic,
    synthetic_run,
    synthetic_still,
    synthetic_walk,
    synthetic_walk_then_run,
)
from mocycle.errors import MocycleError
from mocycle.motion import JOINT_GROUPS, Motion


def geodesic_deg(qa: np.ndarray, qb: np.ndarray) -> np.ndarray:
    """Angle (degrees) between two broadcastable arrays of quaternions ``(..., 4)``."""
    qa, qb = np.broadcast_arrays(qa, qb)
    shape = qa.shape[:-1]
    ra, rb = Rotation.from_quat(qa.reshape(-1, 4)), Rotation.from_quat(qb.reshape(-1, 4))
    return np.degrees((ra.inv() * rb).magnitude()).reshape(shape)


def lowest_points(motion: Motion) -> np.ndarray:
    """``(T,)`` height of the lowest foot point (heels, joints, End Sites), cm."""
    R, P = motion.world_transforms()
    E = motion.world_positions(end_sites=True)
    sk = motion.skeleton
    heels = [P[:, sk.index(f)] + R[:, sk.index(f)] @ np.array([0.0, -7.0, -4.0])
             for f in ("LeftFoot", "RightFoot")]
    return np.concatenate([E, np.stack(heels, axis=1)], axis=1)[..., 1].min(axis=1)


def channel_angles(motion: Motion) -> np.ndarray:
    """``(T, J, 3)`` Euler angles in each joint's own channel order, degrees."""
    sk = motion.skeleton
    return np.stack(
        [Rotation.from_quat(motion.rotations[:, j]).as_euler(sk.euler_order(j), degrees=True)
         for j in range(sk.n_joints)],
        axis=1,
    )


def wrap_deg(a: np.ndarray) -> np.ndarray:
    return (a + 180.0) % 360.0 - 180.0


# -- skeleton ------------------------------------------------------------------


def test_skeleton_structure():
    sk = humanoid_skeleton()
    assert 18 <= sk.n_joints <= 24
    assert sk.names[0] == "Hips" and sk.parents[0] == -1
    assert all(sk.parents[j] < j for j in range(1, sk.n_joints))
    assert sk.channels[0] == (
        "Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation"
    )
    assert all(len(c) == 3 for c in sk.channels[1:])
    orders = {sk.euler_order(j) for j in range(sk.n_joints)}
    assert len(orders) >= 2 and "ZYX" in orders
    # every leaf joint carries an End Site
    leaves = {j for j in range(sk.n_joints) if not sk.children(j)}
    assert leaves == {s.parent for s in sk.end_sites}
    assert {sk.names[j] for j in leaves} == {
        "Head", "LeftHand", "RightHand", "LeftToeBase", "RightToeBase"
    }


def test_skeleton_names_match_joint_groups():
    sk = humanoid_skeleton()
    legs = {sk.names[j] for j in sk.select("legs")}
    arms = {sk.names[j] for j in sk.select("arms")}
    spine = {sk.names[j] for j in sk.select("spine")}
    for side in ("Left", "Right"):
        assert {f"{side}UpLeg", f"{side}Leg", f"{side}Foot", f"{side}ToeBase"} <= legs
        assert {f"{side}Shoulder", f"{side}Arm", f"{side}ForeArm", f"{side}Hand"} <= arms
    assert {"Spine", "Spine1", "Neck", "Head"} <= spine
    assert not (arms & legs) and not (arms & spine)
    assert set(JOINT_GROUPS) >= {"legs", "arms", "spine"}


def test_rest_pose_proportions():
    sk = humanoid_skeleton()
    P = Motion.rest(sk).world_positions(end_sites=True)[0]
    names = list(sk.names) + [s.name for s in sk.end_sites]
    y = dict(zip(names, P[:, 1], strict=True))
    assert y["LeftToeEnd"] == pytest.approx(0.0, abs=1e-9)  # standing on the floor
    assert 160.0 < y["HeadTop"] < 190.0  # centimetres, Y up
    leg = y["LeftUpLeg"] - y["LeftFoot"]
    assert 80.0 < leg < 95.0
    # left is +X, the feet point forward (+Z)
    assert P[names.index("LeftHand"), 0] > 40.0 > -40.0 > P[names.index("RightHand"), 0]
    assert P[names.index("LeftToeEnd"), 2] > 10.0


# -- walk: shapes, determinism, phase --------------------------------------------


def test_walk_shapes_and_types():
    take = synthetic_walk()
    assert isinstance(take, SyntheticTake)
    m = take.motion
    assert m.n_frames == 600 and m.n_joints == humanoid_skeleton().n_joints
    assert m.rotations.shape == (600, m.n_joints, 4)
    assert m.fps == pytest.approx(60.0)
    for arr in (take.phase, take.unwrapped_phase, take.period_frames):
        assert arr.shape == (600,)
    assert take.euler_deg.shape == (600, m.n_joints, 3)
    assert take.segments == [("walk", 0, 600)]
    assert "walk" in take.description


def test_walk_is_deterministic_for_a_seed():
    a = synthetic_walk(noise_deg=2.0, seed=3)
    b = synthetic_walk(noise_deg=2.0, seed=3)
    c = synthetic_walk(noise_deg=2.0, seed=4)
    np.testing.assert_array_equal(a.motion.rotations, b.motion.rotations)
    np.testing.assert_array_equal(a.motion.translations, b.motion.translations)
    assert not np.allclose(a.motion.rotations, c.motion.rotations)


@pytest.mark.parametrize("gen", [synthetic_walk, synthetic_run])
@pytest.mark.parametrize("n_frames,fps,period_s", [(600, 60.0, 1.0), (500, 120.0, 0.8),
                                                   (333, 30.0, 1.3)])
def test_phase_constant_speed(gen, n_frames, fps, period_s):
    take = gen(n_frames=n_frames, fps=fps, period_s=period_s, phase0=0.3)
    u, p = take.unwrapped_phase, take.phase
    assert np.all((p >= 0.0) & (p < 1.0))
    assert np.all(np.diff(u) > 0)
    np.testing.assert_allclose(p, u % 1.0, atol=1e-12)
    assert u[0] == pytest.approx(0.3, abs=1e-12)
    per_frame = 1.0 / (period_s * fps)
    np.testing.assert_allclose(np.diff(u), per_frame, atol=1e-12)
    # n_frames frames span n_frames / (period_s * fps) cycles
    assert u[-1] - u[0] + per_frame == pytest.approx(n_frames / (period_s * fps), abs=1e-9)
    np.testing.assert_allclose(take.period_frames, period_s * fps, rtol=1e-12)


def test_phase_with_speed_change():
    take = synthetic_walk(speed_change=0.2)
    pf, u = take.period_frames, take.unwrapped_phase
    assert pf[0] == pytest.approx(60.0)
    assert pf[-1] == pytest.approx(60.0 / 1.2)
    assert np.all(np.diff(pf) < 0)
    # the phase is the integral of the frequency (trapezoid is exact for a linear ramp)
    np.testing.assert_allclose(np.diff(u), 0.5 * (1 / pf[1:] + 1 / pf[:-1]), atol=1e-12)
    assert u[-1] - u[0] == pytest.approx(599 / 60 * 1.1, abs=1e-9)
    slower = synthetic_walk(speed_change=-0.3)
    assert slower.period_frames[-1] == pytest.approx(60.0 / 0.7)


def test_pose_is_a_function_of_phase_only():
    """The pose at any frame equals the designed pose at that frame's true phase."""
    take = synthetic_run(n_frames=300, speed_change=0.35, phase0=0.6)
    for k in (0, 77, 150, 299):
        ref = synthetic_run(n_frames=1, phase0=float(take.phase[k]))
        assert geodesic_deg(take.motion.rotations[k], ref.motion.rotations[0]).max() < 1e-6
        assert take.motion.root_positions[k, 1] == pytest.approx(
            ref.motion.root_positions[0, 1], abs=1e-6)


def test_fps_only_changes_sampling():
    a = synthetic_walk(n_frames=300, fps=60.0)
    b = synthetic_walk(n_frames=600, fps=120.0)
    assert geodesic_deg(a.motion.rotations, b.motion.rotations[::2]).max() < 1e-6
    np.testing.assert_allclose(a.motion.root_positions, b.motion.root_positions[::2], atol=1e-9)


# -- walk: periodicity and asymmetry ---------------------------------------------


@pytest.mark.parametrize("gen,period", [(synthetic_walk, 60), (synthetic_run, 42)])
def test_full_cycle_repeats_and_half_cycle_differs(gen, period):
    take = gen(n_frames=4 * period, period_s=period / 60.0)
    q = take.motion.rotations
    assert geodesic_deg(q[:-period], q[period:]).max() < 1e-8
    rp = take.motion.root_positions
    np.testing.assert_allclose(rp[period:, :2], rp[:-period, :2], atol=1e-8)
    stride = rp[period:, 2] - rp[:-period, 2]
    np.testing.assert_allclose(stride, stride[0], atol=1e-8)
    half = period // 2
    diff = geodesic_deg(q[:-half], q[half:]).mean(axis=1)  # mean over joints, per frame
    assert diff.min() > 5.0


def test_walk_pose_is_one_to_one_over_a_cycle():
    q = synthetic_walk(n_frames=60).motion.rotations  # one cycle, one frame per 1/60 cycle
    d = geodesic_deg(q[:, None], q[None, :]).mean(axis=2)  # (60, 60) mean joint angle
    lag = np.abs(np.arange(60)[:, None] - np.arange(60)[None, :])
    lag = np.minimum(lag, 60 - lag)
    assert d[lag >= 3].min() > 1.0


def test_left_right_asymmetric():
    """Half a cycle later the pose is not the mirror image (a slight limp)."""
    take = synthetic_walk(n_frames=60)
    e = take.euler_deg
    sk = take.motion.skeleton
    left = [sk.index(n) for n in ("LeftUpLeg", "LeftLeg", "LeftArm")]
    right = [sk.index(n) for n in ("RightUpLeg", "RightLeg", "RightArm")]
    # sagittal leg angles (X is the last channel of ZYX) and arm swing (Y, last of ZXY)
    lx = e[:, left, 2]
    rx = np.roll(e[:, right, 2], -30, axis=0)
    assert np.abs(np.abs(lx) - np.abs(rx)).max(axis=0).min() > 1.0


def test_euler_channels_reproduce_rotations():
    takes = (synthetic_walk(noise_deg=2.0, drift=0.5), synthetic_walk(n_frames=3000, drift=1.0),
             synthetic_run(), synthetic_still(), synthetic_walk_then_run(noise_deg=1.0),
             synthetic_nonperiodic())
    for take in takes:
        got = channel_angles(take.motion)
        assert np.abs(wrap_deg(got - take.euler_deg)).max() < 1e-8


def test_written_bvh_holds_the_designed_angles(tmp_path):
    from mocycle.io import read, write

    take = synthetic_walk(n_frames=120, noise_deg=1.0, drift=0.5)
    path = write(take.motion, tmp_path / "walk.bvh")
    text = path.read_text()
    body = text.split("Frame Time:", 1)[1].split("\n", 1)[1]
    values = np.loadtxt(body.splitlines(), ndmin=2)
    sk = take.motion.skeleton
    rot_cols, k = [], 0
    for chans in sk.channels:
        for c in chans:
            if c.endswith("rotation"):
                rot_cols.append(k)
            k += 1
    assert values.shape == (120, sk.n_channels)
    rot = values[:, rot_cols].reshape(120, sk.n_joints, 3)
    assert np.abs(wrap_deg(rot - take.euler_deg)).max() < 1e-5
    np.testing.assert_allclose(values[:, :3], take.motion.root_positions, atol=1e-5)
    back = read(path)
    assert geodesic_deg(back.rotations, take.motion.rotations).max() < 1e-5


# -- noise and drift ---------------------------------------------------------------


@pytest.mark.parametrize("noise", [0.5, 3.0])
def test_noise_has_requested_std(noise):
    clean = synthetic_walk(n_frames=300)
    noisy = synthetic_walk(n_frames=300, noise_deg=noise, seed=1)
    d = wrap_deg(channel_angles(noisy.motion) - clean.euler_deg)
    assert np.std(d) == pytest.approx(noise, rel=0.05)
    assert abs(np.mean(d)) < 0.05 * noise
    # the truth does not change with noise
    np.testing.assert_array_equal(noisy.phase, clean.phase)


def test_drift_changes_posture_and_heading():
    base = synthetic_walk()
    drift = synthetic_walk(drift=1.0)
    sk = base.motion.skeleton
    t = np.arange(600) / 60.0

    def yaw(take):
        fwd = take.motion.rotation(0).apply([0.0, 0.0, 1.0])
        return np.degrees(np.arctan2(fwd[:, 0], fwd[:, 2]))

    np.testing.assert_allclose(wrap_deg(yaw(drift) - yaw(base) - 3.0 * t), 0.0, atol=1e-9)
    # only the root turns: the other joints' local rotations keep their design
    legs = sk.select("legs")[1:]
    assert geodesic_deg(drift.motion.rotations[:, legs], base.motion.rotations[:, legs]).max() < 1e-8
    spine = sk.index("Spine")
    lean = drift.euler_deg[:, spine, 2] - base.euler_deg[:, spine, 2]
    assert lean[-1] > lean[0] + 1.0
    # the path turns with the heading: the root ends far to the side
    assert abs(drift.motion.root_positions[-1, 0]) > 100.0
    assert abs(base.motion.root_positions[-1, 0]) < 5.0
    # no longer exactly periodic
    q = drift.motion.rotations
    assert geodesic_deg(q[:-60], q[60:]).max() > 1.0


# -- root ---------------------------------------------------------------------------


@pytest.mark.parametrize("gen,stride", [(synthetic_walk, 140.0), (synthetic_run, 250.0)])
def test_root_advances_forward(gen, stride):
    take = gen()
    rp = take.motion.root_positions
    assert np.all(np.diff(rp[:, 2]) > 0)
    cycles = take.unwrapped_phase[-1] - take.unwrapped_phase[0]
    assert rp[-1, 2] - rp[0, 2] == pytest.approx(stride * cycles, abs=5.0)
    assert np.abs(rp[:, 0]).max() < 5.0
    assert 80.0 < rp[:, 1].min() and rp[:, 1].max() < 105.0


@pytest.mark.parametrize("gen", [synthetic_walk, synthetic_run])
def test_vertical_bob_at_twice_the_step_frequency(gen):
    take = gen()
    n = int(np.floor(take.unwrapped_phase[-1] - take.unwrapped_phase[0]))
    frames = int(round(n * take.period_frames[0]))
    y = take.motion.root_positions[:frames, 1]
    spectrum = np.abs(np.fft.rfft(y - y.mean()))
    assert np.argmax(spectrum) == 2 * n


def test_feet_stay_on_the_floor_while_walking():
    lowest = lowest_points(synthetic_walk(speed_change=0.3).motion)
    assert lowest.min() > -0.05
    assert lowest.max() < 1.0  # one foot is always down


def test_run_has_a_flight_phase():
    lowest = lowest_points(synthetic_run().motion)
    assert lowest.min() > -0.05
    assert lowest.max() > 3.0  # both feet off the ground
    walk = synthetic_walk()
    run = synthetic_run()
    assert np.ptp(run.motion.root_positions[:, 1]) > 2 * np.ptp(walk.motion.root_positions[:, 1])


# -- walk then run --------------------------------------------------------------------


def test_walk_then_run_segments_and_phase():
    take = synthetic_walk_then_run(n_walk=300, n_run=240, blend_frames=20)
    T = take.motion.n_frames
    assert T == 540
    assert take.segments == [("walk", 0, 300), ("run", 300, 540)]
    assert sum(b - a for _, a, b in take.segments) == T
    assert all(take.segments[i][2] == take.segments[i + 1][1]
               for i in range(len(take.segments) - 1))
    nan = np.isnan(take.phase)
    assert nan.sum() == 20 and np.all(np.flatnonzero(nan) == np.arange(290, 310))
    assert np.array_equal(nan, np.isnan(take.period_frames))
    ok = ~nan
    assert np.all((take.phase[ok] >= 0) & (take.phase[ok] < 1))
    assert np.all(np.diff(take.unwrapped_phase[ok]) > 0)
    np.testing.assert_allclose(take.period_frames[:290], 60.0)
    np.testing.assert_allclose(take.period_frames[310:], 42.0)


def test_walk_then_run_matches_the_pure_gaits():
    take = synthetic_walk_then_run(n_walk=300, n_run=240, blend_frames=20)
    walk = synthetic_walk(n_frames=290)
    assert geodesic_deg(take.motion.rotations[:290], walk.motion.rotations).max() < 1e-8
    for k in (310, 400, 539):
        ref = synthetic_run(n_frames=1, phase0=float(take.phase[k]))
        assert geodesic_deg(take.motion.rotations[k], ref.motion.rotations[0]).max() < 1e-6


def test_walk_then_run_is_continuous():
    take = synthetic_walk_then_run(noise_deg=0.0)
    rp = take.motion.root_positions
    step = np.linalg.norm(np.diff(rp, axis=0), axis=1)
    assert step.max() < 8.0
    assert np.all(np.diff(rp[:, 2]) > 0)
    q = take.motion.rotations
    jump = geodesic_deg(q[1:], q[:-1]).max(axis=1)
    run_jump = geodesic_deg(synthetic_run().motion.rotations[1:],
                            synthetic_run().motion.rotations[:-1]).max()
    assert jump.max() < run_jump + 2.0


def test_walk_then_run_noise_and_no_blend():
    a = synthetic_walk_then_run(n_walk=120, n_run=120, noise_deg=1.0, seed=2)
    b = synthetic_walk_then_run(n_walk=120, n_run=120, noise_deg=1.0, seed=2)
    np.testing.assert_array_equal(a.motion.rotations, b.motion.rotations)
    hard = synthetic_walk_then_run(n_walk=120, n_run=120, blend_frames=0)
    assert not np.any(np.isnan(hard.phase))
    assert hard.period_frames[119] == 60.0 and hard.period_frames[120] == pytest.approx(42.0)


# -- non-periodic and still --------------------------------------------------------------


def test_nonperiodic():
    take = synthetic_nonperiodic()
    assert take.motion.n_frames == 600
    assert np.all(np.isnan(take.phase)) and np.all(np.isnan(take.period_frames))
    assert take.segments == [("nonperiodic", 0, 600)]
    again = synthetic_nonperiodic()
    np.testing.assert_array_equal(take.motion.rotations, again.motion.rotations)
    other = synthetic_nonperiodic(seed=1)
    assert not np.allclose(take.motion.rotations, other.motion.rotations)
    # it moves about as much as the walk does ...
    walk_sd = np.std(synthetic_walk().euler_deg, axis=0).mean()
    sd = np.std(take.euler_deg, axis=0).mean()
    assert 0.5 * walk_sd < sd < 3.0 * walk_sd
    # ... but never comes back to a pose the way a cycle does
    q = take.motion.rotations
    for lag in (30, 42, 60, 90, 120):
        assert geodesic_deg(q[:-lag], q[lag:]).mean() > 3.0
    rp = take.motion.root_positions
    assert np.linalg.norm(rp[-1, [0, 2]] - rp[0, [0, 2]]) > 50.0
    assert lowest_points(take.motion).min() > -0.05


def test_still():
    take = synthetic_still()
    assert take.motion.n_frames == 300
    np.testing.assert_allclose(take.motion.rotations[..., 3], 1.0)
    assert np.ptp(take.motion.root_positions, axis=0).max() == 0.0
    assert np.all(np.isnan(take.phase))
    noisy = synthetic_still(noise_deg=0.5, seed=1)
    assert np.std(channel_angles(noisy.motion)) == pytest.approx(0.5, rel=0.05)


# -- errors and speed ------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call",
    [
        lambda: synthetic_walk(n_frames=0),
        lambda: synthetic_walk(fps=0.0),
        lambda: synthetic_walk(period_s=0.0),
        lambda: synthetic_walk(speed_change=-1.0),
        lambda: synthetic_walk(noise_deg=-1.0),
        lambda: synthetic_walk(phase0=float("inf")),
        lambda: synthetic_walk(n_frames=2.5),
        lambda: synthetic_run(period_s=float("nan")),
        lambda: synthetic_nonperiodic(n_frames=-3),
        lambda: synthetic_still(fps=-60.0),
        lambda: synthetic_walk_then_run(n_walk=50, n_run=50, blend_frames=80),
    ],
)
def test_bad_arguments_raise(call):
    with pytest.raises(MocycleError):
        call()


def test_single_frame_walk():
    take = synthetic_walk(n_frames=1)
    assert take.motion.n_frames == 1 and take.period_frames[0] == pytest.approx(60.0)


def test_default_walk_is_fast():
    synthetic_walk()  # warm the caches
    best = min(_timed(synthetic_walk) for _ in range(5))
    assert best < 0.05


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def test_circle_walk_turns_by_its_turn_per_cycle_on_both_up_axes():
    from mocycle.cycle.representation import CycleSpace
    from mocycle.datasets import synthetic_circle_walk

    for up, axis in (("y", 1), ("z", 2)):
        take = synthetic_circle_walk(n_frames=120, fps=30.0, period_s=1.0, turn_per_cycle_deg=45.0, up=up)
        space = CycleSpace.fit(take.motion)
        _, L = space.encode(take.motion)
        assert np.isclose(np.degrees(L[-1, 3] - L[0, 3]), 45.0 * 119 / 30, atol=1.0)
        height = take.motion.world_positions()[:, 0, axis]
        assert 80 < height.mean() < 100  # the hips stay up along the vertical axis
        path = take.motion.root_positions
        assert np.linalg.norm(np.diff(path, axis=0), axis=1).max() < 10.0  # continuous


def test_walk_then_run_root_path_is_continuous():
    from mocycle.datasets import synthetic_walk_then_run

    take = synthetic_walk_then_run(n_walk=150, n_run=150, fps=30.0)
    step = np.linalg.norm(np.diff(take.motion.root_positions, axis=0), axis=1)
    assert step.max() < 1.2 * np.percentile(step, 99)  # no jump at the switch


def test_half_cycle_trap_is_left_right_symmetric():
    from mocycle.datasets import synthetic_half_cycle_trap

    take = synthetic_half_cycle_trap(n_frames=120, fps=30.0, period_s=1.0)
    P = take.motion.world_positions()
    skel = take.motion.skeleton
    hips = P[:, skel.index("Hips")]
    # half a cycle later the root is where it was, moved on by half a stride: its height repeats every step
    assert np.allclose(hips[15:, 1], hips[:-15, 1], atol=1e-6)
    left, right = P[:, skel.index("LeftFoot")] - hips, P[:, skel.index("RightFoot")] - hips
    assert np.allclose(left[15:, [1, 2]], right[:-15, [1, 2]], atol=1e-6)  # the feet trade places
