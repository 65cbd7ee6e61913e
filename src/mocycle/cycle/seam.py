"""Where a loop wraps, and how ordinary that wrap is.

For one cycle ``C (N, D)`` (row ``N`` would equal row 0) the step into frame
``k`` is ``||C[k] - C[k-1]||`` and the velocity change at frame ``k`` is the
second difference ``||C[k+1] - 2 C[k] + C[k-1]||``, indices modulo ``N``.
The seam is at frame 0: its ratios compare the wrap's step and velocity
changes with the median over the whole cycle (``global``) or over the eight
frames nearest the wrap (``local``, a pop detector that does not depend on
where the wrap is placed).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

LOCAL = 4  # frames on each side of the wrap for the local ratio


#: values per block of rows in :func:`_changes` (its temporaries stay in the cache: on a 100-joint trial cycle,
#: 640 x 909 values, whole-array differences took twice as long)
_BLOCK_VALUES = 1 << 14


def _changes(C: np.ndarray, stride: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """``step[k]`` into sample k and ``acc[k]`` at sample k, ``(N,)`` each, wrapping around; one frame is
    ``stride`` samples.  The second difference ``C[k+s] - 2 C[k] + C[k-s]`` is taken as the change of the
    first, ``(C[k+s] - C[k]) - (C[k] - C[k-s])``; a block of rows at a time."""
    C = np.asarray(C, dtype=np.float64).reshape(C.shape[0], -1)
    N = C.shape[0]
    s = stride % N
    step, acc = np.empty(N), np.empty(N)
    rows = max(1, _BLOCK_VALUES // max(1, C.shape[1]))
    for r0 in range(0, N, rows):
        r1 = min(N, r0 + rows)
        k = np.arange(r0, r1)
        cur = C[r0:r1]
        before = C[r0 - s:r1 - s] if r0 >= s else C[(k - s) % N]
        after = C[r0 + s:r1 + s] if r1 + s <= N else C[(k + s) % N]
        D = cur - before
        A = after - cur
        np.subtract(A, D, out=A)
        step[r0:r1] = _row_norms(D)
        acc[r0:r1] = _row_norms(A)
    return step, acc


def _row_norms(X: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(X, axis=1)`` of ``X`` ``(n, D)``, squaring in place (``X`` is a temporary)."""
    np.multiply(X, X, out=X)
    return np.sqrt(np.add.reduce(X, axis=1))


def _ratio(value: float, reference: float) -> float:
    if reference > 0:
        return float(value / reference)
    return 0.0 if value == 0 else float("inf")


def seam_ratios(C: np.ndarray) -> dict[str, float]:
    """``pose``, ``velocity`` (global median) and ``pose_local``, ``velocity_local`` ratios of the wrap."""
    N = C.shape[0]
    if N < 2 * LOCAL + 3:
        nan = float("nan")
        return {"pose": nan, "velocity": nan, "pose_local": nan, "velocity_local": nan}
    step, acc = _changes(C)
    wrap_acc = max(acc[0], acc[-1])
    near = np.r_[1:LOCAL + 1, N - LOCAL:N]               # steps into frames 1..4 and N-4..N-1
    near_acc = np.r_[1:LOCAL + 1, N - LOCAL - 1:N - 1]   # second differences away from frames 0 and N-1
    return {
        "pose": _ratio(step[0], np.median(step[1:])),
        "velocity": _ratio(wrap_acc, np.median(acc[1:-1])),
        "pose_local": _ratio(step[0], np.median(step[near])),
        "velocity_local": _ratio(wrap_acc, np.median(acc[near_acc])),
    }


def calmest_start(*blocks: np.ndarray, stride: int = 1) -> int:
    """The sample to start the cycle at so that the wrap is the most ordinary step of every block.

    For each candidate start ``k`` the wrap's global pose and velocity ratios are computed for every
    block (``(n, D_b)`` arrays of one cycle sampled ``stride`` times per frame, e.g. rotations and the
    in-place root path); the start with the smallest largest ratio wins.  Where a loop is smooth this puts
    the wrap at a calm pose, which is where animators cut loops too.  ``stride > 1`` chooses the start
    between frames (for cycles that can be sampled anywhere, such as a harmonic fit; :func:`calmest_sample`
    does so from a few samples).
    """
    score = np.zeros(blocks[0].shape[0])
    for C in blocks:
        step, acc = _changes(C, stride)
        ms, ma = np.median(step), np.median(acc)
        score = np.maximum(score, _score(step, np.roll(acc, stride), acc, ms, ma))
    return int(np.argmin(score))


def _score(step: np.ndarray, acc_before: np.ndarray, acc: np.ndarray, ms: float, ma: float) -> np.ndarray:
    """The wrap's larger ratio at each start: its step over the median step ``ms``, the larger velocity change
    on either side of it over the median change ``ma`` (0 where a median is 0)."""
    pose = step / ms if ms > 0 else np.zeros_like(step)
    vel = np.maximum(acc, acc_before) / ma if ma > 0 else np.zeros_like(acc)
    return np.maximum(pose, vel)


#: the calmest frames between which :func:`calmest_sample` looks at every sample
CANDIDATES = 3


def calmest_sample(blocks_at: Callable[[np.ndarray], Sequence[np.ndarray]], samples: int, stride: int,
                   candidates: int = CANDIDATES) -> int:
    """:func:`calmest_start` (``stride`` samples per frame) of a cycle of ``samples`` samples that is sampled
    only where it is looked at: ``blocks_at(rows)`` gives its blocks at those sample indices (sorted).

    The ratios are first made at every frame (every ``stride``-th sample, one frame apart; their medians are
    the ones every start is measured against), then at every sample within a frame of the ``candidates``
    calmest frames, from the samples up to three frames before and two after them: about ``candidates * 5``
    frames' samples made, not all ``samples``."""
    frames = np.arange(0, samples, stride)
    medians, score = [], np.zeros(frames.size)
    for C in blocks_at(frames):
        step, acc = _changes(C, 1)
        ms, ma = float(np.median(step)), float(np.median(acc))
        medians.append((ms, ma))
        score = np.maximum(score, _score(step, np.roll(acc, 1), acc, ms, ma))
    best = frames[np.argsort(score, kind="stable")[:candidates]]
    if stride == 1:
        return int(best[0])
    starts = np.unique((best[:, None] + np.arange(-stride, stride + 1)).ravel() % samples)
    need = np.unique((best[:, None] + np.arange(-3 * stride, 2 * stride + 1)).ravel() % samples)

    def at(k: np.ndarray) -> np.ndarray:  # rows of the blocks made at ``need`` for samples ``k``
        return np.searchsorted(need, k % samples)

    score = np.zeros(starts.size)
    for C, (ms, ma) in zip(blocks_at(need), medians, strict=True):
        C = np.asarray(C, dtype=np.float64).reshape(C.shape[0], -1)
        a, b, c, d = (C[at(starts + o * stride)] for o in (-2, -1, 0, 1))
        into = c - b
        acc = _row_norms((d - c) - into)
        acc_before = _row_norms(into - (b - a))
        step = _row_norms(into)  # last: squares ``into`` in place
        score = np.maximum(score, _score(step, acc_before, acc, ms, ma))
    return int(starts[np.argmin(score)])
