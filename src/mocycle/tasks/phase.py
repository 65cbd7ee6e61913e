"""``phase``: periodic motions and the phase of every frame (persistent cohomology, paper 001)."""

from __future__ import annotations

from dataclasses import dataclass

from . import fields
from .options import Integer, option
from .options import Options as _Options
from .report import Recorder, Report, load

LABELS = {
    "frames": ("frames", ""), "fps": ("frame rate", "fps"),
    "classes": ("periodic motions (H1 classes)", ""),
    "autocorrelation_period_frames": ("autocorrelation period (cross-check)", "frames"),
    "reason": ("why", ""),
}
#: per periodic motion (each entry of ``facts["classes"]``)
CLASS_LABELS = {
    "birth": ("bar birth", ""), "death": ("bar death", ""), "period_frames": ("period", "frames"),
    "period_s": ("period", "s"), "n_periods": ("periods", ""), "excitation": ("excitation", "frames"),
}


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
    """Find the periodic motions of one take; ``facts["classes"]`` is empty when there is none (with the
    reason in ``facts["reason"]``). ``keep_features``: keep the point cloud in ``result.features`` (the phase
    plot needs it)."""
    from ..phase import find_phase

    options = options or Options()
    with Recorder() as rec:
        motion = load(take, options.amc_fps, options.take)
        result = find_phase(motion, classes=options.classes, joints=options.joints, pca=options.pca,
                            delay=options.delay, min_periods=options.min_periods, n_landmarks=options.n_landmarks,
                            keep_features=keep_features)
        facts = {k: v for k, v in result.to_dict().items() if k != "seconds"}
    return rec.report("phase", facts, {"motion": motion}, result)
