"""The lapped cosine transform (LCT) of paper 004 §3: Malvar's fold with a smooth window, then DCT-IV.

The time axis ``[0, T)`` is cut into blocks at ``edges`` (``0 = e_0 < e_1 < ... < e_K = T``).  At every
interior edge ``b`` the signal is *folded* over ``overlap`` samples on each side with a smooth rising cutoff
``r`` (``r(t)^2 + r(-t)^2 = 1``; Wickerhauser's iterated sine), for ``t = j + 1/2``, ``j = 0..overlap-1``::

    y(b + t) = r(t) x(b + t) + r(-t) x(b - t)      (start of the right block: even part)
    y(b - t) = r(t) x(b - t) - r(-t) x(b + t)      (end of the left block: odd part)

and each block of the folded signal goes through an orthonormal DCT-IV (``scipy.fft.dct(type=4,
norm="ortho")``).  The edges of the whole signal are not folded.  Every step is an orthogonal map, so the
transform is orthonormal: energy is kept and the inverse (DCT-IV, its own inverse, then the unfold) gives
perfect reconstruction.  The basis functions are smooth, overlapping "time-frequency atoms": a cosine of
frequency ``(k + 1/2) / (2 L)`` cycles per frame on block ``[e_i, e_{i+1})`` of length ``L`` (even about the
block's start, odd about its end), tapered by the bell over ``overlap`` samples beyond each interior edge.

Everything works on ``(T,)`` curves or ``(T, D)`` matrices (D curves at once, along axis 0).  Coefficients
come back with the same shape as the input: rows ``e_i .. e_{i+1}-1`` hold block ``i``'s DCT-IV coefficients,
lowest frequency first.  With equal blocks of length ``N``, ``C[:K*N].reshape(K, N, D)`` is the
time-frequency image of the paper (time along the first axis, frequency along the second).
"""

from __future__ import annotations

import numpy as np
from scipy import fft as sp_fft

from .. import _validate
from ..errors import MocycleError

__all__ = ["bell", "block_edges", "fold", "ilct", "lct", "max_overlap", "unfold"]


def bell(overlap: int) -> tuple[np.ndarray, np.ndarray]:
    """The smooth cutoff over one fold: ``(r(t_j), r(-t_j))`` for ``t_j = (j + 1/2) / overlap``, each ``(overlap,)``.

    ``r(t) = sin(pi/4 (1 + sin(pi t / 2)))`` on ``[-1, 1]`` (Wickerhauser's iterated sine): it rises from 0 to
    1 with zero slope at both ends and ``r(t)^2 + r(-t)^2 = 1`` (the condition for an orthogonal fold).
    """
    overlap = _int_at_least(overlap, "overlap", 0)
    t = (np.arange(overlap) + 0.5) / max(overlap, 1)
    rise = np.sin(0.25 * np.pi * (1.0 + np.sin(0.5 * np.pi * t)))
    fall = np.sin(0.25 * np.pi * (1.0 - np.sin(0.5 * np.pi * t)))
    return rise, fall


def block_edges(n_frames: int, window: int) -> np.ndarray:
    """Edges of blocks of ``window`` frames over ``n_frames``; the last block takes the remainder.

    Returns ``[0, N, 2N, ..., (K-1) N, T]`` with ``K = T // N`` blocks: every block has ``N`` frames except
    the last, which has ``N + T mod N`` (``N <= T`` needed).
    """
    T = _int_at_least(n_frames, "n_frames", 1)
    N = _int_at_least(window, "window", 1)
    if N > T:
        raise MocycleError(f"window must be at most the number of frames ({T}); got {N}")
    K = T // N
    return np.concatenate([np.arange(K) * N, [T]]).astype(np.int64)


def fold(X, edges, overlap: int) -> np.ndarray:
    """Malvar's fold of ``X`` (``(T,)`` or ``(T, D)``) at the interior ``edges`` over ``overlap`` samples each side."""
    A, edges, overlap = _check(X, edges, overlap)
    return _fold(A, edges, overlap, inverse=False)


def unfold(Y, edges, overlap: int) -> np.ndarray:
    """The inverse of :func:`fold` (the same rotation, transposed)."""
    A, edges, overlap = _check(Y, edges, overlap)
    return _fold(A, edges, overlap, inverse=True)


def lct(X, edges, overlap: int | None = None) -> np.ndarray:
    """Lapped cosine transform of ``X`` (``(T,)`` or ``(T, D)``) on blocks ``edges``; same shape as ``X``.

    ``edges``: increasing block edges from 0 to T (e.g. :func:`block_edges`).  ``overlap``: samples folded
    on each side of an interior edge (default: as large as allowed, ``min(block length) // 2``).
    """
    A, edges, overlap = _check(X, edges, overlap, copy=False)
    return _by_columns(A, lambda B: _dct4_blocks(_fold(B, edges, overlap, inverse=False), edges))


