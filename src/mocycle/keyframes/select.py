"""Keyframe selection (thesis section 2.2, Algorithms 1, 2 and 9); the first and last frames are always kept.

``uniform``  Uniform Sampling (US): evenly spaced in time
``scs``      Simple Curve Simplification (Algorithm 1, Lim & Thalmann): start from the
             first and last frames, repeatedly add the frame worst rebuilt by slerp
``pb``       Position Based (Algorithm 2, Togawa & Okuda): start from every frame,
             repeatedly drop the frame its two neighbours rebuild best
``rols``     Regularised Orthogonal Least Squares (Algorithm 9, Amorim et al.): the
             control points whose multiquadric RBF columns best explain a 2-D projection

The pose distance is eq. 3.2 everywhere (:mod:`mocycle.keyframes.distance`).
"""

from __future__ import annotations

import numpy as np

from .. import _validate, defaults
from ..errors import MocycleError
from .distance import pose_distance
from .temporal import slerp

#: the selections (one home: :mod:`mocycle.defaults`)
METHODS = defaults.KEY_SELECTIONS


def keyframe_count(n_frames: int, ratio: float | None = None, count: int | None = None) -> int:
    """Number of keyframes for a take: ``round(ratio · n_frames)`` or ``count``, at least 2, at most ``n_frames``."""
    if n_frames < 2:
        raise MocycleError(f"keyframe compression needs a take of at least 2 frames; got {n_frames}")
    if (ratio is None) == (count is None):
        raise MocycleError("give exactly one of a keyframe ratio or a keyframe count")
    if ratio is not None:
        ratio = _validate.real("ratio", ratio, 0, 1, low_open=True)
        k = int(round(ratio * n_frames))
    else:
        k = _validate.integer("count", count, 2)
    return int(min(max(k, 2), n_frames))


def select_uniform(n_frames: int, k: int) -> np.ndarray:
    """Uniform Sampling: ``k`` frames evenly spaced from the first to the last."""
    k = keyframe_count(n_frames, count=k)
    return np.unique(np.round(np.linspace(0, n_frames - 1, k)).astype(np.int64))


def _segment_errors(quats: np.ndarray, weights: np.ndarray, a: int, b: int) -> np.ndarray:
    """Eq. 3.2 error of frames ``a..b`` rebuilt by slerp between frames ``a`` and ``b``."""
    u = (np.arange(a, b + 1) - a) / (b - a)
    J = quats.shape[1]
    rec = slerp(np.broadcast_to(quats[a], (len(u), J, 4)), np.broadcast_to(quats[b], (len(u), J, 4)),
                np.broadcast_to(u[:, None], (len(u), J)))
    return pose_distance(quats[a: b + 1], rec, weights)


def select_scs(quats: np.ndarray, weights: np.ndarray, k: int) -> np.ndarray:
    """Algorithm 1 (SCS): greedily add the frame with the largest slerp reconstruction error.

    ``quats``: ``(T, J, 4)``; ``weights``: ``(J,)``.  Only the segment split by a new
    keyframe is recomputed.  If every frame is rebuilt exactly before ``k`` keyframes,
    the rest are filled uniformly.
    """
    q = np.asarray(quats, dtype=np.float64)
    n = q.shape[0]
    k = keyframe_count(n, count=k)
    keys = [0, n - 1]
    err = _segment_errors(q, weights, 0, n - 1)
    err[[0, n - 1]] = -1.0
    while len(keys) < k:
        m = int(np.argmax(err))
        if err[m] <= 1e-12:
            break
        pos = int(np.searchsorted(keys, m))
        a, b = keys[pos - 1], keys[pos]
        keys.insert(pos, m)
        if m - a > 1:
            err[a: m + 1] = _segment_errors(q, weights, a, m)
        if b - m > 1:
            err[m: b + 1] = _segment_errors(q, weights, m, b)
        err[keys] = -1.0
    return _fill(np.array(keys, dtype=np.int64), n, k)


