"""``decompress``: rebuild a take from its keyframes (a ``.mck`` file or a Compressed)."""

from __future__ import annotations

from dataclasses import dataclass

from . import fields
from .options import Choice, option
from .options import Options as _Options
from .report import Recorder, Report

FEET_HELP = ("keep (default: the keyframes come back exactly, the in-betweens as interpolated), lock (feet held "
             "still on the floor during each contact of the rebuilt take: in-betweens and keyframes near a "
             "contact change, so the keyframes no longer come back exactly) or auto (the same as keep).")


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``decompress``."""

    feet: str = option("keep", FEET_HELP, Choice(("auto", "lock", "keep")))
    foot_joints: str | None = fields.foot_joints()


def run(source, options: Options | None = None) -> Report:
    """The take rebuilt (``motions["motion"]``); with ``feet="keep"`` (default) the keyframes come back exactly,
    with ``feet="lock"`` its feet are locked (``facts["keyframes_exact"]`` is then False)."""
    from ..keyframes import read_compressed
    from .feet_option import lock_motion

    options = options or Options()
    with Recorder() as rec:
        packed = source if hasattr(source, "decompress") else read_compressed(source)
        motion = packed.decompress()
        with rec.part("feet"):
            # auto is keep: rebuilding the keyframes exactly is what decompress promises
            motion, feet_facts = lock_motion(motion, options.feet, options.foot_joints, options.feet == "lock",
                                             hand_over=True)
        facts = {"frames": motion.n_frames, "keyframes": packed.n_keyframes, "scheme": packed.scheme,
                 "keyframes_exact": feet_facts["mode"] == "keep", "feet": feet_facts}
    return rec.report("decompress", facts, {"motion": motion}, packed)
