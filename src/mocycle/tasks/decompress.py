"""``decompress``: rebuild a take from its keyframes (a ``.mck`` file or a Compressed)."""

from __future__ import annotations

from dataclasses import dataclass

from .options import Options as _Options
from .report import Recorder, Report

LABELS = {"frames": ("frames rebuilt", ""), "keyframes": ("keyframes", ""), "scheme": ("scheme", "")}


@dataclass(frozen=True)
class Options(_Options):
    """Options of ``decompress`` (none yet)."""


def run(source, options: Options | None = None) -> Report:
    """The take rebuilt (``motions["motion"]``); the keyframes come back exactly."""
    from ..keyframes import read_compressed

    with Recorder() as rec:
        packed = source if hasattr(source, "decompress") else read_compressed(source)
        motion = packed.decompress()
        facts = {"frames": motion.n_frames, "keyframes": packed.n_keyframes, "scheme": packed.scheme}
    return rec.report("decompress", facts, {"motion": motion}, packed)
