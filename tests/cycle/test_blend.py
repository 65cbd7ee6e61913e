import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import shared_path
from helpers import max_angle
from mocycle.cycle import extract_cycle
from mocycle.cycle.blend import (
    align_phase,
    blend_cycles,
    check_weights,
    cycle_seam,
    resample_cycle,
    skeleton_differences,
    transition,
    transition_smoothness,
)
from mocycle.cycle.metric_rows import metric_features
from mocycle.cycle.metrics import template_error
from mocycle.datasets import humanoid_skeleton, synthetic_walk
from mocycle.errors import MocycleError
from mocycle.io import read
from mocycle.motion import Motion, Skeleton
from mocycle.rotations import weighted_rotation_mean


@pytest.fixture(scope="module")
def takes():
    return synthetic_walk(n_frames=400, period_s=1.0), synthetic_walk(n_frames=400, period_s=0.8, phase0=0.3)


@pytest.fixture(scope="module")
def cycles(takes):
    return tuple(extract_cycle(t.motion) for t in takes)


def _start_phase(take, cycle) -> float:
    """The true gait phase (cycles) of the cycle's frame 0, from the synthetic take's ground truth."""
    f = cycle.axis.frames()
    d = take.phase[f] - cycle.positions[np.searchsorted(cycle.axis.frames(), f)] / cycle.n_frames
    return float(np.angle(np.mean(np.exp(2j * np.pi * d))) / (2 * np.pi) % 1.0)


def _circular(a: float, b: float) -> float:
    return abs((a - b + 0.5) % 1.0 - 0.5)


def _loop_error(c1: Motion, c2: Motion) -> float:
    """RMS rotation error (rad per frame) between two loops at the best circular offset."""
    return template_error(metric_features(c1), metric_features(c2))[0]


def test_blended_period_lies_between_and_stride_is_blended(cycles):
    a, b = cycles
    for w in (0.25, 0.5, 0.75):
        r = blend_cycles([a, b], [1 - w, w])
        expected = (1 - w) * a.period_frames + w * b.period_frames
        assert b.period_frames < r.period_frames < a.period_frames
        assert np.isclose(r.period_frames, expected) and r.n_frames == round(expected)
        assert np.allclose(r.weights, [1 - w, w])
        assert abs(r.drift[2] - 140.0) < 1.0 and abs(np.degrees(r.drift[3])) < 0.5   # both strides: 140 cm
        walked = r.repeat(3, root="motion").root_positions
        assert abs(walked[-1, 2] - walked[0, 2] - 140.0 * (3 - 1 / r.n_frames)) < 3.0


def test_weight_one_reproduces_the_input_cycle(cycles):
    a, b = cycles
    r = blend_cycles([a, b], [1, 0])
    assert r.n_frames == a.n_frames and r.start_phase == 0.0
    assert max_angle(r.motion().rotations, a.motion().rotations) < 1e-9
    assert np.allclose(r.repeat(2, root="motion").translations, a.repeat(2, root="motion").translations, atol=1e-9)
    # the other way round: the second cycle, only shifted in phase to the first one's (by a fraction of a
    # frame too, so not to round-off; 0.03 rad RMS over all 66 angles is a small part of a frame's step)
    r = blend_cycles([a, b], [0, 1])
    assert r.n_frames == b.n_frames and _loop_error(r.motion(), b.motion()) < 0.03


def test_phase_offset_recovers_the_true_gait_phase(takes, cycles):
    r = blend_cycles(list(cycles), [0.5, 0.5])
    truth = (_start_phase(takes[0], cycles[0]) - _start_phase(takes[1], cycles[1])) % 1.0
    assert r.phase_offsets[0] == 0.0
    assert _circular(r.phase_offsets[1], truth) < 0.01   # under a frame of the 54-frame blend


def test_align_phase_finds_integer_shifts(cycles):
    a = cycles[0]
    N = a.n_frames
    for k in (0, 7, 31):
        assert _circular(align_phase(a, a.rolled(k)), -k / N) < 1e-6
        assert _circular(align_phase(a.rolled(k), a, n_frames=2 * N), k / N) < 1e-6


def test_sub_frame_offset_of_a_resampled_loop(cycles):
    from mocycle.cycle.blend import _best_shift

    a = cycles[0].motion()
    N = a.n_frames
    R = a.rotation_matrices().reshape(N, -1)
    for shift in (0.3, 4.6, 12.25):
        S = resample_cycle(a, N, shift=shift / N).rotation_matrices().reshape(N, -1)
        found, cost = _best_shift(R, S)
        assert abs(((found + shift) + N / 2) % N - N / 2) < 0.1
        assert cost.shape == (N,)


def test_blending_a_loop_with_its_own_rolled_copy_gives_it_back_only_when_aligned(cycles):
    a = cycles[0]
    r = blend_cycles([a, a.rolled(20)], [0.5, 0.5])
    assert _loop_error(r.motion(), a.motion()) < 1e-6
    unaligned = blend_cycles([a, a.rolled(20)], [0.5, 0.5], align=False)
    assert _loop_error(unaligned.motion(), a.motion()) > 0.1


