"""``swings``: a take as joint swings and holds (paper 003), their playback error and compressed size."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from . import fields
from .options import Options as _Options
from .report import Recorder, Report, is_motion, load


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``swings``."""

    threshold: float = fields.threshold()
    joints: str | None = fields.swing_joints()
    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()


def swing_table(seg) -> list[dict]:
    """One row per segmented joint: ``joint``, ``swings`` (count), ``indices`` (``"0-11"``, what ``edit --swing``
    takes, 0-based in time order), ``mean_length_s``, ``mean_angle_deg``, ``holds``."""
    rows = []
    for j in seg.joints:
        sw = seg.swings_of(j)
        n = len(sw)
        rows.append({
            "joint": seg.skeleton.names[j], "swings": n,
            "indices": "" if n == 0 else "0" if n == 1 else f"0-{n - 1}",
            "mean_length_s": sum(s.end - s.start for s in sw) / n * seg.frame_time if n else 0.0,
            "mean_angle_deg": math.degrees(sum(abs(s.end_angle - s.start_angle) for s in sw) / n) if n else 0.0,
            "holds": len(seg.holds_of(j)),
        })
    return rows


def run(source, options: Options | None = None) -> Report:
    """Segment a take (a Motion or motion file) into swings, or read a ``.mosw`` swings file to play back.

    ``result`` is the segmentation, ``motions["playback"]`` the motion rebuilt from it.
    """
    from ..swings import playback, playback_errors, read_swings, segment, size_report

    o = options or Options()
    with Recorder() as rec:
        if not is_motion(source) and Path(source).suffix.lower() == ".mosw":
            motion, seg = None, read_swings(source)
        else:
            motion = load(source, o.amc_fps, o.take)
            seg = segment(motion, threshold=o.threshold, joints=o.joints)
        rebuilt = playback(seg)
        facts = {"joints": [seg.skeleton.names[j] for j in seg.joints], "n_swings": seg.n_swings}
        if motion is not None:
            errs = playback_errors(motion, rebuilt)
            facts.update({k: errs[k] for k in ("segmentation_error", "per_angle_error_deg", "geodesic_error_deg")})
            size = size_report(seg, motion)
        else:
            facts.update(segmentation_error=None, per_angle_error_deg=None, geodesic_error_deg=None)
            size = size_report(seg)
        facts.update(compressed_bytes=size["compressed_bytes"], raw_float32_bytes=size["raw_float32_bytes"],
                     ratio_raw=size["ratio_raw"], ratio_bvh=size["ratio_bvh"], frames=seg.n_frames, fps=seg.fps,
                     threshold=seg.threshold, per_joint=swing_table(seg))
    return rec.report("swings", facts, {"playback": rebuilt}, seg)
