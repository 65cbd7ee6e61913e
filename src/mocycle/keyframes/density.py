"""How many keyframes a take needs: enough for its own rhythm (issue 11, item 9).

The thesis keeps 3 % of the frames.  At 120 fps that is about four keys per gait
cycle; at 30 fps a walk of 33 frames per cycle gets one key every 39 frames, the
legs freeze and the body glides.  The ``"auto"`` density therefore keeps

* at least :data:`KEYS_PER_PERIOD` keys per period of the take's fastest periodic
  motion (its phase, :func:`~mocycle.phase.find_phase`, on at most about
  :data:`PHASE_FRAMES` frames; when it finds no loop, as on many 70-frame
  takes, the autocorrelation period it reports as a cross-check), and
* at least 3 % of the frames (the thesis' ratio), and
* at least :data:`MIN_KEYS` keys, and for the spatial scheme at least
  :data:`SPATIAL_MIN_KEYS` whatever the ratio: its back-projection is an RBF with a
  linear polynomial fitted to the keys' 2-D points, which with two or three keys
  collapses (on 69- and 146-frame Bandai takes, 2-3 keys gave errors 5-14 times
  slerp's; from 6 keys on it beat slerp).

An explicit ratio that leaves fewer than :data:`KEYS_PER_PERIOD` keys per period
gets a warning that names the spacing and the period.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import MocycleError, MocycleWarning, OptionError
from ..motion import Motion
from .select import keyframe_count

THESIS_RATIO = 0.03
KEYS_PER_PERIOD = 4
MIN_KEYS = 6
SPATIAL_MIN_KEYS = 6
PHASE_FRAMES = 1200   # the phase is found on every k-th frame so that at most about this many are used


@dataclass(frozen=True)
class KeyDensity:
    """``count`` keyframes for a take; ``period_frames``: its fastest periodic motion's period (``None`` when it
    has none); ``keys_per_period``; ``rule``: what set the count (``ratio``, ``rhythm``, ``floor``, ``count``)."""

    count: int
    period_frames: float | None
    keys_per_period: float | None
    rule: str

    def to_dict(self) -> dict:
        return {"keyframes": self.count, "period_frames": self.period_frames,
                "keys_per_period": self.keys_per_period, "rule": self.rule}


def rhythm_period(motion: Motion) -> float | None:
    """The period (frames) of the take's fastest periodic motion, else its pose features' autocorrelation
    period, or ``None`` when neither is found (or the take is too short to tell)."""
    from ..phase import find_phase

    step = max(1, math.ceil(motion.n_frames / PHASE_FRAMES))
    try:
        phase = find_phase(motion[::step])
    except MocycleError:
        return None
    if phase.classes:
        return float(min(c.period_frames for c in phase.classes) * step)
    acf = phase.autocorrelation_period_frames  # no loop found (short takes): the cross-check's period
    return float(acf * step) if np.isfinite(acf) else None


def keyframe_density(motion: Motion, ratio: float | str = "auto", scheme: str = "slerp",
                     count: int | None = None) -> KeyDensity:
    """The keyframe count for ``motion`` (see the module docstring).

    ``ratio``: ``"auto"`` or a fraction of the frames in ``(0, 1]``; ``count``: an exact number (wins; no
    floor).  Warns when an explicit ratio leaves fewer than :data:`KEYS_PER_PERIOD` keys per period.
    """
    n = motion.n_frames
    if count is not None:
        k = keyframe_count(n, count=count)
        period = rhythm_period(motion)
        return KeyDensity(k, period, None if period is None else k * period / n, "count")
    auto = isinstance(ratio, str)
    if auto and ratio != "auto":
        raise OptionError("ratio", f"must be 'auto' or a number in (0, 1]; got {ratio!r}")
    k = keyframe_count(n, ratio=THESIS_RATIO if isinstance(ratio, str) else ratio)  # a str is "auto" here
    rule = "ratio"
    period = rhythm_period(motion)
    if auto and period is not None:
        rhythm = min(n, math.ceil(KEYS_PER_PERIOD * n / period) + 1)
        if rhythm > k:
            k, rule = rhythm, "rhythm"
    floor = min(n, max(MIN_KEYS if auto else 2, SPATIAL_MIN_KEYS if scheme == "spatial" else 2))
    if floor > k:
        k, rule = floor, "floor"
    per = None if period is None else k * period / n
    if not auto and per is not None and per < KEYS_PER_PERIOD:
        warnings.warn(f"{k} keyframes of {n} frames is one every {n / k:.0f} frames, {per:.1f} per period of the "
                      f"take's {period:.0f}-frame rhythm (fewer than {KEYS_PER_PERIOD}): the motion will alias "
                      f"(frozen limbs, gliding); option 'ratio' = auto keeps {KEYS_PER_PERIOD} per period",
                      MocycleWarning, stacklevel=2)
    return KeyDensity(int(k), period, None if per is None else float(np.round(per, 3)), rule)
