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
    between frames (for cycles that can be sampled anywhere, such as a harmonic fit).
    """
    score = np.zeros(blocks[0].shape[0])
    for C in blocks:
        step, acc = _changes(C, stride)
        ms, ma = np.median(step), np.median(acc)
        pose = step / ms if ms > 0 else np.zeros_like(step)
        vel = np.maximum(acc, np.roll(acc, stride)) / ma if ma > 0 else np.zeros_like(acc)
        score = np.maximum(score, np.maximum(pose, vel))
    return int(np.argmin(score))
