import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import shared_path
from helpers import tiny_skeleton
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError
from mocycle.io import read
from mocycle.io.swings_json import segmentation_from_dict, swings_document
from mocycle.motion import Motion
from mocycle.swings import PAPER_WINDOW_S, choose_joints, segment
from mocycle.swings.segment import angular_velocity, grow_swings, swing_error, unit_axes, window_frames

AXIS = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
BASE = Rotation.from_rotvec([0.2, 0.1, -0.3])


def swing_then_hold(fps=120, turn_deg=90.0, swing_s=1.0, hold_s=1.0, lead_s=0.0):
    """Joint 'Left Up Leg' still, then turning about AXIS at constant speed, then still."""
    n_lead, n_sw, n_hold = int(round(lead_s * fps)), int(round(swing_s * fps)), int(round(hold_s * fps))
    theta = np.concatenate([np.zeros(n_lead), np.linspace(0, np.radians(turn_deg), n_sw + 1),
                            np.full(n_hold, np.radians(turn_deg))])
    skel = tiny_skeleton()
    q = np.zeros((theta.size, skel.n_joints, 4))
    q[..., 3] = 1.0
    q[:, 1] = (Rotation.from_rotvec(theta[:, None] * AXIS) * BASE).as_quat()
    return Motion(skel, q, None, 1.0 / fps), n_lead, n_lead + n_sw


def test_constant_speed_swing_then_hold_is_one_swing_with_the_true_axis_and_angles():
    m, s0, s1 = swing_then_hold(lead_s=0.5)
    seg = segment(m, joints="Left Up Leg")
    assert seg.joints == [1]
    (sw,) = seg.swings
    # the box filter smears the ends by at most half its 20 frames
    assert s0 - 10 <= sw.start <= s0 + 1 and s1 - 1 <= sw.end <= s1 + 10
    assert np.degrees(np.arccos(abs(np.dot(sw.axis, AXIS)))) < 0.5
    turned = np.sign(np.dot(sw.axis, AXIS)) * np.degrees(sw.end_angle - sw.start_angle)
    assert turned == pytest.approx(90.0, abs=2.0)
    # the still parts are holds: before the swing and after it
    holds = seg.holds_of(1)
    assert holds[0].start == 0 and holds[-1].end == m.n_frames - 1
    assert all(h.end < sw.start or h.start > sw.end for h in holds)


def test_window_is_in_seconds():
    assert window_frames(PAPER_WINDOW_S, 120) == 20
    assert window_frames(PAPER_WINDOW_S, 30) == 5
    assert window_frames(PAPER_WINDOW_S, 60) == 10
    # the same swing at 30 fps is found at the same times
    m, s0, s1 = swing_then_hold(fps=30, lead_s=0.5)
    (sw,) = segment(m, joints="Left Up Leg").swings
    assert s0 - 3 <= sw.start <= s0 + 1 and s1 - 1 <= sw.end <= s1 + 3


def test_angular_velocity_of_a_steady_turn_is_constant():
    m, _, _ = swing_then_hold()
    w = angular_velocity(m.rotations[:, 1], m.frame_time)[:120]
    assert np.allclose(w, AXIS * np.radians(90.0), atol=1e-6)


def test_swing_error_and_growth():
    axes = np.tile([1.0, 0.0, 0.0], (30, 1))
    axes[15:] = [0.0, 1.0, 0.0]  # the axis turns 90°: cos 0, error 1
    err = swing_error(axes, 5)
    assert err[:12].max() < 1e-12 and err[14:17].min() > 0.1
    runs = grow_swings(axes, err, np.ones(30, bool), threshold=0.0, min_length=2)
    assert [(a, b) for a, b, _ in runs] == [(0, 14), (15, 29)]
    # a loose threshold lets one swing cross the turn
    runs = grow_swings(axes, err, np.ones(30, bool), threshold=0.6, min_length=2)
    assert len(runs) == 1 and runs[0][2] <= 0.6
    # still samples are never part of a swing
    eligible = np.ones(30, bool)
    eligible[5:8] = False
    runs = grow_swings(axes, np.where(eligible, err, np.inf), eligible, threshold=0.0, min_length=2)
    assert all(not (a <= 6 <= b) for a, b, _ in runs)


def test_unit_axes_of_still_samples_are_zero():
    axes, speed = unit_axes(np.array([[0.0, 0.0, 0.0], [0.0, 2.0, 0.0]]))
    assert np.allclose(axes, [[0, 0, 0], [0, 1, 0]]) and np.allclose(speed, [0, 2])


def test_higher_threshold_gives_fewer_longer_swings():
    m = synthetic_walk(n_frames=360, fps=60, noise_deg=0.5, seed=1).motion
    counts = [segment(m, threshold=t).n_swings for t in (0.05, 0.4, 1.5)]
    assert counts[0] > counts[1] > counts[2] > 0


def test_default_joints_leave_out_toes_and_still_joints():
    m = synthetic_walk(n_frames=240, seed=0).motion
    names = [m.skeleton.names[j] for j in choose_joints(m)]
    assert "LeftUpLeg" in names and "RightArm" in names
    assert not any("Toe" in n for n in names)
    still, _, _ = swing_then_hold()
    assert choose_joints(still) == [1]  # only the joint that moves
    assert choose_joints(m, "legs") == m.skeleton.select("legs")


@pytest.mark.parametrize("kwargs, word", [(dict(threshold=-0.1), r"threshold must be a number in \[0, 2\]"),
                                          (dict(threshold=2.5), r"in \[0, 2\]"),
                                          (dict(window_s=0), "window_s"), (dict(max_hold_s=0), "max_hold_s"),
                                          (dict(joints="Nope"), "Nope")])
