"""Gait checks on the legs: their own period, and whether a found period is one step or a full cycle.

A gait cycle is two steps.  Features that look alike for the left and the
right step (the root's bob, a symmetric trunk) can make the circular
coordinate wrap once per *step*; the "cycle" then ends with the legs swapped.
The legs themselves tell the difference, whatever the rig:

* :func:`leg_curves` — every leg joint's position relative to the travel
  joint, in the travel joint's heading frame (forward, up, lateral; file
  units), so the curves do not depend on where the actor walks or faces;
* :func:`leg_sides` — leg joints paired left/right by their mean lateral
  position (no joint names needed beyond the ``legs`` group);
* :func:`legs_period` — the legs' windowed-autocorrelation period (paper 004):
  left and right curves are different columns, so it is the full cycle;
* :func:`sides_swap` — compares each side's curves one found period later
  with the same side and with the other side: a half cycle makes the sides
  trade places.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import MocycleError
from ..features import HeadingFrame
from ..motion import Motion
from .period import autocorrelation_period


def leg_curves(motion: Motion) -> tuple[np.ndarray, np.ndarray]:
    """Positions of the ``legs`` joints relative to the travel joint in its heading frame.

    Returns the joint indices ``(n,)`` and the curves ``(T, n, 3)`` as (forward, up, lateral) components
    (lateral: along the line between the two hip joints, the leg joints whose parent is no leg joint);
    ``(0,)`` and ``(T, 0, 3)`` when the skeleton has no leg joints.  Every step works on ``(T,)`` component
    arrays (quaternion and vector components apart, :func:`_world_chain`), several times faster on long
    takes than ``(T, 4)`` and ``(T, 3, 3)`` arrays.
    """
    skel = motion.skeleton
    try:
        legs = np.asarray(skel.select("legs"), dtype=np.intp)
    except MocycleError:
        return np.zeros(0, dtype=np.intp), np.zeros((motion.n_frames, 0, 3))
    frame = HeadingFrame.fit(motion)
    travel = frame.travel
    legs = legs[legs != travel]
    parent = int(skel.parents[travel])
    chain = [*legs.tolist(), travel, parent]
    _, psi = frame.tilt(motion)
    basis = np.stack([frame.e1, frame.up, frame.e2])  # (3, 3): rows e1, up, e2 in the parent frame
    T = motion.n_frames
    xyz = np.empty((T, legs.size, 3))
    fixed = _fixed_offsets(motion, chain)
    for a in range(0, T, _BLOCK):  # blocks of frames: the (T,) temporaries stay in the cache
        frames = slice(a, min(a + _BLOCK, T))
        Q, P = _world_chain(motion, chain, frames, fixed)
        c, s = np.cos(psi[frames]), np.sin(psi[frames])
        for k, j in enumerate(legs.tolist()):
            rel = P[j] - P[travel]                                  # (3, n) world
            if parent >= 0:                                         # into the travel joint's parent frame
                rel = _rotate(Q[parent], rel, inverse=True)
            e, h, f = basis @ rel                                   # (e1, up, e2) components
            # turning by -psi about up turns (e, f) along (e1, e2) to (e cos psi + f sin psi, f cos psi - e sin psi)
            xyz[frames, k, 0] = e * c + f * s
            xyz[frames, k, 1] = h
            xyz[frames, k, 2] = f * c - e * s
    # The lateral direction: from one top leg joint (its parent is no leg joint: the hips) to the other.
    tops = [k for k, j in enumerate(legs) if int(skel.parents[j]) not in set(legs.tolist())]
    if len(tops) >= 2:
        mean = _frame_mean(xyz)[:, [0, 2]]
        gaps = mean[tops][:, None] - mean[tops][None]
        i, j = np.unravel_index(np.argmax(np.linalg.norm(gaps, axis=2)), gaps.shape[:2])
        side = gaps[i, j]
        if np.linalg.norm(side) > 0:
            side = side / np.linalg.norm(side)
            fwd = np.array([side[1], -side[0]])
            for a in range(0, T, _BLOCK):
                x, z = xyz[a:a + _BLOCK, :, 0].copy(), xyz[a:a + _BLOCK, :, 2].copy()
                xyz[a:a + _BLOCK, :, 0] = x * fwd[0] + z * fwd[1]
                xyz[a:a + _BLOCK, :, 2] = x * side[0] + z * side[1]
    return legs, xyz


#: Frames per block of :func:`leg_curves`: (4, 4096) float64 temporaries stay in the cache.
_BLOCK = 4096


def _chain(motion: Motion, joints: list[int]) -> list[int]:
    """``joints`` and their ancestors, parents before children."""
    parents = motion.skeleton.parents
    needed: set[int] = set()
    for j in joints:
        while j >= 0 and j not in needed:
            needed.add(j)
            j = int(parents[j])
    return sorted(needed)


def _fixed_offsets(motion: Motion, joints: list[int]) -> dict[int, np.ndarray]:
    """The local translation ``(3, 1)`` of each joint of the chain of ``joints`` that has the same one in every
    frame (a bone offset: turned as one vector, not one per frame)."""
    chain = _chain(motion, joints)
    moving = set(motion.moving_joints())
    first = motion.translations_at(0)
    return {j: first[j][:, None].copy() for j in chain if j not in moving}


def _world_chain(motion: Motion, joints: list[int], frames: slice = slice(None),
                 fixed: dict[int, np.ndarray] | None = None) -> tuple[dict[int, np.ndarray], dict[int, np.ndarray]]:
    """World rotations (quaternion components ``(4, T)``: x, y, z, w) and positions ``(3, T)`` of ``joints``
    and their ancestors only (a leg chain, not the whole rig: forward kinematics by quaternion products),
    keyed by joint index, on ``frames``.  ``fixed``: :func:`_fixed_offsets` of the chain, if known."""
    if fixed is None:
        fixed = _fixed_offsets(motion, joints)
    parents = motion.skeleton.parents
    Q: dict[int, np.ndarray] = {}
    P: dict[int, np.ndarray] = {}
    for j in _chain(motion, joints):  # parents come before their children
        p = int(parents[j])
        q = np.ascontiguousarray(motion.rotations[frames, j].T)  # one gather, then contiguous components
        if p < 0:
            Q[j], P[j] = q, np.ascontiguousarray(motion.joint_translations(j)[frames].T)
        else:
            Q[j] = _multiply(Q[p], q)
            offset = fixed[j] if j in fixed else np.ascontiguousarray(motion.joint_translations(j)[frames].T)
            P[j] = _rotate(Q[p], offset, add=P[p])
    return Q, P


def _multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products ``a ⊗ b`` of quaternion components ``(4, T)`` (x, y, z, w): ``(4, T)``."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    out = np.empty((4, a.shape[1]))
    np.subtract(aw * bx + ax * bw + ay * bz, az * by, out=out[0])
    np.add(aw * by - ax * bz + ay * bw, az * bx, out=out[1])
    np.add(aw * bz + ax * by - ay * bx, az * bw, out=out[2])
    np.subtract(aw * bw - ax * bx - ay * by, az * bz, out=out[3])
    return out


def _rotate(q: np.ndarray, v: np.ndarray, inverse: bool = False, add: np.ndarray | None = None) -> np.ndarray:
    """Vectors ``v`` (components ``(3, T)`` or ``(3, 1)``) turned by unit quaternions ``q`` (components
    ``(4, T)``; ``inverse``: by their conjugates): ``v + 2w (u × v) + 2 u × (u × v)``, ``u`` the vector part;
    plus ``add`` ``(3, T)`` when given."""
    x, y, z, w = q
    if inverse:
        x, y, z = -x, -y, -z
    vx, vy, vz = v
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    out = np.empty((3, q.shape[1]))
    np.add(vx + w * tx, y * tz - z * ty, out=out[0])
    np.add(vy + w * ty, z * tx - x * tz, out=out[1])
    np.add(vz + w * tz, x * ty - y * tx, out=out[2])
    if add is not None:
        out += add
    return out


def leg_sides(curves: np.ndarray, legs: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of leg joints on opposite sides: two index arrays ``(k,)`` into the columns of ``curves``.

    A joint is on a side when its mean lateral position is at least a fifth of the widest one's; each
    joint of one side is paired with the joint of the other side whose mean position, laterally mirrored,
    is nearest.  Empty arrays when the legs do not split into two sides.
    """
    mean = _frame_mean(curves)                                      # (n, 3)
    lat = mean[:, 2]
    if lat.size == 0 or not np.abs(lat).max() > 0:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    wide = np.abs(lat) >= 0.2 * np.abs(lat).max()
    a, b = np.flatnonzero(wide & (lat > 0)), np.flatnonzero(wide & (lat < 0))
    if a.size == 0 or b.size == 0:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp)
    mirrored = mean[b] * np.array([1.0, 1.0, -1.0])
    cost = np.linalg.norm(mean[a][:, None] - mirrored[None], axis=2)  # (|a|, |b|)
    pairs_a, pairs_b = [], []
    for _ in range(min(a.size, b.size)):                            # greedy: closest pairs first
        i, j = np.unravel_index(np.argmin(cost), cost.shape)
        pairs_a.append(a[i])
        pairs_b.append(b[j])
        cost[i, :] = np.inf
        cost[:, j] = np.inf
    return np.asarray(pairs_a, dtype=np.intp), np.asarray(pairs_b, dtype=np.intp)


