"""The 1-D filters foot locking uses, along the first axis with the ends repeated beyond the edges.

Equal to ``scipy.ndimage``'s ``gaussian_filter1d``, ``maximum_filter1d``, ``minimum_filter1d`` and
``uniform_filter1d`` with
``mode="nearest"`` (within rounding; the tests compare them), written on numpy's sliding windows so that
locking the feet does not import ``scipy.ndimage`` (about 0.1 s of every ``mocycle loop`` that locks).
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ..phase.period import moving_average

TRUNCATE = 4.0  # the Gaussian kernel reaches this many standard deviations, as scipy's


def _edge_padded(x: np.ndarray, before: int, after: int) -> np.ndarray:
    """``x`` ``(T, ...)`` with its first sample repeated ``before`` times ahead of it and its last ``after`` times
    behind it along axis 0: ``np.pad(x, ..., mode="edge")`` (a new C-ordered array), without its overhead."""
    return np.concatenate([np.repeat(x[:1], before, axis=0), x, np.repeat(x[-1:], after, axis=0)])


def gaussian(x: np.ndarray, sigma: float) -> np.ndarray:
    """``x`` ``(T, ...)`` smoothed along axis 0 by a Gaussian of ``sigma`` samples (``gaussian_filter1d``)."""
    x = np.asarray(x, dtype=np.float64)
    radius = int(TRUNCATE * float(sigma) + 0.5)
    if radius == 0 or x.shape[0] == 0:
        return x.copy()
    k = np.arange(-radius, radius + 1, dtype=np.float64)
    w = np.exp(-0.5 / (float(sigma) ** 2) * k ** 2)
    w /= w.sum()
    return sliding_window_view(_edge_padded(x, radius, radius), 2 * radius + 1, axis=0) @ w


def maximum(x: np.ndarray, size: int) -> np.ndarray:
    """The largest of ``x`` ``(T,)`` over ``size`` samples about each one (``maximum_filter1d``)."""
    x = np.asarray(x, dtype=np.float64)
    size = int(size)
    if size <= 1 or x.size == 0:
        return x.copy()
    return sliding_window_view(_edge_padded(x, size // 2, size - 1 - size // 2), size).max(axis=-1)


def minimum(x: np.ndarray, size: int) -> np.ndarray:
    """The smallest of ``x`` ``(T, ...)`` over ``size`` samples about each one, along axis 0
    (``minimum_filter1d``), in O(T) whatever ``size`` (van Herk / Gil-Werman: running minima within blocks
    of ``size`` samples, forwards and backwards; a window spans at most two blocks)."""
    x = np.asarray(x, dtype=np.float64)
    size = int(size)
    T = x.shape[0]
    if size <= 1 or T == 0:
        return x.copy()
    size = min(size, 2 * T - 1)  # a wider window holds every sample already
    n = T + size - 1
    blocks = -(-n // size)
    # the edges repeated, then +inf up to whole blocks
    padded = np.concatenate([_edge_padded(x, size // 2, size - 1 - size // 2),
                             np.full((blocks * size - n,) + x.shape[1:], np.inf)])
    b = padded.reshape((blocks, size) + x.shape[1:])
    forward = np.minimum.accumulate(b, axis=1).reshape(padded.shape)
    backward = np.minimum.accumulate(b[:, ::-1], axis=1)[:, ::-1].reshape(padded.shape)
    return np.minimum(backward[:T], forward[size - 1:size - 1 + T])


def uniform(x: np.ndarray, size: int) -> np.ndarray:
    """The mean of ``x`` ``(T,)`` over ``size`` samples about each one (``uniform_filter1d``)."""
    return moving_average(x, size)