def _fill(keys: np.ndarray, n: int, k: int) -> np.ndarray:
    """Add uniformly spaced frames until there are ``k`` keyframes."""
    if len(keys) >= k:
        return np.sort(keys)
    spare = np.setdiff1d(np.arange(n), keys)
    extra = spare[np.round(np.linspace(0, len(spare) - 1, k - len(keys))).astype(np.int64)]
    return np.sort(np.unique(np.concatenate([keys, extra])))


def select_pb(quats: np.ndarray, weights: np.ndarray, k: int) -> np.ndarray:
    """Algorithm 2 (PB): repeatedly drop the frame that slerp between its kept neighbours rebuilds best.

    The error of a frame is its own eq. 3.2 distance to the slerp of its current
    neighbours; after a drop only the two neighbours are re-evaluated.
    """
    q = np.asarray(quats, dtype=np.float64)
    w = np.asarray(weights, dtype=np.float64)
    n = q.shape[0]
    k = keyframe_count(n, count=k)
    prev = np.arange(n) - 1
    nxt = np.arange(n) + 1
    E = np.full(n, np.inf)
    if n > 2:
        j = np.arange(1, n - 1)
        E[1:-1] = pose_distance(q[j], slerp(q[j - 1], q[j + 1], np.full((n - 2, q.shape[1]), 0.5)), w)

    def error(j: int) -> float:
        a, b = prev[j], nxt[j]
        u = (j - a) / (b - a)
        return float(pose_distance(q[j], slerp(q[a], q[b], np.full(q.shape[1], u)), w))

    for _ in range(n - k):
        m = int(np.argmin(E))
        E[m] = np.inf
        a, b = prev[m], nxt[m]
        nxt[a], prev[b] = b, a
        if a > 0:
            E[a] = error(a)
        if b < n - 1:
            E[b] = error(b)
    alive = np.ones(n, dtype=bool)
    alive[np.isinf(E)] = False
    alive[[0, n - 1]] = True
    # frames dropped have E = inf; kept interior frames have a finite error
    return np.flatnonzero(alive)


def select_rols(distances: np.ndarray, targets: np.ndarray, k: int, reg: float = 1e-5,
                forced: tuple[int, ...] | None = None) -> np.ndarray:
    """Algorithm 9 (ROLS): control points by regularised orthogonal least squares.

    Parameters
    ----------
    distances : ``(n, n)`` pose distances between the candidates (eq. 3.2).
    targets : ``(n, 2)`` the candidates' 2-D projection ``Q``.
    k : number of control points, including the ``forced`` ones (default: first and last).
    reg : the regularisation ``r``.

    Each step takes the multiquadric column ``a = √(1 + d²)`` with the largest error
    reduction ``Σ_i (aᵀq_i)² / ((aᵀa + r) q_iᵀq_i)`` and removes its direction from the
    other columns (Gram-Schmidt).  Returns the chosen candidate indices, sorted.
    """
    D = np.asarray(distances, dtype=np.float64)
    Q = np.asarray(targets, dtype=np.float64)
    n = D.shape[0]
    if D.shape != (n, n) or Q.shape != (n, 2):
        raise MocycleError(f"ROLS needs (n, n) distances and (n, 2) targets; got {D.shape}, {Q.shape}")
    k = keyframe_count(n, count=k)
    forced = (0, n - 1) if forced is None else forced
    W = np.sqrt(1.0 + D**2)
    Q = Q - Q.mean(axis=0)
    qq = np.maximum(np.sum(Q**2, axis=0), 1e-300)
    chosen: list[int] = []

    def take(m: int) -> None:
        col = W[:, m].copy()
        chosen.append(m)
        nn = float(col @ col)
        if nn > 1e-300:
            W[:] -= np.outer(col, (col @ W) / nn)
        W[:, m] = 0.0

    for f in dict.fromkeys(forced):
        take(int(f))
    while len(chosen) < k:
        num = (W.T @ Q) ** 2
        den = (np.sum(W**2, axis=0) + reg)[:, None] * qq[None, :]
        score = (num / den).sum(axis=1)
        score[chosen] = -np.inf
        take(int(np.argmax(score)))
    return np.sort(np.array(chosen, dtype=np.int64))
