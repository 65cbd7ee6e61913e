"""``stretch``: lengthen a take by time-frequency warping (paper 004), keeping its cycle."""

from __future__ import annotations

from dataclasses import dataclass

from . import fields
from .options import Flag, Integer, Real, option
from .options import Options as _Options
from .report import Recorder, Report, load

LABELS = {
    "factor": ("length ratio", ""), "frames_in": ("frames in", ""), "frames_out": ("frames out", ""),
    "windows": ("window per joint group", "frames"), "cycles": ("fundamental cycle per joint group", "frames"),
    "trend_curves": ("warped as line + residual", ""), "periodic_regions": ("periodic regions warped", "frames"),
    "periodic_regions_out": ("where they are in the output", "frames"), "forced": ("warped although not periodic", ""),
}


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``stretch``."""

    factor: float = option(help="Length ratio: 2 doubles the take (frames out = round(frames * F)).",
                           check=Real(0, low_open=True))
    window_frames: int | str = option("auto", "Block length in frames: 'auto' (each joint group's largest "
                                              "fundamental cycle) or N.", Integer(1, words={"auto": "auto"}),
                                      flag="--window")
    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()
    force: bool = option(False, "Warp the whole take even when it has no periodic motion (a warning says so). It "
                                "also lets an output replace an input file.", Flag())
    feet: str = fields.feet("lock (feet held still on the floor during each contact), keep (as warped) or auto "
                            "(lock when the take travels and feet are found, else keep).")
    foot_joints: str | None = fields.foot_joints()


def run(take, options: Options) -> Report:
    """The take lengthened by ``options.factor``: ``motions["stretched"]``; the windows used in ``facts``.

    Only the periodic region(s) are warped; raises NoPeriodicMotion when there is none (``force``: the whole take
    is warped, with a warning)."""
    from ..warp import stretch_motion
    from .feet import lock_motion, travels

    with Recorder() as rec:
        motion = load(take, options.amc_fps, options.take)
        result, report = stretch_motion(motion, options.factor, window=options.window_frames, force=options.force)
        with rec.part("feet"):
            # the stretched take before locking is not kept: the locked one is made from its arrays (memory)
            result, feet_facts = lock_motion(result, options.feet, options.foot_joints, travels(motion),
                                             hand_over=True)
        facts = {**report.to_dict(), "fps": motion.fps,
                 "joints_per_group": {g: len(names) for g, names in report.groups.items()}, "feet": feet_facts}
    return rec.report("stretch", facts, {"stretched": result, "input": motion}, report)
