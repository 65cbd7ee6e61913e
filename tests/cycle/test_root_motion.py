"""``--root motion``: the root's height is periodic and a turning walk's loop walks a circle (issue 11, item 5)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocycle.cycle import extract_cycle
from mocycle.datasets import synthetic_walk
from mocycle.phase import find_phase


def _turning(take, turn_per_cycle_deg: float, rise_per_cycle: float = 0.0):
    """The synthetic walk bent onto a circle: its heading and its path turn ``turn_per_cycle_deg`` per cycle
    (about +Y, its up), and its root rises ``rise_per_cycle`` cm per cycle (a creeping capture)."""
    m = take.motion
    period = float(np.median(take.period_frames))
    psi = np.radians(turn_per_cycle_deg) * np.arange(m.n_frames) / period
    turn = Rotation.from_rotvec(psi[:, None] * np.array([0.0, 1.0, 0.0]))
    root = m.translations[:, 0]
    step = np.diff(root, axis=0, prepend=root[:1])
    path = root[0] + np.cumsum(turn.apply(step), axis=0)
    path[:, 1] = root[:, 1] + rise_per_cycle * np.arange(m.n_frames) / period
    quats = m.rotations.copy()
    quats[:, 0] = (turn * Rotation.from_quat(m.rotations[:, 0])).as_quat()
    trans = m.translations.copy()
    trans[:, 0] = path
    return m.replace(rotations=quats, translations=trans)


@pytest.fixture(scope="module")
def straight():
    return synthetic_walk(n_frames=600, noise_deg=0.5, seed=2)


def test_a_creeping_take_loops_at_a_constant_height(straight):
    motion = _turning(straight, 0.0, rise_per_cycle=1.5)   # 1.5 cm per cycle: ~1% of the body height
    cycle = extract_cycle(motion, phase=find_phase(straight.motion))
    assert abs(cycle.drift[:3] @ cycle.space.up) < 1e-9
    assert abs(cycle.drift[2]) > 100                     # the travel is kept
    heights = cycle.repeat(20, root="motion").root_positions[:, 1]
    N = cycle.n_frames
    assert np.allclose(heights[N:], heights[:-N], atol=1e-6)   # periodic: no floating after 20 cycles


def test_a_turning_walk_repeats_along_a_circle(straight):
    turn = 30.0
    motion = _turning(straight, turn)
    # the gait phase of the straight walk is the turning walk's too (the legs do the same)
    cycle = extract_cycle(motion, phase=find_phase(straight.motion))
    assert abs(np.degrees(cycle.drift[3]) - turn) < 0.1 * turn
    n = int(round(360.0 / np.degrees(cycle.drift[3])))
    looped = cycle.repeat(n + 1, root="motion")
    N = cycle.n_frames
    starts = looped.root_positions[::N][:, [0, 2]]                  # the root at the start of every repeat
    # a rigid turn per repeat puts the starts on one circle: equal chords, equal distance to their centre
    chords = np.linalg.norm(np.diff(starts, axis=0), axis=1)
    assert np.ptp(chords) < 1e-6 * chords.mean()
    centre = starts[:n].mean(axis=0)
    radius = np.linalg.norm(starts[:n] - centre, axis=1)
    assert np.ptp(radius) < 0.05 * radius.mean()
    stride = np.linalg.norm(cycle.drift[[0, 2]])
    assert abs(radius.mean() - stride / (2 * np.sin(cycle.drift[3] / 2))) < 0.05 * radius.mean()
    # after a full turn the walk is back near where it started, not 12 strides down a straight line
    assert np.linalg.norm(starts[n] - starts[0]) < 0.25 * stride * abs(360.0 / turn - n) + 0.1 * stride
    # and the body faces along the path: each chord points between the headings at its two ends
    fwd = Rotation.from_quat(looped.rotations[::N, 0]).apply([0.0, 0.0, 1.0])
    yaw = np.unwrap(np.arctan2(fwd[:, 0], fwd[:, 2]))
    along = np.diff(starts, axis=0)
    chord = np.arctan2(along[:, 0], along[:, 1])
    off = np.angle(np.exp(1j * (chord - 0.5 * (yaw[:-1] + yaw[1:]))))
    assert np.all(np.abs(off) < np.radians(20))
    assert np.ptp(off) < 1e-6


@pytest.mark.parametrize("turn_deg", [0.0, 45.0, -90.0])
def test_a_turning_walk_loops_in_place_without_a_seam(turn_deg):
    """In place, a turning walk's steps are turned back along the cycle, so the root's path and velocity wrap
    as smoothly as a straight walk's and the loop checks pass (the chord alone left an 18x velocity jump)."""
    from mocycle.cycle import loop_metrics
    from mocycle.cycle.checks import loop_checks
    from mocycle.datasets import synthetic_circle_walk

    take = synthetic_circle_walk(n_frames=480, turn_per_cycle_deg=turn_deg, noise_deg=0.5)
    cycle = extract_cycle(take.motion)
    assert abs(cycle.to_dict()["turn_per_cycle_deg"] - turn_deg) < 3.0
    metrics = loop_metrics(take.motion, cycle)
    assert metrics["seam_velocity_local"] < 1.5 and metrics["seam_pose_local"] < 1.5
    assert loop_checks(take.motion, cycle) == []
    inplace = cycle.motion("inplace").root_positions
    assert np.abs(np.ptp(inplace[:, [0, 2]], axis=0)).max() < 30.0   # on the spot: sway, no travel


def test_drifting_path_is_the_inverse_of_the_in_place_path():
    from mocycle.cycle.result import drifting_L
    from mocycle.datasets import synthetic_circle_walk

    cycle = extract_cycle(synthetic_circle_walk(n_frames=300, turn_per_cycle_deg=60.0, noise_deg=0.5).motion)
    assert np.abs(drifting_L(cycle.space.up, cycle.inplace_L(), cycle.drift) - cycle.L).max() < 1e-9


def test_repeat_path_is_the_path_of_the_repeated_cycle_bit_for_bit(straight):
    """``Cycle.repeat_path`` (the review's long view reads it) decodes the travel joint alone: the numbers of
    ``space.path(cycle.repeat(...))``, a turning walk's heading unwrapped over every repeat included."""
    cycle = extract_cycle(_turning(straight, 30.0), phase=find_phase(straight.motion))
    for root in ("inplace", "motion"):
        for count in (1, 14):
            np.testing.assert_array_equal(cycle.repeat_path(count, root),
                                          cycle.space.path(cycle.repeat(count, root)))
