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
