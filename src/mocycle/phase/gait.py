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
from ..rotations import quat_conj, quat_multiply
from .period import autocorrelation_period


def leg_curves(motion: Motion) -> tuple[np.ndarray, np.ndarray]:
    """Positions of the ``legs`` joints relative to the travel joint in its heading frame.

    Returns the joint indices ``(n,)`` and the curves ``(T, n, 3)`` as (forward, up, lateral) components
    (lateral: along the line between the two hip joints, the leg joints whose parent is no leg joint);
    ``(0,)`` and ``(T, 0, 3)`` when the skeleton has no leg joints.
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
    Q, P = _world_chain(motion, [*legs.tolist(), travel, parent])
    rel = np.stack([P[j] - P[travel] for j in legs.tolist()], axis=1)  # (T, n, 3) world
    if parent >= 0:                                                 # into the travel joint's parent frame
        rel = _rotate(quat_conj(Q[parent])[:, None], rel)
    _, psi = frame.tilt(motion)
    # (e1, up, e2) components in the heading frame (frame.to_local, then onto the basis): turning by -psi about
    # up turns the horizontal components (a, b) along (e1, e2) to (a cos psi + b sin psi, b cos psi - a sin psi)
    a, h, b = np.moveaxis(rel @ np.stack([frame.e1, frame.up, frame.e2]).T, -1, 0)
    c, s = np.cos(psi)[:, None], np.sin(psi)[:, None]
    xyz = np.stack([a * c + b * s, h, b * c - a * s], axis=-1)
    # The lateral direction: from one top leg joint (its parent is no leg joint: the hips) to the other.
    tops = [k for k, j in enumerate(legs) if int(skel.parents[j]) not in set(legs.tolist())]
    mean = xyz.mean(axis=0)[:, [0, 2]]
    if len(tops) >= 2:
        gaps = mean[tops][:, None] - mean[tops][None]
        i, j = np.unravel_index(np.argmax(np.linalg.norm(gaps, axis=2)), gaps.shape[:2])
        side = gaps[i, j]
        if np.linalg.norm(side) > 0:
            side = side / np.linalg.norm(side)
            fwd = np.array([side[1], -side[0]])
            xyz = np.stack([xyz[..., [0, 2]] @ fwd, xyz[..., 1], xyz[..., [0, 2]] @ side], axis=-1)
    return legs, xyz


def _world_chain(motion: Motion, joints: list[int]) -> tuple[dict[int, np.ndarray], dict[int, np.ndarray]]:
    """World rotations (quaternions ``(T, 4)``) and positions ``(T, 3)`` of ``joints`` and their ancestors only
    (a leg chain, not the whole rig: forward kinematics by quaternion products), keyed by joint index."""
    parents = motion.skeleton.parents
    needed: set[int] = set()
    for j in joints:
        while j >= 0 and j not in needed:
            needed.add(j)
            j = int(parents[j])
    Q: dict[int, np.ndarray] = {}
    P: dict[int, np.ndarray] = {}
    R: dict[int, np.ndarray] = {}  # a parent's world matrices, made once for all its children
    for j in sorted(needed):  # parents come before their children
        p = int(parents[j])
        if p < 0:
            Q[j], P[j] = motion.rotations[:, j], motion.translations[:, j]
        else:
            if p not in R:
                R[p] = _matrices(Q[p])
            Q[j] = quat_multiply(Q[p], motion.rotations[:, j])
            P[j] = P[p] + np.einsum("...ij,...j->...i", R[p], motion.translations[:, j])
    return Q, P


def _matrices(q: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of unit quaternions ``(..., 4)``."""
    x, y, z, w = np.moveaxis(q, -1, 0)
    R = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                  2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                  2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1)
    return R.reshape(R.shape[:-1] + (3, 3))


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Vectors ``(..., 3)`` rotated by unit quaternions ``(..., 4)`` (broadcast), through their rotation matrices."""
    return np.einsum("...ij,...j->...i", _matrices(q), v)


def leg_sides(curves: np.ndarray, legs: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of leg joints on opposite sides: two index arrays ``(k,)`` into the columns of ``curves``.

    A joint is on a side when its mean lateral position is at least a fifth of the widest one's; each
    joint of one side is paired with the joint of the other side whose mean position, laterally mirrored,
    is nearest.  Empty arrays when the legs do not split into two sides.
    """
    mean = curves.mean(axis=0)                                      # (n, 3)
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


def _shifted(Y: np.ndarray, lag: float) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``t`` and rows ``t + lag`` (linear interpolation) of ``Y`` ``(T, ...)`` for every valid ``t``."""
    T = Y.shape[0]
    k = int(np.floor(lag))
    f = lag - k
    n = T - k - 1
    if n < 1:
        return Y[:0], Y[:0]
    later = (1.0 - f) * Y[k: k + n] + f * Y[k + 1: k + 1 + n]
    return Y[:n], later


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
    Y = Y[:, :, :2] - Y[:, :, :2].mean(axis=0)
    now, later = _shifted(Y, float(period))
    if now.shape[0] < 2:
        return SideSwap(float("nan"), float("nan"), 0)
    same = np.mean((later[:, a] - now[:, a]) ** 2) + np.mean((later[:, b] - now[:, b]) ** 2)
    swapped = np.mean((later[:, a] - now[:, b]) ** 2) + np.mean((later[:, b] - now[:, a]) ** 2)
    return SideSwap(float(same), float(swapped), int(a.size))
