"""tasks.clips: what a front end writes for a task's output motion (clip, closing frame)."""

from __future__ import annotations

import numpy as np
import pytest

from mocycle import tasks
from mocycle.datasets import synthetic_circle_walk, synthetic_walk
from mocycle.tasks.clips import clip_of, for_output


@pytest.fixture(scope="module")
def circle_loop():
    take = synthetic_circle_walk(n_frames=360, turn_per_cycle_deg=30.0).motion
    return tasks.loop.run(take, tasks.loop.Options(root="motion", cycles=2))


def test_glb_loops_get_the_closing_frame_bvh_loops_do_not(circle_loop):
    loop = circle_loop.motions["loop"]
    n = circle_loop.facts["cycle_frames"]
    assert loop.n_frames == 2 * n
    motion, clip = for_output(circle_loop, "loop", "out/walk.bvh")
    assert motion is loop and clip is None
    motion, clip = for_output(circle_loop, "loop", "out/walk.glb")
    assert motion.n_frames == 2 * n + 1 and clip.name == "walk_loop" and clip.closing_frame and clip.cycles == 2
    assert np.allclose(motion.rotations[:-1], loop.rotations) and np.allclose(motion.translations[:-1],
                                                                               loop.translations)
    # the closing frame is frame 0 of a third cycle: the first cycle's frame 0 moved on by two cycles
    third = circle_loop.result.repeat(3, root="motion")
    assert np.allclose(motion.world_positions()[-1], third.world_positions()[2 * n])
    assert for_output(circle_loop, "loop", "walk.glb", closing_frame=False)[0] is loop
    assert for_output(circle_loop, "loop", "walk.bvh", closing_frame=True)[0].n_frames == 2 * n + 1


def test_the_clip_carries_the_loop_facts(circle_loop):
    clip = clip_of(circle_loop, "loop", "walk_loop")
    f = circle_loop.facts
    assert clip.name == "walk_loop"  # not walk_loop_loop
    assert clip.loopable and clip.root == "motion" and clip.travel_joint == "Hips"
    assert clip.travel_per_cycle == tuple(f["travel_per_cycle"]) and clip.turn_per_cycle_deg == f["turn_per_cycle_deg"]
    meta = clip.metadata(1 / 60, length=lambda v: 0.01 * v)
    assert meta["root_motion"] and not meta["in_place"]
    assert meta["travel_per_cycle"] == pytest.approx(0.01 * np.asarray(f["travel_per_cycle"]))
    assert meta["cycle_seconds"] == pytest.approx(f["cycle_frames"] / 60)


def test_other_tasks_give_plain_clips():
    report = tasks.stretch.run(synthetic_walk(n_frames=240).motion, tasks.stretch.Options(factor=1.5))
    motion, clip = for_output(report, "stretched", "long.glb")
    assert motion is report.motions["stretched"] and clip.name == "long" and not clip.loopable
    assert clip.metadata(0.1)["loopable"] is False
