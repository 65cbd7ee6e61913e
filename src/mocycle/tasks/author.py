"""``author``: a new animation from a trajectory drawn on the spatial-keyframe plane (thesis 002, chapter 6).

Not a CLI command (a stroke is drawn, not typed): the studio and scripts call it.  The plane itself is
:mod:`mocycle.tasks.project`; :func:`relayout` re-projects the in-between frames after markers moved.

    >>> from mocycle.datasets import synthetic_walk
    >>> from mocycle.tasks import author, project
    >>> take = synthetic_walk(n_frames=120).motion
    >>> plane = project.run(take, project.Options(ratio=0.1)).result
    >>> key, pts = plane["keyframes"], plane["points"]
    >>> stroke = {"keyframes": key, "markers": pts[key], "points": pts[:60], "times_s": [i / 60 for i in range(60)]}
    >>> report = author.run((take, stroke), author.Options(feet="keep"))
    >>> report.motions["authored"].n_frames, report.facts["frames"]
    (60, 60)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from . import fields
from .options import Choice, option
from .options import Options as _Options
from .report import Recorder, Report, load

PLANT_CHOICES = ("lowest-foot", "none")


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``author``."""

    plant: str = option("lowest-foot", "Root placement: lowest-foot (the lowest foot point stays put on the floor, "
                                       "thesis chapter 6) or none (in place, the take's first-frame translations).",
                        Choice(PLANT_CHOICES))
    feet: str = fields.feet("After placing the root: lock (feet held still during each contact, two-bone IK), "
                            "keep, or auto (lock when the animation travels and feet are found).")
    foot_joints: str | None = fields.foot_joints()
    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()


def _stroke(stroke: Mapping, n_frames: int):
    from ..errors import MocycleError

    try:
        key = np.asarray(stroke["keyframes"], dtype=np.int64)
        markers = np.asarray(stroke["markers"], dtype=np.float64)
        points = np.asarray(stroke["points"], dtype=np.float64)
        times = np.asarray(stroke["times_s"], dtype=np.float64)
    except KeyError as exc:
        raise MocycleError(f"a stroke needs keyframes, markers, points and times_s; {exc.args[0]} is missing") from None
    except (TypeError, ValueError) as exc:
        raise MocycleError(f"a stroke holds numbers only: {exc}") from None
    return key, markers, points, times


def run(inputs, options: Options | None = None) -> Report:
    """``inputs = (take, stroke)``; ``stroke`` maps ``keyframes`` (K,), ``markers`` (K, 2), ``points`` (N, 2)
    and ``times_s`` (N,) (the mouse's timestamps).  ``motions["authored"]`` is the animation at the take's frame
    rate; ``facts["trajectory"]`` the stroke resampled per frame."""
    from ..contacts import floor_height, plant_lowest_foot
    from ..keyframes import author_motion, resample_stroke
    from .feet_option import lock_motion, travels

    o = options or Options()
    take, stroke = inputs
    with Recorder() as rec:
        motion = load(take, o.amc_fps, o.take)
        key, markers, points, times = _stroke(stroke, motion.n_frames)
        with rec.part("back-projection"):
            traj = resample_stroke(points, times, motion.frame_time)
            authored = author_motion(motion, key, markers, traj)
        feet_facts = None
        with rec.part("feet"):
            if o.plant == "lowest-foot":
                authored = plant_lowest_foot(authored, floor_height(motion, o.foot_joints), o.foot_joints)
                authored, feet_facts = lock_motion(authored, o.feet, o.foot_joints, travels(authored))
        facts = {"frames": authored.n_frames, "fps": motion.fps, "duration_s": authored.duration,
                 "keyframes": key.tolist(), "stroke_samples": len(points), "plant": o.plant, "feet": feet_facts,
                 "trajectory": traj.round(6).tolist()}
    return rec.report("author", facts, {"authored": authored, "input": motion})


def relayout(take, keyframes, markers, optimize: bool = True, stop=None, progress=None,
             amc_fps: float = fields.AMC_FPS) -> Report:
    """Every frame's 2-D point after the keyframes' ``markers`` moved: RBFP seed, then Algorithm 12 (when
    ``optimize``; ``stop()`` ends it early, ``progress(fraction)`` follows it).  ``facts["points"]`` (T, 2)."""
    from ..keyframes import PoseSpace
    from ..keyframes import relayout as _relayout

    with Recorder() as rec:
        motion = load(take, amc_fps)
        points, opt = _relayout(PoseSpace(motion), keyframes, markers, optimize, stop, progress)
        facts = {"frames": motion.n_frames, "keyframes": np.asarray(keyframes).tolist(),
                 "points": points.round(6).tolist(), "optimized": opt is not None,
                 "error_before": None if opt is None else opt.error_before,
                 "error_after": None if opt is None else opt.error_after,
                 "passes": None if opt is None else opt.passes,
                 "stopped": bool(stop is not None and stop())}
    return rec.report("relayout", facts, result={"points": points})