def legs_period(motion: Motion, curves: np.ndarray | None = None) -> float:
    """The legs' windowed-autocorrelation period in frames (NaN without legs or rhythm).

    Lags under a quarter of a second are ignored, as in :func:`~mocycle.phase.find_phase`.
    """
    if curves is None:
        curves = leg_curves(motion)[1]
    T = curves.shape[0]
    if curves.shape[1] == 0 or T < 8:
        return float("nan")
    min_lag = max(2, int(round(0.25 / motion.frame_time)))
    if min_lag > T // 2:
        return float("nan")
    return autocorrelation_period(curves.reshape(T, -1), min_lag=min_lag)


@dataclass(frozen=True)
class SideSwap:
    """Result of :func:`sides_swap`: mean squared distances (file units²) one period apart.

    ``same``: each side against itself; ``swapped``: each side against the other; ``pairs``: joint pairs used.
    """

    same: float
    swapped: float
    pairs: int

    @property
    def swaps(self) -> bool:
        """True when the sides trade places across the period (a half cycle)."""
        return self.pairs > 0 and self.swapped < 0.5 * self.same


def sides_swap(curves: np.ndarray, period: float, frames: np.ndarray | slice | None = None) -> SideSwap:
    """Whether left and right leg curves ``(T, n, 3)`` trade places across ``period`` frames.

    Uses the forward and up components (lateral ones mirror between sides), each joint's mean removed,
    on ``frames`` (a contiguous run of frame indices, or a slice; default all).
    """
    a, b = leg_sides(curves)
    if a.size == 0 or not np.isfinite(period) or period <= 0:
        return SideSwap(float("nan"), float("nan"), 0)
    Y = curves if frames is None else curves[frames]
    k = int(np.floor(period))
    f = float(period) - k
    n = Y.shape[0] - k - 1  # frames t with t + period inside (as _shifted)
    if n < 2:
        return SideSwap(float("nan"), float("nan"), 0)
    # forward and up of each side's joints as rows (2k, T): every step below runs along contiguous rows
    sides = [np.ascontiguousarray(Y[:, j, :2].reshape(Y.shape[0], -1).T) for j in (a, b)]
    sides = [S - S.mean(axis=1, keepdims=True) for S in sides]
    now = [S[:, :n] for S in sides]
    later = [(1.0 - f) * S[:, k: k + n] + f * S[:, k + 1: k + 1 + n] for S in sides]
    same = _sum_squares(later[0] - now[0]) + _sum_squares(later[1] - now[1])
    swapped = _sum_squares(later[0] - now[1]) + _sum_squares(later[1] - now[0])
    count = n * a.size * 2
    return SideSwap(same / count, swapped / count, int(a.size))


def _frame_mean(curves: np.ndarray) -> np.ndarray:
    """The mean over frames ``(n, 3)`` of curves ``(T, n, 3)``, as rows of a ``(T, 3n)`` matrix (numpy reduces
    those several times faster than the first axis of a 3-D array with 3-element rows)."""
    return curves.reshape(curves.shape[0], -1).mean(axis=0).reshape(curves.shape[1:])


def _sum_squares(d: np.ndarray) -> float:
    """The sum of the squares of ``d`` ``(m, n)``."""
    return float(np.einsum("ij,ij->", d, d))
