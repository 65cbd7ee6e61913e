"""Foot locking without pops: a held foot's joints leave and meet their holds without a jump of a frame."""

import numpy as np
import pytest

from mocycle.contacts import foot_jumps
from mocycle.contacts.lock import _heels_about_toes
from mocycle.cycle import extract_cycle, lock_cycle
from mocycle.io import read


def test_a_heel_down_again_within_a_toe_contact_is_held_about_the_toe():
    """A toe contact over two heel contacts (the heel lifts and comes down again while the toe stays): the second
    heel contact is held where the rigid foot puts it about the toe's hold, so the toe is not pulled to
    another place when it starts; the first, the toe's partner, keeps its own hold."""
    T = 40
    a = np.zeros((T, 3))
    a[:, 2] = np.linspace(0.0, 4.0, T)            # the ankle drifts forward
    t = a + np.array([0.0, -8.0, 12.0])             # the toe: a foot vector ahead and below
    t[25:] += np.array([0.0, 1.0, 0.5])             # the foot rolls a little while the heel is up
    held = [np.array([0.0, 0.0, 1.0]), np.array([5.0, 5.0, 5.0])]   # the second: its own place, far off
    ra, rt = [(0, 10), (20, 30)], [(5, 35)]
    partner = {0: (0, 7)}                           # the toe's hold is made with the first heel contact
    toe_hold = held[0] + (t[7] - a[7])
    _heels_about_toes(held, ra, rt, partner, a, t)
    np.testing.assert_array_equal(held[0], [0.0, 0.0, 1.0])
    mid = (20 + 30 - 1) // 2
    np.testing.assert_allclose(held[1], toe_hold + (a[mid] - t[mid]))
    assert np.linalg.norm(toe_hold - held[1]) == pytest.approx(np.linalg.norm(t[mid] - a[mid]))
    # a heel contact that is itself the partner of another toe contact keeps its own hold
    held = [np.array([0.0, 0.0, 1.0]), np.array([5.0, 5.0, 5.0])]
    _heels_about_toes(held, ra, [(5, 22), (24, 35)], {0: (0, 7), 1: (1, 26)}, a, t)
    np.testing.assert_array_equal(held[1], [5.0, 5.0, 5.0])


def test_a_locked_walk_at_120_fps_has_no_foot_pops(shared_data):
    """A Bandai walk at 120 fps, its cycle's feet locked: no ankle or toe jumps in one frame (the heel lifted
    about a held toe used to drop back to its own path at toe-off, and a heel down again within a toe contact
    pulled the held toe away: two jumps of 1-2 % of the body height per cycle)."""
    path = shared_data / "bandai2" / "dataset-2_walk_youthful_025.bvh"
    if not path.is_file():
        pytest.skip("dataset-2_walk_youthful_025.bvh is absent from ../shared/data/bandai2")
    take = read(path).resample(120)
    cycle = extract_cycle(take)
    locked, _ = lock_cycle(cycle, reference=take)
    assert foot_jumps(cycle.repeat(1, root="motion"), wrap=True) == []
    assert foot_jumps(locked.repeat(1, root="motion"), wrap=True) == []


def test_foot_jumps_finds_a_jump_of_one_frame_and_not_a_swing():
    """A walk's feet swing fast and smoothly: no jump; the body moved up by 1 % of its height from one frame on:
    one jump, at that frame; played round as a loop, the seam's step counts too."""
    from mocycle.contacts import body_height, up_axis
    from mocycle.datasets import synthetic_walk

    walk = synthetic_walk(n_frames=120, fps=60, noise_deg=0.0, seed=1).motion
    assert foot_jumps(walk) == []
    j = walk.travel_joint
    track = walk.joint_translations(j).copy()
    track[50:] += 0.01 * body_height(walk, up_axis(walk)) * up_axis(walk)
    jumped = walk.replace(tracks={j: track})
    assert foot_jumps(jumped) == [49]
    assert foot_jumps(jumped, wrap=True) == [49, walk.n_frames - 1]