def test_bad_options_raise_one_clear_error(kwargs, word):
    m, _, _ = swing_then_hold()
    with pytest.raises(MocycleError, match=word):
        segment(m, **kwargs)


def test_short_and_still_takes_have_only_holds():
    m, _, _ = swing_then_hold()
    seg = segment(m[:2])
    assert seg.n_swings == 0 and {h.joint for h in seg.holds} == set(range(m.n_joints))
    rest = Motion.rest(tiny_skeleton(), 50)
    assert segment(rest).n_swings == 0


def test_records_and_dict_round_trip():
    m, _, _ = swing_then_hold(lead_s=0.3)
    seg = segment(m)
    rows = seg.to_records()
    kinds = {r["kind"] for r in rows}
    assert kinds == {"swing", "hold"}
    sw = next(r for r in rows if r["kind"] == "swing")
    assert sw["joint"] == "Left Up Leg" and sw["end_s"] > sw["start_s"]
    back = segmentation_from_dict(swings_document(seg))
    assert back.swings == seg.swings and back.holds == seg.holds and back.joints == seg.joints
    assert back.skeleton.same_as(seg.skeleton)
    with pytest.raises(MocycleError, match="swings JSON"):
        segmentation_from_dict({"frames": 3})


def test_real_bandai_walk_segments_major_bones():
    m = read(shared_path("bandai", "dataset-1_walk_normal_001.bvh"))
    seg = segment(m)
    names = {m.skeleton.names[j] for j in seg.joints}
    assert {"UpperLeg_L", "LowerLeg_R", "UpperArm_L"} <= names and not any("Toes" in n for n in names)
    legs = seg.swings_of("UpperLeg_L")
    # about two thigh swings (forward, back) per stride of about 1.1 s over 6.5 s
    assert 8 <= len(legs) <= 30
    assert all(s.error <= 0.4 + 1e-9 for s in seg.swings)


def _fit_one_by_one(q, axes, speed, first, last, frame_time):
    """The per-swing fit written plainly (what fit_swings does for all swings at once)."""
    from mocycle.rotations import axis_angle_quats, mean_quat, quat_conj, quat_multiply, quat_rotvec, twist_angles

    w = speed[first:last + 1]
    axis = (axes[first:last + 1] * w[:, None]).sum(axis=0)
    axis = axis / np.linalg.norm(axis)
    qs = q[first:last + 2]
    theta = twist_angles(qs, axis)
    base = mean_quat(quat_multiply(axis_angle_quats(axis, -theta), qs))
    theta = twist_angles(quat_multiply(qs, quat_conj(base)[None, :]), axis)
    n = theta.size
    u = np.linspace(0.0, 1.0, n)
    dur = (n - 1) * frame_time
    a0, a1 = theta[0], theta[-1]
    h = np.stack([u**3 - 2 * u**2 + u, u**3 - u**2], axis=1) * dur
    rest = theta - (2 * u**3 - 3 * u**2 + 1) * a0 - (-2 * u**3 + 3 * u**2) * a1
    (v0, v1), *_ = np.linalg.lstsq(h, rest, rcond=None) if n >= 3 else [((a1 - a0) / dur,) * 2]
    shift = 2 * np.pi * np.round(a0 / (2 * np.pi))
    return np.r_[axis, a0 - shift, a1 - shift, v0, v1, quat_rotvec(base)]


@pytest.mark.parametrize("fps", [30, 120])
def test_swings_fitted_all_at_once_match_the_fit_of_each_swing(fps):
    from mocycle.swings.segment import fit_swings, smooth_velocity

    walk = synthetic_walk(n_frames=8 * fps, fps=fps, noise_deg=0.5, seed=3).motion
    j = walk.skeleton.index("LeftUpLeg")
    n = window_frames(PAPER_WINDOW_S, fps)
    omega = smooth_velocity(angular_velocity(walk.rotations[:, j], walk.frame_time), n)
    axes, speed = unit_axes(omega)
    eligible = speed >= np.radians(20.0)
    spans = grow_swings(axes, np.where(eligible, swing_error(axes, n), np.inf), eligible, 0.4, 2)
    spans = [sp for sp in spans if sp[1] < axes.shape[0] - 12]
    assert len(spans) > 10
    # and short ones: 2 frames (no inside to fit) and 3 frames (one inside frame for two end speeds)
    end = spans[-1][1]
    spans += [(end + 2, end + 2, 0.1), (end + 4, end + 5, 0.2), (end + 7, end + 8, 0.3)]
    fitted = fit_swings(walk.rotations[:, j], axes, speed, spans, j, "LeftUpLeg", walk.frame_time)
    for (a, b, err), s in zip(spans, fitted, strict=True):
        got = np.r_[s.axis, s.start_angle, s.end_angle, s.start_speed, s.end_speed, s.base]
        want = _fit_one_by_one(walk.rotations[:, j], axes, speed, a, b, walk.frame_time)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)
        assert (s.start, s.end, s.error) == (a, b + 1, err)


def test_translation_track_of_a_long_periodic_path_keeps_a_key_every_span_and_the_tolerance():
    from mocycle.swings.segment import TRACK_SPAN, translation_track

    t = np.arange(3 * TRACK_SPAN + 100)
    path = np.stack([np.sin(2 * np.pi * t / 120.0), np.zeros(t.size), 0.5 * t], axis=1)
    frames, values = translation_track(path, 0.01)
    assert set(range(0, t.size - 1, TRACK_SPAN)) | {t.size - 1} <= set(frames.tolist())
    back = np.stack([np.interp(t, frames, values[:, a]) for a in range(3)], axis=1)
    assert np.linalg.norm(back - path, axis=1).max() <= 0.01
