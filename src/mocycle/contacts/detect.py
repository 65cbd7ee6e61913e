"""Foot contacts: when each contact joint (ankle, toe) is planted.

A contact joint is planted while it is **near its floor and slow**: its height
above its floor is under ``height``, its horizontal speed under
``speed`` and its vertical speed under ``rise`` (a heel that starts to lift or
is still coming down is not planted).
Both are fractions of the body height (and body heights per second), so the
same numbers work for centimetres, metres or inches, and the
speed is measured on positions smoothed over a fixed time (not a fixed number
of frames), so 30, 60 and 120 fps agree.

* **hysteresis** — a contact starts below ``height`` and ``speed`` and ends
  only above ``release`` times them, so noise at the threshold does not
  chatter;
* **minimum durations** — gaps shorter than ``min_gap`` seconds are filled,
  contacts shorter than ``min_contact`` seconds dropped.

A foot is in contact while its ankle or its toe is.

**The floor** of a contact joint is its lowest level *nearby*: the lowest over
``FLOOR_SECONDS`` about each frame, never more than ``FLOOR_DRIFT`` above its
lowest level over the whole motion.  A capture whose floor drifts, a
retargeted take whose stances sit at different heights (CMU on the iClone rig:
up to 3-4 % of the body height apart within one take) or a gentle slope then
keeps every stance near its floor; with the lowest level of the whole take,
the stances above it were missed and stayed unlocked.

**A foot with no contact at all** over the motion is looked at again (a foot
that never touches the floor while the other one walks or runs is nearly
always a miss): a fast run's stance rolls from heel to toe, so the toe dips
lowest while it pushes off at speed and rocks up and down while it rests, and
a fitted loop or a 30 fps capture smooths that further.  For such a foot, each
joint's floor is its lowest level while slow, and the vertical threshold is
relative to the body's speed like the horizontal one (``_relaxed``).  A foot
that is held up (its floor so found well above the other foot's) stays
without contacts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import MocycleError
from ..motion import Motion
from ..rotations import vector_norms
from .legs import ChainArray, Foot, along, body_height, chain_joints, chain_positions, find_feet, up_axis
from .smooth import gaussian, minimum

CONTACT_HEIGHT = 0.025  # of the body height, above the joint's lowest level
CONTACT_SPEED = 0.15    # body heights per second, horizontal
CONTACT_RISE = 0.05     # body heights per second, vertical: a heel that lifts faster is not planted
TRAVEL_SHARE = 0.15     # or this share of the body's own horizontal speed (over TRAVEL_SECONDS), if faster
RELAX_FLOOR = 0.05      # of the body height: a relaxed floor at most this above the lowest same joint of any foot
TRAVEL_SECONDS = 0.5    # std of the Gaussian the body's speed is averaged with
RELEASE = 1.5           # a contact ends above RELEASE × the thresholds
SMOOTH_SECONDS = 1 / 60  # std of the Gaussian the positions are smoothed with before differencing
MIN_CONTACT = 0.03      # seconds
MIN_GAP = 0.06          # seconds
FLOOR_SECONDS = 2.0     # a contact joint's floor: its lowest level over this time about each frame ...
FLOOR_DRIFT = 0.10      # ... at most this (of the body height) above its lowest level over the whole motion


def ranges(mask: np.ndarray) -> list[tuple[int, int]]:
    """``[(start, stop), ...]`` (stop exclusive) of the runs of True in a boolean ``(T,)`` array."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    edges = np.flatnonzero(m[1:] != m[:-1]).tolist()
    return list(zip(edges[::2], edges[1::2], strict=True))


@dataclass(frozen=True, eq=False)
class Contacts:
    """Contacts of ``feet`` over ``T`` frames.

    ``joints``: the contact joints ``(C,)`` (each foot's ankle, then its toe if any); ``foot_of``: the foot
    (index into ``feet``) of each; ``mask``: ``(T, C)`` True while planted; ``up``: world up ``(3,)``;
    ``body``: the body height (file units); ``frame_time``: seconds; ``clearance``: ``(C,)`` the swing
    clearance foot locking used (fraction of the body height), when the contacts were locked.
    """

    feet: tuple[Foot, ...]
    joints: tuple[int, ...]
    foot_of: tuple[int, ...]
    mask: np.ndarray
    up: np.ndarray
    body: float
    frame_time: float
    clearance: np.ndarray | None = None

    @property
    def n_frames(self) -> int:
        return self.mask.shape[0]

    def joint_ranges(self, c: int) -> list[tuple[int, int]]:
        """Frame ranges of contact joint ``c`` (index into ``joints``)."""
        return ranges(self.mask[:, c])

    def foot_mask(self, f: int) -> np.ndarray:
        """``(T,)`` True while foot ``f`` touches the floor (ankle or toe)."""
        return self.mask[:, [c for c, g in enumerate(self.foot_of) if g == f]].any(axis=1)  # type: ignore[return-value]  # numpy stubs: any(axis=) of a 2-D array is an array

    def foot_ranges(self, f: int) -> list[tuple[int, int]]:
        return ranges(self.foot_mask(f))

    def window(self, start: int, stop: int) -> Contacts:
        """The contacts of frames ``start .. stop-1``."""
        return Contacts(self.feet, self.joints, self.foot_of, self.mask[start:stop], self.up, self.body,
                        self.frame_time, self.clearance)

    def to_dict(self, names: Sequence[str], period: int | None = None) -> dict:
        """Per foot (by side): its joints and its contacts as ``[start, stop]`` frame ranges (stop exclusive).

        With ``period`` (a loop of that many frames) a contact that runs over the end and on at frame 0 is
        one contact ``[start, stop]`` with ``stop > period``: it crosses the seam.
        """
        out = {}
        for f, foot in enumerate(self.feet):
            cs = [c for c, g in enumerate(self.foot_of) if g == f]
            entry = {"joints": foot.names_of(names),
                     "contacts": _as_lists(ranges(self.foot_mask(f)), period)}
            for c in cs:
                kind = "ankle" if self.joints[c] == foot.ankle else "toe"
                entry[f"{kind}_contacts"] = _as_lists(self.joint_ranges(c), period)
            out[foot.side] = entry
        return out


