"""Spatial-keyframe authoring (thesis 002, chapter 6): timed strokes, back-projected poses, the planted root,
the re-layout after markers move."""

from __future__ import annotations

import numpy as np
import pytest

from mocycle.contacts import floor_height, foot_points, plant_lowest_foot, up_axis
from mocycle.datasets import synthetic_nonperiodic, synthetic_walk
from mocycle.errors import MocycleError
from mocycle.keyframes import (
    PoseSpace,
    author_motion,
    joint_weights,
    pose_distance_matrix,
    relayout,
    resample_stroke,
    spatial_layout,
)
from mocycle.tasks import author


def test_stroke_is_resampled_at_the_frame_rate_by_its_own_timing():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]])
    traj = resample_stroke(pts, [0.0, 0.1, 0.3], 0.05)
    assert traj.shape == (7, 2)  # 0.3 s at 20 fps, both ends included
    np.testing.assert_allclose(traj[2], [1.0, 0.0])  # at 0.1 s
    np.testing.assert_allclose(traj[4], [1.0, 1.0])  # half way through the slow second segment
    with pytest.raises(MocycleError, match="must not decrease"):
        resample_stroke(pts, [0.0, 0.2, 0.1], 0.05)
    with pytest.raises(MocycleError, match="NaN"):
        resample_stroke([[0, np.nan]], [0.0], 0.05)


def test_keyframe_markers_give_back_the_keyframe_poses():
    take = synthetic_walk(n_frames=120).motion
    space = PoseSpace(take)
    key, pts = spatial_layout(space, "mds", "uniform", 8)
    out = author_motion(take, key, pts[key], pts[key])
    d = pose_distance_matrix(out.rotations, space.weights, take.rotations[key])
    np.testing.assert_allclose(np.diag(d), 0.0, atol=1e-6)


def test_a_stroke_along_the_first_half_gives_the_first_half_poses_in_order():
    take = synthetic_nonperiodic(n_frames=240).motion
    space = PoseSpace(take)
    key, pts = spatial_layout(space, "mds", "uniform", 12)
    half = 120
    out = author.run((take, {"keyframes": key, "markers": pts[key], "points": pts[:half],
                             "times_s": np.arange(half) * take.frame_time}), author.Options(feet="keep"))
    m = out.motions["authored"]
    near = pose_distance_matrix(m.rotations, joint_weights(take.skeleton), take.rotations).argmin(axis=1)
    assert m.n_frames == half
    assert np.mean(near < half + 10) > 0.9
    assert np.corrcoef(near, np.arange(half))[0, 1] > 0.9


def test_the_lowest_foot_stays_put_on_the_floor():
    take = synthetic_walk(n_frames=180).motion
    inplace = take.replace(translations=np.broadcast_to(take.translations[0], take.translations.shape))
    planted = plant_lowest_foot(inplace, floor_height(take))
    up = up_axis(take)
    W = planted.world_positions(end_sites=True)[:, foot_points(take)]
    h = W @ up
    low = h.argmin(axis=1)
    np.testing.assert_allclose(h.min(axis=1), floor_height(take), atol=1e-9)
    same = np.flatnonzero(low[1:] == low[:-1]) + 1
    step = np.linalg.norm(W[same, low[same]] - W[same - 1, low[same]], axis=1)
    assert step.max() < 1e-6 * np.ptp(W)  # the planted point does not slide
    travel = planted.root_positions[-1] - planted.root_positions[0]
    assert np.linalg.norm(travel - (travel @ up) * up) > 0.5 * np.linalg.norm(take.root_positions[-1] -
                                                                              take.root_positions[0])


def test_relayout_keeps_markers_lowers_the_error_and_can_stop():
    take = synthetic_walk(n_frames=150).motion
    space = PoseSpace(take)
    key, pts = spatial_layout(space, "mds", "uniform", 8)
    moved = pts[key] * 1.5 + [0.3, -0.2]
    seen = []
    new, opt = relayout(space, key, moved, progress=seen.append)
    np.testing.assert_allclose(new[key], moved)
    assert opt.error_after < opt.error_before and seen and 0 < seen[-1] <= 1
    stopped, opt2 = relayout(space, key, moved, stop=lambda: True)
    assert opt2.passes <= 1 and opt2.error_after == pytest.approx(opt2.error_before)
    seed, none = relayout(space, key, moved, optimize=False)
    assert none is None and np.all(np.isfinite(seed))


def test_author_refuses_a_stroke_without_its_fields():
    take = synthetic_walk(n_frames=60).motion
    with pytest.raises(MocycleError, match="times_s is missing"):
        author.run((take, {"keyframes": [0, 10, 20], "markers": [[0, 0], [1, 0], [0, 1]], "points": [[0, 0]]}))
