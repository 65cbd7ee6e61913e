"""``edit``: scale the angle or the duration of one swing of one joint (paper 003)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from . import fields
from .options import Integer, Real, Text, option
from .options import Options as _Options
from .report import Recorder, Report, is_motion, load


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``edit``."""

    joint: str = option(help="Joint whose swing to edit (exact name).", check=Text(optional=False))
    swing: int = option(help="Which swing of the joint, 0-based in time order (see `mocycle swings IN`).",
                        check=Integer(0))
    angle_scale: float = option(1.0, "Scale of the angle the swing turns through (0-10).", Real(0, 10))
    duration_scale: float = option(1.0, "Scale of the swing's length in time (0.05-20).", Real(0.05, 20))
    threshold: float = fields.threshold()
    joints: str | None = fields.swing_joints()
    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()


def run(take, options: Options) -> Report:
    """The take with one swing edited: ``motions["edited"]``."""
    from ..swings import edit_swing, segment

    o = options
    with Recorder() as rec:
        motion = load(take, o.amc_fps, o.take)
        seg = segment(motion, threshold=o.threshold, joints=o.joints)
        j = motion.skeleton.index(o.joint)
        if j not in seg.joints and o.joints is None:
            names = sorted({*(motion.skeleton.names[k] for k in seg.joints), o.joint})
            seg = segment(motion, threshold=o.threshold, joints=names)
        edited = edit_swing(motion, seg, o.joint, o.swing, angle_scale=o.angle_scale,
                            duration_scale=o.duration_scale, hand_over=not is_motion(take))  # a file: ours
        sw = seg.swings_of(o.joint)[o.swing]
        facts = {"joint": o.joint, "swing": o.swing, "start": sw.start, "end": sw.end,
                 "angle_deg": math.degrees(abs(sw.end_angle - sw.start_angle)), "angle_scale": o.angle_scale,
                 "duration_scale": o.duration_scale}
    return rec.report("edit", facts, {"edited": edited}, seg)
