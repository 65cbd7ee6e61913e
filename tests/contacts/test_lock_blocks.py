"""``lock_feet`` with the legs' world rotations made a block of frames at a time, and with the take handed
over: the same motion, to the bit, as with the whole take's transforms in one array."""

import numpy as np
import pytest

import mocycle.contacts.legs as legs_module
from mocycle.contacts import detect_contacts, lock_feet
from mocycle.contacts.legs import chain_joints, chain_transforms, leg_joints
from mocycle.datasets import synthetic_walk
from mocycle.motion import EndSite, Motion, Skeleton


def _rooted(walk: Motion, turn_deg: float) -> Motion:
    """``walk`` below a static root turned ``turn_deg`` about the vertical (Bandai's rig has a static
    joint_Root above the travelling hips): the travel joint has a parent whose rotation counts."""
    sk = walk.skeleton
    rooted = Skeleton(("joint_Root", *sk.names), [-1, *(sk.parents + 1)], np.vstack([[0, 0, 0], sk.offsets]),
                      [("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"),
                       *sk.channels], [EndSite(e.parent + 1, e.offset, e.name) for e in sk.end_sites])
    half = np.radians(turn_deg) / 2
    root = np.tile([0.0, np.sin(half), 0.0, np.cos(half)], (walk.n_frames, 1, 1))
    q = np.concatenate([root, walk.rotations], axis=1)
    t = np.concatenate([np.zeros((walk.n_frames, 1, 3)), walk.translations], axis=1)
    return Motion(rooted, q, t, walk.frame_time)


@pytest.mark.parametrize("turn_deg", [None, 25.0])
def test_feet_locked_a_block_at_a_time_are_locked_as_in_one_array(monkeypatch, turn_deg):
    walk = synthetic_walk(n_frames=300, fps=60, noise_deg=1.0, seed=4).motion
    m = walk if turn_deg is None else _rooted(walk, turn_deg)
    contacts = detect_contacts(m)
    chain = chain_joints(m, leg_joints(contacts.feet))
    whole = lock_feet(m, contacts, transforms=chain_transforms(m, chain))
    part_whole = lock_feet(m, contacts, frames=slice(40, 250), transforms=chain_transforms(m, chain))
    assert np.abs(whole.rotations - m.rotations).max() > 1e-3  # the lock changes the legs
    assert np.abs(whole.translations - m.translations).max() > 1e-3  # and moves the travel joint
    monkeypatch.setattr(legs_module, "POSITIONS_BLOCK", 37)  # nine blocks, the last one short
    blocked = lock_feet(m, contacts)
    np.testing.assert_array_equal(blocked.rotations, whole.rotations)
    np.testing.assert_array_equal(blocked.translations, whole.translations)
    part = lock_feet(m, contacts, frames=slice(40, 250))
    np.testing.assert_array_equal(part.rotations, part_whole.rotations)
    np.testing.assert_array_equal(part.translations, part_whole.translations)

    given = Motion(m.skeleton, m.rotations, m.translations, m.frame_time)  # arrays only this motion holds
    copied = lock_feet(given, contacts)
    handed = lock_feet(given, contacts, hand_over=True)
    np.testing.assert_array_equal(handed.rotations, copied.rotations)
    np.testing.assert_array_equal(handed.translations, copied.translations)
    with pytest.raises(AttributeError):
        given.rotations  # noqa: B018 (the handed-over motion is emptied)
    np.testing.assert_array_equal(lock_feet(m, contacts).rotations, whole.rotations)  # m itself untouched
