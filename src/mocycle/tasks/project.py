"""``project``: every pose in 2-D with its keyframes, the spatial keyframing view of a take (thesis 002)."""

from __future__ import annotations

from dataclasses import dataclass

from . import fields, keyframe_fields
from .options import Options as _Options
from .report import Recorder, Report, load


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``project``."""

    projection: str = keyframe_fields.projection()
    select: str = keyframe_fields.select()
    ratio: float = keyframe_fields.ratio("Keyframes as a fraction of the frames.")
    seed_projection: str = keyframe_fields.seed_projection()
    optimize: bool = keyframe_fields.optimize("Also optimise the projection (Algorithm 12) and plot both.")
    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()


def run(take, options: Options | None = None) -> Report:
    """Project every pose to 2-D and pick keyframes; ``result`` holds the arrays
    (``points`` (T, 2), ``keyframes`` (K,), ``optimized`` (T, 2) or None) for plots."""
    from ..keyframes import PoseSpace, keyframe_count, optimize_projection, spatial_layout, stress
    from ..keyframes.distance import check_pairwise_frames

    o = options or Options()
    with Recorder() as rec:
        motion = load(take, o.amc_fps, o.take)
        check_pairwise_frames(motion.n_frames)  # the stress needs every pair: refused before any work
        space = PoseSpace(motion)
        k = keyframe_count(motion.n_frames, ratio=o.ratio)
        key, points = spatial_layout(space, o.projection, o.select, k, seed=o.seed_projection)
        opt = optimize_projection(points, key, motion.rotations, space.weights).points if o.optimize else None
        facts = {"frames": motion.n_frames, "keyframes": key.tolist(), "projection": o.projection,
                 "select": o.select, "stress": stress(space.distances, points) if motion.n_frames > 1 else None}
        if opt is not None:
            facts["stress_optimized"] = stress(space.distances, opt)
        facts["points"] = points.round(6).tolist()
        if opt is not None:
            facts["points_optimized"] = opt.round(6).tolist()
    return rec.report("project", facts, result={"points": points, "keyframes": key, "optimized": opt})
