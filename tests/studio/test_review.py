"""The loop as the review plays it (``studio/review.py``): in step with the take's phase, repeated with root
motion as ``Cycle.repeat`` does (a turning walk's loop walks the circle), placed at the take."""

from __future__ import annotations

import numpy as np
import pytest

from mocycle import tasks
from mocycle.contacts import body_height, up_axis
from mocycle.datasets import synthetic_circle_walk, synthetic_walk
from mocycle.studio.review import cycle_frames, loop_view


@pytest.fixture(scope="module")
def circle():
    return tasks.loop.run(synthetic_circle_walk(n_frames=600).motion, tasks.loop.Options(root="motion"))


def _heading_turn(path, up):
    """Total turn (rad) of a horizontal path's direction of travel, over one-second chords."""
    h = path - np.outer(path @ up, up)
    d = h[60::60] - h[:-60:60]
    a = np.arctan2(d[:, 2], d[:, 0]) if abs(up[1]) > 0.9 else np.arctan2(d[:, 1], d[:, 0])
    return np.unwrap(a)[-1] - np.unwrap(a)[0]


def test_a_turning_walks_loop_walks_the_circle_with_the_take(circle):
    take = circle.motions["input"]
    view, facts = loop_view(circle)
    up = up_axis(take)
    height = body_height(take, up)
    t = take.travel_joint
    A, B = take.world_positions(end_sites=True), view.world_positions(end_sites=True)
    assert view.n_frames == take.n_frames and facts["root"] == "motion"
    assert np.linalg.norm(A[:, t] - B[:, t], axis=1).max() < 0.05 * height
    turn_take, turn_loop = _heading_turn(A[:, t], up), _heading_turn(B[:, t], up)
    assert abs(turn_take) > np.radians(250) and abs(turn_loop - turn_take) < np.radians(20)
    gap = np.linalg.norm((A - A[:, t:t + 1]) - (B - B[:, t:t + 1]), axis=2).mean()
    assert gap < 0.03 * height  # same pose at the same time: phase-aligned and turned with the take


def test_cycle_frames_follow_the_phase_and_go_on_outside_the_regions():
    report = tasks.loop.run(synthetic_walk(n_frames=300).motion, tasks.loop.Options())
    cycle = report.result
    u, segments = cycle_frames(cycle, 300)
    N = cycle.n_frames
    frames = cycle.axis.frames()
    np.testing.assert_allclose(np.mod(u[frames], N), cycle.positions, atol=1e-9)
    assert segments[0][0] == 0 and segments[-1][1] == 300 and np.all(np.isfinite(u))
    np.testing.assert_allclose(np.diff(u), N / cycle.period_frames, rtol=0.05)  # a steady walk: one per frame


def test_an_inplace_loop_is_carried_along_the_take():
    report = tasks.loop.run(synthetic_walk(n_frames=300).motion, tasks.loop.Options(root="inplace"))
    take = report.motions["input"]
    view, _ = loop_view(report)
    up = up_axis(take)
    t = take.travel_joint
    gap = take.world_positions()[:, t] - view.world_positions()[:, t]
    assert np.abs(gap - np.outer(gap @ up, up)).max() < 1e-6 * body_height(take, up)
