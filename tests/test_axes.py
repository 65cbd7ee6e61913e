"""mocycle.axes: the vertical axis (detected or given) and headings about it."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mocycle.axes import heading_angles, horizontal_basis, parse_up, vertical_axis
from mocycle.cycle.representation import CycleSpace
from mocycle.datasets import synthetic_walk
from mocycle.errors import MocycleError


@pytest.mark.parametrize("name, vector", [("y", [0, 1, 0]), ("+Z", [0, 0, 1]), ("-x", [-1, 0, 0]),
                                          ([0, 0, 2], [0, 0, 1])])
def test_parse_up(name, vector):
    assert np.array_equal(parse_up(name), vector)


@pytest.mark.parametrize("bad", ["up", [0, 0, 0], [1, 2], [np.nan, 1, 0]])
def test_parse_up_refuses_what_is_not_an_axis(bad):
    with pytest.raises(MocycleError, match="up must be one of"):
        parse_up(bad)


def test_override_wins_over_detection():
    walk = synthetic_walk(n_frames=60).motion
    assert np.array_equal(vertical_axis(walk), [0, 1, 0])
    assert np.array_equal(vertical_axis(walk, "z"), [0, 0, 1])
    space = CycleSpace.fit(walk, up="y")
    assert np.array_equal(space.world_up, [0, 1, 0])


def test_heading_about_any_up_axis_is_unwrapped():
    for up in ([0, 1, 0], [0, 0, 1], [0, 0, -1]):
        up = np.array(up, dtype=float)
        e1, e2 = horizontal_basis(up)
        assert abs(e1 @ up) < 1e-12 and abs(e2 @ up) < 1e-12 and np.isclose(np.cross(e1, e2) @ up, 1.0)
        turns = np.linspace(0, 5 * np.pi, 200)
        forward = Rotation.from_rotvec(np.outer(turns, up)).apply(e1 + 0.3 * up)   # tilted up: no effect
        assert np.allclose(heading_angles(forward, e1, e2), turns)


def test_the_detected_up_axis_is_kept_per_motion_and_handed_out_as_a_copy():
    from mocycle.axes import _detect_up, vertical_axis
    from mocycle.datasets import synthetic_walk

    walk = synthetic_walk(n_frames=120, fps=60, seed=1).motion
    up = vertical_axis(walk)
    up[:] = 7.0  # a caller scribbling on its copy changes nothing
    assert vertical_axis(walk).tolist() == _detect_up(walk).tolist() == [0.0, 1.0, 0.0]
    assert vertical_axis(walk[::2]).tolist() == [0.0, 1.0, 0.0]  # a new motion detects again
    assert vertical_axis(walk, "-z").tolist() == [0.0, 0.0, -1.0]  # an override is never cached
    assert vertical_axis(walk).tolist() == [0.0, 1.0, 0.0]


def fingered_walk(up: str = "y"):
    """The synthetic walk with five fingers of four joints on each hand (40 joints hanging below the hands
    while the arms swing down), as Mixamo rigs have them; ``up="z"``: the same turned Z-up."""
    from mocycle.datasets import to_z_up
    from mocycle.motion import Motion, Skeleton

    walk = synthetic_walk(n_frames=120, fps=30, seed=2).motion
    sk = walk.skeleton
    names, parents, offsets = list(sk.names), list(sk.parents), [tuple(o) for o in sk.offsets]
    channels = list(sk.channels)
    world_rotations, _ = walk.world_transforms()
    for side in ("Left", "Right"):
        hand = names.index(f"{side}Hand")
        down = world_rotations[:, hand].mean(axis=0).T  # world directions in the hand's frame (about)
        for f in range(5):
            parent = hand
            for k in range(4):
                names.append(f"{side}Finger{f}_{k}")
                parents.append(parent)
                offsets.append(tuple(down @ [0.4 * (f - 2), -3.0, 0.0]))
                channels.append(("Zrotation", "Xrotation", "Yrotation"))
                parent = len(names) - 1
    skeleton = Skeleton(tuple(names), parents, np.asarray(offsets), tuple(channels), sk.end_sites)
    T, extra = walk.n_frames, len(names) - sk.n_joints
    rot = np.concatenate([walk.rotations, np.tile([0.0, 0, 0, 1], (T, extra, 1))], axis=1)
    static = np.vstack([walk.translations[0], np.asarray(offsets[sk.n_joints:])])
    motion = Motion(skeleton, rot, static, walk.frame_time, tracks={0: walk.root_positions})
    return to_z_up(motion) if up == "z" else motion


@pytest.mark.parametrize("up, expected", [("y", [0, 1, 0]), ("z", [0, 0, 1])])
def test_up_is_found_from_the_body_not_from_where_most_joints_hang(up, expected):
    """40 finger joints below the hips (arms down): most joints hang in the lower half, which put mocycle's
    vertical upside down; the chest above the feet does not."""
    from mocycle.axes import _detect_up, _mean_pose_up

    motion = fingered_walk(up)
    W = motion.world_positions(end_sites=True)
    assert _mean_pose_up(motion, W).tolist() == [-v for v in expected]  # the old rule: upside down
    assert _detect_up(motion).tolist() == expected
    assert vertical_axis(motion).tolist() == expected


def test_the_declared_up_wins_over_detection_and_an_override_over_both():
    from mocycle.motion import Motion, Skeleton

    walk = synthetic_walk(n_frames=60).motion
    sk = walk.skeleton
    declared = Skeleton(sk.names, sk.parents, sk.offsets, sk.channels, sk.end_sites, up=(0, 0, -2))
    motion = Motion(declared, walk.rotations, walk.translations)
    assert declared.up == (0.0, 0.0, -1.0)
    assert vertical_axis(motion).tolist() == [0.0, 0.0, -1.0]  # what the file says, not what the body shows
    assert vertical_axis(motion[10:20]).tolist() == [0.0, 0.0, -1.0]  # slices keep the skeleton
    assert vertical_axis(motion, "y").tolist() == [0.0, 1.0, 0.0]
    with pytest.raises(MocycleError, match="up must be a non-zero 3-vector"):
        Skeleton(sk.names, sk.parents, sk.offsets, sk.channels, up=(0, 0, 0))
