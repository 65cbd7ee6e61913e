"""``stretch``: lengthen a take by time-frequency warping (paper 004), keeping its cycle."""

from __future__ import annotations

from dataclasses import dataclass

from . import fields
from .options import Flag, Integer, Real, option
from .options import Options as _Options
from .report import Recorder, Report, load


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
    is warped, with a warning).  A take that is one cycle (a game clip, :func:`~mocycle.activities.one_cycle`)
    has no second cycle to warp against: it is lengthened by repeating itself seamlessly
    (:func:`_repeated_clip`)."""
    from ..activities import one_cycle
    from ..warp import stretch_motion
    from .feet_option import lock_motion, travels

    with Recorder() as rec:
        motion = load(take, options.amc_fps, options.take)
        if one_cycle(motion) is not None:
            result, report = _repeated_clip(motion, options)
        else:
            result, report = stretch_motion(motion, options.factor, window=options.window_frames,
                                            force=options.force)
        with rec.part("feet"):
            # the stretched take before locking is not kept: the locked one is made from its arrays (memory)
            result, feet_facts = lock_motion(result, options.feet, options.foot_joints, travels(motion),
                                             hand_over=True)
        facts = {**report.to_dict(), "fps": motion.fps,
                 "joints_per_group": {g: len(names) for g, names in report.groups.items()}, "feet": feet_facts}
    return rec.report("stretch", facts, {"stretched": result, "input": motion}, report)


def _repeated_clip(motion, options: Options):
    """A one-cycle take lengthened by ``options.factor``: its loop (the clip as it is,
    :func:`~mocycle.cycle.parts.part_cycle`) repeated with its root motion, cut to ``round(T * factor)``
    frames; the report says so (one region, the whole take, and its cycle as every group's window)."""
    import math

    from ..cycle.parts import part_cycle
    from ..warp.stretch import StretchReport

    cycle = part_cycle(motion, force=options.force)
    n_out = max(1, int(round(motion.n_frames * options.factor)))
    N = cycle.n_frames
    result = cycle.repeat(math.ceil(n_out / N), root="motion")[:n_out]
    report = StretchReport(factor=options.factor, frames_in=motion.n_frames, frames_out=n_out,
                           windows={"all": N}, cycles={"all": float(cycle.period_frames)},
                           groups={"all": tuple(motion.skeleton.names)}, regions=((0, motion.n_frames),),
                           regions_out=((0, n_out),))
    return result, report
