"""How high a swinging foot clears the floor: the capture's own clearance, for foot locking to keep.

A fitted loop is an average of the take's cycles, and averaging cycles whose
heel strikes and toe-offs fall a little apart in time blurs them: the heel
comes down earlier and lifts later, moving fast while it skims the floor
(cmu-iclone 07_02: skate of the input 2.2 units/s, of its fitted loop 9.4).
Locking holds the feet that are planted; a swinging foot is lifted (foot
locking's *swing clearance*) to where the capture's own swinging feet are.

``swing_clearance`` measures that on a reference take: for each contact joint,
the lower quartile (``SWING_QUANTILE``) of its height above its floor over the
frames where it moves faster than ``SWING_SPEED`` body heights per second.
Below that a swinging foot of the capture seldom goes, so a locked foot lifted
to it passes no lower than the capture's usually does; a style that drags its
feet (a shuffle, an old person's walk) keeps a low clearance.  It is at most
``MAX_CLEARANCE`` (a kick or a dance whose fast feet are mostly high in the air
would otherwise lift a walking foot high too).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..motion import Motion
from .legs import Foot, body_height, find_feet, up_axis

SWING_SPEED = 0.5       # body heights/s: a foot moving faster than this (and not planted) is swinging
SWING_QUANTILE = 0.25   # the clearance: this quantile of a swinging foot's height above its floor
MAX_CLEARANCE = 0.05    # of the body height
MIN_SWING_SECONDS = 0.05  # a joint swinging for less than this over the take gets no clearance (0)


def swing_clearance(motion: Motion | Sequence[Motion], feet: Sequence[Foot] | str | None = None, *,
                    up: np.ndarray | None = None, body: float | None = None,
                    quantile: float = SWING_QUANTILE) -> np.ndarray:
    """``(C,)`` the clearance of each contact joint of ``feet`` (each foot's ankle, then its toe: the order
    of ``Contacts.joints``), as a fraction of the body height, measured on ``motion`` (a reference take; with
    several takes, e.g. the two takes of a blend, the mean of theirs).  0 for a joint that hardly swings.
    ``up``, ``body``: the vertical and the body height (file units) when the caller has them (the same rig's)."""
    from .detect import heights_and_speeds, local_floor
    from .legs import chain_joints, chain_positions

    if not isinstance(motion, Motion):
        return np.mean([swing_clearance(m, feet, up=up, body=body, quantile=quantile) for m in motion], axis=0)
    if feet is None or isinstance(feet, str):
        feet = find_feet(motion.skeleton, feet)
    up = up_axis(motion) if up is None else np.asarray(up, dtype=np.float64)
    joints = [j for f in feet for j in f.contact_joints]
    if motion.n_frames < 3:
        return np.zeros(len(joints))
    body = body_height(motion, up) if body is None else float(body)
    W = chain_positions(motion, chain_joints(motion, joints))   # the feet and the travel joint only
    h, v, _ = heights_and_speeds(motion, joints, up, positions=W)
    h, v = h / body, v / body
    h = h - local_floor(h, motion.fps)
    swinging = v > SWING_SPEED   # a planted foot under a dashing body may glide this fast: a lower clearance
    enough = max(3, int(round(MIN_SWING_SECONDS * motion.fps)))
    out = np.zeros(len(joints))
    for c in range(len(joints)):
        x = np.sort(h[swinging[:, c], c])
        if x.size >= enough:   # numpy's quantile ("linear"), without its overhead on a few hundred values
            at = quantile * (x.size - 1)
            lo = int(at)
            value = x[lo] + (at - lo) * (x[min(lo + 1, x.size - 1)] - x[lo])
            out[c] = min(float(value), MAX_CLEARANCE)
    return out
