"""Ground truth of the takes that change what they do (issue 28), checked against the motion itself.

The heading is measured from the hips (perpendicular to the left-to-right upper-leg vector), the waving
from the hand's and elbow's motion, the standing from the feet: none of it uses the generators' truth to
measure.
"""

from __future__ import annotations

import numpy as np
import pytest

from mocycle.datasets import (
    STEADY_KINDS,
    synthetic_walk,
    synthetic_walk_then_wave,
    synthetic_walk_turn_walk,
    synthetic_wave,
)
from mocycle.errors import MocycleError


def hips_heading(take) -> np.ndarray:
    """``(T,)`` facing from the hips in degrees (0 = +Z, positive towards +X = left), unwrapped."""
    P = take.motion.world_positions()
    sk = take.motion.skeleton
    d = P[:, sk.index("RightUpLeg")] - P[:, sk.index("LeftUpLeg")]
    # forward = up x (left -> right) with up = +Y: (dz, 0, -dx)
    return np.degrees(np.unwrap(np.arctan2(d[:, 2], -d[:, 0])))


def smooth_cycle(x: np.ndarray, n: int) -> np.ndarray:
    """Moving mean over ``n`` frames (one cycle), valid part only: removes the pelvis' per-cycle swing."""
    return np.convolve(x, np.ones(n) / n, mode="valid")