def ilct(C, edges, overlap: int | None = None) -> np.ndarray:
    """Inverse of :func:`lct`: DCT-IV of every block, then the unfold.  Same shape as ``C``."""
    A, edges, overlap = _check(C, edges, overlap, copy=False)
    return _by_columns(A, lambda B: _fold(_dct4_blocks(B, edges), edges, overlap, inverse=True))


#: columns transformed at a time (the transform works on each column alone: the fold's and the DCT's
#: temporaries are a few times a block of columns, not of the whole array)
COLUMNS = 8


def _by_columns(A: np.ndarray, transform) -> np.ndarray:
    """``transform`` (which may change its argument) applied to copies of ``COLUMNS`` columns of ``A`` at a time."""
    if A.ndim == 1:
        return transform(A.copy())
    out = np.empty_like(A)
    for c0 in range(0, A.shape[1], COLUMNS):
        out[:, c0:c0 + COLUMNS] = transform(A[:, c0:c0 + COLUMNS].copy())
    return out


# -- internals ---------------------------------------------------------------------------------------------------


def _int_at_least(value, name: str, minimum: int) -> int:
    return _validate.integer(name, value, minimum)


def max_overlap(edges: np.ndarray) -> int:
    """The largest overlap the blocks allow: no sample is folded twice (inner blocks fold at both ends)."""
    lengths = np.diff(edges)
    if lengths.size < 2:
        return 0
    inner = lengths[1:-1]
    limit = min(int(lengths[0]), int(lengths[-1]))
    if inner.size:
        limit = min(limit, int(inner.min()) // 2)
    return limit


def _check(X, edges, overlap, copy: bool = True):
    try:
        A = np.asarray(X, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise MocycleError(f"X must be a (T,) or (T, D) array of numbers; got {type(X).__name__} ({exc})") from None
    if A.ndim not in (1, 2) or A.shape[0] == 0:
        raise MocycleError(f"X must be a non-empty (T,) or (T, D) array; got shape {A.shape}")
    if not np.all(np.isfinite(A)):
        raise MocycleError("X must be finite (no NaN or infinite values)")
    T = A.shape[0]
    try:
        e = np.asarray(edges)
    except (TypeError, ValueError):
        raise MocycleError("edges must be a 1-D array of integer frame indices") from None
    if e.ndim != 1 or e.size < 2 or not np.issubdtype(e.dtype, np.integer):
        raise MocycleError(f"edges must be a 1-D integer array [0, ..., {T}] with at least 2 entries; got {edges!r}")
    e = e.astype(np.int64)
    if e[0] != 0 or e[-1] != T or np.any(np.diff(e) <= 0):
        raise MocycleError(f"edges must increase strictly from 0 to the number of frames ({T}); got "
                           f"{e[:3].tolist()}...{e[-2:].tolist()}")
    limit = max_overlap(e)
    if overlap is None:
        overlap = limit
    overlap = _int_at_least(overlap, "overlap", 0)
    if overlap > limit:
        raise MocycleError(f"overlap must be at most {limit} samples for these blocks (half the shortest inner "
                           f"block); got {overlap}")
    return (A.copy() if copy else A), e, overlap


def _fold(A: np.ndarray, edges: np.ndarray, overlap: int, inverse: bool) -> np.ndarray:
    inner = edges[1:-1]
    if overlap == 0 or inner.size == 0:
        return A
    rise, fall = bell(overlap)
    j = np.arange(overlap)
    right = inner[:, None] + j  # (K-1, overlap): b + t
    left = inner[:, None] - 1 - j  # b - t
    shape = (1, overlap) + (1,) * (A.ndim - 1)
    r, m = rise.reshape(shape), fall.reshape(shape)
    xr, xl = A[right], A[left]
    if inverse:
        A[right], A[left] = r * xr - m * xl, r * xl + m * xr
    else:
        A[right], A[left] = r * xr + m * xl, r * xl - m * xr
    return A


def _dct4_blocks(A: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Orthonormal DCT-IV of every block (blocks of equal length in one call)."""
    lengths = np.diff(edges)
    out = np.empty_like(A)
    for L in np.unique(lengths):
        starts = edges[:-1][lengths == L]
        idx = starts[:, None] + np.arange(L)  # (n, L)
        out[idx] = sp_fft.dct(A[idx], type=4, norm="ortho", axis=1)
    return out
