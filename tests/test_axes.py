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
    with pytest.raises(MocycleError, match="up axis"):
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
