"""``phase``: periodic motions and the phase of every frame (persistent cohomology, paper 001)."""

from __future__ import annotations

from dataclasses import dataclass

from . import fields
from .options import Integer, option
from .options import Options as _Options
from .report import Recorder, Report, load


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``phase``."""

    classes: int | str = fields.classes()
    joints: str | None = fields.phase_joints()
    pca: int | str | None = fields.pca()
    delay: int = fields.delay()
    min_periods: float = fields.min_periods()
    n_landmarks: int = option(120, "Landmarks for the Rips filtration.", Integer(3), flag="--landmarks")
    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()


def run(take, options: Options | None = None, *, keep_features: bool = False) -> Report:
    """The take's steady parts and the periodic motion of each part that loops (the parts ``loop`` loops:
    :func:`~mocycle.activities.segment_activities`, the phase options used inside the parts): one entry of
    ``facts["classes"]`` per such part, with ``part`` (its index in ``facts["parts"]``), ``kind`` and its
    frames; empty when none loops (``facts["reason"]`` says why).  ``keep_features``: keep the take's point
    cloud in ``result.features`` (the phase plot needs it)."""
    from ..activities import parts_phase, segment_activities
    from ..phase.analysis import phase_features

    options = options or Options()
    with Recorder() as rec:
        motion = load(take, options.amc_fps, options.take)
        acts = segment_activities(motion, min_periods=options.min_periods, joints=options.joints,
                                  classes=options.classes, pca=options.pca, delay=options.delay,
                                  n_landmarks=options.n_landmarks)
        result = parts_phase(acts)
        if keep_features:
            result.features = phase_features(motion, joints=options.joints, pca=options.pca)
        facts = {k: v for k, v in result.to_dict().items() if k != "seconds"}
        looping = [k for k, p in enumerate(acts.parts) if p.loop]
        for k, c in zip(looping, facts["classes"], strict=True):
            c.update(part=k, kind=acts.parts[k].kind, frames=[acts.parts[k].start, acts.parts[k].stop])
        facts["parts"] = [p.to_dict() for p in acts.parts]
    return rec.report("phase", facts, {"motion": motion}, result)
