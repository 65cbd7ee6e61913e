"""``info``: the facts of a take (frames, frame time, joints, channels, root travel, rotation ranges)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..errors import DefaultTake
from . import fields
from .options import Options as _Options
from .report import Recorder, Report, load

if TYPE_CHECKING:
    from ..motion import Motion

@dataclass(frozen=True)
class Options(_Options):
    """Options of ``info``."""

    amc_fps: float = fields.amc_fps()
    take: str | None = fields.take()


def motion_info(motion: Motion) -> dict:
    """The facts of a take, JSON-ready."""
    import numpy as np

    from ..io.bvh import channel_blocks

    skel = motion.skeleton
    travel = motion.travel_joint
    root = motion.joint_path(travel)  # the travel joint's chain only, not every joint's positions
    steps = np.linalg.norm(np.diff(root, axis=0), axis=1) if motion.n_frames > 1 else np.zeros(0)
    high = np.full(skel.n_channels, -np.inf)  # each channel's range over the take, a block of rows at a time
    low = np.full(skel.n_channels, np.inf)
    for _, values in channel_blocks(motion):
        np.maximum(high, values.max(axis=0, initial=-np.inf), out=high)
        np.minimum(low, values.min(axis=0, initial=np.inf), out=low)
    ptp = high - low
    ranges: dict[str, dict[str, float]] = {}
    spread: dict[str, float] = {}
    col = 0
    for j, name in enumerate(skel.names):
        per = {}
        for c in skel.channels[j]:
            if c.endswith("rotation"):
                per[c] = float(ptp[col])
            col += 1
        if per:
            ranges[name] = per
            r = motion.rotation(j)
            spread[name] = float(np.degrees((r.mean().inv() * r).magnitude().max()))
    return {
        "frames": motion.n_frames,
        "frame_time": motion.frame_time,
        "fps": motion.fps,
        "duration_s": motion.duration,
        "joints": skel.n_joints,
        "channels": skel.n_channels,
        "end_sites": len(skel.end_sites),
        "travel_joint": skel.names[travel],
        "root_start": root[0].tolist(),
        "root_end": root[-1].tolist(),
        "root_displacement": float(np.linalg.norm(root[-1] - root[0])),
        "root_path_length": float(steps.sum()),
        "rotation_range_deg": ranges,
        "rotation_spread_deg": spread,
    }


def take_names(item, chosen: str | None, motion: Motion | None = None) -> dict:
    """``takes`` (the names of the takes a glTF or FBX file holds) and ``take`` (the one read: the reader keeps
    its name with the ``motion``, ``motion.cache("take")``); nothing for other inputs."""
    from pathlib import Path

    from ..io import MULTI_TAKE_SUFFIXES, takes
    from .report import is_motion

    if is_motion(item) or Path(item).suffix.lower() not in MULTI_TAKE_SUFFIXES:
        return {}
    names = takes(item)
    known = None if motion is None else motion.cache("take")
    if known is not None:
        read = known
    elif chosen is None:
        read = names[0] if names else None
    else:
        read = str(chosen) if str(chosen) in names else names[int(chosen)]
    return {"takes": names, "take": read}


def run(take, options: Options | None = None) -> Report:
    """The facts of one take (a :class:`Motion` or a motion file)."""
    options = options or Options()
    with Recorder() as rec:
        with warnings.catch_warnings():  # the facts list the takes and the one read
            warnings.simplefilter("ignore", DefaultTake)
            motion = load(take, options.amc_fps, options.take)
        facts = motion_info(motion)
        facts.update(take_names(take, options.take, motion))
    return rec.report("info", facts, {"motion": motion})