def dominant_period(x: np.ndarray) -> float:
    """The period (frames) of the first autocorrelation peak of ``x`` ``(T,)`` or ``(T, D)``, refined."""
    x = np.asarray(x, dtype=np.float64).reshape(len(x), -1)
    x = x - x.mean(axis=0)
    n = len(x)
    f = np.fft.rfft(x, 2 * n, axis=0)
    ac = np.fft.irfft(np.abs(f) ** 2, axis=0)[:n].sum(axis=1)
    ac /= ac[0]
    lag = int(np.argmax(ac < 0))                   # past the first zero crossing
    k = lag + int(np.argmax(ac[lag:n // 2]))
    a, b, c = ac[k - 1], ac[k], ac[k + 1]
    return k + 0.5 * (a - c) / (a - 2 * b + c)


@pytest.mark.parametrize(("turn", "strides", "fps", "period_s"),
                         [(90, 2, 60, 1.0), (-90, 2, 30, 1.1), (45, 3, 60, 0.9), (-45, 3, 30, 1.2)])
def test_walk_turn_walk_heading_turns_only_in_the_turning_part(turn, strides, fps, period_s):
    take = synthetic_walk_turn_walk(n_before_s=4, turn_deg=turn, turn_strides=strides, n_after_s=4, fps=fps,
                                    period_s=period_s, noise_deg=1.0, seed=3)
    (k0, a, b), (k1, b1, c), (k2, c1, d) = take.segments
    assert (k0, k1, k2) == ("straight", "turning left" if turn > 0 else "turning right", "straight")
    assert a == 0 and b1 == b and c1 == c and d == take.n_frames
    assert b == round(4 * fps) and c - b == round(strides * period_s * fps)
    assert take.steady_parts == take.segments
    assert np.allclose(take.period_frames, period_s * fps)
    n = round(period_s * fps)
    h = hips_heading(take)
    # the hips' heading follows the truth within the pelvis' own swing (5 deg) and the noise
    assert np.max(np.abs(h - take.heading_deg)) < 10.0
    hs = smooth_cycle(h, n)               # hs[i] = mean heading over frames [i, i + n)
    # straight before and after: constant within 2 degrees once the pelvis swing is averaged out
    assert np.ptp(hs[:b - n]) < 2.0 and abs(np.mean(hs[:b - n])) < 2.0
    assert np.ptp(hs[c:]) < 2.0 and abs(np.mean(hs[c:]) - turn) < 2.0
    # the whole turn happens in [b, c): a cycle before b to a cycle after c turns turn_deg
    assert hs[c] - hs[b - n] == pytest.approx(turn, abs=3.0)
    # the heading rate is smooth: no jump anywhere in the truth, and it is largest inside the turn
    rate = np.diff(take.heading_deg) * fps
    assert np.max(np.abs(np.diff(rate))) < 0.1 * np.max(np.abs(rate))
    assert np.all(np.abs(rate[:b - 1]) < 1e-9) and np.all(np.abs(rate[c:]) < 1e-9)
    # the path turns with the body: the root's direction of travel over a cycle before and after
    root = take.motion.root_positions
    v0, v1 = root[b - 1] - root[b - 1 - n], root[c + n] - root[c]
    path_turn = np.degrees(np.arctan2(v1[0], v1[2]) - np.arctan2(v0[0], v0[2]))
    assert path_turn == pytest.approx(turn, abs=3.0)


def test_walk_turn_walk_zero_turn_and_bad_options():
    take = synthetic_walk_turn_walk(turn_deg=0.0, noise_deg=0.0)
    assert {s[0] for s in take.segments} == {"straight"}
    assert np.all(take.heading_deg == 0.0)
    with pytest.raises(MocycleError):
        synthetic_walk_turn_walk(turn_strides=0)
    with pytest.raises(MocycleError):
        synthetic_walk_turn_walk(n_before_s=-1)


def elbow_angle(take, side: str) -> np.ndarray:
    P = take.motion.world_positions()
    sk = take.motion.skeleton
    s, e, w = (P[:, sk.index(f"{side}{j}")] for j in ("Arm", "ForeArm", "Hand"))
    u, v = s - e, w - e
    cos = np.sum(u * v, axis=1) / np.linalg.norm(u, axis=1) / np.linalg.norm(v, axis=1)
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


@pytest.mark.parametrize(("hand", "period_s", "fps"), [("right", 0.6, 60), ("left", 0.5, 30), ("both", 0.8, 60)])
def test_wave_hand_oscillates_at_the_period_and_the_feet_stand(hand, period_s, fps):
    take = synthetic_wave(n_frames=6 * fps, fps=fps, hand=hand, wave_period_s=period_s, noise_deg=0.5, seed=1)
    labels = [s[0] for s in take.segments]
    assert labels == ["raise", "wave", "lower"]
    _, a, b = take.segments[1]
    assert take.steady_parts == [("wave", a, b)]
    p = period_s * fps
    assert np.allclose(take.period_frames[a:b], p) and np.all(np.isnan(take.period_frames[:a]))
    assert np.all(np.diff(take.unwrapped_phase[a:b]) == pytest.approx(1.0 / p))
    P = take.motion.world_positions()
    sk = take.motion.skeleton
    chest = P[:, sk.index("Spine2")]
    waving = ("Left", "Right") if hand == "both" else (hand.capitalize(),)
    for side in ("Left", "Right"):
        hand_rel = P[:, sk.index(f"{side}Hand")] - chest
        if side in waving:
            # raised: the hand is well above the chest while waving, below it before the raise
            assert np.min(hand_rel[a:b, 1]) > 30.0 and hand_rel[0, 1] < -30.0
            assert dominant_period(hand_rel[a:b]) == pytest.approx(p, rel=0.03)
            assert dominant_period(hand_rel[a:b, 1]) == pytest.approx(p, rel=0.03)   # its height too
            el = elbow_angle(take, side)[a:b]
            assert np.ptp(el) > 40.0
            assert dominant_period(el) == pytest.approx(p, rel=0.03)
        else:
            assert np.max(hand_rel[:, 1]) < -30.0                # the other arm hangs
            assert np.ptp(elbow_angle(take, side)) < 10.0
    for foot in ("LeftFoot", "RightFoot", "LeftToeBase", "RightToeBase"):
        f = P[:, sk.index(foot)]
        assert np.max(np.std(f, axis=0)) < 1.5                 # noise only (0.5 deg on each channel)
    assert np.ptp(take.motion.root_positions, axis=0).max() == 0.0


def test_wave_counts_and_no_raise():
    take = synthetic_wave(n_frames=300, fps=60, n_waves=4, wave_period_s=0.5, raise_s=0.5, noise_deg=0.0)
    assert [s[0] for s in take.segments] == ["stand", "raise", "wave", "lower", "stand"]
    _, a, b = take.segments[2]
    assert b - a == 120
    assert take.unwrapped_phase[b - 1] == pytest.approx(4.0 - 1.0 / 30.0)
    bare = synthetic_wave(n_frames=240, fps=60, raise_s=0.0, noise_deg=0.0)
    assert bare.segments == [("wave", 0, 240)]
    with pytest.raises(MocycleError):
        synthetic_wave(n_frames=60, n_waves=10)
    with pytest.raises(MocycleError):
        synthetic_wave(hand="middle")


def test_walk_then_wave_has_two_steady_parts_that_do_what_they_say():
    take = synthetic_walk_then_wave(walk_s=4, stop_s=0.8, wave_s=4, fps=60, period_s=1.0, hand="left",
                                    wave_period_s=0.6, noise_deg=0.5, seed=2)
    parts = take.steady_parts
    assert [p[0] for p in parts] == ["walk", "wave"]
    (_, w0, w1), (_, a, b) = parts
    assert w0 == 0 and w1 == 240 and a > w1 and b <= take.n_frames
    assert all(s[0] not in STEADY_KINDS for s in take.segments if s not in parts)
    root = take.motion.root_positions
    speed = np.linalg.norm(np.diff(root[:, [0, 2]], axis=0), axis=1) * take.fps
    assert np.median(speed[w0:w1 - 1]) == pytest.approx(140.0, rel=0.1)   # walking at 140 cm per 1 s cycle
    assert np.max(speed[a - 30:]) < 1e-6                                  # standing from the raise on
    P = take.motion.world_positions()
    sk = take.motion.skeleton
    # continuous: no joint jumps more in a frame than the walk's own fastest joint does
    step = np.linalg.norm(np.diff(P, axis=0), axis=2).max(axis=1)
    assert step[w1 - 1:].max() < 1.2 * step[:w1 - 1].max()
    hand_rel = P[:, sk.index("LeftHand")] - P[:, sk.index("Spine2")]
    assert dominant_period(hand_rel[a:b]) == pytest.approx(36.0, rel=0.03)
    assert dominant_period(root[w0:w1, 0]) == pytest.approx(60.0, rel=0.05)  # sways once a cycle
    for foot in ("LeftFoot", "RightFoot"):
        assert np.max(np.std(P[a:b, sk.index(foot)], axis=0)) < 1.5
    assert np.allclose(take.period_frames[w0:w1], 60.0) and np.allclose(take.period_frames[a:b], 36.0)


@pytest.mark.parametrize(("period_s", "fps"), [(1.0, 60), (1.1, 30), (0.7, 60)])
def test_short_walk_of_one_and_a_third_periods(period_s, fps):
    n = round(1.3 * period_s * fps)
    short = synthetic_walk(n_frames=n, fps=fps, period_s=period_s)
    long = synthetic_walk(n_frames=10 * n, fps=fps, period_s=period_s)
    assert short.n_frames == n
    # the short take is the start of the long one, with the same truth
    assert np.array_equal(short.motion.rotations, long.motion.rotations[:n])
    assert np.allclose(short.motion.root_positions, long.motion.root_positions[:n])
    assert short.unwrapped_phase[-1] - short.unwrapped_phase[0] == pytest.approx((n - 1) / (period_s * fps))
    assert 1.2 < (n - 1) / short.period_frames[0] < 1.4
    # and it really is periodic at period_frames: a frame one period on repeats the pose
    p = period_s * fps
    if p == round(p):
        k = int(p)
        dot = np.abs(np.sum(short.motion.rotations[k:] * short.motion.rotations[:n - k], axis=-1))
        assert np.allclose(dot, 1.0, atol=1e-9)