def test_blend_loops_as_well_as_its_inputs(cycles):
    a, b = cycles
    for w in (0.3, 0.5):
        seam = blend_cycles([a, b], [1 - w, w]).seam()
        assert seam["seam_pose"] <= 1.0 and seam["seam_velocity"] <= 1.0
        assert seam["seam_pose_local"] < 1.5 and seam["seam_velocity_local"] < 1.5
    assert cycle_seam(a)["seam_pose"] <= 1.0


def test_rotations_are_blended_by_the_weighted_chordal_mean_of_scipy():
    rng = np.random.default_rng(1)
    q = Rotation.random(3 * 40, random_state=rng).as_quat().reshape(3, 40, 4)
    w = np.array([0.5, 0.2, 0.3])
    mean = weighted_rotation_mean(q, w)
    for i in range(40):
        ref = Rotation.from_quat(q[:, i]).mean(weights=w)
        assert (ref.inv() * Rotation.from_quat(mean[i])).magnitude() < 1e-7
    # and a 50/50 blend of two rotations about one axis is the half-way rotation, not an Euler average
    r1, r2 = Rotation.from_euler("xyz", [170, 0, 0], degrees=True), Rotation.from_euler("xyz", [-170, 0, 0],
                                                                                        degrees=True)
    half = Rotation.from_quat(weighted_rotation_mean(np.stack([r1.as_quat(), r2.as_quat()]), [1, 1]))
    assert abs(abs(half.as_euler("xyz", degrees=True)[0]) - 180) < 1e-6


def test_transition_moves_period_and_pose_continuously(cycles):
    a, b = cycles
    tr = transition(a, b, cycles=3)
    pa, pb = a.period_frames, b.period_frames
    assert abs(tr.motion.n_frames - 3 * (pa + pb) / 2) <= 0.5
    assert abs(tr.period_frames[0] - pa) < 0.2 and abs(tr.period_frames[-1] - pb) < 0.2
    assert np.all(np.diff(tr.period_frames) <= 1e-9)                   # monotonic, from A's to B's
    assert np.all(np.diff(tr.weights) >= 0) and tr.weights[0] == 0.0 and tr.weights[-1] > 0.99
    dphase = np.diff(tr.phase)
    assert np.all(dphase > 0) and np.abs(np.diff(dphase)).max() < 1e-3  # the phase speeds up with no jump
    assert abs(tr.phase[-1] + dphase[-1] - 3) < 1e-3                     # frame T would be phase 3
    # frame 0 is A's loop frame 0 (in place); pose steps stay ordinary
    start = a.motion("inplace")
    assert max_angle(tr.motion.rotations[0, 1:], start.rotations[0, 1:]) < 1e-6
    sm = transition_smoothness(tr)   # no step or velocity change stands out from its neighbours more than
    assert sm["step_local"] < 1.1 * sm["input_step_local"]           # in the input loops
    assert sm["velocity_local"] < 1.1 * sm["input_velocity_local"]
    assert sm["step_ratio"] < 1.3 * sm["input_step_ratio"] * pa / pb  # the global figures grow with the tempo
    root = tr.motion.root_positions
    assert abs(root[-1, 2] - root[0, 2] - 140 * 3) < 10                  # three strides of 140 cm
    inplace = transition(a, b, cycles=2, root="inplace")
    assert np.ptp(inplace.motion.root_positions[:, 2]) < 20


def test_inputs_at_other_frame_rates_are_blended_in_seconds(cycles):
    a = cycles[0]
    slow = extract_cycle(synthetic_walk(n_frames=200, fps=30.0, period_s=0.8).motion)   # 24 frames at 30 fps
    r = blend_cycles([a, slow], [0.5, 0.5])
    assert np.isclose(r.input_periods[1], slow.period_frames * 2)
    assert abs(r.period_frames - 0.5 * (a.period_frames + 48)) < 0.5 and np.isclose(r.motion().fps, 60)


def _renamed(motion: Motion, old: str, new: str) -> Motion:
    s = motion.skeleton
    skel = Skeleton(tuple(new if n == old else n for n in s.names), s.parents, s.offsets, s.channels, s.end_sites)
    return Motion(skel, motion.rotations, motion.translations, motion.frame_time)


def test_different_skeletons_are_refused_naming_the_joints(takes):
    walk = takes[0].motion
    with pytest.raises(MocycleError, match="LeftKnee.*only in the second|only in the first.*LeftLeg"):
        blend_cycles([walk, _renamed(walk, "LeftLeg", "LeftKnee")])
    s = humanoid_skeleton()
    offsets = s.offsets.copy()
    j = s.index("RightForeArm")
    offsets[j] *= 1.5
    longer = Motion(Skeleton(s.names, s.parents, offsets, s.channels, s.end_sites), walk.rotations,
                    None, walk.frame_time, root_positions=walk.root_positions)
    with pytest.raises(MocycleError, match="rest offsets.*'RightForeArm'"):
        transition(walk, longer)


