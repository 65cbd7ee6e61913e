"""Foot locking for loops: contacts that cross the seam are one contact, and the cleaned cycle still loops.

A cycle of ``N`` frames is repeated three times with its root motion (each
repeat moved on by the travel and turned by the turn per cycle), contacts are
found and locked on those ``3N`` frames, and the second (middle) repeat's ``N`` frames
are read back into the cycle's own space, moved back by one cycle.  Everything
the clean-up does depends only on the frames around it (contacts, their means,
the low frames, the swing bridges and the root lowering reach less than a
cycle), so that cycle is cleaned exactly as its neighbours are: frame ``N`` of the
cleaned loop is frame 0 moved on by exactly the travel per cycle, the held
feet of consecutive cycles are exactly one travel apart, and the in-place
loop (the travel taken out at a constant rate) slides a held foot back at
exactly the treadmill speed.

It lives with the cycle it cleans, above :mod:`mocycle.contacts`, whose detection and locking it uses: the
contacts package knows nothing of cycles.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ..contacts.clearance import swing_clearance
from ..contacts.detect import Contacts, detect_contacts
from ..contacts.legs import Foot, chain_joints, chain_transforms, find_feet, leg_joints
from ..contacts.lock import BLEND_SECONDS, REACH, lock_feet
from ..motion import Motion
from ..rotations import axis_rotations
from .result import Cycle


def lock_cycle(cycle: Cycle, feet: Sequence[Foot] | str | None = None, *, blend: float = BLEND_SECONDS,
               reach: float = REACH, clearance: float | np.ndarray | None = None,
               reference: Motion | Sequence[Motion] | None = None, **detect_options) -> tuple[Cycle, Contacts]:
    """The cycle with its feet locked, and its contacts over its ``N`` frames (a contact running over the
    last frame continues at frame 0).

    ``clearance``: as :func:`~mocycle.contacts.lock_feet`'s; by default the swing clearance of ``reference``,
    the take (or takes) the cycle was made from, or of the cycle itself without one (a fitted cycle's
    swinging feet skim lower than the capture's: pass the take)."""
    N = cycle.n_frames
    ext = cycle.repeat(3, root="motion")
    detect_options.setdefault("up", cycle.space.world_up)   # the take's vertical (found once, by the fit)
    if feet is None or isinstance(feet, str):
        feet = find_feet(ext.skeleton, feet)
    Rw, W = chain_transforms(ext, chain_joints(ext, leg_joints(feet)))   # once for detection and locking
    contacts = detect_contacts(ext, feet, positions=W, **detect_options)
    if clearance is None:
        clearance = swing_clearance(ext if reference is None else reference, contacts.feet,
                                    up=detect_options["up"], body=contacts.body)
    contacts = replace(contacts, clearance=np.broadcast_to(np.asarray(clearance, dtype=np.float64),
                                                           (len(contacts.joints),)).copy())
    locked = lock_feet(ext, contacts, blend=blend, reach=reach, period=N, frames=slice(N, 2 * N),
                       clearance=clearance, transforms=(Rw, W), turn=float(cycle.drift[3]),
                       turn_axis=cycle.space.up)
    P, L = cycle.space.encode(locked)
    turn, move = cycle.drift[3], cycle.drift[:3]
    R = axis_rotations(cycle.space.up, np.array([turn]))[0]
    p0 = cycle.L[0, :3]
    L[:, :3] = (L[:, :3] - p0 - move) @ R + p0    # undo repeat's move to the second cycle
    L[:, 3] -= turn
    L[:, 3] += 2 * np.pi * np.round((cycle.L[0, 3] - L[0, 3]) / (2 * np.pi))
    # P's rotation blocks are the locked motion's rotations (the travel joint's less its heading): already
    # rotations, so kept as the projection rather than projected again
    J = cycle.space.n_joints
    projected = P[:, :9 * J].reshape(N, J, 3, 3).copy()
    return replace(cycle, P=P, L=L, regression=None, projected=projected), contacts.window(N, 2 * N)
