"""Size limits: absurd input or options are refused before they ask for absurd memory.

A motion of ``T`` frames and ``J`` joints holds about ``32·T·J`` bytes (float64
quaternions; translations once per joint that stands still, ``24·T`` bytes per joint
that moves).  Readers check every count against the bytes the file really holds;
sizes that a file only *claims* (a ``Frames:`` count with no channels, a swings
file's frame count) and sizes asked for by options
(``--fps``, ``--cycles``, ``--factor``) are checked here against

* ``MOCYCLE_MAX_FRAMES`` frames (default 2,000,000: 4.6 hours at 120 fps), and
* ``MOCYCLE_MAX_FRAMES × 50`` joint-frames (default 100,000,000: about 3 GiB
  as a motion).

Set the environment variable ``MOCYCLE_MAX_FRAMES`` to raise (or lower) both.
"""

from __future__ import annotations

import os

from .errors import MocycleError, MotionFileError

ENV_MAX_FRAMES = "MOCYCLE_MAX_FRAMES"
DEFAULT_MAX_FRAMES = 2_000_000
JOINTS_BUDGET = 50  # joint-frames allowed = max_frames() * JOINTS_BUDGET
BYTES_PER_JOINT_FRAME = 32  # a Motion: 4 float64 per joint and frame (the translations of joints that move aside)


def max_frames() -> int:
    """The frame limit: ``$MOCYCLE_MAX_FRAMES`` or 2,000,000."""
    text = os.environ.get(ENV_MAX_FRAMES, "").strip()
    if not text:
        return DEFAULT_MAX_FRAMES
    try:
        value = int(float(text))
    except (ValueError, OverflowError):
        value = 0
    if value < 1:
        raise MocycleError(f"{ENV_MAX_FRAMES} must be a positive whole number of frames; got {text!r}")
    return value


def check_frames(n_frames: float, n_joints: int = 1, what: str = "the result", path=None,
                 line: int | None = None) -> int:
    """``n_frames`` as an int if ``n_frames × n_joints`` is within the limits, else one clear error.

    ``what`` says what would be that long (e.g. ``"--cycles 100000"``); with ``path`` the error is a
    :class:`MotionFileError` naming the file (a count the file claims), else a :class:`MocycleError`.
    """
    limit = max_frames()
    joints = max(int(n_joints), 1)
    too_long = not (n_frames <= limit)  # also catches NaN
    too_big = not too_long and n_frames * joints > limit * JOINTS_BUDGET
    if not (too_long or too_big):
        return int(n_frames)
    size = n_frames * joints * BYTES_PER_JOINT_FRAME / 2**30
    frames = f"{n_frames:,.0f}" if n_frames < 1e18 else f"{n_frames:.3g}"
    bound = (f"the limit is {limit:,} frames" if too_long
             else f"the limit is {limit * JOINTS_BUDGET:,} joint-frames")
    plural = "s" if joints != 1 else ""
    message = (f"{what} would hold {frames} frames × {joints} joint{plural} (about {size:,.3g} GiB in memory); "
               f"{bound} (set {ENV_MAX_FRAMES} to raise it)")
    if path is not None:
        raise MotionFileError(message, path, line)
    raise MocycleError(message)


#: The largest magnitude a coordinate, offset or angle may have: far beyond any capture in any unit, and
#: far below where squares (and squares of sums of squares) overflow float64.
MAX_MAGNITUDE = 1e30
#: Frame times outside this range (seconds) are refused: 1 MHz to one frame in about three hours.
FRAME_TIME_RANGE = (1e-6, 1e4)


def frame_time_problem(frame_time: float) -> str | None:
    """Why ``frame_time`` (seconds) is unusable, or ``None`` when it is fine."""
    lo, hi = FRAME_TIME_RANGE
    if not lo <= frame_time <= hi:  # also NaN
        return f"the frame time must lie within [{lo:g}, {hi:g}] s; got {frame_time!r}"
    return None