@pytest.mark.parametrize("weights,message", [([1, -1], ">= 0"), ([1, 2, 3], "must be 2 numbers"),
                                             ([0, 0], "all zero"), (["a", 1], "numbers"),
                                             ([np.nan, 1], ">= 0")])
def test_bad_weights_are_refused(cycles, weights, message):
    with pytest.raises(MocycleError, match=message):
        blend_cycles(list(cycles), weights)


def test_bad_arguments_are_refused(cycles):
    a, b = cycles
    assert np.allclose(check_weights(None, 4), 0.25)
    with pytest.raises(MocycleError, match="non-empty list"):
        blend_cycles([])
    with pytest.raises(MocycleError, match="Motion or a Cycle"):
        blend_cycles([a, "walk.bvh"])
    with pytest.raises(MocycleError, match="positive integer"):
        transition(a, b, cycles=0)
    with pytest.raises(MocycleError, match="root must be"):
        transition(a, b, root="sideways")
    with pytest.raises(MocycleError, match=">= 2"):
        resample_cycle(a.motion(), 1)


def test_resample_cycle_keeps_the_loop(cycles):
    m = cycles[0].motion()
    same = resample_cycle(m, m.n_frames)
    assert max_angle(same.rotations, m.rotations) < 1e-9 and np.allclose(same.translations, m.translations)
    longer = resample_cycle(m, 2 * m.n_frames)
    assert max_angle(longer.rotations[::2], m.rotations) < 1e-9 and np.isclose(longer.frame_time, m.frame_time / 2)
    # the wrap is part of the circle: the last new frame lies between the last old frame and the first
    assert max_angle(longer.rotations[-1:], m.rotations[-1:]) < max_angle(m.rotations[-1:], m.rotations[:1])


def test_bandai_normal_and_tired_walks_blend_into_a_loop():
    normal = read(shared_path("bandai", "dataset-1_walk_normal_001.bvh"))
    tired = read(shared_path("bandai", "dataset-1_walk_tired_001.bvh"))
    cn, ct = extract_cycle(normal), extract_cycle(tired)
    lo, hi = sorted([cn.period_frames, ct.period_frames])
    for w in (0.3, 0.5, 0.7):
        r = blend_cycles([cn, ct], [1 - w, w])
        assert lo < r.period_frames < hi
        seam = r.seam()
        assert seam["seam_pose"] <= 1.0 and seam["seam_velocity"] <= 1.0, seam
        assert 115 < r.drift[2] < 140   # between the tired (120 cm) and the normal (137 cm) stride
    tr = transition(cn, ct, cycles=3)
    assert np.all(np.diff(tr.period_frames) >= -1e-9)
    assert abs(tr.period_frames[0] - cn.period_frames) < 0.3 and abs(tr.period_frames[-1] - ct.period_frames) < 0.3
    sm = transition_smoothness(tr)
    assert sm["step_local"] < 1.1 * sm["input_step_local"] and sm["velocity_local"] < 1.1 * sm["input_velocity_local"]


def test_three_takes_blend_with_normalised_weights(cycles):
    a, b = cycles
    r = blend_cycles([a, b, a.rolled(13)], [1, 1, 2])
    assert np.allclose(r.weights, [0.25, 0.25, 0.5])
    assert np.isclose(r.period_frames, 0.75 * a.period_frames + 0.25 * b.period_frames)
    assert _circular(r.phase_offsets[2], -13 / a.n_frames) < 0.02
    assert r.seam()["seam_pose"] <= 1.0


def test_rest_offsets_agree_within_the_offset_tolerance():
    """A file's two takes may store a bone's rest offset with float32 round-off apart (RobotExpressive's palms
    3.8e-7 m); a real difference of bone length is still named."""
    a = humanoid_skeleton()
    near, far = a.offsets.copy(), a.offsets.copy()
    size = float(np.abs(a.offsets).max())
    near[5] += 2e-6 * size
    far[5] += 1e-3 * size
    as_near = Skeleton(a.names, a.parents, near, a.channels, a.end_sites)
    as_far = Skeleton(a.names, a.parents, far, a.channels, a.end_sites)
    assert skeleton_differences(a, as_near) == []
    assert skeleton_differences(a, as_far) == [f"joints with other rest offsets (bone lengths): {a.names[5]!r}"]


def test_a_blended_cycle_summarises_without_a_phase():
    """A blend has no one take's phase (``Cycle.periodic`` is None): its summary says so by leaving the phase's
    provenance out instead of failing (found by mypy once cycle.blend was type-checked)."""
    a = extract_cycle(synthetic_walk(n_frames=300, period_s=1.0).motion)
    b = extract_cycle(synthetic_walk(n_frames=300, period_s=0.8, phase0=0.4).motion)
    blended = blend_cycles([a, b], [0.5, 0.5]).cycle
    assert blended.periodic is None
    facts = blended.to_dict()
    assert facts["method"] == "blend" and facts["cycle_frames"] == blended.n_frames