def _as_lists(rs: list[tuple[int, int]], period: int | None) -> list[list[int]]:
    out = [list(r) for r in rs]
    if period and len(out) >= 2 and out[0][0] == 0 and out[-1][1] == period:
        first = out.pop(0)
        out[-1][1] = period + first[1]
    return out


def _hysteresis(on: np.ndarray, keep: np.ndarray) -> np.ndarray:
    """True from each frame where ``on`` holds for as long as ``keep`` holds (``on`` implies ``keep``)."""
    keep = keep | on
    out = np.zeros_like(on)
    for a, b in ranges(keep):
        hits = np.flatnonzero(on[a:b])
        if hits.size:
            out[a + hits[0]:b] = True
    return out


def _durations(mask: np.ndarray, min_contact: int, min_gap: int) -> np.ndarray:
    mask = mask.copy()
    rs = ranges(mask)
    for (_, b), (c, _) in zip(rs[:-1], rs[1:], strict=True):
        if c - b < min_gap:
            mask[b:c] = True
    for a, b in ranges(mask):
        if b - a < min_contact:
            mask[a:b] = False
    return mask


def heights_and_speeds(motion: Motion, joints: Sequence[int], up: np.ndarray, smooth: float = SMOOTH_SECONDS,
                       positions: np.ndarray | ChainArray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Height above the lowest level ``(T, C)``, horizontal speed ``(T, C)`` and vertical speed ``(T, C)``
    (units/s) of ``joints``.

    Speeds are central differences of positions smoothed by a Gaussian of ``smooth`` seconds.
    """
    W = motion.world_positions() if positions is None else positions
    P = W[:, list(joints)]
    h = along(P, up)
    h = h - h.min(axis=0)
    sigma = smooth / motion.frame_time
    if motion.n_frames < 2:
        return h, np.zeros_like(h), np.zeros_like(h)
    if sigma >= 0.3:
        P = gaussian(P, sigma)
    v = np.gradient(P, motion.frame_time, axis=0)
    del P  # (T, C, 3) arrays held one or two at a time (memory)
    vu = along(v, up)
    for k in range(3):  # the horizontal velocity in place: v - vu up, axis by axis
        v[..., k] -= vu * up[k]
    return h, vector_norms(v), np.abs(vu)


def local_floor(h: np.ndarray, fps: float) -> np.ndarray:
    """``(T, C)`` each contact joint's floor under heights ``h`` ``(T, C)`` (body heights above its lowest
    level over the motion): its lowest level over ``FLOOR_SECONDS`` about each frame, at most
    ``FLOOR_DRIFT``."""
    return np.minimum(minimum(h, max(1, int(round(FLOOR_SECONDS * fps)))), FLOOR_DRIFT)


def _travel_speed(motion: Motion, W: np.ndarray | ChainArray, up: np.ndarray) -> np.ndarray:
    """``(T,)`` horizontal speed of the travel joint (units/s), averaged by a Gaussian of ``TRAVEL_SECONDS``."""
    if motion.n_frames < 2:
        return np.zeros(motion.n_frames)
    p = W[:, motion.travel_joint]
    v = np.gradient(p, motion.frame_time, axis=0)
    v = vector_norms(v - np.outer(v @ up, up))
    return gaussian(v, TRAVEL_SECONDS / motion.frame_time)


def _find(h, v, vu, height, speed, rise, release, n_contact, n_gap) -> np.ndarray:
    """``(T, C)`` contacts of the joints whose heights, horizontal and vertical speeds are ``h, v, vu``
    ``(T, C)`` (body heights, per second): the thresholds with hysteresis and minimum durations (frames)."""
    mask = np.zeros(h.shape, bool)
    for c in range(h.shape[1]):
        on = (h[:, c] < height) & (v[:, c] < speed) & (vu[:, c] < rise)
        keep = (h[:, c] < release * height) & (v[:, c] < release * speed) & (vu[:, c] < release * rise)
        mask[:, c] = _durations(_hysteresis(on, keep), n_contact, n_gap)
    return mask


def detect_contacts(motion: Motion, feet: Sequence[Foot] | str | None = None, *, height: float = CONTACT_HEIGHT,
                    speed: float = CONTACT_SPEED, rise: float = CONTACT_RISE, release: float = RELEASE,
                    min_contact: float = MIN_CONTACT,
                    min_gap: float = MIN_GAP, travel: float = TRAVEL_SHARE, up: np.ndarray | None = None,
                    relax: bool = True, positions: np.ndarray | ChainArray | None = None) -> Contacts:
    """Contacts of every contact joint of ``feet`` (default: :func:`find_feet`; a string names them).

    ``height``: fraction of the body height above the joint's floor (:func:`local_floor`); ``speed``: body heights per
    second (horizontal), or ``travel`` times the body's own horizontal speed where that is more (averaged
    over ``TRAVEL_SECONDS``), ``rise``: body heights per second (vertical); ``release``: hysteresis factor (> 1);
    ``min_contact``, ``min_gap``: seconds; ``relax``: a foot with no contact at all is looked at again with
    the rules for a rolling stance (:func:`_relaxed`); ``positions``: world positions ``(T, J, 3)`` of at
    least the feet's chains and the travel joint (:func:`~mocycle.contacts.legs.chain_transforms`), when the
    caller has them.
    """
    if not (height > 0 and speed > 0 and rise > 0 and release >= 1 and min_contact >= 0 and min_gap >= 0
            and travel >= 0):
        raise MocycleError(f"contact thresholds must be positive (height {height}, speed {speed}, release "
                           f"{release} >= 1, durations {min_contact}, {min_gap} >= 0)")
    if feet is None or isinstance(feet, str):
        feet = find_feet(motion.skeleton, feet)
    feet = tuple(feet)
    up = up_axis(motion) if up is None else np.asarray(up, dtype=np.float64)
    body = body_height(motion, up)
    joints = tuple(j for f in feet for j in f.contact_joints)
    foot_of = tuple(i for i, f in enumerate(feet) for _ in f.contact_joints)
    W = chain_positions(motion, chain_joints(motion, joints)) if positions is None else positions  # legs only
    h, v, vu = heights_and_speeds(motion, joints, up, positions=W)
    h, v, vu = h / body, v / body, vu / body
    h = h - local_floor(h, motion.fps)
    # a foot under a running body is planted when it is slow for the body: a fitted or resampled stance
    # glides at a share of the travel speed
    body_speed = travel * _travel_speed(motion, W, up) / body
    slow_below = np.maximum(speed, body_speed)  # (T,): the speed threshold, raised under a running body
    n_contact, n_gap = (max(1, int(round(s * motion.fps))) for s in (min_contact, min_gap))

    def find(h, v, vu, rise):
        return _find(h, v, vu, height, slow_below, rise, release, n_contact, n_gap)

    mask = find(h, v, vu, rise)
    if relax:
        lows = along(W[:, list(joints)], up).min(axis=0) / body            # each joint's lowest level
        kind = [0 if j == feet[f].ankle else 1 for j, f in zip(joints, foot_of, strict=True)]
        ground = {k: min(lo for lo, kk in zip(lows, kind, strict=True) if kk == k) for k in set(kind)}
        for f in range(len(feet)):
            cols = [c for c, g in enumerate(foot_of) if g == f]
            if not mask[:, cols].any():
                mask[:, cols] = _relaxed(h[:, cols], v[:, cols], vu[:, cols], slow_below, rise, body_speed,
                                         lows[cols] - np.array([ground[kind[c]] for c in cols]), find)
    return Contacts(feet, joints, foot_of, mask, up, body, motion.frame_time)


def _relaxed(h, v, vu, speed, rise, body_speed, above, find):
    """The contacts ``(T, k)`` of one foot that has none by the usual rules (its joints' ``h``, ``v``, ``vu``
    ``(T, k)`` in body heights): a fast run's stance (or its fitted loop's, or a 30 fps capture's) rolls.

    * each joint's floor is its lowest level **while slow** (horizontal speed under ``speed``), not its
      lowest level overall: a toe that dips as the foot rolls over it at push-off, moving fast, is not
      where it rests;
    * the vertical test is relative to the body's speed like the horizontal one: ``rise`` or
      ``body_speed`` (the horizontal threshold's share of the travel speed), if more — a rolling stance
      rocks up and down at a share of the running speed.

    A joint whose floor found so is more than ``RELAX_FLOOR`` above the lowest level of the same joint of
    any foot (``above`` ``(k,)``: its own lowest level above that, body heights) gets no contact: a foot
    held up (a hop on the other leg) is not planted in the air."""
    slow = v < speed[:, None]
    floor = np.where(slow.any(axis=0), np.where(slow, h, np.inf).min(axis=0), np.inf)
    ok = above + floor <= RELAX_FLOOR
    if not ok.any():
        return np.zeros(h.shape, bool)
    mask = find(h - np.where(ok, floor, 0.0), v, vu, np.maximum(rise, body_speed))
    mask[:, ~ok] = False
    return mask
