import numpy as np

from mocycle.contacts import body_height, find_feet
from mocycle.contacts.clearance import MAX_CLEARANCE, SWING_SPEED, swing_clearance
from mocycle.contacts.detect import heights_and_speeds, local_floor
from mocycle.cycle import extract_cycle, lock_cycle
from mocycle.datasets import synthetic_still
from mocycle.motion import Motion
from tests.contacts.test_contacts import _planted_walk

UP = np.array([0.0, 1.0, 0.0])


def _lifted(motion: Motion, height: float) -> Motion:
    """``motion`` with its root raised by ``height`` while its left foot moves fast: a take whose left foot
    swings higher (its stance frames, while the right foot swings, stay where they were)."""
    left = find_feet(motion.skeleton)[0]
    _, v, _ = heights_and_speeds(motion, list(left.contact_joints), UP)
    fast = (v / body_height(motion, UP) > SWING_SPEED).any(axis=1)
    t = motion.translations.copy()
    t[fast, 0, 1] += height
    return Motion(motion.skeleton, motion.rotations, t, motion.frame_time)


def test_the_clearance_is_where_the_capture_s_own_swinging_feet_pass():
    """The lower quartile of each contact joint's height while it swings: the same wherever the floor is, higher
    for a take whose swinging feet pass higher, capped for one whose fast feet are all high in the air, and
    0 for a take whose feet never swing."""
    _, walk = _planted_walk(n_frames=240, fps=60.0)
    body = body_height(walk, UP)
    base = swing_clearance(walk, up=UP)
    assert base.shape == (4,) and np.all(base >= 0) and np.all(base <= MAX_CLEARANCE)
    # by hand: the quartile of the heights above the floor while faster than SWING_SPEED
    feet = find_feet(walk.skeleton)
    joints = [j for f in feet for j in f.contact_joints]
    h, v, _ = heights_and_speeds(walk, joints, UP)
    h = h / body - local_floor(h / body, walk.fps)
    for c in range(4):
        fast = v[:, c] / body > SWING_SPEED
        assert abs(base[c] - min(np.quantile(h[fast, c], 0.25), MAX_CLEARANCE)) < 1e-12
    t = walk.translations.copy()
    t[:, 0, 1] += 0.3 * body                                   # the whole take higher: the same clearance
    assert np.allclose(swing_clearance(Motion(walk.skeleton, walk.rotations, t, walk.frame_time), up=UP), base)
    higher = swing_clearance(_lifted(walk, 0.01 * body), up=UP)
    assert feet[0].side == "left" and np.all(higher[:2] > base[:2] + 0.005)   # the left ankle and toe
    assert np.allclose(swing_clearance(_lifted(walk, 0.5 * body), up=UP)[:2], MAX_CLEARANCE)
    assert not swing_clearance(synthetic_still(n_frames=120).motion, up=UP).any()
    both = swing_clearance([walk, _lifted(walk, 0.01 * body)], up=UP)   # a blend's two takes: the mean
    assert np.allclose(both, (base + higher) / 2)


def test_a_loop_keeps_the_clearance_of_the_take_it_was_made_from():
    """lock_cycle measures the swing clearance on ``reference`` (the take) and says which it used; a take that
    steps higher lifts the loop's swinging feet higher."""
    take, walk = _planted_walk(n_frames=360, fps=60.0, noise_deg=0.3)
    cycle = extract_cycle(walk)
    body = body_height(walk, UP)
    _, contacts = lock_cycle(cycle, reference=walk)
    assert np.allclose(contacts.clearance, swing_clearance(walk, contacts.feet, up=contacts.up, body=contacts.body))
    high = _lifted(walk, 0.03 * body)
    low_loop, _ = lock_cycle(cycle, reference=walk)
    high_loop, hc = lock_cycle(cycle, reference=high)
    assert np.all(hc.clearance[:2] > contacts.clearance[:2])
    ankles = [contacts.feet[0].ankle]
    lo = low_loop.repeat(2, root="motion").world_positions()[:, ankles, 1]
    hi = high_loop.repeat(2, root="motion").world_positions()[:, ankles, 1]
    assert np.all(hi >= lo - 1e-9) and (hi - lo).max() > 0.005 * body   # lifted, never lowered
    _, none = lock_cycle(cycle, reference=walk, clearance=0.0)
    assert not none.clearance.any()
